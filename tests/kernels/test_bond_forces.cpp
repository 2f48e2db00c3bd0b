// The bonded disc lattice (docs/physics.md 1.2): elasticity of the lattice against the continuum,
// rigid motions, angular momentum, and the bond failure calibration.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <vector>

#include "host/simulation.hpp"
#include "kernels/bond_forces.hpp"
#include "test_util.hpp"

namespace fracta {
namespace {

Case lattice_case(int nx, int ny, double h, double E, double nu, Formulation f) {
  Case c = test::rectangle_case(nx, ny, h, E, nu, 7800.0, f);
  c.bodies[0].method = BodyMethod::de;
  c.sim.end_time = 1.0;
  return c;
}

// Imposes the homogeneous strain eps (symmetric, so the discs do not rotate) on the lattice in
// one step and returns the stress the boundary forces carry: sxx from the right edge, syy from
// the top edge, sxy from the right edge's y forces. Also returns the largest interior force.
struct LatticeResponse {
  double sxx, syy, sxy, interior_force;
};

LatticeResponse impose_strain(const Case& c, const double eps[2][2]) {
  Case fixed_dt = c;
  Simulation probe(c);
  fixed_dt.sim.dt = 0.5 * probe.stable_dt_bound();
  Simulation sim(fixed_dt);
  Nodes& n = sim.model().nodes;
  const double dt = sim.dt();
  auto x0 = Kokkos::create_mirror_view_and_copy(HostSpace(), n.x0);
  auto v = Kokkos::create_mirror_view_and_copy(HostSpace(), n.v);
  for (int i = 0; i < n.count; ++i)
    for (int d = 0; d < 2; ++d) v(i, d) = (eps[d][0] * x0(i, 0) + eps[d][1] * x0(i, 1)) / dt;
  Kokkos::deep_copy(n.v, v);
  sim.step();  // x = (I + eps) x0; the bond forces are those of the strained lattice
  auto f = Kokkos::create_mirror_view_and_copy(HostSpace(), n.f);
  const double W = c.bodies[0].shape.width, H = c.bodies[0].shape.height, t = c.sim.thickness;
  const double tol = 1e-3 * c.bodies[0].cell_size;
  LatticeResponse r{0, 0, 0, 0};
  double fx_right = 0, fy_right = 0, fy_top = 0;
  for (int i = 0; i < n.count; ++i) {
    const bool right = x0(i, 0) > W - tol, top = x0(i, 1) > H - tol;
    const bool left = x0(i, 0) < tol, bottom = x0(i, 1) < tol;
    if (right) {
      fx_right += f(i, 0);
      fy_right += f(i, 1);
    }
    if (top) fy_top += f(i, 1);
    if (!right && !top && !left && !bottom)
      r.interior_force = std::max({r.interior_force, std::fabs(f(i, 0)), std::fabs(f(i, 1))});
  }
  // The bonds pull the edge inwards; the traction that holds the strain is the opposite.
  r.sxx = -fx_right / (H * t);
  r.syy = -fy_top / (W * t);
  r.sxy = -fy_right / (H * t);
  return r;
}

// Elastic constants of the lattice from imposed uniaxial strain and pure shear: E and nu of
// uniaxial stress follow from C11, C12 (plane stress: nu = C12/C11, E = C11 (1 - nu^2); plane
// strain: nu = C12/(C11 + C12), E = C11 (1 + nu)(1 - 2 nu)/(1 - nu)) and G = sxy / (2 eps_xy).
// The strain is 1e-6, so the lattice's geometric nonlinearity is O(1e-6); the tolerance 1e-4
// is that with margin (1% would be the accuracy of a wave test).
void check_lattice(double E, double nu, Formulation f) {
  const Case c = lattice_case(12, 8, 1e-3, E, nu, f);
  const double e = 1e-6;
  const double uniaxial[2][2] = {{e, 0}, {0, 0}};
  const double shear[2][2] = {{0, e}, {e, 0}};
  const LatticeResponse a = impose_strain(c, uniaxial);
  const LatticeResponse s = impose_strain(c, shear);
  const double C11 = a.sxx / e, C12 = a.syy / e;
  double nu_m, E_m;
  if (f == Formulation::plane_stress) {
    nu_m = C12 / C11;
    E_m = C11 * (1 - nu_m * nu_m);
  } else {
    nu_m = C12 / (C11 + C12);
    E_m = C11 * (1 + nu_m) * (1 - 2 * nu_m) / (1 - nu_m);
  }
  const double G_m = s.sxy / (2 * e);
  EXPECT_NEAR(E_m, E, 1e-4 * E) << to_string(f) << " nu " << nu;
  EXPECT_NEAR(nu_m, nu, 1e-4) << to_string(f) << " nu " << nu;
  EXPECT_NEAR(G_m, E / (2 * (1 + nu)), 1e-4 * E) << to_string(f) << " nu " << nu;
  // Homogeneous strain is an equilibrium state of the lattice: no force on interior discs.
  EXPECT_LT(a.interior_force, 1e-6 * std::fabs(a.sxx) * 1e-3 * c.sim.thickness);
  EXPECT_LT(s.interior_force, 1e-6 * std::fabs(s.sxy) * 1e-3 * c.sim.thickness);
}

// Pair springs alone up to the Poisson limit (nu = 1/3 in plane stress, 1/4 in plane strain),
// the volumetric cell term beyond it (cell_forces.hpp): nu from 0 to 0.45 in both formulations.
TEST(BondLattice, ReproducesElasticConstantsPlaneStress) {
  for (const double nu : {0.0, 0.21, 0.25, 0.3, 1.0 / 3.0, 0.35, 0.45})
    check_lattice(232e9, nu, Formulation::plane_stress);
}

TEST(BondLattice, ReproducesElasticConstantsPlaneStrain) {
  for (const double nu : {0.0, 0.2, 0.25, 0.3, 0.35, 0.45})
    check_lattice(232e9, nu, Formulation::plane_strain);
}

TEST(BondLattice, NegativePoissonRatioIsRefused) {
  // The diagonal springs would be negative; steel's nu = 0.3 in plane strain is accepted.
  EXPECT_THROW(Simulation{lattice_case(4, 4, 1e-3, 1e9, -0.2, Formulation::plane_strain)},
               InputError);
  EXPECT_NO_THROW(Simulation{lattice_case(4, 4, 1e-3, 232e9, 0.3, Formulation::plane_strain)});
}

// A free square of discs spinning rigidly (v = w x r, spin = w) keeps its angular momentum
// sum m (x vy - y vx) + I w to round-off over many steps: bond forces are central pairs and the
// shear moments balance the shear couples exactly; the volumetric cell term (steel in plane
// strain) is invariant under rotations of the current positions, so it carries no net moment.
void spinning_square(double nu, Formulation f) {
  SCOPED_TRACE(std::string(to_string(f)) + " nu " + std::to_string(nu));
  Case c = lattice_case(8, 8, 1e-3, 92e9, nu, f);
  Simulation sim(c);
  Nodes& n = sim.model().nodes;
  const double w = 2000.0, cx = 4e-3, cy = 4e-3;
  auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), n.x);
  auto v = Kokkos::create_mirror_view_and_copy(HostSpace(), n.v);
  auto spin = Kokkos::create_mirror_view_and_copy(HostSpace(), n.spin);
  for (int i = 0; i < n.count; ++i) {
    v(i, 0) = -w * (x(i, 1) - cy);
    v(i, 1) = w * (x(i, 0) - cx);
    spin(i) = w;
  }
  Kokkos::deep_copy(n.v, v);
  Kokkos::deep_copy(n.spin, spin);
  auto angular_momentum = [&]() {
    auto xh = Kokkos::create_mirror_view_and_copy(HostSpace(), n.x);
    auto vh = Kokkos::create_mirror_view_and_copy(HostSpace(), n.v);
    auto sh = Kokkos::create_mirror_view_and_copy(HostSpace(), n.spin);
    auto m = Kokkos::create_mirror_view_and_copy(HostSpace(), n.mass);
    auto I = Kokkos::create_mirror_view_and_copy(HostSpace(), n.inertia);
    double L = 0;
    for (int i = 0; i < n.count; ++i)
      L += m(i) * ((xh(i, 0) - cx) * vh(i, 1) - (xh(i, 1) - cy) * vh(i, 0)) + I(i) * sh(i);
    return L;
  };
  const double L0 = angular_momentum();
  for (int s = 0; s < 5000 && !sim.failed(); ++s) sim.step();
  EXPECT_FALSE(sim.failed());
  // Round-off: 5000 steps of sums over 81 discs in double precision.
  EXPECT_NEAR(angular_momentum(), L0, 1e-12 * std::fabs(L0));
}

