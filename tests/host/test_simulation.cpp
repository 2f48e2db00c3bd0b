// The solver loop (host/simulation.cpp): steps with the second half kick deferred and fused with
// the next step's first (Simulation::step(true), as run_case runs) give the same run.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "host/checkpoint.hpp"
#include "host/simulation.hpp"
#include "kernels/integrate.hpp"
#include "test_util.hpp"

namespace fracta {
namespace {

double max_abs(const View<double* [2]>& v) {
  const auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), v);
  double m = 0.0;
  for (size_t n = 0; n < h.extent(0); ++n)
    for (int d = 0; d < 2; ++d) m = std::max(m, std::fabs(h(n, d)));
  return m;
}

double max_abs_1d(const View<double*>& v) {
  const auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), v);
  double m = 0.0;
  for (size_t n = 0; n < h.extent(0); ++n) m = std::max(m, std::fabs(h(n)));
  return m;
}

template <class V>
double max_difference(const V& a, const V& b) {
  const auto ha = Kokkos::create_mirror_view_and_copy(HostSpace(), a);
  const auto hb = Kokkos::create_mirror_view_and_copy(HostSpace(), b);
  double m = 0.0;
  const double* pa = ha.data();
  const double* pb = hb.data();
  for (size_t i = 0; i < ha.span(); ++i) m = std::max(m, std::fabs(pa[i] - pb[i]));
  return m;
}

// Runs the case `steps` steps both ways and compares the states and energies: the fused kick
// is the same arithmetic in the same order, so the runs agree to round-off (1e-12 of the largest
// value; measured: bitwise equal). On the device path the node sums add atomically, in an order
// that differs between the runs, and the rotating lattice carries that on: 1e-10 there (measured
// 2e-11 of the largest spin after 200 steps).
void expect_same_run(const Case& c, int steps) {
  const double tolerance = test::kBitwiseRuns ? 1e-12 : 1e-10;
  Simulation plain(c), deferred(c);
  for (int s = 0; s < steps; ++s) {
    plain.step();
    deferred.step(true);
  }
  const HistoryRecord hp = plain.history(), hd = deferred.history();  // finishes the kick
  const Nodes &a = plain.model().nodes, &b = deferred.model().nodes;
  ASSERT_GT(max_abs(a.v), 0.0);
  EXPECT_LE(max_difference(a.v, b.v), tolerance * max_abs(a.v));
  EXPECT_LE(max_difference(a.x, b.x), tolerance * max_abs(a.x));
  if (a.has_particles()) {
    EXPECT_LE(max_difference(a.spin, b.spin), tolerance * max_abs_1d(a.spin));
    EXPECT_LE(max_difference(a.rotation, b.rotation), tolerance);
  }
  ASSERT_GT(hp.energy.external, 0.0);
  EXPECT_NEAR(hd.energy.external, hp.energy.external, tolerance * hp.energy.external);
  EXPECT_NEAR(hd.energy.kinetic, hp.energy.kinetic, tolerance * hp.energy.external);
  EXPECT_NEAR(hd.energy.internal, hp.energy.internal, tolerance * hp.energy.external);
  EXPECT_NEAR(hd.energy.error, hp.energy.error, tolerance);
}

TEST(Simulation, DeferredKicksGiveTheSameRunOfAPlateWithFixedEdges) {
  Case c = test::rectangle_case(30, 12, 1e-3);
  c.sim.end_time = 1.0;
  test::add_pressure(c, test::segment(0, 0, 0, 0.012), {0.0, 1e-6}, {0.0, 200e6});
  test::add_fixed(c, test::segment(0.03, 0, 0.03, 0.012), Boundary::Type::fixed);
  expect_same_run(c, 200);
}

TEST(Simulation, DeferredKicksGiveTheSameRunOfARotatingLattice) {
  Case c = test::rectangle_case(24, 10, 1e-3, 70e9, 0.25, 2700.0, Formulation::plane_stress);
  c.bodies[0].method = BodyMethod::de;
  c.sim.end_time = 1.0;
  // A traction along the left edge: shear, so the discs rotate.
  test::add_traction(c, test::segment(0, 0, 0, 0.010), {0.0, 1.0}, {0.0, 1e-6}, {0.0, 100e6});
  expect_same_run(c, 200);
}

