// Throughput of the bond phase of the disc lattice (cell stress for failure + bond forces with
// shear, rotation and failure checks) on square lattices of about 10^4, 10^5 and 10^6 discs,
// in bond-steps per second (active bonds x steps / s). Run with OMP_NUM_THREADS=1 and =2
// (bench/run_threads.sh does both). BM_BondPhaseFullCheck does every bond's failure check (no
// cell marked below its strength); BM_CellStress and BM_BondForces time the two kernels alone.
#include <benchmark/benchmark.h>

#include "bench_main.hpp"

#include <Kokkos_Core.hpp>
#include <chrono>
#include <cmath>

#include "host/simulation.hpp"
#include "test_util.hpp"

namespace {

// Which part of the phase a benchmark times.
enum class BondPart { phase, cell_stress, bond_forces };

// bound_faces: whether the cell kernel may mark cells below their strength on every face (the
// bond kernel then skips their failure check: kCellBelowStrength); false times the full check of
// every bond, the case of a lattice loaded near its strength.
// weibull_modulus > 0: Weibull bond strengths (kernels/heterogeneity.hpp); rate: a
// rate_dependence table (RateLaw, with the velocity filter of every step). The *Weibull and
// *Rate benchmarks give their cost beside the uniform, rate-independent ones.
void bond_part(benchmark::State& state, BondPart part, bool bound_faces = true,
               double weibull_modulus = 0, bool rate = false) {
  using namespace fracta;
  const int n = static_cast<int>(std::lround(std::sqrt(static_cast<double>(state.range(0))))) - 1;
  const double h = 1e-3;
  Case c = test::rectangle_case(n, n, h, 92e9, 0.21, 2400.0, Formulation::plane_stress);
  c.bodies[0].method = BodyMethod::de;
  c.materials[0].model = MaterialModel::mohr_coulomb;
  c.materials[0].cohesion = 1e12;  // strong: no bond breaks, every bond works every step
  c.materials[0].friction_angle = 0.5;
  c.materials[0].tensile_strength = 1e12;
  c.materials[0].weibull_modulus = weibull_modulus;
  if (rate) c.materials[0].rate_dependence = {{1e-2, 1e2, 1e4}, {1.0, 1.5, 4.0}, {1.0, 1.0, 1.0}};
  c.sim.end_time = 1.0;
  test::add_pressure(c, test::segment(0, 0, 0, n * h), {0.0}, {100e6});
  Simulation sim(c);
  for (int i = 0; i < 20; ++i) sim.step();  // a strained, moving lattice
  Model& m = sim.model();
  const double dt = sim.dt();
  for (auto _ : state) {
    Kokkos::fence();
    const auto t0 = std::chrono::steady_clock::now();
    if (part == BondPart::phase) filter_velocities(m.nodes);
    if (part != BondPart::bond_forces)
      compute_cell_stress(m.converted, m.converted_count, m.lattice_stiffness, m.bond_laws,
                          m.elements, m.nodes, bound_faces);
    if (part != BondPart::cell_stress)
      compute_bond_forces(m.nodes, m.elements, m.bonds, m.bond_laws, dt);
    Kokkos::fence();
    state.SetIterationTime(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  state.counters["discs"] = m.nodes.count;
  state.counters["bonds"] = m.bonds.count;
  // Per bond for every part, so the parts' times add up as the inverses of their rates.
  state.counters["items_per_s"] = benchmark::Counter(
      static_cast<double>(m.bonds.count) * state.iterations(), benchmark::Counter::kIsRate);
  state.SetLabel("bond-steps/s");
}

// The whole phase (the target's figure), the same with every bond's failure check done, then
// the phase's two kernels alone.
void BM_BondPhase(benchmark::State& state) {
  bond_part(state, BondPart::phase);
}
void BM_BondPhaseFullCheck(benchmark::State& state) {
  bond_part(state, BondPart::phase, false);
}
// The same two with Weibull strengths (m = 6): the cost of heterogeneity.
void BM_BondPhaseWeibull(benchmark::State& state) {
  bond_part(state, BondPart::phase, true, 6.0);
}
void BM_BondPhaseFullCheckWeibull(benchmark::State& state) {
  bond_part(state, BondPart::phase, false, 6.0);
}
void BM_BondPhaseRate(benchmark::State& state) {
  bond_part(state, BondPart::phase, true, 0.0, true);
}
void BM_BondPhaseFullCheckRate(benchmark::State& state) {
  bond_part(state, BondPart::phase, false, 0.0, true);
}
void BM_CellStress(benchmark::State& state) {
  bond_part(state, BondPart::cell_stress);
}
void BM_BondForces(benchmark::State& state) {
  bond_part(state, BondPart::bond_forces);
}

// Manual time (the phase only, fenced), in ms, with the lattice size named.
void timed_discs(benchmark::internal::Benchmark* b) {
  b->ArgName("discs")->UseManualTime()->Unit(benchmark::kMillisecond);
}

BENCHMARK(BM_BondPhase)->Arg(10000)->Arg(100000)->Arg(1000000)->Apply(timed_discs);
BENCHMARK(BM_BondPhaseFullCheck)->Arg(1000000)->Apply(timed_discs);
BENCHMARK(BM_BondPhaseWeibull)->Arg(1000000)->Apply(timed_discs);
BENCHMARK(BM_BondPhaseFullCheckWeibull)->Arg(1000000)->Apply(timed_discs);
BENCHMARK(BM_BondPhaseRate)->Arg(1000000)->Apply(timed_discs);
BENCHMARK(BM_BondPhaseFullCheckRate)->Arg(1000000)->Apply(timed_discs);
BENCHMARK(BM_CellStress)->Arg(1000000)->Apply(timed_discs);
BENCHMARK(BM_BondForces)->Arg(1000000)->Apply(timed_discs);

}  // namespace

int main(int argc, char** argv) {
  return fracta::bench::run_benchmarks(argc, argv, [] {});
}