TEST(BondLattice, SpinningSquareKeepsAngularMomentum) {
  spinning_square(0.21, Formulation::plane_stress);
  spinning_square(0.3, Formulation::plane_strain);
}

}  // namespace
}  // namespace fracta

namespace fracta {
namespace {

// The bond kernel runs batches of eight consecutive elastic bonds of one material as one SIMD
// batch (BondForces::elastic_batch) and everything else bond by bond. Both must give the same
// forces: a lattice loaded for some steps (pressure on the left edge, a shear traction on the
// top, so the discs move, rotate and shear their bonds) is evaluated three times from the same
// state: with batches of runs of slots (vector loads, the default), with gathered batches only,
// and bond by bond. build_lattice's slot order must give runs (else the run path goes untested),
// run batches take the law from the cells (so every active bond's material must be its cells'),
// and diagonal runs skip the shear (so a diagonal's ks and fs must stay 0). In the weak variant
// (a tensile strength the load exceeds, with softening) bonds reach their strength in that
// evaluation, so batches fall back when a lane does. Tolerance: 1e-13 of each field's
// largest value (the two paths may contract a*b+c into FMA differently).
struct BondEvaluation {
  std::vector<double> f, moment, fn, fs, onset;
  long broken = 0;
};

std::vector<double> host_values(const View<double*>& v) {
  const auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), v);
  return std::vector<double>(h.data(), h.data() + h.span());
}
std::vector<double> host_values(const View<double* [2]>& v) {
  const auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), v);
  return std::vector<double>(h.data(), h.data() + h.span());
}

