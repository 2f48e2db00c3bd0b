// Bond forces of the bonded disc lattice (DESIGN.md 1.2; paper Eqs. 5, 6 and 8-10 corrected).
// One kernel over the bond slots: active bonds compute their normal and shear spring forces,
// check Mohr-Coulomb failure with tension cut-off, and add what they apply to their two discs
// (kernels/scatter.hpp: no atomics on CPUs, and a fixed summation order).
#pragma once
#include "kernels/compat.hpp"
#include "kernels/conversion.hpp"
#include "kernels/simd.hpp"
#include "kernels/state.hpp"

namespace fracta {

// Per-material bond parameters (plain data, copied into the kernel by value).
struct BondLaw {
  double youngs_modulus_eff = 0;  // E in plane stress, E / (1 - nu^2) in plane strain (Pa)
  double yield_stress = 0;        // bilinear springs (Pa); 0 = elastic bonds
  double hardening = 0;           // H of the bilinear law (Pa per unit bond plastic strain)
  double tensile_strength = 0;    // Pa; 0 = no tensile failure
  double cohesion = 0;            // Pa; 0 = no shear failure
  double tan_friction = 0;        // tan(phi)
  // Cohesive softening: G_f (J/m^2); 0 = brittle (the bond breaks at its strength). A bond
  // that reached its strength then dissipates G_f times the crack area it stands for,
  // A_b = kn L0 crack_area_factor[kind] (m^2): kn L0 / E for an edge bond and
  // kn L0 (1 - nu) / (2 sqrt(2) E) for a diagonal (plane-strain E*, nu*). These are the shares
  // of the face h t a straight crack along a lattice line cuts, in proportion to the energy
  // each bond holds under uniaxial tension normal to that face (per row: one edge bond, k1,
  // 1 / (1 + nu); two diagonals, k2, nu / (2 (1 + nu)) each), so such a crack dissipates G_f
  // per unit area exactly (tested). kn is the bond's own stiffness, so a boundary edge with
  // one cell carries half.
  double fracture_energy = 0;
  double crack_area_factor[2] = {0, 0};  // per BondKind (m^2 per (N/m) per m)
};

struct BondStepResult {
  double fracture_energy = 0;  // elastic energy of the bonds that broke this step (J)
  double plastic_work = 0;     // plastic work of the bonds this step (J)
  long broken = 0;             // bonds broken this step
};

// One-dimensional elastoplastic spring with linear isotropic hardening (paper Eq. 5 with
// elastic unloading): force = k (u - u_p), |force| <= f_y + k_h * alpha. Returns the plastic work.
KOKKOS_INLINE_FUNCTION double bilinear_spring(double k, double u, double f_yield, double k_hard,
                                              double& u_plastic, double& alpha, double& force) {
  force = k * (u - u_plastic);
  if (f_yield <= 0.0) return 0.0;
  const double limit = f_yield + k_hard * alpha;
  const double excess = fabs_(force) - limit;
  if (excess <= 0.0) return 0.0;
  const double dgamma = excess / (k + k_hard);
  const double sign = force > 0.0 ? 1.0 : -1.0;
  u_plastic += sign * dgamma;
  alpha += dgamma;
  force -= sign * k * dgamma;
  return fabs_(force) * dgamma;  // the dissipation of the return (backward Euler)
}

// Continuum stress of each converted cell from its 4 discs: deformation gradient F at the cell
// centre (reference one-point gradients), Green-Lagrange strain E = (F^T F - I)/2 (rotation
// invariant, so fragments may spin) less the cell's offset at conversion (its strain beyond the
// elastic part then), and the lattice's own elastic law S = C : E (the C the bonds reproduce). A
// cell with a broken or softening bond is no longer a continuum: it is marked not intact.
inline void compute_cell_stress(const View<int*>& cells, int count,
                                const View<int* [6]>& element_bonds,
                                const View<const LatticeStiffness*>& stiffness,
                                const Elements& elements, const Nodes& nodes, const Bonds& bonds) {
  if (count == 0) return;
  Kokkos::parallel_for(
      "fracta::cell_stress", Kokkos::RangePolicy<ExecSpace>(0, count), KOKKOS_LAMBDA(const int k) {
        const int e = cells(k);
        int intact = 1;
        for (int a = 0; a < 6; ++a) {
          const int b = element_bonds(e, a);
          // A broken or softening (cracking) bond: the cell is no longer a continuum.
          if (b >= 0 && (bonds.state(b) == kBondBroken || bonds.onset_separation(b) > 0.0))
            intact = 0;
        }
        elements.cell_intact(e) = intact;
        double green[3];
        cell_green_lagrange(elements, nodes, e, green);
        const double exx = green[0] - elements.cell_strain_offset(e, 0);
        const double eyy = green[1] - elements.cell_strain_offset(e, 1);
        const double exy = green[2] - elements.cell_strain_offset(e, 2);
        const LatticeStiffness s = stiffness(elements.material(e));
        const double c = s.youngs_modulus_eff / (1.0 - s.poisson_ratio_eff * s.poisson_ratio_eff);
        elements.cell_stress(e, 0) = c * (exx + s.poisson_ratio_eff * eyy);
        elements.cell_stress(e, 1) = c * (eyy + s.poisson_ratio_eff * exx);
        elements.cell_stress(e, 2) = s.youngs_modulus_eff / (1.0 + s.poisson_ratio_eff) * exy;
      });
}

// Cohesive bonds (BondLaw::fracture_energy > 0). Effective separation of a bond from its
// undamaged spring forces: |(<u_n>, u_s)| with u = f / k (compression does not open a crack).
KOKKOS_INLINE_FUNCTION double effective_separation(double fn, double fs, double kn, double ks) {
  const double un = fn > 0.0 && kn > 0.0 ? fn / kn : 0.0;
  const double us = ks > 0.0 ? fs / ks : 0.0;
  return sqrt_(un * un + us * us);
}

// Energy a bond stores with applied forces fn, fs at damage D (J): the secant springs
// (1 - D) k carry the tension and the shear; compression is carried undamaged.
KOKKOS_INLINE_FUNCTION double stored_bond_energy(double fn, double fs, double damage, double kn,
                                                 double ks) {
  double e = 0.0;
  if (kn > 0.0) e += 0.5 * fn * fn / (fn > 0.0 ? (1.0 - damage) * kn : kn);
  if (ks > 0.0 && damage < 1.0) e += 0.5 * fs * fs / ((1.0 - damage) * ks);
  return e;
}

// Trapezoidal work of the discs on a bond over a step (J): normal forces fn_old -> fn_new over
// the change of the elastic elongation, from fn_old (at damage D_old) to the undamaged force
// fn_trial of this step; shear forces fs_old -> fs_new over the shear increment. Elastic
// bonds only: cohesive materials are elastic up to their strength.
KOKKOS_INLINE_FUNCTION double bond_work(double fn_old, double fn_new, double fs_old, double fs_new,
                                        double fn_trial, double damage_old, double kn,
                                        double shear_increment) {
  double w = 0.5 * (fs_old + fs_new) * shear_increment;
  if (kn > 0.0) {
    const double u_old = fn_old / (fn_old > 0.0 ? (1.0 - damage_old) * kn : kn);
    w += 0.5 * (fn_old + fn_new) * (fn_trial / kn - u_old);
  }
  return w;
}

struct BondForces {
  Nodes nodes;
  Elements elements;
  Bonds bonds;
  View<const BondLaw*> laws;
  double dt;
  // The list positions to slots (Bonds::used) when the kernel sweeps that list; empty: every slot.
  View<int*> list;
  // Forces added straight into nodes.f and nodes.moment (kernels/scatter.hpp), atomically when
  // the bonds do not run by the chunks of a ScatterPlan (GPUs).
  bool atomic = true;

