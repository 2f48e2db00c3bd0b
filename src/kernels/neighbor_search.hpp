// Contact pre-search (docs/physics.md 1.2, "Search"; the paper's "pre-search"): a Verlet list of
// candidate disc pairs built by uniform cell binning, plus the all-pairs (O(N^2)) builder kept as
// the test oracle and the benchmark baseline (paper Fig. 8 "traversal").
//
// Definitions and invariants:
//  - The contact discs are a list of node ids in increasing order (`discs`); "disc a" is the
//    a-th entry of that list. Disc radii are nodes.radius and never change.
//  - A candidate pair (i, j) holds two node ids with i < j and |x_i - x_j| < r_i + r_j + skin at
//    the time of the build. Pairs are stored row by row: the row of disc a (its pairs with
//    larger node ids) is [row_offset(a), row_offset(a + 1)), sorted by j. The list is therefore
//    a deterministic function of the positions (no atomic counter decides the order).
//  - With each pair the list keeps pair_b, the disc index of j (discs(pair_b(k)) == pair_j(k)),
//    and row_offset is the rows' start: what the contact gather's columns and rows are built
//    from (build_contact_gather) without searching the lists.
//  - Building is two-pass: count per disc -> exclusive parallel_scan -> fill.
//  - Verlet criterion: the list stays valid while no disc moved more than skin / 2 since the
//    build (two discs then approached by at most skin, so every pair now closer than r_i + r_j
//    was closer than r_i + r_j + skin at the build).
//  - Joined pairs (an active bond or an active element between them: Topology::joined) are
//    left out, as LAMMPS leaves bonded atoms out of its pair lists: in an intact lattice every
//    neighbour is joined, and the list holds only the pairs that can touch. Two discs can only
//    come apart, never join again (a slot turns active only when a cell converts, and the cell
//    joined the pair while it was alive; a broken slot stays broken; only a restore returns
//    to an earlier state, and it rebuilds). What unjoins a listed-out pair between two builds
//    is a bond breaking (Bonds::note_broken) or a cell converting: those pairs are merged into
//    the list at once ("Admitting unjoined pairs" below), so the force kernel needs no joined
//    check, and the list is the one a build would give at that moment, in the same order.
//
// Memory is allocated by the caller (src/host/contact.cpp); these functions only fill views.
#pragma once
#include <cmath>

#include "kernels/compat.hpp"
#include "kernels/state.hpp"

namespace fracta {

// Bounding box of the disc centres and the largest radius. Reduced with the operator+= of
// reduction_identity (as Sums<N>): += is "merge", the identity is the empty box.
struct DiscBounds {
  double lo[2], hi[2];
  double r_max;
  KOKKOS_INLINE_FUNCTION DiscBounds() {
    lo[0] = lo[1] = 1e300;
    hi[0] = hi[1] = -1e300;
    r_max = 0.0;
  }
  KOKKOS_INLINE_FUNCTION void merge(double x, double y, double r) {
    lo[0] = min_(lo[0], x);
    lo[1] = min_(lo[1], y);
    hi[0] = max_(hi[0], x);
    hi[1] = max_(hi[1], y);
    r_max = max_(r_max, r);
  }
  KOKKOS_INLINE_FUNCTION DiscBounds& operator+=(const DiscBounds& o) {
    for (int d = 0; d < 2; ++d) {
      lo[d] = min_(lo[d], o.lo[d]);
      hi[d] = max_(hi[d], o.hi[d]);
    }
    r_max = max_(r_max, o.r_max);
    return *this;
  }
  KOKKOS_INLINE_FUNCTION void operator+=(const volatile DiscBounds& o) volatile {
    for (int d = 0; d < 2; ++d) {
      lo[d] = lo[d] < o.lo[d] ? lo[d] : o.lo[d];
      hi[d] = hi[d] > o.hi[d] ? hi[d] : o.hi[d];
    }
    r_max = r_max > o.r_max ? r_max : o.r_max;
  }
};

}  // namespace fracta

namespace Kokkos {
template <>
struct reduction_identity<fracta::DiscBounds> {
  KOKKOS_FORCEINLINE_FUNCTION static fracta::DiscBounds sum() { return fracta::DiscBounds(); }
};
}  // namespace Kokkos

