// How long a run's phases last: equilibration, then production, each in collisions per
// particle (c = 2 N_coll / N) or in simulated time (run.time, run.equilibration_time), and what
// a run continued from a restart file has left of them.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>

#include <fmt/format.h>

#include "core/error.hpp"
#include "io/config.hpp"
#include "io/config_choices.hpp"
#include "run/restart_plan.hpp"
#include "run/run_progress.hpp"

namespace kairos {

// A phase's length: collisions per particle, or simulated time.
struct PhaseLength {
  double value = 0.0;
  bool in_time = false;
  // A phase in time resumed from a restart file: its end as recorded (value is then what was
  // left), so that it ends where the interrupted run would have, bit for bit.
  double end = std::numeric_limits<double>::quiet_NaN();
  // The same for a phase in collisions: the collision count it ends at (0: value from now).
  std::uint64_t target = 0;
};

// The equilibration a restart file leaves to do, in the unit it was started in (its recorded end
// time says: time); a config that gives it in the other unit is refused.
inline PhaseLength resumed_equilibration(const RunConfig& r, const RunProgress& resumed,
                                         const std::string& restart_file) {
  const bool in_time = std::isfinite(resumed.equilibration_end_time);
  const bool config_in_time = r.equilibration_time >= 0.0;
  if (resumed.equilibration_remaining > 0.0 && in_time != config_in_time) {
    throw InputError(fmt::format(
        "restart file '{}' has an unfinished equilibration measured in {}, but the config gives "
        "run.{}: continue it with the same unit",
        restart_file, in_time ? "simulated time" : "collisions per particle",
        config_in_time ? "equilibration_time" : "equilibration_collisions_per_particle"));
  }
  return {resumed.equilibration_remaining, in_time, resumed.equilibration_end_time};
}

// Whether the output intervals are in simulated time (the reader resolves the unit; a config
// built in code may leave it "", the production length's unit).
inline bool intervals_in_time(const Config& c) {
  if (c.output.interval_unit.empty()) return c.run.time > 0.0;
  return interval_units().at(c.output.interval_unit) == IntervalUnit::kTime;
}

inline PhaseLength production_length(const RunConfig& r) {
  return r.time > 0.0 ? PhaseLength{r.time, true} : PhaseLength{r.collisions_per_particle, false};
}
inline PhaseLength equilibration_length(const RunConfig& r) {
  return r.equilibration_time >= 0.0 ? PhaseLength{r.equilibration_time, true}
                                     : PhaseLength{r.equilibration_collisions_per_particle, false};
}

// Whether the run-length keys changed at a restart (then a new length counts from now).
inline bool length_given_anew(const std::optional<RestartPlan>& plan) {
  if (!plan) return false;
  for (const std::string& k : plan->resumed)
    if (k == "run.collisions_per_particle" || k == "run.time") return true;
  return false;
}

// The production of a continued run: an unfinished one (the restart file records its end) is
// completed, as one uninterrupted run would be, unless the config gives the length anew; a
// finished one is extended by the config's length.
inline PhaseLength continued_production(const RunConfig& r, const RunProgress& resumed,
                                        const std::optional<RestartPlan>& plan, double now,
                                        std::uint64_t collisions) {
  PhaseLength length = production_length(r);
  if (length_given_anew(plan)) return length;
  if (length.in_time && std::isfinite(resumed.production_end_time)) {
    length.end = resumed.production_end_time;
    length.value = std::max(0.0, length.end - now);
  } else if (!length.in_time && resumed.production_target > collisions) {
    length.target = resumed.production_target;
  }
  return length;
}

}  // namespace kairos
