// HDF5 output (docs/output.md): layout and exact values read back with the HDF5 C API, the
// .xdmf's references, empty frames, float32 and deflated frames, the commit schedule, and a run
// killed with SIGKILL after two frames.
//
// Set FRACTA_KEEP_OUTPUT_TEST=1 to keep the files (the test prints where they are).
#include "host/output.hpp"

#include <gtest/gtest.h>
#include <hdf5.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "cli_util.hpp"

namespace fracta {
namespace {

namespace fs = std::filesystem;

const char* const kEnergyNames[] = {"kinetic", "internal", "plastic",    "hourglass", "viscous",
                                    "contact", "fracture", "conversion", "external",  "error"};
const char* const kCountNames[] = {"elements",     "particles", "composite",  "bonds",
                                   "broken_bonds", "contacts",  "conversions"};

// --- writing side: deterministic records ---------------------------------------------------

HistoryRecord history_row(long i) {
  HistoryRecord r;
  r.time = 1e-8 * i;
  r.dt = 1e-8 + 1e-12 * i;
  r.step = i;
  double* e[] = {&r.energy.kinetic,  &r.energy.internal, &r.energy.plastic,  &r.energy.hourglass,
                 &r.energy.viscous,  &r.energy.contact,  &r.energy.fracture, &r.energy.conversion,
                 &r.energy.external, &r.energy.error};
  for (int k = 0; k < 10; ++k) *e[k] = 0.25 * i + k / 3.0;
  long* c[] = {&r.count.elements,     &r.count.particles, &r.count.composite,  &r.count.bonds,
               &r.count.broken_bonds, &r.count.contacts,  &r.count.conversions};
  for (int k = 0; k < 7; ++k) *c[k] = 1000L * k + 3 * i + 5000000000L;  // beyond int32
  r.mass = 2.5 + 1e-3 * i;
  r.momentum_x = 0.1 * i;
  r.momentum_y = -0.2 * i;
  return r;
}

ProbeRecord probe_row(long i) {
  const double t = 1e-8 * i;
  return {t, 1e-6 * i, -1e-6 * i, 3.0 * i, -4.0 * i, 1e6 * i, -2e6 * i, 5e5 * i};
}

BodyProbeRecord body_probe_row(long i) {
  return {2e-8 * i, 0.01 + 1e-5 * i, 0.02, 300.0 - 0.5 * i, 0.25 * i};
}

// nx x ny quads of size h, counter-clockwise; every array filled with distinct values.
FrameData make_frame(int nx, int ny, double time, long step, std::vector<std::string> fields) {
  FrameData f;
  f.time = time;
  f.step = step;
  const double h = 1e-3;
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) {
      const int n = j * (nx + 1) + i;
      f.node_position.insert(f.node_position.end(), {i * h + 1e-7 * n, j * h - 2e-7 * n});
      f.node_displacement.insert(f.node_displacement.end(), {1e-7 * n, -2e-7 * n});
      f.node_velocity.insert(f.node_velocity.end(), {10.0 + n, -0.5 * n});
    }
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const int a = j * (nx + 1) + i, e = j * nx + i;
      f.element_nodes.insert(f.element_nodes.end(), {a, a + 1, a + nx + 2, a + nx + 1});
      f.element_id.push_back(3 * e + 1);
      f.element_body.push_back(e % 2);
      f.element_stress.insert(f.element_stress.end(), {1e6 * e, -2e6 * e, 3e5 * e, 4e5 * e});
      f.element_plastic_strain.push_back(0.01 * e);
      f.element_pressure.push_back(-1e5 * e);
      f.element_von_mises.push_back(2e6 * e + 1);
    }
  f.fields = std::move(fields);
  return f;
}

// Appends a row of `count` discs (new nodes right of the mesh, 1 mm apart) to `f`, bonded in a
// chain and to every second neighbour; bonds whose index is in `broken` are broken (state 2, no
// force).
void add_discs(FrameData& f, int count, const std::vector<int>& broken) {
  const int first = static_cast<int>(f.node_position.size() / 2);
  for (int i = 0; i < count; ++i) {
    const int n = first + i;
    f.node_position.insert(f.node_position.end(), {0.02 + 1e-3 * i, 5e-4 + 1e-8 * n});
    f.node_displacement.insert(f.node_displacement.end(), {2e-7 * i, 1e-8 * n});
    f.node_velocity.insert(f.node_velocity.end(), {-3.0 * i, 0.25 * n});
    f.particle_node.push_back(n);
    f.particle_radius.push_back(5e-4 + 1e-6 * i);
    f.particle_rotation.push_back(0.01 * i - 0.02);
    f.particle_spin.push_back(-150.0 * i);
  }
  for (int step : {1, 2})
    for (int i = 0; i + step < count; ++i) {
      const int k = static_cast<int>(f.bond_state.size());
      bool is_broken = false;
      for (int b : broken) is_broken = is_broken || b == k;
      f.bond_nodes.insert(f.bond_nodes.end(), {first + i, first + i + step});
      f.bond_state.push_back(is_broken ? 2 : 1);
      f.bond_normal_force.push_back(is_broken ? 0.0 : 125.5 * k - 400.0);
      f.bond_damage.push_back(is_broken ? 1.0 : 0.01 * k);
    }
}

// Frames in float64, unfiltered: every value reads back exactly.
const FrameStorage kDouble{false, 0};

