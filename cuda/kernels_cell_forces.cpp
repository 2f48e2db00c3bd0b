// CUDA check unit for src/kernels/cell_forces.hpp: the volumetric cell term's forces and energy
// (atomic path: no scatter plan on the device), the count of cells with the term and the
// plan's builder.
#include "kernels/cell_forces.hpp"

namespace fracta::cuda_check {

double cell_forces_kernels(const Nodes& nodes, Elements& elements,
                           const View<const LatticeStiffness*>& stiffness,
                           const View<int*>& converted, int count) {
  build_cell_scatter_plan(elements);
  return compute_cell_bulk_forces(nodes, elements, stiffness) +
         cell_bulk_energy(converted, count, nodes, elements, stiffness) +
         cell_term_cells(converted, count, elements, stiffness);
}

}  // namespace fracta::cuda_check
