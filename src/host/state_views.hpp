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
#include "kernels/state.hpp"

namespace fracta {

struct StateViews {
  Nodes nodes;
  Elements elements;
  Bonds bonds;
  View<int*> converted;                      // converted cells, in conversion order
  View<double* [3]> contact_force_previous;  // contact (fx, fy, moment) of the last evaluation
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

}  // namespace fracta
