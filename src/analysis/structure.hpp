// Structure of a configuration of particles, averaged over samples (docs/physics.md#structure):
//
//   PairCorrelation       g(r) per species pair (Allen & Tildesley, Computer Simulation of
//                         Liquids, 2nd ed. (2017), §2.6 and chapter 8), with the contact values
//                         g(σ⁺) and the compressibility factor they give by the contact theorem
//   StructureFactor       S(k) = <|Σ_j exp(-i k·r_j)|²> / N on the box's wave vectors,
//                         averaged over shells of |k| (Allen & Tildesley §2.6)
//   BondOrder             Steinhardt's q4, q6 (3D; Steinhardt, Nelson & Ronchetti, Phys. Rev. B
//                         28, 784 (1983)) or ψ6 (2D; Halperin & Nelson, Phys. Rev. Lett. 41, 121
//                         (1978); Nelson & Halperin, Phys. Rev. B 19, 2457 (1979)), local and
//                         global
//   VelocityDistribution  one velocity component in units of sqrt(kT/m): histogram, kurtosis,
//                         Sonine a2, the tail against the Maxwellian
//
// Pure functions and accumulators with no run dependency: a sample is a Configuration
// (analysis/neighbour_pairs.hpp) or a stream of velocities; every averaged value carries its
// standard error by Flyvbjerg-Petersen blocking over the samples (analysis/block_average.hpp),
// and the values derived from a sample (contact values, the contact Z, S(0), Q6) are linear
// or computed per sample, so that blocking applies to them as to the histograms.
#pragma once

#include <array>
#include <complex>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "analysis/block_average.hpp"
#include "analysis/neighbour_pairs.hpp"
#include "core/vec.hpp"

namespace kairos {

// Unordered species pairs: (0,0), (0,1), ..., (0,S-1), (1,1), ..., (S-1,S-1).
std::size_t species_pairs(std::size_t species);
std::size_t species_pair_index(std::size_t a, std::size_t b, std::size_t species);

// The weights w_k of the intercept of a weighted least-squares fit: for a design matrix
// `design` (one row per point: the basis functions there) and point weights `weights`, the fit's
// value of the first coefficient is sum_k w_k y_k (linear in the data y).
std::vector<double> intercept_weights(const std::vector<std::vector<double>>& design,
                                      const std::vector<double>& weights);

// ----- g(r)

// The fraction of the ideal-gas pairs a finite box keeps in the shell r0 <= r < r1: the mean
// over the shell (weighted by r^(D-1)) of prod over bounded axes a of (1 - |u_a| / L_a), the
// set covariance of a box (an ideal gas uniform in [0, L_a) has that many fewer pairs at
// separation u than an unbounded one). 1 for a fully periodic box; valid for r1 <= the shortest
// bounded edge.
template <int D>
double box_pair_fraction(const Vec<D>& box, const std::array<bool, D>& periodic, double r0,
                         double r1);

template <int D>
class PairCorrelation {
 public:
  // The contact value g(σ⁺) is extrapolated from a histogram of its own: kContactBins bins over
  // σ <= r < σ (1 + kContactWindow), fitted by a cubic in r (the bins' averages of the cubic
  // matched exactly, weighted by r^(D-1)); its value at σ is a fixed linear combination of the
  // bins. For g ∝ exp(-α (r - σ)) the bias is below 2e-4 relative for α <= 8 (hard spheres at
  // η = 0.45 have α ≈ 7).
  static constexpr double kContactWindow = 0.1;
  static constexpr int kContactBins = 10;
  static constexpr int kContactDegree = 3;

  // `counts[a]`: the particles of species a (fixed over the samples); bins of width
  // max_distance / bins over [0, max_distance]; `contact[p]`: the contact distance of species
  // pair p (species_pair_index), or NaN where it has none (no contact value). std::invalid_
  // argument if max_distance (or a contact window) exceeds half a periodic edge or a bounded
  // edge.
  PairCorrelation(const Vec<D>& box, const std::array<bool, D>& periodic,
                  std::vector<std::size_t> counts, double max_distance, int bins,
                  std::vector<double> contact);

  void sample(const Configuration<D>& c);

