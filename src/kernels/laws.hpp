// Pointwise laws of the bonded disc lattice and of contact (docs/physics.md 1.2): small copyable
// structs, captured by value by the loops that apply them (bond_forces.hpp, contact_forces.hpp,
// energy.hpp). Their members act on the values of one bond or pair and touch no view. Each is a
// template on the number type T: double (one bond: GPUs, and the bonds a CPU batch leaves), or
// Double8 (eight bonds, one per lane: simd.hpp), so the CPU batches and the bond-by-bond path run
// the same arithmetic. Per-bond quantities are arguments of type T; per-material parameters are
// the structs' members (double). Lane-dependent choices are selects (c ? a : b); an `if` asks
// only whether any lane takes a branch (any_lane). Where products are summed, the two
// instantiations keep the same control flow around them, so the compiler contracts the same
// products into fused multiply-adds and they agree bit for bit (tests/kernels/test_laws.cpp).
#pragma once
#include "kernels/compat.hpp"
#include "kernels/simd.hpp"

namespace fracta {

// One-dimensional bond springs (docs/physics.md 1.2, "Bond laws"; paper Eq. 5 with elastic
// unloading). Elastic: the normal force from the natural length, fn = kn (L - L0 - u_p), and the
// shear force incrementally, fs <- fs + ks du_s. Bilinear elastoplastic (yield_stress > 0):
// yield force sigma_y S in the normal spring and sigma_y S / sqrt(3) in the shear spring (von
// Mises), linear isotropic hardening of stiffness H S / L0, with S the bond's effective area.
struct SpringLaw {
  double yield_stress = 0;  // Pa; 0 = elastic springs
  double hardening = 0;     // H (Pa per unit bond plastic strain)

  KOKKOS_INLINE_FUNCTION bool plastic() const { return yield_stress > 0.0; }

  // Elastic normal force of a spring of stiffness k, length `length` and natural length
  // `natural_length` (L0 + u_p: Bonds::rest_length).
  template <class T>
  KOKKOS_INLINE_FUNCTION static T elastic_force(const T& k, const T& length,
                                                const T& natural_length) {
    return k * (length - natural_length);
  }

  // Elastic shear force after a tangential displacement increment du: f + k du (k (u - u_p)
  // without the round trip through the total displacement).
  template <class T>
  KOKKOS_INLINE_FUNCTION static T elastic_increment(const T& k, const T& force, const T& du) {
    return force + k * du;
  }

  // Yield forces and hardening stiffness in force units of a bond of area S and length L0.
  template <class T>
  KOKKOS_INLINE_FUNCTION T normal_yield_force(const T& area) const {
    return yield_stress * area;
  }
  template <class T>
  KOKKOS_INLINE_FUNCTION T shear_yield_force(const T& area) const {
    return yield_stress * area / 1.7320508075688772;  // von Mises: sigma_y / sqrt(3)
  }
  template <class T>
  KOKKOS_INLINE_FUNCTION T hardening_stiffness(const T& area, const T& length0) const {
    return hardening * area / length0;
  }

  // Bilinear spring of stiffness k at total displacement u: force = k (u - u_p) with
  // |force| <= f_yield + k_hard alpha, by a one-dimensional return mapping (backward Euler,
  // Simo & Hughes 1998, Ch. 1): dgamma = (|f_trial| - f_yield - k_hard alpha) / (k + k_hard),
  // u_p += sign(f_trial) dgamma, alpha += dgamma. Sets force, updates u_plastic and alpha, and
  // returns the plastic work of the step |force| dgamma. f_yield <= 0: elastic.
  template <class T>
  KOKKOS_INLINE_FUNCTION static T bilinear(const T& k, const T& u, const T& f_yield,
                                           const T& k_hard, T& u_plastic, T& alpha, T& force) {
    force = k * (u - u_plastic);
    const auto may_yield = f_yield > 0.0;
    if (!any_lane(may_yield)) return splat<T>(0.0);
    const T limit = f_yield + k_hard * alpha;
    const T excess = fabs_(force) - limit;
    const auto yields = may_yield && excess > 0.0;
    if (!any_lane(yields)) return splat<T>(0.0);
    const T dgamma = yields ? excess / (k + k_hard) : splat<T>(0.0);
    const T sign = force > 0.0 ? splat<T>(1.0) : splat<T>(-1.0);
    u_plastic += sign * dgamma;
    alpha += dgamma;
    force -= sign * k * dgamma;
    return fabs_(force) * dgamma;
  }
};

// Face failure: Mohr-Coulomb with a tension cut-off on the face a bond stands for
// (docs/physics.md 1.2, "Face failure"; paper Sec. 2.3 with Eq. 6 corrected). With the normal
// traction sigma_n (tension positive) and the shear traction tau >= 0 on the face, the bond
// reaches its strength when
//   sigma_n >= sigma_t  (tensile_strength > 0)   or   tau >= c - sigma_n tan(phi)  (cohesion > 0).
// below_on_every_face is the same criterion over every face of a stress at once, which the cell
// stress uses to let bonds skip the check.
struct FaceStrength {
  double tensile_strength = 0;  // sigma_t (Pa); 0 = no tensile failure
  double cohesion = 0;          // c (Pa); 0 = no shear failure
  double tan_friction = 0;      // tan(phi)

