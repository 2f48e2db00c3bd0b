// Checkpoints, restart and crash-safe output (docs/output.md), through the command line on
// tests/data/restart/impact.toml: a coarse projectile-into-slab scene with FE elements,
// conversion to bonded discs, bond breakage and contact, ~1 s per run.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <hdf5.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <tuple>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "cli_util.hpp"
#include "test_util.hpp"

extern char** environ;

namespace {

namespace fs = std::filesystem;
using fracta_test::data;
using fracta_test::Result;
using fracta_test::run;

// --- HDF5 reading -------------------------------------------------------------------------

struct H5File {
  hid_t id;
  explicit H5File(const std::string& path) {
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    id = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  }
  ~H5File() {
    if (id >= 0) H5Fclose(id);
  }
};

// Any numeric dataset as doubles (integers up to 2^53 convert exactly); empty on failure.
bool read_doubles(hid_t file, const std::string& path, std::vector<double>& out) {
  out.clear();
  const hid_t ds = H5Dopen2(file, path.c_str(), H5P_DEFAULT);
  if (ds < 0) return false;
  const hid_t space = H5Dget_space(ds);
  const hssize_t n = H5Sget_simple_extent_npoints(space);
  out.resize(n > 0 ? n : 0);
  const bool ok =
      n == 0 || H5Dread(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()) >= 0;
  H5Sclose(space);
  H5Dclose(ds);
  return ok && n >= 0;
}

std::vector<double> doubles(hid_t file, const std::string& path) {
  std::vector<double> v;
  EXPECT_TRUE(read_doubles(file, path, v)) << path;
  return v;
}

double attribute(hid_t file, const char* name) {
  double v = NAN;
  const hid_t a = H5Aopen_by_name(file, "/", name, H5P_DEFAULT, H5P_DEFAULT);
  EXPECT_GE(a, 0) << name;
  if (a >= 0) {
    H5Aread(a, H5T_NATIVE_DOUBLE, &v);
    H5Aclose(a);
  }
  return v;
}

std::string string_attribute(hid_t file, const char* object, const char* name) {
  const hid_t a = H5Aopen_by_name(file, object, name, H5P_DEFAULT, H5P_DEFAULT);
  if (a < 0) return "";
  const hid_t type = H5Tcopy(H5T_C_S1);
  H5Tset_size(type, H5T_VARIABLE);
  H5Tset_cset(type, H5T_CSET_UTF8);
  char* p = nullptr;
  std::string s;
  if (H5Aread(a, type, &p) >= 0 && p) s = p;
  H5free_memory(p);
  H5Tclose(type);
  H5Aclose(a);
  return s;
}

// Full paths of every dataset below `group` (recursively), sorted by name.
std::vector<std::string> datasets_under(hid_t file, const std::string& group) {
  std::vector<std::string> out;
  const hid_t g = H5Gopen2(file, group.c_str(), H5P_DEFAULT);
  if (g < 0) return out;
  H5G_info_t info;
  H5Gget_info(g, &info);
  for (hsize_t k = 0; k < info.nlinks; ++k) {
    char name[256];
    H5Lget_name_by_idx(g, ".", H5_INDEX_NAME, H5_ITER_INC, k, name, sizeof name, H5P_DEFAULT);
    const std::string path = group + "/" + name;
    // The object's kind through H5Oopen/H5Iget_type (the same call in HDF5 1.10 and 1.12).
    const hid_t obj = H5Oopen(file, path.c_str(), H5P_DEFAULT);
    const H5I_type_t kind = obj >= 0 ? H5Iget_type(obj) : H5I_BADID;
    if (obj >= 0) H5Oclose(obj);
    if (kind == H5I_GROUP) {
      const auto sub = datasets_under(file, path);
      out.insert(out.end(), sub.begin(), sub.end());
    } else if (kind == H5I_DATASET) {
      out.push_back(path);
    }
  }
  H5Gclose(g);
  return out;
}

// The number of complete frames, /frames@count (docs/output.md: a killed
// run may leave a link /frames/K to a partial frame beyond it); -1 if it is missing.
long frame_count(hid_t file) {
  const hid_t g = H5Gopen2(file, "/frames", H5P_DEFAULT);
  if (g < 0) return -1;
  std::int64_t count = -1;
  const hid_t a = H5Aopen(g, "count", H5P_DEFAULT);
  if (a >= 0) {
    if (H5Aread(a, H5T_NATIVE_INT64, &count) < 0) count = -1;
    H5Aclose(a);
  }
  H5Gclose(g);
  return static_cast<long>(count);
}

std::string last_frame(hid_t file) {
  return "/frames/" + std::to_string(frame_count(file) - 1);
}

bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0);
}

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// --- the scene and its runs ---------------------------------------------------------------

