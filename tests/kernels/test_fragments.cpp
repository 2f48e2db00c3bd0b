// Fragment statistics (kernels/fragments.hpp): connected components of the nodes over active
// bonds and alive elements, checked on scenes built by the model and against a host
// union-find oracle.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <random>
#include <vector>

#include "host/model.hpp"
#include "kernels/fragments.hpp"
#include "test_util.hpp"

namespace fracta {
namespace {

Case block_case(int nx, int ny, double h, BodyMethod method) {
  Case c = test::rectangle_case(nx, ny, h, 200e9, 0.25, 7800.0, Formulation::plane_stress);
  c.bodies[0].method = method;
  return c;
}

// Host copies of what the labelling reads.
struct HostGraph {
  int n = 0;
  std::vector<double> mass;
  std::vector<double> x;  // reference x of each node
  std::vector<std::array<int, 4>> elements;
  std::vector<int> alive;
  std::vector<std::array<int, 2>> bonds;
  std::vector<int> state;
};

HostGraph host_graph(const Nodes& nodes, const Elements& el, const Bonds& bonds) {
  HostGraph g;
  g.n = nodes.count;
  auto mass = Kokkos::create_mirror_view_and_copy(HostSpace(), nodes.mass);
  g.mass.assign(mass.data(), mass.data() + g.n);
  if (nodes.x0.extent(0) > 0) {
    auto x0 = Kokkos::create_mirror_view_and_copy(HostSpace(), nodes.x0);
    for (int i = 0; i < g.n; ++i) g.x.push_back(x0(i, 0));
  }
  if (el.count > 0) {
    auto en = Kokkos::create_mirror_view_and_copy(HostSpace(), el.nodes);
    auto alive = Kokkos::create_mirror_view_and_copy(HostSpace(), el.alive);
    for (int e = 0; e < el.count; ++e) {
      g.elements.push_back({en(e, 0), en(e, 1), en(e, 2), en(e, 3)});
      g.alive.push_back(alive(e));
    }
  }
  if (bonds.count > 0) {
    auto bn = Kokkos::create_mirror_view_and_copy(HostSpace(), bonds.nodes);
    auto st = Kokkos::create_mirror_view_and_copy(HostSpace(), bonds.state);
    for (int b = 0; b < bonds.count; ++b) {
      g.bonds.push_back({bn(b, 0), bn(b, 1)});
      g.state.push_back(st(b));
    }
  }
  return g;
}

void set_bond_states(Bonds& bonds, const std::vector<int>& state) {
  auto st = Kokkos::create_mirror_view(bonds.state);
  for (int b = 0; b < bonds.count; ++b) st(b) = state[b];
  Kokkos::deep_copy(bonds.state, st);
}

void set_alive(Elements& el, const std::vector<int>& alive) {
  auto a = Kokkos::create_mirror_view(el.alive);
  for (int e = 0; e < el.count; ++e) a(e) = alive[e];
  Kokkos::deep_copy(el.alive, a);
}

std::vector<int> host_labels(const View<int*>& labels, int n) {
  auto l = Kokkos::create_mirror_view_and_copy(HostSpace(), labels);
  return std::vector<int>(l.data(), l.data() + n);
}

// The oracle: sequential union-find (union by smaller id), labels = smallest node id.
std::vector<int> oracle_labels(const HostGraph& g) {
  std::vector<int> p(g.n);
  std::iota(p.begin(), p.end(), 0);
  auto find = [&](int v) {
    while (p[v] != v) v = p[v] = p[p[v]];
    return v;
  };
  auto join = [&](int a, int b) {
    a = find(a);
    b = find(b);
    if (a != b) p[std::max(a, b)] = std::min(a, b);
  };
  for (size_t b = 0; b < g.bonds.size(); ++b)
    if (g.state[b] == kBondActive) join(g.bonds[b][0], g.bonds[b][1]);
  for (size_t e = 0; e < g.elements.size(); ++e)
    if (g.alive[e])
      for (int c = 1; c < 4; ++c) join(g.elements[e][0], g.elements[e][c]);
  std::vector<int> label(g.n);
  for (int i = 0; i < g.n; ++i) label[i] = find(i);
  return label;
}

// Per-fragment (mass, size) of a labelling, masses sorted descending; sizes sorted descending
// separately (near-equal masses may order differently, sizes as a multiset do not).
struct HostStats {
  std::vector<double> masses;
  std::vector<long> sizes_sorted;
  double total = 0;
};

HostStats oracle_stats(const HostGraph& g, const std::vector<int>& label) {
  std::vector<double> m(g.n, 0.0);
  std::vector<long> s(g.n, 0);
  for (int i = 0; i < g.n; ++i) {
    m[label[i]] += g.mass[i];
    s[label[i]] += 1;
    EXPECT_LE(label[i], i);
  }
  HostStats h;
  for (int i = 0; i < g.n; ++i)
    if (label[i] == i) {
      h.masses.push_back(m[i]);
      h.sizes_sorted.push_back(s[i]);
      h.total += m[i];
    }
  std::sort(h.masses.rbegin(), h.masses.rend());
  std::sort(h.sizes_sorted.rbegin(), h.sizes_sorted.rend());
  return h;
}

void expect_matches(const FragmentStats& s, const HostStats& h) {
  ASSERT_EQ(s.count, static_cast<long>(h.masses.size()));
  ASSERT_EQ(s.masses.size(), h.masses.size());
  ASSERT_EQ(s.sizes.size(), h.masses.size());
  for (size_t k = 0; k < h.masses.size(); ++k)
    EXPECT_NEAR(s.masses[k], h.masses[k], 1e-12 * h.masses[k]) << "fragment " << k;
  std::vector<long> sizes = s.sizes;
  std::sort(sizes.rbegin(), sizes.rend());
  EXPECT_EQ(sizes, h.sizes_sorted);
  EXPECT_NEAR(s.total_mass, h.total, 1e-12 * h.total);
  if (!h.masses.empty()) {
    EXPECT_EQ(s.largest_mass, s.masses[0]);
  }
  EXPECT_TRUE(std::is_sorted(s.masses.rbegin(), s.masses.rend()));
  EXPECT_EQ(std::accumulate(s.sizes.begin(), s.sizes.end(), 0L),
            std::accumulate(h.sizes_sorted.begin(), h.sizes_sorted.end(), 0L));
}

// A structured lattice built directly (no case, no mesh): nx x ny cells, row-major nodes with
// random masses, elements counter-clockwise, bond slots = edges then diagonals (as the model).
struct Lattice {
  Nodes nodes;
  Elements elements;
  Bonds bonds;
};

Lattice make_lattice(int nx, int ny, unsigned seed) {
  Lattice l;
  const int n = (nx + 1) * (ny + 1), ne = nx * ny;
  auto id = [&](int i, int j) { return j * (nx + 1) + i; };
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.5, 1.5);
  l.nodes.count = n;
  l.nodes.mass = View<double*>("mass", n);
  auto mass = Kokkos::create_mirror_view(l.nodes.mass);
  for (int i = 0; i < n; ++i) mass(i) = 1e-3 * u(rng);
  Kokkos::deep_copy(l.nodes.mass, mass);
  l.elements.count = ne;
  l.elements.nodes = View<int* [4]>("element_nodes", ne);
  l.elements.alive = View<int*>("alive", ne);
  auto en = Kokkos::create_mirror_view(l.elements.nodes);
  std::vector<std::array<int, 2>> bonds;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const int e = j * nx + i;
      en(e, 0) = id(i, j);
      en(e, 1) = id(i + 1, j);
      en(e, 2) = id(i + 1, j + 1);
      en(e, 3) = id(i, j + 1);
    }
  Kokkos::deep_copy(l.elements.nodes, en);
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) {
      if (i < nx) bonds.push_back({id(i, j), id(i + 1, j)});
      if (j < ny) bonds.push_back({id(i, j), id(i, j + 1)});
    }
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      bonds.push_back({id(i, j), id(i + 1, j + 1)});
      bonds.push_back({id(i + 1, j), id(i, j + 1)});
    }
  const int nb = static_cast<int>(bonds.size());
  l.bonds.count = nb;
  l.bonds.nodes = View<int* [2]>("bond_nodes", nb);
  l.bonds.state = View<int*>("bond_state", nb);
  auto bn = Kokkos::create_mirror_view(l.bonds.nodes);
  for (int b = 0; b < nb; ++b) {
    bn(b, 0) = bonds[b][0];
    bn(b, 1) = bonds[b][1];
  }
  Kokkos::deep_copy(l.bonds.nodes, bn);
  return l;
}

