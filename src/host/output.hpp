// HDF5 output (docs/output.md) and its XDMF side file for ParaView.
// Host-only: the solver copies device state into these plain structs at output time.
// Frame K is written once, to OUT.h5.frames/K.h5; history rows are buffered in memory. A commit
// writes the index OUT.h5 (the run attributes, the series, links to the frames) whole to
// OUT.h5.tmp and renames it into place, then the .xdmf likewise (output.cpp explains why), so at
// every instant OUT.h5 is a complete file: a killed run leaves every frame committed before the
// kill. A commit costs in proportion to what the run has written, so write_frame() commits only
// when the last commit took at most 1/20 of the wall time since it ended: whatever the run's
// length, commits take at most about 5% of its wall time and a frame costs the same.
#pragma once
#include <array>
#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "host/io_error.hpp"

namespace fracta {

struct RunInfo {
  std::string version;  // FRACTA_VERSION
  std::string backend;  // Kokkos execution space name
  int threads = 1;
  std::string case_text;  // the case file text
  std::string case_path;
};

// Energies in J (for the modelled thickness), docs/physics.md 1.4. `error` is the relative balance
// error |E_kin + E_td + E_int + E_dissipated - E_ext - E_0| / max(E_ext + E_0, E_kin).
// `time_discretization` (E_td <= 0) is -(dt^2/8) sum |f|^2 / m: the bounded, non-accumulating
// difference between the full-step kinetic energy and the energy central differences conserve,
// 1/2 m v(n-1/2).v(n+1/2) (Hughes, The Finite Element Method, 9.3).
struct EnergyRecord {
  double kinetic = 0, internal = 0, plastic = 0, hourglass = 0, viscous = 0, contact = 0,
         fracture = 0, conversion = 0, external = 0, time_discretization = 0, error = 0;
};

struct CountRecord {
  long elements = 0, particles = 0, composite = 0, bonds = 0, broken_bonds = 0, contacts = 0,
       conversions = 0;
};

struct HistoryRecord {
  double time = 0;
  double dt = 0;
  long step = 0;
  EnergyRecord energy;
  CountRecord count;
  double mass = 0, momentum_x = 0, momentum_y = 0;  // kg, kg m/s (totals over all nodes)
};

struct ProbeRecord {  // nearest node (u, v) and containing element (stress)
  double time = 0, ux = 0, uy = 0, vx = 0, vy = 0, sxx = 0, syy = 0, sxy = 0;
};

struct BodyProbeRecord {  // mass-averaged position and velocity of a body
  double time = 0, x = 0, y = 0, vx = 0, vy = 0;
};

// A named boundary (docs/output.md, /boundaries/NAME): the force its constraints apply to the
// body (N, fixed, velocity and support boundaries: m a - f on their held components; bars:
// A sigma along the bar), its nodes' mass-averaged velocity (m/s), and for bars the face stress,
// the incident stress Z v_I and the reflected stress sigma - Z v_I (Pa, compression positive).
struct BoundaryRecord {
  double time = 0, fx = 0, fy = 0, vx = 0, vy = 0, stress = 0, incident = 0, reflected = 0;
};

// One field frame. Node arrays have 2 entries per node (x, y interleaved); element arrays one
// entry per active element, except stress (4: sxx, syy, szz, sxy) and connectivity (4 node ids).
struct FrameData {
  double time = 0;
  long step = 0;
  std::vector<double> node_position;  // current coordinates (m), 2 per node
  std::vector<double> node_displacement;
  std::vector<double> node_velocity;
  std::vector<int> element_nodes;  // 4 per active element, counter-clockwise
  std::vector<int> element_id;     // mesh index of each active element
  std::vector<int> element_body;
  std::vector<double> element_stress;  // Pa, 4 per element
  std::vector<double> element_plastic_strain;
  std::vector<double> element_pressure;   // Pa, -(sxx + syy + szz) / 3
  std::vector<double> element_von_mises;  // Pa
  // Discs (particles): node id, radius (m), rotation (rad), spin (rad/s), one entry per disc.
  std::vector<int> particle_node;
  std::vector<double> particle_radius, particle_rotation, particle_spin;
  // Bonds that are or were active: node pair (2 per bond), state (1 active, 2 broken), normal
  // force (N, tension positive; 0 once broken).
  std::vector<int> bond_nodes, bond_state;
  std::vector<double> bond_normal_force;
  std::vector<double> bond_damage;  // cohesive damage D in [0, 1] (1 once broken, 0 if brittle)
  // Fragments (connected components over active bonds and alive elements): per node its
  // fragment label (the smallest node id in it), and each fragment's mass (kg, largest first)
  // and node count.
  std::vector<int> node_fragment;
  std::vector<double> fragment_mass;
  std::vector<long> fragment_size;
  std::vector<std::string> fields;  // which optional fields to write ("velocity", "stress", ...)
};

// How frames store their arrays ([output] precision and compression, docs/output.md).
// Checkpoints and the history series are always float64.
struct FrameStorage {
  bool single_precision = true;  // floating-point frame arrays as float32 (d3plot's choice)
  int deflate = 0;               // 1-9: chunked, shuffled and deflated at that level; 0: raw
};

// Wall time (s) of a run and of its parts, for the /run attributes and the run summary.
struct RunTimes {
  double wall = 0;        // the whole run, from start-up
  double output = 0;      // frames: gathering from the device, writing, commits, the final copy
  double history = 0;     // history, probe and boundary rows: evaluating and buffering them
  double checkpoint = 0;  // checkpoints (with the commit of the output that precedes each)
};

// Adds the wall time (s) of its scope to `total`, also when the scope ends by an exception.
class ScopedSeconds {
 public:
  explicit ScopedSeconds(double& total) : total_(total), start_(std::chrono::steady_clock::now()) {}
  ~ScopedSeconds() {
    total_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }
  ScopedSeconds(const ScopedSeconds&) = delete;
  ScopedSeconds& operator=(const ScopedSeconds&) = delete;

