// HDF5 output (docs/output.md) and the XDMF side file that lets ParaView open it.
//
// File format choices:
// - Crash safety by atomic replacement, not by flushing: HDF5 1.10 updates its metadata in place
//   in many writes (B-tree splits, heap moves, the superblock's end-of-file address), so a
//   process killed inside a flush could leave a file that does not open, or whose older frames
//   are lost (both seen: "addr overflow" and empty frame groups, in about 5% of kills on a
//   loaded machine). So no file is ever modified after it is closed:
//     * frame K is written to OUT.h5.frames/K.h5 (group /frame) through K.h5.tmp and a rename;
//     * OUT.h5 itself is written whole to OUT.h5.tmp at every commit and renamed over the old
//       one: /run, /history and the probes (the series copied from the previous OUT.h5 with
//       H5Ocopy, then the new rows appended), and /frames/K as external links to the frame
//       files (HDF5 and h5py follow them; relative to OUT.h5's directory);
//     * finish() consolidates: the last commit copies every frame into /frames/K of OUT.h5
//       itself and removes OUT.h5.frames, so a completed (or interrupted, or failed) run is one
//       self-contained file. A killed run leaves OUT.h5 + OUT.h5.frames/, complete as of its
//       last commit; OUT.h5 must then be moved together with OUT.h5.frames.
//   A rename is atomic, so at every instant OUT.h5 is one complete file.
// - Cost. A frame file costs what the frame holds, whenever it is written; a commit costs in
//   proportion to what the run has written (a link per frame, the history rows, the .xdmf's
//   grids), about 4 ms per 100 frames on the paper's plate. Committing at every frame made a
//   long run's output quadratic in its frames (the plate: 12.5 ms a frame at 100 frames, 43 ms
//   at 1000; bench/output_cost.py). So a frame commits only when the last commit took at most
//   1/kCommitSpacing of the wall time since it ended: commits then take at most
//   1/(kCommitSpacing + 1) of the run's wall time, whatever its length, and a frame's cost does
//   not grow with the frames before it. The first frame, checkpoints (flush()) and finish()
//   always commit. The price: a killed run's OUT.h5 may miss the frames of its last moments
//   (each one is in OUT.h5.frames, complete, but not listed), kCommitSpacing commit times at
//   most.
// - Frames store floating-point arrays as float32 by default (FrameStorage; LS-DYNA's d3plot
//   does the same): half the bytes of float64, and 7 significant digits are more than a plot or
//   a crack measure needs. Chunked deflate with the byte shuffle is an option: float32 positions
//   and velocities gain little from it, connectivity and bond states much (docs/output.md).
// - libver bounds (earliest, v18): superblock version 0/2, readable by any HDF5 1.8+.
// - Strings (version, backend, case, case_path, status) are scalar variable-length UTF-8 string
//   attributes. Variable-length data lives in the global heap, so the 64 KiB object-header limit
//   does not apply and the whole case text is always the attribute /run/case (tested with
//   200 KB); h5py reads them as str.
// - History and probe series are 1-D float64/int64 chunked datasets (chunk 512 rows, unlimited
//   maximum) that grow at every commit; frame arrays are datasets written once.
//
// XDMF choices (checked with ParaView 5.11's three readers, "XDMF Reader", "Xdmf3 Reader S" and
// "Xdmf3 Reader T", through pvbatch):
// - Node vectors are Attribute Type "Vector" with Dimensions "N 2". The XDMF Reader pads them
//   to 3 components (z = 0) and makes node_velocity the active vector, so Glyph works directly;
//   the Xdmf3 readers load them as 2-component arrays (colour by magnitude/X/Y works; for
//   glyphs there, use a Calculator to build a 3-vector). A 3-component copy would cost 50 %
//   more node storage, and XDMF JOIN functions and hyperslabs did not read correctly.
// - element_stress (M x 4: sxx, syy, szz, sxy) is Attribute Type "Matrix": 4 components in all
//   three readers.
// - Three temporal collections, "mesh" (quadrilaterals), "discs" (Polyvertex, one vertex cell
//   per disc: connectivity particle_node) and "bonds" (Polyline, NodesPerElement 2:
//   connectivity bond_nodes), all over the frame's node_position. All three readers load them
//   (pvbatch, on a mixed FE/DE plate with broken bonds and on a plate of discs only); the
//   XDMF Reader gives a multiblock with the stable block names mesh/discs/bonds (Extract Block
//   /Root/discs etc.) and an empty block at times a collection does not list; the Xdmf3 readers
//   give unnamed blocks. One spatial collection per time step also loads in all three, but the
//   XDMF Reader then names the blocks mesh, mesh[1], mesh[2], ... so a selection by block name
//   does not survive a change of time step. (Its grid list names every frame's grid either way.)
// - Disc quantities (particle_radius, _rotation, _spin) are Cell attributes (one per vertex
//   cell): the geometry is every node, so a Node attribute would need one value per node. The
//   disc grid also carries node_velocity/node_displacement (Node). For circles in ParaView:
//   Cell Centers (one point per disc, the cell arrays become point arrays), then the "Point
//   Gaussian" representation, Shader Preset "Plain circle", Scale By Array with Scale Array
//   particle_radius and Use Scale Function off, Gaussian Radius 1 (true radii). Bonds:
//   bond_state (1 active, 2 broken), bond_normal_force and bond_damage, Cell attributes.
// - A frame without nodes or elements, discs or bonds is left out of that collection (an XML
//   comment says so), and a collection empty in every frame is left out (a pure-FE run has only
//   "mesh"): empty grids crash the Xdmf3 readers and fail in the XDMF Reader. The .h5 still
//   holds every frame, with zero-size particle/bond datasets when there are none.
#include "host/output.hpp"