// Random states: bonds active with probability p_bond (else broken or never activated), elements
// alive with probability p_element.
void randomise(Elements& el, Bonds& bonds, double p_bond, double p_element, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<int> state(bonds.count), alive(el.count);
  for (int& s : state) s = u(rng) < p_bond ? kBondActive : (u(rng) < 0.5 ? kBondBroken : 0);
  for (int& a : alive) a = u(rng) < p_element;
  if (bonds.count > 0) set_bond_states(bonds, state);
  if (el.count > 0) set_alive(el, alive);
}

// Runs the device labelling twice and checks labels (exactly) and statistics against the oracle.
void check_against_oracle(const Nodes& nodes, const Elements& el, const Bonds& bonds) {
  const HostGraph g = host_graph(nodes, el, bonds);
  const std::vector<int> expected = oracle_labels(g);
  View<int*> labels("labels", nodes.count);
  const FragmentStats s = fragment_statistics(nodes, el, bonds, labels);
  EXPECT_EQ(host_labels(labels, nodes.count), expected);
  expect_matches(s, oracle_stats(g, expected));
  FragmentWorkspace ws(nodes.count);
  const FragmentStats again = fragment_statistics(nodes, el, bonds, ws);
  EXPECT_EQ(host_labels(ws.labels, nodes.count), expected);
  EXPECT_EQ(again.count, s.count);
  EXPECT_EQ(again.sizes.size(), s.sizes.size());
}

