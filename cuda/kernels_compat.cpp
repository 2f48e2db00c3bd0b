// CUDA check unit for src/kernels/compat.hpp: every math shim called from a device kernel.
#include "kernels/compat.hpp"

namespace fracta::cuda_check {

void compat_kernels(const View<double*>& out) {
  ProfilingRegion region("fracta::cuda_check");  // host side
  Kokkos::parallel_for(
      "fracta::cuda_check_compat", Kokkos::RangePolicy<ExecSpace>(0, out.extent(0)),
      KOKKOS_LAMBDA(const int i) {
        const double a = out(i);
        double r = sqrt_(fabs_(a)) + min_(a, 1.0) + max_(a, -1.0) + atan2_(a, 2.0) + cos_(a) +
                   sin_(a) + static_cast<double>(min_(i, 3) + max_(i, 2));
        if (!isfinite_(r)) r = 0.0;
        out(i) = r;
      });
}

}  // namespace fracta::cuda_check
