// Node-force scatter without atomics and without a gather pass (CPUs).
//
// Element corners and bond ends add their forces straight into the node accumulators (nodes.f,
// nodes.moment). Two work items that share a node must then not run at the same time. The
// items of a list (the active elements, the used bond slots) are cut into chunks of
// consecutive list positions; a chunk's nodes lie in the interval [lo, hi] of the node indices
// its items touch, and chunks whose intervals overlap get different colours (first fit in the
// order of lo, which is optimal for intervals: as many colours as the deepest overlap, 2 on a
// structured mesh whose rows are shorter than a chunk). One colour runs at a time; each of its
// chunks is one work item, run by one thread in list order, so no two threads ever write one
// node and the sum at every node has a fixed order, whatever the thread count (the chunks
// depend on the list only). The plan's data is ScatterPlan (state.hpp, a member of Elements and
// Bonds); this file builds it (build_scatter_plan, and update_scatter_plan for each entity) and
// runs kernels by it (for_each_chunk).
//
// Why not corner/end arrays and a node gather: they cost every force
// three times in memory (the store, its write-allocate, the gather's load) plus the node ->
// corner lists, about 200 B per element-step of the FE step's 700. Why not atomics: on CPUs an
// atomic double add is a compare-and-swap loop, and the order of the sums would change from
// run to run. GPUs take the atomic path (kAtomicScatter): thousands of threads, fast atomics,
// and a chunk per thread would serialize the work.
#pragma once
#include <algorithm>
#include <numeric>
#include <utility>
#include <vector>

#include "kernels/compat.hpp"
#include "kernels/state.hpp"