// Conversions while the kick is deferred (Simulation::convert leaves it pending and takes the new
// discs' spin from v(n+1)): the concrete slab of the impact test converts under the projectile.
// The runs start from one checkpoint taken as the slab begins to convert and compare a short
// window. Runs repeat bitwise on any number of threads (TwoRuns* below), so the deferred run
// must agree with the plain one to round-off. (Before the contact gather and the spin rule of
// Conversion.NewDiscSpinIsTheMeanRateOfItsBatchCells, runs on 2 threads parted by round-off
// flipping a threshold event, and this test allowed a second plain run's spread; a spin taken
// from v(n+1/2) differed by ~3e3 rad/s.)
TEST(Simulation, DeferredKicksGiveTheSameRunThroughConversions) {
  const Case c = test::impact_case(500.0);
  const std::string checkpoint =
      (std::filesystem::temp_directory_path() / "fracta_deferred_kicks.ckpt.h5").string();
  long conversions_at_start = 0;
  {
    Simulation lead(c);
    for (int steps = 0; steps < 400 && lead.conversions() < 10; ++steps) lead.step();
    ASSERT_GE(lead.conversions(), 10);
    conversions_at_start = lead.conversions();
    write_checkpoint(lead, checkpoint, CheckpointInfo{});
  }
  Simulation plain(c), deferred(c);
  for (Simulation* sim : {&plain, &deferred}) read_checkpoint_state(*sim, checkpoint);
  std::filesystem::remove(checkpoint);
  ASSERT_EQ(plain.conversions(), conversions_at_start);
  for (int s = 0; s < 8; ++s) {
    plain.step();
    deferred.step(true);
  }
  // Cells converted in the window, many at once: new discs started spinning and acted on it.
  ASSERT_GE(plain.conversions() - conversions_at_start, 3)
      << plain.conversions() - conversions_at_start;
  EXPECT_EQ(deferred.conversions(), plain.conversions());
  const HistoryRecord hp = plain.history(), hd = deferred.history();
  const Nodes &a = plain.model().nodes, &b = deferred.model().nodes;
  ASSERT_GT(max_abs_1d(a.spin), 0.0);
  EXPECT_LE(max_difference(a.spin, b.spin), 1e-12 * max_abs_1d(a.spin));
  EXPECT_LE(max_difference(a.v, b.v), 1e-12 * max_abs(a.v));
  EXPECT_LE(max_difference(a.x, b.x), 1e-12 * max_abs(a.x));
  // The conversion term sums the lattice's rotational energy before and after: with the kick left
  // pending the spins of the older discs differ by the half kick, so the sums cancel to
  // round-off, not bitwise.
  ASSERT_GT(std::fabs(hp.energy.conversion), 0.0);
  EXPECT_NEAR(hd.energy.conversion, hp.energy.conversion, 1e-12 * hp.energy.kinetic);
  EXPECT_NEAR(hd.energy.error, hp.energy.error, 1e-12);  // J
}

// A 20 x 2 mm strip moving at 5 m/s onto a push-only support at its left end.
Case strip_onto_a_support() {
  Case c = test::rectangle_case(40, 4, 0.5e-3);
  c.bodies[0].initial_velocity = {-5.0, 0.0};
  Boundary support;
  support.name = "support";
  support.type = Boundary::Type::support;
  support.direction = {1.0, 0.0};
  support.where.kind = NodeSelector::Kind::segment;
  support.where.segment = test::segment(0, 0, 0, 2e-3);
  c.boundaries.push_back(support);
  c.sim.end_time = 1e-3;
  return c;
}

