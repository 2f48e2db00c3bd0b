// The boundary laws (src/kernels/boundaries.hpp) against their closed forms: the bar end's
// implicit face stress satisfies sigma = Z (2 v_I - v) at the end of the kicks it drives, never
// pulls, and damps a lone face for any Z A dt / M; the push-only support holds while pressed and
// catches a node moving into it. Exact-solution tests (algebra of the laws, no discretization
// error).
#include <gtest/gtest.h>

#include <cmath>

#include "kernels/boundaries.hpp"

namespace fracta {
namespace {

// Over the kicks the force drives (dt: this step's second half and the next's first), the face
// ends at v_end = v_half + dt (F + A sigma) / M, and sigma = Z (2 v_I - v_end) exactly.
TEST(BarImpedance, FaceStressSolvesTheBarEquationAtTheIntervalsEnd) {
  const BarImpedance bar{4.3e7, 5e-5};
  const double mass = 2e-3, dt = 8e-8, force = -150.0, v_half = 1.5, v_incident = 10.0;
  const double sigma = bar.stress(v_incident, v_half, force, mass, dt);
  const double v_end = v_half + dt * (force + bar.area * sigma) / mass;
  EXPECT_NEAR(sigma, bar.impedance * (2 * v_incident - v_end), 1e-12 * sigma);
  // At rest with no other force: Z 2 v_I / (1 + D), D = Z A dt / M.
  const double d = dt * bar.impedance * bar.area / mass;
  EXPECT_NEAR(bar.stress(v_incident, 0, 0, mass, dt), 2 * bar.impedance * v_incident / (1 + d),
              1e-12 * bar.impedance * v_incident);
}

TEST(BarImpedance, NeverPulls) {
  const BarImpedance bar{4.3e7, 5e-5};
  // A face leaving the bar faster than twice the incident velocity separates from it.
  EXPECT_EQ(bar.stress(1.0, 3.0, 0.0, 1e-3, 1e-8), 0.0);
  EXPECT_EQ(bar.stress(0.0, 0.5, 0.0, 1e-3, 1e-8), 0.0);   // transmitted bar, face pulled away
  EXPECT_GT(bar.stress(0.0, -0.5, 0.0, 1e-3, 1e-8), 0.0);  // face pressing into it
}

// A lone face of mass M moving into a transmitted bar, stepped as the integrator does (the force
// of one evaluation drives the second half kick and the next first half): it must slow by
// exactly 1 / (1 + D) per step for any D = Z A dt / M, never reverse (a trapezoidal dashpot
// would, for D > 2), and for D << 1 follow the exact exp(-D n).
TEST(BarImpedance, DampsALoneFaceForAnyStep) {
  for (const double d : {0.01, 1.0, 10.0, 1e4}) {
    const double mass = 1e-3, dt = 1e-7, area = 1e-4;
    const BarImpedance bar{d * mass / (area * dt), area};
    double v_half = -1.0;  // v(1/2), moving into the bar
    for (int n = 0; n < 50; ++n) {
      const double sigma = bar.stress(0.0, v_half, 0.0, mass, dt);
      const double v_next = v_half + dt * area * sigma / mass;
      ASSERT_NEAR(v_next, v_half / (1 + d), 1e-14) << "D = " << d << ", step " << n;
      ASSERT_LE(v_next, 0.0) << "D = " << d;  // never thrown back out of the bar
      v_half = v_next;
    }
    if (d == 0.01) {
      EXPECT_NEAR(v_half, -std::exp(-0.5), 0.01 * std::exp(-0.5));
    }
  }
}

TEST(UnilateralSupport, HoldsWhilePressedAndCatchesAnApproach) {
  // The support pushes along +x (sign +1).
  EXPECT_TRUE(UnilateralSupport::holds(+1, -10.0));   // pressed into it
  EXPECT_FALSE(UnilateralSupport::holds(+1, +10.0));  // pulled away
  EXPECT_TRUE(UnilateralSupport::holds(-1, +10.0));   // a support pushing along -x
  EXPECT_TRUE(UnilateralSupport::catches(+1, 0.0, -1.0));
  EXPECT_TRUE(UnilateralSupport::catches(+1, -1e-9, -1.0));  // overshot within the step
  EXPECT_FALSE(UnilateralSupport::catches(+1, 1e-6, -1.0));  // still short of it
  EXPECT_FALSE(UnilateralSupport::catches(+1, 0.0, +1.0));   // leaving
}

}  // namespace
}  // namespace fracta
