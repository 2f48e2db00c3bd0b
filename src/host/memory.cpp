#include "host/memory.hpp"

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#if defined(__GLIBC__)
#include <malloc.h>
#endif
#if defined(__linux__)
#include <sys/mman.h>
#include <unistd.h>
#endif

#include "host/mesh.hpp"

namespace fracta {

namespace {

bool convertible(BodyMethod m) {
  return m == BodyMethod::de || m == BodyMethod::adaptive;
}

bool body_has_lattice(const Body& b) {
  bool lattice = convertible(b.method);
  for (const Region& r : b.regions) lattice = lattice || convertible(r.method);
  return lattice;
}

// Bytes per item of a model, counted from the views and host arrays that build_model and a run
// allocate (src/host/model.cpp, src/kernels/state.hpp), plus two measured terms for what is not
// itemised (the run's host buffers: output frames, history, mirrors; transient copies while the
// model is built). Calibrated on the peak RSS of `fracta run` (g++ 12 Release, OpenMP, 2
// threads; a 30 x 60 mm plate, 45 000 and 180 000 cells, a few steps, two output frames):
//   fe: measured 43.3 / 109.6 MB (21 MB + 491 B per cell);
//   de: measured 70.5 / 213.8 MB (23 MB + 1060 B per cell);
//   adaptive (before it converts): 51.1 / 135.1 MB (23 MB + 622 B per cell).
// Repeated runs of one case peak up to 6 % apart (fe 122-128 MB, adaptive 173-183 MB when it
// held its slots' topology from the start): the estimate is set to about 1.1 times the middle
// of that spread, 1.05-1.15 times each run.
// tests/host/test_memory.cpp re-measures and requires 1 <= estimate / measured <= 1.2.
constexpr double kBaseBytes = 22e6;  // Kokkos, HDF5, the executable: 22 MB measured
// Node: x0, x, v, f, f_ext (10 doubles), mass, fixed on the device; the node-id grid and
// output/history buffers of a run. (The host mesh's copy is freed before the run's peak.)
constexpr double kNodeBytes = 80 + 8 + 4 + 4 + 24;
// Element: 4 nodes, material, body, active, alive; the last hourglass force and four work
// tallies; output buffers.
constexpr double kElementBytes = 32 + 48 + 24;
// The stiffness hourglass form's generalized displacement and its snapshot row (none for the
// viscous form).
constexpr double kStiffnessHourglassBytes = 2 * 16;
// Quadrature point: stress (4), epeq, volume, bulk viscosity.
constexpr double kQuadraturePointBytes = 56;
// Not itemised, per cell of any body: the failure snapshot's rows (positions, velocities,
// forces; the external forces and supports only where loads, bars or supports act:
// state_view_constant) and the run's buffers (measured 491 B per cell in all, 282 B itemised
// above; the rest, with the margin that keeps the estimate about 1.1 times the measured peak).
constexpr double kRunBytesPerCell = 265;
// Nodes of any model with a lattice (a convertible body, or several bodies in contact): the
// particle views (flags, radius, inertia, rotation, spin, moment, contact stiffness), topology
// offsets, the stable-step cache (stale flag, bound), and the host lists build_lattice fills on
// the way (node -> bonds, node -> elements).
constexpr double kLatticeNodeBytes = 56 + 8 + 12 + 2 * 56;
// Elements of any model with a lattice: element bond slots, cell stress, intact flag, strain
// offset, conversion workspace.
constexpr double kLatticeElementBytes = 88;
// Cells of a convertible body: about 4 bond slots each (2 edges, 2 diagonals) of 108 B on the
// device, the topology's node -> element list, build_lattice's host slot arrays and edge map,
// and the part not itemised (measured 1200 B per cell beyond the FE part, 1030 B itemised, when
// a node -> slot list and each slot's kind were held too: 40 B per cell that the de plate's
// measured peak no longer holds, left in as margin).
// Cohesive state (damage, onset and final separation) adds 24 B per slot.
constexpr double kConvertibleCellBytes = 4 * (108 + 24) + 32 + 16 + 232 + 350;
// The part of the terms above that a cell of an adaptive body takes only once it has converted
// (sparse_zero_view.hpp; the lean snapshot, snapshot.cpp): its four slots' state
// (material, state, kn, ks, area, fn, fs, plastic and cohesive state, rest length, used-list
// entry: 112 B each) and their rows in the failure snapshot, the cell's lattice state and its
// snapshot rows (60 + 60 B), its corners' rotation and spin: 1090 B itemised. Measured 1190 B:
// peak RSS of the 30 x 60 mm plate at 0.1 mm cells, 402 MB as de against 188 MB as an adaptive
// body that does not convert, when a de body still held what a converted adaptive cell holds
// (the FE state, every slot's rows in the snapshot; now it does not: kAllDeCellSavingBytes).
constexpr double kConvertedCellBytes = 1190;
// What a scene whose bodies are all de (nothing converts, no element is integrated) does not
// hold, per cell: the FE state (model.cpp: the quadrature points' and hourglass views are empty,
// 40 B + 56 B a point); in the failure snapshot, what only a conversion writes (state_views.hpp,
// state_view_constant: each slot's kn, ks, area, material, used entry, plastic elongation and
// rest length, 4 x 48 B; the cell's strain offset (and the view itself) and list entries, 60 B;
// its nodes' particle flags, list entries, radii, 20 B); the rest-length view, which is the
// reference length's without yielding (4 x 8 B): 400 B itemised at one point. Measured: the de
// plate above peaks at 1335 B per cell where the terms above give 2300 B; the estimate subtracts
// 848 B, the part beyond the itemised one (the run's unitemised buffers, smaller for a lattice
// without FE state) taken as measured, so that it stays about 1.08 times the measured peak.
constexpr double kFeStateCellBytes = 40;
constexpr double kAllDeCellSavingBytes = 848 - 96;  // besides the FE state (40 + 56 B)
// The part of the terms above that a cell of an adaptive body takes only once it has converted,
// beyond its start: its slots' topology (ends, cells, reference length: 4 x 24 B, written at
// conversion: fill_slot_topology) and what the adaptive plate's peak before it converts (724 B
// per cell) leaves of the other terms, the estimate kept about 1.1 times the measured peak.
constexpr double kAdaptiveStartSavingBytes = 316;
// Weibull strengths: a factor per slot and the smallest per cell (heterogeneity.hpp).
constexpr double kWeibullCellBytes = 4 * 8 + 8;
// Law state of every quadrature point when a material keeps one (hjc, johnson_cook: 3 doubles),
// in the state
// and its snapshot.
constexpr double kLawStatePointBytes = 2 * 24;
// Rate dependence: the filtered velocity of every node, in the state and its snapshot.
constexpr double kRateNodeBytes = 2 * 16;
// Contact discs (every node of a convertible body, the boundary nodes of the others): disc id,
// position at the last build, binning, candidate pairs; the gather's columns (8 B; its rows
// are the list's row offsets) and, per candidate pair (about 2 per disc of a lattice: the edge
// neighbours), its disc index, column entry and stored force (40 B); the work space of an
// insertion (ContactSystem::Insertion: the old list's copy, positions, maps, 64 B per disc and
// 16 B per pair).
constexpr double kDiscBytes = 56 + 8 + 64 + 2 * (40 + 16);
// What a disc of a lattice holds only once its bonds break: the contact list leaves joined
// pairs out (neighbor_search.hpp), so an intact lattice lists no pair and never writes its
// discs' contact forces (the force now and the last one, 2 x 24 B; sparse views). Counted in
// the all-converted figure (a lattice broken everywhere: its free pairs, 2 x 56 B of
// kDiscBytes, and forces), not in the start of a body that starts as a lattice (de). Measured
// on the de plate above: 1226 B per cell before, 1060 B after (70.5 / 213.8 MB).
constexpr double kFreeDiscBytes = 2 * (40 + 16) + 2 * 24;

// Axisymmetric lattices (rings): each convertible cell's hoop state (Elements::cell_hoop, 32 B)
// and volumetric strain (8 B), both in the failure snapshot's rows once it converts, and each of
// its nodes' flag for the push-only support on the axis (SupportDofs::axis_ring, 4 B).
constexpr double kRingCellBytes = 2 * (32 + 8);
constexpr double kRingNodeBytes = 4;

// Indices are 32-bit ints (node ids, element ids, 4 bond slots per cell): keep well below.
constexpr double kMaxCells = INT_MAX / 8.0;

}  // namespace

BodyGrid body_grid(const Body& b) {
  const auto bb = shape_bounds(b.shape);
  const double w = bb[2] - bb[0], h = bb[3] - bb[1];
  BodyGrid g;
  // The same rounding as build_mesh (lround of the ratio), in doubles so that nothing overflows.
  g.nx = std::round(w / b.cell_size);
  g.ny = std::round(h / b.cell_size);
  if (!(g.nx >= 1) || !(g.ny >= 1)) g.nx = g.ny = 0;  // build_mesh reports "smaller than a cell"
  return g;
}

MemoryEstimate estimate_memory(const Case& c) {
  MemoryEstimate e;
  const bool lattice =
      c.bodies.size() > 1 || std::any_of(c.bodies.begin(), c.bodies.end(), body_has_lattice);
  const int qp = c.sim.integration == Integration::full ? 4 : 1;
  // Allocated for every point of the mesh when any material keeps a state (model.cpp).
  const bool law_state = std::any_of(c.materials.begin(), c.materials.end(),
                                     [](const Material& m) { return m.keeps_law_state(); });
  // Every body de: no element is integrated and nothing converts (model.cpp, state_views.hpp).
  const bool all_de = std::all_of(c.bodies.begin(), c.bodies.end(), [](const Body& b) {
    return b.method == BodyMethod::de &&
           std::all_of(b.regions.begin(), b.regions.end(),
                       [](const Region& r) { return r.method == BodyMethod::de; });
  });
  double largest = -1;
  for (size_t i = 0; i < c.bodies.size(); ++i) {
    const BodyGrid g = body_grid(c.bodies[i]);
    const double cells = g.cells(), nodes = g.nodes();
    double bytes = nodes * kNodeBytes +
                   cells * (kElementBytes + qp * kQuadraturePointBytes + kRunBytesPerCell);
    if (law_state) bytes += cells * qp * kLawStatePointBytes;
    if (c.sim.hourglass == HourglassForm::stiffness) bytes += cells * kStiffnessHourglassBytes;
    if (all_de)
      bytes -= cells * (kFeStateCellBytes + qp * kQuadraturePointBytes + kAllDeCellSavingBytes +
                        (law_state ? qp * kLawStatePointBytes : 0.0));
    if (lattice) bytes += nodes * kLatticeNodeBytes + cells * kLatticeElementBytes;
    if (body_has_lattice(c.bodies[i])) {
      bytes += cells * kConvertibleCellBytes + nodes * kDiscBytes;
      const int material = c.bodies[i].material_index;
      if (material >= 0 && c.materials[material].random_strength())
        bytes += cells * kWeibullCellBytes;
      if (material >= 0 && !c.materials[material].rate_dependence.strain_rate.empty())
        bytes += nodes * kRateNodeBytes;
      if (c.sim.formulation == Formulation::axisymmetric)
        bytes += cells * kRingCellBytes + nodes * kRingNodeBytes;
    } else if (lattice)
      bytes += 2 * (g.nx + g.ny) * kDiscBytes;  // boundary nodes
    e.cells += cells;
    e.nodes += nodes;
    e.bytes_all_converted += bytes;
    // An adaptive body starts as FE: its cells' lattice state comes as they convert (a de
    // body's, and a de region's, is there from the start: counted as converted).
    if (c.bodies[i].method == BodyMethod::adaptive)
      bytes -= cells * (kConvertedCellBytes + kAdaptiveStartSavingBytes);
    else if (body_has_lattice(c.bodies[i]))
      bytes -= nodes * kFreeDiscBytes;  // an intact lattice: no free pair yet
    e.bytes += bytes;
    if (bytes > largest) {
      largest = bytes;
      e.largest_body = static_cast<int>(i);
    }
  }
  e.bytes += kBaseBytes;
  e.bytes_all_converted += kBaseBytes;
  return e;
}

double available_memory_bytes() {
  if (const char* env = std::getenv("FRACTA_MEMORY_LIMIT_BYTES")) {
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(env, &end);
    if (end == env || *end != '\0' || errno != 0 || !(v > 0) || !std::isfinite(v))
      throw InputError("environment", 0, "FRACTA_MEMORY_LIMIT_BYTES",
                       std::string("must be a positive number of bytes (got '") + env + "')");
    return v;
  }
  std::ifstream in("/proc/meminfo");
  std::string line;
  while (std::getline(in, line)) {
    double kib = 0;
    if (std::sscanf(line.c_str(), "MemAvailable: %lf kB", &kib) == 1) return kib * 1024.0;
  }
  return -1;
}

void zero_lazily(void* data, size_t bytes) {
  char* const begin = static_cast<char*>(data);
  char* const end = begin + bytes;
#if defined(__linux__)
  const long page_size = sysconf(_SC_PAGESIZE);
  if (page_size > 0 && bytes > 0) {
    const uintptr_t page = static_cast<uintptr_t>(page_size);
    char* const first = begin + (page - reinterpret_cast<uintptr_t>(begin) % page) % page;
    char* const last = end - reinterpret_cast<uintptr_t>(end) % page;
    // The whole pages: no huge pages (one written row would cost 2 MiB), and handed back, so that
    // each is a zero page until first written (private anonymous memory, as every heap and
    // malloc block is: madvise(2), MADV_DONTNEED).
    if (first < last) {
      madvise(first, static_cast<size_t>(last - first), MADV_NOHUGEPAGE);  // advice only
      if (madvise(first, static_cast<size_t>(last - first), MADV_DONTNEED) == 0) {
        std::memset(begin, 0, static_cast<size_t>(first - begin));
        std::memset(last, 0, static_cast<size_t>(end - last));
        return;
      }
    }
  }
#endif
  std::memset(begin, 0, bytes);
}

void keep_large_blocks_mapped() {
#if defined(__GLIBC__)
  mallopt(M_MMAP_THRESHOLD, 1 << 20);  // a fixed threshold also stops the dynamic one
#endif
}

std::string format_bytes(double bytes) {
  char buf[64];
  if (bytes >= 1e9)
    std::snprintf(buf, sizeof buf, "%.3g GB", bytes / 1e9);
  else
    std::snprintf(buf, sizeof buf, "%.3g MB", bytes / 1e6);
  return buf;
}

void check_memory(const Case& c) {
  const MemoryEstimate e = estimate_memory(c);
  if (e.largest_body < 0) return;
  const Body& body = c.bodies[e.largest_body];
  const BodyGrid g = body_grid(body);
  std::ostringstream grid;
  grid.precision(3);
  grid << "this body: " << g.nx << " x " << g.ny << " cells of " << body.cell_size << " m";
  const std::string key = "body['" + body.name + "'].cell_size";
  if (!std::isfinite(e.bytes) || e.cells > kMaxCells) {
    std::ostringstream msg;
    msg.precision(3);
    msg << "the case asks for " << e.cells << " cells (" << grid.str() << "), more than the "
        << kMaxCells << " the mesh's 32-bit indices allow; make cell_size larger";
    throw InputError(body.pos.file, body.pos.line, key, msg.str());
  }
  const double available = available_memory_bytes();
  if (available > 0 && e.bytes > available) {
    std::ostringstream msg;
    msg.precision(3);
    msg << "the case needs about " << format_bytes(e.bytes) << " of memory (" << e.cells
        << " cells, " << e.nodes << " nodes; " << grid.str() << ") but only "
        << format_bytes(available) << " is available ("
        << (std::getenv("FRACTA_MEMORY_LIMIT_BYTES") ? "FRACTA_MEMORY_LIMIT_BYTES"
                                                     : "MemAvailable in /proc/meminfo")
        << "); make cell_size larger";
    throw InputError(body.pos.file, body.pos.line, key, msg.str());
  }
}

}  // namespace fracta