// A checkpoint taken while a support holds a strip and a bar pushes it (the held components are
// state: nodes.fixed) continues exactly as the uninterrupted run: every state view, bitwise.
TEST(Simulation, RestartWithSupportsAndBarsIsExact) {
  Case c = strip_onto_a_support();
  Boundary bar = c.boundaries.back();
  bar.name = "bar";
  bar.type = Boundary::Type::bar;
  bar.direction = {-1.0, 0.0};
  bar.where.segment = test::segment(20e-3, 0, 20e-3, 2e-3);
  bar.impedance = 4e7;
  bar.area = 2e-5;
  bar.time = {0.0, 1e-6};
  bar.value = {0.0, 10.0};  // faster than the strip moves away from it
  c.boundaries.push_back(bar);
  const std::string checkpoint =
      (std::filesystem::temp_directory_path() / "fracta_support_restart.ckpt.h5").string();
  Simulation uninterrupted(c), restarted(c);
  for (int s = 0; s < 60; ++s) uninterrupted.step();
  ASSERT_GT(uninterrupted.boundary_records()[0].fx, 0.0);      // the support holds
  ASSERT_GT(uninterrupted.boundary_records()[1].stress, 0.0);  // the bar pushes
  write_checkpoint(uninterrupted, checkpoint, CheckpointInfo{});
  read_checkpoint_state(restarted, checkpoint);
  std::filesystem::remove(checkpoint);
  for (int s = 0; s < 60; ++s) {
    uninterrupted.step();
    restarted.step();
  }
  EXPECT_GE(test::expect_same_state(uninterrupted, restarted), 20);
  const double external = uninterrupted.history().energy.external;
  EXPECT_NEAR(restarted.history().energy.external, external, test::run_tolerance(1e-12) * external);
}

// A failure snapshot taken while a support holds a strip restores the held components after
// the strip has rebounded and the support let go: they are the state a support changes
// (nodes.fixed), which a scene without supports never writes and so never copies
// (state_view_constant). A snapshot that kept no copy of it here would leave the strip free.
TEST(Simulation, RestoreAfterASupportLetsGoIsBitForBit) {
  Simulation sim(strip_onto_a_support());
  ASSERT_TRUE(sim.model().supports.any());
  const auto held = [&] {
    const auto fixed = Kokkos::create_mirror_view_and_copy(HostSpace(), sim.model().nodes.fixed);
    int count = 0;
    for (int n = 0; n < sim.model().nodes.count; ++n) count += fixed(n) != 0;
    return count;
  };
  for (int s = 0; s < 20; ++s) sim.step();
  ASSERT_GT(held(), 0);  // the support holds the strip
  sim.save_snapshot();
  const test::StateCopy saved = test::copy_state(sim);
  for (int s = 0; s < 400 && held() > 0; ++s) sim.step();
  ASSERT_EQ(held(), 0);  // the strip rebounded: the support let go
  sim.restore_snapshot();
  EXPECT_GE(test::expect_same_state(saved, test::copy_state(sim), 0.0), 20);
}

// The same with a pressure that ramps up during the detour: the external forces are state a
// load changes (nodes.f_ext), which a scene without loads or bars never writes and so never
// copies (state_view_constant).
TEST(Simulation, RestoreUnderARampedLoadIsBitForBit) {
  Case c = test::rectangle_case(20, 4, 0.5e-3);
  test::add_pressure(c, test::segment(0, 0, 0, 2e-3), {0.0, 1e-5}, {0.0, 50e6});
  c.sim.end_time = 1e-3;
  Simulation sim(c);
  ASSERT_TRUE(scene_changes(sim.model()).external_forces);
  for (int s = 0; s < 10; ++s) sim.step();
  sim.save_snapshot();
  const test::StateCopy saved = test::copy_state(sim);
  for (int s = 0; s < 30; ++s) sim.step();
  sim.restore_snapshot();
  EXPECT_GE(test::expect_same_state(saved, test::copy_state(sim), 0.0), 15);
}

