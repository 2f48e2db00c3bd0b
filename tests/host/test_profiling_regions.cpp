// The named profiling regions the benchmarks time (bench/region_timer.hpp), and the contract
// they show (docs/physics.md 1.3: model only what a scene requires): a scene without contact-capable bodies never runs
// the neighbour search, and no bond or conversion work is done where no body can convert.
// Counts are exact integers: every step enters each of its phases once (integration twice:
// kick_drift and kick).
#include <gtest/gtest.h>

#include "../../bench/region_timer.hpp"
#include "host/simulation.hpp"
#include "test_util.hpp"

namespace fracta {
namespace {

using bench::RegionTimer;

constexpr int kSteps = 12;

// Runs kSteps steps of an 8 x 4 cell elastic block of the given method under an edge pressure
// (so there is motion), with the region timer attached only for those steps.
void run_block(BodyMethod method) {
  Case c = test::rectangle_case(8, 4, 1e-3, 200e9, 0.2);  // nu <= 1/4: discs allowed
  c.bodies[0].method = method;
  c.materials[0].conversion_strain = 0.5;  // adaptive: convertible, but elastic never yields
  c.sim.end_time = 1.0;                    // never reached
  test::add_pressure(c, test::segment(0, 0, 0, 4e-3), {0.0, 1.0}, {100e6, 100e6});
  Simulation sim(c);
  RegionTimer::install();
  for (int s = 0; s < kSteps; ++s) sim.step();
  ASSERT_FALSE(sim.failed()) << sim.failure();
}

class ProfilingRegions : public ::testing::Test {
 protected:
  void TearDown() override { RegionTimer::uninstall(); }
};

TEST_F(ProfilingRegions, NestedRegionOfTheSameNameCountsOnce) {
  RegionTimer::install();
  Kokkos::Profiling::pushRegion("outer");
  Kokkos::Profiling::pushRegion("outer");  // as contact_search inside contact_search
  Kokkos::Profiling::pushRegion("inner");
  Kokkos::Profiling::popRegion();
  Kokkos::Profiling::popRegion();
  Kokkos::Profiling::popRegion();
  EXPECT_EQ(RegionTimer::get("outer").calls, 1);
  EXPECT_EQ(RegionTimer::get("inner").calls, 1);
  EXPECT_GE(RegionTimer::get("outer").seconds, RegionTimer::get("inner").seconds);
}

TEST_F(ProfilingRegions, FeOnlySceneRunsNoContactSearchBondsOrConversion) {
  run_block(BodyMethod::fe);
  EXPECT_EQ(RegionTimer::get("fracta::step").calls, kSteps);
  EXPECT_EQ(RegionTimer::get("fracta::fe_forces").calls, kSteps);
  EXPECT_EQ(RegionTimer::get("fracta::integrate").calls, 2 * kSteps);
  EXPECT_EQ(RegionTimer::get("fracta::contact_search").calls, 0);
  EXPECT_EQ(RegionTimer::get("fracta::contact_forces").calls, 0);
  EXPECT_EQ(RegionTimer::get("fracta::bond_forces").calls, 0);
  EXPECT_EQ(RegionTimer::get("fracta::conversion").calls, 0);
}

TEST_F(ProfilingRegions, DeSceneRunsBondsAndContactEveryStep) {
  run_block(BodyMethod::de);
  EXPECT_EQ(RegionTimer::get("fracta::bond_forces").calls, kSteps);
  EXPECT_EQ(RegionTimer::get("fracta::contact_search").calls, kSteps);  // outermost: update()
  EXPECT_EQ(RegionTimer::get("fracta::contact_forces").calls, kSteps);
  EXPECT_EQ(RegionTimer::get("fracta::conversion").calls, 0);  // nothing left to convert
}

// The FE kernel checks the conversion criterion every step, and the conversion phase runs only
// when it flagged an element (its reduction's count): in this block nothing converts, so none
// runs.
TEST_F(ProfilingRegions, AdaptiveSceneRunsNoConversionPhaseWhileNothingIsFlagged) {
  run_block(BodyMethod::adaptive);
  EXPECT_EQ(RegionTimer::get("fracta::conversion").calls, 0);
  EXPECT_EQ(RegionTimer::get("fracta::fe_forces").calls, kSteps);
  EXPECT_EQ(RegionTimer::get("fracta::bond_forces").calls, 0);
}

}  // namespace
}  // namespace fracta
