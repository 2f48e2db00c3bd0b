// Constants of the laws with many of them (materials.hpp: Holmquist-Johnson-Cook concrete, model
// kHjc; Johnson-Cook metal, model kJohnsonCook): plain data, shared by the case file reader
// (host/case.hpp) and the kernels.
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

// Johnson-Cook plasticity (Johnson & Cook 1983, 7th Int. Symp. Ballistics) and fracture
// (Johnson & Cook 1985, Eng. Fract. Mech. 21): flow stress, failure strain, adiabatic heating
// (docs/physics.md 1.1, "johnson_cook"). Stresses in Pa, temperatures in K.
struct JohnsonCookParams {
  double a = 0, b = 0, n = 1;  // sigma_y = (A + B eps_p^n) [1 + C ln(eps_dot*)] (1 - T*^m)
  double c = 0, m = 1;
  double eps0 = 1.0;                              // reference strain rate (1/s)
  double t_room = 293.0;                          // K, T* = (T - t_room) / (t_melt - t_room)
  double t_melt = 0;                              // K
  double specific_heat = 0;                       // J/(kg K); 0: isothermal (no adiabatic heating)
  double taylor_quinney = 0.9;                    // share of the plastic work that heats
  double d1 = 0, d2 = 0, d3 = 0, d4 = 0, d5 = 0;  // failure strain; all 0: none
};

}  // namespace fracta