namespace fracta {

// Uniform grid of square cells of size `cell` >= the largest interaction distance
// 2 r_max + skin, so every candidate of a disc lies in its own or one of the 8 adjacent cells.
// Discs outside the box (never after a build, which spans all centres) are clamped to the edge
// cells, which keeps the search correct because clamping never separates two close discs by
// more than one cell.
struct CellGrid {
  double origin[2] = {0.0, 0.0};
  double cell = 1.0;
  int nx = 1, ny = 1;
  KOKKOS_INLINE_FUNCTION int coord(double x, int d) const {
    const double s = (x - origin[d]) / cell;
    const int n = d == 0 ? nx : ny;
    if (!(s > 0.0)) return 0;  // also NaN
    if (s >= static_cast<double>(n)) return n - 1;
    return static_cast<int>(s);
  }
  KOKKOS_INLINE_FUNCTION int cell_of(double x, double y) const {
    return coord(x, 0) + nx * coord(y, 1);
  }
  long cell_count() const { return static_cast<long>(nx) * ny; }
};

inline DiscBounds disc_bounds(const Nodes& nodes, const View<const int*>& discs) {
  DiscBounds b;
  const auto x = nodes.x;
  const auto radius = nodes.radius;
  Kokkos::parallel_reduce(
      "fracta::contact_bounds", Kokkos::RangePolicy<ExecSpace>(0, discs.extent(0)),
      KOKKOS_LAMBDA(const int a, DiscBounds& acc) {
        const int n = discs(a);
        acc.merge(x(n, 0), x(n, 1), radius(n));
      },
      b);
  return b;
}

// Host arithmetic: the grid for these bounds. The cell is at least 2 r_max + skin; if the box
// would need more than `max_cells` cells (discs flying apart), the cells grow instead, which
// only adds candidates to check, never loses one.
inline CellGrid make_grid(const DiscBounds& b, double skin, long max_cells) {
  CellGrid g;
  double cell = 2.0 * b.r_max + skin;
  const double wx = b.hi[0] - b.lo[0], wy = b.hi[1] - b.lo[1];
  if (!(wx >= 0.0) || !(wy >= 0.0)) return g;  // no discs, or non-finite positions: one cell
  if (!(cell > 0.0)) cell = max_(max_(wx, wy), 1.0);
  const auto cells = [&](double c) {
    return (std::floor(wx / c) + 1.0) * (std::floor(wy / c) + 1.0);
  };
  if (cells(cell) > static_cast<double>(max_cells))
    cell = max_(cell, sqrt_(wx * wy / static_cast<double>(max_cells)) * 1.01);
  while (cells(cell) > static_cast<double>(max_cells)) cell *= 1.25;
  g.origin[0] = b.lo[0];
  g.origin[1] = b.lo[1];
  g.cell = cell;
  g.nx = static_cast<int>(std::floor(wx / cell)) + 1;
  g.ny = static_cast<int>(std::floor(wy / cell)) + 1;
  return g;
}

// Positions of list entries for the binning: disc a of a disc list at its node's position
// (DiscPositions), or entry q of a list of disc indices at a position kept per disc index
// (ListedPositions: the build positions of the inserted discs).
struct DiscPositions {
  View<const int*> discs;
  View<const double* [2]> x;
  KOKKOS_INLINE_FUNCTION double operator()(const int a, const int d) const {
    return x(discs(a), d);
  }
};
struct ListedPositions {
  View<const int*> items;
  View<const double* [2]> position;
  KOKKOS_INLINE_FUNCTION double operator()(const int q, const int d) const {
    return position(items(q), d);
  }
};

// Counting sort of `count` points (positions pos(k, d)) into cells. cell_start has
// cell_count() + 1 entries, cell_cursor cell_count(), cell_items one per point (its k). Within
// a cell the points are sorted by k (a per-cell insertion sort after the atomic fill), so the
// result is deterministic.
template <class Positions>
void bin_points(int count, const Positions& pos, const CellGrid& grid, const View<int*>& cell_start,
                const View<int*>& cell_cursor, const View<int*>& cell_items) {
  const int n_cells = static_cast<int>(grid.cell_count());
  Kokkos::deep_copy(Kokkos::subview(cell_start, std::make_pair(0, n_cells + 1)), 0);
  Kokkos::parallel_for(
      "fracta::contact_bin_count", Kokkos::RangePolicy<ExecSpace>(0, count),
      KOKKOS_LAMBDA(const int k) {
        Kokkos::atomic_increment(&cell_start(grid.cell_of(pos(k, 0), pos(k, 1))));
      });
  Kokkos::parallel_scan(
      "fracta::contact_bin_scan", Kokkos::RangePolicy<ExecSpace>(0, n_cells + 1),
      KOKKOS_LAMBDA(const int c, int& sum, const bool final) {
        const int in_cell = c < n_cells ? cell_start(c) : 0;
        if (final) {
          cell_start(c) = sum;
          if (c < n_cells) cell_cursor(c) = sum;
        }
        sum += in_cell;
      });
  Kokkos::parallel_for(
      "fracta::contact_bin_fill", Kokkos::RangePolicy<ExecSpace>(0, count),
      KOKKOS_LAMBDA(const int k) {
        const int c = grid.cell_of(pos(k, 0), pos(k, 1));
        cell_items(Kokkos::atomic_fetch_add(&cell_cursor(c), 1)) = k;
      });
  Kokkos::parallel_for(
      "fracta::contact_bin_sort", Kokkos::RangePolicy<ExecSpace>(0, n_cells),
      KOKKOS_LAMBDA(const int c) { sort_segment(cell_items, cell_start(c), cell_start(c + 1)); });
}

// The discs at their nodes' positions, binned: cell_discs holds disc indices.
inline void bin_discs(const Nodes& nodes, const View<const int*>& discs, const CellGrid& grid,
                      const View<int*>& cell_start, const View<int*>& cell_cursor,
                      const View<int*>& cell_discs) {
  bin_points(static_cast<int>(discs.extent(0)), DiscPositions{discs, nodes.x}, grid, cell_start,
             cell_cursor, cell_discs);
}

// Binned pair search. Fill = false counts the candidates of each disc into row_offset(a);
// Fill = true writes them at row_offset(a) (already scanned) into pair_i / pair_b, in bin
// order (fill_candidates then sorts each row and writes pair_j).
template <bool Fill>
struct BinnedPairs {
  View<const int*> discs;
  View<const double* [2]> x;
  View<const double*> radius;
  CellGrid grid;
  View<const int*> cell_start, cell_discs;
  double skin;
  Topology topo;
  View<int*> row_offset;
  View<int*> pair_i, pair_b;