namespace fracta {

// *target += value: a plain add inside a chunk of a ScatterPlan, an atomic one otherwise.
KOKKOS_INLINE_FUNCTION void scatter_add(double* target, double value, bool atomic) {
  if (atomic)
    Kokkos::atomic_add(target, value);
  else
    *target += value;
}

// Chunk size: at least 64 items (less and the colour passes cost more than they save), at most
// max_size, and about count / 64 between (64 chunks: enough for the threads of a CPU to share
// each colour); a multiple of 8. The default 2048 keeps an element chunk's working set in the
// L2 cache: about 2048 nodes. Bonds take 8192, the same span of discs (four bonds per disc):
// a chunk of 2048 bonds spans half a row of a 1000-wide lattice, so its node interval overlaps
// three others, which makes four colours, and every colour pass streams the node data again
// (bench_bonds, 1e6 discs, 2 threads: bond forces 126 -> 192 M bond-steps/s with 8192; 4096:
// 158 M, 16384: 180 M; docs/performance.md 1d).
inline int scatter_chunk_size(int count, int max_size = 2048) {
  const int target = std::min(max_size, std::max(64, count / 64));
  return (target + 7) / 8 * 8;
}

// Where each chunk of the plan starts in a list of `count` increasing item indices (`list`;
// an empty view: the identity, item k at position k).
inline void locate_scatter_chunks(ScatterPlan& plan, const View<int*>& list, int count) {
  plan.item_count = -1;
  if (plan.colors == 0) return;
  const auto begin = plan.chunk_begin_position;
  const int size = plan.chunk_size;
  Kokkos::parallel_for(
      "fracta::scatter_locate", Kokkos::RangePolicy<ExecSpace>(0, plan.chunks + 1),
      KOKKOS_LAMBDA(const int c) {
        const long first_item = static_cast<long>(c) * size;
        if (list.extent(0) == 0) {
          begin(c) = static_cast<int>(first_item < count ? first_item : count);
          return;
        }
        int lo = 0, hi = count;  // the first position whose item is >= first_item
        while (lo < hi) {
          const int mid = lo + (hi - lo) / 2;
          if (list(mid) < first_item)
            lo = mid + 1;
          else
            hi = mid;
        }
        begin(c) = lo;
      });
  plan.item_count = count;
}

// Builds the plan for `universe` items whose item i touches the nodes in [lo, hi] as
// `node_range(i, lo, hi)` (a device functor) sets them, and locates it for `list` (see
// locate_scatter_chunks). Host: it loops over the chunks (about 64 to universe / max_chunk_size
// of them), never over the items. max_chunk_size: scatter_chunk_size.
template <class NodeRange>
void build_scatter_plan(ScatterPlan& plan, int universe, const NodeRange& node_range,
                        const View<int*>& list, int count, int max_chunk_size = 2048) {
  plan = ScatterPlan{};
  if (kAtomicScatter || universe <= 0) return;
  const int size = scatter_chunk_size(universe, max_chunk_size);
  const int chunks = (universe + size - 1) / size;
  View<int* [2]> interval("fracta::scatter_intervals", chunks);
  Kokkos::parallel_for(
      "fracta::scatter_intervals", Kokkos::RangePolicy<ExecSpace>(0, chunks),
      KOKKOS_LAMBDA(const int c) {
        int lo = 2147483647, hi = -1;
        const int end = min_(c * size + size, universe);
        for (int k = c * size; k < end; ++k) {
          int a, b;
          node_range(k, a, b);
          lo = min_(lo, a);
          hi = max_(hi, b);
        }
        interval(c, 0) = lo;
        interval(c, 1) = hi;
      });
  const auto host = Kokkos::create_mirror_view_and_copy(HostSpace(), interval);
  std::vector<int> order(chunks);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return host(a, 0) < host(b, 0); });
  // First fit in the order of lo: a chunk takes the first colour whose last chunk ends below it.
  std::vector<int> color_end, color(chunks);
  for (const int c : order) {
    int k = 0;
    while (k < static_cast<int>(color_end.size()) && color_end[k] >= host(c, 0)) ++k;
    if (k == static_cast<int>(color_end.size())) color_end.push_back(-1);
    color_end[k] = host(c, 1);
    color[c] = k;
  }
  const int colors = static_cast<int>(color_end.size());
  if (colors > ScatterPlan::kMaxColors) return;  // a mesh this tangled adds atomically
  std::vector<int> grouped;
  grouped.reserve(chunks);
  plan.color_offset[0] = 0;
  for (int k = 0; k < colors; ++k) {
    for (const int c : order)
      if (color[c] == k) grouped.push_back(c);
    plan.color_offset[k + 1] = static_cast<int>(grouped.size());
  }
  plan.color_chunks = View<int*>("fracta::scatter_color_chunks", chunks);
  const auto mirror = Kokkos::create_mirror_view(plan.color_chunks);
  for (int i = 0; i < chunks; ++i) mirror(i) = grouped[i];
  Kokkos::deep_copy(plan.color_chunks, mirror);
  plan.chunk_begin_position = View<int*>("fracta::scatter_chunk_begin", chunks + 1);
  plan.chunk_size = size;
  plan.chunks = chunks;
  plan.universe = universe;
  plan.colors = colors;
  locate_scatter_chunks(plan, list, count);
}

// One colour's chunks of a plan as a work item per chunk (for_each_chunk).
template <class ChunkWork, class Value>
struct ColorChunks {
  ChunkWork work;
  ScatterPlan plan;
  int first = 0;  // the colour's first position in plan.color_chunks
  KOKKOS_INLINE_FUNCTION void operator()(const int i, Value& v) const {
    const int c = plan.color_chunks(first + i);
    work.chunk(plan.chunk_begin(c), plan.chunk_end(c), v);
  }
};

