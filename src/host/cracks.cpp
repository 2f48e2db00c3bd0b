// Crack tracing (cracks.hpp): Dijkstra's shortest paths from the seed through the broken-bond
// midpoints, neighbours found in a grid of `link`-sized bins.
#include "host/cracks.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <queue>
#include <unordered_map>
#include <utility>

#include "host/simulation.hpp"

namespace fracta {
namespace {

// Points binned on a square grid of side `link`: the neighbours within `link` of a point lie in
// its bin and the eight around it.
class PointGrid {
 public:
  PointGrid(const std::vector<Vec2>& points, double link) : points_(points), link_(link) {
    for (int i = 0; i < static_cast<int>(points.size()); ++i)
      bins_[key(bin(points[i]))].push_back(i);
  }

  template <class F>
  void for_each_near(const Vec2& p, F&& visit) const {
    const auto [bx, by] = bin(p);
    for (long dx = -1; dx <= 1; ++dx)
      for (long dy = -1; dy <= 1; ++dy) {
        const auto it = bins_.find(key({bx + dx, by + dy}));
        if (it == bins_.end()) continue;
        for (int j : it->second) {
          const double d = std::hypot(points_[j][0] - p[0], points_[j][1] - p[1]);
          if (d <= link_) visit(j, d);
        }
      }
  }

 private:
  std::pair<long, long> bin(const Vec2& p) const {
    return {static_cast<long>(std::floor(p[0] / link_)),
            static_cast<long>(std::floor(p[1] / link_))};
  }
  // Distinct bins, distinct keys (a shared key would only make a bin hold more candidates:
  // the distance test decides).
  static long long key(std::pair<long, long> b) {
    return static_cast<long long>(static_cast<std::uint64_t>(static_cast<std::uint32_t>(b.first))
                                      << 32 |
                                  static_cast<std::uint32_t>(b.second));
  }
  const std::vector<Vec2>& points_;
  double link_;
  std::unordered_map<long long, std::vector<int>> bins_;
};

constexpr double kUnreached = std::numeric_limits<double>::infinity();

// Shortest distances through the points from several sources at once (Dijkstra): each source is
// a point and its starting distance. previous: the point before on the path (-1 at a source);
// origin: the source the path starts from.
struct ShortestPaths {
  std::vector<double> distance;
  std::vector<int> previous, origin;

  // The reached point farthest from the sources (-1 if none).
  int farthest() const {
    int best = -1;
    for (int i = 0; i < static_cast<int>(distance.size()); ++i)
      if (distance[i] != kUnreached && (best < 0 || distance[i] > distance[best])) best = i;
    return best;
  }
};

ShortestPaths shortest_paths(const PointGrid& grid, const std::vector<Vec2>& points,
                             const std::vector<std::pair<int, double>>& sources) {
  const int n = static_cast<int>(points.size());
  ShortestPaths paths{std::vector<double>(n, kUnreached), std::vector<int>(n, -1),
                      std::vector<int>(n, -1)};
  using Entry = std::pair<double, int>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> queue;
  for (const auto& [i, d] : sources)
    if (d < paths.distance[i]) {
      paths.distance[i] = d;
      paths.origin[i] = i;
      queue.push({d, i});
    }
  while (!queue.empty()) {
    const auto [d, i] = queue.top();
    queue.pop();
    if (d > paths.distance[i]) continue;
    grid.for_each_near(points[i], [&, d = d, i = i](int j, double step) {
      if (d + step < paths.distance[j]) {
        paths.distance[j] = d + step;
        paths.previous[j] = i;
        paths.origin[j] = paths.origin[i];
        queue.push({paths.distance[j], j});
      }
    });
  }
  return paths;
}

}  // namespace

CrackTrace trace_crack(const std::vector<Vec2>& points, const Vec2 seed, const double link,
                       const double min_branch, const int max_branches) {
  CrackTrace trace;
  const int n = static_cast<int>(points.size());
  if (n == 0 || !(link > 0)) return trace;
  const PointGrid grid(points, link);
  // From the seed: the points within a link of it start at their distance to it.
  std::vector<std::pair<int, double>> sources;
  grid.for_each_near(seed, [&](int j, double d) { sources.push_back({j, d}); });
  const ShortestPaths from_seed = shortest_paths(grid, points, sources);
  const int tip = from_seed.farthest();
  if (tip < 0) return trace;
  for (double d : from_seed.distance) trace.points += d != kUnreached;
  trace.found = true;
  trace.tip = points[tip];
  trace.length = from_seed.distance[tip];
  // The path, and the points on the crack so far (the path, then each branch's).
  std::vector<char> on_crack(n, 0);
  for (int i = tip; i >= 0; i = from_seed.previous[i]) {
    trace.path.push_back(points[i]);
    on_crack[i] = 1;
  }
  trace.path.push_back(seed);
  std::reverse(trace.path.begin(), trace.path.end());
  // Branches: the reached point farthest from the crack through the set (shortest paths from
  // every point on the crack at once), as long as that is at least min_branch; its path then
  // joins the crack. Measured from the crack, not from the seed, so a chain of points running
  // beside the path (the midpoints of a crack's edge and diagonal bonds interleave) is no branch.
  while (static_cast<int>(trace.branches.size()) < max_branches) {
    sources.clear();
    for (int i = 0; i < n; ++i)
      if (on_crack[i]) sources.push_back({i, 0.0});
    const ShortestPaths from_crack = shortest_paths(grid, points, sources);
    const int best = from_crack.farthest();
    if (best < 0 || from_crack.distance[best] < min_branch) break;
    CrackBranch branch;
    branch.junction = points[from_crack.origin[best]];
    branch.tip = points[best];
    branch.length = from_crack.distance[best];
    trace.branches.push_back(branch);
    for (int i = best; i >= 0 && !on_crack[i]; i = from_crack.previous[i]) on_crack[i] = 1;
  }
  return trace;
}

CrackTrace trace_crack(Simulation& sim, const Vec2 seed, const double link, const double min_branch,
                       const int max_branches) {
  const Model& m = sim.model();
  const auto state = Kokkos::create_mirror_view_and_copy(HostSpace(), m.bonds.state);
  const auto ends = Kokkos::create_mirror_view_and_copy(HostSpace(), m.bonds.nodes);
  const auto x0 = Kokkos::create_mirror_view_and_copy(HostSpace(), m.nodes.x0);
  std::vector<Vec2> points;
  for (int b = 0; b < m.bonds.count; ++b) {
    if (state(b) != kBondBroken) continue;
    const int i = ends(b, 0), j = ends(b, 1);
    points.push_back({0.5 * (x0(i, 0) + x0(j, 0)), 0.5 * (x0(i, 1) + x0(j, 1))});
  }
  return trace_crack(points, seed, link, min_branch, max_branches);
}

}  // namespace fracta
