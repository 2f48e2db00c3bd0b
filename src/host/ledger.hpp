// The solver's scalars: the clock, the stable-step bounds, the energy terms and the event
// counters, as a few value structs. The failure snapshot copies them whole, the checkpoint
// visits them by name (for_each_field), and the history reads them: a scalar added here is
// saved, restored and checkpointed without another list to edit.
//
// Units: s for times and bounds, J (per modelled thickness) for energies.
#pragma once
#include "host/model.hpp"
#include "kernels/bond_forces.hpp"
#include "kernels/fe_forces.hpp"

namespace fracta {

struct StepClock {
  double time = 0.0;        // s
  double dt = 0.0;          // the next step (s)
  double dt_initial = 0.0;  // the first step (s): the reference of the collapse check
  long steps = 0;
};

// Stable-step bounds before the safety factor (docs/physics.md 1.4).
struct StableStep {
  double step = 0.0;       // the last evaluation's: min(FE, lattice); negative: an inverted element
  double lattice = 1e300;  // the bond network's Gershgorin bound; lowered by conversions
  double motion = 1e300;   // the contact discs' motion bound (ContactSystem::motion_bound)
};

// Energies since t = 0 (J). The balance (Simulation::history) is
// kinetic + internal + dissipated - external - initial.
struct EnergyLedger {
  double initial = 0.0;   // kinetic + internal at t = 0
  double floor = 0.0;     // the relative error's smallest scale, 1e-12 M c^2
  double external = 0.0;  // work of the loads and fixed-velocity supports
  double element_plastic = 0.0, hourglass = 0.0, viscous = 0.0;  // FE dissipation
  double fracture = 0.0;            // released by bonds that broke or softened
  double contact_elastic = 0.0;     // stored in the touching pairs now
  double contact_dissipated = 0.0;  // damping, friction and clamping of the contacts
  double conversion = 0.0;          // taken out by conversions (negative: put in)
};

struct EventCounts {
  long conversions = 0;            // cells converted since t = 0
  long conversions_this_step = 0;  // by the last step's conversion phase
  long broken_bonds = 0;           // since t = 0
  long touching = 0;               // contact pairs touching at the last evaluation
};

// What the contact phase hands the ledger.
struct ContactPhaseSums {
  double work = 0.0;            // trapezoidal work of the contact forces over the step (J)
  double elastic_energy = 0.0;  // stored in the touching pairs now (J)
  long touching = 0;
};

// The sums a step's phases reduce into slots in device memory (ResultSlot), which the host copies
// once per step (Simulation::settle_step_sums) instead of waiting for each phase.
struct StepSums {
  double kick_work_first = 0.0;  // external work of the first half kick (and drift) (J)
  FeStepSums fe;
  BondSums bonds;                 // bond_step_result
  double cell_fracture = 0.0;     // compute_cell_bulk_forces (J)
  Sums<3> contact;                // contact_step_result (ContactSums)
  double contact_work = 0.0;      // store_forces_after_and_work (J)
  double kick_work_second = 0.0;  // external work of the second half kick (J)
};

struct Ledger {
  StepClock clock;
  StableStep bounds;
  EnergyLedger energy;
  EventCounts counts;

  void add(const FeStepSums& fe) {
    energy.element_plastic += fe.plastic;
    energy.hourglass += fe.hourglass;
    energy.viscous += fe.viscous;
  }
  void add(const BondStepResult& bonds) {
    energy.fracture += bonds.fracture_energy;
    counts.broken_bonds += bonds.broken;
  }
  // What the contact did not store as elastic energy over a step of dt it dissipated (damping,
  // friction, clamping). dt = 0 (the initial evaluation) only sets the stored energy.
  void add(const ContactPhaseSums& contact, double dt) {
    if (dt > 0.0)
      energy.contact_dissipated +=
          -contact.work - (contact.elastic_energy - energy.contact_elastic);
    energy.contact_elastic = contact.elastic_energy;
    counts.touching = contact.touching;
  }
};

// Calls f(name, value&) for every ledger field; the names are the checkpoint's.
template <class F>
void for_each_field(Ledger& l, F&& f) {
  f("time", l.clock.time);
  f("dt", l.clock.dt);
  f("dt_bound", l.bounds.step);
  f("dt_initial", l.clock.dt_initial);
  f("steps", l.clock.steps);
  f("external_work", l.energy.external);
  f("initial_energy", l.energy.initial);
  f("bond_dt_bound", l.bounds.lattice);
  f("fracture_energy", l.energy.fracture);
  f("energy_floor", l.energy.floor);
  f("broken_bonds", l.counts.broken_bonds);
  f("touching", l.counts.touching);
  f("contact_elastic", l.energy.contact_elastic);
  f("contact_dissipated", l.energy.contact_dissipated);
  f("element_plastic_work", l.energy.element_plastic);
  f("hourglass_work", l.energy.hourglass);
  f("viscous_work", l.energy.viscous);
  f("conversion_energy", l.energy.conversion);
  f("conversions", l.counts.conversions);
  f("conversions_this_step", l.counts.conversions_this_step);
}

// The lengths of the model's growing and shrinking lists, which the kernels read from the
// entity structs (Elements::active_count, ...): saved and restored with the ledger.
struct ListCounts {
  int converted = 0;        // Model::converted_count
  int active_elements = 0;  // Elements::active_count
  int used_bonds = 0;       // Bonds::used_count
  int particles = 0;        // Nodes::particle_count

  static ListCounts of(const Model& m) {
    return {m.converted_count, m.elements.active_count, m.bonds.used_count, m.nodes.particle_count};
  }
  void apply_to(Model& m) const {
    m.converted_count = converted;
    m.elements.active_count = active_elements;
    m.bonds.used_count = used_bonds;
    m.nodes.particle_count = particles;
  }
};

template <class F>
void for_each_field(ListCounts& l, F&& f) {
  f("converted_count", l.converted);
  f("active_elements", l.active_elements);
  f("used_bonds", l.used_bonds);
  f("particles", l.particles);
}

}  // namespace fracta
