// Views whose memory grows with the part a run writes (host builds): see sparse_zero_view.
#pragma once
#include <string>

#include "host/memory.hpp"
#include "kernels/compat.hpp"

namespace fracta {

// A zero-filled view of state that a run writes in a small part only, where the cells that
// convert are: the bond slots' state, the lattice state of the cells, the contact forces of the
// nodes that are discs. Allocated without Kokkos' fill and cleared by zero_lazily (memory.hpp),
// so that on a Linux host its memory grows, page by page, with the region the run writes (a
// page is 512 doubles: a few hundred slots along one lattice direction), not with the mesh. On
// a GPU the view is cleared and resident, as any other.
template <class V, class... Extents>
V sparse_zero_view(const std::string& label, const Extents... extents) {
  V view(Kokkos::view_alloc(Kokkos::WithoutInitializing, label), extents...);
  using Value = typename V::non_const_value_type;
  if constexpr (Kokkos::SpaceAccessibility<Kokkos::HostSpace, typename V::memory_space>::accessible)
    zero_lazily(view.data(), view.span() * sizeof(Value));
  else
    Kokkos::deep_copy(view, Value(0));
  return view;
}

}  // namespace fracta
