#include "run/outputs/msd_output.hpp"

#include <cmath>
#include <string>

#include <fmt/format.h>

#include "analysis/granular_theory.hpp"
#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "run/outputs/sampling_interval.hpp"

namespace kairos {

template <int D>
MsdOutput<D>::MsdOutput(const Config& config, const EventIntegrator<D>& engine)
    : engine_(engine), config_(config.analysis), stats_(D, engine.size(), engine.volume()) {
  const std::size_t n = engine.size();
  const auto wanted = static_cast<std::size_t>(config_.msd_particles);
  const std::size_t step = n <= wanted ? 1 : (n + wanted - 1) / wanted;
  slot_.assign(n, ~0u);  // not followed
  const StateBlocks<D> state = engine.state_blocks();
  species_names_ = state.globals().species_names;
  state.for_each(
      [&](const ParticleSystem<D>& part, std::size_t first) {
        for (std::size_t j = 0; j < part.size(); ++j) {
          const std::size_t id = first + j;
          if (id % step != 0) continue;
          slot_[id] = static_cast<std::uint32_t>(group_.size());
          group_.push_back(part.species.empty() ? 0u : part.species[j]);
        }
      },
      StateBlocks<D>::kKinematics | StateBlocks<D>::kIdentity);
  if (species_names_.empty()) species_names_ = {"A"};
  sample_.resize(group_.size());
  interval_ = config_.msd_interval;
  if (interval_ == 0.0) {
    automatic_interval_ = true;
    interval_ = half_enskog_mean_free_time(engine, "analysis.msd_interval");
  }
}

template <int D>
void MsdOutput<D>::production_starts(const RunContext<D>&) {
  const auto groups = static_cast<std::uint32_t>(species_names_.size());
  correlator_.emplace(group_, groups, interval_);
  if (config_.vacf) vacf_.emplace(group_, groups, interval_, MsdCorrelator<D>::Statistic::kProduct);
  start_time_ = engine_.time();
  start_collisions_ = engine_.collisions();
}

template <int D>
void MsdOutput<D>::write(const RunContext<D>& run) {
  if (run.phase() != "production") return;
  if (!correlator_) production_starts(run);  // continued in its production
  engine_.unwrapped_positions(slot_, sample_);
  if (correlator_->samples() == 0) first_sample_ = engine_.time();
  last_sample_ = engine_.time();
  correlator_->add(sample_);
  if (vacf_) {
    engine_.velocities(slot_, sample_);
    vacf_->add(sample_);
  }
}

template <int D>
double MsdOutput<D>::mean_free_time() const {
  return stats_.mean_free_time(engine_.time() - start_time_,
                               engine_.collisions() - start_collisions_);
}

template <int D>
std::pair<double, double> MsdOutput<D>::fit_window() const {
  return correlation_fit_window(last_sample_ - first_sample_, config_.msd_fit_from,
                                config_.msd_fit_to, mean_free_time());
}

template <int D>
void MsdOutput<D>::close(const RunContext<D>& run, bool) {
  if (!correlator_ || correlator_->samples() < 2) return;
  std::string text = "lag\torigins";
  for (const std::string& s : species_names_) text += fmt::format("\tmsd_{0}\tnon_gaussian_{0}", s);
  text += "\n";
  for (const auto& lag : correlator_->lags()) {
    text += fmt::format("{:.10g}\t{}", lag.lag, lag.origins);
    for (std::size_t g = 0; g < species_names_.size(); ++g)
      text += fmt::format("\t{:.10g}\t{:.6g}", lag.mean[g], lag.non_gaussian[g]);
    text += "\n";
  }
  write_text_atomically(run.directory() / name(), text);
  if (!vacf_) return;
  // The velocity autocorrelation and its running Green-Kubo integral (1/d) int_0^lag.
  text = "lag\torigins";
  for (const std::string& s : species_names_) text += fmt::format("\tvacf_{0}\tintegral_{0}", s);
  text += "\n";
  const auto lags = vacf_->lags();
  std::vector<double> integral(species_names_.size(), 0.0);
  for (std::size_t k = 0; k < lags.size(); ++k) {
    text += fmt::format("{:.10g}\t{}", lags[k].lag, lags[k].origins);
    for (std::size_t g = 0; g < species_names_.size(); ++g) {
      if (k > 0) {
        integral[g] +=
            0.5 * (lags[k].lag - lags[k - 1].lag) * (lags[k].mean[g] + lags[k - 1].mean[g]) / D;
      }
      text += fmt::format("\t{:.10g}\t{:.10g}", lags[k].mean[g], integral[g]);
    }
    text += "\n";
  }
  write_text_atomically(run.directory() / "vacf.tsv", text);
}

template <int D>
void MsdOutput<D>::summarize(nlohmann::json& summary, const RunContext<D>&) const {
  nlohmann::json d;
  d["interval"] = interval_;
  d["interval_automatic"] = automatic_interval_;
  d["particles_followed"] = group_.size();
  d["samples"] = correlator_ ? correlator_->samples() : 0;
  d["memory_bytes"] = (correlator_ ? correlator_->bytes() : 0) + (vacf_ ? vacf_->bytes() : 0);
  d["sampled_from"] = first_sample_;
  d["sampled_to"] = last_sample_;
  const double mft = mean_free_time();
  d["mean_free_time"] = std::isfinite(mft) ? nlohmann::json(mft) : nlohmann::json(nullptr);
  const auto [from, to] = fit_window();
  d["fit_from"] = from;
  d["fit_to"] = to;
  nlohmann::json species = nlohmann::json::object();
  const auto gk =
      vacf_
          ? vacf_->green_kubo(to)
          : std::vector<std::optional<typename MsdCorrelator<D>::Diffusion>>(species_names_.size());
  const auto fits =
      correlator_
          ? correlator_->diffusion(from, to)
          : std::vector<std::optional<typename MsdCorrelator<D>::Diffusion>>(species_names_.size());
  // The Yeh-Hummer correction's viscosity: the one given, or the one analysis.transport
  // measured in this run (its part of the summary comes first).
  double viscosity = config_.msd_viscosity;
  if (viscosity == 0.0 && summary.contains("transport")) {
    const nlohmann::json& eta = summary["transport"]["shear_viscosity"]["value"];
    if (eta.is_number()) viscosity = eta.get<double>();
  }
  for (std::size_t g = 0; g < species_names_.size(); ++g) {
    nlohmann::json s;
    if (g < fits.size() && fits[g]) {
      s["coefficient"] = fits[g]->coefficient;
      s["coefficient_stderr"] =
          std::isfinite(fits[g]->stderr_) ? nlohmann::json(fits[g]->stderr_) : nullptr;
      s["lags_fitted"] = fits[g]->lags;
      const auto finite = [](double x) { return std::isfinite(x) ? nlohmann::json(x) : nullptr; };
      s["coefficient_stderr_particles"] = finite(fits[g]->particle_stderr);
      s["coefficient_stderr_epochs"] = finite(fits[g]->epoch_stderr);
      s["epochs_fitted"] = fits[g]->epochs;
      // Runs hold few independent windows of the fit's longest lag: the error bars of the
      // subsets and epochs then miss the scatter between runs (docs/validation.md found up to
      // 3x with the automatic window, fit_to = a quarter of the run).
      s["coefficient_stderr_reliable"] = last_sample_ - first_sample_ >= 20.0 * to;
    } else {
      s["coefficient"] = nullptr;
      s["why"] = fmt::format(
          "fewer than 3 lags in the fit window [{:.4g}, {:.4g}]: the production is too short "
          "for the diffusive regime (or set analysis.msd_fit_from / msd_fit_to)",
          from, to);
    }
    if (fits.size() > g && fits[g] && viscosity > 0.0) {
      // Yeh and Hummer, J. Phys. Chem. B 108, 15873 (2004): a cubic periodic box in 3D.
      const Vec<D>& box = engine_.box();
      bool cubic = D == 3;
      for (int a = 1; a < D; ++a) cubic = cubic && box[a] == box[0];
      if (cubic) {
        constexpr double kXi = 2.837297;
        const double kt = stats_.temperature(engine_.thermal_energy());
        s["coefficient_infinite_size"] =
            fits[g]->coefficient + kXi * kt / (6.0 * M_PI * viscosity * box[0]);
        s["infinite_size_temperature"] = kt;
        s["infinite_size_viscosity"] = viscosity;
      } else {
        s["coefficient_infinite_size"] = nullptr;
        s["infinite_size_why"] = "the Yeh-Hummer correction is for a cubic periodic box in 3D";
      }
    }
    if (g < gk.size() && gk[g]) {
      s["green_kubo_coefficient"] = gk[g]->coefficient;
      s["green_kubo_coefficient_stderr"] =
          std::isfinite(gk[g]->stderr_) ? nlohmann::json(gk[g]->stderr_) : nullptr;
    }
    species[species_names_[g]] = s;
  }
  d["species"] = species;
  summary["diffusion"] = d;
}

template class MsdOutput<2>;
template class MsdOutput<3>;

}  // namespace kairos