#include <hdf5.h>  // host only: the CUDA check skips the files that include it

#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <system_error>
#include <type_traits>
#include <utility>

#include "host/hdf5.hpp"

namespace fracta {
namespace {

namespace fs = std::filesystem;

constexpr hsize_t kChunkRows = 512;  // 4 KB per double series: small files to rewrite
// A frame commits when the wall time since the last commit is at least this many times that
// commit's duration (see the top of the file): commits take at most 1/20 of the wall time.
constexpr double kCommitSpacing = 19.0;

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

using h5::Handle;

// One column of a record series: dataset name (relative to the series group) and accessor.
template <class R, class T>
struct Column {
  const char* name;
  T (*get)(const R&);
};

using HR = HistoryRecord;
const Column<HR, double> kHistoryReal[] = {
    {"time", [](const HR& r) { return r.time; }},
    {"dt", [](const HR& r) { return r.dt; }},
    {"energy/kinetic", [](const HR& r) { return r.energy.kinetic; }},
    {"energy/internal", [](const HR& r) { return r.energy.internal; }},
    {"energy/plastic", [](const HR& r) { return r.energy.plastic; }},
    {"energy/hourglass", [](const HR& r) { return r.energy.hourglass; }},
    {"energy/viscous", [](const HR& r) { return r.energy.viscous; }},
    {"energy/contact", [](const HR& r) { return r.energy.contact; }},
    {"energy/fracture", [](const HR& r) { return r.energy.fracture; }},
    {"energy/conversion", [](const HR& r) { return r.energy.conversion; }},
    {"energy/time_discretization", [](const HR& r) { return r.energy.time_discretization; }},
    {"energy/external", [](const HR& r) { return r.energy.external; }},
    {"energy/error", [](const HR& r) { return r.energy.error; }},
    {"mass", [](const HR& r) { return r.mass; }},
    {"momentum_x", [](const HR& r) { return r.momentum_x; }},
    {"momentum_y", [](const HR& r) { return r.momentum_y; }},
};
const Column<HR, std::int64_t> kHistoryInt[] = {
    {"step", [](const HR& r) -> std::int64_t { return r.step; }},
    {"count/elements", [](const HR& r) -> std::int64_t { return r.count.elements; }},
    {"count/particles", [](const HR& r) -> std::int64_t { return r.count.particles; }},
    {"count/composite", [](const HR& r) -> std::int64_t { return r.count.composite; }},
    {"count/bonds", [](const HR& r) -> std::int64_t { return r.count.bonds; }},
    {"count/broken_bonds", [](const HR& r) -> std::int64_t { return r.count.broken_bonds; }},
    {"count/contacts", [](const HR& r) -> std::int64_t { return r.count.contacts; }},
    {"count/conversions", [](const HR& r) -> std::int64_t { return r.count.conversions; }},
};

using PR = ProbeRecord;
const Column<PR, double> kProbeReal[] = {
    {"time", [](const PR& r) { return r.time; }}, {"ux", [](const PR& r) { return r.ux; }},
    {"uy", [](const PR& r) { return r.uy; }},     {"vx", [](const PR& r) { return r.vx; }},
    {"vy", [](const PR& r) { return r.vy; }},     {"sxx", [](const PR& r) { return r.sxx; }},
    {"syy", [](const PR& r) { return r.syy; }},   {"sxy", [](const PR& r) { return r.sxy; }},
};

using BR = BodyProbeRecord;
const Column<BR, double> kBodyProbeReal[] = {
    {"time", [](const BR& r) { return r.time; }}, {"x", [](const BR& r) { return r.x; }},
    {"y", [](const BR& r) { return r.y; }},       {"vx", [](const BR& r) { return r.vx; }},
    {"vy", [](const BR& r) { return r.vy; }},
};

using BdR = BoundaryRecord;
const Column<BdR, double> kBoundaryReal[] = {
    {"time", [](const BdR& r) { return r.time; }},
    {"fx", [](const BdR& r) { return r.fx; }},
    {"fy", [](const BdR& r) { return r.fy; }},
    {"vx", [](const BdR& r) { return r.vx; }},
    {"vy", [](const BdR& r) { return r.vy; }},
    {"stress", [](const BdR& r) { return r.stress; }},
    {"incident", [](const BdR& r) { return r.incident; }},
    {"reflected", [](const BdR& r) { return r.reflected; }},
};

// Optional element fields: FrameData::fields option -> dataset, data, values per element.
struct ElementField {
  const char* option;
  const char* dataset;
  std::vector<double> FrameData::*data;
  int width;
};
const ElementField kElementFields[] = {
    {"stress", "element_stress", &FrameData::element_stress, 4},
    {"plastic_strain", "element_plastic_strain", &FrameData::element_plastic_strain, 1},
    {"pressure", "element_pressure", &FrameData::element_pressure, 1},
    {"von_mises", "element_von_mises", &FrameData::element_von_mises, 1},
};

// Names of the .xdmf's temporal collections (GridKind order), and what an empty one lacks.
const char* const kGridNames[] = {"mesh", "discs", "bonds"};
const char* const kEmptyWhat[] = {"nodes or elements", "discs", "bonds"};

// What the .xdmf needs to know about a frame already in the file.
struct FrameInfo {
  double time = 0;
  long nodes = 0, elements = 0, particles = 0, bonds = 0;
  bool single_precision = false;  // its floating-point arrays are float32
  std::vector<const ElementField*> fields;
};

// The three kinds of grid of a frame in the .xdmf, one temporal collection each.
enum class GridKind { mesh, discs, bonds };

std::string xml_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

}  // namespace

struct OutputFile::Impl {
  std::string path, xdmf_path, h5_name;
  std::string frames_dir, frames_rel;  // OUT.h5.frames: absolute-or-given, and its file name
  RunInfo info;
  bool committed = false;  // `path` holds a complete output (the last commit)
  std::vector<HistoryRecord> history_rows;
  std::map<std::string, std::vector<ProbeRecord>> probe_rows;
  std::map<std::string, std::vector<BodyProbeRecord>> body_probe_rows;
  std::map<std::string, std::vector<BoundaryRecord>> boundary_rows;
  std::vector<FrameInfo> frame_info;
  FrameStorage storage;
  bool finished = false;
  bool consolidated = false;         // finish() copied the frames into OUT.h5
  std::size_t frames_committed = 0;  // frames the last commit listed
  std::size_t xdmf_frames = 0;       // frames the .xdmf shows
  // The commit schedule (see the top of the file) and the time spent writing.
  Clock::time_point last_commit_end = Clock::now();
  double last_commit_seconds = 0;
  // A test hook (docs/development.md): FRACTA_COMMIT_EVERY_FRAME=1 commits at every frame, so
  // that the kill tests also land inside commits as often as inside frame files.
  double commit_spacing = std::getenv("FRACTA_COMMIT_EVERY_FRAME") ? 0.0 : kCommitSpacing;
  double write_seconds = 0, finish_seconds = 0;
  int commits = 0;
  // Bytes of the files written whole so far (frame files, each commit's OUT.h5 and .xdmf): the
  // output's work as a count, for the constant-cost test, which must not time anything.
  std::uintmax_t bytes_written = 0;

