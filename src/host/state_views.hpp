// The device state a time step mutates: the one list that the failure snapshot (save/restore
// in simulation.cpp) and the checkpoint (checkpoint.cpp) share, so a view added to the solver
// state is added once, here, and both follow.
//
// Not listed, because a step never writes them: reference positions, masses, body
// ids, inertia, contact stiffness, connectivity, bond end nodes, rest lengths and cells, the
// topology CSR arrays (element_alive and bond_state are aliases of elements.alive and
// bonds.state), load tables. Host-side state (Simulation scalars, rigid bodies, the contact
// candidate list) is handled by the users of this list.
#pragma once
#include <initializer_list>
#include <string_view>

#include "kernels/state.hpp"

namespace fracta {

struct StateViews {
  Nodes nodes;
  Elements elements;
  Bonds bonds;
  View<int*> converted;                      // converted cells, in conversion order
  View<double* [3]> contact_force_previous;  // contact (fx, fy, moment) of the last evaluation
  // Not a state view: the contact's discs (node ids, increasing; ContactSystem::discs), the only
  // rows of contact_force_previous a step writes. They only grow between restores (the boundary
  // nodes of the FE bodies and the particles).
  View<const int*> contact_discs;
  int contact_disc_count = 0;
};

// Calls f(name, live_view, other_view) for every view a step mutates, in a fixed order; `name`
// is a stable identifier (the checkpoint's dataset name).
template <class F>
void for_each_state_view(StateViews& a, StateViews& b, F&& f) {
  Nodes &n = a.nodes, &sn = b.nodes;
  Elements &e = a.elements, &se = b.elements;
  Bonds &bo = a.bonds, &sb = b.bonds;
  f("nodes.x", n.x, sn.x);
  f("nodes.v", n.v, sn.v);
  f("nodes.v_filtered", n.v_filtered, sn.v_filtered);  // empty without a rate_dependence
  f("nodes.f", n.f, sn.f);
  f("nodes.f_ext", n.f_ext, sn.f_ext);
  f("nodes.fixed", n.fixed, sn.fixed);  // supports hold and let go
  f("elements.stress", e.stress, se.stress);
  f("elements.epeq", e.epeq, se.epeq);
  f("elements.qp_volume", e.qp_volume, se.qp_volume);
  f("elements.bulk_viscosity", e.bulk_viscosity, se.bulk_viscosity);
  f("elements.law_state", e.law_state, se.law_state);  // empty without an hjc material
  f("elements.hourglass_disp", e.hourglass_disp, se.hourglass_disp);
  f("elements.hourglass_force", e.hourglass_force, se.hourglass_force);
  f("elements.recoverable_work", e.recoverable_work, se.recoverable_work);
  f("elements.active", e.active, se.active);
  f("elements.alive", e.alive, se.alive);
  f("nodes.particle", n.particle, sn.particle);
  f("nodes.rotation", n.rotation, sn.rotation);
  f("nodes.spin", n.spin, sn.spin);
  f("nodes.moment", n.moment, sn.moment);
  f("nodes.contact_disc", n.contact_disc, sn.contact_disc);
  f("nodes.radius", n.radius, sn.radius);
  f("elements.cell_strain_offset", e.cell_strain_offset, se.cell_strain_offset);
  f("elements.cell_stress", e.cell_stress, se.cell_stress);
  f("elements.cell_state", e.cell_state, se.cell_state);
  f("elements.cell_cracked", e.cell_cracked, se.cell_cracked);
  // Empty without the lattice's cell term (cell_forces.hpp).
  f("elements.cell_volumetric_strain", e.cell_volumetric_strain, se.cell_volumetric_strain);
  f("elements.cell_hoop", e.cell_hoop, se.cell_hoop);  // empty but for axisymmetric lattices
  f("bonds.state", bo.state, sb.state);
  f("bonds.material", bo.material, sb.material);  // set by the conversion that activates it
  f("bonds.kn", bo.kn, sb.kn);
  f("bonds.ks", bo.ks, sb.ks);
  f("bonds.area", bo.area, sb.area);
  f("bonds.fn", bo.fn, sb.fn);
  f("bonds.fs", bo.fs, sb.fs);
  f("bonds.plastic_n", bo.plastic_n, sb.plastic_n);
  f("bonds.rest_length", bo.rest_length, sb.rest_length);
  f("bonds.plastic_s", bo.plastic_s, sb.plastic_s);
  f("bonds.hardening", bo.hardening, sb.hardening);
  f("bonds.plastic_work", bo.plastic_work, sb.plastic_work);
  f("bonds.damage", bo.damage, sb.damage);
  f("bonds.onset_separation", bo.onset_separation, sb.onset_separation);
  f("bonds.final_separation", bo.final_separation, sb.final_separation);
  f("bonds.used", bo.used, sb.used);                            // [0, bonds.used_count)
  f("nodes.particle_list", n.particle_list, sn.particle_list);  // [0, nodes.particle_count)
  f("converted", a.converted, b.converted);
  f("contact_force_previous", a.contact_force_previous, b.contact_force_previous);
}

// The rows of a state view that a step can change, by its name in for_each_state_view: the
// lean failure snapshot (snapshot.cpp) keeps only those, and run comparisons (tests) read only
// the used part of a list.
enum class StateRows {
  all,              // any row
  list_prefix,      // a list: the entries [0, count) (converted, bonds.used, particle_list, active)
  active_elements,  // the active elements' rows (their quadrature points' for per-point views):
                    // an element leaves the list by converting and never changes again
  converted_cells,  // the converted cells' rows; a cell's are its initial ones until it converts
  used_bonds,       // the used slots' rows; a slot's are its initial ones until it is activated
  particles,        // the particles' rows; a node's are 0 until it becomes a disc
  contact_discs,    // the contact discs' rows (StateViews::contact_discs); 0 until it is one
};

// Whether `name` is one of `names` (the state views' names below).
inline bool is_one_of(std::string_view name, std::initializer_list<std::string_view> names) {
  for (std::string_view n : names)
    if (n == name) return true;
  return false;
}

// What a scene can change beyond what every step changes (scene_changes, model.hpp).
struct SceneChanges {
  bool may_yield = true;        // a bond law yields (Bonds::may_yield)
  bool may_soften = true;       // a bond law softens (Bonds::may_soften)
  bool may_convert = true;      // a cell can convert (Model::has_adaptive)
  bool supports_change = true;  // a support can hold and let go (SupportDofs::any)
  bool external_forces = true;  // a load or a bar acts (else nodes.f_ext is 0 for good)
};

// Whether the view named `name` keeps its value for the whole run, so that no snapshot need
// copy it:
// - by the scene's bond laws (may_yield, may_soften): without them the plastic and cohesive
//   state stays 0. plastic_n and rest_length are not among them: a conversion sets them for
//   every law;
// - by whether anything can convert (may_convert): without conversion, the views that only a
//   conversion writes (conversion.hpp, Simulation::convert_elements: slot activation and
//   stiffnesses, the disc and cell lists, radii, the cells' strain offsets) keep their set-up
//   values, as do plastic_n and rest_length without a yielding law;
// - by whether a support can hold and let go (supports_change): only those write nodes.fixed
//   after the set-up;
// - by whether a load or a bar acts (external_forces): only those write nodes.f_ext (loads.hpp,
//   push_face), which the kicks clear where it is not 0;
// - nodes.contact_disc is set up once and never written.
// A step that wrote one of them anyway would show in the restore tests
// (Simulation.RestoreGivesTheSavedStateBitForBit and its lattice-only and support twins).
inline bool state_view_constant(std::string_view name, const SceneChanges& scene) {
  if (name == "nodes.contact_disc") return true;
  if (name == "nodes.fixed") return !scene.supports_change;
  if (name == "nodes.f_ext") return !scene.external_forces;
  if (!scene.may_yield &&
      is_one_of(name, {"bonds.plastic_s", "bonds.hardening", "bonds.plastic_work"}))
    return true;
  if (!scene.may_soften &&
      is_one_of(name, {"bonds.damage", "bonds.onset_separation", "bonds.final_separation"}))
    return true;
  if (scene.may_convert) return false;
  if (!scene.may_yield && is_one_of(name, {"bonds.plastic_n", "bonds.rest_length"})) return true;
  return is_one_of(
      name, {"bonds.material", "bonds.kn", "bonds.ks", "bonds.area", "bonds.used", "nodes.particle",
             "nodes.particle_list", "nodes.radius", "elements.cell_strain_offset",
             "elements.active", "elements.alive", "converted"});
}

inline StateRows state_rows(std::string_view name) {
  if (is_one_of(name, {"converted", "bonds.used", "nodes.particle_list", "elements.active"}))
    return StateRows::list_prefix;
  if (name.substr(0, 6) == "bonds.") return StateRows::used_bonds;
  // Not elements.cell_cracked: a broken bond marks the cells on both its sides, converted or not.
  // elements.alive too: an element's is 1 until it converts (state_value_before_joining), 0
  // after (rigid elements are 1 for good and never convert).
  if (is_one_of(name, {"elements.cell_strain_offset", "elements.cell_stress", "elements.cell_state",
                       "elements.cell_volumetric_strain", "elements.cell_hoop", "elements.alive"}))
    return StateRows::converted_cells;
  if (is_one_of(name, {"nodes.particle", "nodes.rotation", "nodes.spin", "nodes.moment"}))
    return StateRows::particles;
  if (name == "contact_force_previous") return StateRows::contact_discs;
  if (is_one_of(name, {"elements.stress", "elements.epeq", "elements.qp_volume",
                       "elements.bulk_viscosity", "elements.law_state", "elements.hourglass_disp",
                       "elements.hourglass_force", "elements.recoverable_work"}))
    return StateRows::active_elements;
  return StateRows::all;  // positions, velocities, forces, supports, radii, cracked flags
}

// The value of a row of the view named `name` before it joined its list (state_rows), to which a
// restore returns the rows that joined since the save: 0, but 1 for elements.alive.
inline int state_value_before_joining(std::string_view name) {
  return name == "elements.alive" ? 1 : 0;
}

}  // namespace fracta
