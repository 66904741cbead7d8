// The state a run starts from: the restart file's, else system.initial_state's (checked for
// overlaps, float32 rounding overlaps removed), else a generated one (a lattice or random
// insertion, with room made for walls). The first step of the setup chain
// (run/setup_chain.hpp).
#pragma once

#include <filesystem>
#include <optional>
#include <random>

#include "core/particle_system.hpp"
#include "io/config.hpp"
#include "run/run_progress.hpp"

namespace kairos {

// From the restart file (its progress into `progress`: the restart plan decides what the rest
// of the configuration then means), else system.initial_state, else generated from
// config.system with `rng`. InputError for anything the user must fix.
// A generated random start denser than random insertion reaches (init's
// random_insertion_limit): it is inserted at that limit and grown to system.packing_fraction
// (run/compression.hpp) before the run.
bool grows_random_start(const Config& config);

template <int D>
ParticleSystem<D> build_start_state(const Config& config,
                                    const std::optional<std::filesystem::path>& restart_file,
                                    std::mt19937_64& rng, RunProgress& progress);

}  // namespace kairos
