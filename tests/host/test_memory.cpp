// Extreme but valid sizes: a body of one cell runs; a case asking for 10^7 cells or more is
// refused by the memory check before the mesh is allocated; the estimate is compared with the
// peak resident memory of real runs.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "host/memory.hpp"
#include "host/mesh.hpp"
#include "host/simulation.hpp"
#include "test_util.hpp"

extern char** environ;

namespace fracta {
namespace {

namespace fs = std::filesystem;
using test::MemoryLimit;

// A free body of a single cell translating at (3, -2) m/s: no strain, so nothing may change.
// Momentum and kinetic energy stay m v and m v^2 / 2 to round-off (1e-12 relative: positions
// grow by v dt each step, and the strain from their differences is ~1e-16).
TEST(Memory, OneCellBodyRunsForEveryMethod) {
  for (BodyMethod method : {BodyMethod::fe, BodyMethod::de, BodyMethod::adaptive}) {
    SCOPED_TRACE(to_string(method));
    Case c = test::rectangle_case(1, 1, 1e-3, 200e9, 0.2);  // nu inside the lattice's range
    c.bodies[0].method = method;
    c.bodies[0].initial_velocity = {3.0, -2.0};
    Simulation sim(c);
    ASSERT_EQ(sim.model().elements.count, 1);
    ASSERT_EQ(sim.model().nodes.count, 4);
    const double mass = 7800.0 * 1e-3 * 1e-3 * 0.01;  // rho * area * thickness (kg)
    const double worst_energy_error = test::run_to_end(sim);
    EXPECT_FALSE(sim.failed());
    EXPECT_GT(sim.steps(), 3);
    const HistoryRecord h = sim.history();
    EXPECT_NEAR(h.mass, mass, 1e-12 * mass);
    EXPECT_NEAR(h.momentum_x, 3.0 * mass, 1e-12 * 3.0 * mass);
    EXPECT_NEAR(h.momentum_y, -2.0 * mass, 1e-12 * 3.0 * mass);
    EXPECT_NEAR(h.energy.kinetic, 0.5 * mass * 13.0, 1e-12 * 0.5 * mass * 13.0);
    EXPECT_LT(worst_energy_error, 1e-9);
  }
}

// The estimate counts the bounding-box grid: exactly the mesh's cells and nodes for a rectangle,
// an upper bound for a circle (the mesh keeps about pi/4 of the box, staircased).
// Resident memory of the process now (B), from /proc/self/statm.
double resident_bytes() {
  std::ifstream statm("/proc/self/statm");
  double pages = 0, resident = 0;
  statm >> pages >> resident;
  return resident * static_cast<double>(sysconf(_SC_PAGESIZE));
}

// zero_lazily clears exactly the bytes asked, whatever they held, and on Linux the pages it
// hands back cost memory again only once used: 256 MiB filled, cleared lazily, then written at
// one byte in every 16th page. (Reading a page may commit it too: on some kernels, this CI's
// among them, an untouched anonymous page has no shared zero page behind it.)
TEST(Memory, ZeroLazilyCostsOnlyTheWrittenPages) {
  const size_t bytes = size_t(256) << 20;
  const size_t page = static_cast<size_t>(sysconf(_SC_PAGESIZE));
  char* block = static_cast<char*>(std::malloc(bytes));
  ASSERT_NE(block, nullptr);
  std::memset(block, 0xab, bytes);
  const double filled = resident_bytes();
  // Unaligned ends: the partial pages are cleared in place, the bytes around them stay.
  zero_lazily(block + 100, bytes - 300);
  const double cleared = resident_bytes();
  for (size_t k = 16 * page; k < bytes - 16 * page; k += 16 * page) block[k] = 1;
  const double written = resident_bytes();
  EXPECT_EQ(static_cast<unsigned char>(block[99]), 0xabu);
  EXPECT_EQ(static_cast<unsigned char>(block[bytes - 200]), 0xabu);
  size_t nonzero = 0;
  for (size_t k = 100; k < bytes - 200; ++k) nonzero += block[k] != 0 && k % (16 * page) != 0;
  EXPECT_EQ(nonzero, 0u);
  std::free(block);
  // Reset this process's peak RSS: a child it spawns later inherits the peak through exec, and
  // Memory.EstimateBoundsTheMeasuredPeakRss measures its children's (proc(5), clear_refs).
  std::ofstream("/proc/self/clear_refs") << "5";
  RecordProperty("released_mib", std::to_string((filled - cleared) / (1 << 20)));
  RecordProperty("written_mib", std::to_string((written - cleared) / (1 << 20)));
#if defined(__linux__)
  EXPECT_GT(filled - cleared, 0.95 * bytes);                   // handed back
  EXPECT_NEAR(written - cleared, bytes / 16.0, 0.02 * bytes);  // one page in 16 used
#endif
}

TEST(Memory, EstimateCountsTheBoundingBoxGrid) {
  Case c = test::rectangle_case(32, 64, 0.9375e-3);
  MemoryEstimate e = estimate_memory(c);
  HostMesh m = build_mesh(c);
  EXPECT_EQ(e.cells, m.element_count());
  EXPECT_EQ(e.nodes, m.node_count());
  c.bodies[0].shape.type = Shape::Type::circle;
  c.bodies[0].shape.radius = 0.01;
  e = estimate_memory(c);
  m = build_mesh(c);
  EXPECT_EQ(e.cells, 21.0 * 21.0);  // 0.02 m / 0.9375 mm = 21.3 cells across, rounded
  EXPECT_GT(e.cells, m.element_count());
  EXPECT_NEAR(m.element_count(), M_PI / 4 * e.cells, 0.05 * e.cells);  // staircase: O(h / R)
}

long peak_rss_kib() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss;
}

// 0.03 x 0.06 m in cells of 6 um: 5000 x 10000 = 5e7 cells, some 20 GB. With 8 GB available it
// is refused at the body's cell_size with the estimate and the limit in the message, and before
// the mesh is built: the process's peak RSS grows by less than 10 MB (the node-id grid alone
// would take 200 MB).
TEST(Memory, TenMillionCellsAreRefusedBeforeAllocating) {
  MemoryLimit limit("8e9");
  Case c = test::rectangle_case(32, 64, 0.9375e-3);
  c.bodies[0].cell_size = 6e-6;
  c.bodies[0].pos = {"big.toml", 17, 1};
  const long rss_before = peak_rss_kib();
  try {
    (void)build_mesh(c);
    FAIL() << "a 5e7-cell mesh was built with 8 GB available";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind("big.toml:17: body['block'].cell_size: ", 0), 0u) << what;
    EXPECT_NE(what.find("5e+07 cells"), std::string::npos) << what;
    EXPECT_NE(what.find("only 8 GB is available (FRACTA_MEMORY_LIMIT_BYTES)"), std::string::npos)
        << what;
  }
  EXPECT_LT(peak_rss_kib() - rss_before, 10 * 1024);
  // The same case with more memory than it needs passes the check.
  MemoryLimit plenty("1e12");
  EXPECT_NO_THROW(check_memory(c));
}