// A run repeats bitwise on any number of threads: no state update adds in a run-dependent order
// (element and bond forces scatter by chunk colours in list order, contact forces gather per disc
// in pair order, the bond stable dt is a gather over particles, a new disc's spin is the mean of
// its batch cells in Topology order, candidate lists are sorted). Two runs of a case, stepped as
// run_case steps, are compared view by view, every byte. Only the energy sums over dynamically
// scheduled chunks join in a run-dependent order (scatter.hpp): they feed no state and are
// compared at round-off. On the device path (atomic node sums) the runs part at round-off:
// 1e-10 of each view's largest value there (measured: up to 1.3e-12 after the 500 steps of the
// shattering lattice). Returns the first run's record and its conversion count.
std::pair<HistoryRecord, long> expect_bitwise_repeat(const Case& c, int steps) {
  Simulation first(c), second(c);
  for (int s = 0; s < steps; ++s) {
    first.step(true);
    second.step(true);
  }
  const HistoryRecord h1 = first.history(), h2 = second.history();
  EXPECT_EQ(second.conversions(), first.conversions());
  EXPECT_EQ(h2.count.broken_bonds, h1.count.broken_bonds);
  EXPECT_EQ(h2.count.contacts, h1.count.contacts);
  const int views = test::expect_same_state(first, second, 1e-10);
  EXPECT_GE(views, 40);
  const double energy = h1.energy.kinetic + h1.energy.internal;  // J (the projectile's, mostly)
  EXPECT_GT(h1.energy.kinetic, 0.0);
  for (const auto& [e1, e2] : {std::pair{h1.energy.kinetic, h2.energy.kinetic},
                               {h1.energy.internal, h2.energy.internal},
                               {h1.energy.conversion, h2.energy.conversion},
                               {h1.energy.error, h2.energy.error}})
    EXPECT_NEAR(e2, e1, 1e-12 * energy);
  return {h1, first.conversions()};
}

// The impact case through conversions (new discs, spins, bonds, the contact list refreshed).
TEST(Simulation, TwoRunsThroughConversionsAreBitwiseTheSame) {
  const auto [h, conversions] = expect_bitwise_repeat(test::impact_case(500.0), 500);
  EXPECT_GE(conversions, 20);
  EXPECT_GT(h.count.broken_bonds, 0);
}

// A lattice slab shattered at 1000 m/s: many broken bonds and touching discs. With the contact
// forces added by atomics instead of the gather, 3 of 20 tries on 2 threads differed (tried).
TEST(Simulation, TwoRunsOfAShatteringLatticeAreBitwiseTheSame) {
  const auto [h, conversions] =
      expect_bitwise_repeat(test::impact_case(1000.0, BodyMethod::de), 500);
  EXPECT_EQ(conversions, 0);
  EXPECT_GT(h.count.broken_bonds, 100);
  EXPECT_GT(h.count.contacts, 50);
}

// /history/count/conversions counts every conversion since t = 0, whatever the history
// interval: the impact slab converts over many steps with no history row in between.
TEST(Simulation, HistoryCountsEveryConversionSinceTheStart) {
  Simulation sim(test::impact_case(500.0));
  const long active_at_start = sim.history().count.elements;
  int steps_converting = 0;
  for (int s = 0; s < 400 && (sim.conversions() < 20 || steps_converting < 3); ++s) {
    const long before = sim.conversions();
    sim.step(true);
    if (sim.conversions() > before) ++steps_converting;
  }
  ASSERT_GE(steps_converting, 3);  // so no single step's count is the total
  const HistoryRecord h = sim.history();
  EXPECT_EQ(h.count.conversions, sim.conversions());
  // Conversion is the only way an element leaves the active list.
  EXPECT_EQ(h.count.conversions, active_at_start - h.count.elements);
}

