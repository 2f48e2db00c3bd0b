// Stability at the extremes: the time-step bound, very fast impacts, a
// stiffness ratio of 10^4 across a contact, nu = 0 and nu = 0.49, and scale invariance from
// 1 um to 1 m cells. Each test states its tolerance and the reason.
// The 10^6-step elastic run is a spinning block (below): the free vibration of a squeezed
// block still drifts (a solver bug reported to the lead, not tested around).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "host/case.hpp"
#include "host/simulation.hpp"
#include "test_util.hpp"

namespace fracta {
namespace {

// A number for RecordProperty, with its significant digits.
std::string sci(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3e", x);
  return buf;
}

constexpr double kSteelE = 232e9, kSteelNu = 0.3, kSteelRho = 7800.0;  // the paper's plate

struct RunStats {
  double worst_error = 0.0;  // worst relative energy error seen at the checks
  double max_kinetic = 0.0;  // J, largest kinetic energy seen at the checks
  bool finite = true;        // every checked energy finite
};

// Advances until `steps` steps were taken (or the run failed), checking the energy balance
// every `every` steps (history() is also where an energy blow-up is detected).
RunStats run_steps(Simulation& sim, long steps, int every) {
  RunStats s;
  while (sim.steps() < steps && !sim.failed()) {
    sim.step();
    if (sim.steps() % every != 0) continue;
    const HistoryRecord h = sim.history();
    s.finite = s.finite && std::isfinite(h.energy.kinetic) && std::isfinite(h.energy.internal);
    s.worst_error = std::max(s.worst_error, h.energy.error);
    s.max_kinetic = std::max(s.max_kinetic, h.energy.kinetic);
  }
  return s;
}

// The paper's plate (cases/plate_fe.toml: 30 mm along the wave x 60 mm along the loaded edge,
// 10 mm thick, plane stress, elastic steel, 500 MPa for 3 us on the left edge), with cells
// coarsened from 0.9375 mm to `h` so that 10^5 steps take seconds.
Case paper_plate(double h, double nu = kSteelNu, Formulation f = Formulation::plane_stress) {
  const int nx = static_cast<int>(std::lround(0.03 / h));
  const int ny = static_cast<int>(std::lround(0.06 / h));
  Case c = test::rectangle_case(nx, ny, h, kSteelE, nu, kSteelRho, f);
  test::add_pressure(c, test::segment(0, 0, 0, 0.06), {0.0, 3e-6, 3e-6}, {500e6, 500e6, 0.0});
  c.sim.end_time = 1.0;  // the loops decide the length
  return c;
}

// y-momentum (kg m/s) of the nodes of body `body`.
double body_momentum_y(const Simulation& sim, int body) {
  const auto& range = sim.model().mesh.bodies[body];
  auto v = Kokkos::create_mirror_view_and_copy(HostSpace(), sim.model().nodes.v);
  auto mass = Kokkos::create_mirror_view_and_copy(HostSpace(), sim.model().nodes.mass);
  double p = 0;
  for (int n = range.node_begin; n < range.node_end; ++n) p += mass(n) * v(n, 1);
  return p;
}

// --- Time step -------------------------------------------------------------------------------

// dt_safety = 0.95 on the paper plate (3.75 mm cells: 8 x 16 elements) for 10^5 steps, with
// the default viscous hourglass control and bulk viscosity: no NaN, no failure, kinetic energy
// never above the work put in (1% slack for the O(dt^2) difference between the step-end
// kinetic energy and the energy the scheme conserves), and the energy balance closed to 1%
// (5% is allowed for impacts; the scheme's own error here is O(dt^2) per
// trapezoidal work term, with no drift).
TEST(Extremes, PaperPlateStableAtSafety095For1e5Steps) {
  Case c = paper_plate(3.75e-3);
  c.sim.dt_safety = 0.95;
  Simulation sim(c);
  const long steps = 100000;
  const RunStats s = run_steps(sim, steps, 100);
  ASSERT_FALSE(sim.failed()) << sim.failure();
  EXPECT_EQ(sim.steps(), steps);
  EXPECT_TRUE(s.finite);
  const HistoryRecord end = sim.history();
  EXPECT_GT(end.energy.external, 0.0);
  EXPECT_LT(s.max_kinetic, 1.01 * end.energy.external);
  EXPECT_LT(std::max(s.worst_error, end.energy.error), 0.01);
  RecordProperty("worst_energy_error", sci(s.worst_error));
  RecordProperty("max_kinetic_over_external", sci(s.max_kinetic / end.energy.external));
  RecordProperty("simulated_time", sci(sim.time()));
}

// Composite nodes (an FE/DE interface) take both element and bond forces, while the step is the
// smaller of the FE bound and the bond network's Gershgorin bound, each computed without the
// other. That is not a proof (the largest eigenvalue of the sum can exceed both), but both
// bounds are conservative on a mesh (the FE one by sqrt(2), see below), and at dt_safety = 1
// with bulk viscosity off the paper's coupled plates (cases A and B: 1024 elements beside
// discs, a full interface) run 39,000 steps with energy errors of 3e-6 and 1.3e-5. This test
// runs 5,000 of them: an unstable mode would grow exponentially and trip Simulation::failed().
TEST(Extremes, CoupledPlatesStableAtTheFullStep) {
  for (const char* name : {"plate_case_a", "plate_case_b"}) {
    Case c =
        load_case(std::string(FRACTA_SOURCE_DIR) + "/cases/" + name + ".toml",
                  {"simulation.dt_safety=1.0", "simulation.end_time=1.0",
                   "simulation.bulk_viscosity_linear=0", "simulation.bulk_viscosity_quadratic=0"});
    Simulation sim(c);
    const RunStats s = run_steps(sim, 5000, 50);
    ASSERT_FALSE(sim.failed()) << name << ": " << sim.failure();
    EXPECT_TRUE(s.finite) << name;
    EXPECT_LT(std::max(s.worst_error, sim.history().energy.error), 0.01) << name;
    RecordProperty(std::string("worst_energy_error_") + name, sci(s.worst_error));
  }
}

// How tight is the solver's bound dt = l / c, l = 1 / sqrt(sum b.b) = h / sqrt(2) for a square
// (Flanagan-Belytschko 1981; LS-DYNA's A / longest diagonal)? It bounds every element's largest
// frequency, so (Irons) the mesh's. Exact values for square one-point elements with lumped
// mass, bulk viscosity off (its damping would lower them):
//  - one free element: B B^T = diag(1, 1, 2) / h^2 (Voigt), the largest mode is dilatational,
//    omega^2 = 8 (lambda + mu) / (rho h^2) against the bound's 8 (lambda + 2 mu) / (rho h^2):
//    the critical step is sqrt((lambda + 2 mu) / (lambda + mu)) times the bound, that is
//    sqrt(2 / (1 + nu)) in plane stress and sqrt(2 (1 - nu)) in plane strain (1.00995 at
//    nu = 0.49: the bound is tight);
//  - a mesh: the Fourier symbol of the one-point gradient, a = (2/h) sin(kx h/2) cos(ky h/2),
//    b = (2/h) cos(kx h/2) sin(ky h/2), gives omega^2 <= 4 (lambda + 2 mu) / (rho h^2) for
//    every nu (checked on a 400 x 400 grid of wave numbers), reached by the axial zig-zag:
//    dt = h / c, sqrt(2) times the bound. A clamped mesh has at most that (its modes embed in
//    the infinite mesh); with 16 x 32 cells its highest mode is within 0.6% of it.
// Hourglass control does not enter: these modes are orthogonal to the hourglass vector. A run
// is "blown up" when Simulation::failed() (energy error above its limit, inverted element,
// non-finite energy), checked every 10 steps.
double element_critical_over_bound(double nu, Formulation f) {
  return f == Formulation::plane_stress ? std::sqrt(2.0 / (1.0 + nu)) : std::sqrt(2.0 * (1.0 - nu));
}

// Runs `steps` steps at a fixed dt = factor * (the solver's bound) * critical_over_bound;
// returns (failed, steps taken).
std::pair<bool, long> run_at_fixed_dt(Case c, double factor, double critical_over_bound,
                                      long steps) {
  c.sim.bulk_viscosity_linear = 0.0;
  c.sim.bulk_viscosity_quadratic = 0.0;
  c.sim.allow_unstable_dt = true;
  c.sim.dt = factor * critical_over_bound * Simulation(c).stable_dt_bound();
  Simulation sim(c);
  run_steps(sim, steps, 10);
  return {sim.failed(), sim.steps()};
}

// One element of the plate (3.75 mm, pulse on its left edge). Plane strain, nu = 0.49: 5% above
// the solver's bound blows up, 5% below runs 20,000 steps ("dt_safety 1.05 fails, 0.95 runs").
// Plane stress, nu = 0.3: the exact critical step is 1.240 times the bound; 2% above it blows
// up, 2% below it runs.
TEST(Extremes, SingleElementBlowsUpJustAboveItsCriticalStep) {
  const Case strain = paper_plate(3.75e-3, 0.49, Formulation::plane_strain);
  Case strain_one =
      test::rectangle_case(1, 1, 3.75e-3, kSteelE, 0.49, kSteelRho, Formulation::plane_strain);
  strain_one.loads = strain.loads;
  strain_one.sim.end_time = 1.0;
  const auto below_bound = run_at_fixed_dt(strain_one, 0.95, 1.0, 20000);
  EXPECT_FALSE(below_bound.first);
  EXPECT_EQ(below_bound.second, 20000);
  const auto above_bound = run_at_fixed_dt(strain_one, 1.05, 1.0, 2000);
  EXPECT_TRUE(above_bound.first);
  EXPECT_LT(above_bound.second, 2000);

  Case stress_one =
      test::rectangle_case(1, 1, 3.75e-3, kSteelE, kSteelNu, kSteelRho, Formulation::plane_stress);
  stress_one.loads = strain.loads;
  stress_one.sim.end_time = 1.0;
  const double ratio = element_critical_over_bound(kSteelNu, Formulation::plane_stress);
  const auto below = run_at_fixed_dt(stress_one, 0.98, ratio, 20000);
  EXPECT_FALSE(below.first);
  EXPECT_EQ(below.second, 20000);
  const auto above = run_at_fixed_dt(stress_one, 1.02, ratio, 2000);
  EXPECT_TRUE(above.first);
  EXPECT_LT(above.second, 2000);
  RecordProperty("steps_to_failure_nu049_at_1.05_bound", static_cast<int>(above_bound.second));
  RecordProperty("steps_to_failure_nu03_at_1.02_exact", static_cast<int>(above.second));
}

// The paper plate at 1.875 mm (16 x 32 cells), clamped on all edges, set moving at 1 m/s:
// the mesh's limit is the Courant step h / c = sqrt(2) times the solver's bound. 2% below it
// the run completes 5,000 steps; 2% above it it blows up within 1,000 steps. So on a mesh of
// squares the element bound is conservative by sqrt(2) (dt_safety slightly above 1 does NOT
// blow up a mesh: reported), while it is tight for a lone element (test above).
TEST(Extremes, ClampedPlateBlowsUpJustAboveTheCourantStep) {
  Case c = paper_plate(1.875e-3);
  c.loads.clear();
  c.bodies[0].initial_velocity = {1.0, 0.5};
  for (const auto& edge : {test::segment(0, 0, 0.03, 0), test::segment(0.03, 0, 0.03, 0.06),
                           test::segment(0, 0.06, 0.03, 0.06), test::segment(0, 0, 0, 0.06)})
    test::add_fixed(c, edge, Boundary::Type::fixed);
  const auto below = run_at_fixed_dt(c, 0.98, std::sqrt(2.0), 5000);
  EXPECT_FALSE(below.first);
  EXPECT_EQ(below.second, 5000);
  const auto above = run_at_fixed_dt(c, 1.02, std::sqrt(2.0), 1000);
  EXPECT_TRUE(above.first);
  EXPECT_LT(above.second, 1000);
  RecordProperty("steps_to_failure_at_1.02_courant", static_cast<int>(above.second));
}

// A fixed dt above the bound is refused at input (exit code 2 through the CLI: see
// Cli.FixedDtAboveStableBoundIsRefused in tests/host/test_cli.cpp, with a step 3x the bound).
// Here the edge: exactly the bound is accepted, one part in 10^6 above it is refused and the
// error names simulation.dt.
TEST(Extremes, FixedDtRefusedJustAboveTheBound) {
  Case c = paper_plate(3.75e-3);
  const double bound = Simulation(c).stable_dt_bound();
  c.sim.dt = bound;
  EXPECT_NO_THROW(Simulation{c});
  c.sim.dt = bound * (1 + 1e-6);
  try {
    Simulation sim(c);
    ADD_FAILURE() << "a fixed dt above the stable bound was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.key, "simulation.dt");
  }
}

// --- Impact at 2000 m/s ----------------------------------------------------------------------

// tests/physics/test_impact.cpp covers 50 to 2000 m/s for the adaptive slab with an FE
// projectile. Added here at 2000 m/s: a pure FE slab with an FE projectile (no conversion: the
// elements themselves take the distortion) and a rigid projectile into the adaptive slab.
// Each run reaches its end without NaN; the mass is exact (node masses never change); the
// momentum is conserved to 1e-9 of the projectile's (no load, no support: internal, contact
// and conversion forces cancel in pairs, round-off only); the energy balance closes within
// 5% (a fragmenting impact); the projectile lost at least 10% of its momentum (they met).
// Not asserted: penetration depth. With an FE slab (and the same with an FE slab under a rigid
// projectile) the projectile slips between the slab's surface discs once they spread by more
// than a cell: contact is disc-on-disc only (docs/physics.md 1.3), there is no node-to-segment
// contact, so an FE target is not impenetrable at this speed (reported to the lead).
TEST(Extremes, ImpactAt2000MetresPerSecondFeAndRigid) {
  const std::pair<BodyMethod, BodyMethod> pairs[] = {{BodyMethod::fe, BodyMethod::fe},
                                                     {BodyMethod::adaptive, BodyMethod::rigid}};
  for (const auto& [slab, projectile] : pairs) {
    const std::string label =
        std::string(to_string(slab)) + " slab, " + to_string(projectile) + " projectile";
    Simulation sim(test::impact_case(2000.0, slab, projectile));
    const HistoryRecord h0 = sim.history();
    const double worst = test::run_to_end(sim, 10);
    ASSERT_FALSE(sim.failed()) << label << ": " << sim.failure();
    const HistoryRecord end = sim.history();
    EXPECT_TRUE(std::isfinite(end.energy.kinetic) && std::isfinite(end.energy.internal)) << label;
    EXPECT_EQ(end.mass, h0.mass) << label;
    EXPECT_NEAR(end.momentum_y, h0.momentum_y, 1e-9 * std::fabs(h0.momentum_y)) << label;
    EXPECT_NEAR(end.momentum_x, h0.momentum_x, 1e-9 * std::fabs(h0.momentum_y)) << label;
    EXPECT_LT(std::max(worst, end.energy.error), 0.05) << label;
    const double p_projectile = body_momentum_y(sim, 1);
    EXPECT_LT(std::fabs(p_projectile), 0.9 * std::fabs(h0.momentum_y)) << label;
    const std::string key = std::string(to_string(slab)) + "_" + to_string(projectile);
    RecordProperty("energy_error_" + key, sci(std::max(worst, end.energy.error)));
    RecordProperty("projectile_momentum_left_" + key, sci(p_projectile / h0.momentum_y));
  }
}

// --- Stiffness ratio 10^4 across a contact ---------------------------------------------------

// Two free elastic FE blocks (same density, Young's moduli 200 GPa and 20 MPa) collide at
// 1 m/s, the stiff one striking the soft one and the reverse. The step is set by the stiff
// block, the contact by the soft one (series springs), so the contact lasts ~10^3 steps.
// Stable; linear momentum conserved to 1e-10 (pairwise forces, round-off only); energy balance
// closed within 0.1% (the contact work is trapezoidal, so only O(dt^2) remains: the FE-FE
// collision of test_rigid.cpp closes to 3e-5 at ratio 1); the struck block takes momentum.
struct StiffSoftResult {
  double worst_error, momentum_error, struck_momentum_fraction;
  bool failed;
  long touched;
};

StiffSoftResult stiff_soft_collision(double striker_E, double target_E) {
  const double h = 1e-3, v0 = 1.0;
  Case c = test::rectangle_case(8, 4, h, target_E, 0.3, kSteelRho, Formulation::plane_strain);
  c.bodies[0].name = "target";
  Material m = c.materials[0];
  m.name = "striker_material";
  m.youngs_modulus = striker_E;
  c.materials.push_back(m);
  Body s = c.bodies[0];
  s.name = "striker";
  s.material = m.name;
  s.material_index = 1;
  s.shape.x = 2e-3;
  s.shape.y = 4 * h + 1.1 * h;
  s.shape.width = 4e-3;
  s.shape.height = 4e-3;
  s.initial_velocity = {0.0, -v0};
  c.bodies.push_back(s);
  // Until the bodies separate: the contact lasts about 2 transits of the soft block
  // (c_soft = 59 m/s: 4 mm / 59 m/s = 70 us).
  c.sim.end_time = 400e-6;
  c.contact.damping_ratio = 0.0;
  c.contact.friction = 0.3;
  Simulation sim(c);
  const HistoryRecord h0 = sim.history();
  double worst = 0;
  long touched = 0;
  while (sim.time() < c.sim.end_time * (1 - 1e-12) && !sim.failed()) {
    sim.step();
    if (sim.steps() % 10 != 0) continue;
    const HistoryRecord hr = sim.history();
    worst = std::max(worst, hr.energy.error);
    touched = std::max(touched, hr.count.contacts);
  }
  const HistoryRecord end = sim.history();
  const double p_target = body_momentum_y(sim, 0);
  return {std::max(worst, end.energy.error),
          std::fabs(end.momentum_y - h0.momentum_y) / std::fabs(h0.momentum_y),
          p_target / h0.momentum_y, sim.failed(), touched};
}

// The main job's scene (cases/penetration.toml: steel projectile, adaptive, into an adaptive
// concrete slab, 1.667 mm cells, plane strain) with only the projectile's speed changed, 50 m/s
// to 10 km/s, to 40 us. Answers: conservation (mass exactly; the energy balance within 5 %, as
// for every fragmenting impact); bound: the step never below a tenth of its initial value (an
// element crushed or sheared by the impact converts when its length falls below 0.3 of its
// initial one, conversion_length_ratio, so it cannot drive the step down: with the projectile
// `fe` the 2000 m/s run stopped at 14 us with exit 3, its step at 0.12 of the initial, and the
// 5000 and 10000 m/s runs within 7 us). No tunnelling: no contact disc moves more than about
// half the contact skin in a step (the motion bound: 0.85 of half the skin at the speed of the
// search before the step; an impact can speed a disc up within the step, so 0.6 of the skin is
// asserted, measured here from the positions: at most 0.48). The projectile
// converts where it is crushed: none of its 180 elements at 50 m/s, more than half at 2000 m/s
// and above.
TEST(Extremes, MainJobSceneFromFiftyMetresPerSecondToTenKilometresPerSecond) {
  for (const double speed : {50.0, 500.0, 2000.0, 5000.0, 10000.0}) {
    SCOPED_TRACE(std::to_string(speed) + " m/s");
    const std::string velocity = "[0.0, " + std::to_string(-speed) + "]";
    Case c =
        load_case(std::string(FRACTA_SOURCE_DIR) + "/cases/penetration.toml",
                  {"simulation.end_time=40e-6", "body.projectile.initial_velocity=" + velocity});
    Simulation sim(c);
    const double dt0 = sim.dt(), mass0 = sim.history().mass;
    double dt_min = dt0, worst = 0.0, largest_move = 0.0;
    const double skin = sim.model().contacts->skin();
    const auto disc =
        Kokkos::create_mirror_view_and_copy(HostSpace(), sim.model().nodes.contact_disc);
    // Copies (a mirror of a host view would be the view itself).
    auto before = Kokkos::create_mirror(HostSpace(), sim.model().nodes.x);
    auto after = Kokkos::create_mirror(HostSpace(), sim.model().nodes.x);
    Kokkos::deep_copy(before, sim.model().nodes.x);
    while (sim.time() < c.sim.end_time * (1 - 1e-12) && !sim.failed()) {
      sim.step();
      Kokkos::deep_copy(after, sim.model().nodes.x);
      for (int n = 0; n < sim.model().nodes.count; ++n)
        if (disc(n))
          largest_move = std::max(
              largest_move, std::hypot(after(n, 0) - before(n, 0), after(n, 1) - before(n, 1)));
      Kokkos::deep_copy(before, after);
      // The last step may be shortened to land on end_time.
      if (sim.time() + sim.dt() < c.sim.end_time * (1 - 1e-12)) dt_min = std::min(dt_min, sim.dt());
      if (sim.steps() % 10 == 0) worst = std::max(worst, sim.history().energy.error);
    }
    ASSERT_FALSE(sim.failed()) << sim.failure();
    const HistoryRecord end = sim.history();
    worst = std::max(worst, end.energy.error);
    EXPECT_EQ(end.mass, mass0);
    EXPECT_LT(worst, 0.05);
    EXPECT_GT(dt_min, 0.1 * dt0);
    EXPECT_LE(largest_move, 0.6 * skin);
    const BodyRange& projectile = sim.model().mesh.bodies[1];
    const int projectile_cells = projectile.element_end - projectile.element_begin;
    auto alive = Kokkos::create_mirror_view_and_copy(HostSpace(), sim.model().elements.alive);
    int intact = 0;
    for (int e = projectile.element_begin; e < projectile.element_end; ++e) intact += alive(e);
    if (speed <= 50.0) {
      EXPECT_EQ(intact, projectile_cells);
    }
    if (speed >= 2000.0) {
      EXPECT_LT(intact, projectile_cells / 2);
    }
    std::printf(
        "%6.0f m/s: %ld steps, smallest step %.3f of the initial, largest disc move in a "
        "step %.2f skins, energy error %.4f, projectile elements left %d of %d, "
        "conversions %ld\n",
        speed, sim.steps(), dt_min / dt0, largest_move / skin, worst, intact, projectile_cells,
        sim.conversions());
  }
}

TEST(Extremes, StiffnessRatio1e4AcrossContact) {
  for (const auto& [striker, target] : {std::make_pair(200e9, 20e6), std::make_pair(20e6, 200e9)}) {
    const StiffSoftResult r = stiff_soft_collision(striker, target);
    const std::string label = striker > target ? "stiff on soft" : "soft on stiff";
    EXPECT_FALSE(r.failed) << label;
    EXPECT_GT(r.touched, 0) << label;
    EXPECT_LT(r.momentum_error, 1e-10) << label;
    EXPECT_LT(r.worst_error, 1e-3) << label;
    EXPECT_GT(r.struck_momentum_fraction, 0.1) << label;
    RecordProperty(
        "energy_error_" + std::string(striker > target ? "stiff_on_soft" : "soft_on_stiff"),
        sci(r.worst_error));
  }
}

// --- nu = 0 and nu = 0.49 --------------------------------------------------------------------

// The plane wave of test_plane_wave.cpp at nu = 0 and nu = 0.49, plane strain and plane
// stress: the dilatational speed and the particle velocity behind the front within 1% of the
// analytic values (in this 1D-strain setting the one-point Q4 front's dispersion depends on the
// Courant number only, not on nu: the same 1% as at nu = 0.3); no locking (the speed would be
// too high) and no blow-up: the energy balance closes to 0.1% at the end (O(dt^2); the worst
// step is the first one, where the step load meets bulk viscosity switching on within a single
// step: ~1.7% of the tiny work done then, reported) and the hourglass work stays below 0.1% of
// the work put in.
TEST(Extremes, DilatationalWaveAtNuZeroAndNearlyIncompressible) {
  for (const Formulation f : {Formulation::plane_strain, Formulation::plane_stress})
    for (const double nu : {0.0, 0.49}) {
      const test::PlaneWaveResult r = test::run_plane_wave(f, BodyMethod::fe, nu);
      const std::string label = std::string(to_string(f)) + " nu " + std::to_string(nu);
      EXPECT_NEAR(r.speed, r.c_exact, 0.01 * r.c_exact) << label;
      EXPECT_NEAR(r.plateau, r.v_exact, 0.01 * r.v_exact) << label;
      EXPECT_LT(r.final_energy_error, 1e-3) << label;
      EXPECT_LT(std::fabs(r.hourglass_fraction), 1e-3) << label;
      const std::string key = std::string(to_string(f)) + (nu > 0 ? "_nu049" : "_nu0");
      RecordProperty("speed_error_" + key, sci(r.speed / r.c_exact - 1));
      RecordProperty("plateau_error_" + key, sci(r.plateau / r.v_exact - 1));
      RecordProperty("worst_energy_error_" + key, sci(r.worst_energy_error));
      RecordProperty("final_energy_error_" + key, sci(r.final_energy_error));
    }
}

// The plane wave excites no hourglass mode (it is uniform across the strip). A 2D load does:
// a 500 MPa, 2 us pressure on the lower half of the left edge of a free 16 x 16 block, run for
// three transit times. At nu = 0 and nu = 0.49, plane strain and plane stress: no failure,
// the energy balance within 0.1% at the end (O(dt^2); as for the plane wave the worst step is
// the first, reported), and the hourglass work below 5% of the work put in (it resists only
// the spurious modes; a hourglassing mesh would need far more).
TEST(Extremes, NoHourglassBlowUpAtNuZeroAndNearlyIncompressible) {
  for (const Formulation f : {Formulation::plane_strain, Formulation::plane_stress})
    for (const double nu : {0.0, 0.49}) {
      const double h = 1e-3;
      Case c = test::rectangle_case(16, 16, h, kSteelE, nu, kSteelRho, f);
      test::add_pressure(c, test::segment(0, 0, 0, 8 * h), {0.0, 2e-6, 2e-6}, {500e6, 500e6, 0.0});
      const double c_p = std::sqrt(kSteelE / kSteelRho);  // a speed scale for the run length
      c.sim.end_time = 3 * 16 * h / c_p;
      Simulation sim(c);
      const double worst = test::run_to_end(sim);
      const std::string label = std::string(to_string(f)) + " nu " + std::to_string(nu);
      ASSERT_FALSE(sim.failed()) << label << ": " << sim.failure();
      const HistoryRecord end = sim.history();
      EXPECT_LT(end.energy.error, 1e-3) << label;
      EXPECT_LT(end.energy.hourglass, 0.05 * end.energy.external) << label;
      const std::string key = std::string(to_string(f)) + (nu > 0 ? "_nu049" : "_nu0");
      RecordProperty("worst_energy_error_" + key, sci(worst));
      RecordProperty("final_energy_error_" + key, sci(end.energy.error));
      RecordProperty("hourglass_fraction_" + key, sci(end.energy.hourglass / end.energy.external));
    }
}

// --- Scale invariance ------------------------------------------------------------------------

// Normalised histories of one run: per step, time / length_scale, probe velocities / v0 and
// energies / initial kinetic energy.
struct Normalised {
  std::vector<std::vector<double>> rows;
};

Normalised normalised_run(const Case& c, double length_scale, double v0, long steps) {
  Simulation sim(c);
  const double e0 = sim.history().energy.kinetic;
  Normalised out;
  while (sim.steps() < steps && !sim.failed()) {
    sim.step();
    const HistoryRecord h = sim.history();
    std::vector<double> row{sim.time() / length_scale, h.energy.kinetic / e0,
                            h.energy.internal / e0,    h.energy.plastic / e0,
                            h.energy.hourglass / e0,   h.energy.viscous / e0,
                            h.energy.contact / e0,     h.energy.external / e0};
    for (const ProbeRecord& p : sim.probe_records()) {
      row.push_back(p.vx / v0);
      row.push_back(p.vy / v0);
    }
    out.rows.push_back(row);
  }
  EXPECT_FALSE(sim.failed()) << sim.failure();
  return out;
}

// Largest difference between two normalised histories, column by column relative to the
// column's largest magnitude.
double largest_relative_difference(const Normalised& a, const Normalised& b) {
  EXPECT_EQ(a.rows.size(), b.rows.size());
  const size_t n = std::min(a.rows.size(), b.rows.size());
  if (n == 0) return 1.0;
  double worst = 0;
  for (size_t k = 0; k < a.rows[0].size(); ++k) {
    double scale = 0, diff = 0;
    for (size_t i = 0; i < n; ++i) {
      scale = std::max({scale, std::fabs(a.rows[i][k]), std::fabs(b.rows[i][k])});
      diff = std::max(diff, std::fabs(a.rows[i][k] - b.rows[i][k]));
    }
    if (scale > 0) worst = std::max(worst, diff / scale);
  }
  return worst;
}

// The impact scene with an FE slab (Mohr-Coulomb) and an FE projectile (bilinear J2) at
// 200 m/s (contact with damping and friction, both plasticity models, bulk viscosity,
// hourglass control) with 1 um and 1 m cells: every length and time scaled, stresses and
// speeds unchanged. The equations are invariant, so the normalised probe velocities and
// energies must agree; the two scales round differently (~1e-16 per operation), which the
// plastic and contact nonlinearity amplify over the 120 steps to 2.3e-10 (measured, the same
// in repeated runs with 2 threads; 4e-13 with one thread through the CLI): 1e-9 leaves a
// margin of 4 and still fails at once on any absolute length, time or velocity in the solver
// (an error of order 1 at one of the two scales). Not the adaptive slab: its bond breakage turns
// the non-deterministic order of the atomic sums with 2 threads into percent-level differences
// between two runs at the SAME scale (measured: 1e-2 in the energies, 11% in the conversion count),
// while one thread gives scale invariance to 2e-13 there too (checked with the CLI, reported).
TEST(Extremes, ScaleInvarianceFromMicrometreToMetreCells) {
  const double v0 = 200.0, h_ref = 3.333e-3;
  const long steps = 120;
  std::vector<Normalised> runs;
  for (const double s : {1e-6 / h_ref, 1.0 / h_ref}) {
    Case c = test::impact_case(v0, BodyMethod::fe, BodyMethod::fe, s);
    test::add_probe(c, "slab_top", 0.04 * s, 9 * h_ref * s);
    test::add_probe(c, "slab_bottom", 0.04 * s, 0.0);
    test::add_probe(c, "projectile", 0.04 * s, (10.2 * h_ref + 0.0125) * s);
    c.sim.end_time = 1e300;  // the step count decides
    runs.push_back(normalised_run(c, s, v0, steps));
  }
  ASSERT_EQ(runs[0].rows.size(), static_cast<size_t>(steps));
  const double diff = largest_relative_difference(runs[0], runs[1]);
  EXPECT_LT(diff, 1e-9);
  RecordProperty("largest_relative_difference", sci(diff));
}

// --- 10^6 steps ------------------------------------------------------------------------------

// A free 2 x 2 element steel block (1 mm cells, plane strain, default hourglass control and bulk
// viscosity) set spinning at 7000 rad/s (rim speed ~10 m/s) for 10^6 steps (0.1 s, ~110
// turns): the centrifugal load appears suddenly, so the block vibrates while it turns, and
// every step rotates its stresses (Jaumann) and its geometry. The total energy (kinetic +
// strain + the hourglass and viscous work) must stay within 1% of its value after the first
// step, checked every 10^4 steps. Before the fix in fe_forces.hpp (strain
// increment added in the mid-step frame) this block gained 200 times its energy by 1.5 10^5
// steps (measured with bulk viscosity off; with the stiffness hourglass form or 2 x 2
// integration it inverted): adding the increment in a frame turned by half a step is a
// circulatory coupling of the element's two deviatoric modes, unstable at a rate
// ~ omega c dt / h. Measured drift now: 1.2e-7.
TEST(Extremes, MillionStepSpinningBlockEnergyDrift) {
  const double h = 1e-3, omega = 7000.0;
  Case c = test::rectangle_case(2, 2, h, 200e9, 0.3, kSteelRho, Formulation::plane_strain);
  c.sim.end_time = 1.0;                               // the step count decides
  c.sim.dt = 0.85 * Simulation(c).stable_dt_bound();  // uniform steps
  // The spin is set after construction, so the solver's own balance (referred to the state at
  // construction) does not apply: this test measures the drift itself, below.
  c.sim.energy_error_limit = 1e300;
  Simulation sim(c);
  {
    auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), sim.model().nodes.x);
    auto v = Kokkos::create_mirror_view_and_copy(HostSpace(), sim.model().nodes.v);
    for (int n = 0; n < sim.model().nodes.count; ++n) {  // v = omega x (x - centre)
      v(n, 0) = -omega * (x(n, 1) - h);
      v(n, 1) = omega * (x(n, 0) - h);
    }
    Kokkos::deep_copy(sim.model().nodes.v, v);
  }
  auto total = [](const HistoryRecord& r) {
    return r.energy.kinetic + r.energy.time_discretization + r.energy.internal +
           r.energy.hourglass + r.energy.viscous;
  };
  sim.step();
  const double e_ref = total(sim.history());
  const long steps = 1000000;
  double drift = 0.0;
  while (sim.steps() < steps && !sim.failed()) {
    sim.step();
    if (sim.steps() % 10000 == 0)
      drift = std::max(drift, std::fabs(total(sim.history()) - e_ref) / e_ref);
  }
  ASSERT_FALSE(sim.failed()) << sim.failure();
  EXPECT_EQ(sim.steps(), steps);
  EXPECT_LT(drift, 0.01);
  const double turns = omega * sim.time() / (2 * M_PI);
  EXPECT_GT(turns, 100.0);
  RecordProperty("energy_drift", sci(drift));
  RecordProperty("turns", sci(turns));
}

}  // namespace
}  // namespace fracta
