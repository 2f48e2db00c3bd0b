#include "host/snapshot.hpp"

#include <string_view>
#include <type_traits>
#include <utility>

#include "kernels/rows.hpp"

namespace fracta {

namespace {

struct Rows {
  RowMap map;
  int count = 0;
};

// The rows of `view` that a step can change, under the lists of `lists` at the lengths
// `lengths`. A view whose rows do not match its entity (no list kept, an unexpected extent)
// keeps every row: never too few.
template <class V>
Rows rows_to_keep(std::string_view name, const V& view, const StateViews& lists,
                  const ListCounts& lengths, const int element_count) {
  const int extent = static_cast<int>(view.extent(0));
  if (extent == 0) return {};
  switch (state_rows(name)) {
    case StateRows::list_prefix:
      return {{}, state_list_length(name, lengths)};
    case StateRows::active_elements:
      if (element_count > 0 && extent % element_count == 0) {
        const int per = extent / element_count;  // 1, or the quadrature points
        return {{lists.elements.active, per}, lengths.active_elements * per};
      }
      break;
    case StateRows::converted_cells:
      if (extent == element_count && lists.converted.extent(0) > 0)
        return {{lists.converted, 1}, lengths.converted};
      break;
    case StateRows::used_bonds:
      if (lists.bonds.used.extent(0) > 0) return {{lists.bonds.used, 1}, lengths.used_bonds};
      break;
    case StateRows::particles:
      if (lists.nodes.particle_list.extent(0) > 0)
        return {{lists.nodes.particle_list, 1}, lengths.particles};
      break;
    case StateRows::contact_discs:
      // (No contact: the view is empty, above.)
      return {{lists.contact_discs, 1}, lists.contact_disc_count};
    case StateRows::all:
      break;
  }
  return {{}, extent};
}

// The buffer of a view of `view`'s value type in s (const or not).
template <class V, class S>
auto& buffer_of(const V&, S& s) {
  using Value = typename V::non_const_value_type;
  static_assert(std::is_same_v<Value, double> || std::is_same_v<Value, int>,
                "a state view of another value type needs a buffer of its own");
  if constexpr (std::is_same_v<Value, double>)
    return s.reals;
  else
    return s.ints;
}

// Room in `buffer` for `rows` rows of `columns` (rank 2) or for `rows` entries (rank 1). Grown
// by half again beyond the need, so that a list growing by a few entries between saves does not
// reallocate at every save.
template <class Buffer>
void reserve_rows(Buffer& buffer, const int rows, const int columns, const std::string& label) {
  const int old_rows = static_cast<int>(buffer.extent(0));
  if (old_rows >= rows && (Buffer::rank == 1 || static_cast<int>(buffer.extent(1)) == columns))
    return;
  const int capacity = old_rows == 0 ? rows : std::max(rows, old_rows + old_rows / 2);
  buffer = Buffer();  // free the old one first
  const auto alloc = Kokkos::view_alloc(Kokkos::WithoutInitializing, label);
  if constexpr (Buffer::rank == 1)
    buffer = Buffer(alloc, capacity);
  else
    buffer = Buffer(alloc, capacity, columns);
}

}  // namespace

void StateSnapshot::save(const Model& m, StateViews live) {
  lists_ = ListCounts::of(m);
  const SceneChanges scene = scene_changes(m);
  // The contact's discs are no state view: their list is kept here, as the rows to restore.
  contact_disc_count_ = live.contact_disc_count;
  reserve_rows(contact_discs_, contact_disc_count_, 1, "contact_discs_snapshot");
  if (contact_disc_count_ > 0)
    Kokkos::deep_copy(Kokkos::subview(contact_discs_, std::make_pair(0, contact_disc_count_)),
                      Kokkos::subview(live.contact_discs, std::make_pair(0, contact_disc_count_)));
  size_t index = 0;
  for_each_state_view(live, live, [&](const char* name, const auto& view, const auto&) {
    if (saved_.size() <= index) saved_.emplace_back();
    Saved& s = saved_[index++];
    if (state_view_constant(name, scene)) {
      s = Saved();  // nothing to keep: restore leaves it alone
      return;
    }
    const Rows rows = rows_to_keep(name, view, live, lists_, m.elements.count);
    auto& buffer = buffer_of(view, s);
    reserve_rows(buffer, rows.count, columns_of(view), std::string(name) + "_snapshot");
    gather_rows(view, rows.map, rows.count, buffer);
    s.rows = rows.count;
  });
}

void StateSnapshot::restore(Model& m, StateViews live) const {
  const ListCounts now = ListCounts::of(m);
  const int elements = m.elements.count;
  const SceneChanges scene = scene_changes(m);
  // 1. The rows that joined a list since the save go back to their values before joining
  //    (state_value_before_joining: 0 from build_lattice's sparse_zero_view, or the alive flag's
  //    1). Every row listed now is reset; the saved ones are written again below.
  for_each_state_view(live, live, [&](const char* name, const auto& view, const auto&) {
    const StateRows kind = state_rows(name);
    if ((kind != StateRows::converted_cells && kind != StateRows::used_bonds &&
         kind != StateRows::particles && kind != StateRows::contact_discs) ||
        state_view_constant(name, scene))
      return;
    const Rows rows = rows_to_keep(name, view, live, now, elements);
    if (rows.map.list.extent(0) == 0) return;  // every row is saved
    reset_rows(view, rows.map, rows.count, state_value_before_joining(name));
  });
  // 2. The lists, then 3. every other view's rows through them (the contact's discs: as saved).
  StateViews saved_lists = live;
  saved_lists.contact_discs = contact_discs_;
  saved_lists.contact_disc_count = contact_disc_count_;
  for (const bool lists : {true, false}) {
    size_t index = 0;
    for_each_state_view(live, live, [&](const char* name, const auto& view, const auto&) {
      const Saved& s = saved_[index++];
      if ((state_rows(name) == StateRows::list_prefix) != lists || state_view_constant(name, scene))
        return;
      const Rows rows = rows_to_keep(name, view, saved_lists, lists_, elements);
      scatter_rows(buffer_of(view, s), rows.map, s.rows, view);
    });
  }
  lists_.apply_to(m);
}

double StateSnapshot::bytes() const {
  double total = contact_discs_.span() * sizeof(int);
  for (const Saved& s : saved_)
    total += s.reals.span() * sizeof(double) + s.ints.span() * sizeof(int);
  return total;
}

}  // namespace fracta

namespace fracta {

int state_list_length(std::string_view name, const ListCounts& lengths) {
  if (name == "converted") return lengths.converted;
  if (name == "bonds.used") return lengths.used_bonds;
  if (name == "nodes.particle_list") return lengths.particles;
  return lengths.active_elements;  // elements.active
}

}  // namespace fracta
