// summary.json's `stepped` part (event engine with [[potential]] or [[bond]]): the
// configurational energy over the production thermo rows (blocked for its error) and how the
// pair events split between the hard cores and the steps. docs/outputs.md.
#pragma once

#include <string>
#include <vector>

#include "run/event_adapter.hpp"
#include "run/outputs/observer.hpp"

namespace kairos {

template <int D>
class SteppedSummary final : public Observer<D> {
 public:
  explicit SteppedSummary(const EventIntegrator<D>& engine) : engine_(engine) {}
  std::string name() const override { return "summary.json (stepped)"; }
  bool writes_file() const override { return false; }
  void open(const RunContext<D>&) override { start_ = engine_.counters(); }
  void sample(const RunContext<D>&) override {
    potential_rows_.push_back(engine_.potential_energy());
  }
  void summarize(nlohmann::json& summary, const RunContext<D>& run) const override;

 private:
  const EventIntegrator<D>& engine_;
  EventCounters start_;
  std::vector<double> potential_rows_;  // U at each production thermo row
};

}  // namespace kairos
