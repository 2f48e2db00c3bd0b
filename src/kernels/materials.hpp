// Pointwise material laws (docs/physics.md 1.1): device functions on one material point, no virtual
// calls. Loops that apply them live in fe_forces.hpp.
//
// Conventions: stress in Pa, tension positive, s[0]=xx, s[1]=yy, s[2]=zz, s[3]=xy.
// Strain increments are tensor components (deps[2] = d eps_xy, not the engineering shear).
// Plane strain: eps_zz = 0 and s[2] evolves. Plane stress: s[2] = 0 always and eps_zz is
// whatever keeps it so. Axisymmetric (x = radius, y = axis): z is the hoop direction, the laws
// run as in plane strain with the hoop strain increment deps_zz = (v_r / r) dt given.
#pragma once
#include "kernels/compat.hpp"
#include "kernels/law_params.hpp"
#include "kernels/simd.hpp"

namespace fracta {

enum MaterialModelId : int {
  kElastic = 0,
  kBilinearJ2 = 1,
  kMohrCoulomb = 2,
  kHjc = 3,
  kJohnsonCook = 4
};

// Plain data copied by value into kernels (one per material).
struct MaterialLaw {
  int model = kElastic;
  int plane_strain = 1;       // 1 plane strain, 0 plane stress
  double density = 0;         // kg/m^3
  double youngs_modulus = 0;  // Pa
  double poisson_ratio = 0;
  double shear_modulus = 0;     // G = E / (2 (1 + nu))
  double lame_lambda = 0;       // 3D lambda = E nu / ((1 + nu)(1 - 2 nu))
  double yield_stress = 0;      // bilinear_j2, Pa
  double plastic_modulus = 0;   // bilinear_j2 hardening H = d sigma_y / d epeq, Pa
  double cohesion = 0;          // mohr_coulomb, Pa
  double friction_angle = 0;    // mohr_coulomb, rad
  double tensile_strength = 0;  // Rankine cut-off, Pa (0 = no cut-off)
  double conversion_strain = 0;
  // hjc, johnson_cook: an adaptive element converts when a point's damage D reaches this (0:
  // never).
  double conversion_damage = 0;
  // An adaptive element converts when 1/sqrt(sum b.b) of its centre gradients (the length of
  // its stable step) falls below this fraction of its reference value (0: never).
  double conversion_length_ratio = 0;
  // Derived values cached by cache_derived() (the model does it for every law it hands to the
  // kernels), so the element kernel needs no square root, sine or cosine to get them.
  double p_wave_speed = 0;  // m/s, wave_speed() (0: unset)
  int cone_cached = 0;      // 1: the three below hold the mohr_coulomb cone and cap
  double cone_alpha = 0;    // drucker_prager_constants
  double cone_k = 0;        // Pa
  double tension_cap = -1;  // Pa, effective_tension_cap (negative: none)
  HjcParams hjc;            // model kHjc
  JohnsonCookParams jc;     // model kJohnsonCook

