// The SIMD lanes' helpers (src/kernels/simd.hpp) at both widths, four and eight, whatever the
// machine's own (NativeDouble): each against its plain scalar loop (oracle), to the bit. The
// element kernel and the kicks run on NativeDouble; their results against the element-by-element
// and node-by-node paths are tested in test_fe_forces.cpp (LanePath) and by the kick tests.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

#include "kernels/integrate.hpp"
#include "kernels/simd.hpp"

#ifdef FRACTA_HOST_SIMD
namespace {

using fracta::Double4;
using fracta::Double8;
using fracta::LaneCount;

template <class V>
constexpr int kL = LaneCount<V>::value;

template <class V>
V random_lanes(std::mt19937& rng, double lo, double hi) {
  std::uniform_real_distribution<double> u(lo, hi);
  V v;
  for (int l = 0; l < kL<V>; ++l) v[l] = u(rng);
  return v;
}

template <class V>
void pairs_and_triples() {
  constexpr int L = kL<V>;
  std::mt19937 rng(11);
  std::vector<double> pairs(2 * L), triples(3 * L);
  for (double& p : pairs) p = std::uniform_real_distribution<double>(-1, 1)(rng);
  for (double& t : triples) t = std::uniform_real_distribution<double>(-1, 1)(rng);
  // Interleaved (x, y) rows: lane l of x is row l's first value.
  V x, y;
  fracta::load_pairs(pairs.data(), x, y);
  for (int l = 0; l < L; ++l) {
    EXPECT_EQ(x[l], pairs[2 * l]) << L << " lanes, lane " << l;
    EXPECT_EQ(y[l], pairs[2 * l + 1]) << L << " lanes, lane " << l;
  }
  const V dx = random_lanes<V>(rng, -1, 1), dy = random_lanes<V>(rng, -1, 1);
  std::vector<double> added = pairs;
  fracta::add_pairs(added.data(), dx, dy);
  for (int l = 0; l < L; ++l) {
    EXPECT_EQ(added[2 * l], pairs[2 * l] + dx[l]);
    EXPECT_EQ(added[2 * l + 1], pairs[2 * l + 1] + dy[l]);
  }
  std::vector<double> stored(2 * L, 0.0);
  fracta::store_pairs(stored.data(), dx, dy);
  for (int l = 0; l < L; ++l) {
    EXPECT_EQ(stored[2 * l], dx[l]);
    EXPECT_EQ(stored[2 * l + 1], dy[l]);
  }
  // Rows of three: consecutive rows by vector loads, scattered ones row by row.
  V a, b, c;
  fracta::load_triples(triples.data(), a, b, c);
  std::vector<double> back(3 * L, 0.0);
  fracta::store_triples(back.data(), a, b, c);
  for (int l = 0; l < L; ++l) {
    EXPECT_EQ(a[l], triples[3 * l]);
    EXPECT_EQ(b[l], triples[3 * l + 1]);
    EXPECT_EQ(c[l], triples[3 * l + 2]);
    for (int m = 0; m < 3; ++m) EXPECT_EQ(back[3 * l + m], triples[3 * l + m]);
  }
  std::vector<double> rows(3 * 4 * L);
  for (double& r : rows) r = std::uniform_real_distribution<double>(-1, 1)(rng);
  int consecutive[L], scattered[L];
  for (int l = 0; l < L; ++l) consecutive[l] = L + l, scattered[l] = 3 * l + (l % 2);
  for (const int* index : {consecutive, scattered}) {
    int idx[L];
    for (int l = 0; l < L; ++l) idx[l] = index[l];
    V v[3];
    fracta::load_triple_lanes(rows.data(), idx, v);
    for (int l = 0; l < L; ++l)
      for (int m = 0; m < 3; ++m) EXPECT_EQ(v[m][l], rows[3 * idx[l] + m]);
    for (int m = 0; m < 3; ++m) v[m] = -v[m];
    std::vector<double> written = rows;
    fracta::store_triple_lanes(written.data(), idx, v);
    for (int r = 0; r < 4 * L; ++r) {
      bool row_of_lane = false;
      for (int l = 0; l < L; ++l) row_of_lane = row_of_lane || idx[l] == r;
      for (int m = 0; m < 3; ++m)
        EXPECT_EQ(written[3 * r + m], row_of_lane ? -rows[3 * r + m] : rows[3 * r + m]) << r;
    }
  }
  // Lane l of the shift is lane l - 1; lane 0 is 0.
  const V shifted = fracta::shift_up_one_lane(dx);
  EXPECT_EQ(shifted[0], 0.0);
  for (int l = 1; l < L; ++l) EXPECT_EQ(shifted[l], dx[l - 1]);
}

TEST(Simd, PairsTriplesAndShiftsMoveEachLanesValues) {
  pairs_and_triples<Double4>();
  pairs_and_triples<Double8>();
}

template <class V>
void arithmetic() {
  constexpr int L = kL<V>;
  std::mt19937 rng(3);
  double worst_log_ulps = 0.0;
  for (int round = 0; round < 500; ++round) {
    const V a = random_lanes<V>(rng, 0.0, 1e6), b = random_lanes<V>(rng, -1e3, 1e3);
    V x;
    for (int l = 0; l < L; ++l) x[l] = std::pow(10.0, b[l] / 90.0);
    const V root = fracta::sqrt_(a), e = fracta::exp_(b / 100.0), lg = fracta::log10_(x);
    const V lo = fracta::min_(a, b), hi = fracta::max_(a, b), mag = fracta::fabs_(b);
    for (int l = 0; l < L; ++l) {
      EXPECT_EQ(root[l], std::sqrt(a[l]));  // correctly rounded, both
      EXPECT_EQ(e[l], fracta::exp_(b[l] / 100.0));
      EXPECT_EQ(lo[l], fracta::min_(a[l], b[l]));
      EXPECT_EQ(hi[l], fracta::max_(a[l], b[l]));
      EXPECT_EQ(mag[l], std::fabs(b[l]));
      const double exact = std::log10(x[l]);
      const double ulp =
          std::max(std::fabs(exact), 1e-300) * std::numeric_limits<double>::epsilon();
      worst_log_ulps = std::max(worst_log_ulps, std::fabs(lg[l] - exact) / ulp);
    }
    const auto some = a > 5e5;
    bool any = false;
    for (int l = 0; l < L; ++l) {
      any = any || a[l] > 5e5;
      EXPECT_EQ(fracta::get_lane(some, l), a[l] > 5e5);
    }
    EXPECT_EQ(fracta::any_lane(some), any);
  }
  // The sqrt of a negative lane is NaN, as the scalar's.
  V negative = fracta::splat<V>(4.0);
  negative[L - 1] = -1.0;
  EXPECT_TRUE(std::isnan(fracta::sqrt_(negative)[L - 1]));
  EXPECT_EQ(fracta::sqrt_(negative)[0], 2.0);
  EXPECT_LT(worst_log_ulps, 4.0);
}

TEST(Simd, LaneArithmeticIsTheScalarsLaneByLane) {
  arithmetic<Double4>();
  arithmetic<Double8>();
}

// The kicks' lanes (integrate.hpp, NodeLanes) against the node-by-node pass: the same positions,
// velocities and cleared accumulators to the bit, with fixed components and loads mixed in.
TEST(Simd, KickLanesAreTheNodeByNodeKick) {
  const int n = 8 * 13;
  fracta::Nodes lanes_nodes, node_nodes;
  for (fracta::Nodes* nodes : {&lanes_nodes, &node_nodes}) {
    nodes->count = n;
    nodes->x = fracta::View<double* [2]>("x", n);
    nodes->v = fracta::View<double* [2]>("v", n);
    nodes->f = fracta::View<double* [2]>("f", n);
    nodes->f_ext = fracta::View<double* [2]>("f_ext", n);
    nodes->mass = fracta::View<double*>("mass", n);
    nodes->fixed = fracta::View<int*>("fixed", n);
    std::mt19937 rng(17);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    auto x = Kokkos::create_mirror_view(nodes->x);
    auto v = Kokkos::create_mirror_view(nodes->v);
    auto f = Kokkos::create_mirror_view(nodes->f);
    auto f_ext = Kokkos::create_mirror_view(nodes->f_ext);
    auto mass = Kokkos::create_mirror_view(nodes->mass);
    auto fixed = Kokkos::create_mirror_view(nodes->fixed);
    for (int i = 0; i < n; ++i) {
      for (int d = 0; d < 2; ++d) {
        x(i, d) = u(rng), v(i, d) = u(rng), f(i, d) = u(rng);
        f_ext(i, d) = i % 5 == 0 ? u(rng) : 0.0;
      }
      mass(i) = 1.0 + 0.5 * u(rng);
      fixed(i) = i % 7 == 0 ? fracta::kFixX : i % 11 == 0 ? fracta::kFixX | fracta::kFixY : 0;
    }
    Kokkos::deep_copy(nodes->x, x);
    Kokkos::deep_copy(nodes->v, v);
    Kokkos::deep_copy(nodes->f, f);
    Kokkos::deep_copy(nodes->f_ext, f_ext);
    Kokkos::deep_copy(nodes->mass, mass);
    Kokkos::deep_copy(nodes->fixed, fixed);
  }
  fracta::KickKickDrift with_lanes{lanes_nodes, 1e-3, 1.1e-3, false, true};
  fracta::KickKickDrift node_by_node{node_nodes, 1e-3, 1.1e-3, false, false};
  const double w_lanes = fracta::run_kick("lanes", with_lanes, {});
  const double w_nodes = fracta::run_kick("nodes", node_by_node, {});
  EXPECT_NEAR(w_lanes, w_nodes, 1e-14 * std::fabs(w_nodes));
  auto xa = Kokkos::create_mirror_view_and_copy(fracta::HostSpace(), lanes_nodes.x);
  auto xb = Kokkos::create_mirror_view_and_copy(fracta::HostSpace(), node_nodes.x);
  auto va = Kokkos::create_mirror_view_and_copy(fracta::HostSpace(), lanes_nodes.v);
  auto vb = Kokkos::create_mirror_view_and_copy(fracta::HostSpace(), node_nodes.v);
  auto fa = Kokkos::create_mirror_view_and_copy(fracta::HostSpace(), lanes_nodes.f);
  auto ea = Kokkos::create_mirror_view_and_copy(fracta::HostSpace(), lanes_nodes.f_ext);
  for (int i = 0; i < n; ++i)
    for (int d = 0; d < 2; ++d) {
      EXPECT_EQ(xa(i, d), xb(i, d)) << i;
      EXPECT_EQ(va(i, d), vb(i, d)) << i;
      EXPECT_EQ(fa(i, d), 0.0);
      EXPECT_EQ(ea(i, d), 0.0);
    }
}

}  // namespace
#endif