  // Traction on the face of unit normal n of the stress (sxx, syy, sxy): sigma_n = n.s.n and
  // tau = |t.s.n| with t = n turned by +90 degrees.
  template <class T>
  KOKKOS_INLINE_FUNCTION static void traction(const T& sxx, const T& syy, const T& sxy, const T& nx,
                                              const T& ny, T& sigma_n, T& tau) {
    sigma_n = sxx * nx * nx + syy * ny * ny + 2.0 * sxy * nx * ny;
    tau = fabs_(-(sxx * nx + sxy * ny) * ny + (sxy * nx + syy * ny) * nx);
  }

  // Normal traction at a bond next to a crack (docs/physics.md 1.2, "Face failure"): the mean of
  // the intact cells stands for the stress half a cell away, where a crack tip's stress has
  // dropped steeply, so the normal strain across the face is taken from the bond itself
  // (bond_stress = fn / S = E eps_bond, at the face) and the in-face strain from the cells:
  //   sigma_n' = C11 eps_bond + C12 eps_tt = sigma_n + (bond_stress - (sigma_n - nu sigma_tt)) / (1
  //   - nu^2)
  // with the cells' normal and in-face tractions sigma_n, sigma_tt (E, nu: the lattice's
  // in-plane constants, E*, nu* in plane strain). Equal to sigma_n under uniform strain.
  template <class T>
  KOKKOS_INLINE_FUNCTION static T local_normal(const T& sigma_n, const T& sigma_tt,
                                               const T& bond_stress, double nu) {
    return sigma_n + (bond_stress - (sigma_n - nu * sigma_tt)) / (1.0 - nu * nu);
  }

  // Whether the traction (sigma_n, tau) reaches the strength (true or a lane mask).
  template <class T>
  KOKKOS_INLINE_FUNCTION auto reaches(const T& sigma_n, const T& tau) const {
    auto r = !all_lanes<T>();
    if (tensile_strength > 0.0) r = r || sigma_n >= tensile_strength;
    if (cohesion > 0.0) r = r || tau >= cohesion - sigma_n * tan_friction;
    return r;
  }

  // The same for a bond of strength factor `scale` (kernels/heterogeneity.hpp): sigma_t and c
  // scaled, the friction not.
  template <class T>
  KOKKOS_INLINE_FUNCTION auto reaches(const T& sigma_n, const T& tau, const T& scale) const {
    auto r = !all_lanes<T>();
    if (tensile_strength > 0.0) r = r || sigma_n >= tensile_strength * scale;
    if (cohesion > 0.0) r = r || tau >= cohesion * scale - sigma_n * tan_friction;
    return r;
  }

  // How far the traction (sigma_n, tau) has passed the strength of factor `scale`: the largest
  // ratio of demand to strength over the criteria, sigma_n / (sigma_t scale) and
  // (tau + sigma_n tan(phi)) / (c scale), at least 1. A stress that grows in proportion along a
  // step reached the strength at 1 / ratio of it (CohesiveSoftening::final_separation).
  KOKKOS_INLINE_FUNCTION double excess(const double sigma_n, const double tau,
                                       const double scale) const {
    double ratio = 1.0;
    if (tensile_strength > 0.0) ratio = fmax(ratio, sigma_n / (tensile_strength * scale));
    if (cohesion > 0.0) ratio = fmax(ratio, (tau + sigma_n * tan_friction) / (cohesion * scale));
    return ratio;
  }

