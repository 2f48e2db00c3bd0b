// CUDA check unit for src/kernels/contact_forces.hpp: the contact force functor, with atomic
// adds and with the gather's stored pair forces.
#include "kernels/contact_forces.hpp"

namespace fracta::cuda_check {

double contact_forces_kernels(const Nodes& nodes, const View<const int*>& pair_i,
                              const View<const int*>& pair_j, const ContactGather& gather) {
  const long count = static_cast<long>(pair_i.extent(0));
  const ContactSums s = contact_forces(nodes, pair_i, pair_j, count, ContactLaw{}, 1e-7);
  const ContactSums t = contact_forces(nodes, pair_i, pair_j, count, ContactLaw{}, 1e-7, gather);
  return s.v[0] + s.v[1] + t.v[0];
}

}  // namespace fracta::cuda_check