const std::string kScene = data("restart/impact.toml");

std::string scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("fracta_ckpt_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
}

std::string exact(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

// An uninterrupted run U, a run I that stops at the time of U's step `k` (its end_time, so its
// final checkpoint is U's state after step k), and R restarted from I's checkpoint to U's end.
struct RestartRuns {
  std::string full, part, checkpoint, restarted;
  long k = 0;
  double t_k = 0;
};

// `sets`: extra --set assignments of all three runs ("" for none).
RestartRuns restart_at_middle(const std::string& env, const std::string& dir,
                              const std::string& sets) {
  const std::string extra = sets.empty() ? "" : " --set " + sets;
  RestartRuns r;
  r.full = dir + "/full.h5";
  r.part = dir + "/part.h5";
  r.checkpoint = dir + "/part.ckpt.h5";
  r.restarted = dir + "/restarted.h5";
  const Result u = run("run " + kScene + " -o " + r.full + extra, env);
  EXPECT_EQ(u.code, 0) << u.out;
  {
    H5File f(r.full);
    const std::vector<double> time = doubles(f.id, "/history/time");
    if (time.size() < 20) {
      ADD_FAILURE() << "too few history rows: " << time.size();
      return r;
    }
    // After the projectile hit (~1.25 us) and while the slab is still converting.
    r.k = static_cast<long>(time.size()) / 2;
    r.t_k = time[r.k];
  }
  const Result i = run(
      "run " + kScene + " -o " + r.part + " --set simulation.end_time=" + exact(r.t_k) + " " + sets,
      env);
  EXPECT_EQ(i.code, 0) << i.out;
  const Result restarted =
      run("run " + kScene + " --restart " + r.checkpoint + " -o " + r.restarted + extra, env);
  EXPECT_EQ(restarted.code, 0) << restarted.out;
  return r;
}

void expect_bitwise_restart(const std::string& name, const std::string& sets) {
  SCOPED_TRACE(name);
  const RestartRuns r = restart_at_middle("OMP_NUM_THREADS=1", scratch(name), sets);
  ASSERT_GT(r.k, 0);
  H5File u(r.full), c(r.checkpoint), re(r.restarted);
  ASSERT_GE(u.id, 0);
  ASSERT_GE(c.id, 0);
  ASSERT_GE(re.id, 0);
  // The checkpoint is U's state after step k: the end time was reached exactly, not rounded.
  EXPECT_EQ(attribute(c.id, "time"), r.t_k);
  EXPECT_EQ(attribute(c.id, "steps"), doubles(u.id, "/history/step")[r.k]);
  if (sets.find("weibull_modulus") != std::string::npos) {
    EXPECT_FALSE(doubles(c.id, "/strength/bonds").empty());
  }

  // The scene exercises what a checkpoint must carry, on both sides of step k: conversions
  // (new discs and bonds), broken bonds and touching contact pairs.
  const auto conversions = doubles(u.id, "/history/count/conversions");
  const auto broken = doubles(u.id, "/history/count/broken_bonds");
  const auto contacts = doubles(u.id, "/history/count/contacts");
  // conversions and broken_bonds are cumulative counts.
  const double before = conversions[r.k], after = conversions.back() - conversions[r.k];
  double touching_after = 0;
  for (size_t s = r.k + 1; s < contacts.size(); ++s)
    touching_after = std::max(touching_after, contacts[s]);
  EXPECT_GT(before, 0);
  EXPECT_GT(after, 0);
  EXPECT_GT(broken.back(), broken[r.k]);
  EXPECT_GT(contacts[r.k], 0);
  EXPECT_GT(touching_after, 0);

  // Final frames: every dataset (positions, velocities, stresses, plastic strain, discs,
  // bonds, fragments) identical to the bit.
  const std::string fu = last_frame(u.id), fr = last_frame(re.id);
  const auto names = datasets_under(u.id, fu);
  ASSERT_GE(names.size(), 15u);
  for (const std::string& name : names) {
    const std::string other = fr + name.substr(fu.size());
    EXPECT_TRUE(same_bits(doubles(u.id, name), doubles(re.id, other))) << name << " vs " << other;
  }
  // History and probes: R's rows are U's rows from step k on, to the bit.
  for (const char* group : {"/history", "/probes", "/body_probes"}) {
    const auto series = datasets_under(u.id, group);
    ASSERT_FALSE(series.empty()) << group;
    for (const std::string& name : series) {
      const auto all = doubles(u.id, name);
      ASSERT_GT(all.size(), static_cast<size_t>(r.k)) << name;
      const std::vector<double> tail(all.begin() + r.k, all.end());
      EXPECT_TRUE(same_bits(tail, doubles(re.id, name))) << name;
    }
  }
  EXPECT_EQ(string_attribute(re.id, "/run", "status"), "completed");
}

TEST(Checkpoint, RestartReproducesTheUninterruptedRunBitwiseOnOneThread) {
  expect_bitwise_restart("bitwise_fe_projectile", "");
  // The same with a rigid projectile: rigid-body state (centre, rotation, velocities).
  expect_bitwise_restart("bitwise_rigid_projectile", "body.projectile.method=rigid");
  // The same with Weibull bond strengths: the checkpoint carries the drawn factors (/strength).
  expect_bitwise_restart("bitwise_weibull",
                         "material.concrete.weibull_modulus=5 simulation.seed=3");
}

// The state does not depend on the thread count: every force sum into a node runs in a fixed
// order (chunk colours in list order, the contact gather), every selection is sorted, and the
// stable step is a minimum. So a checkpoint written by a 2-thread run, continued for ~4 steps
// on 2 threads, gives the same final frame as the same continuation on 1 thread, to the bit.
// (Until the contact gather, 84368d8, the contact atomics made two 2-thread runs part by ~1e-4
// in kinetic energy 8 steps after impact, and this test allowed 1e-12 of each field.) Only the
// energy sums over dynamically scheduled chunks join in another order; they feed no state.
TEST(Checkpoint, TwoThreadRestartGivesTheOneThreadFrameBitwise) {
  const std::string dir = scratch("threads2");
  const std::string part = dir + "/part.h5", checkpoint = dir + "/part.ckpt.h5";
  const double t_stop = 6e-6, t_end = 6.3e-6;  // mid-fracture; ~4 steps of ~85 ns after it
  const Result i =
      run("run " + kScene + " -o " + part + " --set simulation.end_time=" + exact(t_stop),
          "OMP_NUM_THREADS=2");
  ASSERT_EQ(i.code, 0) << i.out;
  const std::string two = dir + "/two.h5", one = dir + "/one.h5";
  for (const auto& [out, env] :
       {std::make_pair(two, "OMP_NUM_THREADS=2"), std::make_pair(one, "OMP_NUM_THREADS=1")}) {
    const Result r = run("run " + kScene + " --restart " + checkpoint + " -o " + out +
                             " --set simulation.end_time=" + exact(t_end),
                         env);
    ASSERT_EQ(r.code, 0) << r.out;
  }
  H5File a(two), b(one);
  ASSERT_GE(a.id, 0);
  ASSERT_GE(b.id, 0);
  EXPECT_GE(doubles(a.id, "/history/time").size(), 4u);  // the continuation took some steps
  const std::string fa = last_frame(a.id), fb = last_frame(b.id);
  EXPECT_EQ(doubles(a.id, fa + "/time"), std::vector<double>{t_end});
  // Every dataset of the frame (positions, velocities, stresses, discs, bonds, fragments), but
  // the fragments' masses: output-time sums whose chunk partials add by atomics
  // (fragment_statistics), so within 1e-13 of the largest.
  const auto names = datasets_under(a.id, fa);
  ASSERT_GE(names.size(), 15u);
  // The device path adds node sums atomically (fracta::test::kBitwiseRuns): round-off there.
  const double tolerance = fracta::test::run_tolerance(1e-12);
  for (const std::string& name : names) {
    const auto x = doubles(a.id, name), y = doubles(b.id, fb + name.substr(fa.size()));
    ASSERT_EQ(x.size(), y.size()) << name;
    if (tolerance > 0.0) {
      EXPECT_LE(fracta::test::max_relative_difference(y, x), tolerance) << name;
    } else if (name.size() >= 14 && name.substr(name.size() - 14) == "/fragment_mass") {
      double scale = 0, diff = 0;
      for (size_t k = 0; k < x.size(); ++k) {
        scale = std::max(scale, std::fabs(y[k]));
        diff = std::max(diff, std::fabs(x[k] - y[k]));
      }
      EXPECT_LE(diff, 1e-13 * scale) << name;
    } else {
      EXPECT_TRUE(same_bits(x, y)) << name;
    }
  }
  for (const char* field : {"node_velocity", "bond_normal_force", "particle_spin"})
    EXPECT_FALSE(doubles(a.id, fa + "/" + field).empty()) << field;
}

TEST(Checkpoint, RestartRefusesModelChangesAndBadCheckpointsAndKeepsTheOldOutput) {
  const std::string dir = scratch("refuse");
  const std::string out = dir + "/run.h5", checkpoint = dir + "/run.ckpt.h5";
  const Result r = run("run " + kScene + " -o " + out + " --set simulation.end_time=3e-6");
  ASSERT_EQ(r.code, 0) << r.out;
  ASSERT_TRUE(fs::exists(checkpoint));

  // A changed model: the slab's cell size, in a copy of the case file. The message names the
  // new file, the line and the key (FILE:LINE: KEY: message).
  std::ifstream in(kScene);
  std::stringstream text;
  text << in.rdbuf();
  std::string changed = text.str();
  const std::string from = "cell_size = 2e-3";
  const size_t at = changed.find(from);
  ASSERT_NE(at, std::string::npos);
  changed.replace(at, from.size(), "cell_size = 1e-3");
  const int line = 1 + static_cast<int>(std::count(changed.begin(), changed.begin() + at, '\n'));
  const std::string changed_case = dir + "/changed.toml";
  std::ofstream(changed_case) << changed;
  const Result c = run("run " + changed_case + " --restart " + checkpoint + " -o " + dir + "/x.h5");
  EXPECT_EQ(c.code, 2) << c.out;
  EXPECT_NE(c.out.find(changed_case + ":" + std::to_string(line) + ": body.slab.cell_size:"),
            std::string::npos)
      << c.out;
  // The same change through --set (the checkpoint's run had none).
  const Result s = run("run " + kScene + " --restart " + checkpoint + " -o " + dir +
                       "/x.h5 --set material.concrete.tensile_strength=3e6");
  EXPECT_EQ(s.code, 2) << s.out;
  EXPECT_NE(s.out.find("material.concrete.tensile_strength"), std::string::npos) << s.out;
  // What a restart may change is accepted: end_time and the output settings.
  const Result ok = run("run " + kScene + " --restart " + checkpoint + " -o " + dir +
                        "/ok.h5 --set simulation.end_time=4e-6 simulation.output_interval=1e-6 "
                        "'output.fields=[\"velocity\"]'");
  EXPECT_EQ(ok.code, 0) << ok.out;
  // Never over the output of the run that wrote the checkpoint.
  const Result same = run("run " + kScene + " --restart " + checkpoint + " -o " + out);
  EXPECT_EQ(same.code, 2) << same.out;
  EXPECT_NE(same.out.find(checkpoint + ": restart:"), std::string::npos) << same.out;

  // Without -o, a restart of a case whose output is the interrupted run's own file writes
  // OUT.restart.h5 beside it; the interrupted run's file is left byte for byte as it was.
  const std::string own = dir + "/own.h5", own_checkpoint = dir + "/own.ckpt.h5";
  const Result first =
      run("run " + kScene + " --set output.file=" + own + " simulation.end_time=3e-6");
  ASSERT_EQ(first.code, 0) << first.out;
  const std::string before = slurp(own);
  const Result again = run("run " + kScene + " --restart " + own_checkpoint +
                           " --set output.file=" + own + " simulation.end_time=4e-6");
  EXPECT_EQ(again.code, 0) << again.out;
  EXPECT_TRUE(fs::exists(dir + "/own.restart.h5")) << again.out;
  EXPECT_TRUE(slurp(own) == before) << "the interrupted run's output changed";

  // Missing, truncated and foreign checkpoint files.
  const std::string truncated = dir + "/truncated.ckpt.h5";
  fs::copy_file(checkpoint, truncated);
  fs::resize_file(truncated, fs::file_size(checkpoint) / 2);
  for (const std::string& bad : {dir + "/missing.ckpt.h5", truncated, out}) {
    const Result b = run("run " + kScene + " --restart " + bad + " -o " + dir + "/y.h5");
    EXPECT_EQ(b.code, 2) << bad << "\n" << b.out;
    EXPECT_NE(b.out.find("error: " + bad + ": restart:"), std::string::npos) << b.out;
  }
}

// --- signals --------------------------------------------------------------------------------

// Starts `fracta ARGS` (one thread, stdout and stderr to `log`) without waiting.
pid_t spawn(const std::vector<std::string>& args, const std::string& log,
            const std::vector<std::string>& extra_env = {}) {
  std::vector<std::string> argv_s{FRACTA_EXE};
  argv_s.insert(argv_s.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : argv_s) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::vector<std::string> env_s{"OMP_NUM_THREADS=1"};
  env_s.insert(env_s.end(), extra_env.begin(), extra_env.end());
  for (char** e = environ; *e; ++e)
    if (std::strncmp(*e, "OMP_NUM_THREADS=", 16) != 0) env_s.emplace_back(*e);
  std::vector<char*> envp;
  for (auto& e : env_s) envp.push_back(e.data());
  envp.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, FRACTA_EXE, &actions, nullptr, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&actions);
  return rc == 0 ? pid : -1;
}

