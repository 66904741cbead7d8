// summary.json's granular.outlet for either integrator (docs/outputs.md): the outlet's passes
// in this invocation and their rate over its simulated time, the discharge rate of a
// recirculating silo (the count per unit time, and the mass), and the steady rate over
// production alone when production started in this invocation.
#pragma once

#include <nlohmann/json.hpp>

#include "run/integrator.hpp"

namespace kairos {

template <int D>
class OutletTally {
 public:
  using Reading = typename Integrator<D>::OutletReading;

  void open(const Reading& r, double t) {
    start_ = r;
    time_start_ = t;
  }
  void production_starts(const Reading& r, double t) {
    production_ = r;
    production_time_ = t;
    in_production_ = true;
  }
  nlohmann::json summary(const Reading& now, double t) const {
    nlohmann::json o;
    const auto passes = now.passes - start_.passes;
    const double mass = now.mass - start_.mass;
    const double span = t - time_start_;
    o["passes"] = passes;
    o["mass"] = mass;
    o["energy_taken"] = now.energy - start_.energy;
    o["time"] = span;
    o["rate"] = span > 0.0 ? static_cast<double>(passes) / span : 0.0;
    o["mass_rate"] = span > 0.0 ? mass / span : 0.0;
    o["total_passes_since_start"] = now.passes;
    // The DEM's particles beyond the plane still touching something: many, or the same ones
    // for long, mean the outlet lies in the bed, not where the grains fall free.
    if (now.waiting >= 0) o["waiting_now"] = now.waiting;
    const double production_span = t - production_time_;
    if (in_production_ && production_span > 0.0) {
      o["production_rate"] = static_cast<double>(now.passes - production_.passes) / production_span;
      o["production_mass_rate"] = (now.mass - production_.mass) / production_span;
    }
    return o;
  }

 private:
  Reading start_, production_;
  double time_start_ = 0.0, production_time_ = 0.0;
  bool in_production_ = false;
};

}  // namespace kairos
