// Explicit central-difference integration in velocity-Verlet form (Belytschko, Liu & Moran,
// Nonlinear Finite Elements, Box 6.1):
//   v(n+1/2) = v(n) + dt/2 a(n);  x(n+1) = x(n) + dt v(n+1/2);  forces(n+1);
//   v(n+1) = v(n+1/2) + dt/2 a(n+1).
// Full-step velocities make the kinetic energy exact at output times. The external work uses
// the trapezoidal rule dW = dx . (f_ext(n) + f_ext(n+1)) / 2, split over the two half kicks.
// Disc rotations (particles only) follow the same scheme with moment / inertia.
#pragma once
#include "kernels/compat.hpp"
#include "kernels/simd.hpp"
#include "kernels/state.hpp"

namespace fracta {

#ifdef FRACTA_HOST_SIMD
// The translation state of L = LaneCount<V> consecutive nodes as lanes of V (the CPU form of the
// kicks; NativeDouble, simd.hpp): the interleaved (x, y) rows by two vector loads each
// (load_pairs) instead of a scalar load per value; the work summed per lane. store() writes v back
// and, after a drift, x, and clears the force accumulators.
template <class V>
struct NodeLanes {
  static constexpr int L = LaneCount<V>::value;
  using Ints = IntLanes<L>;
  using Mask = decltype(V{} < 0.0);
  V x[2], v[2], f[2], f_ext[2], inv_m, work;
  Mask fixed[2];

  NodeLanes(const Nodes& nodes, const int first, const bool drift) {
    if (drift) load_pairs(&nodes.x(first, 0), x[0], x[1]);
    load_pairs(&nodes.v(first, 0), v[0], v[1]);
    load_pairs(&nodes.f(first, 0), f[0], f[1]);
    load_pairs(&nodes.f_ext(first, 0), f_ext[0], f_ext[1]);
    V mass;
    __builtin_memcpy(&mass, &nodes.mass(first), sizeof mass);
    inv_m = 1.0 / mass;
    const typename Ints::type fix = Ints::load(&nodes.fixed(first));
    fixed[0] = widen((fix & int{kFixX}) != 0);
    fixed[1] = widen((fix & int{kFixY}) != 0);
    work = splat<V>(0.0);
  }
  void store(const Nodes& nodes, const int first, const bool drift) const {
    store_pairs(&nodes.v(first, 0), v[0], v[1]);
    if (!drift) return;
    store_pairs(&nodes.x(first, 0), x[0], x[1]);
    __builtin_memset(&nodes.f(first, 0), 0, 2 * L * sizeof(double));
    // Most nodes carry no load: leave their (zero) lines clean rather than rewrite them.
    if (any_lane(f_ext[0] != 0.0 || f_ext[1] != 0.0))
      __builtin_memset(&nodes.f_ext(first, 0), 0, 2 * L * sizeof(double));
  }
  // Whether one of the L is a disc (else their rotation update is clearing the moments).
  static bool any_particle(const Nodes& nodes, const int first) {
    return !all_set(Ints::load(&nodes.particle(first)) == 0);
  }
  static void clear_moments(const Nodes& nodes, const int first) {
    __builtin_memset(&nodes.moment(first), 0, L * sizeof(double));
  }
  double work_sum() const {
    double sum = 0.0;
    for (int l = 0; l < L; ++l) sum += work[l];
    return sum;
  }
};
#endif

// One half kick per node. First half (Drift = true): kick, drift, and zero the force and
// moment accumulators for the next force evaluation; the external work uses v(n+1/2) . f_ext(n).
// Second half: the work uses v(n+1/2) . f_ext(n+1), then the kick. Returns that work (J).
// Run by NodeBatches (below): node by node, or groups of nodes as NativeDouble lanes on CPUs.
template <bool Drift>
struct HalfKick {
  static constexpr bool drift = Drift;  // moves x, clears the accumulators
  Nodes nodes;
  double dt;
  bool rotations;     // the scene has particles (their views are allocated)
  bool lanes = true;  // false: node by node (tests)

  // The translation update of one node, or of a group (T = NativeDouble, Fixed = its lane mask).
  template <class T, class Fixed>
  KOKKOS_INLINE_FUNCTION void translate(T (&x)[2], T (&v)[2], const T (&f)[2], const T (&f_ext)[2],
                                        const T& inv_m, const Fixed (&fixed)[2], T& w) const {
    for (int d = 0; d < 2; ++d) {
      if (!Drift) w += 0.5 * dt * v[d] * f_ext[d];
      T vd = v[d] + 0.5 * dt * (f[d] + f_ext[d]) * inv_m;
      vd = fixed[d] ? splat<T>(0.0) : vd;
      v[d] = vd;
      if (Drift) {
        x[d] += dt * vd;
        w += 0.5 * dt * vd * f_ext[d];
      }
    }
  }

