// Rigid bodies (docs/physics.md 1.3): no internal forces, exact rigidity, Newton-Euler through
// contact.
#include <gtest/gtest.h>

#include <cmath>

#include "host/simulation.hpp"
#include "test_util.hpp"

namespace fracta {
namespace {

// Largest change of the distance between any two nodes of a node range, relative to the size.
double shape_change(const Simulation& sim, int begin, int end) {
  auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), sim.model().nodes.x);
  auto x0 = Kokkos::create_mirror_view_and_copy(HostSpace(), sim.model().nodes.x0);
  double worst = 0;
  for (int i = begin; i < end; ++i)
    for (int j = i + 1; j < end; ++j) {
      const double d = std::hypot(x(j, 0) - x(i, 0), x(j, 1) - x(i, 1));
      const double d0 = std::hypot(x0(j, 0) - x0(i, 0), x0(j, 1) - x0(i, 1));
      worst = std::max(worst, std::fabs(d - d0) / d0);
    }
  return worst;
}

// A free rigid square spinning and translating keeps its shape (to round-off), its speed and
// its spin (no force acts), however large the rotation (several turns).
TEST(Rigid, FreeSpinningBodyStaysRigid) {
  Case c = test::rectangle_case(4, 4, 1e-3);
  c.bodies[0].method = BodyMethod::rigid;
  c.bodies[0].initial_velocity = {10.0, 5.0};
  c.sim.end_time = 1.0;
  Simulation sim(c);
  RigidBody& b = sim.model().rigid[0];
  b.omega = 20000.0;  // rad/s
  write_rigid_velocity(b, sim.model().nodes);
  const double ke0 = sim.history().energy.kinetic;
  while (b.theta < 4 * 2 * M_PI && !sim.failed()) sim.step();
  // ~12,600 steps of rotation by cos/sin of a growing angle: round-off, 1e-11 relative.
  EXPECT_LT(shape_change(sim, 0, sim.model().nodes.count), 1e-11);
  EXPECT_NEAR(b.omega, 20000.0, 1e-9 * 20000.0);
  EXPECT_NEAR(b.vx, 10.0, 1e-12 * 10);
  EXPECT_NEAR(sim.history().energy.kinetic, ke0, 1e-9 * ke0);
}

// A rigid steel block strikes a free lattice block: linear momentum is exchanged through contact
// only (conserved to round-off), the striker stays rigid, it slows down, and the energy balance
// (contact damping, bond energy, fracture) closes within 1%.
TEST(Rigid, RigidStrikerOnLatticeConservesMomentum) {
  const double h = 1e-3;
  Case c = test::rectangle_case(8, 8, h, 30e9, 0.2, 2400.0, Formulation::plane_stress);
  c.bodies[0].method = BodyMethod::de;
  c.bodies[0].name = "target";
  Material steel = c.materials[0];
  steel.name = "steel";
  steel.density = 7800;
  steel.youngs_modulus = 200e9;
  c.materials.push_back(steel);
  Body s = c.bodies[0];
  s.name = "striker";
  s.material = "steel";
  s.material_index = 1;
  s.method = BodyMethod::rigid;
  s.shape.x = 2e-3;
  s.shape.y = 8 * h + 1.1 * h;
  s.shape.width = 4e-3;
  s.shape.height = 4e-3;
  s.initial_velocity = {0.0, -30.0};
  c.bodies.push_back(s);
  c.sim.end_time = 30e-6;
  Simulation sim(c);
  const HistoryRecord h0 = sim.history();
  const double worst = test::run_to_end(sim);
  ASSERT_FALSE(sim.failed()) << sim.failure();
  const HistoryRecord h1 = sim.history();
  const RigidBody& b = sim.model().rigid[0];
  EXPECT_NEAR(h1.momentum_y, h0.momentum_y, 1e-10 * std::fabs(h0.momentum_y));
  EXPECT_GT(b.vy, -29.0);  // slowed by the contact
  EXPECT_LT(shape_change(sim, b.node_begin, b.node_end), 1e-12);
  EXPECT_LT(worst, 0.01);
  RecordProperty("worst_energy_error", std::to_string(worst));
  RecordProperty("striker_vy", std::to_string(b.vy));
}

}  // namespace
}  // namespace fracta

namespace fracta {
namespace {

// Two finite-element bodies (no discs anywhere) meet through the contact of their boundary
// nodes: momentum is conserved, the bodies touch, and the energy balance closes. The contact's
// dissipation is the trapezoidal work of its forces less its stored energy (the rule under
// which central differences balance energy), so only O(dt^2) remains: 0.1%, elastic or with
// damping and friction.
double fe_collision(double damping, double friction) {
  const double h = 1e-3;
  Case c = test::rectangle_case(8, 4, h, 30e9, 0.2, 2400.0, Formulation::plane_strain);
  c.bodies[0].name = "target";
  Body s = c.bodies[0];
  s.name = "striker";
  s.shape.x = 2e-3;
  s.shape.y = 4 * h + 1.1 * h;
  s.shape.width = 4e-3;
  s.shape.height = 4e-3;
  s.initial_velocity = {0.0, -20.0};
  c.bodies.push_back(s);
  c.sim.end_time = 20e-6;
  c.contact.damping_ratio = damping;
  c.contact.friction = friction;
  Simulation sim(c);
  EXPECT_TRUE(sim.model().contacts != nullptr);
  EXPECT_EQ(sim.model().bonds.count, 0);  // no convertible body: no bond slots
  const HistoryRecord h0 = sim.history();
  double worst = 0;
  long touched = 0;
  while (sim.time() < c.sim.end_time * (1 - 1e-12) && !sim.failed()) {
    sim.step();
    const HistoryRecord hr = sim.history();
    worst = std::max(worst, hr.energy.error);
    touched = std::max(touched, hr.count.contacts);
  }
  EXPECT_FALSE(sim.failed()) << sim.failure();
  EXPECT_GT(touched, 0);
  EXPECT_NEAR(sim.history().momentum_y, h0.momentum_y, 1e-10 * std::fabs(h0.momentum_y));
  return worst;
}

TEST(FeContact, TwoFeBodiesCollide) {
  const double elastic = fe_collision(0.0, 0.0);
  const double dissipative = fe_collision(0.1, 0.3);
  EXPECT_LT(elastic, 0.001);
  EXPECT_LT(dissipative, 0.001);
  RecordProperty("energy_error_elastic_contact", std::to_string(elastic));
  RecordProperty("energy_error_damped_frictional_contact", std::to_string(dissipative));
}

}  // namespace
}  // namespace fracta