  // Whether a stress of Mohr circle (centre C, radius R) is below the strength on every face,
  // by a margin. Over the faces, sigma_n <= C + R, and tau + sigma_n tan(phi) is largest where the
  // line of slope -tan(phi) touches the circle: C tan(phi) + R sqrt(1 + tan(phi)^2). Both bounds
  // are convex in the stress, so they hold for the mean of two cells too. A margin of 1e-9 of the
  // terms' size keeps rounding out of the decision: reaches() then cannot hold on any face.
  template <class T>
  KOKKOS_INLINE_FUNCTION auto below_on_every_face(const T& centre, const T& radius) const {
    constexpr double margin = 1e-9;
    auto below = all_lanes<T>();
    if (tensile_strength > 0.0)
      below =
          centre + radius + margin * (fabs_(centre) + radius + tensile_strength) < tensile_strength;
    if (cohesion > 0.0) {
      const double secant = sqrt_(1.0 + tan_friction * tan_friction);
      const T shear = centre * tan_friction + radius * secant;
      below =
          below &&
          shear + margin * (fabs_(centre * tan_friction) + radius * secant + cohesion) < cohesion;
    }
    return below;
  }
};

// Cohesive softening of a bond that reached its strength (docs/physics.md 1.2, "Cohesive
// softening"): the bilinear cohesive law in the effective separation
// lambda = |(<u_n>, u_s)|, u = f / k of the undamaged springs (compression opens no crack),
// softening linearly from the onset lambda_0 to lambda_f with irreversible secant damage
//   D = lambda_f (lambda - lambda_0) / (lambda (lambda_f - lambda_0)),
// the applied forces (1 - D) fn in tension (compression undamaged) and (1 - D) fs. Along a
// proportional path the law dissipates E_0 lambda_f / lambda_0 (E_0: what the bond stores at the
// onset), so lambda_f = G_f A_b lambda_0 / E_0 makes it dissipate G_f A_b, with A_b the bond's
// share of the crack area, kn L0 crack_area_factor[kind] (BondLaw).
struct CohesiveSoftening {
  double fracture_energy = 0;            // G_f (J/m^2); 0 = brittle
  double crack_area_factor[2] = {0, 0};  // per BondKind (m^2 per (N/m) per m)

  KOKKOS_INLINE_FUNCTION bool cohesive() const { return fracture_energy > 0.0; }

  // lambda of undamaged forces fn, fs.
  template <class T>
  KOKKOS_INLINE_FUNCTION static T effective_separation(const T& fn, const T& fs, const T& kn,
                                                       const T& ks) {
    // Each square under its select, so that neither instantiation fuses a square and the sum
    // into a multiply-add (one bond's selects are branches, which keep the squares apart).
    const T un = fn / kn, us = fs / ks;
    const T un2 = fn > 0.0 && kn > 0.0 ? un * un : splat<T>(0.0);
    const T us2 = ks > 0.0 ? us * us : splat<T>(0.0);
    return sqrt_(un2 + us2);
  }

  // Energy a bond stores with applied forces fn, fs at damage D (J): the secant springs
  // (1 - D) k carry the tension and the shear; compression is carried undamaged.
  template <class T>
  KOKKOS_INLINE_FUNCTION static T stored_energy(const T& fn, const T& fs, const T& damage,
                                                const T& kn, const T& ks) {
    T e = splat<T>(0.0);
    e += kn > 0.0 ? 0.5 * fn * fn / (fn > 0.0 ? (1.0 - damage) * kn : kn) : splat<T>(0.0);
    e += ks > 0.0 && damage < 1.0 ? 0.5 * fs * fs / ((1.0 - damage) * ks) : splat<T>(0.0);
    return e;
  }

