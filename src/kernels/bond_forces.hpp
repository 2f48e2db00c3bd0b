// Bond forces of the bonded disc lattice (DESIGN.md 1.2; paper Eqs. 5, 6 and 8-10 corrected).
// One kernel over the bond slots: active bonds compute their normal and shear spring forces,
// check Mohr-Coulomb failure with tension cut-off, and add what they apply to their two discs
// (kernels/scatter.hpp: no atomics on CPUs, and a fixed summation order).
#pragma once
#include "kernels/compat.hpp"
#include "kernels/conversion.hpp"
#include "kernels/simd.hpp"
#include "kernels/state.hpp"

namespace fracta {

// Per-material bond parameters (plain data, copied into the kernel by value).
struct BondLaw {
  double youngs_modulus_eff = 0;  // E in plane stress, E / (1 - nu^2) in plane strain (Pa)
  double yield_stress = 0;        // bilinear springs (Pa); 0 = elastic bonds
  double hardening = 0;           // H of the bilinear law (Pa per unit bond plastic strain)
  double tensile_strength = 0;    // Pa; 0 = no tensile failure
  double cohesion = 0;            // Pa; 0 = no shear failure
  double tan_friction = 0;        // tan(phi)
  // Cohesive softening: G_f (J/m^2); 0 = brittle (the bond breaks at its strength). A bond
  // that reached its strength then dissipates G_f times the crack area it stands for,
  // A_b = kn L0 crack_area_factor[kind] (m^2): kn L0 / E for an edge bond and
  // kn L0 (1 - nu) / (2 sqrt(2) E) for a diagonal (plane-strain E*, nu*). These are the shares
  // of the face h t a straight crack along a lattice line cuts, in proportion to the energy
  // each bond holds under uniaxial tension normal to that face (per row: one edge bond, k1,
  // 1 / (1 + nu); two diagonals, k2, nu / (2 (1 + nu)) each), so such a crack dissipates G_f
  // per unit area exactly (tested). kn is the bond's own stiffness, so a boundary edge with
  // one cell carries half.
  double fracture_energy = 0;
  double crack_area_factor[2] = {0, 0};  // per BondKind (m^2 per (N/m) per m)
};

struct BondStepResult {
  double fracture_energy = 0;  // elastic energy of the bonds that broke this step (J)
  double plastic_work = 0;     // plastic work of the bonds this step (J)
  long broken = 0;             // bonds broken this step
};

// One-dimensional elastoplastic spring with linear isotropic hardening (paper Eq. 5 with
// elastic unloading): force = k (u - u_p), |force| <= f_y + k_h * alpha. Returns the plastic work.
KOKKOS_INLINE_FUNCTION double bilinear_spring(double k, double u, double f_yield, double k_hard,
                                              double& u_plastic, double& alpha, double& force) {
  force = k * (u - u_plastic);
  if (f_yield <= 0.0) return 0.0;
  const double limit = f_yield + k_hard * alpha;
  const double excess = fabs_(force) - limit;
  if (excess <= 0.0) return 0.0;
  const double dgamma = excess / (k + k_hard);
  const double sign = force > 0.0 ? 1.0 : -1.0;
  u_plastic += sign * dgamma;
  alpha += dgamma;
  force -= sign * k * dgamma;
  return fabs_(force) * dgamma;  // the dissipation of the return (backward Euler)
}

// Continuum stress of each converted cell from its 4 discs: deformation gradient F at the cell
// centre (reference one-point gradients), Green-Lagrange strain E = (F^T F - I)/2 (rotation
// invariant, so fragments may spin) less the cell's offset at conversion (its strain beyond the
// elastic part then), and the lattice's own elastic law S = C : E (the C the bonds reproduce). A
// cell with a broken or softening bond is no longer a continuum (Elements::cell_cracked, set by
// the bond kernel): it is marked cracked.
//
// An intact cell whose stress is below the strength on every face by a bound is marked
// kCellBelowStrength (with bound_faces), and the bond kernel's batches skip the failure check of
// bonds whose intact cells are all so marked: their check could not find a bond at its strength.
// The bound, from the Mohr circle (centre C, radius R) of the cell stress: on every face
// sigma_n <= C + R, and tau + sigma_n tan(phi) <= C tan(phi) + R sqrt(1 + tan(phi)^2) (the
// tangent to the circle); both are convex in the stress, so they hold for the mean of a bond's
// two cells too. A margin of 1e-9 of the terms' size keeps rounding out of the decision.
// (A bond's law is its cells' law: both cells of a bond belong to one body, of one material.)
//
// A work item is a batch of kLanes positions of the cell list (simd.hpp: 8 on CPUs, 1 on GPUs).
// Eight consecutive cells of one material along one row of a structured mesh run as one cell of
// type Double8: their corners, strain offsets and stresses move by vector loads and stores
// (load_pairs, load_triples, store_triples) instead of 8 scalar gathers per corner; any other
// batch (row ends, irregular meshes, mixed materials, an unsorted list) runs cell by cell.
struct CellStress {
  View<int*> cells;
  int count = 0;
  View<const LatticeStiffness*> stiffness;
  View<const BondLaw*> laws;
  Elements elements;
  Nodes nodes;
  bool bound_faces = true;
  bool row_batches = true;  // false: cell by cell (tests)

  static int batches(int cell_count) { return (cell_count + kLanes - 1) / kLanes; }

  // The cell stress S = C : (E - offset) of L cells of one material, and whether each is below
  // its strength on every face (the bound above; all false without bound_faces).
  template <class T>
  KOKKOS_INLINE_FUNCTION auto stress_of(const T (&x0)[4], const T (&y0)[4], const T (&x)[4],
                                        const T (&y)[4], const T (&offset)[3], int material,
                                        T (&stress)[3]) const {
    T ux[4], uy[4], green[3];
    for (int a = 0; a < 4; ++a) {
      ux[a] = x[a] - x0[a];
      uy[a] = y[a] - y0[a];
    }
    green_lagrange(x0, y0, ux, uy, green);
    const T exx = green[0] - offset[0];
    const T eyy = green[1] - offset[1];
    const T exy = green[2] - offset[2];
    const LatticeStiffness s = stiffness(material);
    const double c = s.youngs_modulus_eff / (1.0 - s.poisson_ratio_eff * s.poisson_ratio_eff);
    const T sxx = c * (exx + s.poisson_ratio_eff * eyy);
    const T syy = c * (eyy + s.poisson_ratio_eff * exx);
    const T sxy = s.youngs_modulus_eff / (1.0 + s.poisson_ratio_eff) * exy;
    stress[0] = sxx;
    stress[1] = syy;
    stress[2] = sxy;
    auto below = !all_lanes<T>();
    if (!bound_faces) return below;
    const BondLaw& law = laws(material);
    const T centre = 0.5 * (sxx + syy);
    const T radius = sqrt_(0.25 * (sxx - syy) * (sxx - syy) + sxy * sxy);
    constexpr double margin = 1e-9;
    below = all_lanes<T>();
    if (law.tensile_strength > 0.0)
      below = centre + radius + margin * (fabs_(centre) + radius + law.tensile_strength) <
              law.tensile_strength;
    if (law.cohesion > 0.0) {
      const double secant = sqrt_(1.0 + law.tan_friction * law.tan_friction);
      const T shear = centre * law.tan_friction + radius * secant;
      below = below &&
              shear + margin * (fabs_(centre * law.tan_friction) + radius * secant + law.cohesion) <
                  law.cohesion;
    }
    return below;
  }

