#include "analysis/block_average.hpp"

#include <algorithm>
#include <cmath>

namespace kairos {

BlockAverage block_average(const std::vector<double>& samples) {
  BlockAverage out;
  out.samples = samples.size();
  if (samples.empty()) return out;
  double sum = 0.0;
  for (double x : samples) sum += x;
  out.mean = sum / static_cast<double>(samples.size());
  std::vector<double> level = samples;
  while (level.size() >= 8) {
    const auto n = static_cast<double>(level.size());
    double var = 0.0;
    for (double x : level) {
      const double d = x - out.mean;
      var += d * d;
    }
    var /= n - 1.0;
    out.stderr_ = std::max(out.stderr_, std::sqrt(var / n));
    ++out.levels;
    std::vector<double> next(level.size() / 2);
    for (std::size_t k = 0; k < next.size(); ++k) next[k] = 0.5 * (level[2 * k] + level[2 * k + 1]);
    level.swap(next);
  }
  if (out.levels == 0 && samples.size() > 1) {
    // Too few samples to block: plain standard error (an underestimate if correlated).
    double var = 0.0;
    for (double x : samples) var += (x - out.mean) * (x - out.mean);
    out.stderr_ = std::sqrt(var / static_cast<double>(samples.size() - 1) /
                            static_cast<double>(samples.size()));
  }
  return out;
}

void StreamingBlocks::add(double x) {
  if (levels_.empty()) shift_ = x;
  double block = x;
  for (std::size_t k = 0;; ++k) {
    if (k == levels_.size()) levels_.emplace_back();
    Level& level = levels_[k];
    const double d = block - shift_;
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

// As block_average: the deviations from the overall mean at every level with >= 8 blocks, the
// largest estimate; the plain standard error below 8 samples.
BlockAverage StreamingBlocks::result() const {
  BlockAverage out;
  out.samples = samples();
  if (out.samples == 0) return out;
  const double n0 = static_cast<double>(levels_[0].count);
  const double mean_shifted = levels_[0].sum / n0;
  out.mean = shift_ + mean_shifted;
  const auto spread = [&](const Level& level) {  // sum of squared deviations from the mean
    const auto n = static_cast<double>(level.count);
    return std::max(
        0.0, level.squares - 2.0 * mean_shifted * level.sum + n * mean_shifted * mean_shifted);
  };
  for (const Level& level : levels_) {
    if (level.count < 8) break;
    const auto n = static_cast<double>(level.count);
    out.stderr_ = std::max(out.stderr_, std::sqrt(spread(level) / (n - 1.0) / n));
    ++out.levels;
  }
  if (out.levels == 0 && out.samples > 1)
    out.stderr_ = std::sqrt(spread(levels_[0]) / (n0 - 1.0) / n0);
  return out;
}

}  // namespace kairos
