// Copies of chosen rows of a state view into a compact buffer and back, for the lean failure
// snapshot (src/host/snapshot.cpp): it keeps only the rows a step can change (the active
// elements, the used bond slots, the particles), not every row of the mesh.
#pragma once
#include "kernels/compat.hpp"

namespace fracta {

// Row r of a buffer holds row list(r / per) * per + r % per of the view (per: the view's rows
// per list entry, e.g. an element's quadrature points), or row r itself without a list.
struct RowMap {
  View<const int*> list;  // empty: the identity
  int per = 1;
  KOKKOS_INLINE_FUNCTION int operator()(const int r) const {
    return list.extent(0) == 0 ? r : list(r / per) * per + r % per;
  }
};

// The buffer of a view's rows: rows x its columns (1 for a rank-1 view).
template <class V>
using RowBuffer = View<typename V::non_const_value_type**>;

template <class V>
inline int columns_of(const V& v) {
  if constexpr (V::rank == 1)
    return 1;
  else
    return static_cast<int>(v.extent(1));
}

// One row's copies, by the view's rank (functions, not in the kernels' lambdas: nvcc's device
// lambdas may not capture first inside an `if constexpr`).
template <class V>
KOKKOS_INLINE_FUNCTION void row_to_buffer(const V& view, const int row, const RowBuffer<V>& buffer,
                                          const int r, const int columns) {
  if constexpr (V::rank == 1)
    buffer(r, 0) = view(row);
  else
    for (int c = 0; c < columns; ++c) buffer(r, c) = view(row, c);
}
template <class V>
KOKKOS_INLINE_FUNCTION void buffer_to_row(const RowBuffer<V>& buffer, const int r, const V& view,
                                          const int row, const int columns) {
  if constexpr (V::rank == 1)
    view(row) = buffer(r, 0);
  else
    for (int c = 0; c < columns; ++c) view(row, c) = buffer(r, c);
}
template <class V>
KOKKOS_INLINE_FUNCTION void fill_row(const V& view, const int row, const int columns,
                                     const typename V::non_const_value_type value) {
  if constexpr (V::rank == 1)
    view(row) = value;
  else
    for (int c = 0; c < columns; ++c) view(row, c) = value;
}

// buffer(r, c) = view(map(r), c) for r < rows.
template <class V>
inline void gather_rows(const V& view, const RowMap& map, const int rows,
                        const RowBuffer<V>& buffer) {
  const int columns = columns_of(view);
  Kokkos::parallel_for(
      "fracta::gather_rows", Kokkos::RangePolicy<ExecSpace>(0, rows),
      KOKKOS_LAMBDA(const int r) { row_to_buffer(view, map(r), buffer, r, columns); });
}

// view(map(r), c) = buffer(r, c) for r < rows.
template <class V>
inline void scatter_rows(const RowBuffer<V>& buffer, const RowMap& map, const int rows,
                         const V& view) {
  const int columns = columns_of(view);
  Kokkos::parallel_for(
      "fracta::scatter_rows", Kokkos::RangePolicy<ExecSpace>(0, rows),
      KOKKOS_LAMBDA(const int r) { buffer_to_row(buffer, r, view, map(r), columns); });
}

// view(map(r), c) = value for r < rows: by default 0, the value a row had before it joined its
// list.
template <class V>
inline void reset_rows(const V& view, const RowMap& map, const int rows,
                       const typename V::non_const_value_type value = 0) {
  const int columns = columns_of(view);
  Kokkos::parallel_for(
      "fracta::reset_rows", Kokkos::RangePolicy<ExecSpace>(0, rows),
      KOKKOS_LAMBDA(const int r) { fill_row(view, map(r), columns, value); });
}

}  // namespace fracta
