// Case file parsing and validation (src/host/case.cpp): a complete case, defaults, malformed
// files under tests/data/bad (each error must name the file, the line and the key), and --set.
#include "host/case.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace fracta {
namespace {

const std::string kData = std::string(FRACTA_SOURCE_DIR) + "/tests/data/";

const char* const kMinimal = R"(
[simulation]
end_time = 1e-5

[[material]]
name = "steel"
model = "elastic"
density = 7800.0
youngs_modulus = 200e9
poisson_ratio = 0.3

[[body]]
name = "slab"
material = "steel"
cell_size = 1e-3
shape = { type = "rectangle", x = 0.0, y = 0.0, width = 0.1, height = 0.02 }
)";

// The message of the InputError thrown by f (fails the test when nothing is thrown).
template <class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError thrown";
  return "";
}

std::string minimal_error(const std::string& extra, const std::vector<std::string>& set = {}) {
  return error_of([&] { parse_case(kMinimal + extra, "mem.toml", set); });
}

// ------------------------------------------------------------------------------------------
// Valid cases

TEST(CaseParse, FullCaseHasEveryValue) {
  const Case c = load_case(kData + "case_full.toml");
  EXPECT_EQ(c.path, kData + "case_full.toml");
  EXPECT_NE(c.text.find("[[body_probe]]"), std::string::npos);

  const SimulationParams& s = c.sim;
  EXPECT_EQ(s.title, "every key");
  EXPECT_EQ(s.formulation, Formulation::plane_stress);
  EXPECT_DOUBLE_EQ(s.thickness, 0.01);
  EXPECT_DOUBLE_EQ(s.end_time, 80e-6);
  EXPECT_DOUBLE_EQ(s.dt_safety, 0.9);
  EXPECT_DOUBLE_EQ(s.dt, 1e-8);
  EXPECT_TRUE(s.allow_unstable_dt);
  EXPECT_DOUBLE_EQ(s.output_interval, 1e-6);
  EXPECT_DOUBLE_EQ(s.history_interval, 1e-7);
  EXPECT_EQ(s.hourglass, HourglassForm::stiffness);
  EXPECT_DOUBLE_EQ(s.hourglass_coefficient, 0.05);
  EXPECT_EQ(s.integration, Integration::full);
  EXPECT_DOUBLE_EQ(s.bulk_viscosity_linear, 0.1);
  EXPECT_DOUBLE_EQ(s.bulk_viscosity_quadratic, 2.0);  // an integer in the file
  EXPECT_DOUBLE_EQ(s.energy_error_limit, 0.25);
  EXPECT_EQ(s.pos.file, c.path);
  EXPECT_EQ(s.pos.line, 2);
  EXPECT_EQ(s.dt_pos.line, 8);

  ASSERT_EQ(c.materials.size(), 4u);
  const Material& steel = c.materials[0];
  EXPECT_EQ(steel.name, "steel");
  EXPECT_EQ(steel.model, MaterialModel::bilinear_j2);
  EXPECT_DOUBLE_EQ(steel.density, 7800.0);
  EXPECT_DOUBLE_EQ(steel.youngs_modulus, 232e9);
  EXPECT_DOUBLE_EQ(steel.poisson_ratio, 0.3);
  EXPECT_DOUBLE_EQ(steel.yield_stress, 235e6);
  EXPECT_DOUBLE_EQ(steel.plastic_modulus, 1.879e9);
  EXPECT_DOUBLE_EQ(steel.tensile_strength, 2.3e6);
  EXPECT_DOUBLE_EQ(steel.conversion_strain, 0.5);  // default for bilinear_j2
  EXPECT_EQ(steel.pos.line, 19);
  const Material& granite = c.materials[1];
  EXPECT_EQ(granite.model, MaterialModel::mohr_coulomb);
  EXPECT_DOUBLE_EQ(granite.cohesion, 30e6);
  EXPECT_NEAR(granite.friction_angle, std::atan(1.0), 1e-15);  // degrees in the file
  EXPECT_DOUBLE_EQ(granite.tensile_strength, 10e6);
  EXPECT_DOUBLE_EQ(granite.conversion_strain, 0.02);  // default for mohr_coulomb
  const Material& aluminium = c.materials[2];
  EXPECT_DOUBLE_EQ(aluminium.plastic_modulus, 70e9 * 7e9 / (70e9 - 7e9));  // from tangent
  EXPECT_DOUBLE_EQ(aluminium.conversion_strain, 0.3);
  const Material& glass = c.materials[3];
  EXPECT_EQ(glass.model, MaterialModel::elastic);
  EXPECT_DOUBLE_EQ(glass.tensile_strength, 0.0);
  EXPECT_DOUBLE_EQ(glass.conversion_strain, 0.5);

  EXPECT_DOUBLE_EQ(c.contact.stiffness_factor, 0.75);
  EXPECT_DOUBLE_EQ(c.contact.damping_ratio, 0.2);
  EXPECT_DOUBLE_EQ(c.contact.friction, 0.4);

  ASSERT_EQ(c.bodies.size(), 3u);
  const Body& slab = c.bodies[0];
  EXPECT_EQ(slab.name, "slab");
  EXPECT_EQ(slab.material, "granite");
  EXPECT_EQ(slab.material_index, 1);
  EXPECT_EQ(slab.method, BodyMethod::adaptive);
  EXPECT_DOUBLE_EQ(slab.cell_size, 1.667e-3);
  EXPECT_EQ(slab.shape.type, Shape::Type::rectangle);
  EXPECT_DOUBLE_EQ(slab.shape.width, 0.08);
  EXPECT_DOUBLE_EQ(slab.shape.height, 0.03);
  ASSERT_EQ(slab.cuts.size(), 2u);
  EXPECT_EQ(slab.cuts[0].type, Shape::Type::rectangle);
  EXPECT_DOUBLE_EQ(slab.cuts[0].x, 0.039);
  EXPECT_EQ(slab.cuts[1].type, Shape::Type::circle);
  EXPECT_DOUBLE_EQ(slab.cuts[1].radius, 0.002);
  ASSERT_EQ(slab.regions.size(), 1u);
  EXPECT_EQ(slab.regions[0].method, BodyMethod::de);
  EXPECT_EQ(slab.regions[0].shape.type, Shape::Type::polygon);
  ASSERT_EQ(slab.regions[0].shape.points.size(), 3u);
  EXPECT_DOUBLE_EQ(slab.regions[0].shape.points[2][1], 0.03);
  EXPECT_DOUBLE_EQ(slab.initial_velocity[0], 0.0);
  const Body& striker = c.bodies[1];
  EXPECT_EQ(striker.method, BodyMethod::rigid);
  EXPECT_EQ(striker.material_index, 0);
  EXPECT_EQ(striker.shape.type, Shape::Type::semicircle);
  EXPECT_DOUBLE_EQ(striker.shape.angle_deg, 90.0);
  EXPECT_DOUBLE_EQ(striker.initial_velocity[1], -20.0);
  EXPECT_EQ(c.bodies[2].method, BodyMethod::fe);  // default

  ASSERT_EQ(c.loads.size(), 2u);
  const Load& pressure = c.loads[0];
  EXPECT_EQ(pressure.type, Load::Type::pressure);
  EXPECT_EQ(pressure.body_index, 0);
  EXPECT_EQ(pressure.where.kind, NodeSelector::Kind::segment);
  EXPECT_DOUBLE_EQ(pressure.where.segment.to[1], 0.03);
  EXPECT_EQ(pressure.time, (std::vector<double>{0.0, 3e-6, 3e-6}));
  EXPECT_EQ(pressure.value, (std::vector<double>{500e6, 500e6, 0.0}));
  const Load& force = c.loads[1];
  EXPECT_EQ(force.type, Load::Type::force);
  EXPECT_EQ(force.body_index, 1);
  EXPECT_EQ(force.where.kind, NodeSelector::Kind::shape);
  EXPECT_DOUBLE_EQ(force.direction[0], 0.0);
  EXPECT_DOUBLE_EQ(force.direction[1], -1.0);  // normalised

  ASSERT_EQ(c.boundaries.size(), 2u);
  EXPECT_EQ(c.boundaries[0].type, Boundary::Type::fixed_y);
  EXPECT_EQ(c.boundaries[0].body_index, 0);
  EXPECT_EQ(c.boundaries[1].type, Boundary::Type::fixed);
  EXPECT_EQ(c.boundaries[1].body, "");
  EXPECT_EQ(c.boundaries[1].body_index, -1);
  EXPECT_EQ(c.boundaries[1].where.kind, NodeSelector::Kind::shape);

  ASSERT_EQ(c.probes.size(), 2u);
  EXPECT_EQ(c.probes[0].name, "tip");
  EXPECT_EQ(c.probes[0].body_index, 0);
  EXPECT_DOUBLE_EQ(c.probes[0].at[1], 0.006);
  EXPECT_EQ(c.probes[1].body_index, -1);
  ASSERT_EQ(c.body_probes.size(), 1u);
  EXPECT_EQ(c.body_probes[0].body_index, 1);

  EXPECT_EQ(c.output.file, "full.h5");
  EXPECT_EQ(c.output.fields.size(), 7u);
  EXPECT_DOUBLE_EQ(c.output.checkpoint_interval, 1e-5);
}

