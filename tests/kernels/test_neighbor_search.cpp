// Contact pre-search tests: the binned Verlet list against a brute-force host oracle.
// Every comparison here is exact (set equality): the binned search, the all-pairs search and
// the host oracle evaluate the same predicate |x_j - x_i|^2 < (r_i + r_j + skin)^2 on the same
// doubles, so there is no tolerance to state; a single missing or extra pair fails.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "host/contact.hpp"
#include "kernels/contact_test_util.hpp"

namespace fracta {
namespace {

using PairList = std::vector<std::array<int, 2>>;

// Polydisperse random packing: n discs of radius r0 * U(0.5, 1.5) in a square box whose
// size gives an area fraction of about `fraction` (overlaps allowed: it is a search test).
test::HostDiscs random_packing(int n, double r0, double fraction, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double side = std::sqrt(n * M_PI * r0 * r0 * 13.0 / 12.0 / fraction);
  test::HostDiscs h;
  for (int i = 0; i < n; ++i) h.add(side * u(rng), side * u(rng), r0 * (0.5 + u(rng)), 1.0, 1.0);
  return h;
}

// The oracle: every pair i < j with |x_j - x_i| < r_i + r_j + reach_extra, sorted.
PairList brute_force(const test::HostDiscs& h, double reach_extra) {
  PairList out;
  for (int i = 0; i < h.size(); ++i)
    for (int j = i + 1; j < h.size(); ++j) {
      const double dx = h.x[j] - h.x[i], dy = h.y[j] - h.y[i];
      const double reach = h.r[i] + h.r[j] + reach_extra;
      if (dx * dx + dy * dy < reach * reach) out.push_back({i, j});
    }
  return out;
}

std::vector<int> iota_nodes(int n) {
  std::vector<int> v(n);
  for (int i = 0; i < n; ++i) v[i] = i;
  return v;
}

void copy_positions(const test::HostDiscs& h, const Nodes& nodes) {
  auto x = Kokkos::create_mirror_view(nodes.x);
  for (int i = 0; i < h.size(); ++i) {
    x(i, 0) = h.x[i];
    x(i, 1) = h.y[i];
  }
  Kokkos::deep_copy(nodes.x, x);
}

bool contains_all(const PairList& list, const PairList& required) {
  return std::includes(list.begin(), list.end(), required.begin(), required.end());
}

TEST(NeighborSearch, RandomPackingsMatchBruteForce) {
  std::mt19937 rng(12345);
  for (int n : {1, 2, 17, 300, 4000}) {
    for (double fraction : {0.3, 0.8}) {
      const double r0 = 1e-3, skin = 0.3 * r0;
      const test::HostDiscs h = random_packing(n, r0, fraction, rng);
      const Nodes nodes = test::make_nodes(h);
      const PairList expected = brute_force(h, skin);
      ContactSystem binned(iota_nodes(n), ContactParams{}, skin);
      EXPECT_TRUE(binned.update(nodes));
      EXPECT_EQ(binned.candidate_pairs_host(), expected) << "n = " << n << " phi = " << fraction;
      EXPECT_EQ(binned.candidate_count(), static_cast<long>(expected.size()));
      ContactSystem all(iota_nodes(n), ContactParams{}, skin);
      all.set_all_pairs(true);
      all.update(nodes);
      EXPECT_EQ(all.candidate_pairs_host(), expected) << "n = " << n;
      if (n >= 300) {
        EXPECT_GT(expected.size(), static_cast<size_t>(n) / 2);  // not vacuous
      }
    }
  }
}

// The benchmark's scene: a jittered square lattice of spacing 2r (the cell size equals the
// spacing when the skin is 0), with and without skin.
TEST(NeighborSearch, JitteredLatticeMatchesBruteForce) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double r = 0.5e-3;
  test::HostDiscs h;
  for (int j = 0; j < 40; ++j)
    for (int i = 0; i < 40; ++i)
      h.add(2 * r * i + 0.05 * r * u(rng), 2 * r * j + 0.05 * r * u(rng), r, 1, 1);
  const Nodes nodes = test::make_nodes(h);
  for (double skin : {0.0, 0.1 * r}) {
    ContactSystem cs(iota_nodes(h.size()), ContactParams{}, skin);
    cs.update(nodes);
    const PairList expected = brute_force(h, skin);
    EXPECT_GT(expected.size(), 1000u);
    EXPECT_EQ(cs.candidate_pairs_host(), expected) << "skin " << skin;
  }
}

// The disc list may be any subset of the nodes, in any order: pairs are node ids, i < j.
TEST(NeighborSearch, SubsetOfNodesInAnyOrder) {
  std::mt19937 rng(7);
  const test::HostDiscs h = random_packing(500, 1e-3, 0.7, rng);
  const Nodes nodes = test::make_nodes(h);
  std::vector<int> subset;
  for (int i = 499; i >= 0; --i)
    if (i % 3 != 1) subset.push_back(i);
  const double skin = 2e-4;
  PairList expected;
  for (const auto& p : brute_force(h, skin))
    if (p[0] % 3 != 1 && p[1] % 3 != 1) expected.push_back(p);
  ContactSystem cs(subset, ContactParams{}, skin);
  cs.update(nodes);
  EXPECT_EQ(cs.candidate_pairs_host(), expected);
}

// Degenerate boxes and far-apart clusters (the grid is capped and its cells grow).
TEST(NeighborSearch, DegenerateAndSparseGeometries) {
  const double r = 1e-3, skin = 1e-4;
  test::HostDiscs line;  // all on one horizontal line: zero-height box
  for (int i = 0; i < 50; ++i) line.add(i * 1.9 * r, 0.0, r, 1.0, 1.0);
  test::HostDiscs far;  // two clusters 10^6 radii apart
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 10 * r);
  for (int i = 0; i < 200; ++i) far.add(u(rng) + (i % 2) * 1e3, u(rng) - (i % 2) * 1e3, r, 1, 1);
  test::HostDiscs same;  // coincident centres
  for (int i = 0; i < 5; ++i) same.add(0.5, 0.5, r, 1.0, 1.0);
  for (const test::HostDiscs* h : {&line, &far, &same}) {
    const Nodes nodes = test::make_nodes(*h);
    ContactSystem cs(iota_nodes(h->size()), ContactParams{}, skin);
    cs.update(nodes);
    const PairList expected = brute_force(*h, skin);
    EXPECT_FALSE(expected.empty());
    EXPECT_EQ(cs.candidate_pairs_host(), expected);
  }
  // No discs at all.
  test::HostDiscs none;
  none.add(0, 0, r, 1, 1);
  const Nodes nodes = test::make_nodes(none);
  ContactSystem empty(std::vector<int>{}, ContactParams{}, skin);
  EXPECT_TRUE(empty.update(nodes));
  EXPECT_EQ(empty.candidate_count(), 0);
  EXPECT_FALSE(empty.update(nodes));
}

