// Device state, one struct of views per entity (docs/physics.md 2). Units SI.
//
// Ordering invariants:
//  - Nodes: body by body (each body's nodes form one contiguous range), rows of the structured
//    mesh within a body. A node index never changes during a run.
//  - Elements: body by body, the mesh index never changes; `active` lists the indices of the
//    active (not converted) elements in increasing order.
//  - Quadrature points: element e owns points [e * qp_per_element, (e + 1) * qp_per_element).
//  - Bonds: the bond slots of the mesh, numbered at set-up (every element edge once and every
//    element diagonal, in runs of one direction: build_lattice); a slot is never moved or
//    removed, its `state` masks it. A slot's topology (ends, cells, reference length) is written
//    when one of its cells converts (fill_slot_topology), so that it costs memory only where the
//    lattice is.
//  - Particle views of Nodes are sized to the node count when the scene can have particles
//    (a de or adaptive body), and empty otherwise.
#pragma once
#include "kernels/compat.hpp"
#include "kernels/materials.hpp"

namespace fracta {

// How kernels add to shared nodes (kernels/scatter.hpp): atomically on GPUs (thousands of
// threads, fast atomics), by the chunks of a ScatterPlan on CPUs.
#ifdef FRACTA_DEVICE_PATH
inline constexpr bool kAtomicScatter = true;
#else
inline constexpr bool kAtomicScatter = false;
#endif

// The chunks and colours of a list of work items (kernels/scatter.hpp: build_scatter_plan,
// update_scatter_plan), held by the entity whose list it cuts (Elements, Bonds).
struct ScatterPlan {
  static constexpr int kMaxColors = 16;
  // Chunks cut the items' index space (element or bond slot indices), not the list: chunk c is
  // the items of index [c * chunk_size, (c + 1) * chunk_size), so its node interval and its
  // colour never change. A list (increasing indices: Elements::active, Bonds::used) only needs
  // the position where each chunk starts in it, chunk_begin (locate_scatter_chunks, after every
  // change of the list: a binary search per chunk).
  int chunk_size = 0;
  int chunks = 0;
  int universe = -1;    // the item count the chunks were cut from (-1: no plan)
  int item_count = -1;  // the list length chunk_begin was located for (-1: none)
  int colors = 0;       // 0: no plan (the kernels then add atomically)
  // The chunks of colour k, increasing in lo: color_chunks[color_offset[k], color_offset[k+1]).
  int color_offset[kMaxColors + 1] = {};
  View<int*> color_chunks;
  View<int*> chunk_begin_position;  // chunks + 1 entries; the last is item_count

  // The plan applies to a list of `count` items (else the kernels take the atomic path).
  bool usable(int count) const { return !kAtomicScatter && colors > 0 && item_count == count; }