  // Trapezoidal work of the discs on a bond over a step (J): normal forces fn_old -> fn_new over
  // the change of the elastic elongation, from fn_old (at damage D_old) to the undamaged force
  // fn_trial of this step; shear forces fs_old -> fs_new over the shear increment du_s. Elastic
  // springs only: cohesive materials are elastic up to their strength.
  template <class T>
  KOKKOS_INLINE_FUNCTION static T work(const T& fn_old, const T& fn_new, const T& fs_old,
                                       const T& fs_new, const T& fn_trial, const T& damage_old,
                                       const T& kn, const T& shear_increment) {
    T w = 0.5 * (fs_old + fs_new) * shear_increment;
    // The normal term under a branch for any lane, as one bond has it: then both instantiations
    // fuse this product, not the shear one, into a multiply-add.
    if (any_lane(kn > 0.0)) {
      const T u_old = fn_old / (fn_old > 0.0 ? (1.0 - damage_old) * kn : kn);
      w += 0.5 * (fn_old + fn_new) * (kn > 0.0 ? fn_trial / kn - u_old : splat<T>(0.0));
    }
    return w;
  }

  // The shear force of the undamaged spring from the applied one.
  template <class T>
  KOKKOS_INLINE_FUNCTION static T undamaged(const T& applied, const T& damage) {
    return damage > 0.0 ? applied / (1.0 - damage) : applied;
  }

  // At the step a bond reaches its strength, with undamaged forces fn, fs that have passed it by
  // the factor `excess` (>= 1, FaceStrength::excess): lambda_0 (onset) and lambda_f (returned),
  // for a bond of stiffnesses kn, ks, length L0 and crack area factor `area_factor` (of its
  // kind). The onset is where the bond met its strength along the step, lambda / excess, holding
  // E_0 = stored / excess^2, not where the step ended: a step that carries a bond past its
  // strength would otherwise raise its peak by up to the step's stress increment, and bonds whose
  // strengths differ by less than that increment would soften alike (a strength scatter finer
  // than a step is lost). The bond softens where onset > 0 and lambda_f > onset; elsewhere it
  // breaks as a brittle one.
  template <class T>
  KOKKOS_INLINE_FUNCTION T final_separation(const T& fn, const T& fs, const T& kn, const T& ks,
                                            const T& length0, const T& area_factor, const T& excess,
                                            T& onset) const {
    onset = effective_separation(fn, fs, kn, ks) / excess;
    const T stored =
        stored_energy(fn > 0.0 ? fn : splat<T>(0.0), fs, splat<T>(0.0), kn, ks) / (excess * excess);
    const T share = fracture_energy * kn * length0 * area_factor;  // G_f A_b
    return stored > 0.0 ? share * onset / stored : splat<T>(0.0);
  }

  // Damage at separation lambda (below lambda_f) from D_old: never decreasing.
  template <class T>
  KOKKOS_INLINE_FUNCTION static T damage(const T& lambda, const T& onset, const T& lambda_f,
                                         const T& damage_old) {
    return lambda > onset
               ? max_(damage_old, lambda_f * (lambda - onset) / (lambda * (lambda_f - onset)))
               : damage_old;
  }

  // The forces a bond at damage D applies: (1 - D) fn in tension (fn in compression), (1 - D) fs.
  template <class T>
  KOKKOS_INLINE_FUNCTION static void applied(const T& fn, const T& fs, const T& damage,
                                             T& fn_applied, T& fs_applied) {
    fn_applied = fn > 0.0 ? (1.0 - damage) * fn : fn;
    fs_applied = (1.0 - damage) * fs;
  }