// The device list is deterministic: rows in disc order, each row sorted by j, so the raw
// device order is the lexicographic order, whatever the thread count.
TEST(NeighborSearch, DeviceOrderIsDeterministic) {
  std::mt19937 rng(99);
  const test::HostDiscs h = random_packing(3000, 1e-3, 0.8, rng);
  const Nodes nodes = test::make_nodes(h);
  ContactSystem cs(iota_nodes(h.size()), ContactParams{}, 3e-4);
  cs.update(nodes);
  const long n = cs.candidate_count();
  ASSERT_GT(n, 0);
  auto pi = Kokkos::create_mirror_view_and_copy(HostSpace(), cs.pair_i());
  auto pj = Kokkos::create_mirror_view_and_copy(HostSpace(), cs.pair_j());
  PairList raw;
  for (long p = 0; p < n; ++p) raw.push_back({pi(p), pj(p)});
  EXPECT_TRUE(std::is_sorted(raw.begin(), raw.end()));
  EXPECT_EQ(std::adjacent_find(raw.begin(), raw.end()), raw.end());  // no duplicates
}

// Random motion: the list is rebuilt exactly when some disc moved more than skin/2 since the
// last build; a rebuilt list equals the oracle with the skin, and a kept list still contains
// every pair that touches now (the Verlet guarantee).
TEST(NeighborSearch, RandomMotionWithAndWithoutRebuilds) {
  std::mt19937 rng(2024);
  for (int n : {200, 2000}) {
    const double r0 = 1e-3, skin = 0.2 * r0;
    test::HostDiscs h = random_packing(n, r0, 0.75, rng);
    const Nodes nodes = test::make_nodes(h);
    for (bool all_pairs : {false, true}) {
      test::HostDiscs cur = h;
      copy_positions(cur, nodes);
      ContactSystem cs(iota_nodes(n), ContactParams{}, skin);
      cs.set_all_pairs(all_pairs);
      ASSERT_TRUE(cs.update(nodes));
      std::vector<double> bx = cur.x, by = cur.y;
      int kept = 0, rebuilt = 0;
      std::normal_distribution<double> step(0.0, 0.02 * skin);
      std::uniform_int_distribution<int> pick(0, n - 1);
      for (int s = 0; s < 60; ++s) {
        for (int i = 0; i < n; ++i) {  // small random walk of everyone
          cur.x[i] += step(rng);
          cur.y[i] += step(rng);
        }
        if (s % 15 == 14) {  // now and then one disc jumps by 0.6 skin
          const int i = pick(rng);
          cur.x[i] += 0.6 * skin;
        }
        copy_positions(cur, nodes);
        double max_d2 = 0;
        for (int i = 0; i < n; ++i) {
          const double dx = cur.x[i] - bx[i], dy = cur.y[i] - by[i];
          max_d2 = std::max(max_d2, dx * dx + dy * dy);
        }
        const bool should = max_d2 > 0.25 * skin * skin;
        const bool did = cs.update(nodes);
        ASSERT_EQ(did, should) << "step " << s;
        const PairList list = cs.candidate_pairs_host();
        if (did) {
          ++rebuilt;
          bx = cur.x;
          by = cur.y;
          EXPECT_EQ(list, brute_force(cur, skin)) << "step " << s;
        } else {
          ++kept;
          const PairList touching = brute_force(cur, 0.0);
          EXPECT_TRUE(contains_all(list, touching)) << "step " << s;
        }
      }
      EXPECT_GT(kept, 10);  // both branches were exercised
      EXPECT_GE(rebuilt, 3);
      EXPECT_EQ(cs.rebuild_count(), rebuilt + 1);
    }
  }
}

