// A straight mode-I crack driven at a known energy release rate (cases/validation/
// crack_speed_h1e-4.toml; docs/validation.md, "Mode-I crack speed"): a glass-like cohesive `de`
// plate (E 72 GPa, nu 0.22, sigma_t 30 MPa, G_c 3.8 J/m^2, plane strain, 0.1 mm cells) with a
// 16 mm pre-crack whose faces carry a suddenly applied pressure p: Freund's semi-infinite crack,
//   K(t) = 2 p sqrt(c_d t (1 - 2 nu) / pi) / (1 - nu),   G(t) = K(t)^2 (1 - nu^2) / E,
// until waves return from the plate's edges (about 4 us). Exact-answer and conservation tests:
// - energy: a running crack dissipates G_c per unit area at any speed (Griffith; the cohesive
//   law's G_c), checked as the slope of the fracture energy over the crack advance while it
//   runs, at p = 6 MPa (about 0.9 km/s) and 15 MPa (about 1.5 km/s): within 5 %;
// - initiation: softening cannot start after G reaches G_c, and the first bond cannot break
//   before (t_soft <= t_i <= t_break, t_i the LEFM time at which G(t) = G_c);
// - speed: below c_R, and below Freund's bound c_R (1 - G_c / G(t)), since the unloaded new
//   faces only lower the energy release rate of the moving tip;
// - path: mode I by symmetry, so no bond off the crack plane breaks;
// - resolution: sigma_t = 20 MPa gives a process zone E* G_c / sigma_t^2 = 0.72 mm, 7 cells;
//   100 MPa gives 0.03 mm, under the 4 cells a crack needs: it is reported and the strength
//   capped, and the crack then dissipates G_c and runs as the resolved one (it did not start at
//   all before the cap).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "host/case.hpp"
#include "host/simulation.hpp"

