// Helpers shared by the tests: scenes built in code (no case file needed).
#pragma once
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#include "host/case.hpp"
#include "host/cracks.hpp"
#include "host/simulation.hpp"

namespace fracta::test {

// Sets FRACTA_MEMORY_LIMIT_BYTES (or unsets it for nullptr) for one scope.
class MemoryLimit {
 public:
  explicit MemoryLimit(const char* bytes) {
    if (const char* old = std::getenv("FRACTA_MEMORY_LIMIT_BYTES")) saved_ = old;
    if (bytes)
      setenv("FRACTA_MEMORY_LIMIT_BYTES", bytes, 1);
    else
      unsetenv("FRACTA_MEMORY_LIMIT_BYTES");
  }
  ~MemoryLimit() {
    if (saved_.empty())
      unsetenv("FRACTA_MEMORY_LIMIT_BYTES");
    else
      setenv("FRACTA_MEMORY_LIMIT_BYTES", saved_.c_str(), 1);
  }

 private:
  std::string saved_;
};

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

// The largest difference of two equally long series, relative to the first's largest magnitude
// (the absolute difference if that is 0).
inline double max_relative_difference(const std::vector<double>& a, const std::vector<double>& b) {
  double scale = 0.0, diff = 0.0;
  for (size_t i = 0; i < a.size(); ++i) {
    scale = std::max(scale, std::fabs(a[i]));
    diff = std::max(diff, std::fabs(a[i] - b[i]));
  }
  return scale > 0.0 ? diff / scale : diff;
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

// Direction (degrees, in (-90, 90]) of the line through `origin` fitted by least squares (the
// principal axis of sum r r^T) to the points of a crack's path between r_min and r_max (m) from
// it; `points` gets how many there were.
inline double path_angle_through(const CrackTrace& t, Vec2 origin, double r_min, double r_max,
                                 int* points = nullptr) {
  double sxx = 0, sxy = 0, syy = 0;
  int used = 0;
  for (const Vec2& p : t.path) {
    const double rx = p[0] - origin[0], ry = p[1] - origin[1], r = std::hypot(rx, ry);
    if (r < r_min || r > r_max) continue;
    sxx += rx * rx, sxy += rx * ry, syy += ry * ry;
    ++used;
  }
  if (points) *points = used;
  return 0.5 * std::atan2(2 * sxy, sxx - syy) * 180 / M_PI;
}

// Rayleigh speed of a plane-stress plate (m/s): Viktorov's (0.862 + 1.14 v) / (1 + v) c_s with
// the in-plane Poisson ratio v = nu / (1 + nu) of plane stress (the formula is for plane strain).
inline double plane_stress_rayleigh_speed(double E, double nu, double rho) {
  const double shear_speed = std::sqrt(E / (2 * (1 + nu)) / rho), v = nu / (1 + nu);
  return (0.862 + 1.14 * v) / (1 + v) * shear_speed;
}

// An angle of a line (degrees) brought into (-90, 90].
inline double line_angle(double degrees) {
  while (degrees > 90) degrees -= 180;
  while (degrees <= -90) degrees += 180;
  return degrees;
}

// A `velocity` boundary named `name` on the nodes within tol of segment s: component (0 = x,
// 1 = y) follows the table (t, v).
inline void add_velocity(Case& c, const std::string& name, const Segment& s, int component,
                         std::vector<double> t, std::vector<double> v) {
  Boundary b;
  b.name = name;
  b.type = Boundary::Type::velocity;
  b.component = component;
  b.where.kind = NodeSelector::Kind::segment;
  b.where.segment = s;
  b.time = std::move(t);
  b.value = std::move(v);
  c.boundaries.push_back(b);
}

inline void add_probe(Case& c, const std::string& name, double x, double y) {
  Probe p;
  p.name = name;
  p.at = {x, y};
  c.probes.push_back(p);
}

// Time at which v first reaches v_half (linear interpolation between samples); -1 if never.
inline double arrival_time(const std::vector<double>& t, const std::vector<double>& v,
                           double v_half) {
  for (size_t i = 1; i < t.size(); ++i)
    if (v[i - 1] < v_half && v[i] >= v_half)
      return t[i - 1] + (v_half - v[i - 1]) / (v[i] - v[i - 1]) * (t[i] - t[i - 1]);
  return -1.0;
}

// Plane longitudinal wave in a strip with rollers on its long sides (eps_yy = 0): the exact
// solution is a step travelling at c with particle velocity v = p / (rho c) behind it, where
// plane stress c = sqrt(E / (rho (1 - nu^2))) and plane strain
// c = sqrt(E (1 - nu) / (rho (1 + nu) (1 - 2 nu))).
struct PlaneWaveResult {
  double speed, plateau, c_exact, v_exact;  // m/s
  double worst_energy_error;                // over every step
  double final_energy_error;                // at the end
  double hourglass_fraction;                // hourglass work / external work at the end
};

// x0: where the strip starts (m; axisymmetric: the radius of its bore).
inline PlaneWaveResult run_plane_wave(Formulation f, BodyMethod method = BodyMethod::fe,
                                      double nu = 0.3, double x0 = 0.0) {
  const double h = 0.5e-3, E = 232e9, rho = 7800.0, p = 500e6;
  const int nx = 160, ny = 4;  // 80 mm long strip
  Case c = rectangle_case(nx, ny, h, E, nu, rho, f);
  c.bodies[0].method = method;
  c.bodies[0].shape.x = x0;
  const double L = nx * h, H = ny * h;
  add_pressure(c, segment(x0, 0, x0, H), {0.0, 1.0}, {p, p});  // step load
  add_fixed(c, segment(x0, 0, x0 + L, 0), Boundary::Type::fixed_y);
  add_fixed(c, segment(x0, H, x0 + L, H), Boundary::Type::fixed_y);
  add_probe(c, "x20", x0 + 20e-3, H / 2);
  add_probe(c, "x50", x0 + 50e-3, H / 2);
  const double c_exact = f == Formulation::plane_stress
                             ? std::sqrt(E / (rho * (1 - nu * nu)))
                             : std::sqrt(E * (1 - nu) / (rho * (1 + nu) * (1 - 2 * nu)));
  const double v_exact = p / (rho * c_exact);
  c.sim.end_time = 0.95 * L / c_exact;  // stop before the front reaches the far end
  Simulation sim(c);
  std::vector<double> t, v1, v2;
  double worst = 0.0;
  while (sim.time() < c.sim.end_time * (1 - 1e-12) && !sim.failed()) {
    sim.step();
    const auto pr = sim.probe_records();
    t.push_back(sim.time());
    v1.push_back(pr[0].vx);
    v2.push_back(pr[1].vx);
    worst = std::max(worst, sim.history().energy.error);
  }
  const double t1 = arrival_time(t, v1, 0.5 * v_exact), t2 = arrival_time(t, v2, 0.5 * v_exact);
  // Plateau at the second probe: mean over the window from the front's passage 9 mm (18 cells)
  // beyond it to the end (the front's ringing has decayed there, and no reflection has come
  // back): 1.5 us at the plane-stress speed of steel, scaled with the speed for other nu.
  double sum = 0;
  int count = 0;
  for (size_t i = 0; i < t.size(); ++i)
    if (t[i] > t2 + 9e-3 / c_exact) {
      sum += v2[i];
      ++count;
    }
  const HistoryRecord end = sim.history();
  const double hourglass = end.energy.external > 0 ? end.energy.hourglass / end.energy.external : 0;
  return {30e-3 / (t2 - t1), count ? sum / count : 0.0, c_exact, v_exact, worst, end.energy.error,
          hourglass};
}

// Axial plane wave in a rod of revolution (formulation = "axisymmetric"): radius 2 mm (4 cells of
// 0.5 mm), 80 mm long, held radially on its mantle (uniaxial strain), a 500 MPa step on its
// end; the body's method a parameter. Exact: a step at c = sqrt((lambda + 2 mu) / rho) with
// particle velocity p / (rho c), the same at every radius, no radial motion. Measured: the
// half-amplitude arrivals on the axis 20 and 50 mm from the loaded end and at the mantle 50 mm
// from it, the speed between the axis probes, the plateaus 50 mm from the end (from 9 mm
// behind the front to the end), the largest radial probe velocity.
struct AxialWaveResult {
  double speed, axis, mantle, c_exact, v_exact;  // m/s
  double t_near, t_axis, t_mantle;               // arrivals (s; -1 if none)
  double largest_radial;                         // m/s
  int plateau_samples;
};

inline AxialWaveResult run_axial_wave(BodyMethod method) {
  const double h = 0.5e-3, E = 232e9, nu = 0.3, rho = 7800.0, p = 500e6;
  const int nr = 4, nz = 160;
  Case c = rectangle_case(nr, nz, h, E, nu, rho, Formulation::axisymmetric);
  c.bodies[0].method = method;
  const double R = nr * h, L = nz * h;
  add_pressure(c, segment(0, L, R, L), {0.0, 1.0}, {p, p});
  add_fixed(c, segment(R, 0, R, L), Boundary::Type::fixed_x);
  add_probe(c, "z60_axis", 0.0, L - 20e-3);
  add_probe(c, "z30_axis", 0.0, L - 50e-3);
  add_probe(c, "z30_mantle", R - h, L - 50e-3);
  AxialWaveResult r{};
  r.c_exact = std::sqrt(E * (1 - nu) / (rho * (1 + nu) * (1 - 2 * nu)));
  r.v_exact = p / (rho * r.c_exact);
  c.sim.end_time = 0.95 * L / r.c_exact;
  Simulation sim(c);
  std::vector<double> t, v1, v2, v3;
  while (sim.time() < c.sim.end_time * (1 - 1e-12) && !sim.failed()) {
    sim.step();
    const auto pr = sim.probe_records();
    t.push_back(sim.time());
    v1.push_back(-pr[0].vy);
    v2.push_back(-pr[1].vy);
    v3.push_back(-pr[2].vy);
    for (const auto& q : pr) r.largest_radial = std::max(r.largest_radial, std::fabs(q.vx));
  }
  EXPECT_FALSE(sim.failed()) << sim.failure();
  r.t_near = arrival_time(t, v1, 0.5 * r.v_exact);
  r.t_axis = arrival_time(t, v2, 0.5 * r.v_exact);
  r.t_mantle = arrival_time(t, v3, 0.5 * r.v_exact);
  r.speed = 30e-3 / (r.t_axis - r.t_near);
  for (size_t i = 0; i < t.size(); ++i)
    if (t[i] > r.t_axis + 9e-3 / r.c_exact) {
      r.axis += v2[i];
      r.mantle += v3[i];
      ++r.plateau_samples;
    }
  if (r.plateau_samples > 0) {
    r.axis /= r.plateau_samples;
    r.mantle /= r.plateau_samples;
  }
  return r;
}

// A steel projectile (bilinear J2, 20 x 25 mm) striking a concrete slab (Mohr-Coulomb,
// 80 x 30 mm) at `speed` (m/s), plane strain, coarse 3.333 mm cells. The slab's and the
// projectile's methods are parameters (the default is an adaptive slab and an FE projectile).
// length_scale multiplies every length (cells, shapes, thickness) and time (end time), leaving
// the speeds, stresses and the dimensionless answer unchanged.
inline Case impact_case(double speed, BodyMethod slab = BodyMethod::adaptive,
                        BodyMethod projectile = BodyMethod::fe, double length_scale = 1.0) {
  const double h = 3.333e-3 * length_scale;
  Case c = rectangle_case(24, 9, h, 92e9, 0.21, 2400.0, Formulation::plane_strain);
  c.sim.thickness = 1.0 * length_scale;
  Material& concrete = c.materials[0];
  concrete.name = "concrete";
  concrete.model = MaterialModel::mohr_coulomb;
  concrete.cohesion = 11.2e6;
  concrete.friction_angle = std::atan(0.125);
  concrete.tensile_strength = 2.3e6;
  concrete.conversion_strain = 0.02;
  c.bodies[0].name = "slab";
  c.bodies[0].material = "concrete";
  c.bodies[0].method = slab;
  Material steel;
  steel.name = "steel";
  steel.model = MaterialModel::bilinear_j2;
  steel.density = 7800;
  steel.youngs_modulus = 232e9;
  steel.poisson_ratio = 0.3;
  steel.yield_stress = 235e6;
  steel.plastic_modulus = 1.879e9;
  steel.conversion_strain = 0.5;
  c.materials.push_back(steel);
  Body p;
  p.name = "projectile";
  p.material = "steel";
  p.material_index = 1;
  p.method = projectile;
  p.cell_size = h;
  p.shape.x = 0.03 * length_scale;
  p.shape.y = 9 * h + 1.2 * h;  // more than one cell above the slab: contact discs are h/2
  p.shape.width = 0.02 * length_scale;
  p.shape.height = 0.025 * length_scale;
  p.initial_velocity = {0.0, -speed};
  c.bodies.push_back(p);
  c.sim.conversion_on_tension = true;
  c.sim.end_time = (0.2 * 3.333e-3 / speed + 20e-6) * length_scale;
  return c;
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

// Lame's thick-walled steel cylinder (inner radius a = 10 mm, outer b = 20 mm; a slice of two
// 0.5 mm rows held in y on its faces) under an internal pressure of 100 MPa that rises over
// 100 us, many periods of the breathing mode (about 6 us), and then holds for 200 us; probes
// "inner" and "outer" on the faces. The exact answer with eps_zz = 0 along the axis
// (Timoshenko & Goodier, Theory of Elasticity, 3rd ed., Sec. 28):
// u(r) = (1 + nu) / E k ((1 - 2 nu) r + b^2 / r), sigma_tt(r) = k (1 + b^2 / r^2),
// k = p a^2 / (b^2 - a^2).
struct LameCylinder {
  double a = 10e-3, b = 20e-3, h = 0.5e-3, E = 200e9, nu = 0.3, rho = 7800.0, p = 100e6;
  double ramp = 100e-6, hold = 200e-6;
  int rows = 2;

  Case make_case(BodyMethod method) const {
    Case c = rectangle_case(20, rows, h, E, nu, rho, Formulation::axisymmetric);
    c.bodies[0].method = method;
    c.bodies[0].shape.x = a;
    const double H = rows * h;
    add_pressure(c, segment(a, 0, a, H), {0.0, ramp, 1.0}, {0.0, p, p});
    add_fixed(c, segment(a, 0, b, 0), Boundary::Type::fixed_y);
    add_fixed(c, segment(a, H, b, H), Boundary::Type::fixed_y);
    add_probe(c, "inner", a, 0.0);
    add_probe(c, "outer", b, 0.0);
    c.sim.end_time = ramp + hold;
    return c;
  }
  double k() const { return p * a * a / (b * b - a * a); }
  double u(double r) const { return (1 + nu) / E * k() * ((1 - 2 * nu) * r + b * b / r); }
  double hoop_stress(double r) const { return k() * (1 + b * b / (r * r)); }
};

// Sets the case's end time to `steps` of its first time step (a run of about that many steps).
inline void end_after_steps(Case& c, long steps) {
  Simulation first(c);
  first.step();
  c.sim.end_time = steps * first.time();
}

// A solid steel cylinder (8 x 8 cells of h) touching the axis, free, set breathing by
// v_r = alpha r (10 m/s at its mantle): axisymmetric, of `method`.
inline Case breathing_cylinder(double h, BodyMethod method) {
  Case c = rectangle_case(8, 8, h, 200e9, 0.3, 7800.0, Formulation::axisymmetric);
  c.bodies[0].method = method;
  c.bodies[0].initial_velocity_gradient = {Vec2{10.0 / (8 * h), 0.0}, Vec2{0.0, 0.0}};
  return c;
}

// The worst |energy error| of a run to its end, sampled every 50 steps, in its first three
// quarters (early) and its last (late): a bounded balance has late no worse than early.
struct EnergyWindows {
  double early = 0.0, late = 0.0;
  long steps = 0;
  HistoryRecord end{};
  std::string failure;  // empty unless the run failed
};
inline EnergyWindows run_energy_windows(const Case& c) {
  Simulation sim(c);
  EnergyWindows r;
  while (sim.time() < c.sim.end_time * (1 - 1e-12) && !sim.failed()) {
    sim.step();
    if (sim.steps() % 50) continue;
    double& worst = sim.time() < 0.75 * c.sim.end_time ? r.early : r.late;
    worst = std::max(worst, std::fabs(sim.history().energy.error));
  }
  r.steps = sim.steps();
  r.end = sim.history();
  if (sim.failed()) r.failure = sim.failure().empty() ? "failed" : sim.failure();
  return r;
}

// The smallest x of any node: an axisymmetric run keeps every node at x >= 0.
inline double leftmost_node_x(const Simulation& sim) {
  const auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), sim.model().nodes.x);
  double leftmost = x.extent(0) ? x(0, 0) : 0.0;
  for (size_t n = 0; n < x.extent(0); ++n) leftmost = std::min(leftmost, x(n, 0));
  return leftmost;
}

// A Mohr-Coulomb concrete (cohesion 20 MPa, friction 30 degrees, tensile strength 10 MPa) whose
// elements convert at a plastic strain of 1e-4: a yield front converts every element it sweeps.
inline void make_quickly_converting_concrete(Material& m) {
  m.model = MaterialModel::mohr_coulomb;
  m.cohesion = 20e6;
  m.friction_angle = 30.0 * M_PI / 180.0;
  m.tensile_strength = 10e6;
  m.conversion_strain = 1e-4;
}

// Two runs of the same input agree to the bit on the host path: the chunk-coloured scatter and
// the fixed reduction trees sum in one order. The device path (FRACTA_DEVICE_PATH: GPUs, and CPU
// builds with -DFRACTA_DEVICE_PATH=ON) adds to nodes atomically, in an order that changes from
// run to run, so its runs agree only to round-off that the dynamics then carries on; the tests
// that compare runs state the tolerance they need there (kBitwiseRuns false).
inline constexpr bool kBitwiseRuns = !kAtomicScatter;

// The tolerance a comparison of two runs uses: 0 (bitwise) on the host path, `device` on the
// device path.
inline double run_tolerance(double device) {
  return kBitwiseRuns ? 0.0 : device;
}

// The state a step mutates (Simulation::state, state_views.hpp), copied to the host: every
// view's values by name, of a list only its used part (the entries beyond a list's length are
// not state: nothing reads them, and a restore leaves them as they are).
struct StateCopy {
  std::vector<std::string> names;
  std::vector<std::vector<double>> reals;  // empty for an integer view
  std::vector<std::vector<int>> ints;      // empty for a floating-point view
  ListCounts lists;
};

inline StateCopy copy_state(Simulation& sim) {
  StateCopy copy;
  StateViews live = sim.state();
  copy.lists = ListCounts::of(sim.model());
  const ListCounts& lists = copy.lists;
  for_each_state_view(live, live, [&](const char* name, const auto& view, const auto&) {
    const auto host = Kokkos::create_mirror_view_and_copy(HostSpace(), view);
    using Value = typename std::decay_t<decltype(host)>::non_const_value_type;
    size_t size = host.span();
    if (state_rows(name) == StateRows::list_prefix && size > 0)
      size = static_cast<size_t>(state_list_length(name, lists));
    copy.names.emplace_back(name);
    copy.reals.emplace_back();
    copy.ints.emplace_back();
    if constexpr (std::is_floating_point_v<Value>)
      copy.reals.back().assign(host.data(), host.data() + size);
    else
      copy.ints.back().assign(host.data(), host.data() + size);
  });
  return copy;
}

// Two copies of the state equal: byte by byte where `relative` is 0; else floating-point views
// within `relative` of the first copy's largest magnitude in the view, integer views exactly.
// Returns how many views were compared.
inline int expect_same_state(const StateCopy& a, const StateCopy& b, double relative) {
  EXPECT_EQ(a.lists.converted, b.lists.converted);
  EXPECT_EQ(a.lists.active_elements, b.lists.active_elements);
  EXPECT_EQ(a.lists.used_bonds, b.lists.used_bonds);
  EXPECT_EQ(a.lists.particles, b.lists.particles);
  EXPECT_EQ(a.names, b.names);
  if (a.names != b.names) return 0;
  for (size_t k = 0; k < a.names.size(); ++k) {
    const std::string& name = a.names[k];
    EXPECT_EQ(a.reals[k].size(), b.reals[k].size()) << name;
    EXPECT_EQ(a.ints[k], b.ints[k]) << name;
    if (a.reals[k].size() != b.reals[k].size() || a.reals[k].empty()) continue;
    if (relative > 0.0)
      EXPECT_LE(max_relative_difference(a.reals[k], b.reals[k]), relative) << name;
    else
      EXPECT_EQ(
          std::memcmp(a.reals[k].data(), b.reals[k].data(), a.reals[k].size() * sizeof(double)), 0)
          << name;
  }
  return static_cast<int>(a.names.size());
}

// Every view a step mutates equal in two runs: byte by byte on the host path; on the device path,
// floating-point views within `device_relative` of the first run's largest magnitude in the
// view, integer views exactly (a decision such as a bond break that round-off flipped shows
// there). Returns how many views were compared.
inline int expect_same_state(Simulation& first, Simulation& second,
                             double device_relative = 1e-12) {
  return expect_same_state(copy_state(first), copy_state(second),
                           kBitwiseRuns ? 0.0 : device_relative);
}

}  // namespace fracta::test
