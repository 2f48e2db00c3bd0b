// The energy and count reductions of kernels/energy.hpp.
#include <gtest/gtest.h>

#include "host/simulation.hpp"
#include "kernels/energy.hpp"
#include "test_util.hpp"

namespace fracta {
namespace {

// A 10 x 4 plate of 1 mm cells whose right half is discs from the start (a de region of an fe
// body): the composite nodes are the discs on the FE/DE interface, the ny + 1 = 5 nodes of the
// line x = 5 mm. A plate all FE or all discs has none.
Case half_and_half(BodyMethod body, bool de_region) {
  Case c = test::rectangle_case(10, 4, 1e-3, 70e9, 0.25, 2700.0, Formulation::plane_stress);
  c.bodies[0].method = body;
  if (de_region) {
    Region r;
    r.method = BodyMethod::de;
    r.shape.type = Shape::Type::rectangle;
    r.shape.x = 0.005;
    r.shape.width = 0.005;
    r.shape.height = 0.004;
    c.bodies[0].regions.push_back(r);
  }
  return c;
}

TEST(Energy, CompositeNodesAreTheDiscsOnTheFeDeInterface) {
  Simulation mixed(half_and_half(BodyMethod::fe, true));
  EXPECT_EQ(composite_count(mixed.model().nodes, mixed.model().topology), 5);
  EXPECT_EQ(mixed.history().count.composite, 5);
  EXPECT_EQ(mixed.history().count.particles, 6 * 5);  // the de half's nodes, interface included
  Simulation discs(half_and_half(BodyMethod::de, false));
  EXPECT_EQ(discs.history().count.composite, 0);
  EXPECT_GT(discs.history().count.particles, 0);
  Simulation fe(half_and_half(BodyMethod::fe, false));
  EXPECT_EQ(fe.history().count.composite, 0);
}

}  // namespace
}  // namespace fracta