  // P-wave modulus of the formulation: plane strain lambda + 2G, plane stress E / (1 - nu^2).
  // hjc (plane strain only): its elastic moduli, K = p_crush / mu_crush; compacted points are
  // stiffer (hjc_wave_speed).
  KOKKOS_INLINE_FUNCTION double p_wave_modulus() const {
    return plane_strain ? lame_lambda + 2.0 * shear_modulus
                        : youngs_modulus / (1.0 - poisson_ratio * poisson_ratio);
  }
  KOKKOS_INLINE_FUNCTION double wave_speed() const { return sqrt_(p_wave_modulus() / density); }
};

inline MaterialLaw make_material_law(int model, bool plane_strain, double density, double E,
                                     double nu) {
  MaterialLaw m;
  m.model = model;
  m.plane_strain = plane_strain ? 1 : 0;
  m.density = density;
  m.youngs_modulus = E;
  m.poisson_ratio = nu;
  m.shear_modulus = E / (2.0 * (1.0 + nu));
  m.lame_lambda = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
  return m;
}

// Elastic trial: s += C : deps for the formulation. T: double, or one element per lane
// (simd.hpp).
template <class T>
KOKKOS_INLINE_FUNCTION void elastic_increment(const MaterialLaw& m, const T deps[3], T s[4]) {
  const double G = m.shear_modulus;
  if (m.plane_strain) {
    const double lam = m.lame_lambda;
    const T tr = deps[0] + deps[1];
    s[0] += lam * tr + 2.0 * G * deps[0];
    s[1] += lam * tr + 2.0 * G * deps[1];
    s[2] += lam * tr;
  } else {
    const double c = m.youngs_modulus / (1.0 - m.poisson_ratio * m.poisson_ratio);
    s[0] += c * (deps[0] + m.poisson_ratio * deps[1]);
    s[1] += c * (deps[1] + m.poisson_ratio * deps[0]);
    s[2] = splat<T>(0.0);
  }
  s[3] += 2.0 * G * deps[2];
}

// 3D elastic trial with a prescribed eps_zz increment (xz = yz = 0): the plane-strain trial
// (deps_zz = 0 gives it bit for bit) and the axisymmetric one (deps_zz the hoop increment).
template <class T>
KOKKOS_INLINE_FUNCTION void elastic_increment_3d(const MaterialLaw& m, const T deps[3],
                                                 const T& deps_zz, T s[4]) {
  const double G = m.shear_modulus, lam = m.lame_lambda;
  const T tr = deps[0] + deps[1] + deps_zz;
  s[0] += lam * tr + 2.0 * G * deps[0];
  s[1] += lam * tr + 2.0 * G * deps[1];
  s[2] += lam * tr + 2.0 * G * deps_zz;
  s[3] += 2.0 * G * deps[2];
}

// Recoverable strain energy density w = 1/2 s : C^-1 : s (J/m^3), valid in both formulations
// because it uses the full 3D compliance with s[2] (= 0 in plane stress).
KOKKOS_INLINE_FUNCTION double elastic_energy_density(const MaterialLaw& m, const double s[4]) {
  const double E = m.youngs_modulus, nu = m.poisson_ratio;
  return (s[0] * s[0] + s[1] * s[1] + s[2] * s[2] -
          2.0 * nu * (s[0] * s[1] + s[1] * s[2] + s[2] * s[0])) /
             (2.0 * E) +
         s[3] * s[3] / (2.0 * m.shear_modulus);
}

// exp(x) of a step's volumetric strain increment (T: double, or simd.hpp's lane type): for
// |x| <= 1/32, every step's in practice, the Taylor polynomial of degree 7 in Horner form with
// explicit fused multiply-adds (fma_), whose truncation x^8/8! is below 3e-17 relative and whose
// rounding costs a few ulps, so that a lane and the scalar update give the same bits without a
// call per lane; larger |x| through exp_ (libm). hjc_update and hjc_elastic_update both take it.
template <class T>
KOKKOS_FORCEINLINE_FUNCTION T exp_of_increment(const T& x) {
  constexpr double kInverseFactorial[8] = {1.0,        1.0,         1.0 / 2.0,   1.0 / 6.0,
                                           1.0 / 24.0, 1.0 / 120.0, 1.0 / 720.0, 1.0 / 5040.0};
  T p = splat<T>(kInverseFactorial[7]);
  for (int k = 6; k >= 0; --k) p = fma_(p, x, splat<T>(kInverseFactorial[k]));
  const auto large = fabs_(x) > 0.03125;
  if (!any_lane(large)) return p;
  return large ? exp_(x) : p;
}

namespace detail {

// ---------------------------------------------------------------------------------------------
// bilinear_j2: von Mises, linear isotropic hardening R(epeq) = yield_stress + H epeq.
// ---------------------------------------------------------------------------------------------

// Plane strain: classical 3D radial return (Simo & Hughes 1998, Box 3.2, linear hardening) on
// the full stress {xx, yy, zz, xy} of the elastic trial (eps_zz = 0 is already in the trial).
// With q = sqrt(3/2) |s| the trial von Mises stress, d epeq = (q - R_n) / (3G + H) and
// s_dev <- s_dev (1 - 3G d epeq / q); the plastic strain is dep = 3/2 d epeq s_dev / q
// (deviatoric, so |dep| = sqrt(3/2) d epeq and epeq grows by exactly d epeq).
// Returns the backward-Euler plastic work s_new : dep = R_new d epeq.
KOKKOS_INLINE_FUNCTION double j2_radial_return_3d(const MaterialLaw& m, double s[4], double& epeq) {
  const double G = m.shear_modulus, H = m.plastic_modulus;
  const double p = (s[0] + s[1] + s[2]) / 3.0;
  const double d0 = s[0] - p, d1 = s[1] - p, d2 = s[2] - p, d3 = s[3];
  const double q = sqrt_(1.5 * (d0 * d0 + d1 * d1 + d2 * d2 + 2.0 * d3 * d3));
  const double R = m.yield_stress + H * epeq;
  if (!(q > R)) return 0.0;
  const double dep = (q - R) / (3.0 * G + H);
  const double f = 1.0 - 3.0 * G * dep / q;
  s[0] = p + f * d0;
  s[1] = p + f * d1;
  s[2] = p + f * d2;
  s[3] = f * d3;
  epeq += dep;
  return (R + H * dep) * dep;
}

// Plane stress: Simo & Taylor (1986) closed-form projection, Simo & Hughes 1998 Box 3.3.
// In Voigt form sigma = {xx, yy, xy}, f = 1/2 sigma.P.sigma - 1/3 R^2 with
// P = 1/3 [[2,-1,0],[-1,2,0],[0,0,6]]; P and the plane-stress elasticity C share eigenvectors,
// so sigma_{n+1} = (I + dgamma C P)^-1 sigma_trial is diagonal in
//   (xx+yy): 1 / (1 + E dgamma / (3 (1 - nu)))   and   (xx-yy), xy: 1 / (1 + 2 G dgamma).
// phi^2(dgamma) = sigma.P.sigma = a1 / (6 (1 + E dg/(3(1-nu)))^2) + (a2/2 + 2 a3)/(1 + 2 G dg)^2
// with a1 = (xx+yy)^2, a2 = (yy-xx)^2, a3 = xy^2 of the trial (Box 3.3, step 3).
// The plastic strain rate is dgamma P sigma = dgamma s (the 3D deviator, zz = -(xx+yy)/3), so
// epeq = sqrt(2/3 dep:dep) grows by sqrt(2/3) dgamma phi (Box 3.3's alpha update).
// Consistency: phi = sqrt(2/3) R(epeq_n + sqrt(2/3) dgamma phi). We solve it with Newton in the
// form g(dg) = phi(dg) - sqrt(2/3) R(...) = 0, the square root of Box 3.3's
// 1/2 phi^2 - 1/3 R^2 = 0 (same root, better scaled; for H >= 0 g is strictly decreasing, so
// the root is unique), starting from dgamma = 0 and falling back to bisection whenever a Newton
// iterate leaves the current bracket. s[2] stays exactly 0.
// Returns the plastic work s_new : dep = dgamma phi^2 (>= 0).
KOKKOS_INLINE_FUNCTION double j2_plane_stress_return(const MaterialLaw& m, double s[4],
                                                     double& epeq) {
  const double E = m.youngs_modulus, nu = m.poisson_ratio, G = m.shear_modulus;
  const double H = m.plastic_modulus;
  const double q2 = s[0] * s[0] + s[1] * s[1] - s[0] * s[1] + 3.0 * s[3] * s[3];
  const double Rn = m.yield_stress + H * epeq;
  if (!(q2 > Rn * Rn)) return 0.0;
  const double a1 = (s[0] + s[1]) * (s[0] + s[1]);
  const double a2 = (s[1] - s[0]) * (s[1] - s[0]);
  const double a3 = s[3] * s[3];
  const double cv = E / (3.0 * (1.0 - nu));  // eigenvalue of C P on (xx+yy)
  const double c2 = 0.5 * a2 + 2.0 * a3;
  const double r23 = 0.81649658092772603;  // sqrt(2/3)
  // Safeguard bracket [lo, hi] (rtsafe-style): for H >= 0, R >= R_n and
  // phi(dg) <= phi_trial / (1 + min(cv, 2G) dg), so g < 0 beyond hi below.
  const double phi_tr = sqrt_(a1 / 6.0 + c2);
  double lo = 0.0, hi = Rn > 0.0 ? (phi_tr / (r23 * Rn) - 1.0) / min_(cv, 2.0 * G) : -1.0;
  double dg = 0.0, phi = 0.0;
  for (int it = 0; it < 60; ++it) {
    const double u = 1.0 + cv * dg, w = 1.0 + 2.0 * G * dg;
    const double phi2 = a1 / (6.0 * u * u) + c2 / (w * w);
    phi = sqrt_(phi2);
    const double R = Rn + H * r23 * dg * phi;
    const double g = phi - r23 * R;
    // d phi^2 / d dg, then d phi = d phi^2 / (2 phi); d R = H sqrt(2/3) (phi + dg dphi).
    const double dphi2 = -a1 * cv / (3.0 * u * u * u) - 4.0 * G * c2 / (w * w * w);
    const double dphi = dphi2 / (2.0 * phi);
    const double dgdg = dphi - r23 * H * r23 * (phi + dg * dphi);
    // Converged at this dg: test before stepping. (A Newton step below the resolution of dg
    // lands on the bracket end lo = dg and would be taken for an escape, sending dg to the
    // bisection midpoint — as happened with FMA contraction on a 30:-20:25 yield-strain step.)
    if (g == 0.0 || fabs_(g) <= 1e-16 * R) break;
    if (g > 0.0) {
      lo = dg;
    } else {
      hi = dg;
    }
    double dn = dg - g / dgdg;
    if (!(dn >= lo && (hi < 0.0 || dn <= hi)) && hi >= 0.0) dn = 0.5 * (lo + hi);
    const double step = dn - dg;
    dg = dn;
    if (fabs_(step) <= 1e-15 * dg) break;
  }
  const double u = 1.0 + cv * dg, w = 1.0 + 2.0 * G * dg;
  const double phi2 = a1 / (6.0 * u * u) + c2 / (w * w);
  phi = sqrt_(phi2);
  const double sum = (s[0] + s[1]) / u, dif = (s[0] - s[1]) / w;
  s[0] = 0.5 * (sum + dif);
  s[1] = 0.5 * (sum - dif);
  s[2] = 0.0;
  s[3] = s[3] / w;
  epeq += r23 * dg * phi;
  return dg * phi2;
}

KOKKOS_INLINE_FUNCTION double bilinear_j2_update(const MaterialLaw& m, const double deps[3],
                                                 double deps_zz, double s[4], double& epeq) {
  if (!m.plane_strain) {
    elastic_increment(m, deps, s);
    return j2_plane_stress_return(m, s, epeq);
  }
  elastic_increment_3d(m, deps, deps_zz, s);
  return j2_radial_return_3d(m, s, epeq);
}

// ---------------------------------------------------------------------------------------------
// mohr_coulomb: Drucker-Prager cone sqrt(J2) + alpha I1 <= k, zero-dilatancy flow, with a
// Rankine tension cut-off. All of it works on the 3D stress {xx, yy, zz, xy} (xz = yz = 0).
// ---------------------------------------------------------------------------------------------

// Cone constants. The flow is non-associated with zero dilatancy (deviatoric return at fixed
// pressure), so in steady plane-strain flow dep_zz = 0 forces s_zz = 0, i.e.
// sigma_zz = (sigma_1 + sigma_2) / 2, sqrt(J2) = t = (sigma_1 - sigma_2) / 2 and
// I1 = 3 s_m with s_m = (sigma_1 + sigma_2) / 2. The cone then reads t = k - 3 alpha s_m and
// coincides with Mohr-Coulomb t = c cos(phi) - s_m sin(phi) exactly when
//   alpha = sin(phi) / 3,  k = c cos(phi)
// (Abaqus Theory Manual, "matching Mohr-Coulomb parameters", plane strain with psi = 0). The
// often quoted alpha = tan(phi) / sqrt(9 + 12 tan^2 phi), k = 3 c / sqrt(9 + 12 tan^2 phi) is the
// plane-strain match for ASSOCIATED flow (psi = phi); with this zero-dilatancy flow it would
// under-predict the plane-strain strength by 4 % at phi = 30 deg and 7 % at 45 deg.
KOKKOS_INLINE_FUNCTION void drucker_prager_constants(const MaterialLaw& m, double& alpha,
                                                     double& k) {
  if (m.cone_cached) {
    alpha = m.cone_alpha;
    k = m.cone_k;
    return;
  }
  alpha = sin_(m.friction_angle) / 3.0;
  k = m.cohesion * cos_(m.friction_angle);
}

// Cut-off actually applied: tensile_strength, but never above the cone's apex mean stress
// k / (3 alpha) (= c cot(phi), the Mohr-Coulomb apex). The cone admits no principal stress above
// the apex value, so the min only acts on trial states past the apex, which the deviatoric
// (fixed-pressure) return cannot bring back; with tensile_strength = 0 ("no cut-off") the apex
// is the cap. Returns a negative number when there is no cap at all (phi = 0 and no cut-off).
KOKKOS_INLINE_FUNCTION double effective_tension_cap(const MaterialLaw& m, double alpha, double k) {
  if (m.cone_cached) return m.tension_cap;  // cache_derived: this function's value
  double cap = m.tensile_strength > 0.0 ? m.tensile_strength : -1.0;
  if (alpha > 0.0) {
    const double apex = k / (3.0 * alpha);
    cap = cap >= 0.0 ? min_(cap, apex) : apex;
  }
  return cap;
}

// The law with its tension cut-off raised by a dynamic increase factor (>= 1): tensile_strength
// (and hjc's hydrostatic tension limit T) times the factor, and the cached cap re-derived from
// it (effective_tension_cap).
KOKKOS_INLINE_FUNCTION MaterialLaw with_tension_factor(const MaterialLaw& m, double factor) {
  MaterialLaw out = m;
  out.tensile_strength = m.tensile_strength * factor;
  out.hjc.t = m.hjc.t * factor;
  if (m.cone_cached) {
    out.cone_cached = 0;
    out.tension_cap = effective_tension_cap(out, m.cone_alpha, m.cone_k);
    out.cone_cached = 1;
  }
  return out;
}

KOKKOS_INLINE_FUNCTION double drucker_prager_f(const double s[4], double alpha, double k) {
  const double p = (s[0] + s[1] + s[2]) / 3.0;
  const double d0 = s[0] - p, d1 = s[1] - p, d2 = s[2] - p;
  const double j2 = 0.5 * (d0 * d0 + d1 * d1 + d2 * d2) + s[3] * s[3];
  return sqrt_(j2) + alpha * 3.0 * p - k;
}

// Shear mechanism: deviatoric radial return at fixed I1 (zero dilatancy): s_dev <- beta s_dev
// with beta = (k - alpha I1) / sqrt(J2_trial), or beta = 0 past the apex (k - alpha I1 <= 0).
// The plastic strain dep = (1 - beta) s_dev / (2G) is deviatoric; it is added to dep_acc.
// Returns the sub-step plastic work s_new : dep = beta (1 - beta) |s_dev|^2 / (2G) >= 0.
KOKKOS_INLINE_FUNCTION double drucker_prager_return(const MaterialLaw& m, double alpha, double k,
                                                    double tol, double s[4], double dep_acc[4]) {
  const double p = (s[0] + s[1] + s[2]) / 3.0;
  const double d0 = s[0] - p, d1 = s[1] - p, d2 = s[2] - p, d3 = s[3];
  const double j2 = 0.5 * (d0 * d0 + d1 * d1 + d2 * d2) + d3 * d3;
  const double rj2 = sqrt_(j2);
  const double r = k - alpha * 3.0 * p;  // admissible sqrt(J2) at this pressure
  if (rj2 - r <= tol) return 0.0;
  const double beta = r > 0.0 ? r / rj2 : 0.0;
  const double c = (1.0 - beta) / (2.0 * m.shear_modulus);
  dep_acc[0] += c * d0;
  dep_acc[1] += c * d1;
  dep_acc[2] += c * d2;
  dep_acc[3] += c * d3;
  s[0] = p + beta * d0;
  s[1] = p + beta * d1;
  s[2] = p + beta * d2;
  s[3] = beta * d3;
  return beta * (1.0 - beta) * 2.0 * j2 / (2.0 * m.shear_modulus);
}

// Rankine cut-off, associated, multi-surface (Koiter) return in principal space. The principal
// stresses are the two in-plane ones and sigma_zz. With isotropic elasticity the principal
// directions do not change during the return and, on the principal axes, C = 2G I + lambda 1 1^T
// (3D elasticity: the increment is at eps_zz fixed, i.e. plane strain; plane stress reaches it
// through the eps_zz iteration of mohr_coulomb_plane_stress, which is equivalent to the
// condensed E/(1-nu^2), nu E/(1-nu^2) moduli with dep_zz = 0). For the active set A,
//   sigma_i = sigma_i^tr - 2G dl_i - lambda sum_A dl_j = T  (i in A)
//   => dl_A = (1/2G) [r_A - lambda / (2G + n_A lambda) sum(r_A)],  r_i = sigma_i^tr - T,
// dropping multipliers < 0 and adding surfaces that the coupling pushes above T (a corner).
// dep = sum dl_i n_i (x) n_i is added to dep_acc and the sub-step work T sum dl_i (>= 0) to
// diss. Returns whether the cut-off was active.
KOKKOS_INLINE_FUNCTION bool rankine_return(const MaterialLaw& m, double T, double s[4],
                                           double dep_acc[4], double& diss) {
  const double c = 0.5 * (s[0] + s[1]), h = 0.5 * (s[0] - s[1]);
  const double rad = sqrt_(h * h + s[3] * s[3]);
  double pv[3] = {c + rad, c - rad, s[2]};
  const double tol = 1e-14 * (fabs_(T) + fabs_(c) + rad + fabs_(s[2]));
  if (!(pv[0] > T + tol) && !(pv[2] > T + tol)) return false;
  const double a = 2.0 * m.shear_modulus, b = m.lame_lambda;
  int act[3] = {pv[0] > T + tol, pv[1] > T + tol, pv[2] > T + tol};
  double dl[3] = {0.0, 0.0, 0.0};
  for (int it = 0; it < 8; ++it) {
    int n = 0;
    double rsum = 0.0;
    for (int i = 0; i < 3; ++i)
      if (act[i]) {
        ++n;
        rsum += pv[i] - T;
      }
    const double f = b / (a + n * b);
    for (int i = 0; i < 3; ++i) dl[i] = act[i] ? ((pv[i] - T) - f * rsum) / a : 0.0;
    int worst = -1;
    double wv = 0.0;
    for (int i = 0; i < 3; ++i)
      if (act[i] && dl[i] < wv) {
        wv = dl[i];
        worst = i;
      }
    if (worst >= 0) {
      act[worst] = 0;
      continue;
    }
    const double sum = dl[0] + dl[1] + dl[2];
    bool added = false;
    for (int i = 0; i < 3; ++i)
      if (!act[i] && pv[i] - b * sum > T + tol) {
        act[i] = 1;
        added = true;
      }
    if (!added) break;
  }
  const double sum = dl[0] + dl[1] + dl[2];
  for (int i = 0; i < 3; ++i) pv[i] = act[i] ? T : pv[i] - a * dl[i] - b * sum;
  // Rotate back with the trial's principal axes: cos 2theta = h / rad, sin 2theta = xy / rad.
  const double c2 = rad > 0.0 ? h / rad : 1.0, s2 = rad > 0.0 ? s[3] / rad : 0.0;
  const double cm = 0.5 * (pv[0] + pv[1]), dm = 0.5 * (pv[0] - pv[1]);
  s[0] = cm + dm * c2;
  s[1] = cm - dm * c2;
  s[2] = pv[2];
  s[3] = dm * s2;
  // n1 (x) n1 = {(1 + c2)/2, (1 - c2)/2, s2/2}, n2 (x) n2 = {(1 - c2)/2, (1 + c2)/2, -s2/2}.
  dep_acc[0] += 0.5 * (dl[0] * (1.0 + c2) + dl[1] * (1.0 - c2));
  dep_acc[1] += 0.5 * (dl[0] * (1.0 - c2) + dl[1] * (1.0 + c2));
  dep_acc[2] += dl[2];
  dep_acc[3] += 0.5 * (dl[0] - dl[1]) * s2;
  diss += T * sum;
  return true;
}

// Both mechanisms on a 3D trial stress. Operator split: cone return, then cut-off. A cut-off
// return only lowers normal stresses (I1 falls, the cone widens) and, to first order, lowers
// J2 (dJ2 = -2G dl s_1 with s_1 >= 0 the largest deviatoric principal value), so one pass is
// normally admissible (it was in every one of ~10^7 random trial states tried); since a finite
// cut-off step is not covered by that first-order argument, the pair is repeated as a safeguard
// if the cone is violated afterwards (free when it is not). epeq grows by sqrt(2/3 dep:dep) of the
// step's total 3D plastic strain (docs/physics.md 1.1, paper Eq. 13). Returns the sum of the
// sub-steps' plastic work (each >= 0).
KOKKOS_INLINE_FUNCTION double mohr_coulomb_return_3d(const MaterialLaw& m, double s[4],
                                                     double& epeq) {
  double alpha, k;
  drucker_prager_constants(m, alpha, k);
  const double T = effective_tension_cap(m, alpha, k);
  const double scale =
      fabs_(s[0]) + fabs_(s[1]) + fabs_(s[2]) + fabs_(s[3]) + fabs_(k) + max_(T, 0.0);
  const double tol = 1e-14 * scale;
  double dep[4] = {0.0, 0.0, 0.0, 0.0};
  double diss = 0.0;
  for (int it = 0; it < 50; ++it) {
    diss += drucker_prager_return(m, alpha, k, tol, s, dep);
    if (!(T >= 0.0)) break;
    if (!rankine_return(m, T, s, dep, diss) || drucker_prager_f(s, alpha, k) <= 16.0 * tol) break;
  }
  const double dd = dep[0] * dep[0] + dep[1] * dep[1] + dep[2] * dep[2] + 2.0 * dep[3] * dep[3];
  epeq += sqrt_(2.0 / 3.0 * dd);
  return diss;
}

// Plane stress for a 3D law: the law's 3D update with an unknown eps_zz increment x, solved
// for sigma_zz(x) = 0 (the plane-stress condition). trial(x, st) runs the update from the
// point's start state with the increment x, leaves the stress in st and keeps the rest of the
// result (plastic strain, state, dissipation) itself, and returns sigma_zz. sigma_zz(x) must be
// continuous and non-decreasing (so for Mohr-Coulomb: elastic and cut-off states have an
// elastic (Schur-complement) slope > 0; on the cone it is >= K (1 - 2 sqrt(3) alpha) > 0
// because alpha = sin(phi)/3 < 1/(2 sqrt(3)); it is flat (at the cap) only when the cut-off
// also holds sigma_zz, which is away from the root sigma_zz = 0; for J2 laws the slope is at
// least that of the bulk modulus). Start from the elastic guess x = -lambda/(lambda+2G)
// (dxx + dyy) (exact for an elastic step, so elastic steps cost one evaluation). Bracket the
// root by secant steps, at least doubling the step while the sign does not change (plateaus and
// soft plastic tangents), then refine with the Illinois variant of regula falsi (guaranteed,
// superlinear). stress_scale: a stress of the law (its strengths) for the tolerance, 1e-13 of
// the stresses in play. The converged st (|s_zz| <= that tolerance) goes to s with s[2] = 0
// exactly; the last trial evaluated is the converged one, so the law's other results are too.
template <class Trial>
KOKKOS_INLINE_FUNCTION void solve_plane_stress(const MaterialLaw& m, const double deps[3],
                                               const double s0[4], double stress_scale, double s[4],
                                               Trial& trial) {
  const double Ee = m.lame_lambda + 2.0 * m.shear_modulus;
  double st[4];
  double xa = -m.lame_lambda / Ee * (deps[0] + deps[1]);
  double ga = trial(xa, st);
  const double tol = 1e-13 * (fabs_(st[0]) + fabs_(st[1]) + fabs_(st[3]) + fabs_(s0[0]) +
                              fabs_(s0[1]) + fabs_(s0[3]) + stress_scale);
  if (fabs_(ga) > tol) {
    double h = -ga / Ee, xb = xa, gb = ga;
    bool bracketed = false;
    for (int it = 0; it < 80; ++it) {
      xb = xa + h;
      gb = trial(xb, st);
      if (fabs_(gb) <= tol) break;
      if ((gb < 0.0) != (ga < 0.0)) {
        bracketed = true;
        break;
      }
      const double slope = (gb - ga) / (xb - xa);
      const double hs = slope > 0.0 ? -gb / slope : 0.0;
      h = fabs_(hs) > 2.0 * fabs_(h) ? hs : 2.0 * h;
      xa = xb;
      ga = gb;
    }
    for (int it = 0; bracketed && it < 200; ++it) {
      const double xc = (xa * gb - xb * ga) / (gb - ga);
      const double gc = trial(xc, st);
      if (fabs_(gc) <= tol) break;
      if ((gc < 0.0) != (gb < 0.0)) {
        xa = xb;
        ga = gb;
      } else {
        ga *= 0.5;  // Illinois: halve the retained end's value
      }
      xb = xc;
      gb = gc;
      if (fabs_(xb - xa) <= 1e-15 * (fabs_(xa) + fabs_(xb))) break;
    }
  }
  for (int i = 0; i < 4; ++i) s[i] = st[i];
  s[2] = 0.0;
}

// The Mohr-Coulomb trial of solve_plane_stress: one 3D update from (s0, ep0) with the eps_zz
// increment x; its epeq and dissipation are kept in ept and diss.
struct MohrCoulombEpsZzTrial {
  const MaterialLaw& m;
  const double* deps;
  const double* s0;
  double ep0, ept, diss;
  KOKKOS_INLINE_FUNCTION double operator()(double x, double st[4]) {
    for (int i = 0; i < 4; ++i) st[i] = s0[i];
    ept = ep0;
    elastic_increment_3d(m, deps, x, st);
    diss = mohr_coulomb_return_3d(m, st, ept);
    return st[2];
  }
};

// Plane stress Mohr-Coulomb: solve_plane_stress with the 3D Mohr-Coulomb update.
KOKKOS_INLINE_FUNCTION double mohr_coulomb_plane_stress(const MaterialLaw& m, const double deps[3],
                                                        double s[4], double& epeq) {
  const double s0[4] = {s[0], s[1], 0.0, s[3]};
  double alpha, k;
  drucker_prager_constants(m, alpha, k);
  MohrCoulombEpsZzTrial trial{m, deps, s0, epeq, epeq, 0.0};
  solve_plane_stress(m, deps, s0, fabs_(k) + m.tensile_strength, s, trial);
  epeq = trial.ept;
  return trial.diss;
}

KOKKOS_INLINE_FUNCTION double mohr_coulomb_update(const MaterialLaw& m, const double deps[3],
                                                  double deps_zz, double s[4], double& epeq) {
  if (!m.plane_strain) return mohr_coulomb_plane_stress(m, deps, s, epeq);
  elastic_increment_3d(m, deps, deps_zz, s);
  return mohr_coulomb_return_3d(m, s, epeq);
}

// ---------------------------------------------------------------------------------------------
// hjc: Holmquist-Johnson-Cook concrete (HjcParams). Plane strain, on the 3D stress
// {xx, yy, zz, xy}: the pressure comes from the equation of state of the volumetric strain
// mu = rho / rho0 - 1, the deviator from a radial return onto the pressure-, damage- and
// rate-dependent strength. State per point: HjcState.
// ---------------------------------------------------------------------------------------------

// The equation of state on its envelope at the largest compaction mu_max (HJC 1993, Fig. 2):
// elastic to (mu_crush, p_crush) with K_e = p_crush / mu_crush; crushing (air voids closing)
// linear to (mu_lock, p_lock), unloading along K_u = (1 - F) K_e + F K1 with
// F = (mu_max - mu_crush) / (mu_lock - mu_crush), so that a crushed point keeps the plastic
// volumetric strain mu_max - p_max / K_u. Gives the envelope pressure p_max and K_u at
// min(mu_max, mu_lock).
KOKKOS_INLINE_FUNCTION void hjc_envelope(const HjcParams& h, double mu_max, double& p_max,
                                         double& k_unload) {
  const double k_elastic = h.p_crush / h.mu_crush;
  if (mu_max <= h.mu_crush) {
    p_max = k_elastic * max_(mu_max, 0.0);
    k_unload = k_elastic;
    return;
  }
  const double f = min_((mu_max - h.mu_crush) / (h.mu_lock - h.mu_crush), 1.0);
  p_max = h.p_crush + (h.p_lock - h.p_crush) * f;
  k_unload = (1.0 - f) * k_elastic + f * h.k1;
}

// Fully dense material beyond mu_lock: P = p_lock + K1 mb + K2 mb^2 + K3 mb^3 with
// mb = (mu - mu_lock) / (1 + mu_lock), loading and unloading alike. The 1993 paper writes
// K1 mb + ... with mb from a separate locking strain (rho_grain / rho0 - 1), which meets the
// crush line at p_lock only for one value of it; measuring mb from mu_lock and adding p_lock
// makes the curve continuous for any constants (as LS-DYNA's *MAT_111 documentation draws it).
KOKKOS_INLINE_FUNCTION double hjc_dense_pressure(const HjcParams& h, double mu) {
  const double mb = (mu - h.mu_lock) / (1.0 + h.mu_lock);
  return h.p_lock + mb * (h.k1 + mb * (h.k2 + mb * h.k3));
}

// Pressure (Pa, compression positive) at volumetric strain mu after the largest compaction
// mu_max, before the tension limit.
KOKKOS_INLINE_FUNCTION double hjc_pressure(const HjcParams& h, double mu, double mu_max) {
  if (mu_max > h.mu_lock && mu >= h.mu_lock) return hjc_dense_pressure(h, mu);
  const double mu_env = min_(mu_max, h.mu_lock);
  double p_max, k_unload;
  hjc_envelope(h, mu_env, p_max, k_unload);
  return p_max - k_unload * (mu_env - mu);
}

// Plastic volumetric strain after the largest compaction mu_max (mu at zero pressure on its
// unloading line), the mu_p of the damage sum: exactly 0 up to the crush point, where the
// loading line is the unloading line (the quotient below would leave the round-off of
// K_e mu_max / K_e).
KOKKOS_INLINE_FUNCTION double hjc_plastic_volumetric_strain(const HjcParams& h, double mu_max) {
  if (mu_max <= h.mu_crush) return 0.0;
  const double mu_env = min_(mu_max, h.mu_lock);
  double p_max, k_unload;
  hjc_envelope(h, mu_env, p_max, k_unload);
  return max_(mu_env - p_max / k_unload, 0.0);
}

// Normalised strength (HJC 1993, Eq. 1): sigma* = [A (1 - D) + B P*^N] [1 + C ln(eps_dot*)]
// <= S_max, with P* = P / f'_c, eps_dot* = eps_dot / eps0 (no rate term below eps0: the
// constants are fitted at and above it). The paper gives the cohesive part only for P* >= 0; at
// negative pressures it falls linearly to 0 at the damaged tension limit -T (1 - D), where the
// material can hold no stress at all (as EPIC and LS-DYNA do). Returns sigma* f'_c (Pa).
KOKKOS_INLINE_FUNCTION double hjc_strength(const HjcParams& h, double p, double damage,
                                           double strain_rate) {
  const double p_star = p / h.fc, intact = 1.0 - damage;
  double s = 0.0;
  if (p_star >= 0.0) {
    s = h.a * intact + h.b * pow_(p_star, h.n);
  } else {
    const double tension_limit = h.t / h.fc * intact;
    s = tension_limit > 0.0 ? h.a * intact * max_(1.0 + p_star / tension_limit, 0.0) : 0.0;
  }
  if (strain_rate > h.eps0) s *= 1.0 + h.c * log_(strain_rate / h.eps0);
  return h.fc * min_(s, h.s_max);
}

// Plastic strain to fracture (HJC 1993, Eq. 3): eps_p^f + mu_p^f = D1 (P* + T*)^D2 >= EF_min.
KOKKOS_INLINE_FUNCTION double hjc_fracture_strain(const HjcParams& h, double p) {
  const double x = (p + h.t) / h.fc;
  return max_(x > 0.0 ? h.d1 * pow_(x, h.d2) : 0.0, h.ef_min);
}

// Bulk modulus the point unloads or reloads with now (Pa): K_u of its envelope, or the dense
// curve's slope, at least K1, beyond mu_lock. Sets the point's wave speed (hjc_wave_speed).
KOKKOS_INLINE_FUNCTION double hjc_tangent_bulk_modulus(const HjcParams& h, double mu,
                                                       double mu_max) {
  if (mu_max > h.mu_lock && mu >= h.mu_lock) {
    const double mb = (mu - h.mu_lock) / (1.0 + h.mu_lock);
    return max_(h.k1, (h.k1 + mb * (2.0 * h.k2 + 3.0 * mb * h.k3)) / (1.0 + h.mu_lock));
  }
  double p_max, k_unload;
  hjc_envelope(h, min_(mu_max, h.mu_lock), p_max, k_unload);
  return k_unload;
}

// One hjc update (HJC 1993; the integration is ours): the volumetric strain moves by the
// increment's trace (1 + mu) <- (1 + mu) exp(-tr deps); the pressure follows the equation of
// state, limited in tension to -T (1 - D); the deviator takes the elastic trial 2G deps_dev and
// returns radially onto the strength at the new pressure with the damage of the step's start
// (d eps_p = (q_trial - sigma_y) / 3G, as J2 flow); then the damage grows by
// (d eps_p + d mu_p) / (D1 (P* + T*)^D2), at most to 1. state: HjcState. strain_rate: the
// equivalent strain rate sqrt(2/3 d':d') (1/s). deps_zz: the out-of-plane increment (0 in plane
// strain). Returns the dissipation density (J/m^3): sigma_y d eps_p of the deviator and
// P d mu_p / (1 + mu) of the crushing.
KOKKOS_INLINE_FUNCTION double hjc_update(const MaterialLaw& m, const double deps[3], double deps_zz,
                                         double s[4], double& epeq, double state[3],
                                         double strain_rate) {
  const HjcParams& h = m.hjc;
  const double G = m.shear_modulus;
  double damage = state[0];
  const double mu_max_old = state[2];
  const double tr = deps[0] + deps[1] + deps_zz;
  const double mu = (1.0 + state[1]) * exp_of_increment(-tr) - 1.0;
  const double mu_max = max_(mu_max_old, mu);
  double p = hjc_pressure(h, mu, mu_max);
  const double tension_limit = h.t * (1.0 - damage);
  p = max_(p, -tension_limit);
  // Deviatoric trial and radial return.
  const double p_old = -(s[0] + s[1] + s[2]) / 3.0;
  const double e_mean = tr / 3.0;
  double d[4] = {s[0] + p_old + 2.0 * G * (deps[0] - e_mean),
                 s[1] + p_old + 2.0 * G * (deps[1] - e_mean),
                 s[2] + p_old + 2.0 * G * (deps_zz - e_mean), s[3] + 2.0 * G * deps[2]};
  const double q = sqrt_(1.5 * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2] + 2.0 * d[3] * d[3]));
  const double yield = hjc_strength(h, p, damage, strain_rate);
  double dep = 0.0, work = 0.0;
  if (q > yield) {
    dep = (q - yield) / (3.0 * G);
    const double f = q > 0.0 ? yield / q : 0.0;
    for (int k = 0; k < 4; ++k) d[k] *= f;
    work += yield * dep;
  }
  // Crushing only while mu_max grows (most steps it does not: no envelope to evaluate).
  const double dmu_p = mu_max > mu_max_old ? hjc_plastic_volumetric_strain(h, mu_max) -
                                                 hjc_plastic_volumetric_strain(h, mu_max_old)
                                           : 0.0;
  work += max_(p, 0.0) * dmu_p / (1.0 + mu);
  damage = min_(damage + (dep + dmu_p) / hjc_fracture_strain(h, p), 1.0);
  s[0] = d[0] - p;
  s[1] = d[1] - p;
  s[2] = d[2] - p;
  s[3] = d[3];
  epeq += dep;
  state[0] = damage;
  state[1] = mu;
  state[2] = mu_max;
  return work;
}

