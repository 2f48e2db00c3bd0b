// Adaptive FE-to-DE conversion (docs/physics.md 1.3): the compaction, and what a conversion may and
// may not change.
#include <gtest/gtest.h>

#include <cmath>

#include "host/simulation.hpp"
#include "kernels/conversion.hpp"
#include "test_util.hpp"

namespace fracta {
namespace {

Case adaptive_case(int nx, int ny, double h, Formulation f = Formulation::plane_stress) {
  Case c = test::rectangle_case(nx, ny, h, 200e9, 0.3, 7800.0, f);
  c.bodies[0].method = BodyMethod::adaptive;
  c.materials[0].conversion_strain = 0.5;
  c.sim.end_time = 1.0;
  return c;
}

// Marks elements for conversion by giving them the conversion strain.
void mark(Simulation& sim, const std::vector<int>& elements) {
  auto ep = Kokkos::create_mirror_view_and_copy(HostSpace(), sim.model().elements.epeq);
  for (int e : elements) ep(e) = 0.5;
  Kokkos::deep_copy(sim.model().elements.epeq, ep);
}

std::vector<int> active_host(const Elements& el) {
  auto a = Kokkos::create_mirror_view_and_copy(HostSpace(), el.active);
  return std::vector<int>(a.data(), a.data() + el.active_count);
}

// Compaction edge cases (Cabana tstRemove style): nothing, every other, everything, and an empty
// active list; the survivors keep their order and the converted list follows the old order.
TEST(Conversion, CompactionEdgeCases) {
  for (int pattern = 0; pattern < 4; ++pattern) {
    Simulation sim(adaptive_case(5, 4, 1e-3));
    Model& m = sim.model();
    View<int*> cells_out("cells_out", m.elements.count);  // the converted cells, in order
    std::vector<int> marked, kept;
    for (int e = 0; e < 20; ++e) {
      const bool convert = pattern == 1 ? e % 2 == 0 : pattern >= 2;
      (convert ? marked : kept).push_back(e);
    }
    mark(sim, marked);
    if (pattern == 3) {  // empty list: convert everything first, then compact again
      compact_converted(m.elements, m.element_adaptive, m.materials, false, cells_out,
                        m.active_scratch);
    }
    const int n = compact_converted(m.elements, m.element_adaptive, m.materials, false, cells_out,
                                    m.active_scratch);
    EXPECT_EQ(n, pattern == 3 ? 0 : static_cast<int>(marked.size()));
    EXPECT_EQ(active_host(m.elements), pattern == 3 ? std::vector<int>{} : kept);
    auto cells = Kokkos::create_mirror_view_and_copy(HostSpace(), cells_out);
    if (pattern != 3) {
      for (int k = 0; k < n; ++k) EXPECT_EQ(cells(k), marked[k]);
    }
  }
}

// The conversion from the FE kernel's candidates (compact_candidates) gives the sweep's lists,
// whatever the candidates' order, duplicates and false alarms, on the same edge cases.
TEST(Conversion, CandidateCompactionMatchesTheSweep) {
  for (int pattern = 0; pattern < 4; ++pattern) {
    std::vector<int> expected_active, expected_cells;
    for (int run = 0; run < 2; ++run) {
      Simulation sim(adaptive_case(5, 4, 1e-3));
      Model& m = sim.model();
      View<int*> cells_out("cells_out", m.elements.count);  // the converted cells, in order
      std::vector<int> marked;
      for (int e = 0; e < 20; ++e)
        if (pattern == 1 ? e % 2 == 0 : pattern >= 2) marked.push_back(e);
      mark(sim, marked);
      if (pattern == 3)  // empty list: convert everything first
        compact_converted(m.elements, m.element_adaptive, m.materials, false, cells_out,
                          m.active_scratch);
      int n = 0;
      if (run == 0) {
        n = compact_converted(m.elements, m.element_adaptive, m.materials, false, cells_out,
                              m.active_scratch);
      } else {
        // Every position in reverse order, the marked ones twice, and an out-of-range one.
        std::vector<int> cand;
        for (int i = 19; i >= 0; --i) cand.push_back(i);
        for (int e : marked) cand.push_back(e);
        cand.push_back(25);
        View<int*> candidates("candidates", cand.size());
        auto h = Kokkos::create_mirror_view(candidates);
        for (size_t k = 0; k < cand.size(); ++k) h(k) = cand[k];
        Kokkos::deep_copy(candidates, h);
        View<int*> keep("keep", cand.size()), sorted("sorted", cand.size());
        n = compact_candidates(m.elements, m.element_adaptive, m.materials, false, candidates,
                               static_cast<int>(cand.size()), keep, sorted, cells_out,
                               m.active_scratch);
      }
      auto cells = Kokkos::create_mirror_view_and_copy(HostSpace(), cells_out);
      const std::vector<int> new_cells(cells.data(), cells.data() + n);
      if (run == 0) {
        expected_active = active_host(m.elements);
        expected_cells = new_cells;
      } else {
        EXPECT_EQ(active_host(m.elements), expected_active) << "pattern " << pattern;
        EXPECT_EQ(new_cells, expected_cells) << "pattern " << pattern;
      }
    }
  }
}

// The spin of a new disc is the mean rotation rate of the cells of its batch around it,
// whatever the order of the batch (a race before: each cell wrote its own rate to the shared
// discs, the last writer won). Velocity field v = (-c y^2, c x^2): the Q4 gradient at the centre
// of a rectangular cell is exact for it, w = (dvy/dx - dvx/dy) / 2 = c (x_c + y_c). Cells 0, 1
// and 4 of a 3 x 2 block convert (3 stays alive); the disc at (h, h) touches 0, 1 and 4.
TEST(Conversion, NewDiscSpinIsTheMeanRateOfItsBatchCells) {
  const double h = 1e-3, c = 2e5;  // 1/(m s)
  Simulation sim(adaptive_case(3, 2, h));
  Model& m = sim.model();
  Nodes& nodes = m.nodes;
  auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), nodes.x);
  auto v = Kokkos::create_mirror_view_and_copy(HostSpace(), nodes.v);
  for (int n = 0; n < nodes.count; ++n) {
    v(n, 0) = -c * x(n, 1) * x(n, 1);
    v(n, 1) = c * x(n, 0) * x(n, 0);
  }
  Kokkos::deep_copy(nodes.v, v);
  const std::vector<int> batch{0, 1, 4};
  auto alive = Kokkos::create_mirror_view_and_copy(HostSpace(), m.elements.alive);
  for (int e : batch) alive(e) = 0;
  Kokkos::deep_copy(m.elements.alive, alive);
  // Expected: per node, the mean of c (x_c + y_c) over the batch cells that hold it.
  auto en = Kokkos::create_mirror_view_and_copy(HostSpace(), m.elements.nodes);
  std::vector<double> w_sum(nodes.count, 0.0);
  std::vector<int> cells_of(nodes.count, 0);
  for (int e : batch) {
    double xc = 0.0, yc = 0.0;
    for (int a = 0; a < 4; ++a) {
      xc += 0.25 * x(en(e, a), 0);
      yc += 0.25 * x(en(e, a), 1);
    }
    for (int a = 0; a < 4; ++a) {
      w_sum[en(e, a)] += c * (xc + yc);
      ++cells_of[en(e, a)];
    }
  }
  int shared_by_three = 0;
  for (int n = 0; n < nodes.count; ++n) shared_by_three += cells_of[n] == 3;
  ASSERT_EQ(shared_by_three, 1);
  std::vector<std::vector<double>> spins;
  for (const std::vector<int>& order : {batch, std::vector<int>{4, 1, 0}}) {
    Kokkos::deep_copy(nodes.spin, 0.0);
    View<int*> cells("cells", order.size());
    auto ch = Kokkos::create_mirror_view(cells);
    for (size_t k = 0; k < order.size(); ++k) ch(k) = order[k];
    Kokkos::deep_copy(cells, ch);
    prestress_converted_bonds(cells, static_cast<int>(order.size()), m.element_bonds,
                              m.lattice_stiffness, m.elements, nodes, m.bonds, m.topology);
    auto spin = Kokkos::create_mirror_view_and_copy(HostSpace(), nodes.spin);
    spins.emplace_back(spin.data(), spin.data() + nodes.count);
    for (int n = 0; n < nodes.count; ++n) {
      const double expected = cells_of[n] > 0 ? w_sum[n] / cells_of[n] : 0.0;
      EXPECT_NEAR(spins.back()[n], expected, 1e-12 * c * 6 * h) << "node " << n;
    }
  }
  EXPECT_EQ(spins[0], spins[1]);  // bitwise: the sum runs in the topology's order
}

