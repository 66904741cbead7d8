// msd.tsv, vacf.tsv (analysis.vacf) and summary.json's `diffusion` (analysis.msd): the mean-square
// displacement of the unwrapped positions (engine/image_counters.hpp) on log-spaced lags with many
// time origins (analysis/msd.hpp), sampled at regular simulated times during the production, and
// each species' self-diffusion coefficient from its long-time slope (docs/outputs.md).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "analysis/msd.hpp"
#include "analysis/thermodynamics.hpp"
#include "run/event_adapter.hpp"
#include "run/outputs/observer.hpp"

namespace kairos {

template <int D>
class MsdOutput final : public Observer<D> {
 public:
  MsdOutput(const Config& config, const EventIntegrator<D>& engine);
  std::string name() const override { return "msd.tsv"; }
  std::vector<std::string> more_files() const override {
    return config_.vacf ? std::vector<std::string>{"vacf.tsv"} : std::vector<std::string>{};
  }
  bool samples_in_time() const override { return true; }
  double interval(const Config&, double) const override { return interval_; }
  void production_starts(const RunContext<D>& run) override;
  void write(const RunContext<D>& run) override;
  void close(const RunContext<D>& run, bool stopped) override;
  void summarize(nlohmann::json& summary, const RunContext<D>& run) const override;

 private:
  // The fit window: the configured one, or from ten mean free times (or a tenth of the longest
  // lag, if later) to a quarter of the sampled time.
  std::pair<double, double> fit_window() const;
  double mean_free_time() const;

  const EventIntegrator<D>& engine_;
  AnalysisConfig config_;
  Thermodynamics stats_;  // the temperature and mean free time, as thermo.tsv defines them
  double interval_ = 0.0;
  bool automatic_interval_ = false;
  std::vector<std::uint32_t> slot_;  // per particle: its place among the followed, or ~0u
  std::vector<std::uint32_t> group_;
  std::vector<std::string> species_names_;
  std::vector<Vec<D>> sample_;
  std::optional<MsdCorrelator<D>> correlator_;
  std::optional<MsdCorrelator<D>> vacf_;  // analysis.vacf
  double first_sample_ = 0.0, last_sample_ = 0.0;
  double start_time_ = 0.0;
  std::uint64_t start_collisions_ = 0;
};

}  // namespace kairos
