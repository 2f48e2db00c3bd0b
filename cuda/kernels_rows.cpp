// CUDA check unit for src/kernels/rows.hpp: the row copies of the lean snapshot, for a rank-1,
// a rank-2 and a LayoutLeft (ColumnView) state view.
#include "kernels/rows.hpp"

namespace fracta::cuda_check {

void rows_kernels(const View<double*>& scalar, const View<int* [2]>& pair,
                  const ColumnView<double* [4]>& column, const View<int*>& list, int rows) {
  const RowMap map{list, 2};
  RowBuffer<View<double*>> scalar_buffer("scalar", rows, 1);
  gather_rows(scalar, map, rows, scalar_buffer);
  scatter_rows(scalar_buffer, map, rows, scalar);
  reset_rows(scalar, map, rows);
  RowBuffer<View<int* [2]>> pair_buffer("pair", rows, 2);
  gather_rows(pair, map, rows, pair_buffer);
  scatter_rows(pair_buffer, map, rows, pair);
  reset_rows(pair, map, rows);
  RowBuffer<ColumnView<double* [4]>> column_buffer("column", rows, 4);
  gather_rows(column, map, rows, column_buffer);
  scatter_rows(column_buffer, map, rows, column);
}

}  // namespace fracta::cuda_check
