// Reductions for the energy balance and the conservation checks (DESIGN.md 1.4).
#pragma once
#include "kernels/compat.hpp"
#include "kernels/materials.hpp"
#include "kernels/state.hpp"

namespace fracta {

// Totals over all nodes: kinetic energy (J), mass (kg), momentum (kg m/s).
struct NodeTotals {
  double kinetic = 0, mass = 0, momentum_x = 0, momentum_y = 0;
};

inline NodeTotals node_totals(const Nodes& nodes) {
  Sums<4> s;
  const auto v = nodes.v;
  const auto mass = nodes.mass;
  Kokkos::parallel_reduce(
      "fracta::node_totals", Kokkos::RangePolicy<ExecSpace>(0, nodes.count),
      KOKKOS_LAMBDA(const int n, Sums<4>& acc) {
        const double m = mass(n), vx = v(n, 0), vy = v(n, 1);
        acc.v[0] += 0.5 * m * (vx * vx + vy * vy);
        acc.v[1] += m;
        acc.v[2] += m * vx;
        acc.v[3] += m * vy;
      },
      Kokkos::Sum<Sums<4>>(s));
  return {s.v[0], s.v[1], s.v[2], s.v[3]};
}

// Totals over the active elements: recoverable strain energy and cumulative dissipation (J).
struct ElementTotals {
  double internal = 0, plastic = 0, hourglass = 0, viscous = 0;
};

inline ElementTotals element_totals(const Elements& el, const View<const MaterialLaw*>& materials) {
  Sums<4> s;
  if (el.active_count == 0) return {};
  const int qp = el.qp_per_element;
  Kokkos::parallel_reduce(
      "fracta::element_totals", Kokkos::RangePolicy<ExecSpace>(0, el.active_count),
      KOKKOS_LAMBDA(const int i, Sums<4>& acc) {
        const int e = el.active(i);
        const MaterialLaw mat = materials(el.material(e));
        for (int g = 0; g < qp; ++g) {
          const int q = e * qp + g;
          const double sig[4] = {el.stress(q, 0), el.stress(q, 1), el.stress(q, 2),
                                 el.stress(q, 3)};
          acc.v[0] += elastic_energy_density(mat, sig) * el.qp_volume(q);
        }
        acc.v[1] += el.plastic_work(e);
        acc.v[2] += el.hourglass_work(e);
        acc.v[3] += el.viscous_work(e);
      },
      Kokkos::Sum<Sums<4>>(s));
  return {s.v[0], s.v[1], s.v[2], s.v[3]};
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
