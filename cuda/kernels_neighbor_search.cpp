// CUDA check unit for src/kernels/neighbor_search.hpp: bounds, binning, both pair searches
// (BinnedPairs and AllPairs, count and fill, joined pairs left out), the scan, the rows of a
// restored list, the Verlet displacement check, and the admission of unjoined pairs.
#include "kernels/neighbor_search.hpp"

namespace fracta::cuda_check {

long neighbor_search_kernels(const Nodes& nodes, const View<const int*>& discs,
                             const View<int*>& cell_start, const View<int*>& cell_cursor,
                             const View<int*>& cell_discs, const View<int*>& row_offset,
                             const View<int*>& pair_i, const View<int*>& pair_j,
                             const View<int*>& pair_b, const View<double* [2]>& x_build,
                             const Topology& topo, const Bonds& bonds,
                             const View<int*>& extra_count, const View<int*>& extra_offset,
                             const View<int*>& extra, const View<int*>& merged_rows) {
  const int n_discs = static_cast<int>(discs.extent(0));
  const double skin = 1e-4;
  const CellGrid grid = make_grid(disc_bounds(nodes, discs), skin, 1 << 20);
  bin_discs(nodes, discs, grid, cell_start, cell_cursor, cell_discs);
  long total = 0, last = 0;
  for (const bool all_pairs : {false, true}) {
    count_candidates(nodes, discs, skin, topo, all_pairs, grid, cell_start, cell_discs, row_offset);
    last = scan_rows(row_offset, n_discs);
    total += last;
    fill_candidates(nodes, discs, skin, topo, all_pairs, grid, cell_start, cell_discs, row_offset,
                    pair_i, pair_j, pair_b);
  }
  index_candidates(discs, pair_i, pair_j, last, row_offset, pair_b);
  record_positions(nodes, discs, x_build);
  const DiscMotion motion = disc_motion(nodes, discs, x_build, bonds.broken_count);
  const double d2 = motion.displacement_sq + motion.speed_sq + motion.broken;
  // Admitting the pairs of the broken slots, then merging them into the rows.
  const int broken = static_cast<int>(bonds.broken_since_search.extent(0));
  Kokkos::parallel_for(
      "fracta::cuda_check_admit", Kokkos::RangePolicy<ExecSpace>(0, broken),
      UnjoinedPairs<true>{bonds.broken_since_search, bonds.nodes, discs, row_offset, pair_b, topo,
                          extra_count, extra_offset, extra});
  count_merged_rows({}, row_offset, extra_offset, extra_count, extra, merged_rows);
  Kokkos::parallel_for("fracta::cuda_check_merge", Kokkos::RangePolicy<ExecSpace>(0, n_discs),
                       MergeInsertedRows{discs,
                                         {},
                                         row_offset,
                                         pair_b,
                                         {},
                                         extra_offset,
                                         extra_count,
                                         extra,
                                         merged_rows,
                                         pair_i,
                                         pair_j,
                                         pair_b});
  return total + (d2 > 1.0 ? 1 : 0);
}

}  // namespace fracta::cuda_check