// The failure snapshot restores the whole state, the ledger included: a run that saves at step
// k, steps on through conversions (which add bonds and so lower the lattice's stable-step bound),
// restores and steps again repeats, bitwise, the run that never went on. Without the lattice
// bound in the snapshot, the restored run kept the lower bound of the abandoned steps, and so a
// shorter step.
TEST(Simulation, RestoreAfterConversionsIsExact) {
  const Case c = test::impact_case(500.0);
  Simulation reference(c), detour(c);
  for (Simulation* sim : {&reference, &detour}) {
    for (int s = 0; s < 400 && sim->conversions() < 10; ++s) sim->step(true);
    ASSERT_GE(sim->conversions(), 10);
    sim->save_snapshot();
  }
  const long conversions_saved = detour.conversions();
  const double lattice_bound_saved = detour.bond_stable_dt_bound();
  for (int s = 0; s < 60; ++s) detour.step(true);
  ASSERT_GT(detour.conversions(), conversions_saved + 5);
  ASSERT_LT(detour.bond_stable_dt_bound(), lattice_bound_saved);  // the detour changed the bound
  detour.restore_snapshot();
  EXPECT_EQ(detour.bond_stable_dt_bound(), lattice_bound_saved);
  EXPECT_EQ(detour.conversions(), conversions_saved);
  for (int s = 0; s < 60; ++s) {
    reference.step(true);
    detour.step(true);
  }
  const double tolerance = test::run_tolerance(1e-12);
  EXPECT_EQ(detour.steps(), reference.steps());
  EXPECT_NEAR(detour.time(), reference.time(), tolerance * reference.time());
  EXPECT_NEAR(detour.dt(), reference.dt(), tolerance * reference.dt());
  EXPECT_EQ(detour.conversions(), reference.conversions());
  EXPECT_GE(test::expect_same_state(reference, detour), 40);
  const HistoryRecord hr = reference.history(), hd = detour.history();
  EXPECT_NEAR(hd.energy.external, hr.energy.external, tolerance * std::fabs(hr.energy.external));
  EXPECT_NEAR(hd.energy.fracture, hr.energy.fracture, tolerance * std::fabs(hr.energy.fracture));
  EXPECT_NEAR(hd.energy.conversion, hr.energy.conversion,
              tolerance * std::fabs(hr.energy.conversion));
  EXPECT_EQ(hd.count.broken_bonds, hr.count.broken_bonds);
}

// The lean snapshot (snapshot.hpp) keeps only the rows a step can change, yet a restore gives
// back the saved state exactly, on both code paths (it is a copy): the rows of the cells, bond
// slots and particles that joined their lists during the detour return to their values before
// joining. Exact by construction; and the snapshot of a barely converted adaptive body is a
// fraction of a whole copy of the state, its bond slots nearly all unused.
TEST(Simulation, RestoreGivesTheSavedStateBitForBit) {
  Simulation sim(test::impact_case(500.0));
  for (int s = 0; s < 400 && sim.conversions() < 10; ++s) sim.step(true);
  ASSERT_GE(sim.conversions(), 10);
  sim.save_snapshot();
  const test::StateCopy saved = test::copy_state(sim);
  const ListCounts lists_saved = ListCounts::of(sim.model());
  for (int s = 0; s < 60; ++s) sim.step(true);
  const ListCounts lists_detour = ListCounts::of(sim.model());
  ASSERT_GT(lists_detour.converted, lists_saved.converted + 5);
  ASSERT_GT(lists_detour.used_bonds, lists_saved.used_bonds);
  ASSERT_GT(lists_detour.particles, lists_saved.particles);
  sim.restore_snapshot();
  EXPECT_GE(test::expect_same_state(saved, test::copy_state(sim), 0.0), 40);

  double whole = 0;  // every row of every state view
  StateViews live = sim.state();
  for_each_state_view(live, live, [&](const char*, const auto& view, const auto&) {
    whole += view.span() * sizeof(typename std::decay_t<decltype(view)>::value_type);
  });
  const double bonds = sim.model().bonds.count, used = lists_saved.used_bonds;
  RecordProperty("snapshot_bytes", std::to_string(sim.snapshot_bytes()));
  RecordProperty("whole_state_bytes", std::to_string(whole));
  ASSERT_LT(used, 0.1 * bonds);
  EXPECT_LT(sim.snapshot_bytes(), 0.6 * whole);
}

