// Dynamic branching in soda-lime glass (Ha & Bobaru 2010, Int. J. Fract. 162;
// cases/validation/ha_bobaru_plate.toml; docs/validation.md, "Glass branching"). Published answer:
// the crack from the pre-crack branches, at 2 MPa in the last third of the plate, running before
// it does at about 1500-1600 m/s, the speed measured in soda-lime glass (Bowden et al. 1967, as
// Ha & Bobaru compare), and never above the Rayleigh speed. The case's lattice is deterministic:
// every bond equally strong. Measured on the crack that src/host/cracks.hpp traces from the
// pre-crack's tip, to the published 43 us. A branch is a lasting one: at least 10 mm (50 cells)
// at the end; side cracks that stop are up to 8.4 mm long (docs/validation.md), so a stopped one
// is not taken for a branch. Asserted:
// - at 2 MPa, a lasting branch;
// - its speed before branching, the mean speed along its path over the 10 us before its tip
//   reaches the junction (a definition fixed before it was measured), within the published band
//   with 10 % on either side (1350 to 1760 m/s; one cell in 10 us is 20 m/s);
// - the fastest 1-us speed up to the junction below the plane-stress Rayleigh speed (a bound;
//   past the junction the traced length follows whichever arm reaches farther, and jumps when
//   that changes);
// - before the reflected waves return: the crack's length and speed within 10 % of Freund's exact
//   crack (CrackRunsAsFreunds..., below; Weibull bond strengths slow it, recorded);
// - with Weibull bond strengths (m = 6) at 4 MPa, a lasting branch in each of seeds 1-3.
// Recorded at 2 MPa: where and when it branches, beside the published model reproduced by
// scripts/pd_branching.py (66.1 mm, 19.6 us with every bond alike). Not tested, and failing: at
// 4 MPa the deterministic lattice sheds side cracks where the published model branches, none of
// which lasts (at 0.1 and 0.05 mm cells it branches); at 0.05 mm cells, where the strength is not
// capped, the 2 MPa plate does not branch, and at 0.1 mm its speed before branching is 1331 m/s,
// 1.4 % below the band: the branch and its speed asserted here are not converged in the cells
// (the published model's branch holds as its horizon halves); with Weibull bond strengths the
// 2 MPa plate branches in only about two realisations of three (docs/validation.md).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "host/case.hpp"
#include "host/cracks.hpp"
#include "host/simulation.hpp"
#include "test_util.hpp"