  KOKKOS_INLINE_FUNCTION void operator()(const int a) const {
    const int i = discs(a);
    const double xi = x(i, 0), yi = x(i, 1), ri = radius(i);
    const int cx = grid.coord(xi, 0), cy = grid.coord(yi, 1);
    int out = Fill ? row_offset(a) : 0;
    for (int gy = max_(cy - 1, 0); gy <= min_(cy + 1, grid.ny - 1); ++gy) {
      for (int gx = max_(cx - 1, 0); gx <= min_(cx + 1, grid.nx - 1); ++gx) {
        const int c = gx + grid.nx * gy;
        for (int k = cell_start(c); k < cell_start(c + 1); ++k) {
          const int b = cell_discs(k);
          if (b <= a) continue;  // discs are sorted by node id: b > a  <=>  j > i
          const int j = discs(b);
          const double dx = x(j, 0) - xi, dy = x(j, 1) - yi;
          const double reach = ri + radius(j) + skin;
          if (dx * dx + dy * dy < reach * reach && !topo.joined(i, j)) {
            if (Fill) {
              pair_i(out) = i;
              pair_b(out) = b;
            }
            ++out;
          }
        }
      }
    }
    if (!Fill) row_offset(a) = out;
  }
};

// All-pairs (O(N^2)) search with the same output as the binned one: the oracle and baseline.
template <bool Fill>
struct AllPairs {
  View<const int*> discs;
  View<const double* [2]> x;
  View<const double*> radius;
  double skin;
  Topology topo;
  int n_discs;
  View<int*> row_offset;
  View<int*> pair_i, pair_j, pair_b;

