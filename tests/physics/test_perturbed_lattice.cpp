// The perturbed lattice ([[body]] node_perturbation; docs/physics.md 1.2, "Heterogeneity"): the
// interior nodes move at set-up by up to a fraction of the cell, so that cracks do not follow the
// square lattice's lines. The lattice must stay isotropic in the mean (elastic constants and wave
// speeds along 0 and 45 degrees against the continuum's) and its cracks must lose the lattice's
// bias of direction.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "host/case.hpp"
#include "host/cracks.hpp"
#include "host/simulation.hpp"
#include "test_util.hpp"

namespace fracta {
namespace {

constexpr double kE = 72e9, kNu = 0.25, kRho = 2440;  // a glass-like solid, plane stress

struct Moduli {
  double youngs = 0, poisson = 0;
};

// Uniaxial stress sigma along n = (cos theta, sin theta) on a free 30 x 30 mm lattice block
// (1 mm cells): tractions sigma (n . normal) n on its four edges, ramped over about 40 transit
// times so that the response is quasi-static. E and nu come from the least-squares slope of the
// strain along n (and across it) against the applied stress over the second half of the ramp,
// the strain from an affine fit of the displacements of the nodes more than two cells inside.
Moduli measure_moduli(double theta, double perturbation, std::uint64_t seed) {
  const double h = 1e-3, L = 30e-3, sigma = 20e6;
  Case c = test::rectangle_case(30, 30, h, kE, kNu, kRho, Formulation::plane_stress);
  c.bodies[0].method = BodyMethod::de;
  c.bodies[0].node_perturbation = perturbation;
  c.sim.seed = seed;
  const double wave = std::sqrt(kE / (kRho * (1 - kNu * kNu)));
  const double ramp = 40 * L / wave;
  c.sim.end_time = ramp;
  const Vec2 n{std::cos(theta), std::sin(theta)};
  const double on_x = std::fabs(n[0]) * sigma, on_y = std::fabs(n[1]) * sigma;
  const double sx = n[0] >= 0 ? 1 : -1, sy = n[1] >= 0 ? 1 : -1;
  // Traction sigma (n . m) n on the edge of outward normal m.
  if (on_x > 0) {
    test::add_traction(c, test::segment(L, 0, L, L), {sx * n[0], sx * n[1]}, {0, ramp}, {0, on_x});
    test::add_traction(c, test::segment(0, 0, 0, L), {-sx * n[0], -sx * n[1]}, {0, ramp},
                       {0, on_x});
  }
  if (on_y > 1e-9 * sigma) {
    test::add_traction(c, test::segment(0, L, L, L), {sy * n[0], sy * n[1]}, {0, ramp}, {0, on_y});
    test::add_traction(c, test::segment(0, 0, L, 0), {-sy * n[0], -sy * n[1]}, {0, ramp},
                       {0, on_y});
  }
  Simulation sim(c);
  Nodes& nodes = sim.model().nodes;
  auto x0 = Kokkos::create_mirror_view_and_copy(HostSpace(), nodes.x0);
  std::vector<int> inner;
  for (int i = 0; i < nodes.count; ++i)
    if (std::min({x0(i, 0), x0(i, 1), L - x0(i, 0), L - x0(i, 1)}) > 2.5 * h) inner.push_back(i);
  Eigen::MatrixXd A(inner.size(), 3);
  for (size_t k = 0; k < inner.size(); ++k) A.row(k) << x0(inner[k], 0), x0(inner[k], 1), 1.0;
  const auto solver = A.colPivHouseholderQr();
  std::vector<double> stress, along, across;
  while (sim.time() < ramp * (1 - 1e-12) && !sim.failed()) {
    sim.step();
    if (sim.time() < 0.5 * ramp || sim.steps() % 5 != 0) continue;
    auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), nodes.x);
    Eigen::VectorXd ux(inner.size()), uy(inner.size());
    for (size_t k = 0; k < inner.size(); ++k) {
      ux(k) = x(inner[k], 0) - x0(inner[k], 0);
      uy(k) = x(inner[k], 1) - x0(inner[k], 1);
    }
    const Eigen::Vector3d gx = solver.solve(ux), gy = solver.solve(uy);
    const double exx = gx(0), eyy = gy(1), exy = 0.5 * (gx(1) + gy(0));
    stress.push_back(sigma * sim.time() / ramp);
    along.push_back(n[0] * n[0] * exx + 2 * n[0] * n[1] * exy + n[1] * n[1] * eyy);
    across.push_back(n[1] * n[1] * exx - 2 * n[0] * n[1] * exy + n[0] * n[0] * eyy);
  }
  EXPECT_FALSE(sim.failed()) << sim.failure();
  // Slopes through the least-squares line (offsets from the start of the window cancel).
  auto slope = [&](const std::vector<double>& y) {
    double ms = 0, my = 0;
    for (size_t k = 0; k < y.size(); ++k) ms += stress[k], my += y[k];
    ms /= y.size(), my /= y.size();
    double num = 0, den = 0;
    for (size_t k = 0; k < y.size(); ++k)
      num += (stress[k] - ms) * (y[k] - my), den += (stress[k] - ms) * (stress[k] - ms);
    return num / den;
  };
  const double compliance = slope(along);
  return {1 / compliance, -slope(across) / compliance};
}

