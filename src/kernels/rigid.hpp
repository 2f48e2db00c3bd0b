// Rigid bodies (docs/physics.md 1.3: `rigid`, no internal forces at all). A rigid body is a node
// range moving as one: after every half kick the nodes' velocities (kicked by their own contact and
// external forces) are projected on the rigid motion with the same linear and angular momentum,
// which is Newton-Euler for the body with its lumped mass and inertia; after the drift the
// nodes are placed exactly at X + R(theta) r0, so the body never deforms. A rigid body of
// revolution (formulation = "axisymmetric") can only translate along the axis: its radial
// velocity and rotation stay zero, and its axial momentum is that of the full revolution
// (the nodes' masses are rings).
#pragma once
#include <cmath>

#include "kernels/compat.hpp"
#include "kernels/state.hpp"

namespace fracta {

struct RigidBody {
  int node_begin = 0, node_end = 0;
  double mass = 0, inertia = 0;      // kg, kg m^2 about the centre of mass (lumped nodes)
  double x = 0, y = 0, theta = 0;    // centre of mass (m) and rotation (rad)
  double vx = 0, vy = 0, omega = 0;  // m/s, rad/s
  bool axial_only = false;           // a body of revolution: moves along the axis (y) only
};

// Writes the body's rigid velocity field V + omega x (x - X) to its nodes.
inline void write_rigid_velocity(const RigidBody& b, const Nodes& nodes) {
  const auto x = nodes.x;
  const auto v = nodes.v;
  const double vx = b.vx, vy = b.vy, w = b.omega, cx = b.x, cy = b.y;
  Kokkos::parallel_for(
      "fracta::rigid_velocity", Kokkos::RangePolicy<ExecSpace>(b.node_begin, b.node_end),
      KOKKOS_LAMBDA(const int n) {
        v(n, 0) = vx - w * (x(n, 1) - cy);
        v(n, 1) = vy + w * (x(n, 0) - cx);
      });
}

// Sets the body's velocity from its nodes' momentum and angular momentum about the centre,
// then writes the rigid velocity field back to the nodes.
inline void project_rigid(RigidBody& b, const Nodes& nodes) {
  Sums<3> s;
  const auto x = nodes.x;
  const auto v = nodes.v;
  const auto mass = nodes.mass;
  const double cx = b.x, cy = b.y;
  Kokkos::parallel_reduce(
      "fracta::rigid_momentum", Kokkos::RangePolicy<ExecSpace>(b.node_begin, b.node_end),
      KOKKOS_LAMBDA(const int n, Sums<3>& acc) {
        const double m = mass(n);
        acc.v[0] += m * v(n, 0);
        acc.v[1] += m * v(n, 1);
        acc.v[2] += m * ((x(n, 0) - cx) * v(n, 1) - (x(n, 1) - cy) * v(n, 0));
      },
      Kokkos::Sum<Sums<3>>(s));
  // A ring's radial forces cancel over the revolution: a body of revolution keeps vx = omega = 0.
  b.vx = b.axial_only ? 0.0 : s.v[0] / b.mass;
  b.vy = s.v[1] / b.mass;
  b.omega = b.axial_only ? 0.0 : s.v[2] / b.inertia;
  write_rigid_velocity(b, nodes);
}

// Drift of the body: X += dt V, theta += dt omega; nodes placed at X + R(theta) r0.
inline void drift_rigid(RigidBody& b, const Nodes& nodes, const View<double* [2]>& offset,
                        double dt) {
  b.x += dt * b.vx;
  b.y += dt * b.vy;
  b.theta += dt * b.omega;
  const double c = std::cos(b.theta), s = std::sin(b.theta), cx = b.x, cy = b.y;
  const auto x = nodes.x;
  Kokkos::parallel_for(
      "fracta::rigid_positions", Kokkos::RangePolicy<ExecSpace>(b.node_begin, b.node_end),
      KOKKOS_LAMBDA(const int n) {
        x(n, 0) = cx + c * offset(n, 0) - s * offset(n, 1);
        x(n, 1) = cy + s * offset(n, 0) + c * offset(n, 1);
      });
}

}  // namespace fracta
