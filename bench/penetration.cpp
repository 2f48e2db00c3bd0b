// The project's throughput benchmark: the penetration scene
// (cases/penetration.toml) at refinement level L, for a fixed number of steps, with a per-phase
// time split from the named profiling regions. One level per process, so the peak memory
// (getrusage max RSS) is that level's; bench/run_penetration.sh runs levels 1, 2, 4, 8 with
// OMP_NUM_THREADS=1 and 2 and merges the results into bench/results/penetration.{csv,json}.
//
// Refinement: cell size = base / L for both bodies, base = 0.4 mm by default (the case itself
// uses 1.667 mm, ~1.1e3 nodes). Level 1: 18.6e3 nodes; level 8 (0.05 mm): 1.17e6 nodes.
// Start of the timed window: the projectile is placed `gap` cells above the slab (default 1.02;
// contact discs have radius h/2, so bodies touch at one cell), then `warmup` steps run untimed
// (default 20: about half a cell of penetration at 200 m/s, contact and conversion active at
// every level), then `steps` steps are timed. No restart file is needed.
// Output inside the window follows run_case's cadence: history and probe records every
// history_interval (to an HDF5 file in /tmp, deleted at the end), frames every output_interval
// (none in a short window), the last-good-state snapshot every 100 steps.
//
// Usage: penetration --level L [--steps N] [--warmup W] [--base-cell H] [--gap CELLS]
//                    [--case FILE] [--json FILE] [--kernels N] [--views 1]
// Prints one human-readable line, the memory held in views after the window by entity (nodes,
// elements, lattice cells, bonds, contact, the failure snapshot; allocated and resident, through
// the Kokkos tools' allocation callbacks) and writes one JSON object (to --json or stdout).
// --kernels N also prints the N kernels that took the most time in the window and the launches (by
// kind) and deep copies per step, with and without conversion (stderr): a profiling aid.
// --views 1 also prints every view's label with its allocated and resident bytes (stderr), the
// largest first: where an entity's memory goes.
#include <sys/resource.h>
#include <unistd.h>

#include <Kokkos_Core.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "host/case.hpp"
#include "host/output.hpp"
#include "host/simulation.hpp"
#include "region_timer.hpp"

namespace {

using namespace fracta;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

double peak_rss_mb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss / 1024.0;  // Linux reports kB
}

// Resident memory now (MB), from /proc/self/statm; 0 where it cannot be read.
double rss_now_mb() {
  std::ifstream statm("/proc/self/statm");
  double pages_total = 0, pages_resident = 0;
  if (!(statm >> pages_total >> pages_resident)) return 0.0;
  return pages_resident * static_cast<double>(sysconf(_SC_PAGESIZE)) / (1024.0 * 1024.0);
}

// The entity a view belongs to, from its label: where the state's memory goes.
std::string view_group(const std::string& label) {
  const auto has_prefix = [&](const char* p) { return label.rfind(p, 0) == 0; };
  if (label.size() > 9 && label.compare(label.size() - 9, 9, "_snapshot") == 0) return "snapshot";
  if (has_prefix("fracta::bond_") || has_prefix("fracta::node_bond") ||
      has_prefix("fracta::element_bonds") || has_prefix("fracta::list_"))
    return "bonds";
  if (has_prefix("fracta::cell_")) return "cells";
  if (has_prefix("fracta::contact_")) return "contact";
  if (has_prefix("fracta::node_") || has_prefix("fracta::particle_")) return "nodes";
  if (has_prefix("fracta::element_") || has_prefix("fracta::qp_") ||
      has_prefix("fracta::reference_") || has_prefix("fracta::active_") ||
      has_prefix("fracta::new_cells") || has_prefix("fracta::converted_"))
    return "elements";
  return "other";
}

// Default timed steps per level: small at high levels (level 8 has 1.2e6 nodes).
long default_steps(int level) {
  return level <= 1 ? 200 : level == 2 ? 100 : 30;
}

struct Options {
  int level = 1;
  long steps = -1, warmup = 20;
  double base_cell = 0.4e-3;  // m
  double gap_cells = 1.02;
  std::string case_path = "cases/penetration.toml";  // relative to the repository root
  std::string json_path;
  int kernels = 0;     // print the top kernels of the window
  bool views = false;  // print every view's memory
};

