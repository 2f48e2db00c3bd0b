// Throughput of one explicit FE step (element forces + integration) on square blocks of
// 10^4, 10^5 and 10^6 elements, elastic and bilinear_j2, in element-steps per second; and the
// same blocks axisymmetric (BM_FeStepAxisymmetric, 10^5 and 10^6: the hoop terms' cost).
// Run with OMP_NUM_THREADS=1 and =2 (bench/run_threads.sh bench_fe does both).
#include <benchmark/benchmark.h>

#include "bench_main.hpp"

#include <Kokkos_Core.hpp>
#include <cmath>
#include <memory>

#include "host/simulation.hpp"
#include "test_util.hpp"  // scenes built in code, shared with the tests

namespace {

// A square steel block of about `elements` cells, pushed by 2 GPa on its left edge (enough to
// drive bilinear_j2 into yield near the edge within the warm-up).
// Axisymmetric: the block is the section of a cylinder (x = radius from the axis), pushed on
// its top instead (an edge on the axis carries no ring load).
fracta::Case block_case(long elements, bool plastic, bool axisymmetric = false) {
  using namespace fracta;
  const int n = static_cast<int>(std::lround(std::sqrt(static_cast<double>(elements))));
  const double h = 1e-3;
  Case c =
      test::rectangle_case(n, n, h, 232e9, 0.3, 7800.0,
                           axisymmetric ? Formulation::axisymmetric : Formulation::plane_strain);
  c.sim.end_time = 1.0;  // never reached: the benchmark decides the number of steps
  if (plastic) {
    c.materials[0].model = MaterialModel::bilinear_j2;
    c.materials[0].yield_stress = 235e6;
    c.materials[0].plastic_modulus = 1.879e9;
  }
  if (axisymmetric)
    test::add_pressure(c, test::segment(0, n * h, n * h, n * h), {0.0}, {2e9});
  else
    test::add_pressure(c, test::segment(0, 0, 0, n * h), {0.0}, {2e9});
  return c;
}

void fe_step(benchmark::State& state, bool axisymmetric) {
  const long elements = state.range(0);
  const bool plastic = state.range(1) != 0;
  fracta::Simulation sim(block_case(elements, plastic, axisymmetric));
  for (int i = 0; i < 5; ++i) sim.step();  // warm-up
  for (auto _ : state) {
    Kokkos::fence();
    const auto t0 = std::chrono::steady_clock::now();
    sim.step(/*defer_kick=*/true);  // as run_case: kicks fused between steps without output
    Kokkos::fence();
    state.SetIterationTime(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  const double n = static_cast<double>(sim.model().elements.active_count);
  state.counters["elements"] = n;
  state.counters["items_per_s"] =
      benchmark::Counter(n * state.iterations(), benchmark::Counter::kIsRate);
  state.counters["threads"] = fracta::ExecSpace().concurrency();
  state.SetLabel(plastic ? "bilinear_j2 element-steps/s" : "elastic element-steps/s");
}

void BM_FeStep(benchmark::State& state) {
  fe_step(state, false);
}
void BM_FeStepAxisymmetric(benchmark::State& state) {
  fe_step(state, true);
}

BENCHMARK(BM_FeStep)
    ->ArgsProduct({{10000, 100000, 1000000}, {0, 1}})
    ->ArgNames({"elements", "plastic"})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);

BENCHMARK(BM_FeStepAxisymmetric)
    ->ArgsProduct({{100000, 1000000}, {0, 1}})
    ->ArgNames({"elements", "plastic"})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  return fracta::bench::run_benchmarks(argc, argv, [] {});
}
