// Standard error of the mean of a correlated time series by blocking (Flyvbjerg & Petersen,
// J. Chem. Phys. 91, 461 (1989)), the level chosen automatically by the hypothesis test of
// M. Jonsson, Phys. Rev. E 98, 043304 (2018). docs/physics.md, "Statistical errors", gives the
// formulas; docs/validation.md the check on AR(1) series.
//
// The series is averaged pairwise again and again (level k: n_k blocks of 2^k samples). At
// each level the variance s_k^2 and the lag-1 autocovariance g_k of the blocks are measured;
// for uncorrelated blocks of levels j, j+1, ... Jonsson's statistic
//   M_j = sum_{k >= j} n_k (g_k / s_k^2)^2
// is asymptotically chi-square with as many degrees of freedom as it has terms, and the first
// level j whose M_j stays below the 99 % quantile is taken as the plateau. Since the test
// cannot see a lag-1 correlation r below about sqrt(6.6 / n_j), which leaves Flyvbjerg &
// Petersen's estimate s_j^2 / (n_j - 1) of the variance of the mean low by about 2r, the
// lag-1 term of their truncation error is kept (Kairos's addition, checked on AR(1) series):
// var(mean) = (s_j^2 + 2 max(g_j, 0)) / (n_j - 1).
#pragma once

#include <cstddef>
#include <vector>

namespace kairos {

struct BlockAverage {
  double mean = 0.0;
  double stderr_ = 0.0;       // standard error of the mean
  double stderr_error = 0.0;  // standard error of stderr_ itself
  std::size_t samples = 0;
  std::size_t levels = 0;  // blocking levels examined (those with >= 2 blocks)
  std::size_t level = 0;   // the level stderr_ comes from: blocks of 2^level samples
  std::size_t blocks = 0;  // blocks at that level: effectively independent when `reliable`
  // Integrated correlation time in samples, tau = samples * stderr_^2 / var(x): 1 for
  // uncorrelated samples; the series holds about samples / tau independent ones.
  double correlation_time = 0.0;
  // A plateau was found at a level with at least kReliableBlocks blocks, and the series holds
  // at least kReliableSamples independent ones (samples / tau); or the series is constant to
  // round-off (>= 2 samples whose spread is below 1e-12 of their mean, or all zero: the mean
  // is exact, tau is reported as 1). When false the series is too short for its correlation
  // time (or too short altogether): stderr_ is then the largest of the estimates at the test's
  // level and at the later levels with >= 8 blocks, at best a lower bound of the true error.
  bool reliable = false;
};

// Fewest blocks at the chosen level for a reliable error bar: with fewer the test has too
// little power to tell a plateau from a still-rising estimate, and the error bar itself is
// uncertain by more than sqrt(3 / (2 * 31)) = 22 %.
inline constexpr std::size_t kReliableBlocks = 32;
// Fewest independent samples (samples / tau) for a reliable error bar: blocks must be a few
// correlation times long for the lag-1 term to be all that is left, and still number >= 32.
inline constexpr double kReliableSamples = 64.0;

BlockAverage block_average(const std::vector<double>& samples);

// Upper tail P(X > x) of the chi-square distribution with `dof` >= 1 degrees of freedom
// (the closed forms for integer dof: Abramowitz & Stegun, Handbook of Mathematical Functions
// (1964), ch. 26).
double chi_square_upper_tail(double x, std::size_t dof);

// The same estimate for a series fed one value at a time, in O(log n) memory: each blocking
// level keeps the sums its variance and lag-1 autocovariance need (of its completed blocks, the
// pairwise means of the level below) and the block it is filling. result() equals
// block_average() of the whole series, to round-off; for the many series of a histogram (one
// per bin) averaged over samples.
class StreamingBlocks {
 public:
  void add(double x);
  std::size_t samples() const { return levels_.empty() ? 0 : levels_[0].count; }
  BlockAverage result() const;

 private:
  struct Sums {             // of one blocking level
    std::size_t count = 0;  // completed blocks
    // Of the blocks less shift_: sum, squares, products of neighbours, first and last.
    double sum = 0.0, squares = 0.0, products = 0.0, first = 0.0, last = 0.0;
    double pending = 0.0;  // a block waiting for its partner
    bool has_pending = false;
  };
  std::vector<Sums> levels_;
  double shift_ = 0.0;  // the first value: sums of deviations from it lose no digits
};

}  // namespace kairos