// The lists of used bond slots and of particles (state.hpp) equal their definitions after
// conversions by insertion (small batches) and by rebuilding (a batch beyond the work space).
TEST(Conversion, BondAndParticleListsFollowTheStates) {
  Case c = adaptive_case(20, 12, 1e-3);
  test::add_pressure(c, test::segment(0, 0, 0, 12e-3), {0.0, 1e-6, 1e-6}, {300e6, 300e6, 0.0});
  Simulation sim(c);
  const Model& m = sim.model();
  auto check = [&](const char* when) {
    auto state = Kokkos::create_mirror_view_and_copy(HostSpace(), m.bonds.state);
    auto particle = Kokkos::create_mirror_view_and_copy(HostSpace(), m.nodes.particle);
    auto used = Kokkos::create_mirror_view_and_copy(HostSpace(), m.bonds.used);
    auto list = Kokkos::create_mirror_view_and_copy(HostSpace(), m.nodes.particle_list);
    std::vector<int> want_used, want_particles;
    for (int b = 0; b < m.bonds.count; ++b)
      if (state(b) != kBondInactive) want_used.push_back(b);
    for (int n = 0; n < m.nodes.count; ++n)
      if (particle(n)) want_particles.push_back(n);
    EXPECT_EQ(std::vector<int>(used.data(), used.data() + m.bonds.used_count), want_used) << when;
    EXPECT_EQ(std::vector<int>(list.data(), list.data() + m.nodes.particle_count), want_particles)
        << when;
  };
  check("at start");
  for (int s = 0; s < 10; ++s) sim.step();
  mark(sim, {3, 4, 23, 24, 100});
  sim.step();
  EXPECT_EQ(sim.conversions(), 5);
  check("after a small batch");
  mark(sim, {5, 44});  // next to converted cells: shared slots and nodes
  sim.step();
  check("after a second batch");
  std::vector<int> many;
  for (int e = 110; e < 240; ++e) many.push_back(e);
  for (int e = 0; e < 100; e += 2) many.push_back(e);  // 3 of them converted already
  mark(sim, many);
  sim.step();
  EXPECT_GT(6 * static_cast<int>(sim.conversions() - 7), ListWorkspace::kCapacity);
  check("after a large batch");
}

