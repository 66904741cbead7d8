#include "analysis/structure.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

namespace kairos {

namespace {

constexpr double kPi = std::numbers::pi;

// The volume of the shell r0 <= r < r1 in D dimensions.
template <int D>
double shell_volume(double r0, double r1) {
  if constexpr (D == 3) return 4.0 / 3.0 * kPi * (r1 * r1 * r1 - r0 * r0 * r0);
  return kPi * (r1 * r1 - r0 * r0);
}

// ∫_{r0}^{r1} r^p dr.
double power_integral(int p, double r0, double r1) {
  return (std::pow(r1, p + 1) - std::pow(r0, p + 1)) / (p + 1);
}

}  // namespace

std::size_t species_pairs(std::size_t species) {
  return species * (species + 1) / 2;
}

std::size_t species_pair_index(std::size_t a, std::size_t b, std::size_t species) {
  if (a > b) std::swap(a, b);
  return a * (2 * species - a + 1) / 2 + (b - a);
}

std::vector<double> intercept_weights(const std::vector<std::vector<double>>& design,
                                      const std::vector<double>& weights) {
  const std::size_t rows = design.size();
  const std::size_t p = rows > 0 ? design[0].size() : 0;
  if (rows < p || p == 0) throw std::invalid_argument("intercept_weights: too few points");
  // The normal equations M y = e_0, M = A^T W A; then the intercept's weights W A y.
  std::vector<std::vector<double>> m(p, std::vector<double>(p + 1, 0.0));
  for (std::size_t k = 0; k < rows; ++k)
    for (std::size_t a = 0; a < p; ++a)
      for (std::size_t b = 0; b < p; ++b) m[a][b] += weights[k] * design[k][a] * design[k][b];
  m[0][p] = 1.0;
  for (std::size_t col = 0; col < p; ++col) {  // Gauss-Jordan with partial pivoting
    std::size_t pivot = col;
    for (std::size_t r = col + 1; r < p; ++r)
      if (std::abs(m[r][col]) > std::abs(m[pivot][col])) pivot = r;
    std::swap(m[col], m[pivot]);
    if (m[col][col] == 0.0) throw std::invalid_argument("intercept_weights: singular fit");
    for (std::size_t r = 0; r < p; ++r) {
      if (r == col) continue;
      const double f = m[r][col] / m[col][col];
      for (std::size_t c = col; c <= p; ++c) m[r][c] -= f * m[col][c];
    }
  }
  std::vector<double> y(p);
  for (std::size_t a = 0; a < p; ++a) y[a] = m[a][p] / m[a][a];
  std::vector<double> w(rows, 0.0);
  for (std::size_t k = 0; k < rows; ++k) {
    for (std::size_t a = 0; a < p; ++a) w[k] += design[k][a] * y[a];
    w[k] *= weights[k];
  }
  return w;
}

// ----- g(r)

template <int D>
double box_pair_fraction(const Vec<D>& box, const std::array<bool, D>& periodic, double r0,
                         double r1) {
  // f(r) = 1 - s1 r + s2 r² - s3 r³: the orientation averages over the unit sphere (circle) of
  // |n_a|, |n_a n_b|, |n_x n_y n_z|: 1/2, 2/(3π), 1/(4π) in 3D; 2/π, 1/π in 2D.
  const double c1 = D == 3 ? 0.5 : 2.0 / kPi;
  const double c2 = D == 3 ? 2.0 / (3.0 * kPi) : 1.0 / kPi;
  const double c3 = 1.0 / (4.0 * kPi);
  std::array<double, D> inv{};
  for (int a = 0; a < D; ++a) inv[a] = periodic[a] ? 0.0 : 1.0 / box[a];
  double s1 = 0.0, s2 = 0.0, s3 = 0.0;
  for (int a = 0; a < D; ++a) {
    s1 += c1 * inv[a];
    for (int b = a + 1; b < D; ++b) s2 += c2 * inv[a] * inv[b];
  }
  if constexpr (D == 3) s3 = c3 * inv[0] * inv[1] * inv[2];
  const double base = power_integral(D - 1, r0, r1);
  return (base - s1 * power_integral(D, r0, r1) + s2 * power_integral(D + 1, r0, r1) -
          s3 * power_integral(D + 2, r0, r1)) /
         base;
}

template <int D>
std::array<double, PairCorrelation<D>::kContactBins> PairCorrelation<D>::contact_weights() {
  // In t = (r/σ - 1) / kContactWindow on [0, 1): a bin's average of t^j weighted by
  // r^(D-1) ∝ (1 + W t)^(D-1), exactly (its polynomial integrated term by term).
  const double w = kContactWindow;
  std::vector<std::vector<double>> design;
  for (int k = 0; k < kContactBins; ++k) {
    const double t0 = static_cast<double>(k) / kContactBins;
    const double t1 = static_cast<double>(k + 1) / kContactBins;
    // (1 + w t)^(D-1) = Σ_i binom(D-1, i) w^i t^i.
    std::array<double, 3> poly{1.0, 0.0, 0.0};
    if (D == 2) poly = {1.0, w, 0.0};
    if (D == 3) poly = {1.0, 2.0 * w, w * w};
    double norm = 0.0;
    for (int i = 0; i < D; ++i) norm += poly[i] * power_integral(i, t0, t1);
    std::vector<double> row(kContactDegree + 1, 0.0);
    for (int j = 0; j <= kContactDegree; ++j) {
      for (int i = 0; i < D; ++i) row[j] += poly[i] * power_integral(i + j, t0, t1);
      row[j] /= norm;
    }
    design.push_back(row);
  }
  const std::vector<double> v = intercept_weights(design, std::vector<double>(kContactBins, 1.0));
  std::array<double, kContactBins> out{};
  std::copy(v.begin(), v.end(), out.begin());
  return out;
}

template <int D>
PairCorrelation<D>::PairCorrelation(const Vec<D>& box, const std::array<bool, D>& periodic,
                                    std::vector<std::size_t> counts, double max_distance, int bins,
                                    std::vector<double> contact)
    : box_(box),
      periodic_(periodic),
      counts_(std::move(counts)),
      max_distance_(max_distance),
      bins_(bins),
      contact_(std::move(contact)) {
  const std::size_t pairs = species_pairs(counts_.size());
  if (!(max_distance_ > 0.0) || bins_ < 1 || contact_.size() != pairs)
    throw std::invalid_argument("PairCorrelation: needs a distance, bins and contact distances");
  search_ = max_distance_;
  for (const double sigma : contact_)
    if (std::isfinite(sigma)) search_ = std::max(search_, sigma * (1.0 + kContactWindow));
  for (int a = 0; a < D; ++a) {
    if (!(search_ <= 0.5 * box_[a]))
      throw std::invalid_argument("PairCorrelation: distance beyond half a box edge");
  }
  const double volume = [&] {
    double v = 1.0;
    for (int a = 0; a < D; ++a) v *= box_[a];
    return v;
  }();
  const double width = max_distance_ / bins_;
  for (int k = 0; k < bins_; ++k) {
    const double r0 = k * width, r1 = (k + 1) * width;
    ideal_.push_back(shell_volume<D>(r0, r1) * box_pair_fraction<D>(box_, periodic_, r0, r1) /
                     volume);
  }
  for (std::size_t p = 0; p < pairs; ++p) {
    for (int k = 0; k < kContactBins; ++k) {
      const double sigma = contact_[p];
      if (!std::isfinite(sigma)) {
        contact_ideal_.push_back(0.0);
        continue;
      }
      const double r0 = sigma * (1.0 + kContactWindow * k / kContactBins);
      const double r1 = sigma * (1.0 + kContactWindow * (k + 1) / kContactBins);
      contact_ideal_.push_back(shell_volume<D>(r0, r1) *
                               box_pair_fraction<D>(box_, periodic_, r0, r1) / volume);
    }
  }
  g_.resize(pairs * static_cast<std::size_t>(bins_));
  all_.resize(static_cast<std::size_t>(bins_));
  contact_value_.resize(pairs);
}

template <int D>
void PairCorrelation<D>::sample(const Configuration<D>& c) {
  const std::size_t species = counts_.size();
  const std::size_t pairs = species_pairs(species);
  const auto bins = static_cast<std::size_t>(bins_);
  std::vector<double> hist(pairs * bins, 0.0), all(bins, 0.0);
  std::vector<double> near(pairs * kContactBins, 0.0);
  std::vector<std::size_t> pair_of(species * species);
  for (std::size_t a = 0; a < species; ++a)
    for (std::size_t b = 0; b < species; ++b)
      pair_of[a * species + b] = species_pair_index(a, b, species);
  const double inverse_width = bins_ / max_distance_;
  std::size_t overlapping = 0, at_contact = 0;
  for_each_pair_within(c, search_, [&](std::uint32_t i, std::uint32_t j, const Vec<D>&, double r2) {
    const double r = std::sqrt(r2);
    const std::size_t p = pair_of[c.species[i] * species + c.species[j]];
    const double sigma = contact_[p];
    const double x = std::isfinite(sigma) ? (r / sigma - 1.0) : 1.0;
    if (std::abs(x) <= kAtContact) {  // a pair that has just collided: left out
      ++at_contact;
      return;
    }
    if (r < max_distance_) {
      const auto k = std::min(bins - 1, static_cast<std::size_t>(r * inverse_width));
      hist[p * bins + k] += 1.0;
      all[k] += 1.0;
    }
    if (x < 0.0) {
      ++overlapping;
    } else if (x < kContactWindow) {
      const auto k = std::min<std::size_t>(
          kContactBins - 1, static_cast<std::size_t>(x / kContactWindow * kContactBins));
      near[p * kContactBins + k] += 1.0;
    }
  });
  overlapping_ = overlapping;
  at_contact_ = at_contact;
  // Pairs of each species pair: N_a (N_a - 1) / 2 alike, N_a N_b unlike.
  std::vector<double> pair_count(pairs, 0.0);
  double n = 0.0;
  for (std::size_t a = 0; a < species; ++a) {
    n += static_cast<double>(counts_[a]);
    for (std::size_t b = a; b < species; ++b) {
      const auto na = static_cast<double>(counts_[a]), nb = static_cast<double>(counts_[b]);
      pair_count[species_pair_index(a, b, species)] = a == b ? 0.5 * na * (na - 1.0) : na * nb;
    }
  }
  for (std::size_t p = 0; p < pairs; ++p) {
    if (!(pair_count[p] > 0.0)) continue;
    for (std::size_t k = 0; k < bins; ++k)
      g_[p * bins + k].add(hist[p * bins + k] / (pair_count[p] * ideal_[k]));
  }
  const double all_pairs = 0.5 * n * (n - 1.0);
  if (all_pairs > 0.0)
    for (std::size_t k = 0; k < bins; ++k) all_[k].add(all[k] / (all_pairs * ideal_[k]));
  // Contact values, and Z by the contact theorem when every pair has one.
  const std::array<double, kContactBins> w = contact_weights();
  double volume = 1.0;
  for (int a = 0; a < D; ++a) volume *= box_[a];
  const double rho = n / volume;
  const double prefactor = D == 3 ? 2.0 * kPi / 3.0 : kPi / 2.0;
  double z = 1.0;
  bool complete = true;
  for (std::size_t a = 0; a < species; ++a) {
    for (std::size_t b = a; b < species; ++b) {
      const std::size_t p = species_pair_index(a, b, species);
      const double sigma = contact_[p];
      if (!std::isfinite(sigma) || !(pair_count[p] > 0.0)) {
        complete = false;
        continue;
      }
      double g0 = 0.0;
      for (int k = 0; k < kContactBins; ++k) {
        const std::size_t at = p * kContactBins + static_cast<std::size_t>(k);
        g0 += w[k] * near[at] / (pair_count[p] * contact_ideal_[at]);
      }
      contact_value_[p].add(g0);
      const double xa = static_cast<double>(counts_[a]) / n;
      const double xb = static_cast<double>(counts_[b]) / n;
      z += prefactor * rho * (a == b ? 1.0 : 2.0) * xa * xb * std::pow(sigma, D) * g0;
    }
  }
  if (complete) contact_z_.add(z);
  ++samples_;
}

// ----- S(k)

template <int D>
StructureFactor<D>::StructureFactor(const Vec<D>& box, double k_max, double fit_max)
    : box_(box), fit_max_(fit_max) {
  const double longest = *std::max_element(box_.begin(), box_.end());
  const double width = kPi / longest;
  for (int a = 0; a < D; ++a)
    n_max_[a] = static_cast<int>(std::floor(k_max * box_[a] / (2.0 * kPi)));
  // The half space: the last non-zero component positive. Enumerated twice: the vectors per
  // shell, then the ones used.
  const auto shell_of = [&](const std::array<int, D>& n) -> long {
    double k2 = 0.0;
    for (int a = 0; a < D; ++a) {
      const double k = 2.0 * kPi * n[a] / box_[a];
      k2 += k * k;
    }
    const double k = std::sqrt(k2);
    if (!(k > 0.0) || k > k_max) return -1;
    return std::lround(k / width);
  };
  const auto enumerate = [&](auto&& visit) {
    std::array<int, D> n{};
    const int top = D - 1;
    for (n[top] = 0; n[top] <= n_max_[top]; ++n[top]) {
      if constexpr (D == 3) {
        for (n[1] = n[top] == 0 ? 0 : -n_max_[1]; n[1] <= n_max_[1]; ++n[1])
          for (n[0] = n[top] == 0 && n[1] == 0 ? 1 : -n_max_[0]; n[0] <= n_max_[0]; ++n[0])
            visit(n);
      } else {
        for (n[0] = n[top] == 0 ? 1 : -n_max_[0]; n[0] <= n_max_[0]; ++n[0]) visit(n);
      }
    }
  };
  std::vector<std::size_t> available;
  enumerate([&](const std::array<int, D>& n) {
    const long s = shell_of(n);
    if (s < 0) return;
    if (static_cast<std::size_t>(s) >= available.size()) available.resize(s + 1, 0);
    ++available[s];
  });
  std::vector<std::vector<std::array<int, D>>> chosen(available.size());
  std::vector<std::size_t> seen(available.size(), 0);
  enumerate([&](const std::array<int, D>& n) {
    const long s = shell_of(n);
    if (s < 0) return;
    const std::size_t c = available[s], o = seen[s]++;
    const std::size_t cap = kMaxVectorsPerShell;
    // Exactly min(c, cap) of them, evenly spaced in the order of enumeration.
    if (c <= cap || (o + 1) * cap / c > o * cap / c) chosen[s].push_back(n);
  });
  std::vector<std::vector<double>> design;
  std::vector<double> weights;
  for (std::size_t s = 0; s < chosen.size(); ++s) {
    if (chosen[s].empty()) continue;
    shell_start_.push_back(vectors_.size());
    shell_available_.push_back(available[s]);
    double k_sum = 0.0;
    for (const auto& n : chosen[s]) {
      double k2 = 0.0;
      for (int a = 0; a < D; ++a) {
        const double k = 2.0 * kPi * n[a] / box_[a];
        k2 += k * k;
      }
      k_sum += std::sqrt(k2);
      vectors_.push_back(n);
    }
    const double k = k_sum / static_cast<double>(chosen[s].size());
    shell_k_.push_back(k);
    if (k <= fit_max_) {
      design.push_back({1.0, k * k, k * k * k * k});
      weights.push_back(static_cast<double>(chosen[s].size()));
    }
  }
  shell_start_.push_back(vectors_.size());
  s_.resize(shell_k_.size());
  if (design.size() >= 4) {
    fit_weights_ = intercept_weights(design, weights);
    fit_shells_ = design.size();
  }
}

template <int D>
void StructureFactor<D>::sample(const Configuration<D>& c) {
  const std::size_t n = c.size();
  const std::size_t nv = vectors_.size();
  if (n == 0) return;
  std::vector<double> re(nv, 0.0), im(nv, 0.0);
  constexpr std::size_t kChunk = 64;
  // Per axis the phases exp(i 2π m x / L) of the chunk's particles for -n_max <= m <= n_max, by
  // powers of exp(i 2π x / L): table[(m + n_max) * kChunk + p].
  std::array<std::vector<double>, D> t_re, t_im;
  for (int a = 0; a < D; ++a) {
    t_re[a].assign((2 * static_cast<std::size_t>(n_max_[a]) + 1) * kChunk, 0.0);
    t_im[a].assign(t_re[a].size(), 0.0);
  }
  std::array<double, kChunk> acc_re{}, acc_im{};
  for (std::size_t first = 0; first < n; first += kChunk) {
    const std::size_t m = std::min(kChunk, n - first);
    for (int a = 0; a < D; ++a) {
      const auto centre = static_cast<std::size_t>(n_max_[a]);
      for (std::size_t p = 0; p < kChunk; ++p) {
        double c1 = 0.0, s1 = 0.0, re0 = 0.0;
        if (p < m) {
          const double theta = 2.0 * kPi * c.position[first + p][a] / box_[a];
          c1 = std::cos(theta);
          s1 = std::sin(theta);
          re0 = 1.0;  // padding particles contribute nothing
        }
        double pr = re0, pi = 0.0;
        t_re[a][centre * kChunk + p] = pr;
        t_im[a][centre * kChunk + p] = pi;
        for (std::size_t q = 1; q <= centre; ++q) {
          const double nr = pr * c1 - pi * s1, ni = pr * s1 + pi * c1;
          pr = nr;
          pi = ni;
          t_re[a][(centre + q) * kChunk + p] = pr;
          t_im[a][(centre + q) * kChunk + p] = pi;
          t_re[a][(centre - q) * kChunk + p] = pr;
          t_im[a][(centre - q) * kChunk + p] = -pi;
        }
      }
    }
    for (std::size_t v = 0; v < nv; ++v) {
      const std::array<int, D>& k = vectors_[v];
      const double* r0 = &t_re[0][static_cast<std::size_t>(k[0] + n_max_[0]) * kChunk];
      const double* i0 = &t_im[0][static_cast<std::size_t>(k[0] + n_max_[0]) * kChunk];
      const double* r1 = &t_re[1][static_cast<std::size_t>(k[1] + n_max_[1]) * kChunk];
      const double* i1 = &t_im[1][static_cast<std::size_t>(k[1] + n_max_[1]) * kChunk];
      for (std::size_t p = 0; p < kChunk; ++p) {
        acc_re[p] = r0[p] * r1[p] - i0[p] * i1[p];
        acc_im[p] = r0[p] * i1[p] + i0[p] * r1[p];
      }
      if constexpr (D == 3) {
        const double* r2 = &t_re[2][static_cast<std::size_t>(k[2] + n_max_[2]) * kChunk];
        const double* i2 = &t_im[2][static_cast<std::size_t>(k[2] + n_max_[2]) * kChunk];
        for (std::size_t p = 0; p < kChunk; ++p) {
          const double ar = acc_re[p] * r2[p] - acc_im[p] * i2[p];
          const double ai = acc_re[p] * i2[p] + acc_im[p] * r2[p];
          acc_re[p] = ar;
          acc_im[p] = ai;
        }
      }
      // Four partial sums each: independent additions, not one chain of 64.
      std::array<double, 4> sr{}, si{};
      for (std::size_t p = 0; p < kChunk; p += 4) {
        for (std::size_t q = 0; q < 4; ++q) {
          sr[q] += acc_re[p + q];
          si[q] += acc_im[p + q];
        }
      }
      re[v] += (sr[0] + sr[1]) + (sr[2] + sr[3]);
      im[v] += (si[0] + si[1]) + (si[2] + si[3]);
    }
  }
  const auto count = static_cast<double>(n);
  double s0 = 0.0;
  std::size_t fit = 0;
  for (std::size_t s = 0; s + 1 < shell_start_.size(); ++s) {
    double sum = 0.0;
    for (std::size_t v = shell_start_[s]; v < shell_start_[s + 1]; ++v)
      sum += (re[v] * re[v] + im[v] * im[v]) / count;
    const double value = sum / static_cast<double>(shell_start_[s + 1] - shell_start_[s]);
    s_[s].add(value);
    if (fit < fit_shells_ && shell_k_[s] <= fit_max_) s0 += fit_weights_[fit++] * value;
  }
  if (fit_shells_ > 0) s_zero_.add(s0);
  ++samples_;
}

template <int D>
std::vector<typename StructureFactor<D>::Shell> StructureFactor<D>::shells() const {
  std::vector<Shell> out;
  for (std::size_t s = 0; s < shell_k_.size(); ++s)
    out.push_back(
        {shell_k_[s], shell_start_[s + 1] - shell_start_[s], shell_available_[s], s_[s].result()});
  return out;
}

template <int D>
double StructureFactor<D>::at(const Configuration<D>& c, const std::array<int, D>& n) {
  double re = 0.0, im = 0.0;
  for (std::size_t j = 0; j < c.size(); ++j) {
    double phase = 0.0;
    for (int a = 0; a < D; ++a) phase += 2.0 * kPi * n[a] * c.position[j][a] / c.box[a];
    re += std::cos(phase);
    im += std::sin(phase);
  }
  return (re * re + im * im) / static_cast<double>(c.size());
}

// ----- bond orientational order

namespace {

// Y_lm(unit) for m = 0 .. l into out[0 .. l].
void spherical_harmonics_into(int l, const Vec<3>& unit, std::complex<double>* out) {
  const double z = unit[2];
  const std::complex<double> u(unit[0], unit[1]);  // sin θ exp(iφ)
  std::complex<double> um(1.0, 0.0);               // u^m
  double double_factorial = 1.0;                   // (2m - 1)!!
  for (int m = 0; m <= l; ++m) {
    if (m > 0) double_factorial *= 2.0 * m - 1.0;
    // P_l^m(z) = Q_l^m(z) sin^m θ (the Condon-Shortley phase in Q_m^m), by the upward
    // recurrence in l.
    double q = (m % 2 == 0 ? 1.0 : -1.0) * double_factorial;  // Q_m^m
    if (l > m) {
      double q_before = q;
      double q_next = z * (2.0 * m + 1.0) * q;  // Q_{m+1}^m
      for (int k = m + 2; k <= l; ++k) {
        const double q_k = ((2.0 * k - 1.0) * z * q_next - (k + m - 1.0) * q_before) / (k - m);
        q_before = q_next;
        q_next = q_k;
      }
      q = q_next;
    }
    // N_lm = sqrt((2l+1)/(4π) (l-m)!/(l+m)!).
    double ratio = 1.0;
    for (int k = l - m + 1; k <= l + m; ++k) ratio /= k;
    const double norm = std::sqrt((2.0 * l + 1.0) / (4.0 * kPi) * ratio);
    out[m] = norm * q * um;
    um *= u;
  }
}

}  // namespace

std::vector<std::complex<double>> spherical_harmonics(int l, const Vec<3>& unit) {
  std::vector<std::complex<double>> out(static_cast<std::size_t>(l) + 1);
  spherical_harmonics_into(l, unit, out.data());
  return out;
}

template <int D>
BondOrderValues<D> bond_order(const Configuration<D>& c, double cutoff) {
  const std::size_t n = c.size();
  BondOrderValues<D> out;
  const auto bonded = [&](std::uint32_t i, std::uint32_t j, double r2) {
    const double reach = cutoff * (c.radius[i] + c.radius[j]);
    return r2 < reach * reach;
  };
  std::vector<std::uint32_t> neighbours(n, 0);
  const auto finish_local = [&](std::size_t channel, std::size_t i, double value) {
    out.local[channel][i] = neighbours[i] > 0 ? value : std::numeric_limits<double>::quiet_NaN();
  };
  if constexpr (D == 2) {
    out.names = {"psi6"};
    out.local.assign(1, std::vector<double>(n, 0.0));
    std::vector<std::complex<double>> psi(n);
    for_each_pair_near_contact(
        c, cutoff, [&](std::uint32_t i, std::uint32_t j, const Vec<D>& r, double r2) {
          if (!bonded(i, j, r2)) return;
          const std::complex<double> u = std::complex<double>(r[0], r[1]) / std::sqrt(r2);
          const std::complex<double> u2 = u * u;
          const std::complex<double> e6 = u2 * u2 * u2;  // exp(6iθ), the same for r and -r
          psi[i] += e6;
          psi[j] += e6;
          ++neighbours[i];
          ++neighbours[j];
          ++out.bonds;
        });
    std::complex<double> total = 0.0;
    std::size_t counted = 0;
    for (std::size_t i = 0; i < n; ++i) {
      if (neighbours[i] == 0) {
        ++out.isolated;
        finish_local(0, i, 0.0);
        continue;
      }
      const std::complex<double> local = psi[i] / static_cast<double>(neighbours[i]);
      finish_local(0, i, std::abs(local));
      total += local;
      ++counted;
    }
    out.global = {counted > 0 ? std::abs(total) / static_cast<double>(counted) : 0.0};
  } else {
    // Neighbour lists (two passes: counts, then members), then q_lm per particle.
    out.names = {"q4", "q6"};
    out.local.assign(2, std::vector<double>(n, 0.0));
    for_each_pair_near_contact(c, cutoff,
                               [&](std::uint32_t i, std::uint32_t j, const Vec<D>&, double r2) {
                                 if (!bonded(i, j, r2)) return;
                                 ++neighbours[i];
                                 ++neighbours[j];
                               });
    std::vector<std::uint32_t> start(n + 1, 0);
    for (std::size_t i = 0; i < n; ++i) start[i + 1] = start[i] + neighbours[i];
    std::vector<std::uint32_t> list(start[n]);
    {
      std::vector<std::uint32_t> next(start.begin(), start.end() - 1);
      for_each_pair_near_contact(c, cutoff,
                                 [&](std::uint32_t i, std::uint32_t j, const Vec<D>&, double r2) {
                                   if (!bonded(i, j, r2)) return;
                                   list[next[i]++] = j;
                                   list[next[j]++] = i;
                                 });
    }
    out.bonds = start[n] / 2;
    constexpr std::array<int, 2> kL = {4, 6};
    std::array<std::vector<std::complex<double>>, 2> global;
    for (std::size_t ch = 0; ch < 2; ++ch) global[ch].assign(kL[ch] + 1, 0.0);
    std::array<std::vector<std::complex<double>>, 2> local;
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t ch = 0; ch < 2; ++ch) local[ch].assign(kL[ch] + 1, 0.0);
      for (std::uint32_t k = start[i]; k < start[i + 1]; ++k) {
        const std::uint32_t j = list[k];
        Vec<3> r{};
        double r2 = 0.0;
        for (int a = 0; a < D; ++a) {
          double d = c.position[j][a] - c.position[i][a];
          if (c.periodic[a]) d = minimum_image(d, c.box[a]);
          r[a] = d;
          r2 += d * d;
        }
        const double inverse = 1.0 / std::sqrt(r2);
        for (int a = 0; a < 3; ++a) r[a] *= inverse;
        for (std::size_t ch = 0; ch < 2; ++ch) {
          std::array<std::complex<double>, 7> y;
          spherical_harmonics_into(kL[ch], r, y.data());
          for (std::size_t m = 0; m < local[ch].size(); ++m) local[ch][m] += y[m];
        }
      }
      if (neighbours[i] == 0) ++out.isolated;
      for (std::size_t ch = 0; ch < 2; ++ch) {
        // Σ_m |q_lm|² = |q_l0|² + 2 Σ_{m>0} |q_lm|² (|q_l,-m| = |q_lm|).
        double sum = 0.0;
        for (std::size_t m = 0; m < local[ch].size(); ++m) {
          sum += (m == 0 ? 1.0 : 2.0) * std::norm(local[ch][m]);
          global[ch][m] += local[ch][m];
        }
        const double nb = static_cast<double>(std::max<std::uint32_t>(neighbours[i], 1));
        finish_local(ch, i, std::sqrt(4.0 * kPi / (2.0 * kL[ch] + 1.0) * sum) / nb);
      }
    }
    const double all = static_cast<double>(std::max<std::uint32_t>(start[n], 1));
    for (std::size_t ch = 0; ch < 2; ++ch) {
      double sum = 0.0;
      for (std::size_t m = 0; m < global[ch].size(); ++m)
        sum += (m == 0 ? 1.0 : 2.0) * std::norm(global[ch][m]);
      out.global.push_back(std::sqrt(4.0 * kPi / (2.0 * kL[ch] + 1.0) * sum) / all);
    }
  }
  return out;
}