  KOKKOS_INLINE_FUNCTION int chunk_begin(int chunk) const { return chunk_begin_position(chunk); }
  KOKKOS_INLINE_FUNCTION int chunk_end(int chunk) const { return chunk_begin_position(chunk + 1); }
};

// 2 pi: the volume of revolution of an axisymmetric area dA at radius r is 2 pi r dA.
inline constexpr double kTwoPi = 6.283185307179586;

enum FixedDof : int { kFixX = 1, kFixY = 2 };

struct Nodes {
  View<double* [2]> x0;  // reference position (m)
  View<double* [2]> x;   // current position (m)
  View<double* [2]> v;   // velocity (m/s); full step between steps, half step inside one
  // The half-step velocity averaged over about ten steps (filter_velocities, bond_forces.hpp):
  // the bonds' strain rates for rate-dependent strength. Empty view without a rate_dependence.
  View<double* [2]> v_filtered;
  View<double* [2]> f;      // internal + contact force (N), rebuilt every step
  View<double* [2]> f_ext;  // external force (N), rebuilt every step
  View<double*> mass;       // lumped mass (kg), constant
  View<int*> fixed;         // FixedDof bits
  int count = 0;
  // Particle (disc) state of a node (docs/physics.md 1.3); empty views when no body can convert.
  View<int*> particle;              // 1 if the node is a disc (a DE particle)
  View<int*> contact_disc;          // 1 if the node takes part in contact (disc or FE boundary)
  View<double*> radius;             // disc radius (m), half the cell size
  View<double*> inertia;            // polar moment m r^2 / 2 (kg m^2)
  View<double*> rotation;           // disc rotation (rad, counter-clockwise)
  View<double*> spin;               // angular velocity (rad/s)
  View<double*> moment;             // moment from bonds and contacts (N m), rebuilt every step
  View<double*> contact_stiffness;  // lambda k1 of the node's material (N/m), paper Eq. 7
  // The particles (particle(n) == 1) in increasing order, [0, particle_count): a node never
  // stops being a particle, so the conversion only inserts (conversion.hpp, update_lists).
  // Empty view when the scene has no lattice: kernels then sweep every node.
  View<int*> particle_list;
  int particle_count = 0;
  // 1 once a change of the node's bonds (a bond broke, its cell converted, a neighbour's radius
  // shrank) left its cached Gershgorin bound stale (bond_stable_dt, StableDtWorkspace); the
  // cache clears it. Empty view: no cache is kept.
  View<int*> bound_stale;
  bool has_particles() const { return particle.extent(0) > 0; }
  // Some node is a disc now (the particle views allocated and, where the list is kept, not
  // empty). Without one no moment is ever set (contacts and bonds give moments to discs
  // alone), so the kicks skip the rotations: an adaptive body before its first conversion
  // kicks as pure FE does.
  bool has_discs_now() const {
    return has_particles() && (particle_list.extent(0) == 0 || particle_count > 0);
  }
};

// The node views of the motion (x, v, f) and the count alone: for the kernels that need no
// more, or these and a few (kick_views). Each view a kernel's functor holds costs an atomic per
// host copy of it (for_each_chunk, scatter.hpp).
inline Nodes node_motion_views(const Nodes& nodes) {
  Nodes k;
  k.x = nodes.x;
  k.v = nodes.v;
  k.f = nodes.f;
  k.count = nodes.count;
  return k;
}

// The first index of the non-decreasing list [begin, end) whose entry is >= value (end if none).
template <class List>
KOKKOS_INLINE_FUNCTION int first_not_below(const List& list, int begin, int end, int value) {
  int lo = begin, hi = end;
  while (lo < hi) {
    const int mid = (lo + hi) / 2;
    if (list(mid) < value)
      lo = mid + 1;
    else
      hi = mid;
  }
  return lo;
}

// Number of entries of the non-decreasing list [0, count) that are < value (the first index
// whose entry is >= value).
template <class List>
KOKKOS_INLINE_FUNCTION int count_below(const List& list, int count, int value) {
  return first_not_below(list, 0, count, value);
}

// Sorts list[begin, end) increasing, in place (insertion sort: the segments are short bins and
// rows of a few entries, sorted so that no atomic counter decides an order).
template <class List>
KOKKOS_INLINE_FUNCTION void sort_segment(const List& list, int begin, int end) {
  for (int k = begin + 1; k < end; ++k) {
    const auto v = list(k);
    int m = k - 1;
    while (m >= begin && list(m) > v) {
      list(m + 1) = list(m);
      --m;
    }
    list(m + 1) = v;
  }
}

// Exclusive scan in place of the per-row counts in offset[0, n) into row starts offset[0, n]
// (n + 1 entries, the last one overwritten by the total); returns the total. The candidate
// rows of the pre-search, the contact gather's columns, an insertion's rows.
inline long scan_rows(const View<int*>& offset, int n) {
  long total = 0;
  Kokkos::parallel_scan(
      "fracta::contact_pair_scan", Kokkos::RangePolicy<ExecSpace>(0, n + 1),
      KOKKOS_LAMBDA(const int a, long& sum, const bool final) {
        const int count = a < n ? offset(a) : 0;
        if (final) offset(a) = static_cast<int>(sum);
        sum += count;
      },
      total);
  return total;
}

// Merges the disjoint increasing lists a[0, na) and b[0, nb) into out[0, na + nb), increasing:
// every entry finds its place by a binary search in the other list.
inline void merge_disjoint_sorted(const char* label, const View<int*>& a, int na,
                                  const View<int*>& b, int nb, const View<int*>& out) {
  Kokkos::parallel_for(
      label, Kokkos::RangePolicy<ExecSpace>(0, na + nb), KOKKOS_LAMBDA(const int k) {
        if (k < na) {
          const int v = a(k);
          out(k + count_below(b, nb, v)) = v;
        } else {
          const int v = b(k - na);
          out(k - na + count_below(a, na, v)) = v;
        }
      });
}

// Of a converted cell (compute_cell_stress): cracked once one of its bonds is broken or
// softening; intact cells are kCellBelowStrength when their stress is below the strength on every
// face by a bound (the bond kernel may then skip their bonds' failure check).
enum CellState : int { kCellCracked = 0, kCellIntact = 1, kCellBelowStrength = 2 };
enum BondState : int { kBondInactive = 0, kBondActive = 1, kBondBroken = 2 };
enum BondKind : int { kBondEdge = 0, kBondDiagonal = 1 };
// Bits of Bonds::run_next.
enum BondRunBits : unsigned char { kRunContinues = 1, kRunNormalOnly = 2 };

// Bond slots (docs/physics.md 1.2-1.3): springs between discs. Normal force fn (tension positive)
// along n = (xj - xi)/|xj - xi|; shear force fs along t = n rotated by +90 degrees. The force on
// disc i is fn n + fs t (on j the opposite); disc i receives the moment l_i fs, with l_i the
// distance from its centre to the contact point (l_i = r_i at the rest length).
struct Bonds {
  // Ends, cells and reference length: written when a cell of the slot converts
  // (fill_slot_topology) and never changed after; 0 before (read them for used slots only).
  View<int* [2]> nodes;
  View<int*> material;      // material of the elements that activated it
  View<int*> state;         // BondState
  View<double*> kn;         // normal stiffness (N/m), sum of element contributions
  View<double*> ks;         // shear stiffness (N/m)
  View<double*> length0;    // rest length (m)
  View<double*> area;       // effective area S (m^2): bond stress = force / S
  View<double*> fn;         // normal force (N), tension positive
  View<double*> fs;         // shear force (N)
  View<double*> plastic_n;  // plastic elongation (m) of the bilinear normal spring
  // Natural length of the normal spring, length0 + plastic_n (m), kept by every writer of
  // plastic_n: elastic springs read this one value instead of two (bond_forces.hpp). The same
  // view as length0 in a scene that neither converts nor yields (build_lattice).
  View<double*> rest_length;
  View<double*> plastic_s;     // plastic slip (m) of the bilinear shear spring
  View<double*> hardening;     // accumulated plastic displacement (m), isotropic hardening
  View<double*> plastic_work;  // cumulative (J)
  // Cohesive softening (material fracture_energy > 0; bond_forces.hpp): damage D in [0, 1) of
  // an active bond, its effective separation at the onset of softening (m; 0 = not
  // softening) and the one at which it is spent. The applied forces are (1 - D) times the undamaged
  // ones (normal: in tension).
  View<double*> damage;
  View<double*> onset_separation;
  View<double*> final_separation;  // effective separation at which it breaks (m)
  View<int* [2]> cells;            // converted cells whose face (edge) or body (diagonal) it is; -1
  // Strength factor w of each slot (kernels/heterogeneity.hpp): the bond reaches its strength at
  // w sigma_t and w c. Drawn once at set-up; empty view when no material has a Weibull modulus.
  View<double*> strength_scale;
  // Per slot b, built with the slots (build_lattice) from data that never change (not state):
  // kRunContinues where slot b + 1 continues a run of slot b (both ends one node on, each cell
  // side one cell on or none on both, the same kind, the cells all of one material), and
  // kRunNormalOnly where b is a diagonal (no shear spring). The CPU batches of a run read it
  // instead of the slots' ends, cells and materials (BondForces::batch).
  View<unsigned char*> run_next;
  // BondKind of slot b: diagonals are the slots without a shear spring (run_next).
  KOKKOS_INLINE_FUNCTION int kind(const int b) const {
    return (run_next(b) & kRunNormalOnly) ? kBondDiagonal : kBondEdge;
  }
  // Forces without atomics on CPUs: the chunks of the used list (or of every slot), coloured so
  // that no two chunks of a colour share a disc (kernels/scatter.hpp; update_scatter_plan after
  // every change of `used`).
  ScatterPlan scatter;
  int count = 0;
  // The slots ever activated (state != kBondInactive: active or broken) in increasing order,
  // [0, used_count): a slot is activated once and never returns to inactive, so the conversion
  // only inserts (conversion.hpp, update_lists). The bond kernels sweep this list instead of
  // every slot. Empty view when the model built no list: kernels then sweep every slot.
  View<int*> used;
  int used_count = 0;
  // Whether some bond law can yield (bilinear springs) or soften (cohesive): without one, the
  // plastic views (but plastic_n, which a conversion sets) or the cohesive views stay 0 for
  // the whole run, so the failure snapshot keeps no copy of them and the sweeps that only sum
  // them do not read them (their pages are then never touched).
  bool may_yield = true;
  bool may_soften = true;
  // The slots broken since the contact search last looked (ContactSystem): the contact list
  // leaves joined pairs out, and a break is what unjoins two discs between two searches, so the
  // search admits these pairs (neighbor_search.hpp, "Joined pairs"). broken_count may exceed
  // the capacity (the list is then rebuilt). Empty views: nobody listens.
  View<int*> broken_since_search;
  View<int> broken_count;
  KOKKOS_INLINE_FUNCTION void note_broken(const int b) const {
    if (broken_since_search.extent(0) == 0) return;
    const int k = Kokkos::atomic_fetch_add(&broken_count(), 1);
    if (k < static_cast<int>(broken_since_search.extent(0))) broken_since_search(k) = b;
  }
};

// The bond list the kernels sweep: Bonds::used when it is a proper subset of the slots, else
// every slot (a list of every slot is the identity).
inline bool bonds_listed(const Bonds& bonds) {
  return bonds.used.extent(0) > 0 && bonds.used_count < bonds.count;
}
inline int bond_list_count(const Bonds& bonds) {
  return bonds_listed(bonds) ? bonds.used_count : bonds.count;
}

// Who is joined to whom, for contact exclusion, and which bond slots a node has: node ->
// elements (CSR) and each element's corners and slots. Two discs joined by an active bond or by
// an active element never contact. Every bond slot is an edge or a diagonal of a lattice cell
// (build_lattice), so a node's slots are those of its cells that end at it: no node -> slot list.
struct Topology {
  View<int*> node_element_offset, node_element;  // elements of node n: [offset(n), offset(n+1))
  View<int*> element_alive;                      // 1 while the element is an active FE element
  View<int* [4]> element_nodes;                  // Elements::nodes
  View<int* [6]> element_slots;                  // Model::element_bonds (-1: none)
  View<int*> bond_state;