namespace fracta {
namespace {

constexpr double kE = 72e9, kNu = 0.22, kRho = 2440.0, kGc = 3.8;
constexpr double kCrackLine = 12e-3, kPreCrack = 16e-3;  // the node row below the crack plane
constexpr double kRayleigh = 3180.0;                     // m/s, plane-strain c_R of the glass

double dilatational_speed() {
  return std::sqrt(kE * (1 - kNu) / ((1 + kNu) * (1 - 2 * kNu) * kRho));
}

// Freund's G(t) / G_c of the stationary crack, at pressure p (Pa).
double release_ratio(double p, double t) {
  const double k = 2 * p * std::sqrt(dilatational_speed() * t * (1 - 2 * kNu) / M_PI) / (1 - kNu);
  return k * k * (1 - kNu * kNu) / kE / kGc;
}

struct CrackSample {
  double t, tip, fracture;  // s, crack advance of the broken bonds (m), fracture energy (J)
  bool advanced = false;    // taken at the step the broken tip reached a new cell
};

struct CrackRun {
  std::vector<CrackSample> samples;
  double t_soften = -1, t_break = -1;
  int off_plane_broken = 0;
  std::vector<std::string> notes;
  double thickness = 1, h = 0;
};

// Runs the case at face pressure p (Pa), tensile strength sigma_t (Pa) and end time (s), sampling
// every 0.2 us and at every step in which a bond broke: the crack advance (the largest x of a
// broken bond across the plane, less the pre-crack), the fracture energy, and when the first
// bond began to soften and broke.
CrackRun run_crack(double p, double sigma_t, double end_time) {
  Case c = load_case(std::string(FRACTA_SOURCE_DIR) + "/cases/validation/crack_speed_h1e-4.toml");
  for (Load& l : c.loads) l.value = {p};
  c.materials[0].tensile_strength = sigma_t;
  c.sim.end_time = end_time;
  Simulation sim(c);
  CrackRun r;
  r.notes = sim.model().notes;
  r.thickness = c.sim.thickness;
  r.h = c.bodies[0].cell_size;
  const double tol = 0.25 * r.h;
  double next_sample = 0.0, last_tip = kPreCrack;
  long broken = 0;
  while (sim.time() < c.sim.end_time * (1 - 1e-12) && !sim.failed()) {
    sim.step();
    const HistoryRecord h = sim.history();
    if (r.t_soften < 0 && h.energy.fracture > 0) r.t_soften = sim.time();
    if (r.t_break < 0 && h.count.broken_bonds > 0) r.t_break = sim.time();
    const bool broke = h.count.broken_bonds != broken;
    broken = h.count.broken_bonds;
    if (sim.time() + 1e-12 < next_sample && !broke) continue;
    if (sim.time() + 1e-12 >= next_sample) next_sample += 0.2e-6;
    const Model& m = sim.model();
    const auto state = Kokkos::create_mirror_view_and_copy(HostSpace(), m.bonds.state);
    const auto ends = Kokkos::create_mirror_view_and_copy(HostSpace(), m.bonds.nodes);
    const auto x0 = Kokkos::create_mirror_view_and_copy(HostSpace(), m.nodes.x0);
    double tip = kPreCrack;
    int off_plane = 0;
    for (int b = 0; b < m.bonds.count; ++b) {
      if (state(b) != kBondBroken) continue;
      const int i = ends(b, 0), j = ends(b, 1);
      const double y_low = std::min(x0(i, 1), x0(j, 1)), y_high = std::max(x0(i, 1), x0(j, 1));
      const bool across =
          std::fabs(y_low - kCrackLine) < tol && std::fabs(y_high - kCrackLine - r.h) < tol;
      if (!across) {
        ++off_plane;
        continue;
      }
      if (std::fabs(x0(i, 0) - x0(j, 0)) < tol) tip = std::max(tip, x0(i, 0));
    }
    r.off_plane_broken = off_plane;
    r.samples.push_back({sim.time(), tip - kPreCrack, h.energy.fracture, tip > last_tip});
    last_tip = tip;
  }
  EXPECT_FALSE(sim.failed()) << sim.failure();
  return r;
}

// Fracture energy per unit crack area while the crack runs (advance beyond two cells): the
// least-squares slope of the fracture energy over the advance, per thickness (J/m^2), from the
// samples taken when the broken tip reaches a new cell. (The tip moves cell by cell while the
// energy grows smoothly; samples at fixed times caught the staircase at a phase that moved with
// the time step: 3.64 and 4.03 J/m^2 at dt_safety 0.85 with stable bounds 5 % apart.)
double dissipation_per_area(const CrackRun& r) {
  double n = 0, sa = 0, se = 0, saa = 0, sae = 0;
  for (const CrackSample& s : r.samples)
    if (s.advanced && s.tip > 2 * r.h) {
      n += 1;
      sa += s.tip;
      se += s.fracture;
      saa += s.tip * s.tip;
      sae += s.tip * s.fracture;
    }
  if (n < 3) return NAN;
  return (n * sae - sa * se) / (n * saa - sa * sa) / r.thickness;
}

// Mean speed of the broken tip over the last microsecond (m/s).
double late_speed(const CrackRun& r) {
  const CrackSample& end = r.samples.back();
  for (const CrackSample& s : r.samples)
    if (s.t >= end.t - 1e-6 - 1e-12) return (end.tip - s.tip) / (end.t - s.t);
  return NAN;
}

// The same from the energy-equivalent crack length a_E = fracture energy / (G_c thickness), which
// counts the process zone by what it has dissipated and moves smoothly (m/s).
double late_energy_speed(const CrackRun& r) {
  const CrackSample& end = r.samples.back();
  for (const CrackSample& s : r.samples)
    if (s.t >= end.t - 1e-6 - 1e-12)
      return (end.fracture - s.fracture) / (kGc * r.thickness) / (end.t - s.t);
  return NAN;
}

void expect_crack_follows_lefm(const CrackRun& r, double p) {
  ASSERT_GE(r.samples.size(), 10u);
  const double toughness_squared = kGc * kE / (1 - kNu * kNu);  // K_c^2
  const double t_initiation = M_PI * toughness_squared * (1 - kNu) * (1 - kNu) /
                              (4 * p * p * dilatational_speed() * (1 - 2 * kNu));
  EXPECT_NEAR(release_ratio(p, t_initiation), 1.0, 1e-12);
  EXPECT_GT(r.t_soften, 0);
  EXPECT_LE(r.t_soften, t_initiation);
  EXPECT_GE(r.t_break, t_initiation);
  const double g = dissipation_per_area(r);
  EXPECT_NEAR(g, kGc, 0.05 * kGc);
  const double end = r.samples.back().t, v = late_speed(r);
  EXPECT_GT(v, 0);
  EXPECT_LT(v, kRayleigh * (1 - 1 / release_ratio(p, end)));
  EXPECT_EQ(r.off_plane_broken, 0);
  ::testing::Test::RecordProperty("dissipation_per_area", std::to_string(g));
  ::testing::Test::RecordProperty("late_speed", std::to_string(v));
  ::testing::Test::RecordProperty("t_soften_us", std::to_string(r.t_soften * 1e6));
  ::testing::Test::RecordProperty("t_break_us", std::to_string(r.t_break * 1e6));
  ::testing::Test::RecordProperty("t_lefm_us", std::to_string(t_initiation * 1e6));
}

TEST(CrackGrowth, ModeICrackDissipatesTheFractureEnergyAndObeysFreund) {
  const CrackRun r = run_crack(6e6, 20e6, 4e-6);
  EXPECT_TRUE(r.notes.empty());
  expect_crack_follows_lefm(r, 6e6);
}

TEST(CrackGrowth, FastModeICrackDissipatesTheFractureEnergy) {
  const double p = 15e6;
  const CrackRun r = run_crack(p, 20e6, 3e-6);
  EXPECT_TRUE(r.notes.empty());
  expect_crack_follows_lefm(r, p);
}

// LEFM's equation of motion holds G_c, not the strength: once the process zone is small beside
// the crack, the crack runs as fast at 100 MPa as at 20 MPa. Tolerance 10% on the speed of the
// energy-equivalent length over the last microsecond (the broken tip moves cell by cell, 0.1 mm
// per step of its history, too coarse for 10%). Before the strength cap the 100 MPa crack did
// not start at all by 4 us.
TEST(CrackGrowth, UnderResolvedProcessZoneIsReportedAndRunsAsTheResolvedOne) {
  const CrackRun r = run_crack(6e6, 100e6, 4e-6), resolved = run_crack(6e6, 20e6, 4e-6);
  ASSERT_EQ(r.notes.size(), 1u);
  EXPECT_NE(r.notes[0].find("bond tensile strength capped"), std::string::npos) << r.notes[0];
  EXPECT_NEAR(dissipation_per_area(r), kGc, 0.05 * kGc);
  EXPECT_EQ(r.off_plane_broken, 0);
  const double v = late_energy_speed(r), v_resolved = late_energy_speed(resolved);
  EXPECT_NEAR(v, v_resolved, 0.10 * v_resolved);
  ::testing::Test::RecordProperty("late_speed", std::to_string(v));
  ::testing::Test::RecordProperty("late_speed_resolved", std::to_string(v_resolved));
}

}  // namespace
}  // namespace fracta