// Conversion during a run changes neither the total mass nor the linear momentum (the node
// velocities are untouched): 1e-12 relative, i.e. round-off of the sums.
TEST(Conversion, ConservesMassAndMomentum) {
  Case c = adaptive_case(8, 6, 1e-3);
  c.bodies[0].initial_velocity = {35.0, -12.0};
  test::add_pressure(c, test::segment(0, 0, 0, 6e-3), {0.0, 1e-6, 1e-6}, {300e6, 300e6, 0.0});
  Simulation sim(c);
  for (int s = 0; s < 30; ++s) sim.step();  // a stressed, moving body (load is off by now)
  const HistoryRecord before = sim.history();
  mark(sim, {3, 4, 11, 12, 19, 20, 27, 28});
  sim.step();
  EXPECT_EQ(sim.conversions(), 8);
  const HistoryRecord after = sim.history();
  EXPECT_NEAR(after.mass, before.mass, 1e-12 * before.mass);
  EXPECT_NEAR(after.momentum_x, before.momentum_x, 1e-12 * std::fabs(before.momentum_x));
  EXPECT_NEAR(after.momentum_y, before.momentum_y, 1e-12 * std::fabs(before.momentum_y));
  EXPECT_EQ(after.count.elements, 48 - 8);
  EXPECT_GT(after.count.bonds, 0);
}