  // Most slots a node can have among its cells (4 cells of 3 slots at a node; duplicates
  // included: an edge is two cells' slot).
  static constexpr int kMaxNodeSlots = 12;

  // Slot position in element e (0..3 the edges a: corners a, a + 1; 4, 5 the diagonals d:
  // corners d, d + 2) joining its corners i and j; -1 when one is not a corner of e.
  KOKKOS_INLINE_FUNCTION int slot_position(const int e, const int i, const int j) const {
    int ai = -1, aj = -1;
    for (int a = 0; a < 4; ++a) {
      const int n = element_nodes(e, a);
      if (n == i) ai = a;
      if (n == j) aj = a;
    }
    if (ai < 0 || aj < 0 || ai == aj) return -1;
    const int step = (aj - ai + 4) % 4;
    return step == 2 ? 4 + ai % 2 : step == 1 ? ai : aj;
  }

  // The bond slots of node n, increasing and without repeats, into `slots`; returns how many.
  KOKKOS_INLINE_FUNCTION int node_slots(const int n, int (&slots)[kMaxNodeSlots]) const {
    int count = 0;
    for (int k = node_element_offset(n); k < node_element_offset(n + 1); ++k) {
      const int e = node_element(k);
      int a = 0;
      while (a < 4 && element_nodes(e, a) != n) ++a;
      const int at_node[3] = {a, (a + 3) % 4, 4 + a % 2};  // the edges from and to n, its diagonal
      for (const int position : at_node) {
        const int b = element_slots(e, position);
        if (b < 0) continue;
        int m = count;
        bool repeat = false;
        for (int q = 0; q < count; ++q) repeat = repeat || slots[q] == b;
        if (repeat || count == kMaxNodeSlots) continue;
        while (m > 0 && slots[m - 1] > b) {
          slots[m] = slots[m - 1];
          --m;
        }
        slots[m] = b;
        ++count;
      }
    }
    return count;
  }