  std::size_t samples() const { return samples_; }
  std::size_t species() const { return counts_.size(); }
  int bins() const { return bins_; }
  double max_distance() const { return max_distance_; }
  double bin_width() const { return max_distance_ / bins_; }
  // g of species pair p in bin k (shell k Δr <= r < (k + 1) Δr), averaged over the samples.
  BlockAverage g(std::size_t pair, int bin) const { return g_[pair * bins_ + bin].result(); }
  // Every pair whatever its species (the same as g(0, bin) for one species).
  BlockAverage g_all(int bin) const { return all_[bin].result(); }
  double contact_distance(std::size_t pair) const { return contact_[pair]; }
  // g(σ⁺) of pair p (samples = 0 where it has no contact distance).
  BlockAverage contact(std::size_t pair) const { return contact_value_[pair].result(); }
  // The contact theorem (hard spheres and disks; Hansen & McDonald, Theory of Simple Liquids,
  // 4th ed. (2013)): Z = 1 + (2π/3) ρ Σ_ab x_a x_b σ_ab³ g_ab(σ⁺) in 3D,
  // 1 + (π/2) ρ Σ_ab x_a x_b σ_ab² g_ab(σ⁺) in 2D (ordered pairs; 4η g(σ⁺) and 2η g(σ⁺) for one
  // species). samples = 0 unless every pair has a contact distance.
  BlockAverage contact_compressibility() const { return contact_z_.result(); }
  // A pair within kAtContact (relative) of its contact distance is left out of every histogram:
  // an event-driven state sampled when a collision count is reached (at a thermo row) holds the
  // pair whose collision reached it exactly at contact, which a state at a random time never
  // does (probability ~1e-9 per pair near contact). Counted in, it adds one pair per sample to
  // the first contact bin: a bias of w_0 / (pairs in that bin), 1 % for 1000 spheres at η = 0.35.
  static constexpr double kAtContact = 1e-9;
  // In the last sample: pairs closer than their contact distance (overlaps; 0 for hard
  // spheres), and pairs left out at contact.
  std::size_t overlapping() const { return overlapping_; }
  std::size_t at_contact() const { return at_contact_; }
  // The weights of the contact extrapolation: g(σ⁺) = Σ_k w_k g_k over the contact bins.
  static std::array<double, kContactBins> contact_weights();

 private:
  Vec<D> box_;
  std::array<bool, D> periodic_;
  std::vector<std::size_t> counts_;
  double max_distance_;
  int bins_;
  std::vector<double> contact_;
  double search_ = 0.0;  // the pair search's cut-off
  std::size_t samples_ = 0, overlapping_ = 0, at_contact_ = 0;
  // Ideal-gas pairs per bin (the box's pair fraction included) per unit pair count.
  std::vector<double> ideal_, contact_ideal_;
  std::vector<StreamingBlocks> g_, all_, contact_value_;
  StreamingBlocks contact_z_;
};

// ----- S(k)

template <int D>
class StructureFactor {
 public:
  // Wave vectors per shell at most: shells beyond hold more, of which every so many in the
  // order of enumeration are used (the cost of a sample is N times the vectors used).
  static constexpr std::size_t kMaxVectorsPerShell = 32;

  // A periodic box (std::invalid_argument otherwise). Shells of width π / L_max (half the
  // spacing of the wave vectors along the longest edge: the smallest |k| = 2π / L of a cubic
  // box is a shell of its own) up to |k| <= k_max; k and -k give the same S, so one of each.
  // `fit_max`: S(0) is extrapolated from the shells with k <= fit_max.
  StructureFactor(const Vec<D>& box, double k_max, double fit_max);

  void sample(const Configuration<D>& c);

  struct Shell {
    double k = 0.0;           // mean |k| of the vectors used
    std::size_t vectors = 0;  // used (of `available`)
    std::size_t available = 0;
    BlockAverage s;
  };
  std::vector<Shell> shells() const;
  std::size_t samples() const { return samples_; }
  // The intercept of S(k) = a + b k² + c k⁴ fitted (each shell weighted by its vectors) to the
  // shells with k <= fit_max; samples = 0 with fewer than 4 such shells.
  BlockAverage s_zero() const { return s_zero_.result(); }
  std::size_t fit_shells() const { return fit_shells_; }
  double fit_max() const { return fit_max_; }

  // S at the one wave vector k = 2π (n_1 / L_1, ..., n_D / L_D) (any box: along bounded axes
  // the same formula).
  static double at(const Configuration<D>& c, const std::array<int, D>& n);

