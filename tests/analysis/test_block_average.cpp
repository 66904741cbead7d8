#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <vector>

#include "analysis/block_average.hpp"

namespace kairos {
namespace {

// A stationary AR(1) series x_{t+1} = phi x_t + e_t, e_t ~ N(0, 1): var(x) = 1 / (1 - phi^2),
// correlation phi^|t - s|, mean 0.
std::vector<double> ar1(double phi, std::size_t n, std::mt19937_64& rng) {
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::vector<double> x(n);
  double v = gauss(rng) / std::sqrt(1.0 - phi * phi);  // drawn from the stationary law
  for (double& s : x) {
    s = v;
    v = phi * v + gauss(rng);
  }
  return x;
}

// The exact variance of the mean of n consecutive AR(1) samples:
// var(x) / n * [1 + 2 sum_{k=1}^{n-1} (1 - k/n) phi^k]  (-> var(x) / n * (1 + phi) / (1 - phi)).
double ar1_variance_of_mean(double phi, std::size_t n) {
  const auto nd = static_cast<double>(n);
  double sum = 0.0, power = 1.0;
  for (std::size_t k = 1; k < n; ++k) {
    power *= phi;
    sum += (1.0 - static_cast<double>(k) / nd) * power;
  }
  return (1.0 + 2.0 * sum) / (1.0 - phi * phi) / nd;
}

TEST(ChiSquare, UpperTailAtTabulatedQuantiles) {
  // The tabulated 99 % and 95 % points of the chi-square distribution.
  const struct {
    double x;
    std::size_t dof;
    double tail;
  } table[] = {{6.634897, 1, 0.01},   {9.210340, 2, 0.01},  {11.344867, 3, 0.01},
               {13.276704, 4, 0.01},  {15.086272, 5, 0.01}, {16.811894, 6, 0.01},
               {50.892181, 30, 0.01}, {3.841459, 1, 0.05},  {5.991465, 2, 0.05},
               {18.307038, 10, 0.05}, {43.772972, 30, 0.05}};
  for (const auto& t : table)
    EXPECT_NEAR(chi_square_upper_tail(t.x, t.dof), t.tail, 1e-7) << t.dof << " " << t.x;
  EXPECT_DOUBLE_EQ(chi_square_upper_tail(0.0, 3), 1.0);
  EXPECT_NEAR(chi_square_upper_tail(2.0, 2), std::exp(-1.0), 1e-15);
  EXPECT_LT(chi_square_upper_tail(1e4, 7), 1e-300);
}

// Over kSeries independent AR(1) series of 2^14 samples: the reported errors against the
// actual scatter of the means and against the exact variance of the mean.
class Ar1Ensemble : public ::testing::TestWithParam<double> {};

TEST_P(Ar1Ensemble, ErrorsMatchTheScatterOfTheMeans) {
  constexpr int kSeries = 400;
  constexpr std::size_t kSamples = 1 << 14;
  const double phi = GetParam();
  std::mt19937_64 rng(20240611 + static_cast<std::uint64_t>(1000 * phi));
  double sum_mean2 = 0.0, sum_err2 = 0.0, sum_err = 0.0, sum_err_err = 0.0;
  double sum_tau = 0.0;
  int covered = 0, reliable = 0;
  for (int s = 0; s < kSeries; ++s) {
    const BlockAverage b = block_average(ar1(phi, kSamples, rng));
    sum_mean2 += b.mean * b.mean;  // the true mean is 0
    sum_err2 += b.stderr_ * b.stderr_;
    sum_err += b.stderr_;
    sum_err_err += b.stderr_error;
    sum_tau += b.correlation_time;
    covered += std::abs(b.mean) <= b.stderr_ ? 1 : 0;
    reliable += b.reliable ? 1 : 0;
  }
  const double scatter = std::sqrt(sum_mean2 / kSeries);
  const double reported = std::sqrt(sum_err2 / kSeries);
  const double exact = std::sqrt(ar1_variance_of_mean(phi, kSamples));
  std::printf(
      "AR(1) phi = %g, %d series of %zu: exact %.5g, scatter %.5g, rms reported %.5g "
      "(/scatter %.3f, /exact %.3f), within 1 error %d, reliable %d, mean tau %.4g\n",
      phi, kSeries, kSamples, exact, scatter, reported, reported / scatter, reported / exact,
      covered, reliable, sum_tau / kSeries);
  // The scatter of 400 means about the true one is known to 1 / sqrt(2 * 400) = 3.5 %, the rms
  // of the reported errors to <= 1.5 %: 3 combined sigma = 11.5 %.
  EXPECT_NEAR(reported / scatter, 1.0, 0.115) << "reported " << reported << " scatter " << scatter;
  // Against the exact value only the reported errors' own spread counts (<= 1.5 %) and the
  // estimator's bias: a plain blocking estimate at the test's level is 20 % low at phi = 0.99.
  EXPECT_NEAR(reported / exact, 1.0, 0.06) << "reported " << reported << " exact " << exact;
  // Within one reported error of the truth: 68.3 % for a normal mean, binomial sigma
  // sqrt(0.683 * 0.317 / 400) = 2.3 %: 3 sigma = 7 %.
  EXPECT_NEAR(static_cast<double>(covered) / kSeries, 0.683, 0.07);
  // The integrated correlation time (1 + phi) / (1 - phi) (exact for 2^14 samples: within 0.1 %
  // of it) within 10 %.
  const double tau = exact * exact * kSamples * (1.0 - phi * phi);
  EXPECT_NEAR(sum_tau / kSeries / tau, 1.0, 0.1) << "tau " << tau;
  // The error of the error against the reported errors' actual spread, within a factor 1.6
  // (the estimate assumes the lag-1 term is kept; at level 0 of white noise it is mostly 0).
  const double mean_err = sum_err / kSeries;
  const double spread = std::sqrt(sum_err2 / kSeries - mean_err * mean_err);
  EXPECT_GT(sum_err_err / kSeries, spread / 1.6) << "spread " << spread;
  EXPECT_LT(sum_err_err / kSeries, spread * 1.6) << "spread " << spread;
  // Reliable: all but the few whose plateau the test rejects by chance (1 % per level); 2^14
  // samples hold 16384, 862 and 82 independent ones, the last near the threshold of 64.
  EXPECT_GE(reliable, phi < 0.95 ? kSeries * 98 / 100 : kSeries * 85 / 100);
}

INSTANTIATE_TEST_SUITE_P(BlockAverage, Ar1Ensemble, ::testing::Values(0.0, 0.9, 0.99));

TEST(BlockAverage, SeriesShorterThanItsCorrelationTimeIsUnreliable) {
  // phi = 0.999: tau = 1999 samples, twice the series' 1024.
  std::mt19937_64 rng(99);
  for (int s = 0; s < 200; ++s) {
    const BlockAverage b = block_average(ar1(0.999, 1 << 10, rng));
    ASSERT_FALSE(b.reliable) << "series " << s << ": " << b.blocks << " blocks, tau "
                             << b.correlation_time;
  }
}

TEST(BlockAverage, WhiteNoiseIsReliableWithABlockPerSample) {
  std::mt19937_64 rng(42);
  std::normal_distribution<double> gauss(3.0, 2.0);
  std::vector<double> x(5000);  // not a power of 2
  for (double& v : x) v = gauss(rng);
  const BlockAverage b = block_average(x);
  EXPECT_TRUE(b.reliable);
  EXPECT_EQ(b.level, 0u);
  EXPECT_EQ(b.blocks, x.size());
  EXPECT_EQ(b.levels, 12u);  // 5000, 2500, ..., 4, 2
  EXPECT_NEAR(b.correlation_time, 1.0, 0.1);
  const double exact = 2.0 / std::sqrt(5000.0);
  EXPECT_NEAR(b.mean, 3.0, 4 * exact);
  EXPECT_NEAR(b.stderr_ / exact, 1.0, 0.06);  // its own error: sqrt(1.5 / 5000) = 1.7 %
  EXPECT_NEAR(b.stderr_error / b.stderr_, std::sqrt(1.5 / 4999.0), 1e-12);
}

TEST(BlockAverage, EmptyTinyAndConstantSeries) {
  EXPECT_EQ(block_average({}).samples, 0u);
  EXPECT_FALSE(block_average({}).reliable);
  const BlockAverage one = block_average({5.0});
  EXPECT_DOUBLE_EQ(one.mean, 5.0);
  EXPECT_DOUBLE_EQ(one.stderr_, 0.0);
  EXPECT_FALSE(one.reliable);
  const BlockAverage b = block_average({1.0, 3.0});
  EXPECT_DOUBLE_EQ(b.mean, 2.0);
  EXPECT_DOUBLE_EQ(b.stderr_, 1.0);  // sample sd sqrt(2) / sqrt(2)
  EXPECT_EQ(b.blocks, 2u);
  EXPECT_FALSE(b.reliable);
  // Constant series (to round-off) have an exact mean: reliable, whatever their length.
  const BlockAverage c = block_average(std::vector<double>(100, 7.1));
  EXPECT_NEAR(c.mean, 7.1, 1e-13);
  EXPECT_LT(c.stderr_, 1e-14);
  EXPECT_DOUBLE_EQ(c.correlation_time, 1.0);
  EXPECT_TRUE(c.reliable);
  EXPECT_TRUE(block_average(std::vector<double>(5, 0.0)).reliable);
  std::vector<double> drift(1000);  // a round-off random walk (the energy of elastic spheres)
  std::mt19937_64 rng(3);
  std::normal_distribution<double> gauss(0.0, 1e-16);
  double v = 1.5;
  for (double& d : drift) d = v += gauss(rng);
  EXPECT_TRUE(block_average(drift).reliable);
  for (std::size_t k = 0; k < drift.size(); ++k) drift[k] += 1e-9 * static_cast<double>(k);
  EXPECT_FALSE(block_average(drift).reliable);  // a drift, no longer round-off
}

}  // namespace
}  // namespace kairos