  // Cracked once one of its bonds broke or started to soften (BondForces marks it then): bonds
  // never heal, so the mark is for good.
  KOKKOS_INLINE_FUNCTION int state_of(const int e, const bool below) const {
    if (elements.cell_cracked(e)) return kCellCracked;
    return below ? kCellBelowStrength : kCellIntact;
  }

  KOKKOS_INLINE_FUNCTION void cell(const int e) const {
    double x0[4], y0[4], x[4], y[4];
    for (int a = 0; a < 4; ++a) {
      const int n = elements.nodes(e, a);
      x0[a] = nodes.x0(n, 0);
      y0[a] = nodes.x0(n, 1);
      x[a] = nodes.x(n, 0);
      y[a] = nodes.x(n, 1);
    }
    const double offset[3] = {elements.cell_strain_offset(e, 0), elements.cell_strain_offset(e, 1),
                              elements.cell_strain_offset(e, 2)};
    double stress[3];
    const bool below = stress_of(x0, y0, x, y, offset, elements.material(e), stress);
    for (int k = 0; k < 3; ++k) elements.cell_stress(e, k) = stress[k];
    elements.cell_state(e) = state_of(e, below);
  }

#ifdef FRACTA_HOST_SIMD
  // Cells e0 .. e0 + 7 (consecutive, one material, along one row): as one Double8 cell.
  void row_batch(const int e0, const int (&node)[4][8]) const {
    Double8 x0[4], y0[4], x[4], y[4], offset[3], stress[3];
    for (int a = 0; a < 4; ++a) {
      load_pairs(&nodes.x0(0, 0) + 2 * node[a][0], x0[a], y0[a]);
      load_pairs(&nodes.x(0, 0) + 2 * node[a][0], x[a], y[a]);
    }
    load_triples(&elements.cell_strain_offset(e0, 0), offset[0], offset[1], offset[2]);
    const Mask8 below = stress_of(x0, y0, x, y, offset, elements.material(e0), stress);
    store_triples(&elements.cell_stress(e0, 0), stress[0], stress[1], stress[2]);
    for (int l = 0; l < 8; ++l) elements.cell_state(e0 + l) = state_of(e0 + l, below[l] != 0);
  }
#endif

  KOKKOS_INLINE_FUNCTION void operator()(const int batch_index) const {
    const int first = batch_index * kLanes;
#ifdef FRACTA_HOST_SIMD
    // Row batches need the interleaved (LayoutRight) node and cell arrays of the CPU build.
    if (row_batches && first + kLanes <= count && nodes.x.stride_0() == 2 &&
        nodes.x0.stride_0() == 2 && elements.cell_stress.stride_0() == 3 &&
        elements.cell_strain_offset.stride_0() == 3) {
      int node[4][8];
      bool row = true;
      const int e0 = cells(first);
      const int material = elements.material(e0);
      for (int l = 0; l < 8 && row; ++l) {
        const int e = cells(first + l);
        row = e == e0 + l && elements.material(e) == material;
        for (int a = 0; a < 4; ++a) node[a][l] = elements.nodes(e, a);
      }
      if (row && structured_row<8>(node)) {
        row_batch(e0, node);
        return;
      }
    }
#endif
    const int last = min_(first + kLanes, count);
    for (int k = first; k < last; ++k) cell(cells(k));
  }
};

inline void compute_cell_stress(const View<int*>& cells, int count,
                                const View<const LatticeStiffness*>& stiffness,
                                const View<const BondLaw*>& laws, const Elements& elements,
                                const Nodes& nodes, bool bound_faces = true,
                                bool row_batches = true) {
  if (count == 0) return;
  const CellStress kernel{cells, count, stiffness, laws, elements, nodes, bound_faces, row_batches};
  Kokkos::parallel_for("fracta::cell_stress",
                       Kokkos::RangePolicy<ExecSpace>(0, CellStress::batches(count)), kernel);
}

// Cohesive bonds (BondLaw::fracture_energy > 0). Effective separation of a bond from its
// undamaged spring forces: |(<u_n>, u_s)| with u = f / k (compression does not open a crack).
KOKKOS_INLINE_FUNCTION double effective_separation(double fn, double fs, double kn, double ks) {
  const double un = fn > 0.0 && kn > 0.0 ? fn / kn : 0.0;
  const double us = ks > 0.0 ? fs / ks : 0.0;
  return sqrt_(un * un + us * us);
}

// Energy a bond stores with applied forces fn, fs at damage D (J): the secant springs
// (1 - D) k carry the tension and the shear; compression is carried undamaged.
KOKKOS_INLINE_FUNCTION double stored_bond_energy(double fn, double fs, double damage, double kn,
                                                 double ks) {
  double e = 0.0;
  if (kn > 0.0) e += 0.5 * fn * fn / (fn > 0.0 ? (1.0 - damage) * kn : kn);
  if (ks > 0.0 && damage < 1.0) e += 0.5 * fs * fs / ((1.0 - damage) * ks);
  return e;
}

// Trapezoidal work of the discs on a bond over a step (J): normal forces fn_old -> fn_new over
// the change of the elastic elongation, from fn_old (at damage D_old) to the undamaged force
// fn_trial of this step; shear forces fs_old -> fs_new over the shear increment. Elastic
// bonds only: cohesive materials are elastic up to their strength.
KOKKOS_INLINE_FUNCTION double bond_work(double fn_old, double fn_new, double fs_old, double fs_new,
                                        double fn_trial, double damage_old, double kn,
                                        double shear_increment) {
  double w = 0.5 * (fs_old + fs_new) * shear_increment;
  if (kn > 0.0) {
    const double u_old = fn_old / (fn_old > 0.0 ? (1.0 - damage_old) * kn : kn);
    w += 0.5 * (fn_old + fn_new) * (fn_trial / kn - u_old);
  }
  return w;
}

// How the CPU bond kernel groups bonds (BondForces::chunk): SIMD batches that load runs of
// slots as whole vectors where they can (the default), SIMD batches that gather every lane, or
// bond by bond (tests compare the three).
enum class BondBatches { runs, gathered, none };

struct BondForces {
  Nodes nodes;
  Elements elements;
  Bonds bonds;
  View<const BondLaw*> laws;
  double dt;
  // The list positions to slots (Bonds::used) when the kernel sweeps that list; empty: every slot.
  View<int*> list;
  // Forces added straight into nodes.f and nodes.moment (kernels/scatter.hpp), atomically when
  // the bonds do not run by the chunks of a ScatterPlan (GPUs).
  bool atomic = true;
  BondBatches batches = BondBatches::runs;  // CPU grouping (chunk())

