// Disc-disc contact forces (docs/physics.md 1.2: broken bonds become contacts; the same law serves
// every contact in the code), evaluated over the candidate pairs of the pre-search.
//
// Geometry of a pair (i, j), the same conventions as the bonds (state.hpp):
//   n = (x_j - x_i) / d, t = n rotated by +90 degrees, overlap delta = r_i + r_j - d.
//   The contact point lies on the centre line in the middle of the overlap, at the lever arms
//   a_i = r_i - delta/2 from x_i and a_j = r_j - delta/2 from x_j (a_i + a_j = d). Using the
//   arms a rather than the radii r makes the pair's forces and moments free of any net torque,
//   so angular momentum is conserved exactly; with r the pair would add the torque fs * delta.
//   Relative tangential velocity of disc j with respect to disc i at the contact point
//   (spin counter-clockwise positive):  vt = (v_j - v_i) . t - (a_i w_i + a_j w_j).
//
// Law: ContactLaw (laws.hpp; docs/physics.md 1.2, "Contact"), a spring-dashpot in compression
// with regularised Coulomb friction, fn = max(0, k delta + c delta_dot) with
// delta_dot = -(v_j - v_i) . n, and fs = mu fn vt / max(|vt|, v_reg) along t on disc i. Force on
// i: -fn n + fs t, on j the opposite; moments a_i fs on i and a_j fs on j. v_reg is at least the
// speed that one step of full friction removes (m_t the pair's tangential effective mass), so
// the viscous branch brings vt to zero in about one step instead of flipping its sign every step
// (chatter); v_reg_min (1e-6 m/s by default) only matters when the normal force is tiny.
//
// Joined pairs (an active bond or element between the discs) never contact: the candidate
// list leaves them out (neighbor_search.hpp, "Joined pairs"), so every listed pair is free.
//
// Special cases: a disc whose fixed bits are both set has infinite mass for m_eff and m_t
// (a wall); pairs of two such discs are skipped. A disc that is not a particle (an FE
// boundary node) has no rotational DOF: its spin counts as zero and it receives no moment.
// Coincident centres (d = 0) have no normal and are skipped.
//
// Energy: elastic 1/2 k delta^2 at the end of the step; dissipation of the step
// ((fn - k delta) delta_dot + fs vt) dt. While fn > 0 the normal term is the damping power
// c delta_dot^2; while the force is clamped at zero (k delta + c delta_dot < 0, the discs
// separate faster than the spring relaxes) it is -k delta delta_dot > 0, the spring energy
// lost because the clamped spring no longer pushes. So K + elastic + dissipated is conserved
// by the law. Discretely, the work velocity Verlet does with the force F(n) is F(n).v(n) dt with
// the FULL-step velocity v(n) = v(n-1/2) + dt/2 a(n), while the kernel sees v(n-1/2): using
// the half-step rates would bias the dissipation by about zeta omega dt (0.8% at zeta = 0.6,
// dt = t_c/200). The rates are therefore advanced by the half kick of the pair's own force
// (delta_dot - dt/2 fn (1/m_i + 1/m_j), vt - dt/2 fs / m_t): exact to O(dt^2) for an isolated
// pair; with other forces on the discs (bonds, FE, other contacts) their half kick is not
// included, an O(dt) remainder. fs vt stays >= 0 (v_reg >= mu fn dt / m_t); the normal term
// of one step may be slightly negative near maximum compression, its sum is what matters.
#pragma once
#include "kernels/compat.hpp"
#include "kernels/laws.hpp"
#include "kernels/state.hpp"