  KOKKOS_INLINE_FUNCTION void operator()(const int a) const {
    const int i = discs(a);
    const double xi = x(i, 0), yi = x(i, 1), ri = radius(i);
    int out = Fill ? row_offset(a) : 0;
    for (int b = a + 1; b < n_discs; ++b) {
      const int j = discs(b);
      const double dx = x(j, 0) - xi, dy = x(j, 1) - yi;
      const double reach = ri + radius(j) + skin;
      if (dx * dx + dy * dy < reach * reach && !topo.joined(i, j)) {
        if (Fill) {
          pair_i(out) = i;
          pair_j(out) = j;
          pair_b(out) = b;
        }
        ++out;
      }
    }
    if (!Fill) row_offset(a) = out;
  }
};

// Counts candidates per disc into row_offset(0..n_discs-1). all_pairs selects the O(N^2) oracle.
// topo: who is joined (empty: free discs, none).
inline void count_candidates(const Nodes& nodes, const View<const int*>& discs, double skin,
                             const Topology& topo, bool all_pairs, const CellGrid& grid,
                             const View<int*>& cell_start, const View<int*>& cell_discs,
                             const View<int*>& row_offset) {
  const int n_discs = static_cast<int>(discs.extent(0));
  const auto policy = Kokkos::RangePolicy<ExecSpace>(0, n_discs);
  if (all_pairs) {
    AllPairs<false> f{discs, nodes.x, nodes.radius, skin, topo, n_discs, row_offset, {}, {}, {}};
    Kokkos::parallel_for("fracta::contact_all_pairs_count", policy, f);
  } else {
    BinnedPairs<false> f{discs, nodes.x, nodes.radius, grid, cell_start, cell_discs,
                         skin,  topo,    row_offset,   {},   {}};
    Kokkos::parallel_for("fracta::contact_binned_count", policy, f);
  }
}

// Writes the candidates at the scanned row offsets, every row sorted by j (its disc indices
// pair_b sorted: the discs are in increasing node id).
inline void fill_candidates(const Nodes& nodes, const View<const int*>& discs, double skin,
                            const Topology& topo, bool all_pairs, const CellGrid& grid,
                            const View<int*>& cell_start, const View<int*>& cell_discs,
                            const View<int*>& row_offset, const View<int*>& pair_i,
                            const View<int*>& pair_j, const View<int*>& pair_b) {
  const int n_discs = static_cast<int>(discs.extent(0));
  const auto policy = Kokkos::RangePolicy<ExecSpace>(0, n_discs);
  if (all_pairs) {
    AllPairs<true> f{discs,   nodes.x,    nodes.radius, skin,   topo,
                     n_discs, row_offset, pair_i,       pair_j, pair_b};
    Kokkos::parallel_for("fracta::contact_all_pairs_fill", policy, f);
    return;  // rows are already in increasing j
  }
  BinnedPairs<true> f{discs, nodes.x, nodes.radius, grid,   cell_start, cell_discs,
                      skin,  topo,    row_offset,   pair_i, pair_b};
  Kokkos::parallel_for("fracta::contact_binned_fill", policy, f);
  Kokkos::parallel_for(
      "fracta::contact_row_sort", policy, KOKKOS_LAMBDA(const int a) {
        sort_segment(pair_b, row_offset(a), row_offset(a + 1));
        for (int k = row_offset(a); k < row_offset(a + 1); ++k) pair_j(k) = discs(pair_b(k));
      });
}

// The rows and disc indices of a candidate list that did not come from fill_candidates (a
// checkpoint's, ContactSystem::restore_list_state): row_offset (n_discs + 1) and pair_b [0, count)
// as fill_candidates leaves them, found by binary search in the sorted lists.
inline void index_candidates(const View<const int*>& discs, const View<const int*>& pair_i,
                             const View<const int*>& pair_j, long count,
                             const View<int*>& row_offset, const View<int*>& pair_b) {
  const int n = static_cast<int>(discs.extent(0)), pairs = static_cast<int>(count);
  Kokkos::parallel_for(
      "fracta::contact_index_rows", Kokkos::RangePolicy<ExecSpace>(0, n + 1),
      KOKKOS_LAMBDA(const int a) {
        row_offset(a) = a < n ? count_below(pair_i, pairs, discs(a)) : pairs;
      });
  Kokkos::parallel_for(
      "fracta::contact_index_pairs", Kokkos::RangePolicy<ExecSpace>(0, pairs),
      KOKKOS_LAMBDA(const int k) { pair_b(k) = count_below(discs, n, pair_j(k)); });
}

// The discs that can touch now, under surface tracking (ContactSystem::refresh_discs): the
// surface nodes (increasing, static) and the particles (nodes.particle_list, increasing),
// without a sweep over the nodes. This keeps the surface nodes that are no particles (into
// surface_only; returns their count), so the two lists are disjoint for merge_disjoint_sorted.
inline int surface_without_particles(const View<const int*>& surface, const Nodes& nodes,
                                     const View<int*>& surface_only) {
  const auto particle = nodes.particle;
  const bool particles = nodes.has_particles();
  int count = 0;
  Kokkos::parallel_scan(
      "fracta::contact_surface_discs", Kokkos::RangePolicy<ExecSpace>(0, surface.extent(0)),
      KOKKOS_LAMBDA(const int k, int& partial, const bool final) {
        const int n = surface(k);
        if (particles && particle(n)) return;
        if (final) surface_only(partial) = n;
        ++partial;
      },
      count);
  return count;
}

// Positions at the build, for the Verlet criterion.
inline void record_positions(const Nodes& nodes, const View<const int*>& discs,
                             const View<double* [2]>& x_build) {
  const auto x = nodes.x;
  Kokkos::parallel_for(
      "fracta::contact_record_positions", Kokkos::RangePolicy<ExecSpace>(0, discs.extent(0)),
      KOKKOS_LAMBDA(const int a) {
        const int n = discs(a);
        x_build(a, 0) = x(n, 0);
        x_build(a, 1) = x(n, 1);
      });
}

// How far the discs moved since the build and how fast they move: the largest squared
// displacement (m^2; a non-finite position gives 1e300, so it triggers a rebuild rather than
// hiding) and the largest squared speed (m^2/s^2, of nodes.v: the drift velocity of the step).
struct DiscMotion {
  double displacement_sq = 0.0, speed_sq = 0.0;
  double broken = 0.0;  // Bonds::broken_count, read in the same pass (no wait of its own)
  // Joined elementwise by the maximum: one pass reduces all (disc_motion runs it through
  // Kokkos::Sum, whose join is +=; the identity is 0, below every value reduced).
  KOKKOS_INLINE_FUNCTION DiscMotion& operator+=(const DiscMotion& o) {
    displacement_sq = max_(displacement_sq, o.displacement_sq);
    speed_sq = max_(speed_sq, o.speed_sq);
    broken = max_(broken, o.broken);
    return *this;
  }
  KOKKOS_INLINE_FUNCTION void operator+=(const volatile DiscMotion& o) volatile {
    displacement_sq = max_(displacement_sq, o.displacement_sq);
    speed_sq = max_(speed_sq, o.speed_sq);
    broken = max_(broken, o.broken);
  }
};

}  // namespace fracta

