// Structured mesh generation (host): each body is covered by a grid of near-square cells of its
// `cell_size`, fitted to the shape's bounding box; a cell belongs to the body when its centre
// lies inside the shape and outside every cut. Curved boundaries are therefore staircased at
// the cell size, as in the paper's meshes.
#pragma once
#include <array>
#include <vector>

#include "host/case.hpp"

namespace fracta {

struct BodyRange {
  int node_begin = 0, node_end = 0;        // nodes [begin, end)
  int element_begin = 0, element_end = 0;  // elements [begin, end)
  double cell_x = 0, cell_y = 0;           // actual cell sizes (m)
};

// build_model keeps the body ranges and boundary edges of its mesh and frees the rest once the
// device views hold it (Model::mesh).
struct HostMesh {
  std::vector<Vec2> position;  // reference node positions (m)
  std::vector<int> node_body;
  std::vector<std::array<int, 4>> element_nodes;  // counter-clockwise
  std::vector<int> element_body;
  std::vector<int> element_material;
  std::vector<BodyMethod> element_method;  // body method, or its region's
  std::vector<BodyRange> bodies;
  // Boundary edges (node a -> node b in counter-clockwise element order), per body.
  std::vector<std::array<int, 2>> boundary_edges;
  std::vector<int> boundary_edge_body;

  int node_count() const { return static_cast<int>(position.size()); }
  int element_count() const { return static_cast<int>(element_nodes.size()); }
  // Element e's area (m^2, the shoelace formula over its diagonals) and the mean radius of its
  // corners (m; x, in an axisymmetric model), in the reference configuration.
  double element_area(int e) const {
    const auto& en = element_nodes[e];
    const Vec2 &p0 = position[en[0]], &p1 = position[en[1]], &p2 = position[en[2]],
               &p3 = position[en[3]];
    return 0.5 * ((p2[0] - p0[0]) * (p3[1] - p1[1]) + (p1[0] - p3[0]) * (p2[1] - p0[1]));
  }
  double element_mean_x(int e) const {
    const auto& en = element_nodes[e];
    return 0.25 *
           (position[en[0]][0] + position[en[1]][0] + position[en[2]][0] + position[en[3]][0]);
  }
};

// Throws InputError (naming the body) when a body gets no cell.
HostMesh build_mesh(const Case& c);

bool shape_contains(const Shape& s, double x, double y, double tol = 0.0);
std::array<double, 4> shape_bounds(const Shape& s);  // xmin, ymin, xmax, ymax
double distance_to_segment(const Segment& s, double x, double y);
Vec2 nearest_on_segment(const Segment& s, double x, double y);
// The point of a polygon's or circle's outline nearest p.
Vec2 nearest_on_outline(const Shape& s, const Vec2& p);

// Nodes of `body` (-1: any body) selected by a segment (within tol of it) or a shape.
std::vector<int> select_nodes(const HostMesh& m, const NodeSelector& sel, int body);
// Boundary edges of `body` whose two nodes lie within tol of the segment.
std::vector<std::array<int, 2>> select_edges(const HostMesh& m, const Segment& seg, int body);

}  // namespace fracta
