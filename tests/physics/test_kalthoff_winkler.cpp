// Kalthoff-Winkler edge-on impact (cases/validation/kalthoff_winkler.toml; docs/validation.md):
// published answer (Kalthoff & Winkler 1987; Kalthoff 2000): the crack leaves the notch tip at
// about 70 degrees to the notch line, away from the struck region. Measured on the crack that
// src/host/cracks.hpp traces from the notch tip: the direction of the line through the tip
// fitted (least squares) to the crack's path from 5 to 25 mm from the tip. Tolerance 5 degrees
// (the required one; measured 69.5 degrees; a line not forced through the tip gives 63 degrees,
// the path curving slightly, and turning the lattice against the plate moves the angle by about
// 4 degrees at these cells: docs/validation.md). Also: the crack runs below the Rayleigh speed,
// does not branch, and nothing breaks except this crack.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "host/case.hpp"
#include "host/cracks.hpp"
#include "host/simulation.hpp"
#include "test_util.hpp"

namespace fracta {
namespace {

TEST(KalthoffWinkler, CrackLeavesTheNotchAtSeventyDegrees) {
  Case c = load_case(std::string(FRACTA_SOURCE_DIR) + "/cases/validation/kalthoff_winkler.toml");
  c.sim.end_time = 50e-6;  // the crack is past 25 mm from the tip by then
  Simulation sim(c);
  const Vec2 notch_tip{50e-3, 25e-3};
  const double h = c.bodies[0].cell_size, link = 1.5 * h;
  double last_length = 0, last_time = 0, fastest = 0;
  while (sim.time() < c.sim.end_time * (1 - 1e-12) && !sim.failed()) {
    sim.step();
    if (sim.steps() % 50 != 0) continue;
    const CrackTrace t = trace_crack(sim, notch_tip, link, 5 * h);
    if (t.length > 5e-3 && last_time > 0)
      fastest = std::max(fastest, (t.length - last_length) / (sim.time() - last_time));
    last_length = t.length;
    last_time = sim.time();
  }
  ASSERT_FALSE(sim.failed()) << sim.failure();
  const CrackTrace t = trace_crack(sim, notch_tip, link, 10 * h);
  ASSERT_TRUE(t.found);
  ASSERT_GT(std::hypot(t.tip[0] - notch_tip[0], t.tip[1] - notch_tip[1]), 25e-3);
  const double angle = test::path_angle_through(t, notch_tip, 5e-3, 25e-3);
  EXPECT_NEAR(angle, 70.0, 5.0);
  EXPECT_LT(fastest, test::plane_stress_rayleigh_speed(190e9, 0.3, 8000.0));
  EXPECT_GT(fastest, 0);
  EXPECT_EQ(t.points, sim.history().count.broken_bonds);  // no damage elsewhere broke through
  ::testing::Test::RecordProperty("angle_deg", std::to_string(angle));
  ::testing::Test::RecordProperty("fastest_m_per_s", std::to_string(fastest));
  // One crack, no branch (Kalthoff's brittle regime); spurs of the damage band are shorter than
  // 10 cells (measured up to 3.2 mm).
  EXPECT_TRUE(t.branches.empty());
}

}  // namespace
}  // namespace fracta
