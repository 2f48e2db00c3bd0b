#include "host/checkpoint.hpp"

#include <fcntl.h>
#include <hdf5.h>  // host only: the CUDA check skips the files that include it
#include <unistd.h>

#include <Kokkos_Core.hpp>
#include <cerrno>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <stdexcept>
#include <type_traits>

#include "host/case.hpp"
#include "host/hdf5.hpp"
#include "host/simulation.hpp"
#include "host/state_views.hpp"
#include "host/text_lines.hpp"

namespace fracta {

namespace {

namespace fs = std::filesystem;

constexpr const char* kFormat = "fracta checkpoint";
// 2: bond damage and onset separation; 3: the lists of used bond slots and of particles;
// 4: the FE dissipation sums; 5: bond slots in the bond kernel's order (build_lattice);
// 6: the contact's discs are the boundary nodes and the particles (x_build has one row each);
// 8: nodes.fixed (supports); 9: the Weibull strength factors (/strength), when drawn;
// 10: the volumetric strains of the lattice's cell term (empty without it); 11: views a scene
// never uses are empty (the FE state of an all-de scene, the viscous hourglass form's
// displacement)
constexpr std::int64_t kFormatVersion = 11;

using h5::Handle;

// Writes go through "checkpoint: ..." messages; reads through bare ones, which the callers turn
// into an InputError naming the file.
const h5::Io kWrite("checkpoint");
const h5::Io kRead("");

template <class V>
std::vector<hsize_t> dims_of(const V& v) {
  std::vector<hsize_t> dims{v.extent(0)};
  if constexpr (static_cast<int>(V::rank) == 2) dims.push_back(v.extent(1));
  return dims;
}

// A view as a row-major host array, whatever the device layout.
template <class V>
void write_view(hid_t loc, const std::string& name, const V& v) {
  using T = typename V::non_const_value_type;
  static_assert(static_cast<int>(V::rank) == 1 || static_cast<int>(V::rank) == 2);
  auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), v);
  std::vector<T> flat;
  flat.reserve(h.size());
  for (size_t i = 0; i < h.extent(0); ++i) {
    if constexpr (static_cast<int>(V::rank) == 1) {
      flat.push_back(h(i));
    } else {
      for (size_t j = 0; j < h.extent(1); ++j) flat.push_back(h(i, j));
    }
  }
  kWrite.write_array(loc, name, dims_of(v), flat);
}

template <class V>
void read_view(hid_t loc, const std::string& name, const V& v) {
  using T = typename V::non_const_value_type;
  const std::vector<T> flat = kRead.read_array<T>(loc, name, dims_of(v));
  auto h = Kokkos::create_mirror_view(v);
  // Only the values that differ are written (bit for bit: a -0 over a 0 is written): the pages
  // of a lazily zeroed view (sparse_zero_view) that the checkpoint holds as zeros stay unused.
  const auto set = [](T& to, const T& from) {
    if (std::memcmp(&to, &from, sizeof(T)) != 0) to = from;
  };
  size_t k = 0;
  for (size_t i = 0; i < h.extent(0); ++i) {
    if constexpr (static_cast<int>(V::rank) == 1) {
      set(h(i), flat[k++]);
    } else {
      for (size_t j = 0; j < h.extent(1); ++j) set(h(i, j), flat[k++]);
    }
  }
  Kokkos::deep_copy(v, h);
}

// fsync of a file or directory; a failure means the data may not be on disk.
void sync_path(const std::string& path, int flags) {
  const int fd = ::open(path.c_str(), flags);
  if (fd < 0 || ::fsync(fd) != 0) {
    const std::string why = std::strerror(errno);
    if (fd >= 0) ::close(fd);
    throw IoError("checkpoint: cannot sync " + path + ": " + why);
  }
  ::close(fd);
}

volatile std::sig_atomic_t g_stop_signal = 0;

extern "C" void on_stop_signal(int signal) {
  g_stop_signal = signal;
}

}  // namespace

// Friend of Simulation: the host-side state that is not a view.
struct CheckpointIO {
  // Calls f(name, value&) for every Simulation scalar that a step reads or writes: the ledger's
  // fields and the lengths of the model's lists (ledger.hpp).
  template <class F>
  static void scalars(Simulation& s, ListCounts& lists, F&& f) {
    for_each_field(s.ledger_, f);
    for_each_field(lists, f);
  }