RunInfo run_info(std::string case_text = "[simulation]\ntitle = \"output test\"\n") {
  RunInfo info;
  info.version = "0.1.0+test";
  info.backend = "OpenMP";
  info.threads = 4;
  info.case_text = std::move(case_text);
  info.case_path = "cases/output_test.toml";
  return info;
}

// --- reading side ---------------------------------------------------------------------------

struct H5Id {
  hid_t id;
  herr_t (*close)(hid_t);
  ~H5Id() {
    if (id >= 0) close(id);
  }
};

template <class T>
hid_t native();
template <>
hid_t native<double>() {
  return H5T_NATIVE_DOUBLE;
}
template <>
hid_t native<std::int64_t>() {
  return H5T_NATIVE_INT64;
}
template <>
hid_t native<int>() {
  return H5T_NATIVE_INT;
}

// True when every component of the absolute `path` exists.
bool exists(hid_t file, const std::string& path) {
  std::string prefix;
  std::stringstream parts(path);
  std::string part;
  while (std::getline(parts, part, '/')) {
    if (part.empty()) continue;
    prefix += "/" + part;
    if (H5Lexists(file, prefix.c_str(), H5P_DEFAULT) <= 0) return false;
  }
  return true;
}

std::vector<hsize_t> dims_of(hid_t file, const std::string& path) {
  H5Id ds{H5Dopen2(file, path.c_str(), H5P_DEFAULT), H5Dclose};
  if (ds.id < 0) ADD_FAILURE() << "cannot open " << path;
  if (ds.id < 0) return {};
  H5Id space{H5Dget_space(ds.id), H5Sclose};
  std::vector<hsize_t> dims(H5Sget_simple_extent_ndims(space.id));
  H5Sget_simple_extent_dims(space.id, dims.data(), nullptr);
  return dims;
}

// Class and size of the stored element type.
std::pair<H5T_class_t, size_t> type_of(hid_t file, const std::string& path) {
  H5Id ds{H5Dopen2(file, path.c_str(), H5P_DEFAULT), H5Dclose};
  H5Id type{H5Dget_type(ds.id), H5Tclose};
  return {H5Tget_class(type.id), H5Tget_size(type.id)};
}

template <class T>
std::vector<T> read(hid_t file, const std::string& path) {
  std::size_t n = 1;
  for (hsize_t d : dims_of(file, path)) n *= d;
  std::vector<T> v(n);
  H5Id ds{H5Dopen2(file, path.c_str(), H5P_DEFAULT), H5Dclose};
  if (n > 0) {
    EXPECT_GE(H5Dread(ds.id, native<T>(), H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()), 0) << path;
  }
  return v;
}

template <class T>
T read_attribute(hid_t file, const std::string& object, const char* name) {
  T value{};
  H5Id a{H5Aopen_by_name(file, object.c_str(), name, H5P_DEFAULT, H5P_DEFAULT), H5Aclose};
  EXPECT_GE(a.id, 0) << object << " " << name;
  if (a.id >= 0) {
    EXPECT_GE(H5Aread(a.id, native<T>(), &value), 0) << object << " " << name;
  }
  return value;
}

template <>
std::string read_attribute<std::string>(hid_t file, const std::string& object, const char* name) {
  H5Id a{H5Aopen_by_name(file, object.c_str(), name, H5P_DEFAULT, H5P_DEFAULT), H5Aclose};
  EXPECT_GE(a.id, 0) << object << " " << name;
  if (a.id < 0) return {};
  H5Id type{H5Tcopy(H5T_C_S1), H5Tclose};
  H5Tset_size(type.id, H5T_VARIABLE);
  H5Tset_cset(type.id, H5T_CSET_UTF8);
  char* p = nullptr;
  EXPECT_GE(H5Aread(a.id, type.id, &p), 0);
  std::string s = p ? p : "";
  H5free_memory(p);
  return s;
}

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

class OutputFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string templ = (fs::path(::testing::TempDir()) / "fracta_output_XXXXXX").string();
    ASSERT_NE(mkdtemp(templ.data()), nullptr);
    dir_ = templ;
    h5_ = (fs::path(dir_) / "out.h5").string();
    xdmf_ = (fs::path(dir_) / "out.xdmf").string();
  }
  void TearDown() override {
    if (std::getenv("FRACTA_KEEP_OUTPUT_TEST"))
      std::printf("kept %s\n", dir_.c_str());
    else
      fs::remove_all(dir_);
  }
  hid_t open_file() const {
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    return H5Fopen(h5_.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  }

  // Every "out.h5:/path" in the .xdmf names a dataset whose shape matches the declared one.
  // Returns the number of DataItems checked.
  int check_xdmf_references(hid_t file) const {
    const std::string text = slurp(xdmf_);
    const std::regex item(
        R"re(<DataItem Dimensions="([0-9 ]+)" NumberType="(\w+)" Precision="(\d)" )re"
        R"re(Format="HDF">([^<:]+):([^<]+)</DataItem>)re");
    int count = 0;
    for (auto it = std::sregex_iterator(text.begin(), text.end(), item);
         it != std::sregex_iterator(); ++it, ++count) {
      const std::string dims_text = (*it)[1], number_type = (*it)[2], file_name = (*it)[4],
                        path = (*it)[5];
      const size_t precision = std::stoul((*it)[3]);
      // The declared type is the stored one (ParaView reads the bytes as declared).
      EXPECT_EQ(type_of(file, path),
                std::make_pair(number_type == "Float" ? H5T_FLOAT : H5T_INTEGER, precision))
          << path;
      EXPECT_EQ(file_name, "out.h5");
      EXPECT_TRUE(exists(file, path)) << path;
      EXPECT_GT(H5Oexists_by_name(file, path.c_str(), H5P_DEFAULT), 0) << path;
      std::vector<hsize_t> declared;
      std::stringstream ds(dims_text);
      for (hsize_t d; ds >> d;) declared.push_back(d);
      EXPECT_EQ(declared, dims_of(file, path)) << path;
    }
    return count;
  }

  std::string dir_, h5_, xdmf_;
};

