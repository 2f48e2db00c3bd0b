// CUDA check unit for src/kernels/contact_forces.hpp: the contact force functor.
#include "kernels/contact_forces.hpp"

namespace fracta::cuda_check {

double contact_forces_kernels(const Nodes& nodes, const Topology& topo,
                              const View<const int*>& pair_i, const View<const int*>& pair_j) {
  const long count = static_cast<long>(pair_i.extent(0));
  const ContactSums s = contact_forces(nodes, topo, pair_i, pair_j, count, ContactLaw{}, 1e-7);
  // With the pairs' joining slots and elements.
  const View<int* [3]> joins("fracta::cuda_check_joins", count);
  pair_topology(topo, pair_i, pair_j, count, joins);
  const ContactSums t =
      contact_forces(nodes, topo, pair_i, pair_j, count, ContactLaw{}, 1e-7, joins);
  return s.v[0] + s.v[1] + t.v[0];
}

}  // namespace fracta::cuda_check