  static void write(Simulation& s, hid_t file) {
    s.finish_kick();
    StateViews live = s.state_views();
    const Handle state = kWrite.create_group(file, "state");
    for_each_state_view(live, live, [&](const char* name, const auto& v, const auto&) {
      write_view(state.get(), name, v);
    });
    const Handle scalar_group = kWrite.create_group(file, "scalars");
    ListCounts lists = ListCounts::of(s.model_);
    scalars(s, lists, [&](const char* name, auto& value) {
      using T = std::decay_t<decltype(value)>;
      if constexpr (std::is_same_v<T, double>)
        kWrite.write_attribute(scalar_group.get(), name, value);
      else
        kWrite.write_attribute(scalar_group.get(), name, static_cast<std::int64_t>(value));
    });
    // Set-up data a step never writes, kept so a restart continues the same realisation.
    if (s.model_.bonds.strength_scale.extent(0) > 0) {
      const Handle strength = kWrite.create_group(file, "strength");
      write_view(strength.get(), "bonds", s.model_.bonds.strength_scale);
      write_view(strength.get(), "cells", s.model_.elements.cell_inverse_strength_scale);
    }
    std::vector<double> rigid;
    for (const RigidBody& b : s.model_.rigid)
      rigid.insert(rigid.end(), {b.x, b.y, b.theta, b.vx, b.vy, b.omega});
    kWrite.write_array<double>(file, "rigid", {s.model_.rigid.size(), 6}, rigid);
    if (s.model_.contacts) {
      const ContactSystem::ListState cs = s.model_.contacts->list_state();
      const Handle g = kWrite.create_group(file, "contact");
      kWrite.write_array<int>(g.get(), "pair_i", {cs.pair_i.size()}, cs.pair_i);
      kWrite.write_array<int>(g.get(), "pair_j", {cs.pair_j.size()}, cs.pair_j);
      kWrite.write_array<double>(g.get(), "x_build", {cs.x_build.size() / 2, 2}, cs.x_build);
      kWrite.write_attribute(g.get(), "built", static_cast<std::int64_t>(cs.built));
      kWrite.write_attribute(g.get(), "rebuilds", static_cast<std::int64_t>(cs.rebuilds));
    }
  }

