// fracta command line: run | check | info (README.md, docs/output.md for the exit codes).
// Exit codes: 0 success, 2 bad input, 3 numerical failure (after writing the last good state),
// 4 I/O error (a full disk, an unwritable path: nothing written before is lost), 5 internal
// error (after writing the last good state), 6 the Kokkos back end could not start (no usable
// GPU, a driver older than the CUDA runtime), 130 / 143 stopped by SIGINT / SIGTERM (after
// writing a checkpoint and a final frame).
#include <unistd.h>
#include <CLI/CLI.hpp>
#include <Kokkos_Core.hpp>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "host/case.hpp"
#include "host/io_error.hpp"
#include "host/memory.hpp"
#include "host/mesh.hpp"
#include "host/model.hpp"
#include "host/simulation.hpp"

namespace {

void print_info() {
  std::printf("fracta %s\n", FRACTA_VERSION);
  std::printf("Kokkos %d.%d.%d, execution space %s, concurrency %d\n", KOKKOS_VERSION / 10000,
              (KOKKOS_VERSION / 100) % 100, KOKKOS_VERSION % 100, fracta::ExecSpace::name(),
              fracta::ExecSpace().concurrency());
#ifdef FRACTA_DEVICE_PATH
  std::printf("code path: device (atomic scatter, one lane per item, LayoutLeft views)\n");
#else
  std::printf("code path: host (scatter by chunk colours, SIMD lanes)\n");
#endif
}

int check_case(const fracta::Case& c) {
  using namespace fracta;
  const HostMesh mesh = build_mesh(c);
  const int qp = c.sim.integration == Integration::full ? 4 : 1;
  const MemoryEstimate memory = estimate_memory(c);  // what build_mesh checked against
  Simulation sim(c);  // validates what the mesh alone cannot (lattice range, stable dt, ...)
  const HistoryRecord h = sim.history();
  const Model& m = sim.model();
  std::printf("case %s: %s\n", c.path.c_str(), c.sim.title.c_str());
  if (c.sim.formulation == Formulation::axisymmetric)
    std::printf(
        "  axisymmetric (x = radius; masses, forces and energies of the full revolution), "
        "end time %g s\n",
        c.sim.end_time);
  else
    std::printf("  %s, thickness %g m, end time %g s\n", to_string(c.sim.formulation),
                c.sim.thickness, c.sim.end_time);
  for (const Material& mat : c.materials)
    std::printf("  material %-12s %-12s rho %g kg/m^3, E %g Pa, nu %g\n", mat.name.c_str(),
                to_string(mat.model), mat.density, mat.youngs_modulus, mat.poisson_ratio);
  for (size_t b = 0; b < c.bodies.size(); ++b) {
    const BodyRange& r = mesh.bodies[b];
    std::printf("  body %-12s %-9s material %-10s %d nodes, %d cells of %.4g x %.4g mm\n",
                c.bodies[b].name.c_str(), to_string(c.bodies[b].method),
                c.bodies[b].material.c_str(), r.node_end - r.node_begin,
                r.element_end - r.element_begin, r.cell_x * 1e3, r.cell_y * 1e3);
  }
  std::printf("  FE: %ld active elements, %s integration%s, bulk viscosity %g/%g\n",
              h.count.elements, qp == 1 ? "one-point" : "2x2 Gauss",
              qp == 1
                  ? (c.sim.hourglass == HourglassForm::viscous ? ", viscous hourglass control"
                                                               : ", stiffness hourglass control")
                  : "",
              c.sim.bulk_viscosity_linear, c.sim.bulk_viscosity_quadratic);
  if (m.contacts)
    std::printf(
        "  DE: %ld discs, %ld active bonds of %d slots; contact on %d discs "
        "(stiffness factor %g, damping ratio %g, friction %g)\n",
        h.count.particles, h.count.bonds, m.bonds.count, m.contacts->disc_count(),
        c.contact.stiffness_factor, c.contact.damping_ratio, c.contact.friction);
  else
    std::printf("  DE: none (no de body): no bonds, no contact search\n");
  for (const std::string& note : m.notes) std::printf("  note: %s\n", note.c_str());
  std::printf("  loads %zu, boundary sets %zu, probes %zu, body probes %zu\n", c.loads.size(),
              c.boundaries.size(), c.probes.size(), c.body_probes.size());
  if (memory.bytes_all_converted > 1.001 * memory.bytes)
    std::printf(
        "  memory estimate %s (peak of a run; up to %s if every cell of the adaptive bodies "
        "converts)\n",
        format_bytes(memory.bytes).c_str(), format_bytes(memory.bytes_all_converted).c_str());
  else
    std::printf("  memory estimate %s (peak of a run)\n", format_bytes(memory.bytes).c_str());
  std::printf("  stable dt bound %.4g s; dt %.4g s (%s); about %.0f steps\n", sim.stable_dt_bound(),
              sim.dt(), c.sim.dt > 0 ? "fixed" : "dt_safety x bound",
              c.sim.end_time / std::max(sim.dt(), 1e-300));
  std::printf("  output %s, fields:", c.output.file.c_str());
  for (const auto& f : c.output.fields) std::printf(" %s", f.c_str());
  std::printf("\n");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  // Kokkos 3.4 prints a warning on stdout unless the OpenMP binding is set: set a good default.
  setenv("OMP_PROC_BIND", "spread", 0);
  setenv("OMP_PLACES", "threads", 0);
  // A file-size limit (ulimit -f) makes a write fail with EFBIG, an I/O error the run reports,
  // instead of killing the process.
  std::signal(SIGXFSZ, SIG_IGN);
  // Kokkos reads its own options (--kokkos-threads=N, ...) but also answers a bare --help
  // with its option list: it gets neither --help nor -h, so `fracta --help` is fracta's help,
  // and the command line parser gets every argument but the --kokkos-* ones.
  std::vector<char*> kokkos_args, cli_args;
  for (int i = 0; i < argc; ++i) {
    const std::string arg = argv[i];
    if (i == 0 || (arg != "--help" && arg != "-h")) kokkos_args.push_back(argv[i]);
    if (i == 0 || arg.rfind("--kokkos-", 0) != 0) cli_args.push_back(argv[i]);
  }
  int kokkos_argc = static_cast<int>(kokkos_args.size());
  kokkos_args.push_back(nullptr);
  // Kokkos throws when it cannot start: a bad --kokkos-* option (bad input, exit 2) or a device
  // it cannot use (exit 6), e.g. a CUDA build on a machine without a GPU or with an old driver.
  std::optional<Kokkos::ScopeGuard> kokkos;
  try {
    kokkos.emplace(kokkos_argc, kokkos_args.data());
  } catch (const std::exception& e) {
    const std::string what = e.what();
    if (dynamic_cast<const std::invalid_argument*>(&e) != nullptr ||
        what.find("command line argument") != std::string::npos) {
      std::fprintf(stderr, "fracta: error: a --kokkos-* option was refused: %s\n", e.what());
      return 2;
    }
    std::fprintf(stderr, "fracta: the Kokkos back end (%s) could not start: %s\n",
                 fracta::ExecSpace::name(), e.what());
    return 6;
  }
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]) == "--kokkos-help") return 0;  // Kokkos printed its options

  CLI::App app{"fracta: 2D adaptive FE-DE impact dynamics"};
  app.footer(
      "Threads: OMP_NUM_THREADS=N or --kokkos-threads=N; --kokkos-help lists Kokkos' "
      "options.\nExit codes: 0 done, 2 bad input, 3 numerical failure, 4 I/O error (full disk, "
      "unwritable path), 5 internal error, 6 the Kokkos back end could not start (no usable "
      "GPU), 130 / 143 stopped by SIGINT / SIGTERM.\nReference: "
      "README.md and docs/.");
  app.require_subcommand(1);
  std::string case_path, output_path, restart_path;
  std::vector<std::string> overrides;
  auto* run = app.add_subcommand("run", "run a case and write HDF5 (+ XDMF) output");
  run->footer(
      "Checkpoints: [output] checkpoint_interval = T (s) writes the complete state to "
      "OUT.ckpt.h5 every T of simulated time and at the end (replaced atomically).\n"
      "SIGINT (Ctrl-C) / SIGTERM: stop after the current step, write a checkpoint and a final "
      "frame, exit 130 / 143.\nExit codes: 0 done, 2 bad input, 3 numerical failure, 4 I/O error, "
      "5 internal error, 6 the Kokkos back end could not start.");
  run->add_option("case", case_path, "case file (TOML)")->required();
  run->add_option("-o,--output", output_path, "output file (default: the case's output.file)");
  run->add_option("--restart", restart_path,
                  "continue from a checkpoint (OUT.ckpt.h5); the case may change only end_time, "
                  "output_interval, history_interval, title and [output]. Writes a new output "
                  "(-o, else OUT.restart.h5), never the interrupted run's");
  run->add_option("--set", overrides, "override a case value: section.key=value")->take_all();
  auto* check = app.add_subcommand("check", "validate a case and print what will be modelled");
  check->add_option("case", case_path, "case file (TOML)")->required();
  check->add_option("--set", overrides, "override a case value: section.key=value")->take_all();
  app.add_subcommand("info", "print version, Kokkos backend and thread count");

  try {
    app.parse(static_cast<int>(cli_args.size()), cli_args.data());
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }

  try {
    if (app.got_subcommand("info")) {
      print_info();
      return 0;
    }
    const fracta::Case c = fracta::load_case(case_path, overrides);
    if (app.got_subcommand("check")) return check_case(c);
    fracta::RunOptions opt;
    opt.output_path = output_path;
    opt.restart_path = restart_path;
    opt.progress_on_terminal = isatty(STDOUT_FILENO);
    return fracta::run_case(c, opt);
  } catch (const fracta::InputError& e) {
    std::fprintf(stderr, "fracta: error: %s\n", e.what());
    return 2;
  } catch (const fracta::IoError& e) {
    std::fprintf(stderr, "fracta: I/O error: %s\n", e.what());
    return 4;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fracta: internal error: %s\n", e.what());
    return 5;
  }
}