// ---------------------------------------------------------------------------------------------
// johnson_cook: Johnson-Cook plasticity and fracture (JohnsonCookParams). On the 3D stress
// {xx, yy, zz, xy}: J2 radial return onto the flow stress at the step's strain rate and start
// temperature; plane stress through solve_plane_stress. State per point: JohnsonCookState.
// ---------------------------------------------------------------------------------------------

// Flow stress (Johnson & Cook 1983, Eq. 1): (A + B eps_p^n) [1 + C ln(eps_dot*)] (1 - T*^m),
// eps_dot* = eps_dot / eps0 (no rate term below eps0), T* = dT / (t_melt - t_room) for a point
// heated by dT above room temperature (0 at or below it; no strength at the melting point).
// jc_rate_thermal_factor: the last two brackets, which do not depend on eps_p.
KOKKOS_INLINE_FUNCTION double jc_rate_thermal_factor(const JohnsonCookParams& j, double strain_rate,
                                                     double heating) {
  const double rate = strain_rate > j.eps0 ? 1.0 + j.c * log_(strain_rate / j.eps0) : 1.0;
  const double t_star = j.t_melt > j.t_room ? heating / (j.t_melt - j.t_room) : 0.0;
  const double thermal = t_star <= 0.0 ? 1.0 : t_star >= 1.0 ? 0.0 : 1.0 - pow_(t_star, j.m);
  return rate * thermal;
}
KOKKOS_INLINE_FUNCTION double jc_hardening(const JohnsonCookParams& j, double ep) {
  return j.a + (ep > 0.0 ? j.b * pow_(ep, j.n) : 0.0);
}
KOKKOS_INLINE_FUNCTION double jc_flow_stress(const JohnsonCookParams& j, double ep,
                                             double strain_rate, double heating) {
  return jc_hardening(j, ep) * jc_rate_thermal_factor(j, strain_rate, heating);
}

