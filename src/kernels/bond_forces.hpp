// Bond forces of the bonded disc lattice (docs/physics.md 1.2; paper Eqs. 5, 6 and 8-10
// corrected). One kernel over the bond slots, gather -> laws -> scatter: active bonds gather
// their discs' motion and their own state, apply the bond laws (laws.hpp: springs, the face
// failure check, cohesive softening), and add what they apply to their two discs
// (kernels/scatter.hpp: no atomics on CPUs, and a fixed summation order). Before it, the cell
// stress kernel gives the continuum stress the failure check reads. The stable step of the
// lattice is in stable_dt.hpp.
#pragma once
#include "kernels/compat.hpp"
#include "kernels/conversion.hpp"
#include "kernels/laws.hpp"
#include "kernels/scatter.hpp"
#include "kernels/simd.hpp"
#include "kernels/stable_dt.hpp"
#include "kernels/state.hpp"

namespace fracta {

struct BondStepResult {
  double fracture_energy = 0;  // elastic energy of the bonds that broke this step (J)
  double plastic_work = 0;     // plastic work of the bonds this step (J)
  long broken = 0;             // bonds broken this step
};

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
// The bound is the bonds' own face check over every face of the cell stress at once, from its
// Mohr circle (FaceStrength::below_on_every_face; docs/physics.md 1.2, "Face failure"). (A
// bond's law is its cells' law: both cells of a bond belong to one body, of one material.)
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
                                        const T& inverse_strength_scale, T (&stress)[3],
                                        const double* hoop_state = nullptr) const {
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
    T sxx = c * (exx + s.poisson_ratio_eff * eyy);
    T syy = c * (eyy + s.poisson_ratio_eff * exx);
    // Rings (one cell, hoop_state its Elements::cell_hoop row): the hoop term's share of the
    // in-plane stress, (lambda / M) sigma_tt on both normal components (HoopLaw: the in-plane
    // derivative of M w^2 / 2).
    if constexpr (LaneCount<T>::value == 1) {
      if (s.hoop.active() && hoop_state != nullptr) {
        double r0 = 0.0, r = 0.0;
        for (int a = 0; a < 4; ++a) {
          r0 += 0.25 * x0[a];
          r += 0.25 * x[a];
        }
        const double w = s.hoop.strain(r, r0, hoop_state[kHoopOffset], exx + eyy);
        const double share =
            s.hoop.lambda / s.hoop.p_wave_modulus * s.hoop.stress(w, hoop_state[kHoopDamage]);
        sxx += share;
        syy += share;
      }
    }
    const T sxy = s.youngs_modulus_eff / (1.0 + s.poisson_ratio_eff) * exy;
    stress[0] = sxx;
    stress[1] = syy;
    stress[2] = sxy;
    if (!bound_faces) return !all_lanes<T>();
    T centre = 0.5 * (sxx + syy);
    T radius = sqrt_(0.25 * (sxx - syy) * (sxx - syy) + sxy * sxy);
    if (elements.cell_inverse_strength_scale.extent(0) > 0) {  // sigma / w below sigma_t
      centre = centre * inverse_strength_scale;
      radius = radius * inverse_strength_scale;
    }
    return laws(material).face().below_on_every_face(centre, radius);
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
    const double offset[3] = {elements.strain_offset(e, 0), elements.strain_offset(e, 1),
                              elements.strain_offset(e, 2)};
    double stress[3];
    const double scale = elements.cell_inverse_strength_scale.extent(0) > 0
                             ? elements.cell_inverse_strength_scale(e)
                             : 1.0;
    double hoop_state[4];
    const bool hoop = elements.cell_hoop.extent(0) > 0;
    if (hoop)
      for (int k = 0; k < 4; ++k) hoop_state[k] = elements.cell_hoop(e, k);
    const bool below = stress_of(x0, y0, x, y, offset, elements.material(e), scale, stress,
                                 hoop ? hoop_state : nullptr);
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
    if (elements.cell_strain_offset.extent(0) > 0)
      load_triples(&elements.cell_strain_offset(e0, 0), offset[0], offset[1], offset[2]);
    else
      offset[0] = offset[1] = offset[2] = splat<Double8>(0.0);
    int cell[8];
    for (int l = 0; l < 8; ++l) cell[l] = e0 + l;
    const Double8 scale =
        elements.cell_inverse_strength_scale.extent(0) > 0
            ? load_lanes<Double8, 8>(elements.cell_inverse_strength_scale.data(), cell, true)
            : splat<Double8>(1.0);
    const Mask8 below = stress_of(x0, y0, x, y, offset, elements.material(e0), scale, stress);
    store_triples(&elements.cell_stress(e0, 0), stress[0], stress[1], stress[2]);
    for (int l = 0; l < 8; ++l) elements.cell_state(e0 + l) = state_of(e0 + l, below[l] != 0);
  }
