// The bonded lattice in motion: energy conservation, tensile failure at the material strength
// (docs/physics.md 1.2 calibration), and the energy balance through breakage.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "host/simulation.hpp"
#include "test_util.hpp"

namespace fracta {
namespace {

// An elastic lattice plate hit by a 3 us pulse then ringing freely for 20,000 steps: discs
// and bonds have no damping at all, so the balance (translational + rotational kinetic, bond
// energy, external work, central-difference term) must close to 0.5% (an O(dt^2)
// shadow-energy error, bounded, as for FE: EnergyBalance.*).
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

// A `de` plate of 16 x 32 cells of 1.875 mm in plane strain, hit on its left edge by a 3 us
// pulse of `pressure` (Pa), then ringing freely for 20,000 steps at the full stable step
// (dt_safety = 1: the Gershgorin bound itself, docs/physics.md 1.4): the worst energy error,
// checked every 100 steps.
double worst_error_at_the_full_step(double E, double nu, double rho, double pressure) {
  const double h = 1.875e-3;
  Case c = test::rectangle_case(16, 32, h, E, nu, rho, Formulation::plane_strain);
  c.bodies[0].method = BodyMethod::de;
  test::add_pressure(c, test::segment(0, 0, 0, 32 * h), {0.0, 3e-6, 3e-6},
                     {pressure, pressure, 0.0});
  c.sim.end_time = 1.0;
  c.sim.dt_safety = 1.0;
  Simulation sim(c);
  double worst = 0.0;
  while (sim.steps() < 20000 && !sim.failed()) {
    sim.step();
    if (sim.steps() % 100 == 0) worst = std::max(worst, sim.history().energy.error);
  }
  EXPECT_FALSE(sim.failed()) << sim.failure();
  EXPECT_GT(sim.history().energy.external, 0.0);
  return worst;
}

// At the full stable step the lattice, with its rotations, stays stable: 20,000 steps of free
// ringing keep the balance within the same 0.5% (an unstable mode would grow exponentially and
// blow it up).
TEST(LatticeEnergy, StableAtTheFullGershgorinStep) {
  EXPECT_LT(worst_error_at_the_full_step(92e9, 0.21, 2400.0, 100e6), 0.005);
}

// Beyond the pair lattice's Poisson limit (docs/physics.md 1.2): steel in plane strain (nu = 0.3,
// nu* = 0.43) and a nearly incompressible solid (nu = 0.45 in plane strain, nu* = 0.82), whose
// intact cells carry the volumetric term (cell_forces.hpp), ring freely for 20,000 steps at the
// full stable step (dt_safety = 1: the Gershgorin bound with the cell term counted on the
// diagonals, stable_dt.hpp). Answer: conservation, the balance within 0.5 % as above; an
// unstable mode, or a cell term the bound underrates, would blow it up.
TEST(LatticeEnergy, CellTermConservesEnergyAtTheFullStep) {
  for (const double nu : {0.3, 0.45}) {
    const double worst = worst_error_at_the_full_step(232e9, nu, 7800.0, 500e6);
    EXPECT_LT(worst, 0.005) << "nu " << nu;
    RecordProperty("worst_energy_error_nu_" + std::to_string(nu), std::to_string(worst));
  }
}

// A lattice block of brittle material pulled by a slowly ramped traction on its right edge
// (left edge on rollers): it must fail when the applied stress reaches the tensile strength.
// The ramp takes ~100 wave transits to reach sigma_t, so dynamic overshoot is ~1%; the
// tolerance is 5%, for the overshoot and the boundary cells' nonuniform stress.
struct TensionRun {
  double failure_stress = 0, worst_error = 0, fracture = 0;
  double first_fracture = 0;  // the fracture term at the step of the first break (J)
  long broken = 0;
  double weakest = 1;  // the smallest applied stress over sigma_t at which a bond reaches its own
};

// With weibull_modulus m > 0 the bonds draw strength factors w (unit mean): under uniaxial
// tension sigma along x, a horizontal edge bond (face normal x) sees sigma_n = sigma and a
// diagonal sigma / 2, a vertical edge none, so the first bond reaches its strength at
// sigma = sigma_t min(min over horizontal edges of w, 2 min over diagonals of w).
double weakest_bond(const Model& model) {
  const auto scale = Kokkos::create_mirror_view_and_copy(HostSpace(), model.bonds.strength_scale);
  const auto ends = Kokkos::create_mirror_view_and_copy(HostSpace(), model.bonds.nodes);
  const auto x0 = Kokkos::create_mirror_view_and_copy(HostSpace(), model.nodes.x0);
  double weakest = 1e300;
  for (int b = 0; b < model.bonds.count; ++b) {
    const double dx = x0(ends(b, 1), 0) - x0(ends(b, 0), 0);
    const double dy = x0(ends(b, 1), 1) - x0(ends(b, 0), 1);
    if (std::fabs(dx) > 1e-9 && std::fabs(dy) > 1e-9)  // a diagonal
      weakest = std::min(weakest, 2.0 * scale(b));
    else if (std::fabs(dy) < 1e-9)
      weakest = std::min(weakest, scale(b));
  }
  return weakest;
}

TensionRun run_tension(Formulation f, double nu, double weibull_modulus = 0) {
  const double h = 1e-3, E = 92e9, rho = 2400.0, sigma_t = 2.3e6;
  const int nx = 20, ny = 10;
  Case c = test::rectangle_case(nx, ny, h, E, nu, rho, f);
  c.bodies[0].method = BodyMethod::de;
  c.materials[0].tensile_strength = sigma_t;
  c.materials[0].weibull_modulus = weibull_modulus;
  c.sim.seed = 11;
  const double c_wave = std::sqrt(E / rho);
  const double ramp = 100 * nx * h / c_wave * 2.0;  // time to reach 2 sigma_t
  test::add_pressure(c, test::segment(nx * h, 0, nx * h, ny * h), {0.0, ramp},
                     {0.0, -2.0 * sigma_t});
  test::add_fixed(c, test::segment(0, 0, 0, ny * h), Boundary::Type::fixed_x);
  c.sim.end_time = 0.75 * ramp;  // past failure (at ramp / 2), into fragment motion
  Simulation sim(c);
  TensionRun r;
  r.failure_stress = -1;
  if (weibull_modulus > 0) r.weakest = weakest_bond(sim.model());
  while (sim.time() < c.sim.end_time * (1 - 1e-12) && !sim.failed()) {
    sim.step();
    const HistoryRecord hr = sim.history();
    r.worst_error = std::max(r.worst_error, hr.energy.error);
    if (r.failure_stress < 0 && hr.count.broken_bonds > 0) {
      r.failure_stress = 2.0 * sigma_t * sim.time() / ramp;
      r.first_fracture = hr.energy.fracture;
    }
  }
  EXPECT_FALSE(sim.failed());
  const HistoryRecord end = sim.history();
  // The frame's fragment statistics: the block broke into pieces whose masses add up to the
  // total mass (1e-12: round-off of the sums).
  const FrameData frame = sim.frame({});
  EXPECT_GE(frame.fragment_mass.size(), 2u);
  double fragments_mass = 0;
  for (double m : frame.fragment_mass) fragments_mass += m;
  EXPECT_NEAR(fragments_mass, end.mass, 1e-12 * end.mass);
  r.fracture = end.energy.fracture;
  r.broken = end.count.broken_bonds;
  return r;
}

TEST(LatticeFailure, UniaxialTensionFailsAtTensileStrength) {
  // nu = 0.3 in plane strain and 0.4 in plane stress: beyond the pair lattice's limit, with the
  // volumetric cell term, whose energy a cracked cell releases into the fracture term. There the
  // fracture term must be positive when the first bonds break; over the whole run it may end
  // negative (measured -2.6e-5 J at nu = 0.4, and -1.5e-4 J with pair springs alone at nu = 1/3):
  // a bond that breaks while its discs overlap hands 1/2 k_c delta^2 to the contact, which is
  // stiffer than the bond, and the strong Poisson contraction of these lattices makes the
  // overlaps of the fragments' bonds large. The balance closes either way. nu = 0: the diagonals
  // have no spring (k2 = 0); the block must still come apart into fragments (it stayed one while
  // those slots, carrying nothing, never broke).
  for (auto [f, nu] :
       {std::pair{Formulation::plane_stress, 0.0}, std::pair{Formulation::plane_stress, 0.21},
        std::pair{Formulation::plane_strain, 0.21}, std::pair{Formulation::plane_strain, 0.3},
        std::pair{Formulation::plane_stress, 0.4}}) {
    const std::string label = std::string(to_string(f)) + "_nu_" + std::to_string(nu);
    const TensionRun r = run_tension(f, nu);
    EXPECT_NEAR(r.failure_stress, 2.3e6, 0.05 * 2.3e6) << label;
    EXPECT_GT(r.broken, 0) << label;
    EXPECT_GT(r.first_fracture, 0.0) << label;
    if (nu < 0.25) {
      EXPECT_GT(r.fracture, 0.0) << label;
    }
    // The balance with fracture energy closes within 1% through the breakage (measured 3e-8).
    // With the cell term 1e-4 (measured 3e-8 and 1.2e-7): a cracked cell's volumetric energy
    // left out of the fracture term gave 3.4e-3 and 5.7e-3.
    EXPECT_LT(r.worst_error, nu < 0.25 ? 0.01 : 1e-4) << label;
    std::printf(
        "%s: first break at %.4g MPa, %ld bonds broken, fracture %.3g J (%.3g J at the "
        "first break), worst balance error %.2e\n",
        label.c_str(), r.failure_stress / 1e6, r.broken, r.fracture, r.first_fracture,
        r.worst_error);
    RecordProperty("failure_stress_" + label, std::to_string(r.failure_stress));
    RecordProperty("worst_error_" + label, std::to_string(r.worst_error));
  }
}

// Weibull strengths (modulus 4 and 12, one seed): the block now fails when its weakest bond
// reaches its own strength, sigma_t times the smallest factor that faces the load (weakest_bond),
// within the same 5 % as the uniform block, not at sigma_t. Answer: exact (from the drawn
// factors); the balance closes within 1 % as above.
TEST(LatticeFailure, WeibullBlockFailsAtItsWeakestBondsStrength) {
  for (double m : {4.0, 12.0}) {
    const TensionRun r = run_tension(Formulation::plane_stress, 0.21, m);
    ASSERT_LT(r.weakest, 0.95) << m;  // a weakest bond the test can tell from sigma_t
    EXPECT_NEAR(r.failure_stress, r.weakest * 2.3e6, 0.05 * r.weakest * 2.3e6) << "m = " << m;
    EXPECT_GT(r.broken, 0);
    EXPECT_LT(r.worst_error, 0.01);
    std::printf("m = %g: first bond broken at %.4g MPa, the weakest bond's strength %.4g MPa\n", m,
                r.failure_stress / 1e6, r.weakest * 2.3);
  }
}

// Rate dependence (RateLaw): a brittle lattice bar pulled apart at a constant strain rate by
// velocity boundaries on both ends (after a ramp of 20 us, some ten wave transits) fails when
// the stress on its ends, from the boundaries' reaction, reaches sigma_t times the table's
// dynamic increase factor at that rate: 1.5, 2 and 2.5 at 0.1, 1 and 10/s (factors 1 and 3 at 0.01
// and 100/s, linear in log10 of the rate). Answer: exact (the table); tolerance 5 %, as for the
// slow tension test (the bar rings about its mean stress after the ramp).
double rate_failure_stress(double strain_rate) {
  const double h = 1e-3, E = 50e9, rho = 2500.0, sigma_t = 10e6;
  const int nx = 10, ny = 4;
  const double L = nx * h, H = ny * h;
  Case c = test::rectangle_case(nx, ny, h, E, 0.2, rho, Formulation::plane_stress);
  c.bodies[0].method = BodyMethod::de;
  c.materials[0].tensile_strength = sigma_t;
  c.materials[0].rate_dependence = {{1e-2, 1e2}, {1.0, 3.0}, {1.0, 1.0}};
  const double speed = 0.5 * strain_rate * L, ramp = 20e-6;
  for (int side = 0; side < 2; ++side)
    test::add_velocity(c, side ? "right" : "left", test::segment(side * L, 0, side * L, H), 0,
                       {0.0, ramp}, {0.0, side ? speed : -speed});
  c.sim.end_time = ramp + 4.0 * sigma_t / (E * strain_rate);
  Simulation sim(c);
  while (sim.time() < c.sim.end_time * (1 - 1e-12) && !sim.failed()) {
    sim.step();
    if (sim.history().count.broken_bonds > 0)
      return sim.boundary_records()[1].fx / (H * c.sim.thickness);
  }
  ADD_FAILURE() << "no bond broke at " << strain_rate << "/s";
  return 0;
}

TEST(LatticeFailure, RateDependentStrengthFollowsTheStrainRate) {
  for (auto [rate, factor] : {std::pair{0.1, 1.5}, std::pair{1.0, 2.0}, std::pair{10.0, 2.5}}) {
    const double stress = rate_failure_stress(rate);
    EXPECT_NEAR(stress, factor * 10e6, 0.05 * factor * 10e6) << rate << "/s";
    std::printf("%g/s: failure stress %.4g MPa, expected %.4g MPa\n", rate, stress / 1e6,
                factor * 10.0);
  }
}

// Cohesive bonds (material fracture_energy G_f): a notched lattice bar pulled apart by a ramped
// traction cracks through its ligament, and the crack must dissipate G_f times its area
// (ligament x thickness) whatever the cell size, where brittle bonds dissipate only the tiny
// elastic energy they held. The notches (1 mm deep, top and bottom, in the middle) make the
// crack run through the ligament's cells, cutting its edge and diagonal bonds.
struct CohesiveRun {
  double fracture, failure_stress, worst_error;
  long broken;
  size_t fragments;
};

CohesiveRun run_cohesive(int refine, double fracture_energy, double energy_factor = 1.0) {
  const double h = 1e-3 / refine, E = 92e9, nu = 0.21, rho = 2400.0, sigma_t = 2.3e6;
  const int nx = 20 * refine, ny = 10 * refine;
  Case c = test::rectangle_case(nx, ny, h, E, nu, rho, Formulation::plane_stress);
  c.bodies[0].method = BodyMethod::de;
  c.materials[0].tensile_strength = sigma_t;
  c.materials[0].fracture_energy = fracture_energy;
  if (energy_factor != 1.0)  // the same factor at every rate (RateLaw)
    c.materials[0].rate_dependence = {{1e-6, 1e6}, {1.0, 1.0}, {energy_factor, energy_factor}};
  for (double y : {0.0, 9e-3}) {
    Shape notch;
    notch.type = Shape::Type::rectangle;
    notch.x = 10e-3;
    notch.y = y;
    notch.width = 1e-3;
    notch.height = 1e-3;
    c.bodies[0].cuts.push_back(notch);
  }
  const double L = 20e-3, H = 10e-3;
  const double ramp = 200 * L / std::sqrt(E / rho);  // traction reaches sigma_t
  test::add_pressure(c, test::segment(L, 0, L, H), {0.0, ramp}, {0.0, -sigma_t});
  test::add_fixed(c, test::segment(0, 0, 0, H), Boundary::Type::fixed_x);
  c.sim.end_time = ramp;
  Simulation sim(c);
  CohesiveRun r{0, -1, 0, 0, 0};
  while (sim.time() < c.sim.end_time * (1 - 1e-12) && !sim.failed()) {
    sim.step();
    const HistoryRecord hr = sim.history();
    r.worst_error = std::max(r.worst_error, hr.energy.error);
    if (r.failure_stress < 0 && hr.count.broken_bonds > 0)
      r.failure_stress = sigma_t * sim.time() / ramp;
  }
  EXPECT_FALSE(sim.failed()) << sim.failure();
  r.fracture = sim.history().energy.fracture;
  r.broken = sim.history().count.broken_bonds;
  r.fragments = sim.frame({}).fragment_mass.size();
  return r;
}

// Tolerances: the crack dissipates G_f A to within +10% / -2% (measured +5% at 1 mm cells, +8%
// at 0.5 mm: the excess is the partial softening of bonds beside the crack, which a lattice
// cannot avoid); the two cell sizes agree within 5% (measured 3%), and twice G_f dissipates
// twice the energy within 5%. The energy balance closes within 1% (measured ~1e-9: the
// softening's dissipation is the exact trapezoidal work less the change of stored energy).
TEST(LatticeFailure, CohesiveCrackDissipatesTheFractureEnergyAtAnyCellSize) {
  const double fracture_energy = 1.0;     // J/m^2
  const double crack_area = 8e-3 * 0.01;  // ligament x thickness (m^2)
  const double expected = fracture_energy * crack_area;
  std::vector<double> ratio;
  for (int refine : {1, 2}) {
    const CohesiveRun r = run_cohesive(refine, fracture_energy);
    EXPECT_EQ(r.fragments, 2u) << refine;  // the bar did separate, in two
    EXPECT_GT(r.fracture, 0.98 * expected) << "cells of " << 1.0 / refine << " mm";
    EXPECT_LT(r.fracture, 1.10 * expected) << "cells of " << 1.0 / refine << " mm";
    EXPECT_LT(r.worst_error, 0.01) << refine;
    ratio.push_back(r.fracture / expected);
    RecordProperty("fracture_over_Gf_area_refine" + std::to_string(refine),
                   std::to_string(ratio.back()));
    std::printf(
        "cells of %.2f mm: fracture energy / (G_f A) = %.4f, first bond broken at a "
        "nominal %.3f MPa, %ld bonds broken, worst energy error %.1e\n",
        1.0 / refine, ratio.back(), r.failure_stress / 1e6, r.broken, r.worst_error);
  }
  EXPECT_NEAR(ratio[1] / ratio[0], 1.0, 0.05);
  const CohesiveRun twice = run_cohesive(1, 2.0 * fracture_energy);
  EXPECT_EQ(twice.fragments, 2u);
  EXPECT_NEAR(twice.fracture / (2.0 * expected), ratio[0], 0.05 * ratio[0]);
  std::printf("2 G_f: fracture energy / (2 G_f A) = %.4f\n", twice.fracture / (2.0 * expected));
  // A rate_dependence whose fracture-energy factor is 2 at every rate dissipates as 2 G_f does
  // (the factor scales the final separation at the onset; the strength factor is 1): within 1 %.
  const CohesiveRun dynamic = run_cohesive(1, fracture_energy, 2.0);
  EXPECT_EQ(dynamic.fragments, 2u);
  EXPECT_NEAR(dynamic.fracture, twice.fracture, 0.01 * twice.fracture);
  std::printf("G_f with a rate factor of 2: fracture energy / (2 G_f A) = %.4f\n",
              dynamic.fracture / (2.0 * expected));
}

// Shear test: a lattice block of a Mohr-Coulomb material under a confining pressure p (ramped
// first) and then a slowly ramped pure shear stress tau (tractions on all four faces). The faces
// of the orthogonal bonds carry (sigma_n, tau) = (-p, tau), so the block must fail on the
// Mohr-Coulomb envelope tau = c + p tan(phi) (docs/physics.md 1.2). Ramps of ~100 wave transits
// keep the dynamic overshoot near 1%; the tolerance is 5%, as in tension.
double run_shear(double p) {
  const double h = 1e-3, E = 30e9, nu = 0.2, rho = 2400.0;
  const double c_coh = 5e6, phi = 30.0 * M_PI / 180.0;
  const int n = 16;
  const double L = n * h;
  Case c = test::rectangle_case(n, n, h, E, nu, rho, Formulation::plane_stress);
  c.bodies[0].method = BodyMethod::de;
  Material& m = c.materials[0];
  m.model = MaterialModel::mohr_coulomb;
  m.cohesion = c_coh;
  m.friction_angle = phi;
  m.tensile_strength = 50e6;  // out of the way: this test is about shear
  const double transit = L / std::sqrt(E / rho);
  const double t1 = 100 * transit, tau_max = 2.0 * (c_coh + p * std::tan(phi));
  const double t2 = t1 + 200 * transit;  // tau reaches tau_max: failure expected halfway
  const std::vector<double> tp{0.0, t1}, vp{0.0, p}, tt{0.0, t1, t2}, vt{0.0, 0.0, tau_max};
  using test::segment;
  for (const Segment& s :
       {segment(0, 0, L, 0), segment(L, 0, L, L), segment(L, L, 0, L), segment(0, L, 0, 0)})
    test::add_pressure(c, s, tp, vp);
  test::add_traction(c, segment(0, L, L, L), {1, 0}, tt, vt);
  test::add_traction(c, segment(0, 0, L, 0), {-1, 0}, tt, vt);
  test::add_traction(c, segment(L, 0, L, L), {0, 1}, tt, vt);
  test::add_traction(c, segment(0, 0, 0, L), {0, -1}, tt, vt);
  c.sim.end_time = t2;
  Simulation sim(c);
  while (sim.time() < c.sim.end_time * (1 - 1e-12) && !sim.failed()) {
    sim.step();
    if (sim.steps() % 10 == 0 && sim.history().count.broken_bonds > 0)
      return sim.time() < t1 ? -1.0 : tau_max * (sim.time() - t1) / (t2 - t1);
  }
  return -2.0;  // never failed
}

TEST(LatticeFailure, ShearFailsOnMohrCoulombEnvelope) {
  const double tan_phi = std::tan(30.0 * M_PI / 180.0);
  for (double p : {0.0, 10e6}) {
    const double expected = 5e6 + p * tan_phi;
    const double tau = run_shear(p);
    EXPECT_NEAR(tau, expected, 0.05 * expected) << "confinement " << p;
    RecordProperty("shear_failure_p" + std::to_string(static_cast<int>(p / 1e6)) + "MPa",
                   std::to_string(tau / expected));
  }
}

}  // namespace
}  // namespace fracta

