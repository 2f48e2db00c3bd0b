// Explicit central-difference integration in velocity-Verlet form (Belytschko, Liu & Moran,
// Nonlinear Finite Elements, Box 6.1):
//   v(n+1/2) = v(n) + dt/2 a(n);  x(n+1) = x(n) + dt v(n+1/2);  forces(n+1);
//   v(n+1) = v(n+1/2) + dt/2 a(n+1).
// Full-step velocities make the kinetic energy exact at output times. The external work uses
// the trapezoidal rule dW = dx . (f_ext(n) + f_ext(n+1)) / 2, split over the two half kicks.
// Disc rotations (particles only) follow the same scheme with moment / inertia.
#pragma once
#include "kernels/compat.hpp"
#include "kernels/state.hpp"

namespace fracta {

// First half kick and drift; zeroes the force accumulators for the next force evaluation.
// Returns this half's external work (J).
inline double kick_drift(const Nodes& nodes, double dt) {
  double work = 0.0;
  const auto x = nodes.x;
  const auto v = nodes.v;
  const auto f = nodes.f;
  const auto f_ext = nodes.f_ext;
  const auto mass = nodes.mass;
  const auto fixed = nodes.fixed;
  Kokkos::parallel_reduce(
      "fracta::kick_drift", Kokkos::RangePolicy<ExecSpace>(0, nodes.count),
      KOKKOS_LAMBDA(const int n, double& w) {
        const double inv_m = 1.0 / mass(n);
        const int fix = fixed(n);
        for (int d = 0; d < 2; ++d) {
          double vd = v(n, d) + 0.5 * dt * (f(n, d) + f_ext(n, d)) * inv_m;
          if (fix & (1 << d)) vd = 0.0;
          v(n, d) = vd;
          x(n, d) += dt * vd;
          w += 0.5 * dt * vd * f_ext(n, d);
          f(n, d) = 0.0;
          f_ext(n, d) = 0.0;
        }
      },
      work);
  if (nodes.has_particles()) {
    const auto particle = nodes.particle;
    const auto spin = nodes.spin;
    const auto rotation = nodes.rotation;
    const auto moment = nodes.moment;
    const auto inertia = nodes.inertia;
    Kokkos::parallel_for(
        "fracta::kick_drift_rotation", Kokkos::RangePolicy<ExecSpace>(0, nodes.count),
        KOKKOS_LAMBDA(const int n) {
          if (particle(n)) {
            const double w = spin(n) + 0.5 * dt * moment(n) / inertia(n);
            spin(n) = w;
            rotation(n) += dt * w;
          }
          moment(n) = 0.0;
        });
  }
  return work;
}

// Second half kick. Returns this half's external work (J).
inline double kick(const Nodes& nodes, double dt) {
  double work = 0.0;
  const auto v = nodes.v;
  const auto f = nodes.f;
  const auto f_ext = nodes.f_ext;
  const auto mass = nodes.mass;
  const auto fixed = nodes.fixed;
  Kokkos::parallel_reduce(
      "fracta::kick", Kokkos::RangePolicy<ExecSpace>(0, nodes.count),
      KOKKOS_LAMBDA(const int n, double& w) {
        const double inv_m = 1.0 / mass(n);
        const int fix = fixed(n);
        for (int d = 0; d < 2; ++d) {
          w += 0.5 * dt * v(n, d) * f_ext(n, d);
          double vd = v(n, d) + 0.5 * dt * (f(n, d) + f_ext(n, d)) * inv_m;
          if (fix & (1 << d)) vd = 0.0;
          v(n, d) = vd;
        }
      },
      work);
  if (nodes.has_particles()) {
    const auto particle = nodes.particle;
    const auto spin = nodes.spin;
    const auto moment = nodes.moment;
    const auto inertia = nodes.inertia;
    Kokkos::parallel_for(
        "fracta::kick_rotation", Kokkos::RangePolicy<ExecSpace>(0, nodes.count),
        KOKKOS_LAMBDA(const int n) {
          if (particle(n)) spin(n) += 0.5 * dt * moment(n) / inertia(n);
        });
  }
  return work;
}

}  // namespace fracta