// Equivalent plastic strain to fracture (Johnson & Cook 1985, Eq. 1):
// [D1 + D2 exp(D3 sigma*)] [1 + D4 ln(eps_dot*)] [1 + D5 T*], sigma* = mean stress / von Mises
// stress (the triaxiality), eps_dot* >= 1 as for the flow stress. 0: no failure (all D 0).
KOKKOS_INLINE_FUNCTION double jc_fracture_strain(const JohnsonCookParams& j, double triaxiality,
                                                 double strain_rate, double heating) {
  const double rate = strain_rate > j.eps0 ? log_(strain_rate / j.eps0) : 0.0;
  const double t_star = j.t_melt > j.t_room ? max_(heating / (j.t_melt - j.t_room), 0.0) : 0.0;
  return (j.d1 + j.d2 * exp_(j.d3 * triaxiality)) * (1.0 + j.d4 * rate) * (1.0 + j.d5 * t_star);
}

// One johnson_cook update: the 3D elastic trial (eps_zz increment deps_zz), then, if the trial's
// von Mises stress q exceeds the flow stress, the radial return q - 3G d = sigma_y(eps_p + d)
// solved for the plastic strain increment d by Newton safeguarded with bisection on
// [0, q / 3G] (the hardening slope B n eps_p^(n-1) is unbounded at eps_p = 0), at the step's
// strain rate and start temperature. Then adiabatic heating dT += chi sigma_y d / (rho c_p) and
// damage D += d / eps_f at the new stress's triaxiality (at most 1). state: JohnsonCookState.
// Returns the plastic work density sigma_y d (J/m^3).
KOKKOS_INLINE_FUNCTION double jc_update(const MaterialLaw& m, const double deps[3], double deps_zz,
                                        double s[4], double& epeq, double state[3],
                                        double strain_rate) {
  const JohnsonCookParams& j = m.jc;
  const double G = m.shear_modulus;
  elastic_increment_3d(m, deps, deps_zz, s);
  const double p = (s[0] + s[1] + s[2]) / 3.0;
  double d[4] = {s[0] - p, s[1] - p, s[2] - p, s[3]};
  const double q = sqrt_(1.5 * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2] + 2.0 * d[3] * d[3]));
  const double heating = state[1];
  const double factor = jc_rate_thermal_factor(j, strain_rate, heating);
  if (!(q > jc_hardening(j, epeq) * factor)) return 0.0;
  double lo = 0.0, hi = q / (3.0 * G), dp = 0.0;
  for (int it = 0; it < 100; ++it) {
    const double ep = epeq + dp;
    const double yield = jc_hardening(j, ep) * factor;
    const double g = q - 3.0 * G * dp - yield;
    if (fabs_(g) <= 1e-14 * q) break;
    if (g > 0.0) {
      lo = dp;
    } else {
      hi = dp;
    }
    // Hardening slope B n eps_p^(n-1) (infinite at eps_p = 0: the step is then 0, outside the
    // bracket, and bisection takes over).
    const double slope = ep > 0.0 ? j.b * j.n * pow_(ep, j.n - 1.0) * factor : 1e300;
    double next = dp + g / (3.0 * G + slope);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (fabs_(next - dp) <= 1e-15 * (epeq + next)) {
      dp = next;
      break;
    }
    dp = next;
  }
  const double q_new = q - 3.0 * G * dp;
  const double f = q_new / q;
  for (int k = 0; k < 4; ++k) d[k] *= f;
  s[0] = p + d[0];
  s[1] = p + d[1];
  s[2] = p + d[2];
  s[3] = d[3];
  epeq += dp;
  if (j.specific_heat > 0.0)
    state[1] = heating + j.taylor_quinney * q_new * dp / (m.density * j.specific_heat);
  const double fracture =
      jc_fracture_strain(j, q_new > 0.0 ? p / q_new : 0.0, strain_rate, heating);
  if (fracture > 0.0) state[0] = min_(state[0] + dp / fracture, 1.0);
  return q_new * dp;
}

