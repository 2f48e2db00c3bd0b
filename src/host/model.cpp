#include "host/model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <sstream>
#include <tuple>

#include "host/memory.hpp"
#include "kernels/cell_forces.hpp"
#include "kernels/conversion.hpp"
#include "kernels/heterogeneity.hpp"

namespace fracta {

MaterialLaw material_law(const Material& m, Formulation f) {
  const int model = m.model == MaterialModel::elastic        ? kElastic
                    : m.model == MaterialModel::bilinear_j2  ? kBilinearJ2
                    : m.model == MaterialModel::hjc          ? kHjc
                    : m.model == MaterialModel::johnson_cook ? kJohnsonCook
                                                             : kMohrCoulomb;
  // Axisymmetric points run the 3D laws as plane strain does, with the hoop increment given.
  MaterialLaw law = make_material_law(model, f != Formulation::plane_stress, m.density,
                                      m.youngs_modulus, m.poisson_ratio);
  law.yield_stress = m.yield_stress;
  law.plastic_modulus = m.plastic_modulus;
  law.cohesion = m.cohesion;
  law.friction_angle = m.friction_angle;
  law.tensile_strength = m.tensile_strength;
  law.conversion_strain = m.conversion_strain;
  law.conversion_length_ratio = m.conversion_length_ratio;
  law.hjc = m.hjc;
  law.jc = m.jc;
  law.conversion_damage = m.conversion_damage;
  cache_derived(law);
  return law;
}

namespace {

template <class T, class HostVec>
View<T*> to_device_1d(const std::string& label, const HostVec& h) {
  View<T*> d(Kokkos::view_alloc(Kokkos::WithoutInitializing, "fracta::" + label), h.size());
  auto m = Kokkos::create_mirror_view(d);
  for (size_t i = 0; i < h.size(); ++i) m(i) = h[i];
  Kokkos::deep_copy(d, m);
  return d;
}

// Rows of N values per item, e.g. the 2 nodes of an edge or the 4 nodes of an element.
template <class T, size_t N>
View<T* [N]> to_device_rows(const std::string& label, const std::vector<std::array<T, N>>& h) {
  View<T* [N]> d(Kokkos::view_alloc(Kokkos::WithoutInitializing, "fracta::" + label), h.size());
  auto m = Kokkos::create_mirror_view(d);
  for (size_t i = 0; i < h.size(); ++i)
    for (size_t k = 0; k < N; ++k) m(i, k) = h[i][k];
  Kokkos::deep_copy(d, m);
  return d;
}

void build_loads(Model& model) {
  const Case& c = model.scene;
  std::vector<double> t, v;
  std::vector<int> offset{0};
  std::vector<std::array<int, 2>> edges;
  std::vector<int> edge_load, force_node, force_load;
  std::vector<Vec2> edge_direction;
  std::vector<Vec2> force_unit;
  for (size_t k = 0; k < c.loads.size(); ++k) {
    const Load& l = c.loads[k];
    t.insert(t.end(), l.time.begin(), l.time.end());
    v.insert(v.end(), l.value.begin(), l.value.end());
    offset.push_back(static_cast<int>(t.size()));
    if (l.type == Load::Type::pressure || l.type == Load::Type::traction) {
      const auto sel = select_edges(model.mesh, l.where.segment, l.body_index);
      if (sel.empty())
        throw InputError(l.pos.file, l.pos.line, "load[" + std::to_string(k) + "].segment",
                         "selects no boundary edge of body '" + l.body + "'");
      for (const auto& e : sel) {
        edges.push_back(e);
        edge_load.push_back(static_cast<int>(k));
        edge_direction.push_back(l.type == Load::Type::traction ? l.direction : Vec2{0.0, 0.0});
      }
    } else {
      const auto sel = select_nodes(model.mesh, l.where, l.body_index);
      if (sel.empty())
        throw InputError(l.pos.file, l.pos.line, "load[" + std::to_string(k) + "]",
                         "selects no node of body '" + l.body + "'");
      const double share = 1.0 / sel.size();
      for (int n : sel) {
        force_node.push_back(n);
        force_load.push_back(static_cast<int>(k));
        force_unit.push_back({l.direction[0] * share, l.direction[1] * share});
      }
    }
  }
  // Then the tables of the velocity and bar boundaries.
  for (const Boundary& b : c.boundaries) {
    if (b.type != Boundary::Type::velocity && b.type != Boundary::Type::bar) continue;
    t.insert(t.end(), b.time.begin(), b.time.end());
    v.insert(v.end(), b.value.begin(), b.value.end());
    offset.push_back(static_cast<int>(t.size()));
  }
  model.tables.time = to_device_1d<double>("load_time", t);
  model.tables.value = to_device_1d<double>("load_value", v);
  model.tables.offset = to_device_1d<int>("load_offset", offset);
  model.tables.count = static_cast<int>(offset.size()) - 1;
  model.host_tables = host_copy(model.tables);

  auto& pe = model.pressure_edges;
  pe.count = static_cast<int>(edges.size());
  pe.nodes = to_device_rows("pressure_edge_nodes", edges);
  pe.load = to_device_1d<int>("pressure_edge_load", edge_load);
  pe.direction = to_device_rows("pressure_edge_direction", edge_direction);

  auto& nf = model.nodal_forces;
  nf.count = static_cast<int>(force_node.size());
  nf.node = to_device_1d<int>("nodal_force_node", force_node);
  nf.load = to_device_1d<int>("nodal_force_load", force_load);
  nf.force_per_unit = to_device_rows("nodal_force_unit", force_unit);
}

// The device lists of the prescribed and support components and the boundary sets. Tables of
// velocity and bar boundaries follow the loads' (build_loads), in boundary order.
void build_boundaries(Model& model) {
  const Case& c = model.scene;
  int table = static_cast<int>(c.loads.size());
  std::vector<int> p_node, p_component, p_table, s_node, s_component;
  std::vector<double> s_sign, s_plane;
  for (size_t k = 0; k < c.boundaries.size(); ++k) {
    const Boundary& b = c.boundaries[k];
    const bool tabled = b.type == Boundary::Type::velocity || b.type == Boundary::Type::bar;
    const int own_table = tabled ? table++ : -1;
    const auto sel = select_nodes(model.mesh, b.where, b.body_index);
    std::vector<std::array<int, 2>> set_table(sel.size(), {-1, -1});
    const int support_begin = static_cast<int>(s_node.size());
    for (size_t i = 0; i < sel.size(); ++i) {
      const int n = sel[i];
      if (b.type == Boundary::Type::velocity) {
        p_node.push_back(n);
        p_component.push_back(b.component);
        p_table.push_back(own_table);
        set_table[i][b.component] = own_table;
      } else if (b.type == Boundary::Type::support) {
        const int d = b.direction[0] != 0.0 ? 0 : 1;
        s_node.push_back(n);
        s_component.push_back(d);
        s_sign.push_back(b.direction[d]);
        s_plane.push_back(model.mesh.position[n][d]);
      }
    }
    if (b.name.empty() && b.type != Boundary::Type::bar) continue;
    BoundarySet set;
    set.name = b.name;
    set.type = b.type;
    set.nodes = to_device_1d<int>("boundary_nodes", sel);
    set.prescribed_table = to_device_rows("boundary_prescribed_table", set_table);
    set.direction[0] = b.direction[0];
    set.direction[1] = b.direction[1];
    set.bar = {b.impedance, b.area};
    set.bar_table = b.type == Boundary::Type::bar ? own_table : -1;
    set.support_begin = support_begin;
    set.support_end = static_cast<int>(s_node.size());
    model.boundary_sets.push_back(set);
  }
  // Rings (axisymmetric discs) cannot cross the axis: every node of a convertible body off the
  // axis, once a disc, has a push-only support on x = 0 along +x, which catches it when it
  // reaches the axis (a perfectly plastic stop, its energy counted as the constraint's work; a
  // node caught behind the axis, by less than a step's motion, is put back on it) and lets it go
  // when pulled away; on the axis it is an axis node, v_r = 0 (docs/physics.md 1.2,
  // "Axisymmetric discs"). Elements resist the axis themselves (their hoop strain rate v_r / r).
  std::vector<int> axis_ring;
  if (c.sim.formulation == Formulation::axisymmetric) {
    const HostMesh& m = model.mesh;
    // Not where a boundary already holds, drives or supports x (a support here would let a
    // fixed component go when pulled).
    std::vector<char> driven_x(m.node_count(), 0), ring(m.node_count(), 0);
    for (const Boundary& b : c.boundaries) {
      const bool x_bound = b.type == Boundary::Type::fixed || b.type == Boundary::Type::fixed_x ||
                           (b.type == Boundary::Type::velocity && b.component == 0) ||
                           ((b.type == Boundary::Type::support || b.type == Boundary::Type::bar) &&
                            b.direction[0] != 0.0);
      if (!x_bound) continue;
      for (const int n : select_nodes(m, b.where, b.body_index)) driven_x[n] = 1;
    }
    for (int e = 0; e < m.element_count(); ++e)
      if (m.element_method[e] == BodyMethod::de || m.element_method[e] == BodyMethod::adaptive)
        for (const int n : m.element_nodes[e]) ring[n] = 1;
    axis_ring.assign(m.node_count(), 0);
    bool any = false;
    for (int n = 0; n < m.node_count(); ++n) {
      axis_ring[n] = ring[n] && !driven_x[n] && m.position[n][0] > 0.0;
      any = any || axis_ring[n];
    }
    if (!any) axis_ring.clear();
  }
  PrescribedDofs& p = model.prescribed;
  p.count = static_cast<int>(p_node.size());
  p.node = to_device_1d<int>("prescribed_node", p_node);
  p.component = to_device_1d<int>("prescribed_component", p_component);
  p.table = to_device_1d<int>("prescribed_table", p_table);
  SupportDofs& sd = model.supports;
  sd.count = static_cast<int>(s_node.size());
  sd.node = to_device_1d<int>("support_node", s_node);
  sd.component = to_device_1d<int>("support_component", s_component);
  sd.sign = to_device_1d<double>("support_sign", s_sign);
  sd.plane = to_device_1d<double>("support_plane", s_plane);
  sd.catch_force = View<double*>("fracta::support_catch_force", sd.count);
  if (!axis_ring.empty()) sd.axis_ring = to_device_1d<int>("support_axis_ring", axis_ring);
}

void build_probes(Model& model) {
  const Case& c = model.scene;
  const HostMesh& m = model.mesh;
  for (const Probe& p : c.probes) {
    ProbeSite site;
    site.name = p.name;
    double best = std::numeric_limits<double>::max();
    for (int n = 0; n < m.node_count(); ++n) {
      if (p.body_index >= 0 && m.node_body[n] != p.body_index) continue;
      const double d = std::hypot(m.position[n][0] - p.at[0], m.position[n][1] - p.at[1]);
      if (d < best) {
        best = d;
        site.node = n;
      }
    }
    // Containing element (reference configuration); ties go to the first.
    for (int e = 0; e < m.element_count() && site.element < 0; ++e) {
      if (p.body_index >= 0 && m.element_body[e] != p.body_index) continue;
      const auto& lo = m.position[m.element_nodes[e][0]];
      const auto& hi = m.position[m.element_nodes[e][2]];
      if (p.at[0] >= lo[0] && p.at[0] <= hi[0] && p.at[1] >= lo[1] && p.at[1] <= hi[1])
        site.element = e;
    }
    if (site.node < 0)
      throw InputError(p.pos.file, p.pos.line, "probe['" + p.name + "']", "no node to attach to");
    model.probes.push_back(site);
  }
  for (const BodyProbe& p : c.body_probes) {
    const BodyRange& r = m.bodies[p.body_index];
    model.body_probes.push_back({p.name, r.node_begin, r.node_end});
  }
}

void build_rigid_bodies(Model& model) {
  const Case& c = model.scene;
  const HostMesh& m = model.mesh;
  auto mass = Kokkos::create_mirror_view_and_copy(HostSpace(), model.nodes.mass);
  std::vector<Vec2> offset(m.node_count(), Vec2{0.0, 0.0});
  for (size_t b = 0; b < c.bodies.size(); ++b) {
    if (c.bodies[b].method != BodyMethod::rigid) continue;
    RigidBody r;
    r.node_begin = m.bodies[b].node_begin;
    r.node_end = m.bodies[b].node_end;
    double mx = 0, my = 0;
    for (int n = r.node_begin; n < r.node_end; ++n) {
      r.mass += mass(n);
      mx += mass(n) * m.position[n][0];
      my += mass(n) * m.position[n][1];
    }
    r.x = mx / r.mass;
    r.y = my / r.mass;
    for (int n = r.node_begin; n < r.node_end; ++n) {
      offset[n] = {m.position[n][0] - r.x, m.position[n][1] - r.y};
      r.inertia += mass(n) * (offset[n][0] * offset[n][0] + offset[n][1] * offset[n][1]);
    }
    r.vx = c.bodies[b].initial_velocity[0];
    r.vy = c.bodies[b].initial_velocity[1];
    r.axial_only = c.sim.formulation == Formulation::axisymmetric;
    model.rigid.push_back(r);
  }
  if (!model.rigid.empty()) model.rigid_offset = to_device_rows("rigid_offset", offset);
}

// A body's initial velocity at x (m/s): v0 + L (x - x0), the uniform part plus the gradient's
// (a linear field: a translation, a rigid rotation, a uniform expansion or any mix).
Vec2 initial_velocity_at(const Body& b, const Vec2& x) {
  const auto& L = b.initial_velocity_gradient;
  const double dx = x[0] - b.initial_velocity_origin[0], dy = x[1] - b.initial_velocity_origin[1];
  return {b.initial_velocity[0] + L[0][0] * dx + L[0][1] * dy,
          b.initial_velocity[1] + L[1][0] * dx + L[1][1] * dy};
}

// The mesh of a body is a staircase of whole cells (build_mesh): a rigid body's nose of
// 2.5 mm cells is a stack of 2.5 mm steps, flat faces that push what they meet along the axis
// as a blunt nose would. A rigid body computes no element forces, so the boundary nodes of a
// rigid polygon or circle (without cuts) are moved onto the shape's outline (the nodes'
// positions and rigid offsets; the host mesh stays the staircase, from which masses, contact
// depths and selections are taken): its contact surface is then the shape to within the chords
// between nodes. The nodes' masses stay those of the staircase (the body's mass and centre are
// set before, build_rigid_bodies), which moves no mass by more than a cell.
void snap_rigid_surfaces(Model& model) {
  const HostMesh& m = model.mesh;
  std::vector<int> moved;
  std::vector<char> seen(m.position.size(), 0);
  for (size_t k = 0; k < m.boundary_edges.size(); ++k) {
    const Body& body = model.scene.bodies[m.boundary_edge_body[k]];
    if (body.method != BodyMethod::rigid || !body.cuts.empty()) continue;
    if (body.shape.type != Shape::Type::polygon && body.shape.type != Shape::Type::circle) continue;
    for (const int n : m.boundary_edges[k])
      if (!seen[n]) seen[n] = 1, moved.push_back(n);
  }
  if (moved.empty()) return;
  auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), model.nodes.x);
  auto x0 = Kokkos::create_mirror_view_and_copy(HostSpace(), model.nodes.x0);
  auto offset = Kokkos::create_mirror_view_and_copy(HostSpace(), model.rigid_offset);
  for (const int n : moved) {
    const Vec2 snapped =
        nearest_on_outline(model.scene.bodies[m.node_body[n]].shape, m.position[n]);
    for (int c = 0; c < 2; ++c) {
      const double shift = snapped[c] - m.position[n][c];
      x(n, c) += shift;
      x0(n, c) += shift;
      offset(n, c) += shift;
    }
  }
  Kokkos::deep_copy(model.nodes.x, x);
  Kokkos::deep_copy(model.nodes.x0, x0);
  Kokkos::deep_copy(model.rigid_offset, offset);
}

