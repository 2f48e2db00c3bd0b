// The command line contract (docs/output.md): exit codes and messages, run end to end.
#include <gtest/gtest.h>
#include <hdf5.h>
#include <sys/wait.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "cli_util.hpp"
#include "kernels/compat.hpp"  // FRACTA_DEVICE_PATH

namespace {

namespace fs = std::filesystem;

using fracta_test::data;
using fracta_test::Result;
using fracta_test::run;

// The line number a bad case file announces for its error: its own parser test knows it; here
// every malformed file must give exit code 2 and a message that starts with its path and a line.
TEST(Cli, EveryMalformedCaseExitsWithCode2NamingFileAndLine) {
  int count = 0;
  for (const auto& entry : fs::directory_iterator(data("bad"))) {
    const std::string path = entry.path().string();
    const Result r = run("check " + path);
    EXPECT_EQ(r.code, 2) << path << "\n" << r.out;
    EXPECT_NE(r.out.find("error: " + path + ":"), std::string::npos) << r.out;
    ++count;
  }
  EXPECT_GE(count, 10);
}

TEST(Cli, RunRejectsBadInputWithCode2) {
  const Result r = run("run " + data("bad/negative_density.toml") + " -o /tmp/fracta_cli_bad.h5");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("density"), std::string::npos) << r.out;
  const Result missing = run("run /nonexistent/case.toml");
  EXPECT_EQ(missing.code, 2);
  const Result bad_set = run("check " + std::string(FRACTA_SOURCE_DIR) +
                             "/cases/plate_fe.toml --set simulation.end_tme=1e-6");
  EXPECT_EQ(bad_set.code, 2);
  EXPECT_NE(bad_set.out.find("end_time"), std::string::npos) << bad_set.out;  // did you mean
}

// Impacts faster than the materials' P-wave speed are noted (shocks are beyond the laws); ten
// times faster are refused (tests/data/bad/closing_speed_absurd.toml). The main job's scene:
// concrete's P-wave speed, sqrt(E (1 - nu) / ((1 + nu) (1 - 2 nu) rho)) = 6569 m/s.
TEST(Cli, HypervelocityImpactsAreNotedAndAbsurdOnesRefused) {
  const std::string scene = std::string(FRACTA_SOURCE_DIR) + "/cases/penetration.toml";
  const std::string note = "above the largest P-wave speed of the materials (6569 m/s)";
  const Result slow =
      run("check " + scene + " --set body.projectile.initial_velocity=[0.0,-6500.0]");
  EXPECT_EQ(slow.code, 0) << slow.out;
  EXPECT_EQ(slow.out.find(note), std::string::npos) << slow.out;
  const Result fast =
      run("check " + scene + " --set body.projectile.initial_velocity=[0.0,-7000.0]");
  EXPECT_EQ(fast.code, 0) << fast.out;
  EXPECT_NE(fast.out.find("note: body 'projectile' closes on body 'slab' at 7000 m/s, " + note),
            std::string::npos)
      << fast.out;
  const Result absurd =
      run("check " + scene + " --set body.projectile.initial_velocity=[0.0,-70000.0]");
  EXPECT_EQ(absurd.code, 2) << absurd.out;
  EXPECT_NE(absurd.out.find("--set: body['projectile'].initial_velocity: closes on body 'slab' "
                            "at 7e+04 m/s, more than 10 times"),
            std::string::npos)
      << absurd.out;
}

TEST(Cli, FixedDtAboveStableBoundIsRefused) {
  const Result r = run("check " + data("cli/dt_too_large.toml"));
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("dt_too_large.toml:5: simulation.dt"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("allow_unstable_dt"), std::string::npos) << r.out;
}

