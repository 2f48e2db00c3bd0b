// Building the model from a case (src/host/model.cpp): boundaries that claim the same velocity
// component in two ways, or act on a rigid body as only a deformable one can, are input errors
// naming the boundary; fixed boundaries may overlap and a bar combines with anything. A body's
// initial velocity field is linear: every node starts at v0 + L (x - x0), its discs spinning at
// the field's rotation rate. A rigid polygon's boundary nodes lie on its outline.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "host/case.hpp"
#include "host/mesh.hpp"
#include "host/model.hpp"
#include "kernels/compat.hpp"
#include "test_util.hpp"

namespace fracta {
namespace {

// A 10 x 4 cell block with its left edge held fixed in x (boundary[0]).
Case held_block() {
  Case c = test::rectangle_case(10, 4, 1e-3);
  test::add_fixed(c, test::segment(0, 0, 0, 4e-3), Boundary::Type::fixed_x);
  return c;
}

Boundary left_edge(Boundary::Type type) {
  Boundary b;
  b.type = type;
  b.where.kind = NodeSelector::Kind::segment;
  b.where.segment = test::segment(0, 0, 0, 4e-3);
  b.time = {0.0};
  b.value = {1.0};
  b.direction = {1.0, 0.0};
  b.impedance = 4e7;
  b.area = 1e-5;
  return b;
}

void expect_input_error(const Case& c, const std::string& key, const std::string& fragment) {
  try {
    build_model(c);
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.key, key) << e.what();
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

TEST(ModelBoundaries, APrescribedOrSupportedComponentCannotAlsoBeHeld) {
  for (const Boundary::Type type : {Boundary::Type::velocity, Boundary::Type::support}) {
    Case c = held_block();
    c.boundaries.push_back(left_edge(type));
    expect_input_error(c, "boundary[1]",
                       "constrains the x velocity of the node at (0, 0) m, "
                       "which boundary[0] already constrains");
  }
}

TEST(ModelBoundaries, FixedBoundariesOverlapAndABarCombinesWithAnything) {
  Case c = held_block();
  c.boundaries.push_back(left_edge(Boundary::Type::fixed));
  c.boundaries.push_back(left_edge(Boundary::Type::bar));
  EXPECT_NO_THROW(build_model(c));
}

TEST(ModelBoundaries, VelocityAndSupportActOnDeformableBodiesOnly) {
  for (const Boundary::Type type : {Boundary::Type::velocity, Boundary::Type::support}) {
    Case c = test::rectangle_case(10, 4, 1e-3);
    c.bodies[0].method = BodyMethod::rigid;
    c.boundaries.push_back(left_edge(type));
    expect_input_error(c, "boundary[0]", "selects nodes of the rigid body 'block'");
  }
}

// Exact: the field is evaluated at each node's position, with the same arithmetic.
TEST(ModelInitialVelocity, NodesStartOnTheLinearFieldAndDiscsAtItsRotationRate) {
  Case c = test::rectangle_case(6, 4, 1e-3, 30e9, 0.2, 2400.0);
  c.bodies[0].method = BodyMethod::de;
  c.bodies[0].initial_velocity = {3.0, -2.0};
  c.bodies[0].initial_velocity_gradient = {Vec2{1e3, -4e3}, Vec2{2e3, 5e2}};
  c.bodies[0].initial_velocity_origin = {1e-3, 2e-3};
  const Model model = build_model(c);
  auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), model.nodes.x);
  auto v = Kokkos::create_mirror_view_and_copy(HostSpace(), model.nodes.v);
  auto spin = Kokkos::create_mirror_view_and_copy(HostSpace(), model.nodes.spin);
  auto particle = Kokkos::create_mirror_view_and_copy(HostSpace(), model.nodes.particle);
  ASSERT_GT(model.nodes.count, 0);
  for (int n = 0; n < model.nodes.count; ++n) {
    const double dx = x(n, 0) - 1e-3, dy = x(n, 1) - 2e-3;
    EXPECT_EQ(v(n, 0), 3.0 + 1e3 * dx + -4e3 * dy) << "node " << n;
    EXPECT_EQ(v(n, 1), -2.0 + 2e3 * dx + 5e2 * dy) << "node " << n;
    EXPECT_EQ(particle(n), 1) << "node " << n;
    EXPECT_EQ(spin(n), 0.5 * (2e3 - -4e3)) << "node " << n;
  }
}

}  // namespace
}  // namespace fracta

namespace fracta {
namespace {

double distance_to_outline(const std::vector<Vec2>& p, const Vec2& q) {
  double best = 1e300;
  for (size_t i = 0, j = p.size() - 1; i < p.size(); j = i++)
    best = std::min(best, distance_to_segment(Segment{p[j], p[i], {}}, q[0], q[1]));
  return best;
}

// Exact (the construction): the boundary nodes of a rigid polygon (the main job's ogive-nose rod)
// lie on its outline after the set-up (within 1e-12 of the cell), its rigid offsets follow them
// (x = centre + offset), every surface edge off the axis is linked into the surface chain, and
// the deformable slab's nodes stay on the grid (a staircase).
TEST(ModelRigidSurface, RigidPolygonsBoundaryNodesLieOnItsOutline) {
  const Case c = load_case(std::string(FRACTA_SOURCE_DIR) + "/cases/perforation.toml", {});
  const Model m = build_model(c);
  ASSERT_EQ(m.rigid.size(), 1u);
  const RigidBody& rod = m.rigid[0];
  const auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), m.nodes.x);
  const auto x0 = Kokkos::create_mirror_view_and_copy(HostSpace(), m.nodes.x0);  // the grid's
  const auto offset = Kokkos::create_mirror_view_and_copy(HostSpace(), m.rigid_offset);
  const auto link = Kokkos::create_mirror_view_and_copy(HostSpace(), m.rigid_surface.link);
  const std::vector<Vec2>& outline = c.bodies[1].shape.points;
  const double h = c.bodies[1].cell_size;
  int surface_nodes = 0, linked_edges = 0, moved_slab_nodes = 0;
  for (size_t k = 0; k < m.mesh.boundary_edges.size(); ++k) {
    const auto& edge = m.mesh.boundary_edges[k];
    if (m.mesh.boundary_edge_body[k] == 0) {
      for (const int n : edge)
        if (x(n, 0) != x0(n, 0) || x(n, 1) != x0(n, 1)) ++moved_slab_nodes;
      continue;
    }
    for (const int n : edge) {
      EXPECT_LT(distance_to_outline(outline, {x(n, 0), x(n, 1)}), 1e-12 * h) << "node " << n;
      EXPECT_NEAR(x(n, 0), rod.x + offset(n, 0), 1e-15);
      EXPECT_NEAR(x(n, 1), rod.y + offset(n, 1), 1e-15);
      ++surface_nodes;
    }
    const bool on_axis = x(edge[0], 0) == 0.0 && x(edge[1], 0) == 0.0;
    const bool linked = link(edge[0] - m.rigid_surface.begin, 1) == edge[1] &&
                        link(edge[1] - m.rigid_surface.begin, 0) == edge[0];
    EXPECT_EQ(linked, !on_axis) << "edge " << edge[0] << " -> " << edge[1];
    linked_edges += linked;
  }
  EXPECT_GT(surface_nodes, 100);
  EXPECT_GT(linked_edges, 50);
  EXPECT_EQ(moved_slab_nodes, 0);
}

}  // namespace
}  // namespace fracta
