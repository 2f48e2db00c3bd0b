// CUDA check unit for src/kernels/contact_forces.hpp: the contact force functor.
#include "kernels/contact_forces.hpp"

namespace fracta::cuda_check {

double contact_forces_kernels(const Nodes& nodes, const Topology& topo,
                              const View<const int*>& pair_i, const View<const int*>& pair_j) {
  const ContactSums s = contact_forces(nodes, topo, pair_i, pair_j,
                                       static_cast<long>(pair_i.extent(0)), ContactLaw{}, 1e-7);
  return s.v[0] + s.v[1];
}

}  // namespace fracta::cuda_check