// The surfaces of the rigid bodies of revolution (RigidSurface, contact_forces.hpp): each
// boundary edge a -> b (counter-clockwise, the body on its left) links a to b, except the edges
// on the axis, which are no surface of the body of revolution. A surface node's radius (which
// only the search reads: its contacts are with the edges) becomes at least half of each of
// its edges, so that a disc touching an edge is a candidate of the edge's nearer end.
void build_rigid_surface(Model& model, std::vector<double>& radius) {
  const HostMesh& m = model.mesh;
  const auto position = Kokkos::create_mirror_view_and_copy(HostSpace(), model.nodes.x0);
  int begin = -1, end = -1;
  for (const RigidBody& r : model.rigid) {
    if (!r.axial_only) continue;
    begin = begin < 0 ? r.node_begin : std::min(begin, r.node_begin);
    end = std::max(end, r.node_end);
  }
  if (begin < 0) return;
  std::vector<int> link(2 * static_cast<size_t>(end - begin), -1);
  for (size_t k = 0; k < m.boundary_edges.size(); ++k) {
    const int a = m.boundary_edges[k][0], b = m.boundary_edges[k][1];
    if (a < begin || a >= end) continue;
    const int body = m.boundary_edge_body[k];
    if (model.scene.bodies[body].method != BodyMethod::rigid) continue;
    // The snapped positions (snap_rigid_surfaces).
    const double length =
        std::hypot(position(b, 0) - position(a, 0), position(b, 1) - position(a, 1));
    const double h = std::min(m.bodies[body].cell_x, m.bodies[body].cell_y);
    if (!(length > 1e-6 * h)) continue;  // two corners snapped to one point: no edge
    if (std::fabs(position(a, 0)) <= 1e-9 * length && std::fabs(position(b, 0)) <= 1e-9 * length)
      continue;
    link[2 * (a - begin) + 1] = b;
    link[2 * (b - begin) + 0] = a;
    radius[a] = std::max(radius[a], 0.5 * length);
    radius[b] = std::max(radius[b], 0.5 * length);
  }
  RigidSurface surface;
  surface.begin = begin;
  surface.end = end;
  surface.link = View<int* [2]>("fracta::rigid_surface_link", end - begin);
  auto host = Kokkos::create_mirror_view(surface.link);
  for (int n = 0; n < end - begin; ++n) {
    host(n, 0) = link[2 * n];
    host(n, 1) = link[2 * n + 1];
  }
  Kokkos::deep_copy(surface.link, host);
  model.rigid_surface = surface;
}

