// Stable time step (docs/physics.md 1.4): the element bound the FE kernel evaluates per element
// (fe_forces.hpp), the Gershgorin bound of the bond network, and how the two combine. The bounds
// are before the safety factor dt_safety.
#pragma once
#include <cmath>

#include "kernels/compat.hpp"
#include "kernels/conversion.hpp"
#include "kernels/simd.hpp"
#include "kernels/state.hpp"

namespace fracta {

// The step's stable bound (s) from the elements' (FeStepSums::dt_min) and the lattice's
// (bond_stable_dt): the smaller, or the FE bound where it is negative, which flags an inverted
// element to the host and must stay so. (As std::min(fe_bound, lattice_bound) where both are
// positive: the FE bound at ties and where the lattice bound is NaN.) T: double, or one bound
// per lane (simd.hpp).
template <class T>
KOKKOS_INLINE_FUNCTION T combined_stable_dt(const T& fe_bound, const T& lattice_bound) {
  return fe_bound < 0.0 ? fe_bound : (lattice_bound < fe_bound ? lattice_bound : fe_bound);
}

// ---------------------------------------------------------------------------------------------
// Elements (docs/physics.md 1.4, "Elements"): dt_e = l_e / (Q + sqrt(Q^2 + c^2)), with c the
// P-wave speed, l_e = 1 / sqrt(sum_a |b_a|^2) and the bulk-viscosity correction Q of a compressed
// element (as LS-DYNA). T: double, or one element per lane (simd.hpp); C, the type of c: double,
// or T where the speed differs by lane (laws whose stiffness follows their state: hjc).
// ---------------------------------------------------------------------------------------------

// Q = C1 c + C2 l |div v| while the element compresses (div_rate < 0: the smallest velocity
// divergence of its points this step), else 0; l the bulk-viscosity length (m).
template <class T, class C>
KOKKOS_INLINE_FUNCTION T bulk_viscosity_speed(const T& length, const T& div_rate, const C& c,
                                              double bulk_linear, double bulk_quadratic) {
  return div_rate < 0.0 ? bulk_quadratic * length * (-div_rate) + bulk_linear * c : splat<T>(0.0);
}

// One-point Q4 (Flanagan & Belytschko 1981): omega_max^2 <= 4 c^2 sum(b.b) of the uniform
// gradients b_a, i.e. dt <= l / c with l = 1 / sqrt(sum b.b) (h / sqrt(2) for a square of side
// h), 1 / (sqrt(sum b.b) (Q + sqrt(Q^2 + c^2))) with the bulk viscosity. b2 = sum b.b and
// sqrt_b2 its root (the hourglass control has it); length: the bulk-viscosity length, the root
// of the element's area. 0 for a degenerate element (b2 not positive).
template <class T, class C>
KOKKOS_INLINE_FUNCTION T one_point_stable_dt(const T& b2, const T& sqrt_b2, const T& length,
                                             const T& div_rate, const C& c, double bulk_linear,
                                             double bulk_quadratic) {
  const T qs = bulk_viscosity_speed(length, div_rate, c, bulk_linear, bulk_quadratic);
  return !(b2 > 0.0) ? splat<T>(0.0)
         : qs > 0.0  ? 1.0 / (sqrt_b2 * (qs + sqrt_(qs * qs + c * c)))
                     : 1.0 / (sqrt_b2 * c);
}

// 2x2 Gauss: for a square the largest element eigenvalue of M^-1 K equals the one-point bound
// 4 c^2 sum(b.b) (checked numerically for nu = 0 ... 0.49); the factor 0.9 covers distorted
// elements, for which the full-integration stiffness can exceed it slightly. b from the corners
// (x, y) counter-clockwise; length: the bulk-viscosity length, the root of the sum of the points'
// weights. 0 for an inverted element.
inline constexpr double kFullIntegrationDtFactor = 0.9;
// hoop_b2: the axisymmetric hoop row's 1 / (4 r_c^2) added to sum b.b (fe_forces.hpp; 0 else).
template <class T, class C>
KOKKOS_INLINE_FUNCTION T full_integration_stable_dt(const T (&x)[4], const T (&y)[4],
                                                    const T& length, const T& div_rate, const C& c,
                                                    double bulk_linear, double bulk_quadratic,
                                                    const T& hoop_b2 = splat<T>(0.0)) {
  const T A = 0.5 * ((x[2] - x[0]) * (y[3] - y[1]) + (x[1] - x[3]) * (y[2] - y[0]));
  T b2 = hoop_b2;
  for (int a = 0; a < 4; ++a) {
    const T bxa = (y[(a + 1) % 4] - y[(a + 3) % 4]) / (2.0 * A);
    const T bya = (x[(a + 3) % 4] - x[(a + 1) % 4]) / (2.0 * A);
    b2 += bxa * bxa + bya * bya;
  }
  const T len = A > 0.0 ? kFullIntegrationDtFactor / sqrt_(b2) : splat<T>(0.0);
  const T qs = bulk_viscosity_speed(length, div_rate, c, bulk_linear, bulk_quadratic);
  return len / (qs + sqrt_(qs * qs + c * c));
}

// ---------------------------------------------------------------------------------------------
// Bonds
// ---------------------------------------------------------------------------------------------

// The bond network (docs/physics.md 1.4, "Lattice"): Gershgorin's bound on the largest
// eigenvalue of M^-1/2 K M^-1/2 over translations and rotations, row by row. Each bond adds to
// the rows of its two discs; `contact_allowance` adds that many contacts of the disc's contact
// stiffness to every contact disc (particles and FE boundary nodes). bond_stable_dt returns
// 2 / sqrt(lambda_max) (s), or a huge value if no bond.

// The volumetric cell term (cell_forces.hpp) of a square cell of side h (A0 b_a = (+-h, +-h) / 2)
// adds to node a's translation row of M^-1/2 K M^-1/2 at most
// kv A0 |b_a|_inf sum_b |b_b|_1 / sqrt(m_a m_b) = (kv / 2) sum_b 1 / sqrt(m_a m_b), the sum over
// the cell's four corners, where a spring k on the diagonal (a, c) adds
// 1.2071 k (1/m_a + 1/sqrt(m_a m_c)). With lumped masses within a factor 4 of each other the
// ratio of the two is at most 1.52 (a heavy corner whose side neighbours are 4 times lighter),
// so the bound counts 1.55 kv on each diagonal (each corner is the end of one diagonal per
// cell); between equal masses that is 1.9 times what the cell needs, room for the geometric
// stiffness kv tr(eps) of strained cells.
// Rings (axisymmetric lattices): the cell's terms take its depth 2 pi r0, and the hoop term
// (HoopLaw) W = V M w^2 / 2 adds V M g_a g_b^T, g_a = dw/dx_a, with
// |g_a|_1 <= 1 / (4 r0) + (lambda / M) |b_a|_1: a row sum of at most
// V M g1^2 sum_b 1 / sqrt(m_a m_b), g1 = 1 / (4 r0) + (lambda / M) (1 / (2 h_x) + 1 / (2 h_y)),
// the volumetric term's form with kv -> 2 V M g1^2. The cell of a diagonal is a rectangle of
// sides h_x, h_y, the diagonal's components, and r0 its midpoint's radius (a perturbed cell's
// differ by the perturbation: the factor's margin covers it).
inline constexpr double kCellTermDiagonalFactor = 1.55;
KOKKOS_INLINE_FUNCTION double cell_term_on_diagonal(
    const Nodes& nodes, const Bonds& bonds, const int b,
    const View<const LatticeStiffness*>& stiffness) {
  if (stiffness.extent(0) == 0 || bonds.kind(b) != kBondDiagonal) return 0.0;
  const LatticeStiffness& s = stiffness(bonds.material(b));
  if (!s.hoop.active()) return kCellTermDiagonalFactor * s.kv;
  const int i = bonds.nodes(b, 0), j = bonds.nodes(b, 1);
  const double r0 = 0.5 * (nodes.x0(i, 0) + nodes.x0(j, 0));
  const double hx = fabs_(nodes.x0(j, 0) - nodes.x0(i, 0));
  const double hy = fabs_(nodes.x0(j, 1) - nodes.x0(i, 1));
  const double depth = kTwoPi * r0, volume = depth * hx * hy;
  const double g1 = 0.25 / r0 + s.hoop.lambda / s.hoop.p_wave_modulus * (0.5 / hx + 0.5 / hy);
  return kCellTermDiagonalFactor * (s.kv * depth + 2.0 * volume * s.hoop.p_wave_modulus * g1 * g1);
}

// What active bond b adds to the rows of its end s (0 or 1); cell_kv: the cell term it stands
// for (cell_term_on_diagonal).
KOKKOS_INLINE_FUNCTION void gershgorin_terms(const Nodes& nodes, const Bonds& bonds, const int b,
                                             const int s, double& trans, double& rot,
                                             const double cell_kv = 0.0) {
  const int i = bonds.nodes(b, s), j = bonds.nodes(b, 1 - s);
  const double k = bonds.kn(b) + bonds.ks(b) + cell_kv, ks = bonds.ks(b);
  const double mi = nodes.mass(i), mj = nodes.mass(j);
  const double Ii = nodes.inertia(i), Ij = nodes.inertia(j);
  const double ri = nodes.radius(i), rj = nodes.radius(j);
  // |K| entries of a 2D spring pair, row x of disc i: |kn nx^2 + ks tx^2| +
  // |(kn - ks) nx ny| <= (1 + sqrt 2)/2 (kn + ks) towards i and towards j; shear couples
  // the translation to both rotations by r ks |tx| <= r ks; rotations couple by r^2 ks
  // and to translations by r ks (|tx| + |ty|) <= sqrt 2 r ks.
  trans = 1.2071067811865475 * k * (1.0 / mi + 1.0 / sqrt_(mi * mj)) +
          ks * (ri / sqrt_(mi * Ii) + rj / sqrt_(mi * Ij));
  rot = ks * (ri * ri / Ii + ri * rj / sqrt_(Ii * Ij)) +
        1.4142135623730951 * ks * ri * (1.0 / sqrt_(Ii * mi) + 1.0 / sqrt_(Ii * mj));
}

struct GershgorinRows {
  Nodes nodes;
  Bonds bonds;
  View<double* [2]> row;                    // translation, rotation
  View<const LatticeStiffness*> stiffness;  // per material, for the cell term; empty: none