  // Energy a bond releases when it breaks at undamaged forces fn, fs (J): what it held plus what
  // the discs did on it this step by the trapezoidal rule with the zero force it now applies.
  // Brittle (undamaged) springs: 1/2 f_old^2 / k + 1/2 f_old (f - f_old) / k = 1/2 f_old f / k
  // each (counting the trial energy 1/2 f^2 / k would over-count by 1/2 f du).
  template <class T>
  KOKKOS_INLINE_FUNCTION T released_energy(const T& fn_old, const T& fs_old, const T& fn,
                                           const T& fs, const T& damage_old, const T& kn,
                                           const T& ks, const T& shear_increment) const {
    if (cohesive()) {
      const T zero = splat<T>(0.0);
      return stored_energy(fn_old, fs_old, damage_old, kn, ks) +
             work(fn_old, zero, fs_old, zero, fn, damage_old, kn, shear_increment);
    }
    return (kn > 0.0 ? 0.5 * fn_old * fn / kn : splat<T>(0.0)) +
           (ks > 0.0 ? 0.5 * fs_old * fs / ks : splat<T>(0.0));
  }
};

// Cells a cohesive process zone (length E* G_f / sigma_t^2) must span for crack growth to follow
// G_f (docs/physics.md 1.2, "Resolving the process zone"): with fewer, the bond tensile strength
// is capped so that it spans this many (build_lattice).
constexpr double kCohesiveZoneCells = 4.0;

// Per-material bond parameters (plain data, copied into the kernels by value), and the laws they
// make. The crack area a cohesive bond stands for (CohesiveSoftening), A_b = kn L0
// crack_area_factor[kind]: kn L0 / E for an edge bond and kn L0 (1 - nu) / (2 sqrt(2) E) for a
// diagonal (plane-strain E*, nu*). These are the shares of the face h t a straight crack along a
// lattice line cuts, in proportion to the energy each bond holds under uniaxial tension normal to
// that face (per row: one edge bond, k1, 1 / (1 + nu); two diagonals, k2, nu / (2 (1 + nu))
// each), so such a crack dissipates G_f per unit area exactly (tested). kn is the bond's own
// stiffness, so a boundary edge with one cell carries half.
// Rate dependence of the bond strength and fracture energy (docs/physics.md 1.2, "Rate
// dependence"): dynamic increase factors tabulated against the strain rate, as LS-DYNA's
// strain-rate curves and the CEB-FIP Model Code's tensile DIF (scripts/dif_table.py tabulates
// that form): piecewise linear in log10 of the rate, held at the end values beyond the table.
// The rate is the magnitude of the bond's normal strain rate, |(v_j - v_i) . n| / L0, when it
// reaches its strength. Factors are >= 1 (case.cpp), so the strength bounds of the cell stress
// and of the batches, which leave the factor out, stay on the safe side.
struct RateLaw {
  static constexpr int kMaxEntries = 16;
  int count = 0;  // 0 = rate independent
  double log10_rate[kMaxEntries] = {};
  double strength[kMaxEntries] = {};
  double fracture_energy[kMaxEntries] = {};

  KOKKOS_INLINE_FUNCTION bool active() const { return count > 0; }

  // The factor of `column` (strength or fracture_energy) at strain rate `rate` (1/s): column[0]
  // at or below the first rate (and for a rate that is not positive), the last entry at or above
  // the last, linear in log10(rate) between. T: double, or one rate per lane (simd.hpp): the
  // segment is found by a select per entry, so the lanes need no branch, and a double gets the
  // walk's own arithmetic.
  template <class T>
  KOKKOS_INLINE_FUNCTION T factor(const double (&column)[kMaxEntries], const T& rate) const {
    if (count < 2) return splat<T>(column[0]);
    const T x = log10_(rate);
    T x0 = splat<T>(log10_rate[0]), x1 = splat<T>(log10_rate[1]);
    T c0 = splat<T>(column[0]), c1 = splat<T>(column[1]);
    for (int k = 2; k < count; ++k) {
      const auto beyond = x >= log10_rate[k - 1];
      x0 = beyond ? splat<T>(log10_rate[k - 1]) : x0;
      x1 = beyond ? splat<T>(log10_rate[k]) : x1;
      c0 = beyond ? splat<T>(column[k - 1]) : c0;
      c1 = beyond ? splat<T>(column[k]) : c1;
    }
    const T t = (x - x0) / (x1 - x0);
    T f = c0 + t * (c1 - c0);
    f = x >= log10_rate[count - 1] ? splat<T>(column[count - 1]) : f;
    return !(rate > 0.0) || x <= log10_rate[0] ? splat<T>(column[0]) : f;
  }
  template <class T>
  KOKKOS_INLINE_FUNCTION T strength_factor(const T& rate) const {
    return factor(strength, rate);
  }
  template <class T>
  KOKKOS_INLINE_FUNCTION T fracture_energy_factor(const T& rate) const {
    return factor(fracture_energy, rate);
  }
};

struct BondLaw {
  double youngs_modulus_eff = 0;  // E in plane stress, E / (1 - nu^2) in plane strain (Pa)
  double yield_stress = 0;        // bilinear springs (Pa); 0 = elastic bonds
  double hardening = 0;           // H of the bilinear law (Pa per unit bond plastic strain)
  double tensile_strength = 0;    // Pa; 0 = no tensile failure
  double cohesion = 0;            // Pa; 0 = no shear failure
  double tan_friction = 0;        // tan(phi)
  double fracture_energy = 0;     // G_f (J/m^2); 0 = brittle (the bond breaks at its strength)
  double crack_area_factor[2] = {0, 0};  // per BondKind (m^2 per (N/m) per m)
  double poisson_ratio_eff = 0;  // nu in plane stress, nu / (1 - nu) in plane strain (local_normal)
  RateLaw rate;                  // dynamic increase factors; count 0 = rate independent

