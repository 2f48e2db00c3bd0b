// The state a frame shows, packed into flat arrays (docs/output.md, /frames): the output's
// gathering phase. Packing on the host item by item took 0.8 s a frame at 10^6 nodes, more than
// writing the frame; these kernels are parallel and the host at most copies.
#pragma once
#include <Kokkos_Core.hpp>

#include "kernels/compat.hpp"
#include "kernels/state.hpp"

namespace fracta {

// The arrays a frame's packing writes: memory the caller owns (the frame's host vectors where
// the kernels run on the host, reused device buffers otherwise), so that a frame allocates
// nothing once the arrays have their size: at 10^6 nodes the page faults of fresh arrays cost
// as much as the packing.
template <class T>
using FrameArray = Kokkos::View<T*, ExecSpace::memory_space, Kokkos::MemoryUnmanaged>;

// How many items each kind of array holds (count_frame), for sizing the arrays.
struct FrameCounts {
  int nodes = 0, elements = 0, discs = 0, bonds = 0;
};

// One frame's arrays, in the layout of the output file: node arrays 2 values per node (x, y),
// element arrays one row per active element in list order, then one per element of the rigid
// bodies (zero stress) (connectivity 4, stress 4: xx, yy,
// zz, xy, averaged over the quadrature points), disc arrays one entry per disc in node order,
// bond arrays one row per bond slot that is or was active, in slot order. Units SI (m, m/s, Pa).
struct FrameViews {
  FrameArray<double> node_position, node_displacement, node_velocity;              // 2 * nodes
  FrameArray<int> element_nodes;                                                   // 4 * elements
  FrameArray<int> element_id, element_body;                                        // elements
  FrameArray<double> element_stress;                                               // 4 * elements
  FrameArray<double> element_plastic_strain, element_pressure, element_von_mises;  // elements
  FrameArray<int> particle_node;                                                   // discs
  FrameArray<double> particle_radius, particle_rotation, particle_spin;            // discs
  FrameArray<int> bond_nodes;                                                      // 2 * bonds
  FrameArray<int> bond_state;                                                      // bonds
  FrameArray<double> bond_normal_force, bond_damage;  // bonds; damage 1 once broken
};

inline FrameCounts count_frame(const Nodes& nodes, const Elements& elements, const Bonds& bonds) {
  FrameCounts c;
  c.nodes = nodes.count;
  c.elements = elements.active_count + elements.rigid_count;
  if (!nodes.has_particles()) return c;
  const auto particle = nodes.particle;
  Kokkos::parallel_reduce(
      "fracta::frame_count_discs", Kokkos::RangePolicy<ExecSpace>(0, nodes.count),
      KOKKOS_LAMBDA(const int i, int& sum) { sum += particle(i) ? 1 : 0; }, c.discs);
  // The used list holds the slots that are not inactive (state.hpp), so it is the count; a scan
  // of every slot's state would also commit the pages of the slots no cell converted.
  if (bonds_listed(bonds)) {
    c.bonds = bonds.used_count;
    return c;
  }
  const auto state = bonds.state;
  Kokkos::parallel_reduce(
      "fracta::frame_count_bonds", Kokkos::RangePolicy<ExecSpace>(0, bonds.count),
      KOKKOS_LAMBDA(const int b, int& sum) { sum += state(b) != kBondInactive ? 1 : 0; }, c.bonds);
  return c;
}

// Packs `nodes`, the active `elements` and the discs and bonds into `out`, sized for
// count_frame's counts of the same state.
inline void pack_frame(const Nodes& nodes, const Elements& elements, const Bonds& bonds,
                       const FrameViews& out) {
  {
    const auto x = nodes.x, x0 = nodes.x0, v = nodes.v;
    Kokkos::parallel_for(
        "fracta::frame_nodes", Kokkos::RangePolicy<ExecSpace>(0, nodes.count),
        KOKKOS_LAMBDA(const int i) {
          for (int d = 0; d < 2; ++d) {
            out.node_position(2 * i + d) = x(i, d);
            out.node_displacement(2 * i + d) = x(i, d) - x0(i, d);
            out.node_velocity(2 * i + d) = v(i, d);
          }
        });
  }
  {
    const auto active = elements.active, rigid = elements.rigid, body = elements.body;
    const auto connectivity = elements.nodes;
    const auto stress = elements.stress;
    const auto epeq = elements.epeq;
    const int qp = elements.qp_per_element, active_count = elements.active_count;
    Kokkos::parallel_for(
        "fracta::frame_elements",
        Kokkos::RangePolicy<ExecSpace>(0, active_count + elements.rigid_count),
        KOKKOS_LAMBDA(const int i) {
          // A rigid body's elements compute no stress: theirs stays zero.
          const int e = i < active_count ? active(i) : rigid(i - active_count);
          double s[4] = {0, 0, 0, 0}, plastic = 0;
          for (int g = 0; g < qp; ++g) {
            for (int k = 0; k < 4; ++k) s[k] += stress(e * qp + g, k) / qp;
            plastic += epeq(e * qp + g) / qp;
          }
          for (int k = 0; k < 4; ++k) {
            out.element_nodes(4 * i + k) = connectivity(e, k);
            out.element_stress(4 * i + k) = s[k];
          }
          out.element_id(i) = e;
          out.element_body(i) = body(e);
          out.element_plastic_strain(i) = plastic;
          out.element_pressure(i) = -(s[0] + s[1] + s[2]) / 3.0;
          // von Mises stress of the 3-D state (szz included): sqrt(3 J2).
          out.element_von_mises(i) =
              sqrt_(0.5 * ((s[0] - s[1]) * (s[0] - s[1]) + (s[1] - s[2]) * (s[1] - s[2]) +
                           (s[2] - s[0]) * (s[2] - s[0])) +
                    3.0 * s[3] * s[3]);
        });
  }
  if (!nodes.has_particles()) return;
  // Discs in node order and bonds in slot order: a scan numbers the items kept.
  {
    const auto particle = nodes.particle;
    const auto radius = nodes.radius, rotation = nodes.rotation, spin = nodes.spin;
    Kokkos::parallel_scan(
        "fracta::frame_discs", Kokkos::RangePolicy<ExecSpace>(0, nodes.count),
        KOKKOS_LAMBDA(const int i, int& k, const bool final) {
          if (!particle(i)) return;
          if (final) {
            out.particle_node(k) = i;
            out.particle_radius(k) = radius(i);
            out.particle_rotation(k) = rotation(i);
            out.particle_spin(k) = spin(i);
          }
          ++k;
        });
  }
  {
    const auto state = bonds.state;
    const auto ends = bonds.nodes;
    const auto fn = bonds.fn, damage = bonds.damage;
    const bool softens = bonds.may_soften;  // else every damage is 0
    // The used slots (in increasing order, as a sweep of every slot finds them) when listed.
    const auto used = bonds_listed(bonds) ? bonds.used : View<int*>();
    const bool listed = used.extent(0) > 0;
    Kokkos::parallel_scan(
        "fracta::frame_bonds", Kokkos::RangePolicy<ExecSpace>(0, bond_list_count(bonds)),
        KOKKOS_LAMBDA(const int position, int& k, const bool final) {
          const int b = listed ? used(position) : position;
          if (state(b) == kBondInactive) return;
          if (final) {
            out.bond_nodes(2 * k) = ends(b, 0);
            out.bond_nodes(2 * k + 1) = ends(b, 1);
            out.bond_state(k) = state(b);
            out.bond_normal_force(k) = fn(b);
            out.bond_damage(k) = state(b) == kBondBroken ? 1.0 : softens ? damage(b) : 0.0;
          }
          ++k;
        });
  }
}

}  // namespace fracta