  KOKKOS_INLINE_FUNCTION int slot(const int k) const { return list.extent(0) > 0 ? list(k) : k; }

  // Atomic path: work item = one list position.
  KOKKOS_INLINE_FUNCTION void operator()(const int k, Sums<3>& acc) const { bond(slot(k), acc); }

  // Chunk path: the list positions [begin, end), in order; on CPUs by batches of kLanes bonds
  // where a batch qualifies (elastic_batch), else bond by bond.
  KOKKOS_INLINE_FUNCTION void chunk(const int begin, const int end, Sums<3>& acc) const {
    int k = begin;
#ifdef FRACTA_HOST_SIMD
    if (batches != BondBatches::none) {
      RunLanes carried;
      while (k + kLanes <= end) k += batch(k, carried, acc);
    }
#endif
    for (; k < end; ++k) bond(slot(k), acc);
#ifdef FRACTA_HOST_SIMD
    stream_fence();  // the batches' streamed stores are seen before the chunk counts as done
#endif
  }

#ifdef FRACTA_HOST_SIMD
  // The first lane of a run batch: its slot, ends and cells (-1: none on that side); lane l has
  // slot + l, i + l, j + l and each cell + l (Bonds::run_next).
  struct RunLanes {
    int slot = -1;
    int i = 0, j = 0;
    int cell[2] = {-1, -1};
  };

  // The bonds from list position k: a batch of kLanes, or the bonds before the start of a run.
  // Returns how many it did. A run is a stretch of consecutive slots whose ends and cells all
  // advance by one per slot (Bonds::run_next; build_lattice orders the slots so): a batch inside
  // one loads and adds the node data as whole vectors, and reads none of its slots' ends, cells
  // or materials (the first lane's are carried on from the run's previous batch: `carried`). A
  // window that holds the start of a run (one or two breaks) goes bond by bond up to it, so the
  // batches that follow line up with the run; a window with more breaks (an irregular mesh) is
  // one batch with its data gathered lane by lane.
  int batch(const int k, RunLanes& carried, Sums<3>& acc) const {
    constexpr int L = kLanes;
    const int b0 = slot(k);
    // The list increases: consecutive slots, whose ends and cells the batches load as (i, j) rows.
    if (slot(k + L - 1) != b0 + L - 1 || bonds.nodes.stride_0() != 2 ||
        bonds.cells.stride_0() != 2) {
      for (int l = 0; l < L; ++l) bond(slot(k + l), acc);
      return L;
    }
    if (batches == BondBatches::runs && bonds.run_next.extent(0) > 0) {
      // Byte l: Bonds::run_next of slot b0 + l (b0 + 7 < count: k + L <= end); its bit
      // kRunContinues: whether slot b0 + l + 1 continues slot b0 + l.
      unsigned long long next;
      static_assert(sizeof(next) == L, "one byte per lane");
      __builtin_memcpy(&next, bonds.run_next.data() + b0, sizeof(next));
      constexpr unsigned long long kContinues = 0x0101010101010101ull * kRunContinues;
      constexpr unsigned long long kWithinBatch = 0x00ffffffffffffffull;
      if ((next & kContinues & kWithinBatch) == (kContinues & kWithinBatch)) {
        RunLanes lanes = carried;
        if (lanes.slot != b0) {
          // A run's first batch starts at a multiple of kLanes (bond by bond up to it), so that
          // the batches load and store whole cache lines of the bond arrays.
          if (b0 % L != 0) {
            for (int l = 0; l < L - b0 % L; ++l) bond(b0 + l, acc);
            return L - b0 % L;
          }
          lanes = {
              b0, bonds.nodes(b0, 0), bonds.nodes(b0, 1), {bonds.cells(b0, 0), bonds.cells(b0, 1)}};
        }
        const bool done = (next & kRunNormalOnly) ? elastic_batch<true, false>(b0, lanes)
                                                  : elastic_batch<true, true>(b0, lanes);
        if (!done)
          for (int l = 0; l < L; ++l) bond(b0 + l, acc);
        carried = RunLanes{};
        if ((next >> 56) & kRunContinues) {  // the run goes on into the next batch
          carried = {b0 + L, lanes.i + L, lanes.j + L, {lanes.cell[0], lanes.cell[1]}};
          for (int& c : carried.cell)
            if (c >= 0) c += L;
        }
        return L;
      }
      unsigned breaks = 0;  // lane l starts a new run
      for (int l = 1; l < L; ++l)
        if (((next >> (8 * (l - 1))) & kRunContinues) == 0) breaks |= 1u << l;
      if (__builtin_popcount(breaks) <= 2) {
        const int run_start = 31 - __builtin_clz(breaks);
        for (int l = 0; l < run_start; ++l) bond(b0 + l, acc);
        return run_start;
      }
    }
    if (!elastic_batch<false, true>(b0, RunLanes{}))
      for (int l = 0; l < L; ++l) bond(b0 + l, acc);
    return L;
  }

