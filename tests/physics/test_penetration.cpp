// Regression on the penetration scene (cases/penetration.toml) at coarse resolution: projectile
// depth below the slab's top face and converted-element count after 60 us.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "host/case.hpp"
#include "host/simulation.hpp"
#include "test_util.hpp"

namespace fracta {
namespace {

struct PenetrationResult {
  double depth, speed;
  long conversions;
  double worst_error;
};

PenetrationResult run_coarse() {
  Case c = load_case(std::string(FRACTA_SOURCE_DIR) + "/cases/penetration.toml",
                     {"body.slab.cell_size=3.333e-3", "body.projectile.cell_size=3.333e-3",
                      "body.projectile.shape.y=0.0345", "simulation.end_time=60e-6"});
  Simulation sim(c);
  double worst = 0;
  while (sim.time() < c.sim.end_time * (1 - 1e-12) && !sim.failed()) {
    sim.step();
    if (sim.steps() % 10 == 0) worst = std::max(worst, sim.history().energy.error);
  }
  EXPECT_FALSE(sim.failed()) << sim.failure();
  const BodyRange& p = sim.model().mesh.bodies[1];
  auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), sim.model().nodes.x);
  double bottom = 1e300;
  for (int n = p.node_begin; n < p.node_end; ++n) bottom = std::min(bottom, x(n, 1));
  const auto bp = sim.body_probe_records();
  return {0.03 - bottom, -bp[0].vy, sim.conversions(), worst};
}

// At 3.33 mm cells every slab cell converts (216 of 216); depth 3.03 mm (1 thread), 2.99 mm (2)
// with brittle bonds; with the case's cohesive concrete (fracture_energy 130 J/m^2) 3.02 mm on
// 1 and 2 threads, and 2.63 mm on both since a cohesive bond's softening starts where it met its
// strength within the step, not at the step's end (docs/physics.md 1.2): under the impact a
// step carried bonds well past their strength, and their peaks with them.
constexpr double kReferenceDepth = 2.63e-3, kReferenceConversions = 216;

// Reference values measured when the test was written (OpenMP, 1 and 2 threads). The run
// fragments the slab, and the order of atomic additions (thread count) changes round-off that
// the fracture cascade amplifies: the tolerances cover the spread seen between thread counts
// with margin (depth 10%, conversions 5%); a physics change moves them more.
TEST(Penetration, CoarseRegressionOnDepthAndConversions) {
  const PenetrationResult r = run_coarse();
  RecordProperty("depth_mm", std::to_string(r.depth * 1e3));
  RecordProperty("projectile_speed", std::to_string(r.speed));
  RecordProperty("conversions", std::to_string(r.conversions));
  RecordProperty("worst_energy_error", std::to_string(r.worst_error));
  EXPECT_NEAR(r.depth, kReferenceDepth, 0.10 * kReferenceDepth);
  EXPECT_NEAR(static_cast<double>(r.conversions), kReferenceConversions,
              0.05 * kReferenceConversions);
  EXPECT_LT(r.worst_error, 0.05);
}

// The projectile stays `fe` (steel's nu = 0.3 in plane strain is outside the lattice's range,
// docs/physics.md 1.2): this shows that it would not have converted anyway. The case as
// shipped (1.667 mm cells) to 100 us, past the deceleration (200 -> 125 m/s by 60 us): the
// projectile's largest equivalent plastic strain must stay below steel's conversion strain
// (0.5, the default for bilinear_j2); measured 0.26 over the whole 300 us run.
TEST(Penetration, ProjectileStaysBelowItsConversionStrain) {
  Case c = load_case(std::string(FRACTA_SOURCE_DIR) + "/cases/penetration.toml",
                     {"simulation.end_time=100e-6"});
  Simulation sim(c);
  while (sim.time() < c.sim.end_time * (1 - 1e-12) && !sim.failed()) sim.step();
  ASSERT_FALSE(sim.failed()) << sim.failure();
  const BodyRange& p = sim.model().mesh.bodies[1];
  const Elements& el = sim.model().elements;
  auto epeq = Kokkos::create_mirror_view_and_copy(HostSpace(), el.epeq);
  double worst = 0;
  for (int q = p.element_begin * el.qp_per_element; q < p.element_end * el.qp_per_element; ++q)
    worst = std::max(worst, epeq(q));
  RecordProperty("projectile_max_plastic_strain", std::to_string(worst));
  EXPECT_GT(worst, 0.01);  // it did yield: the check is not vacuous
  EXPECT_LT(worst, c.materials[c.bodies[1].material_index].conversion_strain);
}

