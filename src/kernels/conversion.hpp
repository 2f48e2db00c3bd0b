// Element-to-particle conversion (docs/physics.md 1.3). A converted element makes its 4 nodes discs
// and adds its stiffness to its bond slots: k1/2 and ks/2 to each of its 4 edges (an interior
// edge is shared by 2 elements) and k2 to each of its 2 diagonals. A `de` body is a set of
// elements converted at time 0.
#pragma once
#include <Kokkos_Sort.hpp>
#include <utility>

#include "kernels/compat.hpp"
#include "kernels/integrate.hpp"
#include "kernels/laws.hpp"
#include "kernels/simd.hpp"
#include "kernels/state.hpp"

namespace fracta {

// Lattice stiffnesses of the formulation (docs/physics.md 1.2), N/m. With the 2-D Lame constants
// mu = E / (2 (1 + nu)), lambda = nu E / (1 - nu^2) (E, nu -> E / (1 - nu^2), nu / (1 - nu) in
// plane strain, paper Eq. 4), the pair springs give C11 = (k1 + k2)/t, C12 = k2/t,
// C66 = (k2 + ks/2)/t and each intact cell's volumetric term adds kv/t to C11 and C12, for
// uniform strain with disc rotations equal to the continuum rotation, whatever the cell size.
// Isotropy (C66 = mu) then needs k1 = 2 mu t and k2 + ks/2 = mu t, and C12 = lambda needs
// k2 + kv = lambda t:
//  - lambda <= mu (nu <= 1/3 in plane stress, 1/4 in plane strain): the pair lattice alone,
//    k2 = lambda t, ks = 2 (mu - lambda) t, kv = 0 (the classical Poisson limit of central-force
//    lattices: no pair lattice reaches lambda > mu);
//  - beyond: k2 = mu t, ks = 0 and kv = (lambda - mu) t, the least many-body stiffness that lifts
//    the limit. The distinct lattice spring model lifts it with shear springs on the local strain
//    (Zhao, Fang & Zhao 2011, Int. J. Numer. Anal. Meth. Geomech. 35: 859-885); Li & He (2026,
//    arXiv:2605.15209) with volumetric constraints, as here: an energy per intact cell
//    (cell_forces.hpp). Continuous at lambda = mu, where ks and kv are both 0.
// Axisymmetric lattices (rings): the stiffnesses are those of plane stress per unit depth, each
// cell's taken times its depth 2 pi r0 (cell_depth), and `hoop` completes the 3D law (HoopLaw).
struct LatticeStiffness {
  double k1 = 0, k2 = 0, ks = 0;
  double kv = 0;  // volumetric stiffness of an intact cell (N/m): energy kv A0 tr(eps)^2 / 2
  double youngs_modulus_eff = 0, poisson_ratio_eff = 0;
  HoopLaw hoop;  // axisymmetric lattices only (hoop.active()); else all 0
};

KOKKOS_INLINE_FUNCTION LatticeStiffness lattice_stiffness(double E, double nu, bool plane_strain,
                                                          double thickness) {
  LatticeStiffness s;
  const double Ef = plane_strain ? E / (1.0 - nu * nu) : E;
  const double nuf = plane_strain ? nu / (1.0 - nu) : nu;
  s.youngs_modulus_eff = Ef;
  s.poisson_ratio_eff = nuf;
  s.k1 = Ef * thickness / (1.0 + nuf);  // 2 mu t
  if (nuf <= 1.0 / 3.0) {               // lambda <= mu
    s.k2 = nuf * Ef * thickness / (1.0 - nuf * nuf);
    s.ks = Ef * thickness * (1.0 - 3.0 * nuf) / (1.0 - nuf * nuf);
  } else {
    const double mu = Ef / (2.0 * (1.0 + nuf)), lambda = nuf * Ef / (1.0 - nuf * nuf);
    s.k2 = mu * thickness;
    s.kv = (lambda - mu) * thickness;
  }
  return s;
}

// The lattice of an axisymmetric body: plane stress per unit depth (the pair springs and the
// volumetric term then give C11 = M - lambda^2 / M, C12 = lambda - lambda^2 / M, C66 = mu: the 3D
// law with sigma_tt = 0), and the cell hoop term (HoopLaw) with the 3D constants; hoop strength
// and fracture energy are the material's (Pa, J/m^2).
inline LatticeStiffness axisymmetric_lattice_stiffness(double E, double nu, double tensile_strength,
                                                       double fracture_energy) {
  LatticeStiffness s = lattice_stiffness(E, nu, false, 1.0);
  s.hoop.lambda = nu * E / ((1.0 + nu) * (1.0 - 2.0 * nu));
  s.hoop.p_wave_modulus = s.hoop.lambda + E / (1.0 + nu);
  s.hoop.tensile_strength = tensile_strength;
  s.hoop.fracture_energy = fracture_energy;
  return s;
}

// The depth of cell e of the lattice: 2 pi r0 for rings (r0 the mean reference radius of its
// corners, where its hoop strain is taken), else 1 (the stiffnesses carry the thickness).
KOKKOS_INLINE_FUNCTION double cell_depth(const LatticeStiffness& s, const Elements& el,
                                         const Nodes& nodes, const int e) {
  if (!s.hoop.active()) return 1.0;
  double r0 = 0.0;
  for (int a = 0; a < 4; ++a) r0 += 0.25 * nodes.x0(el.nodes(e, a), 0);
  return kTwoPi * r0;
}

// Area of a quadrilateral with corners (x, y) counter-clockwise (m^2).
template <class T>
KOKKOS_INLINE_FUNCTION T quad_area(const T (&x)[4], const T (&y)[4]) {
  return 0.5 * ((x[2] - x[0]) * (y[3] - y[1]) + (x[1] - x[3]) * (y[2] - y[0]));
}

// The one-point (centre) gradients b_a of a quadrilateral's bilinear shape functions, from its
// corners (x, y) counter-clockwise; returns its area. T = double, or Double8 for eight cells.
template <class T>
KOKKOS_INLINE_FUNCTION T centre_gradients(const T (&x)[4], const T (&y)[4], T (&bx)[4],
                                          T (&by)[4]) {
  const T A = quad_area(x, y);
  const T inverse_2A = 0.5 / A;  // one division per cell, not eight (every step, every cell)
  for (int a = 0; a < 4; ++a) {
    bx[a] = (y[(a + 1) % 4] - y[(a + 3) % 4]) * inverse_2A;
    by[a] = (x[(a + 3) % 4] - x[(a + 1) % 4]) * inverse_2A;
  }
  return A;
}

// Displacement gradient H = sum_a u_a (x) b_a (xx, xy, yx, yy) of a cell from its corners'
// displacements (ux, uy) and reference gradients (bx, by); F = I + H.
template <class T>
KOKKOS_INLINE_FUNCTION void displacement_gradient(const T (&ux)[4], const T (&uy)[4],
                                                  const T (&bx)[4], const T (&by)[4], T (&h)[4]) {
  h[0] = h[1] = h[2] = h[3] = splat<T>(0.0);
  for (int a = 0; a < 4; ++a) {
    h[0] += ux[a] * bx[a];
    h[1] += ux[a] * by[a];
    h[2] += uy[a] * bx[a];
    h[3] += uy[a] * by[a];
  }
}

// Green-Lagrange strain (xx, yy, xy tensor components) of a cell at its centre, from its 4
// corners' reference positions (x0, y0) and displacements (ux, uy), with the reference one-point
// gradients: rotation invariant. T = double, or Double8 for eight cells at once (simd.hpp).
template <class T>
KOKKOS_INLINE_FUNCTION void green_lagrange(const T (&x0)[4], const T (&y0)[4], const T (&ux)[4],
                                           const T (&uy)[4], T (&strain)[3]) {
  T bx[4], by[4], h[4];
  centre_gradients(x0, y0, bx, by);
  displacement_gradient(ux, uy, bx, by, h);
  const T &h00 = h[0], &h01 = h[1], &h10 = h[2], &h11 = h[3];
  // E = (H + H^T + H^T H) / 2
  strain[0] = h00 + 0.5 * (h00 * h00 + h10 * h10);
  strain[1] = h11 + 0.5 * (h01 * h01 + h11 * h11);
  strain[2] = 0.5 * (h01 + h10 + h00 * h01 + h10 * h11);
}

// The same of cell e of the mesh.
KOKKOS_INLINE_FUNCTION void cell_green_lagrange(const Elements& el, const Nodes& nodes, int e,
                                                double (&strain)[3]) {
  double x0[4], y0[4], ux[4], uy[4];
  for (int a = 0; a < 4; ++a) {
    const int n = el.nodes(e, a);
    x0[a] = nodes.x0(n, 0);
    y0[a] = nodes.x0(n, 1);
    ux[a] = nodes.x(n, 0) - x0[a];
    uy[a] = nodes.x(n, 1) - y0[a];
  }
  green_lagrange(x0, y0, ux, uy, strain);
}

// True when a point of element e has reached damage 1 in its law's state (Elements::law_state,
// kLawDamage: hjc's damage, johnson_cook's failure damage; 0 for laws without one).
KOKKOS_INLINE_FUNCTION bool cell_has_failed(const Elements& el, const int e) {
  if (el.law_state.extent(0) == 0) return false;
  bool failed = false;
  for (int g = 0; g < el.qp_per_element; ++g)
    failed = failed || el.law_state(e * el.qp_per_element + g, kLawDamage) >= 1.0;
  return failed;
}

// Writes the topology of bond slot `position` of cell e (Bonds::nodes, cells, length0), as
// build_lattice numbered the slots: an edge's ends in increasing order, a diagonal's from corner
// d to corner d + 2; an edge's cells in increasing order (the other one: the cell of the edge's
// first corner that holds the same slot), a diagonal's its own; the reference length
// |x0_j - x0_i|. A slot of two cells, or of a cell that converts again after a restore, is
// written with the same values again.
struct SlotTopologyFill {
  Topology topo;
  View<double* [2]> x0;
  Bonds bonds;
  KOKKOS_INLINE_FUNCTION void operator()(const int e, const int position) const {
    const int b = topo.element_slots(e, position);
    if (b < 0) return;
    int i, j, other = -1;
    if (position < 4) {
      const int p = topo.element_nodes(e, position);
      const int q = topo.element_nodes(e, (position + 1) % 4);
      i = min_(p, q);
      j = max_(p, q);
      for (int m = topo.node_element_offset(p); m < topo.node_element_offset(p + 1); ++m) {
        const int cell = topo.node_element(m);
        const int at = cell == e ? -1 : topo.slot_position(cell, p, q);
        if (at >= 0 && topo.element_slots(cell, at) == b) other = cell;
      }
    } else {
      i = topo.element_nodes(e, position - 4);
      j = topo.element_nodes(e, position - 2);
    }
    bonds.nodes(b, 0) = i;
    bonds.nodes(b, 1) = j;
    bonds.cells(b, 0) = other < 0 ? e : min_(e, other);
    bonds.cells(b, 1) = other < 0 ? -1 : max_(e, other);
    bonds.length0(b) = hypot_(x0(j, 0) - x0(i, 0), x0(j, 1) - x0(i, 1));
  }
};

// The slots of cells[0, count) (every cell with `every`: a set-up that reads every slot, the
// strength draws of heterogeneity.hpp): run before a conversion reads them
// (prestress_converted_bonds).
inline void fill_slot_topology(const View<int*>& cells, int count, const Topology& topo,
                               const Nodes& nodes, const Bonds& bonds, const bool every = false) {
  if (every) count = static_cast<int>(topo.element_slots.extent(0));
  if (count == 0) return;
  const SlotTopologyFill fill{topo, nodes.x0, bonds};
  Kokkos::parallel_for(
      "fracta::fill_slot_topology", Kokkos::RangePolicy<ExecSpace>(0, 6 * count),
      KOKKOS_LAMBDA(const int k) { fill(every ? k / 6 : cells(k / 6), k % 6); });
}

// Activates the bond slots of the elements listed in `converted` and makes their nodes discs.
// `element_bonds(e, 0..3)` are the edge slots, `(e, 4..5)` the diagonal slots.
inline void activate_element_bonds(const View<int*>& converted, int count,
                                   const View<int* [6]>& element_bonds,
                                   const View<const LatticeStiffness*>& stiffness,
                                   const Elements& elements, const Nodes& nodes,
                                   const Bonds& bonds) {
  if (count == 0) return;
  Kokkos::parallel_for(
      "fracta::activate_element_bonds", Kokkos::RangePolicy<ExecSpace>(0, count),
      KOKKOS_LAMBDA(const int k) {
        const int e = converted(k);
        const LatticeStiffness s = stiffness(elements.material(e));
        const double depth = cell_depth(s, elements, nodes, e);
        for (int a = 0; a < 6; ++a) {
          const int b = element_bonds(e, a);
          if (b < 0 || bonds.state(b) == kBondBroken) continue;  // a crack stays a crack
          // A slot's natural length is set when it is first activated (the other cell of an
          // edge may write the same value at once); before, it is 0, as all its state.
          if (bonds.state(b) == kBondInactive) bonds.rest_length(b) = bonds.length0(b);
          Kokkos::atomic_add(&bonds.kn(b), depth * (a < 4 ? 0.5 * s.k1 : s.k2));
          if (a < 4) Kokkos::atomic_add(&bonds.ks(b), depth * 0.5 * s.ks);
          bonds.material(b) = elements.material(e);
          bonds.state(b) = kBondActive;
        }
        for (int a = 0; a < 4; ++a) nodes.particle(elements.nodes(e, a)) = 1;
      });
  // Cells whose material has failed (damage 1 at a point: hjc, johnson_cook with failure) have
  // no cohesion left, so their discs inherit it: every slot of the cell is born broken (a crack,
  // contact only) and the cell's own terms (volumetric, hoop) never act, as rubble. A pass of
  // its own after the activation, so that a slot shared with an intact cell of the same batch
  // ends broken whatever the order of the cells (every writer writes the same values).
  if (elements.law_state.extent(0) > 0)
    Kokkos::parallel_for(
        "fracta::unbond_failed_cells", Kokkos::RangePolicy<ExecSpace>(0, count),
        KOKKOS_LAMBDA(const int k) {
          const int e = converted(k);
          if (!cell_has_failed(elements, e)) return;
          for (int a = 0; a < 6; ++a) {
            const int b = element_bonds(e, a);
            if (b < 0) continue;
            if (bonds.state(b) == kBondInactive) bonds.rest_length(b) = bonds.length0(b);
            bonds.state(b) = kBondBroken;
            bonds.fn(b) = 0.0;
            bonds.fs(b) = 0.0;
          }
          if (elements.cell_cracked.extent(0) > 0) elements.cell_cracked(e) = 1;
          if (elements.cell_volumetric_strain.extent(0) > 0)
            elements.cell_volumetric_strain(e) = 0.0;
          if (elements.cell_hoop.extent(0) > 0) elements.cell_hoop(e, kHoopStrain) = 0.0;
        });
  // Effective areas S = kn L0 / E_eff: the bond stress fn / S then equals E_eff times the bond
  // strain, so an orthogonal bond reaches sigma_t exactly when a block in uniaxial tension
  // along it carries sigma_t (docs/physics.md 1.2, "Bond laws").
  // Only the slots of these cells changed stiffness: the others keep their areas. (A slot of
  // two of these cells is written twice with the same value.)
  Kokkos::parallel_for(
      "fracta::bond_areas", Kokkos::RangePolicy<ExecSpace>(0, 6 * count),
      KOKKOS_LAMBDA(const int k) {
        const int b = element_bonds(converted(k / 6), k % 6);
        if (b < 0 || bonds.state(b) != kBondActive) return;
        bonds.area(b) =
            bonds.kn(b) * bonds.length0(b) / stiffness(bonds.material(b)).youngs_modulus_eff;
      });
}

}  // namespace fracta

