// Material-point tests of the pointwise material laws (src/kernels/materials.hpp,
// docs/physics.md 1.1). The laws are KOKKOS_INLINE_FUNCTIONs, host-callable, so most tests drive
// one material point on the host; MaterialDevice.* runs update_stress inside a
// Kokkos::parallel_for.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

#include "kernels/materials.hpp"

namespace {

using fracta::MaterialLaw;
using fracta::update_stress;

constexpr double kPi = 3.14159265358979323846;

MaterialLaw steel(bool plane_strain) {
  MaterialLaw m = fracta::make_material_law(fracta::kBilinearJ2, plane_strain, 7850.0, 200e9, 0.3);
  m.yield_stress = 250e6;
  m.plastic_modulus = 2e9;
  return m;
}

// Rock-like Mohr-Coulomb material: c = 10 MPa, phi = 30 deg, cut-off 2 MPa.
MaterialLaw rock(bool plane_strain, double tensile_strength = 2e6, double phi = kPi / 6.0) {
  MaterialLaw m = fracta::make_material_law(fracta::kMohrCoulomb, plane_strain, 2600.0, 30e9, 0.2);
  m.cohesion = 10e6;
  m.friction_angle = phi;
  m.tensile_strength = tensile_strength;
  return m;
}

double von_mises(const double s[4]) {
  const double a = s[0] - s[1], b = s[1] - s[2], c = s[2] - s[0];
  return std::sqrt(0.5 * (a * a + b * b + c * c) + 3.0 * s[3] * s[3]);
}

// Cone constants expected by the tests, written out independently of the kernel: the
// zero-dilatancy plane-strain match alpha = sin(phi)/3, k = c cos(phi).
double dp_alpha(const MaterialLaw& m) {
  return std::sin(m.friction_angle) / 3.0;
}
double dp_k(const MaterialLaw& m) {
  return m.cohesion * std::cos(m.friction_angle);
}
double dp_f(const MaterialLaw& m, const double s[4]) {
  const double p = (s[0] + s[1] + s[2]) / 3.0;
  const double d0 = s[0] - p, d1 = s[1] - p, d2 = s[2] - p;
  return std::sqrt(0.5 * (d0 * d0 + d1 * d1 + d2 * d2) + s[3] * s[3]) + dp_alpha(m) * 3.0 * p -
         dp_k(m);
}

// Largest principal stress including sigma_zz.
double max_principal(const double s[4]) {
  const double c = 0.5 * (s[0] + s[1]), h = 0.5 * (s[0] - s[1]);
  return std::max(c + std::sqrt(h * h + s[3] * s[3]), s[2]);
}

// Elastic strain C^-1 s (3D isotropic compliance, tensor shear), {xx, yy, zz, xy}.
void elastic_strain(const MaterialLaw& m, const double s[4], double e[4]) {
  const double E = m.youngs_modulus, nu = m.poisson_ratio;
  e[0] = (s[0] - nu * (s[1] + s[2])) / E;
  e[1] = (s[1] - nu * (s[2] + s[0])) / E;
  e[2] = (s[2] - nu * (s[0] + s[1])) / E;
  e[3] = s[3] / (2.0 * m.shear_modulus);
}

// Plane-stress uniaxial-stress driver: for a given d eps_xx (and d eps_xy = 0), finds
// d eps_yy such that s_yy = 0 after the update (secant iteration on the lateral stress, to
// |s_yy| <= 1e-12 of the stress scale), then commits the update. Returns the dissipation and
// writes the d eps_yy used.
double uniaxial_stress_step(const MaterialLaw& m, double dexx, double s[4], double& epeq,
                            double& deyy_out) {
  auto lateral = [&](double deyy, double st[4], double& ep, double& w) {
    for (int i = 0; i < 4; ++i) st[i] = s[i];
    ep = epeq;
    const double d[3] = {dexx, deyy, 0.0};
    w = update_stress(m, d, st, ep);
    return st[1];
  };
  double st[4], ep, w;
  double x0 = -m.poisson_ratio * dexx, x1 = -0.5 * dexx;
  double f0 = lateral(x0, st, ep, w), f1 = lateral(x1, st, ep, w);
  const double scale = std::fabs(s[0]) + m.yield_stress + m.tensile_strength + m.cohesion;
  for (int it = 0; it < 100 && std::fabs(f1) > 1e-12 * scale && f1 != f0; ++it) {
    const double x2 = x1 - f1 * (x1 - x0) / (f1 - f0);
    x0 = x1;
    f0 = f1;
    x1 = x2;
    f1 = lateral(x1, st, ep, w);
  }
  EXPECT_LE(std::fabs(f1), 1e-12 * scale) << "lateral-stress iteration did not converge";
  lateral(x1, st, ep, w);
  for (int i = 0; i < 4; ++i) s[i] = st[i];
  epeq = ep;
  deyy_out = x1;
  return w;
}

// ------------------------------------------------------------------------------------------
// Elastic
// ------------------------------------------------------------------------------------------

TEST(MaterialElastic, EnergyDensityEqualsHalfEpsCEps) {
  for (int ps = 0; ps < 2; ++ps) {
    MaterialLaw m = fracta::make_material_law(fracta::kElastic, ps == 1, 7850.0, 200e9, 0.3);
    const double strains[3][3] = {{1e-3, -4e-4, 2.5e-4}, {-2e-3, -1e-3, 0.0}, {0.0, 0.0, 7e-4}};
    for (const auto& eps : strains) {
      double s[4] = {0, 0, 0, 0}, epeq = 0.0;
      const double w = update_stress(m, eps, s, epeq);
      EXPECT_EQ(w, 0.0);
      EXPECT_EQ(epeq, 0.0);
      // Independent 1/2 eps:C:eps with the 3D strain (eps_zz = 0 in plane strain,
      // -nu/(1-nu)(eps_xx + eps_yy) in plane stress).
      const double lam = m.lame_lambda, G = m.shear_modulus, nu = m.poisson_ratio;
      const double ezz = m.plane_strain ? 0.0 : -nu / (1.0 - nu) * (eps[0] + eps[1]);
      const double tr = eps[0] + eps[1] + ezz;
      const double ref = 0.5 * lam * tr * tr + G * (eps[0] * eps[0] + eps[1] * eps[1] + ezz * ezz +
                                                    2.0 * eps[2] * eps[2]);
      if (!m.plane_strain) {
        EXPECT_EQ(s[2], 0.0);
      }
      // 1e-12: both sides are a few dozen flops on O(1) numbers, so only roundoff (~1e-16).
      EXPECT_NEAR(fracta::elastic_energy_density(m, s), ref, 1e-12 * ref)
          << (ps ? "plane strain" : "plane stress");
    }
  }
}

// ------------------------------------------------------------------------------------------
// bilinear_j2
// ------------------------------------------------------------------------------------------

// Uniaxial stress in plane stress, loading - unloading - reverse yielding, against the exact
// bilinear curve. Backward Euler is exact on this proportional path (fixed flow direction,
// linear hardening), so only the lateral-stress iteration (1e-12) and roundoff remain.
TEST(MaterialBilinearJ2, PlaneStressUniaxialStressCurveWithUnloading) {
  const MaterialLaw m = steel(false);
  const double E = m.youngs_modulus, H = m.plastic_modulus, sy = m.yield_stress;
  const double Et = E * H / (E + H);
  const double de = 1.7e-5;  // 0.0125 / 1.7e-5 is not an integer: yield falls inside a step
  double s[4] = {0, 0, 0, 0}, epeq = 0.0, eps = 0.0, deyy = 0.0;
  double max_err = 0.0, max_ep_err = 0.0;
  // Loading to 1 % strain (8 x the yield strain).
  while (eps < 0.01) {
    uniaxial_stress_step(m, de, s, epeq, deyy);
    eps += de;
    const double ref = eps <= sy / E ? E * eps : sy + Et * (eps - sy / E);
    max_err = std::max(max_err, std::fabs(s[0] - ref) / sy);
    const double ep_ref = ref > sy ? (ref - sy) / H : 0.0;  // uniaxial: epeq = eps_p
    max_ep_err = std::max(max_ep_err, std::fabs(epeq - ep_ref) / 1e-3);
    ASSERT_EQ(s[2], 0.0);
  }
  const double eps_max = eps, sig_max = s[0], R1 = sy + H * epeq, ep_max = epeq;
  EXPECT_NEAR(sig_max, R1, 1e-10 * R1);
  // Unloading with slope E, then reverse yielding at -R1 (isotropic hardening) on slope Et.
  const double eps_rev = eps_max - (sig_max + R1) / E;
  while (eps > -0.01) {
    uniaxial_stress_step(m, -de, s, epeq, deyy);
    eps -= de;
    const double ref = eps >= eps_rev ? sig_max - E * (eps_max - eps) : -R1 - Et * (eps_rev - eps);
    max_err = std::max(max_err, std::fabs(s[0] - ref) / sy);
    if (eps >= eps_rev) {
      EXPECT_EQ(epeq, ep_max) << "unloading is elastic";
    }
  }
  EXPECT_LT(s[0], -R1);  // reached the reverse plastic branch
  // 1e-9 of sigma_y: the path is exact up to the 1e-12 lateral-stress tolerance and roundoff
  // accumulated over ~2300 steps; a wrong hardening slope or return would be off by >= 1e-3.
  EXPECT_LT(max_err, 1e-9);
  EXPECT_LT(max_ep_err, 1e-9);
  std::printf(
      "[info] plane-stress uniaxial: max |sigma - analytic| / sigma_y = %.3g, "
      "max |epeq - analytic| / 1e-3 = %.3g\n",
      max_err, max_ep_err);
}

// Plane-strain pure shear: normal stresses stay 0, tau = 2 G eps_xy up to tau_y = sigma_y/sqrt3,
// then d tau / d gamma = G H / (3G + H) with gamma = 2 eps_xy. Derivation: q = sqrt3 tau,
// d epeq = d q / H = sqrt3 d tau / H; the plastic engineering shear is d gamma_p = sqrt3 d epeq
// (epeq = sqrt(2/3 * 2 eps_p_xy^2) = gamma_p / sqrt3), so d gamma = d tau / G + 3 d tau / H.
TEST(MaterialBilinearJ2, PlaneStrainPureShear) {
  const MaterialLaw m = steel(true);
  const double G = m.shear_modulus, H = m.plastic_modulus, sy = m.yield_stress;
  const double tau_y = sy / std::sqrt(3.0), gamma_y = tau_y / G, slope = G * H / (3.0 * G + H);
  double s[4] = {0, 0, 0, 0}, epeq = 0.0, gamma = 0.0, max_err = 0.0;
  const double dexy = 3.3e-6;
  for (int i = 0; i < 3000; ++i) {
    const double d[3] = {0.0, 0.0, dexy};
    update_stress(m, d, s, epeq);
    gamma += 2.0 * dexy;
    const double ref = gamma <= gamma_y ? G * gamma : tau_y + slope * (gamma - gamma_y);
    max_err = std::max(max_err, std::fabs(s[3] - ref) / tau_y);
    ASSERT_EQ(s[0], 0.0);
    ASSERT_EQ(s[1], 0.0);
    ASSERT_EQ(s[2], 0.0);
  }
  EXPECT_GT(gamma, 10.0 * gamma_y);
  // 1e-10 of tau_y: exact path, roundoff only (~3000 steps x 1e-16 each).
  EXPECT_LT(max_err, 1e-10);
  std::printf("[info] plane-strain shear: max |tau - analytic| / tau_y = %.3g\n", max_err);
}

// Plane-strain uniaxial strain: elastic up to eps_y = sigma_y / (2G) (q = 2 G eps), then
// q = R(epeq) with epeq = (2 G eps - sigma_y) / (3G + H) and p = K eps (isochoric plastic flow):
// s_xx = K eps + 2/3 q, s_yy = s_zz = K eps - q/3.
TEST(MaterialBilinearJ2, PlaneStrainUniaxialStrain) {
  const MaterialLaw m = steel(true);
  const double G = m.shear_modulus, H = m.plastic_modulus, sy = m.yield_stress;
  const double K = m.lame_lambda + 2.0 * G / 3.0, eps_y = sy / (2.0 * G);
  double s[4] = {0, 0, 0, 0}, epeq = 0.0, eps = 0.0;
  const double de = 1.37e-6;  // eps_y / de is not an integer: no step lands on yield
  double max_err = 0.0, max_vm = 0.0;
  bool yielded = false;
  for (int i = 0; i < 5000; ++i) {
    const double d[3] = {de, 0.0, 0.0};
    const double w = update_stress(m, d, s, epeq);
    eps += de;
    EXPECT_GE(w, 0.0);
    // s_yy and s_zz are the same operations on equal numbers: 1e-14 relative is roundoff.
    EXPECT_NEAR(s[1], s[2], 1e-14 * std::fabs(s[1]));
    if (eps <= eps_y) {
      EXPECT_EQ(epeq, 0.0) << "yield before eps_y at eps = " << eps;
      continue;
    }
    yielded = true;
    EXPECT_GT(epeq, 0.0) << "no yield after eps_y at eps = " << eps;
    const double ep_ref = (2.0 * G * eps - sy) / (3.0 * G + H), q = sy + H * ep_ref;
    max_err =
        std::max({max_err, std::fabs(s[0] - (K * eps + 2.0 * q / 3.0)) / sy,
                  std::fabs(s[1] - (K * eps - q / 3.0)) / sy, std::fabs(epeq - ep_ref) / 1e-3});
    max_vm = std::max(max_vm, std::fabs(von_mises(s) - (sy + H * epeq)) / (sy + H * epeq));
  }
  EXPECT_TRUE(yielded);
  // 1e-10 (required by the spec for the yield condition): roundoff only, as for shear.
  EXPECT_LT(max_vm, 1e-10);
  EXPECT_LT(max_err, 1e-10);
  std::printf(
      "[info] plane-strain uniaxial strain: max rel. error vs analytic = %.3g, "
      "max |vm - R| / R = %.3g\n",
      max_err, max_vm);
}

// Multi-axial path with shear and rotating principal directions, cycling in and out of yield.
// The plastic strain is recomputed independently as eps - C^-1 s (plane strain: eps_zz = 0;
// plane stress: s_zz = 0 and J2 flow is isochoric, so eps_p_zz = -(eps_p_xx + eps_p_yy)).
void check_j2_general_path(bool plane_strain) {
  const MaterialLaw m = steel(plane_strain);
  const double sy = m.yield_stress, H = m.plastic_modulus;
  const double ey = sy / m.youngs_modulus;
  const int n = 4000;
  double s[4] = {0, 0, 0, 0}, epeq = 0.0, eps[3] = {0, 0, 0}, ep_old[4] = {0, 0, 0, 0};
  double diss_sum = 0.0, work_sum = 0.0, max_vm = 0.0, max_ep = 0.0;
  int plastic_steps = 0;
  auto path = [&](double t, double e[3]) {  // strain path, amplitude ~ 6 yield strains
    e[0] = 6.0 * ey * std::sin(2.0 * kPi * t) * std::cos(3.0 * t);
    e[1] = 4.0 * ey * std::sin(2.0 * kPi * 1.7 * t + 1.0);
    e[2] = 3.0 * ey * std::sin(2.0 * kPi * 0.6 * t) * std::cos(2.0 * kPi * 1.1 * t);
  };
  for (int i = 1; i <= n; ++i) {
    double e1[3];
    path(3.0 * i / n, e1);
    const double d[3] = {e1[0] - eps[0], e1[1] - eps[1], e1[2] - eps[2]};
    for (int k = 0; k < 3; ++k) eps[k] = e1[k];
    const double ep0 = epeq;
    const double w = update_stress(m, d, s, epeq);
    ASSERT_GE(w, 0.0);
    diss_sum += w;
    if (!plane_strain) {
      ASSERT_EQ(s[2], 0.0);
    }
    double ee[4], ep[4];
    elastic_strain(m, s, ee);
    ep[0] = eps[0] - ee[0];
    ep[1] = eps[1] - ee[1];
    ep[2] = plane_strain ? -ee[2] : -(ep[0] + ep[1]);
    ep[3] = eps[2] - ee[3];
    double dep[4], dd = 0.0;
    for (int k = 0; k < 4; ++k) dep[k] = ep[k] - ep_old[k];
    for (int k = 0; k < 4; ++k) ep_old[k] = ep[k];
    dd = dep[0] * dep[0] + dep[1] * dep[1] + dep[2] * dep[2] + 2.0 * dep[3] * dep[3];
    work_sum += s[0] * dep[0] + s[1] * dep[1] + s[2] * dep[2] + 2.0 * s[3] * dep[3];
    // epeq increment vs the independent plastic strain; normalised by the yield strain since
    // dep comes from differences of O(1e-3) strains (cancellation ~1e-16 * 1e-3 / step).
    max_ep = std::max(max_ep, std::fabs((epeq - ep0) - std::sqrt(2.0 / 3.0 * dd)) / ey);
    if (epeq > ep0) {
      ++plastic_steps;
      const double R = sy + H * epeq;
      max_vm = std::max(max_vm, std::fabs(von_mises(s) - R) / R);
    } else {
      EXPECT_LE(von_mises(s), (sy + H * epeq) * (1.0 + 1e-12));
    }
  }
  EXPECT_GT(plastic_steps, n / 10);
  EXPECT_GT(epeq, 5.0 * ey);
  // 1e-10 (spec): the return enforces the yield condition to roundoff (Newton to 1e-15).
  EXPECT_LT(max_vm, 1e-10);
  // 1e-10 of the yield strain per step: cancellation in eps - C^-1 s is ~1e-16 * 1e-2.
  EXPECT_LT(max_ep, 1e-10);
  // Dissipation = sum of s_{n+1} : d eps_p; relative 1e-9: the independent d eps_p carries the
  // cancellation error above, ~1e-13 relative per step, over 4000 steps.
  EXPECT_NEAR(diss_sum, work_sum, 1e-9 * work_sum);
  std::printf(
      "[info] J2 %s general path: %d plastic steps, max |vm - R| / R = %.3g, "
      "max epeq-increment error / eps_y = %.3g, |sum diss - int s:dep| / int = %.3g\n",
      plane_strain ? "plane-strain" : "plane-stress", plastic_steps, max_vm, max_ep,
      std::fabs(diss_sum - work_sum) / work_sum);
}

TEST(MaterialBilinearJ2, PlaneStressGeneralPath) {
  check_j2_general_path(false);
}
TEST(MaterialBilinearJ2, PlaneStrainGeneralPath) {
  check_j2_general_path(true);
}

// One huge plane-stress step (50 yield strains of pure biaxial + shear): the Simo-Taylor
// return must still land on the yield surface with s_zz = 0; a plane-strain-style 3D return
// followed by zeroing s_zz would not (its von Mises stress would be off by O(1)).
TEST(MaterialBilinearJ2, PlaneStressLargeStepStaysOnYieldSurface) {
  const MaterialLaw m = steel(false);
  const double ey = m.yield_stress / m.youngs_modulus;
  const double cases[3][3] = {
      {50 * ey, 0.0, 0.0}, {50 * ey, 50 * ey, 0.0}, {30 * ey, -20 * ey, 25 * ey}};
  for (const auto& d : cases) {
    double s[4] = {0, 0, 0, 0}, epeq = 0.0;
    const double w = update_stress(m, d, s, epeq);
    const double R = m.yield_stress + m.plastic_modulus * epeq;
    EXPECT_EQ(s[2], 0.0);
    EXPECT_GT(w, 0.0);
    // 1e-10 (spec): Newton on the consistency parameter is converged to ~1e-15.
    EXPECT_NEAR(von_mises(s), R, 1e-10 * R);
  }
}

// Single steps of 0.01 to 100 yield strains from random (possibly plastic) states, for
// H = 0 (perfect plasticity), moderate and strong hardening and nu up to 0.49: von Mises <= R
// to 1e-10 (spec tolerance; returns converge to roundoff) and = R after a plastic step,
// dissipation >= 0, s_zz = 0 exactly in plane stress.
TEST(MaterialBilinearJ2, LargeStepsStayAdmissible) {
  std::mt19937 rng(2024);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int bad = 0, plastic = 0;
  double worst = 0.0;
  for (int ps = 0; ps < 2; ++ps) {
    for (double H : {0.0, 2e9, 50e9}) {
      for (double nu : {0.0, 0.3, 0.49}) {
        MaterialLaw m = fracta::make_material_law(fracta::kBilinearJ2, ps, 7850.0, 200e9, nu);
        m.yield_stress = 250e6;
        m.plastic_modulus = H;
        const double ey = m.yield_stress / m.youngs_modulus;
        for (int i = 0; i < 2000; ++i) {
          double s[4] = {0, 0, 0, 0}, epeq = 0.01 * std::fabs(u(rng));
          const double d0[3] = {8 * ey * u(rng), 8 * ey * u(rng), 8 * ey * u(rng)};
          update_stress(m, d0, s, epeq);
          const double sc = std::pow(10.0, 2.0 * u(rng)) * ey;
          const double d[3] = {sc * u(rng), sc * u(rng), sc * u(rng)};
          const double ep0 = epeq;
          const double w = update_stress(m, d, s, epeq);
          const double R = m.yield_stress + H * epeq;
          const double err = (von_mises(s) - R) / R;
          if (epeq > ep0) {
            ++plastic;
            worst = std::max(worst, std::fabs(err));
            if (!(std::fabs(err) <= 1e-10)) ++bad;
          }
          if (!(err <= 1e-10) || !(w >= 0.0) || (!ps && s[2] != 0.0)) ++bad;
        }
      }
    }
  }
  EXPECT_EQ(bad, 0);
  EXPECT_GT(plastic, 10000);
  std::printf("[info] J2 large random steps: %d plastic of 36000, worst |vm - R| / R = %.3g\n",
              plastic, worst);
}

// ------------------------------------------------------------------------------------------
// mohr_coulomb
// ------------------------------------------------------------------------------------------

// (a) Rankine cut-off, plane strain, uniaxial strain along a direction theta (theta = 0 is
// d eps_xx only). Elastic: sigma_1 = (lambda + 2G) eps. After the cap all further strain along
// n1 is plastic (sigma_1 fixed => elastic strain fixed), so epeq = sqrt(2/3) (eps - T/(l+2G)),
// and the other two principal stresses stay at lambda T / (lambda + 2G).
TEST(MaterialMohrCoulomb, TensionCutOffPlaneStrain) {
  for (double theta : {0.0, 0.4, -1.1}) {
    const MaterialLaw m = rock(true);
    const double T = m.tensile_strength, M = m.lame_lambda + 2.0 * m.shear_modulus;
    const double c = std::cos(theta), sn = std::sin(theta), de = 2e-6;
    double s[4] = {0, 0, 0, 0}, epeq = 0.0, eps = 0.0, max_p = 0.0, max_ep = 0.0, diss = 0.0;
    for (int i = 0; i < 200; ++i) {
      const double d[3] = {de * c * c, de * sn * sn, de * c * sn};
      const double w = update_stress(m, d, s, epeq);
      eps += de;
      diss += w;
      EXPECT_GE(w, 0.0);
      if (eps * M <= T) {
        EXPECT_EQ(epeq, 0.0);
        continue;
      }
      max_p = std::max(max_p, std::fabs(max_principal(s) - T) / T);
      max_ep = std::max(max_ep, std::fabs(epeq - std::sqrt(2.0 / 3.0) * (eps - T / M)) / eps);
      // Principal direction unchanged: the stress component along n1 is T.
      const double s11 = s[0] * c * c + s[1] * sn * sn + 2.0 * s[3] * c * sn;
      EXPECT_NEAR(s11, T, 1e-10 * T);
      EXPECT_NEAR(s[2], m.lame_lambda / M * T, 1e-10 * T);
      EXPECT_LT(dp_f(m, s), 0.0);  // the cone is not involved
    }
    EXPECT_GT(epeq, 1e-4);
    // Dissipation = T x plastic strain along n1 (1e-10: roundoff).
    EXPECT_NEAR(diss, T * (eps - T / M), 1e-10 * T * eps);
    // 1e-10: the cut-off return is closed form, the error is roundoff.
    EXPECT_LT(max_p, 1e-10);
    EXPECT_LT(max_ep, 1e-10);
    std::printf("[info] MC plane-strain cut-off theta=%.1f: max |s1 - T|/T = %.3g, epeq err %.3g\n",
                theta, max_p, max_ep);
  }
}

// (a) plane stress, true uniaxial stress (s_yy = 0 by the lateral iteration, s_zz = 0 by the
// formulation): sigma = E eps capped at T, epeq = sqrt(2/3) (eps - T/E).
TEST(MaterialMohrCoulomb, TensionCutOffPlaneStressUniaxial) {
  const MaterialLaw m = rock(false);
  const double T = m.tensile_strength, E = m.youngs_modulus, de = 1e-6;
  double s[4] = {0, 0, 0, 0}, epeq = 0.0, eps = 0.0, deyy = 0.0, max_err = 0.0, max_ep = 0.0;
  for (int i = 0; i < 300; ++i) {
    const double w = uniaxial_stress_step(m, de, s, epeq, deyy);
    eps += de;
    EXPECT_GE(w, 0.0);
    ASSERT_EQ(s[2], 0.0);
    const double ref = std::min(E * eps, T);
    max_err = std::max(max_err, std::fabs(s[0] - ref) / T);
    max_ep =
        std::max(max_ep, std::fabs(epeq - std::sqrt(2.0 / 3.0) * std::max(0.0, eps - T / E)) / eps);
  }
  EXPECT_NEAR(max_principal(s), T, 1e-10 * T);
  EXPECT_GT(epeq, 1e-4);
  // 1e-10: closed-form cut-off; the lateral iteration (1e-12) and the eps_zz iteration
  // (1e-13) bound the rest.
  EXPECT_LT(max_err, 1e-10);
  EXPECT_LT(max_ep, 1e-10);
  std::printf(
      "[info] MC plane-stress uniaxial cut-off: max |s - analytic|/T = %.3g, epeq err "
      "%.3g\n",
      max_err, max_ep);
}

// (a) corner of the cut-off: equal biaxial tension. Plane stress: both in-plane stresses at T,
// all further in-plane strain plastic, epeq = sqrt(4/3) (eps - T (1 - nu) / E). Plane strain:
// both at T, sigma_zz = lambda T / (lambda + G), epeq = sqrt(4/3) (eps - T / (2 (lambda + G))).
TEST(MaterialMohrCoulomb, TensionCutOffBiaxialCorner) {
  for (int ps = 0; ps < 2; ++ps) {
    const MaterialLaw m = rock(ps == 1);
    const double T = m.tensile_strength, lam = m.lame_lambda, G = m.shear_modulus;
    const double e_cap =
        ps ? T / (2.0 * (lam + G)) : T * (1.0 - m.poisson_ratio) / m.youngs_modulus;
    double s[4] = {0, 0, 0, 0}, epeq = 0.0, eps = 0.0;
    for (int i = 0; i < 150; ++i) {
      const double d[3] = {1e-6, 1e-6, 0.0};
      EXPECT_GE(update_stress(m, d, s, epeq), 0.0);
      eps += 1e-6;
    }
    ASSERT_GT(eps, 2.0 * e_cap);
    // 1e-10: closed-form corner return, roundoff only.
    EXPECT_NEAR(s[0], T, 1e-10 * T);
    EXPECT_NEAR(s[1], T, 1e-10 * T);
    EXPECT_NEAR(s[3], 0.0, 1e-10 * T);
    EXPECT_NEAR(s[2], ps ? lam * T / (lam + G) : 0.0, 1e-10 * T);
    EXPECT_NEAR(epeq, std::sqrt(4.0 / 3.0) * (eps - e_cap), 1e-10 * eps);
  }
}

// Active-set logic of the cut-off corner, plane strain, zero increment from a given trial.
// Drop: with nu = 0.45 (lambda = 4.5 x 2G) capping sigma_1 pulls sigma_2 well below T, so the
// second surface must be released (its multiplier would be negative): only dl1 = r1/(l+2G).
// Add: with nu = -0.3 (lambda < 0) capping sigma_1 alone pushes sigma_2 above T, so the
// corner must be activated: dl1 + dl2 = (r1 + r2) / (2G + 2 lambda), both at T.
TEST(MaterialMohrCoulomb, CutOffActiveSetDropAndAdd) {
  const double T = 2e6;
  {
    MaterialLaw m = fracta::make_material_law(fracta::kMohrCoulomb, true, 2600.0, 30e9, 0.45);
    m.cohesion = 10e6;
    m.friction_angle = kPi / 6.0;
    m.tensile_strength = T;
    const double lam = m.lame_lambda, M = lam + 2.0 * m.shear_modulus, r1 = 5e6, r2 = 0.5e6;
    double s[4] = {T + r1, T + r2, 0.0, 0.0}, epeq = 0.0;
    const double d[3] = {0, 0, 0};
    update_stress(m, d, s, epeq);
    const double dl1 = r1 / M;
    // 1e-10: closed form, roundoff only.
    EXPECT_NEAR(s[0], T, 1e-10 * T);
    EXPECT_NEAR(s[1], T + r2 - lam * dl1, 1e-10 * T);
    EXPECT_NEAR(s[2], -lam * dl1, 1e-10 * T);
    EXPECT_NEAR(epeq, std::sqrt(2.0 / 3.0) * dl1, 1e-10 * dl1);
  }
  {
    MaterialLaw m = fracta::make_material_law(fracta::kMohrCoulomb, true, 2600.0, 30e9, -0.3);
    m.cohesion = 10e6;
    m.friction_angle = kPi / 6.0;
    m.tensile_strength = T;
    const double lam = m.lame_lambda, G = m.shear_modulus, r1 = 5e6, r2 = -0.5e6;
    ASSERT_LT(lam, 0.0);
    ASSERT_GT(T + r2 - lam * r1 / (lam + 2.0 * G), T);  // sigma_1 alone is not enough
    double s[4] = {T + r1, T + r2, 0.0, 0.0}, epeq = 0.0;
    const double d[3] = {0, 0, 0};
    update_stress(m, d, s, epeq);
    const double sum = (r1 + r2) / (2.0 * G + 2.0 * lam);
    const double f = lam / (2.0 * G + 2.0 * lam);
    const double dl1 = (r1 - f * (r1 + r2)) / (2.0 * G), dl2 = (r2 - f * (r1 + r2)) / (2.0 * G);
    EXPECT_NEAR(s[0], T, 1e-10 * T);
    EXPECT_NEAR(s[1], T, 1e-10 * T);
    EXPECT_NEAR(s[2], -lam * sum, 1e-10 * T);
    EXPECT_NEAR(epeq, std::sqrt(2.0 / 3.0 * (dl1 * dl1 + dl2 * dl2)), 1e-10 * sum);
  }
}

// Trial states past the cone's apex (hydrostatic tension p0): plane strain, zero increment.
// With a cut-off T, all three principal stresses go to T (3-surface corner), with
// dl = (p0 - T) / (3K) in each direction, so epeq = sqrt(2) dl. With no cut-off the cap is the
// Mohr-Coulomb apex c cot(phi).
TEST(MaterialMohrCoulomb, ApexReturn) {
  for (double T : {2e6, 0.0}) {
    const MaterialLaw m = rock(true, T);
    const double cap = T > 0 ? T : m.cohesion / std::tan(m.friction_angle);
    const double K = m.lame_lambda + 2.0 * m.shear_modulus / 3.0, p0 = 40e6;
    double s[4] = {p0, p0, p0, 0.0}, epeq = 0.0;
    const double d[3] = {0, 0, 0};
    const double w = update_stress(m, d, s, epeq);
    const double dl = (p0 - cap) / (3.0 * K);
    // 1e-10: closed form, roundoff only.
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(s[i], cap, 1e-10 * cap);
    EXPECT_NEAR(s[3], 0.0, 1e-10 * cap);
    EXPECT_NEAR(epeq, std::sqrt(2.0) * dl, 1e-10 * dl);
    EXPECT_NEAR(w, 3.0 * cap * dl, 1e-10 * cap * dl);
    EXPECT_LE(dp_f(m, s), 1e-10 * dp_k(m));
  }
}

// (b) Pure shear at zero pressure (no cut-off: its cap is then the apex, far above): I1 = 0, so
// the cone gives sqrt(J2) = |tau| = k, perfectly plastic; epeq = (2/sqrt3)(eps_xy - k/(2G)).
// (d) with phi = 0 the cap is tau = c and does not depend on pressure.
void check_pure_shear(const MaterialLaw& m, double p, double tau_ref) {
  const double G = m.shear_modulus;
  double s[4] = {-p, -p, m.plane_strain ? -p : 0.0, 0.0}, epeq = 0.0, exy = 0.0;
  double max_err = 0.0, max_ep = 0.0;
  const double I1_0 = s[0] + s[1] + s[2];
  int plastic = 0;
  double diss = 0.0;
  const int n = static_cast<int>(3.0 * tau_ref / (2.0 * G) / 2e-6);  // to 3 x the yield strain
  for (int i = 0; i < n; ++i) {
    const double d[3] = {0.0, 0.0, 2e-6};
    const double w = update_stress(m, d, s, epeq);
    EXPECT_GE(w, 0.0);
    diss += w;
    exy += 2e-6;
    if (!m.plane_strain) {
      ASSERT_EQ(s[2], 0.0);
    }
    // Zero dilatancy: I1 constant (1e-12 of the stress: roundoff).
    EXPECT_NEAR(s[0] + s[1] + s[2], I1_0, 1e-12 * (tau_ref + p));
    if (2.0 * G * exy <= tau_ref) {
      EXPECT_EQ(epeq, 0.0);
      EXPECT_NEAR(s[3], 2.0 * G * exy, 1e-12 * tau_ref);
      continue;
    }
    ++plastic;
    max_err = std::max(max_err, std::fabs(s[3] - tau_ref) / tau_ref);
    max_ep = std::max(max_ep,
                      std::fabs(epeq - 2.0 / std::sqrt(3.0) * (exy - tau_ref / (2.0 * G))) / exy);
  }
  EXPECT_GT(plastic, n / 2);
  // Perfect plasticity: the dissipation is tau_y times the plastic engineering shear
  // 2 (eps_xy - tau_y / (2G)) (1e-10: roundoff; the yield step is split exactly).
  const double diss_ref = tau_ref * 2.0 * (exy - tau_ref / (2.0 * G));
  EXPECT_NEAR(diss, diss_ref, 1e-10 * diss_ref);
  // 1e-10: deviatoric radial return is closed form, roundoff only.
  EXPECT_LT(max_err, 1e-10) << "p = " << p;
  EXPECT_LT(max_ep, 1e-10) << "p = " << p;
  std::printf(
      "[info] MC %s shear, p = %.3g MPa: tau_y = %.6g MPa, max rel err %.3g, epeq err "
      "%.3g\n",
      m.plane_strain ? "plane-strain" : "plane-stress", p / 1e6, tau_ref / 1e6, max_err, max_ep);
}

TEST(MaterialMohrCoulomb, PureShearZeroPressure) {
  for (int ps = 0; ps < 2; ++ps) {
    const MaterialLaw m = rock(ps == 1, 0.0);
    check_pure_shear(m, 0.0, dp_k(m));
  }
}

// (c) Confinement p (hydrostatic initial stress, plane strain): shear then keeps s_zz = 0 and
// s_m = -p, so the cone gives tau = k + 3 alpha p, which must equal the Mohr-Coulomb plane
// strength c cos(phi) + p sin(phi) (written here directly from c and phi, independently of the
// cone constants). Checked at two pressures; the capacity difference is p sin(phi).
TEST(MaterialMohrCoulomb, ShearCapacityGrowsWithConfinement) {
  const MaterialLaw m = rock(true, 0.0);
  const double c = m.cohesion, phi = m.friction_angle;
  for (double p : {5e6, 20e6}) check_pure_shear(m, p, c * std::cos(phi) + p * std::sin(phi));
}

TEST(MaterialMohrCoulomb, ZeroFrictionIsPressureIndependentTresca) {
  for (int ps = 0; ps < 2; ++ps) {
    const MaterialLaw m = rock(ps == 1, 0.0, 0.0);
    for (double p : {0.0, 15e6}) {
      if (!m.plane_strain && p != 0.0) continue;  // plane stress: s_zz = 0 cannot be confined
      check_pure_shear(m, p, m.cohesion);
    }
  }
}

// General multi-axial path through compression, shear and tension, both formulations: after
// every step the state is admissible (cone to 1e-10 k, cut-off to 1e-10 T), dissipation >= 0,
// s_zz = 0 in plane stress; in plane strain eps_zz = 0 makes the plastic strain eps - C^-1 s
// fully known, so every epeq increment is checked against it.
void check_mc_general_path(bool plane_strain) {
  const MaterialLaw m = rock(plane_strain);
  const double T = m.tensile_strength, k = dp_k(m), e0 = k / m.youngs_modulus;
  const int n = 3000;
  double s[4] = {0, 0, 0, 0}, epeq = 0.0, eps[3] = {0, 0, 0}, ep_old[4] = {0, 0, 0, 0};
  double max_f = 0.0, max_t = 0.0, max_ep = 0.0;
  int plastic = 0, on_cone = 0, on_cutoff = 0;
  for (int i = 1; i <= n; ++i) {
    const double t = 3.0 * i / n;
    const double e1[3] = {e0 * (1.5 * std::sin(2 * kPi * t) - 2.0 * t),
                          e0 * (2.0 * std::sin(2 * kPi * 1.3 * t + 0.5) - 1.0 * t),
                          e0 * 2.5 * std::sin(2 * kPi * 0.7 * t) * std::cos(2 * kPi * 0.9 * t)};
    const double d[3] = {e1[0] - eps[0], e1[1] - eps[1], e1[2] - eps[2]};
    for (int j = 0; j < 3; ++j) eps[j] = e1[j];
    const double ep0 = epeq;
    const double w = update_stress(m, d, s, epeq);
    ASSERT_GE(w, 0.0);
    if (!plane_strain) {
      ASSERT_EQ(s[2], 0.0);
    }
    if (epeq > ep0) {
      ++plastic;
      if (std::fabs(dp_f(m, s)) < 1e-9 * k) ++on_cone;
      if (std::fabs(max_principal(s) - T) < 1e-9 * T) ++on_cutoff;
    }
    max_f = std::max(max_f, dp_f(m, s) / k);
    max_t = std::max(max_t, (max_principal(s) - T) / T);
    if (plane_strain) {
      double ee[4], dep[4];
      elastic_strain(m, s, ee);
      const double ep[4] = {eps[0] - ee[0], eps[1] - ee[1], -ee[2], eps[2] - ee[3]};
      for (int j = 0; j < 4; ++j) {
        dep[j] = ep[j] - ep_old[j];
        ep_old[j] = ep[j];
      }
      const double dd = dep[0] * dep[0] + dep[1] * dep[1] + dep[2] * dep[2] + 2 * dep[3] * dep[3];
      max_ep = std::max(max_ep, std::fabs((epeq - ep0) - std::sqrt(2.0 / 3.0 * dd)) / e0);
    }
  }
  EXPECT_GT(plastic, n / 20);
  EXPECT_GT(on_cone, 10);  // the path must exercise both mechanisms
  EXPECT_GT(on_cutoff, 10);
  // 1e-10: returns are closed form (or iterated to 1e-13), so only roundoff remains.
  EXPECT_LT(max_f, 1e-10);
  EXPECT_LT(max_t, 1e-10);
  // 1e-10 of the cone's yield strain per step: cancellation in eps - C^-1 s.
  EXPECT_LT(max_ep, 1e-10);
  std::printf(
      "[info] MC %s general path: %d plastic steps (%d on the cone, %d on the cut-off), "
      "max f/k = %.3g, max (s1-T)/T = %.3g, "
      "epeq-increment err (plane strain only) = %.3g, epeq = %.3g\n",
      plane_strain ? "plane-strain" : "plane-stress", plastic, on_cone, on_cutoff, max_f, max_t,
      max_ep, epeq);
}

// Single large steps (0.01 to 100 x the cone's yield strain) from random admissible states, for
// several friction angles, Poisson ratios and cut-offs: the result must be admissible (cone and
// cut-off to 1e-10 k: every return is closed form or iterated to 1e-13), with dissipation >= 0
// and s_zz = 0 exactly in plane stress. The first case is a plane-stress step into the biaxial
// tension corner (where sigma_zz(eps_zz) has a plateau) that once defeated the eps_zz solver.
TEST(MaterialMohrCoulomb, LargeStepsStayAdmissible) {
  {
    MaterialLaw m = fracta::make_material_law(fracta::kMohrCoulomb, false, 2600.0, 30e9, 0.2);
    m.cohesion = 10e6;
    m.friction_angle = 0.6;
    m.tensile_strength = 0.5e6;
    double s[4] = {353781.08593825198, 484954.28015277494, 0.0, -46903.825188768351}, epeq = 0.0;
    const double d[3] = {0.0012925044503835483, 0.0013201295831173671, 0.0008691459996641081};
    EXPECT_GE(update_stress(m, d, s, epeq), 0.0);
    EXPECT_LE(dp_f(m, s), 1e-10 * dp_k(m));
    EXPECT_NEAR(max_principal(s), 0.5e6, 1e-10 * 0.5e6);  // biaxial tension: on the cut-off
    EXPECT_EQ(s[2], 0.0);
  }
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int bad = 0, plastic = 0;
  double worst = 0.0;
  for (int ps = 0; ps < 2; ++ps) {
    for (double T : {0.5e6, 5e6, 0.0}) {
      for (double phi : {0.0, 0.6, 1.0}) {
        for (double nu : {0.0, 0.25, 0.45}) {
          MaterialLaw m = fracta::make_material_law(fracta::kMohrCoulomb, ps, 2600.0, 30e9, nu);
          m.cohesion = 10e6;
          m.friction_angle = phi;
          m.tensile_strength = T;
          const double k = dp_k(m), alpha = dp_alpha(m);
          // Cap actually applied: T, but never above the apex c cot(phi) (none if phi = 0, T = 0).
          double cap = T > 0.0 ? T : 1e300;
          if (alpha > 0.0) cap = std::min(cap, k / (3.0 * alpha));
          for (int i = 0; i < 2000; ++i) {
            const double sc = std::pow(10.0, 2.0 * u(rng)) * k / m.youngs_modulus;
            const double d[3] = {sc * u(rng), sc * u(rng), sc * u(rng)};
            const double p0 = 30e6 * u(rng);
            double s[4] = {p0 + 5e6 * u(rng), p0 + 5e6 * u(rng), ps ? p0 : 0.0, 5e6 * u(rng)};
            double epeq = 0.0;
            const double zero[3] = {0.0, 0.0, 0.0};
            update_stress(m, zero, s, epeq);  // make the start admissible
            const double ep0 = epeq;
            const double w = update_stress(m, d, s, epeq);
            if (epeq > ep0) ++plastic;
            const double err = std::max(dp_f(m, s), max_principal(s) - cap) / k;
            worst = std::max(worst, err);
            if (!(err <= 1e-10) || !(w >= 0.0) || (!ps && s[2] != 0.0)) ++bad;
          }
        }
      }
    }
  }
  EXPECT_EQ(bad, 0);
  EXPECT_GT(plastic, 10000);
  std::printf("[info] MC large random steps: %d plastic of 108000, worst violation / k = %.3g\n",
              plastic, worst);
}

TEST(MaterialMohrCoulomb, PlaneStrainGeneralPath) {
  check_mc_general_path(true);
}
TEST(MaterialMohrCoulomb, PlaneStressGeneralPath) {
  check_mc_general_path(false);
}

}  // namespace

