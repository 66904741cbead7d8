// An initial state read from a GSD file (system.initial_state): any HOOMD-schema file, or a
// Kairos restart file or trajectory. In init/, not io/: io/ reads and writes files and knows
// nothing of initial states (init/ uses io/, never the reverse).
#pragma once

#include <filesystem>

#include "core/memory_budget.hpp"
#include "init/initial_state.hpp"

namespace kairos {

// Reads the last frame of any HOOMD-schema GSD file as an initial state: float64 `kairos/`
// positions and velocities when present, else the float32 standard chunks. `has_velocities`
// tells whether the file held velocities. Bonds come from bonds/* (of that frame, else frame 0;
// typeid defaults to 0 and, when there are bonds but no bonds/types, the one type is named
// "backbone"). InputError on a missing file, missing positions, particles/N disagreeing with
// them, a box too small or tilted (nonzero xy, xz, yz: Kairos boxes are rectangular), particles
// outside the box, or a bond naming a particle out of range (or twice) or an unknown type; a
// Kairos restart file whose checksum does not match is refused as damaged.
template <int D>
InitialState<D> read_initial_state(const std::filesystem::path& path, bool& has_velocities,
                                   RunKind kind = RunKind::kDem);

}  // namespace kairos