TEST(CaseParse, MinimalCaseGetsDefaults) {
  const Case c = parse_case(kMinimal, "mem.toml");
  EXPECT_EQ(c.path, "mem.toml");
  EXPECT_EQ(c.text, kMinimal);
  const SimulationParams& s = c.sim;
  EXPECT_EQ(s.formulation, Formulation::plane_strain);
  EXPECT_DOUBLE_EQ(s.thickness, 1.0);
  EXPECT_DOUBLE_EQ(s.dt_safety, 0.85);
  EXPECT_DOUBLE_EQ(s.dt, 0.0);
  EXPECT_FALSE(s.allow_unstable_dt);
  EXPECT_DOUBLE_EQ(s.output_interval, 0.0);
  EXPECT_DOUBLE_EQ(s.history_interval, 0.0);
  EXPECT_EQ(s.hourglass, HourglassForm::viscous);
  EXPECT_DOUBLE_EQ(s.hourglass_coefficient, 0.1);
  EXPECT_EQ(s.integration, Integration::reduced);
  EXPECT_DOUBLE_EQ(s.bulk_viscosity_linear, 0.06);
  EXPECT_DOUBLE_EQ(s.bulk_viscosity_quadratic, 1.5);
  EXPECT_DOUBLE_EQ(s.energy_error_limit, 0.5);
  EXPECT_DOUBLE_EQ(c.contact.stiffness_factor, 0.5);
  EXPECT_DOUBLE_EQ(c.contact.damping_ratio, 0.1);
  EXPECT_DOUBLE_EQ(c.contact.friction, 0.3);
  EXPECT_DOUBLE_EQ(c.materials[0].conversion_strain, 0.5);
  EXPECT_EQ(c.bodies[0].method, BodyMethod::fe);
  EXPECT_TRUE(c.bodies[0].cuts.empty());
  EXPECT_EQ(c.output.file, "out.h5");
  EXPECT_EQ(c.output.fields, (std::vector<std::string>{"velocity", "stress", "plastic_strain"}));
  EXPECT_TRUE(c.loads.empty() && c.boundaries.empty() && c.probes.empty());
}

