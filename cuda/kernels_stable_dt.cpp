// CUDA check unit for src/kernels/stable_dt.hpp: the element bounds and their combination on the
// device; the Gershgorin bound of the bond network (both forms) and the stale-row marking.
#include "kernels/stable_dt.hpp"

namespace fracta::cuda_check {

double stable_dt_kernels(const Nodes& nodes, const Elements& elements, const Bonds& bonds,
                         const Topology& topology, const View<int*>& cells,
                         const View<double*>& out, const View<const LatticeStiffness*>& stiffness) {
  Kokkos::parallel_for(
      "fracta::cuda_check_element_stable_dt", Kokkos::RangePolicy<ExecSpace>(0, out.extent(0)),
      KOKKOS_LAMBDA(const int i) {
        const double x[4] = {0.0, 1e-3, 1e-3, 0.0}, y[4] = {0.0, 0.0, 1e-3, 1e-3};
        const double div = -1e3 * i;
        const double one =
            one_point_stable_dt(2e6, 1.4142135623730951e3, 1e-3, div, 5e3, 0.06, 1.5);
        const double full = full_integration_stable_dt(x, y, 1e-3, div, 5e3, 0.06, 1.5);
        out(i) = combined_stable_dt(one, full);
      });
  mark_converted_rows(cells, static_cast<int>(cells.extent(0)), elements, nodes, bonds, topology);
  StableDtWorkspace ws;
  return bond_stable_dt(nodes, bonds, 2) + bond_stable_dt(nodes, bonds, topology, 2, ws) +
         bond_stable_dt(nodes, bonds, damped_contact_allowance(6.0, 0.1), stiffness);
}

}  // namespace fracta::cuda_check