TEST(BondForces, SimdBatchesMatchBondByBond) {
  for (bool weak : {false, true}) {
    SCOPED_TRACE(weak ? "weak: bonds reach their strength" : "strong: no bond breaks");
    Case c = test::rectangle_case(40, 16, 1e-3, 30e9, 0.2, 2400.0, Formulation::plane_stress);
    c.bodies[0].method = BodyMethod::de;
    c.materials[0].model = MaterialModel::mohr_coulomb;
    c.materials[0].cohesion = weak ? 8e6 : 1e12;
    c.materials[0].friction_angle = 0.5;
    c.materials[0].tensile_strength = weak ? 2e6 : 1e12;
    if (weak) c.materials[0].fracture_energy = 20.0;
    c.sim.end_time = 1.0;
    test::add_pressure(c, test::segment(0, 0, 0, 0.016), {0.0, 1e-6}, {0.0, 60e6});
    test::add_traction(c, test::segment(0, 0.016, 0.04, 0.016), {1.0, 0.0}, {0.0, 1e-6},
                       {0.0, 20e6});
    test::add_fixed(c, test::segment(0.04, 0, 0.04, 0.016), Boundary::Type::fixed);
    Simulation sim(c);
    Model& m = sim.model();
    Bonds& b = m.bonds;
    const auto laws = m.bond_laws;
    {
      const auto ends = Kokkos::create_mirror_view_and_copy(HostSpace(), b.nodes);
      const auto cells = Kokkos::create_mirror_view_and_copy(HostSpace(), b.cells);
      const auto run_next = Kokkos::create_mirror_view_and_copy(HostSpace(), b.run_next);
      const auto x0 = Kokkos::create_mirror_view_and_copy(HostSpace(), m.nodes.x0);
      // A diagonal's ends differ in both coordinates (Bonds::kind reads run_next itself).
      const auto kind = [&](int k) {
        return x0(ends(k, 0), 0) != x0(ends(k, 1), 0) && x0(ends(k, 0), 1) != x0(ends(k, 1), 1)
                   ? kBondDiagonal
                   : kBondEdge;
      };
      int in_runs = 0;
      for (int k = 0; k + 1 < b.count; ++k) {
        const bool cells_on = [&] {
          for (int side = 0; side < 2; ++side)
            if (cells(k, side) < 0 ? cells(k + 1, side) >= 0
                                   : cells(k + 1, side) != cells(k, side) + 1)
              return false;
          return true;
        }();
        const bool run = ends(k + 1, 0) == ends(k, 0) + 1 && ends(k + 1, 1) == ends(k, 1) + 1 &&
                         cells_on && kind(k + 1) == kind(k);  // one material here
        EXPECT_EQ(run_next(k),
                  (run ? kRunContinues : 0) | (kind(k) == kBondDiagonal ? kRunNormalOnly : 0))
            << "slot " << k;
        in_runs += run;
      }
      EXPECT_GT(in_runs, 0.9 * b.count);
    }
    // Every active bond has its cells' material (the bond forces read it so in runs), and a
    // diagonal has no shear (its run batches read neither ks nor fs).
    const auto check_materials = [&] {
      const auto run_next = Kokkos::create_mirror_view_and_copy(HostSpace(), b.run_next);
      const auto kind = [&](int k) {
        return (run_next(k) & kRunNormalOnly) ? kBondDiagonal : kBondEdge;
      };
      const auto ks = Kokkos::create_mirror_view_and_copy(HostSpace(), b.ks);
      const auto fs = Kokkos::create_mirror_view_and_copy(HostSpace(), b.fs);
      int diagonals = 0;
      for (int k = 0; k < b.count; ++k) {
        if (kind(k) != kBondDiagonal) continue;
        ++diagonals;
        EXPECT_EQ(ks(k), 0.0);
        EXPECT_EQ(fs(k), 0.0);
      }
      EXPECT_GT(diagonals, 0);
      const auto state = Kokkos::create_mirror_view_and_copy(HostSpace(), b.state);
      const auto material = Kokkos::create_mirror_view_and_copy(HostSpace(), b.material);
      const auto cells = Kokkos::create_mirror_view_and_copy(HostSpace(), b.cells);
      const auto cell_material =
          Kokkos::create_mirror_view_and_copy(HostSpace(), m.elements.material);
      int active = 0;
      for (int k = 0; k < b.count; ++k) {
        if (state(k) != kBondActive) continue;
        ++active;
        for (int side = 0; side < 2; ++side) {
          if (cells(k, side) < 0) continue;
          EXPECT_EQ(material(k), cell_material(cells(k, side)));
        }
      }
      EXPECT_GT(active, 0);
    };
    // Everything the bond kernel writes.
    const std::vector<View<double*>> state = {
        b.fn, b.fs, b.damage, b.onset_separation, b.final_separation, b.plastic_work};
    // Both evaluations from the state now; the state is left as it was. Returns how many bonds
    // reached their strength in it (broke, or started to soften).
    BondEvaluation r[3];
    const auto evaluate_both = [&] {
      std::vector<std::vector<double>> saved;
      for (const auto& v : state) saved.push_back(host_values(v));
      auto bond_state = Kokkos::create_mirror(HostSpace(), b.state);
      Kokkos::deep_copy(bond_state, b.state);
      auto cracked = Kokkos::create_mirror(HostSpace(), m.elements.cell_cracked);
      Kokkos::deep_copy(cracked, m.elements.cell_cracked);
      const auto f = host_values(m.nodes.f);
      const auto moment = host_values(m.nodes.moment);
      const auto restore = [&] {
        for (size_t k = 0; k < state.size(); ++k) {
          auto h = Kokkos::create_mirror_view(state[k]);
          std::copy(saved[k].begin(), saved[k].end(), h.data());
          Kokkos::deep_copy(state[k], h);
        }
        Kokkos::deep_copy(b.state, bond_state);
        Kokkos::deep_copy(m.elements.cell_cracked, cracked);
      };
      for (int pass = 0; pass < 3; ++pass) {
        restore();
        // Pass 0 batches with the runs' vector loads, pass 1 gathered batches only, pass 2 bond
        // by bond.
        const BondBatches batches[3] = {BondBatches::runs, BondBatches::gathered,
                                        BondBatches::none};
        Kokkos::deep_copy(m.nodes.f, 0.0);
        Kokkos::deep_copy(m.nodes.moment, 0.0);
        r[pass].broken =
            compute_bond_forces(m.nodes, m.elements, b, laws, sim.dt(), batches[pass]).broken;
        r[pass].f = host_values(m.nodes.f);
        r[pass].moment = host_values(m.nodes.moment);
        r[pass].fn = host_values(b.fn);
        r[pass].fs = host_values(b.fs);
        r[pass].onset = host_values(b.onset_separation);
      }
      restore();
      auto hf = Kokkos::create_mirror_view(m.nodes.f);
      std::copy(f.begin(), f.end(), hf.data());
      Kokkos::deep_copy(m.nodes.f, hf);
      auto hm = Kokkos::create_mirror_view(m.nodes.moment);
      std::copy(moment.begin(), moment.end(), hm.data());
      Kokkos::deep_copy(m.nodes.moment, hm);
      int reached = static_cast<int>(r[0].broken);
      for (size_t k = 0; k < saved[3].size(); ++k) reached += saved[3][k] != r[0].onset[k];
      return reached;
    };
    for (int s = 0; s < 150; ++s) sim.step();
    check_materials();
    int reached = evaluate_both();
    // Weak: on until an evaluation has bonds reaching their strength (batches fall back).
    for (int s = 0; weak && reached == 0 && s < 2000; ++s) {
      sim.step();
      reached = evaluate_both();
    }
    for (int pass = 0; pass < 2; ++pass) {
      SCOPED_TRACE(pass == 0 ? "batches of runs" : "gathered batches");
      // The batches run bond()'s steps lane by lane: the same numbers, bit for bit. (The device
      // path has no batches and adds the node sums atomically: round-off of at most 8 terms.)
      EXPECT_LE(test::max_relative_difference(r[pass].f, r[2].f), test::run_tolerance(1e-14));
      EXPECT_LE(test::max_relative_difference(r[pass].moment, r[2].moment),
                test::run_tolerance(1e-14));
      EXPECT_EQ(test::max_relative_difference(r[pass].fn, r[2].fn), 0.0);
      EXPECT_EQ(test::max_relative_difference(r[pass].fs, r[2].fs), 0.0);
      EXPECT_EQ(r[pass].onset, r[2].onset);
      EXPECT_EQ(r[pass].broken, r[2].broken);
    }
    check_materials();
    if (weak)
      EXPECT_GT(reached, 0);  // not vacuous
    else
      EXPECT_EQ(reached, 0);
  }
}

