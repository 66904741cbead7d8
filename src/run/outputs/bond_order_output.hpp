// bond_order.tsv (analysis.bond_order): the distribution of the local bond orientational order
// (Steinhardt's q4 and q6 in 3D, |ψ6| in 2D) over the particles and production samples
// (analysis/structure.hpp BondOrder), and summary.json's `analysis.bond_order`: the global and
// mean local values with their blocked errors. docs/outputs.md.
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

// InputError (naming `key`) unless neighbours up to `cutoff` contact distances of the largest
// particles stay within half of every periodic edge.
template <int D>
void check_bond_cutoff(double cutoff, const StructureSnapshot<D>& snapshot,
                       const Configuration<D>& c, const std::string& key);

template <int D>
class BondOrderOutput final : public AnalysisOutput<D> {
 public:
  explicit BondOrderOutput(std::shared_ptr<StructureSnapshot<D>> snapshot)
      : snapshot_(std::move(snapshot)) {}
  static constexpr std::array<std::string_view, 1> kFiles{"bond_order.tsv"};
  std::string name() const override { return std::string(kFiles[0]); }
  void summarize(nlohmann::json& summary, const RunContext<D>& run) const override;

 protected:
  bool enabled(const Config& config) const override { return config.analysis.bond_order; }
  void begin(const RunContext<D>& run) override;
  void take(const RunContext<D>& run) override { order_->sample(snapshot_->at(run.integrator())); }
  void finish(const RunContext<D>& run) override;
  std::size_t samples() const override { return order_ ? order_->samples() : 0; }

 private:
  std::shared_ptr<StructureSnapshot<D>> snapshot_;
  std::optional<BondOrder<D>> order_;
};

}  // namespace kairos