// A DE block cut by hand along a vertical line between two columns of discs: every bond
// crossing the line (edges and diagonals) broken gives exactly 2 fragments, left and right.
TEST(Fragments, DeBlockCutAlongAColumnGivesTwo) {
  const int nx = 8, ny = 5;
  const double h = 1e-3, xc = 3.5 * h;
  Model m = build_model(block_case(nx, ny, h, BodyMethod::de));
  const HostGraph g = host_graph(m.nodes, m.elements, m.bonds);
  ASSERT_EQ(g.n, (nx + 1) * (ny + 1));
  ASSERT_GT(std::count(g.state.begin(), g.state.end(), int(kBondActive)), 0);
  ASSERT_EQ(std::count(g.alive.begin(), g.alive.end(), 1), 0);  // all converted
  View<int*> labels("labels", g.n);
  EXPECT_EQ(fragment_statistics(m.nodes, m.elements, m.bonds, labels).count, 1);

  std::vector<int> state = g.state;
  int cut = 0;
  for (size_t b = 0; b < g.bonds.size(); ++b)
    if ((g.x[g.bonds[b][0]] - xc) * (g.x[g.bonds[b][1]] - xc) < 0 && state[b] == kBondActive) {
      state[b] = kBondBroken;
      ++cut;
    }
  EXPECT_EQ(cut, (ny + 1) + 2 * ny);  // one edge per row of nodes, two diagonals per cell
  set_bond_states(m.bonds, state);
  const FragmentStats s = fragment_statistics(m.nodes, m.elements, m.bonds, labels);
  ASSERT_EQ(s.count, 2);
  double left = 0, right = 0;
  int left_min = g.n, right_min = g.n;
  for (int i = 0; i < g.n; ++i) (g.x[i] < xc ? left : right) += g.mass[i];
  for (int i = 0; i < g.n; ++i) {
    int& mn = g.x[i] < xc ? left_min : right_min;
    mn = std::min(mn, i);
  }
  // 5 columns of discs on the right, 4 on the left: the right is the heavier.
  EXPECT_NEAR(s.masses[0], right, 1e-12 * right);
  EXPECT_NEAR(s.masses[1], left, 1e-12 * left);
  EXPECT_EQ(s.sizes[0], 5 * (ny + 1));
  EXPECT_EQ(s.sizes[1], 4 * (ny + 1));
  EXPECT_NEAR(s.total_mass, left + right, 1e-12 * (left + right));
  EXPECT_EQ(s.largest_mass, s.masses[0]);
  const std::vector<int> l = host_labels(labels, g.n);
  for (int i = 0; i < g.n; ++i) EXPECT_EQ(l[i], g.x[i] < xc ? left_min : right_min) << i;
}

