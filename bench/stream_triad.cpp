// The memory-bandwidth roofline of this machine for docs/performance.md: a STREAM-like triad
// a = b + 3 c over 5e7 doubles (1.2 GB, far beyond the caches) with Kokkos, best of 10 passes,
// counting 24 B per element (two loads, one store; the store's write-allocate not counted, as
// in STREAM). Run with OMP_NUM_THREADS=1 and =2.
#include <Kokkos_Core.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>

int main(int argc, char** argv) {
  Kokkos::initialize(argc, argv);
  {
    const long n = 50000000;
    Kokkos::View<double*> a("a", n), b("b", n), c("c", n);
    Kokkos::deep_copy(b, 1.0);
    Kokkos::deep_copy(c, 2.0);
    double best = 1e30;
    for (int pass = 0; pass < 10; ++pass) {
      Kokkos::fence();
      const auto t0 = std::chrono::steady_clock::now();
      Kokkos::parallel_for(
          "stream_triad", Kokkos::RangePolicy<>(0, n),
          KOKKOS_LAMBDA(const long i) { a(i) = b(i) + 3.0 * c(i); });
      Kokkos::fence();
      best = std::min(best,
                      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }
    std::printf("stream triad: %d threads, %.1f GB/s (best of 10 passes over %ld doubles)\n",
                Kokkos::DefaultExecutionSpace().concurrency(), 24.0 * n / best / 1e9, n);
  }
  Kokkos::finalize();
  return 0;
}
