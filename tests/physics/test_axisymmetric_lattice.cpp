// Axisymmetric discs (rings; docs/physics.md 1.2, "Axisymmetric discs"): the bonded lattice of a
// body of revolution against the same exact solutions as the axisymmetric finite elements
// (tests/physics/test_axisymmetric.cpp), the conversion of a prestressed adaptive cylinder, and
// the smeared radial cracking of an expanding ring against the fracture energy of its band. All
// are validations (exact solutions or conservation laws), none pins fracta's own output.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "test_util.hpp"

namespace fracta {
namespace {

// Lame's thick-walled cylinder (inner radius a = 10 mm, outer b = 20 mm, 20 cells through the
// wall, eps_zz = 0 by rollers on both ends) under 100 MPa internal pressure ramped over 100 us and
// held 200 us, as a `de` body: u(r) = (1 + nu) / E p a^2 / (b^2 - a^2) ((1 - 2 nu) r + b^2 / r)
// (Timoshenko & Goodier, Theory of Elasticity, 3rd ed., Sec. 28). The lattice reproduces the 3D
// law exactly under uniform strain (the pair springs plane stress, the cell hoop term the rest),
// so it carries the elements' discretisation error only: the displacements at both faces,
// averaged over the hold, within the same 1 % as the elements'.
TEST(AxisymmetricLattice, LameCylinderUnderInternalPressure) {
  const test::LameCylinder lame;
  const Case c = lame.make_case(BodyMethod::de);
  Simulation sim(c);
  double u_in = 0, u_out = 0, worst = 0;
  int samples = 0;
  while (sim.time() < c.sim.end_time * (1 - 1e-12) && !sim.failed()) {
    sim.step();
    if (sim.steps() % 10 == 0) worst = std::max(worst, sim.history().energy.error);
    if (sim.time() < lame.ramp) continue;
    const auto pr = sim.probe_records();
    u_in += pr[0].ux;
    u_out += pr[1].ux;
    ++samples;
  }
  ASSERT_FALSE(sim.failed()) << sim.failure();
  auto u = [&](double r) { return lame.u(r); };
  const double a = lame.a, b = lame.b;
  u_in /= samples;
  u_out /= samples;
  EXPECT_NEAR(u_in, u(a), 0.01 * u(a));
  EXPECT_NEAR(u_out, u(b), 0.01 * u(b));
  EXPECT_LT(worst, 1e-3);
  std::printf(
      "Lame, rings: u(a) %.5g (exact %.5g, %+.2f %%), u(b) %.5g (%.5g, %+.2f %%), "
      "worst energy error %.2g\n",
      u_in, u(a), 100 * (u_in / u(a) - 1), u_out, u(b), 100 * (u_out / u(b) - 1), worst);
}

// Axial plane wave in a rod of rings (radius 2 mm, 4 cells, held radially on its mantle:
// uniaxial strain) under a 500 MPa step on its end: exact speed c = sqrt((lambda + 2 mu) / rho)
// and particle velocity p / (rho c), the same on the axis and at the mantle. The plane-stress
// pair springs alone would run at sqrt(E / (rho (1 - nu^2))), 13 % slower at nu = 0.3: the
// speed checks that the hoop term completes the 3D law, within 1 %.
TEST(AxisymmetricLattice, AxialPlaneWave) {
  const test::AxialWaveResult r = test::run_axial_wave(BodyMethod::de);
  ASSERT_GT(r.t_near, 0.0);
  ASSERT_GT(r.t_axis, 0.0);
  ASSERT_GT(r.t_mantle, 0.0);
  ASSERT_GT(r.plateau_samples, 10);
  EXPECT_NEAR(r.speed, r.c_exact, 0.01 * r.c_exact);
  EXPECT_NEAR(r.axis, r.v_exact, 0.01 * r.v_exact);
  EXPECT_NEAR(r.mantle, r.v_exact, 0.01 * r.v_exact);
  EXPECT_NEAR(r.t_mantle, r.t_axis, 0.01 * (r.t_axis - r.t_near));
  std::printf(
      "axial wave, rings: speed %.1f m/s (exact %.1f), plateau %.4g axis, %.4g mantle "
      "(exact %.4g)\n",
      r.speed, r.c_exact, r.axis, r.mantle, r.v_exact);
}

// Radial wave far from the axis in rings: an annulus from R0 = 10 m, 80 mm thick, rollers on its
// faces, a pressure step on its bore; as the elements' test (test_axisymmetric.cpp): the speed
// of uniaxial strain and the plane particle velocity with its cylindrical spreading
// sqrt(R0 / r), within 1 %.
TEST(AxisymmetricLattice, RadialPlaneWaveFarFromTheAxis) {
  const double R0 = 10.0;
  const test::PlaneWaveResult r =
      test::run_plane_wave(Formulation::axisymmetric, BodyMethod::de, 0.3, R0);
  const double spreading = std::sqrt(R0 / (R0 + 50e-3));
  EXPECT_NEAR(r.speed, r.c_exact, 0.01 * r.c_exact);
  EXPECT_NEAR(r.plateau, spreading * r.v_exact, 0.01 * r.v_exact);
  std::printf("radial wave in rings at 10 m: c %.5g (exact %.5g), v %.5g (exact %.5g)\n", r.speed,
              r.c_exact, r.plateau, spreading * r.v_exact);
}

// A solid cylinder of rings (8 x 8 cells from the axis) moving along its axis at 10 m/s stays a
// rigid translation, as the elements' (test_axisymmetric.cpp): every velocity within 1e-9 m/s of
// the initial one, no bond force above 1e-6 N, axial momentum unchanged to round-off.
TEST(AxisymmetricLattice, RigidTranslationAlongTheAxis) {
  Case c = test::rectangle_case(8, 8, 0.5e-3, 200e9, 0.3, 7800.0, Formulation::axisymmetric);
  c.bodies[0].method = BodyMethod::de;
  c.bodies[0].initial_velocity = {0.0, 10.0};
  c.sim.end_time = 2e-6;
  Simulation sim(c);
  const double momentum = sim.history().momentum_y;
  test::run_to_end(sim);
  ASSERT_FALSE(sim.failed()) << sim.failure();
  EXPECT_GT(sim.steps(), 50);
  const auto v = Kokkos::create_mirror_view_and_copy(HostSpace(), sim.model().nodes.v);
  double worst = 0.0;
  for (size_t n = 0; n < v.extent(0); ++n)
    worst = std::max({worst, std::fabs(v(n, 0)), std::fabs(v(n, 1) - 10.0)});
  EXPECT_LT(worst, 1e-9);
  const auto fn = Kokkos::create_mirror_view_and_copy(HostSpace(), sim.model().bonds.fn);
  double largest = 0.0;
  for (size_t b = 0; b < fn.extent(0); ++b) largest = std::max(largest, std::fabs(fn(b)));
  EXPECT_LT(largest, 1e-6);
  EXPECT_NEAR(sim.history().momentum_y, momentum, 1e-12 * std::fabs(momentum));
}

// Energy balance of a solid cylinder of rings breathing about its axis (v_r = alpha r, cells on
// the axis), no dissipation, 10^5 steps at the full stable bound (dt_safety 1: the lattice's
// bound with the hoop term, docs/physics.md 1.4): bounded, below 1e-3 of the initial kinetic
// energy, and not growing (the last quarter's worst within 1.5 times the rest's; the error
// beats with a period of about 9x10^4 steps, so a shorter run would see a rise).
TEST(AxisymmetricLattice, BreathingCylinderConservesEnergy) {
  Case c = test::breathing_cylinder(0.5e-3, BodyMethod::de);
  c.sim.bulk_viscosity_linear = c.sim.bulk_viscosity_quadratic = 0.0;
  c.contact.damping_ratio = 0.0;
  c.sim.dt_safety = 1.0;
  test::end_after_steps(c, 100000);
  const test::EnergyWindows r = test::run_energy_windows(c);
  ASSERT_TRUE(r.failure.empty()) << r.failure;
  EXPECT_GE(r.steps, 95000);
  EXPECT_LT(std::max(r.early, r.late), 1e-3);
  EXPECT_LE(r.late, 1.5 * r.early);
  // No hoop damage, no dissipation (the hoop term counts it only where a cell is damaged).
  EXPECT_EQ(r.end.energy.fracture, 0.0);
  std::printf(
      "breathing cylinder of rings: %ld steps, worst error %.3g (first 3/4 %.3g, last "
      "1/4 %.3g)\n",
      r.steps, std::max(r.early, r.late), r.early, r.late);
}

// A prestressed adaptive cylinder (radius 12 mm, 12 x 12 cells from the axis) converts its centre
// to rings in equilibrium: a uniform strain u_r = a r, u_z = b z (eps_rr = eps_tt = a,
// eps_zz = b: uniform stress, s_rr = s_tt) held by pressures on its mantle and top and rollers on
// its base, then the 36 centre cells convert. The rings take over the elements' 3D stress (the
// pair springs the in-plane part, the hoop term the rest), so the conversion releases no wave:
// every velocity differs from the same run without the conversion by less than 1 % of the
// wave's particle velocity p / (rho c) at the largest stress. (The run without it is not quite
// at rest: one-point elements on the axis meet the ring-weighted edge load at the axis corner
// only to O(h), and that corner rings at about 13 % of the wave's velocity.) Mass is exact
// through the conversion (nodes keep their masses).
TEST(AxisymmetricLattice, PrestressedConversionReleasesNoWave) {
  const double h = 1e-3, rho = 7800, E = 200e9, nu = 0.3;
  const int n = 12;
  const double L = n * h;
  Case c = test::rectangle_case(n, n, h, E, nu, rho, Formulation::axisymmetric);
  c.bodies[0].method = BodyMethod::adaptive;
  c.materials[0].conversion_strain = 0.5;
  c.sim.end_time = 1.0;
  const double a = 1e-4, bz = -0.6e-4;
  const double lambda = nu * E / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
  const double s_rr = lambda * (2 * a + bz) + 2 * mu * a,
               s_zz = lambda * (2 * a + bz) + 2 * mu * bz;
  c.sim.dt = 0.5 * Simulation(c).stable_dt_bound();
  using test::segment;
  const std::vector<double> on{0.0, 0.5 * c.sim.dt, 0.5 * c.sim.dt};
  // Pressure is compression positive: a tensile s_rr is a negative pressure on the mantle.
  test::add_pressure(c, segment(L, 0, L, L), on, {0.0, -s_rr, -s_rr});
  test::add_pressure(c, segment(0, L, L, L), on, {0.0, -s_zz, -s_zz});
  test::add_fixed(c, segment(0, 0, L, 0), Boundary::Type::fixed_y);
  auto prestressed = [&](bool convert) {
    auto sim = std::make_unique<Simulation>(c);
    Nodes& nodes = sim->model().nodes;
    const double dt = sim->dt();
    auto x0 = Kokkos::create_mirror_view_and_copy(HostSpace(), nodes.x0);
    auto v = Kokkos::create_mirror_view_and_copy(HostSpace(), nodes.v);
    for (int i = 0; i < nodes.count; ++i) {
      v(i, 0) = a * x0(i, 0) / dt;
      v(i, 1) = bz * x0(i, 1) / dt;
    }
    Kokkos::deep_copy(nodes.v, v);
    sim->step();  // imposes the strain; the elements' stress is C : eps
    Kokkos::deep_copy(nodes.v, 0.0);
    if (convert) {
      auto ep = Kokkos::create_mirror_view_and_copy(HostSpace(), sim->model().elements.epeq);
      for (int j = 3; j < 9; ++j)
        for (int i = 3; i < 9; ++i) ep(j * n + i) = 0.5;
      Kokkos::deep_copy(sim->model().elements.epeq, ep);
    }
    return sim;
  };
  auto converted = prestressed(true), reference = prestressed(false);
  const double mass_before = converted->history().mass;
  double difference = 0, ringing = 0;
  for (int s = 0; s < 300; ++s) {
    converted->step();
    reference->step();
    auto v = Kokkos::create_mirror_view_and_copy(HostSpace(), converted->model().nodes.v);
    auto v_ref = Kokkos::create_mirror_view_and_copy(HostSpace(), reference->model().nodes.v);
    for (int i = 0; i < converted->model().nodes.count; ++i)
      for (int k = 0; k < 2; ++k) {
        difference = std::max(difference, std::fabs(v(i, k) - v_ref(i, k)));
        ringing = std::max(ringing, std::fabs(v_ref(i, k)));
      }
  }
  ASSERT_FALSE(converted->failed()) << converted->failure();
  EXPECT_EQ(converted->conversions(), 36);
  EXPECT_EQ(reference->conversions(), 0);
  const double c_p = std::sqrt((lambda + 2 * mu) / rho);
  const double v_wave = std::max(std::fabs(s_rr), std::fabs(s_zz)) / (rho * c_p);
  EXPECT_LT(difference, 0.01 * v_wave);
  const HistoryRecord end = converted->history();
  EXPECT_EQ(end.count.elements, n * n - 36);
  EXPECT_EQ(end.mass, mass_before);
  std::printf(
      "prestressed rings: velocity change %.3g of the wave's (the run without conversion "
      "rings at %.3g), conversion energy %.3g of the internal\n",
      difference / v_wave, ringing / v_wave, end.energy.conversion / end.energy.internal);
}

// Smeared radial cracking (HoopLaw): a thin ring (mean radius 1 m, 2 x 2 cells of 1 mm) flies
// outward at 30 m/s. Its in-plane stresses stay near 0, its hoop stress rises to the strength,
// then softens over the band of one cell: each cell dissipates G_f V / h (V its volume of
// revolution), so the ring dissipates G_f times its volume over h, within 2 % (the trapezoidal
// rule over the softening, and the small in-plane stresses); the hoop stress peaks at the
// strength within 1 %; no bond breaks; the energy balance closes within 1e-3.
TEST(AxisymmetricLattice, HoopCrackingDissipatesTheFractureEnergyOfItsBand) {
  const double h = 1e-3, R = 1.0, E = 72e9, nu = 0.22, rho = 2440.0;
  const double strength = 40e6, toughness = 100.0;  // Pa, J/m^2
  Case c = test::rectangle_case(2, 2, h, E, nu, rho, Formulation::axisymmetric);
  c.bodies[0].method = BodyMethod::de;
  c.bodies[0].shape.x = R - h;
  c.bodies[0].initial_velocity = {30.0, 0.0};
  c.materials[0].tensile_strength = strength;
  c.materials[0].fracture_energy = toughness;
  const double M = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu));
  const double w_final = 2 * toughness / (strength * h);
  c.sim.end_time = 3.0 * w_final * R / 30.0;
  Simulation sim(c);
  double peak = 0.0, worst = 0.0;
  const auto hoop = sim.model().elements.cell_hoop;
  ASSERT_EQ(hoop.extent(0), 4u);
  while (sim.time() < c.sim.end_time * (1 - 1e-12) && !sim.failed()) {
    sim.step();
    if (sim.steps() % 20 == 0) worst = std::max(worst, std::fabs(sim.history().energy.error));
    auto host = Kokkos::create_mirror_view_and_copy(HostSpace(), hoop);
    for (int e = 0; e < 4; ++e) {
      const double w = host(e, kHoopStrain), d = host(e, kHoopDamage);
      peak = std::max(peak, M * w * (w > 0 ? 1 - d : 1));
    }
  }
  ASSERT_FALSE(sim.failed()) << sim.failure();
  auto host = Kokkos::create_mirror_view_and_copy(HostSpace(), hoop);
  for (int e = 0; e < 4; ++e) EXPECT_EQ(host(e, kHoopDamage), 1.0) << "cell " << e;
  const HistoryRecord end = sim.history();
  EXPECT_EQ(end.count.broken_bonds, 0);
  const double volume = 2 * M_PI * R * (2 * h) * (2 * h);  // mean radius R
  const double expected = toughness * volume / h;
  EXPECT_NEAR(end.energy.fracture, expected, 0.02 * expected);
  EXPECT_NEAR(peak, strength, 0.01 * strength);
  EXPECT_LT(worst, 1e-3);
  std::printf(
      "ring, smeared radial cracks: dissipated %.5g J (G_f V / h = %.5g, %+.2f %%), peak "
      "hoop stress %.4g MPa (strength %.4g), worst energy error %.2g\n",
      end.energy.fracture, expected, 100 * (end.energy.fracture / expected - 1), peak / 1e6,
      strength / 1e6, worst);
}

