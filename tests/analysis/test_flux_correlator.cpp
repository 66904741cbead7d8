// The correlator's collective uses (analysis/msd.hpp with one "particle" per moment component,
// as run/outputs/transport_output.cpp feeds it): a random-walk moment with a drift gives back
// its coefficient about the measured drift (and not without it), and the Green-Kubo integral of
// its block-averaged fluxes (kFluxProduct) equals the Einstein one, for white and for
// correlated (AR(1)) fluxes whose integral is known.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "analysis/msd.hpp"

namespace kairos {
namespace {

using Correlator = MsdCorrelator<1>;

// A moment whose increments over dt are dt times an AR(1) flux J_k = phi J_{k-1} + noise of
// stationary variance `variance`, plus drift * t; `components` independent copies in group 0.
struct Walk {
  Correlator moments, fluxes;
  double first = 0.0, last = 0.0, span = 0.0;
};

Walk walk(double phi, double variance, double drift, int samples, int components,
          std::uint64_t seed) {
  const double dt = 0.1;
  std::vector<std::uint32_t> group(static_cast<std::size_t>(components), 0u);
  Walk w{Correlator(group, 1, dt), Correlator(group, 1, dt, Correlator::Statistic::kFluxProduct),
         0.0, 0.0, 0.0};
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, std::sqrt(variance * (1.0 - phi * phi)));
  std::vector<double> flux(group.size());
  for (double& j : flux) j = noise(rng) / std::sqrt(1.0 - phi * phi);
  std::vector<Vec<1>> x(group.size(), Vec<1>{0.0});
  for (int k = 0; k < samples; ++k) {
    w.moments.add(x);
    w.fluxes.add(x);
    if (k == 0) w.first = x[0][0];
    w.last = x[0][0];
    for (std::size_t c = 0; c < x.size(); ++c) {
      flux[c] = phi * flux[c] + noise(rng);
      x[c][0] += (flux[c] + drift) * dt;
    }
  }
  w.span = (samples - 1) * dt;
  return w;
}

// The Einstein coefficient (slope / 2) of the walk: dt C(0) (1/2 + phi / (1 - phi)), the
// discrete Green-Kubo sum of the AR(1) autocorrelation C(k dt) = variance phi^k.
double expected(double phi, double variance) {
  const double dt = 0.1;
  return dt * variance * (0.5 + phi / (1.0 - phi));
}

TEST(FluxCorrelator, AboutItsDriftARandomWalkGivesItsCoefficient) {
  const double variance = 4.0, drift = 3.0;
  const Walk w = walk(0.0, variance, drift, 200000, 1, 1);
  const double from = 1.0, to = 50.0;
  const double measured_drift = (w.last - w.first) / w.span;
  const auto about = w.moments.diffusion(from, to, {Vec<1>{measured_drift}}, w.span);
  ASSERT_TRUE(about[0]);
  const double reference = expected(0.0, variance);
  EXPECT_LT(about[0]->stderr_, 0.1 * reference);
  EXPECT_NEAR(about[0]->coefficient, reference, 4.0 * about[0]->stderr_);
  // Without the drift the slope is the drift's square growing: far off.
  const auto plain = w.moments.diffusion(from, to);
  ASSERT_TRUE(plain[0]);
  EXPECT_GT(plain[0]->coefficient, 10.0 * reference);
}

TEST(FluxCorrelator, GreenKuboOfBlockAveragedFluxesEqualsEinstein) {
  for (const double phi : {0.0, 0.8}) {
    const double variance = 2.0;
    const Walk w = walk(phi, variance, 0.0, 100000, 4, 2);
    const double reference = expected(phi, variance);
    const auto einstein = w.moments.diffusion(2.0, 40.0);
    const auto gk = w.fluxes.green_kubo(40.0);
    ASSERT_TRUE(einstein[0] && gk[0]);
    EXPECT_NEAR(einstein[0]->coefficient, reference, 4.0 * einstein[0]->stderr_) << phi;
    EXPECT_NEAR(gk[0]->coefficient, reference, 4.0 * gk[0]->stderr_) << phi;
    EXPECT_LT(gk[0]->stderr_, 0.15 * reference) << phi;
    // The fluxes' own autocorrelation at lag 0 is the AR(1) variance.
    EXPECT_NEAR(w.fluxes.lags()[0].mean[0], variance, 0.05 * variance) << phi;
  }
}

TEST(FluxCorrelator, GreenKuboAboutTheMeanOfAFluxWithAMean) {
  const double variance = 2.0, drift = 5.0;
  const Walk w = walk(0.5, variance, drift, 100000, 1, 3);
  const double mean = (w.last - w.first) / w.span;
  const auto about = w.fluxes.green_kubo(40.0, {Vec<1>{mean}});
  ASSERT_TRUE(about[0]);
  const auto einstein = w.moments.diffusion(2.0, 40.0, {Vec<1>{mean}}, w.span);
  ASSERT_TRUE(einstein[0]);
  const double reference = expected(0.5, variance);
  EXPECT_NEAR(einstein[0]->coefficient, reference, 4.0 * einstein[0]->stderr_);
  // One component: no subsets to scatter, so the comparison carries Einstein's error.
  EXPECT_NEAR(about[0]->coefficient, reference, 5.0 * einstein[0]->stderr_);
  // Without removing the mean the integral is the mean's square times the lag: far off.
  EXPECT_GT(w.fluxes.green_kubo(40.0)[0]->coefficient, 10.0 * reference);
}

}  // namespace
}  // namespace kairos
