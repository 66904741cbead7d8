#include "run/outputs/transport_output.hpp"

#include <cmath>
#include <string>

#include <fmt/format.h>

#include "io/atomic_file.hpp"
#include "run/outputs/sampling_interval.hpp"

namespace kairos {

namespace {

nlohmann::json finite_or_null(double x) {
  return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr);
}

}  // namespace

template <int D>
TransportOutput<D>::TransportOutput(const Config& config, const EventIntegrator<D>& engine)
    : engine_(engine), config_(config.analysis), stats_(D, engine.size(), engine.volume()) {
  for (int k = 0; k < kComponents; ++k) {
    group_.push_back(k < kShear ? kShearGroup : k == kShear ? kBulkGroup : kHeatGroup);
  }
  sample_.resize(kComponents);
  species_ = std::max<std::size_t>(1, engine.state_blocks().globals().species_names.size());
  interval_ = config_.transport_interval;
  if (interval_ == 0.0) {
    automatic_interval_ = true;
    interval_ = half_enskog_mean_free_time(engine, "analysis.transport_interval");
  }
}

// G_ab = kinetic + collisional (the virial tensor), the energy moment likewise; the estimators
// of the shear group, the pressure's moment (the trace over D) and the energy moment's
// components.
template <int D>
typename TransportOutput<D>::Components TransportOutput<D>::moments_now() const {
  const typename HelfandMoments<D>::Moments m = engine_.helfand_moments();
  const std::array<double, 9>& virial = engine_.counters().virial_tensor;
  const auto g = [&](int a, int b) { return m.kinetic_stress[a * D + b] + virial[a * D + b]; };
  Components c{};
  int k = 0;
  for (int a = 0; a < D; ++a)
    for (int b = a + 1; b < D; ++b) c[k++] = 0.5 * (g(a, b) + g(b, a));
  for (int a = 0; a + 1 < D; ++a) c[k++] = 0.5 * (g(a, a) - g(a + 1, a + 1));
  double trace = 0.0;
  for (int a = 0; a < D; ++a) trace += g(a, a);
  c[k++] = trace / D;
  for (int a = 0; a < D; ++a) c[k++] = m.kinetic_energy_flux[a] + m.collisional_energy_flux[a];
  return c;
}

template <int D>
void TransportOutput<D>::production_starts(const RunContext<D>&) {
  helfand_.emplace(group_, 3u, interval_);
  fluxes_.emplace(group_, 3u, interval_, Correlator::Statistic::kFluxProduct);
  start_time_ = engine_.time();
  start_collisions_ = engine_.collisions();
}

template <int D>
void TransportOutput<D>::write(const RunContext<D>& run) {
  if (run.phase() != "production") return;
  if (!helfand_) production_starts(run);  // continued in its production
  const Components now = moments_now();
  const double t = engine_.time();
  const std::size_t bulk = kShear;
  if (helfand_->samples() == 0) {
    first_ = now;
    first_time_ = t;
  } else if (helfand_->samples() == 1) {
    // The pressure's moment grows as <P> V t: removing the first interval's rate keeps its
    // samples small (the rest of the drift is removed in the fits).
    pressure_offset_ = (now[bulk] - first_[bulk]) / (t - first_time_);
  }
  last_ = now;
  last_time_ = t;
  kinetic_trace_last_ = kinetic_trace();
  if (helfand_->samples() == 0) kinetic_trace_first_ = kinetic_trace_last_;
  for (int k = 0; k < kComponents; ++k) sample_[k][0] = now[k] - first_[k];
  sample_[bulk][0] -= pressure_offset_ * (t - first_time_);
  helfand_->add(sample_);
  fluxes_->add(sample_);
}

template <int D>
double TransportOutput<D>::kinetic_trace() const {
  const typename HelfandMoments<D>::Moments m = engine_.helfand_moments();
  double trace = 0.0;
  for (int a = 0; a < D; ++a) trace += m.kinetic_stress[a * D + a];
  return trace;
}

