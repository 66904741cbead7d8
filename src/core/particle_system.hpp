// The complete state of a hard-particle system: what the engine evolves and a restart stores.
//
// Conventions (reduced units chosen by the user, typically diameter = mass = kT = 1):
//   - positions live in the periodic box [0, L_k) and are stored at each particle's own local
//     time ("delayed states"): the position at time t is pos + vel * (t - time);
//   - this is the exchange form of the state (what outputs, restarts and tests read); the engine
//     keeps its own compact layout (engine/event_engine.hpp) and converts on entry and export.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "core/vec.hpp"

namespace kairos {

// The volume of a sphere (3D) or area of a disk (2D) of radius r.
template <int D>
constexpr double ball_volume(double r) {
  return D == 3 ? 4.0 / 3.0 * M_PI * r * r * r : M_PI * r * r;
}

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
  // Partner values from kKeptBase on are not particles. A cell crossing is kNoPartner, or
  // kKeptBase + p when its prediction found the contact with particle p (counter in
  // partner_count) as the soonest after the crossing, or kNoneKept (2 * D + 2 below kNoPartner)
  // when it found none (incremental crossings, see EventEngine::cross). Walls and a soft
  // contact's release use the codes just below kNoPartner.
  static constexpr std::uint32_t kKeptBase = 0x80000000u;
};

struct EventCounters {
  std::uint64_t events = 0;
  std::uint64_t collisions = 0;  // particle-particle
  std::uint64_t cell_crossings = 0;
  std::uint64_t stale_events = 0;  // popped events invalidated by a partner's collision
  double virial = 0.0;             // sum over collisions of r_ij . J_i (J_i: impulse on i)
  // The same sum as a tensor, r_ij,a J_i,b (row-major D x D; its trace is `virial`): the
  // collisional part of the pressure tensor.
  std::array<double, 9> virial_tensor{};
  // Granular bookkeeping (zero for elastic hard spheres in a periodic box).
  std::uint64_t wall_collisions = 0;
  std::uint64_t elastic_by_rule = 0;     // made elastic by the TC model or elastic_below_speed
  std::uint64_t sliding_collisions = 0;  // Coulomb-limited (Walton) contacts that slid
  std::uint64_t fell_asleep = 0;         // particles put to sleep (resting under gravity)
  // Sleepers woken because the sleeper under them woke and nothing else held them up (not
  // part of the state: counted from the start of this engine).
  std::uint64_t lost_support = 0;
  std::uint64_t driving_kicks = 0;  // velocities set by a thermostat or random kick
  // The normal impulse each wall on a box face (face 2k: the low face of axis k) gave the
  // particles in hard contacts: their pressure on it, summed (not written to restart files: a
  // continued run counts from its start; compression reads a container's pressure from it).
  std::array<double, 6> face_wall_impulse{};
  // Kinetic energy (translational + rotational) dissipated in particle-particle and in
  // particle-wall collisions, and the work moving walls did on the particles.
  double dissipated_in_collisions = 0.0;
  double dissipated_at_walls = 0.0;
  double work_by_walls = 0.0;
  double work_by_driving = 0.0;  // kinetic energy added by thermostat or random kicks
  // Lees-Edwards shear: kinetic energy (box frame) added where particles meet or become images
  // across the sliding y faces. Closes the energy budget; the heating of the peculiar motion is
  // -P_xy shear_rate V on average.
  double work_by_shear = 0.0;
  // Stepped potentials: events where a pair met a step of its potential (outside the hard
  // core) and crossed it or bounced off it. Both also count in `collisions`.
  std::uint64_t step_crossings = 0;
  std::uint64_t step_bounces = 0;
  // Soft spheres (docs/physics.md#event-driven-soft-contacts). soft_contacts: contacts carried
  // out by the mapping (pair and wall contacts; they also count in `collisions` /
  // `wall_collisions`). Exception A (soft_overlap_fallbacks): the placed pair would overlap a
  // third body, so the contact was instantaneous with e = -eps_rdot. Exception B
  // (soft_early_releases): a third body met a frozen pair before its release, which was then
  // released at once. soft_direct_maps: maps integrated directly because the collision lay
  // outside the lookup table (or no table).
  std::uint64_t soft_contacts = 0;
  std::uint64_t soft_overlap_fallbacks = 0;
  std::uint64_t soft_early_releases = 0;
  std::uint64_t soft_direct_maps = 0;
  // The kinetic energy the frozen contacts give back at their release (part of the state:
  // kinetic + this + dissipated energy is what a contact conserves). Deferred contacts
  // (FrozenContact::deferred) are not in it: theirs follows from their velocities
  // (EventEngine::potential_energy() adds it).
  double soft_contact_energy = 0.0;
  // Outlets (boundaries/outlets.hpp): particles that passed through one and were put back, their
  // mass, and the energy they took out (kinetic + rotational + the field's potential energy
  // before the pass less after it).
  std::uint64_t outlet_passes = 0;
  double outlet_mass = 0.0;
  double outlet_energy = 0.0;
};

// A bond of a molecule (chain): particles i and j (the caller's numbering) interact through
// the bond table of `type` instead of their species pair's potential.
struct Bond {
  std::uint32_t i = 0, j = 0;
  std::uint32_t type = 0;
  bool operator==(const Bond&) const = default;
};

// Stepped potentials: which step ("zone") of its potential a pair sits in. Zone 0 is beyond the
// cut-off (never stored for non-bonded pairs), zone z >= 1 the shell between boundaries r_z and
// r_{z-1} of the pair's table. Part of the exact state: a pair that just bounced off a step
// sits on its boundary, where the distance alone cannot tell the two zones apart.
struct PairZone {
  std::uint32_t i = 0, j = 0;  // the caller's numbering, i < j
  std::uint32_t zone = 0;
  bool operator==(const PairZone&) const = default;
};

