// Impacts from 50 to 2000 m/s: a steel projectile (FE, bilinear J2) into an adaptive concrete
// slab (Mohr-Coulomb elements converting to bonded discs), coarse mesh. Every run must reach its
// end without NaN, keep the mass exact, and close the energy balance within 5% (contact,
// conversion and breakage at coarse cells).
#include <gtest/gtest.h>

#include <cmath>

#include "host/simulation.hpp"
#include "test_util.hpp"

namespace fracta {
namespace {

TEST(Impact, FiftyToTwoThousandMetresPerSecond) {
  for (double speed : {50.0, 200.0, 1000.0, 2000.0}) {
    Simulation sim(test::impact_case(speed));
    const double mass0 = sim.history().mass;
    double worst = 0;
    while (sim.time() < sim.model().scene.sim.end_time * (1 - 1e-12) && !sim.failed()) {
      sim.step();
      if (sim.steps() % 10 == 0) worst = std::max(worst, sim.history().energy.error);
    }
    ASSERT_FALSE(sim.failed()) << speed << " m/s: " << sim.failure();
    const HistoryRecord end = sim.history();
    EXPECT_TRUE(std::isfinite(end.energy.kinetic)) << speed;
    EXPECT_EQ(end.mass, mass0) << speed;  // node masses never change
    EXPECT_LT(std::max(worst, end.energy.error), 0.05) << speed << " m/s";
    EXPECT_GT(sim.conversions(), 0) << speed;
    RecordProperty("energy_error_" + std::to_string(static_cast<int>(speed)),
                   std::to_string(std::max(worst, end.energy.error)));
  }
}

}  // namespace
}  // namespace fracta