// Beyond what 32-bit indices address the case is refused even when the memory is unknown, and
// absurd sizes (1e308 m at 1e-300 m cells: an infinite count) do not overflow on the way.
TEST(Memory, CountsBeyondIndexRangeAreRefusedWithoutAMemoryLimit) {
  MemoryLimit none(nullptr);
  Case c = test::rectangle_case(32, 64, 0.9375e-3);
  c.bodies[0].cell_size = 1e-9;  // 1.8e15 cells
  EXPECT_THROW(check_memory(c), InputError);
  c.bodies[0].shape.width = 1e308;
  c.bodies[0].cell_size = 1e-300;
  try {
    check_memory(c);
    FAIL() << "an infinite cell count passed the check";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("32-bit indices"), std::string::npos) << e.what();
  }
}

// Through the CLI: exit code 2 and the message on stderr, for `check` and `run` alike.
TEST(Memory, CliRefusesAnOversizedCaseWithCode2) {
  const std::string plate = std::string(FRACTA_SOURCE_DIR) + "/cases/plate_fe.toml";
  for (const std::string command : {"check", "run -o /dev/null"}) {
    const std::string line = std::string("FRACTA_MEMORY_LIMIT_BYTES=4e9 ") + FRACTA_EXE + " " +
                             command + " " + plate +
                             " --set body.plate.cell_size=5e-6 2>&1 >/dev/null";
    FILE* p = popen(line.c_str(), "r");
    std::string err;
    char buf[4096];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, p)) > 0) err.append(buf, n);
    const int status = pclose(p);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 2) << command << ": " << err;
    EXPECT_NE(err.find("plate_fe.toml:"), std::string::npos) << err;
    EXPECT_NE(err.find(": body['plate'].cell_size: the case needs about"), std::string::npos)
        << err;
    EXPECT_NE(err.find("only 4 GB is available"), std::string::npos) << err;
  }
}

TEST(Memory, MalformedLimitIsAnInputError) {
  MemoryLimit bad("lots");
  EXPECT_THROW(available_memory_bytes(), InputError);
}