// The discs of set-up `de` cells spin with their body's initial velocity field: the rotation
// rate (dvy/dx - dvx/dy) / 2 of the gradient, so a rigidly rotating lattice starts unstrained.
void set_initial_spins(Model& model) {
  const Case& c = model.scene;
  const bool any = std::any_of(c.bodies.begin(), c.bodies.end(), [](const Body& b) {
    return b.initial_velocity_gradient[1][0] != b.initial_velocity_gradient[0][1];
  });
  if (!any || model.nodes.particle.extent(0) == 0) return;
  auto particle = Kokkos::create_mirror_view_and_copy(HostSpace(), model.nodes.particle);
  auto spin = Kokkos::create_mirror_view_and_copy(HostSpace(), model.nodes.spin);
  for (int n = 0; n < model.nodes.count; ++n) {
    if (!particle(n)) continue;
    const auto& L = c.bodies[model.mesh.node_body[n]].initial_velocity_gradient;
    spin(n) = 0.5 * (L[1][0] - L[0][1]);
  }
  Kokkos::deep_copy(model.nodes.spin, spin);
}

bool convertible(BodyMethod m) {
  return m == BodyMethod::de || m == BodyMethod::adaptive;
}

// The bonded lattice reproduces E and nu for 0 <= nu < 1/2: pair springs up to the classical
// Poisson limit (nu <= 1/3 in plane stress, 1/4 in plane strain), a volumetric cell term beyond
// (LatticeStiffness, cell_forces.hpp). Below 0 its diagonal springs would be negative.
void check_lattice_range(const Case& c) {
  for (const Body& b : c.bodies) {
    bool uses_lattice = convertible(b.method);
    for (const Region& r : b.regions) uses_lattice = uses_lattice || convertible(r.method);
    if (!uses_lattice) continue;
    const Material& mat = c.materials[b.material_index];
    if (mat.poisson_ratio < 0.0) {
      std::ostringstream msg;
      msg << "body '" << b.name << "' becomes bonded discs, but the disc lattice reproduces "
          << "Poisson's ratios from 0 to 1/2 only (its diagonal springs would be negative); "
          << "material '" << mat.name << "' has nu = " << mat.poisson_ratio
          << ". Use method = \"fe\" for this body";
      throw InputError(b.pos.file, b.pos.line, "body['" + b.name + "'].method", msg.str());
    }
  }
}

bool needs_particles(const Case& c) {
  for (const Body& b : c.bodies) {
    if (convertible(b.method)) return true;
    for (const Region& r : b.regions)
      if (convertible(r.method)) return true;
  }
  return false;
}

// Whether a material asks for random bond strengths (draw_heterogeneity).
bool draws_heterogeneity(const Case& c) {
  for (const Material& mat : c.materials)
    if (mat.weibull_modulus > 0.0 || mat.strength_spread > 0.0) return true;
  return false;
}

// Strength factors of the bond slots (kernels/heterogeneity.hpp: Weibull or uniform), when a
// material asks for them, and a note of their range for check and run. Reads every slot's
// topology (fill_slot_topology of every cell).
void draw_heterogeneity(Model& model) {
  const Case& c = model.scene;
  std::vector<StrengthDistribution> laws(c.materials.size());
  bool heterogeneous = false;
  for (size_t mi = 0; mi < c.materials.size(); ++mi) {
    const double m = c.materials[mi].weibull_modulus;
    const double spread = c.materials[mi].strength_spread;
    if (m > 0.0)
      laws[mi] = {m, 1.0 / std::tgamma(1.0 + 1.0 / m), 0.0};
    else if (spread > 0.0)
      laws[mi] = {0.0, 1.0, spread};
    else
      continue;
    heterogeneous = true;
  }
  Bonds& bonds = model.bonds;
  if (!heterogeneous || bonds.count == 0) return;
  bonds.strength_scale = View<double*>("fracta::bond_strength_scale", bonds.count);
  model.elements.cell_inverse_strength_scale =
      View<double*>("fracta::cell_inverse_strength_scale", model.elements.count);
  draw_strength_scales(bonds, model.elements, model.element_bonds,
                       to_device_1d<StrengthDistribution>("strength_laws", laws), c.sim.seed);
  double lowest = 0, highest = 0;
  const View<double*> scale = bonds.strength_scale;
  Kokkos::parallel_reduce(
      "fracta::strength_scale_range", Kokkos::RangePolicy<ExecSpace>(0, bonds.count),
      KOKKOS_LAMBDA(const int b, double& lo, double& hi) {
        lo = min_(lo, scale(b));
        hi = max_(hi, scale(b));
      },
      Kokkos::Min<double>(lowest), Kokkos::Max<double>(highest));
  char note[200];
  std::snprintf(note, sizeof note,
                "Random bond strengths, seed %llu: factors %.3g to %.3g of the strength over %d "
                "bond slots",
                static_cast<unsigned long long>(c.sim.seed), lowest, highest, bonds.count);
  model.notes.push_back(note);
}

// Bond slots (every edge once and every diagonal of the elements of convertible bodies, in the
// bond kernel's order; none when no body is convertible), particle views, the topology for contact
// exclusion, the contact system, and the time-0 conversion of de parts.
// A material's dynamic increase factors as the kernels read them (RateLaw): the table in log10
// of the strain rate; count 0 without a table.
RateLaw rate_law(const Material::RateTable& table) {
  static_assert(Material::RateTable::kMaxEntries == RateLaw::kMaxEntries);
  RateLaw law;
  law.count = static_cast<int>(table.strain_rate.size());
  for (int k = 0; k < law.count; ++k) {
    law.log10_rate[k] = std::log10(table.strain_rate[k]);
    law.strength[k] = table.strength[k];
    law.fracture_energy[k] = table.fracture_energy[k];
  }
  return law;
}

