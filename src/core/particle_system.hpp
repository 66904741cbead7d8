// The complete state of a hard-particle system: what the engine evolves and a restart stores.
//
// Conventions (reduced units chosen by the user, typically diameter = mass = kT = 1):
//   - positions live in the periodic box [0, L_k) and are stored at each particle's own local
//     time ("delayed states"): the position at time t is pos + vel * (t - time);
//   - this is the exchange form of the state (what outputs, restarts and tests read); the engine
//     keeps its own compact layout (engine/event_engine.hpp) and converts on entry and export.
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "core/vec.hpp"

namespace kairos {

template <int D>
struct Kinematics {
  Vec<D> pos;     // position at local time `time`
  Vec<D> vel;     // velocity (constant between events)
  double time;    // local time of the stored position
  double radius;  // contact distance of a pair is r_i + r_j
};

// The one pending event a particle keeps (Lubachevsky): the soonest of its predicted collision
// and its next cell crossing. `partner == kNoPartner` marks a cell crossing (or nothing, when
// `time` is infinite). A collision is valid only if the partner's collision counter still
// equals the snapshot taken at prediction time (lazy invalidation).
struct EventSlot {
  static constexpr std::uint32_t kNoPartner = 0xffffffffu;
  double time = std::numeric_limits<double>::infinity();
  std::uint32_t partner = kNoPartner;
  std::uint32_t partner_count = 0;
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
  // Scheduler state, kept for exact restarts; empty means "predict afresh". `order` is the
  // engine's internal numbering (order[k] = the particle stored at position k), which decides
  // ties between equal event times; empty means the identity.
  std::vector<EventSlot> events;
  std::vector<std::uint32_t> cell;
  std::vector<std::uint32_t> order;
  EventCounters counters;

  std::size_t size() const { return kinematics.size(); }
  Vec<D> position_at(std::size_t i, double t) const {
    const auto& k = kinematics[i];
    return k.pos + (t - k.time) * k.vel;
  }
};

}  // namespace kairos
