// The laws with a state per point (materials.hpp: hjc and johnson_cook; docs/physics.md 1.1) in
// the whole solver: blocks compressed in uniaxial strain, the 48 MPa Holmquist-Johnson-Cook
// concrete (cases/validation/hjc_confined_compression.toml) and Johnson-Cook OFHC copper. The
// material-point closed forms are in tests/kernels/test_materials.cpp (MaterialHjc.*,
// MaterialJohnsonCook.*); here the element kernel, the boundaries and the reactions carry them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "host/case.hpp"
#include "host/simulation.hpp"
#include "test_util.hpp"

namespace fracta {
namespace {

const std::string kCase =
    std::string(FRACTA_SOURCE_DIR) + "/cases/validation/hjc_confined_compression.toml";

// Answer: exact. The pressure from the side and top reactions against the equation of state at
// mu = H0 / H - 1 (tolerance 0.1 % of the pressure: the quasi-static block still carries
// inertia stresses of order rho H^2 eps_dot / t, and the trace of each step's strain is a
// midpoint measure); the von Mises stress sigma_xx - sigma_yy between the residual surface
// f'c B P*^N and the intact one f'c (A + B P*^N), with 0.5 % either side; and the energy balance.
TEST(HjcConcrete, ConfinedCompressionFollowsTheEquationOfStateAndStrengthSurfaces) {
  Case c = load_case(kCase);
  const HjcParams& h = c.materials[0].hjc;
  const double H0 = 4e-3, W = 4e-3;
  Simulation sim(c);
  int checked = 0, yielded = 0;
  double worst_pressure = 0.0;  // largest relative pressure error
  double next_check = 0.5e-3;
  while (sim.time() < c.sim.end_time * (1 - 1e-12) && !sim.failed()) {
    sim.step();
    if (sim.time() < next_check) continue;
    next_check += 0.5e-3;
    const std::vector<BoundaryRecord> r = sim.boundary_records();
    const double top_travel = 6e-3 * (sim.time() - 10e-6);  // ramped over 20 us
    const double H = H0 - top_travel, mu = H0 / H - 1.0;
    // Reactions over the faces' current areas (the side faces shorten with the block; the top
    // keeps its width): the force the constraint applies to the body, tension positive.
    const double sxx = r[1].fx / (H * c.sim.thickness);  // right face, outward normal +x
    const double syy = r[3].fy / (W * c.sim.thickness);  // top face, outward normal +y
    // The equation of state on its loading envelope (mu only grows here).
    double p_eos;
    if (mu <= h.mu_crush)
      p_eos = h.p_crush / h.mu_crush * mu;
    else
      p_eos = h.p_crush + (h.p_lock - h.p_crush) * (mu - h.mu_crush) / (h.mu_lock - h.mu_crush);
    const double p = -(syy + 2.0 * sxx) / 3.0;
    const double q = sxx - syy;
    EXPECT_NEAR(p, p_eos, 1e-3 * p_eos) << "mu " << mu;
    worst_pressure = std::max(worst_pressure, std::fabs(p / p_eos - 1.0));
    const double p_star = p_eos / h.fc;
    const double residual = h.fc * h.b * std::pow(p_star, h.n);
    const double intact = h.fc * (h.a + h.b * std::pow(p_star, h.n));
    EXPECT_LE(q, intact * 1.005) << "mu " << mu;
    if (q > 0.99 * residual && sim.history().energy.plastic > 0) {
      EXPECT_GE(q, residual * 0.995) << "mu " << mu;
      ++yielded;
    }
    ++checked;
  }
  ASSERT_FALSE(sim.failed()) << sim.failure();
  EXPECT_GE(checked, 25);
  EXPECT_GE(yielded, 20);  // it yields early (q = 2 G eps reaches the surface at eps ~ 0.002)
  const HistoryRecord end = sim.history();
  std::printf("mu %.4f: pressure within %.3g %% of the EOS, energy error %.3g %%, plastic %.4g J\n",
              H0 / (H0 - 6e-3 * (sim.time() - 10e-6)) - 1.0, 100 * worst_pressure,
              100 * end.energy.error, end.energy.plastic);
  EXPECT_LT(std::fabs(end.energy.error), 0.01);
}

// Answer: exact. OFHC copper (Johnson & Cook 1983: A 90 MPa, B 292 MPa, n 0.31; quasi-static,
// isothermal) in the same confined compression, a 2 x 2 block of 2 mm cells compressed at
// 1.5/s. With the logarithmic strain e = ln(H0 / H): the pressure is K e (hypoelastic volume
// change), and the von Mises stress q = sigma_xx - sigma_yy solves q = A + B eps_p^n with
// eps_p = 2/3 e - q / 3G (the deviatoric strain less its elastic part). Tolerance 0.1 % of q
// and of the pressure (inertia of the quasi-static block; midpoint strain measure).
TEST(JohnsonCookMetal, ConfinedCompressionFollowsTheHardeningCurve) {
  const double H0 = 4e-3, E = 124e9, nu = 0.34, rate = 1.5;
  Case c = test::rectangle_case(2, 2, 2e-3, E, nu, 8960.0, Formulation::plane_strain);
  Material& m = c.materials[0];
  m.model = MaterialModel::johnson_cook;
  m.jc.a = 90e6, m.jc.b = 292e6, m.jc.n = 0.31, m.jc.c = 0.025, m.jc.m = 1.09;
  m.jc.t_room = 294.0, m.jc.t_melt = 1356.0;
  c.sim.end_time = 0.01;
  const double v = rate * H0;
  test::add_velocity(c, "left", test::segment(0, 0, 0, H0), 0, {0.0}, {0.0});
  test::add_velocity(c, "right", test::segment(H0, 0, H0, H0), 0, {0.0}, {0.0});
  test::add_velocity(c, "bottom", test::segment(0, 0, H0, 0), 1, {0.0}, {0.0});
  test::add_velocity(c, "top", test::segment(0, H0, H0, H0), 1, {0.0, 20e-6}, {0.0, -v});
  Simulation sim(c);
  const double G = E / (2 * (1 + nu)), K = E / (3 * (1 - 2 * nu));
  int checked = 0;
  double next_check = 0.5e-3, worst_q = 0.0, worst_p = 0.0;
  while (sim.time() < c.sim.end_time * (1 - 1e-12) && !sim.failed()) {
    sim.step();
    if (sim.time() < next_check) continue;
    next_check += 0.5e-3;
    const std::vector<BoundaryRecord> r = sim.boundary_records();
    const double H = H0 - v * (sim.time() - 10e-6), e = std::log(H0 / H);
    const double sxx = r[1].fx / (H * c.sim.thickness), syy = r[3].fy / (H0 * c.sim.thickness);
    const double p = -(syy + 2.0 * sxx) / 3.0, q = sxx - syy;
    // q = A + B (2/3 e - q / 3G)^n, by bisection on q in [A, A + B (2/3 e)^n].
    double lo = m.jc.a, hi = m.jc.a + m.jc.b * std::pow(2.0 / 3.0 * e, m.jc.n);
    for (int it = 0; it < 200; ++it) {
      const double mid = 0.5 * (lo + hi), ep = 2.0 / 3.0 * e - mid / (3.0 * G);
      (mid < m.jc.a + (ep > 0 ? m.jc.b * std::pow(ep, m.jc.n) : 0.0) ? lo : hi) = mid;
    }
    const double q_exact = 0.5 * (lo + hi);
    if (2.0 / 3.0 * e * 3.0 * G < m.jc.a) continue;  // still elastic
    EXPECT_NEAR(q, q_exact, 1e-3 * q_exact) << "e " << e;
    EXPECT_NEAR(p, K * e, 1e-3 * K * e) << "e " << e;
    worst_q = std::max(worst_q, std::fabs(q / q_exact - 1));
    worst_p = std::max(worst_p, std::fabs(p / (K * e) - 1));
    ++checked;
  }
  ASSERT_FALSE(sim.failed()) << sim.failure();
  EXPECT_GE(checked, 15);
  std::printf(
      "copper to e = %.4f: q within %.3g %%, pressure within %.3g %%, energy error %.3g %%\n",
      std::log(H0 / (H0 - v * (sim.time() - 10e-6))), 100 * worst_q, 100 * worst_p,
      100 * sim.history().energy.error);
  EXPECT_LT(std::fabs(sim.history().energy.error), 0.01);
}

}  // namespace
}  // namespace fracta