// `single`: a floating-point array stored as float32 reads back as each value rounded to float.
template <class T>
void expect_frame_array(hid_t file, const std::string& path, const std::vector<T>& want,
                        std::vector<hsize_t> dims, bool single = false) {
  EXPECT_EQ(dims_of(file, path), dims) << path;
  std::vector<T> stored = want;
  if constexpr (std::is_floating_point_v<T>) {
    if (single)
      for (T& v : stored) v = static_cast<T>(static_cast<float>(v));
    EXPECT_EQ(type_of(file, path), std::make_pair(H5T_FLOAT, single ? size_t{4} : size_t{8}))
        << path;
  }
  EXPECT_EQ(read<T>(file, path), stored) << path;
}

void expect_frame(hid_t file, int k, const FrameData& f, bool single = false) {
  const std::string g = "/frames/" + std::to_string(k);
  const hsize_t n = f.node_position.size() / 2, m = f.element_nodes.size() / 4;
  EXPECT_EQ(read_attribute<double>(file, g, "time"), f.time);
  EXPECT_EQ(read_attribute<std::int64_t>(file, g, "step"), f.step);
  EXPECT_EQ(read<double>(file, g + "/time"), std::vector<double>{f.time});
  EXPECT_TRUE(dims_of(file, g + "/time").empty());  // scalar
  expect_frame_array(file, g + "/node_position", f.node_position, {n, 2}, single);
  expect_frame_array(file, g + "/node_displacement", f.node_displacement, {n, 2}, single);
  expect_frame_array(file, g + "/node_velocity", f.node_velocity, {n, 2}, single);
  expect_frame_array(file, g + "/element_nodes", f.element_nodes, {m, 4});
  expect_frame_array(file, g + "/element_id", f.element_id, {m});
  expect_frame_array(file, g + "/element_body", f.element_body, {m});
  EXPECT_EQ(type_of(file, g + "/element_nodes"), std::make_pair(H5T_INTEGER, size_t{4}));
  EXPECT_EQ(type_of(file, g + "/element_body"), std::make_pair(H5T_INTEGER, size_t{4}));
  auto wanted = [&](const char* option) {
    for (const auto& s : f.fields)
      if (s == option) return true;
    return false;
  };
  struct Optional {
    const char* option;
    const char* dataset;
    const std::vector<double>* data;
    hsize_t width;
  };
  const Optional optional[] = {
      {"stress", "element_stress", &f.element_stress, 4},
      {"plastic_strain", "element_plastic_strain", &f.element_plastic_strain, 1},
      {"pressure", "element_pressure", &f.element_pressure, 1},
      {"von_mises", "element_von_mises", &f.element_von_mises, 1},
  };
  for (const auto& o : optional) {
    const std::string path = g + "/" + o.dataset;
    if (!wanted(o.option)) {
      EXPECT_FALSE(exists(file, path)) << path;
      continue;
    }
    expect_frame_array(file, path, *o.data,
                       o.width == 1 ? std::vector<hsize_t>{m} : std::vector<hsize_t>{m, o.width},
                       single);
  }
  // Discs and bonds: always written, zero-size in a pure-FE frame.
  const hsize_t p = f.particle_node.size(), b = f.bond_nodes.size() / 2;
  expect_frame_array(file, g + "/particle_node", f.particle_node, {p});
  expect_frame_array(file, g + "/particle_radius", f.particle_radius, {p}, single);
  expect_frame_array(file, g + "/particle_rotation", f.particle_rotation, {p}, single);
  expect_frame_array(file, g + "/particle_spin", f.particle_spin, {p}, single);
  expect_frame_array(file, g + "/bond_nodes", f.bond_nodes, {b, 2});
  expect_frame_array(file, g + "/bond_state", f.bond_state, {b});
  expect_frame_array(file, g + "/bond_normal_force", f.bond_normal_force, {b}, single);
  expect_frame_array(file, g + "/bond_damage", f.bond_damage, {b}, single);
  for (const char* name : {"particle_node", "bond_nodes", "bond_state"})
    EXPECT_EQ(type_of(file, g + "/" + name), std::make_pair(H5T_INTEGER, size_t{4})) << name;
}

// Number of matches of `pattern` in `text`.
int count_matches(const std::string& text, const std::string& pattern) {
  const std::regex re(pattern);
  return static_cast<int>(
      std::distance(std::sregex_iterator(text.begin(), text.end(), re), std::sregex_iterator()));
}

