// summary.json's description of the run, alike for both integrators: what ran (version,
// dimension, particles, packing fraction, integrator, run id, restart), how it stopped, and two
// checks of the final state (momentum drift, max overlap). docs/outputs.md has every key.
#pragma once

#include <array>
#include <string>
#include <string_view>

#include "run/output_directory.hpp"
#include "run/outputs/observer.hpp"

namespace kairos {

template <int D>
class RunSummary final : public Observer<D> {
 public:
  // summary.json, which the run driver writes from every observer's summarize().
  static constexpr std::array<std::string_view, 1> kFiles{kSummaryFileName};
  std::string name() const override { return std::string(kFiles[0]); }
  bool writes_file() const override { return false; }
  void open(const RunContext<D>& run) override { momentum_start_ = run.integrator().momentum(); }
  void summarize(nlohmann::json& summary, const RunContext<D>& run) const override;

 private:
  Vec<D> momentum_start_{};
};

}  // namespace kairos
