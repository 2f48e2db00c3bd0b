// Taylor impact (cases/validation/taylor_*.toml; docs/validation.md, "Taylor impact"): a rod
// 25.4 mm long, 7.62 mm across, strikes a rigid frictionless anvil, axisymmetric, Johnson-Cook
// plasticity. At the cases' resolution (8 cells across the radius), each under 2 s on 2 cores.
// Which kind each test is: Steel4340... is a validation against the experiment of Johnson &
// Cook (1983); Copper... checks conservation laws (mass of the full revolution, the anvil's
// impulse against the rod's momentum, plastic incompressibility, the energy balance) and pins
// fracta's own final shape (regression: it fails the experiment's 3 %, docs/validation.md).
#include <gtest/gtest.h>

#include <cmath>

#include "test_util.hpp"

namespace fracta {
namespace {

const std::string kCases = std::string(FRACTA_SOURCE_DIR) + "/cases/validation/";

struct TaylorResult {
  double length, footprint;                 // final length and impact-face diameter (m)
  double mass;                              // total node mass (kg)
  double impulse;                           // of the anvil, summed over the steps (N s)
  double momentum_initial, momentum_final;  // axial (N s)
  double volume_initial, volume_final;      // of revolution of the mesh (m^3)
  double worst_energy_error;
};

// Volume of revolution of the mesh (Pappus, edge by edge: exact for straight edges).
double volume_of_revolution(Simulation& sim) {
  const auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), sim.model().nodes.x);
  const auto en = Kokkos::create_mirror_view_and_copy(HostSpace(), sim.model().elements.nodes);
  double volume = 0.0;
  for (int e = 0; e < sim.model().elements.count; ++e) {
    double v = 0.0;
    for (int a = 0; a < 4; ++a) {
      const int i = en(e, a), j = en(e, (a + 1) % 4);
      const double r1 = x(i, 0), z1 = x(i, 1), r2 = x(j, 0), z2 = x(j, 1);
      v += M_PI * (r1 * r1 + r1 * r2 + r2 * r2) * (z2 - z1) / 3.0;
    }
    volume += v;
  }
  return volume;
}

TaylorResult run_taylor(const std::string& case_file) {
  Case c = load_case(kCases + case_file);
  Simulation sim(c);
  TaylorResult r{};
  r.mass = sim.history().mass;
  r.momentum_initial = sim.history().momentum_y;
  r.volume_initial = volume_of_revolution(sim);
  // The anvil's force at an evaluation acts over the kick interval around it: half the first
  // step at t = 0 (where it catches the whole impact face), then (about) a step each.
  const double initial_force = sim.boundary_records()[0].fy;
  while (sim.time() < c.sim.end_time * (1 - 1e-12) && !sim.failed()) {
    const double before = sim.time();
    sim.step();
    if (before == 0.0) r.impulse += 0.5 * initial_force * sim.time();
    r.impulse += sim.boundary_records()[0].fy * (sim.time() - before);
    r.worst_energy_error = std::max(r.worst_energy_error, std::fabs(sim.history().energy.error));
  }
  EXPECT_FALSE(sim.failed());
  r.momentum_final = sim.history().momentum_y;
  r.volume_final = volume_of_revolution(sim);
  const auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), sim.model().nodes.x);
  const auto x0 = Kokkos::create_mirror_view_and_copy(HostSpace(), sim.model().nodes.x0);
  double top = -1e300, face_low = 1e300, face_radius = 0.0;
  for (size_t n = 0; n < x.extent(0); ++n) {
    top = std::max(top, x(n, 1));
    if (std::fabs(x0(n, 1)) > 1e-12) continue;  // the impact face: y = 0 at the start
    face_low = std::min(face_low, x(n, 1));
    face_radius = std::max(face_radius, x(n, 0));
  }
  r.length = top - face_low;
  r.footprint = 2.0 * face_radius;
  return r;
}

