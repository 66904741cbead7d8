#include "run/outputs/event_summary.hpp"

#include <cmath>

namespace kairos {

template <int D>
void EventSummary<D>::open(const RunContext<D>&) {
  collisions_start_ = engine_.counters().collisions;
  kinetic_start_ = engine_.kinetic_energy();
  potential_start_ = engine_.potential_energy();
}

template <int D>
void EventSummary<D>::summarize(nlohmann::json& j, const RunContext<D>&) const {
  const EventCounters& c = engine_.counters();
  j["event_queue"] = engine_.queue_name();
  j["event_counts"] = {
      {"collisions", c.collisions - collisions_start_},
      {"cell_crossings", c.cell_crossings},
      {"incremental_crossings_this_invocation", engine_.incremental_crossing_scans()},
      {"stale", c.stale_events},
      {"total_events_since_start", c.events},
      {"total_collisions_since_start", c.collisions}};
  // Kinetic plus stepped-potential energy against the starting kinetic energy.
  j["energy_drift_relative"] =
      kinetic_start_ > 0 ? std::abs(engine_.kinetic_energy() + engine_.potential_energy() -
                                    (kinetic_start_ + potential_start_)) /
                               kinetic_start_
                         : 0.0;
  j["bytes_per_particle"] = engine_.bytes_per_particle();
  j["cell_levels"] = engine_.two_level_cells() ? 2 : 1;
}

template class EventSummary<2>;
template class EventSummary<3>;

}  // namespace kairos
