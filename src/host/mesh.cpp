#include "host/mesh.hpp"

#include <algorithm>
#include <cmath>

#include "host/memory.hpp"
#include "kernels/heterogeneity.hpp"

namespace fracta {

namespace {
constexpr double kPi = 3.14159265358979323846;

bool polygon_contains(const std::vector<Vec2>& p, double x, double y) {
  bool inside = false;  // even-odd ray casting
  for (size_t i = 0, j = p.size() - 1; i < p.size(); j = i++) {
    if ((p[i][1] > y) != (p[j][1] > y)) {
      const double xc = p[j][0] + (y - p[j][1]) * (p[i][0] - p[j][0]) / (p[i][1] - p[j][1]);
      if (x < xc) inside = !inside;
    }
  }
  return inside;
}

double polygon_distance(const std::vector<Vec2>& p, double x, double y) {
  double d = 1e300;
  for (size_t i = 0, j = p.size() - 1; i < p.size(); j = i++)
    d = std::min(d, distance_to_segment(Segment{p[j], p[i], {}}, x, y));
  return d;
}

// Minimum cell size over bodies: the natural length scale for geometric tolerances.
double tolerance_for(const HostMesh& m, int body) {
  double h = 1e300;
  for (size_t b = 0; b < m.bodies.size(); ++b)
    if (body < 0 || static_cast<int>(b) == body)
      h = std::min({h, m.bodies[b].cell_x, m.bodies[b].cell_y});
  return 0.25 * h;
}
}  // namespace

Vec2 nearest_on_segment(const Segment& s, double x, double y) {
  const double dx = s.to[0] - s.from[0], dy = s.to[1] - s.from[1];
  const double len2 = dx * dx + dy * dy;
  double t = len2 > 0 ? ((x - s.from[0]) * dx + (y - s.from[1]) * dy) / len2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  return {s.from[0] + t * dx, s.from[1] + t * dy};
}

double distance_to_segment(const Segment& s, double x, double y) {
  const Vec2 c = nearest_on_segment(s, x, y);
  return std::hypot(x - c[0], y - c[1]);
}

Vec2 nearest_on_outline(const Shape& s, const Vec2& p) {
  if (s.type == Shape::Type::circle) {
    const double dx = p[0] - s.x, dy = p[1] - s.y, d = std::hypot(dx, dy);
    return d > 0.0 ? Vec2{s.x + s.radius * dx / d, s.y + s.radius * dy / d} : p;
  }
  Vec2 best = p;
  double best_distance = 1e300;
  for (size_t i = 0, j = s.points.size() - 1; i < s.points.size(); j = i++) {
    const Vec2 c = nearest_on_segment(Segment{s.points[j], s.points[i], {}}, p[0], p[1]);
    const double d = std::hypot(p[0] - c[0], p[1] - c[1]);
    if (d < best_distance) best_distance = d, best = c;
  }
  return best;
}

bool shape_contains(const Shape& s, double x, double y, double tol) {
  switch (s.type) {
    case Shape::Type::rectangle:
      return x >= s.x - tol && x <= s.x + s.width + tol && y >= s.y - tol &&
             y <= s.y + s.height + tol;
    case Shape::Type::circle:
      return std::hypot(x - s.x, y - s.y) <= s.radius + tol;
    case Shape::Type::semicircle: {
      const double a = s.angle_deg * kPi / 180.0;
      const double along = (x - s.x) * std::cos(a) + (y - s.y) * std::sin(a);
      return std::hypot(x - s.x, y - s.y) <= s.radius + tol && along >= -tol;
    }
    case Shape::Type::polygon:
      return polygon_contains(s.points, x, y) ||
             (tol > 0 && polygon_distance(s.points, x, y) <= tol);
  }
  return false;
}

std::array<double, 4> shape_bounds(const Shape& s) {
  switch (s.type) {
    case Shape::Type::rectangle:
      return {s.x, s.y, s.x + s.width, s.y + s.height};
    case Shape::Type::circle:
      return {s.x - s.radius, s.y - s.radius, s.x + s.radius, s.y + s.radius};
    case Shape::Type::semicircle: {
      // Bounding box of the half disc: the flat side's ends and the arc's extreme points.
      const double a = s.angle_deg * kPi / 180.0, r = s.radius;
      std::vector<Vec2> pts{{s.x - r * std::sin(a), s.y + r * std::cos(a)},
                            {s.x + r * std::sin(a), s.y - r * std::cos(a)}};
      for (int k = 0; k < 4; ++k) {
        const double b = k * kPi / 2;
        if (std::cos(b - a) >= -1e-12)
          pts.push_back({s.x + r * std::cos(b), s.y + r * std::sin(b)});
      }
      std::array<double, 4> bb{1e300, 1e300, -1e300, -1e300};
      for (auto& p : pts) {
        bb[0] = std::min(bb[0], p[0]);
        bb[1] = std::min(bb[1], p[1]);
        bb[2] = std::max(bb[2], p[0]);
        bb[3] = std::max(bb[3], p[1]);
      }
      return bb;
    }
    case Shape::Type::polygon: {
      std::array<double, 4> bb{1e300, 1e300, -1e300, -1e300};
      for (auto& p : s.points) {
        bb[0] = std::min(bb[0], p[0]);
        bb[1] = std::min(bb[1], p[1]);
        bb[2] = std::max(bb[2], p[0]);
        bb[3] = std::max(bb[3], p[1]);
      }
      return bb;
    }
  }
  return {0, 0, 0, 0};
}

// Moves every interior node (all four cells around it kept) by a random displacement uniform in
// the disc of radius `radius` (m): r = radius sqrt(U1), angle 2 pi U2, with U1, U2 the counter-
// based draws of kernels/heterogeneity.hpp for the node's id (keys with the top bit set, which
// no bond key has), so the perturbation repeats bit for bit from the seed. Boundary nodes stay,
// so the shape, the cuts and the node sets of loads and boundaries are those of the regular
// grid.
template <class Interior>
void perturb_interior_nodes(HostMesh& m, double radius, std::uint64_t seed,
                            const Interior& interior, int nx, int ny,
                            const std::vector<int>& node_id) {
  constexpr std::uint64_t kNodeStream = 1ull << 63;
  for (int j = 1; j < ny; ++j)
    for (int i = 1; i < nx; ++i) {
      const int n = node_id[static_cast<size_t>(j) * (nx + 1) + i];
      if (n < 0 || !interior(i, j)) continue;
      const std::uint64_t key = kNodeStream | (2 * static_cast<std::uint64_t>(n));
      const double r = radius * std::sqrt(uniform_draw(seed, key));
      const double angle = 2 * M_PI * uniform_draw(seed, key + 1);
      m.position[n][0] += r * std::cos(angle);
      m.position[n][1] += r * std::sin(angle);
    }
}

HostMesh build_mesh(const Case& c) {
  check_memory(c);  // refuses absurd cell counts before anything is allocated
  HostMesh m;
  for (size_t b = 0; b < c.bodies.size(); ++b) {
    const Body& body = c.bodies[b];
    const auto bb = shape_bounds(body.shape);
    const double w = bb[2] - bb[0], h = bb[3] - bb[1];
    const BodyGrid grid = body_grid(body);  // bounded by check_memory: fits an int
    const int nx = static_cast<int>(grid.nx), ny = static_cast<int>(grid.ny);
    if (nx < 1 || ny < 1)  // fitting would silently change the cell size by more than 2x
      throw InputError(body.pos.file, body.pos.line, "body['" + body.name + "'].cell_size",
                       "the shape (" + std::to_string(w) + " x " + std::to_string(h) +
                           " m) is smaller than one cell of " + std::to_string(body.cell_size) +
                           " m");
    const double hx = w / nx, hy = h / ny;
    BodyRange r;
    r.node_begin = m.node_count();
    r.element_begin = m.element_count();
    r.cell_x = hx;
    r.cell_y = hy;
    // Node ids are assigned on first use, row by row, so a body's nodes are contiguous.
    std::vector<int> node_id(static_cast<size_t>(nx + 1) * (ny + 1), -1);
    auto node_at = [&](int i, int j) {
      int& id = node_id[static_cast<size_t>(j) * (nx + 1) + i];
      if (id < 0) {
        id = m.node_count();
        m.position.push_back({bb[0] + i * hx, bb[1] + j * hy});
        m.node_body.push_back(static_cast<int>(b));
      }
      return id;
    };
    std::vector<char> keep(static_cast<size_t>(nx) * ny, 0);
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const double cx = bb[0] + (i + 0.5) * hx, cy = bb[1] + (j + 0.5) * hy;
        bool in = shape_contains(body.shape, cx, cy);
        for (const Shape& cut : body.cuts) in = in && !shape_contains(cut, cx, cy);
        keep[static_cast<size_t>(j) * nx + i] = in;
      }
    // Create nodes row by row (j outer) so node order follows rows.
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) {
        bool used = false;
        for (int dj = -1; dj <= 0 && !used; ++dj)
          for (int di = -1; di <= 0 && !used; ++di) {
            const int ci = i + di, cj = j + dj;
            used =
                ci >= 0 && cj >= 0 && ci < nx && cj < ny && keep[static_cast<size_t>(cj) * nx + ci];
          }
        if (used) node_at(i, j);
      }
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        if (!keep[static_cast<size_t>(j) * nx + i]) continue;
        const double cx = bb[0] + (i + 0.5) * hx, cy = bb[1] + (j + 0.5) * hy;
        BodyMethod method = body.method;
        for (const Region& reg : body.regions)
          if (shape_contains(reg.shape, cx, cy)) method = reg.method;
        m.element_nodes.push_back(
            {node_at(i, j), node_at(i + 1, j), node_at(i + 1, j + 1), node_at(i, j + 1)});
        m.element_body.push_back(static_cast<int>(b));
        m.element_material.push_back(body.material_index);
        m.element_method.push_back(method);
      }
    r.node_end = m.node_count();
    r.element_end = m.element_count();
    if (r.element_end == r.element_begin)
      throw InputError(body.pos.file, body.pos.line, "body['" + body.name + "'].shape",
                       "the shape covers no cell of size " + std::to_string(body.cell_size) +
                           " m (make cell_size smaller or the shape larger)");
    // Boundary edges: element edges whose neighbouring cell across the edge is not kept (bodies
    // share no nodes). A grid lookup, linear in the cell count (a map of edges was not).
    auto kept = [&](int i, int j) {
      return i >= 0 && j >= 0 && i < nx && j < ny && keep[static_cast<size_t>(j) * nx + i];
    };
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        if (!kept(i, j)) continue;
        // Edge a runs from node a to node a + 1 (counter-clockwise): bottom, right, top, left.
        const int corner[4][2] = {{i, j}, {i + 1, j}, {i + 1, j + 1}, {i, j + 1}};
        const int across[4][2] = {{i, j - 1}, {i + 1, j}, {i, j + 1}, {i - 1, j}};
        for (int a = 0; a < 4; ++a) {
          if (kept(across[a][0], across[a][1])) continue;
          const int b1 = (a + 1) % 4;
          m.boundary_edges.push_back(
              {node_at(corner[a][0], corner[a][1]), node_at(corner[b1][0], corner[b1][1])});
          m.boundary_edge_body.push_back(static_cast<int>(b));
        }
      }
    if (body.node_perturbation > 0)
      perturb_interior_nodes(
          m, body.node_perturbation * std::min(hx, hy), c.sim.seed,
          [&](int i, int j) {
            return kept(i - 1, j - 1) && kept(i, j - 1) && kept(i - 1, j) && kept(i, j);
          },
          nx, ny, node_id);
    m.bodies.push_back(r);
  }
  return m;
}

