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

  // tr(eps) of cell e and its reference area A0 (m^2); when forces is set, adds its forces
  // f_a = -p A0 F b_a, p = kv tr.
  KOKKOS_INLINE_FUNCTION double volumetric_strain(const int e, const double kv, const bool forces,
                                                  double& A0) const {
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
                         elements.cell_strain_offset(e, 0) - elements.cell_strain_offset(e, 1);
    if (forces) {
      const double p = kv * trace * A0;
      for (int a = 0; a < 4; ++a) {
        scatter_add(&nodes.f(node[a], 0), -p * ((1.0 + h[0]) * bx[a] + h[1] * by[a]), atomic);
        scatter_add(&nodes.f(node[a], 1), -p * (h[2] * bx[a] + (1.0 + h[3]) * by[a]), atomic);
      }
    }
    return trace;
  }

  // Cell e: forces while intact; the energy it held (J, into released) when it cracked since.
  KOKKOS_INLINE_FUNCTION void cell(const int e, double& released) const {
    if (elements.alive(e)) return;  // an FE element (or a rigid body's): not a lattice cell
    const double kv = stiffness(elements.material(e)).kv;
    if (!(kv > 0.0)) return;
    const double old = elements.cell_volumetric_strain(e);
    double A0;
    if (!elements.cell_cracked(e)) {
      elements.cell_volumetric_strain(e) = volumetric_strain(e, kv, true, A0);
      return;
    }
    if (old == 0.0) return;  // released already (or never strained)
    const double now = volumetric_strain(e, kv, false, A0);
    released += 0.5 * kv * A0 * old * now;
    elements.cell_volumetric_strain(e) = 0.0;
  }

  // Atomic path (GPUs): one element per work item.
  KOKKOS_INLINE_FUNCTION void operator()(const int e, double& released) const { cell(e, released); }
  // Chunk path (CPUs): the elements [begin, end) in order (the plan is located in no list).
  KOKKOS_INLINE_FUNCTION void chunk(const int begin, const int end, double& released) const {
    for (int e = begin; e < end; ++e) cell(e, released);
  }
};

// The plan of Elements::cell_scatter: every mesh element, in no list (built once).
inline void build_cell_scatter_plan(Elements& elements) {
  build_scatter_plan(elements.cell_scatter, elements.count, ElementNodeRange{elements.nodes},
                     View<int*>(), elements.count);
}

// Adds the cell term's forces to nodes.f and returns the energy of the cells that cracked since
// the last call (J). Nothing to do (and no launch) when no material has the term.
inline double compute_cell_bulk_forces(const Nodes& nodes, const Elements& elements,
                                       const View<const LatticeStiffness*>& stiffness) {
  if (elements.cell_volumetric_strain.extent(0) == 0 || elements.count == 0) return 0.0;
  const ScatterPlan& plan = elements.cell_scatter;
  double released = 0.0;
  if (plan.usable(elements.count)) {
    released = for_each_chunk<Kokkos::Sum<double>>(
        "fracta::cell_bulk_forces", plan, CellBulkForces{nodes, elements, stiffness, false});
  } else {
    Kokkos::parallel_reduce(
        "fracta::cell_bulk_forces", Kokkos::RangePolicy<ExecSpace>(0, elements.count),
        CellBulkForces{nodes, elements, stiffness, true}, Kokkos::Sum<double>(released));
  }
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
      KOKKOS_LAMBDA(const int k, int& sum) { sum += stiffness(material(converted(k))).kv > 0.0; },
      cells);
  return cells;
}

// The energy the intact cells' volumetric term holds (J), from the strains of their last
// evaluation (compute_cell_bulk_forces; the conversion sets a new cell's), over the converted
// cells [0, count): sum kv A0 tr^2 / 2.
inline double cell_bulk_energy(const View<int*>& converted, int count, const Nodes& nodes,
                               const Elements& elements,
                               const View<const LatticeStiffness*>& stiffness) {
  if (elements.cell_volumetric_strain.extent(0) == 0 || count == 0) return 0.0;
  const auto trace = elements.cell_volumetric_strain;
  const auto element_nodes = elements.nodes;
  const auto material = elements.material;
  const auto x0 = nodes.x0;
  double energy = 0.0;
  Kokkos::parallel_reduce(
      "fracta::cell_bulk_energy", Kokkos::RangePolicy<ExecSpace>(0, count),
      KOKKOS_LAMBDA(const int k, double& sum) {
        const int e = converted(k);
        const double tr = trace(e);
        if (tr == 0.0) return;
        double x[4], y[4];
        for (int a = 0; a < 4; ++a) {
          x[a] = x0(element_nodes(e, a), 0);
          y[a] = x0(element_nodes(e, a), 1);
        }
        sum += 0.5 * stiffness(material(e)).kv * quad_area(x, y) * tr * tr;
      },
      energy);
  return energy;
}

}  // namespace fracta