  static void read(Simulation& s, hid_t file) {
    StateViews live = s.state_views();
    const Handle state = kRead.open_group(file, "state");
    for_each_state_view(live, live, [&](const char* name, const auto& v, const auto&) {
      read_view(state.get(), name, v);
    });
    s.stable_dt_.invalidate();           // the bonds and radii were replaced
    s.contact_force_prev_zero_ = false;  // the checkpoint's contact forces, as they are
    if (s.model_.bonds.strength_scale.extent(0) > 0) {
      const Handle strength = kRead.open_group(file, "strength");
      read_view(strength.get(), "bonds", s.model_.bonds.strength_scale);
      read_view(strength.get(), "cells", s.model_.elements.cell_inverse_strength_scale);
    }
    const Handle scalar_group = kRead.open_group(file, "scalars");
    ListCounts lists;
    scalars(s, lists, [&](const char* name, auto& value) {
      using T = std::decay_t<decltype(value)>;
      if constexpr (std::is_same_v<T, double>)
        value = kRead.read_attribute<double>(scalar_group.get(), name);
      else
        value = static_cast<T>(kRead.read_attribute<std::int64_t>(scalar_group.get(), name));
    });
    lists.apply_to(s.model_);
    std::vector<RigidBody>& bodies = s.model_.rigid;
    const std::vector<double> rigid = kRead.read_array<double>(file, "rigid", {bodies.size(), 6});
    for (size_t k = 0; k < bodies.size(); ++k) {
      RigidBody& b = bodies[k];
      const double* r = &rigid[6 * k];
      b.x = r[0], b.y = r[1], b.theta = r[2], b.vx = r[3], b.vy = r[4], b.omega = r[5];
    }
    // The active list and counts must agree, or a kernel would read out of bounds.
    const int active = s.model_.elements.active_count, converted = s.model_.converted_count;
    if (active < 0 || active > s.model_.elements.count || converted < 0 ||
        converted > static_cast<int>(s.model_.converted.extent(0)))
      throw std::runtime_error("element counts out of range");
    const int used = s.model_.bonds.used_count, particles = s.model_.nodes.particle_count;
    if (used < 0 || used > static_cast<int>(s.model_.bonds.used.extent(0)) || particles < 0 ||
        particles > static_cast<int>(s.model_.nodes.particle_list.extent(0)))
      throw std::runtime_error("bond or particle list counts out of range");
    // The slots of the converted cells: their topology is written at conversion.
    fill_slot_topology(s.model_.converted, s.model_.converted_count, s.model_.topology,
                       s.model_.nodes, s.model_.bonds);
    if (s.model_.contacts) {
      ContactSystem& contacts = *s.model_.contacts;
      contacts.invalidate();  // the list comes from the checkpoint: nothing to insert into
      contacts.refresh_discs(s.model_.nodes);  // the discs of the restored particles
      const Handle g = kRead.open_group(file, "contact");
      ContactSystem::ListState cs;
      const hsize_t count = kRead.size_of(g.get(), "pair_i");
      cs.pair_i = kRead.read_array<int>(g.get(), "pair_i", {count});
      cs.pair_j = kRead.read_array<int>(g.get(), "pair_j", {count});
      const hsize_t discs = static_cast<hsize_t>(contacts.disc_count());
      cs.x_build = kRead.read_array<double>(g.get(), "x_build", {discs, 2});
      cs.built = kRead.read_attribute<std::int64_t>(g.get(), "built") != 0;
      cs.rebuilds = static_cast<long>(kRead.read_attribute<std::int64_t>(g.get(), "rebuilds"));
      for (size_t p = 0; p < count; ++p)
        if (cs.pair_i[p] < 0 || cs.pair_j[p] < 0 || cs.pair_i[p] >= s.model_.nodes.count ||
            cs.pair_j[p] >= s.model_.nodes.count)
          throw std::runtime_error("contact pair " + std::to_string(p) +
                                   " holds a node id out of range");
      contacts.restore_list_state(cs);
    }
    s.locate_scatter_chunks();
    // The constructor's force evaluation flagged elements of the initial active list.
    Kokkos::deep_copy(s.conversion_pending_, 0);
    // The next step as the uninterrupted run computes it, for the restart's end_time (the
    // stored dt was shortened if the checkpoint's run ended at this time).
    s.ledger_.clock.dt = s.next_dt();
  }
};

std::string checkpoint_path_for(const std::string& output_path) {
  fs::path p(output_path);
  if (p.extension() == ".h5") p.replace_extension();
  return p.string() + ".ckpt.h5";
}

void write_checkpoint(Simulation& sim, const std::string& path, const CheckpointInfo& info) {
  h5::silence_error_stack();  // errors become exceptions, not stderr dumps
  const std::string tmp = path + ".tmp";
  // Room for the new checkpoint beside the old one, before HDF5 writes any of it: the state's
  // bytes (StateViews) and a margin for the case text, the contact list and HDF5's metadata.
  std::uintmax_t bytes = (64u << 10) + 2 * info.case_text.size();
  {
    StateViews live = sim.state();
    for_each_state_view(live, live, [&](const char*, const auto& v, const auto&) {
      bytes += v.span() * sizeof(typename std::decay_t<decltype(v)>::non_const_value_type);
    });
    if (sim.model().contacts) bytes += 12 * sim.model().contacts->candidate_count();
  }
  bytes += bytes / 10;  // HDF5's metadata
  kWrite.require_space(path, bytes, tmp);
  kWrite.write_file(tmp, false, false, [&](hid_t root) {
    kWrite.write_attribute(root, "format", std::string(kFormat));
    kWrite.write_attribute(root, "format_version", kFormatVersion);
    kWrite.write_attribute(root, "version", info.version);
    kWrite.write_attribute(root, "case", info.case_text);
    kWrite.write_attribute(root, "case_path", info.case_path);
    kWrite.write_attribute(root, "overrides", join_lines(info.overrides));
    kWrite.write_attribute(root, "output_path", info.output_path);
    kWrite.write_attribute(root, "time", info.time);
    kWrite.write_attribute(root, "steps", static_cast<std::int64_t>(info.steps));
    CheckpointIO::write(sim, root);
  });
  // Durable before it replaces the previous checkpoint: after a crash PATH holds one complete
  // checkpoint, the old or the new.
  try {
    sync_path(tmp, O_RDONLY);
  } catch (...) {
    h5::Io::remove_file(tmp);  // the previous checkpoint stays as it was
    throw;
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0)
    throw IoError("checkpoint: cannot rename " + tmp + " to " + path + ": " + std::strerror(errno));
  fs::path dir = fs::path(path).parent_path();
  sync_path(dir.empty() ? "." : dir.string(), O_RDONLY | O_DIRECTORY);
}

