// The solver loop (docs/physics.md 1.4 and 2): one Simulation owns a Model and advances it step
// by step. A step reads like the method: kick-drift, loads, element forces, bond forces, contact
// search, contact forces, boundaries, kick, conversion.
#pragma once
#include <string>
#include <vector>

#include "host/ledger.hpp"
#include "host/model.hpp"
#include "host/output.hpp"
#include "host/snapshot.hpp"
#include "host/state_views.hpp"
#include "kernels/fragments.hpp"

namespace fracta {

// Device buffers a frame is packed into where the kernels cannot write host memory (GPUs), one
// per array; grown, never shrunk. Unused on host backends.
struct FrameBuffers {
  std::vector<View<double*>> reals;
  std::vector<View<int*>> ints;
};

class Simulation {
 public:
  // Builds the model, evaluates the initial forces and the stable time step. Throws InputError
  // for a fixed dt above the stable bound (unless simulation.allow_unstable_dt).
  explicit Simulation(const Case& c);

  // One step. With defer_kick, the step's second half kick is left pending and done together
  // with the next step's first (one pass over the nodes instead of two): the velocities are
  // then half-step ones until finish_kick(), which every accessor of the state below calls
  // first. Rigid bodies project once after the fused kick (their projection is linear), and
  // prescribed velocities are set after each half, so with them it never defers.
  void step(bool defer_kick = false);
  void finish_kick();
  bool failed() const { return !failure_.empty(); }
  const std::string& failure() const { return failure_; }

  const Ledger& ledger() const { return ledger_; }
  double time() const { return ledger_.clock.time; }
  double dt() const { return ledger_.clock.dt; }
  long steps() const { return ledger_.clock.steps; }
  long conversions() const { return ledger_.counts.conversions; }
  double stable_dt_bound() const { return ledger_.bounds.step; }  // before the safety factor (s)
  double bond_stable_dt_bound() const { return ledger_.bounds.lattice; }  // the lattice's (s)
  // Per-particle Gershgorin bounds as the last conversion cached them (tests).
  const StableDtWorkspace& bond_stable_dt_workspace() const { return stable_dt_; }

  HistoryRecord history();  // energies, counts and conservation totals now
  std::vector<ProbeRecord> probe_records();
  std::vector<BodyProbeRecord> body_probe_records();
  std::vector<BoundaryRecord> boundary_records();  // the named boundaries, in case order
  // The current state as a frame. The arrays are reused from frame to frame (no page faults of
  // fresh arrays): the reference is valid until the next call.
  const FrameData& frame(const std::vector<std::string>& fields);

  // The last good state, kept so a numerical failure can still write it.
  void save_snapshot();
  void restore_snapshot();
  double snapshot_bytes() const { return snapshot_.state.bytes(); }  // its device memory (B)

  Model& model() { return model_; }
  const Model& model() const { return model_; }
  // Every view a step mutates (state_views.hpp), the kick finished: tests compare runs by it.
  StateViews state() {
    finish_kick();
    return state_views();
  }

 private:
  friend struct CheckpointIO;  // src/host/checkpoint.cpp reads and writes the complete state
  // The live views of the state a step mutates (state_views.hpp).
  StateViews state_views();
  double next_dt() const;

  // The phases of a step, in the order step() runs them (docs/physics.md 2). Each force phase
  // adds into the node accumulators and returns its sums; a phase the scene cannot need (bonds
  // before any conversion, contact within one intact body) does nothing.
  // into_slot: the phase reduces its sums into the step's slots (step_sums_), which
  // settle_step_sums hands the ledger, and returns empty sums; otherwise it returns them (the
  // initial evaluation, whose caller adds them itself).
  void kick_drift(bool into_slot);  // v(n+1/2), x(n+1); rigid bodies drift
  void apply_loads();               // f_ext at the new time
  FeStepSums element_forces(double dt, bool into_slot = false);   // flags elements to convert
  BondStepResult bond_forces(double dt, bool into_slot = false);  // cell stresses, bond laws
  void contact_search();                                          // candidate pairs (Verlet list)
  // Whether a converted cell carries the lattice's volumetric term (cell_forces.hpp): the force
  // kernel runs only then. Counted again whenever the converted list changed length.
  bool cell_term_live();
  // The step's bound (s): the elements' and the lattice's stable bounds and the contact discs'
  // motion bound; negative when an element inverted.
  double step_bound(const FeStepSums& fe) const;
  ContactPhaseSums contact_forces(double dt, bool into_slot = false);  // disc contact law
  // Bars push their faces, supports hold or let go (kernels/boundaries.hpp), with the forces of
  // this evaluation, which act over the kicks of `kick_interval` (s) until the next one.
  void boundary_forces(double kick_interval);
  void kick(bool defer, bool into_slot = false);  // v(n+1), or left pending (defer)
  // Whether bars or supports act: they need the next step's length before the kick.
  bool boundaries_act() const;
  // Whether a kick's external work goes to a slot: not with prescribed components or rigid
  // bodies, whose host work around the kicks keeps the order of the sum.
  bool kick_into_slot(bool into_slot) const;
  // The slot of a member of the step's sums, marked pending.
  template <class T>
  ResultSlot<T> slot(T StepSums::*member, bool& pending);
  // Copies the step's sums to the host (one wait for the device) and adds the pending ones to
  // the ledger in the order the phases ran; sets the step's bound and the conversion flag.
  void settle_step_sums(double dt);
  void convert();  // cells that met their criterion become discs
  // The force phases at dt = 0 (the constructor): f(0) and the first stable bound.
  void initial_forces();
  // The conversion phase of convert(); returns whether cells converted.
  bool convert_cells();
  // After the active or bond list changed (conversion, restore): the force scatter's chunks
  // are re-located in them (kernels/scatter.hpp).
  void locate_scatter_chunks();