// Waits until `path` exists (true) or 30 s passed / the child ended (false).
bool wait_for_file(const std::string& path, pid_t pid) {
  for (int k = 0; k < 3000; ++k) {
    if (fs::exists(path)) return true;
    if (waitpid(pid, nullptr, WNOHANG) == pid) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return false;
}

// Spawns fracta with `args` (output to `log`), waits until `file` exists (the run is stepping),
// lets it run `delay_ms` more, kills it with SIGKILL and reaps it. Fails if it could not be
// started or had already ended (not a kill mid-run).
::testing::AssertionResult kill_run_after(const std::vector<std::string>& args,
                                          const std::string& file, int delay_ms,
                                          const std::string& log,
                                          const std::vector<std::string>& extra_env = {}) {
  const pid_t pid = spawn(args, log, extra_env);
  if (pid <= 0) return ::testing::AssertionFailure() << "cannot spawn fracta";
  if (!wait_for_file(file, pid))
    return ::testing::AssertionFailure() << file << " never appeared: " << slurp(log);
  std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms));
  if (kill(pid, SIGKILL) != 0) return ::testing::AssertionFailure() << "kill failed";
  int status = 0;
  if (waitpid(pid, &status, 0) != pid) return ::testing::AssertionFailure() << "waitpid failed";
  if (!WIFSIGNALED(status))
    return ::testing::AssertionFailure() << "finished before the kill: " << slurp(log);
  return ::testing::AssertionSuccess();
}

