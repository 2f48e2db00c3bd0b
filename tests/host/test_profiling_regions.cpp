// The named profiling regions the benchmarks time (bench/region_timer.hpp), and the contract
// they show (docs/physics.md 1.3: model only what a scene requires): a scene without
// contact-capable bodies never runs the neighbour search, and no bond or conversion work is done
// where no body can convert. Counts are exact integers: every step enters each of its phases once
// (integration twice: kick_drift and kick).
#include <gtest/gtest.h>

#include "../../bench/region_timer.hpp"
#include "host/simulation.hpp"
#include "test_util.hpp"

namespace fracta {
namespace {

using bench::KernelTimer;
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

// What a step without conversion asks of the device (docs/performance.md, "Launches and host
// round trips per step"): the phases' sums go to the step's slots and the host copies them once
// (Simulation::settle_step_sums), so on the device path (what a GPU runs) a step of a scene with
// bonds and contact waits for the device only for the contact search's rebuild check and that
// copy. The host path's chunked phases reduce colour by colour on the host instead: there it is
// their sums that come back once, with no device to wait for.
TEST(DeviceWaits, AStepWithoutConversionWaitsForTheDeviceAtMostThreeTimes) {
  Case c = test::rectangle_case(8, 4, 1e-3, 200e9, 0.2);
  c.bodies[0].method = BodyMethod::de;  // bonds, cells and contact every step
  c.sim.end_time = 1.0;
  test::add_pressure(c, test::segment(0, 0, 0, 4e-3), {0.0, 1.0}, {100e6, 100e6});
  Simulation sim(c);
  sim.step();  // the first step builds the contact lists
  KernelTimer::install();
  const bench::LaunchCounts before = KernelTimer::counts();
  for (int s = 0; s < kSteps; ++s) sim.step(/*defer_kick=*/true);
  const bench::LaunchCounts n = KernelTimer::counts() - before;
  KernelTimer::uninstall();
  ASSERT_FALSE(sim.failed()) << sim.failure();
  // Every phase's sums reach the ledger: the run balances energy as before.
  EXPECT_LT(sim.history().energy.error, 1e-6);
  // The slots: bonds and the kick (deferred: one kick per step, the kick-kick-drift). A `de`
  // body has no active element: the FE sums are stored, not reduced; and its intact lattice
  // lists no contact pair (joined pairs are left out), so the contact phase reduces nothing.
  RecordProperty("host_reduces", std::to_string(n.host_reduces()));
  RecordProperty("deep_copies", std::to_string(n.deep_copies));
  EXPECT_EQ(sim.model().contacts->candidate_count(), 0);
  if (kAtomicScatter) {
    EXPECT_EQ(n.slot_reduces, 2 * kSteps);
    EXPECT_LE(n.host_reduces() + n.deep_copies, 3 * kSteps)
        << n.host_reduces() << " reduces into host values, " << n.deep_copies << " deep copies";
  } else {
    EXPECT_GT(n.slot_reduces, 0);  // the kicks and the unchunked contact kernels
  }
}

}  // namespace
}  // namespace fracta
