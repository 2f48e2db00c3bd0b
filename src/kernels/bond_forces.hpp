// Bond forces of the bonded disc lattice (DESIGN.md 1.2; paper Eqs. 5, 6 and 8-10 corrected).
// One kernel over the bond slots: active bonds compute their normal and shear spring forces,
// check Mohr-Coulomb failure with tension cut-off, and store what they apply at their ends; a
// node kernel gathers them (no atomics, and a fixed summation order).
#pragma once
#include "kernels/compat.hpp"
#include "kernels/conversion.hpp"
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
// cell with a broken bond is no longer a continuum: it is marked not intact.
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
          if (b >= 0 && bonds.state(b) == kBondBroken) intact = 0;
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

struct BondForces {
  Nodes nodes;
  Elements elements;
  Bonds bonds;
  View<const BondLaw*> laws;
  double dt;

  KOKKOS_INLINE_FUNCTION void operator()(const int b, Sums<3>& acc) const {
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
    double up = bonds.plastic_n(b), us_p = bonds.plastic_s(b), alpha = bonds.hardening(b);
    double fn = 0.0, fs = 0.0, plastic = 0.0;
    plastic += bilinear_spring(kn, length - L0, fy_n, k_hard, up, alpha, fn);
    if (ks > 0.0) {
      // Shear displacement increment (paper Eq. 8 corrected): relative tangential velocity
      // of the contact point, with the disc rotations (DESIGN.md 1.2).
      const double dvt = -(nodes.v(j, 0) - nodes.v(i, 0)) * ny +
                         (nodes.v(j, 1) - nodes.v(i, 1)) * nx -
                         (li * nodes.spin(i) + lj * nodes.spin(j));
      // Shear displacement kept as the elastic part fs/ks plus the plastic slip.
      const double us = bonds.fs(b) / ks + us_p + dvt * dt;
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
    const bool tension = law.tensile_strength > 0.0 && sigma_n >= law.tensile_strength;
    const bool shear = law.cohesion > 0.0 && tau >= law.cohesion - sigma_n * law.tan_friction;
    if (tension || shear) {
      // Released as fracture energy: what the bond held, 1/2 f_old^2/k, plus what the discs did
      // on it this step by the trapezoidal rule with the zero force it now applies,
      // 1/2 f_old (f - f_old)/k: together 1/2 f_old f / k per spring. (Counting the trial
      // energy 1/2 f^2/k would over-count by 1/2 f du per break and unbalance the energy.)
      const double fn_old = bonds.fn(b), fs_old = bonds.fs(b);
      double energy =
          (kn > 0.0 ? 0.5 * fn_old * fn / kn : 0.0) + (ks > 0.0 ? 0.5 * fs_old * fs / ks : 0.0);
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
      for (int s = 0; s < 2; ++s)
        for (int k = 0; k < 3; ++k) bonds.end_force(b, s, k) = 0.0;
      acc.v[0] += energy;
      acc.v[1] += plastic;
      acc.v[2] += 1.0;
      return;
    }
    bonds.fn(b) = fn;
    bonds.fs(b) = fs;
    bonds.plastic_n(b) = up;
    bonds.plastic_s(b) = us_p;
    bonds.hardening(b) = alpha;
    bonds.plastic_work(b) += plastic;
    acc.v[1] += plastic;
    // Force on i: fn n + fs t; on j the opposite; moments l_i fs and l_j fs (DESIGN.md 1.2).
    const double fx = fn * nx - fs * ny, fy = fn * ny + fs * nx;
    bonds.end_force(b, 0, 0) = fx;
    bonds.end_force(b, 0, 1) = fy;
    bonds.end_force(b, 0, 2) = li * fs;
    bonds.end_force(b, 1, 0) = -fx;
    bonds.end_force(b, 1, 1) = -fy;
    bonds.end_force(b, 1, 2) = lj * fs;
  }
};

// f(n) and moment(n) += what the bonds apply at disc n (Bonds::end_force).
struct GatherBondForces {
  Nodes nodes;
  Bonds bonds;
  KOKKOS_INLINE_FUNCTION void operator()(const int n) const {
    double fx = 0.0, fy = 0.0, moment = 0.0;
    for (int k = bonds.node_end_offset(n); k < bonds.node_end_offset(n + 1); ++k) {
      const int end = bonds.node_end(k);
      fx += bonds.end_force(end / 2, end % 2, 0);
      fy += bonds.end_force(end / 2, end % 2, 1);
      moment += bonds.end_force(end / 2, end % 2, 2);
    }
    nodes.f(n, 0) += fx;
    nodes.f(n, 1) += fy;
    nodes.moment(n) += moment;
  }
};

inline BondStepResult compute_bond_forces(const Nodes& nodes, const Elements& elements,
                                          const Bonds& bonds, const View<const BondLaw*>& laws,
                                          double dt) {
  BondStepResult r;
  if (bonds.count == 0) return r;
  Sums<3> s;
  Kokkos::parallel_reduce("fracta::bond_forces", Kokkos::RangePolicy<ExecSpace>(0, bonds.count),
                          BondForces{nodes, elements, bonds, laws, dt}, Kokkos::Sum<Sums<3>>(s));
  Kokkos::parallel_for("fracta::bond_gather", Kokkos::RangePolicy<ExecSpace>(0, nodes.count),
                       GatherBondForces{nodes, bonds});
  r.fracture_energy = s.v[0];
  r.plastic_work = s.v[1];
  r.broken = static_cast<long>(s.v[2] + 0.5);
  return r;
}

// Stable step of the bond network (DESIGN.md 1.4): Gershgorin's bound on the largest
// eigenvalue of M^-1/2 K M^-1/2 over translations and rotations, row by row. Each bond adds to
// the rows of its two discs; `contact_allowance` adds that many contacts of the disc's contact
// stiffness to every contact disc (particles and FE boundary nodes). Returns 2 / sqrt(lambda_max)
// (s), or a huge value if no bond.
inline double bond_stable_dt(const Nodes& nodes, const Bonds& bonds, int contact_allowance) {
  if (!nodes.has_particles()) return 1e300;
  View<double* [2]> row("fracta::gershgorin_rows", nodes.count);  // translation, rotation
  const auto x = nodes.x;
  const auto mass = nodes.mass;
  const auto inertia = nodes.inertia;
  const auto radius = nodes.radius;
  if (bonds.count > 0) {
    Kokkos::parallel_for(
        "fracta::bond_gershgorin", Kokkos::RangePolicy<ExecSpace>(0, bonds.count),
        KOKKOS_LAMBDA(const int b) {
          if (bonds.state(b) != kBondActive) return;
          const int ends[2] = {bonds.nodes(b, 0), bonds.nodes(b, 1)};
          const double k = bonds.kn(b) + bonds.ks(b), ks = bonds.ks(b);
          for (int s = 0; s < 2; ++s) {
            const int i = ends[s], j = ends[1 - s];
            const double mi = mass(i), mj = mass(j), Ii = inertia(i), Ij = inertia(j);
            const double ri = radius(i), rj = radius(j);
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
        });
  }
  double lambda = 0.0;
  const auto particle = nodes.particle;
  const auto disc = nodes.contact_disc;
  const auto kc = nodes.contact_stiffness;
  const double allowance = contact_allowance;
  Kokkos::parallel_reduce(
      "fracta::bond_stable_dt", Kokkos::RangePolicy<ExecSpace>(0, nodes.count),
      KOKKOS_LAMBDA(const int n, double& lmax) {
        if (!particle(n) && !disc(n)) return;
        // A contact pair adds at most 1.2071 kc (1/m_i + 1/sqrt(m_i m_j)) <= 3.7 kc / m_i
        // (a neighbour of at least a quarter of the mass: a corner node).
        const double contact = allowance * 3.7 * kc(n) / mass(n);
        const double l = max_(row(n, 0), row(n, 1)) + contact;
        lmax = lmax > l ? lmax : l;
      },
      Kokkos::Max<double>(lambda));
  return lambda > 0.0 ? 2.0 / sqrt_(lambda) : 1e300;
}

}  // namespace fracta