namespace fracta {
namespace {

constexpr double kEndTime = 43e-6;  // s, Ha & Bobaru's run
// The case's glass (Pa, -, kg/m^3) and its plane-stress Rayleigh speed (3052 m/s).
constexpr double kYoungs = 72e9, kNu = 1.0 / 3.0, kDensity = 2440;
const double kRayleigh = test::plane_stress_rayleigh_speed(kYoungs, kNu, kDensity);

struct CrackSample {
  double time = 0;    // s
  double length = 0;  // m, along the crack from the seed
};

// Length of the path from its start to the point of it nearest `p` (m).
double length_along_path_to(const std::vector<Vec2>& path, Vec2 p) {
  double best = 1e300, along = 0, at_best = 0;
  for (std::size_t i = 0; i < path.size(); ++i) {
    if (i > 0) along += std::hypot(path[i][0] - path[i - 1][0], path[i][1] - path[i - 1][1]);
    const double d = std::hypot(path[i][0] - p[0], path[i][1] - p[1]);
    if (d < best) best = d, at_best = along;
  }
  return at_best;
}

// Crack length at time t (m), linear between samples.
double length_at(const std::vector<CrackSample>& samples, double t) {
  for (std::size_t i = 1; i < samples.size(); ++i)
    if (samples[i].time >= t) {
      const CrackSample &a = samples[i - 1], &b = samples[i];
      return a.length + (b.length - a.length) * (t - a.time) / (b.time - a.time);
    }
  return samples.back().length;
}

// The crack of one run, as the header measures it.
struct GlassRun {
  bool branched = false;
  double length = 0;                  // m, along the crack at the end
  double junction_x = 0;              // m, the first junction along the crack
  double branch_time = 0;             // s, when the tip reached it (the end: no branch)
  double branch_length = 0;           // m, the longest branch at the end
  double speed_before_branching = 0;  // m/s, over the 10 us before branch_time
  double fastest = 0;                 // m/s, over 1 us, up to the junction
};

// The case at `load` to `end_time`; weibull_modulus 0 keeps its bonds alike, m > 0 gives them
// Weibull strengths of realisation `seed`.
Case glass_case(const double load, const double end_time, const double weibull_modulus = 0,
                const std::uint64_t seed = 1) {
  Case c = load_case(std::string(FRACTA_SOURCE_DIR) + "/cases/validation/ha_bobaru_plate.toml");
  EXPECT_NEAR(c.materials[0].poisson_ratio, kNu, 1e-9);
  c.materials[0].weibull_modulus = weibull_modulus;
  c.sim.seed = seed;
  c.sim.end_time = end_time;
  for (Load& l : c.loads) l.value = {load};  // the two edges' tractions, applied suddenly
  return c;
}

const Vec2 kSeedPoint{50e-3, 20.1e-3};  // the pre-crack's tip, on its upper face's cell row

// Runs `sim` to its end time, tracing the crack from the pre-crack's tip every 0.5 us.
std::vector<CrackSample> crack_samples(Simulation& sim, const double h, const double end_time) {
  std::vector<CrackSample> samples{{0, 0}};
  int next_sample = 1;  // in 0.5 us; the last step lands on end_time, a sample time
  while (sim.time() < end_time * (1 - 1e-12) && !sim.failed()) {
    sim.step();
    if (sim.time() < next_sample * 0.5e-6 * (1 - 1e-9)) continue;
    ++next_sample;
    const CrackTrace t = trace_crack(sim, kSeedPoint, 1.5 * h, 10 * h);
    samples.push_back({sim.time(), t.found ? t.length : 0.0});
  }
  EXPECT_FALSE(sim.failed()) << sim.failure();
  return samples;
}

GlassRun run_glass(const double load, const double weibull_modulus = 0,
                   const std::uint64_t seed = 1) {
  const Case c = glass_case(load, kEndTime, weibull_modulus, seed);
  Simulation sim(c);
  GlassRun r;
  const double h = c.bodies[0].cell_size;
  const std::vector<CrackSample> samples = crack_samples(sim, h, kEndTime);
  const CrackTrace t = trace_crack(sim, kSeedPoint, 1.5 * h, 10e-3);
  EXPECT_TRUE(t.found);
  r.length = t.length;
  r.branched = !t.branches.empty();
  r.branch_time = kEndTime;
  // The fastest speed over 1 us (samples two apart), up to the junction: past it the traced
  // length follows whichever arm reaches farther, and jumps when that changes.
  const auto fastest_until = [&](const double until) {
    double v = 0;
    for (std::size_t i = 2; i < samples.size() && samples[i].time <= until * (1 + 1e-9); ++i)
      v = std::max(
          v, (samples[i].length - samples[i - 2].length) / (samples[i].time - samples[i - 2].time));
    return v;
  };
  if (!r.branched) {
    r.fastest = fastest_until(kEndTime);
    return r;
  }
  // The first junction along the crack.
  double junction_length = 1e300;
  for (const CrackBranch& b : t.branches) {
    const double l = length_along_path_to(t.path, b.junction);
    if (l < junction_length) junction_length = l, r.junction_x = b.junction[0];
  }
  r.branch_length = t.branches.front().length;
  // The tip reaches the junction between two samples (the first sample, at samples[0], is 0 long):
  // the time, linear between them as length_at is; the sample after is up to 0.5 us late. The
  // fastest 1-us speed, a bound, is taken up to that later sample.
  std::size_t after = 1;
  while (after + 1 < samples.size() && samples[after].length < junction_length) ++after;
  const CrackSample &a = samples[after - 1], &b = samples[after];
  r.branch_time =
      b.length > a.length && b.length >= junction_length
          ? a.time + (b.time - a.time) * (junction_length - a.length) / (b.length - a.length)
          : b.time;
  r.fastest = fastest_until(b.time);
  const double window = 10e-6;
  if (r.branch_time > window)
    r.speed_before_branching =
        (junction_length - length_at(samples, r.branch_time - window)) / window;
  return r;
}

TEST(GlassBranching, CrackBranchesAt2MPaAtTheSpeedMeasuredInGlass) {
  const GlassRun r = run_glass(2e6);
  RecordProperty("crack_length_mm", std::to_string(r.length * 1e3));
  RecordProperty("fastest_1us_to_junction_m_per_s", std::to_string(r.fastest));
  EXPECT_LT(r.fastest, kRayleigh);
  ASSERT_TRUE(r.branched) << "no branch of 10 mm by 43 us; the crack is " << r.length * 1e3
                          << " mm long";
  // The published model, reproduced (scripts/pd_branching.py): 66.1 mm, reached at 19.6 us.
  RecordProperty("junction_x_mm", std::to_string(r.junction_x * 1e3));
  RecordProperty("branch_time_us", std::to_string(r.branch_time * 1e6));
  RecordProperty("branch_length_mm", std::to_string(r.branch_length * 1e3));
  // Within the published 1500-1600 m/s, 10 % on either side (measured 1381 m/s).
  RecordProperty("speed_before_branching_m_per_s", std::to_string(r.speed_before_branching));
  EXPECT_GT(r.speed_before_branching, 0.9 * 1500);
  EXPECT_LT(r.speed_before_branching, 1.1 * 1600);
}

// With Weibull bond strengths (m = 6, in the range measured for soda-lime glass) the 4 MPa plate
// branches in every realisation tried (seeds 1-8), as the published crack does; the deterministic
// lattice sheds side cracks there that stop (docs/validation.md). Seeds 1-3, to 43 us.
TEST(GlassBranching, WeibullBondsBranchAt4MPaInEveryRealisationBelowTheRayleighSpeed) {
  for (const std::uint64_t seed : {1u, 2u, 3u}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const GlassRun r = run_glass(4e6, 6, seed);
    const std::string tag = "seed" + std::to_string(seed) + "_";
    RecordProperty(tag + "junction_x_mm", std::to_string(r.junction_x * 1e3));
    RecordProperty(tag + "branch_time_us", std::to_string(r.branch_time * 1e6));
    EXPECT_TRUE(r.branched) << "no branch of 10 mm by 43 us; the crack is " << r.length * 1e3
                            << " mm long";
    EXPECT_LT(r.fastest, kRayleigh);
  }
}

// Before the waves the crack scatters come back, the plate is Freund's problem (Freund 1990,
// "Dynamic Fracture Mechanics", 7.4 and 7.5): the edge tractions p send two plane waves that meet
// on the crack's plane at t0 = (H/2)/c, where the uncracked plate then carries 2p, so the
// stationary crack's faces take a suddenly applied pressure 2p along their whole length,
// K*(t) = 2 (2p) sqrt(c (t - t0) (1 - 2 nu') / pi) / (1 - nu'), for any tip position (the
// stress acts ahead of the tip too). Plane stress is plane strain with nu' = nu/(1 + nu) and c the
// plane-stress P-wave speed sqrt(E / (rho (1 - nu^2))); G* = K*^2 / E. The running crack obeys the
// equation of motion G_c = g(v) G*(t), g ~ 1 - v/c_R, so v = c_R (1 - tau_i / tau) from
// tau_i = t_i - t0, where G* reaches G_c, and the length is
//   l(t) = c_R ((tau - tau_i) - tau_i ln(tau / tau_i)),   tau = t - t0.
// It holds until the crack's own waves return from the loaded edges, 2 H/2 / c after it starts,
// and the first waves reflected there reach the crack, at 3 t0 = 10.4 us. Returns l (m) at t (s).
double freund_crack_length(const double t, const double load) {
  const double E = kYoungs, gc = 3.8, half_height = 20e-3;
  const double nu_p = kNu / (1 + kNu), c = std::sqrt(E / (kDensity * (1 - kNu * kNu)));
  const double t0 = half_height / c, sigma = 2 * load;
  // G*(tau) = 4 sigma^2 c tau (1 - 2 nu') / (pi (1 - nu')^2 E) = G_c at tau_i:
  const double tau_i =
      M_PI * E * gc * (1 - nu_p) * (1 - nu_p) / (4 * sigma * sigma * c * (1 - 2 * nu_p));
  const double tau = t - t0;
  return tau <= tau_i ? 0.0 : kRayleigh * ((tau - tau_i) - tau_i * std::log(tau / tau_i));
}

// The case's lattice (every bond equally strong) runs as LEFM says: at 2 MPa the crack's length at
// 10 us, and its mean speed over 8-10 us, within 10 % of Freund's (4.62 mm, 1.59 km/s; the first
// bond breaks at about 6.5 us, 0.4 us after Freund's start, t_i = 6.09 us, as the cohesive zone
// takes to open: CrackGrowth). Measured at 0.2 mm cells: 4.70 mm and 1.60 km/s; at 0.1 mm cells
// 4.46 mm and 1.60 km/s. Answer: exact
// (Freund's solution; g(v) ~ 1 - v/c_R is within a few per cent of his exact function). Weibull
// bond strengths (m = 6) slow the crack: seed 1 is recorded, 1.95 mm at 10 us (seeds 2 and 3:
// 3.03, 2.47 mm); so does any scatter of the bonds wider than a few per cent (docs/validation.md,
// "Before the reflected waves return").
TEST(GlassBranching, CrackRunsAsFreundsEquationOfMotionSaysBeforeWavesReturn) {
  constexpr double kLoad = 2e6, kEnd = 10e-6;
  const auto run = [&](const double weibull_modulus) {
    const Case c = glass_case(kLoad, kEnd, weibull_modulus);
    Simulation sim(c);
    return crack_samples(sim, c.bodies[0].cell_size, kEnd);
  };
  const std::vector<CrackSample> equal = run(0);  // the case
  const double freund_10 = freund_crack_length(10e-6, kLoad);
  const double freund_speed = (freund_10 - freund_crack_length(8e-6, kLoad)) / 2e-6;
  EXPECT_NEAR(freund_10, 4.62e-3, 0.01e-3);  // the formula, as the header quotes it
  const double length_10 = length_at(equal, 10e-6);
  const double speed = (length_10 - length_at(equal, 8e-6)) / 2e-6;
  RecordProperty("freund_length_10us_mm", std::to_string(freund_10 * 1e3));
  RecordProperty("freund_speed_8_10us_m_per_s", std::to_string(freund_speed));
  RecordProperty("length_10us_mm", std::to_string(length_10 * 1e3));
  RecordProperty("speed_8_10us_m_per_s", std::to_string(speed));
  EXPECT_NEAR(length_10, freund_10, 0.10 * freund_10);
  EXPECT_NEAR(speed, freund_speed, 0.10 * freund_speed);
  const std::vector<CrackSample> weibull = run(6);  // heterogeneous bonds, seed 1: recorded
  RecordProperty("weibull_m6_seed1_length_10us_mm",
                 std::to_string(length_at(weibull, 10e-6) * 1e3));
}

}  // namespace
}  // namespace fracta