// A plane-stress Mohr-Coulomb lattice (nu = 0.2) with strengths a few MPa: cohesion 8 MPa,
// friction angle 0.5 rad, tensile strength 2 MPa.
Case weak_mohr_coulomb_lattice(int nx, int ny, double h, double E) {
  Case c = lattice_case(nx, ny, h, E, 0.2, Formulation::plane_stress);
  c.materials[0].model = MaterialModel::mohr_coulomb;
  c.materials[0].cohesion = 8e6;
  c.materials[0].friction_angle = 0.5;
  c.materials[0].tensile_strength = 2e6;
  return c;
}

// compute_cell_stress runs eight cells along a mesh row as one vector cell (CellStress's row
// batches); it must give the stresses and states of the cell-by-cell path. A 37 x 9 lattice (its
// rows hold aligned batches, batches across a row end and a short tail), with a random
// displacement field about the strengths (so cells are below and above them), random strain
// offsets and some cells cracked; the cell list in order, then with its second half reversed
// (every batch there goes cell by cell in the batched run too).
TEST(BondForces, CellStressRowBatchesMatchCellByCell) {
  const int nx = 37, ny = 9;
  const double h = 1e-3, E = 30e9;
  const Case c = weak_mohr_coulomb_lattice(nx, ny, h, E);
  Simulation sim(c);
  Model& m = sim.model();
  ASSERT_EQ(m.converted_count, nx * ny);
  std::srand(11);
  const auto uniform = [] { return std::rand() / static_cast<double>(RAND_MAX); };
  auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), m.nodes.x0);
  const double strain = 5.0 * c.materials[0].tensile_strength / E;  // about the strengths
  for (int n = 0; n < m.nodes.count; ++n) {
    const double x0 = x(n, 0), y0 = x(n, 1);
    x(n, 0) = x0 + strain * (0.5 * x0 - 0.3 * y0 + h * (2 * uniform() - 1));
    x(n, 1) = y0 + strain * (0.2 * x0 + 0.4 * y0 + h * (2 * uniform() - 1));
  }
  Kokkos::deep_copy(m.nodes.x, x);
  // A scene that cannot convert holds no offsets (build_lattice): given here, to be read.
  if (m.elements.cell_strain_offset.extent(0) == 0)
    m.elements.cell_strain_offset = View<double* [3]>("offset", m.elements.count);
  auto offset = Kokkos::create_mirror_view(m.elements.cell_strain_offset);
  auto cracked = Kokkos::create_mirror_view(m.elements.cell_cracked);
  for (int e = 0; e < m.elements.count; ++e) {
    for (int k = 0; k < 3; ++k) offset(e, k) = 0.3 * strain * (2 * uniform() - 1);
    cracked(e) = uniform() < 0.1;
  }
  Kokkos::deep_copy(m.elements.cell_strain_offset, offset);
  Kokkos::deep_copy(m.elements.cell_cracked, cracked);

  auto list = Kokkos::create_mirror_view_and_copy(HostSpace(), m.converted);
  const auto connectivity = Kokkos::create_mirror_view_and_copy(HostSpace(), m.elements.nodes);
  for (bool reversed : {false, true}) {
    SCOPED_TRACE(reversed ? "second half of the list reversed" : "list in order");
    if (reversed)
      std::reverse(list.data() + m.converted_count / 2, list.data() + m.converted_count);
    View<int*> cells("cells", m.converted_count);
    Kokkos::deep_copy(cells, list);
    // Batches the vector path takes (kLanes = 8 on this build; 1: none, all cell by cell).
    int row_batches = 0;
    for (int first = 0; kLanes > 1 && first + 8 <= m.converted_count; first += 8) {
      int node[4][8];
      bool consecutive = true;
      for (int l = 0; l < 8; ++l) {
        consecutive = consecutive && list(first + l) == list(first) + l;
        for (int a = 0; a < 4; ++a) node[a][l] = connectivity(list(first + l), a);
      }
      row_batches += consecutive && structured_row<8>(node);
    }
    if (kLanes > 1) {
      EXPECT_GE(row_batches, reversed ? 10 : 30);
    }
    // Pass 0 with the row batches, pass 1 cell by cell.
    // (Copies: a host mirror view of a host view is the view itself.)
    decltype(Kokkos::create_mirror(HostSpace(), m.elements.cell_stress)) stress[2];
    decltype(Kokkos::create_mirror(HostSpace(), m.elements.cell_state)) state[2];
    for (int pass = 0; pass < 2; ++pass) {
      Kokkos::deep_copy(m.elements.cell_stress, 0.0);
      Kokkos::deep_copy(m.elements.cell_state, -1);
      compute_cell_stress(cells, m.converted_count, m.lattice_stiffness, m.bond_laws, m.elements,
                          m.nodes, true, pass == 0);
      stress[pass] = Kokkos::create_mirror(HostSpace(), m.elements.cell_stress);
      state[pass] = Kokkos::create_mirror(HostSpace(), m.elements.cell_state);
      Kokkos::deep_copy(stress[pass], m.elements.cell_stress);
      Kokkos::deep_copy(state[pass], m.elements.cell_state);
    }
    int counts[3] = {0, 0, 0};
    for (int e = 0; e < m.elements.count; ++e) {
      for (int k = 0; k < 3; ++k)
        EXPECT_NEAR(stress[0](e, k), stress[1](e, k), 1e-13 * E * strain)
            << "cell " << e << " component " << k;
      EXPECT_EQ(state[0](e), state[1](e)) << "cell " << e;
      ASSERT_GE(state[1](e), 0);
      ASSERT_LT(state[1](e), 3);
      ++counts[state[1](e)];
    }
    // Not vacuous: all three states occur.
    EXPECT_GT(counts[kCellIntact], 0);
    EXPECT_GT(counts[kCellBelowStrength], 0);
    EXPECT_GT(counts[kCellCracked], 0);
  }
}

