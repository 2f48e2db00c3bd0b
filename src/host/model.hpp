// The model: device state built from a Case (mesh, masses, materials, loads, constraints).
#pragma once
#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "host/case.hpp"
#include "host/contact.hpp"
#include "host/memory.hpp"
#include "host/mesh.hpp"
#include "host/sparse_zero_view.hpp"
#include "host/state_views.hpp"
#include "kernels/bond_forces.hpp"
#include "kernels/boundaries.hpp"
#include "kernels/conversion.hpp"
#include "kernels/fe_forces.hpp"
#include "kernels/rigid.hpp"
#include "kernels/state.hpp"

namespace fracta {

struct ProbeSite {
  std::string name;
  int node = -1;     // nearest node (displacement, velocity)
  int element = -1;  // containing element (stress), -1 if the point is outside every element
};

struct BodyProbeSite {
  std::string name;
  int node_begin = 0, node_end = 0;
};

// A boundary the history reports on (named ones) or the step acts on (bars): its node set,
// and per node of the set the table of each prescribed component (-1: none).
struct BoundarySet {
  std::string name;  // empty: unnamed (a bar still acts)
  Boundary::Type type = Boundary::Type::fixed;
  View<int*> nodes;
  View<int* [2]> prescribed_table;
  double direction[2] = {0.0, 1.0};
  BarImpedance bar;       // bars only
  int bar_table = -1;     // bars: the incident velocity table
  double stress = 0.0;    // bars: the face stress of the last evaluation (Pa, compression > 0)
  double incident = 0.0;  // bars: Z v_I at that time (Pa)
  int support_begin = 0, support_end = 0;  // supports: its components in Model::supports
};

struct Model {
  Case scene;
  // The body ranges and boundary edges of the mesh; its per-node and per-element arrays are
  // freed once the views below hold them (build_model): read those.
  HostMesh mesh;
  Nodes nodes;
  Elements elements;
  View<MaterialLaw*> materials;
  std::vector<MaterialLaw> host_materials;
  LoadTables tables;
  HostLoadTables host_tables;  // the same, on the host (bars' incident velocities)
  PressureEdges pressure_edges;
  NodalForces nodal_forces;
  // Boundaries that act through the integrator (kernels/boundaries.hpp); tables after the loads'.
  PrescribedDofs prescribed;
  SupportDofs supports;
  std::vector<BoundarySet> boundary_sets;  // named boundaries and every bar
  FeParams fe;
  // The bonded lattice (empty when no body can become discs).
  Bonds bonds;
  Topology topology;
  View<int* [6]> element_bonds;  // bond slots of each element: 4 edges, 2 diagonals (-1: none)
  View<int*> converted;          // the converted cells (elements), in conversion order
  int converted_count = 0;
  View<int*> element_adaptive;  // 1 for elements of adaptive bodies and regions
  bool has_adaptive = false;
  View<int*> active_scratch;                  // conversion workspace (capacity: all elements)
  ListWorkspace lists;                        // conversion workspace for the lattice lists
  View<LatticeStiffness*> lattice_stiffness;  // per material
  View<BondLaw*> bond_laws;                   // per material
  // Per material, the dynamic increase factors of the elements' tension cut-off (mohr_coulomb
  // with rate_dependence; RateLaw count 0 for the others); empty when no material has them.
  View<RateLaw*> tension_rates;
  // What a user should know about the model, one line each, printed by `fracta run` and
  // `fracta check`: cohesive materials whose process zone the lattice cannot resolve (the bond
  // tensile strength is capped; build_lattice, docs/physics.md 1.2, "Resolving the process
  // zone"), the random strengths drawn, an impact faster than the materials' P-wave speed.
  std::vector<std::string> notes;
  // Disc contact (particles and FE boundary nodes); null when the scene has no discs.
  std::shared_ptr<ContactSystem> contacts;
  // Rigid bodies and each node's offset from its body's centre of mass in the reference state.
  std::vector<RigidBody> rigid;
  View<double* [2]> rigid_offset;
  // The surfaces of rigid bodies of revolution, for contact (build_rigid_surface); empty: none.
  RigidSurface rigid_surface;
  std::vector<ProbeSite> probes;
  std::vector<BodyProbeSite> body_probes;
};

// Builds the model; throws InputError for scenes that cannot be modelled (a selector that
// selects nothing, a convertible body outside the lattice's Poisson-ratio range, ...).
Model build_model(const Case& c);

// What the scene can change (state_views.hpp: the views the failure snapshot need not copy).
inline SceneChanges scene_changes(const Model& m) {
  SceneChanges s;
  s.may_yield = m.bonds.may_yield;
  s.may_soften = m.bonds.may_soften;
  s.may_convert = m.has_adaptive;
  s.supports_change = m.supports.any();
  s.external_forces =
      m.pressure_edges.count > 0 || m.nodal_forces.count > 0 ||
      std::any_of(m.boundary_sets.begin(), m.boundary_sets.end(),
                  [](const BoundarySet& b) { return b.type == Boundary::Type::bar; });
  return s;
}

MaterialLaw material_law(const Material& m, Formulation f);

// The conversion criterion of the model's elements (kernels/conversion.hpp), as the FE kernel
// flags it and the conversion applies it.
inline ConversionCriterion conversion_criterion(const Model& m) {
  return {m.elements.active,
          m.element_adaptive,
          m.materials,
          m.elements.material,
          m.elements.epeq,
          m.elements.stress,
          m.elements.qp_per_element,
          m.scene.sim.conversion_on_tension,
          m.elements.nodes,
          m.nodes.x,
          m.elements.reference_gradient_norm2,
          m.elements.tension_factor,
          m.elements.law_state};
}

}  // namespace fracta