template <int D>
void BondOrder<D>::sample(const Configuration<D>& c) {
  last_ = bond_order<D>(c, cutoff_);
  if (names_.empty()) {
    names_ = last_.names;
    global_.resize(names_.size());
    local_mean_.resize(names_.size());
    histogram_.assign(names_.size(), std::vector<double>(kBins, 0.0));
  }
  if (c.size() > 0)
    neighbours_ += 2.0 * static_cast<double>(last_.bonds) / static_cast<double>(c.size());
  ++samples_;
  if (last_.bonds == 0) return;
  for (std::size_t ch = 0; ch < names_.size(); ++ch) {
    global_[ch].add(last_.global[ch]);
    double sum = 0.0, counted = 0.0;
    for (const double v : last_.local[ch]) {
      if (std::isnan(v)) continue;
      sum += v;
      counted += 1.0;
      const int bin = std::clamp(static_cast<int>(v * kBins), 0, kBins - 1);
      histogram_[ch][bin] += 1.0;
    }
    local_mean_[ch].add(sum / counted);
  }
}

template <int D>
double BondOrder<D>::density(std::size_t channel, int bin) const {
  double total = 0.0;
  for (const double h : histogram_[channel]) total += h;
  return total > 0.0 ? histogram_[channel][bin] * kBins / total : 0.0;
}