std::vector<int> select_nodes(const HostMesh& m, const NodeSelector& sel, int body) {
  const double tol = tolerance_for(m, body);
  std::vector<int> out;
  for (int n = 0; n < m.node_count(); ++n) {
    if (body >= 0 && m.node_body[n] != body) continue;
    const auto& p = m.position[n];
    const bool hit = sel.kind == NodeSelector::Kind::segment
                         ? distance_to_segment(sel.segment, p[0], p[1]) <= tol
                         : shape_contains(sel.shape, p[0], p[1], tol);
    if (hit) out.push_back(n);
  }
  return out;
}

std::vector<std::array<int, 2>> select_edges(const HostMesh& m, const Segment& seg, int body) {
  const double tol = tolerance_for(m, body);
  std::vector<std::array<int, 2>> out;
  for (size_t k = 0; k < m.boundary_edges.size(); ++k) {
    if (body >= 0 && m.boundary_edge_body[k] != body) continue;
    const auto& pa = m.position[m.boundary_edges[k][0]];
    const auto& pb = m.position[m.boundary_edges[k][1]];
    if (distance_to_segment(seg, pa[0], pa[1]) <= tol &&
        distance_to_segment(seg, pb[0], pb[1]) <= tol)
      out.push_back(m.boundary_edges[k]);
  }
  return out;
}

}  // namespace fracta
