// The case file (docs/case-file.md): a TOML scene read into plain host structs.
// Every value is validated here (types, ranges, unknown keys, cross references); the rest of
// the code trusts a Case. Units are SI throughout (m, s, kg, Pa, N); angles in degrees in the
// file, radians in the struct where noted.
#pragma once
#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "kernels/law_params.hpp"

namespace fracta {

// Where a value came from, for error messages ("file:line: key: what is wrong").
struct SourcePos {
  std::string file;
  int line = 0;
  int column = 0;
};

// Bad input: the message names file, line and key. The CLI exits with code 2 on it.
struct InputError : std::runtime_error {
  InputError(const std::string& file, int line, const std::string& key, const std::string& what);
  std::string file;
  int line = 0;
  std::string key;
};

using Vec2 = std::array<double, 2>;

enum class Formulation { plane_stress, plane_strain, axisymmetric };
enum class MaterialModel { elastic, bilinear_j2, mohr_coulomb, hjc, johnson_cook };
enum class BodyMethod { fe, de, adaptive, rigid };
enum class HourglassForm { viscous, stiffness };
enum class Integration { reduced, full };  // 1-point + hourglass control, or 2x2 Gauss

struct Shape {
  enum class Type { rectangle, circle, semicircle, polygon } type = Type::rectangle;
  // rectangle: lower-left corner (x, y) and width, height.
  // circle: centre (x, y) and radius. semicircle: centre of the flat side (x, y), radius, and
  // angle_deg, the direction from the flat side towards the arc (90 = arc above).
  double x = 0, y = 0, width = 0, height = 0, radius = 0, angle_deg = 90.0;
  std::vector<Vec2> points;  // polygon vertices, either orientation, not self-intersecting
  SourcePos pos;
};

struct Segment {
  Vec2 from{0, 0}, to{0, 0};
  SourcePos pos;
};

// A set of nodes: those within tolerance of a segment, or inside a shape.
struct NodeSelector {
  enum class Kind { segment, shape } kind = Kind::segment;
  Segment segment;
  Shape shape;
};

// Default of [[material]] conversion_length_ratio: an adaptive element converts once its
// characteristic length (that of its stable step) is below 0.3 of its initial one, so no element
// of an adaptive body can take the step below about 0.3 of its initial value by distortion
// (docs/physics.md 1.3).
constexpr double kDefaultConversionLengthRatio = 0.3;
// Largest [[body]] node_perturbation (fraction of the cell size).
constexpr double kMaxNodePerturbation = 0.25;

struct Material {
  std::string name;
  MaterialModel model = MaterialModel::elastic;
  double density = 0;            // kg/m^3
  double youngs_modulus = 0;     // Pa
  double poisson_ratio = 0;      // -
  double yield_stress = 0;       // Pa (bilinear_j2)
  double plastic_modulus = 0;    // Pa, slope of stress vs plastic strain (bilinear_j2)
  double cohesion = 0;           // Pa (mohr_coulomb)
  double friction_angle = 0;     // rad (file: degrees) (mohr_coulomb)
  double tensile_strength = 0;   // Pa; tension cut-off (mohr_coulomb) and bond strength; 0 = none
  double conversion_strain = 0;  // equivalent plastic strain that converts an element
  double conversion_damage = 0;  // hjc, johnson_cook: damage that converts an element (0: never)
  // hjc: its constants (the [[material]] hjc table, compressive_strength, tensile_strength);
  // youngs_modulus and poisson_ratio are then derived from shear_modulus and the elastic bulk
  // modulus p_crush / mu_crush.
  HjcParams hjc;
  JohnsonCookParams jc;  // johnson_cook: the [[material]] johnson_cook table
  // An element converts when its characteristic length has shrunk below this fraction of its
  // initial one (distortion, compression): its stable step is then as much below its initial.
  double conversion_length_ratio = kDefaultConversionLengthRatio;
  double fracture_energy = 0;  // J/m^2, cohesive bond softening; 0 = brittle bonds
  double weibull_modulus = 0;  // m of the bonds' strength factors (unit mean); 0 = uniform
  double strength_spread = 0;  // or factors uniform on [1 - spread, 1 + spread]
  bool random_strength() const { return weibull_modulus > 0.0 || strength_spread > 0.0; }
  // Its law keeps a state per point (Elements::law_state): hjc, johnson_cook.
  bool keeps_law_state() const {
    return model == MaterialModel::hjc || model == MaterialModel::johnson_cook;
  }
  // Dynamic increase factors of the bond strength and fracture energy against the bond's strain
  // rate (1/s, increasing); empty = rate independent.
  struct RateTable {
    static constexpr size_t kMaxEntries = 16;  // RateLaw::kMaxEntries
    std::vector<double> strain_rate, strength, fracture_energy;
  } rate_dependence;
  SourcePos pos;
};

struct ContactParams {
  double stiffness_factor = 0.5;  // lambda of paper Eq. 7
  double damping_ratio = 0.1;
  double friction = 0.3;
};

struct Region {
  BodyMethod method = BodyMethod::de;
  Shape shape;
  SourcePos pos;
};

struct Body {
  std::string name;
  std::string material;     // material name
  int material_index = -1;  // index into Case::materials
  BodyMethod method = BodyMethod::fe;
  double cell_size = 0;  // m
  Shape shape;
  std::vector<Shape> cuts;      // removed from the shape (notches, holes)
  std::vector<Region> regions;  // parts given another method
  Vec2 initial_velocity{0, 0};  // m/s
  // v(x) = initial_velocity + L (x - initial_velocity_origin): L's rows (1/s), origin (m).
  std::array<Vec2, 2> initial_velocity_gradient{};
  Vec2 initial_velocity_origin{0, 0};
  // Random displacement of the interior nodes at set-up, uniform in a disc of this radius
  // (fraction of the cell size), drawn from [simulation] seed (mesh.cpp); 0: the regular grid.
  double node_perturbation = 0;
  SourcePos pos;
};

struct Load {
  // pressure: normal to the segment's boundary edges, positive inwards (Pa); traction: a fixed
  // direction on the segment's boundary edges (Pa); force: a total force on a node set (N).
  enum class Type { pressure, force, traction } type = Type::pressure;
  std::string body;
  int body_index = -1;
  NodeSelector where;         // pressure: a segment; force: a segment or a shape
  Vec2 direction{1, 0};       // force and traction: unit direction
  std::vector<double> time;   // s, non-decreasing, piecewise-linear table
  std::vector<double> value;  // Pa (pressure, positive pushes into the body) or N (total force)
  SourcePos pos;
};

// Constraints and boundaries on node sets (docs/case-file.md, [[boundary]]):
// - fixed_x, fixed_y, fixed: velocity components held at zero;
// - velocity: one component (x or y) follows a piecewise-linear table (m/s), prescribed motion;
// - support: push-only along `direction` (an axis): holds a node that presses into it, lets go
//   when the node pulls away;
// - bar: the end of an elastic bar of impedance Z (Pa s/m) and cross-section `area` (m^2)
//   pushing along `direction`, with the incident wave's particle velocity v_I(t) (m/s):
//   compressive stress Z (2 v_I - v) on the face (an incident bar), Z (-v) without a table (a
//   transmitted bar), never tensile.
struct Boundary {
  enum class Type { fixed_x, fixed_y, fixed, velocity, support, bar } type = Type::fixed;
  std::string name;  // optional: /boundaries/NAME in the output
  std::string body;  // empty = every body
  int body_index = -1;
  NodeSelector where;
  int component = 0;          // velocity: 0 = x, 1 = y
  Vec2 direction{0, 1};       // support, bar: unit direction the boundary pushes the body along
  std::vector<double> time;   // velocity, bar: s, non-decreasing
  std::vector<double> value;  // velocity: m/s; bar: incident particle velocity v_I (m/s)
  double impedance = 0.0;     // bar: Z = rho c (Pa s/m)
  double area = 0.0;          // bar: cross-section (m^2)
  SourcePos pos;
};

struct Probe {
  std::string name;
  Vec2 at{0, 0};
  std::string body;  // empty = any body
  int body_index = -1;
  SourcePos pos;
};

struct BodyProbe {
  std::string name;
  std::string body;
  int body_index = -1;
  SourcePos pos;
};

struct SimulationParams {
  std::string title;
  Formulation formulation = Formulation::plane_strain;
  // m; required for plane stress, default 1 for plane strain. Axisymmetric (x = radius, y = axis)
  // has none: masses, forces and energies are those of the full revolution (2 pi r).
  double thickness = 1.0;
  double end_time = 0;             // s
  double dt_safety = 0.85;         // alpha of paper Eq. 19 (fraction of the stable step)
  double dt = 0;                   // s; 0 = automatic
  bool allow_unstable_dt = false;  // expert switch: accept a fixed dt above the stable bound
  double output_interval = 0;      // s; 0 = only the first and last frame
  double history_interval = 0;     // s; 0 = automatic: end_time / 1000 (history_every_for)
  HourglassForm hourglass = HourglassForm::viscous;
  double hourglass_coefficient = 0.1;
  Integration integration = Integration::reduced;
  double bulk_viscosity_linear = 0.06;
  double bulk_viscosity_quadratic = 1.5;
  double energy_error_limit = 0.5;     // relative error above which the run stops (exit 3)
  int conversion_interval = 1;         // steps between conversion checks of adaptive bodies
  bool conversion_on_tension = false;  // also convert elements at the tension cut-off
  std::uint64_t seed = 0;              // random draws (Weibull strengths): one realisation each
  SourcePos pos;                       // the [simulation] table
  SourcePos dt_pos;                    // the `dt` key, when given
};

struct OutputParams {
  std::string file = "out.h5";
  std::vector<std::string> fields{"velocity", "stress", "plastic_strain"};
  double checkpoint_interval = 0;  // s; 0 = none
  bool single_precision = true;    // precision = "single" (default) or "double": frame arrays
  int compression = 0;             // deflate level of frame arrays, 0 (none) to 9
};

struct Case {
  std::string path;                    // file it was read from
  std::string text;                    // the file text, recorded in the output
  std::vector<std::string> overrides;  // the --set overrides applied to it
  SimulationParams sim;
  std::vector<Material> materials;
  ContactParams contact;
  std::vector<Body> bodies;
  std::vector<Load> loads;
  std::vector<Boundary> boundaries;
  std::vector<Probe> probes;
  std::vector<BodyProbe> body_probes;
  OutputParams output;
};

// Reads and validates a case. `overrides` are "section.key=value" strings (CLI --set); for
// arrays of tables, "body.NAME.key=value" addresses the entry with that name. Throws InputError.
Case load_case(const std::string& path, const std::vector<std::string>& overrides = {});
Case parse_case(const std::string& text, const std::string& source_name,
                const std::vector<std::string>& overrides = {});

// Refuses (InputError at the first differing key of `now`) a case that does not define the same
// model as `stored`, the case a checkpoint was written with: both are compared as parsed TOML
// (with their --set overrides) except what a restart may change, simulation.end_time,
// output_interval, history_interval, title and the [output] table (docs/case-file.md).
void check_restart_compatible(const Case& stored, const Case& now);

// The fastest closing of two bodies at the start: the largest |v_a - v_b| of the bodies' initial
// velocities at the centres of their shapes' bounding boxes (m/s), and the two bodies (-1 when
// there is one body). Against it, the largest P-wave speed of the materials, sqrt(E (1 - nu) / ((1
// + nu) (1 - 2 nu) rho)) (m/s). Above kMaxClosingSpeedRatio times that speed a case is refused (no
// solid's law applies: the impact vaporises what it hits); above the speed itself the model
// notes that shocks are beyond its laws (docs/case-file.md, "Initial velocities").
struct ClosingSpeed {
  double speed = 0;
  int faster = -1, slower = -1;  // body indices; `faster` has the larger initial speed
};
constexpr double kMaxClosingSpeedRatio = 10.0;
ClosingSpeed initial_closing_speed(const Case& c);
double largest_p_wave_speed(const Case& c);

const char* to_string(Formulation f);
const char* to_string(MaterialModel m);
const char* to_string(BodyMethod m);

}  // namespace fracta
