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
//   kairos/state/wall_motion          float64 W x 7: face, time, position, speed, version,
//                                     acceleration, layer of each wall with mass
//                                     (ParticleSystem::wall_motion; only when there is one)
//   kairos/state/wall_spring          float64 S x 9: face, mass, spring stiffness, damping,
//                                     anchor amplitude, angular frequency, phase, the anchor's
//                                     work and the dashpot's dissipation of each wall with mass
//                                     on a spring (only when there is one)
// Format 4 files are read with no soft contacts. Format 6 adds frozen_deferred; format 7 adds
//   kairos/checksum  uint32 x 1: CRC-32 (zlib) of every other chunk of the frame, over their
//                    canonical serialisation (gsd_file.hpp, "Frame checksums"), written last
// and verified by read_restart and read_initial_state (init/initial_state_file.hpp) before
// anything else is read; a mismatch (or a format-7 file without it) is an InputError "... is
// damaged: checksum mismatch". Files of formats 3 to 6 have no checksum and are read
// unverified. Format 7 files may hold
//   kairos/run/id    int8 text: the run id (run/run_progress.hpp), optional: files without it
//                    (written before run ids) still load; a reader that ignores it loses only
//                    the lineage check, so the format number did not change
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <random>
#include <string>

#include "core/memory_budget.hpp"
#include "core/particle_system.hpp"
#include "core/state_blocks.hpp"
#include "io/gsd_file.hpp"

namespace kairos {

// What a trajectory frame holds (output.trajectory_fields and trajectory_precision; the
// default: every per-particle field the state has, in float32). Every frame holds
// configuration/step, dimensions and box, particles/N, particles/position and the log/
// scalars; the file's first frame also holds particles/types, typeid, diameter and mass and the
// bonds (HOOMD readers take a chunk missing from a later frame from frame 0).
struct TrajectoryLayout {
  bool velocity = true;          // particles/velocity
  bool image = true;             // particles/image, when the state counts images
  bool angular_velocity = true;  // log/particles/angular_velocity, when the particles spin
  // particles/typeid, diameter, mass in every frame, not only in frame 0.
  bool typeid_every_frame = false, diameter_every_frame = false, mass_every_frame = false;
  // float64 instead of float32: configuration/box, particles/position (in HOOMD's centred box,
  // correctly rounded from the engine's position), velocity (the engine's, exactly), diameter,
  // mass and log/particles/angular_velocity.
  bool double_precision = false;
};

// Appends one trajectory frame of the state at its current time.
template <int D>
void append_trajectory_frame(gsd::Writer& writer, const ParticleSystem<D>& system,
                             const TrajectoryLayout& layout = {});
// The same from a state read in blocks (an engine's, without a copy of its whole state).
template <int D>
void append_trajectory_frame(gsd::Writer& writer, const StateBlocks<D>& state,
                             const TrajectoryLayout& layout = {});

// More chunks for a restart file's frame, written after the state and before the checksum that
// covers them: the run's bookkeeping (run/run_progress.hpp, the kairos/run/ chunks), which this
// layer stores without knowing what it means.
using RestartChunks = std::function<void(gsd::Writer&)>;
// Reads such chunks back from frame `frame` of the file, given the state read from it.
template <int D>
using RestartChunkReader =
    std::function<void(const gsd::Reader&, std::uint64_t frame, const ParticleSystem<D>&)>;

// Writes the restart file atomically (temporary file + rename).
template <int D>
void write_restart(const std::filesystem::path& path, const ParticleSystem<D>& full_state,
                   const std::mt19937_64& rng, const RestartChunks& more = {});
// The same from a state read in blocks (the file holds the same bytes).
template <int D>
void write_restart(const std::filesystem::path& path, const StateBlocks<D>& state,
                   const std::mt19937_64& rng, const RestartChunks& more = {});

// Reads a restart file written by write_restart; InputError if it is not one or if its
// dimension differs from D. `kind`: the integrator that will run the state, for the memory
// estimate checked first. `more` reads the chunks write_restart's `more` wrote.
template <int D>
ParticleSystem<D> read_restart(const std::filesystem::path& path, std::mt19937_64& rng,
                               RunKind kind = RunKind::kDem,
                               const RestartChunkReader<D>& more = {});

// A frame of a Kairos restart file (one with kairos/format) must carry a matching checksum
// (kairos/checksum, from format 7 on): InputError "`who` is damaged" otherwise. Frames of other
// files are not checked.
void verify_restart_checksum(const gsd::Reader& r, std::uint64_t frame,
                             const std::filesystem::path& path, const std::string& who);

// The spatial dimension stored in a GSD file's last frame (configuration/dimensions).
int gsd_dimension(const std::filesystem::path& path);

}  // namespace kairos
