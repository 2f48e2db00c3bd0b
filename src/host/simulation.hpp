// The solver loop (DESIGN.md 1.4): one Simulation owns a Model and advances it step by step.
// A step reads like the method: kick_drift -> loads -> fe_forces -> kick.
#pragma once
#include <string>
#include <vector>

#include "host/model.hpp"
#include "host/output.hpp"
#include "host/state_views.hpp"
#include "kernels/fragments.hpp"

namespace fracta {

class Simulation {
 public:
  // Builds the model, evaluates the initial forces and the stable time step. Throws InputError
  // for a fixed dt above the stable bound (unless simulation.allow_unstable_dt).
  explicit Simulation(const Case& c);

  // One step. With defer_kick, the step's second half kick is left pending and done together
  // with the next step's first (one pass over the nodes instead of two): the velocities are
  // then half-step ones until finish_kick(), which every accessor of the state below calls
  // first. Rigid bodies project between the two halves, so with rigid bodies it never defers.
  void step(bool defer_kick = false);
  void finish_kick();
  bool failed() const { return !failure_.empty(); }
  const std::string& failure() const { return failure_; }

  double time() const { return time_; }
  double dt() const { return dt_; }
  long steps() const { return steps_; }
  long conversions() const { return conversions_; }
  double stable_dt_bound() const { return dt_bound_; }            // before the safety factor (s)
  double bond_stable_dt_bound() const { return bond_dt_bound_; }  // the bond network's (s)
  // Per-particle Gershgorin bounds as the last conversion cached them (tests).
  const StableDtWorkspace& bond_stable_dt_workspace() const { return stable_dt_; }

  HistoryRecord history();  // energies, counts and conservation totals now
  std::vector<ProbeRecord> probe_records();
  std::vector<BodyProbeRecord> body_probe_records();
  FrameData frame(const std::vector<std::string>& fields);

  // The last good state, kept so a numerical failure can still write it.
  void save_snapshot();
  void restore_snapshot();

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
  // Zeroed forces in, all internal forces out (FE, bonds); returns the stable bound (s).
  double evaluate_forces(double dt);
  // Converts the adaptive elements that reached their conversion criterion (DESIGN.md 1.3).
  void convert();
  // The conversion phase of convert(); returns whether cells converted.
  bool convert_cells();
  // After the active or bond list changed (conversion, restore): the force scatter's chunks
  // are re-located in them (kernels/scatter.hpp).
  void locate_scatter_chunks();

  Model model_;
  double time_ = 0.0, dt_ = 0.0, dt_bound_ = 0.0, dt_initial_ = 0.0;
  long steps_ = 0;
  double external_work_ = 0.0, initial_energy_ = 0.0;
  double bond_dt_bound_ = 1e300, fracture_energy_ = 0.0, energy_floor_ = 0.0;
  long broken_bonds_ = 0, touching_ = 0;
  double contact_elastic_ = 0.0, contact_dissipated_ = 0.0, conversion_energy_ = 0.0;
  // Work the elements dissipated since t = 0 (J), summed per step (FeStepSums).
  double element_plastic_work_ = 0.0, hourglass_work_ = 0.0, viscous_work_ = 0.0;
  long conversions_ = 0, conversions_this_step_ = 0;
  bool kick_pending_ = false;  // step(true) left its second half kick (of last_dt_) to do
  double last_dt_ = 0.0;       // the last step's dt (s)
  std::string failure_;
  View<int*> probe_node_, probe_element_;
  View<double* [7]> probe_values_;
  FragmentWorkspace fragments_;
  View<double*[3]> contact_force_, contact_force_prev_;
  StableDtWorkspace stable_dt_;  // bond_stable_dt without allocations, per-particle cache
  // Counts the adaptive elements the FE kernel flagged for conversion since the last one;
  // the candidates hold the first ones' active indices (compact_candidates).
  View<int> conversion_pending_{"fracta::conversion_pending"};
  View<int*> conversion_candidates_{"fracta::conversion_candidates", ListWorkspace::kCapacity};
  View<int*> conversion_flag_, conversion_position_;  // compact_converted's work space
  // An FE evaluation (evaluate_forces, the only writer of conversion_pending_) flagged elements
  // since convert_cells last read the counter. May stay true after a restore zeroes the counter:
  // reading a zero counter is only slower.
  bool conversion_flagged_ = false;

  struct Snapshot {
    StateViews views;
    double time = 0, dt = 0, dt_bound = 0, external_work = 0, fracture_energy = 0;
    double contact_dissipated = 0, contact_elastic = 0, conversion_energy = 0;
    double element_plastic_work = 0, hourglass_work = 0, viscous_work = 0;
    int converted_count = 0;
    long conversions = 0;
    std::vector<RigidBody> rigid;
    long broken_bonds = 0, steps = -1, touching = 0;
    int active_elements = 0;
    int used_bonds = 0, particles = 0;  // list counts (Bonds::used, Nodes::particle_list)
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

// The /run attributes of an output file of case c written by this build and backend.
RunInfo run_info(const Case& c);

// Declares the case's probes and body probes in out.
void declare_probes(OutputFile& out, const Simulation& sim);
// Appends the current history row and every probe's record to out; returns the history row.
HistoryRecord record_history(OutputFile& out, Simulation& sim);

}  // namespace fracta
