// CUDA check unit for src/kernels/loads.hpp: pressure/traction edges and nodal forces.
#include "kernels/loads.hpp"

namespace fracta::cuda_check {

void loads_kernels(const Nodes& nodes, const LoadTables& tables, const PressureEdges& edges,
                   const NodalForces& forces) {
  apply_loads(nodes, tables, edges, forces, 0.01, false, 1e-6);
  apply_loads(nodes, tables, edges, forces, 0.01, true, 1e-6);
}

}  // namespace fracta::cuda_check