TEST(CaseParse, CutsAsArrayOfInlineTables) {
  const Case c =
      parse_case(std::string(kMinimal) +
                     "cut = [{ type = \"circle\", x = 0.05, y = 0.01, radius = 0.002 },"
                     " { type = \"rectangle\", x = 0, y = 0, width = 1e-3, height = 1 }]\n",
                 "mem.toml");
  ASSERT_EQ(c.bodies[0].cuts.size(), 2u);
  EXPECT_EQ(c.bodies[0].cuts[1].type, Shape::Type::rectangle);
}

// The 48 MPa concrete of Holmquist, Johnson & Cook (1993): its constants reach the law, and the
// elastic constants follow from G and K = p_crush / mu_crush.
TEST(CaseParse, HjcConcreteTakesThePapersSymbols) {
  const Case c = load_case(kData + "../../cases/validation/hjc_confined_compression.toml");
  const Material& m = c.materials[0];
  ASSERT_EQ(m.model, MaterialModel::hjc);
  EXPECT_DOUBLE_EQ(m.hjc.fc, 48e6);
  EXPECT_DOUBLE_EQ(m.hjc.t, 4e6);
  EXPECT_DOUBLE_EQ(m.hjc.n, 0.61);
  EXPECT_DOUBLE_EQ(m.hjc.k2, -171e9);
  EXPECT_DOUBLE_EQ(m.hjc.eps0, 1.0);
  const double K = 16e6 / 0.001, G = 14.86e9;
  EXPECT_NEAR(m.youngs_modulus, 9 * K * G / (3 * K + G), 1e-6 * G);
  EXPECT_NEAR(m.youngs_modulus / (2 * (1 + m.poisson_ratio)), G, 1e-6 * G);
}

