// The Holmquist-Johnson-Cook concrete law (materials.hpp, model hjc; docs/physics.md 1.1) in the
// whole solver: a block of the 48 MPa concrete compressed in uniaxial strain
// (cases/validation/hjc_confined_compression.toml). The material-point closed forms are in
// tests/kernels/test_materials.cpp (MaterialHjc.*); here the element kernel, the boundaries and
// the reactions carry them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "host/case.hpp"
#include "host/simulation.hpp"

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

}  // namespace
}  // namespace fracta