  // Whether nodes i and j are joined: an active bond or an active element between them (false
  // for an empty topology: free discs).
  KOKKOS_INLINE_FUNCTION bool joined(int i, int j) const {
    if (node_element_offset.extent(0) == 0) return false;
    for (int k = node_element_offset(i); k < node_element_offset(i + 1); ++k) {
      const int e = node_element(k);
      const int position = slot_position(e, i, j);
      if (position < 0) continue;
      if (element_alive(e)) return true;
      const int b = element_slots(e, position);
      if (b >= 0 && bond_state(b) == kBondActive) return true;
    }
    return false;
  }
};

// Columns of Elements::cell_hoop: the hoop strain offset at conversion (E_tt less the elastic
// hoop strain), w = sigma_tt / M of the last evaluation, the damage d, and the largest w reached.
// (An enum, as the other columns and states: nvcc takes its values into device lambdas.)
enum HoopColumn : int { kHoopOffset = 0, kHoopStrain = 1, kHoopDamage = 2, kHoopLargest = 3 };

struct Elements {
  View<int* [4]> nodes;  // counter-clockwise
  View<int*> material;   // index into the MaterialLaw table
  View<int*> body;
  View<int*> active;  // active element indices, increasing
  View<int*> alive;   // 1 while the element is an active FE element (per mesh element)
  View<int*> rigid;   // elements of rigid bodies (no forces; frames show them after the active)
  // Converted cells (the lattice): continuum stress from the discs' motion, for bond failure.
  View<double* [3]> cell_stress;  // Pa: xx, yy, xy (reference frame)
  View<int*> cell_state;          // CellState of the last cell stress (compute_cell_stress)
  View<int*> cell_cracked;        // 1 once a bond of the cell broke or started to soften, for good
  // Strain beyond the elastic part at conversion; empty where nothing converts (build_lattice),
  // so read through strain_offset.
  View<double* [3]> cell_strain_offset;
  // 1 / the smallest strength factor of each cell's bonds (Bonds::strength_scale), by which the
  // cell stress's bound scales the stress (a product, not a division, every step); empty view
  // with the bonds'.
  View<double*> cell_inverse_strength_scale;
  // Volumetric strain tr(eps) of each intact converted cell at its last evaluation, for the cell
  // term of lattices beyond the pair lattice's Poisson limit (cell_forces.hpp); 0 for other
  // elements and once the cell cracked. Empty view when no material has the term.
  View<double*> cell_volumetric_strain;
  // Hoop state of each converted cell of an axisymmetric lattice (cell_forces.hpp, HoopLaw), by
  // the kHoop* columns; empty view for plane lattices.
  View<double* [4]> cell_hoop;
  // The chunks of every mesh element for the cell term's scatter (kernels/scatter.hpp; located
  // in no list: the kernel skips what is not an intact converted cell). Empty with the view above.
  ScatterPlan cell_scatter;
  // Converted cells in each chunk of cell_scatter (count_cell_chunks, cell_forces.hpp): the
  // kernel skips a chunk with none. Empty with cell_scatter's chunks (and on GPUs, where the
  // kernel runs over the converted list).
  View<int*> cell_chunk_cells;
  int count = 0;  // all elements of the mesh
  int active_count = 0;
  int rigid_count = 0;
  int qp_per_element = 1;  // 1 (reduced + hourglass control) or 4 (2x2 Gauss)
  // Per quadrature point.
  ColumnView<double* [4]> stress;  // Cauchy stress (Pa): xx, yy, zz, xy
  View<double*> epeq;              // equivalent plastic strain (paper Eq. 13)
  View<double*> qp_volume;         // current volume (m^3) the point represents
  View<double*> bulk_viscosity;    // last artificial viscous pressure q (Pa)
  // State of laws that keep one beyond stress and epeq (materials.hpp, kLawStateSize values:
  // HjcState, JohnsonCookState); empty when no material has one.
  View<double* [3]> law_state;
  // Per element.
  ColumnView<double* [2]> hourglass_disp;   // stiffness-form hourglass generalized displacement (m)
  ColumnView<double* [2]> hourglass_force;  // last generalized hourglass force (N)
  // Cumulative stress work less plastic dissipation (J): the energy the element holds, which the
  // conversion hands to the bonds. The dissipation (plastic, hourglass, bulk viscosity) is
  // summed per step over all elements (FeStepSums), not kept per element.
  View<double*> recoverable_work;
  // sum b.b of each element's reference centre gradients (1/m^2), for the distortion criterion
  // of adaptive conversion (ConversionCriterion); empty when no body is adaptive.
  View<double*> reference_gradient_norm2;
  // Dynamic increase factor of the tension cut-off in each element's last update (mohr_coulomb
  // with a rate_dependence table: FeForces; read by ConversionCriterion); empty: none.
  View<double*> tension_factor;
  // Nodal forces without atomics on CPUs: the chunks of the active list, coloured so that no
  // two chunks of a colour share a node (kernels/scatter.hpp; update_scatter_plan after every
  // change of `active`). The fixed chunks make the FE forces independent of the thread count.
  ScatterPlan scatter;

