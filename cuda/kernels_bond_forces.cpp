// CUDA check unit for src/kernels/bond_forces.hpp: cell stress, the bond force functor
// (BondForces), the Gershgorin stable step, and the bilinear spring on the device.
#include "kernels/bond_forces.hpp"

namespace fracta::cuda_check {

double bond_forces_kernels(const Nodes& nodes, const Elements& elements, const Bonds& bonds,
                           const View<const BondLaw*>& laws, const View<int*>& cells,
                           const View<const LatticeStiffness*>& stiffness, const Topology& topology,
                           const View<double*>& out) {
  Kokkos::parallel_for(
      "fracta::cuda_check_bilinear_spring", Kokkos::RangePolicy<ExecSpace>(0, out.extent(0)),
      KOKKOS_LAMBDA(const int i) {
        double u_plastic = 0.0, alpha = 0.0, force = 0.0;
        out(i) = bilinear_spring(1e6, 1e-3 * i, 10.0, 1e3, u_plastic, alpha, force) + force;
      });
  compute_cell_stress(cells, static_cast<int>(cells.extent(0)), stiffness, laws, elements, nodes);
  const BondStepResult r = compute_bond_forces(nodes, elements, bonds, laws, 1e-7);
  StableDtWorkspace ws;
  return r.fracture_energy + bond_stable_dt(nodes, bonds, 2) +
         bond_stable_dt(nodes, bonds, topology, 2, ws);
}

}  // namespace fracta::cuda_check