  KOKKOS_INLINE_FUNCTION void operator()(const int b) const {
    if (bonds.state(b) != kBondActive) return;
    for (int s = 0; s < 2; ++s) {
      double trans, rot;
      gershgorin_terms(nodes, bonds, b, s, trans, rot,
                       cell_term_on_diagonal(nodes, bonds, b, stiffness));
      Kokkos::atomic_add(&row(bonds.nodes(b, s), 0), trans);
      Kokkos::atomic_add(&row(bonds.nodes(b, s), 1), rot);
    }
  }
};

// Row bound of node n: its bond rows and the allowance of contacts.
struct GershgorinBound {
  Nodes nodes;
  View<double* [2]> row;
  double allowance;
  KOKKOS_INLINE_FUNCTION double contact(const int n) const {
    // A contact pair adds at most 1.2071 kc (1/m_i + 1/sqrt(m_i m_j)) <= 3.7 kc / m_i
    // (a neighbour of at least a quarter of the mass: a corner node).
    return allowance * 3.7 * nodes.contact_stiffness(n) / nodes.mass(n);
  }
  // The bound of node n from its row sums.
  KOKKOS_INLINE_FUNCTION double bound(const int n, const double trans, const double rot) const {
    return max_(trans, rot) + contact(n);
  }
  KOKKOS_INLINE_FUNCTION void operator()(const int n, double& lmax) const {
    if (!nodes.particle(n) && !nodes.contact_disc(n)) return;
    const double l = bound(n, row(n, 0), row(n, 1));
    lmax = lmax > l ? lmax : l;
  }
};

// The contact allowance of the lattice bound: `contacts` contacts at the full penalty stiffness,
// each with its dashpot of damping ratio zeta. Central differences keep a damped oscillator
// stable for omega dt <= 2 (sqrt(1 + zeta^2) - zeta) (Belytschko, Liu & Moran 2000, Sec. 6.3),
// so the damper counts as a stiffness 1 / (sqrt(1 + zeta^2) - zeta)^2 times larger: 1.22 at
// zeta = 0.1.
inline double damped_contact_allowance(double contacts, double damping_ratio) {
  const double shrink = std::sqrt(1.0 + damping_ratio * damping_ratio) - damping_ratio;
  return contacts / (shrink * shrink);
}

inline double bond_stable_dt(const Nodes& nodes, const Bonds& bonds, double contact_allowance,
                             const View<const LatticeStiffness*>& stiffness = {}) {
  if (!nodes.has_particles()) return 1e300;
  View<double* [2]> row("fracta::gershgorin_rows", nodes.count);  // translation, rotation
  if (bonds.count > 0)
    Kokkos::parallel_for("fracta::bond_gershgorin", Kokkos::RangePolicy<ExecSpace>(0, bonds.count),
                         GershgorinRows{nodes, bonds, row, stiffness});
  double lambda = 0.0;
  Kokkos::parallel_reduce("fracta::bond_stable_dt", Kokkos::RangePolicy<ExecSpace>(0, nodes.count),
                          GershgorinBound{nodes, row, contact_allowance},
                          Kokkos::Max<double>(lambda));
  return lambda > 0.0 ? 2.0 / sqrt_(lambda) : 1e300;
}

// The same bound over the particle list (Nodes::particle_list), each particle gathering its
// rows from its bond slots (Topology::node_slots, in increasing slot order: the order in which
// the sweep's atomic adds arrive on one thread, so the value is the sweep's), in one pass with
// no atomics and no row storage. The ends of active bonds are particles; a contact disc that is
// not a particle has the bound contact(n) alone, and a particle's bound is at least its
// contact(n), so lambda = max(max over contact discs of contact(n), max over particles of
// their bound): the first term is constant and computed once.
// With `cache` set, each particle's bound is kept and recomputed only when Nodes::bound_stale
// flags it (set where a row can change: a bond breaking, mark_converted_rows): between
// conversions few rows change, and a particle's row is the same sum of the same terms, so the
// value is the one of a full pass. invalidate() after the state was replaced (a restore).
// Without `cache`, a `bound` view of nodes.count entries given by the caller receives every
// particle's bound (tests), and the stale flags are left alone.
struct StableDtWorkspace {
  double disc_lambda = 0.0;  // max over contact discs of contact(n)
  double allowance = -1;     // the allowance disc_lambda was computed for (-1: none yet)
  bool cache = false;        // keep per-particle bounds (one workspace per model may)
  bool cached = false;       // `bound` holds every particle's current bound but the stale ones
  View<double*> bound;       // per node, 1/s^2
  void invalidate() { cached = false; }
};

inline double bond_stable_dt(const Nodes& nodes, const Bonds& bonds, const Topology& topology,
                             double contact_allowance, StableDtWorkspace& ws,
                             const View<const LatticeStiffness*>& stiffness = {}) {
  if (!nodes.has_particles()) return 1e300;
  if (nodes.particle_list.extent(0) == 0 || topology.element_slots.extent(0) == 0)
    return bond_stable_dt(nodes, bonds, contact_allowance, stiffness);
  const GershgorinBound bound{nodes, {}, contact_allowance};
  if (ws.allowance != contact_allowance) {
    const auto disc = nodes.contact_disc;
    ws.disc_lambda = 0.0;
    Kokkos::parallel_reduce(
        "fracta::disc_stable_dt", Kokkos::RangePolicy<ExecSpace>(0, nodes.count),
        KOKKOS_LAMBDA(const int n, double& lmax) {
          if (!disc(n)) return;
          const double l = bound.contact(n);
          lmax = lmax > l ? lmax : l;
        },
        Kokkos::Max<double>(ws.disc_lambda));
    ws.allowance = contact_allowance;
    ws.cached = false;
  }
  const bool cache = ws.cache && nodes.bound_stale.extent(0) > 0;
  if (cache && ws.bound.extent(0) != static_cast<size_t>(nodes.count)) {
    ws.bound = View<double*>(
        Kokkos::view_alloc(Kokkos::WithoutInitializing, "fracta::particle_stable_bound"),
        nodes.count);
    ws.cached = false;
  }
  const bool all = !cache || !ws.cached;  // recompute every particle
  const bool write_bound = ws.bound.extent(0) == static_cast<size_t>(nodes.count);
  const auto particles = nodes.particle_list;
  const auto stale = nodes.bound_stale;
  const auto cached_bound = ws.bound;
  double lambda = 0.0;
  Kokkos::parallel_reduce(
      "fracta::bond_stable_dt", Kokkos::RangePolicy<ExecSpace>(0, nodes.particle_count),
      KOKKOS_LAMBDA(const int k, double& lmax) {
        const int n = particles(k);
        double l;
        if (all || stale(n)) {
          double row_trans = 0.0, row_rot = 0.0;
          int slots[Topology::kMaxNodeSlots];
          const int slot_count = topology.node_slots(n, slots);
          for (int q = 0; q < slot_count; ++q) {
            const int b = slots[q];
            if (bonds.state(b) != kBondActive) continue;
            double trans, rot;
            gershgorin_terms(nodes, bonds, b, bonds.nodes(b, 0) == n ? 0 : 1, trans, rot,
                             cell_term_on_diagonal(nodes, bonds, b, stiffness));
            row_trans += trans;
            row_rot += rot;
          }
          l = bound.bound(n, row_trans, row_rot);
          if (write_bound) cached_bound(n) = l;
          if (cache) stale(n) = 0;
        } else {
          l = cached_bound(n);
        }
        lmax = lmax > l ? lmax : l;
      },
      Kokkos::Max<double>(lambda));
  ws.cached = cache;
  lambda = lambda > ws.disc_lambda ? lambda : ws.disc_lambda;
  return lambda > 0.0 ? 2.0 / sqrt_(lambda) : 1e300;
}

// Flags the rows a conversion changed (Nodes::bound_stale): every node of the new cells (their
// bonds activate, their radii shrink) and every bond neighbour of those nodes (a row holds the
// other end's radius, mass and inertia).
inline void mark_converted_rows(const View<int*>& cells, int count, const Elements& el,
                                const Nodes& nodes, const Bonds& bonds, const Topology& topology) {
  if (count == 0 || nodes.bound_stale.extent(0) == 0 || topology.element_slots.extent(0) == 0)
    return;
  const auto stale = nodes.bound_stale;
  Kokkos::parallel_for(
      "fracta::mark_converted_rows", Kokkos::RangePolicy<ExecSpace>(0, 4 * count),
      KOKKOS_LAMBDA(const int k) {
        const int n = el.nodes(cells(k / 4), k % 4);
        stale(n) = 1;  // every writer writes 1
        int slots[Topology::kMaxNodeSlots];
        const int slot_count = topology.node_slots(n, slots);
        for (int q = 0; q < slot_count; ++q) {
          const int b = slots[q];
          if (bonds.state(b) != kBondActive) continue;
          stale(bonds.nodes(b, 0) == n ? bonds.nodes(b, 1) : bonds.nodes(b, 0)) = 1;
        }
      });
}

}  // namespace fracta