template <int D>
double BondOrder<D>::mean_neighbours() const {
  return samples_ > 0 ? neighbours_ / static_cast<double>(samples_) : 0.0;
}

// ----- velocity distribution

template <int D>
void VelocityDistribution<D>::begin(double kT) {
  scale_ = 1.0 / kT;
  for (auto& axis : counts_) axis.assign(kBins, 0.0);
  n_ = w2_ = w4_ = v2_ = v4_ = tail_count_ = 0.0;
  if (pooled_.empty()) {
    pooled_.resize(kBins);
    for (auto& axis : axis_) axis.resize(kBins);
  }
}

template <int D>
void VelocityDistribution<D>::add(const Vec<D>& c, double mass) {
  const double f = std::sqrt(mass * scale_);
  double v2 = 0.0;
  for (int a = 0; a < D; ++a) {
    const double w = c[a] * f;
    const double w2 = w * w;
    v2 += w2;
    w2_ += w2;
    w4_ += w2 * w2;
    const double x = (w + kRange) * (kBins / (2.0 * kRange));
    if (x >= 0.0 && x < kBins) {
      counts_[a][static_cast<std::size_t>(x)] += 1.0;
    } else {
      outside_ += 1.0;
    }
    if (std::abs(w) > kTail) tail_count_ += 1.0;
  }
  v2_ += v2;
  v4_ += v2 * v2;
  n_ += 1.0;
}

