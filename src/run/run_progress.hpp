// Where a run stood when it wrote a restart file, beyond the physical state: its phase and
// lengths, its outputs up to that state (rows, frames, the marks that a continued run picks up
// from), the configuration it ran under, its run id. The restart file stores it as kairos/run/*
// chunks beside the state (io/gsd_snapshot.hpp writes them through RestartChunks without knowing
// what they mean); a run continued from the file reads it back (run/run_driver.hpp).
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <map>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include "core/memory_budget.hpp"
#include "core/particle_system.hpp"
#include "core/state_blocks.hpp"

namespace kairos {

// A point of the run that an observer (or the driver) keeps in the restart file, so that a
// run continued in the same directory goes on as one uninterrupted run: a time first, then
// other values, and event or collision counts, the last a collision count. Stored as the
// chunks kairos/run/<name> (the values) and kairos/run/<name><counts_suffix>; checked on
// reading (finite, not after the state). Its owner fills it in Observer::record and reads it
// from RunContext::resumed() by name.
struct ProgressMark {
  std::vector<double> values;
  std::vector<std::uint64_t> counts;
};

// Every mark, declared once: its name, sizes, counts' suffix and owner. A new observer that
// keeps a point of the run adds one line here.
struct ProgressMarkDecl {
  std::string_view name;
  std::size_t values, counts;
  std::string_view counts_suffix;
  std::string_view meaning;
};
inline constexpr ProgressMarkDecl kProgressMarks[] = {
    {"frame_mark", 1, 1, "_collisions",
     "trajectory.gsd's last kept frame: time; collisions (a continued run writes no second)"},
    {"frame_origin", 1, 1, "_collisions",
     "the driver: the origin of log-spaced frames in the phase: time; collisions"},
    {"thermo_mark", 2, 2, "_counts",
     "thermo.tsv: the point the next row is measured from: time, virial; events, collisions"},
    {"production_start", 4, 2, "_counts",
     "thermo.tsv: where an unfinished production began: time, virial, thermal energy, degrees "
     "of freedom held still; events, collisions (a continued run averages the whole of it)"},
};

// Where the run that wrote a restart file stood, beyond the physical state.
struct RunProgress {
  double equilibration_remaining = 0.0;  // collisions per particle (or time) still to equilibrate
  // An unfinished equilibration in time (run.equilibration_time): when it ends. NaN otherwise.
  double equilibration_end_time = std::numeric_limits<double>::quiet_NaN();
  double next_kick_time = -1.0;  // driving: when the next random event is due (< 0: draw)
  // The integrator that wrote the state (run.integrator: "event" or "dem"; files without the
  // chunk are "event"), and the DEM's time step (0 for the event integrator).
  std::string integrator = "event";
  double dem_time_step = 0.0;
  // DEM: the collision count the saved run had nominally reached (the target of the phase it
  // completed; several pairs may enter contact in one step, so the count itself may be past
  // it). A continued run counts its lengths from here, as one uninterrupted run would.
  std::uint64_t dem_collision_mark = 0;
  // The same in simulated time, for lengths in time (run.time, run.equilibration_time): the
  // end time of the phase it completed (a step may end past it). NaN: none recorded.
  double dem_time_mark = std::numeric_limits<double>::quiet_NaN();
  // Soft spheres: the fastest normal impact speed the run's map tables cover (0: no tables), so
  // that a continued run uses the same tables (and stays bit-identical).
  double soft_table_max_speed = 0.0;
  // The configuration the state was run under (to_toml; kairos/run/config), so that a continued
  // run knows which of its keys changed (run/restart_plan.hpp). Empty: not recorded (older files).
  std::string config;
  // The run's id (kairos/run/id, 32 hex digits), the lineage of its outputs: kept by every run
  // continued from this file (run/output_directory.hpp). Empty: not recorded (older files).
  std::string run_id;
  // The run's outputs up to this state (kairos/run/outputs), so that a run continued into the
  // same directory leaves them as one uninterrupted run would: rows and frames written after
  // this state (before an interruption) are dropped. -1: not recorded.
  std::int64_t thermo_rows = -1, trajectory_frames = -1;
  // The thermo row and trajectory frame due at this state whose writing failed
  // (kairos/run/owed, uint8): a run continued in the same directory writes them first.
  static constexpr unsigned kOwedRow = 1, kOwedFrame = 2;
  unsigned owed_outputs = 0;
  // Output schedules in collisions (kairos/run/schedule) of the phase the state is in (0:
  // equilibration, 1: production, -1: not recorded): thermo, trajectory, restart; a step of 0:
  // not scheduled. A continued run in that phase with the same steps keeps them.
  int schedule_phase = -1;
  std::array<std::uint64_t, 3> schedule_step{}, schedule_next{};
  // An unfinished production (kairos/run/production_end): the collision count (0: none) or
  // the time (NaN: none) it was to end at; a continued run completes it.
  std::uint64_t production_target = 0;
  double production_end_time = std::numeric_limits<double>::quiet_NaN();
  // The points of the run that its observers and the driver keep (kProgressMarks), by name.
  std::map<std::string, ProgressMark, std::less<>> marks;
  const ProgressMark* mark(std::string_view name) const {
    const auto it = marks.find(name);
    return it != marks.end() ? &it->second : nullptr;
  }
};

// The restart file of a run: the state (io/gsd_snapshot.hpp) and the run's progress, atomically.
template <int D>
void write_restart_file(const std::filesystem::path& path, const StateBlocks<D>& state,
                        const std::mt19937_64& rng, const RunProgress& progress);
template <int D>
void write_restart_file(const std::filesystem::path& path, const ParticleSystem<D>& state,
                        const std::mt19937_64& rng, const RunProgress& progress);

// Reads a restart file's state and the progress it records (default values for what an older
// file does not hold). InputError for a file that is not a restart file, damaged, or whose
// progress contradicts its state (a mark after the state). `kind`: the integrator that will run
// it (the memory estimate checked first).
template <int D>
ParticleSystem<D> read_restart_file(const std::filesystem::path& path, std::mt19937_64& rng,
                                    RunProgress& progress, RunKind kind);

}  // namespace kairos
