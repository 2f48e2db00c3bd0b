// CUDA check unit for src/kernels/fragments.hpp: union-find labelling and the per-fragment
// sums (both fragment_statistics overloads), plus the host-only mass distribution.
#include "kernels/fragments.hpp"

namespace fracta::cuda_check {

double fragments_kernels(const Nodes& nodes, const Elements& elements, const Bonds& bonds,
                         const View<int*>& labels) {
  label_fragments(nodes.count, elements, bonds, labels);
  const FragmentWorkspace ws(nodes.count, labels);
  const FragmentStats a = fragment_statistics(nodes, elements, bonds, ws);
  const FragmentStats b = fragment_statistics(nodes, elements, bonds, labels);
  const MassDistribution d = mass_distribution(a, 8);
  return a.total_mass + b.largest_mass + d.cumulative.back();
}

}  // namespace fracta::cuda_check