  // --- error handling and helpers (host/hdf5.hpp) -----------------------------------------

  h5::Io io{""};  // "output PATH: ..." messages
  hid_t id(hid_t h, const std::string& what) const { return io.id(h, what); }
  void ok(herr_t status, const std::string& what) const { io.ok(status, what); }
  static std::string where(hid_t loc, const std::string& name) { return h5::Io::where(loc, name); }
  void require_open(const char* op) const {
    if (finished) throw std::runtime_error("output " + path + ": " + op + " after finish()");
  }
  Handle group(hid_t loc, const std::string& name) { return io.create_group(loc, name); }
  template <class T>
  void attribute(hid_t obj, const char* name, const T& value) {
    io.write_attribute(obj, name, value);
  }

  template <class R, class T, std::size_t N>
  void create_columns(hid_t loc, const Column<R, T> (&columns)[N]) {
    for (const auto& c : columns) io.create_series<T>(loc, c.name, kChunkRows);
  }

  template <class R, class T, std::size_t N>
  void append_columns(hid_t loc, const Column<R, T> (&columns)[N], const std::vector<R>& rows) {
    std::vector<T> values(rows.size());
    for (const auto& c : columns) {
      for (std::size_t i = 0; i < rows.size(); ++i) values[i] = c.get(rows[i]);
      io.append_series(loc, c.name, values);
    }
  }

  // Fixed-size frame dataset: `rows` x `width` (1-D when width == 1), zero rows allowed, stored
  // as the run's FrameStorage says.
  template <class T>
  void write_array(hid_t loc, const char* name, const std::vector<T>& values, std::size_t width) {
    const hsize_t rows = values.size() / width;
    io.write_array(loc, name,
                   width == 1 ? std::vector<hsize_t>{rows} : std::vector<hsize_t>{rows, width},
                   values, h5::Storage{storage.single_precision, storage.deflate});
  }

  // --- operations ------------------------------------------------------------------------

  Handle open_read(const std::string& file_path) { return io.open_read(file_path); }

  static void rename_over(const std::string& from, const std::string& to, const std::string& path) {
    if (std::rename(from.c_str(), to.c_str()) != 0)
      throw IoError("output " + path + ": cannot rename " + from + " to " + to + ": " +
                    std::strerror(errno));
  }

