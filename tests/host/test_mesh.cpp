// Mesh generation: cell counts, staircased curved shapes, cuts, node and edge selection.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "host/mesh.hpp"
#include "test_util.hpp"

namespace fracta {
namespace {

double mesh_area(const HostMesh& m) {
  double a = 0;
  for (const auto& en : m.element_nodes) {
    const auto &p0 = m.position[en[0]], &p1 = m.position[en[1]], &p2 = m.position[en[2]],
               &p3 = m.position[en[3]];
    a += 0.5 * ((p2[0] - p0[0]) * (p3[1] - p1[1]) + (p1[0] - p3[0]) * (p2[1] - p0[1]));
  }
  return a;
}

// The paper's plate: 32 x 64 cells of 0.9375 mm, (33 x 65) nodes, every element counter-clockwise.
// [[body]] node_perturbation: interior nodes move within a disc of radius delta h, uniformly
// (exact: E r^2 = (delta h)^2 / 2 for a uniform disc; 3,249 nodes give it within 3 %), boundary
// nodes stay, every cell keeps a positive area and the same seed gives the same mesh bit for bit.
TEST(Mesh, PerturbedInteriorNodesStayInTheirDiscsAndRepeatFromTheSeed) {
  const double h = 1e-3, delta = 0.25;
  Case c = test::rectangle_case(58, 58, h);
  const HostMesh regular = build_mesh(c);
  c.bodies[0].node_perturbation = delta;
  c.sim.seed = 7;
  const HostMesh a = build_mesh(c), b = build_mesh(c);
  c.sim.seed = 8;
  const HostMesh other = build_mesh(c);
  ASSERT_EQ(a.node_count(), regular.node_count());
  double sum_r2 = 0, largest = 0;
  int moved = 0, differ = 0;
  for (int n = 0; n < a.node_count(); ++n) {
    const double dx = a.position[n][0] - regular.position[n][0];
    const double dy = a.position[n][1] - regular.position[n][1];
    const auto& p = regular.position[n];
    const bool boundary = std::min({p[0], p[1], 58 * h - p[0], 58 * h - p[1]}) < 0.5 * h;
    EXPECT_EQ(a.position[n], b.position[n]);
    differ += other.position[n] != a.position[n];
    if (boundary) {
      EXPECT_EQ(dx, 0.0);
      EXPECT_EQ(dy, 0.0);
      continue;
    }
    ++moved;
    sum_r2 += dx * dx + dy * dy;
    largest = std::max(largest, std::hypot(dx, dy));
  }
  EXPECT_EQ(moved, 57 * 57);
  EXPECT_EQ(differ, moved);
  EXPECT_LE(largest, delta * h * (1 + 1e-12));
  EXPECT_GT(largest, 0.95 * delta * h);
  EXPECT_NEAR(sum_r2 / moved, 0.5 * delta * delta * h * h, 0.03 * 0.5 * delta * delta * h * h);
  EXPECT_NEAR(mesh_area(a), mesh_area(regular), 1e-12 * mesh_area(regular));
  for (const auto& en : a.element_nodes) {
    const auto &p0 = a.position[en[0]], &p1 = a.position[en[1]], &p2 = a.position[en[2]],
               &p3 = a.position[en[3]];
    EXPECT_GT(0.5 * ((p2[0] - p0[0]) * (p3[1] - p1[1]) + (p1[0] - p3[0]) * (p2[1] - p0[1])),
              0.25 * h * h);
  }
}

TEST(Mesh, RectangleHasExactCountsAndArea) {
  Case c = test::rectangle_case(32, 64, 0.9375e-3);
  const HostMesh m = build_mesh(c);
  EXPECT_EQ(m.element_count(), 2048);
  EXPECT_EQ(m.node_count(), 33 * 65);
  EXPECT_NEAR(mesh_area(m), 0.03 * 0.06, 1e-15);
  EXPECT_EQ(m.boundary_edges.size(), 2u * (32 + 64));
}

// A circle of radius R staircased by cells of h: the area converges to pi R^2 at O(h / R).
TEST(Mesh, CircleAndSemicircleAreasConverge) {
  Case c = test::rectangle_case(1, 1, 0.5e-3);
  c.bodies[0].shape.type = Shape::Type::circle;
  c.bodies[0].shape.radius = 0.02;
  const double circle = mesh_area(build_mesh(c));
  EXPECT_NEAR(circle, M_PI * 0.02 * 0.02, 0.02 * M_PI * 0.02 * 0.02);  // h/R = 2.5%
  c.bodies[0].shape.type = Shape::Type::semicircle;                    // arc above the flat side
  const HostMesh half = build_mesh(c);
  EXPECT_NEAR(mesh_area(half), 0.5 * M_PI * 0.02 * 0.02, 0.03 * 0.5 * M_PI * 0.02 * 0.02);
  for (const auto& p : half.position) EXPECT_GE(p[1], -1e-12);
}

// A notch cut (1 mm x 5 mm in 0.5 mm cells) removes exactly its 2 x 10 cells.
TEST(Mesh, CutRemovesTheNotchCells) {
  Case c = test::rectangle_case(40, 20, 0.5e-3);
  Shape notch;
  notch.type = Shape::Type::rectangle;
  notch.x = 9.5e-3;
  notch.y = 0.0;
  notch.width = 1e-3;
  notch.height = 5e-3;
  c.bodies[0].cuts.push_back(notch);
  const HostMesh m = build_mesh(c);
  EXPECT_EQ(m.element_count(), 40 * 20 - 2 * 10);
}

TEST(Mesh, SegmentSelectsEdgeNodesAndEdges) {
  Case c = test::rectangle_case(8, 4, 1e-3);
  const HostMesh m = build_mesh(c);
  NodeSelector left;
  left.segment = test::segment(0, 0, 0, 4e-3);
  EXPECT_EQ(select_nodes(m, left, 0).size(), 5u);
  EXPECT_EQ(select_edges(m, left.segment, 0).size(), 4u);
  NodeSelector box;
  box.kind = NodeSelector::Kind::shape;
  box.shape.width = 2e-3;
  box.shape.height = 4e-3;
  EXPECT_EQ(select_nodes(m, box, 0).size(), 3u * 5u);
}

TEST(Mesh, ShapeCoveringNoCellIsAnInputError) {
  Case c = test::rectangle_case(1, 1, 1e-3);
  c.bodies[0].shape.type = Shape::Type::circle;
  c.bodies[0].shape.radius = 1e-4;  // smaller than half a cell: no cell centre inside
  c.bodies[0].shape.x = 0.3e-3;
  EXPECT_THROW(build_mesh(c), InputError);
}

// Boundary edges come from a grid lookup (linear in the cells); the reference is the definition:
// element edges that belong to exactly one element, counted over all elements with a map, in
// element order. Two bodies, one a disc with a hole and a notch, so inner boundaries count too.
TEST(Mesh, BoundaryEdgesAreTheEdgesOfExactlyOneElement) {
  Case c = test::rectangle_case(20, 10, 1e-3);
  Body disc = c.bodies[0];
  disc.name = "disc";
  disc.shape.type = Shape::Type::circle;
  disc.shape.x = 0.05;
  disc.shape.radius = 0.012;
  Shape hole;
  hole.type = Shape::Type::circle;
  hole.x = 0.052;
  hole.radius = 0.004;
  Shape notch;
  notch.x = 0.038;
  notch.y = -0.001;
  notch.width = 0.008;
  notch.height = 0.002;
  disc.cuts = {hole, notch};
  c.bodies.push_back(disc);
  const HostMesh m = build_mesh(c);
  std::map<std::pair<int, int>, int> uses;
  for (const auto& en : m.element_nodes)
    for (int a = 0; a < 4; ++a)
      uses[{std::min(en[a], en[(a + 1) % 4]), std::max(en[a], en[(a + 1) % 4])}]++;
  std::vector<std::array<int, 2>> expected;
  std::vector<int> expected_body;
  for (int e = 0; e < m.element_count(); ++e)
    for (int a = 0; a < 4; ++a) {
      const int p = m.element_nodes[e][a], q = m.element_nodes[e][(a + 1) % 4];
      if (uses[{std::min(p, q), std::max(p, q)}] == 1) {
        expected.push_back({p, q});
        expected_body.push_back(m.element_body[e]);
      }
    }
  EXPECT_EQ(m.boundary_edges, expected);
  EXPECT_EQ(m.boundary_edge_body, expected_body);
  EXPECT_GT(expected.size(), 2u * (20 + 10) + 60u);  // the disc, its hole and notch add edges
}

}  // namespace
}  // namespace fracta
