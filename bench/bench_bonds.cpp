// Throughput of the bond phase of the disc lattice (cell stress for failure + bond forces with
// shear, rotation and failure checks) on square lattices of about 10^4, 10^5 and 10^6 discs,
// in bond-steps per second (active bonds x steps / s). Run with OMP_NUM_THREADS=1 and =2
// (bench/run_threads.sh does both).
#include <benchmark/benchmark.h>

#include "bench_main.hpp"

#include <Kokkos_Core.hpp>
#include <chrono>
#include <cmath>

#include "host/simulation.hpp"
#include "test_util.hpp"

namespace {

void BM_BondPhase(benchmark::State& state) {
  using namespace fracta;
  const int n = static_cast<int>(std::lround(std::sqrt(static_cast<double>(state.range(0))))) - 1;
  const double h = 1e-3;
  Case c = test::rectangle_case(n, n, h, 92e9, 0.21, 2400.0, Formulation::plane_stress);
  c.bodies[0].method = BodyMethod::de;
  c.materials[0].model = MaterialModel::mohr_coulomb;
  c.materials[0].cohesion = 1e12;  // strong: no bond breaks, every bond works every step
  c.materials[0].friction_angle = 0.5;
  c.materials[0].tensile_strength = 1e12;
  c.sim.end_time = 1.0;
  test::add_pressure(c, test::segment(0, 0, 0, n * h), {0.0}, {100e6});
  Simulation sim(c);
  for (int i = 0; i < 20; ++i) sim.step();  // a strained, moving lattice
  Model& m = sim.model();
  const double dt = sim.dt();
  for (auto _ : state) {
    Kokkos::fence();
    const auto t0 = std::chrono::steady_clock::now();
    compute_cell_stress(m.converted, m.converted_count, m.element_bonds, m.lattice_stiffness,
                        m.elements, m.nodes, m.bonds);
    compute_bond_forces(m.nodes, m.elements, m.bonds, m.bond_laws, dt);
    Kokkos::fence();
    state.SetIterationTime(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  state.counters["discs"] = m.nodes.count;
  state.counters["bonds"] = m.bonds.count;
  state.counters["items_per_s"] = benchmark::Counter(
      static_cast<double>(m.bonds.count) * state.iterations(), benchmark::Counter::kIsRate);
  state.SetLabel("bond-steps/s");
}

BENCHMARK(BM_BondPhase)
    ->Arg(10000)
    ->Arg(100000)
    ->Arg(1000000)
    ->ArgName("discs")
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  return fracta::bench::run_benchmarks(argc, argv, [] {});
}