// Contact between rings: two rods of rings (radius 2 mm, 4 x 12 cells each) meet head-on at
// 20 m/s each along the axis and rebound. Axial momentum is conserved to round-off (contact
// forces are equal and opposite, and the rings' weights are in the stiffness, not in the pair's
// geometry), the rods do not pass through each other (the facing discs overlap by less than a
// tenth of their diameter), they separate, and the energy balance closes within 1 % (contact
// damping counted).
TEST(AxisymmetricLattice, RodsOfRingsMeetHeadOnAndRebound) {
  const double h = 0.5e-3, v0 = 20.0;
  Case c = test::rectangle_case(4, 12, h, 200e9, 0.3, 7800.0, Formulation::axisymmetric);
  c.bodies[0].method = BodyMethod::de;
  c.bodies[0].name = "lower";
  c.bodies[0].initial_velocity = {0.0, v0};
  Body upper = c.bodies[0];
  upper.name = "upper";
  // The facing rows of discs (radius h / 2) a cell and 5 % apart: a gap of 5 % of a cell.
  upper.shape.y = 13 * h + 0.05 * h;
  upper.initial_velocity = {0.0, -v0};
  c.bodies.push_back(upper);
  const double c_bar = std::sqrt(200e9 / 7800.0);
  c.sim.end_time = 4.0 * 12 * h / c_bar;  // the contact lasts about 2 L / c
  Simulation sim(c);
  const int nodes_per_body = 5 * 13;
  double worst = 0.0, closest = 1.0, momentum = 0.0;
  const double mass = sim.history().mass;
  while (sim.time() < c.sim.end_time * (1 - 1e-12) && !sim.failed()) {
    sim.step();
    const HistoryRecord r = sim.history();
    worst = std::max(worst, std::fabs(r.energy.error));
    momentum = std::max(momentum, std::fabs(r.momentum_y));
    auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), sim.model().nodes.x);
    // The lower rod's top row against the upper rod's bottom row, ring by ring.
    for (int i = 0; i <= 4; ++i)
      closest = std::min(closest, x(nodes_per_body + i, 1) - x(12 * 5 + i, 1));
  }
  ASSERT_FALSE(sim.failed()) << sim.failure();
  EXPECT_LT(momentum, 1e-9 * mass * v0);
  EXPECT_GT(closest, 0.9 * h);  // facing discs (diameter h) overlap by less than 10 %
  const HistoryRecord end = sim.history();
  auto v = Kokkos::create_mirror_view_and_copy(HostSpace(), sim.model().nodes.v);
  auto m = Kokkos::create_mirror_view_and_copy(HostSpace(), sim.model().nodes.mass);
  double lower = 0, upper_v = 0, body_mass = 0;  // the rods' mass-averaged axial velocities
  for (int i = 0; i < nodes_per_body; ++i) {
    lower += m(i) * v(i, 1);
    upper_v += m(nodes_per_body + i) * v(nodes_per_body + i, 1);
    body_mass += m(i);
  }
  lower /= body_mass;
  upper_v /= body_mass;
  EXPECT_LT(lower, 0.0);
  EXPECT_GT(upper_v, 0.0);
  EXPECT_LT(worst, 0.01);
  std::printf(
      "rods of rings: closest approach %.3g of a cell, worst |momentum| %.3g of m v0, mean "
      "speeds after %.3g / %.3g m/s, energy error %.3g, contact dissipated %.3g J\n",
      closest / h, momentum / (mass * v0), lower, upper_v, worst, end.energy.contact);
}