// A run long enough to be interrupted (1 ms simulated: ~12000 steps, ~30 s), checkpoints every
// 2 us.
const std::vector<std::string> kLongRun{"--set", "simulation.end_time=1e-3"};

TEST(Checkpoint, SigintAndSigtermWriteACheckpointAndACompleteOutput) {
  const std::string dir = scratch("signals");
  for (const auto& [signal, code, name] :
       {std::make_tuple(SIGINT, 130, "SIGINT"), std::make_tuple(SIGTERM, 143, "SIGTERM")}) {
    const std::string out = dir + "/" + name + ".h5", checkpoint = dir + "/" + name + ".ckpt.h5";
    std::vector<std::string> args{"run", kScene, "-o", out};
    args.insert(args.end(), kLongRun.begin(), kLongRun.end());
    const pid_t pid = spawn(args, dir + "/" + name + ".log");
    ASSERT_GT(pid, 0);
    // The first checkpoint (2 us) exists: the run is stepping.
    ASSERT_TRUE(wait_for_file(checkpoint, pid)) << slurp(dir + "/" + name + ".log");
    ASSERT_EQ(kill(pid, signal), 0);
    int status = 0;
    ASSERT_EQ(waitpid(pid, &status, 0), pid);
    const std::string log = slurp(dir + "/" + name + ".log");
    ASSERT_TRUE(WIFEXITED(status)) << log;
    EXPECT_EQ(WEXITSTATUS(status), code) << log;
    EXPECT_NE(log.find(std::string("interrupted by ") + name), std::string::npos) << log;
    EXPECT_NE(log.find(checkpoint), std::string::npos) << log;
    // The printed restart command repeats the run's overrides.
    EXPECT_NE(log.find("continue with: fracta run " + kScene + " --restart " + checkpoint +
                       " --set simulation.end_time=1e-3\n"),
              std::string::npos)
        << log;

    // The output is closed and complete: status, frames, and its last frame is the state the
    // checkpoint holds (same time, same step).
    double t_checkpoint = 0, step_checkpoint = 0;
    {
      H5File c(checkpoint);
      ASSERT_GE(c.id, 0);
      t_checkpoint = attribute(c.id, "time");
      step_checkpoint = attribute(c.id, "steps");
    }
    {
      H5File f(out);
      ASSERT_GE(f.id, 0);
      EXPECT_EQ(string_attribute(f.id, "/run", "status"), std::string("interrupted by ") + name);
      ASSERT_GE(frame_count(f.id), 2);
      const std::string last = last_frame(f.id);
      EXPECT_EQ(doubles(f.id, last + "/time"), std::vector<double>{t_checkpoint});
      EXPECT_EQ(doubles(f.id, last + "/step"), std::vector<double>{step_checkpoint});
      EXPECT_EQ(doubles(f.id, "/history/time").back(), t_checkpoint);
      EXPECT_GT(t_checkpoint, 0.0);
    }
    // And the run continues from it to its (here shortened) end.
    const double t_end = t_checkpoint + 1e-6;
    const Result r = run("run " + kScene + " --restart " + checkpoint + " -o " + dir + "/" + name +
                         "_restarted.h5 --set simulation.end_time=" + exact(t_end));
    EXPECT_EQ(r.code, 0) << r.out;
    H5File f(dir + "/" + name + "_restarted.h5");
    ASSERT_GE(f.id, 0);
    EXPECT_EQ(doubles(f.id, "/history/time").front(), t_checkpoint);
    EXPECT_EQ(doubles(f.id, "/history/time").back(), t_end);
  }
}

