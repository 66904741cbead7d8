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
#include <string_view>
#include <vector>

#include "analysis/helfand_transport.hpp"
#include "analysis/thermodynamics.hpp"
#include "run/event_adapter.hpp"
#include "run/outputs/observer.hpp"

namespace kairos {

// A mixture's mass moments G_a = sum_{i in a} m_i x_i - (M_a / M) sum_i m_i x_i of every
// component present but the last (a component: the particles of one species and one mass),
// from the engine's unwrapped positions (it keeps image counters for analysis.transport on a
// mixture): what the thermal conductivity needs to remove the energy interdiffusion carries
// (analysis/helfand_transport.hpp).
template <int D>
class MassMoments {
 public:
  static constexpr std::size_t kMaxComponents = 16;
  explicit MassMoments(const EventIntegrator<D>& engine);
  std::size_t count() const { return fraction_.size(); }
  // Moment k's component: its species' name, with its mass when the species has several.
  const std::string& name(std::size_t moment) const { return names_[moment]; }
  // Why there are no moments for a system of several components ("": none needed, or kept).
  const std::string& why() const { return why_; }
  // kT / m now (sum m c^2 / (D M)): HelfandTransport's scale of the moments.
  double scale() const { return scale_; }
  void sample(const EventIntegrator<D>& engine, std::vector<Vec<D>>& out);

 private:
  std::vector<std::uint32_t> moment_of_;  // per particle: its species' moment, or ~0u (last)
  std::vector<double> mass_;
  std::vector<double> fraction_;    // per moment: M_a / M
  std::vector<std::string> names_;  // per moment: its component
  std::string why_;
  std::vector<std::uint32_t> every_slot_;
  std::vector<Vec<D>> position_;
  double scale_ = 1.0;
};

// summary.json's and the Python module's words for a mixture's heat moment.
inline constexpr const char* kMassMomentFrame =
    "mass moments relative to the centre of mass; the last component's is minus the sum";
inline constexpr const char* kNotPositiveDefinite =
    "the mass moments' correlations are not positive definite over the fit window: the "
    "production is too short for a mixture's heat flux";

// The Helfand moments of an event engine now (it keeps them: EngineOptions::track_helfand), as
// HelfandTransport samples them; a mixture's mass moments from `mass` (nullptr: one species).
template <int D>
typename HelfandTransport<D>::Moments helfand_sample(const EventIntegrator<D>& engine,
                                                     MassMoments<D>* mass = nullptr);

template <int D>
class TransportOutput final : public Observer<D> {
 public:
  TransportOutput(const Config& config, const EventIntegrator<D>& engine);
  // The Einstein-Helfand moments and the Green-Kubo flux autocorrelations.
  static constexpr std::string_view kHelfandFile = "helfand.tsv";
  static constexpr std::string_view kGreenKuboFile = "green_kubo.tsv";
  static constexpr std::array<std::string_view, 2> kFiles{kHelfandFile, kGreenKuboFile};
  std::string name() const override { return std::string(kHelfandFile); }
  std::vector<std::string> more_files() const override { return {std::string(kGreenKuboFile)}; }
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
  nlohmann::json interdiffusion(double from, double to) const;

  const EventIntegrator<D>& engine_;
  AnalysisConfig config_;
  Thermodynamics stats_;
  double interval_ = 0.0;
  bool automatic_interval_ = false;
  std::optional<Transport> transport_;
  double start_time_ = 0.0;
  std::uint64_t start_collisions_ = 0;
  std::optional<MassMoments<D>> mass_;  // mixtures
};

}  // namespace kairos
