#include "analysis/helfand_transport.hpp"

#include <cmath>
#include <stdexcept>

namespace kairos {

namespace {

// A mixture's groups after the three: per mass moment a, then per a the energy + a, then per
// pair a < b the sum a + b (D components each).
std::uint32_t mass_group(std::size_t a) {
  return static_cast<std::uint32_t>(3 + a);
}
std::uint32_t energy_mass_group(std::size_t moments, std::size_t a) {
  return static_cast<std::uint32_t>(3 + moments + a);
}
std::uint32_t mass_pair_group(std::size_t moments, std::size_t a, std::size_t b) {
  std::size_t before = 0;  // pairs (a', b') with a' < a
  for (std::size_t k = 0; k < a; ++k) before += moments - 1 - k;
  return static_cast<std::uint32_t>(3 + 2 * moments + before + (b - a - 1));
}

template <int D>
std::vector<std::uint32_t> component_groups(std::size_t moments) {
  using T = HelfandTransport<D>;
  std::vector<std::uint32_t> group;
  for (int k = 0; k < T::kShear; ++k) group.push_back(T::kShearGroup);
  group.push_back(T::kBulkGroup);
  const auto add = [&](std::uint32_t g) { group.insert(group.end(), D, g); };
  add(T::kHeatGroup);
  for (std::size_t a = 0; a < moments; ++a) add(mass_group(a));
  for (std::size_t a = 0; a < moments; ++a) add(energy_mass_group(moments, a));
  for (std::size_t a = 0; a < moments; ++a)
    for (std::size_t b = a + 1; b < moments; ++b) add(mass_pair_group(moments, a, b));
  return group;
}

// Solves the symmetric positive definite system A x = b (n x n, row-major) by Cholesky's
// factorisation; nothing if A is not positive definite.
std::optional<std::vector<double>> solve_positive_definite(std::vector<double> A,
                                                           std::vector<double> b) {
  const std::size_t n = b.size();
  for (std::size_t j = 0; j < n; ++j) {
    double d = A[j * n + j];
    for (std::size_t k = 0; k < j; ++k) d -= A[j * n + k] * A[j * n + k];
    if (!(d > 0.0)) return std::nullopt;
    A[j * n + j] = std::sqrt(d);
    for (std::size_t i = j + 1; i < n; ++i) {
      double v = A[i * n + j];
      for (std::size_t k = 0; k < j; ++k) v -= A[i * n + k] * A[j * n + k];
      A[i * n + j] = v / A[j * n + j];
    }
  }
  for (std::size_t i = 0; i < n; ++i) {  // L y = b
    for (std::size_t k = 0; k < i; ++k) b[i] -= A[i * n + k] * b[k];
    b[i] /= A[i * n + i];
  }
  for (std::size_t i = n; i-- > 0;) {  // L^T x = y
    for (std::size_t k = i + 1; k < n; ++k) b[i] -= A[k * n + i] * b[k];
    b[i] /= A[i * n + i];
  }
  return b;
}

}  // namespace

template <int D>
HelfandTransport<D>::HelfandTransport(double interval, std::size_t particles, double volume,
                                      std::size_t mass_moments, double mass_scale)
    : particles_(particles),
      volume_(volume),
      mass_moments_(mass_moments),
      mass_scale_(mass_scale),
      components_(component_groups<D>(mass_moments).size()),
      helfand_(component_groups<D>(mass_moments), groups(), interval),
      fluxes_(component_groups<D>(mass_moments), groups(), interval,
              Correlator::Statistic::kFluxProduct),
      sample_(components_),
      first_(components_),
      last_(components_) {}

template <int D>
std::uint32_t HelfandTransport<D>::groups() const {
  const std::size_t m = mass_moments_;  // 3, then m, m energy + mass, m (m - 1) / 2 pairs
  return static_cast<std::uint32_t>(3 + 2 * m + (m > 1 ? m * (m - 1) / 2 : 0));
}

// The estimators of the shear group, the pressure's moment (the trace over D) and the energy
// moment's components.
template <int D>
typename HelfandTransport<D>::Components HelfandTransport<D>::components(const Moments& m) const {
  const auto g = [&](int a, int b) { return m.stress[a * D + b]; };
  Components c(components_);
  int k = 0;
  for (int a = 0; a < D; ++a)
    for (int b = a + 1; b < D; ++b) c[k++] = 0.5 * (g(a, b) + g(b, a));
  for (int a = 0; a + 1 < D; ++a) c[k++] = 0.5 * (g(a, a) - g(a + 1, a + 1));
  double trace = 0.0;
  for (int a = 0; a < D; ++a) trace += g(a, a);
  c[k++] = trace / D;
  for (int a = 0; a < D; ++a) c[k++] = m.energy[a];
  if (m.mass.size() != mass_moments_)
    throw std::invalid_argument("HelfandTransport: wrong number of mass moments");
  const auto mass = [&](std::size_t i, int a) { return mass_scale_ * m.mass[i][a]; };
  for (std::size_t i = 0; i < mass_moments_; ++i)
    for (int a = 0; a < D; ++a) c[k++] = mass(i, a);
  for (std::size_t i = 0; i < mass_moments_; ++i)
    for (int a = 0; a < D; ++a) c[k++] = m.energy[a] + mass(i, a);
  for (std::size_t i = 0; i < mass_moments_; ++i)
    for (std::size_t j = i + 1; j < mass_moments_; ++j)
      for (int a = 0; a < D; ++a) c[k++] = mass(i, a) + mass(j, a);
  return c;
}

template <int D>
void HelfandTransport<D>::add(double t, const Moments& m) {
  const Components now = components(m);
  constexpr std::size_t bulk = kShear;
  if (helfand_.samples() == 0) {
    first_ = now;
    first_time_ = t;
  } else if (helfand_.samples() == 1) {
    // The pressure's moment grows as <P> V t: removing the first interval's rate keeps its
    // samples small (the rest of the drift is removed in the fits).
    pressure_offset_ = (now[bulk] - first_[bulk]) / (t - first_time_);
  }
  last_ = now;
  last_time_ = t;
  kinetic_trace_last_ = m.kinetic_trace;
  frozen_pair_time_last_ = m.frozen_pair_time;
  if (helfand_.samples() == 0) {
    kinetic_trace_first_ = kinetic_trace_last_;
    frozen_pair_time_first_ = frozen_pair_time_last_;
  }
  for (std::size_t k = 0; k < components_; ++k) sample_[k][0] = now[k] - first_[k];
  sample_[bulk][0] -= pressure_offset_ * (t - first_time_);
  helfand_.add(sample_);
  fluxes_.add(sample_);
}

template <int D>
double HelfandTransport<D>::temperature() const {
  const double span = last_time_ - first_time_;
  // A frozen pair moves as one body: D degrees of freedom fewer while it lasts.
  const double frozen_pairs =
      span > 0.0 ? (frozen_pair_time_last_ - frozen_pair_time_first_) / span : 0.0;
  const double dof =
      D * (static_cast<double>(particles_) - 1.0 -
           (frozen_pairs < static_cast<double>(particles_) - 1.0 ? frozen_pairs : 0.0));
  return span > 0.0 ? (kinetic_trace_last_ - kinetic_trace_first_) / (span * dof) : std::nan("");
}

template <int D>
double HelfandTransport<D>::pressure_drift() const {
  const double span = last_time_ - first_time_;
  return (last_[kShear] - first_[kShear]) / span - pressure_offset_;  // of the sampled moment
}

template <int D>
double HelfandTransport<D>::scale(int group) const {
  // coefficient = <dG^2> slope / 2 (one component): over V kT, or V kT^2 for the energy.
  const double kt = temperature();
  return group == kHeatGroup ? volume_ * kt * kt : volume_ * kt;
}

template <int D>
std::optional<typename HelfandTransport<D>::HeatProjection> HelfandTransport<D>::heat_projection(
    double from, double to) const {
  HeatProjection p;
  p.weight.assign(groups(), 0.0);
  p.weight[kHeatGroup] = 1.0;
  const std::size_t n = mass_moments_;
  if (n == 0) return p;
  if (helfand_.samples() < 2) return std::nullopt;
  const auto fits = helfand_.diffusion(from, to);
  for (const auto& f : fits)
    if (!f) return std::nullopt;
  const auto slope = [&](std::uint32_t g) { return fits[g]->coefficient; };
  // L_ee, L_ea and L_ab (scaled moments) from the groups' slopes: a sum's mean square less
  // its two parts' is twice the cross correlation.
  const double l_ee = slope(kHeatGroup);
  std::vector<double> l_aa(n * n), l_ae(n);
  for (std::size_t a = 0; a < n; ++a) {
    l_aa[a * n + a] = slope(mass_group(a));
    l_ae[a] = 0.5 * (slope(energy_mass_group(n, a)) - l_ee - slope(mass_group(a)));
    for (std::size_t b = a + 1; b < n; ++b) {
      l_aa[a * n + b] = l_aa[b * n + a] =
          0.5 * (slope(mass_pair_group(n, a, b)) - slope(mass_group(a)) - slope(mass_group(b)));
    }
  }
  const auto beta = solve_positive_definite(l_aa, l_ae);
  if (!beta) return std::nullopt;
  // <dG_q^2> = <dG_e^2> - 2 sum_a beta_a <dG_e dG_a> + sum_ab beta_a beta_b <dG_a dG_b>, each
  // cross term as its sum's mean square less its parts'.
  double removed = 0.0;
  for (std::size_t a = 0; a < n; ++a) {
    const double b = (*beta)[a];
    removed += b * l_ae[a];
    p.weight[energy_mass_group(n, a)] -= b;
    p.weight[kHeatGroup] += b;
    p.weight[mass_group(a)] += b + b * b;
    for (std::size_t c = a + 1; c < n; ++c) {
      const double bc = b * (*beta)[c];
      p.weight[mass_pair_group(n, a, c)] += bc;
      p.weight[mass_group(a)] -= bc;
      p.weight[mass_group(c)] -= bc;
    }
    p.beta.push_back(b * mass_scale_);
  }
  p.removed = l_ee > 0.0 ? removed / l_ee : std::nan("");
  return p;
}

template <int D>
std::vector<double> HelfandTransport<D>::heat_weight(double from, double to) const {
  const auto p = heat_projection(from, to);
  return p ? p->weight : std::vector<double>{};
}

// The heat moment's statistic from the groups' (`weight` empty: no projection, NaN).
template <int D>
double HelfandTransport<D>::heat_value(const std::vector<double>& mean,
                                       const std::vector<double>& weight) const {
  if (mass_moments_ == 0) return mean[kHeatGroup];
  if (weight.empty()) return std::nan("");
  double sum = 0.0;
  for (std::size_t g = 0; g < weight.size(); ++g)
    if (weight[g] != 0.0) sum += weight[g] * mean[g];
  return sum;
}

template <int D>
std::array<typename HelfandTransport<D>::Fit, 3> HelfandTransport<D>::einstein_helfand(
    double from, double to) const {
  std::array<Fit, 3> out;
  if (helfand_.samples() < 2) return out;
  const auto plain = helfand_.diffusion(from, to);
  const double span = last_time_ - first_time_;
  const double drift = pressure_drift();
  const auto about_drift = helfand_.diffusion(from, to, {Vec<1>{}, Vec<1>{drift}}, span);
  out[kShearGroup] = plain[kShearGroup];
  out[kBulkGroup] = about_drift[kBulkGroup];
  if (mass_moments_ == 0) {
    out[kHeatGroup] = plain[kHeatGroup];
  } else if (const auto p = heat_projection(from, to)) {
    out[kHeatGroup] = helfand_.combined_diffusion(from, to, p->weight);
  }
  return out;
}

template <int D>
std::array<typename HelfandTransport<D>::Fit, 3> HelfandTransport<D>::green_kubo(double from,
                                                                                 double to) const {
  std::array<Fit, 3> out;
  if (fluxes_.samples() < 3) return out;
  // The pressure's fluctuation: about its mean flux (sampled less the first interval's rate).
  const double mean = pressure_drift();
  const auto gk = fluxes_.green_kubo(to, {Vec<1>{}, Vec<1>{mean}});
  for (int g = 0; g < 3; ++g) out[g] = gk[g];
  if (mass_moments_ > 0) {  // the heat flux: projected as the Einstein-Helfand fit's moment
    const auto p = heat_projection(from, to);
    out[kHeatGroup] = p ? fluxes_.combined_green_kubo(to, p->weight) : std::nullopt;
  }
  return out;
}

template <int D>
std::vector<typename HelfandTransport<D>::Row> HelfandTransport<D>::helfand_rows(double from,
                                                                                 double to) const {
  std::vector<Row> rows;
  if (helfand_.samples() < 2) return rows;
  const std::vector<double> weight = heat_weight(from, to);
  const double kt = temperature();
  const double span = last_time_ - first_time_;
  const double drift = pressure_drift();
  for (const auto& lag : helfand_.lags()) {
    if (!(lag.lag < span)) continue;
    const double tau = lag.lag;
    const double bulk = (lag.mean[kBulkGroup] - 2.0 * tau * drift * lag.mean_linear[kBulkGroup][0] +
                         tau * tau * drift * drift) /
                        (1.0 - tau / span);
    const double scale = 2.0 * tau * volume_ * kt;
    Row row;
    row.lag = tau;
    row.origins = lag.origins;
    const double heat = heat_value(lag.mean, weight);
    row.value = {lag.mean[kShearGroup], bulk, heat};
    row.coefficient = {lag.mean[kShearGroup] / scale, bulk / scale, heat / (scale * kt)};
    rows.push_back(row);
  }
  return rows;
}

template <int D>
std::vector<typename HelfandTransport<D>::Row> HelfandTransport<D>::green_kubo_rows(
    double from, double to) const {
  std::vector<Row> rows;
  if (fluxes_.samples() < 2) return rows;
  const std::vector<double> weight = heat_weight(from, to);
  const double kt = temperature();
  const double drift = pressure_drift();
  const auto lags = fluxes_.lags();
  const auto about_mean = [&](const typename Correlator::Lag& lag, int g) {
    if (g == kHeatGroup) return heat_value(lag.mean, weight);
    if (g != kBulkGroup) return lag.mean[g];
    return lag.mean[g] - drift * lag.mean_linear[g][0] + drift * drift;
  };
  std::array<double, 3> integral{};
  for (std::size_t k = 0; k < lags.size(); ++k) {
    std::array<double, 3> c{};
    for (int g = 0; g < 3; ++g) c[g] = about_mean(lags[k], g);
    if (k > 0) {
      for (int g = 0; g < 3; ++g) {
        integral[g] += 0.5 * (lags[k].lag - lags[k - 1].lag) * (c[g] + about_mean(lags[k - 1], g));
      }
    }
    Row row;
    row.lag = lags[k].lag;
    row.origins = lags[k].origins;
    row.value = c;
    row.coefficient = {integral[0] / (volume_ * kt), integral[1] / (volume_ * kt),
                       integral[2] / (volume_ * kt * kt)};
    rows.push_back(row);
  }
  return rows;
}

template class HelfandTransport<2>;
template class HelfandTransport<3>;

}  // namespace kairos
