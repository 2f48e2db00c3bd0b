// Boundaries that act through the integrator: prescribed velocities (prescribed motion),
// push-only supports, and the end of a split-Hopkinson bar (docs/physics.md 1.4, "Boundaries").
// Fixed components are Nodes::fixed bits, which the kicks hold at zero; the three kinds here
// build on them:
// - a prescribed component is a fixed bit (the kick leaves it alone) whose velocity and position
//   prescribe() then sets from its table, with the work its constraint does counted before each
//   half kick (prescribed_work);
// - a support component is a fixed bit set while the node presses into the support and cleared
//   when the node pulls away (update_supports);
// - a bar is an external force on its face, f_ext += (m_i / M) A sigma d, with the stress
//   sigma = Z (2 v_I - v) of one-dimensional bar theory (BarImpedance).
#pragma once
#include "kernels/compat.hpp"
#include "kernels/state.hpp"

namespace fracta {

// Components whose velocity follows a table: node, component (0 = x, 1 = y), table.
struct PrescribedDofs {
  View<int*> node, component, table;
  int count = 0;
};

// Push-only support components: node, component, the sign of the direction the support pushes
// along (+1 or -1), and the node's reference coordinate along it (the support's plane, m).
struct SupportDofs {
  View<int*> node, component;
  View<double*> sign, plane;
  // The force of a catch at the last evaluation (N, along the component: -m v over the kick
  // interval that stops the node; 0 for a component not caught then), for the force record.
  View<double*> catch_force;
  int count = 0;
  // The axis of an axisymmetric scene (model.cpp): 1 for a node that, once a disc (a ring), has
  // a push-only support on x = 0 along +x, which also moves a caught ring back onto the axis,
  // behind which it would have a negative radius. Empty view: no such node. Per node, not a
  // list of components, so that the sweep visits the discs alone (the particle list).
  View<int*> axis_ring;
  bool any() const { return count > 0 || axis_ring.extent(0) > 0; }
};

// The end of an elastic bar of impedance Z = rho_b c_b (Pa s/m) and cross-section A (m^2) on a
// face that moves with velocity v along the bar (Kolsky 1949; one-dimensional waves, Graff,
// Wave Motion in Elastic Solids, 1.2). With the incident wave's particle velocity v_I, the
// characteristic that leaves the face into the bar gives the face stress (compression positive)
//   sigma = sigma_I + sigma_R = Z v_I + Z (v_I - v) = Z (2 v_I - v),
// reflected stress sigma_R = Z (v_I - v); a transmitted bar (v_I = 0) takes sigma = -Z v (v along
// the direction it pushes, so a face moving into it compresses it). A bar pushes and never pulls:
// sigma >= 0 (the face separates from the bar).
struct BarImpedance {
  double impedance = 0.0;  // Pa s/m
  double area = 0.0;       // m^2

