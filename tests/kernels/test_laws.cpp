// The pointwise laws of the lattice and of contact (src/kernels/laws.hpp; docs/physics.md 1.2),
// each against its analytic form: the springs' forces and plastic return, the face check at the
// tension cut-off and on the Mohr-Coulomb line (and its every-face bound), the energy a cohesive
// bond dissipates, the contact forces and the contact's energy balance; then the double and
// Double8 instantiations lane by lane, bit for bit. The laws are host-callable
// KOKKOS_INLINE_FUNCTIONs; LawsDevice.* runs them inside a Kokkos::parallel_for.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "kernels/laws.hpp"
#include "kernels/state.hpp"  // BondKind

namespace fracta {
namespace {

// ---- Springs --------------------------------------------------------------------------------

TEST(SpringLaw, ElasticForces) {
  EXPECT_EQ(SpringLaw::elastic_force(2e6, 1.25e-3, 1e-3), 2e6 * (1.25e-3 - 1e-3));
  EXPECT_EQ(SpringLaw::elastic_force(2e6, 0.75e-3, 1e-3), 2e6 * (0.75e-3 - 1e-3));  // compression
  EXPECT_EQ(SpringLaw::elastic_increment(3e6, 5.0, 2e-6), 5.0 + 3e6 * 2e-6);
  const SpringLaw spring{0.0, 0.0};
  EXPECT_FALSE(spring.plastic());
}

// Parameters in force units: sigma_y S, sigma_y S / sqrt(3) (von Mises) and H S / L0.
TEST(SpringLaw, ForceUnitParameters) {
  const SpringLaw spring{200e6, 2e9};
  EXPECT_TRUE(spring.plastic());
  const double S = 1e-6, L0 = 1e-3;
  EXPECT_DOUBLE_EQ(spring.normal_yield_force(S), 200.0);
  EXPECT_DOUBLE_EQ(spring.shear_yield_force(S), 200.0 / std::sqrt(3.0));
  EXPECT_DOUBLE_EQ(spring.hardening_stiffness(S, L0), 2e9 * S / L0);
}

// Bilinear spring (k = 1e6 N/m, f_y = 100 N, k_h = 1e5 N/m) loaded, unloaded and reloaded in
// reverse: below yield it is elastic; past it the return gives |f| = f_y + k_h alpha with
// dgamma = (k u - f_y - k_h alpha) / (k + k_h) (Simo & Hughes Box 1.4) and the work |f| dgamma;
// unloading is elastic from the plastic displacement; reverse yield is at -(f_y + k_h alpha).
TEST(SpringLaw, BilinearReturnMapping) {
  const double k = 1e6, fy = 100.0, kh = 1e5;
  double up = 0.0, alpha = 0.0, f = 0.0;
  // Elastic: u = 5e-5, f = 50 N.
  EXPECT_EQ(SpringLaw::bilinear(k, 5e-5, fy, kh, up, alpha, f), 0.0);
  EXPECT_EQ(f, 50.0);
  EXPECT_EQ(up, 0.0);
  EXPECT_EQ(alpha, 0.0);
  // Past yield: u = 2e-4, trial 200 N.
  const double u1 = 2e-4;
  const double dgamma = (k * u1 - fy) / (k + kh);
  const double work = SpringLaw::bilinear(k, u1, fy, kh, up, alpha, f);
  EXPECT_NEAR(f, fy + kh * dgamma, 1e-12 * fy);
  EXPECT_NEAR(up, dgamma, 1e-15);
  EXPECT_NEAR(alpha, dgamma, 1e-15);
  EXPECT_NEAR(work, f * dgamma, 1e-12 * f * dgamma);
  EXPECT_NEAR(f, k * (u1 - up), 1e-12 * fy);  // f = k (u - u_p)
  // Unloading: elastic from u_p.
  const double up1 = up, alpha1 = alpha;
  EXPECT_EQ(SpringLaw::bilinear(k, 1.5e-4, fy, kh, up, alpha, f), 0.0);
  EXPECT_EQ(up, up1);
  EXPECT_NEAR(f, k * (1.5e-4 - up1), 1e-12 * fy);
  // Reverse yield at -(f_y + k_h alpha).
  const double u2 = -2e-4;
  const double limit = fy + kh * alpha1;
  const double dg2 = (std::fabs(k * (u2 - up1)) - limit) / (k + kh);
  SpringLaw::bilinear(k, u2, fy, kh, up, alpha, f);
  EXPECT_NEAR(f, -(limit + kh * dg2), 1e-12 * fy);
  EXPECT_NEAR(up, up1 - dg2, 1e-15);
  EXPECT_NEAR(alpha, alpha1 + dg2, 1e-15);
  // f_y = 0: elastic whatever the displacement.
  double up0 = 0.0, alpha0 = 0.0;
  EXPECT_EQ(SpringLaw::bilinear(k, 1.0, 0.0, kh, up0, alpha0, f), 0.0);
  EXPECT_EQ(f, k);
}

// ---- Face failure ---------------------------------------------------------------------------

// Traction on a face of normal (cos t, sin t) under uniaxial stress s along x:
// sigma_n = s cos^2 t, tau = s |sin t cos t| (the Mohr circle).
TEST(FaceStrength, TractionOfUniaxialStress) {
  const double s = 3e6;
  for (const double t : {0.0, 0.3, 0.7853981633974483, 1.2, 2.0}) {
    double sigma_n, tau;
    FaceStrength::traction(s, 0.0, 0.0, std::cos(t), std::sin(t), sigma_n, tau);
    EXPECT_NEAR(sigma_n, s * std::cos(t) * std::cos(t), 1e-9 * s) << t;
    EXPECT_NEAR(tau, s * std::fabs(std::sin(t) * std::cos(t)), 1e-9 * s) << t;
  }
}

// sigma_t = 2 MPa, c = 8 MPa, tan(phi) = 0.5 (values whose line c - sigma tan(phi) is exact).
FaceStrength rock_face() {
  return FaceStrength{2e6, 8e6, 0.5};
}

TEST(FaceStrength, TensionCutOff) {
  const FaceStrength face = rock_face();
  EXPECT_TRUE(face.reaches(2e6, 0.0));  // at the cut-off
  EXPECT_FALSE(face.reaches(std::nextafter(2e6, 0.0), 0.0));
  EXPECT_TRUE(face.reaches(5e6, 0.0));
  const FaceStrength no_cut_off{0.0, 8e6, 0.5};
  EXPECT_FALSE(no_cut_off.reaches(5e6, 0.0));  // tensile_strength 0: no tensile failure
}

TEST(FaceStrength, OnTheMohrCoulombLine) {
  const FaceStrength face = rock_face();
  for (const double sigma : {-20e6, -2e6, 0.0, 1e6}) {
    const double line = 8e6 - 0.5 * sigma;  // tau = c - sigma tan(phi), exact for these values
    EXPECT_TRUE(face.reaches(sigma, line)) << sigma;
    EXPECT_FALSE(face.reaches(sigma, std::nextafter(line, 0.0))) << sigma;
  }
  const FaceStrength tension_only{2e6, 0.0, 0.5};
  EXPECT_FALSE(tension_only.reaches(-2e6, 1e9));  // cohesion 0: no shear failure
}

// A scaled face (a Weibull factor, a dynamic increase factor) reaches at the scaled tensile
// strength and on the line tau = w c - sigma tan(phi); scale 1 is the unscaled check. Exact.
TEST(FaceStrength, ScaledStrengthScalesTensionAndCohesionNotFriction) {
  const FaceStrength face = rock_face();
  EXPECT_TRUE(face.reaches(3e6, 0.0, 1.5));
  EXPECT_FALSE(face.reaches(std::nextafter(3e6, 0.0), 0.0, 1.5));
  const double line = 1.5 * 8e6 + 0.5 * 4e6;  // sigma = -4 MPa
  EXPECT_TRUE(face.reaches(-4e6, line, 1.5));
  EXPECT_FALSE(face.reaches(-4e6, std::nextafter(line, 0.0), 1.5));
  for (const double sigma : {-20e6, 0.0, 2e6})
    for (const double tau : {0.0, 8e6, 20e6})
      EXPECT_EQ(face.reaches(sigma, tau, 1.0), face.reaches(sigma, tau)) << sigma << " " << tau;
}

// The dynamic increase factor table: piecewise linear in log10 of the strain rate, held at the
// end values outside it (and at the first for a rate of 0). Exact, to round-off.
TEST(RateLaw, FactorIsPiecewiseLinearInTheLogOfTheRate) {
  RateLaw law;
  law.count = 3;
  const double rates[3] = {1e-2, 1.0, 1e2}, strength[3] = {1.0, 2.0, 4.0};
  for (int k = 0; k < 3; ++k) {
    law.log10_rate[k] = std::log10(rates[k]);
    law.strength[k] = strength[k];
    law.fracture_energy[k] = 1.0 + k;
  }
  EXPECT_TRUE(law.active());
  EXPECT_FALSE(RateLaw{}.active());
  EXPECT_DOUBLE_EQ(law.strength_factor(0.0), 1.0);
  EXPECT_DOUBLE_EQ(law.strength_factor(1e-5), 1.0);
  EXPECT_NEAR(law.strength_factor(0.1), 1.5, 1e-14);
  EXPECT_NEAR(law.strength_factor(1.0), 2.0, 1e-14);
  EXPECT_NEAR(law.strength_factor(10.0), 3.0, 1e-14);
  EXPECT_DOUBLE_EQ(law.strength_factor(1e6), 4.0);
  EXPECT_NEAR(law.fracture_energy_factor(10.0), 2.5, 1e-14);
}

// The every-face bound is the check over all faces: where it says below, no face of the
// stress reaches the strength (faces sampled every 0.1 degree); it says so for a stress well
// inside the envelope, and not for one whose circle touches the cut-off or the line.
TEST(FaceStrength, BelowOnEveryFaceBoundsTheCheck) {
  const FaceStrength face = rock_face();
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-12e6, 4e6);
  int below = 0, not_below = 0;
  for (int k = 0; k < 2000; ++k) {
    const double sxx = u(rng), syy = u(rng), sxy = 0.5 * u(rng);
    const double centre = 0.5 * (sxx + syy);
    const double radius = std::sqrt(0.25 * (sxx - syy) * (sxx - syy) + sxy * sxy);
    bool reached = false;
    for (int a = 0; a < 1800; ++a) {
      const double t = a * 3.14159265358979323846 / 1800.0;
      double sigma_n, tau;
      FaceStrength::traction(sxx, syy, sxy, std::cos(t), std::sin(t), sigma_n, tau);
      reached = reached || face.reaches(sigma_n, tau);
    }
    if (face.below_on_every_face(centre, radius)) {
      ++below;
      EXPECT_FALSE(reached) << sxx << " " << syy << " " << sxy;
    } else {
      ++not_below;
    }
  }
  EXPECT_GT(below, 100);  // not vacuous
  EXPECT_GT(not_below, 100);
  // Circles touching the cut-off (C + R = sigma_t) and the line (C tan(phi) + R sec(phi) = c).
  EXPECT_FALSE(face.below_on_every_face(1e6, 1e6));
  const double secant = std::sqrt(1.25);
  EXPECT_FALSE(face.below_on_every_face(-10e6, (8e6 + 5e6) / secant));
  EXPECT_TRUE(face.below_on_every_face(-10e6, 0.9 * (8e6 + 5e6) / secant));
}

// ---- Cohesive softening ---------------------------------------------------------------------

TEST(CohesiveSoftening, SeparationAndStoredEnergy) {
  using Law = CohesiveSoftening;
  // lambda = |(<u_n>, u_s)|: compression opens no crack.
  EXPECT_DOUBLE_EQ(Law::effective_separation(3.0, 4.0, 1.0, 1.0), 5.0);
  EXPECT_DOUBLE_EQ(Law::effective_separation(-3.0, 4.0, 1.0, 1.0), 4.0);
  EXPECT_DOUBLE_EQ(Law::effective_separation(3.0, 0.0, 2.0, 0.0), 1.5);  // no shear spring
  // Secant springs (1 - D) k in tension and shear, k in compression.
  EXPECT_DOUBLE_EQ(Law::stored_energy(2.0, 0.0, 0.5, 4.0, 0.0), 0.5 * 4.0 / 2.0);
  EXPECT_DOUBLE_EQ(Law::stored_energy(-2.0, 0.0, 0.5, 4.0, 0.0), 0.5 * 4.0 / 4.0);
  EXPECT_DOUBLE_EQ(Law::stored_energy(0.0, 3.0, 0.25, 4.0, 6.0), 0.5 * 9.0 / 4.5);
  EXPECT_DOUBLE_EQ(Law::undamaged(3.0, 0.25), 4.0);
  EXPECT_EQ(Law::undamaged(3.0, 0.0), 3.0);
  double fn, fs;
  Law::applied(4.0, 4.0, 0.25, fn, fs);
  EXPECT_EQ(fn, 3.0);
  EXPECT_EQ(fs, 3.0);
  Law::applied(-4.0, 4.0, 0.25, fn, fs);
  EXPECT_EQ(fn, -4.0);  // compression undamaged
  // The damage D = lambda_f (lambda - lambda_0) / (lambda (lambda_f - lambda_0)) never drops.
  EXPECT_DOUBLE_EQ(Law::damage(2.0, 1.0, 3.0, 0.0), 3.0 * 1.0 / (2.0 * 2.0));
  EXPECT_EQ(Law::damage(2.0, 1.0, 3.0, 0.9), 0.9);
  EXPECT_EQ(Law::damage(1.0, 1.0, 3.0, 0.0), 0.0);
}

// A bond opened monotonically in pure mode I, step by step as the bond kernel does it
// (bond_forces.hpp: the undamaged force kn u, the onset where it met f0 within the step that
// passed it, the damage, the energy of each softening step and the release at the break),
// dissipates G_f A_b, A_b = kn L0 crack_area_factor: the energy at the onset plus the area under
// the linear softening branch, 1/2 f(lambda_0) lambda_f. The trapezoidal rule is exact on the
// linear branches; the step that crosses lambda_f over-counts at most 1/2 f du over the
// overshoot, f <= f0 du / (lambda_f - lambda_0), and the step that crosses the peak takes the
// chord under it, missing at most the triangle 1/8 kn du^2: the tolerance. The peak is f0
// whatever the step (steps of 50 and 400 meet it at different points of a step).
TEST(CohesiveSoftening, MonotonicOpeningDissipatesTheFractureEnergy) {
  for (const int steps : {50, 400}) {
    const double kn = 2e6, L0 = 1e-3, f0 = 10.0;
    CohesiveSoftening law;
    law.fracture_energy = 100.0;              // G_f (J/m^2)
    law.crack_area_factor[kBondEdge] = 2e-9;  // A_b = kn L0 2e-9 = 4e-6 m^2
    const double share = law.fracture_energy * kn * L0 * law.crack_area_factor[kBondEdge];
    // lambda_f is about 2 G_f A_b / f0 = 8e-5 m; steps of it.
    const double du = 2.0 * share / f0 / steps;
    double fn_old = 0.0, damage_old = 0.0, onset = 0.0, lambda_f = 0.0, dissipated = 0.0;
    bool broke = false;
    for (int s = 1; s <= 2 * steps && !broke; ++s) {
      const double u = s * du, fn = kn * u;  // undamaged force
      if (onset == 0.0 && fn >= f0) {
        lambda_f = law.final_separation(fn, 0.0, kn, 0.0, L0, law.crack_area_factor[kBondEdge],
                                        fn / f0, onset);
        ASSERT_GT(lambda_f, onset);
      }
      double damage = damage_old;
      if (onset > 0.0) {
        const double lambda = CohesiveSoftening::effective_separation(fn, 0.0, kn, 0.0);
        if (lambda >= lambda_f) {
          dissipated += law.released_energy(fn_old, 0.0, fn, 0.0, damage_old, kn, 0.0, 0.0);
          broke = true;
          break;
        }
        damage = CohesiveSoftening::damage(lambda, onset, lambda_f, damage_old);
        double fn_applied, fs_applied;
        CohesiveSoftening::applied(fn, 0.0, damage, fn_applied, fs_applied);
        dissipated +=
            CohesiveSoftening::work(fn_old, fn_applied, 0.0, 0.0, fn, damage_old, kn, 0.0) +
            CohesiveSoftening::stored_energy(fn_old, 0.0, damage_old, kn, 0.0) -
            CohesiveSoftening::stored_energy(fn_applied, 0.0, damage, kn, 0.0);
        fn_old = fn_applied;
      } else {
        fn_old = fn;
      }
      damage_old = damage;
    }
    ASSERT_TRUE(broke) << steps;
    EXPECT_NEAR(onset * kn, f0, 1e-12 * f0) << steps << " steps";
    const double tolerance =
        0.5 * f0 * du * du / (lambda_f - onset) + 0.125 * kn * du * du + 1e-12 * share;
    EXPECT_NEAR(dissipated, share, tolerance) << steps << " steps";
  }
}

// Brittle: the energy released at a break is 1/2 f_old f / k per spring (what the spring held
// plus the trapezoidal work of the step down to zero force).
TEST(CohesiveSoftening, BrittleReleasedEnergy) {
  const CohesiveSoftening brittle{};
  EXPECT_FALSE(brittle.cohesive());
  EXPECT_DOUBLE_EQ(brittle.released_energy(3.0, 2.0, 4.0, 5.0, 0.0, 2.0, 10.0, 1e-3),
                   0.5 * 3.0 * 4.0 / 2.0 + 0.5 * 2.0 * 5.0 / 10.0);
}

// ---- Contact --------------------------------------------------------------------------------

TEST(ContactLaw, Forces) {
  const ContactLaw law{0.2, 0.3, 1e-6};
  EXPECT_DOUBLE_EQ(ContactLaw::series_stiffness(1e6, 3e6), 2.0 * 3e12 / 4e6);
  EXPECT_EQ(ContactLaw::series_stiffness(0.0, 0.0), 0.0);
  // fn = k delta + c delta_dot, c = 2 zeta sqrt(k m_eff), m_eff = 1 / (1/m_i + 1/m_j).
  const double k = 1.5e6, mi = 2.0, mj = 6.0, inv_m = 1.0 / mi + 1.0 / mj;
  const double c = 2.0 * 0.2 * std::sqrt(k * mi * mj / (mi + mj));
  EXPECT_NEAR(law.normal_force(k, inv_m, 1e-5, 0.1), k * 1e-5 + c * 0.1, 1e-12 * k * 1e-5);
  EXPECT_EQ(law.normal_force(k, inv_m, 1e-5, -10.0), 0.0);  // clamped: no adhesion
  // Friction: Coulomb above v_reg, viscous below it.
  const double fn = 20.0, dt = 1e-7, inv_mt = 0.7;
  const double v_reg = std::max(1e-6, 0.3 * fn * dt * inv_mt);
  EXPECT_DOUBLE_EQ(law.friction_force(fn, 0.5, inv_mt, dt), 0.3 * fn);
  EXPECT_DOUBLE_EQ(law.friction_force(fn, -0.5, inv_mt, dt), -0.3 * fn);
  EXPECT_NEAR(law.friction_force(fn, 0.5 * v_reg, inv_mt, dt), 0.15 * fn, 1e-12 * fn);
  EXPECT_DOUBLE_EQ(ContactLaw::elastic_energy(k, 2e-5), 0.5 * k * 4e-10);
  // Dissipation of a step: (fn - k delta) delta_dot + fs vt at the full-step rates.
  const double delta = 1e-5, delta_dot = 0.1, vt = 0.2, fs = 3.0;
  const double d = ContactLaw::dissipation(k, delta, delta_dot, vt, fn, fs, inv_m, inv_mt, dt);
  const double expected = ((fn - k * delta) * (delta_dot - 0.5 * dt * fn * inv_m) +
                           fs * (vt - 0.5 * dt * fs * inv_mt)) *
                          dt;
  EXPECT_NEAR(d, expected, 1e-14 * std::fabs(expected));
}

// Two discs collide head on (m1 = 1 kg at 1 m/s, m2 = 3 kg at rest), integrated by velocity
// Verlet with the law's normal force and the kernel's rates (the half-step velocities): the
// kinetic energy lost equals the summed dissipation, to O((omega dt)^2) with omega dt about
// pi/100 here (the full-step correction is exact to that order for an isolated pair): 1e-3.
TEST(ContactLaw, HeadOnCollisionDissipationBalancesTheKineticEnergyLost) {
  const ContactLaw law{0.3, 0.0, 1e-6};
  const double k = 1e6, m1 = 1.0, m2 = 3.0, inv_m = 1.0 / m1 + 1.0 / m2, r = 0.01;
  const double omega = std::sqrt(k * inv_m), dt = 3.14159265358979323846 / omega / 100.0;
  double x1 = 0.0, x2 = 2.0 * r + 1e-4, v1 = 1.0, v2 = 0.0;
  double f = 0.0, dissipated = 0.0;  // force on disc 2 along +x
  const double kinetic0 = 0.5 * m1 * v1 * v1 + 0.5 * m2 * v2 * v2;
  int touching = 0;
  for (int s = 0; s < 2000; ++s) {
    v1 -= 0.5 * dt * f / m1;  // half kick
    v2 += 0.5 * dt * f / m2;
    x1 += dt * v1;
    x2 += dt * v2;
    const double delta = 2.0 * r - (x2 - x1), delta_dot = -(v2 - v1);
    f = 0.0;
    if (delta > 0.0) {
      ++touching;
      f = law.normal_force(k, inv_m, delta, delta_dot);
      dissipated += ContactLaw::dissipation(k, delta, delta_dot, 0.0, f, 0.0, inv_m, 0.0, dt);
    }
    v1 -= 0.5 * dt * f / m1;
    v2 += 0.5 * dt * f / m2;
  }
  ASSERT_GT(touching, 50);
  ASSERT_GT(x2 - x1, 2.0 * r);  // separated again
  const double kinetic = 0.5 * m1 * v1 * v1 + 0.5 * m2 * v2 * v2;
  ASSERT_GT(kinetic0 - kinetic, 0.1 * kinetic0);  // damping took a good part
  EXPECT_NEAR(kinetic0 - kinetic, dissipated, 1e-3 * kinetic0);
}

// ---- The same laws for one bond and for eight --------------------------------------------------

}  // namespace