namespace Kokkos {
template <>
struct reduction_identity<fracta::DiscMotion> {
  KOKKOS_FORCEINLINE_FUNCTION static fracta::DiscMotion sum() { return fracta::DiscMotion(); }
};
}  // namespace Kokkos

namespace fracta {

inline DiscMotion disc_motion(const Nodes& nodes, const View<const int*>& discs,
                              const View<const double* [2]>& x_build,
                              const View<const int>& broken_count = {}) {
  DiscMotion m;
  const int count = static_cast<int>(discs.extent(0));
  if (count == 0) return m;
  const auto x = nodes.x, v = nodes.v;
  const bool speeds = v.extent(0) > 0, broken = broken_count.data() != nullptr;
  Kokkos::parallel_reduce(
      "fracta::contact_displacement", Kokkos::RangePolicy<ExecSpace>(0, count),
      KOKKOS_LAMBDA(const int a, DiscMotion& acc) {
        const int n = discs(a);
        const double dx = x(n, 0) - x_build(a, 0), dy = x(n, 1) - x_build(a, 1);
        DiscMotion here;
        here.displacement_sq = dx * dx + dy * dy;
        if (!isfinite_(here.displacement_sq)) here.displacement_sq = 1e300;
        if (speeds) {
          here.speed_sq = v(n, 0) * v(n, 0) + v(n, 1) * v(n, 1);
          if (!isfinite_(here.speed_sq)) here.speed_sq = 1e300;
        }
        if (broken && a == 0) here.broken = broken_count();
        acc += here;
      },
      Kokkos::Sum<DiscMotion>(m));
  return m;
}

// ---- Inserting new discs into a built list (ContactSystem::refresh_discs) -----------------
// A conversion adds discs (the new particles inside the mesh) to a list that is still valid for
// the old ones. Instead of a rebuild, the new discs are searched against every disc with the
// discs at their build positions p (the old discs' x_build, the new discs' positions now, which
// become their x_build): a pair is a candidate when |p_i - p_j| < r_i + r_j + skin, as in a
// build. The Verlet criterion then holds as after a build: while no disc moved more than
// skin / 2 from p, two discs approached by at most skin. Radii only shrink at conversions, so
// the old pairs stay a superset too. The merged list keeps the build's order (rows by
// increasing i, each sorted by j), so the contact gather sums the touching pairs in the same
// order as after a rebuild: the forces are the same to the bit (pairs out of contact add
// nothing), and only which untouching pairs are listed differs.

// Of the discs (the new list), which were in the old list: old_index(a) (-1 for a new disc),
// new_of_old(o) the inverse; p(a) the build position. node_slot: one entry per node, all zero
// (left so): the old discs mark their nodes in it (a binary search per disc cost twice the
// three passes). Returns how many old discs were found (all of them when the new list is a
// superset).
inline int map_inserted_discs(const Nodes& nodes, const View<const int*>& discs,
                              const View<const int*>& old_discs,
                              const View<const double* [2]>& old_x_build,
                              const View<int*>& node_slot, const View<int*>& old_index,
                              const View<int*>& new_of_old, const View<double* [2]>& p) {
  const auto old_policy = Kokkos::RangePolicy<ExecSpace>(0, old_discs.extent(0));
  Kokkos::parallel_for(
      "fracta::contact_insert_mark", old_policy,
      KOKKOS_LAMBDA(const int o) { node_slot(old_discs(o)) = o + 1; });
  const auto x = nodes.x;
  int found = 0;
  Kokkos::parallel_reduce(
      "fracta::contact_insert_map", Kokkos::RangePolicy<ExecSpace>(0, discs.extent(0)),
      KOKKOS_LAMBDA(const int a, int& acc) {
        const int n = discs(a);
        const int o = node_slot(n) - 1;
        old_index(a) = o;
        for (int d = 0; d < 2; ++d) p(a, d) = o >= 0 ? old_x_build(o, d) : x(n, d);
        if (o >= 0) {
          new_of_old(o) = a;
          ++acc;
        }
      },
      found);
  Kokkos::parallel_for(
      "fracta::contact_insert_unmark", old_policy,
      KOKKOS_LAMBDA(const int o) { node_slot(old_discs(o)) = 0; });
  return found;
}

// The new discs' indices (old_index < 0), increasing, into new_discs; returns their count.
inline int list_inserted_discs(const View<const int*>& old_index, const View<int*>& new_discs) {
  int count = 0;
  Kokkos::parallel_scan(
      "fracta::contact_insert_list", Kokkos::RangePolicy<ExecSpace>(0, old_index.extent(0)),
      KOKKOS_LAMBDA(const int a, int& partial, const bool final) {
        if (old_index(a) >= 0) return;
        if (final) new_discs(partial) = a;
        ++partial;
      },
      count);
  return count;
}

// Bounding box of the new discs at p, and the largest radius of theirs.
inline DiscBounds inserted_disc_bounds(const Nodes& nodes, const View<const int*>& discs,
                                       const View<const int*>& new_discs, int count,
                                       const View<const double* [2]>& p) {
  DiscBounds b;
  const auto radius = nodes.radius;
  Kokkos::parallel_reduce(
      "fracta::contact_insert_bounds", Kokkos::RangePolicy<ExecSpace>(0, count),
      KOKKOS_LAMBDA(const int q, DiscBounds& acc) {
        const int a = new_discs(q);
        acc.merge(p(a, 0), p(a, 1), radius(discs(a)));
      },
      b);
  return b;
}

// The pairs with a new disc, found from every disc c: the new discs binned near it (a grid
// over the new discs, cell >= the largest reach) within reach at p. Each pair goes once into
// the row of its smaller disc index: c's if c < a; a's if a < c and c is old (when c is new,
// a's own pass lists it). Fill = false counts per row into extra_count (scan_rows then makes
// them offsets); Fill = true writes the partner's disc index at extra_offset(row) + a slot
// taken from extra_count (zeroed), in any order (sorted afterwards).
template <bool Fill>
struct InsertedPairs {
  View<const int*> discs, old_index, new_discs;
  View<const double* [2]> p;
  View<const double*> radius;
  CellGrid grid;
  View<const int*> cell_start, cell_items;
  double skin;
  Topology topo;
  View<int*> extra_count;
  View<const int*> extra_offset;
  View<int*> extra;

