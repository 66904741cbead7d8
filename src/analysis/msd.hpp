// Mean-square displacement on logarithmically spaced lags with many time origins, in memory
// that grows only with the logarithm of the run's length: a multiple-tau correlator (Ramírez,
// Sukumaran, Vorselaars and Likhtman, J. Chem. Phys. 133, 154103 (2010)) in its subsampling
// form. Level l keeps the last `points` samples taken m^l apart (every m^l-th sample, not block
// averages, so every displacement it reports is exact); a new sample at level l is paired with
// each kept one at lags j m^l, j = 1 .. points - 1 on level 0 and points / m .. points - 1
// above, so that the lags run 1, 2, ..., 7, 8, 10, 12, 14, 16, 20, ... sample intervals (m = 2,
// 8 points: four lags per octave). Every pair (sample, kept sample) is a time origin.
//
// The same correlator gives the velocity autocorrelation <v(t + lag) . v(t)> (Statistic::kProduct,
// lag 0 included) and its Green-Kubo integral.
//
// Particles are split into `groups` (species). Two error bars are kept, and the larger is
// reported: the scatter of D over kSubsets interleaved particle subsets (particle k in subset
// k mod kSubsets), and over time epochs (the origins of 8 to 16 consecutive stretches of the
// run, the stretches doubling as the run grows). The particles' scatter misses the motion all
// particles share (the box's slow shear modes carry them together); the epochs' include it.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/vec.hpp"

namespace kairos {

// The MSD follows every step-th particle that moves, so that at most `wanted` of `mobile` are
// followed (analysis.msd_particles; wanted = 0: all).
inline std::size_t msd_follow_step(std::size_t mobile, std::size_t wanted) {
  return wanted == 0 || mobile <= wanted ? 1 : (mobile + wanted - 1) / wanted;
}

template <int D>
class MsdCorrelator {
 public:
  // kDisplacement: <|x(t + lag) - x(t)|^2> of positions; kProduct: <x(t + lag) . x(t)> of
  // velocities; kFluxProduct: <J(t + lag) . J(t)> of the fluxes J of the samples x (moments,
  // integrals of J), each J the increment of x over the level's own spacing divided by it: the
  // block averages of a multiple-tau correlator, so that a noisy flux is averaged at long lags
  // rather than picked (a lag of j spacings sees the correlation smoothed over one spacing).
  enum class Statistic { kDisplacement, kProduct, kFluxProduct };
  static constexpr int kSubsets = 8;
  static constexpr int kRatio = 2;    // m: lags grow by this factor per level
  static constexpr int kPoints = 8;   // samples kept per level
  static constexpr int kEpochs = 16;  // time epochs at most (merged pairwise when full)

  // group[k]: the group (species) of followed particle k, < groups; samples `interval` apart;
  // at most max_levels levels (lags up to kPoints kRatio^(max_levels - 1) intervals).
  MsdCorrelator(std::vector<std::uint32_t> group, std::uint32_t groups, double interval,
                Statistic statistic = Statistic::kDisplacement, int max_levels = 40);

  // The next sample (the unwrapped positions of the followed particles), `interval` after the
  // previous one.
  void add(const std::vector<Vec<D>>& position);

  struct Lag {
    double lag = 0.0;                  // in time
    std::uint64_t origins = 0;         // pairs of samples averaged
    std::vector<double> mean;          // per group: <|dr|^2>, or <v(t + lag) . v(t)>
    std::vector<double> non_gaussian;  // per group: alpha_2 = D <dr^4> / ((D + 2) <dr^2>^2) - 1
    // per group and subset: the mean of the subset (for error bars)
    std::vector<std::array<double, kSubsets>> subset_mean;
    // per group and epoch: the mean over the epoch's origins (NaN: none at this lag)
    std::vector<std::array<double, kEpochs>> epoch_mean;
    // The linear terms a drift or a mean brings in, likewise: the mean of x(t + lag) - x(t)
    // (kDisplacement) or of x(t + lag) + x(t) (the products).
    std::vector<Vec<D>> mean_linear;
    std::vector<std::array<Vec<D>, kSubsets>> subset_mean_linear;
    std::vector<std::array<Vec<D>, kEpochs>> epoch_mean_linear;
  };
  // Every lag with at least one origin, in increasing order.
  std::vector<Lag> lags() const;