namespace fracta {

// Distortion of a quadrilateral (corners x, y counter-clockwise): its characteristic length
// l = 1 / sqrt(sum b.b) of the centre gradients b_a = (y_{a+1} - y_{a-1}, x_{a-1} - x_{a+1}) / 2A,
// the length of its stable step (stable_dt.hpp), against the reference value l0 = 1 /
// sqrt(reference_norm2): true when l <= ratio l0, i.e. 4A^2 reference_norm2 <= ratio^2
// sum |2A b_a|^2, written without a division so that a degenerate or collapsing element
// (A -> 0) counts as distorted. T: double, or one element per lane (simd.hpp).
template <class T>
KOKKOS_INLINE_FUNCTION auto length_ratio_below(const T (&x)[4], const T (&y)[4],
                                               const T& reference_norm2, double ratio) {
  const T twice_area = 2.0 * quad_area(x, y);
  T sum = splat<T>(0.0);
  for (int a = 0; a < 4; ++a) {
    const T dy = y[(a + 1) % 4] - y[(a + 3) % 4], dx = x[(a + 3) % 4] - x[(a + 1) % 4];
    sum += dx * dx + dy * dy;
  }
  return twice_area * twice_area * reference_norm2 <= ratio * ratio * sum;
}

// 1 if active element i has reached its conversion criterion: the material's conversion strain
// or conversion damage (max over quadrature points) or, with on_tension, the tension cut-off
// (max principal stress), or its distortion (conversion_length_ratio: length_ratio_below).
struct ConversionCriterion {
  View<int*> active;
  View<const int*> adaptive;
  View<const MaterialLaw*> materials;
  View<int*> material;
  View<double*> epeq;
  ColumnView<double* [4]> stress;
  int qp = 1;
  bool on_tension = false;
  // For the distortion criterion: connectivity, current positions, reference sum b.b.
  View<int* [4]> element_nodes;
  View<double* [2]> x;
  View<double*> reference_norm2;
  // Dynamic increase factors of the tension cut-off (Elements::tension_factor); empty: 1.
  View<double*> tension_factor;
  // State of laws that keep one (Elements::law_state: their damage); empty: none.
  View<double* [3]> law_state;
  KOKKOS_INLINE_FUNCTION bool distorted(const int e, const double ratio) const {
    if (!(ratio > 0.0) || reference_norm2.extent(0) == 0 || x.extent(0) == 0) return false;
    double xc[4], yc[4];
    for (int a = 0; a < 4; ++a) {
      xc[a] = x(element_nodes(e, a), 0);
      yc[a] = x(element_nodes(e, a), 1);
    }
    return length_ratio_below(xc, yc, reference_norm2(e), ratio);
  }
  KOKKOS_INLINE_FUNCTION int operator()(const int i) const {
    const int e = active(i);
    if (!adaptive(e)) return 0;
    const MaterialLaw& m = materials(material(e));
    double ep = 0.0, s1 = -1e300, damage = 0.0;
    for (int g = 0; g < qp; ++g) {
      const int q = e * qp + g;
      ep = max_(ep, epeq(q));
      if (m.conversion_damage > 0.0) damage = max_(damage, law_state(q, kLawDamage));
      const double c = 0.5 * (stress(q, 0) + stress(q, 1));
      const double r = sqrt_(0.25 * (stress(q, 0) - stress(q, 1)) * (stress(q, 0) - stress(q, 1)) +
                             stress(q, 3) * stress(q, 3));
      s1 = max_(s1, c + r);
    }
    const bool strain = (m.conversion_strain > 0.0 && ep >= m.conversion_strain) ||
                        (m.conversion_damage > 0.0 && damage >= m.conversion_damage);
    const double factor = tension_factor.extent(0) > 0 ? tension_factor(e) : 1.0;
    // hjc fails in tension through its damage, at its hydrostatic tension limit.
    const bool tension = on_tension && m.tensile_strength > 0.0 && m.model != kHjc &&
                         s1 >= m.tensile_strength * factor * (1.0 - 1e-9);
    return (strain || tension || distorted(e, m.conversion_length_ratio)) ? 1 : 0;
  }
};

// Adaptive conversion (docs/physics.md 1.3; paper Sec. 3.2, Eq. 14) as a stream compaction: flag
// the active elements that reached their material's conversion strain (max over quadrature points;
// optionally also the tension cut-off), then an exclusive parallel_scan gives every element its
// slot in the new active list or in the converted list, and a scatter writes both. Deterministic:
// the order of both lists follows the old active list. Returns the number converted; the new
// cells are in new_cells[0, n).
// flag and position: work space of at least el.active_count entries (the overload below
// allocates them).
// positions: the nodes' current positions, for the distortion criterion (empty: not checked).
inline int compact_converted(Elements& el, const View<const int*>& adaptive,
                             const View<const MaterialLaw*>& materials, bool on_tension,
                             const View<int*>& new_cells, View<int*>& active_scratch,
                             const View<int*>& flag, const View<int*>& position,
                             const View<double* [2]>& positions = {}) {
  const int n_active = el.active_count;
  if (n_active == 0) return 0;
  const auto active = el.active;
  const auto epeq = el.epeq;
  const auto stress = el.stress;
  const auto material = el.material;
  const int qp = el.qp_per_element;
  // The criterion is checked every conversion step, but elements rarely convert: count first
  // (one read-only pass, no allocation) and build the flag/scan/scatter only when some do.
  const ConversionCriterion criterion{active,
                                      adaptive,
                                      materials,
                                      material,
                                      epeq,
                                      stress,
                                      qp,
                                      on_tension,
                                      el.nodes,
                                      positions,
                                      el.reference_gradient_norm2,
                                      el.tension_factor,
                                      el.law_state};
  int flagged = 0;
  Kokkos::parallel_reduce(
      "fracta::conversion_count", Kokkos::RangePolicy<ExecSpace>(0, n_active),
      KOKKOS_LAMBDA(const int i, int& count) { count += criterion(i); }, flagged);
  if (flagged == 0) return 0;
  Kokkos::parallel_for(
      "fracta::conversion_flag", Kokkos::RangePolicy<ExecSpace>(0, n_active),
      KOKKOS_LAMBDA(const int i) { flag(i) = criterion(i); });
  int converted = 0;
  Kokkos::parallel_scan(
      "fracta::conversion_scan", Kokkos::RangePolicy<ExecSpace>(0, n_active),
      KOKKOS_LAMBDA(const int i, int& partial, const bool final) {
        if (final) position(i) = partial;
        partial += flag(i);
      },
      converted);
  if (converted == 0) return 0;
  const auto out_active = active_scratch;
  const auto alive = el.alive;
  Kokkos::parallel_for(
      "fracta::conversion_scatter", Kokkos::RangePolicy<ExecSpace>(0, n_active),
      KOKKOS_LAMBDA(const int i) {
        const int e = active(i);
        if (flag(i)) {
          new_cells(position(i)) = e;
          alive(e) = 0;
        } else {
          out_active(i - position(i)) = e;
        }
      });
  // The compacted list becomes the active list; the old one is the next scratch.
  std::swap(el.active, active_scratch);
  el.active_count = n_active - converted;
  return converted;
}

inline int compact_converted(Elements& el, const View<const int*>& adaptive,
                             const View<const MaterialLaw*>& materials, bool on_tension,
                             const View<int*>& new_cells, View<int*>& active_scratch,
                             const View<double* [2]>& positions = {}) {
  const View<int*> flag("fracta::conversion_flag", el.active_count);
  const View<int*> position("fracta::conversion_position", el.active_count);
  return compact_converted(el, adaptive, materials, on_tension, new_cells, active_scratch, flag,
                           position, positions);
}

// The distinct values candidates(c) with keep(c) = 1 (keep marks one occurrence of each), in
// increasing order into sorted[0, n); returns n. Each kept value's position is the number of
// kept values below it (O(k^2): k is small for both users).
inline int rank_kept(const char* label, const View<int*>& candidates, const View<int*>& keep, int k,
                     const View<int*>& sorted) {
  int n = 0;
  Kokkos::parallel_reduce(
      label, Kokkos::RangePolicy<ExecSpace>(0, k),
      KOKKOS_LAMBDA(const int c, int& count) {
        if (!keep(c)) return;
        const int v = candidates(c);
        int rank = 0;
        for (int j = 0; j < k; ++j) rank += keep(j) && candidates(j) < v ? 1 : 0;
        sorted(rank) = v;
        ++count;
      },
      n);
  return n;
}

// The same conversion from the candidates the FE kernel flagged (compute_fe_forces): active
// indices candidates[0, k), any order, duplicates allowed, a superset of the elements that meet
// the criterion. They are deduplicated, checked exactly and ranked pairwise (O(k^2): k is
// small, the caller takes compact_converted for large k), which gives the converted positions
// in increasing order; then one pass over the tail from the first converted position moves
// every remaining element to its new position (its index less the number of converted
// positions below it, a binary search), in place through active_scratch. The result is
// compact_converted's: the same lists in the same order. keep and sorted hold >= k entries.
inline int compact_candidates(Elements& el, const View<const int*>& adaptive,
                              const View<const MaterialLaw*>& materials, bool on_tension,
                              const View<int*>& candidates, int k, const View<int*>& keep,
                              const View<int*>& sorted, const View<int*>& new_cells,
                              View<int*>& active_scratch, const View<double* [2]>& positions = {}) {
  const int n_active = el.active_count;
  if (n_active == 0 || k == 0) return 0;
  const ConversionCriterion criterion{el.active,
                                      adaptive,
                                      materials,
                                      el.material,
                                      el.epeq,
                                      el.stress,
                                      el.qp_per_element,
                                      on_tension,
                                      el.nodes,
                                      positions,
                                      el.reference_gradient_norm2,
                                      el.tension_factor,
                                      el.law_state};
  Kokkos::parallel_for(
      "fracta::conversion_candidates", Kokkos::RangePolicy<ExecSpace>(0, k),
      KOKKOS_LAMBDA(const int c) {
        const int i = candidates(c);
        int first = i >= 0 && i < n_active ? 1 : 0;
        for (int j = 0; j < c && first; ++j)
          if (candidates(j) == i) first = 0;
        keep(c) = first && criterion(i) ? 1 : 0;
      });
  const int converted = rank_kept("fracta::conversion_rank", candidates, keep, k, sorted);
  if (converted == 0) return 0;
  const auto active = el.active;
  const auto alive = el.alive;
  Kokkos::parallel_for(
      "fracta::conversion_new_cells", Kokkos::RangePolicy<ExecSpace>(0, converted),
      KOKKOS_LAMBDA(const int j) {
        const int e = active(sorted(j));
        new_cells(j) = e;
        alive(e) = 0;
      });
  // Only the tail from the first converted position moves: copy it aside, then write each
  // remaining element at its index less the number converted below it (a binary search).
  int first = 0;
  Kokkos::deep_copy(first, Kokkos::subview(sorted, 0));
  const auto tail = std::make_pair(first, n_active);
  const auto scratch = active_scratch;
  Kokkos::deep_copy(Kokkos::subview(scratch, tail), Kokkos::subview(active, tail));
  Kokkos::parallel_for(
      "fracta::conversion_shift", Kokkos::RangePolicy<ExecSpace>(first, n_active),
      KOKKOS_LAMBDA(const int i) {
        const int below = count_below(sorted, converted, i);
        if (below < converted && sorted(below) == i) return;  // converted
        active(i - below) = scratch(i);
      });
  el.active_count = n_active - converted;
  return converted;
}

// Rotation rate (rad/s) of element e at its centre, w = (dvy/dx - dvx/dy) / 2 from the Q4
// gradient at the centroid, with the velocity v(n+1) (kicked_velocity: pending_kick_dt is the
// step of a second half kick not yet applied to nodes.v, 0 when v is v(n+1)).
KOKKOS_INLINE_FUNCTION double element_rotation_rate(const Elements& el, const Nodes& nodes,
                                                    const int e, const double pending_kick_dt) {
  double x[4], y[4];
  for (int a = 0; a < 4; ++a) {
    x[a] = nodes.x(el.nodes(e, a), 0);
    y[a] = nodes.x(el.nodes(e, a), 1);
  }
  const double A = 0.5 * ((x[2] - x[0]) * (y[3] - y[1]) + (x[1] - x[3]) * (y[2] - y[0]));
  double w = 0.0;
  for (int a = 0; a < 4; ++a) {
    const double bx = (y[(a + 1) % 4] - y[(a + 3) % 4]) / (2.0 * A);
    const double by = (x[(a + 3) % 4] - x[(a + 1) % 4]) / (2.0 * A);
    double v[2];
    kicked_velocity(nodes, el.nodes(e, a), pending_kick_dt, v);
    w += 0.5 * (v[1] * bx - v[0] * by);
  }
  return w;
}

// Initial bond forces of newly converted cells (docs/physics.md 1.3): the forces the lattice
// carries under the element's elastic strain eps = C^-1 sigma, normal kn_e L n.eps.n and shear
// ks_e L t.eps.n per contribution, and the cell term's tr(eps) where it has one, so the
// conversion itself releases no stress wave. Also starts
// the spin of discs that were not particles, and returns (via the reduction) the elastic energy
// the elements held (J). Runs before activate_element_bonds adds the stiffness;
// finish_converted_bonds then re-bases the normal springs.
// Spin: a new disc takes the mean rotation rate of the cells of this batch it belongs to (the
// cells around it that are no longer alive: a node that is not yet a particle has no converted
// cell from an earlier batch), summed in the topology's fixed order and written by the
// lowest-indexed of them alone. Each cell writing its own rate instead was a race between cells
// that share a node (the last writer won, so runs on several threads parted).
// pending_kick_dt (s): the step of a second half kick still to be applied to nodes.v (the solver
// defers it, Simulation::step), so the spin is that of v(n+1) either way; 0: v is v(n+1).
inline double prestress_converted_bonds(const View<int*>& cells, int count,
                                        const View<int* [6]>& element_bonds,
                                        const View<const LatticeStiffness*>& stiffness,
                                        const Elements& el, const Nodes& nodes, const Bonds& bonds,
                                        const Topology& topology,
                                        const double pending_kick_dt = 0.0) {
  const auto node_element_offset = topology.node_element_offset;
  const auto node_element = topology.node_element;
  double element_energy = 0.0;
  if (count == 0) return element_energy;
  const int qp = el.qp_per_element;
  Kokkos::parallel_reduce(
      "fracta::prestress_converted_bonds", Kokkos::RangePolicy<ExecSpace>(0, count),
      KOKKOS_LAMBDA(const int k, double& energy) {
        const int e = cells(k);
        energy += el.recoverable_work(e);
        const LatticeStiffness s = stiffness(el.material(e));
        const double depth = cell_depth(s, el, nodes, e);
        double sig[4] = {0, 0, 0, 0};  // xx, yy, zz, xy averaged over the quadrature points
        for (int g = 0; g < qp; ++g)
          for (int q = 0; q < 4; ++q) sig[q] += el.stress(e * qp + g, q) / qp;
        // In-plane compliance of the formulation (plane strain through E*, nu*); rings: the 3D
        // compliance (E, nu are then the material's own), with the hoop stress sig[2].
        const double E = s.youngs_modulus_eff, nu = s.poisson_ratio_eff;
        const double szz = s.hoop.active() ? sig[2] : 0.0;
        const double exx = (sig[0] - nu * (sig[1] + szz)) / E;
        const double eyy = (sig[1] - nu * (sig[0] + szz)) / E;
        const double exy = sig[3] * (1.0 + nu) / E;
        // The cell's strain beyond its elastic part (plastic flow, and the FE kinematics'
        // difference from Green-Lagrange) is an offset, so the cell stress starts at sigma.
        double green[3];
        cell_green_lagrange(el, nodes, e, green);
        el.cell_strain_offset(e, 0) = green[0] - exx;
        el.cell_strain_offset(e, 1) = green[1] - eyy;
        el.cell_strain_offset(e, 2) = green[2] - exy;
        // The volumetric cell term (cell_forces.hpp) starts from the same elastic strain.
        if (el.cell_volumetric_strain.extent(0) > 0 && (s.kv > 0.0 || s.hoop.active()))
          el.cell_volumetric_strain(e) = exx + eyy;
        // And the hoop term (HoopLaw): w = sigma_tt / M, the hoop strain beyond the elastic one
        // an offset, undamaged.
        if (s.hoop.active()) {
          const double ett = (szz - nu * (sig[0] + sig[1])) / E;
          const double r0 = depth / kTwoPi;
          double r = 0.0;
          for (int a = 0; a < 4; ++a) r += 0.25 * nodes.x(el.nodes(e, a), 0);
          el.cell_hoop(e, kHoopOffset) = HoopLaw::green_strain(r, r0) - ett;
          el.cell_hoop(e, kHoopStrain) = szz / s.hoop.p_wave_modulus;
          el.cell_hoop(e, kHoopDamage) = 0.0;
          el.cell_hoop(e, kHoopLargest) = 0.0;
        }
        for (int a = 0; a < 6; ++a) {
          const int b = element_bonds(e, a);
          if (b < 0 || bonds.state(b) == kBondBroken) continue;
          const int i = bonds.nodes(b, 0), j = bonds.nodes(b, 1);
          const double dx = nodes.x(j, 0) - nodes.x(i, 0), dy = nodes.x(j, 1) - nodes.x(i, 1);
          const double L = sqrt_(dx * dx + dy * dy), nx = dx / L, ny = dy / L;
          const double en = exx * nx * nx + eyy * ny * ny + 2.0 * exy * nx * ny;
          const double et = -(exx * nx + exy * ny) * ny + (exy * nx + eyy * ny) * nx;
          const double kn_e = depth * (a < 4 ? 0.5 * s.k1 : s.k2);
          const double ks_e = depth * (a < 4 ? 0.5 * s.ks : 0.0);
          Kokkos::atomic_add(&bonds.fn(b), kn_e * L * en);
          if (ks_e > 0.0) Kokkos::atomic_add(&bonds.fs(b), ks_e * L * et);
        }
        // Spin of new discs: the mean rotation rate of the node's cells in this batch.
        for (int a = 0; a < 4; ++a) {
          const int n = el.nodes(e, a);
          if (nodes.particle(n)) continue;
          const int begin = node_element_offset(n), end = node_element_offset(n + 1);
          int first = e;
          for (int q = begin; q < end; ++q)
            if (!el.alive(node_element(q)) && node_element(q) < first) first = node_element(q);
          if (first != e) continue;  // the lowest-indexed batch cell writes
          int batch_cells = 0;
          double w_sum = 0.0;
          for (int q = begin; q < end; ++q) {
            const int c = node_element(q);
            if (el.alive(c)) continue;
            w_sum += element_rotation_rate(el, nodes, c, pending_kick_dt);
            ++batch_cells;
          }
          nodes.spin(n) = w_sum / batch_cells;
        }
      },
      element_energy);
  return element_energy;
}

// After the stiffness of new cells was added: re-bases each touched normal spring so its
// total-form force kn (L - L0 - u_p) equals the force it now carries, and shrinks the discs of
// plastically shortened edges to their natural length.
inline void finish_converted_bonds(const View<int*>& cells, int count,
                                   const View<int* [6]>& element_bonds, const Nodes& nodes,
                                   const Bonds& bonds) {
  if (count == 0) return;
  Kokkos::parallel_for(
      "fracta::finish_converted_bonds", Kokkos::RangePolicy<ExecSpace>(0, count),
      KOKKOS_LAMBDA(const int k) {
        const int e = cells(k);
        for (int a = 0; a < 6; ++a) {
          const int b = element_bonds(e, a);
          if (b < 0) continue;
          const int i = bonds.nodes(b, 0), j = bonds.nodes(b, 1);
          const double dx = nodes.x(j, 0) - nodes.x(i, 0), dy = nodes.x(j, 1) - nodes.x(i, 1);
          const double L = sqrt_(dx * dx + dy * dy);
          if (bonds.state(b) != kBondActive || !(bonds.kn(b) > 0.0)) {
            Kokkos::atomic_fetch_min(&nodes.radius(i), 0.5 * L);
            Kokkos::atomic_fetch_min(&nodes.radius(j), 0.5 * L);
            continue;
          }
          // (A softening bond's tension is carried by its secant stiffness (1 - D) k.)
          const double fn = bonds.fn(b);
          const double up = L - bonds.length0(b) -
                            fn / (fn > 0.0 ? (1.0 - bonds.damage(b)) * bonds.kn(b) : bonds.kn(b));
          bonds.plastic_n(b) = up;
          bonds.rest_length(b) = bonds.length0(b) + up;
          // Discs of a cell that flowed plastically (or was strongly sheared) before converting
          // are closer than their radii. Shrink them to the current distance of every pair of
          // the cell, and of an edge also to its natural length L0 + u_p: when a bond breaks,
          // or a pair of a converted cell meets through an already broken slot, the contact
          // must not push the discs apart with energy nobody put in.
          double r = 0.5 * L;
          if (bonds.kind(b) == kBondEdge) r = min_(r, 0.5 * (bonds.length0(b) + up));
          Kokkos::atomic_fetch_min(&nodes.radius(i), r);
          Kokkos::atomic_fetch_min(&nodes.radius(j), r);
        }
      });
}

}  // namespace fracta