  KOKKOS_INLINE_FUNCTION void operator()(const int c) const {
    const double xc = p(c, 0), yc = p(c, 1);
    // Farther than a cell outside the new discs' box: none within reach (reach <= cell).
    const double cell = grid.cell;
    if (xc < grid.origin[0] - cell || yc < grid.origin[1] - cell ||
        xc > grid.origin[0] + (grid.nx + 1) * cell || yc > grid.origin[1] + (grid.ny + 1) * cell)
      return;
    const double rc = radius(discs(c));
    const bool c_new = old_index(c) < 0;
    const int cx = grid.coord(xc, 0), cy = grid.coord(yc, 1);
    for (int gy = max_(cy - 1, 0); gy <= min_(cy + 1, grid.ny - 1); ++gy)
      for (int gx = max_(cx - 1, 0); gx <= min_(cx + 1, grid.nx - 1); ++gx) {
        const int g = gx + grid.nx * gy;
        for (int k = cell_start(g); k < cell_start(g + 1); ++k) {
          const int a = new_discs(cell_items(k));
          if (a == c || (a < c && c_new)) continue;
          const double dx = p(a, 0) - xc, dy = p(a, 1) - yc;
          const double reach = rc + radius(discs(a)) + skin;
          if (!(dx * dx + dy * dy < reach * reach) || topo.joined(discs(c), discs(a))) continue;
          const int row = a < c ? a : c, partner = a < c ? c : a;
          if (Fill)
            extra(extra_offset(row) + Kokkos::atomic_fetch_add(&extra_count(row), 1)) = partner;
          else
            Kokkos::atomic_increment(&extra_count(row));
        }
      }
  }
};

// Sorts each disc's inserted entries (extra from extra_offset(a), extra_count(a) of them, filled
// in any order), drops repeats (extra_count(a) becomes the count left) and writes its merged
// row length into rows(a): old row + inserted entries. old_index empty: every disc is old, at
// its own index (ContactSystem::admit_unjoined).
inline void count_merged_rows(const View<const int*>& old_index,
                              const View<const int*>& old_row_offset,
                              const View<const int*>& extra_offset, const View<int*>& extra_count,
                              const View<int*>& extra, const View<int*>& rows) {
  const bool identity = old_index.extent(0) == 0;
  Kokkos::parallel_for(
      "fracta::contact_insert_rows", Kokkos::RangePolicy<ExecSpace>(0, rows.extent(0) - 1),
      KOKKOS_LAMBDA(const int a) {
        const int begin = extra_offset(a);
        int end = begin + extra_count(a);
        sort_segment(extra, begin, end);
        int kept = begin;
        for (int q = begin; q < end; ++q)
          if (q == begin || extra(q) != extra(kept - 1)) extra(kept++) = extra(q);
        extra_count(a) = kept - begin;
        const int o = identity ? a : old_index(a);
        rows(a) = (o >= 0 ? old_row_offset(o + 1) - old_row_offset(o) : 0) + kept - begin;
      });
}

// Row a of the merged list: its old row (old_index(a) >= 0; the partners' disc indices mapped
// by new_of_old) and its inserted entries (extra_count(a) from extra_offset(a)), both
// increasing, merged at row_offset(a). No pair is in both (an inserted pair has a new disc, an
// admitted one was not listed). old_index and new_of_old empty: every disc is old, at its own
// index.
struct MergeInsertedRows {
  View<const int*> discs, old_index, old_row_offset, old_pair_b, new_of_old;
  View<const int*> extra_offset, extra_count, extra, row_offset;
  View<int*> pair_i, pair_j, pair_b;

