// Throughput of one explicit FE step (element forces + integration) on square blocks of
// 10^4, 10^5 and 10^6 elements, elastic and bilinear_j2, in element-steps per second.
// Run with OMP_NUM_THREADS=1 and =2 (bench/run_fe_bench.sh does both and prints the ratio).
#include <benchmark/benchmark.h>

#include <Kokkos_Core.hpp>
#include <cmath>
#include <memory>

#include "host/simulation.hpp"

namespace {

fracta::Case block_case(long elements, bool plastic) {
  using namespace fracta;
  const int n = static_cast<int>(std::lround(std::sqrt(static_cast<double>(elements))));
  const double h = 1e-3;
  Case c;
  c.path = "<bench>";
  c.sim.formulation = Formulation::plane_strain;
  c.sim.end_time = 1.0;  // never reached: the benchmark decides the number of steps
  Material m;
  m.name = "steel";
  m.model = plastic ? MaterialModel::bilinear_j2 : MaterialModel::elastic;
  m.density = 7800;
  m.youngs_modulus = 232e9;
  m.poisson_ratio = 0.3;
  m.yield_stress = 235e6;
  m.plastic_modulus = 1.879e9;
  c.materials.push_back(m);
  Body b;
  b.name = "block";
  b.material = "steel";
  b.material_index = 0;
  b.cell_size = h;
  b.shape.width = n * h;
  b.shape.height = n * h;
  // A velocity gradient strong enough to drive the plastic model into yield within steps.
  b.initial_velocity = {0, 0};
  c.bodies.push_back(b);
  Load l;
  l.type = Load::Type::pressure;
  l.body = "block";
  l.body_index = 0;
  l.where.segment.from = {0, 0};
  l.where.segment.to = {0, n * h};
  l.time = {0.0};
  l.value = {2e9};
  c.loads.push_back(l);
  return c;
}

void BM_FeStep(benchmark::State& state) {
  const long elements = state.range(0);
  const bool plastic = state.range(1) != 0;
  fracta::Simulation sim(block_case(elements, plastic));
  for (int i = 0; i < 5; ++i) sim.step();  // warm-up
  for (auto _ : state) {
    Kokkos::fence();
    const auto t0 = std::chrono::steady_clock::now();
    sim.step();
    Kokkos::fence();
    state.SetIterationTime(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  const double n = static_cast<double>(sim.model().elements.active_count);
  state.counters["elements"] = n;
  state.counters["element_steps_per_s"] =
      benchmark::Counter(n * state.iterations(), benchmark::Counter::kIsRate);
  state.counters["threads"] = fracta::ExecSpace().concurrency();
  state.SetLabel(plastic ? "bilinear_j2" : "elastic");
}

BENCHMARK(BM_FeStep)
    ->ArgsProduct({{10000, 100000, 1000000}, {0, 1}})
    ->ArgNames({"elements", "plastic"})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  setenv("OMP_PROC_BIND", "spread", 0);
  setenv("OMP_PLACES", "threads", 0);
  Kokkos::ScopeGuard kokkos(argc, argv);
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