// ------------------------------------------------------------------------------------------
// Device: update_stress inside a Kokkos::parallel_for on the default execution space.
// The kernel lives in a free function with external linkage (CUDA extended-lambda rule).
// ------------------------------------------------------------------------------------------
namespace fracta_test_materials {

// Drives npts material points along rotated, scaled copies of one strain path (nsteps steps)
// and stores s[0..3], epeq and the summed dissipation of each point in out(i, 0..5).
void run_points(const fracta::MaterialLaw m, int npts, int nsteps, double de,
                fracta::View<double**> out) {
  Kokkos::parallel_for(
      "materials_test_points", Kokkos::RangePolicy<fracta::ExecSpace>(0, npts),
      KOKKOS_LAMBDA(const int i) {
        const double a = 0.3 * i, scale = 1.0 + 0.25 * i;
        const double ca = fracta::cos_(a), sa = fracta::sin_(a);
        double s[4] = {0.0, 0.0, 0.0, 0.0}, epeq = 0.0, diss = 0.0;
        for (int k = 0; k < nsteps; ++k) {
          // Uniaxial strain along (ca, sa) plus a lateral component, reversing half-way.
          const double sign = k < nsteps / 2 ? 1.0 : -1.0;
          const double e = sign * de * scale;
          const double deps[3] = {e * (ca * ca - 0.2 * sa * sa), e * (sa * sa - 0.2 * ca * ca),
                                  e * 1.2 * ca * sa};
          diss += fracta::update_stress(m, deps, s, epeq);
        }
        for (int c = 0; c < 4; ++c) out(i, c) = s[c];
        out(i, 4) = epeq;
        out(i, 5) = diss;
      });
  Kokkos::fence();
}

}  // namespace fracta_test_materials

