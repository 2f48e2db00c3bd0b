// Contact between discs (docs/physics.md 1.2-1.3): the Verlet-list pre-search and the force law,
// orchestrated on the host; all data stay on the device.
//
// Each step: update(nodes) rebuilds the candidate list when some disc moved more than skin/2
// since the last build (or on the first call, after set_disc_nodes or set_all_pairs);
// compute_forces() then adds the contact forces and moments to nodes.f / nodes.moment (which
// the integrator zeroes) and reports energies. Joined pairs (an active bond or element between
// the discs, set_lattice) are left out of the list, as bonded atoms are out of LAMMPS' pair
// lists: an intact lattice lists nothing. A bond that breaks between two builds is noted by the
// bond kernel (Bonds::note_broken) and its pair admitted at the next update, before the forces;
// a conversion's slots are admitted right after it (admit_converted): the pair contacts at
// once, and the list is the one a build would give (neighbor_search.hpp, "Joined pairs").
//
// Which nodes are discs. Either a fixed list (the constructor, set_disc_nodes: tests,
// benchmarks) or, after track_surface(), the discs that can touch now (docs/physics.md 1.3: "every
// particle and every FE boundary node"): the given surface nodes (the mesh's boundary nodes,
// static) and the particles (nodes.particle_list, which only the conversion and a restore
// change; refresh_discs() re-derives the list from them). A node inside the intact FE mesh
// (every element around it alive) is no disc: a disc of another body reaches it only through
// the surface discs, and a node of its own body within r_i + r_j of it shares an element with
// it unless the mesh between them is crushed to half its cell size. Leaving such pairs out
// changes no force while they do not touch, and the pairs that remain keep their order (rows by
// increasing i, each sorted by j): the forces are summed in the same order. Checked by an
// all-pairs oracle over every node through the penetration impact (tests/host/test_contact.cpp);
// a 1-thread run of cases/penetration.toml is bitwise the same as with every node a disc.
// The list costs O(surface + particles) per refresh, no sweep over the nodes, and the contact
// phases then scale with the discs, not with the mesh (docs/performance.md, 1e).
//
// Requirements on Nodes: the particle views (radius, inertia, spin, moment, contact_stiffness,
// particle) are allocated for every node. The contact stiffness of a disc is
// nodes.contact_stiffness (lambda k1, set by the model), so ContactParams::stiffness_factor is
// not used here; damping_ratio and friction are.
#pragma once
#include <array>
#include <vector>

#include "host/case.hpp"
#include "kernels/contact_forces.hpp"
#include "kernels/neighbor_search.hpp"
#include "kernels/state.hpp"

namespace fracta {

struct ContactStepResult {
  double elastic_energy = 0;  // J, sum of 1/2 k delta^2 at the end of the step
  double dissipated = 0;      // J, damping + friction work of this step (>= 0)
  long touching = 0;          // pairs with overlap > 0 that are not joined
};

// The contact kernel's sums (contact_forces) as a step result.
inline ContactStepResult contact_step_result(const ContactSums& s) {
  ContactStepResult r;
  r.elastic_energy = s.v[0];
  r.dissipated = s.v[1];
  r.touching = static_cast<long>(s.v[2] + 0.5);
  return r;
}

class ContactSystem {
 public:
  // disc_nodes: the node ids that are contact discs (particles and FE boundary nodes), any
  // order, duplicates ignored. skin: Verlet skin (m), >= 0 (0 = rebuild whenever a disc moves).
  ContactSystem(std::vector<int> disc_nodes, const ContactParams& params, double skin);