// OFHC copper in the symbols of Johnson & Cook (1983, 1985), with the defaults of the optional
// constants (room temperature 293 K, reference rate 1/s, isothermal, Taylor-Quinney 0.9).
TEST(CaseParse, JohnsonCookTakesThePapersSymbols) {
  const Case c = parse_case(R"([simulation]
end_time = 1e-5
[[material]]
name = "copper"
model = "johnson_cook"
density = 8960.0
youngs_modulus = 124e9
poisson_ratio = 0.34
johnson_cook = { A = 90e6, B = 292e6, n = 0.31, C = 0.025, m = 1.09, melting_temperature = 1356.0, D1 = 0.54, D2 = 4.89, D3 = -3.03, D4 = 0.014, D5 = 1.12 }
[[body]]
name = "rod"
material = "copper"
cell_size = 1e-3
shape = { type = "rectangle", x = 0.0, y = 0.0, width = 0.01, height = 0.01 }
)",
                            "mem.toml");
  const Material& m = c.materials[0];
  ASSERT_EQ(m.model, MaterialModel::johnson_cook);
  EXPECT_DOUBLE_EQ(m.jc.a, 90e6);
  EXPECT_DOUBLE_EQ(m.jc.n, 0.31);
  EXPECT_DOUBLE_EQ(m.jc.t_melt, 1356.0);
  EXPECT_DOUBLE_EQ(m.jc.t_room, 293.0);
  EXPECT_DOUBLE_EQ(m.jc.eps0, 1.0);
  EXPECT_DOUBLE_EQ(m.jc.specific_heat, 0.0);
  EXPECT_DOUBLE_EQ(m.jc.taylor_quinney, 0.9);
  EXPECT_DOUBLE_EQ(m.jc.d3, -3.03);
  EXPECT_DOUBLE_EQ(m.conversion_damage, 1.0);
}

