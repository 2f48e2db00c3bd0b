// The main() every benchmark program shares: Kokkos initialised around Google Benchmark, with
// the OpenMP binding set (Kokkos 3.4 warns on stdout otherwise).
#pragma once
#include <benchmark/benchmark.h>

#include <Kokkos_Core.hpp>
#include <cstdlib>

namespace fracta::bench {

template <class Register>
int run_benchmarks(int argc, char** argv, Register register_benchmarks) {
  setenv("OMP_PROC_BIND", "spread", 0);
  setenv("OMP_PLACES", "threads", 0);
  Kokkos::ScopeGuard kokkos(argc, argv);
  register_benchmarks();
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

}  // namespace fracta::bench
