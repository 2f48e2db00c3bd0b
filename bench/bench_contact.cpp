// Contact throughput (pre-search + forces) on square packings, and the analogue of the paper's
// Fig. 8: time per 1000 steps against the number of discs for the all-pairs "traversal" versus
// the binned pre-search.
//
// Scene: n discs (radius 0.5 mm) on a square lattice of spacing 2r, jittered by up to 5% of r,
// with random velocities of up to 0.5 m/s, so discs collide, lists go stale and are rebuilt.
// The same 100-step window of this motion is replayed (the state is restored outside the
// timing), so all runs time the same work.
// A step is: kick_drift, ContactSystem::update, compute_forces, kick (integrate.hpp).
//   BM_ContactStep/discs:N              skin 0.1 r, binned: disc-steps/s (search + force)
//   BM_Fig8/discs:N/mode:M              M = 0: all-pairs traversal every step (skin 0: the
//                                       candidate list is rebuilt by the O(N^2) builder each
//                                       step, as the paper's traversal checks every pair);
//                                       M = 1: binned search every step (skin 0);
//                                       M = 2: binned search + Verlet skin 0.1 r.
// The Fig. 8 time is reported as ms_per_1000_steps = (measured time per step) x 1000; the
// all-pairs sizes stop at 2 x 10^4 discs (about 0.5 s per step there).
// Run with OMP_NUM_THREADS=1 and =2: bench/run_contact_bench.sh prints both tables.
#include <benchmark/benchmark.h>

#include "bench_main.hpp"

#include <Kokkos_Core.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <string>

#include "host/contact.hpp"
#include "kernels/contact_test_util.hpp"  // discs built in code, shared with the tests
#include "kernels/integrate.hpp"

namespace {

using namespace fracta;

constexpr double kR = 0.5e-3, kMass = 1e-3, kStiffness = 1e6;

Nodes packing(long discs) {
  const int side = static_cast<int>(std::lround(std::sqrt(static_cast<double>(discs))));
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  test::HostDiscs h;
  for (int j = 0; j < side; ++j)
    for (int i = 0; i < side; ++i)
      h.add(2 * kR * i + 0.05 * kR * u(rng), 2 * kR * j + 0.05 * kR * u(rng), kR, kMass, kStiffness,
            0.5 * u(rng), 0.5 * u(rng));
  return test::make_nodes(h);
}

// dt = 0.1 sqrt(m_eff / k): 60 steps per contact period of a pair.
const double kDt = 0.1 * std::sqrt(0.5 * kMass / kStiffness);

struct Result {
  double seconds = 0;
  long steps = 0, rebuilds = 0, candidates = 0, touching = 0;
};

template <class State>
void run(State& state, long discs, bool all_pairs, double skin, const char* label) {
  const Nodes nodes = packing(discs);
  std::vector<int> ids(nodes.count);
  for (int i = 0; i < nodes.count; ++i) ids[i] = i;
  ContactSystem contact(ids, ContactParams{0.5, 0.1, 0.3}, skin);
  contact.set_all_pairs(all_pairs);
  contact.update(nodes);
  contact.compute_forces(nodes, kDt);
  const auto step = [&] {
    kick_drift(nodes, kDt);
    Kokkos::deep_copy(nodes.moment, 0.0);
    contact.update(nodes);
    const ContactStepResult r = contact.compute_forces(nodes, kDt);
    kick(nodes, kDt);
    return r;
  };
  // The scene is not stationary (overlapping discs repel, discs fly apart): every
  // kResetSteps steps the initial state is restored, outside the timed region, so every
  // benchmark (whatever its iteration count) times the same window of the same motion.
  const View<double* [2]> x_start("fracta::bench_x_start", nodes.count);
  const View<double* [2]> v_start("fracta::bench_v_start", nodes.count);
  Kokkos::deep_copy(x_start, nodes.x);
  Kokkos::deep_copy(v_start, nodes.v);
  const auto reset = [&] {
    Kokkos::deep_copy(nodes.x, x_start);
    Kokkos::deep_copy(nodes.v, v_start);
    Kokkos::deep_copy(nodes.f, 0.0);
    Kokkos::deep_copy(nodes.moment, 0.0);
    contact.update(nodes);
    contact.compute_forces(nodes, kDt);
  };
  constexpr int kResetSteps = 100;
  for (int i = 0; i < 3; ++i) step();  // warm-up
  reset();
  long rebuilds = 0, touching = 0;
  int since_reset = 0;
  for (auto _ : state) {
    if (since_reset == kResetSteps) {
      reset();
      since_reset = 0;
    }
    ++since_reset;
    const long rebuilds0 = contact.rebuild_count();
    Kokkos::fence();
    const auto t0 = std::chrono::steady_clock::now();
    touching = step().touching;
    Kokkos::fence();
    state.SetIterationTime(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    rebuilds += contact.rebuild_count() - rebuilds0;
  }
  const double n = static_cast<double>(nodes.count);
  state.counters["discs"] = n;
  state.counters["disc_steps_per_s"] =
      benchmark::Counter(n * state.iterations(), benchmark::Counter::kIsRate);
  state.counters["items_per_s"] =  // for bench/run_threads.sh (items = disc-steps)
      benchmark::Counter(n * state.iterations(), benchmark::Counter::kIsRate);
  // (time / iterations) x 1000 steps, in ms.
  state.counters["ms_per_1000_steps"] = benchmark::Counter(
      1e-6 * state.iterations(), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["rebuilds_per_step"] = static_cast<double>(rebuilds) / state.iterations();
  state.counters["candidates"] = static_cast<double>(contact.candidate_count());
  state.counters["touching"] = static_cast<double>(touching);
  state.counters["threads"] = ExecSpace().concurrency();
  state.SetLabel(label);
}

// Binned runs time exactly one replay window (kResetSteps = 100 steps) so their rebuilds
// per step are those of the window; all-pairs runs are dominated by the O(N^2) build done every
// step, and time fewer steps at large N (at least 3).
void register_benchmarks() {
  for (long n : {10000L, 100000L, 1000000L})
    benchmark::RegisterBenchmark(
        ("BM_ContactStep/discs:" + std::to_string(n)).c_str(),
        [n](benchmark::State& st) { run(st, n, false, 0.1 * kR, "binned+skin"); })
        ->Iterations(100)
        ->UseManualTime()
        ->Unit(benchmark::kMillisecond);
  const char* labels[3] = {"all-pairs", "binned", "binned+skin"};
  for (long n : {1000L, 2000L, 5000L, 10000L, 20000L, 50000L, 100000L})
    for (int mode : {0, 1, 2}) {
      if (mode == 0 && n > 20000) continue;
      const long iterations =
          mode == 0 ? std::max(3L, std::min(100L, static_cast<long>(1e9 / (double(n) * n)))) : 100;
      const char* label = labels[mode];
      benchmark::RegisterBenchmark(
          ("BM_Fig8/discs:" + std::to_string(n) + "/mode:" + std::to_string(mode)).c_str(),
          [n, mode, label](benchmark::State& st) {
            run(st, n, mode == 0, mode == 2 ? 0.1 * kR : 0.0, label);
          })
          ->Iterations(iterations)
          ->UseManualTime()
          ->Unit(benchmark::kMillisecond);
    }
}

}  // namespace

int main(int argc, char** argv) {
  return fracta::bench::run_benchmarks(argc, argv, register_benchmarks);
}