  KOKKOS_INLINE_FUNCTION void rotate(const int n) const {
    if (nodes.particle(n)) {
      const double spin = nodes.spin(n) + 0.5 * dt * nodes.moment(n) / nodes.inertia(n);
      nodes.spin(n) = spin;
      if (Drift) nodes.rotation(n) += dt * spin;
    }
    if (Drift) nodes.moment(n) = 0.0;
  }
};

// The velocity node n has after a second half kick of dt (HalfKick<false>, the same arithmetic)
// without applying it: what a conversion between a step's force evaluation and its deferred kick
// reads as v(n+1) (m/s). dt = 0: the stored velocity.
KOKKOS_INLINE_FUNCTION void kicked_velocity(const Nodes& nodes, const int n, const double dt,
                                            double (&v)[2]) {
  v[0] = nodes.v(n, 0);
  v[1] = nodes.v(n, 1);
  if (dt == 0.0) return;
  double x[2] = {0.0, 0.0}, w = 0.0;
  const double f[2] = {nodes.f(n, 0), nodes.f(n, 1)};
  const double f_ext[2] = {nodes.f_ext(n, 0), nodes.f_ext(n, 1)};
  const int fix = nodes.fixed(n);
  const bool fixed[2] = {(fix & kFixX) != 0, (fix & kFixY) != 0};
  HalfKick<false>{nodes, dt, false}.translate(x, v, f, f_ext, 1.0 / nodes.mass(n), fixed, w);
}

// The second half kick of one step (dt_last) and the first half kick and drift of the next (dt)
// in one pass over the nodes: the same arithmetic as HalfKick<false> then HalfKick<true> (both
// use the forces of the last evaluation), read and written once. Returns the two halves'
// external work (J).
//
// A work item is kLanes consecutive nodes (simd.hpp: 8 on CPUs, 1 on GPUs). On CPUs a group of
// nodes runs as one of NativeDouble lanes: their interleaved (x, y) rows come by two vector loads
// each (load_pairs) instead of one scalar load per value, and the work is summed per lane. The
// nodes' states are those of the node-by-node pass; only the external work's rounding differs (the
// sum's order), as it differs between thread counts.
struct KickKickDrift {
  static constexpr bool drift = true;
  Nodes nodes;
  double dt_last, dt;
  bool rotations;
  bool lanes = true;  // false: node by node (tests)

  // The translation update of one node, or of a group (T = NativeDouble, Fixed = its lane mask).
  template <class T, class Fixed>
  KOKKOS_INLINE_FUNCTION void translate(T (&x)[2], T (&v)[2], const T (&f)[2], const T (&f_ext)[2],
                                        const T& inv_m, const Fixed (&fixed)[2], T& w) const {
    for (int d = 0; d < 2; ++d) {
      const T force = f[d] + f_ext[d];
      T vd = v[d];
      w += 0.5 * dt_last * vd * f_ext[d];
      vd = vd + 0.5 * dt_last * force * inv_m;  // v(n+1)
      vd = fixed[d] ? splat<T>(0.0) : vd;
      vd = vd + 0.5 * dt * force * inv_m;  // v(n+3/2)
      vd = fixed[d] ? splat<T>(0.0) : vd;
      v[d] = vd;
      x[d] += dt * vd;
      w += 0.5 * dt * vd * f_ext[d];
    }
  }

  KOKKOS_INLINE_FUNCTION void rotate(const int n) const {
    if (nodes.particle(n)) {
      const double moment = nodes.moment(n), inertia = nodes.inertia(n);
      double spin = nodes.spin(n) + 0.5 * dt_last * moment / inertia;
      spin = spin + 0.5 * dt * moment / inertia;
      nodes.spin(n) = spin;
      nodes.rotation(n) += dt * spin;
    }
    nodes.moment(n) = 0.0;
  }
};

// Runs a kick (HalfKick, KickKickDrift: its translate() and rotate()) over the nodes in work
// items of kLanes consecutive nodes (simd.hpp: 8 on CPUs, 1 on GPUs): lanes() on CPUs where the
// node rows are interleaved (LayoutRight), node() for the tail and elsewhere. run_kick returns
// the summed external work (J).
template <class Kick>
struct NodeBatches {
  Kick kick;

