// Kairos states in GSD files (HOOMD schema 1.4).
//
// Trajectory frames hold the standard HOOMD chunks (float32 positions in HOOMD's centred box,
// velocities, box, types, diameters, masses) plus `log/` scalars, so OVITO, python3-gsd and
// MDAnalysis read them. A restart file is one such frame plus `kairos/` chunks holding the exact
// state in float64 together with the scheduler's pending events, counters and RNG state: an
// engine rebuilt from it continues bit-identically. HOOMD readers ignore the `kairos/` chunks.
//
// Bonds (ParticleSystem::bonds, bond_types) are stored in HOOMD's schema: bonds/N (uint32),
// bonds/types (int8 names), bonds/typeid (uint32, N), bonds/group (uint32, N x 2, particle
// indices of the frame), written with the other static data (trajectory: frame 0 only) and only
// when the system has bonds or bond types. Restart format 4 adds to format 3:
//   kairos/state/step_counters  uint64 x 2: counters.step_crossings, step_bounces
//   kairos/state/zone_count     uint64 x 1: present iff ParticleSystem::zones has a value
//   kairos/state/zones          uint32 zone_count x 3 (i, j, zone), only when zone_count > 0
// Format 3 files are still read: no bonds, zones = nullopt, step counters 0. Format 5 adds:
//   kairos/state/soft_counters        uint64 x 4: counters.soft_contacts, soft_overlap_fallbacks,
//                                     soft_early_releases, soft_direct_maps
//   kairos/state/soft_contact_energy  float64 x 1: counters.soft_contact_energy
//   kairos/state/frozen_contacts      uint32 F x 3 (i, j, face) of ParticleSystem::frozen, and
//   kairos/state/frozen_release       float64 F x (1 + 2D): release time, velocity_i, velocity_j
//                                     (both only when some soft contact is in progress)
//   kairos/state/frozen_deferred      float64 F x (1 + 2D): deferred (1 or 0), the release
//                                     positions i and j (only when some release is deferred;
//                                     absent: none is)
// Format 4 files are read with no soft contacts. Format 6 adds frozen_deferred; format 7 adds
//   kairos/checksum  uint32 x 1: CRC-32 (zlib) of every other chunk of the frame, over their
//                    canonical serialisation (gsd_file.hpp, "Frame checksums"), written last
// and verified by read_restart and read_initial_state before anything else is read; a mismatch
// (or a format-7 file without it) is an InputError "... is damaged: checksum mismatch". Files of
// formats 3 to 6 have no checksum and are read unverified. Format 7 files may hold
//   kairos/run/id    int8 text: the run id (RunProgress::run_id), optional: files without it
//                    (written before run ids) still load; a reader that ignores it loses only
//                    the lineage check, so the format number did not change
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <random>
#include <string>

#include "core/particle_system.hpp"
#include "core/state_blocks.hpp"
#include "init/initial_state.hpp"
#include "io/gsd_file.hpp"

namespace kairos {

// Appends one trajectory frame of the state at its current time. Static per-particle data
// (types, diameters, masses) is written only into the file's first frame (HOOMD readers take
// missing chunks from frame 0).
template <int D>
void append_trajectory_frame(gsd::Writer& writer, const ParticleSystem<D>& system);
// The same from a state read in blocks (an engine's, without a copy of its whole state).
template <int D>
void append_trajectory_frame(gsd::Writer& writer, const StateBlocks<D>& state);

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
  // The point the next thermo row is measured from (the last kept row's; kairos/run/thermo_mark).
  bool has_thermo_mark = false;
  double mark_time = 0.0, mark_virial = 0.0;
  std::uint64_t mark_events = 0, mark_collisions = 0;
  // The thermo row and trajectory frame due at this state whose writing failed
  // (kairos/run/owed, uint8): a run continued in the same directory writes them first.
  static constexpr unsigned kOwedRow = 1, kOwedFrame = 2;
  unsigned owed_outputs = 0;
  // The last kept trajectory frame's state (kairos/run/frame_mark): a continued run writes no
  // second frame of it.
  bool has_frame_mark = false;
  double frame_time = 0.0;
  std::uint64_t frame_collisions = 0;
  // Output schedules in collisions (kairos/run/schedule) of the phase the state is in (0:
  // equilibration, 1: production, -1: not recorded): thermo, trajectory, restart; a step of 0:
  // not scheduled. A continued run in that phase with the same steps keeps them.
  int schedule_phase = -1;
  std::array<std::uint64_t, 3> schedule_step{}, schedule_next{};
  // An unfinished production (kairos/run/production_end): the collision count (0: none) or
  // the time (NaN: none) it was to end at; a continued run completes it.
  std::uint64_t production_target = 0;
  double production_end_time = std::numeric_limits<double>::quiet_NaN();
};

// Writes the restart file atomically (temporary file + rename).
template <int D>
void write_restart(const std::filesystem::path& path, const ParticleSystem<D>& full_state,
                   const std::mt19937_64& rng, const RunProgress& progress = {});
// The same from a state read in blocks (the file holds the same bytes).
template <int D>
void write_restart(const std::filesystem::path& path, const StateBlocks<D>& state,
                   const std::mt19937_64& rng, const RunProgress& progress = {});

// Reads a restart file written by write_restart; InputError if it is not one or if its
// dimension differs from D. `progress` (optional) receives the run's progress.
template <int D>
// `kind`: the integrator that will run the state, for the memory estimate checked first.
ParticleSystem<D> read_restart(const std::filesystem::path& path, std::mt19937_64& rng,
                               RunProgress* progress = nullptr, RunKind kind = RunKind::kDem);

// The spatial dimension stored in a GSD file's last frame (configuration/dimensions).
int gsd_dimension(const std::filesystem::path& path);

// Reads the last frame of any HOOMD-schema GSD file as an initial state: float64 `kairos/`
// positions and velocities when present, else the float32 standard chunks. `has_velocities`
// tells whether the file held velocities. Bonds come from bonds/* (of that frame, else frame 0;
// typeid defaults to 0 and, when there are bonds but no bonds/types, the one type is named
// "backbone"). InputError on a missing file, missing positions, particles/N disagreeing with
// them, a box too small or tilted (nonzero xy, xz, yz: Kairos boxes are rectangular), particles
// outside the box, or a bond naming a particle out of range (or twice) or an unknown type.
template <int D>
InitialState<D> read_initial_state(const std::filesystem::path& path, bool& has_velocities,
                                   RunKind kind = RunKind::kDem);

}  // namespace kairos