// Soft spheres (docs/physics.md#event-driven-soft-contacts): a pair frozen inside a mapped
// contact, moving with its centre-of-mass velocity until its release gives it the post-contact
// velocities (or a particle frozen against wall `face`). Scheduler state: part of an exact
// restart.
template <int D>
struct FrozenContact {
  static constexpr std::uint32_t kWall = 0xffffffffu;
  std::uint32_t i = 0;                // the caller's numbering
  std::uint32_t j = kWall;            // the partner (caller's numbering), or kWall
  std::uint32_t face = 0;             // the wall's face when j == kWall
  double release_time = 0.0;          // absolute
  Vec<D> velocity_i{}, velocity_j{};  // after the release (velocity_j unused for a wall)
  // A deferred release (EngineOptions::defer_soft_releases): the engine already holds the
  // motion after the release, as the positions at the release time (exact for a resume).
  bool deferred = false;
  Vec<D> release_position_i{}, release_position_j{};
  bool operator==(const FrozenContact&) const = default;
};

// A wall with mass (boundaries/wall_body.hpp): where the plane of the wall at `face` was along
// its axis at `time` (its last contact), its speed then and its constant acceleration since
// (a run continued with another force, mass or field moves it on with this one to the state's
// time first); `version` counts the changes of its motion (wall events predicted before a
// change are stale), `layer` is the layer of cells its plane is in (-1: work it out from the
// position). Scheduler state: part of an exact restart.
struct WallMotion {
  std::uint32_t face = 0;
  double time = 0.0;
  double position = 0.0;
  double speed = 0.0;
  std::uint32_t version = 0;
  double accel = 0.0;
  std::int32_t layer = -1;
  // A wall on a spring (boundaries/wall_spring.hpp; all 0 otherwise): its mass and the
  // spring's stiffness, damping, anchor amplitude, angular frequency and phase the motion was
  // made with, and the anchor's work and the dashpot's dissipation up to `time`.
  std::array<double, 6> spring{};
  double drive_work = 0.0;
  double dashpot = 0.0;
  bool sprung() const { return spring[1] > 0.0; }
  bool operator==(const WallMotion&) const = default;
};

// Angular velocity: a vector in 3D, the z component alone in 2D.
template <int D>
using AngularVelocity = Vec<D == 3 ? 3 : 1>;

// The DEM integrator's state beyond positions and velocities (DemIntegrator::checkpoint():
// half-step velocities, forces, its numbering and neighbour list, the friction springs), kept
// in restart files so that a continued DEM run is bit-identical. Empty for other states; the
// layout is the DEM's (dem/dem_integrator.cpp).
struct DemResume {
  std::vector<double> scalars;
  std::vector<double> particles;  // a fixed stride per particle, in the caller's numbering
  std::vector<std::uint32_t> order, list_start, list;
  std::vector<double> springs;
  bool empty() const { return scalars.empty(); }
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
  // Rough particles only (empty otherwise): angular velocity per particle.
  std::vector<AngularVelocity<D>> angular_velocity;
  // TC model only (empty otherwise): time of each particle's last collision.
  std::vector<double> last_collision_time;
  // Scheduler state, kept for exact restarts; empty means "predict afresh". `order` is the
  // engine's internal numbering (order[k] = the particle stored at position k), which decides
  // ties between equal event times; empty means the identity.
  std::vector<EventSlot> events;
  std::vector<std::uint32_t> cell;
  std::vector<std::uint32_t> order;
  EventCounters counters;

  // The field and boundaries the trajectories live in (set by the engine on export; the
  // defaults are a periodic box with no field). Positions along a non-periodic axis are never
  // wrapped.
  Vec<D> gravity{};
  std::array<bool, D> periodic = all_periodic();
  // Sleeping particles (empty: none) rest where they are and feel no gravity.
  std::vector<std::uint8_t> asleep;
  // Image counters (empty: not tracked): the unwrapped position at a particle's local time is
  // kinematics.pos + image * box on the periodic axes (under Lees-Edwards shear, x also adds
  // image[1] * shear_rate * L_y * t: engine/image_counters.hpp).
  std::vector<std::array<std::int32_t, D>> image;
  // Molecules: the bonds (topology, not scheduler state) and the names of their types.
  std::vector<Bond> bonds;
  std::vector<std::string> bond_types;
  // Stepped potentials: the zone of every pair inside some step (scheduler state: empty
  // optional = compute from the distances; resumed engines require it).
  std::optional<std::vector<PairZone>> zones;
  // Soft spheres: the contacts in progress (mapped contacts waiting for their release).
  std::vector<FrozenContact<D>> frozen;
  // Walls with mass: their motion (empty: none, or each at rest on its face at `time`).
  std::vector<WallMotion> wall_motion;
  // DEM runs: what a resumed DemIntegrator needs to continue bit for bit (empty: start afresh).
  DemResume dem;

  std::size_t size() const { return kinematics.size(); }
  bool is_asleep(std::size_t i) const { return !asleep.empty() && asleep[i] != 0; }
  Vec<D> position(std::size_t i, double t) const {
    const auto& k = kinematics[i];
    const double dt = t - k.time;
    if (is_asleep(i)) return k.pos;
    return k.pos + dt * k.vel + (0.5 * dt * dt) * gravity;
  }
  Vec<D> velocity(std::size_t i, double t) const {
    const auto& k = kinematics[i];
    if (is_asleep(i)) return Vec<D>{};
    return k.vel + (t - k.time) * gravity;
  }

 private:
  static std::array<bool, D> all_periodic() {
    std::array<bool, D> p;
    p.fill(true);
    return p;
  }
};

}  // namespace kairos
