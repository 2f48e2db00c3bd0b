// Fragment statistics (docs/physics.md 1.3): connected components of the mesh nodes over intact
// bonds and alive elements, with their count, masses and sizes.
//
// Convention
//  - The graph's vertices are ALL mesh nodes [0, nodes.count). Two nodes are joined when an
//    ACTIVE bond (state == kBondActive) links them or when both are corners of one ALIVE element
//    (elements.alive(e) == 1, an active FE element; all 4 corners are joined). Inactive and broken
//    bond slots and converted elements join nothing.
//  - A node joined to nothing (a disc whose bonds are all broken, flying alone) is a fragment of
//    1 node. An intact body is 1 fragment; separate bodies are separate fragments.
//  - Labels are canonical: label(i) = smallest node id of i's fragment. They do not depend on
//    thread count, scheduling or backend.
//  - Fragment mass = sum of nodes.mass over its nodes (the node mass never changes, docs/physics.md
//    1.3, so the fragment masses always add up to the model's mass). Counts, sizes and labels
//    are exact; a mass is a sum in an unspecified (atomic) order, i.e. reproducible to
//    round-off (~1e-16 relative).
//
// Algorithm: lock-free union-find in the ECL-CC style (Jaiganesh & Burtscher, HPDC 2018).
// parent(i) starts at i; every edge (u, v) finds both roots (with intermediate pointer jumping)
// and hooks the LARGER root under the smaller one with a compare-and-swap, retrying from the
// winner when another thread got there first. The invariant parent(i) <= i makes every root the
// smallest id of its tree, hence the canonical labels. One pass over bonds + elements, one
// flattening pass, then a scan numbers the roots and atomics sum mass and node count per
// fragment; only the per-fragment totals (count entries) are copied to the host.
//
// Reads only nodes.count, nodes.mass, elements.count, elements.nodes, elements.alive,
// bonds.count, bonds.used, bonds.nodes, bonds.state (empty Bonds or Elements are fine).
#pragma once
#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>
#include <vector>

#include "kernels/compat.hpp"
#include "kernels/state.hpp"