// Runs chunk_work.chunk(begin, end, value) over every chunk of the plan (its list positions
// [begin, end)), colour by colour (one parallel_reduce each, with the Kokkos reducer Reducer:
// Kokkos::Sum<V>, Kokkos::Min<V>, or one of the project's), and returns the colours' results
// joined on the host by Reducer::join.
// ChunkWork: KOKKOS_INLINE_FUNCTION void chunk(int begin, int end, value_type& v) const.
//
// chunk_work is taken by value and moved into the one functor every colour launches: each host
// copy of a view counts a reference with an atomic (the copies Kokkos makes inside a launch do
// not), and a kernel holding the Nodes and Elements structs holds some 40 views: one copy of the
// FE kernel costs 0.34 us (0.50 us with an adaptive body's views), and a lambda per colour made
// one per colour (FE launch on the 2048-cell plate, 2 threads: 24.4-25.1 -> 23.9-24.2 us).
template <class Reducer, class ChunkWork>
typename Reducer::value_type for_each_chunk(const char* name, const ScatterPlan& plan,
                                            ChunkWork chunk_work) {
  using Value = typename Reducer::value_type;
  Value total;
  Reducer(total).init(total);
  ColorChunks<ChunkWork, Value> color{std::move(chunk_work), plan, 0};
  for (int k = 0; k < plan.colors; ++k) {
    color.first = plan.color_offset[k];
    Value part;
    // Chunks taken dynamically: their costs differ (return mappings, cracked cells and broken
    // bonds gather under an impact), and a static split left one thread with the costly ones
    // (level-1 penetration, 2 threads: bond phase 0.0245 -> 0.0195 s per 200 steps). The node
    // sums keep their order; the reduction's (energies) joins in a run-dependent order on
    // several threads, at round-off, as the contact atomics already make it.
    Kokkos::parallel_reduce(name,
                            Kokkos::RangePolicy<ExecSpace, Kokkos::Schedule<Kokkos::Dynamic>>(
                                0, plan.color_offset[k + 1] - color.first),
                            color, Reducer(part));
    Reducer(total).join(total, part);
  }
  return total;
}

// ---------------------------------------------------------------------------------------------
// The plans of the entities: each cut once from its items (every mesh element, every bond slot)
// and located in its list (Elements::active, the bond list) after every change of the list.
// ---------------------------------------------------------------------------------------------

// The nodes mesh element e touches lie in [lo, hi]: its corners' smallest and largest index.
struct ElementNodeRange {
  View<int* [4]> element_nodes;
  KOKKOS_INLINE_FUNCTION void operator()(const int e, int& lo, int& hi) const {
    lo = hi = element_nodes(e, 0);
    for (int a = 1; a < 4; ++a) {
      lo = min_(lo, element_nodes(e, a));
      hi = max_(hi, element_nodes(e, a));
    }
  }
};

// The elements' plan: of every mesh element, located in the active list.
inline void update_scatter_plan(Elements& elements) {
  if (elements.scatter.universe == elements.count) {
    locate_scatter_chunks(elements.scatter, elements.active, elements.active_count);
    return;
  }
  build_scatter_plan(elements.scatter, elements.count, ElementNodeRange{elements.nodes},
                     elements.active, elements.active_count);
}

// The scatter plan of the bond slots (kernels/scatter.hpp), cut once from the slots and located
// in the bond list after every change of it. Chunks of up to 8192 slots: about as many discs as
// an element chunk spans nodes (scatter_chunk_size). The slots' ends are `slot_ends` when given
// (build_lattice: every slot's, which Bonds::nodes holds only where cells converted), else
// Bonds::nodes.
inline constexpr int kBondChunkMax = 8192;
inline void update_scatter_plan(Bonds& bonds, const View<int* [2]>& slot_ends = {}) {
  const auto list = bonds_listed(bonds) ? bonds.used : View<int*>();
  if (bonds.scatter.universe == bonds.count) {
    locate_scatter_chunks(bonds.scatter, list, bond_list_count(bonds));
    return;
  }
  const auto ends = slot_ends.extent(0) > 0 ? slot_ends : bonds.nodes;
  build_scatter_plan(
      bonds.scatter, bonds.count,
      KOKKOS_LAMBDA(const int b, int& lo, int& hi) {
        lo = min_(ends(b, 0), ends(b, 1));
        hi = max_(ends(b, 0), ends(b, 1));
      },
      list, bond_list_count(bonds), kBondChunkMax);
}

}  // namespace fracta