// The material cards of cases/materials/ load, with the papers' constants.
TEST(CaseParse, MaterialCardsLoad) {
  const std::string dir = std::string(FRACTA_SOURCE_DIR) + "/cases/materials/";
  const Case copper = load_case(dir + "ofhc_copper.toml");
  EXPECT_EQ(copper.materials[0].model, MaterialModel::johnson_cook);
  EXPECT_DOUBLE_EQ(copper.materials[0].jc.a, 90e6);
  EXPECT_DOUBLE_EQ(copper.materials[0].jc.t_melt, 1356.0);
  const Case iron = load_case(dir + "armco_iron.toml");
  EXPECT_DOUBLE_EQ(iron.materials[0].jc.b, 380e6);
  EXPECT_DOUBLE_EQ(iron.materials[0].jc.d1, -2.20);
  const Case steel = load_case(dir + "steel_4340.toml");
  EXPECT_DOUBLE_EQ(steel.materials[0].jc.a, 792e6);
  EXPECT_DOUBLE_EQ(steel.materials[0].jc.n, 0.26);
  const Case concrete = load_case(dir + "concrete_48mpa_hjc.toml");
  EXPECT_EQ(concrete.materials[0].model, MaterialModel::hjc);
  EXPECT_DOUBLE_EQ(concrete.materials[0].hjc.fc, 48e6);
  EXPECT_DOUBLE_EQ(concrete.materials[0].hjc.k3, 208e9);
}

TEST(CaseParse, ToString) {
  EXPECT_STREQ(to_string(Formulation::plane_stress), "plane_stress");
  EXPECT_STREQ(to_string(MaterialModel::mohr_coulomb), "mohr_coulomb");
  EXPECT_STREQ(to_string(BodyMethod::adaptive), "adaptive");
}

// ------------------------------------------------------------------------------------------
// Malformed files: the message names the file, the line and the key.

struct BadCase {
  const char* file;  // under tests/data/bad
  int line;
  const char* key;       // dotted key in the message ("" for syntax errors)
  const char* fragment;  // part of the description
};

std::ostream& operator<<(std::ostream& os, const BadCase& b) {
  return os << b.file;
}

class CaseBadFile : public ::testing::TestWithParam<BadCase> {};

TEST_P(CaseBadFile, NamesFileLineAndKey) {
  const BadCase& b = GetParam();
  const std::string path = kData + "bad/" + b.file;
  try {
    load_case(path);
    FAIL() << b.file << " was accepted";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(e.file, path);
    EXPECT_EQ(e.line, b.line) << msg;
    EXPECT_EQ(e.key, b.key) << msg;
    std::string where = std::string(b.file) + ":" + std::to_string(b.line) + ": ";
    if (*b.key) where += std::string(b.key) + ": ";
    EXPECT_NE(msg.find(where), std::string::npos) << msg;
    EXPECT_NE(msg.find(b.fragment), std::string::npos) << msg;
  }
}