[[noreturn]] void usage(const char* why) {
  std::fprintf(stderr,
               "penetration: %s\nusage: penetration --level L [--steps N] [--warmup W] "
               "[--base-cell H] [--gap CELLS] [--case FILE] [--json FILE] [--kernels N] "
               "[--views 1]\n",
               why);
  std::exit(2);
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (i + 1 >= argc) usage(("missing value after " + a).c_str());
    const char* v = argv[++i];
    if (a == "--level")
      o.level = std::atoi(v);
    else if (a == "--steps")
      o.steps = std::atol(v);
    else if (a == "--warmup")
      o.warmup = std::atol(v);
    else if (a == "--base-cell")
      o.base_cell = std::atof(v);
    else if (a == "--gap")
      o.gap_cells = std::atof(v);
    else if (a == "--case")
      o.case_path = v;
    else if (a == "--json")
      o.json_path = v;
    else if (a == "--kernels")
      o.kernels = std::atoi(v);
    else if (a == "--views")
      o.views = std::atoi(v) != 0;
    else
      usage(("unknown option " + a).c_str());
  }
  if (o.level < 1) usage("--level must be >= 1");
  if (o.steps < 0) o.steps = default_steps(o.level);
  return o;
}

std::string num(double x) {
  char b[64];
  std::snprintf(b, sizeof b, "%.6g", x);
  return b;
}

}  // namespace

