// Contact between discs (DESIGN.md 1.2-1.3): the Verlet-list pre-search and the force law,
// orchestrated on the host; all data stay on the device.
//
// Each step: update(nodes) rebuilds the candidate list when some disc moved more than skin/2
// since the last build (or on the first call, after set_disc_nodes or set_all_pairs);
// compute_forces() then adds the contact forces and moments to nodes.f / nodes.moment (which
// the integrator zeroes) and reports energies. Which pairs are joined (bond, element) is read
// from the Topology at every force evaluation, so a bond breaking between two builds turns the
// pair into a contact at once.
//
// Requirements on Nodes: the particle views (radius, inertia, spin, moment, contact_stiffness,
// particle) are allocated for every node. The contact stiffness of a disc is
// nodes.contact_stiffness (lambda k1, set by the model), so ContactParams::stiffness_factor is
// not used here; damping_ratio and friction are.
#pragma once
#include <array>
#include <vector>

#include "host/case.hpp"
#include "kernels/contact_forces.hpp"
#include "kernels/neighbor_search.hpp"
#include "kernels/state.hpp"

namespace fracta {

struct ContactStepResult {
  double elastic_energy = 0;  // J, sum of 1/2 k delta^2 at the end of the step
  double dissipated = 0;      // J, damping + friction work of this step (>= 0)
  long touching = 0;          // pairs with overlap > 0 that are not joined
};

class ContactSystem {
 public:
  // disc_nodes: the node ids that are contact discs (particles and FE boundary nodes), any
  // order, duplicates ignored. skin: Verlet skin (m), >= 0 (0 = rebuild whenever a disc moves).
  ContactSystem(std::vector<int> disc_nodes, const ContactParams& params, double skin);

  // Rebuilds the candidate list if needed; returns true if it did.
  bool update(const Nodes& nodes);
  ContactStepResult compute_forces(const Nodes& nodes, const Topology& topo, double dt);

  long candidate_count() const { return pair_count_; }
  long rebuild_count() const { return rebuilds_; }
  int disc_count() const { return static_cast<int>(discs_.extent(0)); }
  double skin() const { return skin_; }
  // The O(N^2) builder (test oracle, benchmark baseline); forces a rebuild at the next update.
  void set_all_pairs(bool on);
  // New set of discs (e.g. after a conversion created particles); forces a rebuild.
  void set_disc_nodes(std::vector<int> disc_nodes);
  // Forces a rebuild at the next update.
  void invalidate() { built_ = false; }
  // Candidate pairs (i < j), sorted, copied to the host: for tests.
  std::vector<std::array<int, 2>> candidate_pairs_host() const;
  // Device views of the candidates [0, candidate_count()).
  View<const int*> pair_i() const { return pair_i_; }
  View<const int*> pair_j() const { return pair_j_; }
  // The contact discs' node ids, increasing: contact forces act on these nodes only.
  View<const int*> discs() const { return discs_; }
  const ContactLaw& law() const { return law_; }

  // The candidate list and its reference positions, for checkpoints: a restart that rebuilt
  // the list at another step than the uninterrupted run would change the order of the force
  // sums (and so the last bits of the result); restoring it makes the restart bitwise.
  struct ListState {
    std::vector<int> pair_i, pair_j;  // candidate_count() pairs, in list order
    std::vector<double> x_build;      // disc_count() x 2 positions at the last build (m)
    bool built = false;
    long rebuilds = 0;
  };
  ListState list_state() const;
  // Throws std::invalid_argument if the sizes do not match this system's discs.
  void restore_list_state(const ListState& s);

 private:
  void rebuild(const Nodes& nodes);

  View<int*> discs_;           // node ids, increasing
  View<double* [2]> x_build_;  // disc positions at the last build
  View<int*> cell_start_, cell_cursor_, cell_discs_;
  View<int*> row_offset_;
  View<int*> pair_i_, pair_j_;  // capacity >= pair_count_
  View<int* [3]> pair_joins_;   // pair_topology of the list, when joins_built_
  bool joins_built_ = false;
  const void* joins_topology_ = nullptr;  // the Topology (its node -> bond list) they came from
  long pair_count_ = 0;
  long rebuilds_ = 0;
  bool built_ = false;
  bool all_pairs_ = false;
  double skin_ = 0;
  ContactLaw law_;
};

}  // namespace fracta