// A cylindrical P wave from an explosive source (four equal forces pushing outwards from the
// centre of a 50 x 50 mm plate, 0.5 mm cells, a 1.5 us triangular pulse): its speed along 0 and
// 45 degrees from the half-amplitude arrivals of the radial velocity at the nodes nearest 8 and
// 20 mm from the centre, before any reflection returns. Returns {c(0), c(45)} (m/s).
std::pair<double, double> measure_wave_speeds(double perturbation, std::uint64_t seed) {
  const double h = 0.5e-3, mid = 25e-3, pulse = 1.5e-6, force = 2e3;
  Case c = test::rectangle_case(100, 100, h, kE, kNu, kRho, Formulation::plane_stress);
  c.bodies[0].method = BodyMethod::de;
  c.bodies[0].node_perturbation = perturbation;
  c.sim.seed = seed;
  const double wave = std::sqrt(kE / (kRho * (1 - kNu * kNu)));
  c.sim.end_time = 20e-3 / wave + 2 * pulse;
  const double dirs[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
  for (const auto& d : dirs) {
    Load l;
    l.type = Load::Type::force;
    l.body = "block";
    l.body_index = 0;
    l.where.kind = NodeSelector::Kind::shape;
    l.where.shape.type = Shape::Type::rectangle;
    // The nodes 1 to 2 cells from the centre on the force's side, 3 cells wide.
    l.where.shape.x = mid + (d[0] != 0 ? d[0] * 1.5 * h - 0.5 * h : -1.5 * h);
    l.where.shape.y = mid + (d[1] != 0 ? d[1] * 1.5 * h - 0.5 * h : -1.5 * h);
    l.where.shape.width = d[0] != 0 ? h : 3 * h;
    l.where.shape.height = d[1] != 0 ? h : 3 * h;
    l.direction = {d[0], d[1]};
    l.time = {0, 0.5 * pulse, pulse};
    l.value = {0, force, 0};
    c.loads.push_back(l);
  }
  Simulation sim(c);
  Nodes& nodes = sim.model().nodes;
  auto x0 = Kokkos::create_mirror_view_and_copy(HostSpace(), nodes.x0);
  // Receivers: along 0 and 45 degrees at 8 and 20 mm.
  struct Receiver {
    int node = -1;
    double distance = 0;
    Vec2 direction{0, 0};
    std::vector<double> radial_velocity;
  };
  std::vector<Receiver> receivers;
  for (const double angle : {0.0, M_PI / 4})
    for (const double r : {8e-3, 20e-3}) {
      const double px = mid + r * std::cos(angle), py = mid + r * std::sin(angle);
      Receiver rc;
      double best = 1e300;
      for (int i = 0; i < nodes.count; ++i) {
        const double d = std::hypot(x0(i, 0) - px, x0(i, 1) - py);
        if (d < best) best = d, rc.node = i;
      }
      const double dx = x0(rc.node, 0) - mid, dy = x0(rc.node, 1) - mid;
      rc.distance = std::hypot(dx, dy);
      rc.direction = {dx / rc.distance, dy / rc.distance};
      receivers.push_back(rc);
    }
  std::vector<double> time;
  while (sim.time() < c.sim.end_time * (1 - 1e-12) && !sim.failed()) {
    sim.step();
    auto v = Kokkos::create_mirror_view_and_copy(HostSpace(), nodes.v);
    time.push_back(sim.time());
    for (Receiver& rc : receivers)
      rc.radial_velocity.push_back(v(rc.node, 0) * rc.direction[0] +
                                   v(rc.node, 1) * rc.direction[1]);
  }
  EXPECT_FALSE(sim.failed()) << sim.failure();
  std::vector<double> arrival;
  for (const Receiver& rc : receivers) {
    // The first peak: the largest radial velocity before the pulse has passed.
    const double by = rc.distance / wave + 1.5 * pulse;
    double peak = 0;
    for (size_t k = 0; k < time.size() && time[k] < by; ++k)
      peak = std::max(peak, rc.radial_velocity[k]);
    arrival.push_back(test::arrival_time(time, rc.radial_velocity, 0.5 * peak));
  }
  return {(receivers[1].distance - receivers[0].distance) / (arrival[1] - arrival[0]),
          (receivers[3].distance - receivers[2].distance) / (arrival[3] - arrival[2])};
}

// A mode-I crack at an angle to the lattice: a 40 x 16 mm strip whose axis is turned `alpha`
// against the lattice's x axis, with a 4 mm edge notch across its middle, pulled apart by
// velocity boundaries on its two ends (ramped to 0.1 m/s over 20 us). Mode I: the crack runs
// straight on from the notch, across the strip, at alpha + 90 degrees. Returns the crack's angle
// against that line (degrees): the line through the notch tip fitted to the crack's path from
// 1 to 8 mm from it, as the Kalthoff-Winkler test measures.
double crack_deviation(double alpha_deg, double perturbation, std::uint64_t seed) {
  const double alpha = alpha_deg * M_PI / 180, ca = std::cos(alpha), sa = std::sin(alpha);
  const double cx = 30e-3, cy = 30e-3;  // the strip's centre
  // World point of strip coordinates (s along the axis, n across it), in mm.
  auto at = [&](double s, double n) {
    return std::array<double, 2>{cx + 1e-3 * (s * ca - n * sa), cy + 1e-3 * (s * sa + n * ca)};
  };
  auto polygon = [&](double s0, double s1, double n0, double n1) {
    std::string out = "[";
    for (const auto& p : {at(s0, n0), at(s1, n0), at(s1, n1), at(s0, n1)})
      out += "[" + std::to_string(p[0]) + ", " + std::to_string(p[1]) + "], ";
    return out + "]";
  };
  std::string text = R"(
[simulation]
formulation = "plane_stress"
thickness = 1e-3
end_time = 60e-6
seed = )" + std::to_string(seed) +
                     R"(
[[material]]
name = "rock"
model = "elastic"
density = 2440.0
youngs_modulus = 72e9
poisson_ratio = 0.25
tensile_strength = 20e6
fracture_energy = 10.0
[[body]]
name = "strip"
material = "rock"
method = "de"
cell_size = 2.5e-4
node_perturbation = )" +
                     std::to_string(perturbation) + R"(
