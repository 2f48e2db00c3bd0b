// CUDA check unit for src/kernels/fe_forces.hpp: the element kernel in both integrations
// (FeForces<1>, FeForces<4>, plane and axisymmetric) through compute_fe_forces, and its geometry
// helpers on the device.
#include "kernels/fe_forces.hpp"

namespace fracta::cuda_check {

double fe_forces_kernels(const Nodes& nodes, const Elements& elements,
                         const View<const MaterialLaw*>& materials, const FeParams& p,
                         const View<double*>& out) {
  Kokkos::parallel_for(
      "fracta::cuda_check_fe_helpers", Kokkos::RangePolicy<ExecSpace>(0, out.extent(0)),
      KOKKOS_LAMBDA(const int i) {
        const double x[4] = {0.0, 1.0, 1.0, 0.0}, y[4] = {0.0, 0.0, 1.0, 1.0};
        double bx[4], by[4], s[4] = {1.0, 2.0, 0.0, 0.5};
        jaumann_rotate(s, 1e-3 * i);
        out(i) = q4_gradients(x, y, 0.1, -0.2, bx, by) + qp_gradients<1>(x, y, 0, bx, by) +
                 qp_gradients<4>(x, y, 3, bx, by) + s[0];
      });
  // With the conversion flags and candidates (adaptive scenes).
  const ConversionCriterion criterion{};
  const View<int> pending("fracta::cuda_check_pending");
  const View<int*> candidates("fracta::cuda_check_candidates", 16);
  return compute_fe_forces(nodes, elements, materials, p).dt_min +
         compute_fe_forces(nodes, elements, materials, p, criterion, pending, candidates).plastic;
}

}  // namespace fracta::cuda_check