namespace fracta {

// Host result of fragment_statistics.
struct FragmentStats {
  long count = 0;              // number of fragments (isolated nodes included)
  double largest_mass = 0.0;   // kg (masses[0]; 0 for a model without nodes)
  double total_mass = 0.0;     // kg, sum of all fragment masses
  std::vector<double> masses;  // kg, one per fragment, sorted descending
  std::vector<long> sizes;     // node count of the fragment masses[k] (same order)
};

// Device workspace, sized for n nodes; reuse it across calls to avoid allocations.
struct FragmentWorkspace {
  View<int*> labels;   // per node: canonical fragment label (smallest node id of the fragment)
  View<int*> index;    // per node: at roots, the fragment's number (roots in increasing id order)
  View<double*> mass;  // per fragment number
  View<int*> size;     // per fragment number
  FragmentWorkspace() = default;
  explicit FragmentWorkspace(int n, View<int*> labels_view = View<int*>())
      : labels(labels_view.extent(0) >= static_cast<size_t>(n)
                   ? labels_view
                   : View<int*>(Kokkos::ViewAllocateWithoutInitializing("fracta::fragment_labels"),
                                n)),
        index(Kokkos::ViewAllocateWithoutInitializing("fracta::fragment_index"), n),
        mass(Kokkos::ViewAllocateWithoutInitializing("fracta::fragment_mass"), n),
        size(Kokkos::ViewAllocateWithoutInitializing("fracta::fragment_size"), n) {}
};

namespace detail {

using AtomicIntView = Kokkos::View<int*, MemSpace, Kokkos::MemoryTraits<Kokkos::Atomic>>;

// Root of v, halving the path on the way (each visited node is pointed to its grandparent).
// Other threads may hook roots meanwhile; every write stores an ancestor, so it is benign.
KOKKOS_INLINE_FUNCTION int find_root(const AtomicIntView& parent, int v) {
  int par = parent(v);
  if (par != v) {
    int prev = v;
    int next = parent(par);
    while (par > next) {  // par is not a root (a root is its own parent; parent(i) <= i)
      parent(prev) = next;
      prev = par;
      par = next;
      next = parent(par);
    }
  }
  return par;
}

// Joins the trees of u and v: the larger root is hooked under the smaller one.
KOKKOS_INLINE_FUNCTION void unite(const AtomicIntView& parent, const View<int*>& raw, int u,
                                  int v) {
  int ru = find_root(parent, u);
  int rv = find_root(parent, v);
  while (ru != rv) {
    if (ru > rv) {
      const int old = Kokkos::atomic_compare_exchange(&raw(ru), ru, rv);
      if (old == ru) return;
      ru = find_root(parent, old);  // ru was hooked by another thread: go on from there
    } else {
      const int old = Kokkos::atomic_compare_exchange(&raw(rv), rv, ru);
      if (old == rv) return;
      rv = find_root(parent, old);
    }
  }
}

}  // namespace detail

// Device labelling only: labels(i) = smallest node id of i's fragment, for i < node_count.
inline void label_fragments(int node_count, const Elements& elements, const Bonds& bonds,
                            const View<int*>& labels) {
  if (labels.extent(0) < static_cast<size_t>(node_count))
    throw std::invalid_argument("label_fragments: labels workspace has " +
                                std::to_string(labels.extent(0)) + " entries for " +
                                std::to_string(node_count) + " nodes");
  if (node_count == 0) return;
  const View<int*> raw = labels;
  const detail::AtomicIntView parent = labels;
  Kokkos::parallel_for(
      "fracta::fragments_init", Kokkos::RangePolicy<ExecSpace>(0, node_count),
      KOKKOS_LAMBDA(const int i) { raw(i) = i; });
  // One pass over bond slots and elements (bonds first in the range).
  // The used slots alone when listed (the others are inactive): a sweep of every slot's state
  // would commit the pages of the slots no cell converted.
  const int nb = bond_list_count(bonds), ne = elements.count;
  const View<int*> used = bonds_listed(bonds) ? bonds.used : View<int*>();
  const bool listed = used.extent(0) > 0;
  const View<int* [2]> bond_nodes = bonds.nodes;
  const View<int*> bond_state = bonds.state;
  const View<int* [4]> element_nodes = elements.nodes;
  const View<int*> alive = elements.alive;
  if (nb + ne > 0) {
    Kokkos::parallel_for(
        "fracta::fragments_unite", Kokkos::RangePolicy<ExecSpace>(0, nb + ne),
        KOKKOS_LAMBDA(const int k) {
          if (k < nb) {
            const int b = listed ? used(k) : k;
            if (bond_state(b) == kBondActive)
              detail::unite(parent, raw, bond_nodes(b, 0), bond_nodes(b, 1));
          } else {
            const int e = k - nb;
            if (!alive(e)) return;
            const int a = element_nodes(e, 0);
            for (int c = 1; c < 4; ++c) detail::unite(parent, raw, a, element_nodes(e, c));
          }
        });
  }
  // Flatten: every node points at its root. Concurrent writes only ever store a root.
  Kokkos::parallel_for(
      "fracta::fragments_flatten", Kokkos::RangePolicy<ExecSpace>(0, node_count),
      KOKKOS_LAMBDA(const int i) {
        int r = parent(i);
        int next = parent(r);
        while (r != next) {
          r = next;
          next = parent(r);
        }
        parent(i) = r;
      });
}

// Labels the fragments (ws.labels, canonical) and returns their statistics. Host function.
inline FragmentStats fragment_statistics(const Nodes& nodes, const Elements& elements,
                                         const Bonds& bonds, const FragmentWorkspace& ws) {
  ProfilingRegion region("fracta::fragment_statistics");
  const int n = nodes.count;
  FragmentStats stats;
  if (ws.index.extent(0) < static_cast<size_t>(n) || ws.mass.extent(0) < static_cast<size_t>(n) ||
      ws.size.extent(0) < static_cast<size_t>(n))
    throw std::invalid_argument("fragment_statistics: workspace smaller than the node count");
  label_fragments(n, elements, bonds, ws.labels);
  if (n == 0) return stats;

  // Number the roots in increasing id order.
  const View<int*> labels = ws.labels, index = ws.index, size = ws.size;
  const View<double*> frag_mass = ws.mass;
  int count = 0;
  Kokkos::parallel_scan(
      "fracta::fragments_number_roots", Kokkos::RangePolicy<ExecSpace>(0, n),
      KOKKOS_LAMBDA(const int i, int& prefix, const bool final) {
        if (labels(i) != i) return;
        if (final) index(i) = prefix;
        ++prefix;
      },
      count);
  // Per-fragment sums: mass and node count.
  const auto mass_out = Kokkos::subview(frag_mass, std::make_pair(0, count));
  const auto size_out = Kokkos::subview(size, std::make_pair(0, count));
  Kokkos::deep_copy(mass_out, 0.0);
  Kokkos::deep_copy(size_out, 0);
  // Each thread sums a run of consecutive nodes and flushes when the fragment changes: a
  // fragment's nodes are mostly contiguous in id, so a large fragment costs few atomics (one
  // atomic per node on a single hot address was a third of the cost on 10^6 nodes).
  const View<double*> node_mass = nodes.mass;
  constexpr int chunk = 64;
  Kokkos::parallel_for(
      "fracta::fragments_sum", Kokkos::RangePolicy<ExecSpace>(0, (n + chunk - 1) / chunk),
      KOKKOS_LAMBDA(const int c) {
        const int begin = c * chunk, end = begin + chunk < n ? begin + chunk : n;
        int k = index(labels(begin)), run = 0;
        double m = 0.0;
        for (int i = begin; i < end; ++i) {
          const int ki = index(labels(i));
          if (ki != k) {
            Kokkos::atomic_add(&frag_mass(k), m);
            Kokkos::atomic_add(&size(k), run);
            k = ki;
            m = 0.0;
            run = 0;
          }
          m += node_mass(i);
          ++run;
        }
        Kokkos::atomic_add(&frag_mass(k), m);
        Kokkos::atomic_add(&size(k), run);
      });
  auto mass_h = Kokkos::create_mirror_view_and_copy(HostSpace(), mass_out);
  auto size_h = Kokkos::create_mirror_view_and_copy(HostSpace(), size_out);

  // Sort by mass (descending), then size (descending), then root id: deterministic order.
  std::vector<int> order(count);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    if (mass_h(a) != mass_h(b)) return mass_h(a) > mass_h(b);
    return size_h(a) > size_h(b);
  });
  stats.count = count;
  stats.masses.resize(count);
  stats.sizes.resize(count);
  for (int k = 0; k < count; ++k) {
    stats.masses[k] = mass_h(order[k]);
    stats.sizes[k] = size_h(order[k]);
  }
  // Total in root order (independent of the sort, so of near-ties between masses).
  for (int k = 0; k < count; ++k) stats.total_mass += mass_h(k);
  stats.largest_mass = stats.masses[0];
  return stats;
}