// The same for a lattice that cannot convert (a de slab shattered at 1000 m/s: bonds break,
// discs touch): the views only a conversion writes (stiffnesses, areas, lists, radii; and the
// plastic elongations of elastic springs) are not copied at all (state_view_constant), yet the
// restore gives the saved state bit for bit. A step that wrote one of them would fail here.
TEST(Simulation, RestoreOfALatticeThatCannotConvertIsBitForBit) {
  Simulation sim(test::impact_case(1000.0, BodyMethod::de));
  ASSERT_FALSE(sim.model().has_adaptive);
  for (int s = 0; s < 60; ++s) sim.step(true);
  const long broken_saved = sim.history().count.broken_bonds;
  sim.save_snapshot();
  const test::StateCopy saved = test::copy_state(sim);
  for (int s = 0; s < 60; ++s) sim.step(true);
  std::printf("broken bonds %ld at the save, %ld after the detour\n", broken_saved,
              sim.history().count.broken_bonds);
  ASSERT_GT(sim.history().count.broken_bonds, broken_saved + 10);
  ASSERT_GT(sim.history().count.contacts, 0);
  sim.restore_snapshot();
  EXPECT_GE(test::expect_same_state(saved, test::copy_state(sim), 0.0), 40);
  EXPECT_EQ(sim.history().count.broken_bonds, broken_saved);

  // What is not copied: the bytes of the views that cannot change, against the snapshot's.
  double constant = 0, changing = 0;
  StateViews live = sim.state();
  const Model& m = sim.model();
  for_each_state_view(live, live, [&](const char* name, const auto& view, const auto&) {
    const double bytes = view.span() * sizeof(typename std::decay_t<decltype(view)>::value_type);
    (state_view_constant(name, scene_changes(m)) ? constant : changing) += bytes;
  });
  RecordProperty("snapshot_bytes", std::to_string(sim.snapshot_bytes()));
  RecordProperty("constant_bytes", std::to_string(constant));
  EXPECT_GT(constant, 0.3 * (constant + changing));
  EXPECT_LE(sim.snapshot_bytes(), 1.5 * changing);  // grown by at most half again
}

// A history row per end_time / 1000 unless the case sets an interval.
TEST(Simulation, HistoryIntervalIsAThousandthOfTheRunUnlessSet) {
  SimulationParams p;
  p.end_time = 2e-4;
  EXPECT_DOUBLE_EQ(history_every_for(p), 2e-7);
  p.history_interval = 1e-8;
  EXPECT_EQ(history_every_for(p), 1e-8);
}

// The restart command printed after a signal repeats the run's --set overrides, quoted for the
// shell where they need it.
TEST(Simulation, RestartCommandRepeatsTheOverrides) {
  Case c;
  c.path = "cases/penetration.toml";
  EXPECT_EQ(restart_command(c, "out.ckpt.h5"),
            "fracta run cases/penetration.toml --restart out.ckpt.h5");
  c.overrides = {"simulation.end_time=5e-6", "simulation.title=two words", "body.slab.x=it's"};
  EXPECT_EQ(restart_command(c, "my run/out.ckpt.h5"),
            "fracta run cases/penetration.toml --restart 'my run/out.ckpt.h5' --set "
            "simulation.end_time=5e-6 'simulation.title=two words' 'body.slab.x=it'\\''s'");
}

// Velocity, position, spin, rotation and a sum of the force terms of every node, seven values a
// node, on the host. (A free function: CUDA allows no device lambda inside a test body.)
Kokkos::View<double*, HostSpace> pack_node_values(const Nodes& nodes) {
  View<double*> out("out", 7 * nodes.count);
  Kokkos::parallel_for(
      "test_pack", Kokkos::RangePolicy<ExecSpace>(0, nodes.count), KOKKOS_LAMBDA(const int i) {
        const double values[7] = {nodes.v(i, 0),
                                  nodes.v(i, 1),
                                  nodes.x(i, 0),
                                  nodes.x(i, 1),
                                  nodes.spin(i),
                                  nodes.rotation(i),
                                  nodes.f(i, 0) + nodes.f_ext(i, 1) + nodes.moment(i)};
        for (int k = 0; k < 7; ++k) out(7 * i + k) = values[k];
      });
  return Kokkos::create_mirror_view_and_copy(HostSpace(), out);
}

