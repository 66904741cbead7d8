// The multiple-tau MSD correlator (analysis/msd.hpp): every lag it reports equals the brute-force
// average over the same time origins, ballistic motion gives |v|^2 t^2 exactly, and a random walk
// of known diffusion coefficient gives it back within the reported error (which itself matches
// the scatter over independent walks).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "../release_suite_only.hpp"
#include "analysis/msd.hpp"

namespace kairos {
namespace {

TEST(MsdCorrelator, EveryLagIsTheBruteForceAverageOverItsOrigins) {
  constexpr int n = 13, samples = 300;
  std::mt19937_64 rng(5);
  std::normal_distribution<double> step(0.0, 1.0);
  std::vector<std::vector<Vec<3>>> path(samples, std::vector<Vec<3>>(n));
  for (int s = 1; s < samples; ++s)
    for (int k = 0; k < n; ++k)
      for (int a = 0; a < 3; ++a) path[s][k][a] = path[s - 1][k][a] + step(rng);
  std::vector<std::uint32_t> group(n);
  for (int k = 0; k < n; ++k) group[k] = k % 2;
  MsdCorrelator<3> c(group, 2, 0.5);
  for (const auto& x : path) c.add(x);
  const auto lags = c.lags();
  ASSERT_GT(lags.size(), 20u);
  for (const auto& lag : lags) {
    const auto steps = static_cast<int>(std::lround(lag.lag / 0.5));
    // The origins of this lag: samples on its level's grid (every m^l-th sample).
    int spacing = 1;
    while (steps / spacing >= MsdCorrelator<3>::kPoints) spacing *= MsdCorrelator<3>::kRatio;
    std::array<double, 2> sum{};
    std::array<int, 2> count{};
    std::uint64_t origins = 0;
    for (int s = steps; s < samples; s += spacing) {
      if (s % spacing != 0) continue;
      ++origins;
      for (int k = 0; k < n; ++k) {
        double r2 = 0.0;
        for (int a = 0; a < 3; ++a) r2 += std::pow(path[s][k][a] - path[s - steps][k][a], 2);
        sum[group[k]] += r2;
        ++count[group[k]];
      }
    }
    EXPECT_EQ(lag.origins, origins) << "lag " << steps;
    for (int g = 0; g < 2; ++g)
      EXPECT_NEAR(lag.mean[g], sum[g] / count[g], 1e-12 * lag.mean[g]) << "lag " << steps;
  }
}

TEST(MsdCorrelator, BallisticMotionGivesSpeedSquaredTimesLagSquared) {
  constexpr int n = 50;
  std::vector<Vec<2>> v(n);
  for (int k = 0; k < n; ++k) v[k] = {std::cos(k * 0.3), 2.0 * std::sin(k * 0.7)};
  double v2 = 0.0;
  for (const auto& w : v) v2 += w[0] * w[0] + w[1] * w[1];
  v2 /= n;
  MsdCorrelator<2> c(std::vector<std::uint32_t>(n, 0), 1, 0.1);
  std::vector<Vec<2>> x(n);
  for (int s = 0; s < 5000; ++s) {
    for (int k = 0; k < n; ++k) x[k] = {v[k][0] * 0.1 * s + k, v[k][1] * 0.1 * s - k};
    c.add(x);
  }
  for (const auto& lag : c.lags())
    EXPECT_NEAR(lag.mean[0], v2 * lag.lag * lag.lag, 1e-9 * lag.mean[0]);
  // Lags reach beyond a tenth of the run with memory for a few levels only.
  EXPECT_GT(c.lags().back().lag, 0.1 * 5000 * 0.1);
  EXPECT_LT(c.bytes(), 20u * MsdCorrelator<2>::kPoints * n * sizeof(Vec<2>) + 100000u);
}

// Brownian walkers with diffusion coefficient D0: the fitted D and its error bar.
MsdCorrelator<3>::Diffusion walk(std::uint64_t seed, double d0) {
  constexpr int n = 400, samples = 2000;
  constexpr double dt = 0.05;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> step(0.0, std::sqrt(2.0 * d0 * dt));
  MsdCorrelator<3> c(std::vector<std::uint32_t>(n, 0), 1, dt);
  std::vector<Vec<3>> x(n);
  for (int s = 0; s < samples; ++s) {
    c.add(x);
    for (auto& p : x)
      for (int a = 0; a < 3; ++a) p[a] += step(rng);
  }
  const auto lags = c.lags();
  for (const auto& lag : lags) {  // Gaussian displacements
    if (lag.lag < 10.0) {
      EXPECT_NEAR(lag.non_gaussian[0], 0.0, 0.1);
    }
  }
  const auto d = c.diffusion(1.0, 20.0);
  EXPECT_TRUE(d[0].has_value());
  return *d[0];
}

TEST(MsdCorrelator, ARandomWalkGivesBackItsDiffusionCoefficientWithinItsErrorBar) {
  KAIROS_RELEASE_SUITE_ONLY();
  const double d0 = 0.3;
  std::vector<double> values, errors;
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    const auto d = walk(seed, d0);
    values.push_back(d.coefficient);
    errors.push_back(d.stderr_);
  }
  const auto runs = static_cast<double>(values.size());
  double mean = 0.0, scatter = 0.0, error = 0.0;
  int within = 0;
  for (std::size_t k = 0; k < values.size(); ++k) {
    mean += values[k] / runs;
    error += errors[k] / runs;
    if (std::abs(values[k] - d0) < errors[k]) ++within;
  }
  for (double v : values) scatter += (v - mean) * (v - mean) / (runs - 1.0);
  scatter = std::sqrt(scatter);
  // The mean of 20 walks is within 4 standard errors of the mean of D0.
  EXPECT_NEAR(mean, d0, 4.0 * scatter / std::sqrt(20.0));
  // The reported error is the walks' scatter (8 subsets: its own error is ~25 %; a factor 1.7).
  EXPECT_GT(error, scatter / 1.7);
  EXPECT_LT(error, scatter * 1.7);
  // About 68 % inside one error bar: at least 8 of 20 (binomial, p = 0.68: P(< 8) < 0.1 %).
  EXPECT_GE(within, 8);
}

// A group with no particle (a species none of whose particles is followed) has no coefficient,
// not a zero one, while the other groups are fitted.
TEST(MsdCorrelator, AnEmptyGroupHasNoCoefficient) {
  MsdCorrelator<1> c({0u, 0u, 2u}, 3, 1.0);
  std::mt19937_64 rng(4);
  std::normal_distribution<double> step(0.0, 1.0);
  std::vector<Vec<1>> x(3, Vec<1>{0.0});
  for (int k = 0; k < 200; ++k) {
    c.add(x);
    for (auto& p : x) p[0] += step(rng);
  }
  const auto fits = c.diffusion(2.0, 20.0);
  EXPECT_TRUE(fits[0].has_value());
  EXPECT_FALSE(fits[1].has_value());
  EXPECT_TRUE(fits[2].has_value());
  EXPECT_EQ(c.members(1), 0u);
  EXPECT_EQ(c.members(0), 2u);
}

// Walkers that also share one random displacement per step (as the particles of a box share its
// slow flows): subsets of particles all see it, so only the epochs' scatter measures it.
TEST(MsdCorrelator, MotionTheParticlesShareIsInTheErrorBar) {
  constexpr int n = 400, samples = 2000;
  constexpr double dt = 0.05, own = 0.1, shared = 0.3;
  std::vector<double> values, errors, particle_errors;
  for (std::uint64_t seed = 1; seed <= 16; ++seed) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> step(0.0, 1.0);
    MsdCorrelator<3> c(std::vector<std::uint32_t>(n, 0), 1, dt);
    std::vector<Vec<3>> x(n);
    for (int s = 0; s < samples; ++s) {
      c.add(x);
      Vec<3> common{};
      for (int a = 0; a < 3; ++a) common[a] = std::sqrt(2.0 * shared * dt) * step(rng);
      for (auto& p : x)
        for (int a = 0; a < 3; ++a) p[a] += common[a] + std::sqrt(2.0 * own * dt) * step(rng);
    }
    const auto d = c.diffusion(1.0, 20.0);
    ASSERT_TRUE(d[0].has_value());
    EXPECT_GE(d[0]->epochs, 8);
    values.push_back(d[0]->coefficient);
    errors.push_back(d[0]->stderr_);
    particle_errors.push_back(d[0]->particle_stderr);
  }
  const auto runs = static_cast<double>(values.size());
  double mean = 0.0, scatter = 0.0, error = 0.0, particle_error = 0.0;
  for (std::size_t k = 0; k < values.size(); ++k) {
    mean += values[k] / runs;
    error += errors[k] / runs;
    particle_error += particle_errors[k] / runs;
  }
  for (double v : values) scatter += (v - mean) * (v - mean) / (runs - 1.0);
  scatter = std::sqrt(scatter);
  EXPECT_NEAR(mean, own + shared, 4.0 * scatter / std::sqrt(runs));
  EXPECT_LT(particle_error, scatter / 3.0);  // the subsets cannot see the shared motion
  EXPECT_GT(error, scatter / 2.0);           // the epochs do (16 runs: the scatter to ~20 %)
  EXPECT_LT(error, scatter * 2.0);
}

