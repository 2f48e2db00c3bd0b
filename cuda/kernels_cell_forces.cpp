// CUDA check unit for src/kernels/cell_forces.hpp: the volumetric cell term's forces and energy
// (atomic path: no scatter plan on the device) and the plan's builder.
#include "kernels/cell_forces.hpp"

namespace fracta::cuda_check {

double cell_forces_kernels(const Nodes& nodes, Elements& elements,
                           const View<const LatticeStiffness*>& stiffness) {
  build_cell_scatter_plan(elements);
  return compute_cell_bulk_forces(nodes, elements, stiffness) +
         cell_bulk_energy(nodes, elements, stiffness);
}

}  // namespace fracta::cuda_check
