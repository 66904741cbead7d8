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

}  // namespace kairos