  // The lattice whose joined pairs the list leaves out (default: none, free discs): its
  // topology, and its bonds, which then note their breaks for this system (Bonds::note_broken;
  // the views are set in `bonds`). Forces a rebuild.
  void set_lattice(const Topology& topo, Bonds& bonds);
  // Rebuilds the candidate list if needed and returns true if it did; else admits the pairs of
  // the bonds broken since the last update. Also measures the fastest disc's speed
  // (motion_bound).
  bool update(const Nodes& nodes);
  // The step (s) in which the fastest disc of the last update moves half the skin: the solver's
  // step stays below it, so a disc never moves more than skin/2 in one step, two discs close by
  // at most the skin, and contact starts with an overlap of at most the skin (a quarter cell),
  // whatever the closing speed: no disc can pass through another between two searches
  // (docs/physics.md 1.4, "Contact motion"). 1e300 when nothing moves.
  double motion_bound() const;
  // into: a slot for the kernel's sums (contact_step_result of them; the launch does not wait,
  // and the result returned is empty), or none.
  ContactStepResult compute_forces(const Nodes& nodes, double dt,
                                   const ResultSlot<ContactSums>& into = {});
  // After cells [0, count) of `cells` converted (and refresh_discs took their discs): admits
  // the pairs of their slots that no joint holds any more (a slot broken while its other cell
  // was alive). Nothing to do unless the list is built.
  void admit_converted(const View<const int*>& cells, int count,
                       const View<const int* [6]>& element_bonds);
  // Unjoined pairs admitted into a built list since construction (breaks and conversions).
  long admission_count() const { return admissions_; }
  // Breaks the queue holds between two searches (set_lattice); more rebuild the list.
  int broken_capacity() const { return static_cast<int>(broken_.extent(0)); }

  long candidate_count() const { return pair_count_; }
  long rebuild_count() const { return rebuilds_; }
  int disc_count() const { return static_cast<int>(discs_.extent(0)); }
  double skin() const { return skin_; }
  // The O(N^2) builder (test oracle, benchmark baseline); forces a rebuild at the next update.
  void set_all_pairs(bool on);
  // New fixed set of discs; forces a rebuild and ends surface tracking.
  void set_disc_nodes(std::vector<int> disc_nodes);
  // From now on the discs are the surface nodes (any order, duplicates ignored) and the
  // particles of `nodes`; calls refresh_discs(nodes).
  // Requires nodes.particle_list (increasing, [0, particle_count)) whenever a node is a
  // particle.
  void track_surface(std::vector<int> surface_nodes, const Nodes& nodes);
  // Under surface tracking: re-derives the disc list from the surface and nodes.particle_list
  // (increasing; a merge of the two lists, no sweep over the nodes); if it changed, returns true
  // and either inserts the new discs into the built list (a superset of the old discs, few new
  // ones, insertion on: neighbor_search.hpp, "Inserting new discs") or forces a rebuild.
  // Without tracking: returns false.
  bool refresh_discs(const Nodes& nodes);
  // Inserting new discs instead of rebuilding (default on). Either way the candidate list holds
  // every free pair that can touch before the next rebuild, in the build's order, so the forces
  // are the same to the bit; off: the benchmark baseline and the test's reference.
  void set_insertion(bool on) { insertion_ = on; }
  long insertion_count() const { return insertions_; }
  bool tracks_surface() const { return tracking_; }
  // Forces a rebuild at the next update.
  void invalidate() { built_ = false; }
  // Candidate pairs (i < j), sorted, copied to the host: for tests.
  std::vector<std::array<int, 2>> candidate_pairs_host() const;
  // Device views of the candidates [0, candidate_count()).
  View<const int*> pair_i() const { return pair_i_; }
  View<const int*> pair_j() const { return pair_j_; }
  // The contact discs' node ids, increasing: contact forces act on these nodes only.
  View<const int*> discs() const { return discs_; }
  const ContactLaw& law() const { return law_; }
  // The surfaces of rigid bodies of revolution (contact_forces.hpp, RigidSurface): discs touch
  // them as polygons. Default: none.
  void set_rigid_surface(const RigidSurface& surface) { rigid_surface_ = surface; }

  // The candidate list and its reference positions, for checkpoints: a restart that rebuilt
  // the list at another step than the uninterrupted run would change the order of the force
  // sums (and so the last bits of the result); restoring it makes the restart bitwise.
  struct ListState {
    std::vector<int> pair_i, pair_j;  // candidate_count() pairs, in list order
    std::vector<double> x_build;      // disc_count() x 2 positions at the last build (m)
    bool built = false;
    long rebuilds = 0;
  };
  ListState list_state() const;
  // Throws std::invalid_argument if the sizes do not match this system's discs. A list holding
  // a joined pair (a checkpoint of a version that listed them) is rebuilt at the next update.
  void restore_list_state(const ListState& s);

