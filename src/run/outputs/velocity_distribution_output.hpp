// velocity_distribution.tsv (analysis.velocity_distribution): the distribution of one velocity
// component in units of sqrt(kT/m), each sample scaled by its own kinetic temperature,
// averaged over the production samples (analysis/structure.hpp VelocityDistribution), beside
// the Maxwellian; summary.json's `analysis.velocity_distribution`: the kurtosis, the Sonine
// coefficient a2 and the tail against the Maxwellian's, with their blocked errors.
// docs/outputs.md.
#pragma once

#include <array>
#include <string>
#include <string_view>

#include "analysis/structure.hpp"
#include "run/integrator.hpp"
#include "run/outputs/analysis_output.hpp"

namespace kairos {

// One sample of the integrator's velocities now into `distribution`: relative to their mean
// (under Lees-Edwards shear: to the flow), kT = sum m c^2 / (D N) of this sample. False (no
// sample) when the particles are at rest.
template <int D>
bool sample_velocity_distribution(const Integrator<D>& integrator,
                                  VelocityDistribution<D>& distribution);

template <int D>
class VelocityDistributionOutput final : public AnalysisOutput<D> {
 public:
  static constexpr std::array<std::string_view, 1> kFiles{"velocity_distribution.tsv"};
  std::string name() const override { return std::string(kFiles[0]); }
  void summarize(nlohmann::json& summary, const RunContext<D>& run) const override;

 protected:
  bool enabled(const Config& config) const override {
    return config.analysis.velocity_distribution;
  }
  void begin(const RunContext<D>&) override {}
  void take(const RunContext<D>& run) override;
  void finish(const RunContext<D>& run) override;
  std::size_t samples() const override { return distribution_.samples(); }

 private:
  VelocityDistribution<D> distribution_;
};

}  // namespace kairos