namespace fracta {

// Lists of the used bond slots (Bonds::used) and of the particles (Nodes::particle_list), both
// increasing. They are functions of bonds.state and nodes.particle, built at set-up (the
// particles by a scan, the slots from the de cells: build_lattice) and then kept up to date by
// the conversion, which only adds entries: it collects the slots and nodes it is about to
// activate (collect_new_*), and after activation inserts them (insert_sorted). Deterministic:
// no atomic decides an order.

// Rebuilds nodes.particle_list from nodes.particle; returns the count.
inline int build_particle_list(const Nodes& nodes) {
  int count = 0;
  if (!nodes.has_particles()) return count;
  const auto particle = nodes.particle;
  const auto list = nodes.particle_list;
  Kokkos::parallel_scan(
      "fracta::particle_list_scan", Kokkos::RangePolicy<ExecSpace>(0, nodes.count),
      KOKKOS_LAMBDA(const int n, int& partial, const bool final) {
        if (!particle(n)) return;
        if (final) list(partial) = n;
        ++partial;
      },
      count);
  return count;
}

// Work space of insert_sorted: candidates (kCapacity entries, grown by reserve for a larger
// batch and kept), and a merge buffer as long as the longest list.
struct ListWorkspace {
  // Batches up to this many candidates are ranked pairwise, larger ones sorted (insert_sorted).
  static constexpr int kCapacity = 1024;
  View<int*> bond_candidates, particle_candidates, keep, sorted, merged;
  ListWorkspace() = default;
  explicit ListWorkspace(int longest)
      : bond_candidates("fracta::list_bond_candidates", kCapacity),
        particle_candidates("fracta::list_particle_candidates", kCapacity),
        keep("fracta::list_keep", kCapacity),
        sorted("fracta::list_sorted", kCapacity),
        merged(Kokkos::view_alloc(Kokkos::WithoutInitializing, "fracta::list_merged"), longest) {}
  // Room for `k` candidates in each buffer but merged (twice the size asked when it grows, so
  // that a run's few large batches allocate once or twice).
  void reserve(const int k) {
    if (static_cast<int>(keep.extent(0)) >= k) return;
    const int capacity =
        k > 2 * static_cast<int>(keep.extent(0)) ? k : 2 * static_cast<int>(keep.extent(0));
    for (View<int*>* buffer : {&bond_candidates, &particle_candidates, &keep, &sorted})
      Kokkos::realloc(*buffer, capacity);
  }
};

// Slots of the cells that the activation will turn from inactive to active (-1: none).
inline void collect_new_bonds(const View<int*>& cells, int count,
                              const View<int* [6]>& element_bonds, const Bonds& bonds,
                              const View<int*>& candidates) {
  const auto state = bonds.state;
  Kokkos::parallel_for(
      "fracta::collect_new_bonds", Kokkos::RangePolicy<ExecSpace>(0, 6 * count),
      KOKKOS_LAMBDA(const int k) {
        const int b = element_bonds(cells(k / 6), k % 6);
        candidates(k) = b >= 0 && state(b) == kBondInactive ? b : -1;
      });
}

// Corner nodes of the cells that the activation will make particles (-1: already one).
inline void collect_new_particles(const View<int*>& cells, int count, const Elements& elements,
                                  const Nodes& nodes, const View<int*>& candidates) {
  const auto particle = nodes.particle;
  const auto corners = elements.nodes;
  Kokkos::parallel_for(
      "fracta::collect_new_particles", Kokkos::RangePolicy<ExecSpace>(0, 4 * count),
      KOKKOS_LAMBDA(const int k) {
        const int n = corners(cells(k / 4), k % 4);
        candidates(k) = particle(n) ? -1 : n;
      });
}

// Inserts candidates[0, k) (any order, duplicates and -1 entries allowed, none of them in the
// list) into the increasing list [0, count); returns the new count. The candidates are
// deduplicated and put in increasing order, then the two increasing lists are merged (every
// entry finds its place by a binary search in the other). Up to kCapacity candidates, ranked
// pairwise (O(k^2), small); more (a large conversion), sorted in place and compacted
// (O(k log k)). Either way the list is the same: the increasing set of its entries,
// which no scan of every slot or node need touch (ws: buffers of >= k entries).
inline int insert_sorted(const View<int*>& list, int count, const View<int*>& candidates, int k,
                         const ListWorkspace& ws) {
  if (k == 0) return count;
  const auto keep = ws.keep;
  const auto sorted = ws.sorted;
  const auto merged = ws.merged;
  int added = 0;
  if (k <= ListWorkspace::kCapacity) {
    Kokkos::parallel_for(
        "fracta::list_dedupe", Kokkos::RangePolicy<ExecSpace>(0, k), KOKKOS_LAMBDA(const int i) {
          const int v = candidates(i);
          int first = v >= 0 ? 1 : 0;
          for (int j = 0; j < i && first; ++j)
            if (candidates(j) == v) first = 0;
          keep(i) = first;
        });
    added = rank_kept("fracta::list_rank", candidates, keep, k, sorted);
  } else {
    Kokkos::sort(candidates, 0, k);
    Kokkos::parallel_scan(
        "fracta::list_unique", Kokkos::RangePolicy<ExecSpace>(0, k),
        KOKKOS_LAMBDA(const int i, int& partial, const bool final) {
          const int v = candidates(i);
          if (v < 0 || (i > 0 && candidates(i - 1) == v)) return;
          if (final) sorted(partial) = v;
          ++partial;
        },
        added);
  }
  if (added == 0) return count;
  const int total = count + added;
  merge_disjoint_sorted("fracta::list_merge", list, count, sorted, added, merged);
  Kokkos::deep_copy(Kokkos::subview(list, std::make_pair(0, total)),
                    Kokkos::subview(merged, std::make_pair(0, total)));
  return total;
}

}  // namespace fracta
