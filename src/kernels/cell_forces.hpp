// Cell-based (many-body) forces of the bonded disc lattice (docs/physics.md 1.2, "Poisson ratios
// beyond the pair lattice"). A lattice of pair springs is isotropic only while its Lame constant
// lambda is at most mu (nu <= 1/3 in plane stress, 1/4 in plane strain): the classical Poisson
// limit of central-force lattices. Beyond it each intact converted cell adds the volumetric
// energy
//
//   W = kv A0 tr(eps)^2 / 2,   eps = E - offset,
//
// with E the cell's Green-Lagrange strain from its four discs (reference one-point gradients, so
// rotation invariant), offset its strain beyond the elastic part at conversion (as the cell
// stress: bond_forces.hpp), A0 its reference area and kv = (lambda - mu) t (LatticeStiffness).
// Its forces are f_a = -dW/dx_a = -kv tr(eps) F (A0 b_a), with F the deformation gradient and b_a
// the reference gradients (dE/dx_a = sym(F^T ...) gives d tr(E)/dx_a = F b_a): they sum to zero
// and, W being invariant under rotations of the current positions, carry no net moment. The term
// fails with the cell: once a bond of the cell broke or started to soften (Elements::cell_cracked)
// it applies no force, and the energy it held is released to the `fracture` term as the bonds'
// is, kv A0 tr_old tr_new / 2 (what it held at the last step plus the trapezoidal work on it in
// this one, with the force now 0).
//
// Axisymmetric lattices (rings) add each cell's hoop term, W = V (1 - d [w > 0]) M w^2 / 2 with
// w = E_tt + (lambda / M) tr(eps) (laws.hpp, HoopLaw; docs/physics.md 1.2, "Axisymmetric
// discs"): forces -V sigma_tt r / (4 r0^2) along the radius and -V (lambda / M) sigma_tt F b_a,
// the energy its damage dissipates, and its release with the cell's, as the volumetric term's;
// every term of a ring cell takes its depth 2 pi r0.
//
// One work item is one mesh element; elements that are not intact converted cells of a material
// with kv > 0 return at once. On CPUs the items run by the chunks of Elements::cell_scatter (no
// atomics, a fixed order of the sums at each node: kernels/scatter.hpp), on GPUs atomically.
#pragma once
#include "kernels/compat.hpp"
#include "kernels/conversion.hpp"
#include "kernels/scatter.hpp"
#include "kernels/state.hpp"

namespace fracta {

struct CellBulkForces {
  Nodes nodes;
  Elements elements;
  View<const LatticeStiffness*> stiffness;
  bool atomic = true;

  // The strains of cell e: tr(eps) (the in-plane Green-Lagrange trace less the offset's), and
  // for rings (s.hoop active) w = E_tt - offset + (lambda / M) tr(eps) (HoopLaw); A0 its
  // reference area (m^2), depth its cell_depth. With `forces`, adds f_a = -dW/dx_a for the
  // volumetric force p = kv tr + (lambda / M) sigma_tt (per unit depth and area, on F b_a) and
  // the hoop stress sigma_tt (on dE_tt/dx_a = r / (4 r0^2) along the radius), sigma_tt from
  // hoop_stress(w) (not called without `forces`).
  template <class HoopStress>
  KOKKOS_INLINE_FUNCTION double strains(const int e, const LatticeStiffness& s, const bool forces,
                                        double& A0, double& depth, double& w,
                                        const HoopStress& hoop_stress) const {
    double x0[4], y0[4], ux[4], uy[4], bx[4], by[4], h[4];
    int node[4];
    for (int a = 0; a < 4; ++a) {
      node[a] = elements.nodes(e, a);
      x0[a] = nodes.x0(node[a], 0);
      y0[a] = nodes.x0(node[a], 1);
      ux[a] = nodes.x(node[a], 0) - x0[a];
      uy[a] = nodes.x(node[a], 1) - y0[a];
    }
    A0 = centre_gradients(x0, y0, bx, by);
    displacement_gradient(ux, uy, bx, by, h);
    // tr E = tr(H) + |H|^2 / 2 (green_lagrange's E_xx + E_yy), less the offset's trace.
    const double trace = h[0] + h[3] +
                         0.5 * (h[0] * h[0] + h[1] * h[1] + h[2] * h[2] + h[3] * h[3]) -
                         elements.strain_offset(e, 0) - elements.strain_offset(e, 1);
    depth = 1.0;
    w = 0.0;
    double r0 = 0.0, r = 0.0;
    if (s.hoop.active()) {
      for (int a = 0; a < 4; ++a) {
        r0 += 0.25 * x0[a];
        r += 0.25 * (x0[a] + ux[a]);
      }
      depth = kTwoPi * r0;
      w = s.hoop.strain(r, r0, elements.cell_hoop(e, kHoopOffset), trace);
    }
    if (forces) {
      const double sigma_tt = s.hoop.active() ? hoop_stress(w) : 0.0;
      // Plane lattices: kv tr A0 as before the hoop term, to the bit.
      const double p =
          s.hoop.active()
              ? depth * A0 * (s.kv * trace + s.hoop.lambda / s.hoop.p_wave_modulus * sigma_tt)
              : s.kv * trace * A0;
      const double radial = depth * A0 * sigma_tt * 0.25 * r / (r0 > 0.0 ? r0 * r0 : 1.0);
      for (int a = 0; a < 4; ++a) {
        scatter_add(&nodes.f(node[a], 0), -p * ((1.0 + h[0]) * bx[a] + h[1] * by[a]) - radial,
                    atomic);
        scatter_add(&nodes.f(node[a], 1), -p * (h[2] * bx[a] + (1.0 + h[3]) * by[a]), atomic);
      }
    }
    return trace;
  }