// The Johnson-Cook trial of solve_plane_stress: jc_update from the start state (s0, ep0, state0)
// with the eps_zz increment x; epeq, state and plastic work kept.
struct JohnsonCookEpsZzTrial {
  const MaterialLaw& m;
  const double* deps;
  const double* s0;
  double ep0, state0[3], strain_rate;
  double ept, state[3], work;
  KOKKOS_INLINE_FUNCTION double operator()(double x, double st[4]) {
    for (int i = 0; i < 4; ++i) st[i] = s0[i];
    for (int i = 0; i < 3; ++i) state[i] = state0[i];
    ept = ep0;
    work = jc_update(m, deps, x, st, ept, state, strain_rate);
    return st[2];
  }
};

// Plane stress Johnson-Cook: solve_plane_stress with jc_update (sigma_zz rises with the eps_zz
// increment at least at the bulk modulus's rate: the J2 return leaves the pressure alone).
KOKKOS_INLINE_FUNCTION double jc_plane_stress(const MaterialLaw& m, const double deps[3],
                                              double s[4], double& epeq, double state[3],
                                              double strain_rate) {
  const double s0[4] = {s[0], s[1], 0.0, s[3]};
  JohnsonCookEpsZzTrial trial{
      m, deps, s0, epeq, {state[0], state[1], state[2]}, strain_rate, epeq, {0.0, 0.0, 0.0}, 0.0};
  solve_plane_stress(m, deps, s0, m.jc.a + m.jc.b, s, trial);
  epeq = trial.ept;
  for (int i = 0; i < 3; ++i) state[i] = trial.state[i];
  return trial.work;
}

}  // namespace detail

