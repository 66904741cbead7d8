#include "analysis/helfand_transport.hpp"

#include <cmath>

namespace kairos {

namespace {

template <int D>
std::vector<std::uint32_t> component_groups() {
  using T = HelfandTransport<D>;
  std::vector<std::uint32_t> group;
  for (int k = 0; k < T::kComponents; ++k) {
    group.push_back(k < T::kShear    ? T::kShearGroup
                    : k == T::kShear ? T::kBulkGroup
                                     : T::kHeatGroup);
  }
  return group;
}

}  // namespace

template <int D>
HelfandTransport<D>::HelfandTransport(double interval, std::size_t particles, double volume)
    : particles_(particles),
      volume_(volume),
      helfand_(component_groups<D>(), 3u, interval),
      fluxes_(component_groups<D>(), 3u, interval, Correlator::Statistic::kFluxProduct),
      sample_(kComponents) {}

// The estimators of the shear group, the pressure's moment (the trace over D) and the energy
// moment's components.
template <int D>
typename HelfandTransport<D>::Components HelfandTransport<D>::components(const Moments& m) {
  const auto g = [&](int a, int b) { return m.stress[a * D + b]; };
  Components c{};
  int k = 0;
  for (int a = 0; a < D; ++a)
    for (int b = a + 1; b < D; ++b) c[k++] = 0.5 * (g(a, b) + g(b, a));
  for (int a = 0; a + 1 < D; ++a) c[k++] = 0.5 * (g(a, a) - g(a + 1, a + 1));
  double trace = 0.0;
  for (int a = 0; a < D; ++a) trace += g(a, a);
  c[k++] = trace / D;
  for (int a = 0; a < D; ++a) c[k++] = m.energy[a];
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
  for (int k = 0; k < kComponents; ++k) sample_[k][0] = now[k] - first_[k];
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
std::string HelfandTransport<D>::why_no_conductivity(std::size_t species) {
  if (species > 1) {
    return "a mixture: the heat flux needs the enthalpy carried by interdiffusion removed "
           "(not measured yet)";
  }
  return "";
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
  out[kHeatGroup] = plain[kHeatGroup];
  return out;
}

template <int D>
std::array<typename HelfandTransport<D>::Fit, 3> HelfandTransport<D>::green_kubo(double to) const {
  std::array<Fit, 3> out;
  if (fluxes_.samples() < 3) return out;
  // The pressure's fluctuation: about its mean flux (sampled less the first interval's rate).
  const double mean = pressure_drift();
  const auto gk = fluxes_.green_kubo(to, {Vec<1>{}, Vec<1>{mean}});
  for (int g = 0; g < 3; ++g) out[g] = gk[g];
  return out;
}

template <int D>
std::vector<typename HelfandTransport<D>::Row> HelfandTransport<D>::helfand_rows() const {
  std::vector<Row> rows;
  if (helfand_.samples() < 2) return rows;
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
    row.value = {lag.mean[kShearGroup], bulk, lag.mean[kHeatGroup]};
    row.coefficient = {lag.mean[kShearGroup] / scale, bulk / scale,
                       lag.mean[kHeatGroup] / (scale * kt)};
    rows.push_back(row);
  }
  return rows;
}

template <int D>
std::vector<typename HelfandTransport<D>::Row> HelfandTransport<D>::green_kubo_rows() const {
  std::vector<Row> rows;
  if (fluxes_.samples() < 2) return rows;
  const double kt = temperature();
  const double drift = pressure_drift();
  const auto lags = fluxes_.lags();
  const auto about_mean = [&](const typename Correlator::Lag& lag, int g) {
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