  // Cell e: forces while intact (and the energy its hoop damage dissipates); the energy it held
  // (J, into released) when it cracked since.
  KOKKOS_INLINE_FUNCTION void cell(const int e, double& released) const {
    if (elements.alive(e)) return;  // an FE element (or a rigid body's): not a lattice cell
    const LatticeStiffness s = stiffness(elements.material(e));
    const bool hoop = s.hoop.active();
    if (!(s.kv > 0.0) && !hoop) return;
    const double old = elements.cell_volumetric_strain(e);
    const double w_old = hoop ? elements.cell_hoop(e, kHoopStrain) : 0.0;
    const double d_old = hoop ? elements.cell_hoop(e, kHoopDamage) : 0.0;
    const double sigma_old = hoop ? s.hoop.stress(w_old, d_old) : 0.0;
    double A0, depth, w;
    if (!elements.cell_cracked(e)) {
      double d = d_old, largest = 0.0;
      // The damage of this step's w, before the forces use it.
      const auto hoop_stress = [&](const double w_now) {
        largest = max_(elements.cell_hoop(e, kHoopLargest), w_now);
        d = max_(d_old, s.hoop.damage(largest, sqrt_(A0)));
        return s.hoop.stress(w_now, d);
      };
      elements.cell_volumetric_strain(e) = strains(e, s, true, A0, depth, w, hoop_stress);
      if (hoop) {
        // Dissipated by the damage's growth: the trapezoidal work on the term less the change
        // of what it holds, V (sigma_old w - sigma w_old) / 2 (0 at fixed d, as for any
        // elastic term: the same rule as the bonds' and the cracked cell's release below; left
        // out while d = 0, where it is 0 but for rounding).
        if (d > 0.0) released += 0.5 * depth * A0 * (sigma_old * w - s.hoop.stress(w, d) * w_old);
        elements.cell_hoop(e, kHoopStrain) = w;
        elements.cell_hoop(e, kHoopDamage) = d;
        elements.cell_hoop(e, kHoopLargest) = largest;
      }
      return;
    }
    if (old == 0.0 && w_old == 0.0) return;  // released already (or never strained)
    const double now = strains(e, s, false, A0, depth, w, [](double) { return 0.0; });
    released += 0.5 * s.kv * depth * A0 * old * now;
    if (hoop) released += 0.5 * depth * A0 * sigma_old * w;
    elements.cell_volumetric_strain(e) = 0.0;
    if (hoop) elements.cell_hoop(e, kHoopStrain) = 0.0;
  }

