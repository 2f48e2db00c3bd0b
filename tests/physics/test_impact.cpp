// Impacts from 50 to 2000 m/s: a steel projectile (FE, bilinear J2) into an adaptive concrete
// slab (Mohr-Coulomb elements converting to bonded discs), coarse mesh. Every run must reach its
// end without NaN, keep the mass exact, and close the energy balance within the 5%.
#include <gtest/gtest.h>

#include <cmath>

#include "host/simulation.hpp"
#include "test_util.hpp"

namespace fracta {
namespace {

Case impact_case(double speed) {
  const double h = 3.333e-3;
  Case c = test::rectangle_case(24, 9, h, 92e9, 0.21, 2400.0, Formulation::plane_strain);
  c.sim.thickness = 1.0;
  Material& concrete = c.materials[0];
  concrete.name = "concrete";
  concrete.model = MaterialModel::mohr_coulomb;
  concrete.cohesion = 11.2e6;
  concrete.friction_angle = std::atan(0.125);
  concrete.tensile_strength = 2.3e6;
  concrete.conversion_strain = 0.02;
  c.bodies[0].name = "slab";
  c.bodies[0].material = "concrete";
  c.bodies[0].method = BodyMethod::adaptive;
  Material steel;
  steel.name = "steel";
  steel.model = MaterialModel::bilinear_j2;
  steel.density = 7800;
  steel.youngs_modulus = 232e9;
  steel.poisson_ratio = 0.3;
  steel.yield_stress = 235e6;
  steel.plastic_modulus = 1.879e9;
  steel.conversion_strain = 0.5;
  c.materials.push_back(steel);
  Body p;
  p.name = "projectile";
  p.material = "steel";
  p.material_index = 1;
  p.cell_size = h;
  p.shape.x = 0.03;
  p.shape.y = 9 * h + 1.2 * h;  // more than one cell above the slab: contact discs are h/2
  p.shape.width = 0.02;
  p.shape.height = 0.025;
  p.initial_velocity = {0.0, -speed};
  c.bodies.push_back(p);
  c.sim.conversion_on_tension = true;
  c.sim.end_time = 0.2 * h / speed + 20e-6;
  return c;
}

TEST(Impact, FiftyToTwoThousandMetresPerSecond) {
  for (double speed : {50.0, 200.0, 1000.0, 2000.0}) {
    Simulation sim(impact_case(speed));
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