template <int D>
void VelocityDistribution<D>::end() {
  if (!(n_ > 0.0)) return;
  const double width = 2.0 * kRange / kBins;
  const double components = D * n_;
  for (int k = 0; k < kBins; ++k) {
    double pooled = 0.0;
    for (int a = 0; a < D; ++a) {
      pooled += counts_[a][k];
      axis_[a][k].add(counts_[a][k] / (n_ * width));
    }
    pooled_[k].add(pooled / (components * width));
  }
  const double m2 = w2_ / components, m4 = w4_ / components;
  if (m2 > 0.0) kurtosis_.add(m4 / (m2 * m2));
  const double p2 = v2_ / n_, p4 = v4_ / n_;
  if (p2 > 0.0) a2_.add(D / (D + 2.0) * p4 / (p2 * p2) - 1.0);
  tail_.add(tail_count_ / components / std::erfc(kTail / std::numbers::sqrt2));
  values_ += components;
  ++samples_;
}

template <int D>
BlockAverage VelocityDistribution<D>::density(int bin, int axis) const {
  if (pooled_.empty()) return {};
  return axis < 0 ? pooled_[bin].result() : axis_[axis][bin].result();
}

template <int D>
double VelocityDistribution<D>::maxwellian(int bin) const {
  const double lo = bin_low(bin), hi = bin_low(bin + 1);
  return 0.5 * (std::erf(hi / std::numbers::sqrt2) - std::erf(lo / std::numbers::sqrt2)) /
         (hi - lo);
}

template <int D>
double VelocityDistribution<D>::outside() const {
  return values_ > 0.0 ? outside_ / values_ : 0.0;
}

template double box_pair_fraction<2>(const Vec<2>&, const std::array<bool, 2>&, double, double);
template double box_pair_fraction<3>(const Vec<3>&, const std::array<bool, 3>&, double, double);
template class PairCorrelation<2>;
template class PairCorrelation<3>;
template class StructureFactor<2>;
template class StructureFactor<3>;
template BondOrderValues<2> bond_order<2>(const Configuration<2>&, double);
template BondOrderValues<3> bond_order<3>(const Configuration<3>&, double);
template class BondOrder<2>;
template class BondOrder<3>;
template class VelocityDistribution<2>;
template class VelocityDistribution<3>;

}  // namespace kairos