namespace {

// Opens a checkpoint for reading; InputError when it is not one.
hid_t open_checkpoint(const std::string& path) {
  h5::silence_error_stack();
  std::error_code ec;
  if (!fs::is_regular_file(path, ec))
    throw InputError(path, 0, "restart", "the checkpoint file does not exist");
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (file < 0)
    throw InputError(path, 0, "restart",
                     "cannot open the checkpoint as HDF5 (truncated or corrupt file?)");
  return file;
}

}  // namespace

CheckpointInfo read_checkpoint_info(const std::string& path) {
  const Handle file(open_checkpoint(path), H5Fclose);
  const hid_t root = file.get();
  CheckpointInfo info;
  try {
    if (kRead.read_attribute<std::string>(root, "format") != kFormat)
      throw std::runtime_error("not a fracta checkpoint");
    const std::int64_t version = kRead.read_attribute<std::int64_t>(root, "format_version");
    if (version != kFormatVersion)
      throw std::runtime_error("checkpoint format version " + std::to_string(version) +
                               ", this fracta reads version " + std::to_string(kFormatVersion));
    info.version = kRead.read_attribute<std::string>(root, "version");
    info.case_text = kRead.read_attribute<std::string>(root, "case");
    info.case_path = kRead.read_attribute<std::string>(root, "case_path");
    info.overrides = split_lines(kRead.read_attribute<std::string>(root, "overrides"));
    info.output_path = kRead.read_attribute<std::string>(root, "output_path");
    info.time = kRead.read_attribute<double>(root, "time");
    info.steps = static_cast<long>(kRead.read_attribute<std::int64_t>(root, "steps"));
  } catch (const std::runtime_error& e) {
    throw InputError(path, 0, "restart", std::string("not a valid fracta checkpoint: ") + e.what());
  }
  return info;
}

void read_checkpoint_state(Simulation& sim, const std::string& path) {
  const Handle file(open_checkpoint(path), H5Fclose);
  try {
    CheckpointIO::read(sim, file.get());
  } catch (const std::runtime_error& e) {
    throw InputError(path, 0, "restart",
                     std::string("the checkpoint does not match the model: ") + e.what());
  }
}

std::string prepare_restart(const Case& c, const std::string& checkpoint_path,
                            const std::string& requested_output) {
  const CheckpointInfo info = read_checkpoint_info(checkpoint_path);
  const Case stored = parse_case(info.case_text, info.case_path, info.overrides);
  check_restart_compatible(stored, c);
  std::string target = requested_output.empty() ? c.output.file : requested_output;
  std::error_code ec1, ec2;
  const bool same = fs::weakly_canonical(target, ec1) ==
                    fs::weakly_canonical(info.output_path.empty() ? "." : info.output_path, ec2);
  if (same && !ec1 && !ec2) {
    if (!requested_output.empty())
      throw InputError(checkpoint_path, 0, "restart",
                       "-o " + target +
                           " is the output of the run that wrote this checkpoint; a restart never "
                           "overwrites it: choose another output path");
    fs::path p(target);
    if (p.extension() == ".h5") p.replace_extension();
    target = p.string() + ".restart.h5";
  }
  return target;
}

StopSignals::StopSignals() {
  g_stop_signal = 0;
  struct sigaction sa;
  std::memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_stop_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESETHAND;
  sigaction(SIGINT, &sa, &old_int_);
  sigaction(SIGTERM, &sa, &old_term_);
}

StopSignals::~StopSignals() {
  sigaction(SIGINT, &old_int_, nullptr);
  sigaction(SIGTERM, &old_term_, nullptr);
}

int StopSignals::received() {
  return g_stop_signal;
}

}  // namespace fracta