// State per point of the laws that keep one (Elements::law_state), kLawStateSize values, the
// damage D in [0, 1] first (the conversion criterion reads it, conversion_damage):
//   hjc: D, volumetric strain mu = rho / rho0 - 1, and the largest mu reached;
//   johnson_cook: D, the temperature rise above room temperature (K), unused.
enum HjcState : int { kLawDamage = 0, kHjcMu = 1, kHjcMuMax = 2 };
enum JohnsonCookState : int { kJcHeating = 1 };
constexpr int kLawStateSize = 3;

// Whether a model keeps a state per point (Elements::law_state).
KOKKOS_INLINE_FUNCTION bool has_law_state(int model) {
  return model == kHjc || model == kJohnsonCook;
}

// P-wave speed (m/s) of an hjc point in its state now: its tangent bulk modulus
// (detail::hjc_tangent_bulk_modulus) + 4G/3 over rho0. A compacted point unloads up to K1 /
// K_e times stiffer than the intact one, which the element's stable step must follow.
KOKKOS_INLINE_FUNCTION double hjc_wave_speed(const MaterialLaw& m, const double state[3]) {
  const double k = detail::hjc_tangent_bulk_modulus(m.hjc, state[kHjcMu], state[kHjcMuMax]);
  // K / rho + (4G/3) / rho: no product next to the sum, which a compiler could contract into an
  // FMA in one build of this and not in another (the SIMD lanes' hjc_elastic_update must give
  // the same bits).
  return sqrt_(k / m.density + 4.0 / 3.0 * m.shear_modulus / m.density);
}