namespace fracta {

// Result of one evaluation: v[0] elastic energy (J), v[1] dissipation of this step (J),
// v[2] number of touching pairs (overlap > 0 and not joined).
using ContactSums = Sums<3>;

// The surfaces of rigid bodies of revolution (docs/physics.md 1.3, "Rigid bodies"): for each node
// of [begin, end), its neighbours along its body's surface, previous and next in
// counter-clockwise order (the body on the left), -1 where there is none (an interior node, a
// node whose edges lie on the axis). A disc touches such a surface as the polygon it is, not as
// a row of its nodes' discs, whose bumps would catch what slides along it. Empty: no such body.
struct RigidSurface {
  View<int* [2]> link;
  int begin = 0, end = 0;
  KOKKOS_INLINE_FUNCTION bool has(const int n) const {
    return n >= begin && n < end && (link(n - begin, 0) >= 0 || link(n - begin, 1) >= 0);
  }
};

struct ContactForceKernel {
  View<const int*> pair_i, pair_j;  // free pairs only: the list leaves joined ones out
  View<const double*[2]> x, v;
  View<const double*> mass, radius, inertia, spin, stiffness;
  View<const int*> fixed, particle;
  View<double* [2]> f;
  View<double*> moment;
  ContactLaw law;
  double dt;
  View<double* [4]> pair_force;  // ContactGather::pair_force, or empty: add atomically
  RigidSurface surface;

  KOKKOS_INLINE_FUNCTION void operator()(const int p, ContactSums& sums) const {
    const bool gather = pair_force.extent(0) > 0;
    if (gather)
      for (int c = 0; c < 4; ++c) pair_force(p, c) = 0.0;  // a pair out of contact adds nothing
    const int i = pair_i(p), j = pair_j(p);
    if (surface.end > surface.begin) {
      const bool on_i = surface.has(i), on_j = surface.has(j);
      if (on_i != on_j) {
        surface_pair(p, on_j ? i : j, on_j ? j : i, on_j, gather, sums);
        return;
      }
    }
    const double dx = x(j, 0) - x(i, 0), dy = x(j, 1) - x(i, 1);
    const double ri = radius(i), rj = radius(j);
    const double d2 = dx * dx + dy * dy;
    if (d2 >= (ri + rj) * (ri + rj) || d2 <= 0.0) return;
    const int wall = kFixX | kFixY;
    const double inv_mi = (fixed(i) & wall) == wall ? 0.0 : 1.0 / mass(i);
    const double inv_mj = (fixed(j) & wall) == wall ? 0.0 : 1.0 / mass(j);
    if (inv_mi + inv_mj <= 0.0) return;

    const double d = sqrt_(d2);
    const double delta = ri + rj - d;
    const double nx = dx / d, ny = dy / d;
    const double tx = -ny, ty = nx;
    const double ai = ri - 0.5 * delta, aj = rj - 0.5 * delta;
    const bool rot_i = particle(i) != 0 && inertia(i) > 0.0;
    const bool rot_j = particle(j) != 0 && inertia(j) > 0.0;
    const double wi = rot_i ? spin(i) : 0.0, wj = rot_j ? spin(j) : 0.0;
    const double vx = v(j, 0) - v(i, 0), vy = v(j, 1) - v(i, 1);
    const double delta_dot = -(vx * nx + vy * ny);
    const double vt = vx * tx + vy * ty - (ai * wi + aj * wj);

    // The law (ContactLaw) with the pair's series stiffness and inverse masses.
    const double k = ContactLaw::series_stiffness(stiffness(i), stiffness(j));
    const double inv_m = inv_mi + inv_mj;
    const double fn = law.normal_force(k, inv_m, delta, delta_dot);
    double inv_mt = inv_m;
    if (rot_i && inv_mi > 0.0) inv_mt += ai * ai / inertia(i);
    if (rot_j && inv_mj > 0.0) inv_mt += aj * aj / inertia(j);
    const double fs = law.friction_force(fn, vt, inv_mt, dt);

    const double fx = -fn * nx + fs * tx, fy = -fn * ny + fs * ty;  // on disc i
    if (gather) {
      pair_force(p, 0) = fx;
      pair_force(p, 1) = fy;
      pair_force(p, 2) = ai * fs;
      pair_force(p, 3) = aj * fs;
    } else {
      Kokkos::atomic_add(&f(i, 0), fx);
      Kokkos::atomic_add(&f(i, 1), fy);
      Kokkos::atomic_add(&f(j, 0), -fx);
      Kokkos::atomic_add(&f(j, 1), -fy);
      if (rot_i) Kokkos::atomic_add(&moment(i), ai * fs);
      if (rot_j) Kokkos::atomic_add(&moment(j), aj * fs);
    }

    // Dissipation with the full-step rates the pair's own force produces (see the header).
    sums.v[0] += ContactLaw::elastic_energy(k, delta);
    sums.v[1] += ContactLaw::dissipation(k, delta, delta_dot, vt, fn, fs, inv_m, inv_mt, dt);
    sums.v[2] += 1.0;
  }

