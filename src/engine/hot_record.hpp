// What the event engine keeps of each particle in its hot loops.
#pragma once

#include <cstdint>

#include "core/vec.hpp"
#include "scheduler/cell_grid.hpp"

namespace kairos {

// What a pair test reads of a particle, in one cache line (3D): where the particle's current
// free flight started (position and velocity at its local time) and what invalidates
// predictions made against it.
template <int D>
struct alignas(D == 3 ? 64 : 16) HotRecord {
  Vec<D> pos;                // position at local time `time`
  Vec<D> vel;                // velocity
  double time;               // local time of `pos`
  std::uint32_t collisions;  // collision counter: invalidates partners' predictions
  CellCode cell;             // the cell the particle is in
};
static_assert(sizeof(HotRecord<3>) == 64, "3D hot record must fill one cache line");

// Radius, mass and species shared by many particles: a particle stores the 2-byte index of its
// kind (none when all particles are of one kind).
struct ParticleKind {
  double radius;
  double mass;
  std::uint32_t species;
};

}  // namespace kairos