// An unstable scene stops with exit code 3; the output file opens, says the run failed and its
// last frame holds a finite (last good) state.
TEST(Cli, NumericalFailureExitsWithCode3AndKeepsLastGoodFrame) {
  const std::string out = (fs::temp_directory_path() / "fracta_cli_unstable.h5").string();
  fs::remove(out);
  const Result r = run("run " + data("cli/unstable.toml") + " -o " + out);
  ASSERT_EQ(r.code, 3) << r.out;
  EXPECT_NE(r.out.find("numerical failure"), std::string::npos) << r.out;

  const hid_t f = H5Fopen(out.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  // /run status
  const hid_t run_group = H5Gopen2(f, "/run", H5P_DEFAULT);
  const hid_t attr = H5Aopen(run_group, "status", H5P_DEFAULT);
  ASSERT_GE(attr, 0);
  const hid_t type = H5Aget_type(attr);
  std::string status;
  if (H5Tis_variable_str(type) > 0) {
    char* s = nullptr;
    H5Aread(attr, type, &s);
    status = s ? s : "";
    H5free_memory(s);
  }
  EXPECT_EQ(status.rfind("failed", 0), 0u) << status;
  H5Tclose(type);
  H5Aclose(attr);
  H5Gclose(run_group);
  // The last frame is finite.
  // The complete frames are /frames@count (the group's links may include a partial one).
  std::int64_t nframes = 0;
  const hid_t frames = H5Gopen2(f, "/frames", H5P_DEFAULT);
  const hid_t count = H5Aopen(frames, "count", H5P_DEFAULT);
  ASSERT_GE(H5Aread(count, H5T_NATIVE_INT64, &nframes), 0);
  H5Aclose(count);
  ASSERT_GE(nframes, 2);
  const std::string last = "/frames/" + std::to_string(nframes - 1) + "/node_velocity";
  const hid_t ds = H5Dopen2(f, last.c_str(), H5P_DEFAULT);
  ASSERT_GE(ds, 0);
  const hid_t space = H5Dget_space(ds);
  std::vector<double> v(H5Sget_simple_extent_npoints(space));
  H5Dread(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
  double vmax = 0;
  for (double x : v) {
    ASSERT_TRUE(std::isfinite(x));
    vmax = std::max(vmax, std::fabs(x));
  }
  // Last good state: bounded by a generous multiple of the physical particle velocity
  // p / (rho c) = 100e6 / (7800 * 5875) = 2.2 m/s; a blown-up state has grown by orders more.
  EXPECT_LT(vmax, 1e3);
  H5Sclose(space);
  H5Dclose(ds);
  H5Gclose(frames);
  H5Fclose(f);
}

// Dataset `path` of an HDF5 file as doubles (any numeric type); empty if it cannot be read.
std::vector<double> read_doubles(const std::string& file, const std::string& path) {
  std::vector<double> v;
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) return v;
  const hid_t ds = H5Dopen2(f, path.c_str(), H5P_DEFAULT);
  if (ds >= 0) {
    const hid_t space = H5Dget_space(ds);
    v.resize(static_cast<size_t>(H5Sget_simple_extent_npoints(space)));
    if (!v.empty() && H5Dread(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()) < 0)
      v.clear();
    H5Sclose(space);
    H5Dclose(ds);
  }
  H5Fclose(f);
  return v;
}

// A lone adaptive body has no discs and no contact until its first conversion, which then starts
// both: it used to abort there (the failure snapshot held a contact-force view of zero rows).
// Under tension (conversion at the tension cut-off) and under compression (at the conversion
// strain), on one and two threads: the run completes, elements convert, mass is conserved to the
// bit, the energy balance closes within 1% (measured 6e-7 and 3e-4), and the two thread counts
// give the same final state to the bit.
TEST(Cli, LoneAdaptiveBodyConverts) {
  for (const char* load : {"tension", "compression"}) {
    std::vector<double> positions[2];
    for (int threads : {1, 2}) {
      SCOPED_TRACE(std::string(load) + ", threads " + std::to_string(threads));
      const std::string out = (fs::temp_directory_path() / ("fracta_lone_" + std::string(load) +
                                                            std::to_string(threads) + ".h5"))
                                  .string();
      const Result r = run("run " + data("lone/" + std::string(load) + ".toml") + " -o " + out,
                           "OMP_NUM_THREADS=" + std::to_string(threads));
      ASSERT_EQ(r.code, 0) << r.out;
      const auto conversions = read_doubles(out, "/history/count/conversions");
      const auto elements = read_doubles(out, "/history/count/elements");
      const auto mass = read_doubles(out, "/history/mass");
      const auto error = read_doubles(out, "/history/energy/error");
      ASSERT_FALSE(conversions.empty());
      EXPECT_GE(conversions.back(), 5.0);
      EXPECT_EQ(conversions.back(), elements.front() - elements.back());
      EXPECT_EQ(mass.back(), mass.front());
      EXPECT_LT(error.back(), 1e-2);
      const hid_t f = H5Fopen(out.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
      ASSERT_GE(f, 0);
      std::int64_t count = 0;
      const hid_t a = H5Aopen_by_name(f, "/frames", "count", H5P_DEFAULT, H5P_DEFAULT);
      H5Aread(a, H5T_NATIVE_INT64, &count);
      H5Aclose(a);
      H5Fclose(f);
      ASSERT_GE(count, 2);
      positions[threads - 1] =
          read_doubles(out, "/frames/" + std::to_string(count - 1) + "/node_position");
      ASSERT_FALSE(positions[threads - 1].empty());
    }
    EXPECT_EQ(positions[0], positions[1]) << load;
  }
}

// `fracta --help` is fracta's help (Kokkos answers a bare --help with its own option list
// unless it is kept from it); a subcommand's help is that subcommand's.
TEST(Cli, HelpIsFractasOwn) {
  for (const char* args : {"--help", "-h", "run --help", "check -h"}) {
    const Result r = run(args);
    EXPECT_EQ(r.code, 0) << args << "\n" << r.out;
    EXPECT_EQ(r.out.find("Kokkos command line arguments"), std::string::npos) << args << r.out;
    EXPECT_NE(r.out.find("fracta"), std::string::npos) << args << r.out;
    EXPECT_NE(r.out.find("Usage:"), std::string::npos) << args << r.out;
  }
  EXPECT_NE(run("--help").out.find("Exit codes"), std::string::npos);
  EXPECT_NE(run("run --help").out.find("--restart"), std::string::npos);
  // Kokkos' own options are still read, and its help is there when asked for.
  const Result one_thread = run("info --kokkos-threads=1");
  EXPECT_EQ(one_thread.code, 0);
  EXPECT_NE(one_thread.out.find("concurrency 1"), std::string::npos) << one_thread.out;
  const Result kokkos_help = run("--kokkos-help");
  EXPECT_EQ(kokkos_help.code, 0) << kokkos_help.out;
  EXPECT_NE(kokkos_help.out.find("--kokkos-threads"), std::string::npos) << kokkos_help.out;
}

// A Kokkos option that Kokkos refuses is bad input: a message and exit 2, not an abort (Kokkos
// throws from its initialisation).
TEST(Cli, RefusedKokkosOptionIsBadInput) {
  for (const char* args : {"info --kokkos-threads=abc", "info --kokkos-threads"}) {
    const Result r = run(args);
    EXPECT_EQ(r.code, 2) << args << "\n" << r.out;
    EXPECT_NE(r.out.find("fracta: error: a --kokkos-* option was refused"), std::string::npos)
        << args << "\n"
        << r.out;
  }
}

TEST(Cli, PlateCaseRunsAndInfoPrintsBackend) {
  const Result info = run("info");
  EXPECT_EQ(info.code, 0);
  EXPECT_NE(info.out.find("execution space"), std::string::npos);
#ifdef FRACTA_DEVICE_PATH
  EXPECT_NE(info.out.find("code path: device"), std::string::npos) << info.out;
#else
  EXPECT_NE(info.out.find("code path: host"), std::string::npos) << info.out;
#endif
  const std::string out = (fs::temp_directory_path() / "fracta_cli_plate.h5").string();
  const Result r = run("run " + std::string(FRACTA_SOURCE_DIR) + "/cases/plate_fe.toml -o " + out +
                       " --set simulation.end_time=4e-6");
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_TRUE(fs::exists(out));
  EXPECT_TRUE(fs::exists(fs::path(out).replace_extension(".xdmf")));
}

}  // namespace