  KOKKOS_INLINE_FUNCTION void operator()(const int a) const {
    const bool identity = old_index.extent(0) == 0;
    const int o = identity ? a : old_index(a);
    int k = o >= 0 ? old_row_offset(o) : 0;
    const int k_end = o >= 0 ? old_row_offset(o + 1) : 0;
    int q = extra_offset(a);
    const int q_end = q + extra_count(a), i = discs(a);
    for (int out = row_offset(a); k < k_end || q < q_end; ++out) {
      const int from_old =
          k < k_end ? (identity ? old_pair_b(k) : new_of_old(old_pair_b(k))) : 2147483647;
      const int from_new = q < q_end ? extra(q) : 2147483647;
      const int b = from_old < from_new ? from_old : from_new;
      if (from_old < from_new)
        ++k;
      else
        ++q;
      pair_i(out) = i;
      pair_j(out) = discs(b);
      pair_b(out) = b;
    }
  }
};

// ---- Admitting unjoined pairs (ContactSystem::admit_unjoined) ------------------------------
// The slots whose two discs may have come apart since the list was made: the bonds broken since
// the last search (Bonds::note_broken) and the slots of cells that just converted (a slot that
// was broken while the other cell was alive). The pair of each slot that is now free (not
// joined: Topology::joined), whose ends are both discs and that is not listed yet goes into its
// row (the smaller disc index), whatever the distance (a pair out of reach adds nothing until
// the next build drops it); count_merged_rows and MergeInsertedRows with every disc old then
// merge the rows. The touching pairs are then those a build would list, in the same order.
// Fill = false counts per row into extra_count; Fill = true writes the partner's disc index at
// extra_offset(row) + a slot taken from extra_count (zeroed).
template <bool Fill>
struct UnjoinedPairs {
  View<const int*> slots;           // slot ids, -1: none
  View<const int* [2]> slot_nodes;  // Bonds::nodes
  View<const int*> discs, row_offset, pair_b;
  Topology topo;
  View<int*> extra_count;
  View<const int*> extra_offset;
  View<int*> extra;

  KOKKOS_INLINE_FUNCTION void operator()(const int k) const {
    const int b = slots(k);
    if (b < 0) return;
    const int n0 = slot_nodes(b, 0), n1 = slot_nodes(b, 1);
    const int i = min_(n0, n1), j = max_(n0, n1);
    if (i == j || topo.joined(i, j)) return;
    const int n = static_cast<int>(discs.extent(0));
    const int row = count_below(discs, n, i), partner = count_below(discs, n, j);
    if (row >= n || discs(row) != i || partner >= n || discs(partner) != j) return;
    // Listed already (free at the last build, or admitted since): the row is sorted.
    const int end = row_offset(row + 1);
    const int at = first_not_below(pair_b, row_offset(row), end, partner);
    if (at < end && pair_b(at) == partner) return;
    if (Fill)
      extra(extra_offset(row) + Kokkos::atomic_fetch_add(&extra_count(row), 1)) = partner;
    else
      Kokkos::atomic_increment(&extra_count(row));
  }
};

}  // namespace fracta