// SIGKILL cannot be handled: what was flushed must survive on its own. The run writes a frame
// every step (so most of its time is spent inside HDF5 writes, where a kill is most harmful)
// and is killed at several instants; each time the file must open and every frame it lists
// must read in full, with the history holding at least one row per frame, and the .xdmf must be
// whole and show only listed frames. Each instant twice: with the default commit spacing, and
// with a commit at every frame (the FRACTA_COMMIT_EVERY_FRAME hook), so that kills land inside
// commits as often as inside frame files.
TEST(Checkpoint, SigkillLeavesAReadableOutputWithEveryListedFrame) {
  const std::string dir = scratch("sigkill");
  int killed_with_frames[2] = {0, 0};
  for (int every_frame = 0; every_frame < 2; ++every_frame)
    for (int delay_ms : {20, 60, 120, 200, 300, 450, 700, 1000}) {
      const std::string out =
          dir + "/kill" + std::to_string(delay_ms) + (every_frame ? "_every" : "") + ".h5";
      std::vector<std::string> args{"run",
                                    kScene,
                                    "-o",
                                    out,
                                    "--set",
                                    "simulation.end_time=1e-3",
                                    "simulation.output_interval=1e-9",
                                    "simulation.history_interval=1e-9",  // below dt: every step
                                    "output.checkpoint_interval=0"};
      ASSERT_TRUE(kill_run_after(args, out, delay_ms, out + ".log",
                                 every_frame
                                     ? std::vector<std::string>{"FRACTA_COMMIT_EVERY_FRAME=1"}
                                     : std::vector<std::string>{}));

      H5File f(out);
      ASSERT_GE(f.id, 0) << out << " does not open after SIGKILL at " << delay_ms << " ms";
      const long frames = frame_count(f.id);
      ASSERT_GE(frames, 0) << out;
      // Exactly the listed frames are linked.
      hsize_t links = 0;
      {
        const hid_t g = H5Gopen2(f.id, "/frames", H5P_DEFAULT);
        H5Gget_num_objs(g, &links);
        H5Gclose(g);
      }
      EXPECT_EQ(static_cast<long>(links), frames) << out;
      std::vector<double> v;
      for (long k = 0; k < frames; ++k) {
        // Every listed frame is complete: all 21 datasets of this scene's frames (time, step,
        // 3 node, 5 element, 4 disc, 4 bond, 3 fragment arrays) are there and read.
        const auto names = datasets_under(f.id, "/frames/" + std::to_string(k));
        EXPECT_EQ(names.size(), 21u) << out << ": frame " << k;
        for (const std::string& name : names)
          EXPECT_TRUE(read_doubles(f.id, name, v)) << out << ": " << name;
      }
      const auto time = doubles(f.id, "/history/time");
      EXPECT_GE(static_cast<long>(time.size()), frames) << out;
      // The .xdmf, once there (it follows the first commit of a frame), is whole and shows no
      // frame beyond the listed ones.
      const std::string xdmf_path =
          dir + "/kill" + std::to_string(delay_ms) + (every_frame ? "_every" : "") + ".xdmf";
      if (fs::exists(xdmf_path)) {
        const std::string xdmf = slurp(xdmf_path), tail = "</Xdmf>\n";
        EXPECT_TRUE(xdmf.size() >= tail.size() &&
                    xdmf.compare(xdmf.size() - tail.size(), tail.size(), tail) == 0)
            << xdmf_path;
        EXPECT_EQ(xdmf.find(":/frames/" + std::to_string(frames) + "/"), std::string::npos)
            << xdmf_path;
      }
      if (frames >= 2) ++killed_with_frames[every_frame];
    }
  // The kills did land mid-run, after frames were written.
  // (Spaced commits list fewer frames early on, the more so on a loaded machine.)
  EXPECT_GE(killed_with_frames[0], 2);
  EXPECT_GE(killed_with_frames[1], 5);
}