shape = { type = "polygon", points = )" +
                     polygon(-20, 20, -8, 8) + R"( }
[[body.cut]]
type = "polygon"
points = )" + polygon(-0.3, 0.3, -9, -4) +
                     "\n";
  for (const int side : {-1, 1})
    for (const int k : {0, 1}) {
      const double v = 0.1 * side * (k == 0 ? ca : sa);
      text += "[[boundary]]\ntype = \"velocity\"\ncomponent = \"" +
              std::string(k == 0 ? "x" : "y") + "\"\nshape = { type = \"polygon\", points = " +
              polygon(side < 0 ? -21 : 19, side < 0 ? -19 : 21, -9, 9) +
              " }\ntime = [0.0, 20e-6]\nvalue = [0.0, " + std::to_string(v) + "]\n";
    }
  Case c = parse_case(text, "<rotated strip>");
  Simulation sim(c);
  test::run_to_end(sim, 1000);
  EXPECT_FALSE(sim.failed()) << sim.failure();
  const auto tip = at(0, -4);
  const Vec2 notch_tip{tip[0], tip[1]};
  const double h = 2.5e-4;
  const CrackTrace t = trace_crack(sim, notch_tip, 2 * h, 10 * h);
  EXPECT_TRUE(t.found);
  int used = 0;
  const double angle = test::path_angle_through(t, notch_tip, 1e-3, 8e-3, &used);
  EXPECT_GT(used, 10) << "the crack is " << t.length * 1e3 << " mm long";
  return test::line_angle(angle - (alpha_deg + 90));
}

