// The force scatter without atomics (kernels/scatter.hpp): the chunk plan covers every list
// position once, no two chunks of a colour share a node, first fit uses as many colours as the
// deepest overlap of the chunks' node intervals, and the chunked forces equal the atomic ones.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <vector>

#include "host/simulation.hpp"
#include "kernels/bond_forces.hpp"
#include "kernels/fe_forces.hpp"
#include "test_util.hpp"

namespace fracta {
namespace {

// The device path (kAtomicScatter) cuts no chunk plan: every kernel adds atomically there. Checks
// that contract and returns true on the device path, where the plan tests have no plan to
// inspect and stop after it.
bool device_path_without_plan(const ScatterPlan& plan, int count) {
  if (!kAtomicScatter) return false;
  EXPECT_EQ(plan.colors, 0);
  EXPECT_FALSE(plan.usable(count));
  return true;
}

// Checks the plan against the nodes each list position really touches (item_nodes(k)). With
// `optimal`, the list is every item in order, and first fit must use as many colours as the
// deepest overlap of the chunks' node intervals (optimal for intervals).
void expect_valid_plan(const ScatterPlan& plan, int count,
                       const std::vector<std::vector<int>>& item_nodes, bool optimal) {
  ASSERT_TRUE(plan.usable(count));
  const auto chunks = Kokkos::create_mirror_view_and_copy(HostSpace(), plan.color_chunks);
  const auto begin = Kokkos::create_mirror_view_and_copy(HostSpace(), plan.chunk_begin_position);
  std::vector<int> seen(count, 0);
  std::vector<std::pair<int, int>> intervals;  // per chunk
  for (int k = 0; k < plan.colors; ++k) {
    std::set<int> colour_nodes;
    for (int i = plan.color_offset[k]; i < plan.color_offset[k + 1]; ++i) {
      const int c = chunks(i);
      std::set<int> chunk_nodes;
      int lo = 1 << 30, hi = -1;
      for (int p = begin(c); p < begin(c + 1); ++p) {
        ++seen[p];
        for (int n : item_nodes[p]) {
          chunk_nodes.insert(n);
          lo = std::min(lo, n);
          hi = std::max(hi, n);
        }
      }
      for (int n : chunk_nodes)
        EXPECT_EQ(colour_nodes.count(n), 0u) << "colour " << k << " node " << n;
      colour_nodes.insert(chunk_nodes.begin(), chunk_nodes.end());
      if (hi >= 0) intervals.push_back({lo, hi});
    }
  }
  for (int p = 0; p < count; ++p) ASSERT_EQ(seen[p], 1) << "list position " << p;
  if (!optimal) return;
  // The deepest overlap of the intervals (a sweep over their ends).
  std::vector<std::pair<int, int>> events;
  for (const auto& iv : intervals) {
    events.push_back({iv.first, +1});
    events.push_back({iv.second + 1, -1});
  }
  std::sort(events.begin(), events.end());
  int depth = 0, deepest = 0;
  for (const auto& ev : events) deepest = std::max(deepest, depth += ev.second);
  EXPECT_EQ(plan.colors, deepest);
}

std::vector<std::vector<int>> active_element_nodes(const Elements& el) {
  const auto active = Kokkos::create_mirror_view_and_copy(HostSpace(), el.active);
  const auto nodes = Kokkos::create_mirror_view_and_copy(HostSpace(), el.nodes);
  std::vector<std::vector<int>> r(el.active_count);
  for (int k = 0; k < el.active_count; ++k)
    for (int a = 0; a < 4; ++a) r[k].push_back(nodes(active(k), a));
  return r;
}

TEST(Scatter, ChunkSizeIsAMultipleOfEightWithinItsBounds) {
  for (int count : {1, 7, 100, 4096, 50000, 131072, 10000000}) {
    const int size = scatter_chunk_size(count);
    EXPECT_EQ(size % 8, 0) << count;
    EXPECT_GE(size, 64);
    EXPECT_LE(size, 2048);
    const int bond_size = scatter_chunk_size(count, kBondChunkMax);
    EXPECT_EQ(bond_size % 8, 0) << count;
    EXPECT_GE(bond_size, size);
    EXPECT_LE(bond_size, kBondChunkMax);
  }
  EXPECT_EQ(scatter_chunk_size(10000000, kBondChunkMax), kBondChunkMax);
}

TEST(Scatter, ElementPlanCoversTheActiveListAndColoursShareNoNode) {
  // 150 x 90 cells: 13500 elements, chunks of 208, rows of 151 nodes.
  Model m = build_model(test::rectangle_case(150, 90, 1e-3));
  if (device_path_without_plan(m.elements.scatter, m.elements.active_count)) return;
  expect_valid_plan(m.elements.scatter, m.elements.active_count, active_element_nodes(m.elements),
                    true);
  EXPECT_EQ(m.elements.scatter.colors, 2);  // rows shorter than a chunk: two colours
  // A list with holes (every third element gone, as after conversions), rebuilt.
  auto active = Kokkos::create_mirror_view_and_copy(HostSpace(), m.elements.active);
  int n = 0;
  for (int e = 0; e < m.elements.active_count; ++e)
    if (e % 3 != 1) active(n++) = e;
  m.elements.active_count = n;
  Kokkos::deep_copy(m.elements.active, active);
  EXPECT_FALSE(m.elements.scatter.usable(m.elements.active_count));  // stale: not used
  update_scatter_plan(m.elements);  // the same chunks and colours, located in the new list
  EXPECT_EQ(m.elements.scatter.colors, 2);
  expect_valid_plan(m.elements.scatter, m.elements.active_count, active_element_nodes(m.elements),
                    false);
}

TEST(Scatter, BondPlanCoversTheBondListAndColoursShareNoDisc) {
  Case c = test::rectangle_case(120, 60, 1e-3, 70e9, 0.25, 2700.0, Formulation::plane_stress);
  c.bodies[0].method = BodyMethod::de;
  Model m = build_model(c);
  const int count = bond_list_count(m.bonds);
  ASSERT_GT(count, 4 * 120 * 60 - 1000);
  if (device_path_without_plan(m.bonds.scatter, count)) return;
  const auto list = Kokkos::create_mirror_view_and_copy(HostSpace(), m.bonds.used);
  const auto ends = Kokkos::create_mirror_view_and_copy(HostSpace(), m.bonds.nodes);
  std::vector<std::vector<int>> item_nodes(count);
  for (int k = 0; k < count; ++k) {
    const int b = bonds_listed(m.bonds) ? list(k) : k;
    item_nodes[k] = {ends(b, 0), ends(b, 1)};
  }
  expect_valid_plan(m.bonds.scatter, count, item_nodes, !bonds_listed(m.bonds));
}

// The FE forces of a distorted, spinning, yielding block by the chunk path and by the atomic
// path (the same element arithmetic; only the order of the node sums differs). On the device
// path both evaluations add atomically: the same bound holds between two atomic orders.
TEST(Scatter, ChunkedElementForcesEqualAtomicOnes) {
  Case c = test::rectangle_case(64, 48, 1e-3, 200e9, 0.3, 7800.0);
  c.materials[0].model = MaterialModel::bilinear_j2;
  c.materials[0].yield_stress = 100e6;
  c.materials[0].plastic_modulus = 1e9;
  Model m = build_model(c);
  auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), m.nodes.x);
  auto v = Kokkos::create_mirror_view_and_copy(HostSpace(), m.nodes.v);
  for (int n = 0; n < m.nodes.count; ++n) {
    const double X = x(n, 0) / 0.064, Y = x(n, 1) / 0.048;
    v(n, 0) = 50.0 * X * X * (1.0 + Y) + 3.0 * std::sin(17.0 * n);
    v(n, 1) = 50.0 * (X * Y - Y * Y * Y);
  }
  Kokkos::deep_copy(m.nodes.v, v);
  FeParams p = m.fe;
  p.dt = 1e-7;
  ASSERT_EQ(m.elements.scatter.usable(m.elements.active_count), !kAtomicScatter);
  // Ten evaluations build up a stress state, yielding in part of the block.
  for (int pass = 0; pass < 10; ++pass) compute_fe_forces(m.nodes, m.elements, m.materials, p);
  const Elements chunked = m.elements;
  Elements atomic = m.elements;
  atomic.scatter = ScatterPlan{};
  // Same starting state for both: the stresses are updated in place, so save and restore them.
  // (create_mirror always copies; create_mirror_view would alias host views.)
  const auto stress0 = Kokkos::create_mirror(HostSpace(), m.elements.stress);
  const auto epeq0 = Kokkos::create_mirror(HostSpace(), m.elements.epeq);
  const auto q0 = Kokkos::create_mirror(HostSpace(), m.elements.hourglass_disp);
  Kokkos::deep_copy(stress0, m.elements.stress);
  Kokkos::deep_copy(epeq0, m.elements.epeq);
  Kokkos::deep_copy(q0, m.elements.hourglass_disp);
  std::vector<double> forces[2], dts;
  for (int path = 0; path < 2; ++path) {
    Kokkos::deep_copy(m.elements.stress, stress0);
    Kokkos::deep_copy(m.elements.epeq, epeq0);
    Kokkos::deep_copy(m.elements.hourglass_disp, q0);
    Kokkos::deep_copy(m.nodes.f, 0.0);
    dts.push_back(compute_fe_forces(m.nodes, path == 0 ? chunked : atomic, m.materials, p).dt_min);
    const auto f = Kokkos::create_mirror_view_and_copy(HostSpace(), m.nodes.f);
    for (int n = 0; n < m.nodes.count; ++n)
      for (int d = 0; d < 2; ++d) forces[path].push_back(f(n, d));
  }
  int yielded = 0;
  for (size_t q = 0; q < epeq0.extent(0); ++q) yielded += epeq0(q) > 0.0;
  EXPECT_GT(yielded, 0);
  EXPECT_LT(yielded, m.elements.active_count);
  double scale = 0.0, diff = 0.0;
  for (size_t i = 0; i < forces[0].size(); ++i) {
    scale = std::max(scale, std::fabs(forces[0][i]));
    diff = std::max(diff, std::fabs(forces[0][i] - forces[1][i]));
  }
  ASSERT_GT(scale, 0.0);
  EXPECT_LT(diff / scale, 1e-13);  // round-off of sums of at most 4 terms
  EXPECT_EQ(dts[0], dts[1]);
}