// A crash while a checkpoint is being written must leave the previous one intact (write to
// PATH.tmp, fsync, rename). The run writes a checkpoint every step, so most of its time is spent
// writing them, and is killed at several instants; the checkpoint left must always restart.
TEST(Checkpoint, SigkillWhileCheckpointingLeavesAValidCheckpoint) {
  const std::string dir = scratch("sigkill_checkpoint");
  for (int delay_ms : {0, 15, 40, 80}) {
    const std::string out = dir + "/kill" + std::to_string(delay_ms) + ".h5";
    const std::string checkpoint = dir + "/kill" + std::to_string(delay_ms) + ".ckpt.h5";
    ASSERT_TRUE(kill_run_after({"run", kScene, "-o", out, "--set", "simulation.end_time=1e-3",
                                "output.checkpoint_interval=1e-12"},
                               checkpoint, delay_ms, out + ".log"));
    double t = 0;
    {
      H5File c(checkpoint);
      ASSERT_GE(c.id, 0) << checkpoint << " does not open after SIGKILL at " << delay_ms << " ms";
      t = attribute(c.id, "time");
    }
    const Result r =
        run("run " + kScene + " --restart " + checkpoint + " -o " + dir + "/re" +
            std::to_string(delay_ms) + ".h5 --set simulation.end_time=" + exact(t + 0.5e-6));
    EXPECT_EQ(r.code, 0) << r.out;
  }
}