// The fused kernel against the two half kicks it replaces, on arbitrary node data; the CPU forms
// of both (eight nodes as Double8 lanes) against their node-by-node forms too. 54 nodes: six
// batches of eight and a tail of six, some nodes fixed in x or y.
TEST(Integrate, KickKickDriftEqualsTheTwoHalfKicks) {
  Model m = build_model([] {
    Case c = test::rectangle_case(8, 5, 1e-3, 70e9, 0.25, 2700.0, Formulation::plane_stress);
    c.bodies[0].method = BodyMethod::de;
    return c;
  }());
  Nodes& n = m.nodes;
  auto set = [&](auto view, double scale, double phase) {
    auto h = Kokkos::create_mirror_view(view);
    double* p = h.data();
    for (size_t i = 0; i < h.span(); ++i) p[i] = scale * std::sin(1.7 * i + phase);
    Kokkos::deep_copy(view, h);
  };
  auto fixed = Kokkos::create_mirror_view(n.fixed);
  for (int i = 0; i < n.count; ++i) fixed(i) = i % 5 == 0 ? kFixX : (i % 7 == 0 ? kFixY : 0);
  Kokkos::deep_copy(n.fixed, fixed);
  // A batch of eight nodes that are not discs (their kick only clears the moments).
  auto particle = Kokkos::create_mirror_view_and_copy(HostSpace(), n.particle);
  for (int i = 8; i < 16; ++i) particle(i) = 0;
  Kokkos::deep_copy(n.particle, particle);
  enum Mode { split, split_node_by_node, lanes, node_by_node };
  const auto run = [&](Mode mode, double& work) {
    set(n.v, 3.0, 0.1);
    set(n.x, 1e-2, 0.2);
    set(n.f, 50.0, 0.3);
    set(n.f_ext, 20.0, 0.4);
    set(n.spin, 40.0, 0.5);
    set(n.rotation, 0.1, 0.6);
    set(n.moment, 1e-3, 0.7);
    const double dt_last = 2e-7, dt = 1.5e-7;
    work = mode == split || mode == split_node_by_node
               ? kick(n, dt_last, mode == split) + kick_drift(n, dt, mode == split)
               : kick_kick_drift(n, dt_last, dt, mode == lanes);
    return pack_node_values(n);
  };
  ASSERT_EQ(n.count, 54);
  double w_split = 0.0, w_split_node = 0.0, w_fused = 0.0, w_node = 0.0;
  const auto by_halves = run(split, w_split);
  const auto by_halves_node_by_node = run(split_node_by_node, w_split_node);
  const auto fused = run(lanes, w_fused);
  const auto fused_node_by_node = run(node_by_node, w_node);
  double scale = 0.0, diff = 0.0, diff_forms = 0.0;
  for (size_t i = 0; i < by_halves.extent(0); ++i) {
    scale = std::max(scale, std::fabs(by_halves(i)));
    diff = std::max(diff, std::fabs(by_halves(i) - fused(i)));
    diff_forms = std::max(diff_forms, std::fabs(fused_node_by_node(i) - fused(i)));
    diff_forms = std::max(diff_forms, std::fabs(by_halves_node_by_node(i) - by_halves(i)));
  }
  EXPECT_LE(diff, 1e-14 * scale);
  EXPECT_LE(diff_forms, 1e-14 * scale);
  EXPECT_NEAR(w_fused, w_split, 1e-14 * std::fabs(w_split));
  EXPECT_NEAR(w_node, w_split, 1e-14 * std::fabs(w_split));
  EXPECT_NEAR(w_split_node, w_split, 1e-14 * std::fabs(w_split));
  EXPECT_NE(w_split, 0.0);
}

}  // namespace
}  // namespace fracta