// LawsDevice's kernel: in a function with external linkage (CUDA's rule for the function that
// encloses an extended lambda; a TEST body is a private member).
void run_laws_on_device(const BondLaw bond_law, const ContactLaw contact_law,
                        const View<double*> out) {
  Kokkos::parallel_for(
      "fracta::test_laws_device", Kokkos::RangePolicy<ExecSpace>(0, out.extent(0)),
      KOKKOS_LAMBDA(const int i) {
        double onset;
        const CohesiveSoftening soft = bond_law.softening();
        const double lambda_f = soft.final_separation(10.0 + i, 0.0, 2e6, 0.0, 1e-3,
                                                      soft.crack_area_factor[0], 1.0, onset);
        const double reached = bond_law.face().reaches(1e6 * i, 0.0) ? 1.0 : 0.0;
        out(i) = lambda_f / onset + reached + contact_law.normal_force(1e6, 1.0, 1e-6 * i, 0.0);
      });
  Kokkos::fence();
}

namespace {

TEST(LawsDevice, RunOnTheDefaultExecutionSpace) {
  const BondLaw bond_law{30e9, 0.0, 0.0, 2e6, 8e6, 0.5, 100.0, {2e-9, 1e-9}, 0.0, {}};
  View<double*> out("out", 16);
  run_laws_on_device(bond_law, ContactLaw{}, out);
  const auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), out);
  for (int i = 0; i < 16; ++i) {
    double onset;
    const CohesiveSoftening soft = bond_law.softening();
    const double lambda_f =
        soft.final_separation(10.0 + i, 0.0, 2e6, 0.0, 1e-3, soft.crack_area_factor[0], 1.0, onset);
    const double expected = lambda_f / onset + (i >= 2 ? 1.0 : 0.0) + 1e6 * 1e-6 * i;
    EXPECT_NEAR(h(i), expected, 1e-12 * std::fabs(expected)) << i;
  }
}

