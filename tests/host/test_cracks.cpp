// The crack tracer (src/host/cracks.hpp) on drawn broken-bond sets whose tip, length and
// branches are known exactly: a straight crack beside a larger unconnected damage zone, a crack
// that turns, a fork, and no crack at the seed. Exact-answer tests (geometry).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "host/cracks.hpp"

namespace fracta {
namespace {

constexpr double kStep = 0.5e-3, kLink = 0.75e-3;

// Points every kStep from `from` along the unit direction (dx, dy), `count` of them, the first
// one kStep from `from`.
void add_line(std::vector<Vec2>& points, Vec2 from, double dx, double dy, int count) {
  for (int k = 1; k <= count; ++k)
    points.push_back({from[0] + k * kStep * dx, from[1] + k * kStep * dy});
}

TEST(CrackTrace, StraightCrackIgnoresALargerUnconnectedZone) {
  std::vector<Vec2> points;
  add_line(points, {0, 0}, 1, 0, 20);      // the crack: 10 mm along x
  add_line(points, {20e-3, 0}, 0, 1, 40);  // crushed elsewhere, 20 mm long
  const CrackTrace t = trace_crack(points, {0, 0}, kLink, 2e-3);
  ASSERT_TRUE(t.found);
  EXPECT_EQ(t.points, 20);
  EXPECT_NEAR(t.tip[0], 10e-3, 1e-12);
  EXPECT_NEAR(t.tip[1], 0.0, 1e-12);
  EXPECT_NEAR(t.length, 10e-3, 1e-12);
  EXPECT_TRUE(t.branches.empty());
  ASSERT_EQ(t.path.size(), 21u);  // the seed and the 20 points
  EXPECT_EQ(t.path.front()[0], 0.0);
}

TEST(CrackTrace, TurningCrackIsMeasuredAlongItsPathAndShortSpursAreNotBranches) {
  std::vector<Vec2> points;
  add_line(points, {0, 0}, 1, 0, 10);     // 5 mm along x
  add_line(points, {5e-3, 0}, 0, 1, 10);  // then 5 mm along y
  add_line(points, {2e-3, 0}, 0, -1, 2);  // a 1 mm spur beside it
  const CrackTrace t = trace_crack(points, {0, 0}, kLink, 2e-3);
  ASSERT_TRUE(t.found);
  EXPECT_NEAR(t.tip[0], 5e-3, 1e-12);
  EXPECT_NEAR(t.tip[1], 5e-3, 1e-12);
  // Along the points: 4.5 mm, the corner's diagonal step of 0.707 mm (within the link), 4.5 mm;
  // not the straight 7.07 mm.
  EXPECT_NEAR(t.length, 9e-3 + std::sqrt(0.5) * 1e-3, 1e-12);
  EXPECT_TRUE(t.branches.empty());
}

TEST(CrackTrace, ForkGivesTheLongerArmAsTipAndTheOtherAsBranch) {
  std::vector<Vec2> points;
  add_line(points, {0, 0}, 1, 0, 10);  // stem to (5, 0) mm
  const double s = std::sqrt(0.5);
  add_line(points, {5e-3, 0}, s, s, 8);   // upper arm, 4 mm
  add_line(points, {5e-3, 0}, s, -s, 6);  // lower arm, 3 mm
  const CrackTrace t = trace_crack(points, {0, 0}, kLink, 2e-3);
  ASSERT_TRUE(t.found);
  EXPECT_NEAR(t.length, 9e-3, 1e-12);
  EXPECT_NEAR(t.tip[0], 5e-3 + 4e-3 * s, 1e-12);
  EXPECT_NEAR(t.tip[1], 4e-3 * s, 1e-12);
  ASSERT_EQ(t.branches.size(), 1u);
  EXPECT_NEAR(t.branches[0].junction[0], 5e-3, 1e-12);
  EXPECT_NEAR(t.branches[0].junction[1], 0.0, 1e-12);
  EXPECT_NEAR(t.branches[0].length, 3e-3, 1e-12);
  EXPECT_NEAR(t.branches[0].tip[1], -3e-3 * s, 1e-12);
}

// The midpoints of a crack's edge bonds and of its diagonals form two interleaved chains along
// it: the second chain runs beside the path, as long as the crack, and is no branch.
TEST(CrackTrace, ChainBesideThePathIsNoBranch) {
  std::vector<Vec2> points;
  add_line(points, {0, 0}, 1, 0, 30);              // edge bonds, 15 mm
  add_line(points, {0.25e-3, 0.25e-3}, 1, 0, 29);  // diagonals, half a step over and up
  add_line(points, {8e-3, 0}, 0, -1, 8);           // and a real 4 mm branch at x = 8 mm
  const CrackTrace t = trace_crack(points, {0, 0}, kLink, 2e-3);
  ASSERT_TRUE(t.found);
  EXPECT_NEAR(t.tip[0], 15e-3, 0.25e-3 + 1e-12);
  ASSERT_EQ(t.branches.size(), 1u);
  EXPECT_NEAR(t.branches[0].junction[0], 8e-3, 0.5e-3);
  EXPECT_NEAR(t.branches[0].length, 4e-3, 1e-12);
}

TEST(CrackTrace, NothingBrokenAtTheSeedIsNoCrack) {
  std::vector<Vec2> points;
  add_line(points, {5e-3, 0}, 1, 0, 10);
  const CrackTrace t = trace_crack(points, {0, 0}, kLink, 2e-3);
  EXPECT_FALSE(t.found);
  EXPECT_EQ(t.points, 0);
  EXPECT_FALSE(trace_crack(std::vector<Vec2>{}, {0, 0}, kLink, 2e-3).found);
}

}  // namespace
}  // namespace fracta