  KOKKOS_INLINE_FUNCTION SpringLaw springs() const { return {yield_stress, hardening}; }
  KOKKOS_INLINE_FUNCTION FaceStrength face() const {
    return {tensile_strength, cohesion, tan_friction};
  }
  KOKKOS_INLINE_FUNCTION CohesiveSoftening softening() const {
    return {fracture_energy, {crack_area_factor[0], crack_area_factor[1]}};
  }
};

// Hoop response of a cell of an axisymmetric lattice (docs/physics.md 1.2, "Axisymmetric discs").
// The discs are rings and the pair springs carry the in-plane law of plane stress (sigma_tt = 0);
// each intact cell adds
//
//   W = V (1 - d [w > 0]) M w^2 / 2,   w = E_tt + (lambda / M) tr(E_in) = sigma_tt / M,
//
// (V = 2 pi r0 A0 its volume of revolution, E_tt = ((r / r0)^2 - 1) / 2 its Green-Lagrange hoop
// strain, r the mean radius of its discs), which completes plane stress to the 3D isotropic law
// exactly: W_plane_stress(E_in) + M w^2 / 2 = W_3D(E_in, E_tt), since plane stress is the 3D law
// with sigma_tt eliminated. Radial cracks (planes through the axis) cannot be resolved in the
// meridian plane, so they are smeared: the hoop stress sigma_tt = M w (1 - d) softens linearly
// once it reaches the tensile strength, over a crack band of the cell's size l (Bazant & Oh 1983,
// Mater. Struct. 16; the band of LS-DYNA's and Abaqus's smeared-crack concrete in axisymmetric
// elements), with d the secant damage of the largest w reached, so that a cell stretched along
// the hoop direction dissipates G_f V / l. Compression (w < 0) is undamaged: a closed radial crack
// carries hoop compression. A fully damaged cell keeps the plane-stress lattice: hoop-free rubble.
// Its members touch no view; per-cell values are arguments.
struct HoopLaw {
  double p_wave_modulus = 0;    // M = lambda + 2 mu of the 3D law (Pa); 0: a plane lattice
  double lambda = 0;            // Lame's first constant of the 3D law (Pa)
  double tensile_strength = 0;  // Pa; 0 = no hoop failure
  double fracture_energy = 0;   // G_f (J/m^2); 0 = brittle (d jumps to 1 at the strength)

  KOKKOS_INLINE_FUNCTION bool active() const { return p_wave_modulus > 0.0; }

