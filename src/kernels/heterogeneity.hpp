// Heterogeneous strength (docs/physics.md 1.2, "Heterogeneity"): each bond slot of a material with
// a Weibull modulus m draws a strength factor w, and the bond reaches its strength on its face at
// w sigma_t in tension and w c in shear (FaceStrength::reaches with a scale). The factors follow
// the two-parameter Weibull distribution of unit mean,
//   P(w' <= w) = 1 - exp(-(w Gamma(1 + 1/m))^m),   w = (-ln U)^(1/m) / Gamma(1 + 1/m),
// with U uniform on (0, 1) from a counter-based hash of (seed, the slot's end nodes): a draw
// depends on the seed and on which two nodes the bond joins, not on the thread count, the slot
// order or the other draws, so a run repeats bit for bit from its seed. m = 0: w = 1, or, with a
// strength spread d, w = 1 + d (2U - 1), uniform on [1 - d, 1 + d].
#pragma once
#include <cstdint>

#include "kernels/compat.hpp"
#include "kernels/state.hpp"

namespace fracta {

// SplitMix64's output function (Steele, Lea & Flood 2014): a bijection of 64-bit words whose
// outputs for consecutive inputs pass BigCrush; used here as a counter-based generator.
KOKKOS_INLINE_FUNCTION std::uint64_t mix64(std::uint64_t z) {
  z += 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

// A uniform number in (0, 1), open at both ends (53 random bits, centred in their interval),
// for the counter `key` of stream `seed`.
KOKKOS_INLINE_FUNCTION double uniform_draw(std::uint64_t seed, std::uint64_t key) {
  const std::uint64_t bits = mix64(mix64(seed) ^ key) >> 11;
  return (static_cast<double>(bits) + 0.5) * 0x1.0p-53;
}

// The counter of the bond joining nodes i and j (either order).
KOKKOS_INLINE_FUNCTION std::uint64_t bond_key(int i, int j) {
  const std::uint64_t lo = static_cast<std::uint64_t>(min_(i, j));
  const std::uint64_t hi = static_cast<std::uint64_t>(max_(i, j));
  return (hi << 32) | lo;
}

// The law of one material's bond strength factors (unit mean): Weibull of modulus m (above), or
// uniform on [1 - spread, 1 + spread] (the scatter of the cohesive strengths in Zhou, Molinari &
// Ramesh's fragmentation studies), or none (factor 1).
struct StrengthDistribution {
  double modulus = 0;       // Weibull m; 0: not Weibull
  double inverse_mean = 1;  // 1 / Gamma(1 + 1/m), computed on the host
  double spread = 0;        // half-width of the uniform law (relative); 0: none

  KOKKOS_INLINE_FUNCTION double factor(double uniform) const {
    if (modulus > 0.0) {
#if KOKKOS_VERSION >= 40000
      return Kokkos::pow(-Kokkos::log(uniform), 1.0 / modulus) * inverse_mean;
#else
      return Kokkos::Experimental::pow(-Kokkos::Experimental::log(uniform), 1.0 / modulus) *
             inverse_mean;
#endif
    }
    return 1.0 + spread * (2.0 * uniform - 1.0);
  }
};

// Bonds::strength_scale for every slot, with the law of the material of the slot's first cell
// (both cells of a slot belong to one body), and Elements::cell_inverse_strength_scale, 1 / the
// smallest factor of each cell's slots (the cell stress's bound: compute_cell_stress).
inline void draw_strength_scales(const Bonds& bonds, const Elements& elements,
                                 const View<int* [6]>& element_bonds,
                                 const View<const StrengthDistribution*>& laws,
                                 std::uint64_t seed) {
  Kokkos::parallel_for(
      "fracta::draw_strength_scales", Kokkos::RangePolicy<ExecSpace>(0, bonds.count),
      KOKKOS_LAMBDA(const int b) {
        const int cell = bonds.cells(b, 0) >= 0 ? bonds.cells(b, 0) : bonds.cells(b, 1);
        const StrengthDistribution law = laws(elements.material(cell));
        bonds.strength_scale(b) =
            law.factor(uniform_draw(seed, bond_key(bonds.nodes(b, 0), bonds.nodes(b, 1))));
      });
  Kokkos::parallel_for(
      "fracta::cell_inverse_strength_scales", Kokkos::RangePolicy<ExecSpace>(0, elements.count),
      KOKKOS_LAMBDA(const int e) {
        double smallest = 1.0;
        bool any = false;
        for (int a = 0; a < 6; ++a) {
          const int b = element_bonds(e, a);
          if (b < 0) continue;
          smallest = any ? min_(smallest, bonds.strength_scale(b)) : bonds.strength_scale(b);
          any = true;
        }
        elements.cell_inverse_strength_scale(e) = 1.0 / smallest;
      });
}

}  // namespace fracta