#ifdef FRACTA_HOST_SIMD
std::uint64_t bits(double x) {
  std::uint64_t b;
  std::memcpy(&b, &x, sizeof b);
  return b;
}

// Eight random inputs per argument; the Double8 result lane l must equal, bit for bit, the
// double result of lane l's inputs. Values in ranges that take every branch of the laws
// (yielding and not, tension and compression, damage 0 and not, clamped contact and not).
struct Lanes {
  std::mt19937 rng{17};
  Double8 uniform(double lo, double hi) {
    std::uniform_real_distribution<double> u(lo, hi);
    Double8 v;
    for (int l = 0; l < 8; ++l) v[l] = u(rng);
    return v;
  }
  // Some lanes exactly zero (damage 0: the undamaged branches).
  Double8 sometimes_zero(double lo, double hi) {
    Double8 v = uniform(lo, hi);
    for (int l = 0; l < 8; l += 3) v[l] = 0.0;
    return v;
  }
};

// Bitwise in the Release build the solver runs. The sanitizer build (RelWithDebInfo, -O2)
// contracts products into FMAs differently in the scalar and the vector code: there the lanes
// agree within 16 ulps of the round's largest value (a difference of large terms, like the shear
// traction of a nearly hydrostatic stress, keeps the rounding of its terms).
void expect_lanes(const Double8& vector, const std::vector<double>& scalar, const char* what) {
#ifdef FRACTA_SANITIZE_BUILD
  double scale = 0.0;
  for (int l = 0; l < 8; ++l) scale = std::max(scale, std::fabs(scalar[l]));
#endif
  for (int l = 0; l < 8; ++l) {
    // Inputs are drawn in each law's domain: a NaN is a fault, however the lanes agree.
    EXPECT_FALSE(std::isnan(scalar[l])) << what << " lane " << l;
#ifdef FRACTA_SANITIZE_BUILD
    EXPECT_NEAR(vector[l], scalar[l], 16 * std::numeric_limits<double>::epsilon() * scale)
        << what << " lane " << l;
#else
    EXPECT_EQ(bits(vector[l]), bits(scalar[l]))
        << what << " lane " << l << ": " << vector[l] << " vs " << scalar[l];
#endif
  }
}
void expect_lanes(const Mask8& vector, const std::vector<bool>& scalar, const char* what) {
  for (int l = 0; l < 8; ++l) EXPECT_EQ(vector[l] != 0, scalar[l]) << what << " lane " << l;
}

