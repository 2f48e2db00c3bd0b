// Helpers shared by the tests: scenes built in code (no case file needed).
#pragma once
#include <string>

#include <algorithm>

#include "host/case.hpp"
#include "host/simulation.hpp"

namespace fracta::test {

// One rectangular elastic body of nx x ny square cells of size h, plane strain unless told.
inline Case rectangle_case(int nx, int ny, double h, double E = 200e9, double nu = 0.3,
                           double rho = 7800.0, Formulation f = Formulation::plane_strain) {
  Case c;
  c.path = "<test>";
  c.sim.formulation = f;
  c.sim.thickness = 0.01;
  c.sim.end_time = 1e-6;
  Material m;
  m.name = "steel";
  m.model = MaterialModel::elastic;
  m.density = rho;
  m.youngs_modulus = E;
  m.poisson_ratio = nu;
  c.materials.push_back(m);
  Body b;
  b.name = "block";
  b.material = "steel";
  b.material_index = 0;
  b.cell_size = h;
  b.shape.type = Shape::Type::rectangle;
  b.shape.width = nx * h;
  b.shape.height = ny * h;
  c.bodies.push_back(b);
  return c;
}

inline Segment segment(double x0, double y0, double x1, double y1) {
  Segment s;
  s.from = {x0, y0};
  s.to = {x1, y1};
  return s;
}

inline void add_pressure(Case& c, const Segment& s, std::vector<double> t, std::vector<double> v) {
  Load l;
  l.type = Load::Type::pressure;
  l.body = c.bodies[0].name;
  l.body_index = 0;
  l.where.kind = NodeSelector::Kind::segment;
  l.where.segment = s;
  l.time = std::move(t);
  l.value = std::move(v);
  c.loads.push_back(l);
}

inline void add_traction(Case& c, const Segment& s, Vec2 direction, std::vector<double> t,
                         std::vector<double> v) {
  add_pressure(c, s, std::move(t), std::move(v));
  c.loads.back().type = Load::Type::traction;
  c.loads.back().direction = direction;
}

inline void add_fixed(Case& c, const Segment& s, Boundary::Type type) {
  Boundary b;
  b.type = type;
  b.where.kind = NodeSelector::Kind::segment;
  b.where.segment = s;
  c.boundaries.push_back(b);
}

inline void add_probe(Case& c, const std::string& name, double x, double y) {
  Probe p;
  p.name = name;
  p.at = {x, y};
  c.probes.push_back(p);
}

// Runs a simulation to its case's end time (or until it fails) and returns the worst relative
// energy error seen, checked every `every` steps.
inline double run_to_end(Simulation& sim, int every = 1) {
  double worst = 0.0;
  const double end = sim.model().scene.sim.end_time;
  while (sim.time() < end * (1 - 1e-12) && !sim.failed()) {
    sim.step();
    if (sim.steps() % every == 0) worst = std::max(worst, sim.history().energy.error);
  }
  return worst;
}

}  // namespace fracta::test
