#include "host/simulation.hpp"

#include <Kokkos_Core.hpp>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

#include "host/checkpoint.hpp"
#include "kernels/cell_forces.hpp"
#include "kernels/energy.hpp"
#include "kernels/fragments.hpp"
#include "kernels/frame.hpp"
#include "kernels/integrate.hpp"
#include "kernels/loads.hpp"

namespace fracta {

namespace {

// Stress the probe reports: the element's quadrature-point average, or for a converted cell
// the stress of its discs.
struct ProbeGather {
  Nodes nodes;
  Elements elements;
  View<int*> node, element;
  View<double* [7]> out;
  KOKKOS_INLINE_FUNCTION void operator()(const int k) const {
    const int n = node(k), e = element(k);
    out(k, 0) = nodes.x(n, 0) - nodes.x0(n, 0);
    out(k, 1) = nodes.x(n, 1) - nodes.x0(n, 1);
    out(k, 2) = nodes.v(n, 0);
    out(k, 3) = nodes.v(n, 1);
    double s[3] = {0, 0, 0};
    if (e >= 0 && !elements.alive(e) && elements.cell_stress.extent(0) > 0) {
      // A converted cell: the continuum stress of its discs (compute_cell_stress).
      for (int q = 0; q < 3; ++q) s[q] = elements.cell_stress(e, q);
    } else if (e >= 0) {
      const int qp = elements.qp_per_element;
      for (int g = 0; g < qp; ++g) {
        s[0] += elements.stress(e * qp + g, 0) / qp;
        s[1] += elements.stress(e * qp + g, 1) / qp;
        s[2] += elements.stress(e * qp + g, 3) / qp;
      }
    }
    out(k, 4) = s[0];
    out(k, 5) = s[1];
    out(k, 6) = s[2];
  }
};

// out = -(f, moment) of every contact disc before the contact's force evaluation (the contact
// acts on nothing else; the other nodes' entries stay 0).
void store_forces_before(const Nodes& nodes, const View<const int*>& discs,
                         const View<double* [3]>& out) {
  const auto f = nodes.f;
  const auto moment = nodes.moment;
  Kokkos::parallel_for(
      "fracta::store_forces", Kokkos::RangePolicy<ExecSpace>(0, discs.extent(0)),
      KOKKOS_LAMBDA(const int a) {
        const int n = discs(a);
        out(n, 0) = -f(n, 0);
        out(n, 1) = -f(n, 1);
        out(n, 2) = -moment(n);
      });
}

// After the evaluation: after += (f, moment), which leaves the contact's own forces in it, and
// their trapezoidal work (J) over the step on the mid-step velocities, with `before` the last
// evaluation's: dt/2 sum v(n+1/2) . (f(n) + f(n+1)) (+ spin x moment for discs), over the
// contact discs (increasing: the other nodes' terms are zeros, so the sum is the one over every
// node). With a slot given, the work goes there (the launch does not wait) and 0 is returned.
double store_forces_after_and_work(const Nodes& nodes, const View<const int*>& discs,
                                   const View<double* [3]>& before, const View<double* [3]>& after,
                                   double dt, const ResultSlot<double>& into) {
  double work = 0.0;
  const auto f = nodes.f;
  const auto moment = nodes.moment;
  const auto v = nodes.v;
  const auto spin = nodes.spin;
  const auto particle = nodes.particle;
  const auto disc_work = KOKKOS_LAMBDA(const int a, double& w) {
    const int n = discs(a);
    const double fx = after(n, 0) + f(n, 0), fy = after(n, 1) + f(n, 1);
    const double m = after(n, 2) + moment(n);
    after(n, 0) = fx;
    after(n, 1) = fy;
    after(n, 2) = m;
    w += 0.5 * dt * (v(n, 0) * (before(n, 0) + fx) + v(n, 1) * (before(n, 1) + fy));
    if (particle(n)) w += 0.5 * dt * spin(n) * (before(n, 2) + m);
  };
  const auto policy = Kokkos::RangePolicy<ExecSpace>(0, discs.extent(0));
  if (into.data())
    Kokkos::parallel_reduce(slot_label("fracta::contact_work"), policy, disc_work,
                            Kokkos::Sum<double, MemSpace>(into));
  else
    Kokkos::parallel_reduce("fracta::contact_work", policy, disc_work, work);
  return work;
}

std::string format_duration(double s) {
  char buf[32];
  // Over 30 years is no ETA; far larger values would not fit the long (undefined behaviour).
  if (!std::isfinite(s) || s < 0 || s > 1e9) return "--:--";
  const long t = static_cast<long>(s + 0.5);
  if (t >= 3600)
    std::snprintf(buf, sizeof buf, "%ld:%02ld:%02ld", t / 3600, (t / 60) % 60, t % 60);
  else
    std::snprintf(buf, sizeof buf, "%ld:%02ld", t / 60, t % 60);
  return buf;
}

}  // namespace

double history_every_for(const SimulationParams& sim) {
  return sim.history_interval > 0.0 ? sim.history_interval : sim.end_time / kHistoryRows;
}

namespace {

// One argument for a POSIX shell: as it is when it holds no character the shell would treat
// specially, else in single quotes.
std::string shell_quoted(const std::string& arg) {
  const bool plain = !arg.empty() && arg.find_first_not_of(
                                         "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz"
                                         "0123456789._-+=/:,@%") == std::string::npos;
  if (plain) return arg;
  std::string quoted = "'";
  for (char ch : arg) quoted += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
  return quoted + "'";
}

}  // namespace

std::string restart_command(const Case& c, const std::string& checkpoint_path) {
  std::string command =
      "fracta run " + shell_quoted(c.path) + " --restart " + shell_quoted(checkpoint_path);
  // A restart must repeat the run's overrides (check_restart_compatible compares the cases
  // after them).
  if (!c.overrides.empty()) {
    command += " --set";
    for (const std::string& o : c.overrides) command += " " + shell_quoted(o);
  }
  return command;
}

namespace {
// Contacts the lattice's stable bound allows each disc: 6 at the full penalty stiffness, their
// dampers counted (damped_contact_allowance).
double contact_allowance(const Model& m) {
  return damped_contact_allowance(6.0, m.scene.contact.damping_ratio);
}

// The per-material stiffness the lattice's stable step reads for the volumetric cell term
// (stable_dt.hpp); empty when no cell has the term, so other scenes read nothing more.
View<const LatticeStiffness*> cell_term_stiffness(const Model& m) {
  return m.elements.cell_volumetric_strain.extent(0) > 0
             ? View<const LatticeStiffness*>(m.lattice_stiffness)
             : View<const LatticeStiffness*>();
}
}  // namespace

Simulation::Simulation(const Case& c) : model_(build_model(c)) {
  StepClock& clock = ledger_.clock;
  // The contact's forces of the last evaluation are part of the state (snapshot, checkpoint)
  // from the start, also for a lone body whose contact begins at its first conversion.
  if (model_.contacts) {
    contact_force_ =
        sparse_zero_view<View<double* [3]>>("fracta::contact_force", model_.nodes.count);
    contact_force_prev_ =
        sparse_zero_view<View<double* [3]>>("fracta::contact_force_prev", model_.nodes.count);
  }
  // The bond network's bound: bonds only weaken or break, so it stays valid until a conversion
  // adds stiffness; it allows 6 contacts per disc.
  stable_dt_.cache = true;
  ledger_.bounds.lattice =
      bond_stable_dt(model_.nodes, model_.bonds, model_.topology, contact_allowance(model_),
                     stable_dt_, cell_term_stiffness(model_));
  initial_forces();
  if (ledger_.bounds.step <= 0.0)
    throw InputError(c.path, c.sim.pos.line, "body", "an element has zero or negative area");
  if (c.sim.dt > 0.0 && c.sim.dt > ledger_.bounds.step && !c.sim.allow_unstable_dt) {
    std::ostringstream msg;
    msg << "fixed dt = " << c.sim.dt << " s exceeds the stable bound " << ledger_.bounds.step
        << " s (largest stable value; the automatic step would be "
        << c.sim.dt_safety * ledger_.bounds.step
        << " s). Remove dt, lower it, or set simulation.allow_unstable_dt = true (expert)";
    throw InputError(c.path, c.sim.dt_pos.line ? c.sim.dt_pos.line : c.sim.pos.line,
                     "simulation.dt", msg.str());
  }
  clock.dt = next_dt();
  clock.dt_initial = clock.dt;
  double c_max = 0.0;
  for (const MaterialLaw& law : model_.host_materials) c_max = std::max(c_max, law.wave_speed());
  ledger_.energy.floor = 1e-12 * node_totals(model_.nodes, 0.0).mass * c_max * c_max;
  const HistoryRecord h0 = history();
  ledger_.energy.initial = h0.energy.kinetic + h0.energy.time_discretization + h0.energy.internal;
  save_snapshot();
}

void Simulation::step(bool defer_kick) {
  if (failed()) return;
  ProfilingRegion region("fracta::step");
  StepClock& clock = ledger_.clock;
  const double dt = clock.dt;
  // The phases reduce their sums into the step's slots on the device and the host copies them
  // once, after the kick (settle_step_sums): on a GPU the step waits for the device there, in
  // the contact search's rebuild check, and where a conversion was flagged, not once per phase.
  kick_drift(true);
  clock.time += dt;
  apply_loads();
  element_forces(dt, true);
  bond_forces(dt, true);
  contact_search();
  contact_forces(dt, true);
  if (boundaries_act()) {
    // This evaluation's bar forces act over this step's second half kick and the next's first:
    // the next step's length, so the step's sums, are needed now.
    settle_step_sums(dt);
    boundary_forces(0.5 * (dt + next_dt()));
  }
  kick(defer_kick, true);
  settle_step_sums(dt);
  convert();
  ++clock.steps;

  if (!(ledger_.bounds.step > 0.0)) {
    failure_ = "an element inverted or became non-finite at step " + std::to_string(clock.steps);
    return;
  }
  const SimulationParams& sim = model_.scene.sim;
  if (sim.dt <= 0.0 && sim.dt_safety * ledger_.bounds.step < 1e-6 * clock.dt_initial) {
    failure_ = "time step collapsed below 1e-6 of its initial value";
    return;
  }
  clock.dt = next_dt();
}

void Simulation::initial_forces() {
  // dt = 0: no strain increment; the forces f(0) and the first stable bound.
  apply_loads();
  const FeStepSums fe = element_forces(0.0);
  ledger_.add(fe);
  ledger_.add(bond_forces(0.0));
  contact_search();
  ledger_.add(contact_forces(0.0), 0.0);
  ledger_.bounds.step = step_bound(fe);
  boundary_forces(0.5 * next_dt());  // f(0) acts over the first half kick
}

bool Simulation::boundaries_act() const {
  const Model& m = model_;
  if (m.supports.any()) return true;
  for (const BoundarySet& b : m.boundary_sets)
    if (b.type == Boundary::Type::bar) return true;
  return false;
}

bool Simulation::kick_into_slot(const bool into_slot) const {
  // Prescribed components and rigid bodies add host work around the kicks: their kicks' work
  // stays a host value, so that the external work is summed in the same order.
  return into_slot && model_.rigid.empty() && model_.prescribed.count == 0;
}

template <class T>
ResultSlot<T> Simulation::slot(T StepSums::*member, bool& pending) {
  pending = true;
  return ResultSlot<T>(&(step_sums_.data()->*member));
}

void Simulation::settle_step_sums(const double dt) {
  PendingSums& p = pending_sums_;
  if (!(p.fe || p.bonds || p.cell || p.contact || p.kick_drift || p.kick)) return;
  Kokkos::deep_copy(step_sums_host_, step_sums_);  // the step's one wait for the device
  const StepSums& s = step_sums_host_();
  // The ledger in the order the phases ran (the same sums as their host values, bit for bit).
  if (p.kick_drift) ledger_.energy.external += s.kick_work_first;
  if (p.fe) {
    ledger_.add(s.fe);
    if (s.fe.flagged > 0.0) conversion_flagged_ = true;
  }
  if (p.bonds) {
    BondStepResult lattice = bond_step_result(s.bonds);
    if (p.cell) lattice.fracture_energy += s.cell_fracture;
    ledger_.add(lattice);
  }
  if (p.contact) {
    const ContactStepResult r = contact_step_result(s.contact);
    ledger_.add(ContactPhaseSums{s.contact_work, r.elastic_energy, r.touching}, dt);
  }
  if (p.fe) ledger_.bounds.step = step_bound(s.fe);
  if (p.kick) ledger_.energy.external += s.kick_work_second;
  p = PendingSums();
}

void Simulation::kick_drift(const bool into_slot) {
  Model& m = model_;
  const double dt = ledger_.clock.dt;
  {
    ProfilingRegion integrate("fracta::integrate");
    // Prescribed components: the work of their constraint before the kick, their velocity
    // V(t + dt/2) and their drift after it (never with a pending kick: kick() does not defer).
    const double t_mid = ledger_.clock.time + 0.5 * dt;
    ledger_.energy.external += prescribed_work(m.nodes, m.prescribed, m.tables, t_mid, dt, true);
    const ResultSlot<double> into = kick_into_slot(into_slot)
                                        ? slot(&StepSums::kick_work_first, pending_sums_.kick_drift)
                                        : ResultSlot<double>();
    ledger_.energy.external += kick_pending_ ? kick_kick_drift(m.nodes, last_dt_, dt, true, into)
                                             : fracta::kick_drift(m.nodes, dt, true, into);
    kick_pending_ = false;
    prescribe(m.nodes, m.prescribed, m.tables, t_mid, dt);
  }
  for (RigidBody& b : m.rigid) {
    project_rigid(b, m.nodes);
    drift_rigid(b, m.nodes, m.rigid_offset, dt);
    write_rigid_velocity(b, m.nodes);
  }
}

void Simulation::apply_loads() {
  Model& m = model_;
  fracta::apply_loads(m.nodes, m.tables, m.pressure_edges, m.nodal_forces, m.scene.sim.thickness,
                      m.fe.axisymmetric != 0, ledger_.clock.time);
}

FeStepSums Simulation::element_forces(double dt, const bool into_slot) {
  ProfilingRegion region("fracta::fe_forces");
  Model& m = model_;
  FeParams p = m.fe;
  p.dt = dt;
  const ResultSlot<FeStepSums> into =
      into_slot ? slot(&StepSums::fe, pending_sums_.fe) : ResultSlot<FeStepSums>();
  const FeStepSums fe =
      m.has_adaptive
          ? compute_fe_forces(m.nodes, m.elements, m.materials, p, conversion_criterion(m),
                              conversion_pending_, conversion_candidates_, m.tension_rates, into)
          : compute_fe_forces(m.nodes, m.elements, m.materials, p, {}, {}, {}, m.tension_rates,
                              into);
  if (fe.flagged > 0.0) conversion_flagged_ = true;
  return fe;
}

BondStepResult Simulation::bond_forces(double dt, const bool into_slot) {
  Model& m = model_;
  filter_velocities(m.nodes);  // every step, also before the first conversion (RateLaw)
  // Bonds work once a cell has converted.
  if (m.bonds.count == 0 || m.converted_count == 0) return {};
  ProfilingRegion region("fracta::bond_forces");
  compute_cell_stress(m.converted, m.converted_count, m.lattice_stiffness, m.bond_laws, m.elements,
                      m.nodes);
  BondStepResult r = compute_bond_forces(
      m.nodes, m.elements, m.bonds, m.bond_laws, dt, BondBatches::runs,
      into_slot ? slot(&StepSums::bonds, pending_sums_.bonds) : ResultSlot<BondSums>());
  // After the bonds: a cell one of them cracked this step gives up its volumetric term now.
  if (cell_term_live())
    r.fracture_energy += compute_cell_bulk_forces(
        m.nodes, m.elements, m.lattice_stiffness, m.converted, m.converted_count,
        into_slot ? slot(&StepSums::cell_fracture, pending_sums_.cell) : ResultSlot<double>());
  return r;
}

bool Simulation::cell_term_live() {
  Model& m = model_;
  // The converted list only grows, and a restored state restores a prefix of it: its length
  // says whether the count (and the converted cells per chunk of the term's plan) is current.
  if (m.converted_count != cell_term_counted_at_) {
    cell_term_counted_at_ = m.converted_count;
    cell_term_live_ =
        cell_term_cells(m.converted, m.converted_count, m.elements, m.lattice_stiffness) > 0;
    if (cell_term_live_) count_cell_chunks(m.elements, m.converted, m.converted_count);
  }
  return cell_term_live_;
}

namespace {
// Contact needs several bodies or discs: one intact body cannot touch itself.
bool contact_possible(const Model& m) {
  return m.contacts && (m.scene.bodies.size() > 1 || m.converted_count > 0);
}
}  // namespace

void Simulation::contact_search() {
  if (!contact_possible(model_)) return;
  ProfilingRegion region("fracta::contact_search");
  model_.contacts->update(model_.nodes);
  ledger_.bounds.motion = model_.contacts->motion_bound();
}

double Simulation::step_bound(const FeStepSums& fe) const {
  const StableStep& b = ledger_.bounds;
  const double stable = combined_stable_dt(fe.dt_min, b.lattice);
  // (A negative bound flags an inverted element and must stay so.)
  return stable > 0.0 && b.motion < stable ? b.motion : stable;
}

ContactPhaseSums Simulation::contact_forces(double dt, const bool into_slot) {
  Model& m = model_;
  if (!contact_possible(m)) return {0.0, ledger_.energy.contact_elastic, ledger_.counts.touching};
  ProfilingRegion region("fracta::contact_forces");
  if (m.contacts->candidate_count() == 0 && contact_force_prev_zero_) {
    // No pair (an intact lattice lists none) and no force the last time: no force, no work,
    // no sweep over the discs and nothing for the device to reduce. The zero sums go to the
    // ledger at once (the caller adds what is returned when there is no slot): its contact
    // terms depend on no other phase's, so the order does not change them.
    const ContactPhaseSums none{0.0, 0.0, 0};
    if (into_slot) ledger_.add(none, dt);
    return none;
  }
  // The contact's own forces are the change it makes to the accumulators (fx, fy, moment).
  const auto discs = m.contacts->discs();
  store_forces_before(m.nodes, discs, contact_force_);
  const ContactStepResult r = m.contacts->compute_forces(
      m.nodes, dt,
      into_slot ? slot(&StepSums::contact, pending_sums_.contact) : ResultSlot<ContactSums>());
  // Work of the contact forces over the step by the trapezoidal rule with v(n+1/2), the rule
  // under which central differences balance energy (as the external work).
  const double work = store_forces_after_and_work(
      m.nodes, discs, contact_force_prev_, contact_force_, dt,
      into_slot ? slot(&StepSums::contact_work, pending_sums_.contact) : ResultSlot<double>());
  std::swap(contact_force_, contact_force_prev_);
  contact_force_prev_zero_ = m.contacts->candidate_count() == 0;
  return {work, r.elastic_energy, r.touching};
}

void Simulation::boundary_forces(const double kick_interval) {
  Model& m = model_;
  const double t = ledger_.clock.time;
  for (BoundarySet& b : m.boundary_sets) {
    if (b.type != Boundary::Type::bar) continue;
    const double dx = b.direction[0], dy = b.direction[1];
    const FaceTotals face = face_totals(m.nodes, b.nodes, dx, dy);
    const double incident_velocity = table_value(m.host_tables, b.bar_table, t);
    b.stress = b.bar.stress(incident_velocity, face.momentum / face.mass, face.force, face.mass,
                            kick_interval);
    b.incident = b.bar.impedance * incident_velocity;
    if (b.stress > 0.0) push_face(m.nodes, b.nodes, b.bar.area * b.stress / face.mass, dx, dy);
  }
  // After the bars: a support holds against every other force.
  ledger_.energy.external += update_supports(m.nodes, m.supports, kick_interval);
}

void Simulation::kick(bool defer, const bool into_slot) {
  Model& m = model_;
  last_dt_ = ledger_.clock.dt;
  // A rigid body's projection (rigid.hpp) is linear and idempotent, so projecting once after
  // the fused kick of kick_drift (or finish_kick) gives what a projection after each half kick
  // gives: rigid bodies defer too.
  if (defer && m.prescribed.count == 0) {
    kick_pending_ = true;
    return;
  }
  {
    ProfilingRegion integrate("fracta::integrate");
    const double t = ledger_.clock.time;
    ledger_.energy.external += prescribed_work(m.nodes, m.prescribed, m.tables, t, last_dt_, false);
    ledger_.energy.external += fracta::kick(
        m.nodes, last_dt_, true,
        kick_into_slot(into_slot) ? slot(&StepSums::kick_work_second, pending_sums_.kick)
                                  : ResultSlot<double>());
    prescribe(m.nodes, m.prescribed, m.tables, t, 0.0);
  }
  for (RigidBody& b : m.rigid) project_rigid(b, m.nodes);
}

void Simulation::convert() {
  const Model& m = model_;
  if (!m.has_adaptive || (ledger_.clock.steps + 1) % m.scene.sim.conversion_interval != 0) return;
  // The new particles become contact discs after the conversion phase: inserting them into the
  // candidate list (or rebuilding it at the next update) is the contact search's phase.
  const int before = m.converted_count;
  if (!convert_cells() || !model_.contacts) return;
  model_.contacts->refresh_discs(model_.nodes);
  // Pairs the converted cells held and no joint holds now (a slot broken while the cell was
  // alive) contact from now on.
  model_.contacts->admit_converted(
      Kokkos::subview(m.converted, std::make_pair(before, m.converted_count)),
      m.converted_count - before, m.element_bonds);
}

bool Simulation::convert_cells() {
  // No element flagged since the last look (the FE reduction says so): not even the counter's
  // copy to the host, so an adaptive run in which nothing converts costs what pure FE does.
  ledger_.counts.conversions_this_step = 0;
  if (!conversion_flagged_) return false;
  conversion_flagged_ = false;
  int pending = 0;
  {
    ProfilingRegion region("fracta::conversion");
    Kokkos::deep_copy(pending, conversion_pending_);
  }
  if (!pending)
    return false;  // no element met its criterion in the force evaluations since last time
  ProfilingRegion region("fracta::conversion");
  Model& m = model_;
  Kokkos::deep_copy(conversion_pending_, 0);
  // Few flagged: check just those (compact_candidates); many: the sweep (compact_converted).
  // Both give the same lists in the same order. The new cells go straight into the free part of
  // the converted list, which the count then takes in.
  const View<int*> new_cells = Kokkos::subview(
      m.converted, std::make_pair(m.converted_count, static_cast<int>(m.converted.extent(0))));
  int n = 0;
  const bool on_tension = m.scene.sim.conversion_on_tension;
  if (pending > 0 && pending <= static_cast<int>(conversion_candidates_.extent(0)) &&
      m.lists.keep.extent(0) >= static_cast<size_t>(pending)) {
    n = compact_candidates(m.elements, m.element_adaptive, m.materials, on_tension,
                           conversion_candidates_, pending, m.lists.keep, m.lists.sorted, new_cells,
                           m.active_scratch, m.nodes.x);
  } else {
    if (conversion_flag_.extent(0) < static_cast<size_t>(m.elements.count)) {
      conversion_flag_ = View<int*>("fracta::conversion_flag", m.elements.count);
      conversion_position_ = View<int*>("fracta::conversion_position", m.elements.count);
    }
    n = compact_converted(m.elements, m.element_adaptive, m.materials, on_tension, new_cells,
                          m.active_scratch, conversion_flag_, conversion_position_, m.nodes.x);
  }
  ledger_.counts.conversions_this_step = n;
  if (n == 0) return false;
  // The conversion works on the full step. A deferred second half kick stays pending (the whole
  // node sweep that finishing it costs is most of a conversion step's integration): the
  // conversion changes no force, mass or moment it uses (new discs carry no moment yet), and the
  // one velocity it reads, the new discs' spin, is taken as v(n+1) (prestress_converted_bonds).
  const LatticeTotals before = lattice_totals(m.nodes, m.bonds, 0.0);
  const double cells_before =
      cell_bulk_energy(m.converted, m.converted_count, m.nodes, m.elements, m.lattice_stiffness);
  // The slots and nodes this conversion activates go into the lists (state.hpp): collected
  // before the activation, inserted after it.
  const bool lists = m.bonds.used.extent(0) > 0 && m.nodes.particle_list.extent(0) > 0;
  if (lists) {
    m.lists.reserve(6 * n);
    collect_new_bonds(new_cells, n, m.element_bonds, m.bonds, m.lists.bond_candidates);
    collect_new_particles(new_cells, n, m.elements, m.nodes, m.lists.particle_candidates);
  }
  fill_slot_topology(new_cells, n, m.topology, m.nodes, m.bonds);
  const double element_energy =
      prestress_converted_bonds(new_cells, n, m.element_bonds, m.lattice_stiffness, m.elements,
                                m.nodes, m.bonds, m.topology, kick_pending_ ? last_dt_ : 0.0);
  activate_element_bonds(new_cells, n, m.element_bonds, m.lattice_stiffness, m.elements, m.nodes,
                         m.bonds);
  finish_converted_bonds(new_cells, n, m.element_bonds, m.nodes, m.bonds);
  mark_converted_rows(new_cells, n, m.elements, m.nodes, m.bonds, m.topology);
  if (lists) {
    m.bonds.used_count =
        insert_sorted(m.bonds.used, m.bonds.used_count, m.lists.bond_candidates, 6 * n, m.lists);
    m.nodes.particle_count = insert_sorted(m.nodes.particle_list, m.nodes.particle_count,
                                           m.lists.particle_candidates, 4 * n, m.lists);
  }
  locate_scatter_chunks();
  m.converted_count += n;
  ledger_.counts.conversions += n;
  // Energy the conversion takes out (element strain energy) less what it puts in (bond energy,
  // and the spin given to new discs): reported, not hidden (docs/physics.md 1.3). Negative when
  // the conversion adds energy.
  const LatticeTotals after = lattice_totals(m.nodes, m.bonds, 0.0);
  const double cells_after =
      cell_bulk_energy(m.converted, m.converted_count, m.nodes, m.elements, m.lattice_stiffness);
  ledger_.energy.conversion += element_energy - (after.bond_elastic - before.bond_elastic) -
                               (cells_after - cells_before) -
                               (after.rotational_kinetic - before.rotational_kinetic);
  // The new bonds stiffen the lattice: its bound, and so the step, can only go down.
  StableStep& bounds = ledger_.bounds;
  bounds.lattice = bond_stable_dt(m.nodes, m.bonds, m.topology, contact_allowance(m), stable_dt_,
                                  cell_term_stiffness(m));
  bounds.step = std::min(bounds.step, bounds.lattice);
  ledger_.clock.dt = next_dt();
  return true;
}

double Simulation::next_dt() const {
  const SimulationParams& sim = model_.scene.sim;
  const double time = ledger_.clock.time;
  double dt = sim.dt > 0.0 ? sim.dt : sim.dt_safety * ledger_.bounds.step;
  // Land exactly on end_time.
  if (time + dt > sim.end_time) dt = std::max(sim.end_time - time, 0.0);
  return dt;
}

void Simulation::locate_scatter_chunks() {
  update_scatter_plan(model_.elements);
  update_scatter_plan(model_.bonds);
}

void Simulation::finish_kick() {
  if (!kick_pending_) return;
  ProfilingRegion integrate("fracta::integrate");
  ledger_.energy.external += fracta::kick(model_.nodes, last_dt_);
  kick_pending_ = false;
  for (RigidBody& b : model_.rigid) project_rigid(b, model_.nodes);
}

HistoryRecord Simulation::history() {
  finish_kick();
  const SimulationParams& sim = model_.scene.sim;
  const EnergyLedger& e = ledger_.energy;
  HistoryRecord r;
  r.time = ledger_.clock.time;
  r.dt = ledger_.clock.dt;
  r.step = ledger_.clock.steps;
  // The nominal step (not the last one shortened to land on end_time).
  const double dt_nominal = sim.dt > 0 ? sim.dt : sim.dt_safety * ledger_.bounds.step;
  const NodeTotals nt = node_totals(model_.nodes, dt_nominal);
  const ElementTotals et = element_totals(model_.elements);
  const LatticeTotals lt = lattice_totals(model_.nodes, model_.bonds, dt_nominal);
  r.energy.kinetic = nt.kinetic + lt.rotational_kinetic;
  r.energy.internal = et.internal + lt.bond_elastic +
                      cell_bulk_energy(model_.converted, model_.converted_count, model_.nodes,
                                       model_.elements, model_.lattice_stiffness) +
                      e.contact_elastic;
  r.energy.contact = e.contact_dissipated;
  r.energy.conversion = e.conversion;
  r.energy.plastic = e.element_plastic + lt.bond_plastic;
  r.energy.fracture = e.fracture;
  r.energy.hourglass = e.hourglass;
  r.energy.viscous = e.viscous;
  r.energy.external = e.external;
  r.energy.time_discretization = nt.time_discretization + lt.rotational_time_discretization;
  const double dissipated = r.energy.plastic + r.energy.hourglass + r.energy.viscous +
                            r.energy.contact + r.energy.fracture + r.energy.conversion;
  const double balance = r.energy.kinetic + r.energy.time_discretization + r.energy.internal +
                         dissipated - e.external - e.initial;
  // Relative to the energy in play, but never below a floor of 1e-12 M c^2 (M the total mass,
  // c the fastest wave speed): a body at rest holds round-off energies whose ratios mean nothing.
  const double scale = std::max({e.external + e.initial, r.energy.kinetic, e.floor});
  r.energy.error = scale > 0.0 ? std::fabs(balance) / scale : 0.0;
  r.mass = nt.mass;
  r.momentum_x = nt.momentum_x;
  r.momentum_y = nt.momentum_y;
  r.count.elements = model_.elements.active_count;
  r.count.particles = lt.particles;
  r.count.composite = composite_count(model_.nodes, model_.topology);
  r.count.bonds = lt.active_bonds;
  r.count.broken_bonds = ledger_.counts.broken_bonds;
  r.count.contacts = ledger_.counts.touching;
  r.count.conversions = ledger_.counts.conversions;  // cumulative, like broken_bonds
  const long steps = ledger_.clock.steps;
  if (!std::isfinite(nt.kinetic) || !std::isfinite(et.internal))
    failure_ = "non-finite energy at step " + std::to_string(steps);
  else if (scale > 0.0 && steps > 10 && r.energy.error > sim.energy_error_limit) {
    std::ostringstream msg;
    msg << "energy error " << r.energy.error
        << " exceeds simulation.energy_error_limit = " << sim.energy_error_limit << " at step "
        << steps << " (instability?)";
    failure_ = msg.str();
  }
  return r;
}

std::vector<ProbeRecord> Simulation::probe_records() {
  finish_kick();
  const auto& sites = model_.probes;
  std::vector<ProbeRecord> out(sites.size());
  if (sites.empty()) return out;
  if (probe_values_.extent(0) != sites.size()) {  // built once: views allocate
    probe_node_ = View<int*>("fracta::probe_node", sites.size());
    probe_element_ = View<int*>("fracta::probe_element", sites.size());
    probe_values_ = View<double* [7]>("fracta::probe_values", sites.size());
    auto nh = Kokkos::create_mirror_view(probe_node_);
    auto eh = Kokkos::create_mirror_view(probe_element_);
    for (size_t k = 0; k < sites.size(); ++k) {
      nh(k) = sites[k].node;
      eh(k) = sites[k].element;
    }
    Kokkos::deep_copy(probe_node_, nh);
    Kokkos::deep_copy(probe_element_, eh);
  }
  const auto values = probe_values_;
  Kokkos::parallel_for(
      "fracta::probe_gather", Kokkos::RangePolicy<ExecSpace>(0, sites.size()),
      ProbeGather{model_.nodes, model_.elements, probe_node_, probe_element_, values});
  auto vh = Kokkos::create_mirror_view_and_copy(HostSpace(), values);
  for (size_t k = 0; k < sites.size(); ++k)
    out[k] = {time(), vh(k, 0), vh(k, 1), vh(k, 2), vh(k, 3), vh(k, 4), vh(k, 5), vh(k, 6)};
  return out;
}

std::vector<BoundaryRecord> Simulation::boundary_records() {
  finish_kick();
  std::vector<BoundaryRecord> out;
  const Model& m = model_;
  const double t = ledger_.clock.time;
  for (const BoundarySet& b : m.boundary_sets) {
    if (b.name.empty()) continue;
    const SetReaction r = set_reaction(m.nodes, b.nodes, b.prescribed_table, m.tables, t);
    BoundaryRecord rec;
    rec.time = t;
    rec.vx = r.vx;
    rec.vy = r.vy;
    if (b.type == Boundary::Type::bar) {
      const double force = b.bar.area * b.stress;
      rec.fx = force * b.direction[0];
      rec.fy = force * b.direction[1];
      rec.stress = b.stress;
      rec.incident = b.incident;
      rec.reflected = b.stress - b.incident;
    } else {
      rec.fx = r.fx;
      rec.fy = r.fy;
      if (b.type == Boundary::Type::support) {
        // The catches of the last evaluation, along the support's axis.
        const double caught = catch_force_sum(m.supports, b.support_begin, b.support_end);
        (b.direction[0] != 0.0 ? rec.fx : rec.fy) += caught;
      }
    }
    out.push_back(rec);
  }
  return out;
}

std::vector<BodyProbeRecord> Simulation::body_probe_records() {
  finish_kick();
  std::vector<BodyProbeRecord> out;
  for (const auto& bp : model_.body_probes) {
    const Sums<5> s = body_sums(model_.nodes, bp.node_begin, bp.node_end);
    const double m = s.v[0] > 0 ? s.v[0] : 1.0;
    out.push_back({time(), s.v[1] / m, s.v[2] / m, s.v[3] / m, s.v[4] / m});
  }
  return out;
}

namespace {
// Host backends: the packing kernels write the frame's vectors themselves. Device backends: they
// write reused device buffers, copied to the vectors afterwards.
constexpr bool kFrameOnHost = Kokkos::SpaceAccessibility<ExecSpace, HostSpace>::accessible;

// One frame array: where the packing writes it, where FrameData keeps it, its rows and width.
template <class T>
struct FrameField {
  FrameArray<T> FrameViews::*packed;
  std::vector<T> FrameData::*data;
  int FrameCounts::*rows;
  int width;
};
using FV = FrameViews;
using FD = FrameData;
using FC = FrameCounts;
const FrameField<double> kRealFrameFields[] = {
    {&FV::node_position, &FD::node_position, &FC::nodes, 2},
    {&FV::node_displacement, &FD::node_displacement, &FC::nodes, 2},
    {&FV::node_velocity, &FD::node_velocity, &FC::nodes, 2},
    {&FV::element_stress, &FD::element_stress, &FC::elements, 4},
    {&FV::element_plastic_strain, &FD::element_plastic_strain, &FC::elements, 1},
    {&FV::element_pressure, &FD::element_pressure, &FC::elements, 1},
    {&FV::element_von_mises, &FD::element_von_mises, &FC::elements, 1},
    {&FV::particle_radius, &FD::particle_radius, &FC::discs, 1},
    {&FV::particle_rotation, &FD::particle_rotation, &FC::discs, 1},
    {&FV::particle_spin, &FD::particle_spin, &FC::discs, 1},
    {&FV::bond_normal_force, &FD::bond_normal_force, &FC::bonds, 1},
    {&FV::bond_damage, &FD::bond_damage, &FC::bonds, 1},
};
const FrameField<int> kIntFrameFields[] = {
    {&FV::element_nodes, &FD::element_nodes, &FC::elements, 4},
    {&FV::element_id, &FD::element_id, &FC::elements, 1},
    {&FV::element_body, &FD::element_body, &FC::elements, 1},
    {&FV::particle_node, &FD::particle_node, &FC::discs, 1},
    {&FV::bond_nodes, &FD::bond_nodes, &FC::bonds, 2},
    {&FV::bond_state, &FD::bond_state, &FC::bonds, 1},
};

// Sizes each field's vector and points its packed array at it (host) or at a buffer (device).
template <class T, std::size_t N>
void bind_frame_fields(const FrameField<T> (&fields)[N], const FrameCounts& counts, FrameData& f,
                       FrameViews& v, std::vector<View<T*>>& buffers) {
  if (buffers.size() < N) buffers.resize(N);
  for (std::size_t k = 0; k < N; ++k) {
    std::vector<T>& values = f.*fields[k].data;
    const std::size_t n = static_cast<std::size_t>(counts.*fields[k].rows) * fields[k].width;
    values.resize(n);
    T* target = values.data();
    if constexpr (!kFrameOnHost) {
      if (buffers[k].extent(0) < n)
        buffers[k] = View<T*>(
            Kokkos::view_alloc(Kokkos::WithoutInitializing, "fracta::frame_buffer"), n + n / 2);
      target = buffers[k].data();
    }
    v.*fields[k].packed = FrameArray<T>(target, n);
  }
}

template <class T, std::size_t N>
void copy_frame_fields(const FrameField<T> (&fields)[N], const FrameViews& v, FrameData& f) {
  if constexpr (!kFrameOnHost)
    for (const FrameField<T>& field : fields) {
      std::vector<T>& values = f.*field.data;
      Kokkos::deep_copy(
          Kokkos::View<T*, HostSpace, Kokkos::MemoryUnmanaged>(values.data(), values.size()),
          v.*field.packed);
    }
}
}  // namespace

void pack_frame_data(const Model& model, FrameData& f, FrameBuffers& buffers) {
  const FrameCounts counts = count_frame(model.nodes, model.elements, model.bonds);
  FrameViews v;
  bind_frame_fields(kRealFrameFields, counts, f, v, buffers.reals);
  bind_frame_fields(kIntFrameFields, counts, f, v, buffers.ints);
  pack_frame(model.nodes, model.elements, model.bonds, v);
  Kokkos::fence();
  copy_frame_fields(kRealFrameFields, v, f);
  copy_frame_fields(kIntFrameFields, v, f);
}

const FrameData& Simulation::frame(const std::vector<std::string>& fields) {
  finish_kick();
  FrameData& f = frame_;
  f.time = time();
  f.step = steps();
  f.fields = fields;
  const Nodes& n = model_.nodes;
  pack_frame_data(model_, f, frame_buffers_);
  // Fragments: connected components over active bonds and alive elements.
  if (fragments_.labels.extent(0) < static_cast<size_t>(n.count))
    fragments_ = FragmentWorkspace(n.count);
  const FragmentStats st = fragment_statistics(n, model_.elements, model_.bonds, fragments_);
  f.fragment_mass = st.masses;
  f.fragment_size = st.sizes;
  f.node_fragment.resize(n.count);
  Kokkos::deep_copy(Kokkos::View<int*, HostSpace, Kokkos::MemoryUnmanaged>(f.node_fragment.data(),
                                                                           f.node_fragment.size()),
                    Kokkos::subview(fragments_.labels, std::make_pair(0, n.count)));
  return f;
}

StateViews Simulation::state_views() {
  StateViews v;
  v.nodes = model_.nodes;
  v.elements = model_.elements;
  v.bonds = model_.bonds;
  v.converted = model_.converted;
  v.contact_force_previous = contact_force_prev_;
  if (model_.contacts) {
    v.contact_discs = model_.contacts->discs();
    v.contact_disc_count = model_.contacts->disc_count();
  }
  return v;
}

void Simulation::save_snapshot() {
  finish_kick();
  snapshot_.state.save(model_, state_views());
  snapshot_.ledger = ledger_;
  snapshot_.rigid = model_.rigid;
}

void Simulation::restore_snapshot() {
  kick_pending_ = false;    // the snapshot holds a full step
  stable_dt_.invalidate();  // the bonds and radii are replaced
  snapshot_.state.restore(model_, state_views());
  contact_force_prev_zero_ = false;  // the snapshot's contact forces: taken as they are
  ledger_ = snapshot_.ledger;
  model_.rigid = snapshot_.rigid;
  if (model_.contacts) {
    model_.contacts->invalidate();
    model_.contacts->refresh_discs(model_.nodes);  // the snapshot's particles
  }
  locate_scatter_chunks();
  // Flags of the abandoned steps name positions in another active list: drop them (the next
  // force evaluation flags the restored state).
  Kokkos::deep_copy(conversion_pending_, 0);
}

RunInfo run_info(const Case& c) {
  RunInfo info;
  info.version = FRACTA_VERSION;
  info.backend = ExecSpace::name();
  info.threads = ExecSpace().concurrency();
  info.case_text = c.text;
  info.case_path = c.path;
  return info;
}

void declare_probes(OutputFile& out, const Simulation& sim) {
  for (const auto& p : sim.model().probes) out.declare_probe(p.name);
  for (const auto& p : sim.model().body_probes) out.declare_body_probe(p.name);
  for (const auto& b : sim.model().boundary_sets)
    if (!b.name.empty()) out.declare_boundary(b.name);
}

HistoryRecord record_history(OutputFile& out, Simulation& sim) {
  const HistoryRecord h = sim.history();
  out.append_history(h);
  const auto probes = sim.probe_records();
  for (size_t k = 0; k < probes.size(); ++k)
    out.append_probe(sim.model().probes[k].name, probes[k]);
  const auto bprobes = sim.body_probe_records();
  for (size_t k = 0; k < bprobes.size(); ++k)
    out.append_body_probe(sim.model().body_probes[k].name, bprobes[k]);
  const auto boundaries = sim.boundary_records();
  size_t k = 0;
  for (const auto& b : sim.model().boundary_sets)
    if (!b.name.empty()) out.append_boundary(b.name, boundaries[k++]);
  return h;
}

int run_case(const Case& c, const RunOptions& opt) {
  using clock = std::chrono::steady_clock;
  const auto wall0 = clock::now();
  const bool restart = !opt.restart_path.empty();
  // A restart checks the checkpoint and the case before building anything, and never writes
  // over the output the checkpoint's run wrote (prepare_restart).
  const std::string path = restart ? prepare_restart(c, opt.restart_path, opt.output_path)
                           : opt.output_path.empty() ? c.output.file
                                                     : opt.output_path;
  Simulation sim(c);
  for (const std::string& note : sim.model().notes)
    std::fprintf(stderr, "fracta: note: %s\n", note.c_str());
  if (restart) {
    const auto read0 = clock::now();
    read_checkpoint_state(sim, opt.restart_path);
    sim.save_snapshot();
    std::fprintf(stdout, "fracta: restarted from %s at t = %.6g s (step %ld), read in %.3f s\n",
                 opt.restart_path.c_str(), sim.time(), sim.steps(),
                 std::chrono::duration<double>(clock::now() - read0).count());
  }
  const RunInfo info = run_info(c);
  OutputFile out(path, info, FrameStorage{c.output.single_precision, c.output.compression});
  declare_probes(out, sim);
  // Wall time of the run's parts (/run attributes, the summary line): what the output costs.
  RunTimes times;
  auto timed = [&](double& total, auto&& work) {
    const ScopedSeconds timer(total);
    return work();
  };
  auto record = [&]() { return timed(times.history, [&] { return record_history(out, sim); }); };
  auto write_frame = [&]() {
    timed(times.output, [&] { out.write_frame(sim.frame(c.output.fields)); });
  };
  auto finish = [&](const std::string& status) {
    times.wall = std::chrono::duration<double>(clock::now() - wall0).count();
    out.finish(sim.steps(), times, status);
    times.wall += out.finish_seconds();
    times.output += out.finish_seconds();
  };

  const double end = c.sim.end_time;
  const double eps = 1e-12 * end;
  const double frame_every = c.sim.output_interval > 0 ? c.sim.output_interval : end;
  const double history_every = history_every_for(c.sim);
  const double checkpoint_every = c.output.checkpoint_interval;
  // Output instants: k * interval, accumulated by repeated addition. A restart replays the
  // additions up to its time, so it lands on the very same instants as the uninterrupted run.
  double next_frame = frame_every, next_history = history_every, next_checkpoint = checkpoint_every;
  auto advance = [&](double& next, double every) {
    while (every > 0 && next <= sim.time() + eps) next += every;
  };
  advance(next_frame, frame_every);
  advance(next_history, history_every);
  advance(next_checkpoint, checkpoint_every);
  HistoryRecord last = record();
  write_frame();
  long last_frame_step = sim.steps(), last_checkpoint_step = -1;
  // The failure snapshot is the last state that passed the checks of a history row (finite
  // energies, the energy error below its limit), taken at most every snapshot_every steps: a
  // state between two rows is not known to be good.
  const long snapshot_every = 100;
  long last_snapshot_step = sim.steps();
  const std::string checkpoint_path = checkpoint_path_for(path);
  auto checkpoint = [&]() {
    timed(times.checkpoint, [&] {
      out.flush();  // the output holds every history row up to the checkpoint
      const CheckpointInfo ci{FRACTA_VERSION, c.text,     c.path,     c.overrides,
                              path,           sim.time(), sim.steps()};
      write_checkpoint(sim, checkpoint_path, ci);
    });
    last_checkpoint_step = sim.steps();
  };
  const StopSignals stop_signals;

  double last_print = 0.0;
  const long first_step = sim.steps();  // > 0 on a restart
  auto progress = [&](bool final_line) {
    const double wall = std::chrono::duration<double>(clock::now() - wall0).count();
    if (!final_line) {
      const double interval = opt.progress_on_terminal ? 0.5 : opt.log_interval_seconds;
      if (wall - last_print < interval) return;
    }
    last_print = wall;
    const double rate = (sim.steps() - first_step) / std::max(wall, 1e-9);
    const double remaining_steps = sim.dt() > 0 ? (end - sim.time()) / sim.dt() : 0.0;
    char line[256];
    std::snprintf(line, sizeof line,
                  "t = %.4g us / %.4g us (%3.0f%%) | %ld steps, %.3g steps/s | ETA %s | "
                  "elements %ld | energy error %.3g%%",
                  sim.time() * 1e6, end * 1e6, 100.0 * sim.time() / end, sim.steps(), rate,
                  format_duration(remaining_steps / std::max(rate, 1e-9)).c_str(),
                  last.count.elements, 100.0 * last.energy.error);
    if (opt.progress_on_terminal)
      std::fprintf(stdout, "\r%-120s%s", line, final_line ? "\n" : "");
    else
      std::fprintf(stdout, "%s\n", line);
    std::fflush(stdout);
  };

  // An I/O error (IoError: a full file system, an unwritable path) ends the run with exit code 4
  // and writes nothing more: what was written before stays complete (every file is written to a
  // temporary name and renamed into place). An internal error (any other exception of a step)
  // ends it with exit code 5 after writing the last good state, as a numerical failure does.
  std::string internal_error;
  // A test hook: FRACTA_INJECT_INTERNAL_ERROR=N throws an internal error in step N + 1, so the
  // tests can show what a run does with one (docs/development.md).
  const char* inject = std::getenv("FRACTA_INJECT_INTERNAL_ERROR");
  const long inject_at_step = inject ? std::atol(inject) : -1;
  try {
    while (sim.time() < end - eps && !sim.failed()) {
      try {
        if (sim.steps() == inject_at_step)
          throw std::logic_error("injected by FRACTA_INJECT_INTERNAL_ERROR at step " +
                                 std::to_string(inject_at_step + 1));
        sim.step(/*defer_kick=*/true);  // history, frames, snapshots and checkpoints finish it
      } catch (const IoError&) {
        throw;
      } catch (const std::exception& e) {
        internal_error = e.what();
        break;
      }
      if (sim.failed()) break;
      const bool at_end = sim.time() >= end - eps;
      bool checked = false;
      if (history_every <= 0 || sim.time() >= next_history - eps || at_end) {
        last = record();
        advance(next_history, history_every);
        if (sim.failed()) break;
        checked = true;
      }
      if (sim.time() >= next_frame - eps || at_end) {
        write_frame();
        last_frame_step = sim.steps();
        advance(next_frame, frame_every);
      }
      // A final checkpoint too: a restart may extend end_time.
      if (checkpoint_every > 0 && (sim.time() >= next_checkpoint - eps || at_end)) {
        checkpoint();
        advance(next_checkpoint, checkpoint_every);
      }
      if (checked && sim.steps() - last_snapshot_step >= snapshot_every) {
        sim.save_snapshot();
        last_snapshot_step = sim.steps();
      }
      progress(false);
      if (StopSignals::received()) break;
    }
    if (!internal_error.empty()) {
      sim.restore_snapshot();
      write_frame();
      finish("failed: internal error: " + internal_error + "; last frame is the last good state");
      if (opt.progress_on_terminal) std::fprintf(stdout, "\n");
      std::fprintf(stderr,
                   "fracta: internal error: %s\nfracta: wrote the last good state (t = %.6g s, "
                   "step %ld) to %s\n",
                   internal_error.c_str(), sim.time(), sim.steps(), path.c_str());
      return 5;
    }
    if (sim.failed()) {
      const std::string why = sim.failure();
      sim.restore_snapshot();
      write_frame();
      finish("failed: " + why + "; last frame is the last good state");
      if (opt.progress_on_terminal) std::fprintf(stdout, "\n");
      std::fprintf(stderr,
                   "fracta: numerical failure: %s\nfracta: wrote the last good state (t = %.6g s, "
                   "step %ld) to %s\n",
                   why.c_str(), sim.time(), sim.steps(), path.c_str());
      return 3;
    }
    if (const int signal = StopSignals::received()) {
      // Stopped between two steps: the state is consistent. Keep it (checkpoint) and end the
      // output with it (final frame), closed and flushed.
      if (last_checkpoint_step != sim.steps()) checkpoint();
      if (last_frame_step != sim.steps()) write_frame();
      const char* name = signal == SIGINT ? "SIGINT" : "SIGTERM";
      finish(std::string("interrupted by ") + name);
      if (opt.progress_on_terminal) std::fprintf(stdout, "\n");
      std::fprintf(
          stderr,
          "fracta: interrupted by %s at t = %.6g s (step %ld)\nfracta: wrote the checkpoint "
          "%s and the output %s (%d frames, the last one is this state)\nfracta: continue "
          "with: %s\n",
          name, sim.time(), sim.steps(), checkpoint_path.c_str(), path.c_str(),
          out.frames_written(), restart_command(c, checkpoint_path).c_str());
      return 128 + signal;
    }
    progress(true);
    finish("completed");
    if (!out.frames_consolidated())
      std::fprintf(stderr,
                   "fracta: not enough space to copy the frames into %s: they stay in %s.frames, "
                   "which must be kept beside it\n",
                   path.c_str(), path.c_str());
    std::fprintf(stdout, "fracta: completed %ld steps in %.2f s; output %s\n", sim.steps(),
                 times.wall, path.c_str());
    const double stepping = times.wall - times.output - times.history - times.checkpoint;
    std::fprintf(stdout,
                 "fracta: wall time: stepping %.2f s, frames %.2f s (%d frames, %.3g ms each; "
                 "gathering %.2f s, files %.2f s, final copy %.2f s), history %.2f s, "
                 "checkpoints %.2f s\n",
                 stepping, times.output, out.frames_written(),
                 1e3 * times.output / std::max(out.frames_written(), 1),
                 times.output - out.write_seconds(), out.write_seconds() - out.finish_seconds(),
                 out.finish_seconds(), times.history, times.checkpoint);
    return 0;
  } catch (const IoError& e) {
    out.abandon();
    if (opt.progress_on_terminal) std::fprintf(stdout, "\n");
    std::fprintf(
        stderr,
        "fracta: I/O error: %s\nfracta: stopped at t = %.6g s (step %ld). %s holds "
        "%d frames and the history up to its last commit (its frames in %s.frames, "
        "kept beside it)%s%s\n",
        e.what(), sim.time(), sim.steps(), path.c_str(), out.frames_committed(), path.c_str(),
        last_checkpoint_step >= 0 ? "; the checkpoint " : "",
        last_checkpoint_step >= 0
            ? (checkpoint_path + " holds step " + std::to_string(last_checkpoint_step)).c_str()
            : "");
    return 4;
  }
}

}  // namespace fracta
