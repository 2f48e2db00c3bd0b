// CUDA check unit for src/kernels/frame.hpp: the packing of a frame's arrays.
#include "kernels/frame.hpp"

namespace fracta::cuda_check {

std::size_t frame_kernels(const Nodes& nodes, const Elements& elements, const Bonds& bonds) {
  const FrameViews f = pack_frame(nodes, elements, bonds);
  return f.node_position.extent(0) + f.element_nodes.extent(0) + f.bond_damage.extent(0);
}

}  // namespace fracta::cuda_check