  KOKKOS_INLINE_FUNCTION int slot(const int k) const { return list.extent(0) > 0 ? list(k) : k; }

  // Atomic path: work item = one list position.
  KOKKOS_INLINE_FUNCTION void operator()(const int k, Sums<3>& acc) const { bond(slot(k), acc); }

  // Chunk path: the list positions [begin, end), in order; on CPUs by batches of kLanes bonds
  // where a batch qualifies (elastic_batch), else bond by bond.
  KOKKOS_INLINE_FUNCTION void chunk(const int begin, const int end, Sums<3>& acc) const {
    int k = begin;
#ifdef FRACTA_HOST_SIMD
    for (; k + kLanes <= end; k += kLanes)
      if (!elastic_batch(k))
        for (int l = 0; l < kLanes; ++l) bond(slot(k + l), acc);
#endif
    for (; k < end; ++k) bond(slot(k), acc);
  }

#ifdef FRACTA_HOST_SIMD
  // Eight bonds at once in SIMD lanes (simd.hpp), the common case of a lattice at work: eight
  // consecutive active slots of one material with elastic springs (no yield stress), none
  // softening (onset 0, so damage 0) and none reaching its strength this step. The arithmetic
  // is bond()'s on that path, lane by lane, in the same order. If the batch does not qualify,
  // or a lane reaches its strength, it returns false before writing anything, and the caller
  // runs bond() for each (rare: a bond breaks or starts to soften once).
  bool elastic_batch(const int position) const {
    using T = Double8;
    constexpr int L = 8;
    const int b0 = slot(position);
    if (slot(position + L - 1) != b0 + L - 1) return false;  // the list increases
    const int material = bonds.material(b0);
    for (int l = 0; l < L; ++l)
      if (bonds.state(b0 + l) != kBondActive || bonds.material(b0 + l) != material) return false;
    const BondLaw& law = laws(material);
    if (law.yield_stress > 0.0) return false;
    const bool cohesive = law.fracture_energy > 0.0;
    if (cohesive)
      for (int l = 0; l < L; ++l)
        if (bonds.onset_separation(b0 + l) != 0.0) return false;
    int i[L], j[L], c0[L], c1[L];
    for (int l = 0; l < L; ++l) {
      i[l] = bonds.nodes(b0 + l, 0);
      j[l] = bonds.nodes(b0 + l, 1);
      c0[l] = bonds.cells(b0 + l, 0);
      c1[l] = bonds.cells(b0 + l, 1);
    }
    const int xs = static_cast<int>(nodes.x.stride_0()), vs = static_cast<int>(nodes.v.stride_0());
    const int x0s = static_cast<int>(nodes.x0.stride_0());
    const T xi = gather_lanes<T>(&nodes.x(0, 0), i, xs),
            yi = gather_lanes<T>(&nodes.x(0, 1), i, xs);
    const T xj = gather_lanes<T>(&nodes.x(0, 0), j, xs),
            yj = gather_lanes<T>(&nodes.x(0, 1), j, xs);
    const T dx = xj - xi, dy = yj - yi;
    const T length = sqrt_(dx * dx + dy * dy);
    const T nx = dx / length, ny = dy / length;
    const T ri = gather_lanes<T>(nodes.radius.data(), i, 1);
    const T rj = gather_lanes<T>(nodes.radius.data(), j, 1);
    const T li = length * ri / (ri + rj), lj = length * rj / (ri + rj);
    const bool consecutive = true;
    int b[L];
    for (int l = 0; l < L; ++l) b[l] = b0 + l;
    const T kn = load_lanes<T>(bonds.kn.data(), b, consecutive);
    const T ks = load_lanes<T>(bonds.ks.data(), b, consecutive);
    const T area = load_lanes<T>(bonds.area.data(), b, consecutive);
    const T L0 = load_lanes<T>(bonds.length0.data(), b, consecutive);
    const T up = load_lanes<T>(bonds.plastic_n.data(), b, consecutive);
    const T us_p = load_lanes<T>(bonds.plastic_s.data(), b, consecutive);
    const T fs_old = load_lanes<T>(bonds.fs.data(), b, consecutive);
    T fn = kn * ((length - L0) - up);  // bilinear_spring without a yield force
    const T dvt =
        -(gather_lanes<T>(&nodes.v(0, 0), j, vs) - gather_lanes<T>(&nodes.v(0, 0), i, vs)) * ny +
        (gather_lanes<T>(&nodes.v(0, 1), j, vs) - gather_lanes<T>(&nodes.v(0, 1), i, vs)) * nx -
        (li * gather_lanes<T>(nodes.spin.data(), i, 1) +
         lj * gather_lanes<T>(nodes.spin.data(), j, 1));
    const T shear_increment = dvt * dt;
    const T us = fs_old / ks + us_p + shear_increment;  // bond(): (1 - D) ks with D = 0
    T fs = ks > 0.0 ? ks * (us - us_p) : splat<T>(0.0);
    // The face traction from the intact cells around each bond (bond(): the same sum in the same
    // order), or the bond's own stresses without one.
    T s3[3] = {splat<T>(0.0), splat<T>(0.0), splat<T>(0.0)};
    T cells = splat<T>(0.0);
    for (const int* c : {c0, c1}) {
      T in = splat<T>(0.0), st[3] = {in, in, in};
      for (int l = 0; l < L; ++l) {
        if (c[l] < 0 || !elements.cell_intact(c[l])) continue;
        in[l] = 1.0;
        for (int q = 0; q < 3; ++q) st[q][l] = elements.cell_stress(c[l], q);
      }
      for (int q = 0; q < 3; ++q) s3[q] += st[q];
      cells += in;
    }
    const T ux =
        gather_lanes<T>(&nodes.x0(0, 0), j, x0s) - gather_lanes<T>(&nodes.x0(0, 0), i, x0s);
    const T uy =
        gather_lanes<T>(&nodes.x0(0, 1), j, x0s) - gather_lanes<T>(&nodes.x0(0, 1), i, x0s);
    const T n0x = ux / L0, n0y = uy / L0;
    const T divisor = cells > 0.0 ? cells : splat<T>(1.0);
    const T sxx = s3[0] / divisor, syy = s3[1] / divisor, sxy = s3[2] / divisor;
    const T sigma_cells = sxx * n0x * n0x + syy * n0y * n0y + 2.0 * sxy * n0x * n0y;
    const T t_cells = -(sxx * n0x + sxy * n0y) * n0y + (sxy * n0x + syy * n0y) * n0x;
    const T tau_cells = t_cells < 0.0 ? -t_cells : t_cells;
    const T abs_fs = fs < 0.0 ? -fs : fs;
    const T sigma_n = cells > 0.0 ? sigma_cells : (area > 0.0 ? fn / area : splat<T>(0.0));
    const T tau = cells > 0.0 ? tau_cells : (area > 0.0 ? abs_fs / area : splat<T>(0.0));
    auto reaches = !all_lanes<T>();
    if (law.tensile_strength > 0.0) reaches = reaches || sigma_n >= law.tensile_strength;
    if (law.cohesion > 0.0) reaches = reaches || tau >= law.cohesion - sigma_n * law.tan_friction;
    if (any_lane(reaches)) return false;
    store_lanes(fn, bonds.fn.data(), b, consecutive);
    store_lanes(fs, bonds.fs.data(), b, consecutive);
    const T fx = fn * nx - fs * ny, fy = fn * ny + fs * nx;
    const T mi = li * fs, mj = lj * fs;
    for (int l = 0; l < L; ++l) {
      nodes.f(i[l], 0) += fx[l];
      nodes.f(i[l], 1) += fy[l];
      nodes.moment(i[l]) += mi[l];
      nodes.f(j[l], 0) -= fx[l];
      nodes.f(j[l], 1) -= fy[l];
      nodes.moment(j[l]) += mj[l];
    }
    return true;
  }
#endif

