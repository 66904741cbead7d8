// sk.tsv (analysis.structure_factor): S(k) of all particles on the box's wave vectors, in
// shells of |k|, averaged over the production samples (analysis/structure.hpp
// StructureFactor), and summary.json's `analysis.structure_factor`: S at the smallest |k| and
// S(0) extrapolated, with their blocked errors. Periodic boxes without shear only.
// docs/outputs.md.
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "analysis/structure.hpp"
#include "run/outputs/analysis_output.hpp"
#include "run/outputs/structure_snapshot.hpp"

namespace kairos {

// Why S(k) cannot be measured on this system ("": it can): walls or open faces, or shear.
template <int D>
std::string structure_factor_unavailable(const Integrator<D>& integrator,
                                         const Configuration<D>& c);
// analysis.sk_max = 0: 15 / d, d the largest diameter; S(0) is fitted to k <= 2 / d.
template <int D>
double automatic_sk_max(const StructureSnapshot<D>& snapshot) {
  return 15.0 / (2.0 * snapshot.largest_radius());
}
template <int D>
double sk_fit_max(const StructureSnapshot<D>& snapshot) {
  return 2.0 / (2.0 * snapshot.largest_radius());
}

template <int D>
class StructureFactorOutput final : public AnalysisOutput<D> {
 public:
  explicit StructureFactorOutput(std::shared_ptr<StructureSnapshot<D>> snapshot)
      : snapshot_(std::move(snapshot)) {}
  static constexpr std::array<std::string_view, 1> kFiles{"sk.tsv"};
  std::string name() const override { return std::string(kFiles[0]); }
  void summarize(nlohmann::json& summary, const RunContext<D>& run) const override;

 protected:
  bool enabled(const Config& config) const override { return config.analysis.structure_factor; }
  void begin(const RunContext<D>& run) override;
  void take(const RunContext<D>& run) override { sk_->sample(snapshot_->at(run.integrator())); }
  void finish(const RunContext<D>& run) override;
  std::size_t samples() const override { return sk_ ? sk_->samples() : 0; }

 private:
  std::shared_ptr<StructureSnapshot<D>> snapshot_;
  std::optional<StructureFactor<D>> sk_;
  double k_max_ = 0.0;
};

}  // namespace kairos
