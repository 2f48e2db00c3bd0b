// Checkpoints and restart (docs/case-file.md), and the stop signals that end a run cleanly.
//
// A checkpoint holds the complete state after a step: every device view a step mutates (the
// list in state_views.hpp), every Simulation scalar (time, dt and its bounds, step count,
// energies and works, counters, the energy floor), the rigid bodies, and the contact candidate
// list with its reference positions. There is no random-number state: the solver draws no
// random numbers. With it, a restarted run continues bit for bit as the uninterrupted run
// would have, on any number of CPU threads (the forces are summed in a fixed order; GPUs add
// atomically and agree within round-off).
//
// It also records the fracta version and the case (file text, path, --set overrides) so a
// restart can refuse a case that changes the model (check_restart_compatible in case.hpp).
//
// File layout (HDF5): root attributes format = "fracta checkpoint", format_version, version,
// case, case_path, overrides (one per line), output_path, time (s), steps; /state/NAME the
// views (NAME as in state_views.hpp, shapes as the views); /scalars attributes; /rigid
// (bodies x 6: x, y, theta (m, m, rad), vx, vy, omega (m/s, m/s, rad/s)); /contact/{pair_i,
// pair_j, x_build} with attributes built, rebuilds.
//
// Crash safety: write_checkpoint writes PATH.tmp, closes and fsyncs it, renames it over PATH
// and fsyncs the directory, so a crash at any instant leaves either the previous complete
// checkpoint or the new one at PATH.
#pragma once
#include <signal.h>

#include <string>
#include <vector>

namespace fracta {

class Simulation;
struct Case;

struct CheckpointInfo {
  std::string version;  // fracta version that wrote it
  std::string case_text, case_path;
  std::vector<std::string> overrides;  // the --set overrides of that run
  std::string output_path;             // the output file of the run that wrote it
  double time = 0;                     // s
  long steps = 0;
};

// OUT.ckpt.h5 for the output file OUT.h5 (OUT.ckpt.h5 for OUT too).
std::string checkpoint_path_for(const std::string& output_path);

// Writes the state of `sim` to `path`, atomically (see above). Throws std::runtime_error.
void write_checkpoint(Simulation& sim, const std::string& path, const CheckpointInfo& info);

// The metadata of a checkpoint. Throws InputError (PATH:0: restart: ...) if the file is
// missing, not a fracta checkpoint or unreadable.
CheckpointInfo read_checkpoint_info(const std::string& path);

// Loads the complete state into `sim`, which must have been built from a compatible case.
// Throws InputError if an array is missing or its shape does not match the model.
void read_checkpoint_state(Simulation& sim, const std::string& path);

// Checks a restart before anything is built: reads the checkpoint's metadata (InputError if it
// is missing or corrupt), refuses a case that changes the model (check_restart_compatible), and
// returns the output file of the restarted run.
//
// Output policy: a restart writes a new output file and never modifies an existing one. The
// output of the interrupted run stays exactly as it was written (it may be the file of a killed
// process; editing it in place would risk the frames it holds), and the restarted file is
// complete on its own from the checkpoint time: its frame 0 and first history row are the
// checkpoint state. The new file is `requested_output` (-o) if given, else the case's
// output.file; when that is the interrupted run's own output, OUT.restart.h5 instead (an
// explicit -o naming it is refused).
std::string prepare_restart(const Case& c, const std::string& checkpoint_path,
                            const std::string& requested_output);

// SIGINT and SIGTERM set a flag (a volatile sig_atomic_t) that the run loop checks after each
// step, so it can write a checkpoint and a complete output before exiting. Installed for the
// lifetime of the object, the previous handlers restored after. SA_RESETHAND: a second signal
// of the same kind takes its default action (kills at once) if the first is not handled fast.
class StopSignals {
 public:
  StopSignals();
  ~StopSignals();
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;
  // The signal received (SIGINT or SIGTERM), or 0.
  static int received();

 private:
  struct sigaction old_int_, old_term_;
};

}  // namespace fracta