// An element converted in a stress-free state changes nothing: no force, no motion, no energy.
TEST(Conversion, StressFreeConversionChangesNothing) {
  Simulation sim(adaptive_case(4, 4, 1e-3));
  mark(sim, {0, 5, 10, 15});
  for (int s = 0; s < 50; ++s) sim.step();
  EXPECT_EQ(sim.conversions(), 4);
  const HistoryRecord h = sim.history();
  EXPECT_EQ(h.energy.kinetic, 0.0);
  EXPECT_EQ(h.energy.internal, 0.0);
  EXPECT_EQ(h.energy.conversion, 0.0);
}

// A body in uniform static stress (strain imposed in one step, then held by tractions equal to
// the stress on all four faces) converts its central elements: the bonds take over the stress
// with their initial forces, so no wave is released. Probe velocities stay below 1% of the
// particle velocity sigma / (rho c) that the same stress would drive as a wave. Steel (nu = 0.3)
// in plane stress (pair springs) and in plane strain (nu* = 0.43: pair springs and the
// volumetric cell term, which must take its share of the stress too).
void prestressed_conversion(Formulation f) {
  SCOPED_TRACE(to_string(f));
  const bool strain = f == Formulation::plane_strain;
  const double h = 1e-3, rho = 7800;
  const double E = strain ? 200e9 / (1 - 0.3 * 0.3) : 200e9, nu = strain ? 0.3 / 0.7 : 0.3;
  const int n = 12;
  const double L = n * h;
  Case c = adaptive_case(n, n, h, f);
  const double exx = 1e-4, eyy = -0.5e-4, exy = 0.3e-4;
  const double k = E / (1 - nu * nu);  // in-plane constants (E*, nu* in plane strain)
  const double sxx = k * (exx + nu * eyy), syy = k * (eyy + nu * exx), sxy = E / (1 + nu) * exy;
  c.sim.dt = 0.5 * Simulation(c).stable_dt_bound();
  // Tractions sigma.n on each face, switched on at half the first step: the first half kick
  // (forces at t = 0) sees none, the forces at t = dt balance the imposed stress.
  using test::segment;
  const std::vector<double> on{0.0, 0.5 * c.sim.dt, 0.5 * c.sim.dt};
  auto face = [&](const Segment& s, double tx, double ty) {
    const double mag = std::hypot(tx, ty);
    test::add_traction(c, s, {tx / mag, ty / mag}, on, {0.0, 0.0, mag});
  };
  face(segment(L, 0, L, L), sxx, sxy);
  face(segment(0, 0, 0, L), -sxx, -sxy);
  face(segment(0, L, L, L), sxy, syy);
  face(segment(0, 0, L, 0), -sxy, -syy);
  Simulation sim(c);
  Nodes& nodes = sim.model().nodes;
  const double dt = sim.dt();
  {
    auto x0 = Kokkos::create_mirror_view_and_copy(HostSpace(), nodes.x0);
    auto v = Kokkos::create_mirror_view_and_copy(HostSpace(), nodes.v);
    for (int i = 0; i < nodes.count; ++i) {
      v(i, 0) = (exx * x0(i, 0) + exy * x0(i, 1)) / dt;
      v(i, 1) = (exy * x0(i, 0) + eyy * x0(i, 1)) / dt;
    }
    Kokkos::deep_copy(nodes.v, v);
  }
  sim.step();                       // imposes the strain; the FE stress is C : eps
  Kokkos::deep_copy(nodes.v, 0.0);  // and now at rest, in equilibrium with the tractions
  std::vector<int> centre;
  for (int j = 3; j < 9; ++j)
    for (int i = 3; i < 9; ++i) centre.push_back(j * n + i);
  mark(sim, centre);
  double vmax = 0;
  for (int s = 0; s < 300; ++s) {
    sim.step();
    auto v = Kokkos::create_mirror_view_and_copy(HostSpace(), nodes.v);
    for (int i = 0; i < nodes.count; ++i)
      vmax = std::max({vmax, std::fabs(v(i, 0)), std::fabs(v(i, 1))});
  }
  EXPECT_EQ(sim.conversions(), 36);
  const double v_wave = std::max(std::fabs(sxx), std::fabs(syy)) / (rho * std::sqrt(k / rho));
  EXPECT_LT(vmax, 0.01 * v_wave);
  ::testing::Test::RecordProperty(std::string("max_velocity_over_wave_velocity_") + to_string(f),
                                  std::to_string(vmax / v_wave));
  // The bonds hold the element's energy: the conversion term is small against it.
  const HistoryRecord hr = sim.history();
  ::testing::Test::RecordProperty(std::string("conversion_energy_over_internal_") + to_string(f),
                                  std::to_string(hr.energy.conversion / hr.energy.internal));
}

