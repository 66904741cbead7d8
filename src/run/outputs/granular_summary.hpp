// summary.json's `granular` part for the event engine (runs with contact laws, walls, open
// faces, gravity, driving, shear or soft spheres): where the energy went in this invocation
// (dissipated in collisions and at walls, work of walls, driving and shear, taken out through
// an outlet) and whether the budget closes, the outlet's discharge rate, the velocity statistics,
// and what the CLI's granular lines cover. docs/outputs.md. (The DEM's energy budget:
// outputs/dem_summary.hpp.)
#pragma once

#include <string>

#include "run/event_adapter.hpp"
#include "run/outputs/observer.hpp"
#include "run/outputs/outlet_tally.hpp"

namespace kairos {

template <int D>
class GranularSummary final : public Observer<D> {
 public:
  explicit GranularSummary(const EventIntegrator<D>& engine) : engine_(engine) {}
  std::string name() const override { return "summary.json (granular)"; }
  bool writes_file() const override { return false; }
  void open(const RunContext<D>&) override {
    start_ = engine_.counters();
    energy_start_ = engine_.total_energy();
    if (const auto outlet = engine_.outlet()) outlet_.open(*outlet, engine_.time());
  }
  void production_starts(const RunContext<D>&) override {
    if (const auto outlet = engine_.outlet()) outlet_.production_starts(*outlet, engine_.time());
  }
  void summarize(nlohmann::json& summary, const RunContext<D>& run) const override;

 private:
  const EventIntegrator<D>& engine_;
  EventCounters start_;
  double energy_start_ = 0.0;
  OutletTally<D> outlet_;
};

}  // namespace kairos