void build_lattice(Model& model, const std::vector<int>& converted) {
  const Case& c = model.scene;
  const HostMesh& m = model.mesh;
  const int nn = m.node_count(), ne = m.element_count();
  const bool plane_strain = c.sim.formulation == Formulation::plane_strain;
  const bool axisymmetric = c.sim.formulation == Formulation::axisymmetric;

  std::vector<std::array<int, 2>> slot_nodes;
  std::vector<int> slot_kind;
  std::vector<std::array<int, 6>> element_slots(ne);
  {
    // Freed before the views are made: 60 B or so per edge, the largest host array of the
    // set-up (150 MB of a million-cell mesh).
    std::map<std::pair<int, int>, int> edge_slot;
    for (int e = 0; e < ne; ++e) {
      element_slots[e].fill(-1);
      const Body& body = c.bodies[m.element_body[e]];
      bool lattice = convertible(body.method);
      for (const Region& r : body.regions) lattice = lattice || convertible(r.method);
      if (!lattice) continue;
      const auto& en = m.element_nodes[e];
      for (int a = 0; a < 4; ++a) {
        const int p = en[a], q = en[(a + 1) % 4];
        const auto key = std::make_pair(std::min(p, q), std::max(p, q));
        auto it = edge_slot.find(key);
        if (it == edge_slot.end()) {
          it = edge_slot.emplace(key, static_cast<int>(slot_nodes.size())).first;
          slot_nodes.push_back({key.first, key.second});
          slot_kind.push_back(kBondEdge);
        }
        element_slots[e][a] = it->second;
      }
    }
  }
  for (int e = 0; e < ne; ++e) {
    if (element_slots[e][0] < 0) continue;
    const auto& en = m.element_nodes[e];
    for (int d = 0; d < 2; ++d) {
      element_slots[e][4 + d] = static_cast<int>(slot_nodes.size());
      slot_nodes.push_back({en[d], en[d + 2]});
      slot_kind.push_back(kBondDiagonal);
    }
  }

  const int nb = static_cast<int>(slot_nodes.size());
  // Slot order for the bond kernel (bond_forces.hpp, BondForces::chunk): by block of
  // kBondSlotBlock nodes of the first end, then by the offset of the second end from the first,
  // then by the first end. On a mesh numbered row by row, a block's bonds then come as runs of
  // one direction (horizontal, vertical, the two diagonals) whose ends both advance by one node
  // per slot, which the kernel loads and adds as whole vectors; the block keeps the discs a
  // run touches in cache across the four directions. Any other mesh is only less regular.
  {
    constexpr int kBondSlotBlock = 1024;
    const auto key = [&](int s) {
      const auto& ends = slot_nodes[s];
      return std::make_tuple(ends[0] / kBondSlotBlock, ends[1] - ends[0], ends[0]);
    };
    std::vector<int> order(nb);
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return key(a) < key(b); });
    std::vector<int> new_slot(nb);
    std::vector<std::array<int, 2>> sorted_nodes(nb);
    std::vector<int> sorted_kind(nb);
    for (int k = 0; k < nb; ++k) {
      new_slot[order[k]] = k;
      sorted_nodes[k] = slot_nodes[order[k]];
      sorted_kind[k] = slot_kind[order[k]];
    }
    slot_nodes.swap(sorted_nodes);
    slot_kind.swap(sorted_kind);
    for (auto& slots : element_slots)
      for (int& s : slots)
        if (s >= 0) s = new_slot[s];
  }

  Bonds& bonds = model.bonds;
  bonds.count = nb;
  // Written where a cell converts (fill_slot_topology): untouched pages cost no memory.
  bonds.nodes = sparse_zero_view<View<int* [2]>>("fracta::bond_nodes", nb);
  bonds.length0 = sparse_zero_view<View<double*>>("fracta::bond_length0", nb);
  bonds.cells = sparse_zero_view<View<int* [2]>>("fracta::bond_cells", nb);
  bonds.material = sparse_zero_view<View<int*>>("fracta::bond_material", nb);
  bonds.state = sparse_zero_view<View<int*>>("fracta::bond_state", nb);
  bonds.kn = sparse_zero_view<View<double*>>("fracta::bond_kn", nb);
  bonds.ks = sparse_zero_view<View<double*>>("fracta::bond_ks", nb);
  bonds.area = sparse_zero_view<View<double*>>("fracta::bond_area", nb);
  bonds.fn = sparse_zero_view<View<double*>>("fracta::bond_fn", nb);
  bonds.fs = sparse_zero_view<View<double*>>("fracta::bond_fs", nb);
  bonds.plastic_n = sparse_zero_view<View<double*>>("fracta::bond_plastic_n", nb);
  bonds.plastic_s = sparse_zero_view<View<double*>>("fracta::bond_plastic_s", nb);
  bonds.hardening = sparse_zero_view<View<double*>>("fracta::bond_hardening", nb);
  bonds.plastic_work = sparse_zero_view<View<double*>>("fracta::bond_plastic_work", nb);
  bonds.damage = sparse_zero_view<View<double*>>("fracta::bond_damage", nb);
  bonds.onset_separation = sparse_zero_view<View<double*>>("fracta::bond_onset_separation", nb);
  bonds.final_separation = sparse_zero_view<View<double*>>("fracta::bond_final_separation", nb);
  model.element_bonds = to_device_rows("element_bonds", element_slots);
  std::vector<std::array<int, 2>> bond_cells(nb, std::array<int, 2>{-1, -1});
  for (int e = 0; e < ne; ++e)
    for (int a = 0; a < 6; ++a) {
      const int b = element_slots[e][a];
      if (b >= 0) bond_cells[b][bond_cells[b][0] < 0 ? 0 : 1] = e;
    }
  // The slots the time-0 conversion activates (every slot of a de cell), increasing: the used
  // list's start (Bonds::used), found here rather than by a sweep of every slot's state.
  std::vector<int> initial_used;
  for (const int e : converted)
    for (const int b : element_slots[e])
      if (b >= 0) initial_used.push_back(b);
  std::sort(initial_used.begin(), initial_used.end());
  initial_used.erase(std::unique(initial_used.begin(), initial_used.end()), initial_used.end());
  std::vector<std::array<int, 6>>().swap(element_slots);
  // Where the next slot continues a run, and which slots are diagonals (Bonds::run_next;
  // BondForces::batch relies on each condition: the ends and cells it does not read are one on
  // per lane, one law serves all, and a run is all edges or all diagonals).
  {
    const auto continues = [&](int b) {
      if (b + 1 >= nb || slot_kind[b + 1] != slot_kind[b] ||
          slot_nodes[b + 1][0] != slot_nodes[b][0] + 1 ||
          slot_nodes[b + 1][1] != slot_nodes[b][1] + 1)
        return false;
      int material = -1;
      for (int side = 0; side < 2; ++side) {
        const int cell = bond_cells[b][side], next = bond_cells[b + 1][side];
        if (cell < 0 ? next >= 0 : next != cell + 1) return false;
        if (cell < 0) continue;
        if (material < 0) material = m.element_material[cell];
        if (m.element_material[cell] != material || m.element_material[next] != material)
          return false;
      }
      return material >= 0;
    };
    std::vector<unsigned char> run_next(nb);
    for (int b = 0; b < nb; ++b)
      run_next[b] =
          (continues(b) ? kRunContinues : 0) | (slot_kind[b] == kBondDiagonal ? kRunNormalOnly : 0);
    bonds.run_next = to_device_1d<unsigned char>("bond_run_next", run_next);
  }
  std::vector<std::array<int, 2>>().swap(bond_cells);
  std::vector<int>().swap(slot_kind);
  model.elements.cell_stress = sparse_zero_view<View<double* [3]>>("fracta::cell_stress", ne);
  model.elements.cell_state = sparse_zero_view<View<int*>>("fracta::cell_state", ne);
  model.elements.cell_cracked = sparse_zero_view<View<int*>>("fracta::cell_cracked", ne);
  // Capacity for every cell: adaptive conversion appends to the list (its pages are used as it
  // grows), writing a batch's cells straight into the free part (Simulation::convert_elements).
  model.converted = sparse_zero_view<View<int*>>("fracta::converted_cells", ne);
  model.converted_count = static_cast<int>(converted.size());
  if (!converted.empty())
    Kokkos::deep_copy(Kokkos::subview(model.converted, std::make_pair(0, model.converted_count)),
                      to_device_1d<int>("converted_elements", converted));
  std::vector<int> adaptive(ne, 0);
  for (int e = 0; e < ne; ++e) adaptive[e] = m.element_method[e] == BodyMethod::adaptive;
  model.element_adaptive = to_device_1d<int>("element_adaptive", adaptive);
  model.has_adaptive = std::count(adaptive.begin(), adaptive.end(), 1) > 0;
  // Set when a cell converts, 0 for a de cell: empty where nothing converts (read as 0).
  model.elements.cell_strain_offset = sparse_zero_view<View<double* [3]>>(
      "fracta::cell_strain_offset", model.has_adaptive ? ne : 0);
  // The conversion's work space: none where nothing converts.
  model.active_scratch = View<int*>("fracta::active_scratch", model.has_adaptive ? ne : 0);

  // Per-material lattice stiffness and bond law.
  std::vector<LatticeStiffness> stiffness;
  std::vector<BondLaw> laws;
  // The largest cell side of the convertible cells of each material (the process zone check).
  std::vector<double> largest_cell(c.materials.size(), 0.0);
  for (int e = 0; e < ne; ++e) {
    if (!convertible(m.element_method[e])) continue;
    const auto& en = m.element_nodes[e];
    for (int a = 0; a < 4; ++a) {
      const Vec2& p = m.position[en[a]];
      const Vec2& q = m.position[en[(a + 1) % 4]];
      largest_cell[m.element_material[e]] =
          std::max(largest_cell[m.element_material[e]], std::hypot(q[0] - p[0], q[1] - p[1]));
    }
  }
  for (size_t mi = 0; mi < c.materials.size(); ++mi) {
    const Material& mat = c.materials[mi];
    // Rings (axisymmetric): plane stress per unit depth and the hoop term (LatticeStiffness).
    LatticeStiffness s = axisymmetric
                             ? axisymmetric_lattice_stiffness(mat.youngs_modulus, mat.poisson_ratio,
                                                              0.0, mat.fracture_energy)
                             : lattice_stiffness(mat.youngs_modulus, mat.poisson_ratio,
                                                 plane_strain, c.sim.thickness);
    BondLaw law;
    law.youngs_modulus_eff = s.youngs_modulus_eff;
    law.poisson_ratio_eff = s.poisson_ratio_eff;
    law.tensile_strength = mat.tensile_strength;
    // Resolving the process zone (docs/physics.md 1.2): a cohesive crack dissipates G_f and runs
    // at the speed G_f = g(v) G allows only when its process zone, of length
    // l = E* G_f / sigma_t^2, spans kCohesiveZoneCells cells; with fewer, the strength check of
    // the cell ahead traps the crack and the toughness is set by sigma_t and the cell size
    // (sigma_t^2 h / E*), not by G_f. The bond strength is then capped at
    // sqrt(E* G_f / (kCohesiveZoneCells h)): crack growth follows G_f, initiation from a smooth
    // surface comes at the capped strength (a crack band of the cell's width; Bazant & Oh 1983).
    if (mat.fracture_energy > 0.0 && mat.tensile_strength > 0.0 && largest_cell[mi] > 0.0) {
      const double cap = std::sqrt(s.youngs_modulus_eff * mat.fracture_energy /
                                   (kCohesiveZoneCells * largest_cell[mi]));
      if (cap < law.tensile_strength) {
        law.tensile_strength = cap;
        char note[400];
        std::snprintf(note, sizeof note,
                      "material '%s': cohesive zone E* G_f / sigma_t^2 = %.3g mm is below %g "
                      "cells of %.3g mm; bond tensile strength capped at %.4g MPa (crack growth "
                      "follows G_f; a smooth surface cracks at the capped strength)",
                      mat.name.c_str(),
                      1e3 * s.youngs_modulus_eff * mat.fracture_energy /
                          (mat.tensile_strength * mat.tensile_strength),
                      kCohesiveZoneCells, 1e3 * largest_cell[mi], cap / 1e6);
        model.notes.push_back(note);
      }
    }
    // Cohesive bonds: each bond's share of the crack area (BondLaw, bond_forces.hpp).
    law.fracture_energy = mat.fracture_energy;
    law.crack_area_factor[kBondEdge] = 1.0 / s.youngs_modulus_eff;
    law.crack_area_factor[kBondDiagonal] =
        (1.0 - s.poisson_ratio_eff) / (2.0 * std::sqrt(2.0) * s.youngs_modulus_eff);
    if (mat.model == MaterialModel::bilinear_j2) {
      law.yield_stress = mat.yield_stress;
      law.hardening = mat.plastic_modulus;
    }
    // johnson_cook bonds: elastoplastic at the initial flow stress A, no hardening.
    if (mat.model == MaterialModel::johnson_cook) law.yield_stress = mat.jc.a;
    if (mat.model == MaterialModel::mohr_coulomb) {
      law.cohesion = mat.cohesion;
      law.tan_friction = std::tan(mat.friction_angle);
    }
    law.rate = rate_law(mat.rate_dependence);
    laws.push_back(law);
    // The hoop term's strength: the bonds' (capped as they are, so the band of one cell still
    // dissipates G_f: HoopLaw).
    s.hoop.tensile_strength = axisymmetric ? law.tensile_strength : 0.0;
    stiffness.push_back(s);
  }
  model.lattice_stiffness = to_device_1d<LatticeStiffness>("lattice_stiffness", stiffness);
  model.bond_laws = to_device_1d<BondLaw>("bond_laws", laws);
  bonds.may_yield = bonds.may_soften = false;
  for (const BondLaw& law : laws) {
    bonds.may_yield = bonds.may_yield || law.springs().plastic();
    bonds.may_soften = bonds.may_soften || law.softening().cohesive();
  }
  // Set to length0 when a slot is activated (activate_element_bonds); only a conversion and a
  // yielding law change it after. Without either, it is length0 for the whole run: one view.
  bonds.rest_length = model.has_adaptive || bonds.may_yield
                          ? sparse_zero_view<View<double*>>("fracta::bond_rest_length", nb)
                          : bonds.length0;
  // The volumetric cell term (cell_forces.hpp) where a convertible cell's material needs it:
  // beyond the pair lattice's Poisson limit. Other scenes allocate and launch nothing for it.
  bool cell_term = false;
  for (size_t mi = 0; mi < c.materials.size(); ++mi)
    cell_term = cell_term ||
                (largest_cell[mi] > 0.0 && (stiffness[mi].kv > 0.0 || stiffness[mi].hoop.active()));
  if (cell_term) {
    model.elements.cell_volumetric_strain =
        sparse_zero_view<View<double*>>("fracta::cell_volumetric_strain", model.elements.count);
    build_cell_scatter_plan(model.elements);
  }
  if (cell_term && axisymmetric)
    model.elements.cell_hoop =
        sparse_zero_view<View<double* [4]>>("fracta::cell_hoop", model.elements.count);

  // Particle views of the nodes: radius half the cell, inertia m r^2 / 2, lambda k1.
  Nodes& nodes = model.nodes;
  nodes.particle = sparse_zero_view<View<int*>>("fracta::node_particle", nn);
  nodes.rotation = sparse_zero_view<View<double*>>("fracta::node_rotation", nn);
  nodes.spin = sparse_zero_view<View<double*>>("fracta::node_spin", nn);
  nodes.moment = View<double*>("fracta::node_moment", nn);

  {
    std::vector<double> radius(nn), inertia(nn), kc(nn);
    for (int n = 0; n < nn; ++n) {
      const BodyRange& r = m.bodies[m.node_body[n]];
      radius[n] = 0.5 * std::min(r.cell_x, r.cell_y);
    }
    // A perturbed grid (node_perturbation): no disc may overlap another of its cells at rest, or
    // a broken bond would release the overlap as a contact force; each disc takes at most half
    // its distance to every other corner of its cells.
    for (int e = 0; e < m.element_count(); ++e) {
      if (c.bodies[m.element_body[e]].node_perturbation == 0) continue;
      const auto& corner = m.element_nodes[e];
      for (int a = 0; a < 4; ++a)
        for (int b = a + 1; b < 4; ++b) {
          const Vec2 &p = m.position[corner[a]], &q = m.position[corner[b]];
          const double half = 0.5 * std::hypot(q[0] - p[0], q[1] - p[1]);
          radius[corner[a]] = std::min(radius[corner[a]], half);
          radius[corner[b]] = std::min(radius[corner[b]], half);
        }
    }
    build_rigid_surface(model, radius);
    auto mass = Kokkos::create_mirror_view_and_copy(HostSpace(), nodes.mass);
    // Axisymmetric: a node is a ring, and its contact stiffness (k1 per unit depth here, the
    // lattice being set up for depth `thickness`, 1) takes the ring's depth, its mass over
    // rho times its share of the area: the mean 2 pi r_c of its elements (pi h on the axis, so
    // a node there still resists).
    std::vector<double> depth(nn, 0.0);
    if (c.sim.formulation == Formulation::axisymmetric) {
      std::vector<double> area_share(nn, 0.0);
      for (int e = 0; e < ne; ++e)
        for (const int n : m.element_nodes[e]) area_share[n] += 0.25 * m.element_area(e);
      for (int n = 0; n < nn; ++n) {
        const double rho = c.materials[c.bodies[m.node_body[n]].material_index].density;
        if (area_share[n] > 0.0) depth[n] = mass(n) / (rho * area_share[n]);
      }
    }
    for (int n = 0; n < nn; ++n) {
      const Body& body = c.bodies[m.node_body[n]];
      inertia[n] = 0.5 * mass(n) * radius[n] * radius[n];
      kc[n] = c.contact.stiffness_factor * stiffness[body.material_index].k1;
      if (c.sim.formulation == Formulation::axisymmetric) kc[n] *= depth[n] / c.sim.thickness;
    }
    nodes.radius = to_device_1d<double>("node_radius", radius);
    nodes.inertia = to_device_1d<double>("node_inertia", inertia);
    nodes.contact_stiffness = to_device_1d<double>("node_contact_stiffness", kc);
  }

  // Topology (node -> bonds, node -> elements) for contact exclusion: CSR arrays built by
  // counting, each node's entries in increasing order. (A list per node held 170 MB of small
  // vectors for a million-cell mesh at the set-up's peak.)
  Topology& topo = model.topology;
  const auto csr = [nn](const int items, const int per_item, const auto& node_of,
                        const std::string& label, View<int*>& offset, View<int*>& ids) {
    std::vector<int> off(nn + 1, 0);
    for (int i = 0; i < items; ++i)
      for (int k = 0; k < per_item; ++k) ++off[node_of(i, k) + 1];
    for (int n = 0; n < nn; ++n) off[n + 1] += off[n];
    std::vector<int> flat(off[nn]), cursor(off.begin(), off.end() - 1);
    for (int i = 0; i < items; ++i)
      for (int k = 0; k < per_item; ++k) flat[cursor[node_of(i, k)]++] = i;
    offset = to_device_1d<int>(label + "_offset", off);
    ids = to_device_1d<int>(label, flat);
  };
  csr(
      ne, 4, [&](int e, int a) { return m.element_nodes[e][a]; }, "node_element",
      topo.node_element_offset, topo.node_element);
  topo.element_alive = model.elements.alive;
  topo.element_nodes = model.elements.nodes;
  topo.element_slots = model.element_bonds;
  topo.bond_state = bonds.state;

  // Nodes that may take part in contact (nodes.contact_disc, for the stable step): every node
  // of a convertible body's mesh that is or may become a particle, and every FE boundary node
  // (docs/physics.md 1.3). The contact itself tracks the discs that can touch now: the boundary
  // nodes and the particles (ContactSystem::track_surface, after the de parts below). Skin: a
  // quarter of the smallest cell.
  std::vector<int> disc(nn, 0), surface_nodes;
  double h_min = 1e300;
  for (size_t b = 0; b < c.bodies.size(); ++b)
    h_min = std::min({h_min, m.bodies[b].cell_x, m.bodies[b].cell_y});
  for (const auto& edge : m.boundary_edges) {
    disc[edge[0]] = disc[edge[1]] = 1;
    surface_nodes.insert(surface_nodes.end(), {edge[0], edge[1]});
  }
  for (int b = 0; b < nb; ++b) disc[slot_nodes[b][0]] = disc[slot_nodes[b][1]] = 1;
  nodes.contact_disc = to_device_1d<int>("node_contact_disc", disc);
  model.contacts = std::make_shared<ContactSystem>(std::vector<int>{}, c.contact, 0.25 * h_min);
  model.contacts->set_rigid_surface(model.rigid_surface);

  // Random strengths read every slot's ends and cells.
  if (draws_heterogeneity(c)) fill_slot_topology({}, 0, topo, nodes, bonds, true);
  draw_heterogeneity(model);

  // de parts: converted at time 0.
  const View<int*> conv = to_device_1d<int>("converted_elements", converted);
  fill_slot_topology(conv, static_cast<int>(converted.size()), topo, nodes, bonds);
  activate_element_bonds(conv, static_cast<int>(converted.size()), model.element_bonds,
                         model.lattice_stiffness, model.elements, nodes, bonds);

  // The used bond slots and the particles (state.hpp), kept up to date by the conversion.
  bonds.used = sparse_zero_view<View<int*>>("fracta::bond_used", nb);
  bonds.used_count = static_cast<int>(initial_used.size());
  if (bonds.used_count > 0)
    Kokkos::deep_copy(Kokkos::subview(bonds.used, std::make_pair(0, bonds.used_count)),
                      to_device_1d<int>("initial_used_bonds", initial_used));
  std::vector<int>().swap(initial_used);
  // The plan's chunks span the nodes of every slot, converted or not: cut from a temporary copy
  // of the set-up's ends.
  update_scatter_plan(bonds, to_device_rows("bond_plan_ends", slot_nodes));
  nodes.particle_list = sparse_zero_view<View<int*>>("fracta::node_particle_list", nn);
  nodes.bound_stale = sparse_zero_view<View<int*>>("fracta::node_bound_stale", nn);
  nodes.particle_count = build_particle_list(nodes);
  model.lists = ListWorkspace(std::max(nb, nn));
  model.contacts->set_lattice(topo, bonds);  // joined pairs stay out of the contact list
  model.contacts->track_surface(surface_nodes, nodes);
}

}  // namespace