  // Eight bonds at once in SIMD lanes (simd.hpp), the common case of a lattice at work: the
  // consecutive active slots b0 .. b0 + 7 of one material with elastic springs (no yield stress),
  // none softening (onset 0, so damage 0) and none reaching its strength this step. kRun: the
  // slots are the run of `run` (batch()), so the node data of each end and the cell data of each
  // side move as vectors, and the law is the one of the run's cells (a bond's material is the one
  // of the cell that activated it: activate_element_bonds). !kShear: the run's slots are diagonals,
  // which have no shear spring (ks = 0 and fs = 0 always: activate_element_bonds and
  // prestress_converted_bonds give shear only to edges), so the batch reads no velocities, spins,
  // radii, ks or fs, and adds no moments: bond() adds l fs = 0 there. The arithmetic is bond()'s on
  // that path, lane by lane, in the same order, and the adds to each node come in bond()'s order
  // (an end j of an earlier lane before the end i of a later one: the j ends are added first). If
  // the batch does not qualify, or a lane reaches its strength, it returns false before writing
  // anything, and the caller runs bond() for each (rare: a bond breaks or starts to soften once).
  template <bool kRun, bool kShear>
  bool elastic_batch(const int b0, const RunLanes& run) const {
    static_assert(kRun || kShear, "gathered batches take the general path");
    using T = Double8;
    constexpr int L = 8;
    const int material =
        kRun ? elements.material(run.cell[0] >= 0 ? run.cell[0] : run.cell[1]) : bonds.material(b0);
    if (!all_set(load_ints8(bonds.state.data() + b0) == static_cast<int>(kBondActive)) ||
        (!kRun && !all_set(load_ints8(bonds.material.data() + b0) == material)))
      return false;
    const BondLaw& law = laws(material);
    if (law.yield_stress > 0.0) return false;
    const bool cohesive = law.fracture_energy > 0.0;
    int i[L], j[L], b[L];
    for (int l = 0; l < L; ++l) b[l] = b0 + l;
    if (cohesive && any_lane(load_lanes<T>(bonds.onset_separation.data(), b, true) != 0.0))
      return false;
    for (int l = 0; l < L; ++l) {
      i[l] = kRun ? run.i + l : bonds.nodes(b0 + l, 0);
      j[l] = kRun ? run.j + l : bonds.nodes(b0 + l, 1);
    }
    // Node data of the ends: (x, y) pairs of the [n][2] views and the per-node columns.
    const auto pair = [&](const View<double* [2]>& a, const int(&n)[L], T& ax, T& ay) {
      if (kRun && a.stride_0() == 2) {
        load_pairs(&a(n[0], 0), ax, ay);
      } else {
        const int stride = static_cast<int>(a.stride_0());
        ax = gather_lanes<T>(&a(0, 0), n, stride);
        ay = gather_lanes<T>(&a(0, 1), n, stride);
      }
    };
    const auto column = [&](const View<double*>& a, const int(&n)[L]) {
      return kRun ? load_lanes<T>(a.data(), n, true) : gather_lanes<T>(a.data(), n, 1);
    };
    T xi, yi, xj, yj;
    pair(nodes.x, i, xi, yi);
    pair(nodes.x, j, xj, yj);
    const T dx = xj - xi, dy = yj - yi;
    const T length = sqrt_(dx * dx + dy * dy);
    const T inverse_length = 1.0 / length;
    const T nx = dx * inverse_length, ny = dy * inverse_length;
    const T kn = load_lanes<T>(bonds.kn.data(), b, true);
    // bond()'s elastic spring: the natural length L0 + u_p as one value (Bonds::rest_length).
    T fn = kn * (length - load_lanes<T>(bonds.rest_length.data(), b, true));
    T fs = splat<T>(0.0), li = fs, lj = fs;
    if constexpr (kShear) {
      const T ri = column(nodes.radius, i);
      const T rj = column(nodes.radius, j);
      const T length_share = length / (ri + rj);
      li = length_share * ri;
      lj = length_share * rj;
      const T ks = load_lanes<T>(bonds.ks.data(), b, true);
      const T fs_old = load_lanes<T>(bonds.fs.data(), b, true);
      T vxi, vyi, vxj, vyj;
      pair(nodes.v, i, vxi, vyi);
      pair(nodes.v, j, vxj, vyj);
      const T dvt = -(vxj - vxi) * ny + (vyj - vyi) * nx -
                    (li * column(nodes.spin, i) + lj * column(nodes.spin, j));
      const T shear_increment = dvt * dt;
      fs = ks > 0.0 ? fs_old + ks * shear_increment : splat<T>(0.0);  // bond() with D = 0
    }
    // The failure check: skipped where every lane has an intact cell and all its intact cells
    // are below their strength on every face (compute_cell_stress), else as bond() does it.
    Int8 side_cells[2];
    if (kRun) {
      for (int side = 0; side < 2; ++side)
        side_cells[side] =
            run.cell[side] >= 0 ? run.cell[side] + Int8{0, 1, 2, 3, 4, 5, 6, 7} : Int8{} - 1;
    } else {
      const Int16 cell_pairs = load_ints16(&bonds.cells(b0, 0));  // stride_0 2, as the ends
      side_cells[0] = even_lanes(cell_pairs);
      side_cells[1] = odd_lanes(cell_pairs);
    }
    Int8 cell_state[2];
    bool advancing[2];
    for (int side = 0; side < 2; ++side) {
      const Int8 cv = side_cells[side];
      advancing[side] = kRun && cv[0] >= 0;
      if (advancing[side]) {
        cell_state[side] = load_ints8(&elements.cell_state(cv[0]));
      } else if (kRun) {  // no cell on this side of the run (a diagonal's second, a boundary's)
        cell_state[side] = Int8{} + int{kCellCracked};
      } else {
        for (int l = 0; l < L; ++l)
          cell_state[side][l] = cv[l] < 0 ? kCellCracked : elements.cell_state(cv[l]);
      }
    }
    const Int8 cracked = Int8{} + int{kCellCracked}, intact_only = Int8{} + int{kCellIntact},
               below = Int8{} + int{kCellBelowStrength};
    if (!all_set((cell_state[0] == below || cell_state[1] == below) &&
                 (cell_state[0] != intact_only) && (cell_state[1] != intact_only))) {
      // The face traction from the intact cells around each bond (bond(): the same sum in the
      // same order), or the bond's own stresses without one.
      T s3[3] = {splat<T>(0.0), splat<T>(0.0), splat<T>(0.0)};
      T cells = splat<T>(0.0);
      for (int side = 0; side < 2; ++side) {
        const Int8 cv = side_cells[side];
        if (all_set(cell_state[side] == cracked)) continue;
        const Mask8 intact = widen(cell_state[side] != cracked);
        T st[3] = {splat<T>(0.0), splat<T>(0.0), splat<T>(0.0)};
        if (advancing[side] && elements.cell_stress.stride_0() == 3) {
          load_triples(&elements.cell_stress(cv[0], 0), st[0], st[1], st[2]);
        } else {
          for (int l = 0; l < L; ++l)
            for (int q = 0; q < 3; ++q)
              st[q][l] = cell_state[side][l] != kCellCracked ? elements.cell_stress(cv[l], q) : 0.0;
        }
        for (int q = 0; q < 3; ++q) s3[q] += intact ? st[q] : splat<T>(0.0);
        cells += intact ? splat<T>(1.0) : splat<T>(0.0);
      }
      T x0i, y0i, x0j, y0j;
      pair(nodes.x0, i, x0i, y0i);
      pair(nodes.x0, j, x0j, y0j);
      const T ux = x0j - x0i, uy = y0j - y0i;
      const T inverse_L0 = 1.0 / load_lanes<T>(bonds.length0.data(), b, true);
      const T n0x = ux * inverse_L0, n0y = uy * inverse_L0;
      const T mean = cells > 1.0 ? splat<T>(0.5) : splat<T>(1.0);
      const T sxx = s3[0] * mean, syy = s3[1] * mean, sxy = s3[2] * mean;
      const T sigma_cells = sxx * n0x * n0x + syy * n0y * n0y + 2.0 * sxy * n0x * n0y;
      const T t_cells = -(sxx * n0x + sxy * n0y) * n0y + (sxy * n0x + syy * n0y) * n0x;
      const T tau_cells = t_cells < 0.0 ? -t_cells : t_cells;
      T sigma_n = sigma_cells, tau = tau_cells;
      if (any_lane(cells == 0.0)) {  // the bond's own stresses (a fragment's edge): rare
        const T area = load_lanes<T>(bonds.area.data(), b, true);
        const T abs_fs = fs < 0.0 ? -fs : fs;
        sigma_n = cells > 0.0 ? sigma_cells : (area > 0.0 ? fn / area : splat<T>(0.0));
        tau = cells > 0.0 ? tau_cells : (area > 0.0 ? abs_fs / area : splat<T>(0.0));
      }
      auto reaches = !all_lanes<T>();
      if (law.tensile_strength > 0.0) reaches = reaches || sigma_n >= law.tensile_strength;
      if (law.cohesion > 0.0) reaches = reaches || tau >= law.cohesion - sigma_n * law.tan_friction;
      if (any_lane(reaches)) return false;
    }
    // fn is only written here (the next step reads it): past the caches, saving the line's read.
    stream_lanes(fn, bonds.fn.data() + b0);
    if constexpr (kShear) store_lanes(fs, bonds.fs.data(), b, true);
    const T fx = fn * nx - fs * ny, fy = fn * ny + fs * nx;
    const T mi = li * fs, mj = lj * fs;
    if (kRun && nodes.f.stride_0() == 2) {
      // The j ends first: bond()'s order where the two ranges overlap (j = i + d, 0 < d < 8).
      add_pairs(&nodes.f(j[0], 0), -fx, -fy);
      if constexpr (kShear) add_lanes(mj, nodes.moment.data(), j, true);
      add_pairs(&nodes.f(i[0], 0), fx, fy);
      if constexpr (kShear) add_lanes(mi, nodes.moment.data(), i, true);
      return true;
    }
    for (int l = 0; l < L; ++l) {
      nodes.f(i[l], 0) += fx[l];
      nodes.f(i[l], 1) += fy[l];
      nodes.moment(i[l]) += mi[l];
      nodes.f(j[l], 0) -= fx[l];
      nodes.f(j[l], 1) -= fy[l];
      nodes.moment(j[l]) += mj[l];
    }
    return true;
  }
#endif

