// CUDA check unit for src/kernels/bond_forces.hpp: cell stress and the bond force functor
// (BondForces, one bond per work item on the device). The laws are checked by kernels_laws.cpp,
// the stable step by kernels_stable_dt.cpp.
#include "kernels/bond_forces.hpp"

namespace fracta::cuda_check {

double bond_forces_kernels(const Nodes& nodes, const Elements& elements, const Bonds& bonds,
                           const View<const BondLaw*>& laws, const View<int*>& cells,
                           const View<const LatticeStiffness*>& stiffness) {
  compute_cell_stress(cells, static_cast<int>(cells.extent(0)), stiffness, laws, elements, nodes);
  const BondStepResult r = compute_bond_forces(nodes, elements, bonds, laws, 1e-7);
  return r.fracture_energy + r.plastic_work;
}

}  // namespace fracta::cuda_check
