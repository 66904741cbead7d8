// Standard error of a correlated time series by block averaging (Flyvbjerg & Petersen,
// J. Chem. Phys. 91, 461 (1989)): the samples are averaged pairwise again and again; the error
// estimate of the blocked series grows while blocks are shorter than the correlation time and
// levels off after. We report the largest estimate over levels that still hold >= 8 blocks, a
// conservative choice that needs no plateau detection.
#pragma once

#include <cstddef>
#include <vector>

namespace kairos {

struct BlockAverage {
  double mean = 0.0;
  double stderr_ = 0.0;  // standard error of the mean
  std::size_t samples = 0;
  std::size_t levels = 0;  // blocking levels examined
};

BlockAverage block_average(const std::vector<double>& samples);

// The same estimate for a series fed one value at a time, in O(log n) memory: each blocking
// level keeps the sums of its completed blocks and the block it is filling (the pairwise means
// of the level below). result() equals block_average() of the whole series, to round-off; for
// the many series of a histogram (one per bin) averaged over samples.
class StreamingBlocks {
 public:
  void add(double x);
  std::size_t samples() const { return levels_.empty() ? 0 : levels_[0].count; }
  BlockAverage result() const;

 private:
  struct Level {
    std::size_t count = 0;  // completed blocks
    double sum = 0.0;       // of (block - shift_)
    double squares = 0.0;   // of (block - shift_)^2
    double pending = 0.0;   // a block waiting for its partner
    bool has_pending = false;
  };
  std::vector<Level> levels_;
  double shift_ = 0.0;  // the first value: sums of deviations from it lose no digits
};

}  // namespace kairos
