// What a configuration has that keeps an analysis or a protocol from running on it, found
// from the config alone (before any state is built): the first obstacle by its key and why.
// The reader refuses the key with that reason (io/config.cpp), and the Python module and the
// start-state builder ask the same functions.
#pragma once

#include <optional>
#include <string>

#include "io/config.hpp"

namespace kairos {

// What keeps the Einstein-Helfand moments (engine/helfand_moments.hpp) from being measured in
// a system: they need a conservative, translation-invariant one. The first obstacle found, by
// its key ("boundary.wall", "contact.restitution", ...) and why; nothing for a system that has
// none. analysis.transport is refused for it (and so are the Python module's moments).
struct TransportObstacle {
  std::string key, why;
};
std::optional<TransportObstacle> transport_obstacle(const Config& config);

// What keeps a start state from being grown (compression, run/compression.hpp: a periodic box
// of hard cores): the first obstacle by its key and why; nothing when it can be.
std::optional<TransportObstacle> compression_obstacle(const Config& config);

// What keeps replica exchange (replica/replica_exchange.hpp) from a system: each replica must
// sample the canonical distribution of its rung with the engine's potential energy as U (no
// field, no dissipation, no driven or moving boundary, no shear), and have its velocities
// scaled on a swap (no soft spheres, fixed grains or Helfand moments). Nothing when it can.
std::optional<TransportObstacle> replica_exchange_obstacle(const Config& config);

}  // namespace kairos