 private:
  void rebuild(const Nodes& nodes);
  // pair_i_, pair_j_ and pair_b_ hold at least count pairs (contents dropped if they grow).
  void reserve_pairs(long count);
  // The discs_ just re-derived hold the old_count old ones (saved in insert_) and some new
  // ones: adds the new discs' pairs to the list. Returns false (rebuild instead) if the old
  // discs are not all in the new list.
  bool insert_new_discs(const Nodes& nodes, int old_count);
  // The free pairs of slots [0, count) of `slots` (-1: none) not listed yet go into the built
  // list, in its order (neighbor_search.hpp, "Admitting unjoined pairs").
  void admit_unjoined(const View<const int*>& slots, int count);
  // The list's rows remade from the old rows (insert_.old_row_offset, old_pair_b) and each
  // disc's extra_count(a) new entries at extra_offset(a) of insert_.extra (sorted and
  // de-duplicated here): count_merged_rows, scan, MergeInsertedRows into pair_i_, pair_j_ and
  // pair_b_. old_index and new_of_old empty: every disc is old, at its own index. Returns the
  // pair count.
  long merge_rows(const View<const int*>& old_index, const View<const int*>& new_of_old,
                  const View<const int*>& extra_offset, const View<int*>& extra_count);
  // Sizes the per-disc views for n discs, reusing their buffers while they hold n; forces a
  // rebuild.
  void resize_discs(size_t n);

  bool tracking_ = false;
  View<int*> surface_;            // surface tracking: the surface nodes, increasing
  View<int*> surface_only_;       // the surface nodes that are no particles (refresh_discs)
  int refreshed_particles_ = -1;  // nodes.particle_count at the last refresh_discs
  // Capacity buffers behind discs_, x_build_, cell_discs_ and row_offset_ (their first
  // disc_count() entries, row_offset_ one more).
  View<int*> disc_buffer_, cell_discs_buffer_, row_offset_buffer_;
  View<double* [2]> x_build_buffer_;

  View<int*> discs_;           // node ids, increasing
  View<double* [2]> x_build_;  // disc positions at the last build
  View<int*> cell_start_, cell_cursor_, cell_discs_;
  View<int*> row_offset_;
  View<int*> pair_i_, pair_j_;  // capacity >= pair_count_
  View<int*> pair_b_;           // disc index of each pair_j_ (fill_candidates, index_candidates)
  ContactGather gather_;        // rows and columns of the list, when gather_built_
  bool gather_built_ = false;
  Topology topo_;              // set_lattice; empty: nothing is joined
  View<int*> broken_;          // Bonds::broken_since_search (set_lattice), or empty
  View<int> broken_count_;     // Bonds::broken_count
  View<int* [2]> slot_nodes_;  // Bonds::nodes: the ends of a slot
  long admissions_ = 0;
  long pair_count_ = 0;
  long rebuilds_ = 0;
  bool insertion_ = true;
  long insertions_ = 0;
  double build_r_max_ = 0;  // largest disc radius at the last build or insertion (m)
  // Insertion work space: the list before the refresh, and the inserted pairs (capacity reused).
  struct Insertion {
    View<int*> old_discs, old_row_offset, old_pair_b;
    View<int*> slots;  // admit_converted: the converted cells' slots
    View<double*[2]> old_x_build, position;
    View<int*> node_slot;  // per node, zero between insertions
    View<int*> old_index, new_of_old, new_discs;
    View<int*> cell_start, cell_cursor, cell_items;
    View<int*> extra_offset, extra_cursor, extra;
  } insert_;
  bool built_ = false;
  bool all_pairs_ = false;
  double skin_ = 0;
  double max_speed_ = 0;  // m/s, the fastest disc at the last update
  ContactLaw law_;
  RigidSurface rigid_surface_;
};

}  // namespace fracta
