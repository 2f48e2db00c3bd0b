// Dynamic branching in soda-lime glass (Ha & Bobaru 2010, Int. J. Fract. 162;
// cases/validation/ha_bobaru_plate.toml; docs/validation.md, "Glass branching"). Published answer:
// at 2 MPa the crack from the pre-crack branches, running before it does at about 1500-1600 m/s,
// the speed measured in soda-lime glass (Bowden et al. 1967, as Ha & Bobaru compare), and never
// above the Rayleigh speed. Measured on the crack that src/host/cracks.hpp traces from the
// pre-crack's tip, for three realisations of the Weibull bond strengths, to the published 43 us:
// - a lasting branch: one of at least 10 mm (50 cells) at the end; the side cracks that stop are
//   up to 8.4 mm long (docs/validation.md), so a stopped one is not taken for a branch;
// - the fastest 1-us speed below the plane-stress Rayleigh speed (a bound);
// - the speed before branching, recorded, not asserted: the crack's mean speed along its path
//   over the 10 us before its tip reaches the junction, against the published band with 10 % on
//   either side (1350 to 1760 m/s; one cell in 10 us is 20 m/s). Defined before it was measured,
//   it meets that band in seeds 1 and 2 (1461, 1398 m/s) but not in seed 3 (1250 m/s: that
//   crack branches at 21.5 us, so its window holds the slowdown while the loaded edges' waves
//   pass), and the 1-us peaks reach 2.05-2.14 km/s: the part of the benchmark that fails
//   (docs/validation.md).
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

TEST(GlassBranching, CrackBranchesBelowTheRayleighSpeedInEveryRealisation) {
  const double end_time = 43e-6;                                              // Ha & Bobaru's run
  const double nu = 1.0 / 3.0;                                                // the case's glass
  const double rayleigh = test::plane_stress_rayleigh_speed(72e9, nu, 2440);  // 3052 m/s
  for (const std::uint64_t seed : {1u, 2u, 3u}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    Case c = load_case(std::string(FRACTA_SOURCE_DIR) + "/cases/validation/ha_bobaru_plate.toml");
    ASSERT_NEAR(c.materials[0].poisson_ratio, nu, 1e-9);
    c.sim.seed = seed;
    c.sim.end_time = end_time;
    Simulation sim(c);
    const Vec2 seed_point{50e-3, 20.1e-3};  // the pre-crack's tip, on its upper face's cell row
    const double h = c.bodies[0].cell_size, link = 1.5 * h;
    std::vector<CrackSample> samples{{0, 0}};
    double fastest = 0, next_sample = 0.5e-6;
    while (sim.time() < end_time * (1 - 1e-12) && !sim.failed()) {
      sim.step();
      if (sim.time() < next_sample) continue;
      next_sample += 0.5e-6;
      const CrackTrace t = trace_crack(sim, seed_point, link, 10 * h);
      samples.push_back({sim.time(), t.found ? t.length : 0.0});
      // Speed over the last microsecond (two samples back).
      if (samples.size() > 2) {
        const CrackSample &a = samples[samples.size() - 3], &b = samples.back();
        fastest = std::max(fastest, (b.length - a.length) / (b.time - a.time));
      }
    }
    ASSERT_FALSE(sim.failed()) << sim.failure();
    const CrackTrace t = trace_crack(sim, seed_point, link, 10e-3);
    ASSERT_TRUE(t.found);
    ASSERT_FALSE(t.branches.empty())
        << "no branch of 10 mm by 43 us; the crack is " << t.length * 1e3 << " mm long";
    // The first junction along the crack.
    double junction_length = 1e300;
    Vec2 junction{0, 0};
    for (const CrackBranch& b : t.branches) {
      const double l = length_along_path_to(t.path, b.junction);
      if (l < junction_length) junction_length = l, junction = b.junction;
    }
    double branch_time = end_time;
    for (const CrackSample& s : samples)
      if (s.length >= junction_length) {
        branch_time = s.time;
        break;
      }
    const double window = 10e-6;
    ASSERT_GT(branch_time - window, 0);
    const double speed_before_branching =
        (junction_length - length_at(samples, branch_time - window)) / window;
    EXPECT_LT(fastest, rayleigh);
    const std::string tag = "seed" + std::to_string(seed) + "_";
    ::testing::Test::RecordProperty(tag + "junction_x_mm", std::to_string(junction[0] * 1e3));
    ::testing::Test::RecordProperty(tag + "branch_time_us", std::to_string(branch_time * 1e6));
    ::testing::Test::RecordProperty(tag + "branch_length_mm",
                                    std::to_string(t.branches.front().length * 1e3));
    ::testing::Test::RecordProperty(tag + "speed_before_branching_m_per_s",
                                    std::to_string(speed_before_branching));
    ::testing::Test::RecordProperty(tag + "fastest_1us_m_per_s", std::to_string(fastest));
    // Within the published 1500-1600 m/s, 10 % on either side? (reported: see above)
    ::testing::Test::RecordProperty(
        tag + "speed_in_published_band",
        speed_before_branching > 1350 && speed_before_branching < 1760 ? "yes" : "no");
  }
}

}  // namespace
}  // namespace fracta
