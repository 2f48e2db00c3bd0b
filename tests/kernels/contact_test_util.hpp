// Helpers of the contact tests (NeighborSearch*, Contact*) and the contact benchmark: discs
// built by hand as Nodes (every view allocated, particle views included) and Topologies.
#pragma once
#include <array>
#include <vector>

#include "kernels/state.hpp"

namespace fracta::test {

// Host description of a set of discs; node n is disc n.
struct HostDiscs {
  std::vector<double> x, y, vx, vy, r, m, k, spin;
  std::vector<int> fixed, particle;

  int size() const { return static_cast<int>(x.size()); }
  // A particle disc of uniform density (I = m r^2 / 2).
  void add(double x_, double y_, double r_, double m_, double k_, double vx_ = 0, double vy_ = 0,
           double spin_ = 0, int fixed_ = 0) {
    x.push_back(x_);
    y.push_back(y_);
    r.push_back(r_);
    m.push_back(m_);
    k.push_back(k_);
    vx.push_back(vx_);
    vy.push_back(vy_);
    spin.push_back(spin_);
    fixed.push_back(fixed_);
    particle.push_back(1);
  }
};

inline Nodes make_nodes(const HostDiscs& h) {
  const int n = h.size();
  Nodes nodes;
  nodes.count = n;
  nodes.x0 = View<double* [2]>("fracta::test_x0", n);
  nodes.x = View<double* [2]>("fracta::test_x", n);
  nodes.v = View<double* [2]>("fracta::test_v", n);
  nodes.f = View<double* [2]>("fracta::test_f", n);
  nodes.f_ext = View<double* [2]>("fracta::test_f_ext", n);
  nodes.mass = View<double*>("fracta::test_mass", n);
  nodes.fixed = View<int*>("fracta::test_fixed", n);
  nodes.particle = View<int*>("fracta::test_particle", n);
  nodes.radius = View<double*>("fracta::test_radius", n);
  nodes.inertia = View<double*>("fracta::test_inertia", n);
  nodes.rotation = View<double*>("fracta::test_rotation", n);
  nodes.spin = View<double*>("fracta::test_spin", n);
  nodes.moment = View<double*>("fracta::test_moment", n);
  nodes.contact_stiffness = View<double*>("fracta::test_contact_stiffness", n);
  auto x = Kokkos::create_mirror_view(nodes.x);
  auto v = Kokkos::create_mirror_view(nodes.v);
  auto mass = Kokkos::create_mirror_view(nodes.mass);
  auto fixed = Kokkos::create_mirror_view(nodes.fixed);
  auto particle = Kokkos::create_mirror_view(nodes.particle);
  auto radius = Kokkos::create_mirror_view(nodes.radius);
  auto inertia = Kokkos::create_mirror_view(nodes.inertia);
  auto spin = Kokkos::create_mirror_view(nodes.spin);
  auto k = Kokkos::create_mirror_view(nodes.contact_stiffness);
  for (int i = 0; i < n; ++i) {
    x(i, 0) = h.x[i];
    x(i, 1) = h.y[i];
    v(i, 0) = h.vx.empty() ? 0.0 : h.vx[i];
    v(i, 1) = h.vy.empty() ? 0.0 : h.vy[i];
    mass(i) = h.m.empty() ? 1.0 : h.m[i];
    fixed(i) = h.fixed.empty() ? 0 : h.fixed[i];
    particle(i) = h.particle.empty() ? 1 : h.particle[i];
    radius(i) = h.r[i];
    inertia(i) = 0.5 * mass(i) * radius(i) * radius(i);
    spin(i) = h.spin.empty() ? 0.0 : h.spin[i];
    k(i) = h.k.empty() ? 1.0 : h.k[i];
  }
  Kokkos::deep_copy(nodes.x, x);
  Kokkos::deep_copy(nodes.x0, x);
  Kokkos::deep_copy(nodes.v, v);
  Kokkos::deep_copy(nodes.mass, mass);
  Kokkos::deep_copy(nodes.fixed, fixed);
  Kokkos::deep_copy(nodes.particle, particle);
  Kokkos::deep_copy(nodes.radius, radius);
  Kokkos::deep_copy(nodes.inertia, inertia);
  Kokkos::deep_copy(nodes.spin, spin);
  Kokkos::deep_copy(nodes.contact_stiffness, k);
  return nodes;
}

// A topology over `n` nodes with the given bonds (all active) and elements (all alive, each a
// list of 4 node ids). Empty lists: nothing is joined. A mesh's slots are its cells' edges and
// diagonals (Topology); a free bond {i, j} here is the first edge of a cell of its own that is
// not alive and whose other corners are no node (-1), after the given elements. element_slots:
// the slots of the first elements (Topology::slot_position order: edges, then diagonals; -1:
// none), indices into `bonds`; default: none.
inline Topology make_topology(int n, const std::vector<std::array<int, 2>>& bonds = {},
                              const std::vector<std::array<int, 4>>& elements = {},
                              const std::vector<std::array<int, 6>>& element_slots = {}) {
  Topology t;
  const int nb = static_cast<int>(bonds.size()), ne = static_cast<int>(elements.size());
  const int cells = ne + nb;
  t.bond_state = View<int*>("fracta::test_bond_state", nb);
  t.node_element_offset = View<int*>("fracta::test_node_element_offset", n + 1);
  t.node_element = View<int*>("fracta::test_node_element", 4 * ne + 2 * nb);
  t.element_alive = View<int*>("fracta::test_element_alive", cells);
  t.element_nodes = View<int* [4]>("fracta::test_element_nodes", cells);
  t.element_slots = View<int* [6]>("fracta::test_element_slots", cells);
  auto eo = Kokkos::create_mirror_view(t.node_element_offset);
  auto nev = Kokkos::create_mirror_view(t.node_element);
  auto alive = Kokkos::create_mirror_view(t.element_alive);
  auto corners = Kokkos::create_mirror_view(t.element_nodes);
  auto slots = Kokkos::create_mirror_view(t.element_slots);
  std::vector<std::vector<int>> node_elements(n);
  for (int e = 0; e < cells; ++e) {
    for (int a = 0; a < 6; ++a) slots(e, a) = -1;
    alive(e) = e < ne ? 1 : 0;
    for (int c = 0; c < 4; ++c) {
      const int node = e < ne ? elements[e][c] : c < 2 ? bonds[e - ne][c] : -1;
      corners(e, c) = node;
      if (node >= 0) node_elements[node].push_back(e);
    }
    if (e >= ne) slots(e, 0) = e - ne;
    if (e < static_cast<int>(element_slots.size()))
      for (int a = 0; a < 6; ++a) slots(e, a) = element_slots[e][a];
  }
  int ke = 0;
  for (int i = 0; i < n; ++i) {
    eo(i) = ke;
    for (int e : node_elements[i]) nev(ke++) = e;
  }
  eo(n) = ke;
  Kokkos::deep_copy(t.bond_state, static_cast<int>(kBondActive));
  Kokkos::deep_copy(t.node_element_offset, eo);
  Kokkos::deep_copy(t.node_element, nev);
  Kokkos::deep_copy(t.element_alive, alive);
  Kokkos::deep_copy(t.element_nodes, corners);
  Kokkos::deep_copy(t.element_slots, slots);
  return t;
}

// The bonds of make_topology(n, bonds, ...): their ends and the topology's states, for
// ContactSystem::set_lattice (which then has the breaks noted in them).
inline Bonds make_bonds(const Topology& t, const std::vector<std::array<int, 2>>& bonds) {
  Bonds b;
  b.count = static_cast<int>(bonds.size());
  b.state = t.bond_state;
  b.nodes = View<int* [2]>("fracta::test_bond_nodes", bonds.size());
  auto ends = Kokkos::create_mirror_view(b.nodes);
  for (size_t k = 0; k < bonds.size(); ++k) ends(k, 0) = bonds[k][0], ends(k, 1) = bonds[k][1];
  Kokkos::deep_copy(b.nodes, ends);
  return b;
}

// Bonds [first, first + count) break as the bond kernel breaks them: their state, and the note
// to the contact.
inline void break_bonds(const Bonds& bonds, const int first, const int count) {
  Kokkos::parallel_for(
      "fracta::test_break_bonds", Kokkos::RangePolicy<ExecSpace>(first, first + count),
      KOKKOS_LAMBDA(const int b) {
        bonds.state(b) = kBondBroken;
        bonds.note_broken(b);
      });
}
inline void break_bond(const Bonds& bonds, const int slot) {
  break_bonds(bonds, slot, 1);
}

}  // namespace fracta::test
