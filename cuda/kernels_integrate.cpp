// CUDA check unit for src/kernels/integrate.hpp: both half kicks (HalfKick<true>, <false>) and
// the fused pair (KickKickDrift).
#include "kernels/integrate.hpp"

namespace fracta::cuda_check {

double integrate_kernels(const Nodes& nodes, double dt) {
  return kick_drift(nodes, dt) + kick(nodes, dt) + kick_kick_drift(nodes, dt, 0.5 * dt);
}

}  // namespace fracta::cuda_check