template <int D>
double TransportOutput<D>::temperature() const {
  const double span = last_time_ - first_time_;
  const double dof = D * (static_cast<double>(engine_.size()) - 1.0);
  return span > 0.0 ? (kinetic_trace_last_ - kinetic_trace_first_) / (span * dof) : std::nan("");
}

template <int D>
std::pair<double, double> TransportOutput<D>::fit_window() const {
  const double sampled = last_time_ - first_time_;
  const double to = config_.transport_fit_to > 0.0 ? config_.transport_fit_to : 0.25 * sampled;
  double from = config_.transport_fit_from;
  if (from == 0.0) {
    const double mft = stats_.mean_free_time(engine_.time() - start_time_,
                                             engine_.collisions() - start_collisions_);
    from = std::max(0.1 * to, std::isfinite(mft) ? 10.0 * mft : 0.0);
  }
  return {from, to};
}

// The drift of the pressure's moment left after the first interval's rate was removed: its
// mean rate over the samples.
template <int D>
std::array<typename TransportOutput<D>::Fit, 3> TransportOutput<D>::einstein_helfand() const {
  std::array<Fit, 3> out;
  if (!helfand_ || helfand_->samples() < 2) return out;
  const auto [from, to] = fit_window();
  const auto plain = helfand_->diffusion(from, to);
  const double span = last_time_ - first_time_;
  const double drift =
      (last_[kShear] - first_[kShear]) / span - pressure_offset_;  // of the sampled moment
  const auto about_drift = helfand_->diffusion(from, to, {Vec<1>{}, Vec<1>{drift}}, span);
  out[kShearGroup] = plain[kShearGroup];
  out[kBulkGroup] = about_drift[kBulkGroup];
  out[kHeatGroup] = plain[kHeatGroup];
  return out;
}

template <int D>
std::array<typename TransportOutput<D>::Fit, 3> TransportOutput<D>::green_kubo() const {
  std::array<Fit, 3> out;
  if (!fluxes_ || fluxes_->samples() < 3) return out;
  const double to = fit_window().second;
  // The pressure's fluctuation: about its mean flux (sampled less the first interval's rate).
  const double span = last_time_ - first_time_;
  const double mean = (last_[kShear] - first_[kShear]) / span - pressure_offset_;
  const auto gk = fluxes_->green_kubo(to, {Vec<1>{}, Vec<1>{mean}});
  for (int g = 0; g < 3; ++g) out[g] = gk[g];
  return out;
}

template <int D>
std::string TransportOutput<D>::why_not_conductivity() const {
  if (species_ > 1) {
    return "a mixture: the heat flux needs the enthalpy carried by interdiffusion removed "
           "(not measured yet)";
  }
  return "";
}

template <int D>
void TransportOutput<D>::close(const RunContext<D>& run, bool) {
  if (!helfand_ || helfand_->samples() < 2) return;
  const double volume = engine_.volume();
  const double kt = temperature();
  const double span = last_time_ - first_time_;
  const double drift = (last_[kShear] - first_[kShear]) / span - pressure_offset_;
  // Per lag: the mean-square moment (the pressure's about its drift, over 1 - lag / span) and
  // the running coefficient <dG^2> / (2 lag V kT) (kT^2 for the conductivity), whose plateau is
  // the Einstein-Helfand value.
  std::string text =
      "lag\torigins\tshear_moment\tbulk_moment\theat_moment\tshear_viscosity\tbulk_viscosity\t"
      "thermal_conductivity\n";
  for (const auto& lag : helfand_->lags()) {
    if (!(lag.lag < span)) continue;
    const double tau = lag.lag;
    const double bulk = (lag.mean[kBulkGroup] - 2.0 * tau * drift * lag.mean_linear[kBulkGroup][0] +
                         tau * tau * drift * drift) /
                        (1.0 - tau / span);
    const double scale = 2.0 * tau * volume * kt;
    text += fmt::format("{:.10g}\t{}\t{:.10g}\t{:.10g}\t{:.10g}\t{:.10g}\t{:.10g}\t{:.10g}\n", tau,
                        lag.origins, lag.mean[kShearGroup], bulk, lag.mean[kHeatGroup],
                        lag.mean[kShearGroup] / scale, bulk / scale,
                        lag.mean[kHeatGroup] / (scale * kt));
  }
  write_text_atomically(run.directory() / name(), text);
  if (!fluxes_ || fluxes_->samples() < 2) return;
  // The flux autocorrelations (the pressure's about its mean) and their running integrals.
  text =
      "lag\torigins\tshear_flux_acf\tbulk_flux_acf\theat_flux_acf\tshear_viscosity\t"
      "bulk_viscosity\tthermal_conductivity\n";
  const auto lags = fluxes_->lags();
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
    text += fmt::format("{:.10g}\t{}\t{:.10g}\t{:.10g}\t{:.10g}\t{:.10g}\t{:.10g}\t{:.10g}\n",
                        lags[k].lag, lags[k].origins, c[0], c[1], c[2], integral[0] / (volume * kt),
                        integral[1] / (volume * kt), integral[2] / (volume * kt * kt));
  }
  write_text_atomically(run.directory() / "green_kubo.tsv", text);
}

