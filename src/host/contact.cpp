#include "host/contact.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "host/sparse_zero_view.hpp"

namespace fracta {

namespace {

// v holds at least n entries (reallocated with headroom, contents dropped, if not).
template <class V>
void reserve(V& v, size_t n, const char* label) {
  if (v.extent(0) < n || v.data() == nullptr)
    v = V(Kokkos::view_alloc(Kokkos::WithoutInitializing, std::string(label)), n + n / 4 + 16);
}

}  // namespace

ContactSystem::ContactSystem(std::vector<int> disc_nodes, const ContactParams& params, double skin)
    : skin_(skin) {
  if (!(skin >= 0.0)) throw std::invalid_argument("contact skin must be >= 0");
  if (!(params.damping_ratio >= 0.0) || !(params.friction >= 0.0))
    throw std::invalid_argument("contact damping_ratio and friction must be >= 0");
  law_.damping_ratio = params.damping_ratio;
  law_.friction = params.friction;
  set_disc_nodes(std::move(disc_nodes));
}

void ContactSystem::set_disc_nodes(std::vector<int> disc_nodes) {
  std::sort(disc_nodes.begin(), disc_nodes.end());
  disc_nodes.erase(std::unique(disc_nodes.begin(), disc_nodes.end()), disc_nodes.end());
  if (!disc_nodes.empty() && disc_nodes.front() < 0)
    throw std::invalid_argument("contact disc node ids must be >= 0");
  const size_t n = disc_nodes.size();
  tracking_ = false;
  resize_discs(n);
  Kokkos::deep_copy(discs_,
                    Kokkos::View<const int*, HostSpace, Kokkos::MemoryTraits<Kokkos::Unmanaged>>(
                        disc_nodes.data(), n));
}

void ContactSystem::resize_discs(size_t n) {
  reserve(disc_buffer_, n, "fracta::contact_discs");  // headroom: a conversion adds a few
  reserve(x_build_buffer_, n, "fracta::contact_x_build");
  reserve(cell_discs_buffer_, n, "fracta::contact_cell_discs");
  reserve(row_offset_buffer_, n + 1, "fracta::contact_row_offset");
  const auto first = std::make_pair(size_t{0}, n);
  discs_ = Kokkos::subview(disc_buffer_, first);
  x_build_ = Kokkos::subview(x_build_buffer_, first, Kokkos::ALL);
  cell_discs_ = Kokkos::subview(cell_discs_buffer_, first);
  row_offset_ = Kokkos::subview(row_offset_buffer_, std::make_pair(size_t{0}, n + 1));
  built_ = false;
}

void ContactSystem::set_lattice(const Topology& topo, Bonds& bonds) {
  topo_ = topo;
  built_ = false;
  if (bonds.count == 0) return;  // nothing can break
  // A break that a search misses is a contact missed: on overflow (more breaks between two
  // searches than the queue holds) the list is rebuilt instead. One slot in 256 may break
  // between two searches (4096 at least): a shattering lattice then rebuilds only when most of
  // a large region breaks at once.
  const int capacity = std::max(4096, bonds.count / 256);
  broken_ = View<int*>(Kokkos::view_alloc(Kokkos::WithoutInitializing, "fracta::contact_broken"),
                       capacity);
  broken_count_ = View<int>("fracta::contact_broken_count");
  bonds.broken_since_search = broken_;
  bonds.broken_count = broken_count_;
  slot_nodes_ = bonds.nodes;
}

void ContactSystem::track_surface(std::vector<int> surface_nodes, const Nodes& nodes) {
  std::sort(surface_nodes.begin(), surface_nodes.end());
  surface_nodes.erase(std::unique(surface_nodes.begin(), surface_nodes.end()), surface_nodes.end());
  if (!surface_nodes.empty() && (surface_nodes.front() < 0 || surface_nodes.back() >= nodes.count))
    throw std::invalid_argument("contact surface node id out of range");
  const size_t n = surface_nodes.size();
  surface_ =
      View<int*>(Kokkos::view_alloc(Kokkos::WithoutInitializing, "fracta::contact_surface"), n);
  Kokkos::deep_copy(surface_,
                    Kokkos::View<const int*, HostSpace, Kokkos::MemoryTraits<Kokkos::Unmanaged>>(
                        surface_nodes.data(), n));
  surface_only_ = View<int*>(
      Kokkos::view_alloc(Kokkos::WithoutInitializing, "fracta::contact_surface_only"), n);
  tracking_ = true;
  resize_discs(0);
  refreshed_particles_ = -1;
  refresh_discs(nodes);
}

void ContactSystem::reserve_pairs(long count) {
  const size_t n = static_cast<size_t>(count);
  reserve(pair_i_, n, "fracta::contact_pair_i");
  reserve(pair_j_, n, "fracta::contact_pair_j");
  reserve(pair_b_, n, "fracta::contact_pair_b");
}

bool ContactSystem::refresh_discs(const Nodes& nodes) {
  if (!tracking_) return false;
  ProfilingRegion region("fracta::contact_search");
  // The discs are a function of the particles, and the particles only grow between restores
  // (a restore returns to a subset): the same count is the same set.
  const int particle_count = nodes.particle_list.extent(0) > 0 ? nodes.particle_count : 0;
  if (particle_count == refreshed_particles_) return false;
  refreshed_particles_ = particle_count;
  const int surface_count = surface_without_particles(surface_, nodes, surface_only_);
  const int count = surface_count + particle_count;
  const int old_count = disc_count();
  if (old_count == count) return false;
  // Few new discs (a conversion's): insert them. Many (a restore, a large batch): rebuild.
  const bool insert =
      insertion_ && built_ && !all_pairs_ && count > old_count && 8 * (count - old_count) <= count;
  if (insert) {
    Insertion& w = insert_;
    const auto discs = std::make_pair(0, old_count), rows = std::make_pair(0, old_count + 1);
    reserve(w.old_discs, old_count, "fracta::contact_insert_old_discs");
    reserve(w.old_x_build, old_count, "fracta::contact_insert_old_x_build");
    reserve(w.old_row_offset, old_count + 1, "fracta::contact_insert_old_rows");
    Kokkos::deep_copy(Kokkos::subview(w.old_discs, discs), discs_);
    Kokkos::deep_copy(Kokkos::subview(w.old_x_build, discs, Kokkos::ALL), x_build_);
    Kokkos::deep_copy(Kokkos::subview(w.old_row_offset, rows), row_offset_);
    // The per-pair arrays the merge reads are swapped out, not copied: it writes new ones (and
    // if the insertion falls back, the rebuild rewrites them).
    std::swap(pair_b_, w.old_pair_b);
  }
  resize_discs(static_cast<size_t>(count));
  merge_disjoint_sorted("fracta::contact_disc_merge", surface_only_, surface_count,
                        nodes.particle_list, particle_count, discs_);
  if (insert && insert_new_discs(nodes, old_count)) built_ = true;
  return true;
}

bool ContactSystem::insert_new_discs(const Nodes& nodes, int old_count) {
  Insertion& w = insert_;
  const int n = disc_count();
  reserve(w.position, n, "fracta::contact_insert_position");
  reserve(w.old_index, n, "fracta::contact_insert_old_index");
  reserve(w.new_of_old, old_count, "fracta::contact_insert_new_of_old");
  reserve(w.new_discs, n, "fracta::contact_insert_new_discs");
  const auto all = std::make_pair(0, n);
  const auto old_discs = Kokkos::subview(w.old_discs, std::make_pair(0, old_count));
  const auto old_x_build =
      Kokkos::subview(w.old_x_build, std::make_pair(0, old_count), Kokkos::ALL);
  const auto position = Kokkos::subview(w.position, all, Kokkos::ALL);
  const auto old_index = Kokkos::subview(w.old_index, all);
  if (w.node_slot.extent(0) < static_cast<size_t>(nodes.count))
    // Zero, and written at the discs' nodes alone: its pages are used where the discs are.
    w.node_slot = sparse_zero_view<View<int*>>("fracta::contact_insert_node_slot", nodes.count);
  const int found = map_inserted_discs(nodes, discs_, old_discs, old_x_build, w.node_slot,
                                       old_index, w.new_of_old, position);
  if (found != old_count) return false;
  const int added = list_inserted_discs(old_index, w.new_discs);
  DiscBounds box = inserted_disc_bounds(nodes, discs_, w.new_discs, added, position);
  box.r_max = std::max(box.r_max, build_r_max_);  // radii only shrink: the old discs' bound
  build_r_max_ = box.r_max;
  const CellGrid grid = make_grid(box, skin_, std::max(4L * added, 64L));
  reserve(w.cell_start, grid.cell_count() + 1, "fracta::contact_insert_cell_start");
  reserve(w.cell_cursor, grid.cell_count(), "fracta::contact_insert_cell_cursor");
  reserve(w.cell_items, added, "fracta::contact_insert_cell_items");
  bin_points(added, ListedPositions{w.new_discs, position}, grid, w.cell_start, w.cell_cursor,
             w.cell_items);
  // The inserted pairs, per row: count, scan, fill, sort.
  reserve(w.extra_offset, n + 1, "fracta::contact_insert_extra_offset");
  reserve(w.extra_cursor, n, "fracta::contact_insert_extra_cursor");
  const auto extra_offset = Kokkos::subview(w.extra_offset, std::make_pair(0, n + 1));
  const auto extra_cursor = Kokkos::subview(w.extra_cursor, all);
  const auto policy = Kokkos::RangePolicy<ExecSpace>(0, n);
  Kokkos::deep_copy(extra_offset, 0);
  Kokkos::parallel_for("fracta::contact_insert_count", policy,
                       InsertedPairs<false>{discs_,
                                            old_index,
                                            w.new_discs,
                                            position,
                                            nodes.radius,
                                            grid,
                                            w.cell_start,
                                            w.cell_items,
                                            skin_,
                                            topo_,
                                            extra_offset,
                                            {},
                                            {}});
  const long extra_total = scan_rows(extra_offset, n);
  reserve(w.extra, extra_total, "fracta::contact_insert_extra");
  Kokkos::deep_copy(extra_cursor, 0);
  Kokkos::parallel_for("fracta::contact_insert_fill", policy,
                       InsertedPairs<true>{discs_, old_index, w.new_discs, position, nodes.radius,
                                           grid, w.cell_start, w.cell_items, skin_, topo_,
                                           extra_cursor, extra_offset, w.extra});
  pair_count_ = merge_rows(old_index, w.new_of_old, extra_offset, extra_cursor);
  Kokkos::deep_copy(x_build_, position);
  gather_built_ = false;
  ++insertions_;
  return true;
}

void ContactSystem::set_all_pairs(bool on) {
  if (on != all_pairs_) built_ = false;
  all_pairs_ = on;
}

long ContactSystem::merge_rows(const View<const int*>& old_index,
                               const View<const int*>& new_of_old,
                               const View<const int*>& extra_offset,
                               const View<int*>& extra_count) {
  const Insertion& w = insert_;
  const int n = disc_count();
  count_merged_rows(old_index, w.old_row_offset, extra_offset, extra_count, w.extra, row_offset_);
  const long total = scan_rows(row_offset_, n);
  if (total > 2147483647L) throw std::runtime_error("contact: more than 2^31 candidate pairs");
  reserve_pairs(total);
  Kokkos::parallel_for(
      "fracta::contact_merge_rows", Kokkos::RangePolicy<ExecSpace>(0, n),
      MergeInsertedRows{discs_, old_index, w.old_row_offset, w.old_pair_b, new_of_old, extra_offset,
                        extra_count, w.extra, row_offset_, pair_i_, pair_j_, pair_b_});
  return total;
}

void ContactSystem::admit_unjoined(const View<const int*>& slots, const int count) {
  if (!built_ || count == 0 || disc_count() == 0) return;
  Insertion& w = insert_;
  const int n = disc_count();
  reserve(w.extra_offset, n + 1, "fracta::contact_insert_extra_offset");
  reserve(w.extra_cursor, n, "fracta::contact_insert_extra_cursor");
  const auto extra_offset = Kokkos::subview(w.extra_offset, std::make_pair(0, n + 1));
  const auto extra_cursor = Kokkos::subview(w.extra_cursor, std::make_pair(0, n));
  const auto policy = Kokkos::RangePolicy<ExecSpace>(0, count);
  Kokkos::deep_copy(extra_offset, 0);
  Kokkos::parallel_for(
      "fracta::contact_admit_count", policy,
      UnjoinedPairs<false>{
          slots, slot_nodes_, discs_, row_offset_, pair_b_, topo_, extra_offset, {}, {}});
  const long extra_total = scan_rows(extra_offset, n);
  if (extra_total == 0) return;
  reserve(w.extra, extra_total, "fracta::contact_insert_extra");
  Kokkos::deep_copy(extra_cursor, 0);
  Kokkos::parallel_for("fracta::contact_admit_fill", policy,
                       UnjoinedPairs<true>{slots, slot_nodes_, discs_, row_offset_, pair_b_, topo_,
                                           extra_cursor, extra_offset, w.extra});
  // Every disc is old: its row now, and the admitted entries, merged.
  reserve(w.old_row_offset, n + 1, "fracta::contact_insert_old_rows");
  const auto rows = std::make_pair(0, n + 1);
  Kokkos::deep_copy(Kokkos::subview(w.old_row_offset, rows), row_offset_);
  std::swap(pair_b_, w.old_pair_b);  // read by the merge, which writes a new one
  const long total = merge_rows({}, {}, extra_offset, extra_cursor);
  admissions_ += total - pair_count_;
  pair_count_ = total;
  gather_built_ = false;
}

void ContactSystem::admit_converted(const View<const int*>& cells, const int count,
                                    const View<const int* [6]>& element_bonds) {
  if (!built_ || count == 0 || broken_.extent(0) == 0) return;
  Insertion& w = insert_;
  reserve(w.slots, 6 * static_cast<size_t>(count), "fracta::contact_admit_slots");
  const auto slots = w.slots;
  Kokkos::parallel_for(
      "fracta::contact_admit_cell_slots", Kokkos::RangePolicy<ExecSpace>(0, 6 * count),
      KOKKOS_LAMBDA(const int k) { slots(k) = element_bonds(cells(k / 6), k % 6); });
  admit_unjoined(slots, 6 * count);
}

bool ContactSystem::update(const Nodes& nodes) {
  if (built_) {
    const double half = 0.5 * skin_;
    const DiscMotion motion = disc_motion(nodes, discs_, x_build_, broken_count_);
    max_speed_ = std::sqrt(motion.speed_sq);
    const int broken = static_cast<int>(motion.broken);
    if (motion.displacement_sq <= half * half && broken <= static_cast<int>(broken_.extent(0))) {
      if (broken > 0) {
        admit_unjoined(broken_, broken);
        Kokkos::deep_copy(broken_count_, 0);
      }
      return false;
    }
    rebuild(nodes);
    return true;
  }
  rebuild(nodes);  // the build positions are those of the discs now
  max_speed_ = std::sqrt(disc_motion(nodes, discs_, x_build_).speed_sq);
  return true;
}

double ContactSystem::motion_bound() const {
  // Half the skin per step at the fastest disc's speed (see contact.hpp).
  return max_speed_ > 0.0 ? 0.5 * skin_ / max_speed_ : 1e300;
}

void ContactSystem::rebuild(const Nodes& nodes) {
  Kokkos::Profiling::pushRegion("fracta::contact_search");
  // The build sees every break so far (the bonds' states).
  if (broken_count_.data()) Kokkos::deep_copy(broken_count_, 0);
  const int n = disc_count();
  CellGrid grid;
  if (!all_pairs_ && n > 0) {
    // At most 4 cells per disc, but 65536 in any case: the discs of a scene are often a hollow
    // frame (the boundary nodes) whose box would otherwise get cells of several radii.
    const DiscBounds box = disc_bounds(nodes, discs_);
    build_r_max_ = box.r_max;
    grid = make_grid(box, skin_, std::max(4L * n, 65536L));
    const size_t cells = static_cast<size_t>(grid.cell_count());
    reserve(cell_start_, cells + 1, "fracta::contact_cell_start");  // bin_points zeroes it
    reserve(cell_cursor_, cells, "fracta::contact_cell_cursor");
    bin_discs(nodes, discs_, grid, cell_start_, cell_cursor_, cell_discs_);
  }
  count_candidates(nodes, discs_, skin_, topo_, all_pairs_, grid, cell_start_, cell_discs_,
                   row_offset_);
  const long total = scan_rows(row_offset_, n);
  if (total > 2147483647L) throw std::runtime_error("contact: more than 2^31 candidate pairs");
  reserve_pairs(total);
  fill_candidates(nodes, discs_, skin_, topo_, all_pairs_, grid, cell_start_, cell_discs_,
                  row_offset_, pair_i_, pair_j_, pair_b_);
  record_positions(nodes, discs_, x_build_);
  pair_count_ = total;
  built_ = true;
  gather_built_ = false;
  ++rebuilds_;
  Kokkos::Profiling::popRegion();
}

ContactStepResult ContactSystem::compute_forces(const Nodes& nodes, double dt,
                                                const ResultSlot<ContactSums>& into) {
  if (!built_) throw std::logic_error("ContactSystem::compute_forces before update");
  if (pair_count_ == 0) {  // an intact lattice: no pair, no force
    if (into.data()) put(into, ContactSums());
    return {};
  }
  Kokkos::Profiling::pushRegion("fracta::contact_forces");
  // The gather's columns, once per list.
  if (!gather_built_) {
    // Capacity kept across lists: an insertion changes the disc count at every conversion.
    const size_t n = discs_.extent(0), pairs = std::max(pair_count_, 1L);
    reserve(gather_.col_offset, n + 1, "fracta::contact_col_offset");
    reserve(gather_.col_cursor, n, "fracta::contact_col_cursor");
    reserve(gather_.col_pairs, pairs, "fracta::contact_col_pairs");
    reserve(gather_.pair_force, pairs, "fracta::contact_pair_force");
    build_contact_gather(discs_, row_offset_, pair_b_, pair_count_, gather_);
    gather_built_ = true;
  }
  const ContactSums s =
      contact_forces(nodes, pair_i_, pair_j_, pair_count_, law_, dt, gather_, into, rigid_surface_);
  Kokkos::Profiling::popRegion();
  return contact_step_result(s);
}

std::vector<std::array<int, 2>> ContactSystem::candidate_pairs_host() const {
  std::vector<std::array<int, 2>> out(static_cast<size_t>(pair_count_));
  if (pair_count_ == 0) return out;
  const auto range = std::make_pair(0L, pair_count_);
  auto hi = Kokkos::create_mirror_view_and_copy(HostSpace(), Kokkos::subview(pair_i_, range));
  auto hj = Kokkos::create_mirror_view_and_copy(HostSpace(), Kokkos::subview(pair_j_, range));
  for (long p = 0; p < pair_count_; ++p) out[p] = {hi(p), hj(p)};
  std::sort(out.begin(), out.end());
  return out;
}

ContactSystem::ListState ContactSystem::list_state() const {
  ListState s;
  s.built = built_;
  s.rebuilds = rebuilds_;
  const auto range = std::make_pair(0L, pair_count_);
  auto hi = Kokkos::create_mirror_view_and_copy(HostSpace(), Kokkos::subview(pair_i_, range));
  auto hj = Kokkos::create_mirror_view_and_copy(HostSpace(), Kokkos::subview(pair_j_, range));
  s.pair_i.assign(hi.data(), hi.data() + pair_count_);
  s.pair_j.assign(hj.data(), hj.data() + pair_count_);
  auto xb = Kokkos::create_mirror_view_and_copy(HostSpace(), x_build_);
  for (size_t k = 0; k < xb.extent(0); ++k)
    for (int d = 0; d < 2; ++d) s.x_build.push_back(xb(k, d));
  return s;
}

void ContactSystem::restore_list_state(const ListState& s) {
  const size_t n = discs_.extent(0);
  if (s.pair_i.size() != s.pair_j.size() || s.x_build.size() != 2 * n)
    throw std::invalid_argument("contact list state: sizes do not match the contact discs");
  const long count = static_cast<long>(s.pair_i.size());
  reserve_pairs(count);
  using HostInts = Kokkos::View<const int*, HostSpace, Kokkos::MemoryTraits<Kokkos::Unmanaged>>;
  const auto range = std::make_pair(0L, count);
  Kokkos::deep_copy(Kokkos::subview(pair_i_, range), HostInts(s.pair_i.data(), count));
  Kokkos::deep_copy(Kokkos::subview(pair_j_, range), HostInts(s.pair_j.data(), count));
  auto xb = Kokkos::create_mirror_view(x_build_);
  for (size_t k = 0; k < n; ++k)
    for (int d = 0; d < 2; ++d) xb(k, d) = s.x_build[2 * k + d];
  Kokkos::deep_copy(x_build_, xb);
  index_candidates(discs_, pair_i_, pair_j_, count, row_offset_, pair_b_);  // for the gather
  pair_count_ = count;
  built_ = s.built;
  gather_built_ = false;
  rebuilds_ = s.rebuilds;
  if (broken_count_.data()) Kokkos::deep_copy(broken_count_, 0);
  // A list that holds a joined pair breaks the force kernel's premise: rebuilt.
  const Topology topo = topo_;
  const auto pi = pair_i_, pj = pair_j_;
  int joined = 0;
  Kokkos::parallel_reduce(
      "fracta::contact_restored_joined", Kokkos::RangePolicy<ExecSpace>(0, count),
      KOKKOS_LAMBDA(const int p, int& acc) { acc += topo.joined(pi(p), pj(p)) ? 1 : 0; }, joined);
  if (joined > 0) built_ = false;
}

}  // namespace fracta
