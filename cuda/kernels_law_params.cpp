// CUDA check unit for src/kernels/law_params.hpp: plain data, copied by value into a device
// kernel (the hjc law itself is checked with materials.hpp).
#include "kernels/compat.hpp"
#include "kernels/law_params.hpp"

namespace fracta::cuda_check {

void hjc_params_kernels(const View<double*>& out) {
  HjcParams h;
  h.fc = 48e6;
  h.p_crush = 16e6;
  h.mu_crush = 1e-3;
  Kokkos::parallel_for(
      "fracta::cuda_check_hjc_params", Kokkos::RangePolicy<ExecSpace>(0, out.extent(0)),
      KOKKOS_LAMBDA(const int i) { out(i) = h.fc + h.p_crush / h.mu_crush + i; });
}

}  // namespace fracta::cuda_check