// An intact FE block (no bonds allocated at all) is one fragment; so is an FE body with a DE
// region (composite nodes join the bonds to the elements).
TEST(Fragments, FeBlockIsOneFragment) {
  Model m = build_model(block_case(6, 4, 1e-3, BodyMethod::fe));
  EXPECT_EQ(m.bonds.count, 0);
  View<int*> labels("labels", m.nodes.count);
  const FragmentStats s = fragment_statistics(m.nodes, m.elements, m.bonds, labels);
  const HostGraph g = host_graph(m.nodes, m.elements, m.bonds);
  const double total = std::accumulate(g.mass.begin(), g.mass.end(), 0.0);
  ASSERT_EQ(s.count, 1);
  EXPECT_EQ(s.sizes[0], m.nodes.count);
  EXPECT_NEAR(s.masses[0], total, 1e-12 * total);
  EXPECT_NEAR(s.largest_mass, total, 1e-12 * total);
  for (int l : host_labels(labels, m.nodes.count)) EXPECT_EQ(l, 0);

  Case c = block_case(6, 4, 1e-3, BodyMethod::fe);
  Region r;
  r.method = BodyMethod::de;
  r.shape.width = 3e-3;
  r.shape.height = 4e-3;
  r.shape.x = 3e-3;
  c.bodies[0].regions.push_back(r);
  Model mixed = build_model(c);
  ASSERT_GT(mixed.bonds.count, 0);
  View<int*> labels2("labels", mixed.nodes.count);
  EXPECT_EQ(fragment_statistics(mixed.nodes, mixed.elements, mixed.bonds, labels2).count, 1);
  check_against_oracle(mixed.nodes, mixed.elements, mixed.bonds);
}

// Two bodies apart are two fragments, FE + FE and FE + DE.
TEST(Fragments, TwoSeparateBodiesAreTwo) {
  for (BodyMethod second : {BodyMethod::fe, BodyMethod::de}) {
    Case c = block_case(4, 3, 1e-3, BodyMethod::fe);
    Body b = c.bodies[0];
    b.name = "second";
    b.method = second;
    b.shape.x = 10e-3;
    b.shape.width = 2e-3;
    c.bodies.push_back(b);
    Model m = build_model(c);
    ASSERT_EQ(m.nodes.count, 5 * 4 + 3 * 4);
    View<int*> labels("labels", m.nodes.count);
    const FragmentStats s = fragment_statistics(m.nodes, m.elements, m.bonds, labels);
    ASSERT_EQ(s.count, 2);
    EXPECT_EQ(s.sizes[0], 20);
    EXPECT_EQ(s.sizes[1], 12);
    const double rho_t = 7800.0 * 0.01;
    EXPECT_NEAR(s.masses[0], rho_t * 12e-6, 1e-12 * rho_t * 12e-6);
    EXPECT_NEAR(s.masses[1], rho_t * 6e-6, 1e-12 * rho_t * 6e-6);
    check_against_oracle(m.nodes, m.elements, m.bonds);
  }
}

// Every bond broken: each disc is a fragment of one node, labelled by itself.
TEST(Fragments, AllBondsBrokenGivesOneFragmentPerNode) {
  Model m = build_model(block_case(7, 4, 1e-3, BodyMethod::de));
  set_bond_states(m.bonds, std::vector<int>(m.bonds.count, kBondBroken));
  View<int*> labels("labels", m.nodes.count);
  const FragmentStats s = fragment_statistics(m.nodes, m.elements, m.bonds, labels);
  const HostGraph g = host_graph(m.nodes, m.elements, m.bonds);
  ASSERT_EQ(s.count, m.nodes.count);
  for (long size : s.sizes) EXPECT_EQ(size, 1);
  std::vector<double> masses = g.mass;
  std::sort(masses.rbegin(), masses.rend());
  EXPECT_EQ(s.masses, masses);  // single terms: exact
  const std::vector<int> l = host_labels(labels, m.nodes.count);
  for (int i = 0; i < m.nodes.count; ++i) EXPECT_EQ(l[i], i);
}