// The <Time> values of the temporal collection `name` of the .xdmf.
std::vector<double> collection_times(const std::string& text, const std::string& name) {
  const std::string open = "<Grid Name=\"" + name + "\" GridType=\"Collection\"";
  const std::size_t begin = text.find(open);
  if (begin == std::string::npos) return {};
  // Collections hold uniform grids only, so the first "    </Grid>" (4 spaces) closes it.
  const std::size_t end = text.find("\n    </Grid>", begin);
  const std::string body = text.substr(begin, end - begin);
  const std::regex time_re(R"re(<Time Value="([^"]+)")re");
  std::vector<double> times;
  for (auto it = std::sregex_iterator(body.begin(), body.end(), time_re);
       it != std::sregex_iterator(); ++it)
    times.push_back(std::stod((*it)[1]));
  return times;
}

// History rows [0, rows) as written by history_row().
void expect_history(hid_t file, long rows) {
  std::vector<double> time, dt, mass, px, py;
  std::vector<std::int64_t> step;
  std::vector<std::vector<double>> energy(10);
  std::vector<std::vector<std::int64_t>> count(7);
  for (long i = 0; i < rows; ++i) {
    const HistoryRecord r = history_row(i);
    time.push_back(r.time);
    dt.push_back(r.dt);
    step.push_back(r.step);
    mass.push_back(r.mass);
    px.push_back(r.momentum_x);
    py.push_back(r.momentum_y);
    const double e[] = {r.energy.kinetic,   r.energy.internal,   r.energy.plastic,
                        r.energy.hourglass, r.energy.viscous,    r.energy.contact,
                        r.energy.fracture,  r.energy.conversion, r.energy.external,
                        r.energy.error};
    const long c[] = {r.count.elements,     r.count.particles, r.count.composite,  r.count.bonds,
                      r.count.broken_bonds, r.count.contacts,  r.count.conversions};
    for (int k = 0; k < 10; ++k) energy[k].push_back(e[k]);
    for (int k = 0; k < 7; ++k) count[k].push_back(c[k]);
  }
  EXPECT_EQ(read<double>(file, "/history/time"), time);
  EXPECT_EQ(read<double>(file, "/history/dt"), dt);
  EXPECT_EQ(read<std::int64_t>(file, "/history/step"), step);
  EXPECT_EQ(read<double>(file, "/history/mass"), mass);
  EXPECT_EQ(read<double>(file, "/history/momentum_x"), px);
  EXPECT_EQ(read<double>(file, "/history/momentum_y"), py);
  for (int k = 0; k < 10; ++k)
    EXPECT_EQ(read<double>(file, std::string("/history/energy/") + kEnergyNames[k]), energy[k])
        << kEnergyNames[k];
  for (int k = 0; k < 7; ++k) {
    const std::string path = std::string("/history/count/") + kCountNames[k];
    EXPECT_EQ(read<std::int64_t>(file, path), count[k]) << path;
    EXPECT_EQ(type_of(file, path), std::make_pair(H5T_INTEGER, size_t{8})) << path;
  }
}

TEST_F(OutputFileTest, WritesEveryDatasetOfTheContract) {
  const std::vector<FrameData> frames = {
      make_frame(3, 2, 1e-6, 100,
                 {"velocity", "stress", "plastic_strain", "pressure", "von_mises"}),
      make_frame(2, 2, 2e-6, 200, {"stress", "damage"}),  // unknown options are ignored
      make_frame(4, 1, 2.5e-6, 250, {"plastic_strain", "von_mises"}),
  };
  const long frame_after[] = {100, 200, 250};  // frame k is written after that many rows
  const long rows = 300, probe_rows = 120, body_rows = 80;
  {
    OutputFile out(h5_, run_info(), kDouble);
    EXPECT_EQ(out.path(), h5_);
    out.declare_probe("tip");
    out.declare_body_probe("projectile");
    int k = 0;
    for (long i = 0; i < rows; ++i) {
      out.append_history(history_row(i));
      if (i < probe_rows) out.append_probe("tip", probe_row(i));
      if (i < body_rows) out.append_body_probe("projectile", body_probe_row(i));
      if (k < 3 && i + 1 == frame_after[k]) out.write_frame(frames[k++]);
    }
    EXPECT_EQ(out.frames_written(), 3);
    out.finish(rows, RunTimes{1.5, 0.25, 0.125, 0.0625}, "completed");
    out.finish(rows, RunTimes{2.5, 0, 0, 0}, "twice");  // a second finish is a no-op
    EXPECT_EQ(out.frames_committed(), 3);
  }

  H5Id file{open_file(), H5Fclose};
  ASSERT_GE(file.id, 0);
  EXPECT_EQ(read_attribute<std::string>(file.id, "/run", "version"), "0.1.0+test");
  EXPECT_EQ(read_attribute<std::string>(file.id, "/run", "backend"), "OpenMP");
  EXPECT_EQ(read_attribute<int>(file.id, "/run", "threads"), 4);
  EXPECT_EQ(read_attribute<std::string>(file.id, "/run", "case"), run_info().case_text);
  EXPECT_EQ(read_attribute<std::string>(file.id, "/run", "case_path"), "cases/output_test.toml");
  EXPECT_EQ(read_attribute<std::int64_t>(file.id, "/run", "steps"), rows);
  // The times given, plus finish()'s own time (the last commit) for the wall and the output.
  const double wall = read_attribute<double>(file.id, "/run", "wall_seconds");
  EXPECT_GE(wall, 1.5);
  EXPECT_LT(wall, 1.5 + 10.0);
  EXPECT_NEAR(read_attribute<double>(file.id, "/run", "output_seconds") - 0.25, wall - 1.5, 1e-12);
  EXPECT_EQ(read_attribute<double>(file.id, "/run", "history_seconds"), 0.125);
  EXPECT_EQ(read_attribute<double>(file.id, "/run", "checkpoint_seconds"), 0.0625);
  EXPECT_EQ(read_attribute<std::string>(file.id, "/run", "status"), "completed");
  EXPECT_EQ(read_attribute<std::string>(file.id, "/run", "frame_precision"), "double");
  EXPECT_EQ(read_attribute<std::int64_t>(file.id, "/run", "frame_compression"), 0);

  expect_history(file.id, rows);
  for (const char* name : {"time", "ux", "uy", "vx", "vy", "sxx", "syy", "sxy"})
    EXPECT_EQ(dims_of(file.id, std::string("/probes/tip/") + name),
              std::vector<hsize_t>{probe_rows})
        << name;
  for (const char* name : {"time", "x", "y", "vx", "vy"})
    EXPECT_EQ(dims_of(file.id, std::string("/body_probes/projectile/") + name),
              std::vector<hsize_t>{body_rows})
        << name;
  std::vector<double> sxy, body_vx;
  for (long i = 0; i < probe_rows; ++i) sxy.push_back(probe_row(i).sxy);
  for (long i = 0; i < body_rows; ++i) body_vx.push_back(body_probe_row(i).vx);
  EXPECT_EQ(read<double>(file.id, "/probes/tip/sxy"), sxy);
  EXPECT_EQ(read<double>(file.id, "/body_probes/projectile/vx"), body_vx);

  for (int k = 0; k < 3; ++k) expect_frame(file.id, k, frames[k]);
  EXPECT_FALSE(exists(file.id, "/frames/3"));
  // Readers list frames by /frames@count (complete frames), written last for each frame.
  EXPECT_EQ(read_attribute<std::int64_t>(file.id, "/frames", "count"), 3);

  // The .xdmf: one grid per frame with its time, and only references that resolve.
  ASSERT_TRUE(fs::exists(xdmf_));
  EXPECT_FALSE(fs::exists(xdmf_ + ".tmp"));
  const std::string text = slurp(xdmf_);
  EXPECT_NE(text.find(R"(CollectionType="Temporal")"), std::string::npos);
  const std::regex time_re(R"re(<Time Value="([^"]+)")re");
  std::vector<double> times;
  for (auto it = std::sregex_iterator(text.begin(), text.end(), time_re);
       it != std::sregex_iterator(); ++it)
    times.push_back(std::stod((*it)[1]));
  EXPECT_EQ(times, (std::vector<double>{1e-6, 2e-6, 2.5e-6}));
  // Per grid: topology, geometry, velocity, displacement, id, body + optional fields (4, 1, 2).
  EXPECT_EQ(check_xdmf_references(file.id), 3 * 6 + 4 + 1 + 2);
  for (const char* name : {"/frames/0/element_stress", "/frames/2/element_von_mises",
                           "/frames/1/node_velocity", "/frames/2/element_body"})
    EXPECT_NE(text.find(std::string("out.h5:") + name), std::string::npos) << name;
  // A pure-FE run: one temporal collection (the mesh), no disc or bond grid.
  EXPECT_EQ(count_matches(text, R"(CollectionType="Temporal")"), 1);
  EXPECT_EQ(collection_times(text, "mesh"), (std::vector<double>{1e-6, 2e-6, 2.5e-6}));
  for (const char* absent :
       {"Polyvertex", "Polyline", "particle_", "bond_", R"(Name="discs")", R"(Name="bonds")"})
    EXPECT_EQ(text.find(absent), std::string::npos) << absent;
}

// Frames with discs and bonds: FE mesh + discs, then some bonds broken, then every element
// converted (discs only), then a frame with neither (nothing to show).
TEST_F(OutputFileTest, WritesDiscsAndBonds) {
  std::vector<FrameData> frames;
  frames.push_back(make_frame(3, 2, 1e-6, 100, {"stress"}));  // pure FE
  frames.push_back(make_frame(2, 2, 2e-6, 200, {"von_mises"}));
  add_discs(frames.back(), 5, {});  // 4 + 3 bonds, all active
  frames.push_back(make_frame(2, 1, 3e-6, 300, {"von_mises", "plastic_strain"}));
  add_discs(frames.back(), 6, {0, 3, 7});  // 5 + 4 bonds, 3 broken
  frames.push_back(make_frame(0, 0, 4e-6, 400, {"stress"}));
  frames.back().node_position.clear();  // no FE node at all: only the discs' nodes
  frames.back().node_displacement.clear();
  frames.back().node_velocity.clear();
  add_discs(frames.back(), 4, {0, 1, 2, 3, 4});  // every bond broken
  frames.push_back(make_frame(1, 1, 5e-6, 500, {}));
  frames.back().element_nodes.clear();  // nodes, but no element, disc or bond
  frames.back().element_id.clear();
  frames.back().element_body.clear();
  {
    OutputFile out(h5_, run_info(), kDouble);
    for (const FrameData& f : frames) out.write_frame(f);
    out.finish(500, RunTimes{0.5}, "completed");
  }
  H5Id file{open_file(), H5Fclose};
  ASSERT_GE(file.id, 0);
  for (int k = 0; k < 5; ++k) expect_frame(file.id, k, frames[k]);
  EXPECT_EQ(dims_of(file.id, "/frames/0/particle_node"), (std::vector<hsize_t>{0}));
  EXPECT_EQ(dims_of(file.id, "/frames/0/bond_nodes"), (std::vector<hsize_t>{0, 2}));
  EXPECT_EQ(dims_of(file.id, "/frames/2/bond_nodes"), (std::vector<hsize_t>{9, 2}));
  EXPECT_EQ(read<int>(file.id, "/frames/2/bond_state"),
            (std::vector<int>{2, 1, 1, 2, 1, 1, 1, 2, 1}));
  EXPECT_EQ(read<int>(file.id, "/frames/3/particle_node"), (std::vector<int>{0, 1, 2, 3}));

  // The .xdmf: one temporal collection per kind of grid, each listing the frames that have it.
  const std::string text = slurp(xdmf_);
  EXPECT_EQ(count_matches(text, R"(CollectionType="Temporal")"), 3);
  EXPECT_EQ(collection_times(text, "mesh"), (std::vector<double>{1e-6, 2e-6, 3e-6}));
  EXPECT_EQ(collection_times(text, "discs"), (std::vector<double>{2e-6, 3e-6, 4e-6}));
  EXPECT_EQ(collection_times(text, "bonds"), (std::vector<double>{2e-6, 3e-6, 4e-6}));
  EXPECT_EQ(count_matches(text, R"(TopologyType="Polyvertex" NumberOfElements="[0-9]+" )"
                                R"(NodesPerElement="1")"),
            3);
  EXPECT_EQ(count_matches(text, R"(TopologyType="Polyline" NumberOfElements="[0-9]+" )"
                                R"(NodesPerElement="2")"),
            3);
  EXPECT_NE(text.find(R"(NumberOfElements="9" NodesPerElement="2")"), std::string::npos);
  for (const char* name : {"particle_radius", "particle_rotation", "particle_spin", "bond_state",
                           "bond_normal_force", "bond_damage"})
    EXPECT_EQ(count_matches(text, std::string("<Attribute Name=\"") + name +
                                      R"(" AttributeType="Scalar" Center="Cell">)"),
              3)
        << name;
  EXPECT_EQ(text.find("/frames/4/"), std::string::npos);  // nothing to show in frame 4
  EXPECT_EQ(text.find("out.h5:/frames/0/particle"), std::string::npos);
  EXPECT_EQ(text.find("out.h5:/frames/3/element"), std::string::npos);
  // Mesh grids: 6 references each + fields (1 stress, 1 von Mises, 2); disc grids 7, bond
  // grids 5 (topology, geometry, state, normal force, damage).
  EXPECT_EQ(check_xdmf_references(file.id), 3 * 6 + 1 + 1 + 2 + 3 * 7 + 3 * 5);
}

TEST_F(OutputFileTest, EmptyFramesWriteZeroSizeDatasets) {
  const FrameData no_nodes = make_frame(0, 0, 1e-6, 10, {"stress", "plastic_strain"});
  FrameData none;  // nothing at all
  none.time = 2e-6;
  none.step = 20;
  none.fields = {"stress", "pressure", "von_mises"};
  const FrameData some = make_frame(1, 1, 3e-6, 30, {"von_mises"});
  {
    OutputFile out(h5_, run_info(), kDouble);
    out.write_frame(none);
    out.write_frame(no_nodes);  // 1 node, no element
    out.write_frame(some);
    out.finish(30, RunTimes{0.1}, "completed");
  }
  H5Id file{open_file(), H5Fclose};
  ASSERT_GE(file.id, 0);
  expect_frame(file.id, 0, none);
  EXPECT_EQ(dims_of(file.id, "/frames/0/node_position"), (std::vector<hsize_t>{0, 2}));
  EXPECT_EQ(dims_of(file.id, "/frames/0/element_stress"), (std::vector<hsize_t>{0, 4}));
  EXPECT_EQ(dims_of(file.id, "/frames/0/element_von_mises"), (std::vector<hsize_t>{0}));
  expect_frame(file.id, 1, no_nodes);
  expect_frame(file.id, 2, some);
  expect_history(file.id, 0);  // no rows: the series exist, empty
  EXPECT_EQ(dims_of(file.id, "/history/time"), (std::vector<hsize_t>{0}));
  // Frames without elements are left out of the .xdmf (empty grids break ParaView's readers).
  const std::string text = slurp(xdmf_);
  EXPECT_EQ(text.find("/frames/0/"), std::string::npos);
  EXPECT_EQ(text.find("/frames/1/"), std::string::npos);
  EXPECT_EQ(check_xdmf_references(file.id), 6 + 1);
}

TEST_F(OutputFileTest, LargeCaseTextIsKeptWhole) {
  std::string big = "[simulation]\ntitle = \"big\"\n";
  while (big.size() < 200000) big += "# padding line to make the case text large: 0123456789\n";
  { OutputFile out(h5_, run_info(big)); }  // no finish: the destructor closes the file
  H5Id file{open_file(), H5Fclose};
  ASSERT_GE(file.id, 0);
  EXPECT_EQ(read_attribute<std::string>(file.id, "/run", "case"), big);
  EXPECT_LE(H5Aexists_by_name(file.id, "/run", "status", H5P_DEFAULT), 0);
}

TEST_F(OutputFileTest, ErrorsNameThePathAndWhatFailed) {
  const std::string bad = dir_ + "/no/such/dir/out.h5";
  try {
    OutputFile out(bad, run_info());
    FAIL() << "created " << bad;
  } catch (const IoError& e) {  // exit code 4 through the command line
    EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("the directory " + dir_ + "/no/such/dir does not exist"),
              std::string::npos)
        << e.what();
  }
  OutputFile out(h5_, run_info());
  EXPECT_THROW(out.append_probe("undeclared", probe_row(1)), std::runtime_error);
  EXPECT_THROW(out.declare_probe("a/b"), std::runtime_error);
  FrameData f = make_frame(2, 1, 0.0, 0, {"stress"});
  f.element_stress.pop_back();
  EXPECT_THROW(out.write_frame(f), std::runtime_error);
  FrameData d = make_frame(2, 1, 0.0, 0, {});
  add_discs(d, 3, {});
  d.particle_spin.pop_back();
  EXPECT_THROW(out.write_frame(d), std::runtime_error);
  d = make_frame(2, 1, 0.0, 0, {});
  add_discs(d, 3, {});
  d.bond_normal_force.push_back(1.0);
  EXPECT_THROW(out.write_frame(d), std::runtime_error);
  d = make_frame(2, 1, 0.0, 0, {});
  add_discs(d, 3, {});
  d.bond_damage.pop_back();
  EXPECT_THROW(out.write_frame(d), std::runtime_error);
  d = make_frame(2, 1, 0.0, 0, {});
  add_discs(d, 3, {});
  d.bond_nodes.back() = static_cast<int>(d.node_position.size() / 2);  // one past the last node
  try {
    out.write_frame(d);
    ADD_FAILURE() << "wrote a bond to a missing node";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("bond_nodes"), std::string::npos) << e.what();
  }
  d = make_frame(2, 1, 0.0, 0, {});
  add_discs(d, 3, {});
  d.particle_node[0] = -1;
  EXPECT_THROW(out.write_frame(d), std::runtime_error);
  EXPECT_EQ(out.frames_written(), 0);
  out.finish(0, RunTimes{}, "failed: test");
  EXPECT_THROW(out.append_history(history_row(0)), std::runtime_error);
}

// Frames in float32 (the default) and deflated: every array reads back as written (float32:
// rounded to float), the filters are on the datasets, and the .xdmf declares the stored types.
TEST_F(OutputFileTest, SinglePrecisionAndDeflatedFramesReadBack) {
  for (const FrameStorage storage :
       {FrameStorage{}, FrameStorage{true, 4}, FrameStorage{false, 6}}) {
    SCOPED_TRACE(std::string(storage.single_precision ? "single" : "double") + ", deflate " +
                 std::to_string(storage.deflate));
    std::vector<FrameData> frames;
    frames.push_back(make_frame(40, 30, 1e-6, 100, {"stress", "von_mises"}));
    add_discs(frames.back(), 50, {3, 7, 20});
    frames.push_back(make_frame(0, 0, 2e-6, 200, {"stress"}));  // zero-size arrays
    {
      OutputFile out(h5_, run_info(), storage);
      for (const FrameData& f : frames) out.write_frame(f);
      out.finish(200, RunTimes{}, "completed");
    }
    H5Id file{open_file(), H5Fclose};
    ASSERT_GE(file.id, 0);
    for (int k = 0; k < 2; ++k) expect_frame(file.id, k, frames[k], storage.single_precision);
    EXPECT_EQ(read_attribute<std::string>(file.id, "/run", "frame_precision"),
              storage.single_precision ? "single" : "double");
    EXPECT_EQ(read_attribute<std::int64_t>(file.id, "/run", "frame_compression"), storage.deflate);
    // Shuffle then deflate on every non-empty array of a deflated frame, none otherwise.
    for (const char* name : {"node_position", "element_nodes", "bond_state", "element_stress"}) {
      H5Id ds{H5Dopen2(file.id, (std::string("/frames/0/") + name).c_str(), H5P_DEFAULT), H5Dclose};
      H5Id dcpl{H5Dget_create_plist(ds.id), H5Pclose};
      const int filters = H5Pget_nfilters(dcpl.id);
      if (storage.deflate == 0) {
        EXPECT_EQ(filters, 0) << name;
        continue;
      }
      ASSERT_EQ(filters, 2) << name;
      unsigned flags = 0, values[4] = {};
      size_t count = 4;
      EXPECT_EQ(H5Pget_filter2(dcpl.id, 0, &flags, &count, values, 0, nullptr, nullptr),
                H5Z_FILTER_SHUFFLE);
      count = 4;
      EXPECT_EQ(H5Pget_filter2(dcpl.id, 1, &flags, &count, values, 0, nullptr, nullptr),
                H5Z_FILTER_DEFLATE);
      EXPECT_EQ(values[0], static_cast<unsigned>(storage.deflate)) << name;
    }
    EXPECT_GT(check_xdmf_references(file.id), 0);
    file.close(file.id);
    file.id = -1;
    fs::remove(h5_);
  }
}

// Commits are spaced (output.cpp): frames written back to back commit only now and then, the
// first frame commits at once, and a frame after a pause commits. What is listed is complete.
TEST_F(OutputFileTest, CommitsAreSpacedAndAFrameAfterAPauseCommits) {
  const FrameData f = make_frame(10, 10, 0.0, 0, {"stress"});
  OutputFile out(h5_, run_info());
  out.write_frame(f);
  EXPECT_EQ(out.frames_committed(), 1);  // the first frame is listed at once
  const int frames = 150;
  for (int k = 1; k < frames; ++k) out.write_frame(f);
  EXPECT_EQ(out.frames_written(), frames);
  // A commit is due once 19 times its duration has passed: back to back, a frame (an HDF5 file
  // of its own) costs no more than a commit, so at most one frame in 3 commits.
  EXPECT_LE(out.commits(), 1 + frames / 3) << out.commits() << " commits";
  std::printf("%d frames back to back: %d commits\n", frames, out.commits());
  EXPECT_LE(out.frames_committed(), frames);
  // After a pause, the next frame commits everything (waits up to 10 s for a slow machine).
  const auto start = std::chrono::steady_clock::now();
  while (out.frames_committed() != out.frames_written() &&
         std::chrono::steady_clock::now() - start < std::chrono::seconds(10)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    out.write_frame(f);
  }
  EXPECT_EQ(out.frames_committed(), out.frames_written());
  H5Id file{open_file(), H5Fclose};
  ASSERT_GE(file.id, 0);
  EXPECT_EQ(read_attribute<std::int64_t>(file.id, "/frames", "count"), out.frames_committed());
  EXPECT_GT(check_xdmf_references(file.id), 0);
}

// A run killed (SIGKILL, no finish, no destructor) after two frames leaves a readable file with
// the frames and history rows of its last commit: the first frame commits at once, the second
// when flush() commits it (as a checkpoint does), with every row buffered before it.
TEST_F(OutputFileTest, KilledAfterTwoFramesLeavesReadableFile) {
  const FrameData f0 = make_frame(2, 2, 1e-6, 40, {"stress"});
  const FrameData f1 = make_frame(3, 1, 2e-6, 90, {"von_mises"});
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    try {
      OutputFile out(h5_, run_info(), kDouble);
      out.declare_probe("tip");
      for (long i = 0; i < 150; ++i) {
        out.append_history(history_row(i));
        out.append_probe("tip", probe_row(i));
        if (i + 1 == 40) out.write_frame(f0);
        if (i + 1 == 90) {
          out.write_frame(f1);
          out.flush();
        }
      }
      kill(getpid(), SIGKILL);
    } catch (...) {
    }
    _exit(1);
  }
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) << "child status " << status;

  H5Id file{open_file(), H5Fclose};
  ASSERT_GE(file.id, 0) << "killed run left an unreadable file";
  expect_frame(file.id, 0, f0);
  expect_frame(file.id, 1, f1);
  EXPECT_FALSE(exists(file.id, "/frames/2"));
  EXPECT_EQ(read_attribute<std::int64_t>(file.id, "/frames", "count"), 2);
  expect_history(file.id, 90);
  EXPECT_EQ(dims_of(file.id, "/probes/tip/time"), (std::vector<hsize_t>{90}));
  EXPECT_EQ(read_attribute<std::string>(file.id, "/run", "backend"), "OpenMP");
  EXPECT_EQ(check_xdmf_references(file.id), 2 * 6 + 1 + 1);
}