// The lanes' log10 (simd.hpp) against the library's, over rates of 1e-12 to 1e12 1/s and the
// table rates themselves; and the lanes' table factor against the double walk (oracle: the
// scalar log10 and the same table), for the CEB-FIP-like table of cases/perforation.toml, with
// rates at, below, between and beyond its entries, zero, negative and NaN.
TEST(LawsSimd, RateFactorOfTheLanesFollowsTheScalarTable) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> exponent(-12.0, 12.0);
  double worst_ulps = 0.0;
  for (int round = 0; round < 2000; ++round) {
    Double8 x;
    for (int l = 0; l < 8; ++l) x[l] = std::pow(10.0, exponent(rng));
    if (round == 0) x = Double8{1.0, 10.0, 0.5, 2.0, 1.4142135623730951, 1e-6, 1233.0, 1e4};
    const Double8 y = fracta::log10_(x);
    for (int l = 0; l < 8; ++l) {
      const double exact = std::log10(x[l]);
      const double ulp =
          std::max(std::fabs(exact), 1e-300) * std::numeric_limits<double>::epsilon();
      worst_ulps = std::max(worst_ulps, std::fabs(y[l] - exact) / ulp);
      if (exact == 0.0) {
        EXPECT_EQ(y[l], 0.0);
      }
    }
  }
  EXPECT_LT(worst_ulps, 4.0);

  RateLaw law;
  const double rates[12] = {1e-06,  8.111e-06, 6.579e-05, 0.0005337, 0.004329, 0.03511,
                            0.2848, 2.31,      18.74,     152,       1233,     1e+04};
  const double strength[12] = {1,    1.026, 1.084, 1.145, 1.21,  1.278,
                               1.35, 1.426, 1.506, 2.639, 5.303, 10.65};
  law.count = 12;
  for (int k = 0; k < 12; ++k)
    law.log10_rate[k] = std::log10(rates[k]), law.strength[k] = strength[k];
  double worst = 0.0;
  for (int round = 0; round < 500; ++round) {
    Double8 rate;
    for (int l = 0; l < 8; ++l) rate[l] = std::pow(10.0, exponent(rng) / 1.5);
    if (round == 0) rate = Double8{0.0, -1.0, std::nan(""), 1e-6, 1e4, 152.0, 1e-7, 1e9};
    const Double8 lanes = law.strength_factor(rate);
    for (int l = 0; l < 8; ++l) {
      const double scalar = law.strength_factor(rate[l]);
      ASSERT_FALSE(std::isnan(lanes[l])) << rate[l];
      worst = std::max(worst, std::fabs(lanes[l] - scalar) / scalar);
      // Beyond the ends, and where no logarithm is needed, the lanes are the scalar's exactly.
      if (round == 0 && (l < 3 || l > 5)) {
        EXPECT_EQ(lanes[l], scalar) << rate[l];
      }
    }
  }
  EXPECT_LT(worst, 1e-14);
  std::printf("lanes' log10 within %.2f ulps; table factor within %.2g of the scalar walk\n",
              worst_ulps, worst);
}

