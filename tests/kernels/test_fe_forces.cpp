// FE kernel tests: patch test on a distorted mesh, rigid-body motions, hourglass control.
#include <gtest/gtest.h>

#include <cmath>

#include "host/model.hpp"
#include "host/simulation.hpp"
#include "kernels/energy.hpp"
#include "kernels/fe_forces.hpp"
#include "test_util.hpp"

namespace fracta {
namespace {

// Moves interior nodes of the model's mesh by a deterministic pseudo-random offset of up to
// `amount` cell sizes (reference and current positions alike), and sets v = v0 + L x, or, when
// theta != 0, the velocity of an exact rigid rotation by theta over the step dt:
// x(n+1) = x, x(n) = R(theta)^T x, v = (x(n+1) - x(n)) / dt + v0.
void distort_and_set_velocity(Model& m, double amount, const double L[2][2], const double v0[2],
                              double theta = 0.0, double dt = 1.0) {
  auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), m.nodes.x);
  auto v = Kokkos::create_mirror_view_and_copy(HostSpace(), m.nodes.v);
  const double h = m.scene.bodies[0].cell_size;
  const double W = m.scene.bodies[0].shape.width, H = m.scene.bodies[0].shape.height;
  for (int n = 0; n < m.nodes.count; ++n) {
    const bool interior =
        x(n, 0) > 1e-12 && x(n, 0) < W - 1e-12 && x(n, 1) > 1e-12 && x(n, 1) < H - 1e-12;
    if (interior) {
      x(n, 0) += amount * h * std::sin(12.9898 * n + 1.0);
      x(n, 1) += amount * h * std::sin(78.233 * n + 2.0);
    }
    if (theta != 0.0) {
      const double c = std::cos(theta), sn = std::sin(theta);
      const double xn[2] = {c * x(n, 0) + sn * x(n, 1), -sn * x(n, 0) + c * x(n, 1)};
      for (int d = 0; d < 2; ++d) v(n, d) = v0[d] + (x(n, d) - xn[d]) / dt;
    } else {
      for (int d = 0; d < 2; ++d) v(n, d) = v0[d] + L[d][0] * x(n, 0) + L[d][1] * x(n, 1);
    }
  }
  Kokkos::deep_copy(m.nodes.x, x);
  Kokkos::deep_copy(m.nodes.x0, x);
  Kokkos::deep_copy(m.nodes.v, v);
}

struct PatchResult {
  double max_stress_error = 0;    // relative to the exact stress magnitude
  double max_interior_force = 0;  // relative to sigma h t
  double max_stress = 0;          // absolute (Pa)
};