// Distortion (conversion_length_ratio, default 0.3): an elastic adaptive block, whose elements
// never reach a conversion strain, has the top row of nodes moved down in one step by 0.8 of a
// cell on the left half and 0.7 on the right. An element converts exactly when its
// characteristic length 1/sqrt(sum b.b) of the centre gradients is below 0.3 of its initial
// one, computed here on the host from the positions (exact: the criterion's definition; a
// squashed square of side h to height 0.2 h has 0.277, to 0.3 h 0.406).
TEST(Conversion, DistortedElementsConvertWhateverTheirMaterial) {
  const double h = 1e-3;
  const int n = 8;
  Case c = adaptive_case(n, n, h);
  c.materials[0].conversion_length_ratio = kDefaultConversionLengthRatio;
  c.sim.dt = 0.5 * Simulation(c).stable_dt_bound();
  Simulation sim(c);
  Nodes& nodes = sim.model().nodes;
  auto x0 = Kokkos::create_mirror_view_and_copy(HostSpace(), nodes.x0);
  {
    auto v = Kokkos::create_mirror_view_and_copy(HostSpace(), nodes.v);
    for (int i = 0; i < nodes.count; ++i)
      if (x0(i, 1) > n * h - 1e-9) v(i, 1) = -(x0(i, 0) < 0.5 * n * h ? 0.8 : 0.7) * h / sim.dt();
    Kokkos::deep_copy(nodes.v, v);
  }
  sim.step();
  const auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), nodes.x);
  const auto alive = Kokkos::create_mirror_view_and_copy(HostSpace(), sim.model().elements.alive);
  const auto corners = Kokkos::create_mirror_view_and_copy(HostSpace(), sim.model().elements.nodes);
  auto length = [&](const auto& p, int e) {
    double px[4], py[4];
    for (int a = 0; a < 4; ++a) px[a] = p(corners(e, a), 0), py[a] = p(corners(e, a), 1);
    const double A = 0.5 * ((px[2] - px[0]) * (py[3] - py[1]) + (px[1] - px[3]) * (py[2] - py[0]));
    double b2 = 0;
    for (int a = 0; a < 4; ++a) {
      const double bx = (py[(a + 1) % 4] - py[(a + 3) % 4]) / (2 * A);
      const double by = (px[(a + 3) % 4] - px[(a + 1) % 4]) / (2 * A);
      b2 += bx * bx + by * by;
    }
    return 1.0 / std::sqrt(b2);
  };
  int converted = 0, kept = 0;
  for (int e = 0; e < sim.model().elements.count; ++e) {
    const double ratio = length(x, e) / length(x0, e);
    ASSERT_GT(std::fabs(ratio - 0.3), 0.01) << "element " << e << " too close to the limit";
    EXPECT_EQ(alive(e) == 0, ratio < 0.3) << "element " << e << ", length ratio " << ratio;
    (ratio < 0.3 ? converted : kept) += 1;
  }
  // The left half of the top row, but for its last element, whose right corners moved 0.7 h.
  EXPECT_EQ(converted, n / 2 - 1);
  EXPECT_EQ(sim.conversions(), converted);
  EXPECT_GT(kept, 0);
}