  // A bond broke or started to soften: its cells are no longer a continuum, from the next cell
  // stress on (compute_cell_stress; this sweep reads cell_state only). Every writer writes 1.
  KOKKOS_INLINE_FUNCTION void mark_cells_cracked(const int b) const {
    for (int k = 0; k < 2; ++k) {
      const int c = bonds.cells(b, k);
      if (c >= 0) elements.cell_cracked(c) = 1;
    }
  }

  KOKKOS_INLINE_FUNCTION void bond(const int b, Sums<3>& acc) const {
    if (bonds.state(b) != kBondActive) return;
    const int i = bonds.nodes(b, 0), j = bonds.nodes(b, 1);
    const double dx = nodes.x(j, 0) - nodes.x(i, 0), dy = nodes.x(j, 1) - nodes.x(i, 1);
    const double length = sqrt_(dx * dx + dy * dy);
    // Reciprocals, then products: divisions are the slowest arithmetic of the kernel (the SIMD
    // batch, which must give the same numbers, has three per bond).
    const double inverse_length = 1.0 / length;
    const double nx = dx * inverse_length, ny = dy * inverse_length;  // n; t = (-ny, nx)
    // Lever arms to the contact point, which splits the current length in the ratio of the
    // radii: then the moments l_i fs + l_j fs = L fs balance the couple of the shear forces
    // exactly (angular momentum is conserved whatever the stretch).
    const double ri = nodes.radius(i), rj = nodes.radius(j);
    const double length_share = length / (ri + rj);
    const double li = length_share * ri, lj = length_share * rj;
    const BondLaw& law = laws(bonds.material(b));
    const double kn = bonds.kn(b), ks = bonds.ks(b), area = bonds.area(b), L0 = bonds.length0(b);
    // Bilinear parameters in force units: yield force = yield stress * S, hardening modulus
    // in force per unit plastic displacement H S / L0.
    const double fy_n = law.yield_stress * area;
    const double fy_s = law.yield_stress * area / 1.7320508075688772;  // von Mises shear yield
    const double k_hard = law.hardening * area / L0;
    // Elastic springs (yield_stress 0) never change their plastic state (which a conversion may
    // have set: the cell's strain beyond its elastic part): read what the forces need, write
    // nothing back (a sixth of the bytes a bond moves per step).
    const bool plastic_law = law.yield_stress > 0.0;
    double up = plastic_law ? bonds.plastic_n(b) : 0.0,
           us_p = plastic_law ? bonds.plastic_s(b) : 0.0;
    double alpha = plastic_law ? bonds.hardening(b) : 0.0;
    // fn, fs: the undamaged spring forces; a softening bond applies (1 - D) of them.
    const bool cohesive = law.fracture_energy > 0.0;
    const double damage_old = cohesive ? bonds.damage(b) : 0.0;
    const double fn_old = bonds.fn(b), fs_old = bonds.fs(b);
    double fn = 0.0, fs = 0.0, plastic = 0.0;
    if (plastic_law)
      plastic += bilinear_spring(kn, length - L0, fy_n, k_hard, up, alpha, fn);
    else
      fn = kn * (length - bonds.rest_length(b));  // L0 + u_p: the spring's natural length
    double shear_increment = 0.0;
    if (ks > 0.0) {
      // Shear displacement increment (paper Eq. 8 corrected): relative tangential velocity
      // of the contact point, with the disc rotations (DESIGN.md 1.2).
      const double dvt = -(nodes.v(j, 0) - nodes.v(i, 0)) * ny +
                         (nodes.v(j, 1) - nodes.v(i, 1)) * nx -
                         (li * nodes.spin(i) + lj * nodes.spin(j));
      // Shear displacement kept as the elastic part fs/ks plus the plastic slip.
      shear_increment = dvt * dt;
      const double fs_undamaged = damage_old > 0.0 ? fs_old / (1.0 - damage_old) : fs_old;
      if (plastic_law) {
        const double us = fs_undamaged / ks + us_p + shear_increment;
        plastic += bilinear_spring(ks, us, fy_s, k_hard, us_p, alpha, fs);
      } else {
        fs = fs_undamaged + ks * shear_increment;  // ks (us - us_p), without the round trip
      }
    }
    // Failure (paper Sec. 2.3 with Eq. 6 corrected; DESIGN.md 1.2): Mohr-Coulomb with tension
    // cut-off on the face the bond stands for: the cell face normal to an edge bond, the
    // diagonal plane for a diagonal bond. Its traction (sigma_n = n.s.n, tension positive;
    // tau = |t.s.n|) comes from the continuum stress of the intact cells around the bond
    // (compute_cell_stress), so uniaxial tension breaks it at sigma_t and a direct shear test
    // at tau = c + sigma tan(phi): a single bond's fn / S cannot see the stress along its face
    // (the Poisson coupling) and would miss the envelope under confinement. With no intact cell
    // left around it (a fragment's edge), the bond's own stresses fn / S and |fs| / S are used.
    double sigma_n, tau;
    {
      double s3[3] = {0, 0, 0};
      int cells = 0;
      for (int k = 0; k < 2; ++k) {
        const int c = bonds.cells(b, k);
        if (c < 0 || elements.cell_state(c) == kCellCracked) continue;
        for (int q = 0; q < 3; ++q) s3[q] += elements.cell_stress(c, q);
        ++cells;
      }
      if (cells > 0) {
        // Reference-frame stress with the reference bond direction (rotation invariant).
        const double ux = nodes.x0(j, 0) - nodes.x0(i, 0), uy = nodes.x0(j, 1) - nodes.x0(i, 1);
        const double inverse_L0 = 1.0 / L0;
        const double n0x = ux * inverse_L0, n0y = uy * inverse_L0;
        const double mean = cells > 1 ? 0.5 : 1.0;  // exactly s3 / cells
        const double sxx = s3[0] * mean, syy = s3[1] * mean, sxy = s3[2] * mean;
        sigma_n = sxx * n0x * n0x + syy * n0y * n0y + 2.0 * sxy * n0x * n0y;
        tau = fabs_(-(sxx * n0x + sxy * n0y) * n0y + (sxy * n0x + syy * n0y) * n0x);
      } else {
        sigma_n = area > 0.0 ? fn / area : 0.0;
        tau = area > 0.0 ? fabs_(fs) / area : 0.0;
      }
    }
    double onset = cohesive ? bonds.onset_separation(b) : 0.0;
    bool breaks = false;
    if (onset == 0.0) {
      const bool tension = law.tensile_strength > 0.0 && sigma_n >= law.tensile_strength;
      const bool shear = law.cohesion > 0.0 && tau >= law.cohesion - sigma_n * law.tan_friction;
      if (tension || shear) {
        // Brittle: the bond breaks at its strength. Cohesive: it starts to soften from the
        // effective separation lambda_0 it has now, and is spent at lambda_f, chosen so that
        // it dissipates its share of G_f: along a proportional path the bilinear law
        // dissipates E_0 lambda_f / lambda_0 (E_0 = what the bond stores at the onset; pure
        // mode I: 1/2 f_0 lambda_f), so lambda_f = G_f A_b lambda_0 / E_0.
        breaks = true;
        if (cohesive) {
          onset = effective_separation(fn, fs, kn, ks);
          const double stored = stored_bond_energy(fn > 0.0 ? fn : 0.0, fs, 0.0, kn, ks);
          const double share = law.fracture_energy * kn * L0 * law.crack_area_factor[bonds.kind(b)];
          const double final_separation = stored > 0.0 ? share * onset / stored : 0.0;
          if (onset > 0.0 && final_separation > onset) {
            breaks = false;
            bonds.onset_separation(b) = onset;
            mark_cells_cracked(b);
            bonds.final_separation(b) = final_separation;
          } else {
            onset = 0.0;
          }
        }
      }
    }
    double damage = damage_old;
    if (onset > 0.0) {
      // Linear softening of the effective traction against the effective separation
      // lambda = |(<u_n>, u_s)| (the elastic displacements of the undamaged springs), from
      // lambda_0 to lambda_f, with irreversible secant damage (the bilinear cohesive law)
      //   D = lambda_f (lambda - lambda_0) / (lambda (lambda_f - lambda_0)).
      const double lambda_f = bonds.final_separation(b);
      const double lambda = effective_separation(fn, fs, kn, ks);
      if (lambda >= lambda_f) {
        breaks = true;
      } else if (lambda > onset) {
        damage = max_(damage, lambda_f * (lambda - onset) / (lambda * (lambda_f - onset)));
      }
    }
    if (breaks) {
      // Released as fracture energy: what the bond held, plus what the discs did on it this
      // step by the trapezoidal rule with the zero force it now applies (for an undamaged
      // bond 1/2 f_old^2/k + 1/2 f_old (f - f_old)/k = 1/2 f_old f / k per spring; counting
      // the trial energy 1/2 f^2/k would over-count by 1/2 f du and unbalance the energy).
      double energy =
          cohesive ? stored_bond_energy(fn_old, fs_old, damage_old, kn, ks) +
                         bond_work(fn_old, 0.0, fs_old, 0.0, fn, damage_old, kn, shear_increment)
                   : (kn > 0.0 ? 0.5 * fn_old * fn / kn : 0.0) +
                         (ks > 0.0 ? 0.5 * fs_old * fs / ks : 0.0);
      // A bond that breaks while its discs overlap hands part of its energy to the contact
      // that takes over at once (1/2 k_c delta^2 with the contact law's series stiffness):
      // that part is not fracture energy, or the balance would count it twice.
      const double overlap = ri + rj - length;
      if (overlap > 0.0) {
        const double kci = nodes.contact_stiffness(i), kcj = nodes.contact_stiffness(j);
        const double kc = kci + kcj > 0.0 ? 2.0 * kci * kcj / (kci + kcj) : 0.0;
        energy -= 0.5 * kc * overlap * overlap;
      }
      bonds.state(b) = kBondBroken;
      if (nodes.bound_stale.extent(0) > 0) nodes.bound_stale(i) = nodes.bound_stale(j) = 1;
      mark_cells_cracked(b);
      bonds.fn(b) = 0.0;
      bonds.fs(b) = 0.0;
      acc.v[0] += energy;
      acc.v[1] += plastic;
      acc.v[2] += 1.0;
      return;
    }
    if (onset > 0.0) {
      // A softening bond: the applied forces, and the energy the softening dissipated this
      // step, the trapezoidal work of the discs on the bond less the change of what it stores
      // (zero for an undamaged spring, so the balance is the elastic one until the onset).
      const double fn_applied = fn > 0.0 ? (1.0 - damage) * fn : fn;
      const double fs_applied = (1.0 - damage) * fs;
      acc.v[0] +=
          bond_work(fn_old, fn_applied, fs_old, fs_applied, fn, damage_old, kn, shear_increment) +
          stored_bond_energy(fn_old, fs_old, damage_old, kn, ks) -
          stored_bond_energy(fn_applied, fs_applied, damage, kn, ks);
      fn = fn_applied;
      fs = fs_applied;
      bonds.damage(b) = damage;
    }
    bonds.fn(b) = fn;
    bonds.fs(b) = fs;
    if (plastic_law) {
      bonds.plastic_n(b) = up;
      bonds.rest_length(b) = L0 + up;
      bonds.plastic_s(b) = us_p;
      bonds.hardening(b) = alpha;
      bonds.plastic_work(b) += plastic;
      acc.v[1] += plastic;
    }
    // Force on i: fn n + fs t; on j the opposite; moments l_i fs and l_j fs (DESIGN.md 1.2).
    const double fx = fn * nx - fs * ny, fy = fn * ny + fs * nx;
    scatter_add(&nodes.f(i, 0), fx, atomic);
    scatter_add(&nodes.f(i, 1), fy, atomic);
    scatter_add(&nodes.moment(i), li * fs, atomic);
    scatter_add(&nodes.f(j, 0), -fx, atomic);
    scatter_add(&nodes.f(j, 1), -fy, atomic);
    scatter_add(&nodes.moment(j), lj * fs, atomic);
  }
};

// The bond list the kernels sweep: Bonds::used when it is a proper subset of the slots, else
// every slot (a list of every slot is the identity).
inline bool bonds_listed(const Bonds& bonds) {
  return bonds.used.extent(0) > 0 && bonds.used_count < bonds.count;
}
inline int bond_list_count(const Bonds& bonds) {
  return bonds_listed(bonds) ? bonds.used_count : bonds.count;
}

// Bond forces added into nodes.f and nodes.moment. The list is increasing, so the order of
// every node's sum is the one of the sweep over all slots. Without a usable bonds.scatter (the
// plan of the list: update_scatter_plan) the forces are added atomically. batches: how the CPU
// kernel groups the bonds (the default everywhere but in tests).
inline BondStepResult compute_bond_forces(const Nodes& nodes, const Elements& elements,
                                          const Bonds& bonds, const View<const BondLaw*>& laws,
                                          double dt, BondBatches batches = BondBatches::runs) {
  BondStepResult r;
  if (bonds.count == 0) return r;
  const int count = bond_list_count(bonds);
  BondForces forces{
      nodes, elements, bonds, laws, dt, bonds_listed(bonds) ? bonds.used : View<int*>(), true};
  forces.batches = batches;
  Sums<3> s;
  if (bonds.scatter.usable(count)) {
    forces.atomic = false;
    s = for_each_chunk<Kokkos::Sum<Sums<3>>>("fracta::bond_forces", bonds.scatter,
                                             std::move(forces));
  } else {
    Kokkos::parallel_reduce("fracta::bond_forces", Kokkos::RangePolicy<ExecSpace>(0, count), forces,
                            Kokkos::Sum<Sums<3>>(s));
  }
  r.fracture_energy = s.v[0];
  r.plastic_work = s.v[1];
  r.broken = static_cast<long>(s.v[2] + 0.5);
  return r;
}

// The scatter plan of the bond slots (kernels/scatter.hpp), cut once from the slots and located
// in the bond list after every change of it. Chunks of up to 8192 slots: about as many discs as
// an element chunk spans nodes (scatter_chunk_size).
inline constexpr int kBondChunkMax = 8192;
inline void update_scatter_plan(Bonds& bonds) {
  const auto list = bonds_listed(bonds) ? bonds.used : View<int*>();
  if (bonds.scatter.universe == bonds.count) {
    locate_scatter_chunks(bonds.scatter, list, bond_list_count(bonds));
    return;
  }
  const auto ends = bonds.nodes;
  build_scatter_plan(
      bonds.scatter, bonds.count,
      KOKKOS_LAMBDA(const int b, int& lo, int& hi) {
        lo = min_(ends(b, 0), ends(b, 1));
        hi = max_(ends(b, 0), ends(b, 1));
      },
      list, bond_list_count(bonds), kBondChunkMax);
}

// Stable step of the bond network (DESIGN.md 1.4): Gershgorin's bound on the largest
// eigenvalue of M^-1/2 K M^-1/2 over translations and rotations, row by row. Each bond adds to
// the rows of its two discs; `contact_allowance` adds that many contacts of the disc's contact
// stiffness to every contact disc (particles and FE boundary nodes). Returns 2 / sqrt(lambda_max)
// (s), or a huge value if no bond.
// What active bond b adds to the rows of its end s (0 or 1).
KOKKOS_INLINE_FUNCTION void gershgorin_terms(const Nodes& nodes, const Bonds& bonds, const int b,
                                             const int s, double& trans, double& rot) {
  const int i = bonds.nodes(b, s), j = bonds.nodes(b, 1 - s);
  const double k = bonds.kn(b) + bonds.ks(b), ks = bonds.ks(b);
  const double mi = nodes.mass(i), mj = nodes.mass(j);
  const double Ii = nodes.inertia(i), Ij = nodes.inertia(j);
  const double ri = nodes.radius(i), rj = nodes.radius(j);
  // |K| entries of a 2D spring pair, row x of disc i: |kn nx^2 + ks tx^2| +
  // |(kn - ks) nx ny| <= (1 + sqrt 2)/2 (kn + ks) towards i and towards j; shear couples
  // the translation to both rotations by r ks |tx| <= r ks; rotations couple by r^2 ks
  // and to translations by r ks (|tx| + |ty|) <= sqrt 2 r ks.
  trans = 1.2071067811865475 * k * (1.0 / mi + 1.0 / sqrt_(mi * mj)) +
          ks * (ri / sqrt_(mi * Ii) + rj / sqrt_(mi * Ij));
  rot = ks * (ri * ri / Ii + ri * rj / sqrt_(Ii * Ij)) +
        1.4142135623730951 * ks * ri * (1.0 / sqrt_(Ii * mi) + 1.0 / sqrt_(Ii * mj));
}

struct GershgorinRows {
  Nodes nodes;
  Bonds bonds;
  View<double* [2]> row;  // translation, rotation

