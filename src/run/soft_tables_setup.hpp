// Lookup tables of the soft-sphere collision map for a run (docs/physics.md#map-tables): one per
// species pair present, and one per species against the walls, over the normal impact speeds the
// run can see, loaded from the cache or built (interactions/soft_map_table.hpp).
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "core/particle_system.hpp"
#include "interactions/soft_map_table.hpp"
#include "model/environment.hpp"

namespace kairos {

struct SoftTableSettings {
  double tolerance = 1e-6;          // relative, every component
  std::filesystem::path cache_dir;  // empty: default_soft_table_cache_dir()
  // The fastest normal impact speed covered is this many times twice the state's largest
  // particle speed (or the driving's thermal speed), rounded up to a quarter decade; the slowest
  // is speed_decades below it.
  double speed_margin = 2.5;
  double speed_decades = 4.0;
  double driving_temperature = 0.0;  // > 0: an Andersen thermostat sets speeds too
  // > 0: the fastest normal speed covered, as recorded by the run this one continues (the
  // state's speeds are then not used: a continued run must use the same tables).
  double max_speed = 0.0;
};

struct SoftTableUse {
  std::string contact;  // "A-B" or "A-wall"
  SoftTableReport report;
  SoftTableSpec spec;
};

// Fills env.soft_tables (per species pair) and env.soft_wall_tables (per species, if the box
// has walls). A species whose particles do not all share one mass and one radius gets no
// tables (its collisions integrate the map directly). `progress` sees (contact, fraction).
template <int D>
std::vector<SoftTableUse> attach_soft_tables(
    Environment<D>& env, const ParticleSystem<D>& state, const SoftTableSettings& settings,
    const std::function<void(const std::string&, double)>& progress = {});

}  // namespace kairos