// Rings cannot cross the axis: rubble of rings flies at the axis. A glass block of 4 x 4 cells
// of 1 mm from r = 1 mm with a tiny tensile strength (1 kPa), thrown at the axis at 100 m/s and
// stretched along it (v_z = 2x10^4/s (z - z_c)), so every bond breaks at once and the cells'
// hoop terms go with them: free rings, which nothing in the lattice keeps from passing r = 0 to
// negative radii (a volume of revolution below 0). Each off-axis ring is caught by the axis's
// push-only support when it reaches it (and may leave it again, knocked outward by the rings
// that follow), so no node ever has x < 0, and the energy balance closes within 1 % (the
// catches are the constraint's work, as contact and fracture are counted).
TEST(AxisymmetricLattice, RingsThrownAtTheAxisStopThere) {
  const double h = 1e-3;
  Case c = test::rectangle_case(4, 4, h, 72e9, 0.22, 2440.0, Formulation::axisymmetric);
  c.bodies[0].method = BodyMethod::de;
  c.bodies[0].shape.x = h;
  c.bodies[0].initial_velocity = {-100.0, 0.0};
  c.bodies[0].initial_velocity_gradient = {Vec2{0.0, 0.0}, Vec2{0.0, 2e4}};
  c.bodies[0].initial_velocity_origin = {0.0, 2 * h};
  c.materials[0].tensile_strength = 1e3;
  c.sim.end_time = 80e-6;
  Simulation sim(c);
  double leftmost = 1.0, worst = 0.0;
  while (sim.time() < c.sim.end_time * (1 - 1e-12) && !sim.failed()) {
    sim.step();
    worst = std::max(worst, std::fabs(sim.history().energy.error));
    leftmost = std::min(leftmost, test::leftmost_node_x(sim));
  }
  ASSERT_FALSE(sim.failed()) << sim.failure();
  EXPECT_GE(leftmost, 0.0);
  EXPECT_LT(worst, 0.01);
  const HistoryRecord end = sim.history();
  EXPECT_EQ(end.count.broken_bonds, end.count.bonds + end.count.broken_bonds);
  EXPECT_LT(end.energy.external, 0.0);  // the catches took energy
  auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), sim.model().nodes.x);
  double rightmost = 0.0;
  for (size_t n = 0; n < x.extent(0); ++n) rightmost = std::max(rightmost, x(n, 0));

  std::printf(
      "rings thrown at the axis: leftmost node x = %.3g m, rightmost at the end %.3g m, "
      "energy error %.3g, catch work %.3g J, %ld bonds broken\n",
      leftmost, rightmost, worst, end.energy.external, end.count.broken_bonds);
}

