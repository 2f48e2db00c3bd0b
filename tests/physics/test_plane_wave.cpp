// Plane longitudinal wave in a strip with rollers on its long sides (eps_yy = 0): the exact
// solution is a step travelling at c with particle velocity v = p / (rho c) behind it, where
// plane stress c = sqrt(E / (rho (1 - nu^2))) and plane strain
// c = sqrt(E (1 - nu) / (rho (1 + nu) (1 - 2 nu))).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "host/simulation.hpp"
#include "test_util.hpp"

namespace fracta {
namespace {

struct WaveResult {
  double speed, plateau, c_exact, v_exact;
};

// Time at which a probe's vx first reaches half of v_half (linear interpolation between steps).
double arrival_time(const std::vector<double>& t, const std::vector<double>& v, double v_half) {
  for (size_t i = 1; i < t.size(); ++i)
    if (v[i - 1] < v_half && v[i] >= v_half)
      return t[i - 1] + (v_half - v[i - 1]) / (v[i] - v[i - 1]) * (t[i] - t[i - 1]);
  return -1.0;
}

void record(const WaveResult& r) {
  ::testing::Test::RecordProperty("speed_error", std::to_string(r.speed / r.c_exact - 1));
  ::testing::Test::RecordProperty("plateau_error", std::to_string(r.plateau / r.v_exact - 1));
}

WaveResult run_wave(Formulation f, BodyMethod method = BodyMethod::fe, double nu = 0.3) {
  const double h = 0.5e-3, E = 232e9, rho = 7800.0, p = 500e6;
  const int nx = 160, ny = 4;  // 80 mm long strip
  Case c = test::rectangle_case(nx, ny, h, E, nu, rho, f);
  c.bodies[0].method = method;
  const double L = nx * h, H = ny * h;
  test::add_pressure(c, test::segment(0, 0, 0, H), {0.0, 1.0}, {p, p});  // step load
  test::add_fixed(c, test::segment(0, 0, L, 0), Boundary::Type::fixed_y);
  test::add_fixed(c, test::segment(0, H, L, H), Boundary::Type::fixed_y);
  test::add_probe(c, "x20", 20e-3, H / 2);
  test::add_probe(c, "x50", 50e-3, H / 2);
  const double c_exact = f == Formulation::plane_stress
                             ? std::sqrt(E / (rho * (1 - nu * nu)))
                             : std::sqrt(E * (1 - nu) / (rho * (1 + nu) * (1 - 2 * nu)));
  const double v_exact = p / (rho * c_exact);
  c.sim.end_time = 0.95 * L / c_exact;  // stop before the front reaches the far end
  Simulation sim(c);
  std::vector<double> t, v1, v2;
  while (sim.time() < c.sim.end_time * (1 - 1e-12) && !sim.failed()) {
    sim.step();
    const auto pr = sim.probe_records();
    t.push_back(sim.time());
    v1.push_back(pr[0].vx);
    v2.push_back(pr[1].vx);
  }
  const double t1 = arrival_time(t, v1, 0.5 * v_exact), t2 = arrival_time(t, v2, 0.5 * v_exact);
  // Plateau at the second probe: mean over the window from 1.5 us after arrival to the end
  // (the front's ringing has decayed there, and no reflection has come back).
  double sum = 0;
  int count = 0;
  for (size_t i = 0; i < t.size(); ++i)
    if (t[i] > t2 + 1.5e-6) {
      sum += v2[i];
      ++count;
    }
  return {30e-3 / (t2 - t1), count ? sum / count : 0.0, c_exact, v_exact};
}

// Tolerance 1%: the requirement; the one-point Q4 with lumped mass has a dispersive front,
// whose half-amplitude point travels at c to well within that at 40 cells per probe distance.
TEST(PlaneWave, PlaneStressSpeedAndParticleVelocity) {
  const WaveResult r = run_wave(Formulation::plane_stress);
  EXPECT_NEAR(r.speed, r.c_exact, 0.01 * r.c_exact);
  EXPECT_NEAR(r.plateau, r.v_exact, 0.01 * r.v_exact);
  record(r);
}

TEST(PlaneWave, PlaneStrainSpeedAndParticleVelocity) {
  const WaveResult r = run_wave(Formulation::plane_strain);
  EXPECT_NEAR(r.speed, r.c_exact, 0.01 * r.c_exact);
  EXPECT_NEAR(r.plateau, r.v_exact, 0.01 * r.v_exact);
  record(r);
}

// The same plane wave through the bonded disc lattice (DESIGN.md 1.2): its stiffness equals the
// continuum's, so speed and plateau particle velocity match the continuum values; 1.5% is the
// issue's bound for the lattice, whose front rings more (no bulk viscosity acts on discs).
TEST(PlaneWave, LatticePlaneStressSpeedAndParticleVelocity) {
  const WaveResult r = run_wave(Formulation::plane_stress, BodyMethod::de);
  EXPECT_NEAR(r.speed, r.c_exact, 0.015 * r.c_exact);
  EXPECT_NEAR(r.plateau, r.v_exact, 0.015 * r.v_exact);
  record(r);
}

TEST(PlaneWave, LatticePlaneStrainSpeedAndParticleVelocity) {
  const WaveResult r = run_wave(Formulation::plane_strain, BodyMethod::de, 0.2);
  EXPECT_NEAR(r.speed, r.c_exact, 0.015 * r.c_exact);
  EXPECT_NEAR(r.plateau, r.v_exact, 0.015 * r.v_exact);
  record(r);
}

}  // namespace
}  // namespace fracta
