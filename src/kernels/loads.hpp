// External loads at time t: pressure on boundary edges (follower load on the current geometry)
// and concentrated forces on node sets. Both add into Nodes::f_ext (N).
#pragma once
#include "kernels/compat.hpp"
#include "kernels/state.hpp"

namespace fracta {

// thickness: the depth of plane strain and plane stress; axisymmetric (x = radius): the edge's
// consistent ring weights instead, node a of edge (a, b) taking 2 pi (2 r_a + r_b) / 6 of its
// length (int N_a 2 pi r ds), so the forces are those of the full revolution (N).
// (0.5 p t L) * 2 pi (2 r_a + r_b) / (3 t) = p L 2 pi (2 r_a + r_b) / 6.
inline void apply_loads(const Nodes& nodes, const LoadTables& tables, const PressureEdges& edges,
                        const NodalForces& forces, double thickness, bool axisymmetric,
                        double time) {
  const auto x = nodes.x;
  const auto f_ext = nodes.f_ext;
  if (edges.count > 0) {
    Kokkos::parallel_for(
        "fracta::pressure_loads", Kokkos::RangePolicy<ExecSpace>(0, edges.count),
        KOKKOS_LAMBDA(const int k) {
          const int a = edges.nodes(k, 0), b = edges.nodes(k, 1);
          const double p = table_value(tables, edges.load(k), time);
          // Outward normal times length is (dy, -dx); pressure pushes inwards. A traction acts
          // along its fixed direction over the current edge length. Half per node.
          const double dx = x(b, 0) - x(a, 0), dy = x(b, 1) - x(a, 1);
          const double tx = edges.direction(k, 0), ty = edges.direction(k, 1);
          double fx, fy;
          if (tx == 0.0 && ty == 0.0) {
            fx = -0.5 * p * thickness * dy;
            fy = 0.5 * p * thickness * dx;
          } else {
            const double len = sqrt_(dx * dx + dy * dy);
            fx = 0.5 * p * thickness * len * tx;
            fy = 0.5 * p * thickness * len * ty;
          }
          if (axisymmetric) {
            // fx, fy are those of depth `thickness` halved: rescale to the ring weights.
            const double ra = x(a, 0), rb = x(b, 0), to_ring = kTwoPi / (3.0 * thickness);
            const double wa = (2.0 * ra + rb) * to_ring, wb = (2.0 * rb + ra) * to_ring;
            Kokkos::atomic_add(&f_ext(a, 0), wa * fx);
            Kokkos::atomic_add(&f_ext(a, 1), wa * fy);
            Kokkos::atomic_add(&f_ext(b, 0), wb * fx);
            Kokkos::atomic_add(&f_ext(b, 1), wb * fy);
            return;
          }
          Kokkos::atomic_add(&f_ext(a, 0), fx);
          Kokkos::atomic_add(&f_ext(a, 1), fy);
          Kokkos::atomic_add(&f_ext(b, 0), fx);
          Kokkos::atomic_add(&f_ext(b, 1), fy);
        });
  }
  if (forces.count > 0) {
    Kokkos::parallel_for(
        "fracta::nodal_loads", Kokkos::RangePolicy<ExecSpace>(0, forces.count),
        KOKKOS_LAMBDA(const int k) {
          const double value = table_value(tables, forces.load(k), time);
          const int n = forces.node(k);
          Kokkos::atomic_add(&f_ext(n, 0), value * forces.force_per_unit(k, 0));
          Kokkos::atomic_add(&f_ext(n, 1), value * forces.force_per_unit(k, 1));
        });
  }
}

}  // namespace fracta
