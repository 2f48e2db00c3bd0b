// CUDA check unit for src/kernels/simd.hpp: on a GPU build the lane type is double (one element
// per thread), and the lane helpers must be callable from device code.
#include "kernels/simd.hpp"

namespace fracta::cuda_check {

static_assert(kLanes == 1 && kNativeLanes == 1, "a GPU build runs one element per thread");

void simd_kernels(const View<double*>& out) {
  ProfilingRegion region("fracta::cuda_check");  // host side
  Kokkos::parallel_for(
      "fracta::cuda_check_simd", Kokkos::RangePolicy<ExecSpace>(0, out.extent(0)),
      KOKKOS_LAMBDA(const int i) {
        NativeDouble v = splat<NativeDouble>(out(i));
        set_lane(v, 0, get_lane(v, 0) + 1.0);
        const bool positive = v > 0.0;
        out(i) = any_lane(positive) && get_lane(positive, 0) ? sqrt_(v) : 0.0;
      });
}

}  // namespace fracta::cuda_check