Model build_model(const Case& c) {
  keep_large_blocks_mapped();  // before the mesh's views and the set-up's host vectors
  // A rigid part of a deformable body is not modelled: refuse, never ignore.
  for (const Body& b : c.bodies) {
    auto refuse = [&](BodyMethod m, const SourcePos& pos, const std::string& key) {
      if (m == BodyMethod::rigid && key.find(".region") != std::string::npos)
        throw InputError(pos.file, pos.line, key,
                         "a region cannot be rigid: make the whole body rigid");
    };
    refuse(b.method, b.pos, "body['" + b.name + "'].method");
    for (const Region& r : b.regions) refuse(r.method, r.pos, "body['" + b.name + "'].region");
  }
  check_lattice_range(c);
  Model model;
  {
    // Faster than a P-wave, an impact drives shocks, which the materials' laws (no equation of
    // state) do not describe; much faster is refused when the case is read (case.hpp).
    const ClosingSpeed closing = initial_closing_speed(c);
    const double wave = largest_p_wave_speed(c);
    if (closing.faster >= 0 && closing.speed > wave) {
      char note[320];
      std::snprintf(note, sizeof note,
                    "body '%s' closes on body '%s' at %.4g m/s, above the largest P-wave speed of "
                    "the materials (%.4g m/s): the shocks of such an impact are beyond the "
                    "materials' laws (no equation of state)",
                    c.bodies[closing.faster].name.c_str(), c.bodies[closing.slower].name.c_str(),
                    closing.speed, wave);
      model.notes.push_back(note);
    }
  }
  for (const Body& body : c.bodies) {
    // A perturbed lattice's bond strains scatter about their mean, so its first bonds fail below
    // the nominal strength (docs/validation.md, "The perturbed lattice").
    const Material& mat = c.materials[body.material_index];
    if (body.node_perturbation > 0 && body.method != BodyMethod::rigid &&
        (mat.tensile_strength > 0 || mat.cohesion > 0)) {
      char note[320];
      std::snprintf(note, sizeof note,
                    "body '%s': node_perturbation %.3g makes the lattice weaker than its "
                    "material's strengths (a brittle Brazilian disc fails at 0.74 of them at "
                    "0.15): calibrate them for the perturbed lattice",
                    body.name.c_str(), body.node_perturbation);
      model.notes.push_back(note);
    }
  }
  {
    // An adaptive body's lattice state takes memory as its cells convert (sparse_zero_view):
    // build_mesh refuses a case that does not fit at its start; say how much of it may convert
    // when not all of it fits.
    const MemoryEstimate e = estimate_memory(c);
    const double available = available_memory_bytes();
    if (available > 0 && e.bytes < available && e.bytes_all_converted > available) {
      char note[320];
      std::snprintf(note, sizeof note,
                    "memory: the run needs about %s at its start and %s of it is available, but "
                    "%s if every cell of its adaptive bodies converts: about %.0f %% of them can",
                    format_bytes(e.bytes).c_str(), format_bytes(available).c_str(),
                    format_bytes(e.bytes_all_converted).c_str(),
                    100.0 * (available - e.bytes) / (e.bytes_all_converted - e.bytes));
      model.notes.push_back(note);
    }
  }
  model.scene = c;
  model.mesh = build_mesh(c);
  const HostMesh& m = model.mesh;
  const int nn = m.node_count(), ne = m.element_count();
  const int qp = c.sim.integration == Integration::full ? 4 : 1;
  const bool axisymmetric = c.sim.formulation == Formulation::axisymmetric;

  for (const Material& mat : c.materials)
    model.host_materials.push_back(material_law(mat, c.sim.formulation));
  model.materials = View<MaterialLaw*>("fracta::materials", model.host_materials.size());
  {
    auto h = Kokkos::create_mirror_view(model.materials);
    for (size_t i = 0; i < model.host_materials.size(); ++i) h(i) = model.host_materials[i];
    Kokkos::deep_copy(model.materials, h);
  }

  // Nodes: positions, lumped masses rho A t / 4 per element corner (axisymmetric: 2 pi r_c for
  // t), initial velocities.
  Nodes& nodes = model.nodes;
  nodes.count = nn;
  nodes.x0 = View<double* [2]>("fracta::node_x0", nn);
  nodes.x = View<double* [2]>("fracta::node_x", nn);
  nodes.v = View<double* [2]>("fracta::node_v", nn);
  nodes.f = View<double* [2]>("fracta::node_f", nn);
  nodes.f_ext = View<double* [2]>("fracta::node_f_ext", nn);
  nodes.mass = View<double*>("fracta::node_mass", nn);
  nodes.fixed = View<int*>("fracta::node_fixed", nn);
  {
    auto x = Kokkos::create_mirror_view(nodes.x);
    auto v = Kokkos::create_mirror_view(nodes.v);
    auto mass = Kokkos::create_mirror_view(nodes.mass);
    auto fixed = Kokkos::create_mirror_view(nodes.fixed);
    Kokkos::deep_copy(mass, 0.0);
    Kokkos::deep_copy(fixed, 0);
    for (int n = 0; n < nn; ++n) {
      x(n, 0) = m.position[n][0];
      x(n, 1) = m.position[n][1];
      const Vec2 v0 = initial_velocity_at(c.bodies[m.node_body[n]], m.position[n]);
      v(n, 0) = v0[0];
      v(n, 1) = v0[1];
    }
    for (int e = 0; e < ne; ++e) {
      const auto& en = m.element_nodes[e];
      const double area = m.element_area(e);
      // Axisymmetric: the element's volume of revolution 2 pi r_c A (r_c the mean radius of its
      // corners, where the one-point forces are taken), lumped by quarters as in plane strain,
      // so each element's mass and stiffness scale alike (docs/physics.md 1.1, "Axisymmetry").
      const double depth = axisymmetric ? kTwoPi * m.element_mean_x(e) : c.sim.thickness;
      const double em = c.materials[m.element_material[e]].density * area * depth;
      for (int a = 0; a < 4; ++a) mass(en[a]) += 0.25 * em;
    }
    // Each component takes one kind of constraint: fixed (several fixed boundaries may hold
    // it), prescribed, or support; a bar is a force and combines with anything.
    enum Claim : int { kFree = 0, kFixedClaim, kPrescribedClaim, kSupportClaim };
    std::vector<std::array<int, 2>> claim(nn, {kFree, kFree}), claimed_by(nn, {-1, -1});
    if (axisymmetric) {
      // Nodes on the axis (x = 0) move along it only: v_r = 0 (docs/physics.md 1.1, "Axisymmetry").
      // A fixed claim, so a fixed_x boundary there agrees with it and nothing else may move them in
      // x.
      for (int n = 0; n < nn; ++n)
        if (m.position[n][0] <= 1e-9 * c.bodies[m.node_body[n]].cell_size) {
          claim[n][0] = kFixedClaim;
          fixed(n) |= kFixX;
          v(n, 0) = 0.0;
        }
    }
    for (size_t k = 0; k < c.boundaries.size(); ++k) {
      const Boundary& b = c.boundaries[k];
      const std::string key = "boundary[" + std::to_string(k) + "]";
      const auto sel = select_nodes(m, b.where, b.body_index);
      if (sel.empty()) throw InputError(b.pos.file, b.pos.line, key, "selects no node");
      int bits = 0, kind = kFree;
      switch (b.type) {
        case Boundary::Type::fixed_x:
          bits = kFixX, kind = kFixedClaim;
          break;
        case Boundary::Type::fixed_y:
          bits = kFixY, kind = kFixedClaim;
          break;
        case Boundary::Type::fixed:
          bits = kFixX | kFixY, kind = kFixedClaim;
          break;
        case Boundary::Type::velocity:
          bits = b.component == 0 ? kFixX : kFixY, kind = kPrescribedClaim;
          break;
        case Boundary::Type::support:
          bits = b.direction[0] != 0.0 ? kFixX : kFixY, kind = kSupportClaim;
          break;
        case Boundary::Type::bar:
          break;
      }
      for (int n : sel) {
        if (c.bodies[m.node_body[n]].method == BodyMethod::rigid && kind != kFixedClaim &&
            kind != kFree)
          throw InputError(b.pos.file, b.pos.line, key,
                           "selects nodes of the rigid body '" + c.bodies[m.node_body[n]].name +
                               "': velocity and support boundaries act on deformable bodies");
        for (int d = 0; d < 2; ++d) {
          if (!(bits & (1 << d))) continue;
          const int had = claim[n][d];
          if (had != kFree && !(had == kFixedClaim && kind == kFixedClaim)) {
            std::ostringstream msg;
            msg << "constrains the " << (d == 0 ? "x" : "y") << " velocity of the node at ("
                << m.position[n][0] << ", " << m.position[n][1] << ") m, which ";
            if (claimed_by[n][d] < 0)
              msg << "lies on the axis (formulation = \"axisymmetric\" holds v_x = 0 there)";
            else
              msg << "boundary[" << claimed_by[n][d] << "] already constrains";
            throw InputError(b.pos.file, b.pos.line, key, msg.str());
          }
          claim[n][d] = kind;
          claimed_by[n][d] = static_cast<int>(k);
          // Support components start free: update_supports holds them when they press.
          if (kind == kFixedClaim) {
            fixed(n) |= 1 << d;
            v(n, d) = 0.0;
          } else if (kind == kPrescribedClaim) {
            fixed(n) |= 1 << d;
            v(n, d) = b.value.front();  // V(0): a table is its first value up to its first time
          }
        }
      }
    }
    Kokkos::deep_copy(nodes.x, x);
    Kokkos::deep_copy(nodes.x0, x);
    Kokkos::deep_copy(nodes.v, v);
    Kokkos::deep_copy(nodes.mass, mass);
    Kokkos::deep_copy(nodes.fixed, fixed);
  }

  // Elements: those of fe parts are active; de parts are converted at time 0 (below).
  Elements& el = model.elements;
  el.count = ne;
  el.qp_per_element = qp;
  el.nodes = to_device_rows("element_nodes", m.element_nodes);
  el.material = to_device_1d<int>("element_material", m.element_material);
  el.body = to_device_1d<int>("element_body", m.element_body);
  std::vector<int> active, converted, rigid, alive(ne, 0);
  for (int e = 0; e < ne; ++e) {
    if (m.element_method[e] == BodyMethod::de) {
      converted.push_back(e);
    } else if (m.element_method[e] == BodyMethod::rigid) {
      alive[e] = 1;  // no FE forces, but it still joins its nodes (no self-contact)
      rigid.push_back(e);
    } else {
      active.push_back(e);
      alive[e] = 1;
    }
  }
  el.active_count = static_cast<int>(active.size());
  active.resize(ne, -1);  // capacity of every element: compaction swaps it with a scratch list
  el.active = to_device_1d<int>("element_active", active);
  el.rigid_count = static_cast<int>(rigid.size());
  el.rigid = to_device_1d<int>("element_rigid", rigid);
  el.alive = to_device_1d<int>("element_alive", alive);
  // The FE state. A scene whose elements are all de cells (no FE, rigid or adaptive element)
  // never integrates, reads or writes it: empty there (the force, stable-step, frame and energy
  // loops run over the active and rigid lists, and a de cell is never alive).
  const bool integrates = std::any_of(m.element_method.begin(), m.element_method.end(),
                                      [](BodyMethod method) { return method != BodyMethod::de; });
  const size_t fe_rows = integrates ? static_cast<size_t>(ne) : 0;
  el.stress = decltype(el.stress)("fracta::qp_stress", fe_rows * qp);
  el.epeq = View<double*>("fracta::qp_epeq", fe_rows * qp);
  el.qp_volume = View<double*>("fracta::qp_volume", fe_rows * qp);
  el.bulk_viscosity = View<double*>("fracta::qp_bulk_viscosity", fe_rows * qp);
  // The state of laws that keep one (hjc, johnson_cook), zero: intact, at rest density, at room
  // temperature.
  if (std::any_of(c.materials.begin(), c.materials.end(),
                  [](const Material& mat) { return mat.keeps_law_state(); }))
    el.law_state = View<double* [3]>("fracta::qp_law_state", fe_rows * qp);
  // The generalized hourglass displacement is the stiffness form's alone (fe_forces.hpp).
  el.hourglass_disp = decltype(el.hourglass_disp)(
      "fracta::element_hourglass_disp", c.sim.hourglass == HourglassForm::stiffness ? fe_rows : 0);
  el.hourglass_force = decltype(el.hourglass_force)("fracta::element_hourglass_force", fe_rows);
  el.recoverable_work = View<double*>("fracta::element_recoverable_work", fe_rows);
  // Reference sum b.b of the centre gradients, for the distortion criterion of adaptive bodies.
  if (std::count(m.element_method.begin(), m.element_method.end(), BodyMethod::adaptive) > 0) {
    std::vector<double> norm2(ne);
    for (int e = 0; e < ne; ++e) {
      double x[4], y[4];
      for (int a = 0; a < 4; ++a) {
        x[a] = m.position[m.element_nodes[e][a]][0];
        y[a] = m.position[m.element_nodes[e][a]][1];
      }
      double bx[4], by[4];
      centre_gradients(x, y, bx, by);
      norm2[e] = 0.0;
      for (int a = 0; a < 4; ++a) norm2[e] += bx[a] * bx[a] + by[a] * by[a];
    }
    el.reference_gradient_norm2 = to_device_1d<double>("reference_gradient_norm2", norm2);
  }
  update_scatter_plan(el);

  model.fe.thickness = c.sim.thickness;
  model.fe.axisymmetric = c.sim.formulation == Formulation::axisymmetric ? 1 : 0;
  model.fe.hourglass_stiffness = c.sim.hourglass == HourglassForm::stiffness ? 1 : 0;
  model.fe.hourglass_coefficient = c.sim.hourglass_coefficient;
  model.fe.bulk_linear = c.sim.bulk_viscosity_linear;
  model.fe.bulk_quadratic = c.sim.bulk_viscosity_quadratic;

  build_rigid_bodies(model);
  snap_rigid_surfaces(model);
  build_loads(model);
  build_boundaries(model);
  build_probes(model);
  // The lattice (bond slots of convertible bodies, disc views, contact) is built when a body can
  // hold discs or when several bodies can touch; a single FE body needs none of it.
  if (needs_particles(c) || c.bodies.size() > 1) build_lattice(model, converted);
  set_initial_spins(model);
  // The filtered velocities of rate-dependent bonds (filter_velocities), from the initial ones.
  const bool rate_dependent =
      std::any_of(c.materials.begin(), c.materials.end(),
                  [](const Material& mat) { return !mat.rate_dependence.strain_rate.empty(); });
  // The elements' rate-dependent tension cut-off (FeForces::tension_rates): mohr_coulomb and
  // hjc materials with a table, from the same strain rates.
  const auto rated_law = [](const Material& mat) {
    return mat.model == MaterialModel::mohr_coulomb || mat.model == MaterialModel::hjc;
  };
  const bool rated_elements =
      std::any_of(c.materials.begin(), c.materials.end(), [&](const Material& mat) {
        return rated_law(mat) && !mat.rate_dependence.strain_rate.empty();
      });
  if (rated_elements) {
    std::vector<RateLaw> rates(c.materials.size());
    for (size_t i = 0; i < c.materials.size(); ++i)
      if (rated_law(c.materials[i])) rates[i] = rate_law(c.materials[i].rate_dependence);
    model.tension_rates = to_device_1d<RateLaw>("tension_rates", rates);
    model.elements.tension_factor =
        View<double*>("fracta::element_tension_factor", model.elements.count);
    Kokkos::deep_copy(model.elements.tension_factor, 1.0);
  }
  if (rate_dependent && (model.bonds.count > 0 || rated_elements)) {
    model.nodes.v_filtered = View<double* [2]>("fracta::node_v_filtered", model.nodes.count);
    Kokkos::deep_copy(model.nodes.v_filtered, model.nodes.v);
  }
  // A run reads the device views alone: the host mesh's arrays per node and per element (the
  // reference positions, the connectivity, the bodies, materials and methods: about 48 B per
  // node, as much again as a step's own node state) go once they are. Its body ranges and
  // boundary edges stay.
  HostMesh& mesh = model.mesh;
  std::vector<Vec2>().swap(mesh.position);
  std::vector<int>().swap(mesh.node_body);
  std::vector<std::array<int, 4>>().swap(mesh.element_nodes);
  std::vector<int>().swap(mesh.element_body);
  std::vector<int>().swap(mesh.element_material);
  std::vector<BodyMethod>().swap(mesh.element_method);
  return model;
}

}  // namespace fracta