  // Bytes a commit writes to OUT.h5.tmp, beside the OUT.h5 it replaces, with a margin: the
  // previous file, the buffered rows, the case text and, when consolidating, every frame file.
  std::uintmax_t commit_bytes(bool consolidate) const {
    std::error_code ec;
    std::uintmax_t bytes = (64u << 10) + info.case_text.size();
    if (committed) {
      const std::uintmax_t old = fs::file_size(path, ec);
      if (!ec) bytes += old;
    }
    std::size_t rows = history_rows.size();
    for (const auto& [name, r] : probe_rows) rows += r.size();
    for (const auto& [name, r] : body_probe_rows) rows += r.size();
    for (const auto& [name, r] : boundary_rows) rows += r.size();
    bytes += 256 * rows;
    if (consolidate)
      for (std::size_t k = 0; k < frame_info.size(); ++k) {
        const std::uintmax_t frame = fs::file_size(frame_file(k), ec);
        if (!ec) bytes += frame;
      }
    return bytes;
  }

  std::string frame_file(std::size_t k) const {
    return frames_dir + "/" + std::to_string(k) + ".h5";
  }

  void open(const RunInfo& run_info) {
    info = run_info;
    fs::path p(path);
    h5_name = p.filename().string();
    fs::path x = p;
    x.replace_extension(".xdmf");
    if (x == p) x = fs::path(path + ".xdmf");
    xdmf_path = x.string();
    frames_dir = path + ".frames";
    frames_rel = h5_name + ".frames";

    // A missing or read-only directory is named as such (HDF5 would only say it cannot create).
    std::error_code ignored;
    const fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
    if (!fs::is_directory(dir, ignored))
      throw IoError("output " + path + ": the directory " + dir.string() + " does not exist");
    if (::access(dir.c_str(), W_OK) != 0)
      throw IoError("output " + path + ": the directory " + dir.string() +
                    " is not writable: " + std::strerror(errno));

    // What an earlier run of the same name left: a .xdmf describing frames this run will not
    // have, its frame files, a half-written OUT.h5.tmp.
    fs::remove(xdmf_path, ignored);
    fs::remove_all(frames_dir, ignored);
    fs::remove(path + ".tmp", ignored);
    commit(nullptr, false);
  }

  struct FinalAttributes {
    long steps;
    RunTimes times;
    std::string status;
    Clock::time_point finish_start;  // finish()'s own time counts as output time
  };

  // Writes the whole output to OUT.h5.tmp and renames it over OUT.h5 (see the top of the file).
  // `consolidate`: frames copied in from their files rather than linked. On failure the
  // temporary file is removed and OUT.h5 is the previous commit's, untouched.
  void commit(const FinalAttributes* final_attributes, bool consolidate) {
    const auto start = Clock::now();
    const std::string tmp = path + ".tmp";
    io.require_space(path, commit_bytes(consolidate), tmp);
    // A commit copies the previous history (an object copy): in memory, as it is small, but not
    // the final one that copies the frames in (that would hold them twice in memory).
    io.write_file(tmp, true, !consolidate,
                  [&](hid_t root) { write_output(root, final_attributes, consolidate); });
    rename_over(tmp, path, path);
    bytes_written += written_size(path);
    committed = true;
    history_rows.clear();
    for (auto& [name, rows] : probe_rows) rows.clear();
    for (auto& [name, rows] : body_probe_rows) rows.clear();
    for (auto& [name, rows] : boundary_rows) rows.clear();
    if (consolidate) {
      std::error_code ignored;
      fs::remove_all(frames_dir, ignored);
    }
    frames_committed = frame_info.size();
    // The .xdmf after OUT.h5, so that it never shows a frame OUT.h5 does not list.
    if (xdmf_frames != frame_info.size()) {
      write_xdmf();
      bytes_written += written_size(xdmf_path);
      xdmf_frames = frame_info.size();
    }
    last_commit_seconds = seconds_since(start);
    last_commit_end = Clock::now();
    ++commits;
  }

  // The size of a file just written (0 if it cannot be read: the count is a measure, not a check).
  static std::uintmax_t written_size(const std::string& file) {
    std::error_code ignored;
    const std::uintmax_t size = fs::file_size(file, ignored);
    return ignored ? 0 : size;
  }

  // A frame's commit is due once the wall time since the last commit is kCommitSpacing times
  // what that commit took (see the top of the file).
  bool commit_due() const {
    return seconds_since(last_commit_end) >= commit_spacing * last_commit_seconds;
  }