int main(int argc, char** argv) {
  setenv("OMP_PROC_BIND", "spread", 0);
  setenv("OMP_PLACES", "threads", 0);
  Kokkos::ScopeGuard kokkos(argc, argv);
  const Options o = parse(argc, argv);
  bench::RegionTimer::install();
  if (o.kernels > 0) bench::KernelTimer::install();
  bench::ViewMemory::install();

  const double h = o.base_cell / o.level;
  std::vector<std::string> set = {"simulation.end_time=1.0"};  // never reached
  const Case probe_case = load_case(o.case_path);
  double slab_top = 0.0;
  for (size_t b = 0; b < probe_case.bodies.size(); ++b) {
    set.push_back("body." + std::to_string(b) + ".cell_size=" + num(h));
    if (probe_case.bodies[b].name == "slab")
      slab_top = probe_case.bodies[b].shape.y + probe_case.bodies[b].shape.height;
  }
  // A polygon has no y to move: its projectile starts where the case puts it (then choose a
  // warm-up that reaches the impact, e.g. --warmup 150 for cases/perforation.toml at level 4).
  for (const Body& b : probe_case.bodies)
    if (b.name == "projectile" && o.gap_cells > 0 && b.shape.type != Shape::Type::polygon)
      set.push_back("body.projectile.shape.y=" + num(slab_top + o.gap_cells * h));
  const Case c = load_case(o.case_path, set);

  const auto t_setup = Clock::now();
  Simulation sim(c);
  const double setup_seconds = seconds_since(t_setup);
  const double rss_after_setup = peak_rss_mb();
  char tmpl[] = "/tmp/fracta_bench_XXXXXX";
  const int fd = mkstemp(tmpl);
  if (fd >= 0) close(fd);
  const std::string out_path = std::string(tmpl) + ".h5";
  const RunInfo info = run_info(c);
  double output_seconds = 0.0;
  {
    OutputFile out(out_path, info, FrameStorage{c.output.single_precision, c.output.compression});
    declare_probes(out, sim);
    const auto record = [&] { record_history(out, sim); };

    for (long s = 0; s < o.warmup && !sim.failed(); ++s) sim.step();
    const HistoryRecord h0 = sim.history();
    const long conversions0 = sim.conversions();
    const auto rebuilds = [&] {
      return sim.model().contacts ? sim.model().contacts->rebuild_count() : 0L;
    };
    const long rebuilds0 = rebuilds();
    const auto insertions = [&] {
      return sim.model().contacts ? sim.model().contacts->insertion_count() : 0L;
    };
    const long insertions0 = insertions();
    bench::RegionTimer::reset();
    bench::KernelTimer::reset();
    const double eps = 1e-12;
    double next_history = sim.time() + c.sim.history_interval;
    double next_frame = sim.time() + (c.sim.output_interval > 0 ? c.sim.output_interval : 1.0);
    const auto t_run = Clock::now();
    long steps = 0;
    // Launch counts of the steps alone (output and snapshots apart), split by whether the step
    // converted elements (--kernels).
    bench::LaunchCounts quiet_counts, converting_counts;
    long quiet_steps = 0, converting_steps = 0;
    for (; steps < o.steps && !sim.failed(); ++steps) {
      const bench::LaunchCounts before = bench::KernelTimer::counts();
      const long conversions_before = sim.conversions();
      sim.step(/*defer_kick=*/true);  // as run_case
      if (o.kernels > 0) {
        const bool converted = sim.conversions() > conversions_before;
        (converted ? converting_counts : quiet_counts) += bench::KernelTimer::counts() - before;
        ++(converted ? converting_steps : quiet_steps);
      }
      const bool history_due = c.sim.history_interval <= 0 || sim.time() >= next_history - eps;
      const bool frame_due = sim.time() >= next_frame - eps;
      const bool snapshot_due = sim.steps() % 100 == 0;
      // The pending half kick is integration, not output (its own profiling region).
      if (history_due || frame_due || snapshot_due) sim.finish_kick();
      const auto t_out = Clock::now();
      if (history_due) {
        record();
        while (c.sim.history_interval > 0 && next_history <= sim.time() + eps)
          next_history += c.sim.history_interval;
      }
      if (frame_due) {
        out.write_frame(sim.frame(c.output.fields));
        next_frame += c.sim.output_interval;
      }
      if (snapshot_due) sim.save_snapshot();
      output_seconds += seconds_since(t_out);
    }
    sim.finish_kick();
    const double run_seconds = seconds_since(t_run);
    // The views held after the window (the last snapshot included), by entity (MB): allocated,
    // and resident in RAM (what the run touched).
    std::map<std::string, double> view_mb, view_resident_mb;
    for (const auto& [label, bytes] : bench::ViewMemory::allocated())
      view_mb[view_group(label)] += bytes / 1e6;
    for (const auto& [label, bytes] : bench::ViewMemory::resident())
      view_resident_mb[view_group(label)] += bytes / 1e6;
    if (o.views) {
      const auto allocated = bench::ViewMemory::allocated();
      const auto resident = bench::ViewMemory::resident();
      std::vector<std::pair<double, std::string>> by_size;
      for (const auto& [label, bytes] : resident) by_size.emplace_back(bytes, label);
      std::sort(by_size.rbegin(), by_size.rend());
      std::fprintf(stderr, "%-44s %12s %12s\n", "view", "allocated MB", "resident MB");
      for (const auto& [bytes, label] : by_size)
        std::fprintf(stderr, "%-44s %12.3f %12.3f\n", label.c_str(), allocated.at(label) / 1e6,
                     bytes / 1e6);
    }
    double view_total_mb = 0, view_resident_total_mb = 0;
    for (const auto& [group, mb] : view_mb) view_total_mb += mb;
    for (const auto& [group, mb] : view_resident_mb) view_resident_total_mb += mb;
    const auto totals = bench::RegionTimer::totals();
    const HistoryRecord h1 = sim.history();
    out.finish(sim.steps(), RunTimes{run_seconds, output_seconds},
               sim.failed() ? "failed" : "completed");

    // Counts: the mean of the window's first and last state (they change with conversion).
    const auto mean = [&](long a, long b) { return 0.5 * static_cast<double>(a + b); };
    const double elements = mean(h0.count.elements, h1.count.elements);
    const double particles = mean(h0.count.particles, h1.count.particles);
    const double bonds = mean(h0.count.bonds, h1.count.bonds);
    const double contacts = mean(h0.count.contacts, h1.count.contacts);
    const double steps_per_s = steps / run_seconds;
    const char* phases[] = {"fracta::fe_forces",      "fracta::bond_forces",
                            "fracta::contact_search", "fracta::contact_forces",
                            "fracta::integrate",      "fracta::conversion"};
    const double step_seconds = bench::RegionTimer::get("fracta::step").seconds;
    double phase_sum = 0.0;
    for (const char* p : phases) phase_sum += bench::RegionTimer::get(p).seconds;

    std::ostringstream js;
    js << "{\"case\": \"" << c.path << "\", \"level\": " << o.level
       << ", \"cell_size_m\": " << num(h) << ", \"threads\": " << ExecSpace().concurrency()
       << ", \"nodes\": " << sim.model().nodes.count << ", \"active_elements\": " << elements
       << ", \"particles\": " << particles << ", \"bonds\": " << bonds
       << ", \"contacts\": " << contacts << ", \"warmup_steps\": " << o.warmup
       << ", \"steps\": " << steps << ", \"dt_s\": " << num(sim.dt())
       << ", \"conversions_in_window\": " << sim.conversions() - conversions0
       << ", \"contact_rebuilds_in_window\": " << rebuilds() - rebuilds0
       << ", \"contact_insertions_in_window\": " << insertions() - insertions0
       << ", \"contact_discs\": " << (sim.model().contacts ? sim.model().contacts->disc_count() : 0)
       << ", \"failed\": " << (sim.failed() ? "true" : "false")
       << ", \"setup_s\": " << num(setup_seconds) << ", \"run_s\": " << num(run_seconds)
       << ", \"steps_per_s\": " << num(steps_per_s)
       << ", \"entity_steps_per_s\": " << num((elements + particles) * steps_per_s)
       << ", \"bond_steps_per_s\": " << num(bonds * steps_per_s)
       << ", \"rss_after_setup_mb\": " << num(rss_after_setup)
       << ", \"peak_rss_mb\": " << num(peak_rss_mb()) << ", \"rss_now_mb\": " << num(rss_now_mb())
       << ", \"view_peak_mb\": " << num(bench::ViewMemory::peak() / 1e6) << ", \"view_mb\": {";
    for (const auto& [group, mb] : view_mb) js << "\"" << group << "\": " << num(mb) << ", ";
    js << "\"total\": " << num(view_total_mb) << "}, \"view_resident_mb\": {";
    for (const auto& [group, mb] : view_resident_mb)
      js << "\"" << group << "\": " << num(mb) << ", ";
    js << "\"total\": " << num(view_resident_total_mb) << "}, \"phase_s\": {";
    for (const char* p : phases)
      js << "\"" << (p + 8) << "\": " << num(bench::RegionTimer::get(p).seconds) << ", ";
    js << "\"output\": " << num(output_seconds)
       << ", \"other\": " << num(std::max(step_seconds - phase_sum, 0.0))
       << "}, \"phase_calls\": {";
    for (const char* p : phases)
      js << "\"" << (p + 8) << "\": " << bench::RegionTimer::get(p).calls << ", ";
    js << "\"step\": " << bench::RegionTimer::get("fracta::step").calls << "}}";
    (void)totals;
    if (o.kernels > 0) {
      std::vector<std::pair<double, std::string>> top;
      for (const auto& [name, t] : bench::KernelTimer::totals()) top.emplace_back(t.seconds, name);
      std::sort(top.rbegin(), top.rend());
      std::fprintf(stderr, "%-48s %10s %8s %10s\n", "kernel", "ms", "calls", "us/call");
      for (size_t k = 0; k < top.size() && k < static_cast<size_t>(o.kernels); ++k) {
        const auto& t = bench::KernelTimer::totals().at(top[k].second);
        std::fprintf(stderr, "%-48s %10.2f %8ld %10.1f\n", top[k].second.c_str(), 1e3 * t.seconds,
                     t.calls, 1e6 * t.seconds / t.calls);
      }
      const auto per_step = [](const char* what, const bench::LaunchCounts& n, long count) {
        if (count == 0) return;
        const double k = 1.0 / count;
        std::fprintf(stderr,
                     "per %s step (%ld): %.1f launches (%.1f for, %.1f reduce of which %.1f into "
                     "slots, %.1f scan), %.1f deep copies; waits for the device: %.1f\n",
                     what, count, k * n.launches(), k * n.fors, k * n.reduces, k * n.slot_reduces,
                     k * n.scans, k * n.deep_copies, k * (n.host_reduces() + n.deep_copies));
      };
      per_step("quiet", quiet_counts, quiet_steps);
      per_step("converting", converting_counts, converting_steps);
    }

    std::fprintf(stderr,
                 "level %d (h = %.4g mm), %d threads: %d nodes, %.0f elements, %.0f particles, "
                 "%.0f bonds, %.0f contacts; setup %.2f s; %ld steps in %.3f s = %.1f steps/s; "
                 "peak RSS %.0f MB\n",
                 o.level, h * 1e3, ExecSpace().concurrency(), sim.model().nodes.count, elements,
                 particles, bonds, contacts, setup_seconds, steps, run_seconds, steps_per_s,
                 peak_rss_mb());
    const double per_node = 1e6 / sim.model().nodes.count;
    std::fprintf(stderr, "views after the window, MB allocated (resident):");
    for (const auto& [group, mb] : view_mb)
      std::fprintf(stderr, " %s %.0f (%.0f),", group.c_str(), mb, view_resident_mb[group]);
    std::fprintf(stderr, " total %.0f (%.0f); per node %.0f (%.0f) B\n", view_total_mb,
                 view_resident_total_mb, per_node * view_total_mb,
                 per_node * view_resident_total_mb);
    if (o.json_path.empty()) {
      std::printf("%s\n", js.str().c_str());
    } else {
      std::ofstream f(o.json_path);
      f << js.str() << "\n";
    }
  }
  std::remove(out_path.c_str());
  std::remove(tmpl);
  const std::string xdmf = std::string(tmpl) + ".xdmf";
  std::remove(xdmf.c_str());
  return sim.failed() ? 3 : 0;
}
