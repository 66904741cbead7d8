#include "analysis/block_average.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace kairos {

namespace {

// Significance of Jonsson's test: a level is accepted as the plateau when M_j stays below the
// 99 % quantile of its chi-square distribution.
constexpr double kAlpha = 0.01;
// Levels with fewer blocks give the estimate of an unreliable error bar no say.
constexpr std::size_t kFallbackMinBlocks = 8;
// A series whose spread is below this fraction of its mean is constant up to round-off.
constexpr double kConstant = 1e-12;

// One blocking level: its variance and lag-1 autocovariance (1/n normalisation, both about the
// level's own mean).
struct Level {
  std::size_t n = 0;
  double variance = 0.0;
  double lag1 = 0.0;

  double blocks_minus_one() const { return static_cast<double>(n - 1); }
  // Flyvbjerg & Petersen's estimate of the variance of the mean: s^2 / (n - 1).
  double plain() const { return variance / blocks_minus_one(); }
  // With the lag-1 term of the truncation error (a negative g is taken for noise).
  double corrected() const { return (variance + 2.0 * std::max(lag1, 0.0)) / blocks_minus_one(); }
  // Jonsson's term n r^2, r = g / s^2 (0 for a constant level).
  double test_term() const {
    if (!(variance > 0.0)) return 0.0;
    const double r = lag1 / variance;
    return static_cast<double>(n) * r * r;
  }
};

Level measure(const std::vector<double>& x) {
  Level l;
  l.n = x.size();
  double mean = 0.0;
  for (double v : x) mean += v;
  mean /= static_cast<double>(l.n);
  double var = 0.0, lag1 = 0.0;
  for (std::size_t i = 0; i < l.n; ++i) {
    const double d = x[i] - mean;
    var += d * d;
    if (i + 1 < l.n) lag1 += d * (x[i + 1] - mean);
  }
  l.variance = var / static_cast<double>(l.n);
  l.lag1 = lag1 / static_cast<double>(l.n);
  return l;
}

}  // namespace

double chi_square_upper_tail(double x, std::size_t dof) {
  if (!(x > 0.0)) return 1.0;
  const double chi = std::sqrt(x);
  const double density = std::exp(-0.5 * x);  // sqrt(2 pi) times the normal density at chi
  double sum = 0.0, term = 0.0;
  if (dof % 2 == 0) {
    // Even dof: Q = e^{-x/2} [1 + sum_{r=1}^{(dof-2)/2} x^r / (2 4 ... 2r)].
    term = 1.0;
    sum = 1.0;
    for (std::size_t r = 1; r < dof / 2; ++r) {
      term *= x / (2.0 * static_cast<double>(r));
      sum += term;
    }
    return std::min(1.0, density * sum);
  }
  // Odd dof: Q = 2 Q_normal(chi) + 2 Z(chi) sum_{r=1}^{(dof-1)/2} chi^{2r-1} / (1 3 ... (2r-1)).
  term = chi;
  for (std::size_t r = 1; r <= (dof - 1) / 2; ++r) {
    if (r > 1) term *= x / (2.0 * static_cast<double>(r) - 1.0);
    sum += term;
  }
  return std::min(1.0, std::erfc(chi / std::numbers::sqrt2) +
                           std::sqrt(2.0 / std::numbers::pi) * density * sum);
}