// --- I/O and internal errors --------------------------------------------------------------

// No temporary file is left in `dir` (*.tmp), and every frame `file` lists reads in full.
void expect_clean_and_complete(const std::string& dir, const std::string& file) {
  for (const auto& entry : fs::recursive_directory_iterator(dir))
    EXPECT_NE(entry.path().extension(), ".tmp") << entry.path();
  H5File f(file);
  ASSERT_GE(f.id, 0) << file << " does not open";
  const long frames = frame_count(f.id);
  ASSERT_GE(frames, 0);
  for (long k = 0; k < frames; ++k) {
    std::vector<double> v;
    EXPECT_TRUE(read_doubles(f.id, "/frames/" + std::to_string(k) + "/node_position", v)) << k;
    EXPECT_FALSE(v.empty()) << k;
  }
  if (frames > 0) {
    const double t_last = doubles(f.id, last_frame(f.id) + "/time").at(0);
    EXPECT_GE(doubles(f.id, "/history/time").back(), t_last);  // the history reaches it
  }
}

// A file-size limit (prlimit --fsize: writes fail with EFBIG, as on a full file system) ends the
// run with exit code 4 and a message naming the file, never a crash: HDF5 1.10 crashed inside an
// object copy when a write failed (exit 139 on a full file system). What was written before the
// failure stays complete and no temporary file is left. 150 KiB fails a plain write of OUT.h5's
// image at its first frame; 300 KiB fails the space check of a later commit. (prlimit, of
// util-linux, sets the limit in bytes whatever the shell; ulimit -f counts blocks of 512 bytes
// in dash and 1024 in bash.)
TEST(Checkpoint, FileSizeLimitEndsTheRunWithCode4AndKeepsWhatWasWritten) {
  for (const int kib : {150, 300}) {
    SCOPED_TRACE(std::to_string(kib) + " KiB");
    const std::string dir = scratch("fsize" + std::to_string(kib)), out = dir + "/run.h5";
    const Result r =
        run("run " + kScene + " -o " + out, "prlimit --fsize=" + std::to_string(1024 * kib));
    EXPECT_EQ(r.code, 4) << r.out;
    EXPECT_NE(r.out.find("fracta: I/O error: output " + out), std::string::npos) << r.out;
    expect_clean_and_complete(dir, out);
  }
}

