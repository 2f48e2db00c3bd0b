// CUDA check unit for src/kernels/boundaries.hpp: prescribed velocities, unilateral supports,
// bar faces and the reaction of a node set.
#include "kernels/boundaries.hpp"

namespace fracta::cuda_check {

double boundaries_kernels(const Nodes& nodes, const PrescribedDofs& dofs,
                          const SupportDofs& supports, const LoadTables& tables,
                          const View<int*>& set, const View<int* [2]>& set_tables) {
  double work = prescribed_work(nodes, dofs, tables, 1e-6, 1e-7, true);
  prescribe(nodes, dofs, tables, 1e-6, 1e-7);
  work += update_supports(nodes, supports, 1e-7);
  work += catch_force_sum(supports, 0, supports.count);
  const FaceTotals face = face_totals(nodes, set, 1.0, 0.0);
  push_face(nodes, set, face.force / face.mass, 1.0, 0.0);
  const SetReaction reaction = set_reaction(nodes, set, set_tables, tables, 1e-6);
  return work + face.momentum + reaction.fx + reaction.vy;
}

}  // namespace fracta::cuda_check