// compute_cell_stress marks a cell kCellBelowStrength only if no face through it is at its
// strength, and the bond kernels then skip its bonds' failure check: a face at its strength
// hidden there would be a missed fracture. Homogeneous random strains (stresses from a tenth to
// three times the strengths, all orientations, tension and compression) on a Mohr-Coulomb
// lattice: for every cell so marked, its stress is checked on 720 face orientations (the
// lattice's faces among them); a cell with a face at its strength must not be marked. The bound
// must not be vacuous either: most cells well below the strength are marked.
TEST(BondForces, CellsBelowStrengthHaveNoFaceAtStrength) {
  // 20 x 3 cells: most batches of eight run as vector row batches (CellStress), some cell by cell.
  const Case c = weak_mohr_coulomb_lattice(20, 3, 1e-3, 30e9);
  Simulation sim(c);
  Model& m = sim.model();
  const auto law = Kokkos::create_mirror_view_and_copy(HostSpace(), m.bond_laws)(0);
  auto x0 = Kokkos::create_mirror_view_and_copy(HostSpace(), m.nodes.x0);
  auto x = Kokkos::create_mirror_view(m.nodes.x);
  const double pi = std::acos(-1.0);
  const auto at_strength = [&](double sxx, double syy, double sxy) {
    for (int a = 0; a < 720; ++a) {
      const double nx = std::cos(a * pi / 720), ny = std::sin(a * pi / 720);
      const double sigma = sxx * nx * nx + syy * ny * ny + 2.0 * sxy * nx * ny;
      const double tau = std::fabs(-(sxx * nx + sxy * ny) * ny + (sxy * nx + syy * ny) * nx);
      if (sigma >= law.tensile_strength || tau >= law.cohesion - sigma * law.tan_friction)
        return true;
    }
    return false;
  };
  std::srand(7);
  const auto uniform = [] { return std::rand() / static_cast<double>(RAND_MAX); };
  int marked = 0, far_below = 0, far_below_marked = 0, at = 0;
  const double E = 30e9, nu = 0.2;
  for (int trial = 0; trial < 800; ++trial) {
    double exx, eyy, exy;
    if (trial < 400) {
      // Strain of size s: a stress of about E s.
      const double size = (0.1 + 2.9 * uniform()) * law.tensile_strength / E *
                          (trial % 2 ? 1.0 : law.cohesion / law.tensile_strength);
      exx = size * (2 * uniform() - 1);
      eyy = size * (2 * uniform() - 1);
      exy = size * (2 * uniform() - 1);
    } else {
      // Near the envelope: a Mohr circle (centre C, radius R, random orientation) whose
      // largest principal stress (odd trials) or largest tau + sigma tan(phi) (even trials) is
      // within 3% of the strength; the strain of that plane stress (Hooke, as the lattice).
      const double centre = -30e6 * uniform(), factor = 0.97 + 0.06 * uniform();
      const double secant = std::sqrt(1.0 + law.tan_friction * law.tan_friction);
      const double radius = trial % 2
                                ? factor * law.tensile_strength - centre
                                : factor * (law.cohesion - centre * law.tan_friction) / secant;
      const double angle = pi * uniform();
      const double sxx = centre + radius * std::cos(2 * angle),
                   syy = centre - radius * std::cos(2 * angle), sxy = radius * std::sin(2 * angle);
      exx = (sxx - nu * syy) / E;
      eyy = (syy - nu * sxx) / E;
      exy = (1.0 + nu) / E * sxy;
    }
    for (int n = 0; n < m.nodes.count; ++n) {
      x(n, 0) = x0(n, 0) + exx * x0(n, 0) + exy * x0(n, 1);
      x(n, 1) = x0(n, 1) + exy * x0(n, 0) + eyy * x0(n, 1);
    }
    Kokkos::deep_copy(m.nodes.x, x);
    compute_cell_stress(m.converted, m.converted_count, m.lattice_stiffness, m.bond_laws,
                        m.elements, m.nodes);
    const auto stress = Kokkos::create_mirror_view_and_copy(HostSpace(), m.elements.cell_stress);
    const auto state = Kokkos::create_mirror_view_and_copy(HostSpace(), m.elements.cell_state);
    for (int e = 0; e < m.elements.count; ++e) {
      ASSERT_NE(state(e), kCellCracked);
      const bool reached = at_strength(stress(e, 0), stress(e, 1), stress(e, 2));
      const bool below = state(e) == kCellBelowStrength;
      if (below) {
        EXPECT_FALSE(reached) << "trial " << trial << " cell " << e;
      }
      marked += below;
      at += reached;
      // Far below: no face above 90% of the strength (the strengths scaled by 0.9).
      const double s[3] = {stress(e, 0) / 0.9, stress(e, 1) / 0.9, stress(e, 2) / 0.9};
      if (!at_strength(s[0], s[1], s[2])) {
        ++far_below;
        far_below_marked += below;
      }
    }
  }
  EXPECT_GT(marked, 0);
  EXPECT_GT(at, 0);  // the trials reach the strength too
  EXPECT_GT(far_below, 0);
  EXPECT_GT(far_below_marked, 0.5 * far_below);
}

