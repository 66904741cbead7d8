// Kairos states in GSD files (HOOMD schema 1.4).
//
// Trajectory frames hold the standard HOOMD chunks (float32 positions in HOOMD's centred box,
// velocities, box, types, diameters, masses) plus `log/` scalars, so OVITO, python3-gsd and
// MDAnalysis read them. A restart file is one such frame plus `kairos/` chunks holding the exact
// state in float64 together with the scheduler's pending events, counters and RNG state: an
// engine rebuilt from it continues bit-identically. HOOMD readers ignore the `kairos/` chunks.
#pragma once

#include <cstdint>
#include <filesystem>
#include <random>
#include <string>

#include "core/particle_system.hpp"
#include "init/initial_state.hpp"
#include "io/gsd_file.hpp"

namespace kairos {

// Appends one trajectory frame of the state at its current time. Static per-particle data
// (types, diameters, masses) is written only into the file's first frame (HOOMD readers take
// missing chunks from frame 0).
template <int D>
void append_trajectory_frame(gsd::Writer& writer, const ParticleSystem<D>& system);

// Where the run that wrote a restart file stood, beyond the physical state.
struct RunProgress {
  double equilibration_remaining = 0.0;  // collisions per particle still to equilibrate
  double next_kick_time = -1.0;          // driving: when the next random event is due (< 0: draw)
};

// Writes the restart file atomically (temporary file + rename).
template <int D>
void write_restart(const std::filesystem::path& path, const ParticleSystem<D>& full_state,
                   const std::mt19937_64& rng, const RunProgress& progress = {});

// Reads a restart file written by write_restart; InputError if it is not one or if its
// dimension differs from D. `progress` (optional) receives the run's progress.
template <int D>
ParticleSystem<D> read_restart(const std::filesystem::path& path, std::mt19937_64& rng,
                               RunProgress* progress = nullptr);

// The spatial dimension stored in a GSD file's last frame (configuration/dimensions).
int gsd_dimension(const std::filesystem::path& path);

// Reads the last frame of any HOOMD-schema GSD file as an initial state: float64 `kairos/`
// positions and velocities when present, else the float32 standard chunks. `has_velocities`
// tells whether the file held velocities. InputError on a missing file, missing positions,
// a box too small, or particles outside the box.
template <int D>
InitialState<D> read_initial_state(const std::filesystem::path& path, bool& has_velocities);

}  // namespace kairos
