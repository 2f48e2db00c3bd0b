// CUDA check unit for src/kernels/frame.hpp: counting and packing a frame's arrays into
// caller-owned device memory.
#include "kernels/frame.hpp"

namespace fracta::cuda_check {

std::size_t frame_kernels(const Nodes& nodes, const Elements& elements, const Bonds& bonds,
                          const View<double*>& reals, const View<int*>& ints) {
  const FrameCounts c = count_frame(nodes, elements, bonds);
  FrameViews v;
  v.node_position = v.node_displacement = v.node_velocity =
      FrameArray<double>(reals.data(), 2 * c.nodes);
  v.element_stress = FrameArray<double>(reals.data(), 4 * c.elements);
  v.element_plastic_strain = v.element_pressure = v.element_von_mises =
      FrameArray<double>(reals.data(), c.elements);
  v.particle_radius = v.particle_rotation = v.particle_spin =
      FrameArray<double>(reals.data(), c.discs);
  v.bond_normal_force = v.bond_damage = FrameArray<double>(reals.data(), c.bonds);
  v.element_nodes = FrameArray<int>(ints.data(), 4 * c.elements);
  v.element_id = v.element_body = FrameArray<int>(ints.data(), c.elements);
  v.particle_node = FrameArray<int>(ints.data(), c.discs);
  v.bond_nodes = FrameArray<int>(ints.data(), 2 * c.bonds);
  v.bond_state = FrameArray<int>(ints.data(), c.bonds);
  pack_frame(nodes, elements, bonds, v);
  return static_cast<std::size_t>(c.nodes + c.elements + c.discs + c.bonds);
}

}  // namespace fracta::cuda_check
