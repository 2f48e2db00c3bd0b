// Random bond strengths (kernels/heterogeneity.hpp): the draws follow the Weibull law of unit
// mean, or the uniform law of a strength spread (exact distributions, tested statistically), and a
// model's factors are a function of the seed and the bond's end nodes alone (the same bits on any
// thread count, from any slot order).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "host/simulation.hpp"
#include "kernels/heterogeneity.hpp"
#include "test_util.hpp"

namespace fracta {
namespace {

StrengthDistribution weibull_of(double m) {
  return {m, 1.0 / std::tgamma(1.0 + 1.0 / m)};
}

std::vector<double> draws(double m, std::uint64_t seed, int count) {
  const StrengthDistribution law = weibull_of(m);
  std::vector<double> w(count);
  for (int k = 0; k < count; ++k) w[k] = law.factor(uniform_draw(seed, bond_key(k, k + 1)));
  return w;
}

// Kolmogorov-Smirnov against the exact law F(w) = 1 - exp(-(w Gamma(1 + 1/m))^m): the statistic
// of a sample of n true draws exceeds 1.63 / sqrt(n) with probability 1% (Kolmogorov's limit
// law), and the fixed seeds make the test deterministic. The sample mean is 1 within 5 standard
// errors. Answer: exact (the distribution); tolerance: statistical.
TEST(StrengthWeibull, DrawsFollowTheWeibullLawOfUnitMean) {
  const int n = 100000;
  for (double m : {1.0, 3.0, 8.0, 20.0}) {
    std::vector<double> w = draws(m, 12345, n);
    std::sort(w.begin(), w.end());
    const double g = std::tgamma(1.0 + 1.0 / m);
    double ks = 0, mean = 0;
    for (int k = 0; k < n; ++k) {
      const double cdf = 1.0 - std::exp(-std::pow(w[k] * g, m));
      ks = std::max({ks, std::fabs(cdf - double(k) / n), std::fabs(cdf - double(k + 1) / n)});
      mean += w[k] / n;
    }
    const double sd = std::sqrt(std::tgamma(1.0 + 2.0 / m) / (g * g) - 1.0);
    EXPECT_LT(ks, 1.63 / std::sqrt(double(n))) << "m = " << m;
    EXPECT_NEAR(mean, 1.0, 5.0 * sd / std::sqrt(double(n))) << "m = " << m;
    EXPECT_GT(w.front(), 0.0);
    EXPECT_TRUE(std::isfinite(w.back()));
  }
}

// The uniform law on [1 - d, 1 + d]: Kolmogorov-Smirnov against F(w) = (w - 1 + d) / (2 d), as
// above, and every draw inside the interval. Answer: exact; tolerance: statistical.
TEST(StrengthUniform, DrawsFollowTheUniformLawOfTheSpread) {
  const int n = 100000;
  for (double d : {0.0033, 0.1, 0.5}) {
    const StrengthDistribution law{0.0, 1.0, d};
    std::vector<double> w(n);
    for (int k = 0; k < n; ++k) w[k] = law.factor(uniform_draw(99, bond_key(k, k + 1)));
    std::sort(w.begin(), w.end());
    double ks = 0;
    for (int k = 0; k < n; ++k) {
      const double cdf = (w[k] - 1.0 + d) / (2.0 * d);
      ks = std::max({ks, std::fabs(cdf - double(k) / n), std::fabs(cdf - double(k + 1) / n)});
    }
    EXPECT_LT(ks, 1.63 / std::sqrt(double(n))) << "spread " << d;
    EXPECT_GE(w.front(), 1.0 - d);
    EXPECT_LE(w.back(), 1.0 + d);
  }
}

// Two seeds give independent realisations: the correlation of their draws is within 5 / sqrt(n)
// of zero (its standard error is 1 / sqrt(n)); one seed gives the same draws every time.
TEST(StrengthWeibull, SeedsGiveIndependentRealisations) {
  const int n = 100000;
  const std::vector<double> a = draws(6.0, 1, n), b = draws(6.0, 2, n), a2 = draws(6.0, 1, n);
  EXPECT_EQ(a, a2);
  double ma = 0, mb = 0;
  for (int k = 0; k < n; ++k) ma += a[k] / n, mb += b[k] / n;
  double sab = 0, saa = 0, sbb = 0;
  for (int k = 0; k < n; ++k) {
    sab += (a[k] - ma) * (b[k] - mb);
    saa += (a[k] - ma) * (a[k] - ma);
    sbb += (b[k] - mb) * (b[k] - mb);
  }
  EXPECT_LT(std::fabs(sab / std::sqrt(saa * sbb)), 5.0 / std::sqrt(double(n)));
}

Case weibull_block(double m, std::uint64_t seed) {
  Case c = test::rectangle_case(24, 12, 1e-3, 50e9, 0.2, 2500.0);
  c.bodies[0].method = BodyMethod::de;
  c.materials[0].tensile_strength = 10e6;
  c.materials[0].weibull_modulus = m;
  c.sim.seed = seed;
  return c;
}

template <class V>
auto on_host(const V& v) {
  return Kokkos::create_mirror_view_and_copy(HostSpace(), v);
}

// The model's factors, drawn by a parallel kernel, equal the serial recomputation from the seed
// and each slot's end nodes to the bit (so no thread count or schedule can change them), and
// each cell's bound is 1 / the smallest factor of its six slots. Answer: exact.
TEST(StrengthWeibull, ModelFactorsAreTheSeedsDrawsOfEachBondsEnds) {
  Simulation sim(weibull_block(6.0, 7));
  const Model& model = sim.model();
  ASSERT_EQ(model.bonds.strength_scale.extent(0), static_cast<size_t>(model.bonds.count));
  const auto scale = on_host(model.bonds.strength_scale);
  const auto ends = on_host(model.bonds.nodes);
  const auto cell_scale = on_host(model.elements.cell_inverse_strength_scale);
  const auto slots = on_host(model.element_bonds);
  const StrengthDistribution law = weibull_of(6.0);
  for (int b = 0; b < model.bonds.count; ++b) {
    const double expected = law.factor(uniform_draw(7, bond_key(ends(b, 0), ends(b, 1))));
    ASSERT_EQ(scale(b), expected) << "slot " << b;
  }
  for (int e = 0; e < model.elements.count; ++e) {
    double smallest = 1e300;
    for (int a = 0; a < 6; ++a) smallest = std::min(smallest, scale(slots(e, a)));
    EXPECT_EQ(cell_scale(e), 1.0 / smallest) << "cell " << e;
  }
  // Another model of the same seed draws the same; another seed draws others.
  Simulation same(weibull_block(6.0, 7)), other(weibull_block(6.0, 8));
  const auto same_scale = on_host(same.model().bonds.strength_scale);
  const auto other_scale = on_host(other.model().bonds.strength_scale);
  int equal = 0;
  for (int b = 0; b < model.bonds.count; ++b) {
    EXPECT_EQ(same_scale(b), scale(b));
    equal += other_scale(b) == scale(b);
  }
  EXPECT_EQ(equal, 0);
  // A uniform material draws nothing: the bond kernel then runs as without heterogeneity.
  Simulation uniform(weibull_block(0.0, 7));
  EXPECT_EQ(uniform.model().bonds.strength_scale.extent(0), 0u);
  EXPECT_EQ(uniform.model().elements.cell_inverse_strength_scale.extent(0), 0u);
}

}  // namespace
}  // namespace fracta