// Random bond and element states on model blocks and on larger lattices, several seeds: labels
// exactly those of a sequential union-find, statistics equal to its sums.
TEST(Fragments, RandomBreaksMatchUnionFindOracle) {
  const int blocks[][2] = {{1, 1}, {3, 2}, {7, 5}, {16, 9}};
  unsigned seed = 1;
  for (const auto& nxy : blocks) {
    Model m = build_model(block_case(nxy[0], nxy[1], 1e-3, BodyMethod::de));
    for (double p : {0.2, 0.5, 0.8}) {
      randomise(m.elements, m.bonds, p, 0.0, ++seed);
      check_against_oracle(m.nodes, m.elements, m.bonds);
    }
  }
  const int lattices[][2] = {{1, 1}, {2, 9}, {31, 17}, {120, 90}, {300, 200}};
  for (const auto& nxy : lattices) {
    Lattice l = make_lattice(nxy[0], nxy[1], ++seed);
    // Near the percolation thresholds too (bond-only and element-only), and mixed.
    const double cases[][2] = {{0.15, 0.0}, {0.3, 0.0}, {0.6, 0.0}, {0.0, 0.4},
                               {0.0, 0.6},  {0.2, 0.3}, {1.0, 0.0}, {0.0, 1.0}};
    for (const auto& pe : cases) {
      randomise(l.elements, l.bonds, pe[0], pe[1], ++seed);
      check_against_oracle(l.nodes, l.elements, l.bonds);
    }
  }
}

// Nothing joined: empty bond and element sets; and a model without nodes.
TEST(Fragments, NoEdgesAndNoNodes) {
  Lattice l = make_lattice(5, 4, 7);
  Elements none;
  Bonds no_bonds;
  View<int*> labels("labels", l.nodes.count);
  const FragmentStats s = fragment_statistics(l.nodes, none, no_bonds, labels);
  EXPECT_EQ(s.count, l.nodes.count);
  Nodes empty;
  const FragmentStats z = fragment_statistics(empty, none, no_bonds, View<int*>());
  EXPECT_EQ(z.count, 0);
  EXPECT_EQ(z.total_mass, 0.0);
  EXPECT_TRUE(z.masses.empty());
  EXPECT_THROW(fragment_statistics(l.nodes, none, no_bonds, View<int*>("small", 3)),
               std::invalid_argument);
}

TEST(Fragments, MassDistribution) {
  FragmentStats s;
  s.masses = {7.0, 3.0, 1.5, 1.2, 1.0};
  s.sizes = {7, 3, 2, 1, 1};
  s.count = 5;
  s.largest_mass = 7.0;
  s.total_mass = 13.7;
  // Fixed range 1..8 in 3 bins: edges 1, 2, 4, 8.
  MassDistribution d = mass_distribution(s, 3, 1.0, 8.0);
  ASSERT_EQ(d.edges.size(), 4u);
  EXPECT_NEAR(d.edges[1], 2.0, 1e-12);
  EXPECT_NEAR(d.edges[2], 4.0, 1e-12);
  EXPECT_EQ(d.counts, (std::vector<long>{3, 1, 1}));
  ASSERT_EQ(d.cumulative.size(), 4u);
  EXPECT_NEAR(d.cumulative[0], 1.0 / 13.7, 1e-15);  // the fragment of exactly m_min
  EXPECT_NEAR(d.cumulative[1], 3.7 / 13.7, 1e-15);
  EXPECT_NEAR(d.cumulative[2], 6.7 / 13.7, 1e-15);
  EXPECT_NEAR(d.cumulative[3], 1.0, 1e-15);
  // Automatic range: lightest to largest, both ends included.
  d = mass_distribution(s, 4);
  EXPECT_EQ(d.edges.front(), 1.0);
  EXPECT_EQ(d.edges.back(), 7.0);
  EXPECT_EQ(std::accumulate(d.counts.begin(), d.counts.end(), 0L), 5);
  EXPECT_NEAR(d.cumulative.back(), 1.0, 1e-15);
  EXPECT_TRUE(std::is_sorted(d.cumulative.begin(), d.cumulative.end()));
  // A range below the largest fragment: it is in no bin.
  d = mass_distribution(s, 2, 1.0, 4.0);
  EXPECT_EQ(std::accumulate(d.counts.begin(), d.counts.end(), 0L), 4);
  EXPECT_NEAR(d.cumulative.back(), 6.7 / 13.7, 1e-15);
  // A single fragment: one decade below it.
  FragmentStats one;
  one.masses = {2.0};
  one.sizes = {10};
  one.count = 1;
  one.largest_mass = one.total_mass = 2.0;
  d = mass_distribution(one, 5);
  EXPECT_NEAR(d.edges.front(), 0.2, 1e-15);
  EXPECT_EQ(d.counts.back(), 1);
  EXPECT_NEAR(d.cumulative.back(), 1.0, 1e-15);
  EXPECT_THROW(mass_distribution(one, 0), std::invalid_argument);
}

}  // namespace
}  // namespace fracta