  // Component k of cell e's strain offset: 0 where nothing converts (an empty view), so the
  // strain less it is the same to the bit.
  KOKKOS_INLINE_FUNCTION double strain_offset(const int e, const int k) const {
    return cell_strain_offset.extent(0) > 0 ? cell_strain_offset(e, k) : 0.0;
  }
};

// Piecewise-linear load tables, one per load, flattened: entries [offset[k], offset[k+1]).
struct LoadTables {
  View<double*> time;
  View<double*> value;
  View<int*> offset;
  int count = 0;
};

// Pressure (or traction) acting on boundary edges: node a -> node b in the element's
// counter-clockwise order, so the outward normal times the edge length is (dy, -dx).
struct PressureEdges {
  View<int* [2]> nodes;
  View<int*> load;
  View<double* [2]> direction;  // (0, 0): pressure along the inward normal; else a traction
  int count = 0;
};

// Concentrated forces on node sets: each entry carries a share of its load's total force.
struct NodalForces {
  View<int*> node;
  View<int*> load;
  View<double* [2]> force_per_unit;  // direction * share (N per unit table value)
  int count = 0;
};

// The same tables in host memory, for the host's own reads (a bar's incident velocity).
struct HostLoadTables {
  View<double*>::HostMirror time, value;
  View<int*>::HostMirror offset;
  int count = 0;
};

inline HostLoadTables host_copy(const LoadTables& t) {
  HostLoadTables h{Kokkos::create_mirror_view(t.time), Kokkos::create_mirror_view(t.value),
                   Kokkos::create_mirror_view(t.offset), t.count};
  Kokkos::deep_copy(h.time, t.time);
  Kokkos::deep_copy(h.value, t.value);
  Kokkos::deep_copy(h.offset, t.offset);
  return h;
}

// Table k at `time`: piecewise linear, its first value before and its last after (LoadTables or
// HostLoadTables).
template <class Tables>
KOKKOS_INLINE_FUNCTION double table_value(const Tables& t, int k, double time) {
  const int begin = t.offset(k), end = t.offset(k + 1);
  if (time <= t.time(begin)) return t.value(begin);
  for (int i = begin + 1; i < end; ++i) {
    if (time <= t.time(i)) {
      const double t0 = t.time(i - 1), t1 = t.time(i);
      // A repeated time is a jump: take the value after it once time passes it.
      if (t1 <= t0) return t.value(i);
      const double w = (time - t0) / (t1 - t0);
      return (1.0 - w) * t.value(i - 1) + w * t.value(i);
    }
  }
  return t.value(end - 1);
}

// Small fixed-size sum for parallel_reduce (works with Kokkos 3.4 and 4.x).
template <int N>
struct Sums {
  double v[N];
  KOKKOS_INLINE_FUNCTION Sums() {
    for (int i = 0; i < N; ++i) v[i] = 0.0;
  }
  KOKKOS_INLINE_FUNCTION Sums& operator+=(const Sums& o) {
    for (int i = 0; i < N; ++i) v[i] += o.v[i];
    return *this;
  }
  KOKKOS_INLINE_FUNCTION void operator+=(const volatile Sums& o) volatile {
    for (int i = 0; i < N; ++i) v[i] += o.v[i];
  }
};

// Where a reduction leaves its result when the host is not to wait for it: an unmanaged view of
// one member of a struct in the execution space's memory (the step's sums, which the host copies
// once per step: Simulation::settle_step_sums). A launch that reduces into a slot is queued like a
// parallel_for; one that reduces into a host value makes the host wait for the device (a round
// trip on a GPU). An empty slot: reduce into the host value, as before.
template <class T>
using ResultSlot = Kokkos::View<T, MemSpace, Kokkos::MemoryUnmanaged>;

// The label of a launch that reduces into a slot: its kernel's name and kSlotLabel, so that the
// profiling tools tell it from one the host waits for (bench/region_timer.hpp counts them apart).
constexpr const char* kSlotLabel = " [slot]";
inline std::string slot_label(const char* name) {
  return std::string(name) + kSlotLabel;
}

// Stores a value the host holds into a slot: a plain store where the host reaches the slot's
// memory (CPU builds, whose chunked reductions end on the host), a copy otherwise.
template <class T>
inline void put(const ResultSlot<T>& slot, const T& value) {
  if constexpr (Kokkos::SpaceAccessibility<HostSpace, MemSpace>::accessible) {
    *slot.data() = value;
  } else {
    Kokkos::deep_copy(slot, Kokkos::View<const T, HostSpace, Kokkos::MemoryUnmanaged>(&value));
  }
}

}  // namespace fracta

namespace Kokkos {
template <int N>
struct reduction_identity<fracta::Sums<N>> {
  KOKKOS_FORCEINLINE_FUNCTION static fracta::Sums<N> sum() { return fracta::Sums<N>(); }
};
}  // namespace Kokkos
