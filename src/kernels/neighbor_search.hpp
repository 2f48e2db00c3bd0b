// Contact pre-search (DESIGN.md 1.3, the paper's "pre-search"): a Verlet list of candidate disc
// pairs built by uniform cell binning, plus the all-pairs (O(N^2)) builder kept as the test
// oracle and the benchmark baseline (paper Fig. 8 "traversal").
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
//  - Joined pairs (bond or element) are NOT filtered here: the force kernel checks them every
//    step, so a bond that breaks between two builds becomes a contact at once.
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

// Counting sort of the discs into cells. cell_start has cell_count() + 1 entries, cell_cursor
// cell_count(), cell_discs one per disc. Within a cell the discs are sorted by index (a
// per-cell insertion sort after the atomic fill), so the result is deterministic.
inline void bin_discs(const Nodes& nodes, const View<const int*>& discs, const CellGrid& grid,
                      const View<int*>& cell_start, const View<int*>& cell_cursor,
                      const View<int*>& cell_discs) {
  const int n_discs = static_cast<int>(discs.extent(0));
  const int n_cells = static_cast<int>(grid.cell_count());
  const auto x = nodes.x;
  Kokkos::deep_copy(cell_start, 0);
  Kokkos::parallel_for(
      "fracta::contact_bin_count", Kokkos::RangePolicy<ExecSpace>(0, n_discs),
      KOKKOS_LAMBDA(const int a) {
        const int n = discs(a);
        Kokkos::atomic_increment(&cell_start(grid.cell_of(x(n, 0), x(n, 1))));
      });
  Kokkos::parallel_scan(
      "fracta::contact_bin_scan", Kokkos::RangePolicy<ExecSpace>(0, n_cells + 1),
      KOKKOS_LAMBDA(const int c, int& sum, const bool final) {
        const int count = c < n_cells ? cell_start(c) : 0;
        if (final) {
          cell_start(c) = sum;
          if (c < n_cells) cell_cursor(c) = sum;
        }
        sum += count;
      });
  Kokkos::parallel_for(
      "fracta::contact_bin_fill", Kokkos::RangePolicy<ExecSpace>(0, n_discs),
      KOKKOS_LAMBDA(const int a) {
        const int n = discs(a);
        const int c = grid.cell_of(x(n, 0), x(n, 1));
        cell_discs(Kokkos::atomic_fetch_add(&cell_cursor(c), 1)) = a;
      });
  Kokkos::parallel_for(
      "fracta::contact_bin_sort", Kokkos::RangePolicy<ExecSpace>(0, n_cells),
      KOKKOS_LAMBDA(const int c) { sort_segment(cell_discs, cell_start(c), cell_start(c + 1)); });
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
          if (dx * dx + dy * dy < reach * reach) {
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
      if (dx * dx + dy * dy < reach * reach) {
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

// Exclusive scan of the per-disc counts in row_offset (n_discs + 1 entries, the last one is
// overwritten); returns the total number of candidates.
inline long scan_rows(const View<int*>& row_offset, int n_discs) {
  long total = 0;
  Kokkos::parallel_scan(
      "fracta::contact_pair_scan", Kokkos::RangePolicy<ExecSpace>(0, n_discs + 1),
      KOKKOS_LAMBDA(const int a, long& sum, const bool final) {
        const int count = a < n_discs ? row_offset(a) : 0;
        if (final) row_offset(a) = static_cast<int>(sum);
        sum += count;
      },
      total);
  return total;
}

// Counts candidates per disc into row_offset(0..n_discs-1). all_pairs selects the O(N^2) oracle.
inline void count_candidates(const Nodes& nodes, const View<const int*>& discs, double skin,
                             bool all_pairs, const CellGrid& grid, const View<int*>& cell_start,
                             const View<int*>& cell_discs, const View<int*>& row_offset) {
  const int n_discs = static_cast<int>(discs.extent(0));
  const auto policy = Kokkos::RangePolicy<ExecSpace>(0, n_discs);
  if (all_pairs) {
    AllPairs<false> f{discs, nodes.x, nodes.radius, skin, n_discs, row_offset, {}, {}, {}};
    Kokkos::parallel_for("fracta::contact_all_pairs_count", policy, f);
  } else {
    BinnedPairs<false> f{discs,      nodes.x, nodes.radius, grid, cell_start,
                         cell_discs, skin,    row_offset,   {},   {}};
    Kokkos::parallel_for("fracta::contact_binned_count", policy, f);
  }
}

// Writes the candidates at the scanned row offsets, every row sorted by j (its disc indices
// pair_b sorted: the discs are in increasing node id).
inline void fill_candidates(const Nodes& nodes, const View<const int*>& discs, double skin,
                            bool all_pairs, const CellGrid& grid, const View<int*>& cell_start,
                            const View<int*>& cell_discs, const View<int*>& row_offset,
                            const View<int*>& pair_i, const View<int*>& pair_j,
                            const View<int*>& pair_b) {
  const int n_discs = static_cast<int>(discs.extent(0));
  const auto policy = Kokkos::RangePolicy<ExecSpace>(0, n_discs);
  if (all_pairs) {
    AllPairs<true> f{discs,      nodes.x, nodes.radius, skin,  n_discs,
                     row_offset, pair_i,  pair_j,       pair_b};
    Kokkos::parallel_for("fracta::contact_all_pairs_fill", policy, f);
    return;  // rows are already in increasing j
  }
  BinnedPairs<true> f{discs,      nodes.x, nodes.radius, grid,   cell_start,
                      cell_discs, skin,    row_offset,   pair_i, pair_b};
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

// Largest squared displacement of a disc since the build (m^2). A non-finite position gives
// +inf, so it triggers a rebuild rather than hiding.
inline double max_displacement_sq(const Nodes& nodes, const View<const int*>& discs,
                                  const View<const double* [2]>& x_build) {
  double m = 0.0;
  const auto x = nodes.x;
  Kokkos::parallel_reduce(
      "fracta::contact_displacement", Kokkos::RangePolicy<ExecSpace>(0, discs.extent(0)),
      KOKKOS_LAMBDA(const int a, double& acc) {
        const int n = discs(a);
        const double dx = x(n, 0) - x_build(a, 0), dy = x(n, 1) - x_build(a, 1);
        double d2 = dx * dx + dy * dy;
        if (!isfinite_(d2)) d2 = 1e300;
        acc = max_(acc, d2);
      },
      Kokkos::Max<double>(m));
  return m;
}

}  // namespace fracta
