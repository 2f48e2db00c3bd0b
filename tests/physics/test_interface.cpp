// A plane wave crossing an FE/DE interface (docs/physics.md 1.3: composite nodes, bond slots from
// the mesh, no interpolation and no penalty): the paper's cases A (interface along the wave) and B
// (interface across it), in a strip with rollers on its long sides so the exact solution is a
// step of speed c and particle velocity p / (rho c).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "host/simulation.hpp"
#include "test_util.hpp"

namespace fracta {
namespace {

const double kH = 0.5e-3, kE = 232e9, kNu = 0.3, kRho = 7800.0, kP = 500e6;
const double kC = std::sqrt(kE / (kRho * (1 - kNu * kNu)));  // plane stress, eps_yy = 0
const double kV = kP / (kRho * kC);

struct Series {
  std::vector<double> t;
  std::vector<std::vector<double>> vx;  // per probe
};

Series run(Case c) {
  Simulation sim(c);
  Series s;
  s.vx.resize(c.probes.size());
  while (sim.time() < c.sim.end_time * (1 - 1e-12) && !sim.failed()) {
    sim.step();
    const auto pr = sim.probe_records();
    s.t.push_back(sim.time());
    for (size_t k = 0; k < pr.size(); ++k) s.vx[k].push_back(pr[k].vx);
  }
  EXPECT_FALSE(sim.failed()) << sim.failure();
  return s;
}

double arrival(const Series& s, int k) {
  for (size_t i = 1; i < s.t.size(); ++i)
    if (s.vx[k][i - 1] < 0.5 * kV && s.vx[k][i] >= 0.5 * kV)
      return s.t[i - 1] +
             (0.5 * kV - s.vx[k][i - 1]) / (s.vx[k][i] - s.vx[k][i - 1]) * (s.t[i] - s.t[i - 1]);
  return -1;
}

double mean(const Series& s, int k, double t0, double t1) {
  double sum = 0;
  int n = 0;
  for (size_t i = 0; i < s.t.size(); ++i)
    if (s.t[i] >= t0 && s.t[i] <= t1) {
      sum += s.vx[k][i];
      ++n;
    }
  return n ? sum / n : 0.0;
}

Case strip(int nx, int ny, const Shape& de_region) {
  Case c = test::rectangle_case(nx, ny, kH, kE, kNu, kRho, Formulation::plane_stress);
  Region r;
  r.method = BodyMethod::de;
  r.shape = de_region;
  c.bodies[0].regions.push_back(r);
  const double L = nx * kH, H = ny * kH;
  test::add_pressure(c, test::segment(0, 0, 0, H), {0.0, 1.0}, {kP, kP});  // a step
  test::add_fixed(c, test::segment(0, 0, L, 0), Boundary::Type::fixed_y);
  test::add_fixed(c, test::segment(0, H, L, H), Boundary::Type::fixed_y);
  c.sim.end_time = 0.95 * L / kC;
  return c;
}

// Case B: FE for x < 40 mm, discs beyond. The wave enters the lattice through the interface:
// the plateau behind it at an FE probe must not change when the reflection (if any) comes back
// (< 2% of the amplitude), and the speed between two lattice probes must stay within 1% of c.
TEST(Interface, CaseBWaveCrossesFeToDeInterface) {
  Shape right;
  right.x = 40e-3;
  right.width = 40e-3;
  right.height = 2e-3;
  Case c = strip(160, 4, right);
  test::add_probe(c, "fe", 20e-3, 1e-3);
  test::add_probe(c, "de1", 50e-3, 1e-3);
  test::add_probe(c, "de2", 70e-3, 1e-3);
  const Series s = run(c);
  const double t_fe = arrival(s, 0);
  const double t_reflect = t_fe + 2 * 20e-3 / kC;  // FE probe -> interface -> FE probe
  const double before = mean(s, 0, t_fe + 1.5e-6, t_reflect - 0.2e-6);
  const double after = mean(s, 0, t_reflect + 1.0e-6, s.t.back());
  const double reflected = std::fabs(after - before) / kV;
  const double speed = 20e-3 / (arrival(s, 2) - arrival(s, 1));
  EXPECT_LT(reflected, 0.02);
  EXPECT_NEAR(speed, kC, 0.01 * kC);
  // Plateau in the lattice (1.5%, the lattice wave test's bound).
  EXPECT_NEAR(mean(s, 1, arrival(s, 1) + 1.5e-6, s.t.back()), kV, 0.015 * kV);
  RecordProperty("reflected_fraction", std::to_string(reflected));
  RecordProperty("speed_error_de", std::to_string(speed / kC - 1));
}

// Case A: discs in the lower half of the strip, FE in the upper half; the wave runs along the
// interface. Both halves must carry it at c (1%), with the same plateau (2%).
TEST(Interface, CaseAWaveAlongFeDeInterface) {
  Shape lower;
  lower.width = 80e-3;
  lower.height = 2e-3;
  Case c = strip(160, 8, lower);
  test::add_probe(c, "fe1", 20e-3, 3.5e-3);
  test::add_probe(c, "fe2", 50e-3, 3.5e-3);
  test::add_probe(c, "de1", 20e-3, 0.5e-3);
  test::add_probe(c, "de2", 50e-3, 0.5e-3);
  const Series s = run(c);
  const double speed_fe = 30e-3 / (arrival(s, 1) - arrival(s, 0));
  const double speed_de = 30e-3 / (arrival(s, 3) - arrival(s, 2));
  EXPECT_NEAR(speed_fe, kC, 0.01 * kC);
  EXPECT_NEAR(speed_de, kC, 0.01 * kC);
  const double v_fe = mean(s, 1, arrival(s, 1) + 1.5e-6, s.t.back());
  const double v_de = mean(s, 3, arrival(s, 3) + 1.5e-6, s.t.back());
  EXPECT_NEAR(v_fe, v_de, 0.02 * kV);
  RecordProperty("speed_error_fe", std::to_string(speed_fe / kC - 1));
  RecordProperty("speed_error_de", std::to_string(speed_de / kC - 1));
  RecordProperty("plateau_difference", std::to_string((v_de - v_fe) / kV));
}

}  // namespace
}  // namespace fracta