  // Disc d against the surface of a rigid body of revolution near its node s (RigidSurface):
  // the half of each of the two edges at s that is nearer s, and the corner s itself when d
  // lies beyond both edges, so that every part of the surface belongs to exactly one pair of
  // the candidate list (the node nearer the touching point is within reach of the search:
  // its radius is at least half of each of its edges, build_rigid_surface). An edge pushes
  // along its outward normal, a corner along the line from it to d. The rigid body counts as a
  // wall for the law's damping and friction (its mass is that of the whole body) and takes the
  // reaction at s: a body of revolution moves along the axis alone, so where along its surface
  // a force acts does not matter to it. d_is_i: the pair is (d, s), else (s, d).
  KOKKOS_INLINE_FUNCTION void surface_pair(const int p, const int d, const int s, const bool d_is_i,
                                           const bool gather, ContactSums& sums) const {
    const int wall = kFixX | kFixY;
    if ((fixed(d) & wall) == wall) return;
    const int prev = surface.link(s - surface.begin, 0), next = surface.link(s - surface.begin, 1);
    const double rd = radius(d);
    const double px = x(d, 0), py = x(d, 1);
    // Projection of d on the edge a -> b: the parameter along it, unclamped.
    const auto along = [&](const int a, const int b) {
      const double ex = x(b, 0) - x(a, 0), ey = x(b, 1) - x(a, 1);
      return ((px - x(a, 0)) * ex + (py - x(a, 1)) * ey) / (ex * ex + ey * ey);
    };
    double fx = 0.0, fy = 0.0, md = 0.0;
    // One touching feature: the edge a -> b at parameter t in [0, 1] (corner: t = 0 or 1,
    // pushing along the line from it).
    const auto touch = [&](const int a, const int b, const double t, const bool corner) {
      const double cx = x(a, 0) + t * (x(b, 0) - x(a, 0)), cy = x(a, 1) + t * (x(b, 1) - x(a, 1));
      double nx, ny, gap;  // n: from d towards the surface; gap: d's centre to the surface
      if (corner) {
        const double gx = cx - px, gy = cy - py, g = sqrt_(gx * gx + gy * gy);
        if (!(g < rd) || g <= 0.0) return;
        nx = gx / g;
        ny = gy / g;
        gap = g;
      } else {
        const double ex = x(b, 0) - x(a, 0), ey = x(b, 1) - x(a, 1), e = sqrt_(ex * ex + ey * ey);
        nx = -ey / e;  // minus the outward normal (ey, -ex) / e: the body is on the edge's left
        ny = ex / e;
        gap = -((px - cx) * nx + (py - cy) * ny);
        if (!(gap < rd) || gap <= -rd) return;  // apart, or passed through the surface
      }
      const double delta = rd - gap;
      const double tx = -ny, ty = nx;
      const double arm = gap;  // from d's centre to the touching point, on the surface
      const bool rot = particle(d) != 0 && inertia(d) > 0.0;
      const double w = rot ? spin(d) : 0.0;
      const double vx = (1.0 - t) * v(a, 0) + t * v(b, 0) - v(d, 0);
      const double vy = (1.0 - t) * v(a, 1) + t * v(b, 1) - v(d, 1);
      const double delta_dot = -(vx * nx + vy * ny);
      const double vt = vx * tx + vy * ty - arm * w;
      const double k = ContactLaw::series_stiffness(stiffness(d), stiffness(s));
      const double inv_m = 1.0 / mass(d);
      const double fn = law.normal_force(k, inv_m, delta, delta_dot);
      const double inv_mt = inv_m + (rot ? arm * arm / inertia(d) : 0.0);
      const double fs = law.friction_force(fn, vt, inv_mt, dt);
      fx += -fn * nx + fs * tx;
      fy += -fn * ny + fs * ty;
      md += arm * fs;
      sums.v[0] += ContactLaw::elastic_energy(k, delta);
      sums.v[1] += ContactLaw::dissipation(k, delta, delta_dot, vt, fn, fs, inv_m, inv_mt, dt);
      sums.v[2] += 1.0;
    };
    const double t_prev = prev >= 0 ? along(prev, s) : 2.0;   // 2: no edge before s
    const double t_next = next >= 0 ? along(s, next) : -1.0;  // -1: no edge after s
    if (next >= 0 && t_next >= 0.0 && t_next < 0.5) touch(s, next, t_next, false);
    if (prev >= 0 && t_prev >= 0.5 && t_prev <= 1.0) touch(prev, s, t_prev, false);
    if (t_next < 0.0 && t_prev > 1.0) {  // beyond both edges: the corner s
      if (next >= 0)
        touch(s, next, 0.0, true);
      else
        touch(prev, s, 1.0, true);
    }
    if (fx == 0.0 && fy == 0.0 && md == 0.0) return;
    const double sign = d_is_i ? 1.0 : -1.0;  // pair_force holds the force on the pair's i
    if (gather) {
      pair_force(p, 0) = sign * fx;
      pair_force(p, 1) = sign * fy;
      pair_force(p, d_is_i ? 2 : 3) = md;
    } else {
      Kokkos::atomic_add(&f(d, 0), fx);
      Kokkos::atomic_add(&f(d, 1), fy);
      Kokkos::atomic_add(&f(s, 0), -fx);
      Kokkos::atomic_add(&f(s, 1), -fy);
      if (particle(d) != 0 && inertia(d) > 0.0) Kokkos::atomic_add(&moment(d), md);
    }
  }
};

// Forces added in a fixed order (no atomics), so a run is the same run every time on any
// number of threads: the pair kernel stores each pair's force and moments, then every disc
// gathers its pairs. The pair list of the pre-search (neighbor_search.hpp) is row by row in
// increasing i, and i < j, so in pair order a disc's pairs as j (its column) all come before
// its pairs as i (its row): the gather adds the column, then the row, each in pair order, onto
// the accumulator: the order and so the sums of the atomic adds on one thread.
struct ContactGather {
  View<const int*> discs;        // the contact discs the list was built over (node ids)
  View<const int*> row_begin;    // disc a's pairs as i: [row_begin(a), row_begin(a + 1))
  View<int*> col_offset;         // disc b's pairs as j: col_pairs[col_offset(b), col_offset(b+1))
  View<int*> col_cursor;         // work space of the fill
  View<int*> col_pairs;          // pair indices, increasing within a column
  View<double* [4]> pair_force;  // per pair: fx, fy on i (N); moment on i, moment on j (N m)
  bool built() const { return pair_force.extent(0) > 0; }
};

// The rows and columns of the candidate list [0, count) over the contact discs (node ids,
// increasing), from what the pre-search keeps with it (neighbor_search.hpp): row_offset, the
// rows' start (n + 1 entries), becomes row_begin; pair_b, the disc index of each pair's j, gives
// the columns. Views sized by the caller, at least (col_offset n + 1, col_cursor n, col_pairs
// and pair_force count). The column fill takes slots by atomic counters; sorting each column
// by pair index makes the result independent of their order.
inline void build_contact_gather(const View<const int*>& discs, const View<const int*>& row_offset,
                                 const View<const int*>& pair_b, long count, ContactGather& g) {
  g.discs = discs;
  g.row_begin = row_offset;
  const int n = static_cast<int>(discs.extent(0));
  const int pairs = static_cast<int>(count);
  const auto col_offset = g.col_offset, cursor = g.col_cursor, col_pairs = g.col_pairs;
  Kokkos::deep_copy(Kokkos::subview(col_offset, std::make_pair(0, n + 1)), 0);
  Kokkos::parallel_for(
      "fracta::contact_gather_count", Kokkos::RangePolicy<ExecSpace>(0, pairs),
      KOKKOS_LAMBDA(const int k) { Kokkos::atomic_increment(&col_offset(pair_b(k))); });
  scan_rows(col_offset, n);
  Kokkos::deep_copy(Kokkos::subview(cursor, std::make_pair(0, n)), 0);
  Kokkos::parallel_for(
      "fracta::contact_gather_fill", Kokkos::RangePolicy<ExecSpace>(0, pairs),
      KOKKOS_LAMBDA(const int k) {
        const int b = pair_b(k);
        col_pairs(col_offset(b) + Kokkos::atomic_fetch_add(&cursor(b), 1)) = k;
      });
  Kokkos::parallel_for(
      "fracta::contact_gather_sort", Kokkos::RangePolicy<ExecSpace>(0, n),
      KOKKOS_LAMBDA(const int b) { sort_segment(col_pairs, col_offset(b), col_offset(b + 1)); });
}

// Each disc adds its pairs' stored forces: the column (as j: minus the force, its own moment)
// then the row (as i). A pair out of contact stored zeros and adds nothing.
inline void gather_contact_forces(const Nodes& nodes, const ContactGather& g) {
  const auto discs = g.discs;
  const auto row_begin = g.row_begin;
  const auto col_offset = g.col_offset, col_pairs = g.col_pairs;
  const auto pf = g.pair_force;
  const auto f = nodes.f;
  const auto moment = nodes.moment;
  const auto particle = nodes.particle;
  const auto inertia = nodes.inertia;
  Kokkos::parallel_for(
      "fracta::contact_gather", Kokkos::RangePolicy<ExecSpace>(0, discs.extent(0)),
      KOKKOS_LAMBDA(const int a) {
        const int i = discs(a);
        const bool rot = particle(i) != 0 && inertia(i) > 0.0;  // as the pair kernel's rot_i
        double fx = f(i, 0), fy = f(i, 1), m = rot ? moment(i) : 0.0;
        // Pair k's share: the force times sign (+1 on i, -1 on j) and its moment column.
        const auto add = [&](const int k, const double sign, const int moment_column) {
          if (pf(k, 0) != 0.0 || pf(k, 1) != 0.0) {
            fx += sign * pf(k, 0);
            fy += sign * pf(k, 1);
          }
          if (pf(k, moment_column) != 0.0) m += pf(k, moment_column);
        };
        for (int q = col_offset(a); q < col_offset(a + 1); ++q) add(col_pairs(q), -1.0, 3);
        for (int k = row_begin(a); k < row_begin(a + 1); ++k) add(k, 1.0, 2);
        f(i, 0) = fx;
        f(i, 1) = fy;
        if (rot) moment(i) = m;
      });
}

// Adds the contact forces of the candidate pairs [0, count) (free pairs: no joined one) to
// nodes.f and nodes.moment. gather: build_contact_gather of these pairs (a fixed summation
// order), or not built: atomic adds (any pair list). With a slot given, the sums go there
// (ResultSlot: the launch does not wait) and the value returned is empty.
inline ContactSums contact_forces(const Nodes& nodes, const View<const int*>& pair_i,
                                  const View<const int*>& pair_j, long count, const ContactLaw& law,
                                  double dt, const ContactGather& gather = {},
                                  const ResultSlot<ContactSums>& into = {},
                                  const RigidSurface& surface = {}) {
  ContactForceKernel kernel{pair_i,
                            pair_j,
                            nodes.x,
                            nodes.v,
                            nodes.mass,
                            nodes.radius,
                            nodes.inertia,
                            nodes.spin,
                            nodes.contact_stiffness,
                            nodes.fixed,
                            nodes.particle,
                            nodes.f,
                            nodes.moment,
                            law,
                            dt,
                            gather.built() ? gather.pair_force : View<double* [4]>(),
                            surface};
  ContactSums sums;
  const auto policy = Kokkos::RangePolicy<ExecSpace>(0, count);
  if (into.data())
    Kokkos::parallel_reduce(slot_label("fracta::contact_forces"), policy, kernel,
                            Kokkos::Sum<ContactSums, MemSpace>(into));
  else
    Kokkos::parallel_reduce("fracta::contact_forces", policy, kernel, sums);
  if (gather.built()) gather_contact_forces(nodes, gather);
  return sums;
}

}  // namespace fracta
