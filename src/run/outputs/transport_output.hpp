// helfand.tsv, green_kubo.tsv and summary.json's `transport` (analysis.transport): the
// Einstein-Helfand shear viscosity, bulk viscosity and thermal conductivity of a conservative
// periodic system from the exact Helfand moments (engine/helfand_moments.hpp plus the engine's
// virial tensor), sampled at regular simulated times during the production and correlated on
// log-spaced lags with many time origins (analysis/helfand_transport.hpp); Green-Kubo from the
// same samples as the cross-check. docs/physics.md#einstein-helfand-transport-coefficients.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "analysis/helfand_transport.hpp"
#include "analysis/thermodynamics.hpp"
#include "run/event_adapter.hpp"
#include "run/outputs/observer.hpp"

namespace kairos {

// The Helfand moments of an event engine now (it keeps them: EngineOptions::track_helfand), as
// HelfandTransport samples them.
template <int D>
typename HelfandTransport<D>::Moments helfand_sample(const EventIntegrator<D>& engine);

template <int D>
class TransportOutput final : public Observer<D> {
 public:
  TransportOutput(const Config& config, const EventIntegrator<D>& engine);
  std::string name() const override { return "helfand.tsv"; }
  std::vector<std::string> more_files() const override { return {"green_kubo.tsv"}; }
  bool samples_in_time() const override { return true; }
  double interval(const Config&, double) const override { return interval_; }
  void production_starts(const RunContext<D>& run) override;
  void write(const RunContext<D>& run) override;
  void close(const RunContext<D>& run, bool stopped) override;
  void summarize(nlohmann::json& summary, const RunContext<D>& run) const override;

 private:
  using Transport = HelfandTransport<D>;
  using Fit = typename Transport::Fit;
  std::pair<double, double> fit_window() const;
  std::string why_not_conductivity() const;

  const EventIntegrator<D>& engine_;
  AnalysisConfig config_;
  Thermodynamics stats_;
  double interval_ = 0.0;
  bool automatic_interval_ = false;
  std::optional<Transport> transport_;
  double start_time_ = 0.0;
  std::uint64_t start_collisions_ = 0;
  std::size_t species_ = 1;
};

}  // namespace kairos
