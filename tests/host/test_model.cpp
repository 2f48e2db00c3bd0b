// Building the model from a case (src/host/model.cpp): boundaries that claim the same velocity
// component in two ways, or act on a rigid body as only a deformable one can, are input errors
// naming the boundary; fixed boundaries may overlap and a bar combines with anything.
#include <gtest/gtest.h>

#include <string>

#include "host/model.hpp"
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

}  // namespace
}  // namespace fracta