  // The self-diffusion coefficient of each group from the slope of <|dr|^2> = 2 D_dim D t + c
  // (least squares over the lags in [from, to]), with the standard error from the subsets'
  // slopes; nothing when fewer than 3 lags fall in the window or the group has no particle.
  struct Diffusion {
    double coefficient = 0.0;
    double stderr_ = 0.0;                              // the larger of the two below
    double particle_stderr = 0.0, epoch_stderr = 0.0;  // NaN: fewer than 2 subsets / epochs
    int lags = 0;                                      // lags in the fit
    int epochs = 0;                                    // epochs with a slope in the window
  };
  std::vector<std::optional<Diffusion>> diffusion(double from, double to) const;
  // The same about a steady drift (per group: a velocity; a collective moment that grows on
  // average, such as the time integral of the pressure): the slope of <|dx - drift lag|^2>,
  // from the mean square and the mean of the displacements at each lag. With the drift
  // measured over the sampled span T itself (drift = (x(T) - x(0)) / T), each lag's value is
  // divided by 1 - lag / T, the bias that estimate leaves in a random walk (pass span = T;
  // span = 0: a drift known exactly).
  std::vector<std::optional<Diffusion>> diffusion(double from, double to,
                                                  const std::vector<Vec<D>>& drift,
                                                  double span) const;
  // kProduct: the Green-Kubo self-diffusion coefficient (1 / D_dim) integral_0^to <v(lag) . v(0)>
  // by the trapezoid rule over the lags, with the standard error from the subsets.
  std::vector<std::optional<Diffusion>> green_kubo(double to) const;
  // The same of the fluctuations about a mean (per group; a flux with a non-zero mean such as
  // the pressure's): <(x(t + lag) - m).(x(t) - m)> = <x(t + lag).x(t)> - m.<x(t + lag) + x(t)>
  // + m.m at each lag.
  std::vector<std::optional<Diffusion>> green_kubo(double to,
                                                   const std::vector<Vec<D>>& mean) const;

  // A linear combination sum_g weight[g] mean_g of the groups' statistics (cross correlations
  // enter by sums of two moments: <(x + y)^2> - <x^2> - <y^2> = 2 <x . y>): its slope as
  // diffusion() fits one group's, and its Green-Kubo integral as green_kubo() (the products).
  // The error comes from the time epochs alone (the groups' subsets need not hold the same
  // components). Nothing when fewer than 3 lags fall in the window.
  std::optional<Diffusion> combined_diffusion(double from, double to,
                                              const std::vector<double>& weight) const;
  std::optional<Diffusion> combined_green_kubo(double to, const std::vector<double>& weight) const;

  std::uint64_t samples() const { return samples_; }
  double interval() const { return interval_; }
  std::size_t particles() const { return group_.size(); }
  std::uint64_t members(std::uint32_t group) const;  // particles in the group
  std::size_t bytes() const;

 private:
  struct Level {
    std::vector<Vec<D>> ring;  // kPoints samples of all particles: ring[slot * n + k]
    std::uint64_t kept = 0;    // samples taken into this level so far
    // Per lag index j (0 .. kPoints - 1), per group and subset: sums of |dr|^2, |dr|^4, count.
    std::vector<double> sum2, sum4;
    std::vector<double> sum1;  // kDisplacement: the displacements' D components, likewise
    std::vector<std::uint64_t> count;
    // Per lag index j and epoch e, per group: the sum of |dr|^2 (epoch_sum[(j kEpochs + e) G +
    // g]) and the origins (epoch_count[j kEpochs + e]).
    std::vector<double> epoch_sum;
    std::vector<double> epoch_sum1;  // the displacements' components: [(..) G + g] D + a
    std::vector<std::uint64_t> epoch_count;
  };
  void merge_epochs();
  std::size_t slot(std::uint32_t g, int subset) const { return g * kSubsets + subset; }
  // The first lag index of level l: 1 on level 0 (0 too for products: C(0)), above it the lags
  // the level below does not reach.
  int first_lag(int l) const {
    if (l > 0) return kPoints / kRatio;
    return statistic_ == Statistic::kDisplacement ? 1 : 0;
  }
  void correlate(Level& level, const std::vector<Vec<D>>& x, int first_j, std::size_t epoch,
                 double spacing);

  std::vector<std::uint32_t> group_;
  std::uint32_t groups_;
  double interval_;
  Statistic statistic_;
  int max_levels_;
  std::vector<std::uint64_t> group_size_;  // per (group, subset)
  std::vector<Level> levels_;
  std::uint64_t samples_ = 0;
  std::uint64_t epoch_length_ = 1;  // samples per epoch
  std::vector<Vec<D>> flux_now_;    // kFluxProduct: the current sample's fluxes (scratch)
};

// The fit window [from, to] of a correlator's slope (analysis.msd, analysis.transport and the
// Python module's): `to` as given (> 0), else `to_mean_free_times` mean free times when that is
// > 0 and the mean free time is known, else a quarter of the sampled span; `from` as given
// (> 0) or the larger of a tenth of `to` and ten mean free times (NaN: not known).
std::pair<double, double> correlation_fit_window(double sampled, double from, double to,
                                                 double mean_free_time,
                                                 double to_mean_free_times = 0.0);
// The transport coefficients' default longest lag: their Helfand moments reach their slope
// within ~10-40 mean free times up to eta = 0.4 (docs/validation.md, "Transport
// coefficients"); a window reaching further only adds noise.
inline constexpr double kTransportFitMeanFreeTimes = 40.0;

}  // namespace kairos
