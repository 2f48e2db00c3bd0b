// Constants of the Holmquist-Johnson-Cook concrete law (materials.hpp, model kHjc): plain data,
// shared by the case file reader (host/case.hpp) and the kernels.
#pragma once

namespace fracta {

// Holmquist-Johnson-Cook concrete (Holmquist, Johnson & Cook 1993, "A computational constitutive
// model for concrete subjected to large strains, high strain rates, and high pressures", 14th
// Int. Symp. Ballistics): normalised strength, damage and the three-part equation of state
// (docs/physics.md 1.1, "hjc"). Pressures and strengths in Pa, strains dimensionless.
struct HjcParams {
  double a = 0, b = 0, n = 1, c = 0;  // sigma* = [A (1 - D) + B P*^N] [1 + C ln(eps_dot*)]
  double fc = 0;                      // f'_c, quasi-static unconfined compressive strength
  double s_max = 0;                   // largest normalised strength sigma* (of f'_c)
  double t = 0;                       // T, largest hydrostatic tension of undamaged material
  double eps0 = 1.0;                  // reference strain rate (1/s)
  double d1 = 0, d2 = 1, ef_min = 0;  // plastic strain to fracture D1 (P* + T*)^D2 >= EF_min
  double p_crush = 0, mu_crush = 0;   // end of the elastic part of the EOS
  double p_lock = 0, mu_lock = 0;     // start of the fully dense part
  double k1 = 0, k2 = 0, k3 = 0;      // fully dense P(mu_bar)
};

}  // namespace fracta