namespace {

// The estimate from the levels of a series (levels[0]: the samples themselves, at least 2) and
// its mean: Jonsson's test, the lag-1 term, the fallback of an unreliable series.
BlockAverage from_levels(const std::vector<Level>& levels, double mean, std::size_t samples) {
  BlockAverage out;
  out.samples = samples;
  out.mean = mean;
  out.levels = levels.size();
  out.level = 0;
  out.blocks = samples;
  out.correlation_time = 1.0;
  const double naive = levels[0].plain();  // var(x) / n
  if (levels[0].variance <= kConstant * kConstant * out.mean * out.mean) {
    // Constant to round-off (the temperature of elastic hard spheres, the potential energy of
    // particles without potentials): the mean is exact.
    out.stderr_ = std::sqrt(naive);
    out.reliable = true;
    return out;
  }

  // Jonsson's test: the first level j at which M_j = sum_{k >= j} n_k r_k^2 is compatible with
  // chi-square(levels - j). The last level (2 blocks, r = -1/2) always passes.
  std::vector<double> tail(levels.size() + 1, 0.0);
  for (std::size_t k = levels.size(); k-- > 0;) tail[k] = tail[k + 1] + levels[k].test_term();
  std::size_t chosen = levels.size() - 1;
  for (std::size_t j = 0; j < levels.size(); ++j) {
    if (chi_square_upper_tail(tail[j], levels.size() - j) >= kAlpha) {
      chosen = j;
      break;
    }
  }
  double variance_of_mean = levels[chosen].corrected();
  // Relative error of the error: var(s^2 + 2g) = 6 s^4 / n for uncorrelated blocks, half of
  // that relative spread for the square root.
  double relative_error = std::sqrt(1.5 / levels[chosen].blocks_minus_one());
  const double tau = variance_of_mean / naive;
  out.reliable =
      levels[chosen].n >= kReliableBlocks && static_cast<double>(samples) >= kReliableSamples * tau;
  if (!out.reliable) {
    // Too short a series: the estimates still rise with the block length, so the largest of
    // the test's and the later levels' that hold a few blocks.
    for (std::size_t k = chosen + 1; k < levels.size(); ++k) {
      if (levels[k].n >= kFallbackMinBlocks && levels[k].plain() > variance_of_mean) {
        variance_of_mean = levels[k].plain();
        relative_error = std::sqrt(0.5 / levels[k].blocks_minus_one());
        chosen = k;
      }
    }
  }
  out.level = chosen;
  out.blocks = levels[chosen].n;
  out.stderr_ = std::sqrt(variance_of_mean);
  out.stderr_error = out.stderr_ * relative_error;
  out.correlation_time = variance_of_mean / naive;
  return out;
}

}  // namespace

BlockAverage block_average(const std::vector<double>& samples) {
  BlockAverage out;
  out.samples = samples.size();
  if (samples.empty()) return out;
  double sum = 0.0;
  for (double x : samples) sum += x;
  out.mean = sum / static_cast<double>(samples.size());
  if (samples.size() < 2) return out;

  // Levels 0, 1, ... while at least 2 blocks remain; an odd sample left over at a level is
  // dropped from the next (Flyvbjerg & Petersen).
  std::vector<Level> levels;
  std::vector<double> x = samples;
  while (x.size() >= 2) {
    levels.push_back(measure(x));
    std::vector<double> next(x.size() / 2);
    for (std::size_t k = 0; k < next.size(); ++k) next[k] = 0.5 * (x[2 * k] + x[2 * k + 1]);
    x.swap(next);
  }
  return from_levels(levels, out.mean, samples.size());
}

void StreamingBlocks::add(double x) {
  if (levels_.empty()) shift_ = x;
  double block = x;
  for (std::size_t k = 0;; ++k) {
    if (k == levels_.size()) levels_.emplace_back();
    Sums& level = levels_[k];
    const double d = block - shift_;
    if (level.count == 0) level.first = d;
    if (level.count > 0) level.products += level.last * d;
    level.last = d;
    ++level.count;
    level.sum += d;
    level.squares += d * d;
    if (!level.has_pending) {
      level.pending = block;
      level.has_pending = true;
      return;
    }
    block = 0.5 * (level.pending + block);
    level.has_pending = false;
  }
}

// Each level's variance and lag-1 autocovariance about its own mean from its sums (as
// measure() computes them from the blocks), then the estimate of block_average().
BlockAverage StreamingBlocks::result() const {
  BlockAverage out;
  out.samples = samples();
  if (out.samples == 0) return out;
  out.mean = shift_ + levels_[0].sum / static_cast<double>(levels_[0].count);
  if (out.samples < 2) return out;
  std::vector<Level> levels;
  for (const Sums& s : levels_) {
    if (s.count < 2) break;
    const auto n = static_cast<double>(s.count);
    const double m = s.sum / n;  // of the deviations from shift_
    Level l;
    l.n = s.count;
    l.variance = std::max(0.0, s.squares / n - m * m);
    // Σ_{i<n-1} (d_i - m)(d_{i+1} - m) / n.
    l.lag1 = (s.products - m * ((s.sum - s.last) + (s.sum - s.first)) + (n - 1.0) * m * m) / n;
    levels.push_back(l);
  }
  return from_levels(levels, out.mean, out.samples);
}

}  // namespace kairos