TEST(MsdCorrelator, ProductsAreTheBruteForceVelocityAutocorrelation) {
  constexpr int n = 7, samples = 200;
  std::mt19937_64 rng(8);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::vector<std::vector<Vec<2>>> v(samples, std::vector<Vec<2>>(n));
  for (int s = 0; s < samples; ++s)
    for (int k = 0; k < n; ++k)
      for (int a = 0; a < 2; ++a) v[s][k][a] = (s > 0 ? 0.9 * v[s - 1][k][a] : 0.0) + noise(rng);
  using C = MsdCorrelator<2>;
  C c(std::vector<std::uint32_t>(n, 0), 1, 1.0, C::Statistic::kProduct);
  for (const auto& x : v) c.add(x);
  const auto lags = c.lags();
  ASSERT_EQ(lags.front().lag, 0.0);  // C(0) = <v^2>
  for (const auto& lag : lags) {
    const auto steps = static_cast<int>(std::lround(lag.lag));
    int spacing = 1;
    while (steps / spacing >= C::kPoints) spacing *= C::kRatio;
    double sum = 0.0;
    int count = 0;
    for (int s = steps; s < samples; s += 1) {
      if (s % spacing != 0) continue;
      for (int k = 0; k < n; ++k) {
        sum += v[s][k][0] * v[s - steps][k][0] + v[s][k][1] * v[s - steps][k][1];
        ++count;
      }
    }
    EXPECT_NEAR(lag.mean[0], sum / count, 1e-12 * std::abs(sum / count) + 1e-14) << steps;
  }
}