// Sanitizers add shadow memory and quarantines to the resident set: the comparison with the
// estimate is only meaningful (and only compiled) in an uninstrumented build.
#if defined(__SANITIZE_ADDRESS__)
#define FRACTA_RSS_IS_MEANINGFUL 0
#else
#define FRACTA_RSS_IS_MEANINGFUL 1
#endif

#if FRACTA_RSS_IS_MEANINGFUL
// Peak RSS (KiB) of `fracta run CASE` in a child process, from wait4's rusage.
long child_peak_rss_kib(const std::string& case_path, const std::string& output) {
  std::vector<std::string> args{FRACTA_EXE, "run", case_path, "-o", output};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  EXPECT_EQ(posix_spawn(&pid, FRACTA_EXE, &actions, nullptr, argv.data(), environ), 0);
  posix_spawn_file_actions_destroy(&actions);
  int status = 0;
  rusage u{};
  wait4(pid, &status, 0, &u);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << case_path;
  return u.ru_maxrss;
}

// A 30 x 60 mm plate of square cells of `cell` m, a few steps, FE or bonded discs.
std::string plate_case(const fs::path& dir, const std::string& method, double cell) {
  const fs::path path = dir / (method + "_" + std::to_string(cell) + ".toml");
  std::ofstream(path) << "[simulation]\nend_time = 4e-9\ndt = 1e-9\n"
                      << "[[material]]\nname = \"steel\"\nmodel = \"elastic\"\n"
                      << "density = 7800.0\nyoungs_modulus = 200e9\npoisson_ratio = 0.2\n"
                      << "[[body]]\nname = \"plate\"\nmaterial = \"steel\"\nmethod = \"" << method
                      << "\"\ncell_size = " << cell << "\n"
                      << "shape = { type = \"rectangle\", x = 0.0, y = 0.0, width = 0.03, "
                         "height = 0.06 }\n";
  return path.string();
}

// The estimate against the measured peak RSS of real runs (initialisation, model, a few steps,
// two output frames) at two sizes, for an FE body and a bonded-disc body. Measured (g++ 12
// Release, OpenMP, 2 threads): see MEASURED below. The estimate must be at least the measured
// peak (a case that is let through must fit) and at most 1.2 times it (a case that would fit
// with room to spare must not be refused).
TEST(Memory, EstimateBoundsTheMeasuredPeakRss) {
  const fs::path dir = fs::temp_directory_path() / "fracta_memory_test";
  fs::create_directories(dir);
  // An adaptive body that does not convert (4 steps at rest) peaks at MemoryEstimate::bytes,
  // its lattice state not yet used.
  for (const char* method : {"fe", "de", "adaptive"})
    for (double cell : {2e-4, 1e-4}) {  // 45 000 and 180 000 cells
      const std::string path = plate_case(dir, method, cell);
      const double measured = 1024.0 * child_peak_rss_kib(path, (dir / "out.h5").string());
      const double estimate = estimate_memory(load_case(path)).bytes;
      std::printf("[ memory ] %s, cell %g m: estimate %.1f MB, measured peak %.1f MB, ratio %.2f\n",
                  method, cell, estimate / 1e6, measured / 1e6, estimate / measured);
      EXPECT_GE(estimate, measured) << method << " " << cell;
      EXPECT_LE(estimate, 1.2 * measured) << method << " " << cell;
    }
  fs::remove_all(dir);
}

// Memory for an adaptive body's start but not for all of it converted: the run starts, with a
// note of the share of its cells that can convert (the estimate's arithmetic: exact).
TEST(Memory, AdaptiveBodyThatFitsOnlyAtItsStartGetsANote) {
  const fs::path dir = fs::temp_directory_path() / "fracta_memory_note_test";
  fs::create_directories(dir);
  const Case c = load_case(plate_case(dir, "adaptive", 2e-4));
  const MemoryEstimate e = estimate_memory(c);
  ASSERT_GT(e.bytes_all_converted, 1.5 * e.bytes);
  const double limit = 0.5 * (e.bytes + e.bytes_all_converted);  // half of the cells can convert
  MemoryLimit memory_limit(std::to_string(limit).c_str());
  const Model m = build_model(c);
  std::string memory_note;
  for (const std::string& note : m.notes)
    if (note.rfind("memory:", 0) == 0) memory_note = note;
  EXPECT_NE(memory_note.find("about 50 % of them can"), std::string::npos) << memory_note;
  fs::remove_all(dir);
}
#endif  // FRACTA_RSS_IS_MEANINGFUL

}  // namespace
}  // namespace fracta
