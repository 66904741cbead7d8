#include "run/outputs/stepped_summary.hpp"

#include "analysis/block_average.hpp"

namespace kairos {

template <int D>
void SteppedSummary<D>::summarize(nlohmann::json& j, const RunContext<D>&) const {
  const EventCounters& c = engine_.counters();
  const BlockAverage u = block_average(potential_rows_);
  const auto n = static_cast<double>(engine_.size());
  const std::uint64_t steps =
      (c.step_crossings - start_.step_crossings) + (c.step_bounces - start_.step_bounces);
  nlohmann::json s;
  s["potential_energy"] = engine_.potential_energy();
  s["potential_energy_per_particle_mean"] = u.mean / n;
  s["potential_energy_per_particle_stderr"] = u.stderr_ / n;
  s["potential_energy_per_particle_stderr_blocks"] = u.blocks;
  s["potential_energy_per_particle_stderr_reliable"] = u.reliable;
  s["potential_energy_rows"] = potential_rows_.size();
  s["total_energy"] = engine_.kinetic_energy() + engine_.potential_energy();
  s["step_crossings"] = c.step_crossings - start_.step_crossings;
  s["step_bounces"] = c.step_bounces - start_.step_bounces;
  s["core_collisions"] = (c.collisions - start_.collisions) - steps;
  j["stepped"] = s;
}

template class SteppedSummary<2>;
template class SteppedSummary<3>;

}  // namespace kairos