TEST(MsdCorrelator, GreenKuboOfAnOrnsteinUhlenbeckVelocityGivesItsDiffusionCoefficient) {
  // v(t + dt) = phi v(t) + noise: <v_x(t) v_x(0)> = s2 phi^(t / dt), s2 = q / (1 - phi^2), and
  // D = s2 dt (1 / 2 + phi / (1 - phi)) exactly for the trapezoid rule on the sample grid; the
  // log-spaced lags beyond 7 samples add a small quadrature error (here < 1 %).
  constexpr int n = 300, samples = 6000;
  const double phi = 0.95, q = 0.1, dt = 0.1;
  std::mt19937_64 rng(4);
  std::normal_distribution<double> noise(0.0, std::sqrt(q));
  using C = MsdCorrelator<3>;
  C c(std::vector<std::uint32_t>(n, 0), 1, dt, C::Statistic::kProduct);
  const double s2 = q / (1.0 - phi * phi);
  std::normal_distribution<double> start(0.0, std::sqrt(s2));
  std::vector<Vec<3>> v(n);
  for (auto& w : v)
    for (int a = 0; a < 3; ++a) w[a] = start(rng);
  for (int s = 0; s < samples; ++s) {
    c.add(v);
    for (auto& w : v)
      for (int a = 0; a < 3; ++a) w[a] = phi * w[a] + noise(rng);
  }
  const double exact = s2 * dt * (0.5 + phi / (1.0 - phi));
  const auto d = c.green_kubo(200.0 * dt);
  ASSERT_TRUE(d[0].has_value());
  EXPECT_LT(d[0]->stderr_, 0.05 * exact);
  EXPECT_NEAR(d[0]->coefficient, exact, 3.0 * d[0]->stderr_ + 0.01 * exact);
  // Displacements give no Green-Kubo integral.
  C msd(std::vector<std::uint32_t>(n, 0), 1, dt);
  msd.add(v);
  EXPECT_FALSE(msd.green_kubo(1.0)[0].has_value());
}

}  // namespace
}  // namespace kairos