  // The contents of OUT.h5 into the open file `root`.
  void write_output(hid_t root, const FinalAttributes* final_attributes, bool consolidate) {
    {
      Handle old;
      if (committed) old = open_read(path);

      Handle run = group(root, "run");
      attribute(run.get(), "version", info.version);
      attribute(run.get(), "backend", info.backend);
      attribute(run.get(), "threads", info.threads);
      attribute(run.get(), "case", info.case_text);
      attribute(run.get(), "case_path", info.case_path);
      attribute(run.get(), "frame_precision",
                std::string(storage.single_precision ? "single" : "double"));
      attribute(run.get(), "frame_compression", static_cast<std::int64_t>(storage.deflate));

      // Series: the previous commit's, then the rows buffered since.
      if (old.get() >= 0) {
        for (const char* name : {"history", "probes", "body_probes", "boundaries"})
          ok(H5Ocopy(old.get(), name, root, name, H5P_DEFAULT, H5P_DEFAULT),
             std::string("cannot copy /") + name + " from the previous " + path);
      } else {
        Handle history = group(root, "history");
        group(history.get(), "energy");
        group(history.get(), "count");
        create_columns(history.get(), kHistoryReal);
        create_columns(history.get(), kHistoryInt);
        group(root, "probes");
        group(root, "body_probes");
        group(root, "boundaries");
      }
      {
        Handle history(id(H5Gopen2(root, "history", H5P_DEFAULT), "cannot open /history"),
                       H5Gclose);
        append_columns(history.get(), kHistoryReal, history_rows);
        append_columns(history.get(), kHistoryInt, history_rows);
      }
      append_probes(root, "probes", probe_rows, kProbeReal);
      append_probes(root, "body_probes", body_probe_rows, kBodyProbeReal);
      append_probes(root, "boundaries", boundary_rows, kBoundaryReal);

      // Frames: /frames@count complete frames, /frames/K linked to (or copied from) its file.
      Handle frames = group(root, "frames");
      attribute(frames.get(), "count", static_cast<std::int64_t>(frame_info.size()));
      for (std::size_t k = 0; k < frame_info.size(); ++k) {
        const std::string name = std::to_string(k);
        if (consolidate) {
          Handle src = open_read(frame_file(k));
          ok(H5Ocopy(src.get(), "frame", frames.get(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT),
             "cannot copy " + frame_file(k) + " into /frames/" + name);
        } else {
          const std::string target = frames_rel + "/" + name + ".h5";
          ok(H5Lcreate_external(target.c_str(), "/frame", frames.get(), name.c_str(), H5P_DEFAULT,
                                H5P_DEFAULT),
             "cannot link /frames/" + name + " to " + target);
        }
      }
      // The end of the run, last, so that the times include the copy of the frames.
      if (final_attributes) {
        const RunTimes& t = final_attributes->times;
        const double finishing = seconds_since(final_attributes->finish_start);
        attribute(run.get(), "steps", static_cast<std::int64_t>(final_attributes->steps));
        attribute(run.get(), "wall_seconds", t.wall + finishing);
        attribute(run.get(), "output_seconds", t.output + finishing);
        attribute(run.get(), "history_seconds", t.history);
        attribute(run.get(), "checkpoint_seconds", t.checkpoint);
        attribute(run.get(), "status", final_attributes->status);
      }
    }  // every object closed: the caller closes the file
  }

  static void check_name(const std::string& path, const std::string& name) {
    if (name.empty() || name == "." || name.find('/') != std::string::npos)
      throw std::runtime_error("output " + path + ": invalid probe name '" + name + "'");
  }

  template <class R>
  void declare(std::map<std::string, std::vector<R>>& rows, const std::string& name) {
    require_open("declare probe");
    check_name(path, name);
    rows[name];  // its group is created by the next commit
  }

  template <class R>
  static void buffer(const std::string& path, std::map<std::string, std::vector<R>>& rows,
                     const std::string& name, const R& r) {
    auto it = rows.find(name);
    if (it == rows.end())
      throw std::runtime_error("output " + path + ": probe '" + name + "' was not declared");
    it->second.push_back(r);
  }

  // /GROUP/NAME series of every declared probe: created if new, then the buffered rows.
  template <class R, std::size_t N>
  void append_probes(hid_t root, const char* group_name,
                     const std::map<std::string, std::vector<R>>& all,
                     const Column<R, double> (&columns)[N]) {
    Handle parent(
        id(H5Gopen2(root, group_name, H5P_DEFAULT), std::string("cannot open /") + group_name),
        H5Gclose);
    for (const auto& [name, rows] : all) {
      const std::string what = "cannot open group " + where(parent.get(), name);
      if (H5Lexists(parent.get(), name.c_str(), H5P_DEFAULT) <= 0) {
        Handle g = group(parent.get(), name);
        create_columns(g.get(), columns);
      }
      Handle g(id(H5Gopen2(parent.get(), name.c_str(), H5P_DEFAULT), what), H5Gclose);
      append_columns(g.get(), columns, rows);
    }
  }

  void flush() {
    require_open("flush");
    commit(nullptr, false);
  }

  void check_size(const char* what, std::size_t got, std::size_t want) const {
    if (got != want)
      throw std::runtime_error("output " + path + ": frame " + std::to_string(frame_info.size()) +
                               ": " + what + " has " + std::to_string(got) + " values, expected " +
                               std::to_string(want));
  }

  void check_node_ids(const char* what, const std::vector<int>& ids, std::size_t nodes) const {
    for (int id : ids)
      if (id < 0 || static_cast<std::size_t>(id) >= nodes)
        throw std::runtime_error("output " + path + ": frame " + std::to_string(frame_info.size()) +
                                 ": " + what + " holds node " + std::to_string(id) +
                                 ", but the frame has " + std::to_string(nodes) + " nodes");
  }

  void write_frame(const FrameData& f) {
    require_open("write_frame");
    if (f.node_position.size() % 2 != 0 || f.element_nodes.size() % 4 != 0)
      throw std::runtime_error("output " + path +
                               ": node_position must hold 2 and element_nodes 4 values per item");
    FrameInfo info;
    info.time = f.time;
    info.nodes = static_cast<long>(f.node_position.size() / 2);
    info.elements = static_cast<long>(f.element_nodes.size() / 4);
    const std::size_t n = info.nodes, m = info.elements;
    check_size("node_displacement", f.node_displacement.size(), 2 * n);
    check_size("node_velocity", f.node_velocity.size(), 2 * n);
    check_size("element_id", f.element_id.size(), m);
    check_size("element_body", f.element_body.size(), m);
    if (f.bond_nodes.size() % 2 != 0)
      throw std::runtime_error("output " + path + ": bond_nodes must hold 2 values per bond");
    info.particles = static_cast<long>(f.particle_node.size());
    info.bonds = static_cast<long>(f.bond_nodes.size() / 2);
    const std::size_t p = info.particles, b = info.bonds;
    check_size("particle_radius", f.particle_radius.size(), p);
    check_size("particle_rotation", f.particle_rotation.size(), p);
    check_size("particle_spin", f.particle_spin.size(), p);
    check_size("bond_state", f.bond_state.size(), b);
    check_size("bond_normal_force", f.bond_normal_force.size(), b);
    check_size("bond_damage", f.bond_damage.size(), b);
    // An out-of-range id would make ParaView's readers crash, not fail.
    check_node_ids("particle_node", f.particle_node, n);
    check_node_ids("bond_nodes", f.bond_nodes, n);
    // Unknown options (e.g. "velocity", always written, or fields this writer is not given
    // yet) are ignored; the case parser validates the names.
    for (const auto& field : kElementFields) {
      bool wanted = false;
      for (const auto& option : f.fields) wanted = wanted || option == field.option;
      if (!wanted) continue;
      check_size(field.dataset, (f.*field.data).size(), m * field.width);
      info.fields.push_back(&field);
    }

    // The frame's own file, written whole and renamed into place.
    const std::string final_name = frame_file(frame_info.size()), tmp = final_name + ".tmp";
    std::error_code dir_error;
    fs::create_directories(frames_dir, dir_error);
    if (dir_error)
      throw IoError("output " + path + ": cannot create directory " + frames_dir + ": " +
                    dir_error.message());
    // The frame and the commit that lists it, before HDF5 writes any of them.
    io.require_space(frames_dir, frame_bytes(f) + commit_bytes(false), final_name);
    info.single_precision = storage.single_precision;
    io.write_file(tmp, true, false, [&](hid_t file) { write_frame_datasets(file, f, info); });
    rename_over(tmp, final_name, path);
    bytes_written += written_size(final_name);
    frame_info.push_back(std::move(info));
    // The first frame at once (a run shows its initial state), the others when due.
    if (frames_committed == 0 || commit_due()) commit(nullptr, false);
  }

  // Bytes of frame f's datasets, with a margin for HDF5's metadata.
  static std::uintmax_t frame_bytes(const FrameData& f) {
    std::uintmax_t bytes = 16u << 10;
    for (const auto* v : {&f.node_position, &f.node_displacement, &f.node_velocity,
                          &f.element_stress, &f.element_plastic_strain, &f.element_pressure,
                          &f.element_von_mises, &f.particle_radius, &f.particle_rotation,
                          &f.particle_spin, &f.bond_normal_force, &f.bond_damage, &f.fragment_mass})
      bytes += v->size() * sizeof(double);
    for (const auto* v : {&f.element_nodes, &f.element_id, &f.element_body, &f.particle_node,
                          &f.bond_nodes, &f.bond_state, &f.node_fragment})
      bytes += v->size() * sizeof(int);
    return bytes + f.fragment_size.size() * sizeof(std::int64_t);
  }

  void write_frame_datasets(hid_t file, const FrameData& f, const FrameInfo& info) {
    Handle g = group(file, "frame");
    attribute(g.get(), "time", f.time);
    attribute(g.get(), "step", static_cast<std::int64_t>(f.step));
    io.write_scalar(g.get(), "time", f.time);
    io.write_scalar(g.get(), "step", static_cast<std::int64_t>(f.step));
    write_array(g.get(), "node_position", f.node_position, 2);
    write_array(g.get(), "node_displacement", f.node_displacement, 2);
    write_array(g.get(), "node_velocity", f.node_velocity, 2);
    write_array(g.get(), "element_nodes", f.element_nodes, 4);
    write_array(g.get(), "element_id", f.element_id, 1);
    write_array(g.get(), "element_body", f.element_body, 1);
    for (const ElementField* field : info.fields)
      write_array(g.get(), field->dataset, f.*field->data, field->width);
    write_array(g.get(), "particle_node", f.particle_node, 1);
    write_array(g.get(), "particle_radius", f.particle_radius, 1);
    write_array(g.get(), "particle_rotation", f.particle_rotation, 1);
    write_array(g.get(), "particle_spin", f.particle_spin, 1);
    write_array(g.get(), "bond_nodes", f.bond_nodes, 2);
    write_array(g.get(), "bond_state", f.bond_state, 1);
    write_array(g.get(), "bond_normal_force", f.bond_normal_force, 1);
    write_array(g.get(), "bond_damage", f.bond_damage, 1);
    write_array(g.get(), "node_fragment", f.node_fragment, 1);
    write_array(g.get(), "fragment_mass", f.fragment_mass, 1);
    write_array(g.get(), "fragment_size", f.fragment_size, 1);
  }

  // <DataItem> for the dataset /frames/K/NAME of shape `dims`.
  template <class T>
  void data_item(std::ostream& x, std::size_t k, const char* name, const std::string& dims) const {
    const bool single = std::is_floating_point_v<T> && frame_info[k].single_precision;
    x << "          <DataItem Dimensions=\"" << dims << "\" "
      << (single ? R"(NumberType="Float" Precision="4")" : h5::Types<T>::xdmf) << " Format=\"HDF\">"
      << xml_escape(h5_name) << ":/frames/" << k << "/" << name << "</DataItem>\n";
  }

  template <class T>
  void xdmf_attribute(std::ostream& x, std::size_t k, const char* name, const char* type,
                      const char* center, const std::string& dims) const {
    x << "        <Attribute Name=\"" << name << "\" AttributeType=\"" << type << "\" Center=\""
      << center << "\">\n";
    data_item<T>(x, k, name, dims);
    x << "        </Attribute>\n";
  }

  // One uniform grid: frame k's mesh (quadrilaterals), discs (one vertex cell per disc) or
  // bonds (two-node polylines), all over the frame's node positions.
  void xdmf_grid(std::ostream& x, std::size_t k, GridKind kind) const {
    const FrameInfo& fi = frame_info[k];
    const std::string n = std::to_string(fi.nodes), m = std::to_string(fi.elements),
                      p = std::to_string(fi.particles), b = std::to_string(fi.bonds);
    x << "      <Grid Name=\"" << kGridNames[static_cast<int>(kind)] << "_" << k
      << "\" GridType=\"Uniform\">\n"
      << "        <Time Value=\"" << fi.time << "\"/>\n";
    switch (kind) {
      case GridKind::mesh:
        x << "        <Topology TopologyType=\"Quadrilateral\" NumberOfElements=\"" << m << "\">\n";
        data_item<int>(x, k, "element_nodes", m + " 4");
        break;
      case GridKind::discs:
        x << "        <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"" << p
          << "\" NodesPerElement=\"1\">\n";
        data_item<int>(x, k, "particle_node", p);
        break;
      case GridKind::bonds:
        x << "        <Topology TopologyType=\"Polyline\" NumberOfElements=\"" << b
          << "\" NodesPerElement=\"2\">\n";
        data_item<int>(x, k, "bond_nodes", b + " 2");
        break;
    }
    x << "        </Topology>\n"
      << "        <Geometry GeometryType=\"XY\">\n";
    data_item<double>(x, k, "node_position", n + " 2");
    x << "        </Geometry>\n";
    switch (kind) {
      case GridKind::mesh:
        xdmf_attribute<double>(x, k, "node_velocity", "Vector", "Node", n + " 2");
        xdmf_attribute<double>(x, k, "node_displacement", "Vector", "Node", n + " 2");
        xdmf_attribute<int>(x, k, "element_id", "Scalar", "Cell", m);
        xdmf_attribute<int>(x, k, "element_body", "Scalar", "Cell", m);
        for (const ElementField* field : fi.fields) {
          const bool scalar = field->width == 1;
          xdmf_attribute<double>(x, k, field->dataset, scalar ? "Scalar" : "Matrix", "Cell",
                                 scalar ? m : m + " " + std::to_string(field->width));
        }
        break;
      case GridKind::discs:
        xdmf_attribute<double>(x, k, "node_velocity", "Vector", "Node", n + " 2");
        xdmf_attribute<double>(x, k, "node_displacement", "Vector", "Node", n + " 2");
        xdmf_attribute<double>(x, k, "particle_radius", "Scalar", "Cell", p);
        xdmf_attribute<double>(x, k, "particle_rotation", "Scalar", "Cell", p);
        xdmf_attribute<double>(x, k, "particle_spin", "Scalar", "Cell", p);
        break;
      case GridKind::bonds:
        xdmf_attribute<int>(x, k, "bond_state", "Scalar", "Cell", b);
        xdmf_attribute<double>(x, k, "bond_normal_force", "Scalar", "Cell", b);
        xdmf_attribute<double>(x, k, "bond_damage", "Scalar", "Cell", b);
        break;
    }
    x << "      </Grid>\n";
  }

  static bool has(const FrameInfo& fi, GridKind kind) {
    switch (kind) {
      case GridKind::mesh:
        return fi.nodes > 0 && fi.elements > 0;
      case GridKind::discs:
        return fi.particles > 0;
      case GridKind::bonds:
        return fi.bonds > 0;
    }
    return false;
  }

  void write_xdmf() const {
    std::ostringstream x;
    x.precision(std::numeric_limits<double>::max_digits10);
    x << "<?xml version=\"1.0\" ?>\n"
      << "<Xdmf Version=\"3.0\">\n"
      << "  <Domain>\n";
    for (GridKind kind : {GridKind::mesh, GridKind::discs, GridKind::bonds}) {
      const char* name = kGridNames[static_cast<int>(kind)];
      bool any = false;
      for (const FrameInfo& fi : frame_info) any = any || has(fi, kind);
      if (!any) {
        x << "    <!-- " << name << ": empty in every frame, not listed (empty grids break "
          << "ParaView's readers) -->\n";
        continue;
      }
      x << "    <Grid Name=\"" << name
        << "\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
      for (std::size_t k = 0; k < frame_info.size(); ++k) {
        const FrameInfo& fi = frame_info[k];
        if (has(fi, kind))
          xdmf_grid(x, k, kind);
        else
          x << "      <!-- frame " << k << " (time " << fi.time << ") has no "
            << kEmptyWhat[static_cast<int>(kind)]
            << ": not listed, empty grids break ParaView's readers -->\n";
      }
      x << "    </Grid>\n";
    }
    x << "  </Domain>\n"
      << "</Xdmf>\n";

    const std::string tmp = xdmf_path + ".tmp";
    {
      std::ofstream out(tmp, std::ios::trunc);
      out << x.str();
      out.close();
      if (!out) {
        std::error_code ignored;
        fs::remove(tmp, ignored);
        throw IoError("output " + path + ": cannot write " + tmp + " (file system full?)");
      }
    }
    rename_over(tmp, xdmf_path, path);
  }

  void finish(long steps, const RunTimes& times, const std::string& status) {
    if (finished) return;
    const FinalAttributes final_attributes{steps, times, status, Clock::now()};
    // Without room to copy the frames in, the last commit links them (OUT.h5.frames stays).
    // (commit checks the room first; a failed commit leaves OUT.h5 and the frames as they were).
    try {
      commit(&final_attributes, true);
      consolidated = true;
    } catch (const IoError&) {
      commit(&final_attributes, false);
      consolidated = false;
    }
    finished = true;
  }

  // After an I/O error: no more writing (the destructor would try), and no temporary files left.
  void abandon() {
    finished = true;
    std::error_code ignored;
    fs::remove(path + ".tmp", ignored);
    fs::remove(xdmf_path + ".tmp", ignored);
    for (std::size_t k = 0; k <= frame_info.size(); ++k)
      fs::remove(frame_file(k) + ".tmp", ignored);
  }
};

OutputFile::OutputFile(const std::string& path, const RunInfo& info, const FrameStorage& storage)
    : impl_(std::make_unique<Impl>()) {
  h5::silence_error_stack();  // errors become exceptions, not stderr dumps
  impl_->path = path;
  impl_->storage = storage;
  impl_->io = h5::Io("output " + path);
  impl_->open(info);
}

OutputFile::~OutputFile() {
  if (!impl_ || impl_->finished) return;
  try {
    impl_->flush();
  } catch (...) {
    // Destructors must not throw; the rows buffered since the last commit are lost.
  }
}

void OutputFile::declare_probe(const std::string& name) {
  impl_->declare(impl_->probe_rows, name);
}

void OutputFile::declare_body_probe(const std::string& name) {
  impl_->declare(impl_->body_probe_rows, name);
}

void OutputFile::declare_boundary(const std::string& name) {
  impl_->declare(impl_->boundary_rows, name);
}

void OutputFile::append_history(const HistoryRecord& r) {
  impl_->require_open("append_history");
  impl_->history_rows.push_back(r);
}

void OutputFile::append_probe(const std::string& name, const ProbeRecord& r) {
  impl_->require_open("append_probe");
  Impl::buffer(impl_->path, impl_->probe_rows, name, r);
}

void OutputFile::append_body_probe(const std::string& name, const BodyProbeRecord& r) {
  impl_->require_open("append_body_probe");
  Impl::buffer(impl_->path, impl_->body_probe_rows, name, r);
}

void OutputFile::append_boundary(const std::string& name, const BoundaryRecord& r) {
  impl_->require_open("append_boundary");
  Impl::buffer(impl_->path, impl_->boundary_rows, name, r);
}

void OutputFile::write_frame(const FrameData& f) {
  const ScopedSeconds timer(impl_->write_seconds);
  impl_->write_frame(f);
}

void OutputFile::flush() {
  impl_->flush();  // the caller's time (a checkpoint's), not the frames'
}

void OutputFile::finish(long steps, const RunTimes& times, const std::string& status) {
  const auto start = Clock::now();
  {
    const ScopedSeconds timer(impl_->write_seconds);
    impl_->finish(steps, times, status);
  }
  impl_->finish_seconds = seconds_since(start);
}

void OutputFile::abandon() {
  impl_->abandon();
}

bool OutputFile::frames_consolidated() const {
  return impl_->consolidated;
}

const std::string& OutputFile::path() const {
  return impl_->path;
}

int OutputFile::frames_written() const {
  return static_cast<int>(impl_->frame_info.size());
}

int OutputFile::frames_committed() const {
  return static_cast<int>(impl_->frames_committed);
}

std::uintmax_t OutputFile::bytes_written() const {
  return impl_->bytes_written;
}

int OutputFile::commits() const {
  return impl_->commits;
}

double OutputFile::write_seconds() const {
  return impl_->write_seconds;
}

double OutputFile::finish_seconds() const {
  return impl_->finish_seconds;
}

}  // namespace fracta