  KOKKOS_INLINE_FUNCTION void bond(const int b, Sums<3>& acc) const {
    if (bonds.state(b) != kBondActive) return;
    const int i = bonds.nodes(b, 0), j = bonds.nodes(b, 1);
    const double dx = nodes.x(j, 0) - nodes.x(i, 0), dy = nodes.x(j, 1) - nodes.x(i, 1);
    const double length = sqrt_(dx * dx + dy * dy);
    const double nx = dx / length, ny = dy / length;  // n; t = (-ny, nx)
    // Lever arms to the contact point, which splits the current length in the ratio of the
    // radii: then the moments l_i fs + l_j fs = L fs balance the couple of the shear forces
    // exactly (angular momentum is conserved whatever the stretch).
    const double ri = nodes.radius(i), rj = nodes.radius(j);
    const double li = length * ri / (ri + rj), lj = length * rj / (ri + rj);
    const BondLaw& law = laws(bonds.material(b));
    const double kn = bonds.kn(b), ks = bonds.ks(b), area = bonds.area(b), L0 = bonds.length0(b);
    // Bilinear parameters in force units: yield force = yield stress * S, hardening modulus
    // in force per unit plastic displacement H S / L0.
    const double fy_n = law.yield_stress * area;
    const double fy_s = law.yield_stress * area / 1.7320508075688772;  // von Mises shear yield
    const double k_hard = law.hardening * area / L0;
    // Elastic springs (yield_stress 0) never change their plastic state (which a conversion may
    // have set: the cell's strain beyond its elastic part): read what the forces need, write
    // nothing back (a sixth of the bytes a bond moves per step).
    const bool plastic_law = law.yield_stress > 0.0;
    double up = bonds.plastic_n(b), us_p = bonds.plastic_s(b);
    double alpha = plastic_law ? bonds.hardening(b) : 0.0;
    // fn, fs: the undamaged spring forces; a softening bond applies (1 - D) of them.
    const bool cohesive = law.fracture_energy > 0.0;
    const double damage_old = cohesive ? bonds.damage(b) : 0.0;
    const double fn_old = bonds.fn(b), fs_old = bonds.fs(b);
    double fn = 0.0, fs = 0.0, plastic = 0.0;
    plastic += bilinear_spring(kn, length - L0, fy_n, k_hard, up, alpha, fn);
    double shear_increment = 0.0;
    if (ks > 0.0) {
      // Shear displacement increment (paper Eq. 8 corrected): relative tangential velocity
      // of the contact point, with the disc rotations (DESIGN.md 1.2).
      const double dvt = -(nodes.v(j, 0) - nodes.v(i, 0)) * ny +
                         (nodes.v(j, 1) - nodes.v(i, 1)) * nx -
                         (li * nodes.spin(i) + lj * nodes.spin(j));
      // Shear displacement kept as the elastic part fs/ks plus the plastic slip.
      shear_increment = dvt * dt;
      const double us = fs_old / ((1.0 - damage_old) * ks) + us_p + shear_increment;
      plastic += bilinear_spring(ks, us, fy_s, k_hard, us_p, alpha, fs);
    }
    // Failure (paper Sec. 2.3 with Eq. 6 corrected; DESIGN.md 1.2): Mohr-Coulomb with tension
    // cut-off on the face the bond stands for: the cell face normal to an edge bond, the
    // diagonal plane for a diagonal bond. Its traction (sigma_n = n.s.n, tension positive;
    // tau = |t.s.n|) comes from the continuum stress of the intact cells around the bond
    // (compute_cell_stress), so uniaxial tension breaks it at sigma_t and a direct shear test
    // at tau = c + sigma tan(phi): a single bond's fn / S cannot see the stress along its face
    // (the Poisson coupling) and would miss the envelope under confinement. With no intact cell
    // left around it (a fragment's edge), the bond's own stresses fn / S and |fs| / S are used.
    double sigma_n, tau;
    {
      double s3[3] = {0, 0, 0};
      int cells = 0;
      for (int k = 0; k < 2; ++k) {
        const int c = bonds.cells(b, k);
        if (c < 0 || !elements.cell_intact(c)) continue;
        for (int q = 0; q < 3; ++q) s3[q] += elements.cell_stress(c, q);
        ++cells;
      }
      if (cells > 0) {
        // Reference-frame stress with the reference bond direction (rotation invariant).
        const double ux = nodes.x0(j, 0) - nodes.x0(i, 0), uy = nodes.x0(j, 1) - nodes.x0(i, 1);
        const double n0x = ux / L0, n0y = uy / L0;
        const double sxx = s3[0] / cells, syy = s3[1] / cells, sxy = s3[2] / cells;
        sigma_n = sxx * n0x * n0x + syy * n0y * n0y + 2.0 * sxy * n0x * n0y;
        tau = fabs_(-(sxx * n0x + sxy * n0y) * n0y + (sxy * n0x + syy * n0y) * n0x);
      } else {
        sigma_n = area > 0.0 ? fn / area : 0.0;
        tau = area > 0.0 ? fabs_(fs) / area : 0.0;
      }
    }
    double onset = cohesive ? bonds.onset_separation(b) : 0.0;
    bool breaks = false;
    if (onset == 0.0) {
      const bool tension = law.tensile_strength > 0.0 && sigma_n >= law.tensile_strength;
      const bool shear = law.cohesion > 0.0 && tau >= law.cohesion - sigma_n * law.tan_friction;
      if (tension || shear) {
        // Brittle: the bond breaks at its strength. Cohesive: it starts to soften from the
        // effective separation lambda_0 it has now, and is spent at lambda_f, chosen so that
        // it dissipates its share of G_f: along a proportional path the bilinear law
        // dissipates E_0 lambda_f / lambda_0 (E_0 = what the bond stores at the onset; pure
        // mode I: 1/2 f_0 lambda_f), so lambda_f = G_f A_b lambda_0 / E_0.
        breaks = true;
        if (cohesive) {
          onset = effective_separation(fn, fs, kn, ks);
          const double stored = stored_bond_energy(fn > 0.0 ? fn : 0.0, fs, 0.0, kn, ks);
          const double share = law.fracture_energy * kn * L0 * law.crack_area_factor[bonds.kind(b)];
          const double final_separation = stored > 0.0 ? share * onset / stored : 0.0;
          if (onset > 0.0 && final_separation > onset) {
            breaks = false;
            bonds.onset_separation(b) = onset;
            bonds.final_separation(b) = final_separation;
          } else {
            onset = 0.0;
          }
        }
      }
    }
    double damage = damage_old;
    if (onset > 0.0) {
      // Linear softening of the effective traction against the effective separation
      // lambda = |(<u_n>, u_s)| (the elastic displacements of the undamaged springs), from
      // lambda_0 to lambda_f, with irreversible secant damage (the bilinear cohesive law)
      //   D = lambda_f (lambda - lambda_0) / (lambda (lambda_f - lambda_0)).
      const double lambda_f = bonds.final_separation(b);
      const double lambda = effective_separation(fn, fs, kn, ks);
      if (lambda >= lambda_f) {
        breaks = true;
      } else if (lambda > onset) {
        damage = max_(damage, lambda_f * (lambda - onset) / (lambda * (lambda_f - onset)));
      }
    }
    if (breaks) {
      // Released as fracture energy: what the bond held, plus what the discs did on it this
      // step by the trapezoidal rule with the zero force it now applies (for an undamaged
      // bond 1/2 f_old^2/k + 1/2 f_old (f - f_old)/k = 1/2 f_old f / k per spring; counting
      // the trial energy 1/2 f^2/k would over-count by 1/2 f du and unbalance the energy).
      double energy =
          cohesive ? stored_bond_energy(fn_old, fs_old, damage_old, kn, ks) +
                         bond_work(fn_old, 0.0, fs_old, 0.0, fn, damage_old, kn, shear_increment)
                   : (kn > 0.0 ? 0.5 * fn_old * fn / kn : 0.0) +
                         (ks > 0.0 ? 0.5 * fs_old * fs / ks : 0.0);
      // A bond that breaks while its discs overlap hands part of its energy to the contact
      // that takes over at once (1/2 k_c delta^2 with the contact law's series stiffness):
      // that part is not fracture energy, or the balance would count it twice.
      const double overlap = ri + rj - length;
      if (overlap > 0.0) {
        const double kci = nodes.contact_stiffness(i), kcj = nodes.contact_stiffness(j);
        const double kc = kci + kcj > 0.0 ? 2.0 * kci * kcj / (kci + kcj) : 0.0;
        energy -= 0.5 * kc * overlap * overlap;
      }
      bonds.state(b) = kBondBroken;
      bonds.fn(b) = 0.0;
      bonds.fs(b) = 0.0;
      acc.v[0] += energy;
      acc.v[1] += plastic;
      acc.v[2] += 1.0;
      return;
    }
    if (onset > 0.0) {
      // A softening bond: the applied forces, and the energy the softening dissipated this
      // step, the trapezoidal work of the discs on the bond less the change of what it stores
      // (zero for an undamaged spring, so the balance is the elastic one until the onset).
      const double fn_applied = fn > 0.0 ? (1.0 - damage) * fn : fn;
      const double fs_applied = (1.0 - damage) * fs;
      acc.v[0] +=
          bond_work(fn_old, fn_applied, fs_old, fs_applied, fn, damage_old, kn, shear_increment) +
          stored_bond_energy(fn_old, fs_old, damage_old, kn, ks) -
          stored_bond_energy(fn_applied, fs_applied, damage, kn, ks);
      fn = fn_applied;
      fs = fs_applied;
      bonds.damage(b) = damage;
    }
    bonds.fn(b) = fn;
    bonds.fs(b) = fs;
    if (plastic_law) {
      bonds.plastic_n(b) = up;
      bonds.plastic_s(b) = us_p;
      bonds.hardening(b) = alpha;
      bonds.plastic_work(b) += plastic;
      acc.v[1] += plastic;
    }
    // Force on i: fn n + fs t; on j the opposite; moments l_i fs and l_j fs (DESIGN.md 1.2).
    const double fx = fn * nx - fs * ny, fy = fn * ny + fs * nx;
    scatter_add(&nodes.f(i, 0), fx, atomic);
    scatter_add(&nodes.f(i, 1), fy, atomic);
    scatter_add(&nodes.moment(i), li * fs, atomic);
    scatter_add(&nodes.f(j, 0), -fx, atomic);
    scatter_add(&nodes.f(j, 1), -fy, atomic);
    scatter_add(&nodes.moment(j), lj * fs, atomic);
  }
};

// The bond list the kernels sweep: Bonds::used when it is a proper subset of the slots, else
// every slot (a list of every slot is the identity).
inline bool bonds_listed(const Bonds& bonds) {
  return bonds.used.extent(0) > 0 && bonds.used_count < bonds.count;
}
inline int bond_list_count(const Bonds& bonds) {
  return bonds_listed(bonds) ? bonds.used_count : bonds.count;
}

// Bond forces added into nodes.f and nodes.moment. The list is increasing, so the order of
// every node's sum is the one of the sweep over all slots. Without a usable bonds.scatter (the
// plan of the list: update_scatter_plan) the forces are added atomically.
inline BondStepResult compute_bond_forces(const Nodes& nodes, const Elements& elements,
                                          const Bonds& bonds, const View<const BondLaw*>& laws,
                                          double dt) {
  BondStepResult r;
  if (bonds.count == 0) return r;
  const int count = bond_list_count(bonds);
  BondForces forces{
      nodes, elements, bonds, laws, dt, bonds_listed(bonds) ? bonds.used : View<int*>(), true};
  Sums<3> s;
  if (bonds.scatter.usable(count)) {
    forces.atomic = false;
    s = for_each_chunk<Kokkos::Sum<Sums<3>>>("fracta::bond_forces", bonds.scatter, forces);
  } else {
    Kokkos::parallel_reduce("fracta::bond_forces", Kokkos::RangePolicy<ExecSpace>(0, count), forces,
                            Kokkos::Sum<Sums<3>>(s));
  }
  r.fracture_energy = s.v[0];
  r.plastic_work = s.v[1];
  r.broken = static_cast<long>(s.v[2] + 0.5);
  return r;
}

// The scatter plan of the bond slots (kernels/scatter.hpp), cut once from the slots and located
// in the bond list after every change of it.
inline void update_scatter_plan(Bonds& bonds) {
  const auto list = bonds_listed(bonds) ? bonds.used : View<int*>();
  if (bonds.scatter.universe == bonds.count) {
    locate_scatter_chunks(bonds.scatter, list, bond_list_count(bonds));
    return;
  }
  const auto ends = bonds.nodes;
  build_scatter_plan(
      bonds.scatter, bonds.count,
      KOKKOS_LAMBDA(const int b, int& lo, int& hi) {
        lo = min_(ends(b, 0), ends(b, 1));
        hi = max_(ends(b, 0), ends(b, 1));
      },
      list, bond_list_count(bonds));
}

// Stable step of the bond network (DESIGN.md 1.4): Gershgorin's bound on the largest
// eigenvalue of M^-1/2 K M^-1/2 over translations and rotations, row by row. Each bond adds to
// the rows of its two discs; `contact_allowance` adds that many contacts of the disc's contact
// stiffness to every contact disc (particles and FE boundary nodes). Returns 2 / sqrt(lambda_max)
// (s), or a huge value if no bond.
struct GershgorinRows {
  Nodes nodes;
  Bonds bonds;
  View<double* [2]> row;  // translation, rotation
  KOKKOS_INLINE_FUNCTION void operator()(const int b) const {
    if (bonds.state(b) != kBondActive) return;
    const int ends[2] = {bonds.nodes(b, 0), bonds.nodes(b, 1)};
    const double k = bonds.kn(b) + bonds.ks(b), ks = bonds.ks(b);
    for (int s = 0; s < 2; ++s) {
      const int i = ends[s], j = ends[1 - s];
      const double mi = nodes.mass(i), mj = nodes.mass(j);
      const double Ii = nodes.inertia(i), Ij = nodes.inertia(j);
      const double ri = nodes.radius(i), rj = nodes.radius(j);
      // |K| entries of a 2D spring pair, row x of disc i: |kn nx^2 + ks tx^2| +
      // |(kn - ks) nx ny| <= (1 + sqrt 2)/2 (kn + ks) towards i and towards j; shear couples
      // the translation to both rotations by r ks |tx| <= r ks; rotations couple by r^2 ks
      // and to translations by r ks (|tx| + |ty|) <= sqrt 2 r ks.
      const double trans = 1.2071067811865475 * k * (1.0 / mi + 1.0 / sqrt_(mi * mj)) +
                           ks * (ri / sqrt_(mi * Ii) + rj / sqrt_(mi * Ij));
      const double rot =
          ks * (ri * ri / Ii + ri * rj / sqrt_(Ii * Ij)) +
          1.4142135623730951 * ks * ri * (1.0 / sqrt_(Ii * mi) + 1.0 / sqrt_(Ii * mj));
      Kokkos::atomic_add(&row(i, 0), trans);
      Kokkos::atomic_add(&row(i, 1), rot);
    }
  }
};

// Row bound of node n: its bond rows and the allowance of contacts.
struct GershgorinBound {
  Nodes nodes;
  View<double* [2]> row;
  double allowance;
  KOKKOS_INLINE_FUNCTION double contact(const int n) const {
    // A contact pair adds at most 1.2071 kc (1/m_i + 1/sqrt(m_i m_j)) <= 3.7 kc / m_i
    // (a neighbour of at least a quarter of the mass: a corner node).
    return allowance * 3.7 * nodes.contact_stiffness(n) / nodes.mass(n);
  }
  KOKKOS_INLINE_FUNCTION void operator()(const int n, double& lmax) const {
    if (!nodes.particle(n) && !nodes.contact_disc(n)) return;
    const double l = max_(row(n, 0), row(n, 1)) + contact(n);
    lmax = lmax > l ? lmax : l;
  }
};

inline double bond_stable_dt(const Nodes& nodes, const Bonds& bonds, int contact_allowance) {
  if (!nodes.has_particles()) return 1e300;
  View<double* [2]> row("fracta::gershgorin_rows", nodes.count);  // translation, rotation
  if (bonds.count > 0)
    Kokkos::parallel_for("fracta::bond_gershgorin", Kokkos::RangePolicy<ExecSpace>(0, bonds.count),
                         GershgorinRows{nodes, bonds, row});
  double lambda = 0.0;
  Kokkos::parallel_reduce("fracta::bond_stable_dt", Kokkos::RangePolicy<ExecSpace>(0, nodes.count),
                          GershgorinBound{nodes, row, static_cast<double>(contact_allowance)},
                          Kokkos::Max<double>(lambda));
  return lambda > 0.0 ? 2.0 / sqrt_(lambda) : 1e300;
}

// The same bound over the lists (Bonds::used, Nodes::particle_list), without allocating: the
// rows live in the work space (only the particles' entries are ever written: the ends of
// active bonds are particles; the others stay 0). A contact disc that is not a particle then
// has the bound contact(n) alone, and a particle's bound is at least its contact(n), so
// lambda = max(max over contact discs of contact(n), max over particles of their bound): the
// first term is constant and computed once. Max is exact: the same value as the sweep.
struct StableDtWorkspace {
  View<double* [2]> row;
  double disc_lambda = 0.0;  // max over contact discs of contact(n)
  int allowance = -1;        // the allowance disc_lambda was computed for (-1: none yet)
};

inline double bond_stable_dt(const Nodes& nodes, const Bonds& bonds, int contact_allowance,
                             StableDtWorkspace& ws) {
  if (!nodes.has_particles()) return 1e300;
  if (bonds.used.extent(0) == 0 || nodes.particle_list.extent(0) == 0)
    return bond_stable_dt(nodes, bonds, contact_allowance);
  if (ws.row.extent(0) != static_cast<size_t>(nodes.count))
    ws.row = View<double* [2]>("fracta::gershgorin_rows", nodes.count);
  const GershgorinBound bound{nodes, ws.row, static_cast<double>(contact_allowance)};
  if (ws.allowance != contact_allowance) {
    const auto disc = nodes.contact_disc;
    ws.disc_lambda = 0.0;
    Kokkos::parallel_reduce(
        "fracta::disc_stable_dt", Kokkos::RangePolicy<ExecSpace>(0, nodes.count),
        KOKKOS_LAMBDA(const int n, double& lmax) {
          if (!disc(n)) return;
          const double l = bound.contact(n);
          lmax = lmax > l ? lmax : l;
        },
        Kokkos::Max<double>(ws.disc_lambda));
    ws.allowance = contact_allowance;
  }
  const auto row = ws.row;
  const auto particles = nodes.particle_list;
  const auto used = bonds.used;
  Kokkos::parallel_for(
      "fracta::gershgorin_zero", Kokkos::RangePolicy<ExecSpace>(0, nodes.particle_count),
      KOKKOS_LAMBDA(const int k) { row(particles(k), 0) = row(particles(k), 1) = 0.0; });
  const GershgorinRows rows{nodes, bonds, row};
  Kokkos::parallel_for(
      "fracta::bond_gershgorin", Kokkos::RangePolicy<ExecSpace>(0, bonds.used_count),
      KOKKOS_LAMBDA(const int k) { rows(used(k)); });
  double lambda = 0.0;
  Kokkos::parallel_reduce(
      "fracta::bond_stable_dt", Kokkos::RangePolicy<ExecSpace>(0, nodes.particle_count),
      KOKKOS_LAMBDA(const int k, double& lmax) { bound(particles(k), lmax); },
      Kokkos::Max<double>(lambda));
  lambda = lambda > ws.disc_lambda ? lambda : ws.disc_lambda;
  return lambda > 0.0 ? 2.0 / sqrt_(lambda) : 1e300;
}

}  // namespace fracta