// The skin criterion is tight: moving discs by just under skin/2 towards each other keeps the
// list valid (no rebuild, touching pairs present), while a list built without skin would miss
// them; just over skin/2 forces a rebuild.
TEST(NeighborSearch, SkinCriterionBoundary) {
  const double r = 1e-3, skin = 2e-4;
  test::HostDiscs h;
  const double gap = 0.98 * skin;  // surface gap: a candidate, not touching
  h.add(0.0, 0.0, r, 1, 1);
  h.add(2 * r + gap, 0.0, r, 1, 1);
  h.add(10 * r, 0.0, r, 1, 1);  // far away, stays out
  const Nodes nodes = test::make_nodes(h);
  ContactSystem cs(iota_nodes(3), ContactParams{}, skin);
  ContactSystem no_skin(iota_nodes(3), ContactParams{}, 0.0);
  cs.update(nodes);
  no_skin.update(nodes);
  EXPECT_EQ(cs.candidate_pairs_host(), (PairList{{0, 1}}));
  EXPECT_TRUE(no_skin.candidate_pairs_host().empty());
  // Both discs move towards each other by 0.499 skin: they overlap now.
  test::HostDiscs moved = h;
  moved.x[0] += 0.499 * skin;
  moved.x[1] -= 0.499 * skin;
  copy_positions(moved, nodes);
  EXPECT_FALSE(cs.update(nodes));
  EXPECT_EQ(brute_force(moved, 0.0), (PairList{{0, 1}}));
  EXPECT_EQ(cs.candidate_pairs_host(), (PairList{{0, 1}}));
  EXPECT_TRUE(no_skin.update(nodes));  // skin 0: any motion rebuilds
  EXPECT_EQ(no_skin.candidate_pairs_host(), (PairList{{0, 1}}));
  moved.x[2] += 0.501 * skin;
  copy_positions(moved, nodes);
  EXPECT_TRUE(cs.update(nodes));
}

}  // namespace
}  // namespace fracta
