// Crack measurement (docs/output.md, "Measuring cracks"): the crack that grows from a given
// point (a notch tip), its tip, length and path, and its branches, from the broken bonds.
// Post-processing on the host, as scripts/cracks.py does on an output file; tests call it on a
// Simulation's state.
//
// The crack is the set of broken bonds (their reference midpoints) joined to the seed by steps
// of at most `link` (m); its tip is the point of that set farthest from the seed along the set
// (the geodesic distance through it, not the straight-line distance), so damage beside the crack
// or near the seed is never taken for the tip, and a crack that turns is measured along its
// path. A branch is a part of the set that leaves the path to the tip (or an earlier branch)
// and reaches at least `min_branch` (m) from it, measured along the set.
#pragma once
#include <vector>

#include "host/case.hpp"

namespace fracta {

class Simulation;

struct CrackBranch {
  Vec2 junction{0, 0};  // where it leaves the crack (m, reference configuration)
  Vec2 tip{0, 0};       // its far end (m)
  double length = 0;    // along the set from the junction (m)
};

struct CrackTrace {
  bool found = false;                 // a broken bond lies within `link` of the seed
  Vec2 tip{0, 0};                     // m, reference configuration
  double length = 0;                  // m, from the seed along the crack to the tip
  std::vector<Vec2> path;             // seed, ..., tip
  std::vector<CrackBranch> branches;  // longest first
  int points = 0;                     // broken bonds joined to the seed
};

// points: reference midpoints of the broken bonds (m); seed: where the crack starts (m).
CrackTrace trace_crack(const std::vector<Vec2>& points, Vec2 seed, double link, double min_branch,
                       int max_branches = 8);

// The same for the broken bonds of a running simulation.
CrackTrace trace_crack(Simulation& sim, Vec2 seed, double link, double min_branch,
                       int max_branches = 8);

}  // namespace fracta