// A softening bond whose damage rounds to 1 short of lambda_f breaks. With lambda_f / lambda_0
// vast, 1 - D ~ lambda_0 / lambda drops below half an ulp once lambda passes about 2^53
// lambda_0: in the glass plate at Weibull modulus 3 (cases/validation/ha_bobaru_plate.toml,
// weibull_modulus = 3), an edge bond of strength factor 0.033 met its strength through its
// cells' Poisson stress while its own springs held fn = 0 and a shear force of rounding size
// (1.5e-27 N), so it softened from lambda_0 = 1.85e-25 m towards lambda_f = 7.6e20 m; at
// lambda ~ 1e-9 m D rounded to 1, and left active the bond's next step recovered its undamaged
// shear force as 0 / 0: NaN forces and energies, then "time step collapsed" at step 781. Here
// one edge bond of a small cohesive block is given such an onset (1e-25 m, 1e20 m) and stretched
// by 10 nm (lambda / lambda_0 = 1e17, D = 1 exactly): it must break, and the run stay finite.
TEST(BondForces, BondWhoseDamageRoundsToOneBreaks) {
  const double h = 1e-3;
  Case c = test::rectangle_case(2, 1, h, 72e9, 0.25, 2440.0, Formulation::plane_stress);
  c.bodies[0].method = BodyMethod::de;
  c.materials[0].tensile_strength = 30e6;
  c.materials[0].fracture_energy = 3.8;
  c.sim.end_time = 1.0;
  Simulation sim(c);
  Model& m = sim.model();
  Bonds& bonds = m.bonds;
  const auto ends = Kokkos::create_mirror_view_and_copy(HostSpace(), bonds.nodes);
  const auto state = Kokkos::create_mirror_view_and_copy(HostSpace(), bonds.state);
  const auto ks = Kokkos::create_mirror_view_and_copy(HostSpace(), bonds.ks);
  const auto x0 = Kokkos::create_mirror_view_and_copy(HostSpace(), m.nodes.x0);
  int b = -1;  // an active edge bond with a shear spring, along x
  for (int k = 0; k < bonds.count && b < 0; ++k)
    if (state(k) == kBondActive && ks(k) > 0.0 && x0(ends(k, 0), 1) == x0(ends(k, 1), 1)) b = k;
  ASSERT_GE(b, 0);
  const auto onset = Kokkos::create_mirror_view_and_copy(HostSpace(), bonds.onset_separation);
  const auto final_separation =
      Kokkos::create_mirror_view_and_copy(HostSpace(), bonds.final_separation);
  onset(b) = 1e-25;
  final_separation(b) = 1e20;
  Kokkos::deep_copy(bonds.onset_separation, onset);
  Kokkos::deep_copy(bonds.final_separation, final_separation);
  auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), m.nodes.x);
  const int j = x0(ends(b, 1), 0) > x0(ends(b, 0), 0) ? ends(b, 1) : ends(b, 0);
  x(j, 0) += 1e-8;  // away from the other end
  Kokkos::deep_copy(m.nodes.x, x);
  for (int step = 0; step < 3; ++step) sim.step();
  ASSERT_FALSE(sim.failed()) << sim.failure();
  Kokkos::deep_copy(state, bonds.state);
  EXPECT_EQ(state(b), kBondBroken);
  const HistoryRecord r = sim.history();
  EXPECT_TRUE(std::isfinite(r.energy.fracture));
  EXPECT_TRUE(std::isfinite(r.energy.kinetic));
  Kokkos::deep_copy(x, m.nodes.x);
  for (int n = 0; n < m.nodes.count; ++n)
    EXPECT_TRUE(std::isfinite(x(n, 0)) && std::isfinite(x(n, 1))) << "disc " << n;
}

}  // namespace
}  // namespace fracta