// detail::hjc_update where it is elastic, for one point per lane (T: double, or simd.hpp's lane
// type): no deviatoric flow and no new crushing. hjc_update's arithmetic in its order, so a lane it
// takes gets hjc_update's stress and state to the bit, and wave_speed hjc_wave_speed's.
// tension_factor: the lanes' dynamic increase factor of T (with_tension_factor; 1: none).
// Returns the lanes it takes; the others must run detail::hjc_update from their old s and state. A
// lane is taken when its deviatoric trial is within a lower bound of the strength that needs
// neither the power nor the rate's logarithm: for P* >= 0, f'_c min(A (1 - D), S_max) (B P*^N
// adds to it and the rate factor is at least 1, and rounding keeps both so), below it the
// tension branch itself; and when mu_max grows no further than mu_crush (no plastic volume) and
// the point is short of the dense curve. A law whose B or C is negative, or whose EF_min is not
// positive (a 0 / 0 damage increment), takes no lane.
// factor_free: the lanes taken whose pressure is at or above the tension limit: their step is
// the same, to the bit, for any larger tension_factor (a larger factor lowers the limit, so it
// still does not bind, and only raises the tension branch's strength, so the lane is still
// taken; the rest of the step does not depend on it).
template <class T, class Mask>
KOKKOS_FORCEINLINE_FUNCTION auto hjc_elastic_update(const MaterialLaw& m, const T deps[3],
                                                    const T& deps_zz, const T s[4],
                                                    const T state[3], const T& tension_factor,
                                                    T s_new[4], T& mu, T& mu_max, T& wave_speed,
                                                    Mask& factor_free) {
  const HjcParams& h = m.hjc;
  const double G = m.shear_modulus;
  const T zero = splat<T>(0.0);
  const T tr = deps[0] + deps[1] + deps_zz;
  mu = (1.0 + state[1]) * exp_of_increment(-tr) - 1.0;
  mu_max = max_(state[2], mu);
  // The envelope (hjc_envelope) at mu_env and the pressure (hjc_pressure) short of the dense
  // curve.
  const T mu_env = min_(mu_max, splat<T>(h.mu_lock));
  const double k_elastic = h.p_crush / h.mu_crush;
  const auto below_crush = mu_env <= h.mu_crush;
  const T f = min_((mu_env - h.mu_crush) / (h.mu_lock - h.mu_crush), splat<T>(1.0));
  const T p_max =
      below_crush ? k_elastic * max_(mu_env, zero) : h.p_crush + (h.p_lock - h.p_crush) * f;
  const T k_unload = below_crush ? splat<T>(k_elastic) : (1.0 - f) * k_elastic + f * h.k1;
  const T p_envelope = p_max - k_unload * (mu_env - mu);
  const T damage = state[0];
  // with_tension_factor's raised limit T.
  const T t = h.t * tension_factor;
  const T tension_limit = t * (1.0 - damage);
  const T p = max_(p_envelope, -tension_limit);
  const T p_old = -(s[0] + s[1] + s[2]) / 3.0;
  const T e_mean = tr / 3.0;
  const T d[4] = {s[0] + p_old + 2.0 * G * (deps[0] - e_mean),
                  s[1] + p_old + 2.0 * G * (deps[1] - e_mean),
                  s[2] + p_old + 2.0 * G * (deps_zz - e_mean), s[3] + 2.0 * G * deps[2]};
  const T q = sqrt_(1.5 * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2] + 2.0 * d[3] * d[3]));
  // The strength's lower bound (hjc_strength without B P*^N and the rate factor).
  const T p_star = p / h.fc, intact = 1.0 - damage;
  const T tension_star = t / h.fc * intact;
  const T cohesion = h.a * intact;
  const T tensile = tension_star > 0.0 ? cohesion * max_(1.0 + p_star / tension_star, zero) : zero;
  const T strength_low = h.fc * min_(p_star >= 0.0 ? cohesion : tensile, splat<T>(h.s_max));
  const auto dense = mu_max > h.mu_lock && mu >= h.mu_lock;
  const auto taken =
      (q <= strength_low) && !dense && (!(mu_max > state[2]) || mu_max <= h.mu_crush);
  for (int k = 0; k < 3; ++k) s_new[k] = d[k] - p;
  s_new[3] = d[3];
  wave_speed = sqrt_(k_unload / m.density + 4.0 / 3.0 * G / m.density);  // as hjc_wave_speed
  const bool bound_holds = h.b >= 0.0 && h.c >= 0.0 && h.ef_min > 0.0;
  const auto taken_lanes = bound_holds ? taken : !all_lanes<T>();
  factor_free = taken_lanes && p_envelope >= -tension_limit;
  return taken_lanes;
}
// The same without factor_free.
template <class T>
KOKKOS_FORCEINLINE_FUNCTION auto hjc_elastic_update(const MaterialLaw& m, const T deps[3],
                                                    const T& deps_zz, const T s[4],
                                                    const T state[3], const T& tension_factor,
                                                    T s_new[4], T& mu, T& mu_max, T& wave_speed) {
  auto factor_free = !all_lanes<T>();
  return hjc_elastic_update(m, deps, deps_zz, s, state, tension_factor, s_new, mu, mu_max,
                            wave_speed, factor_free);
}