PatchResult run_patch(Formulation f, int qp, const double L[2][2], const double v0[2],
                      double theta) {
  const bool rigid = theta != 0.0 || (L[0][0] == 0 && L[0][1] == 0 && L[1][0] == 0 && L[1][1] == 0);
  Case c = test::rectangle_case(5, 4, 1e-3, 200e9, 0.3, 7800.0, f);
  c.sim.integration = qp == 4 ? Integration::full : Integration::reduced;
  c.sim.hourglass = HourglassForm::stiffness;  // both hourglass forms must stay silent
  Model m = build_model(c);
  FeParams p = m.fe;
  p.dt = 1e-7;
  distort_and_set_velocity(m, 0.2, L, v0, theta, p.dt);
  const double dt_bound = compute_fe_forces(m.nodes, m.elements, m.materials, p).dt_min;
  EXPECT_GT(dt_bound, 0.0);
  p.hourglass_stiffness = 0;
  Kokkos::deep_copy(m.nodes.f, 0.0);  // second pass with the viscous form: forces only
  Kokkos::deep_copy(m.elements.stress, 0.0);
  compute_fe_forces(m.nodes, m.elements, m.materials, p);

  // Exact stress: the kernel differentiates the increment dt v over the mid-step configuration
  // x - dt/2 v = (I - dt/2 L) x - dt/2 v0, so the exact gradient is Lm = L (I - dt/2 L)^-1 and
  // the strain increment sym(Lm) dt (the midpoint rule; zero for an exact rigid rotation).
  const MaterialLaw law = m.host_materials[0];
  const double a = 1 - 0.5 * p.dt * L[0][0], b = -0.5 * p.dt * L[0][1];
  const double cc = -0.5 * p.dt * L[1][0], d = 1 - 0.5 * p.dt * L[1][1];
  const double det = a * d - b * cc;
  const double inv[2][2] = {{d / det, -b / det}, {-cc / det, a / det}};
  double Lm[2][2];
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) Lm[i][j] = L[i][0] * inv[0][j] + L[i][1] * inv[1][j];
  double exact[4] = {0, 0, 0, 0};
  if (theta == 0.0) {
    const double deps[3] = {Lm[0][0] * p.dt, Lm[1][1] * p.dt, 0.5 * (Lm[0][1] + Lm[1][0]) * p.dt};
    elastic_increment(law, deps, exact);
    // The increment is added in the mid-step frame and turned with the body over the second
    // half of the step (by half the step's spin, Lm's skew part).
    jaumann_rotate(exact, 0.25 * (Lm[0][1] - Lm[1][0]) * p.dt);
  }
  // Rigid: relative to E |theta| (the size of the displacement gradient, for round-off).
  const double scale = rigid ? law.youngs_modulus * std::max(std::fabs(theta), 1e-6)
                             : std::sqrt(exact[0] * exact[0] + exact[1] * exact[1] +
                                         exact[2] * exact[2] + exact[3] * exact[3]);

  PatchResult r;
  auto s = Kokkos::create_mirror_view_and_copy(HostSpace(), m.elements.stress);
  for (size_t q = 0; q < s.extent(0); ++q)
    for (int k = 0; k < 4; ++k) {
      r.max_stress_error = std::max(r.max_stress_error, std::fabs(s(q, k) - exact[k]) / scale);
      r.max_stress = std::max(r.max_stress, std::fabs(s(q, k)));
    }
  auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), m.nodes.x);
  auto fh = Kokkos::create_mirror_view_and_copy(HostSpace(), m.nodes.f);
  const double fscale = scale * 1e-3 * c.sim.thickness;
  for (int n = 0; n < m.nodes.count; ++n) {
    const bool interior =
        x(n, 0) > 1e-9 && x(n, 0) < 5e-3 - 1e-9 && x(n, 1) > 1e-9 && x(n, 1) < 4e-3 - 1e-9;
    if (!interior) continue;
    for (int d = 0; d < 2; ++d)
      r.max_interior_force = std::max(r.max_interior_force, std::fabs(fh(n, d)) / fscale);
  }
  return r;
}

// Patch test: a linear velocity field on a distorted mesh gives the exact constant strain in
// every element and zero resultant force at interior nodes (equilibrium of a constant stress).
// Tolerance 1e-10: only round-off of O(10) flops per value is allowed.
TEST(FeForces, PatchTestConstantStrainOnDistortedMesh) {
  const double L[2][2] = {{3.0, 1.5}, {-0.5, -2.0}};  // 1/s, non-symmetric (strain + spin)
  const double v0[2] = {0.7, -0.3};
  for (Formulation f : {Formulation::plane_strain, Formulation::plane_stress})
    for (int qp : {1, 4}) {
      const PatchResult r = run_patch(f, qp, L, v0, 0.0);
      EXPECT_LT(r.max_stress_error, 1e-10) << to_string(f) << " qp " << qp;
      EXPECT_LT(r.max_interior_force, 1e-10) << to_string(f) << " qp " << qp;
    }
}

// Rigid translation and an exact rigid rotation over the step: the mid-step strain increment
// 2 (R - I)(R + I)^-1 is exactly skew (a Cayley transform), so no stress and no force appear.
// Relative to E * |theta| (1e-6 for translation): only round-off is allowed.
TEST(FeForces, RigidBodyMotionProducesNoStress) {
  const double zero[2][2] = {{0, 0}, {0, 0}};
  const double v0[2] = {12.0, -7.0};
  for (int qp : {1, 4}) {
    for (double theta : {0.0, 0.01, -0.3}) {
      const PatchResult r = run_patch(Formulation::plane_strain, qp, zero, v0, theta);
      EXPECT_LT(r.max_stress_error, 1e-12) << "qp " << qp << " theta " << theta;
      EXPECT_LT(r.max_interior_force, 1e-12) << "qp " << qp << " theta " << theta;
    }
  }
}