// Regression (fracta's own figures, validates nothing) on cases/penetration_hjc.toml: with the
// Holmquist-Johnson-Cook concrete, converting by damage, what has converted at 20 us is the
// crater and the spall zone only. Measured (2 threads): 80 of 864 slab elements, all within
// 20 mm of the axis, in the top or bottom 10 mm of the slab (the crater's edges and the rear
// face under the projectile). Tolerances: 1 to 10 % of the slab; the places exactly.
TEST(Penetration, HjcConcreteConvertsOnlyTheCraterAndSpallZoneFirst) {
  Case c = load_case(std::string(FRACTA_SOURCE_DIR) + "/cases/penetration_hjc.toml",
                     {"simulation.end_time=20e-6"});
  Simulation sim(c);
  test::run_to_end(sim, 1000);
  ASSERT_FALSE(sim.failed()) << sim.failure();
  const Elements& el = sim.model().elements;
  const auto alive = Kokkos::create_mirror_view_and_copy(HostSpace(), el.alive);
  const auto body = Kokkos::create_mirror_view_and_copy(HostSpace(), el.body);
  const auto corners = Kokkos::create_mirror_view_and_copy(HostSpace(), el.nodes);
  const auto x0 = Kokkos::create_mirror_view_and_copy(HostSpace(), sim.model().nodes.x0);
  int slab = 0, converted = 0, misplaced = 0;
  for (int e = 0; e < el.count; ++e) {
    if (body(e) != 0) continue;
    ++slab;
    if (alive(e)) continue;
    ++converted;
    double cx = 0, cy = 0;
    for (int a = 0; a < 4; ++a) cx += x0(corners(e, a), 0) / 4, cy += x0(corners(e, a), 1) / 4;
    const bool near_axis = std::fabs(cx - 0.04) < 0.02;
    const bool crater_or_spall = cy > 0.02 || cy < 0.01;
    if (!near_axis || !crater_or_spall) ++misplaced;
  }
  std::printf(
      "hjc slab at 20 us: %d of %d elements converted, %d outside the crater and spall "
      "zones\n",
      converted, slab, misplaced);
  EXPECT_GE(converted, slab / 100);
  EXPECT_LE(converted, slab / 10);
  EXPECT_EQ(misplaced, 0);
}

// cases/penetration_axisymmetric.toml (the paper's scene turned about the projectile's axis,
// both bodies adaptive: rings where they fail) to 100 us, as CI can afford: conservation, not
// figures. Mass exact (nodes keep their masses through the conversion), no node at a negative
// radius (the axis's supports), the energy balance within 1 % (the plane scene's bound;
// measured 1.3e-3 at 300 us), and the projectile slowed (the check is not vacuous: rings
// converted, contact acted).
TEST(Penetration, AxisymmetricSceneConservesMassAndEnergy) {
  Case c = load_case(std::string(FRACTA_SOURCE_DIR) + "/cases/penetration_axisymmetric.toml",
                     {"simulation.end_time=100e-6"});
  Simulation sim(c);
  const double mass = sim.history().mass;
  const double worst = test::run_to_end(sim, 100);
  ASSERT_FALSE(sim.failed()) << sim.failure();
  const HistoryRecord end = sim.history();
  EXPECT_EQ(end.mass, mass);
  EXPECT_LT(worst, 0.01);
  EXPECT_GT(sim.conversions(), 50);
  EXPECT_GE(test::leftmost_node_x(sim), 0.0);
  const BodyProbeRecord projectile = sim.body_probe_records().at(0);
  EXPECT_GT(projectile.vy, -150.0);  // from -200 m/s
  std::printf(
      "axisymmetric penetration at 100 us: %ld conversions, energy error %.3g, projectile "
      "%.1f m/s\n",
      sim.conversions(), worst, projectile.vy);
}

// The main job (cases/perforation.toml: a rigid 0.5 kg ogive-nose rod into a 178 mm slab of HJC
// concrete at 750 m/s, axisymmetric, the slab adaptive), whole, as CI can afford it (about 10 s).
// Conservation: mass exact, the energy balance within 1 % (measured 4.9e-4), no node at a
// negative radius, the rod moving along the axis only. Regression (fracta's own figure, which
// validates nothing): it perforates, and its residual velocity stays within 10 % of the 532 m/s
// measured with the rod's smooth surface and the unbonded rubble (278 m/s before both); the
// experiment's is not known here (docs/validation.md, "Perforation").
TEST(Penetration, PerforationMainJob) {
  Case c = load_case(std::string(FRACTA_SOURCE_DIR) + "/cases/perforation.toml", {});
  Simulation sim(c);
  const double mass = sim.history().mass;
  const double worst = test::run_to_end(sim, 100);
  ASSERT_FALSE(sim.failed()) << sim.failure();
  EXPECT_EQ(sim.history().mass, mass);
  EXPECT_LT(worst, 0.01);
  EXPECT_GE(test::leftmost_node_x(sim), 0.0);
  const RigidBody& rod = sim.model().rigid.at(0);
  EXPECT_EQ(rod.vx, 0.0);
  const auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), sim.model().nodes.x);
  // The nose (the rod's lowest node) has passed the slab's rear face (y = 0).
  double nose = 1e9;
  for (int n = rod.node_begin; n < rod.node_end; ++n) nose = std::min(nose, x(n, 1));
  EXPECT_LT(nose, 0.0);
  EXPECT_NEAR(-rod.vy, 532.0, 53.2);
  std::printf(
      "perforation main job: residual velocity %.1f m/s, energy error %.3g, %ld conversions\n",
      -rod.vy, worst, sim.conversions());
}

}  // namespace
}  // namespace fracta