// P-wave speed (m/s) of a point of a law with a state: hjc_wave_speed, or the law's own.
KOKKOS_INLINE_FUNCTION double law_wave_speed(const MaterialLaw& m, const double state[3]) {
  return m.model == kHjc ? hjc_wave_speed(m, state) : m.p_wave_speed;
}

// Fills the cached derived values of a law (host, once, after its parameters are set).
inline void cache_derived(MaterialLaw& m) {
  m.cone_cached = 0;
  m.p_wave_speed = m.wave_speed();
  double alpha = 0.0, k = 0.0;
  detail::drucker_prager_constants(m, alpha, k);
  m.cone_alpha = alpha;
  m.cone_k = k;
  m.tension_cap = detail::effective_tension_cap(m, alpha, k);
  m.cone_cached = 1;
}

// Whether update_stress may return anything but the elastic trial s_trial = s + C : deps, from
// the trial and epeq alone. It errs only towards true (each test has a relative margin of 1e-9
// beyond its scalar counterpart, and a NaN gives true), so a kernel may take the trial for every
// point where it is false and run update_stress only where it is true. T: double (gives bool)
// or one point per lane (gives a lane mask, simd.hpp), so no branch on the data.
//   bilinear_j2: trial von Mises stress q > R = yield + H epeq (3 J2 = q^2 in plane strain; in
//     plane stress, with s_zz = 0, 3 J2 is the q2 of j2_plane_stress_return);
//   mohr_coulomb, plane strain: trial outside the cone (sqrt J2 > k - alpha I1) or a principal
//     stress above the cap; plane stress (an eps_zz iteration) and uncached laws: always true;
//   hjc, johnson_cook: always true (update_stress_with_state).
template <class T>
KOKKOS_INLINE_FUNCTION auto may_leave_elastic(const MaterialLaw& m, const T s_trial[4],
                                              const T& epeq) {
  constexpr double margin = 1.0 - 1e-9;
  if (m.model == kElastic) return !all_lanes<T>();
  // hjc: its pressure is not the elastic trial's; johnson_cook: its flow stress depends on the
  // strain rate and temperature, which the trial does not see.
  if (m.model == kHjc || m.model == kJohnsonCook) return all_lanes<T>();
  if (m.model == kMohrCoulomb && (!m.cone_cached || !m.plane_strain)) return all_lanes<T>();
  const T p = (s_trial[0] + s_trial[1] + s_trial[2]) / 3.0;
  const T d0 = s_trial[0] - p, d1 = s_trial[1] - p, d2 = s_trial[2] - p;
  const T j2 = 0.5 * (d0 * d0 + d1 * d1 + d2 * d2) + s_trial[3] * s_trial[3];
  if (m.model == kBilinearJ2) {
    const T R = m.yield_stress + m.plastic_modulus * epeq;
    return R <= 0.0 || !(3.0 * j2 <= R * R * margin);
  }
  // mohr_coulomb, plane strain, cached.
  const T r = m.cone_k - m.cone_alpha * 3.0 * p;
  const auto cone = r <= 0.0 || !(j2 <= r * r * margin);
  const double cap = m.tension_cap;
  if (!(cap >= 0.0)) return cone;
  const T centre = 0.5 * (s_trial[0] + s_trial[1]), h = 0.5 * (s_trial[0] - s_trial[1]);
  const T rad2 = h * h + s_trial[3] * s_trial[3], room = cap - centre;
  return cone || room <= 0.0 || !(rad2 <= room * room * margin) || !(s_trial[2] <= cap * margin);
}

// Updates the stress of one material point for the strain increment deps, accumulating the
// equivalent plastic strain epeq = sqrt(2/3 dep_ij dep_ij) summed over increments (paper Eq. 13).
// Returns the plastic dissipation density of the increment (J/m^3, >= 0): the backward-Euler
// plastic work s_new : dep (for mohr_coulomb, summed over the cone and cut-off sub-steps).
// deps_zz: the out-of-plane (axisymmetric: hoop) increment, 0 in plane strain; plane stress
// finds its own. Dispatch by switch, no virtual calls (docs/physics.md 1.1).
KOKKOS_INLINE_FUNCTION double update_stress(const MaterialLaw& m, const double deps[3], double s[4],
                                            double& epeq, double deps_zz = 0.0) {
  switch (m.model) {
    case kBilinearJ2:
      return detail::bilinear_j2_update(m, deps, deps_zz, s, epeq);
    case kMohrCoulomb:
      return detail::mohr_coulomb_update(m, deps, deps_zz, s, epeq);
    default:
      if (m.plane_strain)
        elastic_increment_3d(m, deps, deps_zz, s);
      else
        elastic_increment(m, deps, s);
      return 0.0;
  }
}

// update_stress for laws with a state beyond the stress and epeq (kLawStateSize values per
// point, Elements::law_state) and a strain-rate term: hjc, johnson_cook; the others ignore both.
// strain_rate: the point's equivalent strain rate sqrt(2/3 d':d') (1/s).
// deps_zz as for update_stress.
KOKKOS_INLINE_FUNCTION double update_stress_with_state(const MaterialLaw& m, const double deps[3],
                                                       double s[4], double& epeq, double state[3],
                                                       double strain_rate, double deps_zz = 0.0) {
  if (m.model == kHjc) return detail::hjc_update(m, deps, deps_zz, s, epeq, state, strain_rate);
  if (m.model == kJohnsonCook)
    return m.plane_strain ? detail::jc_update(m, deps, deps_zz, s, epeq, state, strain_rate)
                          : detail::jc_plane_stress(m, deps, s, epeq, state, strain_rate);
  return update_stress(m, deps, s, epeq, deps_zz);
}

}  // namespace fracta