// A lattice run step by step with the chunk path and with the atomic path: the same motion up to
// the round-off of the node sums (a sum of at most 8 bond terms per disc, in another order). On
// the device path both runs add atomically, in orders that differ between them: the same bound.
TEST(Scatter, ChunkedBondForcesEqualAtomicOnes) {
  Case c = test::rectangle_case(40, 30, 1e-3, 70e9, 0.25, 2700.0);
  c.bodies[0].method = BodyMethod::de;
  c.sim.end_time = 1.0;
  test::add_pressure(c, test::segment(0, 0, 0, 0.03), {0.0}, {200e6});
  Simulation chunked(c), atomic(c);
  ASSERT_EQ(chunked.model().bonds.scatter.usable(bond_list_count(chunked.model().bonds)),
            !kAtomicScatter);
  atomic.model().bonds.scatter = ScatterPlan{};
  for (int s = 0; s < 40; ++s) {
    chunked.step();
    atomic.step();
  }
  const auto xa = Kokkos::create_mirror_view_and_copy(HostSpace(), chunked.model().nodes.x);
  const auto xb = Kokkos::create_mirror_view_and_copy(HostSpace(), atomic.model().nodes.x);
  const auto x0 = Kokkos::create_mirror_view_and_copy(HostSpace(), chunked.model().nodes.x0);
  double moved = 0.0, diff = 0.0;
  for (size_t n = 0; n < xa.extent(0); ++n)
    for (int d = 0; d < 2; ++d) {
      moved = std::max(moved, std::fabs(xa(n, d) - x0(n, d)));
      diff = std::max(diff, std::fabs(xa(n, d) - xb(n, d)));
    }
  ASSERT_GT(moved, 1e-7);  // the load moved the discs
  EXPECT_LT(diff / moved, 1e-10);
}

