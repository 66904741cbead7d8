// helfand.tsv, green_kubo.tsv and summary.json's `transport` (analysis.transport): the
// Einstein-Helfand shear viscosity, bulk viscosity and thermal conductivity of a conservative
// periodic system from the exact Helfand moments (engine/helfand_moments.hpp plus the engine's
// virial tensor), sampled at regular simulated times during the production and correlated on
// log-spaced lags with many time origins (analysis/msd.hpp, one "particle" per moment
// component); Green-Kubo from the same samples (the autocorrelation of the fluxes, block-averaged
// over each level's spacing) as the cross-check.
// docs/physics.md#einstein-helfand-transport-coefficients.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "analysis/msd.hpp"
#include "analysis/thermodynamics.hpp"
#include "run/event_adapter.hpp"
#include "run/outputs/observer.hpp"

namespace kairos {

template <int D>
class TransportOutput final : public Observer<D> {
 public:
  // The moments' components, grouped: the shear estimators (the symmetrised off-diagonal
  // components and the normal-stress differences, all with the same autocorrelation in an
  // isotropic fluid), the pressure (one), the energy flux (D).
  static constexpr int kShear = D == 3 ? 5 : 2;
  static constexpr int kComponents = kShear + 1 + D;
  enum Group : std::uint32_t { kShearGroup = 0, kBulkGroup = 1, kHeatGroup = 2 };

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
  using Components = std::array<double, kComponents>;
  using Correlator = MsdCorrelator<1>;
  using Fit = std::optional<typename Correlator::Diffusion>;
  Components moments_now() const;
  double kinetic_trace() const;  // of the kinetic stress's moment now
  std::pair<double, double> fit_window() const;
  // The time-averaged temperature over the samples (exact: the kinetic stress's trace), per
  // degree of freedom of the motion relative to the centre of mass.
  double temperature() const;
  // The Einstein-Helfand fits of the three groups (the bulk one about the pressure's drift).
  std::array<Fit, 3> einstein_helfand() const;
  std::array<Fit, 3> green_kubo() const;
  std::string why_not_conductivity() const;

  const EventIntegrator<D>& engine_;
  AnalysisConfig config_;
  Thermodynamics stats_;
  double interval_ = 0.0;
  bool automatic_interval_ = false;
  std::vector<std::uint32_t> group_;  // per component
  std::optional<Correlator> helfand_;
  std::optional<Correlator> fluxes_;  // the same samples as fluxes (kFluxProduct)
  std::vector<Vec<1>> sample_;
  Components first_{}, last_{};
  double pressure_offset_ = 0.0;  // the pressure's moment's rate in the first interval
  double kinetic_trace_first_ = 0.0, kinetic_trace_last_ = 0.0;
  double first_time_ = 0.0, last_time_ = 0.0;
  double start_time_ = 0.0;
  std::uint64_t start_collisions_ = 0;
  std::size_t species_ = 1;
};

}  // namespace kairos