  // The face stress the face takes over the kicks this force evaluation drives: the second half
  // kick of this step and the first of the next, dt (s) in all. With the face's velocity v_half
  // before them, its mass M (kg) and the other forces on it F (N, along the bar),
  //   v_end = v_half + dt (F + A sigma) / M,   sigma = Z (2 v_I - v_end),
  // solved for sigma: backward Euler over the interval the force acts. A lone face then slows
  // by 1 / (1 + D) per step, D = Z A dt / M, for any D, never overshooting. (The bar equation
  // at v(n+1) instead, one half kick, is the trapezoidal rule: (1 - D/2) / (1 + D/2) per step,
  // which reverses the face's velocity for D > 2, and D = 2 alpha Z_b A_b / (Z_s A_face) of a
  // stiff bar on a small face is often far above 2; the push-only cut-off then throws the face
  // off the bar.)
  KOKKOS_INLINE_FUNCTION double stress(const double incident_velocity, const double v_half,
                                       const double force, const double mass,
                                       const double dt) const {
    const double free_velocity = v_half + dt * force / mass;
    const double sigma = impedance * (2.0 * incident_velocity - free_velocity) /
                         (1.0 + dt * impedance * area / mass);
    return sigma > 0.0 ? sigma : 0.0;
  }
};

// Push-only contact with a fixed plane, one component at a time.
struct UnilateralSupport {
  // A held component stays held while the other forces press it into the support (N).
  KOKKOS_INLINE_FUNCTION static bool holds(const double sign, const double force) {
    return sign * force <= 0.0;
  }
  // A free component is caught at or behind the plane (gap <= 0, m) while moving into it.
  KOKKOS_INLINE_FUNCTION static bool catches(const double sign, const double gap,
                                             const double velocity) {
    return gap <= 0.0 && sign * velocity < 0.0;
  }
};

// The slope of a table at time t (per s): that of the segment after t (0 past its end).
KOKKOS_INLINE_FUNCTION double table_slope(const LoadTables& t, int k, double time) {
  const int begin = t.offset(k), end = t.offset(k + 1);
  for (int i = begin + 1; i < end; ++i) {
    const double t0 = t.time(i - 1), t1 = t.time(i);
    if (time < t1 && t1 > t0) return time < t0 ? 0.0 : (t.value(i) - t.value(i - 1)) / (t1 - t0);
  }
  return 0.0;
}

// Work (J) the outside does on the prescribed components over the half kick that takes them
// from their stored velocity to V(t_to), under the forces of the last evaluation. The kick
// counts f_ext . v_half over the second half kick (where v_half, the stored velocity, is
// V(t_n+1/2)) but nothing over the first (the fixed component's velocity is zeroed first), so:
//   first half (drift):  V(t_to) [m (V(t_to) - v) - dt/2 f]
//   second half:         v       [m (V(t_to) - v) - dt/2 (f + f_ext)]
// the trapezoidal work the central-difference energy balance uses, as for a load (integrate.hpp).
inline double prescribed_work(const Nodes& nodes, const PrescribedDofs& dofs,
                              const LoadTables& tables, const double t_to, const double dt,
                              const bool drift) {
  if (dofs.count == 0) return 0.0;
  const auto v = nodes.v;
  const auto f = nodes.f;
  const auto f_ext = nodes.f_ext;
  const auto mass = nodes.mass;
  double work = 0.0;
  Kokkos::parallel_reduce(
      "fracta::prescribed_work", Kokkos::RangePolicy<ExecSpace>(0, dofs.count),
      KOKKOS_LAMBDA(const int k, double& w) {
        const int n = dofs.node(k), d = dofs.component(k);
        const double target = table_value(tables, dofs.table(k), t_to);
        const double change = mass(n) * (target - v(n, d));
        if (drift)
          w += target * (change - 0.5 * dt * f(n, d));
        else
          w += v(n, d) * (change - 0.5 * dt * (f(n, d) + f_ext(n, d)));
      },
      work);
  return work;
}

// After a half kick: the prescribed components take their velocity V(t) and, after a drift of
// dt (0: none), move by dt V(t) (t is the half step's midpoint then).
inline void prescribe(const Nodes& nodes, const PrescribedDofs& dofs, const LoadTables& tables,
                      const double t, const double drift_dt) {
  if (dofs.count == 0) return;
  const auto v = nodes.v;
  const auto x = nodes.x;
  Kokkos::parallel_for(
      "fracta::prescribe", Kokkos::RangePolicy<ExecSpace>(0, dofs.count),
      KOKKOS_LAMBDA(const int k) {
        const int n = dofs.node(k), d = dofs.component(k);
        const double velocity = table_value(tables, dofs.table(k), t);
        v(n, d) = velocity;
        x(n, d) += drift_dt * velocity;
      });
}

// One support component: node n's component d, pushing along `sign` from `plane` (m). A held
// component lets go when its forces pull it away; a free one at or behind the plane and moving
// into it is caught (and, with `project`, put on the plane). Returns the velocity caught (m/s;
// 0: no catch).
template <class NodeInts, class NodeVectors>
KOKKOS_INLINE_FUNCTION double update_support(const NodeInts& fixed, const NodeVectors& x,
                                             const NodeVectors& v, const NodeVectors& f,
                                             const NodeVectors& f_ext, const int n, const int d,
                                             const double sign, const double plane,
                                             const bool project) {
  const int bit = 1 << d;
  if (fixed(n) & bit) {
    if (!UnilateralSupport::holds(sign, f(n, d) + f_ext(n, d))) fixed(n) &= ~bit;
    return 0.0;
  }
  if (!UnilateralSupport::catches(sign, sign * (x(n, d) - plane), v(n, d))) return 0.0;
  fixed(n) |= bit;
  if (project) x(n, d) = plane;
  return v(n, d);
}

// Before the second half kick, with the forces of this evaluation: held components whose
// forces pull them away let go; free ones at or behind their plane and moving into it are
// caught (the kick then zeroes their velocity). Returns the work of the catches (J, <= 0): the
// kinetic energy m v^2 / 2 of the caught component, taken by a perfectly plastic impact; and
// leaves in catch_force the impulse -m v of each catch over kick_interval (s, the interval the
// evaluation's forces act over), so the force record carries it. The rings' axis supports
// (SupportDofs::axis_ring) act alike on the discs, and put a caught ring back on the axis.
inline double update_supports(const Nodes& nodes, const SupportDofs& s,
                              const double kick_interval) {
  const auto fixed = nodes.fixed;
  const auto x = nodes.x;
  const auto v = nodes.v;
  const auto f = nodes.f;
  const auto f_ext = nodes.f_ext;
  const auto mass = nodes.mass;
  double work = 0.0;
  if (s.count > 0) {
    const auto catch_force = s.catch_force;
    Kokkos::parallel_reduce(
        "fracta::update_supports", Kokkos::RangePolicy<ExecSpace>(0, s.count),
        KOKKOS_LAMBDA(const int k, double& w) {
          const int n = s.node(k);
          const double caught = update_support(fixed, x, v, f, f_ext, n, s.component(k), s.sign(k),
                                               s.plane(k), false);
          w -= 0.5 * mass(n) * caught * caught;
          catch_force(k) =
              caught != 0.0 && kick_interval > 0.0 ? -mass(n) * caught / kick_interval : 0.0;
        },
        work);
  }
  if (s.axis_ring.extent(0) == 0 || !nodes.has_discs_now()) return work;
  // The axis acts on rings alone (elements resist it through their hoop rate v_r / r), so the
  // sweep visits the particles, in increasing order, where the list is kept.
  const auto axis_ring = s.axis_ring;
  const auto particle = nodes.particle;
  const auto particles = nodes.particle_list;
  const bool listed = particles.extent(0) > 0;
  double axis_work = 0.0;
  Kokkos::parallel_reduce(
      "fracta::update_axis_supports",
      Kokkos::RangePolicy<ExecSpace>(0, listed ? nodes.particle_count : nodes.count),
      KOKKOS_LAMBDA(const int k, double& w) {
        const int n = listed ? particles(k) : k;
        if (!axis_ring(n) || !particle(n)) return;
        const double caught = update_support(fixed, x, v, f, f_ext, n, 0, 1.0, 0.0, true);
        w -= 0.5 * mass(n) * caught * caught;
      },
      axis_work);
  return work + axis_work;
}

// The catch forces (update_supports) of the support components [begin, end) (N).
inline double catch_force_sum(const SupportDofs& s, const int begin, const int end) {
  if (end <= begin) return 0.0;
  const auto catch_force = s.catch_force;
  double sum = 0.0;
  Kokkos::parallel_reduce(
      "fracta::catch_force_sum", Kokkos::RangePolicy<ExecSpace>(begin, end),
      KOKKOS_LAMBDA(const int k, double& acc) { acc += catch_force(k); }, sum);
  return sum;
}

// A bar face's totals along the bar direction: mass (kg), momentum (kg m/s), force (N) of the
// last evaluation (internal and external).
struct FaceTotals {
  double mass = 0.0, momentum = 0.0, force = 0.0;
};

inline FaceTotals face_totals(const Nodes& nodes, const View<int*>& face, const double dx,
                              const double dy) {
  Sums<3> s;
  const auto v = nodes.v;
  const auto f = nodes.f;
  const auto f_ext = nodes.f_ext;
  const auto mass = nodes.mass;
  Kokkos::parallel_reduce(
      "fracta::face_totals", Kokkos::RangePolicy<ExecSpace>(0, static_cast<int>(face.extent(0))),
      KOKKOS_LAMBDA(const int k, Sums<3>& acc) {
        const int n = face(k);
        acc.v[0] += mass(n);
        acc.v[1] += mass(n) * (v(n, 0) * dx + v(n, 1) * dy);
        acc.v[2] += (f(n, 0) + f_ext(n, 0)) * dx + (f(n, 1) + f_ext(n, 1)) * dy;
      },
      Kokkos::Sum<Sums<3>>(s));
  return {s.v[0], s.v[1], s.v[2]};
}

// Adds the bar's force to its face: acceleration (m/s^2) along (dx, dy) for every node, i.e.
// f_ext += m_i a, the share of each node in proportion to its mass (the bar end moves the face
// as one).
inline void push_face(const Nodes& nodes, const View<int*>& face, const double acceleration,
                      const double dx, const double dy) {
  const auto f_ext = nodes.f_ext;
  const auto mass = nodes.mass;
  Kokkos::parallel_for(
      "fracta::push_face", Kokkos::RangePolicy<ExecSpace>(0, static_cast<int>(face.extent(0))),
      KOKKOS_LAMBDA(const int k) {
        const int n = face(k);
        f_ext(n, 0) += mass(n) * acceleration * dx;
        f_ext(n, 1) += mass(n) * acceleration * dy;
      });
}

// The force (N) the constraints of a node set apply along each axis at the last evaluation:
// R = m a - (f + f_ext) on its held components (fixed bits), with a the prescribed acceleration
// of its prescribed ones (table slope at t, `table` per node of the set, -1 if none), and its
// mass-averaged velocity (m/s).
struct SetReaction {
  double fx = 0.0, fy = 0.0, vx = 0.0, vy = 0.0;
};

inline SetReaction set_reaction(const Nodes& nodes, const View<int*>& set,
                                const View<int* [2]>& table, const LoadTables& tables,
                                const double t) {
  Sums<5> s;
  const auto fixed = nodes.fixed;
  const auto v = nodes.v;
  const auto f = nodes.f;
  const auto f_ext = nodes.f_ext;
  const auto mass = nodes.mass;
  Kokkos::parallel_reduce(
      "fracta::set_reaction", Kokkos::RangePolicy<ExecSpace>(0, static_cast<int>(set.extent(0))),
      KOKKOS_LAMBDA(const int k, Sums<5>& acc) {
        const int n = set(k);
        for (int d = 0; d < 2; ++d) {
          if (!(fixed(n) & (1 << d))) continue;
          const double a = table(k, d) >= 0 ? table_slope(tables, table(k, d), t) : 0.0;
          acc.v[d] += mass(n) * a - (f(n, d) + f_ext(n, d));
        }
        acc.v[2] += mass(n) * v(n, 0);
        acc.v[3] += mass(n) * v(n, 1);
        acc.v[4] += mass(n);
      },
      Kokkos::Sum<Sums<5>>(s));
  return {s.v[0], s.v[1], s.v[2] / s.v[4], s.v[3] / s.v[4]};
}

}  // namespace fracta
