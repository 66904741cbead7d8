// The [run] and [output] keys.
//
// Each key's name, type, default, range and doc line (io/config_keys.hpp); io/config_keys.cpp
// places the groups into their tables.
#include <fmt/format.h>

#include <algorithm>
#include <cstdint>

#include "interactions/parameter_domain.hpp"
#include "interactions/potential_spec.hpp"
#include "io/config.hpp"
#include "io/config_choices.hpp"
#include "io/keys/key_tables.hpp"

namespace kairos::key_tables {

namespace {

// ----- [run], [output]

bool equilibration_in_time(const void* r) {
  return static_cast<const RunConfig*>(r)->equilibration_time >= 0.0;
}
bool equilibration_in_collisions(const void* r) {
  return !equilibration_in_time(r);
}
bool production_in_time(const void* r) {
  return static_cast<const RunConfig*>(r)->time > 0.0;
}
bool production_in_collisions(const void* r) {
  return !production_in_time(r);
}

const RunConfig kRunDefaults{};
constexpr KeyDecl kRun[] = {
    {.name = "equilibration_time",
     .type = KeyType::kFloat,
     .member = field<&RunConfig::equilibration_time>,
     .range = up_to(1e9, Scale::kTime),
     .default_text = "none",
     .unit = "time",
     .doc = "equilibration length in simulated time (instead of collisions)",
     .written = &equilibration_in_time},
    {.name = "equilibration_collisions_per_particle",
     .type = KeyType::kFloat,
     .member = field<&RunConfig::equilibration_collisions_per_particle>,
     .range = {.lo = 0.0, .hi = 1e9},
     .unit = "collisions per particle",
     .doc = "equilibration length",
     .written = &equilibration_in_collisions},
    {.name = "time",
     .type = KeyType::kFloat,
     .member = field<&RunConfig::time>,
     .range = {.lo = 0.0, .hi = 1e9, .lo_open = true, .scale = Scale::kTime},
     .default_text = "none",
     .unit = "time",
     .doc = "production length in simulated time (instead of collisions)",
     .written = &production_in_time},
    {.name = "collisions_per_particle",
     .type = KeyType::kFloat,
     .member = field<&RunConfig::collisions_per_particle>,
     .range = {.lo = 0.0, .hi = 1e9, .lo_open = true},
     .unit = "collisions per particle",
     .doc = "production length",
     .written = &production_in_collisions},
    {.name = "event_queue",
     .type = KeyType::kString,
     .member = field<&RunConfig::event_queue>,
     .choices = &choices_of<&event_queues>,
     .doc = "event queue (bit-identical runs with any)"},
    {.name = "max_wall_seconds",
     .type = KeyType::kFloat,
     .member = field<&RunConfig::max_wall_seconds>,
     .range = {.lo = 0.0, .hi = 1e9, .why = "(seconds; 0: no limit)"},
     .unit = "seconds",
     .doc = "wall-clock limit (0: none)"},
    {.name = "size_levels",
     .type = KeyType::kBoolean,
     .member = field<&RunConfig::size_levels>,
     .doc = "two cell levels for wide size distributions when they apply (same physics)"},
    {.name = "validate",
     .type = KeyType::kBoolean,
     .member = field<&RunConfig::validate>,
     .doc = "debug: check the engine against brute force after every event"},
    {.name = "integrator",
     .type = KeyType::kString,
     .member = field<&RunConfig::integrator>,
     .choices = &choices_of<&integrators>,
     .doc = "event-driven engine or the DEM reference integrator"},
    {.name = "time_step",
     .type = KeyType::kFloat,
     .member = field<&RunConfig::time_step>,
     .range = {.lo = 1e-12, .hi = 1.0, .scale = Scale::kTime, .also = 0.0},
     .unit = "time",
     .doc = "dem: the time step (0: automatic)"},
};

bool has_interval_unit(const void* o) {
  return !static_cast<const OutputConfig*>(o)->interval_unit.empty();
}

// The keys of log-spaced frames are written (and act) only with them.
bool log_spaced(const void* o) {
  return static_cast<const OutputConfig*>(o)->trajectory_spacing == "log";
}

const OutputConfig kOutputDefaults{};
constexpr KeyDecl kOutput[] = {
    {.name = "directory",
     .type = KeyType::kString,
     .member = field<&OutputConfig::directory>,
     .doc = "output directory (-o replaces it)"},
    {.name = "thermo_interval",
     .type = KeyType::kFloat,
     .member = field<&OutputConfig::thermo_interval>,
     .range = non_negative,
     .unit = "interval_unit",
     .doc = "between thermo rows (0: automatic)"},
    {.name = "trajectory_interval",
     .type = KeyType::kFloat,
     .member = field<&OutputConfig::trajectory_interval>,
     .range = non_negative,
     .unit = "interval_unit",
     .doc = "between trajectory frames (0: automatic)"},
    {.name = "restart_interval",
     .type = KeyType::kFloat,
     .member = field<&OutputConfig::restart_interval>,
     .range = non_negative,
     .unit = "interval_unit",
     .doc = "between restart files (0: at the end only)"},
    {.name = "interval_unit",
     .type = KeyType::kString,
     .member = field<&OutputConfig::interval_unit>,
     .choices = &choices_of<&interval_units>,
     .default_text = "the production length's",
     .doc = "the unit of the three intervals",
     .written = &has_interval_unit},
    {.name = "trajectory",
     .type = KeyType::kBoolean,
     .member = field<&OutputConfig::trajectory>,
     .doc = "write trajectory.gsd"},
    {.name = "trajectory_phases",
     .type = KeyType::kString,
     .member = field<&OutputConfig::trajectory_phases>,
     .choices = &choices_of<&trajectory_phases>,
     .doc = "trajectory frames of every phase, or of the production only"},
    {.name = "trajectory_fields",
     .type = KeyType::kStrings,
     .member = field<&OutputConfig::trajectory_fields>,
     .range = {.by_rule = true},  // position required, no name twice, what the state has
     .choices = &choices_of<&trajectory_fields>,
     .default_text = "`[]`",
     .doc = "per-particle fields of every frame ([]: every field the state has)"},
    {.name = "trajectory_precision",
     .type = KeyType::kString,
     .member = field<&OutputConfig::trajectory_precision>,
     .choices = &choices_of<&trajectory_precisions>,
     .doc = "float32 or float64 floating-point chunks in trajectory.gsd"},
    {.name = "trajectory_spacing",
     .type = KeyType::kString,
     .member = field<&OutputConfig::trajectory_spacing>,
     .choices = &choices_of<&trajectory_spacings>,
     .doc = "trajectory frames evenly or logarithmically spaced"},
    {.name = "trajectory_frames_per_decade",
     .type = KeyType::kInteger,
     .member = field<&OutputConfig::trajectory_frames_per_decade>,
     .range = {.lo = 1.0, .hi = 1000.0},
     .doc = "log-spaced frames: frames per factor 10 of the lag",
     .written = &log_spaced},
    {.name = "trajectory_log_period",
     .type = KeyType::kFloat,
     .member = field<&OutputConfig::trajectory_log_period>,
     .range = non_negative,
     .unit = "interval_unit",
     .doc = "log-spaced frames: the sequence starts again every period (0: never)",
     .written = &log_spaced},
    {.name = "progress",
     .type = KeyType::kString,
     .member = field<&OutputConfig::progress>,
     .choices = &choices_of<&progress_modes>,
     .doc = "progress line on stderr"},
    {.name = "log_interval",
     .type = KeyType::kFloat,
     .member = field<&OutputConfig::log_interval>,
     .range = {.lo = 0.0, .hi = 1e9, .why = "(seconds; 0: no run.log)"},
     .unit = "seconds",
     .doc = "wall seconds between progress lines in run.log (and on stdout in a batch run; "
            "0: no run.log)"},
    {.name = "profile_axis",
     .type = KeyType::kString,
     .member = field<&OutputConfig::profile_axis>,
     .range = {.by_rule = true},  // "" is none; the message names the dimension
     .choices = &choices_in<&axes>,
     .doc = "profile.tsv along this axis (\"\": none)"},
    {.name = "profile_bins",
     .type = KeyType::kInteger,
     .member = field<&OutputConfig::profile_bins>,
     .range = counted,
     .doc = "slabs of the profile"},
};

}  // namespace

constexpr KeyGroup kRunGroup{"run", kRun, &kRunDefaults};
constexpr KeyGroup kOutputGroup{"output", kOutput, &kOutputDefaults};

}  // namespace kairos::key_tables
