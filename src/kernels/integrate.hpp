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

// One half kick per node. First half (Drift = true): kick, drift, and zero the force and
// moment accumulators for the next force evaluation; the external work uses v(n+1/2) . f_ext(n).
// Second half: the work uses v(n+1/2) . f_ext(n+1), then the kick. Returns that work (J).
template <bool Drift>
struct HalfKick {
  Nodes nodes;
  double dt;
  bool rotations;  // the scene has particles (their views are allocated)

  KOKKOS_INLINE_FUNCTION void operator()(const int n, double& w) const {
    const double inv_m = 1.0 / nodes.mass(n);
    const int fix = nodes.fixed(n);
    for (int d = 0; d < 2; ++d) {
      if (!Drift) w += 0.5 * dt * nodes.v(n, d) * nodes.f_ext(n, d);
      double vd = nodes.v(n, d) + 0.5 * dt * (nodes.f(n, d) + nodes.f_ext(n, d)) * inv_m;
      if (fix & (1 << d)) vd = 0.0;
      nodes.v(n, d) = vd;
      if (Drift) {
        nodes.x(n, d) += dt * vd;
        w += 0.5 * dt * vd * nodes.f_ext(n, d);
        nodes.f(n, d) = 0.0;
        // Most nodes carry no load: leave their (zero) line clean rather than rewrite it.
        if (nodes.f_ext(n, d) != 0.0) nodes.f_ext(n, d) = 0.0;
      }
    }
    if (rotations) {
      if (nodes.particle(n)) {
        const double spin = nodes.spin(n) + 0.5 * dt * nodes.moment(n) / nodes.inertia(n);
        nodes.spin(n) = spin;
        if (Drift) nodes.rotation(n) += dt * spin;
      }
      if (Drift) nodes.moment(n) = 0.0;
    }
  }
};

// The second half kick of one step (dt_last) and the first half kick and drift of the next (dt)
// in one pass over the nodes: the same arithmetic as HalfKick<false> then HalfKick<true> (both
// use the forces of the last evaluation), read and written once. Returns the two halves'
// external work (J).
struct KickKickDrift {
  Nodes nodes;
  double dt_last, dt;
  bool rotations;

  KOKKOS_INLINE_FUNCTION void operator()(const int n, double& w) const {
    const double inv_m = 1.0 / nodes.mass(n);
    const int fix = nodes.fixed(n);
    for (int d = 0; d < 2; ++d) {
      const double f_ext = nodes.f_ext(n, d), f = nodes.f(n, d) + f_ext;
      double vd = nodes.v(n, d);
      w += 0.5 * dt_last * vd * f_ext;
      vd = vd + 0.5 * dt_last * f * inv_m;  // v(n+1)
      if (fix & (1 << d)) vd = 0.0;
      vd = vd + 0.5 * dt * f * inv_m;  // v(n+3/2)
      if (fix & (1 << d)) vd = 0.0;
      nodes.v(n, d) = vd;
      nodes.x(n, d) += dt * vd;
      w += 0.5 * dt * vd * f_ext;
      nodes.f(n, d) = 0.0;
      if (f_ext != 0.0) nodes.f_ext(n, d) = 0.0;
    }
    if (rotations) {
      if (nodes.particle(n)) {
        const double moment = nodes.moment(n), inertia = nodes.inertia(n);
        double spin = nodes.spin(n) + 0.5 * dt_last * moment / inertia;
        spin = spin + 0.5 * dt * moment / inertia;
        nodes.spin(n) = spin;
        nodes.rotation(n) += dt * spin;
      }
      nodes.moment(n) = 0.0;
    }
  }
};

inline double kick_kick_drift(const Nodes& nodes, double dt_last, double dt) {
  double work = 0.0;
  Kokkos::parallel_reduce("fracta::kick_kick_drift", Kokkos::RangePolicy<ExecSpace>(0, nodes.count),
                          KickKickDrift{nodes, dt_last, dt, nodes.has_particles()}, work);
  return work;
}

// First half kick and drift. Returns this half's external work (J).
inline double kick_drift(const Nodes& nodes, double dt) {
  double work = 0.0;
  Kokkos::parallel_reduce("fracta::kick_drift", Kokkos::RangePolicy<ExecSpace>(0, nodes.count),
                          HalfKick<true>{nodes, dt, nodes.has_particles()}, work);
  return work;
}

// Second half kick. Returns this half's external work (J).
inline double kick(const Nodes& nodes, double dt) {
  double work = 0.0;
  Kokkos::parallel_reduce("fracta::kick", Kokkos::RangePolicy<ExecSpace>(0, nodes.count),
                          HalfKick<false>{nodes, dt, nodes.has_particles()}, work);
  return work;
}

}  // namespace fracta