// 4340 steel at 208 m/s: final length 22.48 mm measured (Johnson & Cook 1983, L/L0 = 0.885 as
// tabulated by Zerilli & Armstrong 1987), within 3 % (it meets it by 0.5 %: 22.59
// mm). The footprint, 11.1 mm measured, comes out 10.7 mm (-3.3 %), outside 3 %: reported in
// docs/validation.md, not asserted.
TEST(TaylorImpact, Steel4340At208MetersPerSecondFinalLength) {
  const TaylorResult r = run_taylor("taylor_steel_4340.toml");
  EXPECT_NEAR(r.length, 22.48e-3, 0.03 * 22.48e-3);
  EXPECT_LT(r.worst_energy_error, 0.01);
  std::printf(
      "4340 steel at 208 m/s: final length %.3f mm (measured 22.48), footprint %.3f mm "
      "(measured 11.1)\n",
      1e3 * r.length, 1e3 * r.footprint);
}

// OFHC copper at 190 m/s. Conservation: the mass is rho pi R^2 L (the full revolution, exact
// for a rectangle's corner-mean radius) to 1e-12; the anvil's recorded force (its catches of
// landing nodes included), summed over the steps, equals the rod's change of axial momentum
// within 1e-3 (measured 2.4e-4: the record's force acts over the kick interval, the sum takes
// each step's dt);
// the volume of revolution changes only elastically (plastic flow is isochoric; residual
// stresses of a few 100 MPa give |dV/V| < 1e-3); energy balance within 1 %. Regression: final
// length 17.30 mm and footprint 14.58 mm at these cells, within 0.5 % (the experiment's 16.2
// and 13.6 mm are 6.7 % and 7 % away; docs/validation.md).
// Oracle, code to code: an independent Johnson-Cook solver in 3D (eight-node hexahedra, one-point
// integration, Mie-Gruneisen pressure; the same strength constants, heating at a Taylor-Quinney
// fraction of 0.9, a frictionless rigid anvil) reports 17.40 mm and a largest diameter of 14.6 mm,
// unchanged between two meshes, and its particle solver a length 0.9 % shorter
// (github.com/molanocortes/OpenPhysicsAI, docs/lab/impact.md; unreviewed). Within 2 % in length
// and 3 % in diameter (its two methods differ by 0.9 % and 0.5 %; its pressure is stiffer than
// the linear one here: bulk modulus 139 against 129 GPa): measured -0.6 % and -0.1 %. So the
// rod's excess length over the test is the model's (the constants), not the integration's.
TEST(TaylorImpact, CopperConservesMassAndVolume) {
  const TaylorResult r = run_taylor("taylor_copper.toml");
  const double R = 3.81e-3, L = 25.4e-3, rho = 8960.0;
  EXPECT_NEAR(r.mass, rho * M_PI * R * R * L, 1e-12 * r.mass);
  const double change = r.momentum_final - r.momentum_initial;
  EXPECT_NEAR(r.impulse, change, 1e-3 * change);
  EXPECT_GT(r.momentum_final, 0.0);  // it rebounds
  EXPECT_NEAR(r.volume_final / r.volume_initial, 1.0, 1e-3);
  EXPECT_NEAR(r.volume_initial, M_PI * R * R * L, 1e-12 * r.volume_initial);
  EXPECT_NEAR(r.mass, rho * r.volume_initial, 1e-12 * r.mass);
  EXPECT_LT(r.worst_energy_error, 0.01);
  EXPECT_NEAR(r.length, 17.30e-3, 0.005 * 17.30e-3);     // regression
  EXPECT_NEAR(r.footprint, 14.58e-3, 0.005 * 14.58e-3);  // regression
  EXPECT_NEAR(r.length, 17.40e-3, 0.02 * 17.40e-3);      // another code
  EXPECT_NEAR(r.footprint, 14.6e-3, 0.03 * 14.6e-3);     // another code
  std::printf(
      "copper at 190 m/s: final length %.3f mm, footprint %.3f mm, dV/V %.3g, impulse "
      "%.6g vs momentum change %.6g N s\n",
      1e3 * r.length, 1e3 * r.footprint, r.volume_final / r.volume_initial - 1, r.impulse,
      r.momentum_final - r.momentum_initial);
}

