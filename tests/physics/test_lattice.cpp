// The bonded lattice in motion: energy conservation, tensile failure at the material strength
// (DESIGN.md 1.2 calibration), and the energy balance through breakage.
#include <gtest/gtest.h>

#include <cmath>

#include "host/simulation.hpp"
#include "test_util.hpp"

namespace fracta {
namespace {

// An elastic lattice plate hit by a 3 us pulse then ringing freely for 20,000 steps: discs
// and bonds have no damping at all, so the balance (translational + rotational kinetic, bond
// energy, external work, central-difference term) must close to the 0.5%.
TEST(LatticeEnergy, ElasticLatticeConservesEnergyOver20000Steps) {
  const double h = 1.875e-3;
  Case c = test::rectangle_case(16, 32, h, 232e9, 0.3, 7800.0, Formulation::plane_stress);
  c.bodies[0].method = BodyMethod::de;
  test::add_pressure(c, test::segment(0, 0, 0, 32 * h), {0.0, 3e-6, 3e-6}, {500e6, 500e6, 0.0});
  c.sim.end_time = 1.0;
  c.sim.dt = 0.85 * Simulation(c).stable_dt_bound();  // uniform steps
  Simulation sim(c);
  double worst = 0.0;
  while (sim.steps() < 20000 && !sim.failed()) {
    sim.step();
    if (sim.steps() % 100 == 0) worst = std::max(worst, sim.history().energy.error);
  }
  EXPECT_FALSE(sim.failed());
  EXPECT_GT(sim.history().energy.external, 0.0);
  EXPECT_LT(worst, 0.005);
  RecordProperty("worst_energy_error", std::to_string(worst));
}

// A lattice block of brittle material pulled by a slowly ramped traction on its right edge
// (left edge on rollers): it must fail when the applied stress reaches the tensile strength.
// The ramp takes ~100 wave transits to reach sigma_t, so dynamic overshoot is ~1%; the
// issue's tolerance is 5%.
struct TensionRun {
  double failure_stress, worst_error, fracture;
  long broken;
};

TensionRun run_tension(Formulation f, double nu) {
  const double h = 1e-3, E = 92e9, rho = 2400.0, sigma_t = 2.3e6;
  const int nx = 20, ny = 10;
  Case c = test::rectangle_case(nx, ny, h, E, nu, rho, f);
  c.bodies[0].method = BodyMethod::de;
  c.materials[0].tensile_strength = sigma_t;
  const double c_wave = std::sqrt(E / rho);
  const double ramp = 100 * nx * h / c_wave * 2.0;  // time to reach 2 sigma_t
  test::add_pressure(c, test::segment(nx * h, 0, nx * h, ny * h), {0.0, ramp},
                     {0.0, -2.0 * sigma_t});
  test::add_fixed(c, test::segment(0, 0, 0, ny * h), Boundary::Type::fixed_x);
  c.sim.end_time = 0.75 * ramp;  // past failure (at ramp / 2), into fragment motion
  Simulation sim(c);
  TensionRun r{-1, 0, 0, 0};
  while (sim.time() < c.sim.end_time * (1 - 1e-12) && !sim.failed()) {
    sim.step();
    const HistoryRecord hr = sim.history();
    r.worst_error = std::max(r.worst_error, hr.energy.error);
    if (r.failure_stress < 0 && hr.count.broken_bonds > 0)
      r.failure_stress = 2.0 * sigma_t * sim.time() / ramp;
  }
  EXPECT_FALSE(sim.failed());
  const HistoryRecord end = sim.history();
  r.fracture = end.energy.fracture;
  r.broken = end.count.broken_bonds;
  return r;
}

TEST(LatticeFailure, UniaxialTensionFailsAtTensileStrength) {
  for (auto [f, nu] :
       {std::pair{Formulation::plane_stress, 0.21}, std::pair{Formulation::plane_strain, 0.21}}) {
    const TensionRun r = run_tension(f, nu);
    EXPECT_NEAR(r.failure_stress, 2.3e6, 0.05 * 2.3e6) << to_string(f);
    EXPECT_GT(r.broken, 0);
    EXPECT_GT(r.fracture, 0.0);
    // The balance with fracture energy closes within the 1% through the breakage.
    EXPECT_LT(r.worst_error, 0.01) << to_string(f);
    RecordProperty(std::string("failure_stress_") + to_string(f), std::to_string(r.failure_stress));
    RecordProperty(std::string("worst_error_") + to_string(f), std::to_string(r.worst_error));
  }
}

}  // namespace
}  // namespace fracta