const BadCase kBadCases[] = {
    {"syntax_error.toml", 8, "", "TOML syntax error"},
    {"unknown_key.toml", 9, "material['steel'].youngs_modulu",
     "unknown key 'youngs_modulu'; did you mean 'youngs_modulus'?"},
    {"missing_end_time.toml", 3, "simulation.end_time", "required key is missing"},
    {"negative_density.toml", 8, "material['steel'].density", "must be > 0 (got -7800)"},
    {"poisson_half.toml", 10, "material['rubber'].poisson_ratio", "must be < 0.5 (got 0.5)"},
    {"dt_safety_zero.toml", 4, "simulation.dt_safety", "must be > 0 (got 0)"},
    {"dt_safety_large.toml", 4, "simulation.dt_safety", "must be <= 1 (got 1.5)"},
    {"wrong_type.toml", 9, "material['steel'].youngs_modulus", "expected a number, got a string"},
    {"unknown_material.toml", 16, "body['slab'].material",
     "no material named 'steal'; did you mean 'steel'?"},
    {"duplicate_body.toml", 22, "body['slab'].name", "duplicate body name 'slab'"},
    {"unknown_method.toml", 17, "body['slab'].method",
     "unknown value 'sph' (expected one of: fe, de, adaptive, rigid)"},
    {"pressure_without_segment.toml", 21, "load[0].segment", "required table is missing"},
    {"time_value_length.toml", 26, "load[0].value", "has 2 entries but 'time' has 3"},
    {"time_not_monotonic.toml", 25, "load[0].time", "must be non-decreasing"},
    {"cohesion_on_elastic.toml", 11, "material['glass'].cohesion",
     "does not apply to model 'elastic'"},
    {"plane_stress_no_thickness.toml", 2, "simulation.thickness", "required for formulation"},
    {"degenerate_polygon.toml", 18, "body['wedge'].shape.points", "degenerate"},
    {"self_intersecting_polygon.toml", 23, "body['slab'].cut[0].points", "self-intersecting"},
    {"unknown_shape_key.toml", 18, "body['slab'].shape.widht", "did you mean 'width'?"},
    {"infinite_value.toml", 3, "simulation.end_time", "must be a finite number"},
    {"friction_angle_90.toml", 12, "material['sand'].friction_angle", "must be < 90"},
    {"unknown_output_field.toml", 23, "output.fields", "unknown field 'strain'"},
    {"output_precision_half.toml", 23, "output.precision", "unknown value 'half'"},
    {"closing_speed_absurd.toml", 25, "body['projectile'].initial_velocity",
     "more than 10 times the largest P-wave speed of the materials (5875 m/s)"},
    {"output_compression_fraction.toml", 23, "output.compression", "whole number from 0 to 9"},
    {"boundary_segment_and_shape.toml", 24, "boundary[0].shape", "not both"},
    {"no_body.toml", 1, "body", "at least one [[body]] is required"},
    {"fracture_energy_without_strength.toml", 11, "material['glass'].fracture_energy",
     "needs a tensile_strength > 0"},
    {"fracture_energy_on_j2.toml", 13, "material['steel'].fracture_energy",
     "does not apply to model 'bilinear_j2'"},
    {"support_diagonal.toml", 23, "boundary[0].direction", "a support pushes along x or y"},
    {"velocity_component_z.toml", 23, "boundary[0].component", "must be \"x\" or \"y\""},
    {"duplicate_boundary_name.toml", 27, "boundary['grip'].name", "duplicate boundary name 'grip'"},
    {"weibull_below_one.toml", 12, "material['glass'].weibull_modulus", "at least 1"},
    {"seed_fraction.toml", 4, "simulation.seed", "must be a whole number"},
    {"spread_and_weibull.toml", 13, "material['glass'].strength_spread", "not both"},
    {"velocity_gradient_rigid.toml", 18, "body['ball'].initial_velocity_gradient", "rigid body"},
    {"velocity_gradient_one_row.toml", 17, "body['plate'].initial_velocity_gradient", "2 rows"},
    {"node_perturbation_large.toml", 17, "body['pane'].node_perturbation", "must be <= 0.25"},
    {"hjc_plane_stress.toml", 9, "material['concrete'].model", "needs simulation.formulation"},
    {"axisymmetric_thickness.toml", 5, "simulation.thickness", "full revolution"},
    {"axisymmetric_rigid_body.toml", 19, "body['rod'].initial_velocity", "along the axis only"},
    {"axisymmetric_negative_radius.toml", 17, "body['rod'].shape", "x is the radius"},
    {"hjc_soft_lock.toml", 12, "material['concrete'].hjc.K1",
     "must be at least the slope of the crush line"},
    {"johnson_cook_damage_without_failure.toml", 12, "material['copper'].conversion_damage",
     "needs the failure constants D1..D5"},
};

INSTANTIATE_TEST_SUITE_P(CaseFiles, CaseBadFile, ::testing::ValuesIn(kBadCases),
                         [](const ::testing::TestParamInfo<BadCase>& info) {
                           std::string name = info.param.file;
                           return name.substr(0, name.find('.'));
                         });

TEST(CaseErrors, UnreadableFileHasLineZeroAndNoKey) {
  try {
    load_case(kData + "no_such_case.toml");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.line, 0);
    EXPECT_EQ(e.key, "");
    EXPECT_NE(std::string(e.what()).find("no_such_case.toml: cannot open"), std::string::npos);
  }
}

TEST(CaseErrors, MessageFormat) {
  const InputError e("cases/bad.toml", 12, "material[0].poisson_ratio", "must be < 0.5 (got 0.52)");
  EXPECT_STREQ(e.what(), "cases/bad.toml:12: material[0].poisson_ratio: must be < 0.5 (got 0.52)");
}

