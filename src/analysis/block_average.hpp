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

}  // namespace kairos
