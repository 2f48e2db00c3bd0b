// Building the model from a case (src/host/model.cpp): boundaries that claim the same velocity
// component in two ways, or act on a rigid body as only a deformable one can, are input errors
// naming the boundary; fixed boundaries may overlap and a bar combines with anything. A body's
// initial velocity field is linear: every node starts at v0 + L (x - x0), its discs spinning at
// the field's rotation rate.
#include <gtest/gtest.h>

#include <string>

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
