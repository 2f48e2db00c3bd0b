// Reductions for the energy balance and the conservation checks (docs/physics.md 1.4).
#pragma once
#include "kernels/bond_forces.hpp"
#include "kernels/compat.hpp"
#include "kernels/materials.hpp"
#include "kernels/state.hpp"

namespace fracta {

// Totals over all nodes: kinetic energy (J), mass (kg), momentum (kg m/s), and the
// central-difference term -(dt^2/8) sum |f|^2/m over free degrees of freedom (J): with it,
// 1/2 m v(n-1/2).v(n+1/2) = 1/2 m v(n)^2 - dt^2/8 m a(n)^2 is the energy the scheme conserves.
struct NodeTotals {
  double kinetic = 0, mass = 0, momentum_x = 0, momentum_y = 0, time_discretization = 0;
};

inline NodeTotals node_totals(const Nodes& nodes, double dt) {
  Sums<5> s;
  const auto v = nodes.v;
  const auto f = nodes.f;
  const auto f_ext = nodes.f_ext;
  const auto fixed = nodes.fixed;
  const auto mass = nodes.mass;
  Kokkos::parallel_reduce(
      "fracta::node_totals", Kokkos::RangePolicy<ExecSpace>(0, nodes.count),
      KOKKOS_LAMBDA(const int n, Sums<5>& acc) {
        const double m = mass(n), vx = v(n, 0), vy = v(n, 1);
        acc.v[0] += 0.5 * m * (vx * vx + vy * vy);
        acc.v[1] += m;
        acc.v[2] += m * vx;
        acc.v[3] += m * vy;
        for (int d = 0; d < 2; ++d) {
          const double ftot = f(n, d) + f_ext(n, d);
          if (!(fixed(n) & (1 << d))) acc.v[4] -= 0.125 * dt * dt * ftot * ftot / m;
        }
      },
      Kokkos::Sum<Sums<5>>(s));
  return {s.v[0], s.v[1], s.v[2], s.v[3], s.v[4]};
}

// Disc rotations and the bonded lattice: rotational kinetic energy and its central-difference
// term -(dt^2/8) M^2 / I, bond elastic energy and plastic work (J), and counts.
struct LatticeTotals {
  double rotational_kinetic = 0, rotational_time_discretization = 0, bond_elastic = 0,
         bond_plastic = 0;
  long particles = 0, active_bonds = 0;
};

inline LatticeTotals lattice_totals(const Nodes& nodes, const Bonds& bonds, double dt) {
  LatticeTotals t;
  if (!nodes.has_particles()) return t;
  // Over the particle list and the used bond slots when the model keeps them (state.hpp): what
  // the sweeps skip adds nothing (never-activated slots have no plastic work), and the lists
  // are increasing, so the sums are the sweeps' sums.
  const bool particle_list = nodes.particle_list.extent(0) > 0;
  const bool used_list = bonds.used.extent(0) > 0;
  const auto particles = nodes.particle_list;
  const auto used = bonds.used;
  Sums<3> n;
  Kokkos::parallel_reduce(
      "fracta::rotation_totals",
      Kokkos::RangePolicy<ExecSpace>(0, particle_list ? nodes.particle_count : nodes.count),
      KOKKOS_LAMBDA(const int k, Sums<3>& acc) {
        const int i = particle_list ? particles(k) : k;
        if (!nodes.particle(i)) return;
        const double I = nodes.inertia(i), w = nodes.spin(i), M = nodes.moment(i);
        acc.v[0] += 0.5 * I * w * w;
        acc.v[1] -= 0.125 * dt * dt * M * M / I;
        acc.v[2] += 1.0;
      },
      Kokkos::Sum<Sums<3>>(n));
  t.rotational_kinetic = n.v[0];
  t.rotational_time_discretization = n.v[1];
  t.particles = static_cast<long>(n.v[2] + 0.5);
  if (bonds.count > 0) {
    const bool yields = bonds.may_yield, softens = bonds.may_soften;  // else those views are 0
    Sums<3> b;
    Kokkos::parallel_reduce(
        "fracta::bond_totals",
        Kokkos::RangePolicy<ExecSpace>(0, used_list ? bonds.used_count : bonds.count),
        KOKKOS_LAMBDA(const int j, Sums<3>& acc) {
          const int k = used_list ? used(j) : j;
          if (yields) acc.v[1] += bonds.plastic_work(k);
          if (bonds.state(k) != kBondActive) return;
          acc.v[0] += CohesiveSoftening::stored_energy(
              bonds.fn(k), bonds.fs(k), softens ? bonds.damage(k) : 0.0, bonds.kn(k), bonds.ks(k));
          acc.v[2] += 1.0;
        },
        Kokkos::Sum<Sums<3>>(b));
    t.bond_elastic = b.v[0];
    t.bond_plastic = b.v[1];
    t.active_bonds = static_cast<long>(b.v[2] + 0.5);
  }
  return t;
}

// Composite nodes (docs/physics.md 1.3): discs still attached to an active element, where the
// FE and DE parts of a body share a node and it takes element, bond and contact forces.
inline long composite_count(const Nodes& nodes, const Topology& topology) {
  if (!nodes.has_particles() || topology.node_element_offset.extent(0) == 0) return 0;
  const bool particle_list = nodes.particle_list.extent(0) > 0;
  const auto particles = nodes.particle_list;
  const auto offset = topology.node_element_offset;
  const auto elements = topology.node_element;
  const auto alive = topology.element_alive;
  long count = 0;
  Kokkos::parallel_reduce(
      "fracta::composite_count",
      Kokkos::RangePolicy<ExecSpace>(0, particle_list ? nodes.particle_count : nodes.count),
      KOKKOS_LAMBDA(const int k, long& acc) {
        const int n = particle_list ? particles(k) : k;
        if (!nodes.particle(n)) return;
        for (int q = offset(n); q < offset(n + 1); ++q)
          if (alive(elements(q))) {
            ++acc;
            return;
          }
      },
      count);
  return count;
}

// Totals over the active elements: the recoverable strain energy (J). (Their dissipation is
// summed per step: FeStepSums.)
struct ElementTotals {
  double internal = 0;
};

inline ElementTotals element_totals(const Elements& el) {
  double internal = 0.0;
  if (el.count == 0) return {};
  // A converted element's recoverable energy went to the bonds (and the difference to the
  // conversion term).
  Kokkos::parallel_reduce(
      "fracta::element_totals", Kokkos::RangePolicy<ExecSpace>(0, el.count),
      KOKKOS_LAMBDA(const int e, double& acc) {
        if (el.alive(e)) acc += el.recoverable_work(e);
      },
      internal);
  return {internal};
}

// Mass-weighted sums over a node range [begin, end): mass, m x, m y, m vx, m vy.
inline Sums<5> body_sums(const Nodes& nodes, int begin, int end) {
  Sums<5> s;
  const auto x = nodes.x;
  const auto v = nodes.v;
  const auto mass = nodes.mass;
  Kokkos::parallel_reduce(
      "fracta::body_sums", Kokkos::RangePolicy<ExecSpace>(begin, end),
      KOKKOS_LAMBDA(const int n, Sums<5>& acc) {
        const double m = mass(n);
        acc.v[0] += m;
        acc.v[1] += m * x(n, 0);
        acc.v[2] += m * x(n, 1);
        acc.v[3] += m * v(n, 0);
        acc.v[4] += m * v(n, 1);
      },
      Kokkos::Sum<Sums<5>>(s));
  return s;
}

}  // namespace fracta