// Without room to copy the frames into OUT.h5 at the end, the run still completes: the last
// commit links the frames (OUT.h5.frames stays beside it) and says so.
TEST(Checkpoint, WithoutRoomToConsolidateTheFramesStayBesideTheOutput) {
  const std::string dir = scratch("fsize_consolidate"), out = dir + "/run.h5";
  const Result r = run("run " + kScene + " -o " + out, "prlimit --fsize=409600");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("they stay in " + out + ".frames"), std::string::npos) << r.out;
  EXPECT_TRUE(fs::is_directory(out + ".frames"));
  expect_clean_and_complete(dir, out);
  H5File f(out);
  EXPECT_EQ(string_attribute(f.id, "/run", "status"), "completed");
  EXPECT_GE(frame_count(f.id), 4);
}

// An output path whose directory does not exist is an I/O error (4), named as such.
TEST(Checkpoint, MissingOutputDirectoryIsAnIoError) {
  const Result r = run("run " + kScene + " -o /nonexistent-fracta-dir/run.h5");
  EXPECT_EQ(r.code, 4) << r.out;
  EXPECT_NE(r.out.find("the directory /nonexistent-fracta-dir does not exist"), std::string::npos)
      << r.out;
}

// An internal error in a step (an exception that is not an I/O error; injected here) writes the
// last good state as the final frame, records the error in /run status, consolidates the output
// into one file and exits with code 5.
TEST(Checkpoint, InternalErrorWritesTheLastGoodStateAndExitsWith5) {
  const std::string dir = scratch("internal"), out = dir + "/run.h5";
  const Result r = run("run " + kScene + " -o " + out, "FRACTA_INJECT_INTERNAL_ERROR=120");
  ASSERT_EQ(r.code, 5) << r.out;
  EXPECT_NE(r.out.find("fracta: internal error: injected"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(out + ".frames"));  // one self-contained file
  expect_clean_and_complete(dir, out);
  H5File f(out);
  EXPECT_EQ(string_attribute(f.id, "/run", "status").rfind("failed: internal error: injected", 0),
            0u);
  // The last frame is the snapshot of step 100 (taken at most every 100 steps, at a checked
  // history row), before the error.
  EXPECT_EQ(doubles(f.id, last_frame(f.id) + "/step"), std::vector<double>{100.0});
}

}  // namespace
