// The last good state of a run, kept so that a numerical failure can write it (simulation.cpp:
// save_snapshot, restore_snapshot). Lean: of each view a step mutates (state_views.hpp) it keeps
// only the rows a step can change (state_rows): the active elements', the used bond slots', the
// converted cells', the particles', the contact discs' and the used part of each list, so a large
// adaptive body that has barely converted keeps no copy of its millions of inactive bond slots.
// Restoring puts back the saved rows and returns every row that joined a list since to its value
// before joining, so the state is the saved one, bit for bit.
#pragma once
#include <string>
#include <string_view>
#include <vector>

#include "host/ledger.hpp"
#include "host/state_views.hpp"

namespace fracta {

// The length in `lengths` of the list named `name` (StateRows::list_prefix: converted,
// bonds.used, nodes.particle_list, elements.active).
int state_list_length(std::string_view name, const ListCounts& lengths);

class StateSnapshot {
 public:
  // Saves the rows of `live` (the model's state views) that a step can change, and the lists'
  // lengths. The buffers grow when the lists do (by half again), and are kept.
  void save(const Model& m, StateViews live);
  // Puts the saved state back into `live` and the lists' lengths into m.
  void restore(Model& m, StateViews live) const;
  double bytes() const;  // device memory of the buffers (B)

 private:
  struct Saved {
    View<double**> reals;
    View<int**> ints;
    int rows = 0;  // rows saved
  };
  std::vector<Saved> saved_;  // one per state view, in for_each_state_view's order
  ListCounts lists_;
  View<int*> contact_discs_;  // the contact's discs at the save (StateViews::contact_discs)
  int contact_disc_count_ = 0;
};

}  // namespace fracta