// The Kalthoff-Winkler plate turned 30 degrees against the lattice
// (cases/validation/kalthoff_winkler_turned.toml: the full model, 1 mm cells). Its two cracks
// are mirror images in the plate, so any difference of their angles is the lattice's. Returns the
// angles of the upper and lower crack against the notch line (degrees), each the line through
// its notch tip fitted to its path from 5 to 25 mm from the tip.
std::array<double, 2> turned_kalthoff_angles(double perturbation, std::uint64_t seed) {
  const double alpha = 30 * M_PI / 180, ca = std::cos(alpha), sa = std::sin(alpha);
  const double cx = 60e-3, cy = 120e-3;  // the plate's origin (struck edge, midline)
  auto at = [&](double s, double n) {    // plate coordinates in mm -> world (m)
    return std::array<double, 2>{cx + 1e-3 * (s * ca - n * sa), cy + 1e-3 * (s * sa + n * ca)};
  };
  const Case c =
      load_case(std::string(FRACTA_SOURCE_DIR) + "/cases/validation/kalthoff_winkler_turned.toml",
                {"body.plate.node_perturbation=" + std::to_string(perturbation),
                 "simulation.seed=" + std::to_string(seed)});
  Simulation sim(c);
  test::run_to_end(sim, 1000);
  EXPECT_FALSE(sim.failed()) << sim.failure();
  std::array<double, 2> angles{0, 0};
  for (const int side : {1, -1}) {
    const auto tip = at(50, side * 25);
    const CrackTrace t = trace_crack(sim, Vec2{tip[0], tip[1]}, 2e-3, 10e-3);
    EXPECT_TRUE(t.found);
    int used = 0;
    const double world = test::path_angle_through(t, Vec2{tip[0], tip[1]}, 5e-3, 25e-3, &used);
    EXPECT_GE(used, 5) << "side " << side << ": the crack is " << t.length * 1e3 << " mm long";
    // In the plate's axes, the lower crack mirrored onto the upper one.
    angles[side > 0 ? 0 : 1] = test::line_angle(side * (world - 30));
  }
  return angles;
}

// Published answer: about 70 degrees (Kalthoff & Winkler 1987), tolerance 5 degrees, as
// KalthoffWinkler.*: the mean over the two cracks of seeds 1 to 4 at delta = 0.15, a path that
// runs off the lattice's lines. The regular lattice's two angles are recorded beside it.
TEST(PerturbedLattice, TurnedKalthoffWinklerCracksLeaveAtSeventyDegreesInTheMean) {
  const auto regular = turned_kalthoff_angles(0.0, 1);
  double sum = 0, sum2 = 0;
  for (const std::uint64_t seed : {1u, 2u, 3u, 4u}) {
    const auto a = turned_kalthoff_angles(0.15, seed);
    for (const double angle : a) sum += angle, sum2 += angle * angle;
    ::testing::Test::RecordProperty("angles_deg_seed" + std::to_string(seed),
                                    std::to_string(a[0]) + " " + std::to_string(a[1]));
  }
  const double mean = sum / 8, spread = std::sqrt(std::max(0.0, sum2 / 8 - mean * mean));
  EXPECT_NEAR(mean, 70.0, 5.0);
  ::testing::Test::RecordProperty("mean_deg", std::to_string(mean));
  ::testing::Test::RecordProperty("standard_deviation_deg", std::to_string(spread));
  ::testing::Test::RecordProperty("regular_deg",
                                  std::to_string(regular[0]) + " " + std::to_string(regular[1]));
}

// Published answer: the mode-I line (exact by symmetry). Tolerance 5 degrees, the Kalthoff-
// Winkler test's. The regular lattice runs it too at 30 degrees (measured -0.26 degrees: in mode
// I its staircase averages out); the perturbed one scatters about it (-0.91, -4.35, -0.19 and
// 4.20 degrees for seeds 1 to 4 at 0.15), with a mean of a degree or less.
TEST(PerturbedLattice, ModeICrackRunsOnAcrossTheTurnedLattice) {
  const double regular = crack_deviation(30, 0.0, 1);
  EXPECT_NEAR(regular, 0.0, 5.0);
  double sum = 0;
  for (const std::uint64_t seed : {1u, 2u, 3u, 4u}) {
    const double d = crack_deviation(30, 0.15, seed);
    EXPECT_NEAR(d, 0.0, 5.0) << "seed " << seed;
    sum += d;
    ::testing::Test::RecordProperty("deviation_deg_seed" + std::to_string(seed), std::to_string(d));
  }
  EXPECT_NEAR(sum / 4, 0.0, 2.0);
  ::testing::Test::RecordProperty("deviation_deg_regular", std::to_string(regular));
}