// A translating body keeps zero stress over many steps through the full solver.
TEST(FeForces, TranslationOverManyStepsStaysStressFree) {
  Case c = test::rectangle_case(4, 3, 1e-3);
  c.bodies[0].initial_velocity = {150.0, -40.0};
  c.sim.end_time = 2e-5;
  Simulation sim(c);
  while (sim.time() < c.sim.end_time * (1 - 1e-12) && !sim.failed()) sim.step();
  EXPECT_GT(sim.steps(), 100);
  const HistoryRecord h = sim.history();
  const double ke = 0.5 * h.mass * (150.0 * 150.0 + 40.0 * 40.0);
  EXPECT_NEAR(h.energy.kinetic, ke, 1e-12 * ke);
  EXPECT_LT(h.energy.internal, 1e-20 * ke);
}

// Hourglass mode of a single element: v_a = h_a (V, 0) with h = (1, -1, 1, -1).
// Without control it is a zero-energy mode (no stress, kinetic energy kept); with viscous control
// it decays and the hourglass work accounts for the lost kinetic energy; with stiffness control
// it oscillates with its energy stored in the hourglass term.
struct HourglassRun {
  double kinetic0, kinetic, hourglass, internal, error;
};

HourglassRun run_hourglass(HourglassForm form, double coefficient, double time,
                           double dt_safety = 0.85) {
  Case c = test::rectangle_case(1, 1, 1e-3);
  c.sim.hourglass = form;
  c.sim.hourglass_coefficient = coefficient;
  c.sim.bulk_viscosity_linear = 0.0;
  c.sim.bulk_viscosity_quadratic = 0.0;
  c.sim.end_time = time;
  c.sim.dt_safety = dt_safety;
  Simulation sim0(c);
  {
    auto v = Kokkos::create_mirror_view_and_copy(HostSpace(), sim0.model().nodes.v);
    const double h[4] = {1, -1, 1, -1};
    for (int a = 0; a < 4; ++a) {  // nodes are numbered row by row: 0,1 bottom; 2,3 top
      const int corner_node[4] = {0, 1, 3, 2};
      v(corner_node[a], 0) = 1.0 * h[a];
      v(corner_node[a], 1) = 0.0;
    }
    Kokkos::deep_copy(sim0.model().nodes.v, v);
  }
  // Restart the energy bookkeeping with the hourglass velocity as the initial state.
  Simulation& sim = sim0;
  const double ke0 = 0.5 * sim.history().mass * 1.0;
  HourglassRun r{ke0, 0, 0, 0, 0};
  while (sim.time() < time * (1 - 1e-12) && !sim.failed()) sim.step();
  const HistoryRecord h = sim.history();
  r.kinetic = h.energy.kinetic;
  r.hourglass = h.energy.hourglass;
  r.internal = h.energy.internal;
  r.error = std::fabs(h.energy.kinetic + h.energy.internal + h.energy.hourglass - ke0) / ke0;
  return r;
}

TEST(FeForces, HourglassModeIsZeroEnergyWithoutControl) {
  const HourglassRun r = run_hourglass(HourglassForm::viscous, 0.0, 2e-6);
  // The mode is orthogonal to every linear field: it produces no strain at the single point.
  EXPECT_NEAR(r.kinetic, r.kinetic0, 1e-9 * r.kinetic0);
  EXPECT_LT(r.internal, 1e-12 * r.kinetic0);
}

TEST(FeForces, ViscousHourglassControlResistsModeAndAccountsEnergy) {
  const HourglassRun r = run_hourglass(HourglassForm::viscous, 0.1, 2e-6);
  EXPECT_LT(r.kinetic, 0.5 * r.kinetic0);  // the mode is damped
  EXPECT_GT(r.hourglass, 0.5 * r.kinetic0);
  // Balance: kinetic + hourglass work = initial kinetic energy. The viscous work is integrated
  // with the half-step velocity, an O(dt^2) difference: 1e-3 is ample and still strict.
  EXPECT_LT(r.error, 1e-3);
}

