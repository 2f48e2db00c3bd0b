// CUDA check unit for src/kernels/energy.hpp: every energy and momentum reduction.
#include "kernels/energy.hpp"

namespace fracta::cuda_check {

double energy_kernels(const Nodes& nodes, const Bonds& bonds, const Elements& elements,
                      const Topology& topology) {
  const NodeTotals n = node_totals(nodes, 1e-7);
  const LatticeTotals l = lattice_totals(nodes, bonds, 1e-7);
  const ElementTotals e = element_totals(elements);
  const Sums<5> b = body_sums(nodes, 0, nodes.count);
  const long composite = composite_count(nodes, topology);
  return n.kinetic + l.bond_elastic + e.internal + b.v[0] + static_cast<double>(composite);
}

}  // namespace fracta::cuda_check