 private:
  Vec<D> box_;
  double fit_max_;
  std::array<int, D> n_max_{};
  std::vector<std::array<int, D>> vectors_;  // used, shell by shell
  std::vector<std::size_t> shell_start_, shell_available_;
  std::vector<double> shell_k_;
  std::vector<double> fit_weights_;  // per shell with k <= fit_max: S(0) = Σ w_s S_s
  std::size_t fit_shells_ = 0, samples_ = 0;
  std::vector<StreamingBlocks> s_;
  StreamingBlocks s_zero_;
};

// ----- bond orientational order

// Y_lm(direction) for m = 0 .. l (m < 0 follows from Y_l,-m = (-1)^m conj(Y_lm)), with the
// Condon-Shortley phase; `unit` of length 1.
std::vector<std::complex<double>> spherical_harmonics(int l, const Vec<3>& unit);

// The bond order of one configuration. Neighbours: pairs closer than cutoff (R_i + R_j).
//   3D: q_lm(i) = (1 / N_b(i)) Σ_j Y_lm(r̂_ij), q_l(i) = sqrt(4π/(2l+1) Σ_m |q_lm(i)|²), and
//       the global Q_l from Q_lm = Σ_i Σ_j Y_lm(r̂_ij) / Σ_i N_b(i) (over all bonds; Steinhardt
//       et al. 1983).
//   2D: ψ6(i) = (1 / N_b(i)) Σ_j exp(6 i θ_ij); local |ψ6(i)|, global |Σ_i ψ6(i)| / N
//       (Halperin & Nelson 1978).
// Particles without neighbours have NaN local values and count in neither global value.
template <int D>
struct BondOrderValues {
  std::vector<std::string> names;          // 3D: q4, q6; 2D: psi6
  std::vector<std::vector<double>> local;  // [channel][particle]
  std::vector<double> global;              // [channel]
  std::size_t bonds = 0, isolated = 0;     // neighbour pairs; particles with none
};
template <int D>
BondOrderValues<D> bond_order(const Configuration<D>& c, double cutoff);

template <int D>
class BondOrder {
 public:
  static constexpr int kBins = 100;  // the local values' histogram over [0, 1]
  explicit BondOrder(double cutoff) : cutoff_(cutoff) {}

  void sample(const Configuration<D>& c);

  const std::vector<std::string>& names() const { return names_; }
  std::size_t samples() const { return samples_; }
  double cutoff() const { return cutoff_; }
  // Per channel: the global value, the mean local value, and the histogram of the local values
  // (a probability density over [0, 1], pooled over the samples).
  BlockAverage global(std::size_t channel) const { return global_[channel].result(); }
  BlockAverage local_mean(std::size_t channel) const { return local_mean_[channel].result(); }
  double density(std::size_t channel, int bin) const;
  // Neighbours per particle, averaged over the samples.
  double mean_neighbours() const;
  const BondOrderValues<D>& last() const { return last_; }

 private:
  double cutoff_;
  std::vector<std::string> names_;
  std::size_t samples_ = 0;
  double neighbours_ = 0.0;
  std::vector<StreamingBlocks> global_, local_mean_;
  std::vector<std::vector<double>> histogram_;  // counts
  BondOrderValues<D> last_;
};

// ----- velocity distribution

// One sample: begin(kT), add(c, m) for every particle (c its velocity relative to the mean, or
// to the flow), end(). Each component w = c_a sqrt(m / kT) is one value of the distribution
// (pooled over the D axes, and per axis).
template <int D>
class VelocityDistribution {
 public:
  static constexpr double kRange = 8.0;  // the histogram covers -8 <= w < 8
  static constexpr int kBins = 160;
  static constexpr double kTail = 3.0;  // tail_ratio: |w| > 3

  void begin(double kT);
  void add(const Vec<D>& c, double mass);
  void end();

  std::size_t samples() const { return samples_; }
  double bin_low(int bin) const { return -kRange + bin * (2.0 * kRange / kBins); }
  // The probability density in a bin: pooled over the axes (axis = -1) or of one axis.
  BlockAverage density(int bin, int axis = -1) const;
  // The unit Gaussian's mean density over the bin (the Maxwellian).
  double maxwellian(int bin) const;
  // <w⁴> / <w²>² of the components (3 for a Maxwellian; 3 (1 + a2) for an isotropic one).
  BlockAverage kurtosis() const { return kurtosis_.result(); }
  // a2 = D/(D+2) <|w|⁴> / <|w|²>² - 1 of the whole velocities (Sonine coefficient; 0 for a
  // Maxwellian).
  BlockAverage sonine_a2() const { return a2_.result(); }
  // The fraction of components with |w| > kTail over the Maxwellian's, erfc(kTail / sqrt 2).
  BlockAverage tail_ratio() const { return tail_.result(); }
  // Components beyond the histogram's range, per component (pooled over the samples).
  double outside() const;

 private:
  double scale_ = 1.0;  // 1 / kT of the sample being added
  std::size_t samples_ = 0;
  double values_ = 0.0, outside_ = 0.0;
  // The sample being added.
  std::array<std::vector<double>, D> counts_;
  double n_ = 0.0, w2_ = 0.0, w4_ = 0.0, v2_ = 0.0, v4_ = 0.0, tail_count_ = 0.0;
  std::vector<StreamingBlocks> pooled_;
  std::array<std::vector<StreamingBlocks>, D> axis_;
  StreamingBlocks kurtosis_, a2_, tail_;
};

}  // namespace kairos