// Everything converting in rings: an adaptive Mohr-Coulomb cylinder (radius 8 mm, 8 x 16 cells
// of 1 mm from the axis, nu = 0.21, tensile strength 10 MPa) hit on its end by a 400 MPa pulse
// of 4 us, with a tiny conversion strain, so the yield front converts every element as it sweeps
// through, and the rings crack in-plane (bonds) and radially (hoop damage) and collide. The run
// reaches its end without NaN, leaves no element, and closes the energy balance (plastic,
// conversion, fracture, contact terms included) within 2 %, as the plane-strain test
// (Conversion.EverythingConvertsAndBalanceCloses: a fragmenting run's contact and conversion
// terms are O(dt) accurate).
TEST(AxisymmetricLattice, EverythingConvertsAndBalanceCloses) {
  const double h = 1e-3;
  const int nr = 8, nz = 16;
  Case c = test::rectangle_case(nr, nz, h, 92e9, 0.21, 2400.0, Formulation::axisymmetric);
  c.bodies[0].method = BodyMethod::adaptive;
  test::make_quickly_converting_concrete(c.materials[0]);
  test::add_pressure(c, test::segment(0, 0, nr * h, 0), {0.0, 4e-6, 4e-6}, {400e6, 400e6, 0.0});
  c.sim.end_time = 30e-6;
  Simulation sim(c);
  const double worst = test::run_to_end(sim);
  ASSERT_FALSE(sim.failed()) << sim.failure();
  const HistoryRecord end = sim.history();
  EXPECT_EQ(end.count.elements, 0);
  EXPECT_EQ(sim.conversions(), nr * nz);
  EXPECT_TRUE(std::isfinite(end.energy.kinetic));
  EXPECT_GT(end.energy.fracture, 0.0);
  EXPECT_LT(worst, 0.02);
  std::printf(
      "everything converts in rings: worst energy error %.3g, fracture %.3g J, "
      "conversion %.3g J of external %.3g J, %ld bonds broken\n",
      worst, end.energy.fracture, end.energy.conversion, end.energy.external,
      end.count.broken_bonds);
}

}  // namespace
}  // namespace fracta
