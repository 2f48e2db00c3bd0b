// CUDA check unit for src/kernels/integrate.hpp: both half kicks (HalfKick<true>, <false>).
#include "kernels/integrate.hpp"

namespace fracta::cuda_check {

double integrate_kernels(const Nodes& nodes, double dt) {
  return kick_drift(nodes, dt) + kick(nodes, dt);
}

}  // namespace fracta::cuda_check