template <int D>
void TransportOutput<D>::summarize(nlohmann::json& summary, const RunContext<D>&) const {
  nlohmann::json j;
  j["interval"] = interval_;
  j["interval_automatic"] = automatic_interval_;
  j["samples"] = helfand_ ? helfand_->samples() : 0;
  j["memory_bytes"] = (helfand_ ? helfand_->bytes() : 0) + (fluxes_ ? fluxes_->bytes() : 0);
  j["sampled_from"] = first_time_;
  j["sampled_to"] = last_time_;
  const double kt = temperature();
  const double volume = engine_.volume();
  j["temperature"] = finite_or_null(kt);
  j["volume"] = volume;
  const auto [from, to] = fit_window();
  j["fit_from"] = from;
  j["fit_to"] = to;
  const bool reliable = last_time_ - first_time_ >= 20.0 * to;
  const std::array<Fit, 3> eh = einstein_helfand();
  const std::array<Fit, 3> gk = green_kubo();
  const char* names[3] = {"shear_viscosity", "bulk_viscosity", "thermal_conductivity"};
  for (int g = 0; g < 3; ++g) {
    // coefficient = <dG^2> slope / 2 (one component): over V kT, or V kT^2 for the energy.
    const double scale = g == kHeatGroup ? volume * kt * kt : volume * kt;
    nlohmann::json c;
    const std::string why = g == kHeatGroup ? why_not_conductivity() : "";
    if (!why.empty()) {
      c["value"] = nullptr;
      c["why"] = why;
    } else if (eh[g]) {
      c["value"] = eh[g]->coefficient / scale;
      c["stderr"] = finite_or_null(eh[g]->stderr_ / scale);
      c["stderr_epochs"] = finite_or_null(eh[g]->epoch_stderr / scale);
      c["stderr_components"] = finite_or_null(eh[g]->particle_stderr / scale);
      c["epochs_fitted"] = eh[g]->epochs;
      c["lags_fitted"] = eh[g]->lags;
      // As the MSD's: few independent windows of the longest lag make the bars too small.
      c["stderr_reliable"] = reliable;
    } else {
      c["value"] = nullptr;
      c["why"] = fmt::format(
          "fewer than 3 lags in the fit window [{:.4g}, {:.4g}]: the production is too short "
          "(or set analysis.transport_fit_from / transport_fit_to)",
          from, to);
    }
    if (why.empty() && gk[g]) {
      c["green_kubo"] = gk[g]->coefficient / scale;
      c["green_kubo_stderr"] = finite_or_null(gk[g]->stderr_ / scale);
    }
    j[names[g]] = c;
  }
  summary["transport"] = j;
}

template class TransportOutput<2>;
template class TransportOutput<3>;

}  // namespace kairos