  // Chunk path (CPUs): the elements [begin, end) in order (the plan is located in no list, so
  // a chunk starts at a multiple of its size); a chunk without converted cells at once.
  KOKKOS_INLINE_FUNCTION void chunk(const int begin, const int end, double& released) const {
    if (elements.cell_chunk_cells.extent(0) > 0 &&
        elements.cell_chunk_cells(begin / elements.cell_scatter.chunk_size) == 0)
      return;
    for (int e = begin; e < end; ++e) cell(e, released);
  }
};

// The converted cells per chunk of Elements::cell_scatter, from the converted list [0, count)
// (after every change of it: a conversion, a restored state). Cells only convert, so the
// chunks the kernel skips hold none of its work; the sums it makes are the same, bit for bit.
inline void count_cell_chunks(Elements& elements, const View<int*>& converted, int count) {
  const ScatterPlan& plan = elements.cell_scatter;
  if (plan.chunks == 0 || plan.chunk_size == 0) return;
  if (elements.cell_chunk_cells.extent(0) != static_cast<size_t>(plan.chunks))
    elements.cell_chunk_cells = View<int*>("fracta::cell_chunk_cells", plan.chunks);
  else
    Kokkos::deep_copy(elements.cell_chunk_cells, 0);
  if (count == 0) return;
  const auto cells = elements.cell_chunk_cells;
  const int size = plan.chunk_size;
  Kokkos::parallel_for(
      "fracta::count_cell_chunks", Kokkos::RangePolicy<ExecSpace>(0, count),
      KOKKOS_LAMBDA(const int k) { Kokkos::atomic_add(&cells(converted(k) / size), 1); });
}

// The plan of Elements::cell_scatter: every mesh element, in no list (built once).
inline void build_cell_scatter_plan(Elements& elements) {
  build_scatter_plan(elements.cell_scatter, elements.count, ElementNodeRange{elements.nodes},
                     View<int*>(), elements.count);
}

// Adds the cell term's forces to nodes.f and returns the energy of the cells that cracked since
// the last call (J). Nothing to do (and no launch) when no material has the term. CPUs: by the
// chunks of every mesh element that hold converted cells (count_cell_chunks); GPUs (and a plan
// that cannot be used): atomically over the converted list [0, count). With a slot given, the
// energy goes there (ResultSlot: the launch does not wait) and 0 is returned.
inline double compute_cell_bulk_forces(const Nodes& nodes, const Elements& elements,
                                       const View<const LatticeStiffness*>& stiffness,
                                       const View<int*>& converted, const int count,
                                       const ResultSlot<double>& into = {}) {
  if (elements.cell_volumetric_strain.extent(0) == 0 || elements.count == 0 || count == 0) {
    if (into.data()) put(into, 0.0);
    return 0.0;
  }
  const ScatterPlan& plan = elements.cell_scatter;
  double released = 0.0;
  if (plan.usable(elements.count)) {
    released = for_each_chunk<Kokkos::Sum<double>>(
        "fracta::cell_bulk_forces", plan, CellBulkForces{nodes, elements, stiffness, false});
    if (!into.data()) return released;
    put(into, released);
    return 0.0;
  }
  const CellBulkForces kernel{nodes, elements, stiffness, true};
  const auto cell = KOKKOS_LAMBDA(const int k, double& sum) {
    kernel.cell(converted(k), sum);
  };
  const auto policy = Kokkos::RangePolicy<ExecSpace>(0, count);
  if (into.data())
    Kokkos::parallel_reduce(slot_label("fracta::cell_bulk_forces"), policy, cell,
                            Kokkos::Sum<double, MemSpace>(into));
  else
    Kokkos::parallel_reduce("fracta::cell_bulk_forces", policy, cell,
                            Kokkos::Sum<double>(released));
  return released;
}

// How many of the converted cells [0, count) have the term (a material with kv > 0): when none,
// the force kernel has nothing to do (Simulation::cell_term_live).
inline int cell_term_cells(const View<int*>& converted, int count, const Elements& elements,
                           const View<const LatticeStiffness*>& stiffness) {
  if (elements.cell_volumetric_strain.extent(0) == 0 || count == 0) return 0;
  const auto material = elements.material;
  int cells = 0;
  Kokkos::parallel_reduce(
      "fracta::cell_term_cells", Kokkos::RangePolicy<ExecSpace>(0, count),
      KOKKOS_LAMBDA(const int k, int& sum) {
        const LatticeStiffness& s = stiffness(material(converted(k)));
        sum += s.kv > 0.0 || s.hoop.active();
      },
      cells);
  return cells;
}

// The energy the intact cells' terms hold (J), from the strains of their last evaluation
// (compute_cell_bulk_forces; the conversion sets a new cell's), over the converted cells
// [0, count): sum depth A0 (kv tr^2 + M w^2 (1 - d [w > 0])) / 2.
inline double cell_bulk_energy(const View<int*>& converted, int count, const Nodes& nodes,
                               const Elements& elements,
                               const View<const LatticeStiffness*>& stiffness) {
  if (elements.cell_volumetric_strain.extent(0) == 0 || count == 0) return 0.0;
  const auto trace = elements.cell_volumetric_strain;
  const auto hoop = elements.cell_hoop;
  const auto element_nodes = elements.nodes;
  const auto material = elements.material;
  const auto x0 = nodes.x0;
  double energy = 0.0;
  Kokkos::parallel_reduce(
      "fracta::cell_bulk_energy", Kokkos::RangePolicy<ExecSpace>(0, count),
      KOKKOS_LAMBDA(const int k, double& sum) {
        const int e = converted(k);
        const LatticeStiffness& s = stiffness(material(e));
        const double tr = trace(e);
        const double w = s.hoop.active() ? hoop(e, kHoopStrain) : 0.0;
        if (tr == 0.0 && w == 0.0) return;
        double x[4], y[4], r0 = 0.0;
        for (int a = 0; a < 4; ++a) {
          x[a] = x0(element_nodes(e, a), 0);
          y[a] = x0(element_nodes(e, a), 1);
          r0 += 0.25 * x[a];
        }
        const double depth = s.hoop.active() ? kTwoPi * r0 : 1.0;
        const double hoop_energy =
            s.hoop.active() ? s.hoop.stress(w, hoop(e, kHoopDamage)) * w : 0.0;
        const double area = quad_area(x, y);
        sum += 0.5 * s.kv * depth * area * tr * tr;
        if (s.hoop.active()) sum += 0.5 * depth * area * hoop_energy;
      },
      energy);
  return energy;
}

}  // namespace fracta
