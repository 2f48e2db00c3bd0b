// CUDA check unit for src/kernels/rigid.hpp: the rigid-body projection and drift kernels.
#include "kernels/rigid.hpp"

namespace fracta::cuda_check {

void rigid_kernels(RigidBody& body, const Nodes& nodes, const View<double* [2]>& offset) {
  project_rigid(body, nodes);  // also write_rigid_velocity
  drift_rigid(body, nodes, offset, 1e-7);
  write_rigid_velocity(body, nodes);
}

}  // namespace fracta::cuda_check
