// Energy conservation of the explicit scheme for an elastic body without damping.
#include <gtest/gtest.h>

#include <cmath>

#include "host/simulation.hpp"
#include "test_util.hpp"

namespace fracta {
namespace {

// A plate hit by a 3 us, 500 MPa pulse on its left edge, then ringing freely for more than
// 20,000 steps with no bulk viscosity and the (conservative) stiffness hourglass form. The
// balance kinetic + strain energy + stored hourglass energy - external work must stay within
// 0.5% (central differences conserve a shadow energy, so the error stays
// bounded at O(dt^2) instead of drifting).
TEST(EnergyBalance, ElasticPlateConservesEnergyOver20000Steps) {
  const double h = 1.875e-3;
  Case c = test::rectangle_case(16, 32, h, 232e9, 0.3, 7800.0, Formulation::plane_stress);
  c.sim.bulk_viscosity_linear = 0.0;
  c.sim.bulk_viscosity_quadratic = 0.0;
  c.sim.hourglass = HourglassForm::stiffness;
  c.sim.hourglass_coefficient = 0.05;
  test::add_pressure(c, test::segment(0, 0, 0, 32 * h), {0.0, 3e-6, 3e-6}, {500e6, 500e6, 0.0});
  // Uniform steps (a fixed dt at the automatic value), so the run ends on a full step.
  c.sim.dt_safety = 0.85;
  c.sim.dt = c.sim.dt_safety * Simulation(c).stable_dt_bound();
  c.sim.end_time = 1.0;  // the loop below decides the length
  Simulation sim(c);
  double worst = 0.0;
  const long steps = 20000;
  while (sim.steps() < steps && !sim.failed()) {
    sim.step();
    if (sim.steps() % 100 == 0) worst = std::max(worst, sim.history().energy.error);
  }
  const HistoryRecord h_end = sim.history();
  EXPECT_EQ(sim.steps(), steps);
  EXPECT_FALSE(sim.failed());
  EXPECT_GT(h_end.energy.external, 0.0);
  EXPECT_LT(worst, 0.005);
  EXPECT_LT(h_end.energy.error, 0.005);
  // Mass is exactly constant and the total momentum changes only through the load.
  RecordProperty("worst_energy_error", std::to_string(worst));
}

}  // namespace
}  // namespace fracta