// Axisymmetric contact (docs/physics.md, "Axisymmetry"): two copper rods meeting head-on at
// 95 m/s each (the symmetric Taylor test) deform as one rod striking a frictionless rigid wall
// at 95 m/s, since their interface stays on the plane of symmetry and slides freely there. The
// support's rod is the oracle: final length within 0.5 % and footprint within 2 % (the contact
// discs' penalty and damping against the support's exact catch: measured -0.06 % and +0.6 %).
// Conservation: the total axial momentum stays 0 to round-off, the two rods are mirror images
// to 1e-5 (measured 1.3e-6), energy balance within 1e-4.
TEST(TaylorImpact, RodOnRodMatchesRodOnARigidWall) {
  Case wall = load_case(kCases + "taylor_copper.toml");
  wall.bodies[0].initial_velocity = {0.0, -95.0};
  Case pair = wall;
  pair.boundaries.clear();
  Body second = pair.bodies[0];
  second.name = "rod2";
  second.initial_velocity = {0.0, 95.0};
  const double h = second.cell_size, gap = 1.2 * h;  // contact discs are h / 2
  second.shape.y = -gap - second.shape.height;
  pair.bodies.push_back(second);

  // Final length and footprint diameter of the rod whose impact face starts at face_y: the
  // upper rod (nodes at or above face_y) or the lower one (at or below it).
  auto shape_of = [](Simulation& sim, double face_y, bool upper) {
    const auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), sim.model().nodes.x);
    const auto x0 = Kokkos::create_mirror_view_and_copy(HostSpace(), sim.model().nodes.x0);
    const double sign = upper ? 1.0 : -1.0;
    double far = -1e300, face = 1e300, radius = 0.0;
    for (size_t n = 0; n < x.extent(0); ++n) {
      if (sign * (x0(n, 1) - face_y) < -1e-9) continue;  // the other rod
      far = std::max(far, sign * x(n, 1));
      if (std::fabs(x0(n, 1) - face_y) > 1e-9) continue;
      face = std::min(face, sign * x(n, 1));
      radius = std::max(radius, x(n, 0));
    }
    return std::array<double, 2>{far - face, 2.0 * radius};
  };
  Simulation reference(wall);
  test::run_to_end(reference);
  ASSERT_FALSE(reference.failed());
  const auto expected = shape_of(reference, 0.0, true);

  Simulation sim(pair);
  double worst = 0.0, drift = 0.0;
  const double p_scale = sim.history().mass / 2 * 95.0;
  while (sim.time() < pair.sim.end_time * (1 - 1e-12) && !sim.failed()) {
    sim.step();
    worst = std::max(worst, std::fabs(sim.history().energy.error));
    drift = std::max(drift, std::fabs(sim.history().momentum_y));
  }
  ASSERT_FALSE(sim.failed());
  const auto upper = shape_of(sim, 0.0, true);
  const auto lower = shape_of(sim, -gap, false);
  EXPECT_NEAR(upper[0], expected[0], 0.005 * expected[0]);
  EXPECT_NEAR(upper[1], expected[1], 0.02 * expected[1]);
  // Mirror images, to round-off in the contact, which the plastic flow carries on (host path,
  // Release: footprints 4.7e-6 apart; tolerance 1e-5). On the device path the order of the
  // atomic sums changes from run to run: 5.9e-6 in most runs, up to 1.4e-5 in one of about 90.
  // The sanitizer build (-O2) contracts products into FMAs differently: 1.49e-5. Those: 5e-5.
#ifdef FRACTA_SANITIZE_BUILD
  const double mirror = 5e-5;
#else
  const double mirror = kAtomicScatter ? 5e-5 : 1e-5;
#endif
  EXPECT_NEAR(lower[0], upper[0], mirror * upper[0]);
  EXPECT_NEAR(lower[1], upper[1], mirror * upper[1]);
  EXPECT_LT(drift, 1e-12 * p_scale);
  EXPECT_LT(worst, 1e-4);
  EXPECT_GT(sim.history().energy.contact, 0.0);
  std::printf(
      "rod on rod at 2 x 95 m/s: length %.3f mm, footprint %.3f mm; on the wall %.3f, "
      "%.3f mm; momentum %.3g of m v, energy error %.3g; mirror difference %.3g (length), %.3g "
      "(footprint)\n",
      1e3 * upper[0], 1e3 * upper[1], 1e3 * expected[0], 1e3 * expected[1], drift / p_scale, worst,
      std::fabs(lower[0] - upper[0]) / upper[0], std::fabs(lower[1] - upper[1]) / upper[1]);
}

}  // namespace
}  // namespace fracta
