// The complete state of a hard-particle system: what the engine evolves and a restart stores.
//
// Conventions (reduced units chosen by the user, typically diameter = mass = kT = 1):
//   - positions live in the periodic box [0, L_k) and are stored at each particle's own local
//     time ("delayed states"): the position at time t is pos + vel * (t - time);
//   - the hot record a pair prediction reads (position, velocity, local time, radius) is one
//     64-byte line in 3D; everything else lives in separate arrays.
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "core/vec.hpp"

namespace kairos {

template <int D>
struct alignas(D == 3 ? 64 : 16) Kinematics {
  Vec<D> pos;     // position at local time `time`
  Vec<D> vel;     // velocity (constant between events)
  double time;    // local time of the stored position
  double radius;  // contact distance of a pair is r_i + r_j
};
static_assert(sizeof(Kinematics<3>) == 64, "3D hot record must fill one cache line");

// The one pending event a particle keeps (Lubachevsky): its soonest predicted collision and its
// next cell crossing. A collision is valid only if the partner's collision counter still equals
// the snapshot taken at prediction time (lazy invalidation).
struct EventSlot {
  double collision_time = std::numeric_limits<double>::infinity();
  double crossing_time = std::numeric_limits<double>::infinity();
  std::uint32_t partner = 0;
  std::uint32_t partner_count = 0;
  std::int32_t crossing = -1;  // 2 * axis + (moving up ? 1 : 0); -1: none
};

struct EventCounters {
  std::uint64_t events = 0;
  std::uint64_t collisions = 0;
  std::uint64_t cell_crossings = 0;
  std::uint64_t stale_events = 0;  // popped events invalidated by a partner's collision
  double virial = 0.0;             // sum over collisions of r_ij . J_i (J_i: impulse on i)
};

template <int D>
struct ParticleSystem {
  Vec<D> box{};
  double time = 0.0;
  std::vector<Kinematics<D>> kinematics;
  std::vector<double> mass;
  std::vector<std::uint32_t> species;
  std::vector<std::string> species_names;
  std::vector<std::uint32_t> collision_count;  // per particle: invalidates partners' predictions
  // Scheduler state, kept for exact restarts; empty means "predict afresh".
  std::vector<EventSlot> events;
  std::vector<std::uint32_t> cell;
  EventCounters counters;

  std::size_t size() const { return kinematics.size(); }
  Vec<D> position_at(std::size_t i, double t) const {
    const auto& k = kinematics[i];
    return k.pos + (t - k.time) * k.vel;
  }
};

}  // namespace kairos
