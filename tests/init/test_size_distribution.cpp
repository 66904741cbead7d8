// system.size_distribution (docs/config.md): the generated diameters follow the requested
// distribution (Kolmogorov-Smirnov against its exact CDF), the box holds exactly the packing
// fraction asked of the diameters drawn, and random insertion places them without overlap.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "core/periodic.hpp"
#include "init/initial_state.hpp"

namespace kairos {
namespace {

double normal_cdf(double z) {
  return 0.5 * std::erfc(-z / std::sqrt(2.0));
}

// The CDF of the factor (diameter over the species' diameter) of each distribution, mean 1 and
// relative standard deviation p.
double factor_cdf(const std::string& kind, double p, double x) {
  if (kind == "uniform") {
    const double half = std::sqrt(3.0) * p;
    return std::clamp((x - (1.0 - half)) / (2.0 * half), 0.0, 1.0);
  }
  if (kind == "gaussian") {  // cut to (0, 2)
    const double lo = normal_cdf(-1.0 / p), hi = normal_cdf(1.0 / p);
    return std::clamp((normal_cdf((x - 1.0) / p) - lo) / (hi - lo), 0.0, 1.0);
  }
  const double s2 = std::log1p(p * p);  // lognormal
  return x > 0.0 ? normal_cdf((std::log(x) + 0.5 * s2) / std::sqrt(s2)) : 0.0;
}

InitialState<3> generate(const std::string& kind, double p, std::uint64_t n, double eta) {
  SystemConfig c;
  c.particles = n;
  c.packing_fraction = eta;
  c.lattice = "random";
  c.size_distribution = kind;
  c.polydispersity = p;
  c.species = {SpeciesConfig{.name = "A", .diameter = 2.0}};
  std::mt19937_64 rng(42);
  return make_initial_state<3>(c, rng);
}

TEST(SizeDistribution, DiametersPassKolmogorovSmirnov) {
  constexpr std::uint64_t kN = 20000;
  for (const auto& [kind, p] : {std::pair<std::string, double>{"uniform", 0.1},
                                {"gaussian", 0.1},
                                {"gaussian", 0.25},
                                {"lognormal", 0.1},
                                {"lognormal", 0.3}}) {
    SCOPED_TRACE(kind + " " + std::to_string(p));
    const InitialState<3> s = generate(kind, p, kN, 0.2);
    std::vector<double> x;
    for (double d : s.diameter) x.push_back(d / 2.0);
    std::sort(x.begin(), x.end());
    double ks = 0.0;
    for (std::size_t i = 0; i < x.size(); ++i) {
      const double f = factor_cdf(kind, p, x[i]);
      ks = std::max({ks, std::abs(f - static_cast<double>(i) / kN),
                     std::abs(f - static_cast<double>(i + 1) / kN)});
    }
    // The 1 % critical value of the KS statistic is 1.63 / sqrt(N).
    EXPECT_LT(ks, 1.63 / std::sqrt(static_cast<double>(kN)));
    EXPECT_NEAR(packing_fraction(s), 0.2, 1e-12);
    double mean = 0.0, var = 0.0;
    for (double v : x) mean += v;
    mean /= kN;
    for (double v : x) var += (v - mean) * (v - mean);
    EXPECT_NEAR(mean, 1.0, 4.0 * p / std::sqrt(static_cast<double>(kN)));
    EXPECT_NEAR(std::sqrt(var / kN), p, 0.05 * p);
  }
}

TEST(SizeDistribution, ALatticeStartHasNoSizeGradient) {
  SystemConfig c;
  c.particles = 4000;
  c.packing_fraction = 0.3;
  c.lattice = "fcc";
  c.size_distribution = "uniform";
  c.polydispersity = 0.2;
  std::mt19937_64 rng(3);
  const InitialState<3> s = make_initial_state<3>(c, rng);
  double low = 0.0, high = 0.0;
  int n_low = 0, n_high = 0;
  for (std::size_t i = 0; i < s.position.size(); ++i) {
    (s.position[i][2] < 0.5 * s.box[2] ? low : high) += s.diameter[i];
    ++(s.position[i][2] < 0.5 * s.box[2] ? n_low : n_high);
  }
  // The halves' mean diameters agree within a few standard errors (0.2 / sqrt(2000)).
  EXPECT_NEAR(low / n_low, high / n_high, 0.02);
}

TEST(SizeDistribution, NoneKeepsTheSpeciesDiameter) {
  const InitialState<3> s = generate("none", 0.0, 500, 0.3);
  for (double d : s.diameter) EXPECT_EQ(d, 2.0);
}

TEST(SizeDistribution, DenseInsertionHasNoOverlap) {
  const InitialState<3> s = generate("lognormal", 0.3, 3000, 0.34);
  double worst = 0.0;
  for (std::size_t i = 0; i < s.position.size(); ++i)
    for (std::size_t j = i + 1; j < s.position.size(); ++j)
      worst = std::max(worst, pair_overlap<3>(s.box, s.position[i], s.position[j], s.diameter[i],
                                              s.diameter[j]));
  EXPECT_EQ(worst, 0.0);
}

}  // namespace
}  // namespace kairos
