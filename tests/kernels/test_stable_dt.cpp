// The stable time step (src/kernels/stable_dt.hpp; docs/physics.md 1.4): the element bounds
// against their closed forms, how the FE and lattice bounds combine, and the Gershgorin bound of
// the bond network in its two forms and with its per-particle cache.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "host/simulation.hpp"
#include "kernels/stable_dt.hpp"
#include "test_util.hpp"

namespace fracta {
namespace {

TEST(CombinedStableDt, SmallerBoundOrTheInvertedFlag) {
  EXPECT_EQ(combined_stable_dt(3e-7, 2e-7), 2e-7);
  EXPECT_EQ(combined_stable_dt(2e-7, 3e-7), 2e-7);
  EXPECT_EQ(combined_stable_dt(2e-7, 1e300), 2e-7);  // no lattice
  EXPECT_EQ(combined_stable_dt(-1.0, 2e-7), -1.0);   // an inverted element stays flagged
  EXPECT_EQ(combined_stable_dt(0.0, 2e-7), 0.0);     // a degenerate element
}

// A square of side h at rest: sum b.b = 2 / h^2 for the one-point gradients, so the bound is
// h / (sqrt(2) c), and 0.9 of it for 2x2 Gauss. In compression the bulk viscosity's
// Q = C1 c + C2 sqrt(A) |div| lowers it to l / (Q + sqrt(Q^2 + c^2)).
TEST(ElementStableDt, SquareOfSideH) {
  const double h = 2e-3, c = 5000.0, C1 = 0.06, C2 = 1.5;
  const double x[4] = {0.0, h, h, 0.0}, y[4] = {0.0, 0.0, h, h};
  const double b2 = 2.0 / (h * h), l = h / std::sqrt(2.0);
  EXPECT_NEAR(one_point_stable_dt(b2, std::sqrt(b2), h, 0.0, c, C1, C2), l / c, 1e-15 * l / c);
  EXPECT_NEAR(full_integration_stable_dt(x, y, h, 0.0, c, C1, C2), 0.9 * l / c, 1e-15 * l / c);
  const double div = -2e4, Q = C1 * c + C2 * h * (-div);
  EXPECT_NEAR(bulk_viscosity_speed(h, div, c, C1, C2), Q, 1e-12 * Q);
  EXPECT_EQ(bulk_viscosity_speed(h, 3.0, c, C1, C2), 0.0);  // no viscosity in expansion
  const double bound = l / (Q + std::sqrt(Q * Q + c * c));
  EXPECT_NEAR(one_point_stable_dt(b2, std::sqrt(b2), h, div, c, C1, C2), bound, 1e-14 * bound);
  EXPECT_NEAR(full_integration_stable_dt(x, y, h, div, c, C1, C2), 0.9 * bound, 1e-14 * bound);
  // Degenerate and inverted elements: 0.
  EXPECT_EQ(one_point_stable_dt(0.0, 0.0, 0.0, 0.0, c, C1, C2), 0.0);
  const double xi[4] = {0.0, 0.0, h, h};  // clockwise: negative area
  // Zero to round-off (1e-23 s in the sanitizer build, whose -O2 contracts other products).
  EXPECT_LE(std::fabs(full_integration_stable_dt(xi, y, h, 0.0, c, C1, C2)), 1e-15 * l / c);
}

// The stable step of the bond network: the particles gathering their rows from their slots
// (the solver's form) against the sweep over all slots with atomic row sums, on the impact
// test's slab after it converted and broke bonds. One thread: the same sums in the same order,
// so the same value; more: the atomics' order differs, so within round-off.
TEST(BondStableDt, GatherOverParticlesEqualsTheSweep) {
  Simulation sim(test::impact_case(500.0));
  for (int s = 0; s < 400 && sim.conversions() < 100; ++s) sim.step();
  const HistoryRecord h = sim.history();
  ASSERT_GE(h.count.broken_bonds, 20);
  ASSERT_GE(h.count.bonds, 100);
  const Model& m = sim.model();
  // Masses, inertias and radii varied from node to node (up to +-30%), so that a row summed
  // with the wrong end's values, or a term left out, changes the largest bound.
  std::srand(7);
  const auto vary = [](const View<double*>& v) {
    const auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), v);
    for (size_t n = 0; n < h.extent(0); ++n) h(n) *= 0.7 + 0.6 * std::rand() / RAND_MAX;
    Kokkos::deep_copy(v, h);
  };
  vary(m.nodes.mass);
  vary(m.nodes.inertia);
  vary(m.nodes.radius);
  for (const int allowance : {0, 6}) {
    StableDtWorkspace ws;
    const double sweep = bond_stable_dt(m.nodes, m.bonds, allowance);
    const double gather = bond_stable_dt(m.nodes, m.bonds, m.topology, allowance, ws);
    ASSERT_LT(sweep, 1e300);
    if (ExecSpace().concurrency() == 1)
      EXPECT_EQ(gather, sweep);
    else
      EXPECT_NEAR(gather, sweep, 1e-14 * sweep);
  }
}