// Published answer: the continuum's P-wave speed, the same along every direction. A cylindrical
// wave's half-amplitude arrivals give the speed within about 2 % (the regular lattice: 0.978 and
// 0.996 of c_P along 0 and 45 degrees; its dispersion at this 8.4 mm pulse differs with the
// direction by 1.8 %). Tolerance: 3 % of c_P in each direction, and the two directions within 1 %
// (measured 0.05 % and 0.25 % for seeds 1 and 2 at 0.15).
TEST(PerturbedLattice, WaveSpeedIsTheSameAlongZeroAndFortyFiveDegrees) {
  const double wave = std::sqrt(kE / (kRho * (1 - kNu * kNu)));
  const auto regular = measure_wave_speeds(0.0, 1);
  ::testing::Test::RecordProperty("regular_c0_over_cP", std::to_string(regular.first / wave));
  ::testing::Test::RecordProperty("regular_c45_over_cP", std::to_string(regular.second / wave));
  for (const std::uint64_t seed : {1u, 2u}) {
    const auto c = measure_wave_speeds(0.15, seed);
    EXPECT_NEAR(c.first, wave, 0.03 * wave) << "seed " << seed;
    EXPECT_NEAR(c.second, wave, 0.03 * wave) << "seed " << seed;
    EXPECT_NEAR(c.second / c.first, 1.0, 0.01) << "seed " << seed;
    ::testing::Test::RecordProperty("c45_over_c0_seed" + std::to_string(seed),
                                    std::to_string(c.second / c.first));
  }
}

// Published answer: the continuum's E and nu (exact). The measurement's own accuracy is that of
// the regular lattice, which holds them exactly: measured E +0.13 %, nu -0.0014 (tolerance 0.5 %
// and 0.005). The perturbed lattice is softer by non-affine relaxation, about delta^2 / 2 (E
// -1.1 % and -0.4 % along 0 and 45 degrees at delta = 0.15; -3.4 % and -1.5 % at 0.25).
// Tolerances: at 0.15, E within 1.5 % (the lattice's plane-wave tolerance) and nu within 0.01 in
// both directions, the directions within 1 % of each other; at 0.25, the largest allowed,
// E within 5 %, nu within 0.03, the directions within 3 %.
TEST(PerturbedLattice, ElasticConstantsStayIsotropicInTheMean) {
  struct Tolerance {
    double perturbation, youngs, poisson, directions;
  };
  for (const Tolerance& tol :
       {Tolerance{0.0, 0.005, 0.005, 0.005}, Tolerance{0.15, 0.015, 0.01, 0.01},
        Tolerance{0.25, 0.05, 0.03, 0.03}})
    for (const std::uint64_t seed : {1u, 2u}) {
      const Moduli along_0 = measure_moduli(0.0, tol.perturbation, seed);
      const Moduli along_45 = measure_moduli(M_PI / 4, tol.perturbation, seed);
      const std::string what =
          "perturbation " + std::to_string(tol.perturbation) + " seed " + std::to_string(seed);
      for (const Moduli& m : {along_0, along_45}) {
        EXPECT_NEAR(m.youngs, kE, tol.youngs * kE) << what;
        EXPECT_NEAR(m.poisson, kNu, tol.poisson) << what;
      }
      EXPECT_NEAR(along_45.youngs / along_0.youngs, 1.0, tol.directions) << what;
      const std::string tag =
          "p" + std::to_string(int(100 * tol.perturbation)) + "_seed" + std::to_string(seed) + "_";
      ::testing::Test::RecordProperty(tag + "E0", std::to_string(along_0.youngs / kE));
      ::testing::Test::RecordProperty(tag + "E45", std::to_string(along_45.youngs / kE));
      ::testing::Test::RecordProperty(tag + "nu0", std::to_string(along_0.poisson));
      ::testing::Test::RecordProperty(tag + "nu45", std::to_string(along_45.poisson));
      if (tol.perturbation == 0) break;  // the regular lattice has no realisations
    }
}

}  // namespace
}  // namespace fracta