// Constant cost per frame (docs/output.md, crash-safe writing), counted in bytes, not timed:
// 100 and 1000 frames of a 40 x 40 mesh, each with a history row, written back to back and
// finished, write the same bytes per frame within 10 %: frame files, the commits' OUT.h5 and
// .xdmf (each lists every frame so far) and the final copy of the frames into OUT.h5. The
// commits' own share stays bounded only because they are spaced: with a commit at every frame
// (the test hook FRACTA_COMMIT_EVERY_FRAME) a commit rewrites what the run has written so far,
// and the bytes per frame grow with the frames (measured: 1.6 times from 100 to 400 frames, 2.8
// times from 100 to 1000), which the second half checks so that the first can fail.
TEST(OutputCost, BytesPerFrameDoNotGrowWithTheFramesWritten) {
  std::string templ = (fs::path(::testing::TempDir()) / "fracta_output_cost_XXXXXX").string();
  ASSERT_NE(mkdtemp(templ.data()), nullptr);
  const FrameData frame = make_frame(40, 40, 0.0, 0, {"stress", "von_mises"});
  // Bytes per frame of a run of `frames` frames, finished.
  const auto bytes_per_frame = [&](int frames) {
    const std::string h5 = templ + "/run" + std::to_string(frames) + ".h5";
    OutputFile out(h5, run_info());
    for (int k = 0; k < frames; ++k) {
      out.append_history(history_row(k));
      out.write_frame(frame);
    }
    out.finish(frames, RunTimes{1.0}, "completed");
    EXPECT_EQ(out.frames_written(), frames);
    EXPECT_TRUE(out.frames_consolidated());
    const double per_frame = static_cast<double>(out.bytes_written()) / frames;
    std::printf("%4d frames: %d commits, %.1f kB per frame\n", frames, out.commits(),
                1e-3 * per_frame);
    fs::remove(h5);
    return per_frame;
  };
  const double spaced = bytes_per_frame(1000) / bytes_per_frame(100);
  std::printf("spaced commits: bytes per frame at 1000 frames / at 100 frames = %.3f\n", spaced);
  EXPECT_LT(spaced, 1.1);
  EXPECT_GT(spaced, 1.0 / 1.1);

  setenv("FRACTA_COMMIT_EVERY_FRAME", "1", 1);
  const double every_frame = bytes_per_frame(400) / bytes_per_frame(100);
  unsetenv("FRACTA_COMMIT_EVERY_FRAME");
  std::printf("a commit at every frame: ratio %.3f\n", every_frame);
  EXPECT_GT(every_frame, 1.3) << "the count cannot tell a growing cost per frame";
  fs::remove_all(templ);
}

}  // namespace
}  // namespace fracta