  // Damage after the largest hoop strain `largest` (of w) in a band of length `band` (m): 0 up to
  // the onset w0 = sigma_t / M, then d = w_f (w - w0) / (w (w_f - w0)) to 1 at
  // w_f = 2 G_f / (sigma_t band) (linear softening of sigma_tt from sigma_t to 0). A band too
  // long for G_f (w_f <= w0: the softening would snap back) fails at once.
  KOKKOS_INLINE_FUNCTION double damage(const double largest, const double band) const {
    if (!(tensile_strength > 0.0)) return 0.0;
    const double onset = tensile_strength / p_wave_modulus;
    if (largest <= onset) return 0.0;
    const double final_w = 2.0 * fracture_energy / (tensile_strength * band);
    if (final_w <= onset || largest >= final_w) return 1.0;
    return final_w * (largest - onset) / (largest * (final_w - onset));
  }
  // The Green-Lagrange hoop strain E_tt = ((r / r0)^2 - 1) / 2 of a ring of radius r, r0 at rest.
  KOKKOS_INLINE_FUNCTION static double green_strain(const double r, const double r0) {
    return 0.5 * ((r / r0) * (r / r0) - 1.0);
  }
  // w = E_tt - offset + (lambda / M) tr(E_in) of a cell whose discs' mean radius is r (r0 at
  // rest), with its hoop offset and in-plane trace (both less their offsets at conversion).
  KOKKOS_INLINE_FUNCTION double strain(const double r, const double r0, const double offset,
                                       const double in_plane_trace) const {
    return green_strain(r, r0) - offset + lambda / p_wave_modulus * in_plane_trace;
  }
  // The hoop stress sigma_tt (Pa) at w with damage d.
  KOKKOS_INLINE_FUNCTION double stress(const double w, const double d) const {
    return p_wave_modulus * w * (w > 0.0 ? 1.0 - d : 1.0);
  }
};

// Disc-disc contact (docs/physics.md 1.2, "Contact"): a spring-dashpot in compression with
// regularised Coulomb friction. For a pair of overlap delta, closing rate delta_dot and
// tangential slip rate vt at the contact point:
//   fn = max(0, k delta + c delta_dot),  k = 2 k_i k_j / (k_i + k_j),  c = 2 zeta sqrt(k m_eff),
//   fs = mu fn vt / max(|vt|, v_reg),    v_reg = max(v_reg_min, mu fn dt / m_t),
// with m_eff = 1 / (1/m_i + 1/m_j) and 1/m_t = 1/m_i + 1/m_j + a_i^2/I_i + a_j^2/I_j. The
// regularised branch is a viscous damper mu fn / v_reg, so static friction is not exact: a disc at
// rest on a slope creeps at a speed of order v_reg; v_reg is at least the slip one step of full
// friction removes, so friction does not chatter. Energy: elastic 1/2 k delta^2, and the
// dissipation of a step ((fn - k delta) delta_dot + fs vt) dt (damping, friction, and the spring
// energy lost while the force is clamped at zero), with the full-step rates (contact_forces.hpp
// says why).
struct ContactLaw {
  double damping_ratio = 0.1;  // zeta
  double friction = 0.3;       // mu
  double v_reg_min = 1e-6;     // m/s

  // Series stiffness of two contact springs k_i, k_j (0 if both are 0).
  template <class T>
  KOKKOS_INLINE_FUNCTION static T series_stiffness(const T& ki, const T& kj) {
    return ki + kj > 0.0 ? 2.0 * ki * kj / (ki + kj) : splat<T>(0.0);
  }

  // Normal force of stiffness k, inverse masses inv_m = 1/m_i + 1/m_j (> 0), overlap delta and
  // closing rate delta_dot: compression only, no adhesion.
  template <class T>
  KOKKOS_INLINE_FUNCTION T normal_force(const T& k, const T& inv_m, const T& delta,
                                        const T& delta_dot) const {
    const T m_eff = 1.0 / inv_m;
    const T c = 2.0 * damping_ratio * sqrt_(k * m_eff);
    return max_(splat<T>(0.0), k * delta + c * delta_dot);
  }

  // Friction force on disc i along t of normal force fn, slip rate vt and tangential inverse
  // mass inv_mt = 1 / m_t, over a step dt.
  template <class T>
  KOKKOS_INLINE_FUNCTION T friction_force(const T& fn, const T& vt, const T& inv_mt,
                                          double dt) const {
    const T v_reg = max_(splat<T>(v_reg_min), friction * fn * dt * inv_mt);
    return friction * fn * vt / max_(fabs_(vt), v_reg);
  }

  template <class T>
  KOKKOS_INLINE_FUNCTION static T elastic_energy(const T& k, const T& delta) {
    return 0.5 * k * delta * delta;
  }

  // Dissipation of a step (J) with the rates advanced by the half kick of the pair's own force
  // (delta_dot - dt/2 fn (1/m_i + 1/m_j), vt - dt/2 fs / m_t): the full-step rates of velocity
  // Verlet, to O(dt^2) for an isolated pair.
  template <class T>
  KOKKOS_INLINE_FUNCTION static T dissipation(const T& k, const T& delta, const T& delta_dot,
                                              const T& vt, const T& fn, const T& fs, const T& inv_m,
                                              const T& inv_mt, double dt) {
    const T delta_dot_full = delta_dot - 0.5 * dt * fn * inv_m;
    const T vt_full = vt - 0.5 * dt * fs * inv_mt;
    return ((fn - k * delta) * delta_dot_full + fs * vt_full) * dt;
  }
};

}  // namespace fracta