// As above with a caller-owned labels view (at least nodes.count entries): on return it holds
// the canonical per-node labels. Allocates the rest of the workspace (3 views of nodes.count)
// per call; keep a FragmentWorkspace to avoid that in a loop.
inline FragmentStats fragment_statistics(const Nodes& nodes, const Elements& elements,
                                         const Bonds& bonds, View<int*> labels_workspace) {
  if (labels_workspace.extent(0) < static_cast<size_t>(nodes.count))
    throw std::invalid_argument("fragment_statistics: labels workspace has " +
                                std::to_string(labels_workspace.extent(0)) + " entries for " +
                                std::to_string(nodes.count) + " nodes");
  return fragment_statistics(nodes, elements, bonds,
                             FragmentWorkspace(nodes.count, labels_workspace));
}

// Cumulative mass distribution over log-spaced fragment-mass bins, for output. Host only.
//  edges:      bins + 1 fragment masses (kg), geometric from m_min to m_max.
//  counts:     bins entries; counts[k] = fragments with edges[k] < m <= edges[k + 1]; the first
//              bin also takes the fragments lighter than edges[0].
//  cumulative: bins + 1 entries; cumulative[k] = (mass in fragments with m <= edges[k]) /
//              total_mass. Fragments heavier than m_max are in no bin (cumulative.back() < 1).
struct MassDistribution {
  std::vector<double> edges;
  std::vector<long> counts;
  std::vector<double> cumulative;
};

// m_min, m_max <= 0 pick the range from the fragments (lightest positive mass to the largest;
// for a single mass, one decade below it). Give a fixed range to compare frames of a run.
inline MassDistribution mass_distribution(const FragmentStats& stats, int bins, double m_min = 0.0,
                                          double m_max = 0.0) {
  if (bins < 1) throw std::invalid_argument("mass_distribution: bins must be >= 1");
  if (m_max <= 0.0) m_max = stats.largest_mass;
  if (m_min <= 0.0) {
    m_min = m_max;
    for (double m : stats.masses)
      if (m > 0.0) m_min = std::min(m_min, m);
    if (!(m_min < m_max)) m_min = 0.1 * m_max;
  }
  MassDistribution d;
  if (!(m_max > 0.0) || !(m_min < m_max)) {  // no mass at all: an empty distribution
    d.edges.assign(bins + 1, 0.0);
    d.counts.assign(bins, 0);
    d.cumulative.assign(bins + 1, 0.0);
    return d;
  }
  d.edges.resize(bins + 1);
  const double ratio = std::log(m_max / m_min);
  for (int k = 0; k <= bins; ++k) d.edges[k] = m_min * std::exp(ratio * k / bins);
  d.edges[0] = m_min;
  d.edges[bins] = m_max;  // exact ends: a fragment of exactly m_max is counted
  d.counts.assign(bins, 0);
  d.cumulative.assign(bins + 1, 0.0);
  // masses are sorted descending: walk them from the lightest.
  std::vector<double> below(bins + 1, 0.0);
  for (auto it = stats.masses.rbegin(); it != stats.masses.rend(); ++it) {
    const double m = *it;
    const int k = static_cast<int>(std::lower_bound(d.edges.begin(), d.edges.end(), m) -
                                   d.edges.begin());  // first edge >= m
    if (k > bins) continue;                           // heavier than m_max
    below[k] += m;
    d.counts[k == 0 ? 0 : k - 1] += 1;
  }
  double acc = 0.0;
  for (int k = 0; k <= bins; ++k) {
    acc += below[k];
    d.cumulative[k] = stats.total_mass > 0.0 ? acc / stats.total_mass : 0.0;
  }
  return d;
}

}  // namespace fracta