  KOKKOS_INLINE_FUNCTION void node(const int n, double& w) const {
    const Nodes& nodes = kick.nodes;
    double x[2], v[2], f[2], f_ext[2];
    for (int d = 0; d < 2; ++d) {
      x[d] = Kick::drift ? nodes.x(n, d) : 0.0;
      v[d] = nodes.v(n, d);
      f[d] = nodes.f(n, d);
      f_ext[d] = nodes.f_ext(n, d);
    }
    const int fix = nodes.fixed(n);
    const bool fixed[2] = {(fix & kFixX) != 0, (fix & kFixY) != 0};
    kick.translate(x, v, f, f_ext, 1.0 / nodes.mass(n), fixed, w);
    for (int d = 0; d < 2; ++d) {
      nodes.v(n, d) = v[d];
      if (Kick::drift) {
        nodes.x(n, d) = x[d];
        nodes.f(n, d) = 0.0;
        // Most nodes carry no load: leave their (zero) line clean rather than rewrite it.
        if (f_ext[d] != 0.0) nodes.f_ext(n, d) = 0.0;
      }
    }
    if (kick.rotations) kick.rotate(n);
  }

#ifdef FRACTA_HOST_SIMD
  // Nodes first .. first + kLanes - 1, by groups of kNativeLanes.
  void lanes(const int first, double& w) const {
    const Nodes& nodes = kick.nodes;
    using Group = NodeLanes<NativeDouble>;
    for (int group = first; group < first + kLanes; group += kNativeLanes) {
      Group e(nodes, group, Kick::drift);
      kick.translate(e.x, e.v, e.f, e.f_ext, e.inv_m, e.fixed, e.work);
      e.store(nodes, group, Kick::drift);
      w += e.work_sum();
      if (kick.rotations) {
        if (Group::any_particle(nodes, group)) {
          for (int n = group; n < group + kNativeLanes; ++n) kick.rotate(n);
        } else if (Kick::drift) {
          Group::clear_moments(nodes, group);
        }
      }
    }
  }
#endif

  KOKKOS_INLINE_FUNCTION void operator()(const int item, double& w) const {
    const int first = item * kLanes;
    const Nodes& nodes = kick.nodes;
#ifdef FRACTA_HOST_SIMD
    if (kick.lanes && first + kLanes <= nodes.count && nodes.x.stride_0() == 2 &&
        nodes.v.stride_0() == 2 && nodes.f.stride_0() == 2 && nodes.f_ext.stride_0() == 2) {
      lanes(first, w);
      return;
    }
#endif
    const int last = min_(first + kLanes, nodes.count);
    for (int n = first; n < last; ++n) node(n, w);
  }
};

// The kick is moved, not copied, into the batches: a host copy of the Nodes views counts each
// reference with an atomic (for_each_chunk in scatter.hpp). With a slot given, the external work
// goes there (ResultSlot: the launch does not wait) and 0 is returned.
template <class Kick>
double run_kick(const char* name, Kick kick, const ResultSlot<double>& into) {
  double work = 0.0;
  const int items = (kick.nodes.count + kLanes - 1) / kLanes;
  const auto policy = Kokkos::RangePolicy<ExecSpace>(0, items);
  if (into.data())
    Kokkos::parallel_reduce(slot_label(name), policy, NodeBatches<Kick>{std::move(kick)},
                            Kokkos::Sum<double, MemSpace>(into));
  else
    Kokkos::parallel_reduce(name, policy, NodeBatches<Kick>{std::move(kick)}, work);
  return work;
}

// The node views a kick uses, the disc views only while some node is a disc (rotations): each
// view a kernel's functor holds costs an atomic per host copy (for_each_chunk, scatter.hpp), so
// an adaptive body's disc views, which the kicks leave alone until a cell converts, would make
// its kicks dearer than pure FE's.
inline Nodes kick_views(const Nodes& nodes, const bool rotations) {
  Nodes k = node_motion_views(nodes);
  k.f_ext = nodes.f_ext;
  k.mass = nodes.mass;
  k.fixed = nodes.fixed;
  if (rotations) {
    k.particle = nodes.particle;
    k.inertia = nodes.inertia;
    k.rotation = nodes.rotation;
    k.spin = nodes.spin;
    k.moment = nodes.moment;
  }
  return k;
}

// lanes = false: node by node (tests). into: a slot for the external work (then 0 is returned).
inline double kick_kick_drift(const Nodes& nodes, double dt_last, double dt, bool lanes = true,
                              const ResultSlot<double>& into = {}) {
  const bool rotations = nodes.has_discs_now();
  return run_kick("fracta::kick_kick_drift",
                  KickKickDrift{kick_views(nodes, rotations), dt_last, dt, rotations, lanes}, into);
}

// First half kick and drift. Returns this half's external work (J).
inline double kick_drift(const Nodes& nodes, double dt, bool lanes = true,
                         const ResultSlot<double>& into = {}) {
  const bool rotations = nodes.has_discs_now();
  return run_kick("fracta::kick_drift",
                  HalfKick<true>{kick_views(nodes, rotations), dt, rotations, lanes}, into);
}

// Second half kick. Returns this half's external work (J).
inline double kick(const Nodes& nodes, double dt, bool lanes = true,
                   const ResultSlot<double>& into = {}) {
  const bool rotations = nodes.has_discs_now();
  return run_kick("fracta::kick",
                  HalfKick<false>{kick_views(nodes, rotations), dt, rotations, lanes}, into);
}

}  // namespace fracta
