// Boundaries that load as experiments do (docs/physics.md 1.4, "Boundaries"), each against the
// exact solution of one-dimensional wave theory in a strip with rollers on its long sides
// (uniaxial strain: waves travel at the plane-strain dilatational speed c, a step of particle
// velocity v carries the stress rho c v):
// - a prescribed face velocity V launches sigma_xx = -rho c V, and its reaction is rho c V A;
// - a split-Hopkinson bar of impedance Z_b on a specimen of Z_s transmits
//   sigma = 2 Z_s Z_b / (Z_s + Z_b) v_I and reflects (Z_s - Z_b) / (Z_s + Z_b) of the incident
//   stress Z_b v_I (Kolsky 1949; Graff, Wave Motion in Elastic Solids, 1.2);
// - a bar striking a push-only support stays in contact for 2 L / c and leaves it with the
//   velocity it came with (Graff 1.2, the longitudinal impact of a rod on a rigid wall).
// All are exact-solution tests.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "host/simulation.hpp"
#include "test_util.hpp"

namespace fracta {
namespace {

constexpr double kCell = 0.5e-3, kE = 200e9, kNu = 0.25, kRho = 7800.0;
constexpr int kRows = 4;
constexpr double kHeight = kRows * kCell;

// Plane-strain dilatational speed and specific impedance of the strip's steel.
double wave_speed() {
  return std::sqrt(kE * (1 - kNu) / (kRho * (1 + kNu) * (1 - 2 * kNu)));
}
double impedance() {
  return kRho * wave_speed();
}

// A strip of `columns` cells, rollers on both long sides.
Case strip(int columns) {
  Case c = test::rectangle_case(columns, kRows, kCell, kE, kNu, kRho);
  const double L = columns * kCell;
  test::add_fixed(c, test::segment(0, 0, L, 0), Boundary::Type::fixed_y);
  test::add_fixed(c, test::segment(0, kHeight, L, kHeight), Boundary::Type::fixed_y);
  return c;
}

Boundary face_boundary(const std::string& name, Boundary::Type type, double x) {
  Boundary b;
  b.name = name;
  b.type = type;
  b.where.kind = NodeSelector::Kind::segment;
  b.where.segment = test::segment(x, 0, x, kHeight);
  return b;
}

// The mean of the samples whose time lies in [from, to].
double window_mean(const std::vector<double>& t, const std::vector<double>& v, double from,
                   double to) {
  double sum = 0;
  int count = 0;
  for (size_t i = 0; i < t.size(); ++i)
    if (t[i] >= from && t[i] <= to) {
      sum += v[i];
      ++count;
    }
  return count ? sum / count : NAN;
}

// Tolerance 1%, as for the pressure-driven plane wave (test_plane_wave.cpp): the lumped-mass
// front rings, and the plateau is averaged from 9 mm behind it. Energy (conservation, with the
// boundaries' work in the external work): the balance closes to 1e-4 sampled every 100 steps
// (measured 1e-5 and below; the first steps, while the energy in play is still tiny, carry a
// start-up offset of about 5e-7 J that the sampling skips).
TEST(Boundaries, PrescribedVelocityLaunchesThePlaneWaveAndItsReaction) {
  const double v0 = 10.0, c = wave_speed();
  Case cs = strip(160);  // 80 mm
  Boundary driver = face_boundary("driver", Boundary::Type::velocity, 0.0);
  driver.component = 0;
  driver.time = {0.0, 0.5e-6};
  driver.value = {0.0, v0};
  cs.boundaries.push_back(driver);
  test::add_probe(cs, "x50", 50e-3, kHeight / 2);
  cs.sim.end_time = 0.95 * 80e-3 / c;
  Simulation sim(cs);
  std::vector<double> t, vx, sxx, reaction;
  double worst_energy = 0;
  while (sim.time() < cs.sim.end_time * (1 - 1e-12) && !sim.failed()) {
    sim.step();
    t.push_back(sim.time());
    const ProbeRecord p = sim.probe_records()[0];
    vx.push_back(p.vx);
    sxx.push_back(p.sxx);
    reaction.push_back(sim.boundary_records()[0].fx);
    if (sim.steps() % 100 == 0) worst_energy = std::max(worst_energy, sim.history().energy.error);
  }
  ASSERT_FALSE(sim.failed()) << sim.failure();
  const double arrival = test::arrival_time(t, vx, 0.5 * v0);
  ASSERT_GT(arrival, 0);
  const double end = t.back();
  const double force = impedance() * v0 * kHeight * cs.sim.thickness;  // N
  EXPECT_NEAR(arrival, 50e-3 / c + 0.25e-6, 0.01 * 50e-3 / c);         // the ramp's midpoint
  EXPECT_NEAR(window_mean(t, vx, arrival + 9e-3 / c, end), v0, 0.01 * v0);
  EXPECT_NEAR(window_mean(t, sxx, arrival + 9e-3 / c, end), -impedance() * v0,
              0.01 * impedance() * v0);
  EXPECT_NEAR(window_mean(t, reaction, 2e-6, end), force, 0.01 * force);
  EXPECT_LT(worst_energy, 1e-4);
}

// Incident and transmitted bars of twice the specimen's impedance and `area_ratio` times its
// cross-section: with the force impedances K = Z A of bar and specimen, the face moves at
// v = 2 K_b v_I / (K_s + K_b), the bar reflects (K_s - K_b) / (K_s + K_b) of the incident
// stress, and the far bar carries 2 K_b / (K_s + K_b) of the specimen's force. Area ratio 10
// (D = Z A dt / M about 30 on the face: a stiff bar on a small face, as in most Hopkinson
// tests) leaves the face nearly at 2 v_I; it must neither ring nor leave the bar. Tolerance
// 1%, as above.
void expect_bars_as_theory(double area_ratio) {
  const double v_incident = 5.0, c = wave_speed(), zs = impedance(), zb = 2 * zs;
  const double length = 60e-3;
  Case cs = strip(120);
  const double face_area = kHeight * cs.sim.thickness;
  const double ks = zs * face_area, kb = zb * area_ratio * face_area;
  Boundary incident = face_boundary("incident", Boundary::Type::bar, 0.0);
  incident.direction = {1.0, 0.0};
  incident.impedance = zb;
  incident.area = area_ratio * face_area;
  incident.time = {0.0, 0.5e-6};
  incident.value = {0.0, v_incident};
  cs.boundaries.push_back(incident);
  Boundary transmitted = incident;
  transmitted.name = "transmitted";
  transmitted.direction = {-1.0, 0.0};
  transmitted.where.segment = test::segment(length, 0, length, kHeight);
  transmitted.time = {0.0};
  transmitted.value = {0.0};
  cs.boundaries.push_back(transmitted);
  test::add_probe(cs, "x30", 30e-3, kHeight / 2);
  cs.sim.end_time = 1.6 * length / c;  // before the far end's reflection returns
  Simulation sim(cs);
  std::vector<double> t, vx, face, reflected, far;
  double worst_energy = 0;
  while (sim.time() < cs.sim.end_time * (1 - 1e-12) && !sim.failed()) {
    sim.step();
    t.push_back(sim.time());
    vx.push_back(sim.probe_records()[0].vx);
    const auto b = sim.boundary_records();
    face.push_back(b[0].stress);
    reflected.push_back(b[0].reflected / b[0].incident);
    far.push_back(b[1].stress);
    if (sim.steps() % 100 == 0) worst_energy = std::max(worst_energy, sim.history().energy.error);
  }
  ASSERT_FALSE(sim.failed()) << sim.failure();
  const double end = t.back();
  const double v_face = 2 * kb / (ks + kb) * v_incident;
  const double bar_stress = zb * (2 * v_incident - v_face);
  const double far_stress = 2 * kb / (ks + kb) * ks * v_face / incident.area;
  EXPECT_NEAR(window_mean(t, face, 2e-6, end), bar_stress, 0.01 * bar_stress);
  EXPECT_NEAR(window_mean(t, reflected, 2e-6, end), (ks - kb) / (ks + kb), 0.01);
  const double arrival = test::arrival_time(t, vx, v_face / 2);
  ASSERT_GT(arrival, 0);
  // The probe until the far end's reflection passes it back (at 1.5 L / c).
  EXPECT_NEAR(window_mean(t, vx, arrival + 9e-3 / c, 1.45 * length / c), v_face, 0.01 * v_face);
  EXPECT_NEAR(window_mean(t, far, length / c + 9e-3 / c, end), far_stress, 0.01 * far_stress);
  EXPECT_LT(worst_energy, 1e-4);
  // No ringing: the face stress's scatter about its plateau (measured 1e-5).
  const double mean = window_mean(t, face, 2e-6, end);
  std::vector<double> square(t.size());
  for (size_t i = 0; i < t.size(); ++i) square[i] = (face[i] - mean) * (face[i] - mean);
  EXPECT_LT(std::sqrt(window_mean(t, square, 2e-6, end)), 1e-3 * bar_stress);
}

TEST(Boundaries, BarTransmitsAndReflectsAsOneDimensionalTheory) {
  expect_bars_as_theory(1.0);
}

TEST(Boundaries, StiffBarOnASmallFaceNeitherRingsNorLetsGo) {
  expect_bars_as_theory(10.0);
}

// A strip moving at v0 onto a push-only support at its left end: in contact for 2 L / c with
// the reaction rho c v0 A, then leaving at +v0. The lumped-mass chain's front disperses as it
// travels, so the release comes early and part of the energy stays behind as ringing: the
// deficits (contact time, rebound velocity) measured at 60, 120, 240, 480 cells are 1.5, 1.0,
// 0.65, 0.4% and 2.8, 1.9, 1.3, 0.9%, going to 0 with refinement. Asserted at 240 cells: the
// reaction plateau and the contact time within 1%, the rebound within 1.5%, and the rebound
// deficit smaller than at 120 cells (convergence to the exact answer).
struct Rebound {
  double plateau, force, release, contact_time, velocity;
};

Rebound strip_rebound(int columns, double v0) {
  const double c = wave_speed(), length = columns * kCell;
  Case cs = strip(columns);
  cs.bodies[0].initial_velocity = {-v0, 0.0};
  Boundary support = face_boundary("support", Boundary::Type::support, 0.0);
  support.direction = {1.0, 0.0};
  cs.boundaries.push_back(support);
  const double contact_time = 2 * length / c;
  cs.sim.end_time = contact_time + 6e-6;
  Simulation sim(cs);
  std::vector<double> t, reaction;
  double worst_energy = 0;
  while (sim.time() < cs.sim.end_time * (1 - 1e-12) && !sim.failed()) {
    sim.step();
    t.push_back(sim.time());
    reaction.push_back(sim.boundary_records()[0].fx);
    if (sim.steps() % 100 == 0) worst_energy = std::max(worst_energy, sim.history().energy.error);
  }
  EXPECT_LT(worst_energy, 1e-4);
  EXPECT_FALSE(sim.failed()) << sim.failure();
  const double force = impedance() * v0 * kHeight * cs.sim.thickness;
  // Release: the last sample at or above half the plateau force.
  double release = -1;
  for (size_t i = 0; i < t.size(); ++i)
    if (reaction[i] >= 0.5 * force) release = t[i];
  EXPECT_EQ(window_mean(t, reaction, contact_time + 2e-6, t.back()), 0.0);  // free again
  const HistoryRecord h = sim.history();
  return {window_mean(t, reaction, 2e-6, contact_time - 2e-6), force, release, contact_time,
          h.momentum_x / h.mass};
}

TEST(Boundaries, StripReboundsFromASupportAfterTwoTransitTimes) {
  const double v0 = 5.0;
  const Rebound fine = strip_rebound(240, v0), coarse = strip_rebound(120, v0);
  EXPECT_NEAR(fine.plateau, fine.force, 0.01 * fine.force);
  EXPECT_NEAR(fine.release, fine.contact_time, 0.01 * fine.contact_time);
  EXPECT_NEAR(fine.velocity, v0, 0.015 * v0);
  EXPECT_LT(std::fabs(fine.velocity - v0), std::fabs(coarse.velocity - v0));
}

}  // namespace
}  // namespace fracta
