// summary.json's `stepped` part (event engine with [[potential]] or [[bond]]): the
// configurational energy over the production thermo rows (blocked for its error) and how the
// pair events split between the hard cores and the steps. docs/outputs.md.
#pragma once

#include <string>
#include <vector>

#include "run/event_adapter.hpp"
#include "run/outputs/observer.hpp"
#include "run/outputs/thermo_output.hpp"

namespace kairos {

template <int D>
class SteppedSummary final : public Observer<D> {
 public:
  SteppedSummary(const EventIntegrator<D>& engine, const ThermoOutput<D>& thermo)
      : engine_(engine), thermo_(thermo) {}
  std::string name() const override { return "summary.json (stepped)"; }
  bool writes_file() const override { return false; }
  // A continued production: the earlier invocations' rows, from thermo.tsv's potential_energy.
  void open(const RunContext<D>&) override {
    start_ = engine_.counters();
    if (const auto* rows = thermo_.earlier_production_column("potential_energy"))
      potential_rows_ = *rows;
  }
  void sample(const RunContext<D>&) override {
    potential_rows_.push_back(engine_.potential_energy());
  }
  void summarize(nlohmann::json& summary, const RunContext<D>& run) const override;

 private:
  const EventIntegrator<D>& engine_;
  const ThermoOutput<D>& thermo_;
  EventCounters start_;
  std::vector<double> potential_rows_;  // U at each production thermo row
};

}  // namespace kairos