 private:
  double& total_;
  std::chrono::steady_clock::time_point start_;
};

class OutputFile {
 public:
  // Creates (truncates) `path` and writes /run attributes. Writes throw IoError (hdf5.hpp) when
  // a file cannot be written (full file system, missing or read-only directory).
  OutputFile(const std::string& path, const RunInfo& info, const FrameStorage& storage = {});
  ~OutputFile();
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;

  void declare_probe(const std::string& name);
  void declare_body_probe(const std::string& name);
  void declare_boundary(const std::string& name);

  void append_history(const HistoryRecord& r);
  void append_probe(const std::string& name, const ProbeRecord& r);
  void append_body_probe(const std::string& name, const BodyProbeRecord& r);
  void append_boundary(const std::string& name, const BoundaryRecord& r);

  // Writes frame K (K = 0, 1, ...) to its file and commits if a commit is due (see above): then
  // OUT.h5 lists /frames/K and the buffered history, and the .xdmf beside it shows the frame.
  void write_frame(const FrameData& f);
  // Commits now: every frame written and every buffered row.
  void flush();
  // Final /run attributes (steps, wall_seconds and the parts of `times`, status: "completed",
  // "failed: ...", ...), the last commit, with every frame copied into OUT.h5 (one
  // self-contained file; the frame files are removed). The time of this call is added to
  // times.wall and times.output in the attributes. Safe to call once; the destructor commits
  // without these otherwise.
  void finish(long steps, const RunTimes& times, const std::string& status);

  // After an I/O error (IoError): writes nothing more, not even from the destructor, and removes
  // the temporary files. OUT.h5 (with OUT.h5.frames) stays as the last commit left it.
  void abandon();
  // Whether finish() copied the frames into OUT.h5 (false: no room; OUT.h5.frames stays).
  bool frames_consolidated() const;

  const std::string& path() const;
  int frames_written() const;
  int frames_committed() const;  // frames OUT.h5 lists (after an I/O error: what it holds)
  int commits() const;           // commits so far (OUT.h5 written and renamed into place)
  // Bytes of the files written so far: frame files, and OUT.h5 and OUT.xdmf at each commit.
  std::uintmax_t bytes_written() const;
  // Wall time (s) spent inside write_frame and finish, and in the last finish alone.
  double write_seconds() const;
  double finish_seconds() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace fracta