// The lattice's Gershgorin bound (without contact allowance) against the largest eigenvalue of
// M^-1/2 K M^-1/2, found by power iteration with the solver's own force evaluation (an oracle:
// K w = -f(x0 + eps w) / eps from rest, for a displacement eps of 1e-6 of a cell), for a `de`
// block at nu = 0.45 in plane strain, whose cells carry the volumetric term (cell_forces.hpp;
// no shear springs there, so the rotations carry no stiffness). The bound must hold; the record
// says how much the cell term's share in it (kCellTermDiagonalFactor) adds.
TEST(BondStableDt, CellTermBoundHoldsTheLatticesLargestEigenvalue) {
  const double h = 1e-3;
  Case c = test::rectangle_case(6, 6, h, 232e9, 0.45, 7800.0, Formulation::plane_strain);
  c.bodies[0].method = BodyMethod::de;
  c.sim.end_time = 1.0;
  c.sim.dt = 1e-9;
  Simulation sim(c);
  const Model& m = sim.model();
  const int n = m.nodes.count;
  const auto x0 = Kokkos::create_mirror_view_and_copy(HostSpace(), m.nodes.x0);
  const auto mass = Kokkos::create_mirror_view_and_copy(HostSpace(), m.nodes.mass);
  auto x = Kokkos::create_mirror(HostSpace(), m.nodes.x);
  auto v = Kokkos::create_mirror(HostSpace(), m.nodes.v);
  auto f = Kokkos::create_mirror(HostSpace(), m.nodes.f);
  std::vector<double> w(2 * n), aw(2 * n);
  std::srand(7);
  for (double& value : w) value = std::rand() / static_cast<double>(RAND_MAX) - 0.5;
  const double eps = 1e-6 * h;
  double lambda = 0.0;
  for (int iteration = 0; iteration < 400; ++iteration) {
    double norm = 0.0;
    for (double value : w) norm += value * value;
    norm = std::sqrt(norm);
    for (double& value : w) value /= norm;
    // From rest at x0 with no force, one step of the drift moves node i by dt v_i.
    for (int i = 0; i < n; ++i)
      for (int d = 0; d < 2; ++d) {
        x(i, d) = x0(i, d);
        v(i, d) = eps * w[2 * i + d] / std::sqrt(mass(i)) / sim.dt();
        f(i, d) = 0.0;
      }
    Kokkos::deep_copy(m.nodes.x, x);
    Kokkos::deep_copy(m.nodes.v, v);
    Kokkos::deep_copy(m.nodes.f, f);
    sim.step();
    Kokkos::deep_copy(f, m.nodes.f);
    lambda = 0.0;
    for (int i = 0; i < n; ++i)
      for (int d = 0; d < 2; ++d) {
        aw[2 * i + d] = -f(i, d) / std::sqrt(mass(i)) / eps;
        lambda += w[2 * i + d] * aw[2 * i + d];
      }
    w = aw;
  }
  ASSERT_FALSE(sim.failed()) << sim.failure();
  const View<const LatticeStiffness*> stiffness = m.lattice_stiffness;
  const double dt_with = bond_stable_dt(m.nodes, m.bonds, 0.0, stiffness);
  const double dt_without = bond_stable_dt(m.nodes, m.bonds, 0.0);
  const double bound_with = 4.0 / (dt_with * dt_with),
               bound_without = 4.0 / (dt_without * dt_without);
  EXPECT_GT(lambda, 0.0);
  EXPECT_LE(lambda, bound_with);
  RecordProperty("largest_eigenvalue_over_bound", std::to_string(lambda / bound_with));
  RecordProperty("largest_eigenvalue_over_bound_without_cell_term",
                 std::to_string(lambda / bound_without));
  std::printf(
      "largest eigenvalue %.4g 1/s^2: %.3f of the bound, %.3f of the bound without the "
      "cell term\n",
      lambda, lambda / bound_with, lambda / bound_without);
}

// The solver keeps each particle's bound and recomputes only the rows flagged stale (a bond
// broke, a conversion touched the row): after every conversion of an impact that breaks bonds,
// each particle's kept bound and the solver's step equal those of a full pass, bitwise.
TEST(BondStableDt, CachedBoundsEqualAFullPass) {
  Simulation sim(test::impact_case(500.0));
  const Model& m = sim.model();
  long conversions = 0, checked = 0, particles_checked = 0;
  long broken_between = 0, broken = 0;
  for (int s = 0; s < 400 && sim.conversions() < 150; ++s) {
    sim.step();
    const long broken_now = sim.history().count.broken_bonds;
    if (sim.conversions() == conversions) continue;  // the bound is recomputed at conversions
    if (broken_now > broken) ++broken_between;
    conversions = sim.conversions();
    broken = broken_now;
    StableDtWorkspace full;  // no cache: every row, flags untouched
    full.bound = View<double*>("full_bound", m.nodes.count);
    const double dt_full =
        bond_stable_dt(m.nodes, m.bonds, m.topology,
                       damped_contact_allowance(6.0, m.scene.contact.damping_ratio), full);
    EXPECT_EQ(sim.bond_stable_dt_bound(), dt_full) << "step " << s;
    const auto kept =
        Kokkos::create_mirror_view_and_copy(HostSpace(), sim.bond_stable_dt_workspace().bound);
    const auto fresh = Kokkos::create_mirror_view_and_copy(HostSpace(), full.bound);
    const auto list = Kokkos::create_mirror_view_and_copy(HostSpace(), m.nodes.particle_list);
    int differing = 0;
    for (int k = 0; k < m.nodes.particle_count; ++k) differing += kept(list(k)) != fresh(list(k));
    EXPECT_EQ(differing, 0) << "step " << s << ": of " << m.nodes.particle_count << " particles";
    particles_checked += m.nodes.particle_count;
    ++checked;
  }
  ASSERT_GE(checked, 20);
  ASSERT_GE(broken_between, 5);  // bonds broke between conversions: flagged rows were used
  RecordProperty("conversion_steps_checked", std::to_string(checked));
  RecordProperty("particle_bounds_checked", std::to_string(particles_checked));
}

}  // namespace
}  // namespace fracta
