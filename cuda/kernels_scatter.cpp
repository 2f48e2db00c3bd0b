// CUDA check unit for src/kernels/scatter.hpp: the plan builder (a no-op with atomic scatter,
// but its kernel must compile), the chunk runner and the atomic add.
#include "kernels/scatter.hpp"

namespace fracta::cuda_check {

namespace {
struct ChunkSum {
  View<double*> values;
  KOKKOS_INLINE_FUNCTION void chunk(const int begin, const int end, double& sum) const {
    for (int k = begin; k < end; ++k) scatter_add(&values(k), 1.0, true), sum += values(k);
  }
};
}  // namespace

double scatter_kernels(const View<int* [2]>& ends, const View<double*>& values) {
  ScatterPlan plan;
  build_scatter_plan(
      plan, static_cast<int>(ends.extent(0)),
      KOKKOS_LAMBDA(const int k, int& lo, int& hi) {
        lo = ends(k, 0) < ends(k, 1) ? ends(k, 0) : ends(k, 1);
        hi = ends(k, 0) < ends(k, 1) ? ends(k, 1) : ends(k, 0);
      },
      View<int*>(), static_cast<int>(ends.extent(0)));
  locate_scatter_chunks(plan, View<int*>(), static_cast<int>(ends.extent(0)));
  return for_each_chunk<Kokkos::Sum<double>>("fracta::cuda_check_chunks", plan, ChunkSum{values}) +
         (plan.usable(static_cast<int>(ends.extent(0))) ? 1.0 : 0.0);
}

}  // namespace fracta::cuda_check