TEST(FeForces, StiffnessHourglassControlStoresModeEnergy) {
  const HourglassRun r = run_hourglass(HourglassForm::stiffness, 0.1, 2e-6);
  EXPECT_LT(r.kinetic, 0.999 * r.kinetic0);  // resisted: energy moved into the hourglass spring
  // Central differences conserve energy up to the bounded term (dt^2/8) f.a, which for this
  // oscillator is at most (omega dt)^2 / 4 of its energy (no drift). omega^2 = k / M with
  // k = kappa (lambda + 2G) t A sum(b.b) = kappa (lambda + 2G) t * 2 for a square, M = rho A t.
  const double E = 200e9, nu = 0.3, rho = 7800, h = 1e-3;
  const double p_modulus = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu));
  const double omega = std::sqrt(0.1 * p_modulus * 2.0 / (rho * h * h));
  const double dt = 0.85 * (h / std::sqrt(2.0)) / std::sqrt(p_modulus / rho);
  EXPECT_LT(r.error, 0.25 * omega * omega * dt * dt);
  // ... and the error is second order in dt: halving the step divides it by about 4.
  const HourglassRun half = run_hourglass(HourglassForm::stiffness, 0.1, 2e-6, 0.425);
  EXPECT_GT(r.error / half.error, 3.0);
  EXPECT_LT(r.error / half.error, 5.0);
}

// The element kernel runs batches of kLanes elements of one material as one SIMD element
// (simd.hpp; vector loads and stores when the batch's elements are consecutive, lane by lane
// otherwise) and everything else element by element. Both must give the same numbers: the same
// scene is run once as is (batches) and once with its elements alternating between two copies
// of the material (every batch mixed, so element by element). A non-uniform velocity field makes
// some elements yield (or reach the cone and the tension cap) and leaves others elastic, and two
// force evaluations give the second a rotated, non-zero starting stress. Run with every element
// active and with every fifth one removed from the active list (scattered batches). Tolerance:
// 1e-12 of each field's largest value (the two paths may contract a*b+c into FMA differently).
struct LanePathResult {
  std::vector<double> stress, epeq, node_force, work, dissipation;
  double dt = 0;
  int flagged = 0;
  int yielded = 0;
};