// A mesh numbered in no spatial order (its elements shuffled): every chunk spans almost the
// whole mesh, more colours than the plan allows, so there is no plan and the kernel adds
// atomically; the node forces stay those of the ordered mesh (the same elements). On the device
// path neither mesh has a plan.
TEST(Scatter, ATangledMeshFallsBackToAtomicAdds) {
  Model m = build_model(test::rectangle_case(64, 64, 1e-3));
  auto v = Kokkos::create_mirror_view_and_copy(HostSpace(), m.nodes.v);
  for (int n = 0; n < m.nodes.count; ++n)
    v(n, 0) = std::sin(0.37 * n), v(n, 1) = std::cos(0.11 * n);
  Kokkos::deep_copy(m.nodes.v, v);
  FeParams p = m.fe;
  p.dt = 1e-8;
  ASSERT_EQ(m.elements.scatter.usable(m.elements.active_count), !kAtomicScatter);
  compute_fe_forces(m.nodes, m.elements, m.materials, p);
  const auto ordered = Kokkos::create_mirror(HostSpace(), m.nodes.f);
  Kokkos::deep_copy(ordered, m.nodes.f);
  auto connectivity = Kokkos::create_mirror(HostSpace(), m.elements.nodes);
  Kokkos::deep_copy(connectivity, m.elements.nodes);
  const int count = m.elements.count;
  for (int e = 0; e < count; ++e) {
    const int other = static_cast<int>((e * 7919L + 13) % count);
    for (int a = 0; a < 4; ++a) std::swap(connectivity(e, a), connectivity(other, a));
  }
  Kokkos::deep_copy(m.elements.nodes, connectivity);
  m.elements.scatter = ScatterPlan{};
  update_scatter_plan(m.elements);  // cut anew from the shuffled mesh
  EXPECT_FALSE(m.elements.scatter.usable(count));
  EXPECT_EQ(m.elements.scatter.colors, 0);
  Kokkos::deep_copy(m.nodes.f, 0.0);
  Kokkos::deep_copy(m.elements.stress, 0.0);  // the first call updated them: start again
  Kokkos::deep_copy(m.elements.hourglass_disp, 0.0);
  compute_fe_forces(m.nodes, m.elements, m.materials, p);
  const auto tangled = Kokkos::create_mirror_view_and_copy(HostSpace(), m.nodes.f);
  double scale = 0.0, diff = 0.0;
  for (int n = 0; n < m.nodes.count; ++n)
    for (int d = 0; d < 2; ++d) {
      scale = std::max(scale, std::fabs(ordered(n, d)));
      diff = std::max(diff, std::fabs(ordered(n, d) - tangled(n, d)));
    }
  ASSERT_GT(scale, 0.0);
  EXPECT_LT(diff / scale, 1e-13);
}

}  // namespace
}  // namespace fracta