  Model model_;
  Ledger ledger_;
  bool kick_pending_ = false;  // step(true) left its second half kick (of last_dt_) to do
  double last_dt_ = 0.0;       // the last step's dt (s)
  std::string failure_;
  View<int*> probe_node_, probe_element_;
  View<double* [7]> probe_values_;
  FragmentWorkspace fragments_;
  FrameData frame_;  // the last frame(), its arrays kept for the next
  FrameBuffers frame_buffers_;
  View<double*[3]> contact_force_, contact_force_prev_;
  // contact_force_prev_ is zero: allocated so, or the last evaluation had no pair
  // (contact_forces then skips the sweeps while the list stays empty). False after a restore or
  // a restart, until an evaluation shows it again.
  bool contact_force_prev_zero_ = true;
  // The step's sums on the device, the host's copy, and which of them a phase left there since
  // the last copy (settle_step_sums).
  View<StepSums> step_sums_{"fracta::step_sums"};
  View<StepSums>::HostMirror step_sums_host_ = Kokkos::create_mirror_view(step_sums_);
  struct PendingSums {
    bool kick_drift = false, fe = false, bonds = false, cell = false, contact = false, kick = false;
  } pending_sums_;
  StableDtWorkspace stable_dt_;    // bond_stable_dt without allocations, per-particle cache
  int cell_term_counted_at_ = -1;  // converted_count when cell_term_live_ was counted
  bool cell_term_live_ = false;
  // Counts the adaptive elements the FE kernel flagged for conversion since the last one;
  // the candidates hold the first ones' active indices (compact_candidates).
  View<int> conversion_pending_{"fracta::conversion_pending"};
  View<int*> conversion_candidates_{"fracta::conversion_candidates", ListWorkspace::kCapacity};
  View<int*> conversion_flag_, conversion_position_;  // compact_converted's work space
  // An FE evaluation (element_forces, the only writer of conversion_pending_) flagged elements
  // since convert_cells last read the counter. May stay true after a restore zeroes the counter:
  // reading a zero counter is only slower.
  bool conversion_flagged_ = false;

  // The last good state: the rows of the views a step mutates and the list lengths
  // (snapshot.hpp), the ledger and the rigid bodies (taken after the kick is finished).
  struct Snapshot {
    StateSnapshot state;
    Ledger ledger;
    std::vector<RigidBody> rigid;
  } snapshot_;
};

struct RunOptions {
  std::string output_path;           // empty: the case's output.file
  std::string restart_path;          // a checkpoint to continue from (empty: start at t = 0)
  bool progress_on_terminal = true;  // a live progress line; plain log lines otherwise
  double log_interval_seconds = 10.0;
};

// Runs a case to its end_time with output. Returns the process exit code: 0 completed,
// 3 numerical failure (after writing the last good state), 130 / 143 stopped by SIGINT /
// SIGTERM (after writing a checkpoint and a final frame). Throws InputError for bad input
// (including an unreadable or incompatible restart checkpoint).
int run_case(const Case& c, const RunOptions& opt);

// The history interval a run uses (s): simulation.history_interval, or when it is 0 (the
// default) end_time / kHistoryRows, so that a run's history keeps about that many rows.
// Recording a row costs a pass over every node, bond and element: every step would cost a large
// disc run about a fifth of its time.
inline constexpr double kHistoryRows = 1000.0;
double history_every_for(const SimulationParams& sim);

// The command that continues a run of case c from its checkpoint, with the run's --set
// overrides (a restart must repeat them), quoted for a POSIX shell.
std::string restart_command(const Case& c, const std::string& checkpoint_path);

// The /run attributes of an output file of case c written by this build and backend.
// Packs the state's nodes, active elements, discs and bonds into f's arrays (kernels/frame.hpp),
// resizing them (their capacity is kept: no page faults once a frame has been that large).
// Leaves f's time, step, fields and fragments alone.
void pack_frame_data(const Model& model, FrameData& f, FrameBuffers& buffers);

RunInfo run_info(const Case& c);

// Declares the case's probes and body probes in out.
void declare_probes(OutputFile& out, const Simulation& sim);
// Appends the current history row and every probe's record to out; returns the history row.
HistoryRecord record_history(OutputFile& out, Simulation& sim);

}  // namespace fracta
