// CUDA check unit for src/kernels/conversion.hpp: element-to-disc conversion (compaction,
// slot topology, prestress, bond activation, re-basing) and the lattice helpers on the device.
#include "kernels/conversion.hpp"

namespace fracta::cuda_check {

double conversion_kernels(Elements& elements, const Nodes& nodes, const Bonds& bonds,
                          const View<const int*>& adaptive,
                          const View<const MaterialLaw*>& materials,
                          const View<int* [6]>& element_bonds, const View<int*>& new_cells,
                          View<int*>& active_scratch, const Topology& topology,
                          const View<double*>& out) {
  const Elements el = elements;
  Kokkos::parallel_for(
      "fracta::cuda_check_lattice", Kokkos::RangePolicy<ExecSpace>(0, out.extent(0)),
      KOKKOS_LAMBDA(const int e) {
        const LatticeStiffness s = lattice_stiffness(2e11, 0.3, e % 2 == 0, 0.01);
        double green[3];
        cell_green_lagrange(el, nodes, e, green);
        const double x[4] = {0.0, 1e-3, 1e-3, 0.0}, y[4] = {0.0, 0.0, 2e-4, 1e-3};
        out(e) =
            s.k1 + s.k2 + s.ks + s.kv + green[0] + (length_ratio_below(x, y, 2e6, 0.3) ? 1.0 : 0.0);
      });
  View<LatticeStiffness*> stiffness("fracta::cuda_check_stiffness", 1);
  const View<const LatticeStiffness*> stiffness_c = stiffness;
  const int n =
      compact_converted(elements, adaptive, materials, true, new_cells, active_scratch, nodes.x);
  // The conversion from candidates, and the lists it keeps.
  ListWorkspace ws(bonds.count > nodes.count ? bonds.count : nodes.count);
  const int m = compact_candidates(elements, adaptive, materials, true, ws.bond_candidates, 8,
                                   ws.keep, ws.sorted, new_cells, active_scratch, nodes.x);
  fill_slot_topology(new_cells, n, topology, nodes, bonds);
  fill_slot_topology(new_cells, 0, topology, nodes, bonds, true);
  collect_new_bonds(new_cells, n, element_bonds, bonds, ws.bond_candidates);
  collect_new_particles(new_cells, n, elements, nodes, ws.particle_candidates);
  const double energy = prestress_converted_bonds(new_cells, n, element_bonds, stiffness_c,
                                                  elements, nodes, bonds, topology, 1e-9);
  activate_element_bonds(new_cells, n, element_bonds, stiffness_c, elements, nodes, bonds);
  finish_converted_bonds(new_cells, n, element_bonds, nodes, bonds);
  const int used = insert_sorted(bonds.used, bonds.used_count, ws.bond_candidates, 6 * n, ws);
  const int particles =
      insert_sorted(nodes.particle_list, nodes.particle_count, ws.particle_candidates, 4 * n, ws) +
      build_particle_list(nodes);
  return energy + m + used + particles;
}

}  // namespace fracta::cuda_check
