// CUDA check unit for src/kernels/heterogeneity.hpp: the counter-based draws and the random
// bond-strength factors of every slot and cell.
#include "kernels/heterogeneity.hpp"

namespace fracta::cuda_check {

void heterogeneity_kernels(const Bonds& bonds, const Elements& elements,
                           const View<int* [6]>& element_bonds,
                           const View<const StrengthDistribution*>& laws) {
  draw_strength_scales(bonds, elements, element_bonds, laws, 1);
}

}  // namespace fracta::cuda_check
