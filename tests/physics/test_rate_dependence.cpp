// Rate-dependent tension of the elements (FeForces::tension_rates; docs/physics.md 1.1, "Rate
// dependence"): a mohr_coulomb material with a rate_dependence table raises its Rankine cut-off,
// and the stress at which an adaptive element converts by tension, by the table's strength
// factor at the element's largest principal strain rate.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <utility>

#include "host/simulation.hpp"
#include "test_util.hpp"

namespace fracta {
namespace {

// An FE (or adaptive) bar of a Mohr-Coulomb solid (sigma_t 10 MPa, c 100 MPa: tension governs)
// pulled apart at a constant strain rate by velocity boundaries on both ends, after a ramp of
// 20 us (some ten wave transits). The table gives factors 1 and 3 at 0.01 and 100/s, linear in
// log10 of the rate: 1.5, 2 and 2.5 at 0.1, 1 and 10/s. Returns the end stress (from the
// boundary's reaction) at the step the cut-off first acts (FE: the first plastic work) or the
// first element converts (adaptive).
struct RateRun {
  double stress = 0;  // Pa
  long converted = 0;
};

RateRun pull(double strain_rate, BodyMethod method) {
  const double h = 1e-3, E = 50e9, rho = 2500.0, sigma_t = 10e6;
  const int nx = 10, ny = 4;
  const double L = nx * h, H = ny * h;
  Case c = test::rectangle_case(nx, ny, h, E, 0.2, rho, Formulation::plane_stress);
  c.bodies[0].method = method;
  Material& m = c.materials[0];
  m.model = MaterialModel::mohr_coulomb;
  m.cohesion = 100e6;
  m.friction_angle = 30.0 * M_PI / 180.0;
  m.tensile_strength = sigma_t;
  m.rate_dependence = {{1e-2, 1e2}, {1.0, 3.0}, {1.0, 1.0}};
  c.sim.conversion_on_tension = method == BodyMethod::adaptive;
  const double speed = 0.5 * strain_rate * L, ramp = 20e-6;
  for (int side = 0; side < 2; ++side)
    test::add_velocity(c, side ? "right" : "left", test::segment(side * L, 0, side * L, H), 0,
                       {0.0, ramp}, {0.0, side ? speed : -speed});
  c.sim.end_time = ramp + 2.0 * 3.0 * sigma_t / (E * strain_rate);
  Simulation sim(c);
  RateRun r;
  while (sim.time() < c.sim.end_time * (1 - 1e-12) && !sim.failed()) {
    sim.step();
    const HistoryRecord now = sim.history();
    if (method == BodyMethod::adaptive ? now.count.conversions > 0 : now.energy.plastic > 0) {
      r.converted = now.count.conversions;
      r.stress = sim.boundary_records()[1].fx / (H * c.sim.thickness);
      return r;
    }
  }
  ADD_FAILURE() << "the cut-off never acted at " << strain_rate
                << "/s: " << (sim.failed() ? sim.failure() : "");
  return r;
}

// Answer: exact (the table's factor times sigma_t). Tolerance 5 %, as for the lattice's
// rate-dependent strength (the bar rings about its mean stress after the ramp).
TEST(RateDependence, ElementTensionCutOffFollowsTheStrainRate) {
  for (auto [rate, factor] : {std::pair{0.1, 1.5}, std::pair{1.0, 2.0}, std::pair{10.0, 2.5}}) {
    const RateRun r = pull(rate, BodyMethod::fe);
    EXPECT_NEAR(r.stress, factor * 10e6, 0.05 * factor * 10e6) << rate << "/s";
    std::printf("FE %g/s: cut-off stress %.4g MPa, expected %.4g MPa\n", rate, r.stress / 1e6,
                factor * 10.0);
  }
}

TEST(RateDependence, AdaptiveElementsConvertAtTheRaisedTensionCutOff) {
  for (auto [rate, factor] : {std::pair{0.1, 1.5}, std::pair{10.0, 2.5}}) {
    const RateRun r = pull(rate, BodyMethod::adaptive);
    EXPECT_GT(r.converted, 0) << rate << "/s";
    EXPECT_NEAR(r.stress, factor * 10e6, 0.05 * factor * 10e6) << rate << "/s";
    std::printf("adaptive %g/s: converted at %.4g MPa, expected %.4g MPa\n", rate, r.stress / 1e6,
                factor * 10.0);
  }
}

}  // namespace
}  // namespace fracta