TEST(LawsSimd, DoubleAndDouble8AgreeBitwise) {
  Lanes r;
  for (int round = 0; round < 200; ++round) {
    // Springs.
    const Double8 k = r.uniform(1e5, 1e7), u = r.uniform(-3e-4, 3e-4);
    const Double8 f_yield = r.sometimes_zero(20.0, 200.0), k_hard = r.uniform(0.0, 1e6);
    Double8 up = r.uniform(-5e-5, 5e-5), alpha = r.uniform(0.0, 1e-4), force;
    std::vector<double> s_up(8), s_alpha(8), s_force(8), s_work(8), s_el(8), s_inc(8);
    for (int l = 0; l < 8; ++l) {
      s_up[l] = up[l];
      s_alpha[l] = alpha[l];
      s_work[l] =
          SpringLaw::bilinear(k[l], u[l], f_yield[l], k_hard[l], s_up[l], s_alpha[l], s_force[l]);
      s_el[l] = SpringLaw::elastic_force(k[l], u[l], up[l]);
      s_inc[l] = SpringLaw::elastic_increment(k[l], f_yield[l], u[l]);
    }
    const Double8 el = SpringLaw::elastic_force(k, u, up);
    const Double8 inc = SpringLaw::elastic_increment(k, f_yield, u);
    const Double8 work = SpringLaw::bilinear(k, u, f_yield, k_hard, up, alpha, force);
    expect_lanes(work, s_work, "bilinear work");
    expect_lanes(force, s_force, "bilinear force");
    expect_lanes(up, s_up, "bilinear u_p");
    expect_lanes(alpha, s_alpha, "bilinear alpha");
    expect_lanes(el, s_el, "elastic force");
    expect_lanes(inc, s_inc, "elastic increment");

    // Face check.
    const FaceStrength face = rock_face();
    const Double8 sxx = r.uniform(-12e6, 4e6), syy = r.uniform(-12e6, 4e6),
                  sxy = r.uniform(-4e6, 4e6), angle = r.uniform(0.0, 3.2);
    Double8 nx, ny;
    for (int l = 0; l < 8; ++l) {
      nx[l] = std::cos(angle[l]);
      ny[l] = std::sin(angle[l]);
    }
    Double8 sigma_n, tau;
    FaceStrength::traction(sxx, syy, sxy, nx, ny, sigma_n, tau);
    const Double8 centre = 0.5 * (sxx + syy);
    const Double8 radius = sqrt_(0.25 * (sxx - syy) * (sxx - syy) + sxy * sxy);
    std::vector<double> s_sigma(8), s_tau(8);
    std::vector<bool> s_reaches(8), s_below(8);
    for (int l = 0; l < 8; ++l) {
      FaceStrength::traction(sxx[l], syy[l], sxy[l], nx[l], ny[l], s_sigma[l], s_tau[l]);
      s_reaches[l] = face.reaches(s_sigma[l], s_tau[l]);
      s_below[l] = face.below_on_every_face(centre[l], radius[l]);
    }
    expect_lanes(sigma_n, s_sigma, "traction sigma_n");
    expect_lanes(tau, s_tau, "traction tau");
    expect_lanes(face.reaches(sigma_n, tau), s_reaches, "reaches");
    expect_lanes(face.below_on_every_face(centre, radius), s_below, "below on every face");

    // Cohesive softening.
    CohesiveSoftening soft;
    soft.fracture_energy = 100.0;
    const Double8 fn = r.uniform(-10.0, 30.0), fs = r.uniform(-10.0, 10.0);
    const Double8 fn_old = r.uniform(-10.0, 30.0), fs_old = r.uniform(-10.0, 10.0);
    const Double8 kn = r.uniform(1e6, 3e6), ks = r.sometimes_zero(1e5, 1e6);
    const Double8 damage = r.sometimes_zero(0.0, 0.9), du = r.uniform(-1e-6, 1e-6);
    const Double8 L0 = r.uniform(1e-3, 2e-3), factor = r.uniform(1e-9, 3e-9);
    Double8 onset;
    const Double8 excess = r.uniform(1.0, 1.5);
    const Double8 lambda_f = soft.final_separation(fn, fs, kn, ks, L0, factor, excess, onset);
    // Damage in its domain, as the bond kernel calls it: 0 < onset < lambda_f, lambda < lambda_f
    // (below onset too: the damage then stays). lambda_f == onset is a brittle bond, 0/0 here.
    const Double8 soft_onset = r.uniform(1e-6, 2e-6);
    const Double8 soft_lambda_f = soft_onset + r.uniform(1e-7, 1e-5);
    const Double8 lambda = soft_lambda_f * r.uniform(0.0, 1.0);
    Double8 fn_applied, fs_applied;
    CohesiveSoftening::applied(fn, fs, damage, fn_applied, fs_applied);
    std::vector<double> s_lf(8), s_onset(8), s_sep(8), s_stored(8), s_work2(8), s_und(8), s_dmg(8),
        s_fna(8), s_fsa(8), s_rel(8), s_brittle(8);
    const CohesiveSoftening brittle{};
    for (int l = 0; l < 8; ++l) {
      s_lf[l] = soft.final_separation(fn[l], fs[l], kn[l], ks[l], L0[l], factor[l], excess[l],
                                      s_onset[l]);
      s_sep[l] = CohesiveSoftening::effective_separation(fn[l], fs[l], kn[l], ks[l]);
      s_stored[l] = CohesiveSoftening::stored_energy(fn[l], fs[l], damage[l], kn[l], ks[l]);
      s_work2[l] = CohesiveSoftening::work(fn_old[l], fn_applied[l], fs_old[l], fs_applied[l],
                                           fn[l], damage[l], kn[l], du[l]);
      s_und[l] = CohesiveSoftening::undamaged(fs_old[l], damage[l]);
      s_dmg[l] = CohesiveSoftening::damage(lambda[l], soft_onset[l], soft_lambda_f[l], damage[l]);
      CohesiveSoftening::applied(fn[l], fs[l], damage[l], s_fna[l], s_fsa[l]);
      s_rel[l] =
          soft.released_energy(fn_old[l], fs_old[l], fn[l], fs[l], damage[l], kn[l], ks[l], du[l]);
      s_brittle[l] = brittle.released_energy(fn_old[l], fs_old[l], fn[l], fs[l], damage[l], kn[l],
                                             ks[l], du[l]);
    }
    expect_lanes(lambda_f, s_lf, "final separation");
    expect_lanes(onset, s_onset, "onset");
    expect_lanes(CohesiveSoftening::effective_separation(fn, fs, kn, ks), s_sep, "separation");
    expect_lanes(CohesiveSoftening::stored_energy(fn, fs, damage, kn, ks), s_stored, "stored");
    expect_lanes(
        CohesiveSoftening::work(fn_old, fn_applied, fs_old, fs_applied, fn, damage, kn, du),
        s_work2, "work");
    expect_lanes(CohesiveSoftening::undamaged(fs_old, damage), s_und, "undamaged");
    expect_lanes(CohesiveSoftening::damage(lambda, soft_onset, soft_lambda_f, damage), s_dmg,
                 "damage");
    expect_lanes(fn_applied, s_fna, "applied fn");
    expect_lanes(fs_applied, s_fsa, "applied fs");
    expect_lanes(soft.released_energy(fn_old, fs_old, fn, fs, damage, kn, ks, du), s_rel,
                 "released (cohesive)");
    expect_lanes(brittle.released_energy(fn_old, fs_old, fn, fs, damage, kn, ks, du), s_brittle,
                 "released (brittle)");

    // Contact.
    const ContactLaw contact{0.2, 0.3, 1e-6};
    const Double8 ki = r.sometimes_zero(1e5, 1e7), kj = r.uniform(1e5, 1e7);
    const Double8 inv_m = r.uniform(0.1, 10.0), inv_mt = r.uniform(0.1, 20.0);
    const Double8 delta = r.uniform(-1e-6, 1e-5), delta_dot = r.uniform(-20.0, 20.0);
    const Double8 vt = r.uniform(-1e-5, 1e-5);
    const double dt = 1e-7;
    const Double8 kc = ContactLaw::series_stiffness(ki, kj);
    const Double8 cn = contact.normal_force(kc, inv_m, delta, delta_dot);
    const Double8 ct = contact.friction_force(cn, vt, inv_mt, dt);
    std::vector<double> s_kc(8), s_cn(8), s_ct(8), s_ce(8), s_cd(8);
    for (int l = 0; l < 8; ++l) {
      s_kc[l] = ContactLaw::series_stiffness(ki[l], kj[l]);
      s_cn[l] = contact.normal_force(s_kc[l], inv_m[l], delta[l], delta_dot[l]);
      s_ct[l] = contact.friction_force(s_cn[l], vt[l], inv_mt[l], dt);
      s_ce[l] = ContactLaw::elastic_energy(s_kc[l], delta[l]);
      s_cd[l] = ContactLaw::dissipation(s_kc[l], delta[l], delta_dot[l], vt[l], s_cn[l], s_ct[l],
                                        inv_m[l], inv_mt[l], dt);
    }
    expect_lanes(kc, s_kc, "series stiffness");
    expect_lanes(cn, s_cn, "normal force");
    expect_lanes(ct, s_ct, "friction force");
    expect_lanes(ContactLaw::elastic_energy(kc, delta), s_ce, "contact elastic energy");
    expect_lanes(ContactLaw::dissipation(kc, delta, delta_dot, vt, cn, ct, inv_m, inv_mt, dt), s_cd,
                 "contact dissipation");
    if (HasFailure()) break;
  }
}
#endif

}  // namespace
}  // namespace fracta
