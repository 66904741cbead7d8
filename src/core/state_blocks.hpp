// A state read in blocks of particles: what the outputs of a large system (restart files,
// trajectory frames, thermo sums) are computed from, so that no second copy of the whole state
// lives beside the engine's arrays (docs/performance.md, "Memory").
#pragma once

#include <algorithm>
#include <cstddef>
#include <functional>
#include <memory>

#include "core/particle_system.hpp"

namespace kairos {

template <int D>
struct StateBlocks {
  // Particles per block: a block's buffers (up to 64 bytes per particle an array) stay below
  // the 2 MiB from which allocations are mappings of their own (cli/main.cpp), so that the heap
  // reuses them from one output to the next instead of faulting fresh pages in.
  static constexpr std::size_t kBlock = std::size_t{1} << 13;
  // Which per-particle arrays a reader needs (fill may leave the others unset): a chunk of
  // positions need not read the scheduler's arrays.
  enum Fields : unsigned {
    kKinematics = 1,  // kinematics, asleep, image
    kIdentity = 2,    // mass, species
    kScheduler = 4,   // collision_count, events, cell, order
    kExtras = 8,      // angular_velocity, last_collision_time
    kAll = 15
  };

  // Every field of the state except the per-particle arrays (kinematics, mass, species,
  // collision_count, events, cell, order, asleep, angular_velocity, last_collision_time), which
  // are read through fill() only (empty in an engine's blocks).
  const ParticleSystem<D>& globals() const { return *globals_; }
  std::shared_ptr<const ParticleSystem<D>> globals_;
  std::size_t particles = 0;
  // Sets the per-particle arrays of `out` to those of particles [first, first + count), in the
  // caller's numbering (an array the state lacks stays empty); the other fields of `out` are
  // left alone.
  // Arrays outside `fields` may be left as they were.
  std::function<void(std::size_t first, std::size_t count, ParticleSystem<D>& out, unsigned fields)>
      fill;

  // The blocks of a whole state (copies of its ranges); `whole` must outlive the result.
  static StateBlocks of(const ParticleSystem<D>& whole) {
    StateBlocks b;
    b.globals_ = std::shared_ptr<const ParticleSystem<D>>(&whole, [](const ParticleSystem<D>*) {});
    b.particles = whole.size();
    b.fill = [&whole](std::size_t first, std::size_t count, ParticleSystem<D>& out, unsigned) {
      const auto range = [&](const auto& all, auto& part) {
        if (all.empty()) {
          part.clear();
        } else {
          part.assign(all.begin() + static_cast<std::ptrdiff_t>(first),
                      all.begin() + static_cast<std::ptrdiff_t>(first + count));
        }
      };
      range(whole.kinematics, out.kinematics);
      range(whole.mass, out.mass);
      range(whole.species, out.species);
      range(whole.collision_count, out.collision_count);
      range(whole.events, out.events);
      range(whole.cell, out.cell);
      range(whole.order, out.order);
      range(whole.asleep, out.asleep);
      range(whole.image, out.image);
      range(whole.angular_velocity, out.angular_velocity);
      range(whole.last_collision_time, out.last_collision_time);
    };
    return b;
  }

  // The state's particles [first, first + count) with the fields their positions and
  // velocities at the state's time need (box, time, gravity, periodic axes, counters).
  ParticleSystem<D> block(std::size_t first, std::size_t count, unsigned fields = kAll) const {
    ParticleSystem<D> out;
    out.box = globals().box;
    out.time = globals().time;
    out.gravity = globals().gravity;
    out.periodic = globals().periodic;
    out.counters = globals().counters;
    fill(first, count, out, fields);
    return out;
  }

  // Calls f(block, first) for the blocks of at most kBlock particles, in order.
  template <class F>
  void for_each(F&& f, unsigned fields = kAll) const {
    ParticleSystem<D> part = block(0, 0);
    for (std::size_t first = 0; first < particles; first += kBlock) {
      fill(first, std::min(kBlock, particles - first), part, fields);
      f(static_cast<const ParticleSystem<D>&>(part), first);
    }
  }
};

}  // namespace kairos