#endif

  KOKKOS_INLINE_FUNCTION void operator()(const int batch_index) const {
    const int first = batch_index * kLanes;
#ifdef FRACTA_HOST_SIMD
    // Row batches need the interleaved (LayoutRight) node and cell arrays of the CPU build.
    // (Not rings: their hoop term's share is added cell by cell.)
    if (row_batches && elements.cell_hoop.extent(0) == 0 && first + kLanes <= count &&
        nodes.x.stride_0() == 2 && nodes.x0.stride_0() == 2 &&
        elements.cell_stress.stride_0() == 3 &&
        (elements.cell_strain_offset.extent(0) == 0 ||
         elements.cell_strain_offset.stride_0() == 3)) {
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

// How the CPU bond kernel groups bonds (BondForces::chunk): SIMD batches that load runs of
// slots as whole vectors where they can (the default), SIMD batches that gather every lane, or
// bond by bond (tests compare the three).
enum class BondBatches { runs, gathered, none };

// The bonds one evaluation of the bond steps works on: L = LaneCount<T> of them (1, or 8 for a
// CPU batch), their slots b and ends i, j. run: the slots, both ends and the cells advance by one
// per lane (Bonds::run_next), so the lanes' data moves as whole vectors.
template <int L>
struct BondLanes {
  int b[L], i[L], j[L];
  bool run = false;
};

// The current geometry of the lanes' bonds (docs/physics.md 1.2, "Bond kinematics and forces").
template <class T>
struct BondGeometry {
  T length;  // |x_j - x_i|
  T nx, ny;  // n = (x_j - x_i) / length; t = (-ny, nx)
  T li, lj;  // lever arms to the contact point (0 where not wanted: geometry())
};

// What the bond-by-bond path carries through the steps of one bond: its data, its state at the
// start of the step, and its undamaged spring forces of this step.
struct BondValues {
  double kn = 0, ks = 0, area = 0, length0 = 0;
  double fn_old = 0, fs_old = 0, damage_old = 0;  // the applied forces and damage of the last step
  double up = 0, us_p = 0, alpha = 0;             // plastic state of bilinear springs
  double fn = 0, fs = 0;                          // undamaged spring forces
  double du = 0;                                  // shear displacement increment (m)
  double plastic = 0;                             // plastic work of the step (J)
};

// A bond's step is gather -> laws -> scatter: geometry() and the column loads gather the lanes'
// data, elastic_springs() (SpringLaw) and reaches_strength() (FaceStrength) apply the laws of
// laws.hpp, and scatter() adds the forces to the discs. The same member templates serve one bond
// (bond(), with T = double) and eight (elastic_batch(), with T = Double8): the batch is bond()'s
// arithmetic lane by lane, bit for bit. The rest of a bond's laws, the bilinear springs and the
// cohesive softening (springs(), start_softening(), soften(), break_bond()), run bond by bond:
// the batches take elastic bonds that neither soften nor reach their strength.
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
#endif

  // ---- Gather ---------------------------------------------------------------------------------

  // The (x, y) pairs of an [n][2] node view at the lanes' nodes n: whole vectors along a run.
  template <class T, int L>
  KOKKOS_FORCEINLINE_FUNCTION static void node_pairs(const View<double* [2]>& a, const int (&n)[L],
                                                     const bool run, T& ax, T& ay) {
    if constexpr (L == 1) {
      (void)run;
      ax = a(n[0], 0);
      ay = a(n[0], 1);
    } else {
#ifdef FRACTA_HOST_SIMD
      if (run && a.stride_0() == 2) {
        load_pairs(&a(n[0], 0), ax, ay);
        return;
      }
#endif
      const int stride = static_cast<int>(a.stride_0());
      ax = gather_lanes<T>(&a(0, 0), n, stride);
      ay = gather_lanes<T>(&a(0, 1), n, stride);
    }
  }

  // A per-node or per-slot column at the lanes' indices k: one vector load where they are
  // consecutive.
  template <class T, int L, class V>
  KOKKOS_FORCEINLINE_FUNCTION static T column(const V& a, const int (&k)[L],
                                              const bool consecutive) {
    if constexpr (L == 1) {
      (void)consecutive;
      return a(k[0]);
    } else {
      return load_lanes<T>(a.data(), k, consecutive);
    }
  }

  // Direction and length of the lanes' bonds, and with `arms` their lever arms to the contact
  // point, which splits the current length in the ratio of the radii: then the moments
  // l_i fs + l_j fs = L fs balance the couple of the shear forces exactly (angular momentum is
  // conserved whatever the stretch).
  template <class T, int L>
  KOKKOS_FORCEINLINE_FUNCTION BondGeometry<T> geometry(const BondLanes<L>& s,
                                                       const bool arms) const {
    BondGeometry<T> g;
    T xi, yi, xj, yj;
    node_pairs(nodes.x, s.i, s.run, xi, yi);
    node_pairs(nodes.x, s.j, s.run, xj, yj);
    const T dx = xj - xi, dy = yj - yi;
    g.length = sqrt_(dx * dx + dy * dy);
    // Reciprocals, then products: divisions are the slowest arithmetic of the kernel.
    const T inverse_length = 1.0 / g.length;
    g.nx = dx * inverse_length;
    g.ny = dy * inverse_length;
    g.li = g.lj = splat<T>(0.0);
    if (arms) {
      const T ri = column<T>(nodes.radius, s.i, s.run);
      const T rj = column<T>(nodes.radius, s.j, s.run);
      const T length_share = g.length / (ri + rj);
      g.li = length_share * ri;
      g.lj = length_share * rj;
    }
    return g;
  }

  // Shear displacement increment of the step (paper Eq. 8 corrected; docs/physics.md 1.2): the
  // relative tangential velocity of the contact point, with the disc rotations, times dt.
  template <class T, int L>
  KOKKOS_FORCEINLINE_FUNCTION T shear_increment(const BondLanes<L>& s,
                                                const BondGeometry<T>& g) const {
    T vxi, vyi, vxj, vyj;
    node_pairs(nodes.v, s.i, s.run, vxi, vyi);
    node_pairs(nodes.v, s.j, s.run, vxj, vyj);
    const T dvt =
        -(vxj - vxi) * g.ny + (vyj - vyi) * g.nx -
        (g.li * column<T>(nodes.spin, s.i, s.run) + g.lj * column<T>(nodes.spin, s.j, s.run));
    return dvt * dt;
  }

  // ---- Laws -----------------------------------------------------------------------------------

  // Undamaged forces of elastic springs (SpringLaw): fn from the natural length L0 + u_p, one
  // value (Bonds::rest_length); with `shear`, fs incrementally from fs_undamaged where the bond
  // has a shear spring (ks > 0), else 0. du: the shear displacement increment (0 without shear).
  template <class T, int L>
  KOKKOS_FORCEINLINE_FUNCTION void elastic_springs(const BondLanes<L>& s, const BondGeometry<T>& g,
                                                   const bool shear, const T& kn, const T& ks,
                                                   const T& fs_undamaged, T& fn, T& fs,
                                                   T& du) const {
    fn = SpringLaw::elastic_force(kn, g.length, column<T>(bonds.rest_length, s.b, true));
    fs = du = splat<T>(0.0);
    if (shear) {
      du = shear_increment(s, g);
      fs = ks > 0.0 ? SpringLaw::elastic_increment(ks, fs_undamaged, du) : splat<T>(0.0);
    }
  }

  // Whether the lanes' strengths are scaled: by random strength factors (Bonds::strength_scale) or
  // by a dynamic increase factor (RateLaw). Unscaled, the check keeps the arithmetic of a uniform,
  // rate-independent lattice.
  KOKKOS_INLINE_FUNCTION bool scaled(const double rate_factor) const {
    return bonds.strength_scale.extent(0) > 0 || rate_factor != 1.0;
  }
  // The lanes' random strength factors (1 without them).
  template <class T, int L>
  KOKKOS_FORCEINLINE_FUNCTION T strength_scale(const BondLanes<L>& s) const {
    return bonds.strength_scale.extent(0) > 0 ? column<T>(bonds.strength_scale, s.b, true)
                                              : splat<T>(1.0);
  }

  // Whether the lanes' bonds reach their strength (FaceStrength; docs/physics.md 1.2, "Face
  // failure") on the face each stands for: the cell face normal to an edge bond, the diagonal
  // plane for a diagonal. The traction comes from the mean continuum stress of the bond's intact
  // cells (their stresses summed in s3, `cells` of them: compute_cell_stress), in the reference
  // frame with the reference bond direction (rotation invariant), so uniaxial tension breaks a
  // bond at sigma_t and a direct shear test at tau = c + sigma tan(phi): a single bond's fn / S
  // cannot see the stress along its face (the Poisson coupling) and would miss the envelope under
  // confinement. With no intact cell left (a fragment's edge): the bond's own fn / S and |fs| / S.
  // The strengths are scaled by each bond's random factor (Bonds::strength_scale) and by
  // rate_factor (the bond-by-bond path's dynamic increase factor, RateLaw).
  template <class T, int L>
  KOKKOS_FORCEINLINE_FUNCTION auto reaches_strength(const FaceStrength& face, const BondLanes<L>& s,
                                                    const T (&s3)[3], const T& cells, const T& fn,
                                                    const T& fs,
                                                    const double rate_factor = 1.0) const {
    T sigma_n, tau;
    face_traction(s, s3, cells, fn, fs, sigma_n, tau);
    if (!scaled(rate_factor)) return face.reaches(sigma_n, tau);
    return face.reaches(sigma_n, tau, strength_scale<T>(s) * rate_factor);
  }

  // The traction (sigma_n, tau) reaches_strength checks.
  template <class T, int L>
  KOKKOS_FORCEINLINE_FUNCTION void face_traction(const BondLanes<L>& s, const T (&s3)[3],
                                                 const T& cells, const T& fn, const T& fs,
                                                 T& sigma_n, T& tau) const {
    T x0i, y0i, x0j, y0j;
    node_pairs(nodes.x0, s.i, s.run, x0i, y0i);
    node_pairs(nodes.x0, s.j, s.run, x0j, y0j);
    const T ux = x0j - x0i, uy = y0j - y0i;
    const T inverse_L0 = 1.0 / column<T>(bonds.length0, s.b, true);
    const T n0x = ux * inverse_L0, n0y = uy * inverse_L0;
    const T mean = cells > 1.0 ? splat<T>(0.5) : splat<T>(1.0);  // exactly s3 / cells
    FaceStrength::traction(s3[0] * mean, s3[1] * mean, s3[2] * mean, n0x, n0y, sigma_n, tau);
    if (any_lane(cells == 0.0)) {  // rare in a batch: it then gathers the areas
      const T area = column<T>(bonds.area, s.b, true);
      sigma_n = cells > 0.0 ? sigma_n : (area > 0.0 ? fn / area : splat<T>(0.0));
      tau = cells > 0.0 ? tau : (area > 0.0 ? fabs_(fs) / area : splat<T>(0.0));
    }
  }

  // Next to a crack (one of bond b's cells cracked, `cells` > 0 intact ones left): the intact
  // cell lies half a cell ahead of the bond, in the steep stress rise of a crack tip, so the
  // normal traction takes the normal strain across the face from the bond itself, at the face
  // (FaceStrength::local_normal; docs/physics.md 1.2, "Face failure"): the front of a crack sees
  // the stress where it is. The shear traction is the cells'. Out of line: bond() calls it for
  // the few bonds beside a crack, and its hot path keeps its code.
  FRACTA_NOINLINE KOKKOS_FUNCTION bool reaches_strength_beside_crack(
      const BondLaw& law, const BondLanes<1>& s, const double (&s3)[3], const double cells,
      const double fn, const double rate_factor) const {
    double local, tau;
    if (!traction_beside_crack(law, s, s3, cells, fn, local, tau)) return false;
    if (!scaled(rate_factor)) return law.face().reaches(local, tau);
    return law.face().reaches(local, tau, strength_scale<double>(s) * rate_factor);
  }

  // The traction reaches_strength_beside_crack checks; false where it does not apply.
  KOKKOS_INLINE_FUNCTION bool traction_beside_crack(const BondLaw& law, const BondLanes<1>& s,
                                                    const double (&s3)[3], const double cells,
                                                    const double fn, double& local,
                                                    double& tau) const {
    const int b = s.b[0], i = s.i[0], j = s.j[0];
    const double area = bonds.area(b);
    if (!(cells > 0.0) || !(area > 0.0)) return false;
    const double inverse_L0 = 1.0 / bonds.length0(b);
    const double n0x = (nodes.x0(j, 0) - nodes.x0(i, 0)) * inverse_L0;
    const double n0y = (nodes.x0(j, 1) - nodes.x0(i, 1)) * inverse_L0;
    const double mean = 1.0 / cells;
    double sigma_n;
    FaceStrength::traction(s3[0] * mean, s3[1] * mean, s3[2] * mean, n0x, n0y, sigma_n, tau);
    const double sigma_tt = (s3[0] + s3[1]) * mean - sigma_n;
    local = FaceStrength::local_normal(sigma_n, sigma_tt, fn / area, law.poisson_ratio_eff);
    return true;
  }

  // How far bond b has passed its strength (FaceStrength::excess) on the tractions of the face
  // checks that found it there, the larger of the two beside a crack. Out of line: only a bond
  // that starts to soften asks.
  FRACTA_NOINLINE KOKKOS_FUNCTION double strength_excess(const BondLaw& law, const BondLanes<1>& s,
                                                         const double (&s3)[3], const double cells,
                                                         const double fn, const double fs,
                                                         const double rate_factor) const {
    const double scale = strength_scale<double>(s) * rate_factor;
    double sigma_n, tau;
    face_traction(s, s3, cells, fn, fs, sigma_n, tau);
    double excess = law.face().excess(sigma_n, tau, scale);
    if (beside_crack(s.b[0]) && traction_beside_crack(law, s, s3, cells, fn, sigma_n, tau))
      excess = fmax(excess, law.face().excess(sigma_n, tau, scale));
    return excess;
  }

  // The magnitude of bond b's normal strain rate |(v_j - v_i) . n| / L0 (1/s), with the
  // filtered half-step velocities (filter_velocities; RateLaw).
  KOKKOS_INLINE_FUNCTION double normal_strain_rate(const BondLanes<1>& s,
                                                   const BondGeometry<double>& g,
                                                   const double length0) const {
    const int i = s.i[0], j = s.j[0];
    const View<double* [2]>& v = nodes.v_filtered;
    const double rate = ((v(j, 0) - v(i, 0)) * g.nx + (v(j, 1) - v(i, 1)) * g.ny) / length0;
    return fabs_(rate);
  }

  // Whether one of the bonds b0 .. b0 + 7 has a cracked cell; run_cell: the first lane's cells of
  // a run (each advances by one per lane), or null to read each slot's. Out of line, so that the
  // batch's arithmetic keeps its code.
  FRACTA_NOINLINE bool any_beside_crack(const int b0, const int* run_cell) const {
    for (int l = 0; l < kLanes; ++l)
      for (int k = 0; k < 2; ++k) {
        const int c = run_cell ? (run_cell[k] >= 0 ? run_cell[k] + l : -1) : bonds.cells(b0 + l, k);
        if (c >= 0 && elements.cell_state(c) == kCellCracked) return true;
      }
    return false;
  }

  // Whether one of bond b's cells is cracked (a side without a cell is not).
  KOKKOS_INLINE_FUNCTION bool beside_crack(const int b) const {
    for (int k = 0; k < 2; ++k) {
      const int c = bonds.cells(b, k);
      if (c >= 0 && elements.cell_state(c) == kCellCracked) return true;
    }
    return false;
  }

  // ---- Scatter --------------------------------------------------------------------------------

  // What the lanes' bonds apply (docs/physics.md 1.2): fn n + fs t on disc i, the opposite on j,
  // and the moments l_i fs on i and l_j fs on j. Along a run, as vector adds (the j ends first:
  // the bond-by-bond order where the two ranges overlap, j = i + d with 0 < d < 8), with the
  // moments only where `moments` (bonds without shear add l fs = 0); else lane by lane.
  template <class T, int L>
  KOKKOS_FORCEINLINE_FUNCTION void scatter(const BondLanes<L>& s, const BondGeometry<T>& g,
                                           const T& fn, const T& fs, const bool moments) const {
    const T fx = fn * g.nx - fs * g.ny, fy = fn * g.ny + fs * g.nx;
    const T mi = g.li * fs, mj = g.lj * fs;
#ifdef FRACTA_HOST_SIMD
    if constexpr (L > 1) {
      if (s.run && !atomic && nodes.f.stride_0() == 2) {
        add_pairs(&nodes.f(s.j[0], 0), -fx, -fy);
        if (moments) add_lanes(mj, nodes.moment.data(), s.j, true);
        add_pairs(&nodes.f(s.i[0], 0), fx, fy);
        if (moments) add_lanes(mi, nodes.moment.data(), s.i, true);
        return;
      }
    }
#endif
    (void)moments;
    for (int l = 0; l < L; ++l) {
      scatter_add(&nodes.f(s.i[l], 0), get_lane(fx, l), atomic);
      scatter_add(&nodes.f(s.i[l], 1), get_lane(fy, l), atomic);
      scatter_add(&nodes.moment(s.i[l]), get_lane(mi, l), atomic);
      scatter_add(&nodes.f(s.j[l], 0), -get_lane(fx, l), atomic);
      scatter_add(&nodes.f(s.j[l], 1), -get_lane(fy, l), atomic);
      scatter_add(&nodes.moment(s.j[l]), get_lane(mj, l), atomic);
    }
  }

#ifdef FRACTA_HOST_SIMD
  // ---- Eight bonds at once --------------------------------------------------------------------

  // Eight bonds in SIMD lanes (simd.hpp), the common case of a lattice at work: the consecutive
  // active slots b0 .. b0 + 7 of one material with elastic springs (no yield stress), none
  // softening (onset 0, so damage 0) and none reaching its strength this step. kRun: the slots
  // are the run of `run` (batch()), so the node data of each end and the cell data of each side
  // move as vectors, and the law is the one of the run's cells (a bond's material is the one of
  // the cell that activated it: activate_element_bonds). !kShear: the run's slots are diagonals,
  // which have no shear spring (ks = 0 and fs = 0 always: activate_element_bonds and
  // prestress_converted_bonds give shear only to edges), so the batch reads no velocities, spins,
  // radii, ks or fs, and adds no moments. The steps are bond()'s, lane by lane. If the batch does
  // not qualify, or a lane reaches its strength, it returns false before writing anything, and
  // the caller runs bond() for each (rare: a bond breaks or starts to soften once).
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
    if (law.springs().plastic()) return false;
    BondLanes<L> s;
    s.run = kRun;
    for (int l = 0; l < L; ++l) s.b[l] = b0 + l;
    if (law.softening().cohesive() && any_lane(column<T>(bonds.onset_separation, s.b, true) != 0.0))
      return false;
    // A bond beside a cracked cell takes the local traction (reaches_strength_beside_crack):
    // bond by bond.
    if (any_beside_crack(b0, kRun ? run.cell : nullptr)) return false;
    for (int l = 0; l < L; ++l) {
      s.i[l] = kRun ? run.i + l : bonds.nodes(b0 + l, 0);
      s.j[l] = kRun ? run.j + l : bonds.nodes(b0 + l, 1);
    }
    const BondGeometry<T> g = geometry<T>(s, kShear);
    const T zero = splat<T>(0.0);
    const T kn = column<T>(bonds.kn, s.b, true);
    const T ks = kShear ? column<T>(bonds.ks, s.b, true) : zero;
    const T fs_old = kShear ? column<T>(bonds.fs, s.b, true) : zero;  // undamaged: D = 0
    T fn, fs, du;
    elastic_springs(s, g, kShear, kn, ks, fs_old, fn, fs, du);
    T s3[3], cells;
    if (!batch_cells<kRun>(s, run, s3, cells) &&
        any_lane(reaches_strength(law.face(), s, s3, cells, fn, fs)))
      return false;
    // fn is only written here (the next step reads it): past the caches, saving the line's read.
    stream_lanes(fn, bonds.fn.data() + b0);
    if constexpr (kShear) store_lanes(fs, bonds.fs.data(), s.b, true);
    scatter(s, g, fn, fs, kShear);
    return true;
  }

  // The intact cells of a batch's bonds for their failure check: returns true where the check
  // can be skipped, every lane having an intact cell and all its intact cells below their
  // strength on every face (kCellBelowStrength: compute_cell_stress); else sums each lane's
  // intact cells' stresses in s3 and counts them in `cells`, as bond() does (intact_cells).
  template <bool kRun>
  bool batch_cells(const BondLanes<8>& s, const RunLanes& run, Double8 (&s3)[3],
                   Double8& cells) const {
    using T = Double8;
    constexpr int L = 8;
    Int8 side_cells[2];
    if (kRun) {
      for (int side = 0; side < 2; ++side)
        side_cells[side] =
            run.cell[side] >= 0 ? run.cell[side] + Int8{0, 1, 2, 3, 4, 5, 6, 7} : Int8{} - 1;
    } else {
      const Int16 cell_pairs = load_ints16(&bonds.cells(s.b[0], 0));  // stride_0 2, as the ends
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
    if (all_set((cell_state[0] == below || cell_state[1] == below) &&
                (cell_state[0] != intact_only) && (cell_state[1] != intact_only)))
      return true;
    for (int q = 0; q < 3; ++q) s3[q] = splat<T>(0.0);
    cells = splat<T>(0.0);
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
    return false;
  }
#endif

  // ---- One bond -------------------------------------------------------------------------------

  // A bond broke or started to soften: its cells are no longer a continuum, from the next cell
  // stress on (compute_cell_stress; this sweep reads cell_state only). Every writer writes 1.
  KOKKOS_INLINE_FUNCTION void mark_cells_cracked(const int b) const {
    for (int k = 0; k < 2; ++k) {
      const int c = bonds.cells(b, k);
      if (c >= 0) elements.cell_cracked(c) = 1;
    }
  }

  // Bond b's data and state, and its undamaged spring forces of this step (SpringLaw). Elastic
  // springs never change their plastic state (which a conversion may have set: the cell's strain
  // beyond its elastic part): they read the natural length alone and write nothing back (a sixth
  // of the bytes a bond moves per step). Bilinear springs take their parameters in force units
  // (yield force = yield stress x S, hardening stiffness H S / L0) and accumulate plastic work.
  KOKKOS_FORCEINLINE_FUNCTION BondValues springs(const BondLanes<1>& s,
                                                 const BondGeometry<double>& g,
                                                 const BondLaw& law) const {
    const int b = s.b[0];
    BondValues v;
    v.kn = bonds.kn(b);
    v.ks = bonds.ks(b);
    v.area = bonds.area(b);
    v.length0 = bonds.length0(b);
    // fn, fs: the undamaged spring forces; a softening bond applies (1 - D) of them.
    v.damage_old = law.softening().cohesive() ? bonds.damage(b) : 0.0;
    v.fn_old = bonds.fn(b);
    v.fs_old = bonds.fs(b);
    const double fs_undamaged = CohesiveSoftening::undamaged(v.fs_old, v.damage_old);
    const SpringLaw spring = law.springs();
    if (!spring.plastic()) {
      elastic_springs(s, g, v.ks > 0.0, v.kn, v.ks, fs_undamaged, v.fn, v.fs, v.du);
      return v;
    }
    v.up = bonds.plastic_n(b);
    v.us_p = bonds.plastic_s(b);
    v.alpha = bonds.hardening(b);
    const double k_hard = spring.hardening_stiffness(v.area, v.length0);
    v.plastic += SpringLaw::bilinear(v.kn, g.length - v.length0, spring.normal_yield_force(v.area),
                                     k_hard, v.up, v.alpha, v.fn);
    if (v.ks > 0.0) {
      // Shear displacement kept as the elastic part fs/ks plus the plastic slip.
      v.du = shear_increment(s, g);
      const double us = fs_undamaged / v.ks + v.us_p + v.du;
      v.plastic += SpringLaw::bilinear(v.ks, us, spring.shear_yield_force(v.area), k_hard, v.us_p,
                                       v.alpha, v.fs);
    }
    return v;
  }

  // The summed stresses of bond b's intact cells (compute_cell_stress) and their number.
  KOKKOS_FORCEINLINE_FUNCTION void intact_cells(const int b, double (&s3)[3], double& cells) const {
    s3[0] = s3[1] = s3[2] = 0.0;
    cells = 0.0;
    for (int k = 0; k < 2; ++k) {
      const int c = bonds.cells(b, k);
      if (c < 0 || elements.cell_state(c) == kCellCracked) continue;
      for (int q = 0; q < 3; ++q) s3[q] += elements.cell_stress(c, q);
      cells += 1.0;
    }
  }

  // A bond at its strength: brittle, it breaks; cohesive, it starts to soften from the effective
  // separation at which it met its strength, its separation now over `excess`
  // (CohesiveSoftening::final_separation), unless its share of G_f is no more than it held
  // there. Returns the onset separation, or 0 where it breaks.
  KOKKOS_FORCEINLINE_FUNCTION double start_softening(const int b, const CohesiveSoftening& law,
                                                     const BondValues& v,
                                                     const double excess) const {
    if (!law.cohesive()) return 0.0;
    // The step's path is taken proportional, so the bond met its strength at 1 / excess of its
    // separation now; but never before the last step, when it was below its strength: where the
    // traction jumped past the strength without the bond stretching as much (a neighbour broke
    // and the face check beside the crack took over), the crossing is the last step's
    // separation. Undamaged before the onset, the last step's forces are its springs'.
    const double now = CohesiveSoftening::effective_separation(v.fn, v.fs, v.kn, v.ks);
    const double before = CohesiveSoftening::effective_separation(v.fn_old, v.fs_old, v.kn, v.ks);
    const double within_step =
        before >= now ? 1.0 : (before > 0.0 ? fmin(excess, now / before) : excess);
    double onset;
    const double final_separation =
        law.final_separation(v.fn, v.fs, v.kn, v.ks, v.length0,
                             law.crack_area_factor[bonds.kind(b)], within_step, onset);
    if (!(onset > 0.0 && final_separation > onset)) return 0.0;
    bonds.onset_separation(b) = onset;
    mark_cells_cracked(b);
    bonds.final_separation(b) = final_separation;
    return onset;
  }

  // Bond b breaks. Released as fracture energy: CohesiveSoftening::released_energy, less what a
  // bond that breaks while its discs overlap hands to the contact that takes over at once
  // (1/2 k_c delta^2 with the contact law's series stiffness): that part is not fracture energy,
  // or the balance would count it twice.
  KOKKOS_FORCEINLINE_FUNCTION void break_bond(const BondLanes<1>& s, const BondGeometry<double>& g,
                                              const CohesiveSoftening& law, const BondValues& v,
                                              Sums<3>& acc) const {
    const int b = s.b[0], i = s.i[0], j = s.j[0];
    double energy =
        law.released_energy(v.fn_old, v.fs_old, v.fn, v.fs, v.damage_old, v.kn, v.ks, v.du);
    const double overlap = nodes.radius(i) + nodes.radius(j) - g.length;
    if (overlap > 0.0) {
      const double kc =
          ContactLaw::series_stiffness(nodes.contact_stiffness(i), nodes.contact_stiffness(j));
      energy -= ContactLaw::elastic_energy(kc, overlap);
    }
    bonds.state(b) = kBondBroken;
    bonds.note_broken(b);
    if (nodes.bound_stale.extent(0) > 0) nodes.bound_stale(i) = nodes.bound_stale(j) = 1;
    mark_cells_cracked(b);
    bonds.fn(b) = 0.0;
    bonds.fs(b) = 0.0;
    acc.v[0] += energy;
    acc.v[1] += v.plastic;
    acc.v[2] += 1.0;
  }

  // A softening bond at damage D: the forces it applies (v.fn, v.fs become them), and the energy
  // the softening dissipated this step, the trapezoidal work of the discs on the bond less the
  // change of what it stores (zero for an undamaged spring, so the balance is the elastic one
  // until the onset).
  KOKKOS_FORCEINLINE_FUNCTION void soften(const int b, const double damage, BondValues& v,
                                          Sums<3>& acc) const {
    using Law = CohesiveSoftening;
    double fn_applied, fs_applied;
    Law::applied(v.fn, v.fs, damage, fn_applied, fs_applied);
    acc.v[0] +=
        Law::work(v.fn_old, fn_applied, v.fs_old, fs_applied, v.fn, v.damage_old, v.kn, v.du) +
        Law::stored_energy(v.fn_old, v.fs_old, v.damage_old, v.kn, v.ks) -
        Law::stored_energy(fn_applied, fs_applied, damage, v.kn, v.ks);
    v.fn = fn_applied;
    v.fs = fs_applied;
    bonds.damage(b) = damage;
  }

  // The step of active bond b: gather and springs, the face check (a bond not yet softening),
  // the softening of a cohesive one (its damage grows with its effective separation; it breaks
  // when spent), then the state written back and the forces scattered.
  KOKKOS_INLINE_FUNCTION void bond(const int b, Sums<3>& acc) const {
    if (bonds.state(b) != kBondActive) return;
    BondLanes<1> s;
    s.b[0] = b;
    s.i[0] = bonds.nodes(b, 0);
    s.j[0] = bonds.nodes(b, 1);
    const BondLaw& law = laws(bonds.material(b));
    const BondGeometry<double> g = geometry<double>(s, true);
    BondValues v = springs(s, g, law);
    CohesiveSoftening softening = law.softening();
    double onset = softening.cohesive() ? bonds.onset_separation(b) : 0.0;
    bool breaks = false;
    if (onset == 0.0) {
      double s3[3], cells;
      intact_cells(b, s3, cells);
      const auto reaches = [&](const double rate_factor) {
        return reaches_strength(law.face(), s, s3, cells, v.fn, v.fs, rate_factor) ||
               (beside_crack(b) &&
                reaches_strength_beside_crack(law, s, s3, cells, v.fn, rate_factor));
      };
      // The static strength first: the dynamic increase factor is >= 1, so only a bond that
      // reaches it needs its strain rate and the factor (a logarithm), not every bond each step.
      bool reached = reaches(1.0);
      double factor = 1.0;  // the dynamic increase factor the check used
      if (reached && law.rate.active()) {
        const double rate = normal_strain_rate(s, g, v.length0);
        factor = law.rate.strength_factor(rate);
        reached = reaches(factor);
        if (reached) softening.fracture_energy *= law.rate.fracture_energy_factor(rate);
      }
      if (reached) {
        const double excess =
            softening.cohesive() ? strength_excess(law, s, s3, cells, v.fn, v.fs, factor) : 1.0;
        onset = start_softening(b, softening, v, excess);
        breaks = onset == 0.0;
      } else if (cells == 0.0 && !(v.kn > 0.0) && !(v.ks > 0.0)) {
        // A slot without springs (a diagonal at nu = 0, where k2 = 0: docs/physics.md 1.2)
        // carries no force and stands only for its cells' material: once none is intact it
        // holds nothing together, and left active it would join its discs for the fragments
        // and the contact list (a cracked nu = 0 block stayed one fragment).
        breaks = true;
      }
    }
    double damage = v.damage_old;
    if (onset > 0.0) {
      const double lambda_f = bonds.final_separation(b);
      const double lambda = CohesiveSoftening::effective_separation(v.fn, v.fs, v.kn, v.ks);
      if (lambda >= lambda_f)
        breaks = true;
      else
        damage = CohesiveSoftening::damage(lambda, onset, lambda_f, damage);
      // Short of lambda_f, 1 - D = lambda_0 (lambda_f - lambda) / (lambda (lambda_f - lambda_0))
      // may fall below half an ulp, and D rounds to 1: next to lambda_f, or, where lambda_f /
      // lambda_0 is vast, once lambda passes about 2^53 lambda_0 (a weak bond whose cells' stress
      // met its strength while its own springs held nothing: lambda_0 and E_0 of rounding size).
      // At D = 1 the bond applies nothing, and its next step would recover its undamaged shear
      // force from the applied one as 0 / 0 (CohesiveSoftening::undamaged): it is spent, and
      // breaks as at lambda_f.
      if (damage >= 1.0) breaks = true;
    }
    if (breaks) {
      break_bond(s, g, softening, v, acc);
      return;
    }
    if (onset > 0.0) soften(b, damage, v, acc);
    bonds.fn(b) = v.fn;
    bonds.fs(b) = v.fs;
    if (law.springs().plastic()) {
      bonds.plastic_n(b) = v.up;
      bonds.rest_length(b) = v.length0 + v.up;
      bonds.plastic_s(b) = v.us_p;
      bonds.hardening(b) = v.alpha;
      bonds.plastic_work(b) += v.plastic;
      acc.v[1] += v.plastic;
    }
    scatter(s, g, v.fn, v.fs, true);
  }
};

// The velocities the bonds' strain rates are taken from (RateLaw): an exponential average of the
// half-step velocity, v_f <- v_f + w (v - v_f), weight w = kVelocityFilterWeight per step, so
// over about ten steps. The lattice rings at periods of a few steps (its highest frequency,
// about 2 c / h), where a bond's instantaneous strain rate swings far above and below its
// mean; the average passes 7 % of a 4-step oscillation and 32 % of a 20-step one, and follows
// a loading rate that changes over more than about ten steps.
constexpr double kVelocityFilterWeight = 0.1;

// v_f <- v_f + w (v - v_f) for the T-lane group of storage entries from `first` on.
template <class T>
KOKKOS_INLINE_FUNCTION void filter_lanes(const double* v, double* v_filtered, const int first) {
  int index[LaneCount<T>::value];
  for (int l = 0; l < LaneCount<T>::value; ++l) index[l] = first + l;
  const T velocity = load_lanes<T>(v, index, true);
  const T filtered = load_lanes<T>(v_filtered, index, true);
  store_lanes(filtered + kVelocityFilterWeight * (velocity - filtered), v_filtered, index, true);
}

inline void filter_velocities(const Nodes& nodes) {
  if (nodes.v_filtered.extent(0) == 0) return;
  // The same update for every component: a sweep over the two views' storage (of the same
  // layout) in groups of kLanes entries, by NativeDouble lanes on CPUs; the (node, component)
  // loop was not vectorised (3.5 % of the main job's instructions).
  if (nodes.v.span() != nodes.v_filtered.span())
    Kokkos::abort("filter_velocities: v and v_filtered differ in size");
  const double* const v = nodes.v.data();
  double* const v_filtered = nodes.v_filtered.data();
  const int size = static_cast<int>(nodes.v_filtered.span());
  Kokkos::parallel_for(
      "fracta::filter_velocities", Kokkos::RangePolicy<ExecSpace>(0, (size + kLanes - 1) / kLanes),
      KOKKOS_LAMBDA(const int group) {
        const int first = group * kLanes;
        if (first + kLanes <= size) {
          for (int c = first; c < first + kLanes; c += kNativeLanes)
            filter_lanes<NativeDouble>(v, v_filtered, c);
        } else {
          for (int i = first; i < size; ++i) filter_lanes<double>(v, v_filtered, i);
        }
      });
}

// Bond forces added into nodes.f and nodes.moment. The list is increasing, so the order of
// every node's sum is the one of the sweep over all slots. Without a usable bonds.scatter (the
// plan of the list: update_scatter_plan) the forces are added atomically. batches: how the CPU
// kernel groups the bonds (the default everywhere but in tests). With a slot given, the sums
// (fracture energy, plastic work, broken bonds: bond_step_result) go there (ResultSlot: the
// launch does not wait) and the result returned is empty.
using BondSums = Sums<3>;

inline BondStepResult bond_step_result(const BondSums& s) {
  BondStepResult r;
  r.fracture_energy = s.v[0];
  r.plastic_work = s.v[1];
  r.broken = static_cast<long>(s.v[2] + 0.5);
  return r;
}

inline BondStepResult compute_bond_forces(const Nodes& nodes, const Elements& elements,
                                          const Bonds& bonds, const View<const BondLaw*>& laws,
                                          double dt, BondBatches batches = BondBatches::runs,
                                          const ResultSlot<BondSums>& into = {}) {
  BondStepResult r;
  if (bonds.count == 0) {
    if (into.data()) put(into, BondSums());
    return r;
  }
  const int count = bond_list_count(bonds);
  BondForces forces{
      nodes, elements, bonds, laws, dt, bonds_listed(bonds) ? bonds.used : View<int*>(), true};
  forces.batches = batches;
  BondSums s;
  if (bonds.scatter.usable(count)) {
    forces.atomic = false;
    s = for_each_chunk<Kokkos::Sum<BondSums>>("fracta::bond_forces", bonds.scatter,
                                              std::move(forces));
    if (!into.data()) return bond_step_result(s);
    put(into, s);
    return r;
  }
  const auto policy = Kokkos::RangePolicy<ExecSpace>(0, count);
  if (into.data()) {
    Kokkos::parallel_reduce(slot_label("fracta::bond_forces"), policy, forces,
                            Kokkos::Sum<BondSums, MemSpace>(into));
    return r;
  }
  Kokkos::parallel_reduce("fracta::bond_forces", policy, forces, Kokkos::Sum<BondSums>(s));
  return bond_step_result(s);
}

}  // namespace fracta
