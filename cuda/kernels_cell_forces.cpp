// CUDA check unit for src/kernels/cell_forces.hpp: the cell term's forces and energy (volumetric
// and hoop; atomic path over the converted list: no scatter plan on the device), the count of
// cells with the term, the plan's builder and its chunk counts.
#include "kernels/cell_forces.hpp"

namespace fracta::cuda_check {

double cell_forces_kernels(const Nodes& nodes, Elements& elements,
                           const View<const LatticeStiffness*>& stiffness,
                           const View<int*>& converted, int count) {
  build_cell_scatter_plan(elements);
  count_cell_chunks(elements, converted, count);
  return compute_cell_bulk_forces(nodes, elements, stiffness, converted, count) +
         cell_bulk_energy(converted, count, nodes, elements, stiffness) +
         cell_term_cells(converted, count, elements, stiffness);
}

}  // namespace fracta::cuda_check
