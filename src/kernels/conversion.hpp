// Element-to-particle conversion (DESIGN.md 1.3). A converted element makes its 4 nodes discs
// and adds its stiffness to its bond slots: k1/2 and ks/2 to each of its 4 edges (an interior
// edge is shared by 2 elements) and k2 to each of its 2 diagonals. A `de` body is a set of
// elements converted at time 0.
#pragma once
#include "kernels/compat.hpp"
#include "kernels/state.hpp"

namespace fracta {

// Lattice spring stiffnesses of the formulation (DESIGN.md 1.2), N/m:
// k1 = E t / (1 + nu), k2 = nu E t / (1 - nu^2), ks = E t (1 - 3 nu) / (1 - nu^2), with
// (E, nu) -> (E / (1 - nu^2), nu / (1 - nu)) in plane strain (paper Eq. 4). They give
// C11 = (k1 + k2)/t, C12 = k2/t, C66 = (k2 + ks/2)/t for uniform strain with disc rotations equal
// to the continuum rotation, independent of the cell size.
struct LatticeStiffness {
  double k1 = 0, k2 = 0, ks = 0;
  double youngs_modulus_eff = 0, poisson_ratio_eff = 0;
};

KOKKOS_INLINE_FUNCTION LatticeStiffness lattice_stiffness(double E, double nu, bool plane_strain,
                                                          double thickness) {
  LatticeStiffness s;
  const double Ef = plane_strain ? E / (1.0 - nu * nu) : E;
  const double nuf = plane_strain ? nu / (1.0 - nu) : nu;
  s.youngs_modulus_eff = Ef;
  s.poisson_ratio_eff = nuf;
  s.k1 = Ef * thickness / (1.0 + nuf);
  s.k2 = nuf * Ef * thickness / (1.0 - nuf * nuf);
  s.ks = Ef * thickness * (1.0 - 3.0 * nuf) / (1.0 - nuf * nuf);
  return s;
}

// Activates the bond slots of the elements listed in `converted` and makes their nodes discs.
// `element_bonds(e, 0..3)` are the edge slots, `(e, 4..5)` the diagonal slots.
inline void activate_element_bonds(const View<int*>& converted, int count,
                                   const View<int* [6]>& element_bonds,
                                   const View<const LatticeStiffness*>& stiffness,
                                   const Elements& elements, const Nodes& nodes,
                                   const Bonds& bonds) {
  if (count == 0) return;
  Kokkos::parallel_for(
      "fracta::activate_element_bonds", Kokkos::RangePolicy<ExecSpace>(0, count),
      KOKKOS_LAMBDA(const int k) {
        const int e = converted(k);
        const LatticeStiffness s = stiffness(elements.material(e));
        for (int a = 0; a < 6; ++a) {
          const int b = element_bonds(e, a);
          if (b < 0) continue;
          Kokkos::atomic_add(&bonds.kn(b), a < 4 ? 0.5 * s.k1 : s.k2);
          if (a < 4) Kokkos::atomic_add(&bonds.ks(b), 0.5 * s.ks);
          bonds.material(b) = elements.material(e);
          bonds.state(b) = kBondActive;
        }
        for (int a = 0; a < 4; ++a) nodes.particle(elements.nodes(e, a)) = 1;
      });
  // Effective areas S = kn L0 / E_eff: the bond stress fn / S then equals E_eff times the bond
  // strain, so an orthogonal bond reaches sigma_t exactly when a block in uniaxial tension
  // along it carries sigma_t (DESIGN.md 1.2 asks for that calibration).
  Kokkos::parallel_for(
      "fracta::bond_areas", Kokkos::RangePolicy<ExecSpace>(0, bonds.count),
      KOKKOS_LAMBDA(const int b) {
        if (bonds.state(b) != kBondActive) return;
        bonds.area(b) =
            bonds.kn(b) * bonds.length0(b) / stiffness(bonds.material(b)).youngs_modulus_eff;
      });
}

}  // namespace fracta