  KOKKOS_INLINE_FUNCTION void operator()(const int b) const {
    if (bonds.state(b) != kBondActive) return;
    for (int s = 0; s < 2; ++s) {
      double trans, rot;
      gershgorin_terms(nodes, bonds, b, s, trans, rot);
      Kokkos::atomic_add(&row(bonds.nodes(b, s), 0), trans);
      Kokkos::atomic_add(&row(bonds.nodes(b, s), 1), rot);
    }
  }
};

// Row bound of node n: its bond rows and the allowance of contacts.
struct GershgorinBound {
  Nodes nodes;
  View<double* [2]> row;
  double allowance;
  KOKKOS_INLINE_FUNCTION double contact(const int n) const {
    // A contact pair adds at most 1.2071 kc (1/m_i + 1/sqrt(m_i m_j)) <= 3.7 kc / m_i
    // (a neighbour of at least a quarter of the mass: a corner node).
    return allowance * 3.7 * nodes.contact_stiffness(n) / nodes.mass(n);
  }
  // The bound of node n from its row sums.
  KOKKOS_INLINE_FUNCTION double bound(const int n, const double trans, const double rot) const {
    return max_(trans, rot) + contact(n);
  }
  KOKKOS_INLINE_FUNCTION void operator()(const int n, double& lmax) const {
    if (!nodes.particle(n) && !nodes.contact_disc(n)) return;
    const double l = bound(n, row(n, 0), row(n, 1));
    lmax = lmax > l ? lmax : l;
  }
};

inline double bond_stable_dt(const Nodes& nodes, const Bonds& bonds, int contact_allowance) {
  if (!nodes.has_particles()) return 1e300;
  View<double* [2]> row("fracta::gershgorin_rows", nodes.count);  // translation, rotation
  if (bonds.count > 0)
    Kokkos::parallel_for("fracta::bond_gershgorin", Kokkos::RangePolicy<ExecSpace>(0, bonds.count),
                         GershgorinRows{nodes, bonds, row});
  double lambda = 0.0;
  Kokkos::parallel_reduce("fracta::bond_stable_dt", Kokkos::RangePolicy<ExecSpace>(0, nodes.count),
                          GershgorinBound{nodes, row, static_cast<double>(contact_allowance)},
                          Kokkos::Max<double>(lambda));
  return lambda > 0.0 ? 2.0 / sqrt_(lambda) : 1e300;
}

// The same bound over the particle list (Nodes::particle_list), each particle gathering its
// rows from its bond slots (Topology::node_bond, in increasing slot order: the order in which
// the sweep's atomic adds arrive on one thread, so the value is the sweep's), in one pass with
// no atomics and no row storage. The ends of active bonds are particles; a contact disc that is
// not a particle has the bound contact(n) alone, and a particle's bound is at least its
// contact(n), so lambda = max(max over contact discs of contact(n), max over particles of
// their bound): the first term is constant and computed once.
// With `cache` set, each particle's bound is kept and recomputed only when Nodes::bound_stale
// flags it (set where a row can change: a bond breaking, mark_converted_rows): between
// conversions few rows change, and a particle's row is the same sum of the same terms, so the
// value is the one of a full pass. invalidate() after the state was replaced (a restore).
// Without `cache`, a `bound` view of nodes.count entries given by the caller receives every
// particle's bound (tests), and the stale flags are left alone.
struct StableDtWorkspace {
  double disc_lambda = 0.0;  // max over contact discs of contact(n)
  int allowance = -1;        // the allowance disc_lambda was computed for (-1: none yet)
  bool cache = false;        // keep per-particle bounds (one workspace per model may)
  bool cached = false;       // `bound` holds every particle's current bound but the stale ones
  View<double*> bound;       // per node, 1/s^2
  void invalidate() { cached = false; }
};

inline double bond_stable_dt(const Nodes& nodes, const Bonds& bonds, const Topology& topology,
                             int contact_allowance, StableDtWorkspace& ws) {
  if (!nodes.has_particles()) return 1e300;
  if (nodes.particle_list.extent(0) == 0 || topology.node_bond_offset.extent(0) == 0)
    return bond_stable_dt(nodes, bonds, contact_allowance);
  const GershgorinBound bound{nodes, {}, static_cast<double>(contact_allowance)};
  if (ws.allowance != contact_allowance) {
    const auto disc = nodes.contact_disc;
    ws.disc_lambda = 0.0;
    Kokkos::parallel_reduce(
        "fracta::disc_stable_dt", Kokkos::RangePolicy<ExecSpace>(0, nodes.count),
        KOKKOS_LAMBDA(const int n, double& lmax) {
          if (!disc(n)) return;
          const double l = bound.contact(n);
          lmax = lmax > l ? lmax : l;
        },
        Kokkos::Max<double>(ws.disc_lambda));
    ws.allowance = contact_allowance;
    ws.cached = false;
  }
  const bool cache = ws.cache && nodes.bound_stale.extent(0) > 0;
  if (cache && ws.bound.extent(0) != static_cast<size_t>(nodes.count)) {
    ws.bound = View<double*>(
        Kokkos::view_alloc(Kokkos::WithoutInitializing, "fracta::particle_stable_bound"),
        nodes.count);
    ws.cached = false;
  }
  const bool all = !cache || !ws.cached;  // recompute every particle
  const bool write_bound = ws.bound.extent(0) == static_cast<size_t>(nodes.count);
  const auto particles = nodes.particle_list;
  const auto offset = topology.node_bond_offset;
  const auto slots = topology.node_bond;
  const auto stale = nodes.bound_stale;
  const auto cached_bound = ws.bound;
  double lambda = 0.0;
  Kokkos::parallel_reduce(
      "fracta::bond_stable_dt", Kokkos::RangePolicy<ExecSpace>(0, nodes.particle_count),
      KOKKOS_LAMBDA(const int k, double& lmax) {
        const int n = particles(k);
        double l;
        if (all || stale(n)) {
          double row_trans = 0.0, row_rot = 0.0;
          for (int q = offset(n); q < offset(n + 1); ++q) {
            const int b = slots(q);
            if (bonds.state(b) != kBondActive) continue;
            double trans, rot;
            gershgorin_terms(nodes, bonds, b, bonds.nodes(b, 0) == n ? 0 : 1, trans, rot);
            row_trans += trans;
            row_rot += rot;
          }
          l = bound.bound(n, row_trans, row_rot);
          if (write_bound) cached_bound(n) = l;
          if (cache) stale(n) = 0;
        } else {
          l = cached_bound(n);
        }
        lmax = lmax > l ? lmax : l;
      },
      Kokkos::Max<double>(lambda));
  ws.cached = cache;
  lambda = lambda > ws.disc_lambda ? lambda : ws.disc_lambda;
  return lambda > 0.0 ? 2.0 / sqrt_(lambda) : 1e300;
}

// Flags the rows a conversion changed (Nodes::bound_stale): every node of the new cells (their
// bonds activate, their radii shrink) and every bond neighbour of those nodes (a row holds the
// other end's radius, mass and inertia).
inline void mark_converted_rows(const View<int*>& cells, int count, const Elements& el,
                                const Nodes& nodes, const Bonds& bonds, const Topology& topology) {
  if (count == 0 || nodes.bound_stale.extent(0) == 0 || topology.node_bond_offset.extent(0) == 0)
    return;
  const auto stale = nodes.bound_stale;
  const auto offset = topology.node_bond_offset;
  const auto slots = topology.node_bond;
  Kokkos::parallel_for(
      "fracta::mark_converted_rows", Kokkos::RangePolicy<ExecSpace>(0, 4 * count),
      KOKKOS_LAMBDA(const int k) {
        const int n = el.nodes(cells(k / 4), k % 4);
        stale(n) = 1;  // every writer writes 1
        for (int q = offset(n); q < offset(n + 1); ++q) {
          const int b = slots(q);
          if (bonds.state(b) != kBondActive) continue;
          stale(bonds.nodes(b, 0) == n ? bonds.nodes(b, 1) : bonds.nodes(b, 0)) = 1;
        }
      });
}

}  // namespace fracta
