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
    time_start_ = engine_.time();
  }
  void production_starts(const RunContext<D>&) override {
    production_ = engine_.counters();
    production_time_ = engine_.time();
    in_production_ = true;
  }
  void summarize(nlohmann::json& summary, const RunContext<D>& run) const override;

 private:
  nlohmann::json outlet_summary(const EventCounters& c, const RunContext<D>& run) const;

  const EventIntegrator<D>& engine_;
  EventCounters start_;
  double energy_start_ = 0.0;
  double time_start_ = 0.0;
  // The counters where production started in this invocation (the outlet's rate).
  EventCounters production_;
  double production_time_ = 0.0;
  bool in_production_ = false;
};

}  // namespace kairos
