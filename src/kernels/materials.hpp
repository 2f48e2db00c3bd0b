// Pointwise material laws (DESIGN.md 1.1): device functions on one material point, no virtual
// calls. Loops that apply them live in fe_forces.hpp.
//
// Conventions: stress in Pa, tension positive, s[0]=xx, s[1]=yy, s[2]=zz, s[3]=xy.
// Strain increments are tensor components (deps[2] = d eps_xy, not the engineering shear).
// Plane strain: eps_zz = 0 and s[2] evolves. Plane stress: s[2] = 0 always and eps_zz is
// whatever keeps it so.
#pragma once
#include "kernels/compat.hpp"

namespace fracta {

enum MaterialModelId : int { kElastic = 0, kBilinearJ2 = 1, kMohrCoulomb = 2 };

// Plain data copied by value into kernels (one per material).
struct MaterialLaw {
  int model = kElastic;
  int plane_strain = 1;       // 1 plane strain, 0 plane stress
  double density = 0;         // kg/m^3
  double youngs_modulus = 0;  // Pa
  double poisson_ratio = 0;
  double shear_modulus = 0;   // G = E / (2 (1 + nu))
  double lame_lambda = 0;     // 3D lambda = E nu / ((1 + nu)(1 - 2 nu))
  double yield_stress = 0;    // bilinear_j2, Pa
  double plastic_modulus = 0; // bilinear_j2 hardening H = d sigma_y / d epeq, Pa
  double cohesion = 0;        // mohr_coulomb, Pa
  double friction_angle = 0;  // mohr_coulomb, rad
  double tensile_strength = 0;  // Rankine cut-off, Pa (0 = no cut-off)
  double conversion_strain = 0;

  // P-wave modulus of the formulation: plane strain lambda + 2G, plane stress E / (1 - nu^2).
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

// Elastic trial: s += C : deps for the formulation.
KOKKOS_INLINE_FUNCTION void elastic_increment(const MaterialLaw& m, const double deps[3],
                                              double s[4]) {
  const double G = m.shear_modulus;
  if (m.plane_strain) {
    const double lam = m.lame_lambda;
    const double tr = deps[0] + deps[1];
    s[0] += lam * tr + 2.0 * G * deps[0];
    s[1] += lam * tr + 2.0 * G * deps[1];
    s[2] += lam * tr;
  } else {
    const double c = m.youngs_modulus / (1.0 - m.poisson_ratio * m.poisson_ratio);
    s[0] += c * (deps[0] + m.poisson_ratio * deps[1]);
    s[1] += c * (deps[1] + m.poisson_ratio * deps[0]);
    s[2] = 0.0;
  }
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

// Updates the stress of one material point for the strain increment deps, accumulating the
// equivalent plastic strain epeq = sqrt(2/3 dep_ij dep_ij) summed over increments (paper Eq. 13).
// Returns the plastic dissipation density of the increment (J/m^3, >= 0).
KOKKOS_INLINE_FUNCTION double update_stress(const MaterialLaw& m, const double deps[3],
                                            double s[4], double& epeq) {
  elastic_increment(m, deps, s);
  (void)epeq;
  return 0.0;  // plastic models: see bilinear_j2_return / mohr_coulomb_return (to be added)
}

}  // namespace fracta
