// CUDA check unit for src/kernels/state.hpp: the device helpers of the state structs
// (Topology::joined, table_value) and the Sums<N> reduction type.
#include "kernels/state.hpp"

namespace fracta::cuda_check {

double state_kernels(const Topology& topo, const LoadTables& tables, int pairs) {
  Sums<2> s;
  Kokkos::parallel_reduce(
      "fracta::cuda_check_state", Kokkos::RangePolicy<ExecSpace>(0, pairs),
      KOKKOS_LAMBDA(const int i, Sums<2>& acc) {
        acc.v[0] += topo.joined(i, i + 1) ? 1.0 : 0.0;
        acc.v[1] += tables.count > 0 ? table_value(tables, 0, 1e-6 * i) : 0.0;
      },
      Kokkos::Sum<Sums<2>>(s));
  return s.v[0] + s.v[1];
}

}  // namespace fracta::cuda_check