LanePathResult run_lane_path(MaterialModel model, Formulation f, int qp, bool mixed, bool holes) {
  Case c = test::rectangle_case(9, 7, 1e-3, 30e9, 0.2, 2600.0, f);
  c.sim.integration = qp == 4 ? Integration::full : Integration::reduced;
  c.sim.hourglass = HourglassForm::stiffness;
  Material& mat = c.materials[0];
  mat.model = model;
  mat.yield_stress = 60e6;  // bilinear_j2
  mat.plastic_modulus = 1e9;
  mat.cohesion = 40e6;  // mohr_coulomb
  mat.friction_angle = 0.5;
  mat.tensile_strength = 20e6;
  mat.conversion_strain = 1e-3;
  c.bodies[0].method = BodyMethod::adaptive;  // the kernel's conversion flags are compared too
  c.sim.conversion_on_tension = true;
  Model m = build_model(c);
  if (mixed) {
    View<MaterialLaw*> two("two_materials", 2);
    auto h = Kokkos::create_mirror_view(two);
    h(0) = h(1) = m.host_materials[0];
    Kokkos::deep_copy(two, h);
    m.materials = two;
    auto em = Kokkos::create_mirror_view_and_copy(HostSpace(), m.elements.material);
    for (size_t e = 0; e < em.extent(0); ++e) em(e) = static_cast<int>(e % 2);
    Kokkos::deep_copy(m.elements.material, em);
  }
  if (holes) {  // every fifth element inactive (as if converted): batches of scattered elements
    auto active = Kokkos::create_mirror_view_and_copy(HostSpace(), m.elements.active);
    int n = 0;
    for (int e = 0; e < m.elements.active_count; ++e)
      if (e % 5 != 2) active(n++) = e;
    m.elements.active_count = n;
    Kokkos::deep_copy(m.elements.active, active);
    update_scatter_plan(m.elements);
  }
  // v = A ((x/W)^2 (1 + y/H), -(y/H)^3 + x y / (W H)): strain increments from 0 (lower left)
  // to about 4e-3 per step (upper right), with spin.
  auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), m.nodes.x);
  auto v = Kokkos::create_mirror_view_and_copy(HostSpace(), m.nodes.v);
  const double W = 9e-3, H = 7e-3, A = 100.0;
  for (int n = 0; n < m.nodes.count; ++n) {
    const double X = x(n, 0) / W, Y = x(n, 1) / H;
    v(n, 0) = A * X * X * (1.0 + Y);
    v(n, 1) = A * (-Y * Y * Y + X * Y);
  }
  Kokkos::deep_copy(m.nodes.v, v);
  FeParams p = m.fe;
  p.dt = 1e-7;
  const ConversionCriterion criterion = conversion_criterion(m);
  View<int> pending("pending");
  View<int*> candidates("candidates", 1024);
  LanePathResult r;
  FeStepSums sums;
  for (int pass = 0; pass < 2; ++pass) {
    Kokkos::deep_copy(m.nodes.f, 0.0);  // the node forces of the second pass
    sums = compute_fe_forces(m.nodes, m.elements, m.materials, p, criterion, pending, candidates);
  }
  r.dt = sums.dt_min;
  r.dissipation = {sums.plastic, sums.hourglass, sums.viscous};
  auto hp = Kokkos::create_mirror_view_and_copy(HostSpace(), pending);
  r.flagged = hp();
  auto s = Kokkos::create_mirror_view_and_copy(HostSpace(), m.elements.stress);
  auto ep = Kokkos::create_mirror_view_and_copy(HostSpace(), m.elements.epeq);
  auto nf = Kokkos::create_mirror_view_and_copy(HostSpace(), m.nodes.f);
  auto rw = Kokkos::create_mirror_view_and_copy(HostSpace(), m.elements.recoverable_work);
  for (size_t q = 0; q < s.extent(0); ++q) {
    for (int k = 0; k < 4; ++k) r.stress.push_back(s(q, k));
    r.epeq.push_back(ep(q));
    if (ep(q) > 0.0) ++r.yielded;
  }
  for (size_t n = 0; n < nf.extent(0); ++n)
    for (int d = 0; d < 2; ++d) r.node_force.push_back(nf(n, d));
  for (size_t e = 0; e < rw.extent(0); ++e) r.work.push_back(rw(e));
  return r;
}

TEST(FeForces, SimdBatchesMatchElementByElement) {
  for (MaterialModel model :
       {MaterialModel::elastic, MaterialModel::bilinear_j2, MaterialModel::mohr_coulomb})
    for (Formulation f : {Formulation::plane_strain, Formulation::plane_stress})
      for (int qp : {1, 4}) {
        SCOPED_TRACE(::testing::Message() << "model " << static_cast<int>(model) << " plane_strain "
                                          << (f == Formulation::plane_strain) << " qp " << qp);
        for (bool holes : {false, true}) {
          SCOPED_TRACE(holes ? "with inactive elements" : "all active");
          const LanePathResult batched = run_lane_path(model, f, qp, false, holes);
          const LanePathResult single = run_lane_path(model, f, qp, true, holes);
          ASSERT_EQ(batched.stress.size(), single.stress.size());
          EXPECT_LT(test::max_relative_difference(batched.stress, single.stress), 1e-12);
          EXPECT_LT(test::max_relative_difference(batched.epeq, single.epeq), 1e-12);
          EXPECT_LT(test::max_relative_difference(batched.node_force, single.node_force), 1e-12);
          EXPECT_LT(test::max_relative_difference(batched.work, single.work), 1e-12);
          EXPECT_LT(test::max_relative_difference(batched.dissipation, single.dissipation), 1e-12);
          EXPECT_NEAR(batched.dt, single.dt, 1e-12 * single.dt);
          EXPECT_EQ(batched.flagged, single.flagged);
          EXPECT_EQ(batched.yielded, single.yielded);
          if (model != MaterialModel::elastic) {
            // Not vacuous: some points yield and some stay elastic.
            EXPECT_GT(batched.yielded, 0);
            EXPECT_LT(batched.yielded, static_cast<int>(batched.epeq.size()));
          }
        }
      }
}

}  // namespace
}  // namespace fracta