TEST(CaseErrors, PlasticAndTangentModulusTogether) {
  std::string text = kMinimal;
  text.replace(text.find("\"elastic\""), 9, "\"bilinear_j2\"");
  text.replace(text.find("poisson_ratio = 0.3"), 19,
               "poisson_ratio = 0.3\nyield_stress = 1e8\nplastic_modulus = 1e9\n"
               "tangent_modulus = 1e9");
  std::string msg = error_of([&] { parse_case(text, "mem.toml"); });
  EXPECT_NE(msg.find("mem.toml:13: material['steel'].tangent_modulus: give 'plastic_modulus' or "
                     "'tangent_modulus', not both"),
            std::string::npos)
      << msg;
}

TEST(CaseErrors, ForceNeedsNonZeroDirection) {
  std::string msg = minimal_error(
      "\n[[load]]\nbody = \"slab\"\ntype = \"force\"\n"
      "segment = { from = [0, 0], to = [0, 1] }\ndirection = [0, 0]\ntime = [0]\nvalue = [1]\n");
  EXPECT_NE(msg.find("mem.toml:22: load[0].direction: must be a non-zero vector"),
            std::string::npos)
      << msg;
}

// ------------------------------------------------------------------------------------------
// --set overrides

TEST(CaseOverrides, ChangeSimulationAndNamedBody) {
  const Case c = load_case(kData + "case_full.toml",
                           {"simulation.end_time=2e-6", "body.slab.cell_size=1e-3",
                            "material.steel.yield_stress = 300e6", "load.1.value=[5e3]"});
  EXPECT_DOUBLE_EQ(c.sim.end_time, 2e-6);
  EXPECT_DOUBLE_EQ(c.bodies[0].cell_size, 1e-3);
  EXPECT_DOUBLE_EQ(c.bodies[1].cell_size, 1e-3);  // unchanged (it was 1e-3 already)
  EXPECT_DOUBLE_EQ(c.bodies[2].cell_size, 2e-3);  // unchanged
  EXPECT_DOUBLE_EQ(c.materials[0].yield_stress, 300e6);
  EXPECT_EQ(c.loads[1].value, std::vector<double>{5e3});
}

TEST(CaseOverrides, StringsQuotedOrBare) {
  EXPECT_EQ(parse_case(kMinimal, "mem.toml", {"output.file=\"x.h5\""}).output.file, "x.h5");
  EXPECT_EQ(parse_case(kMinimal, "mem.toml", {"output.file=y.h5"}).output.file, "y.h5");
  EXPECT_EQ(parse_case(kMinimal, "mem.toml", {"body.slab.method=de"}).bodies[0].method,
            BodyMethod::de);
}

TEST(CaseOverrides, ErrorsNameTheSetSource) {
  EXPECT_EQ(minimal_error("", {"simulation.end_tme=2e-6"}),
            "--set: simulation.end_tme: unknown key 'end_tme'; did you mean 'end_time'?");
  EXPECT_EQ(minimal_error("", {"simulation.end_time=-1"}),
            "--set: simulation.end_time: must be > 0 (got -1)");
  EXPECT_EQ(minimal_error("", {"body.slab.cell_size=fine"}),
            "--set: body['slab'].cell_size: expected a number, got a string");
  EXPECT_NE(minimal_error("", {"body.slob.cell_size=1e-3"})
                .find("--set: body.slob.cell_size: no "
                      "[[body]] entry named 'slob'"),
            std::string::npos);
  EXPECT_NE(minimal_error("", {"simulation.end_time"})
                .find("--set: simulation.end_time: expected "
                      "KEY=VALUE"),
            std::string::npos);
  EXPECT_NE(minimal_error("", {"outptu.file=x.h5"})
                .find("--set: outptu: unknown key 'outptu'; "
                      "did you mean 'output'?"),
            std::string::npos);
}

}  // namespace
}  // namespace fracta