TEST(Conversion, PrestressedConversionReleasesNoWave) {
  prestressed_conversion(Formulation::plane_stress);
  prestressed_conversion(Formulation::plane_strain);
}

}  // namespace
}  // namespace fracta

namespace fracta {
namespace {

// Everything converting: a Mohr-Coulomb block (plane strain, nu = 0.21) hit by a strong pulse
// with a tiny conversion strain, so the yield front converts every element as it sweeps
// through. The run must reach its end without NaN, leave no FE element, and close the energy
// balance (plastic, conversion, fracture, contact terms included) within 2% (a fragmenting
// run's contact and conversion terms are O(dt) accurate).
TEST(Conversion, EverythingConvertsAndBalanceCloses) {
  const double h = 1e-3;
  const int nx = 16, ny = 8;
  Case c = test::rectangle_case(nx, ny, h, 92e9, 0.21, 2400.0, Formulation::plane_strain);
  c.bodies[0].method = BodyMethod::adaptive;
  Region strip;  // a de part from the start: the active list starts shorter than the mesh
  strip.method = BodyMethod::de;
  strip.shape.x = 12 * h;
  strip.shape.width = 4 * h;
  strip.shape.height = ny * h;
  c.bodies[0].regions.push_back(strip);
  test::make_quickly_converting_concrete(c.materials[0]);
  test::add_pressure(c, test::segment(0, 0, 0, ny * h), {0.0, 4e-6, 4e-6}, {400e6, 400e6, 0.0});
  c.sim.end_time = 30e-6;
  Simulation sim(c);
  const double worst = test::run_to_end(sim);
  ASSERT_FALSE(sim.failed()) << sim.failure();
  const HistoryRecord end = sim.history();
  EXPECT_EQ(end.count.elements, 0);
  EXPECT_EQ(sim.conversions(), nx * ny - 4 * ny);  // all but the de strip, converted at t = 0
  EXPECT_TRUE(std::isfinite(end.energy.kinetic));
  EXPECT_LT(worst, 0.02);
  RecordProperty("worst_energy_error", std::to_string(worst));
  RecordProperty("conversion_energy_over_external",
                 std::to_string(end.energy.conversion / end.energy.external));
}

// A 4 x 4 adaptive block of the Holmquist-Johnson-Cook 48 MPa concrete (Holmquist, Johnson &
// Cook 1993) converting at damage 1 only.
Case hjc_adaptive_case() {
  Case c = adaptive_case(4, 4, 1e-3, Formulation::plane_strain);
  Material& m = c.materials[0];
  m.model = MaterialModel::hjc;
  m.density = 2440.0;
  m.hjc = HjcParams{0.79, 1.60, 0.61, 0.007, 48e6,  7.0,  4e6,  1.0,    0.04,
                    1.0,  0.01, 16e6, 0.001, 0.8e9, 0.10, 85e9, -171e9, 208e9};
  const double K = 16e9, G = 14.86e9;
  m.youngs_modulus = 9 * K * G / (3 * K + G);
  m.poisson_ratio = (3 * K - 2 * G) / (2 * (3 * K + G));
  m.tensile_strength = 4e6;
  m.conversion_strain = 1e300;
  m.conversion_damage = 1.0;
  return c;
}

// An adaptive hjc body converts an element when a point's damage reaches the material's
// conversion_damage (exact: the damage is set by hand, so the answer is known), and not by the
// principal-stress tension criterion, which hjc replaces by its damage: both through the sweep
// (compact_converted) and through a step (the element kernel's flags).
TEST(Conversion, HjcElementsConvertAtTheirConversionDamageOnly) {
  Case c = hjc_adaptive_case();
  c.sim.conversion_on_tension = true;
  for (const bool through_step : {false, true}) {
    Simulation sim(c);
    Model& model = sim.model();
    ASSERT_EQ(model.elements.law_state.extent(0), 16u);
    auto state = Kokkos::create_mirror_view_and_copy(HostSpace(), model.elements.law_state);
    state(5, kLawDamage) = 1.0;
    state(6, kLawDamage) = 0.99;
    state(9, kLawDamage) = 1.0;
    Kokkos::deep_copy(model.elements.law_state, state);
    // Element 10: a principal stress of 3 T, which converts a mohr_coulomb element by tension.
    auto stress = Kokkos::create_mirror_view_and_copy(HostSpace(), model.elements.stress);
    stress(10, 0) = 12e6;
    Kokkos::deep_copy(model.elements.stress, stress);
    if (through_step) {
      sim.step();
      EXPECT_EQ(sim.conversions(), 2);
    } else {
      const View<int*> cells_out("cells_out", model.elements.count);
      EXPECT_EQ(compact_converted(model.elements, model.element_adaptive, model.materials, true,
                                  cells_out, model.active_scratch),
                2);
    }
    const auto alive = Kokkos::create_mirror_view_and_copy(HostSpace(), model.elements.alive);
    for (int e = 0; e < 16; ++e) EXPECT_EQ(alive(e) == 0, e == 5 || e == 9) << "element " << e;
  }
}

// Exact (the model's own rule, docs/physics.md 1.3): a cell whose material has failed (hjc
// damage 1) has no cohesion, so its discs are born unbonded: every slot of the two converted
// cells (5 and 9, sharing an edge) is broken with no force, the cells are cracked (their own
// terms never act), their nodes are discs, no slot of the lattice is active, and the nodes keep
// their masses. On one and two threads alike (the slots the two cells share are written by both).
TEST(Conversion, FailedHjcCellsConvertToUnbondedDiscs) {
  Case c = hjc_adaptive_case();
  Simulation sim(c);
  Model& model = sim.model();
  const auto mass_before = Kokkos::create_mirror_view_and_copy(HostSpace(), model.nodes.mass);
  auto state = Kokkos::create_mirror_view_and_copy(HostSpace(), model.elements.law_state);
  state(5, kLawDamage) = 1.0;
  state(9, kLawDamage) = 1.0;
  Kokkos::deep_copy(model.elements.law_state, state);
  sim.step();
  ASSERT_EQ(sim.conversions(), 2);
  const auto slots = Kokkos::create_mirror_view_and_copy(HostSpace(), model.element_bonds);
  const auto bond_state = Kokkos::create_mirror_view_and_copy(HostSpace(), model.bonds.state);
  const auto fn = Kokkos::create_mirror_view_and_copy(HostSpace(), model.bonds.fn);
  const auto cracked =
      Kokkos::create_mirror_view_and_copy(HostSpace(), model.elements.cell_cracked);
  const auto particle = Kokkos::create_mirror_view_and_copy(HostSpace(), model.nodes.particle);
  const auto corners = Kokkos::create_mirror_view_and_copy(HostSpace(), model.elements.nodes);
  const auto mass = Kokkos::create_mirror_view_and_copy(HostSpace(), model.nodes.mass);
  int broken = 0;
  for (const int e : {5, 9}) {
    EXPECT_EQ(cracked(e), 1) << "cell " << e;
    for (int a = 0; a < 6; ++a) {
      const int b = slots(e, a);
      if (b < 0) continue;
      EXPECT_EQ(bond_state(b), int{kBondBroken}) << "cell " << e << " slot " << a;
      EXPECT_EQ(fn(b), 0.0);
      ++broken;
    }
    for (int a = 0; a < 4; ++a) EXPECT_EQ(particle(corners(e, a)), 1);
  }
  EXPECT_EQ(broken, 12);  // 6 slots each; the shared edge's slot counted twice
  for (size_t b = 0; b < bond_state.extent(0); ++b) EXPECT_NE(bond_state(b), int{kBondActive});
  for (size_t n = 0; n < mass.extent(0); ++n) EXPECT_EQ(mass(n), mass_before(n));
}

}  // namespace
}  // namespace fracta