namespace fracta {
namespace {

// Two lattice blocks collide head-on through disc contact (spring-dashpot with damping ratio
// 0.1 and friction): momentum is conserved to round-off (no external force), the blocks separate
// afterwards, and the energy balance including the contact's dissipated energy closes within
// 1% (the contact work is trapezoidal, O(dt^2)).
TEST(LatticeContact, BlocksCollideAndBalanceCloses) {
  const double h = 1e-3;
  Case c = test::rectangle_case(6, 6, h, 30e9, 0.2, 2400.0, Formulation::plane_stress);
  c.bodies[0].method = BodyMethod::de;
  Body other = c.bodies[0];
  other.name = "target";
  other.shape.x = 6 * h + 1.05 * h;  // a gap of 0.05 h beyond touching discs
  c.bodies.push_back(other);
  c.bodies[0].initial_velocity = {20.0, 0.0};
  const double c_wave = std::sqrt(30e9 / 2400.0);
  c.sim.end_time = 0.1 * h / 20.0 + 20 * 6 * h / c_wave;  // closing + several transits
  Simulation sim(c);
  const HistoryRecord h0 = sim.history();
  const double worst = test::run_to_end(sim);
  ASSERT_FALSE(sim.failed()) << sim.failure();
  const HistoryRecord h1 = sim.history();
  EXPECT_NEAR(h1.momentum_x, h0.momentum_x, 1e-10 * std::fabs(h0.momentum_x));
  EXPECT_GT(h1.energy.contact, 0.0);  // the dashpot dissipated
  const auto probes = sim.body_probe_records();
  (void)probes;
  EXPECT_LT(worst, 0.01);
  RecordProperty("worst_energy_error", std::to_string(worst));
  RecordProperty("contact_dissipated_fraction",
                 std::to_string(h1.energy.contact / h0.energy.kinetic));
}

// A lattice block set spinning rigidly (initial velocity field L = [[0, -w], [w, 0]] about its
// centre, discs at spin w) turns through 0.2 rad unstrained: a rigid rotation stretches no bond
// and turns no disc against its bonds. The only strain is the centripetal stress, about
// (3 + nu) / 8 rho w^2 R^2 = 6e4 Pa here, which the block, started without it, overshoots:
// its energy swings up to about 6e-6 of the kinetic (1e-4 at 2e4 rad/s: as w^2). Bound 1e-4.
// Discs started without spin would shear every bond by the turned angle.
TEST(LatticeMotion, ARigidlySpinningBlockStaysUnstrained) {
  const double h = 1e-3, w = 2e3;
  Case c = test::rectangle_case(8, 8, h, 30e9, 0.2, 2400.0, Formulation::plane_stress);
  c.bodies[0].method = BodyMethod::de;
  c.bodies[0].initial_velocity_gradient = {Vec2{0.0, -w}, Vec2{w, 0.0}};
  c.bodies[0].initial_velocity_origin = {4 * h, 4 * h};
  c.sim.end_time = 0.2 / w;
  Simulation sim(c);
  const HistoryRecord start = sim.history();
  test::run_to_end(sim);
  ASSERT_FALSE(sim.failed()) << sim.failure();
  const HistoryRecord end = sim.history();
  EXPECT_LT(end.energy.internal, 1e-4 * start.energy.kinetic);
  EXPECT_NEAR(end.energy.kinetic, start.energy.kinetic, 1e-4 * start.energy.kinetic);
  RecordProperty("internal_over_kinetic",
                 std::to_string(end.energy.internal / start.energy.kinetic));
}

}  // namespace
}  // namespace fracta