namespace {

TEST(MaterialDevice, ParallelForMatchesHostLoop) {
  const int npts = 16, nsteps = 400;
  struct Case {
    MaterialLaw m;
    double de;
  };
  const Case cases[4] = {
      {steel(true), 2e-5}, {steel(false), 2e-5}, {rock(true), 1e-5}, {rock(false), 1e-5}};
  for (const Case& cs : cases) {
    fracta::View<double**> out("out", npts, 6);
    fracta_test_materials::run_points(cs.m, npts, nsteps, cs.de, out);
    auto h = Kokkos::create_mirror_view(out);
    Kokkos::deep_copy(h, out);
    int yielded = 0;
    for (int i = 0; i < npts; ++i) {
      // Same path on the host.
      const double a = 0.3 * i, scale = 1.0 + 0.25 * i, ca = std::cos(a), sa = std::sin(a);
      double s[4] = {0, 0, 0, 0}, epeq = 0.0, diss = 0.0;
      for (int k = 0; k < nsteps; ++k) {
        const double e = (k < nsteps / 2 ? 1.0 : -1.0) * cs.de * scale;
        const double deps[3] = {e * (ca * ca - 0.2 * sa * sa), e * (sa * sa - 0.2 * ca * ca),
                                e * 1.2 * ca * sa};
        diss += update_stress(cs.m, deps, s, epeq);
      }
      if (epeq > 0.0) ++yielded;
      const double sc = std::fabs(s[0]) + std::fabs(s[1]) + std::fabs(s[2]) + std::fabs(s[3]);
      // 1e-12 relative: same code and inputs; only a device compiler's different FMA
      // contraction / math library (cos_/sin_ vs std::) can change the last bits.
      for (int c = 0; c < 4; ++c) EXPECT_NEAR(h(i, c), s[c], 1e-12 * sc) << "point " << i;
      EXPECT_NEAR(h(i, 4), epeq, 1e-12 * epeq + 1e-300) << "point " << i;
      EXPECT_NEAR(h(i, 5), diss, 1e-12 * diss + 1e-300) << "point " << i;
      if (!cs.m.plane_strain) {
        EXPECT_EQ(h(i, 2), 0.0);
      }
    }
    EXPECT_EQ(yielded, npts) << "every point must go plastic for the test to mean something";
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// hjc: Holmquist-Johnson-Cook concrete, the 48 MPa concrete of Holmquist, Johnson & Cook (1993)
// as used for Hanchak's perforation tests. Every expected value below is the model's closed
// form (its Eqs. 1-3 and the equation of state), evaluated here independently of the law's code.
// ---------------------------------------------------------------------------------------------

struct HjcPoint {
  MaterialLaw m;
  double s[4] = {0, 0, 0, 0};
  double epeq = 0;
  double state[3] = {0, 0, 0};
  // One increment: in-plane strains exx, eyy, exy (tensor), out-of-plane ezz; rate in 1/s.
  double step(double exx, double eyy, double exy, double ezz, double rate = 0.0) {
    const double d[3] = {exx, eyy, exy};
    return fracta::detail::hjc_update(m, d, ezz, s, epeq, state, rate);
  }
  double pressure() const { return -(s[0] + s[1] + s[2]) / 3.0; }
};

constexpr double kFc = 48e6, kT = 4e6, kA = 0.79, kB = 1.60, kN = 0.61, kC = 0.007;
constexpr double kPc = 16e6, kMuc = 0.001, kPl = 0.8e9, kMul = 0.10, kK1 = 85e9;
constexpr double kK2 = -171e9, kK3 = 208e9, kD1 = 0.04, kEfMin = 0.01, kG = 14.86e9;

MaterialLaw hjc_concrete() {
  const double K = kPc / kMuc;
  MaterialLaw m = fracta::make_material_law(fracta::kHjc, true, 2440.0, 9 * K * kG / (3 * K + kG),
                                            (3 * K - 2 * kG) / (2 * (3 * K + kG)));
  fracta::HjcParams& h = m.hjc;
  h.a = kA, h.b = kB, h.n = kN, h.c = kC, h.fc = kFc, h.s_max = 7.0, h.t = kT, h.eps0 = 1.0;
  h.d1 = kD1, h.d2 = 1.0, h.ef_min = kEfMin;
  h.p_crush = kPc, h.mu_crush = kMuc, h.p_lock = kPl, h.mu_lock = kMul;
  h.k1 = kK1, h.k2 = kK2, h.k3 = kK3;
  m.tensile_strength = kT;
  fracta::cache_derived(m);
  return m;
}

// Volumetric strain increment (each of the three normal components tr/3) that takes mu from
// mu_from to mu_to: (1 + mu) = (1 + mu_from) exp(-tr).
double trace_to(double mu_from, double mu_to) {
  return -std::log((1.0 + mu_to) / (1.0 + mu_from));
}

void compress_to(HjcPoint& pt, double mu_to, int steps) {
  const double tr = trace_to(pt.state[fracta::kHjcMu], mu_to) / steps;
  for (int i = 0; i < steps; ++i) pt.step(tr / 3, tr / 3, 0.0, tr / 3);
}

TEST(MaterialHjc, EquationOfStateLoadsCrushesUnloadsAndLocks) {
  HjcPoint pt{hjc_concrete()};
  const double Ke = kPc / kMuc;
  // Elastic: P = K_e mu.
  compress_to(pt, 0.0006, 10);
  EXPECT_NEAR(pt.pressure(), Ke * 0.0006, 1e-9 * kPc);
  // Crushing: linear from (mu_c, p_c) to (mu_l, p_l).
  const double mu_max = 0.05;
  compress_to(pt, mu_max, 50);
  const double F = (mu_max - kMuc) / (kMul - kMuc);
  const double p_max = kPc + (kPl - kPc) * F;
  EXPECT_NEAR(pt.pressure(), p_max, 1e-9 * kPl);
  // Unloading along K_u = (1 - F) K_e + F K1, and reloading along it up to the envelope.
  const double Ku = (1 - F) * Ke + F * kK1;
  compress_to(pt, 0.045, 5);
  EXPECT_NEAR(pt.pressure(), p_max - Ku * (mu_max - 0.045), 1e-9 * kPl);
  compress_to(pt, mu_max, 5);
  EXPECT_NEAR(pt.pressure(), p_max, 1e-9 * kPl);
  // Fully dense: P = p_l + K1 mb + K2 mb^2 + K3 mb^3, mb = (mu - mu_l) / (1 + mu_l).
  compress_to(pt, 0.2, 100);
  const double mb = (0.2 - kMul) / (1 + kMul);
  EXPECT_NEAR(pt.pressure(), kPl + kK1 * mb + kK2 * mb * mb + kK3 * mb * mb * mb, 1e-9 * kPl);
  // No deviator on a hydrostatic path.
  EXPECT_NEAR(pt.s[0], pt.s[2], 1e-12 * kPl);
  EXPECT_EQ(pt.epeq, 0.0);
}

TEST(MaterialHjc, HydrostaticTensionStopsAtT) {
  HjcPoint pt{hjc_concrete()};
  const double Ke = kPc / kMuc;
  compress_to(pt, -0.5 * kT / Ke, 4);
  EXPECT_NEAR(pt.pressure(), -0.5 * kT, 1e-9 * kT);
  compress_to(pt, -3.0 * kT / Ke, 4);
  EXPECT_NEAR(pt.pressure(), -kT, 1e-9 * kT);
  // No crushing and no plastic strain beyond the round-off of a hydrostatic path (at the limit
  // the strength is 0, so a round-off deviator yields).
  EXPECT_LT(pt.state[fracta::kLawDamage], 1e-12);
}

// A dynamic increase factor (rate_dependence) raises the tension limit T with the factor.
TEST(MaterialHjc, TensionFactorRaisesTheTensionLimit) {
  HjcPoint pt{fracta::detail::with_tension_factor(hjc_concrete(), 2.5)};
  compress_to(pt, -5.0 * kT / (kPc / kMuc), 4);
  EXPECT_NEAR(pt.pressure(), -2.5 * kT, 1e-9 * kT);
}

// Pure shear at the pressure of an elastic compression mu0 (below mu_crush): the trace is 0, so
// the pressure stays K_e mu0 (exactly: the shear increments have no trace).
struct ShearAtPressure {
  HjcPoint pt{hjc_concrete()};
  double p;
  explicit ShearAtPressure(double mu0) {
    compress_to(pt, mu0, 1);
    p = pt.pressure();
  }
};

TEST(MaterialHjc, ShearYieldsAtTheNormalisedStrengthAndDamageSoftensIt) {
  ShearAtPressure sp(0.0008);  // P = 12.8 MPa, P* = 0.267
  HjcPoint& pt = sp.pt;
  const double p_star = sp.p / kFc;
  const double ef = std::max(kD1 * (p_star + kT / kFc), kEfMin);  // D1 (P* + T*)^D2, D2 = 1
  const double intact = kFc * (kA + kB * std::pow(p_star, kN));
  int plastic_steps = 0;
  for (int i = 0; i < 1200; ++i) {
    const double d_old = pt.state[fracta::kLawDamage], ep_old = pt.epeq;
    pt.step(2e-5, -2e-5, 0.0, 0.0);
    EXPECT_NEAR(pt.pressure(), sp.p, 1e-9 * kFc);
    if (pt.epeq == ep_old) continue;
    ++plastic_steps;
    // On the strength of the step's start damage (Eq. 1) ...
    const double yield = kFc * (kA * (1 - d_old) + kB * std::pow(p_star, kN));
    EXPECT_NEAR(von_mises(pt.s), yield, 1e-9 * kFc) << "step " << i;
    // ... and the damage grows by d eps_p / (D1 (P* + T*)^D2) (Eq. 2-3), to at most 1.
    EXPECT_NEAR(pt.state[fracta::kLawDamage], std::min(d_old + (pt.epeq - ep_old) / ef, 1.0),
                1e-12);
  }
  EXPECT_GT(plastic_steps, 100);
  // Fully damaged: only the pressure term is left (Eq. 1 with D = 1).
  EXPECT_EQ(pt.state[fracta::kLawDamage], 1.0);
  EXPECT_NEAR(von_mises(pt.s), kFc * kB * std::pow(p_star, kN), 1e-9 * kFc);
  EXPECT_LT(von_mises(pt.s), 0.6 * intact);
}

TEST(MaterialHjc, StrainRateRaisesTheStrengthByOnePlusCLnRate) {
  for (const double rate : {0.5, 1.0, 10.0, 1000.0}) {
    ShearAtPressure sp(0.0005);
    HjcPoint& pt = sp.pt;
    double q = 0.0;
    for (int i = 0; i < 200 && pt.epeq == 0.0; ++i) {
      pt.step(2e-5, -2e-5, 0.0, 0.0, rate);
      q = von_mises(pt.s);
    }
    ASSERT_GT(pt.epeq, 0.0);
    const double factor = rate > 1.0 ? 1.0 + kC * std::log(rate) : 1.0;  // eps0 = 1/s
    EXPECT_NEAR(q, kFc * (kA + kB * std::pow(sp.p / kFc, kN)) * factor, 1e-9 * kFc) << rate;
  }
}

TEST(MaterialHjc, StrengthIsCappedAtSmax) {
  // P = 0.7 GPa on the crush line: B P*^N = 11.4 > S_max = 7. Crushing damages the point
  // (mu_p / EF), which the cap does not see as long as the pressure term alone exceeds it.
  HjcPoint pt{hjc_concrete()};
  const double mu = kMuc + (0.7e9 - kPc) / (kPl - kPc) * (kMul - kMuc);
  compress_to(pt, mu, 200);
  ASSERT_NEAR(pt.pressure(), 0.7e9, 1e-6 * kPl);
  for (int i = 0; i < 400 && pt.epeq == 0.0; ++i) pt.step(5e-5, -5e-5, 0.0, 0.0);
  ASSERT_GT(pt.epeq, 0.0);
  EXPECT_NEAR(von_mises(pt.s), 7.0 * kFc, 1e-9 * kFc);
}

TEST(MaterialHjc, StrengthFallsLinearlyToZeroAtTheTensionLimit) {
  // Hydrostatic tension to P = -T/2, then shear: the strength is A f'c (1 + P*/T*) = A f'c / 2.
  HjcPoint pt{hjc_concrete()};
  compress_to(pt, -0.5 * kT / (kPc / kMuc), 1);
  for (int i = 0; i < 1000 && pt.epeq == 0.0; ++i) pt.step(1e-6, -1e-6, 0.0, 0.0);
  ASSERT_GT(pt.epeq, 0.0);
  EXPECT_NEAR(von_mises(pt.s), 0.5 * kA * kFc, 1e-9 * kFc);
}

TEST(MaterialHjc, CrushingDamagesByThePlasticVolumetricStrain) {
  // Hydrostatic crushing from mu_c to mu: mu_p = mu - p_max / K_u (the unloading line's zero),
  // and D = integral of d mu_p / EF(P) with EF = D1 (P* + T*) here (above EF_min): the sum of
  // the law's increments against a fine midpoint quadrature of the same integral.
  HjcPoint pt{hjc_concrete()};
  const double Ke = kPc / kMuc;
  const int steps = 20000;
  compress_to(pt, kMuc, 1);
  compress_to(pt, 0.03, steps);
  auto mu_p = [&](double mu) {
    const double F = (mu - kMuc) / (kMul - kMuc);
    return mu - (kPc + (kPl - kPc) * F) / ((1 - F) * Ke + F * kK1);
  };
  double damage = 0.0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const double a = kMuc + (0.03 - kMuc) * i / n, b = kMuc + (0.03 - kMuc) * (i + 1) / n;
    const double p = kPc + (kPl - kPc) * (0.5 * (a + b) - kMuc) / (kMul - kMuc);
    damage += (mu_p(b) - mu_p(a)) / std::max(kD1 * (p + kT) / kFc, kEfMin);
  }
  ASSERT_GT(damage, 0.01);
  // The law uses each step's end pressure: first order in the step, about 1e-4 of D here.
  EXPECT_NEAR(pt.state[fracta::kLawDamage], damage, 1e-3 * damage);
}

TEST(MaterialHjc, WaveSpeedFollowsTheUnloadingModulus) {
  HjcPoint pt{hjc_concrete()};
  const double Ke = kPc / kMuc, rho = 2440.0;
  EXPECT_NEAR(fracta::hjc_wave_speed(pt.m, pt.state), std::sqrt((Ke + 4.0 / 3.0 * kG) / rho), 1e-9);
  EXPECT_NEAR(pt.m.p_wave_speed, std::sqrt((Ke + 4.0 / 3.0 * kG) / rho), 1e-6);
  compress_to(pt, 0.05, 20);
  const double F = (0.05 - kMuc) / (kMul - kMuc);
  EXPECT_NEAR(fracta::hjc_wave_speed(pt.m, pt.state),
              std::sqrt(((1 - F) * Ke + F * kK1 + 4.0 / 3.0 * kG) / rho), 1e-9);
}

// The batched elastic step (hjc_elastic_update, the element kernel's path for most hjc points)
// against the full update (oracle: detail::hjc_update): random states, elastic and crushed,
// damaged and not, in compression and in tension, with and without a raised tension limit, and
// increments that stay elastic or yield or crush. Where it takes a point, the stress, the state
// and the wave speed are the full update's to the bit and the full update dissipates nothing;
// it must take the points well inside the strength (a point at rest under a small increment).
// With SIMD lanes (Double4 and Double8), each lane is the double's result to the bit.
struct HjcDraw {
  double deps[3], deps_zz, s[4], state[3], factor;
};
HjcDraw draw_hjc_point(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  HjcDraw d{};
  const double step = u(rng) < 0.5 ? 2e-6 : 4e-4;  // elastic-sized, or large enough to flow
  for (double& e : d.deps) e = step * (2 * u(rng) - 1);
  d.deps_zz = u(rng) < 0.5 ? 0.0 : step * (2 * u(rng) - 1);
  const double mu = -2e-4 + 0.02 * u(rng) * u(rng);
  d.state[fracta::kLawDamage] = u(rng) < 0.4 ? 0.0 : 0.6 * u(rng);
  d.state[fracta::kHjcMu] = mu;
  d.state[fracta::kHjcMuMax] = u(rng) < 0.5 ? std::max(mu, 0.0) : mu + 0.01 * u(rng);
  const double p = -3e6 + 60e6 * u(rng), dev = (u(rng) < 0.5 ? 2e6 : 40e6) * u(rng);
  d.s[0] = -p + dev, d.s[1] = -p - 0.5 * dev, d.s[2] = -p - 0.5 * dev, d.s[3] = 0.3 * dev;
  d.factor = u(rng) < 0.7 ? 1.0 : 1.0 + 2.0 * u(rng);
  return d;
}

// Bit for bit in the Release build; the sanitizer build (-O2) may contract products into FMAs
// differently in the two paths, so there within 16 ulps.
void expect_same(double a, double b, int i) {
#ifdef FRACTA_SANITIZE_BUILD
  EXPECT_NEAR(a, b, 16 * std::numeric_limits<double>::epsilon() * std::fabs(b)) << i;
#else
  EXPECT_EQ(a, b) << i;
#endif
}

#ifdef FRACTA_HOST_SIMD
// Lanes of V (both widths, whatever the machine's own) against the double's result, lane by
// lane: taken, the stress, the state, the wave speed and factor_free.
template <class V>
void expect_lanes_as_double(const MaterialLaw& m, std::mt19937& rng) {
  constexpr int L = fracta::LaneCount<V>::value;
  for (int round = 0; round < 200; ++round) {
    HjcDraw lane[L];
    V deps_v[3], deps_zz_v, s_v[4], state_v[3], factor_v;
    for (int l = 0; l < L; ++l) {
      lane[l] = draw_hjc_point(rng);
      for (int k = 0; k < 3; ++k) deps_v[k][l] = lane[l].deps[k], state_v[k][l] = lane[l].state[k];
      for (int k = 0; k < 4; ++k) s_v[k][l] = lane[l].s[k];
      deps_zz_v[l] = lane[l].deps_zz, factor_v[l] = lane[l].factor;
    }
    V s_new_v[4], mu_v, mu_max_v, wave_speed_v;
    auto free_v = !fracta::all_lanes<V>();
    const auto taken_v = fracta::hjc_elastic_update(m, deps_v, deps_zz_v, s_v, state_v, factor_v,
                                                    s_new_v, mu_v, mu_max_v, wave_speed_v, free_v);
    for (int l = 0; l < L; ++l) {
      const HjcDraw& d = lane[l];
      double s_new[4], mu, mu_max, wave_speed;
      bool factor_free = false;
      const bool taken = fracta::hjc_elastic_update(m, d.deps, d.deps_zz, d.s, d.state, d.factor,
                                                    s_new, mu, mu_max, wave_speed, factor_free);
      ASSERT_EQ(taken_v[l] != 0, taken) << L << " lanes, round " << round << " lane " << l;
      ASSERT_EQ(free_v[l] != 0, factor_free) << L << " lanes, round " << round << " lane " << l;
      if (!taken) continue;
      for (int k = 0; k < 4; ++k) expect_same(s_new_v[k][l], s_new[k], round);
      expect_same(mu_v[l], mu, round);
      expect_same(mu_max_v[l], mu_max, round);
      expect_same(wave_speed_v[l], wave_speed, round);
    }
  }
}
#endif

// Exact (libm's exp as the reference): the volumetric step's exp_of_increment is within 4 ulps
// of exp for |x| <= 1/32 (its Taylor polynomial's range; 20,001 points, the ends included) and
// is exp itself beyond; and in SIMD lanes of both widths it gives the scalar's bits.
TEST(MaterialHjc, ExpOfIncrementIsExpWithinFourUlps) {
  double worst_ulps = 0.0;
  for (int i = -10000; i <= 10000; ++i) {
    const double x = 0.03125 * i / 10000.0;
    const double reference = std::exp(x);
    const double ulp = std::nextafter(reference, 2.0 * reference) - reference;
    worst_ulps = std::max(worst_ulps, std::fabs(fracta::exp_of_increment(x) - reference) / ulp);
  }
  EXPECT_LE(worst_ulps, 4.0);
  for (const double x : {-0.5, -0.0313, 0.0313, 0.2})
    EXPECT_EQ(fracta::exp_of_increment(x), std::exp(x));
#ifdef FRACTA_HOST_SIMD
  const double xs[8] = {-0.03, -1e-3, -1e-9, 0.0, 2e-6, 0.01, 0.031, 0.05};
  fracta::Double8 v8;
  fracta::Double4 v4;
  for (int l = 0; l < 8; ++l) v8[l] = xs[l];
  for (int l = 0; l < 4; ++l) v4[l] = xs[2 * l];
  const fracta::Double8 e8 = fracta::exp_of_increment(v8);
  const fracta::Double4 e4 = fracta::exp_of_increment(v4);
  for (int l = 0; l < 8; ++l) EXPECT_EQ(e8[l], fracta::exp_of_increment(xs[l])) << l;
  for (int l = 0; l < 4; ++l) EXPECT_EQ(e4[l], fracta::exp_of_increment(xs[2 * l])) << l;
#endif
  RecordProperty("worst_ulps", std::to_string(worst_ulps));
}

TEST(MaterialHjc, BatchedElasticStepIsTheFullUpdateWhereItIsTaken) {
  const MaterialLaw m = hjc_concrete();
  std::mt19937 rng(29);
  int taken_count = 0, flowing_count = 0;
  const int n = 4000;
  for (int i = 0; i < n; ++i) {
    const HjcDraw d = draw_hjc_point(rng);
    double s_new[4], mu, mu_max, wave_speed;
    const bool taken = fracta::hjc_elastic_update(m, d.deps, d.deps_zz, d.s, d.state, d.factor,
                                                  s_new, mu, mu_max, wave_speed);
    double s[4] = {d.s[0], d.s[1], d.s[2], d.s[3]}, state[3] = {d.state[0], d.state[1], d.state[2]};
    double epeq = 0.0;
    const MaterialLaw law = d.factor != 1.0 ? fracta::detail::with_tension_factor(m, d.factor) : m;
    const double work = fracta::detail::hjc_update(law, d.deps, d.deps_zz, s, epeq, state, 50.0);
    if (epeq > 0.0 || state[fracta::kLawDamage] != d.state[fracta::kLawDamage]) ++flowing_count;
    if (!taken) continue;
    ++taken_count;
    EXPECT_EQ(work, 0.0) << i;
    EXPECT_EQ(epeq, 0.0) << i;
    for (int k = 0; k < 4; ++k) expect_same(s_new[k], s[k], i);
    EXPECT_EQ(state[fracta::kLawDamage], d.state[fracta::kLawDamage]) << i;
    expect_same(mu, state[fracta::kHjcMu], i);
    expect_same(mu_max, state[fracta::kHjcMuMax], i);
    expect_same(wave_speed, fracta::hjc_wave_speed(law, state), i);
  }
  // Both kinds are drawn: about half the points flow or crush, and most of the rest are taken.
  EXPECT_GT(flowing_count, n / 5);
  EXPECT_GT(taken_count, n / 4);
  std::printf("hjc batched step: %d of %d points taken, %d flow or crush\n", taken_count, n,
              flowing_count);

  // A point at rest under a small increment is taken, with the full update's stress.
  const double deps[3] = {1e-6, -2e-6, 5e-7}, rest[4] = {0, 0, 0, 0}, fresh[3] = {0, 0, 0};
  double s_new[4], mu, mu_max, wave_speed;
  EXPECT_TRUE(
      fracta::hjc_elastic_update(m, deps, 0.0, rest, fresh, 1.0, s_new, mu, mu_max, wave_speed));

#ifdef FRACTA_HOST_SIMD
  expect_lanes_as_double<fracta::Double4>(m, rng);
  expect_lanes_as_double<fracta::Double8>(m, rng);
#endif
}

// A step taken with the factor 1 and marked factor_free is the full update's with any larger
// tension factor (oracle: detail::hjc_update with the raised limit), to the bit: the element
// kernel then needs no rate factor for it (FeForces::hjc_batch_update). Both kinds occur: points
// free of the factor, and points in tension that the raised limit keeps elastic, which need it.
TEST(MaterialHjc, FactorFreeStepsAreTheSameForAnyLargerTensionFactor) {
  const MaterialLaw m = hjc_concrete();
  std::mt19937 rng(31);
  int free_count = 0, raised_count = 0;
  for (int i = 0; i < 4000; ++i) {
    const HjcDraw d = draw_hjc_point(rng);
    double s_new[4], mu, mu_max, wave_speed;
    bool factor_free = false;
    const bool taken = fracta::hjc_elastic_update(m, d.deps, d.deps_zz, d.s, d.state, 1.0, s_new,
                                                  mu, mu_max, wave_speed, factor_free);
    if (factor_free) {
      ASSERT_TRUE(taken) << i;
    }
    if (!factor_free) {
      double s_f[4], mu_f, mu_max_f, wave_f;
      if (fracta::hjc_elastic_update(m, d.deps, d.deps_zz, d.s, d.state, 4.0, s_f, mu_f, mu_max_f,
                                     wave_f))
        ++raised_count;
      continue;
    }
    ++free_count;
    for (const double factor : {1.0, 1.3, 4.0, 10.65}) {
      double s[4] = {d.s[0], d.s[1], d.s[2], d.s[3]};
      double state[3] = {d.state[0], d.state[1], d.state[2]};
      double epeq = 0.0;
      const MaterialLaw law = fracta::detail::with_tension_factor(m, factor);
      EXPECT_EQ(fracta::detail::hjc_update(law, d.deps, d.deps_zz, s, epeq, state, 50.0), 0.0);
      for (int k = 0; k < 4; ++k) expect_same(s_new[k], s[k], i);
      expect_same(mu, state[fracta::kHjcMu], i);
      expect_same(mu_max, state[fracta::kHjcMuMax], i);
      EXPECT_EQ(state[fracta::kLawDamage], d.state[fracta::kLawDamage]) << i;
      // And the batched step itself, with the factor, takes it with the same result.
      double s_f[4], mu_f, mu_max_f, wave_f;
      ASSERT_TRUE(fracta::hjc_elastic_update(m, d.deps, d.deps_zz, d.s, d.state, factor, s_f, mu_f,
                                             mu_max_f, wave_f))
          << i;
      for (int k = 0; k < 4; ++k) EXPECT_EQ(s_f[k], s_new[k]) << i;
      EXPECT_EQ(wave_f, wave_speed) << i;
    }
  }
  EXPECT_GT(free_count, 500);
  EXPECT_GT(raised_count, 20);
  std::printf("hjc factor-free steps: %d of 4000; %d more taken with the factor 4\n", free_count,
              raised_count);
}

// ---------------------------------------------------------------------------------------------
// johnson_cook: OFHC copper as Johnson & Cook (1983) give it (A 90 MPa, B 292 MPa, n 0.31,
// C 0.025, m 1.09, T_melt 1356 K) and its fracture constants (Johnson & Cook 1985: D1 0.54,
// D2 4.89, D3 -3.03, D4 0.014, D5 1.12). Expected values are the model's closed forms.
// ---------------------------------------------------------------------------------------------

struct JcPoint {
  MaterialLaw m;
  double s[4] = {0, 0, 0, 0};
  double epeq = 0;
  double state[3] = {0, 0, 0};
  double step(double exx, double eyy, double exy, double rate = 0.0) {
    const double d[3] = {exx, eyy, exy};
    return fracta::detail::jc_update(m, d, 0.0, s, epeq, state, rate);
  }
};

MaterialLaw ofhc_copper(double specific_heat = 0.0, bool failure = false) {
  MaterialLaw m = fracta::make_material_law(fracta::kJohnsonCook, true, 8960.0, 124e9, 0.34);
  fracta::JohnsonCookParams& j = m.jc;
  j.a = 90e6, j.b = 292e6, j.n = 0.31, j.c = 0.025, j.m = 1.09;
  j.t_room = 294.0, j.t_melt = 1356.0, j.eps0 = 1.0;
  j.specific_heat = specific_heat, j.taylor_quinney = 0.9;
  if (failure) j.d1 = 0.54, j.d2 = 4.89, j.d3 = -3.03, j.d4 = 0.014, j.d5 = 1.12;
  fracta::cache_derived(m);
  return m;
}

double jc_hardening(double ep) {
  return 90e6 + 292e6 * std::pow(ep, 0.31);
}

TEST(MaterialJohnsonCook, PureShearFollowsTheHardeningCurve) {
  JcPoint pt{ofhc_copper()};
  int plastic = 0;
  for (int i = 0; i < 2000; ++i) {
    const double ep_old = pt.epeq;
    const double work = pt.step(1e-4, -1e-4, 0.0);
    if (pt.epeq == ep_old) continue;
    ++plastic;
    EXPECT_NEAR(von_mises(pt.s), jc_hardening(pt.epeq), 1e-10 * 90e6) << "step " << i;
    EXPECT_NEAR(work, von_mises(pt.s) * (pt.epeq - ep_old), 1e-12 * 90e6);
  }
  EXPECT_GT(plastic, 1900);
  EXPECT_GT(pt.epeq, 0.2);
  EXPECT_EQ(pt.state[fracta::kJcHeating], 0.0);  // isothermal (no specific heat)
}

TEST(MaterialJohnsonCook, OneLargeStepLandsOnTheSurface) {
  JcPoint pt{ofhc_copper()};
  pt.step(0.05, -0.05, 0.02);
  ASSERT_GT(pt.epeq, 0.0);
  EXPECT_NEAR(von_mises(pt.s), jc_hardening(pt.epeq), 1e-10 * 90e6);
  // q_trial - 3 G d_ep = q: the return is radial from the elastic trial.
  const double G = pt.m.shear_modulus;
  const double q_trial = 2.0 * G *
                         std::sqrt(1.5 * (2 * 0.05 * 0.05 + 2 * 0.02 * 0.02) -
                                   0.0);  // deviatoric trial of a traceless increment
  EXPECT_NEAR(von_mises(pt.s) + 3.0 * G * pt.epeq, q_trial, 1e-9 * q_trial);
}

TEST(MaterialJohnsonCook, StrainRateRaisesTheFlowStressByOnePlusCLnRate) {
  for (const double rate : {0.5, 1.0, 100.0, 1e4}) {
    JcPoint pt{ofhc_copper()};
    for (int i = 0; i < 300; ++i) pt.step(1e-4, -1e-4, 0.0, rate);
    ASSERT_GT(pt.epeq, 0.0);
    const double factor = rate > 1.0 ? 1.0 + 0.025 * std::log(rate) : 1.0;
    EXPECT_NEAR(von_mises(pt.s), jc_hardening(pt.epeq) * factor, 1e-10 * 90e6) << rate;
  }
}

TEST(MaterialJohnsonCook, AdiabaticHeatingSoftensByTheTemperatureTerm) {
  const double cp = 383.0, rho = 8960.0, chi = 0.9;
  JcPoint pt{ofhc_copper(cp)};
  double plastic_work = 0.0;
  for (int i = 0; i < 3000; ++i) {
    const double ep_old = pt.epeq, heat_old = pt.state[fracta::kJcHeating];
    plastic_work += pt.step(2e-4, -2e-4, 0.0);
    if (pt.epeq == ep_old) continue;
    // The flow stress at the step's start temperature (Eq. 1: 1 - T*^m) ...
    const double t_star = heat_old / (1356.0 - 294.0);
    const double thermal = t_star > 0 ? 1.0 - std::pow(t_star, 1.09) : 1.0;
    EXPECT_NEAR(von_mises(pt.s), jc_hardening(pt.epeq) * thermal, 1e-10 * 90e6) << "step " << i;
  }
  // ... and the heating is chi / (rho c_p) times the plastic work.
  EXPECT_NEAR(pt.state[fracta::kJcHeating], chi * plastic_work / (rho * cp), 1e-9);
  EXPECT_GT(pt.state[fracta::kJcHeating], 50.0);
}

TEST(MaterialJohnsonCook, DamageIsThePlasticStrainOverTheFailureStrain) {
  // Pure shear at zero pressure: triaxiality 0, so eps_f = D1 + D2 (quasi-static, isothermal),
  // and D = eps_p / (D1 + D2) until it reaches 1.
  JcPoint pt{ofhc_copper(0.0, true)};
  for (int i = 0; i < 20000 && pt.state[fracta::kLawDamage] < 1.0; ++i) {
    pt.step(5e-4, -5e-4, 0.0);
    EXPECT_NEAR(pt.state[fracta::kLawDamage], std::min(pt.epeq / (0.54 + 4.89), 1.0), 1e-9);
  }
  EXPECT_EQ(pt.state[fracta::kLawDamage], 1.0);
  // Under confinement (triaxiality sigma* < 0) the failure strain grows: D1 + D2 exp(D3 sigma*).
  JcPoint confined{ofhc_copper(0.0, true)};
  const double d0[3] = {-1e-3, -1e-3, 0.0};
  fracta::detail::jc_update(confined.m, d0, -1e-3, confined.s, confined.epeq, confined.state, 0.0);
  ASSERT_EQ(confined.epeq, 0.0);
  for (int i = 0; i < 200; ++i) {
    const double d_old = confined.state[fracta::kLawDamage], ep_old = confined.epeq;
    confined.step(1e-4, -1e-4, 0.0);
    if (confined.epeq == ep_old) continue;
    const double p = (confined.s[0] + confined.s[1] + confined.s[2]) / 3.0;
    const double eps_f = 0.54 + 4.89 * std::exp(-3.03 * p / von_mises(confined.s));
    EXPECT_NEAR(confined.state[fracta::kLawDamage], d_old + (confined.epeq - ep_old) / eps_f,
                1e-12);
    EXPECT_GT(eps_f, 0.54 + 4.89);
  }
}

// Plane stress (solve_plane_stress around jc_update): uniaxial tension sigma_xx with
// sigma_yy = 0 held by a free lateral strain. Each step's lateral strain increment is found by
// the same secant as sigma_zz: bisection here on sigma_yy(e_yy) = 0 (exact to 1e-9 of A). Then
// sigma_xx is the von Mises stress, equal to the hardening curve at the plastic strain, and
// sigma_zz is exactly 0.
TEST(MaterialJohnsonCook, PlaneStressUniaxialTensionFollowsTheHardeningCurve) {
  MaterialLaw m = ofhc_copper();
  m.plane_strain = 0;
  fracta::cache_derived(m);
  double s[4] = {0, 0, 0, 0}, ep = 0, state[3] = {0, 0, 0};
  int plastic = 0;
  for (int i = 0; i < 300; ++i) {
    double lo = -2e-4, hi = 2e-4, s_try[4], ep_try = 0, state_try[3];
    for (int it = 0; it < 200; ++it) {
      const double eyy = 0.5 * (lo + hi);
      for (int k = 0; k < 4; ++k) s_try[k] = s[k];
      for (int k = 0; k < 3; ++k) state_try[k] = state[k];
      ep_try = ep;
      const double d[3] = {2e-4, eyy, 0.0};
      fracta::update_stress_with_state(m, d, s_try, ep_try, state_try, 0.0);
      (s_try[1] > 0.0 ? hi : lo) = eyy;
    }
    const double ep_old = ep;
    for (int k = 0; k < 4; ++k) s[k] = s_try[k];
    for (int k = 0; k < 3; ++k) state[k] = state_try[k];
    ep = ep_try;
    ASSERT_EQ(s[2], 0.0);
    ASSERT_NEAR(s[1], 0.0, 1e-6 * 90e6);
    if (ep == ep_old) continue;
    ++plastic;
    EXPECT_NEAR(s[0], jc_hardening(ep), 1e-6 * 90e6) << "step " << i;
  }
  EXPECT_GT(plastic, 250);
}
