#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "analysis/block_average.hpp"

namespace kairos {
namespace {

TEST(BlockAverage, UncorrelatedSeriesGivesSigmaOverRootN) {
  std::mt19937_64 rng(42);
  std::normal_distribution<double> gauss(3.0, 2.0);
  std::vector<double> x(4096);
  for (double& v : x) v = gauss(rng);
  const BlockAverage b = block_average(x);
  EXPECT_NEAR(b.mean, 3.0, 4 * 2.0 / 64.0);
  // sigma / sqrt(N) = 2 / 64; the max over levels is a little above it.
  EXPECT_GT(b.stderr_, 0.8 * 2.0 / 64.0);
  EXPECT_LT(b.stderr_, 1.6 * 2.0 / 64.0);
}

TEST(BlockAverage, CorrelatedSeriesErrorIsNotUnderestimated) {
  // AR(1) with correlation 0.9: the true error of the mean is sqrt((1+a)/(1-a)) ~ 4.4 times
  // the naive one. Blocking must see most of that.
  std::mt19937_64 rng(7);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const double a = 0.9;
  std::vector<double> x(1 << 14);
  double v = 0.0;
  for (double& s : x) s = v = a * v + gauss(rng);
  double var = 0.0;
  for (double s : x) var += s * s;
  var /= static_cast<double>(x.size());
  const double naive = std::sqrt(var / static_cast<double>(x.size()));
  const BlockAverage b = block_average(x);
  EXPECT_GT(b.stderr_, 3.0 * naive);
  EXPECT_LT(b.stderr_, 6.5 * naive);
}

TEST(BlockAverage, EmptyAndTinySeries) {
  EXPECT_EQ(block_average({}).samples, 0u);
  const BlockAverage b = block_average({1.0, 3.0});
  EXPECT_DOUBLE_EQ(b.mean, 2.0);
  EXPECT_DOUBLE_EQ(b.stderr_, 1.0);
}

}  // namespace
}  // namespace kairos
