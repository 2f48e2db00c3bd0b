// Rigid bodies (docs/physics.md 1.3): no internal forces, exact rigidity, Newton-Euler through
// contact.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

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

// A rigid 4 mm steel block at 30 m/s, its left side at striker_x (m), about to strike the top
// of an 8 x 8 mm concrete-like lattice block (1 mm cells, plane stress); 30 us.
Case striker_on_lattice_case(const double striker_x) {
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
  s.shape.x = striker_x;
  s.shape.y = 8 * h + 1.1 * h;
  s.shape.width = 4e-3;
  s.shape.height = 4e-3;
  s.initial_velocity = {0.0, -30.0};
  c.bodies.push_back(s);
  c.sim.end_time = 30e-6;
  return c;
}

// A rigid steel block strikes a free lattice block: linear momentum is exchanged through contact
// only (conserved to round-off), the striker stays rigid, it slows down, and the energy balance
// (contact damping, bond energy, fracture) closes within 1%.
TEST(Rigid, RigidStrikerOnLatticeConservesMomentum) {
  const Case c = striker_on_lattice_case(2e-3);
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

// Scenes with rigid bodies fuse each step's second half kick with the next step's first
// (Simulation::kick): the body is projected on its rigid motion once after the fused kick
// instead of after each half. The projection is linear and idempotent, so both give the same
// motion up to round-off. Oracle: the same run stepped with separate kicks. A striker hits a
// lattice off its centre, so it turns and slows through contact; after 30 us (about 1,500
// steps) the two runs' bodies agree to 1e-9 of their motion (round-off, grown through contact).
TEST(Rigid, FusedKicksMoveTheBodyAsSeparateKicksDo) {
  const Case c = striker_on_lattice_case(5e-3);  // over the target's right half: it turns
  Simulation separate(c), fused(c);
  while (separate.time() < c.sim.end_time * (1 - 1e-12) && !separate.failed()) {
    separate.step(false);
    fused.step(true);
  }
  ASSERT_FALSE(separate.failed()) << separate.failure();
  ASSERT_FALSE(fused.failed()) << fused.failure();
  fused.finish_kick();
  ASSERT_EQ(fused.steps(), separate.steps());
  const RigidBody &a = separate.model().rigid[0], &b = fused.model().rigid[0];
  ASSERT_GT(std::fabs(a.omega), 1.0);  // it turned (rad/s)
  ASSERT_GT(a.vy, -29.0);              // and slowed
  const double speed = 30.0, tolerance = 1e-9;
  EXPECT_NEAR(b.vx, a.vx, tolerance * speed);
  EXPECT_NEAR(b.vy, a.vy, tolerance * speed);
  EXPECT_NEAR(b.omega, a.omega, tolerance * speed / 4e-3);
  EXPECT_NEAR(b.x, a.x, tolerance * 4e-3);
  EXPECT_NEAR(b.y, a.y, tolerance * 4e-3);
  EXPECT_NEAR(b.theta, a.theta, tolerance);
  RecordProperty("omega", std::to_string(a.omega));
  std::printf("separate kicks: vy %.15g omega %.15g; fused: vy %.15g omega %.15g\n", a.vy, a.omega,
              b.vy, b.omega);
}

// A rigid body of revolution (formulation = "axisymmetric") strikes the end of a free elastic
// rod of the same radius. Rod theory's exact answer for a rigid mass M on a bar of impedance
// Z = rho c0 A (Kolsky 1963; Graff 1975, Sec. 2.3): until the wave reflected from the far end
// returns (t < 2 L / c0), the mass slows as v(t) = v0 exp(-t / tau), tau = M / Z. Here M is
// half the rod's mass, so tau = L / (2 c0) and the test reads v at tau and 2 tau (tolerance
// 3 %: the rod is 1/25 as thick as it is long, so lateral inertia is small, and the contact
// spring adds a short rise). The body moves along the axis only (v_r and omega exactly 0), keeps
// its shape, and the axial momentum of the two bodies is conserved to round-off.
TEST(Rigid, BodyOfRevolutionStrikesARod) {
  const double h = 0.5e-3, E = 200e9, nu = 0.3, rho = 7800.0, v0 = 10.0;
  const int nr = 4, nz = 200;
  const double L = nz * h, striker_length = 10e-3;
  Case c = test::rectangle_case(nr, nz, h, E, nu, rho, Formulation::axisymmetric);
  c.bodies[0].name = "rod";
  Material heavy = c.materials[0];
  heavy.name = "striker_material";
  heavy.density = 0.5 * rho * L / striker_length;  // M = half the rod's mass
  c.materials.push_back(heavy);
  Body s = c.bodies[0];
  s.name = "striker";
  s.material = heavy.name;
  s.material_index = 1;
  s.method = BodyMethod::rigid;
  s.shape.y = L + 0.5 * h;  // the rod's end discs (radius h / 2) just touch its face (a surface)
  s.shape.height = striker_length;
  s.initial_velocity = {0.0, -v0};
  c.bodies.push_back(s);
  const double c0 = std::sqrt(E / rho), tau = L / (2 * c0);
  c.sim.end_time = 2.2 * tau;
  Simulation sim(c);
  const RigidBody& b = sim.model().rigid[0];
  ASSERT_TRUE(b.axial_only);
  const HistoryRecord h0 = sim.history();
  double v_tau = 0, v_2tau = 0, largest_off_axis = 0;
  while (sim.time() < c.sim.end_time * (1 - 1e-12) && !sim.failed()) {
    sim.step();
    if (v_tau == 0 && sim.time() >= tau) v_tau = -b.vy;
    if (v_2tau == 0 && sim.time() >= 2 * tau) v_2tau = -b.vy;
    largest_off_axis = std::max({largest_off_axis, std::fabs(b.vx), std::fabs(b.omega)});
  }
  ASSERT_FALSE(sim.failed()) << sim.failure();
  EXPECT_NEAR(v_tau, v0 * std::exp(-1.0), 0.03 * v0 * std::exp(-1.0));
  EXPECT_NEAR(v_2tau, v0 * std::exp(-2.0), 0.03 * v0 * std::exp(-2.0));
  EXPECT_EQ(largest_off_axis, 0.0);
  EXPECT_LT(shape_change(sim, b.node_begin, b.node_end), 1e-12);
  EXPECT_NEAR(sim.history().momentum_y, h0.momentum_y, 1e-10 * std::fabs(h0.momentum_y));
  RecordProperty("v_tau_over_exact", std::to_string(v_tau / (v0 * std::exp(-1.0))));
  RecordProperty("v_2tau_over_exact", std::to_string(v_2tau / (v0 * std::exp(-2.0))));
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
