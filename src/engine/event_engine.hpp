// The event-driven engine for hard spheres (D = 3) and hard disks (D = 2).
//
// One event's path: the queue yields the particle with the soonest pending event. The particle's
// PendingEvent says whether that is a collision (with a partner) or a cell crossing. A collision
// whose partner has collided since the prediction is stale: the particle is re-predicted and
// nothing else happens. A valid collision advances both particles to the event time (their
// local clocks), applies the elastic impulse, bumps both collision counters and re-predicts
// both. A crossing moves the particle to the next cell and re-predicts it.
//
// Every prediction scans the particle's 3^D neighbouring cells. When the crossing comes first,
// the soonest contact after it is kept, named by the crossing's pending event, and the crossing
// then scans only the layer of cells new to the neighbourhood (incremental crossings, see
// cross()); where that does not apply (shear, steps) the crossing bounds the scan and
// rescans everything.
//
// Invariant (checked by validate()): for every pair in neighbouring cells, the sooner of the
// two particles' pending events is no later than the pair's true next contact; so the queue
// never passes over a collision.
//
// Memory layout (what bytes_per_particle() counts): the hot record a pair test reads (position,
// velocity, local time, collision counter, cell) is one 64-byte line in 3D; the pending event
// (partner and its counter snapshot) is 8 bytes; the queue keeps the event time; the cell grid
// a link per particle; the particle's id (outputs keep the caller's numbering while the engine
// renumbers particles along a space-filling curve) 4 bytes; radius, mass and species live in a
// small table of kinds indexed by a 2-byte kind number (absent for a single kind).
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "boundaries/lees_edwards.hpp"
#include "core/event_code.hpp"
#include "core/huge_page_allocator.hpp"
#include "core/particle_system.hpp"
#include "core/periodic.hpp"
#include "core/state_blocks.hpp"
#include "dynamics/collision_time.hpp"
#include "engine/candidate_scan.hpp"
#include "engine/cell_neighbourhood.hpp"
#include "engine/growth.hpp"
#include "engine/helfand_moments.hpp"
#include "engine/hot_record.hpp"
#include "engine/image_counters.hpp"
#include "engine/pair_steps.hpp"
#include "engine/resting_particles.hpp"
#include "engine/soft_contact_state.hpp"
#include "model/boundaries.hpp"
#include "model/environment.hpp"
#include "scheduler/cell_grid.hpp"

namespace kairos {

// kImageShift: under Lees-Edwards shear, the images across the y faces moved on by a cell width
// and the particles next to those faces were predicted again.
// kSoftRelease: a soft contact ended, its frozen pair got its post-contact velocities.
// kWallLayer: the plane of a wall with mass entered another layer of cells, and the particles
// it can now reach were looked at again.
// kOutletPass: a particle's centre crossed an outlet and was put back in its insertion region.
enum class EventKind {
  kNone,
  kCollision,
  kCellCrossing,
  kStale,
  kWallCollision,
  kImageShift,
  kSoftRelease,
  kWallLayer,
  kOutletPass
};

// How an engine starts: predict every event from the state, or resume the scheduler state the
// ParticleSystem carries (from export_state() or a restart file) to continue bit-identically.
enum class StartMode { kPredict, kResume };

// How the cell lists of a neighbourhood are walked: kVector gathers sixteen list heads at a time
// with AVX-512 (fast on Intel's cores, slow on AMD's Zen 4), kScalar follows them one by one,
// kAuto picks by CPU (cpu_gathers_fast). Either lists the same candidates.
enum class ListGather { kAuto, kScalar, kVector };

// How the AVX-512 loops read eight candidates' records: kGather with one gather per field (fast
// on Intel's cores), kRows with one load per record and a transpose (faster on AMD's Zen 4),
// kAuto by CPU (cpu_gathers_fast). The same values either way.
enum class RecordLoads { kAuto, kGather, kRows };

struct EngineOptions {
  // Renumber particles along a Morton curve at the start and every this many collisions per
  // particle (0: never, the caller's order is kept).
  double renumber_interval = 32.0;
  double max_cells_per_particle = CellGrid<3>::kDefaultCellsPerParticle;
  // Test candidates eight at a time with AVX-512 when the CPU has it (same results either way).
  bool vector_scan = true;
  // Soft spheres: when a mapped contact can meet nothing before its end, give the pair its
  // post-contact motion at once (deferred release, see soft_contacts.cpp) instead of freezing
  // it until a release event. Same physics; false keeps every contact frozen (for comparison).
  bool defer_soft_releases = true;
  // After a cell crossing, scan only the layer of cells new to the particle's neighbourhood and
  // keep the soonest contact its last prediction found beyond the crossing (not under shear or
  // with steps). Same physics; false rescans every neighbour (for comparison).
  bool incremental_crossings = true;
  // Keep image counters (engine/image_counters.hpp: 4 D bytes per particle) so that exported
  // states can be unwrapped; a state that carries counters keeps them either way.
  bool track_images = false;
  // Keep the Helfand moments of momentum and energy (engine/helfand_moments.hpp) for the
  // Einstein-Helfand transport coefficients: a conservative periodic system only.
  bool track_helfand = false;
  // Needs vector_scan (and AVX-512) for kVector.
  ListGather list_gather = ListGather::kAuto;
  // Used by the AVX-512 loops only.
  RecordLoads record_loads = RecordLoads::kAuto;
  // Growing particles (engine/growth.hpp, Lubachevsky-Stillinger): every diameter grows by this
  // fraction of its value at the engine's start per unit time (0: none). Elastic, smooth hard
  // spheres in a periodic box only.
  double growth_rate = 0.0;
  // Wide size distributions (the largest radius above 2.5 times the small particles', those
  // within twice the 10th percentile) in a periodic box without walls, steps, bonds, soft
  // contacts, shear or fixed grains: two cell levels (engine/cell_neighbourhood.hpp), small
  // particles in fine cells and big ones in coarse cells. false: one level, cells sized for the
  // largest diameter (the same physics; for comparison).
  bool size_levels = true;
  // Two levels whenever they are possible, without the estimate of their cost (tests).
  bool force_size_levels = false;
  // Cells at least this wide (0: as wide as the largest contact): room for growth.
  double min_cell_width = 0.0;
  // Keep each particle's radius (8 bytes per particle) instead of a kind per radius: chosen by
  // itself when the particles have more than 65 536 distinct (radius, mass, species) kinds (a
  // continuous size distribution); true forces it (the same trajectories either way). The
  // scalar candidate loop is used.
  bool per_particle_radii = false;
};

template <int D, class Queue>
class EventEngine {
 public:
  // Takes the state. kResume requires the scheduler state (events and cells) and throws
  // InputError if it is missing or inconsistent with the positions.
  // The environment (gravity, walls, contact laws) defaults to elastic hard spheres in a
  // periodic box.
  // Pass the state moved (std::move) to keep one copy of it in memory: its largest arrays are
  // released as soon as they are read.
  explicit EventEngine(ParticleSystem<D> system, StartMode mode = StartMode::kPredict,
                       EngineOptions options = {}, const Environment<D>& environment = {});

  // Processes the next event. Returns kNone when nothing can ever happen again.
  EventKind step();

  double time() const { return time_; }
  // When the next event happens (kNever if nothing ever will).
  double next_event_time() {
    const double next = std::min(queue_.top_time(), shear_.next_shift_time());
    return massive_walls_ ? std::min(next, boundaries_.next_layer_change()) : next;
  }

  // Where particle i (the engine's numbering) is and how it moves at time t (not before its local
  // time, unless it sits in a deferred soft contact: then the frozen motion until the release).
  Vec<D> position(std::uint32_t i, double t) const {
    if (in_deferred_contact(i, t)) [[unlikely]]
      return hot_[i].pos - (hot_[i].time - t) * frozen_velocity_of(i);
    return is_asleep(i) ? hot_[i].pos : flight_position(hot_[i], t);
  }
  Vec<D> velocity(std::uint32_t i, double t) const {
    if (in_deferred_contact(i, t)) [[unlikely]]
      return frozen_velocity_of(i);
    return is_asleep(i) ? Vec<D>{} : flight_velocity(hot_[i], t);
  }
  double particle_mass(std::uint32_t k) const { return mass_of(k); }
  // Driving (thermostats, random kicks) acts between events: it sets the velocity of particle k
  // at time t, with time() <= t <= next_event_time(), wakes it if it sleeps, invalidates
  // predictions made against it and re-predicts it. k is the engine's internal index: any
  // numbering serves a uniform random choice, and it is restored on resume.
  void set_velocity(std::uint32_t k, double t, const Vec<D>& v);
  // Moves the present to t without an event (time() <= t <= next_event_time()), for outputs at
  // given times: exports, energies and velocities then describe the system at t. No record
  // changes (they move lazily), so stopping here or not gives the same trajectory.
  void advance_clock(double t) {
    if (!(t >= time_) || !(t <= next_event_time()))
      throw std::logic_error("advance_clock: time outside [time(), next_event_time()]");
    time_ = t;
  }
  const EventCounters& counters() const { return counters_; }
  const Vec<D>& box() const { return box_; }
  // The complete state in the caller's particle numbering, scheduler state included: an engine
  // resumed from it continues bit-identically. Without zones (stepped potentials' capture map,
  // the costly part), enough for outputs but not for a resume.
  ParticleSystem<D> export_state(bool with_zones = true) const;
  // Unwrapped positions now (position + image * box; needs track_images) of the particles with
  // slot[id] != kNotFollowed (id: the caller's number), into out[slot[id]].
  static constexpr std::uint32_t kNotFollowed = ~0u;
  void unwrapped_positions(const std::vector<std::uint32_t>& slot, std::vector<Vec<D>>& out) const;
  // Whether image counters (track_images, or a state that carried them) and the Helfand
  // moments (track_helfand) are kept.
  bool tracks_images() const { return images_.on(); }
  bool tracks_helfand() const { return helfand_.on(); }
  // The Helfand moments now (options track_helfand; their collisional momentum part is
  // counters().virial_tensor plus the moments' jump_stress).
  typename HelfandMoments<D>::Moments helfand_moments() const { return helfand_.at(time_); }
  // Their velocities now, likewise.
  void velocities(const std::vector<std::uint32_t>& slot, std::vector<Vec<D>>& out) const;
  // The same state read in blocks of particles: outputs of a large system without a copy of
  // the whole state (4 bytes per particle, the caller's numbering's map to the engine's). Valid
  // until the engine changes.
  StateBlocks<D> state_blocks(bool with_zones = true) const;
  std::size_t size() const { return hot_.size(); }

  double kinetic_energy() const;  // translational
  // The largest overlap of any pair now (0 when none), from the engine's own cells: each pair
  // tested as init/initial_state's max_overlap tests it (positions wrapped into the box as
  // current_positions() gives them, the nearest image along periodic axes, none along bounded
  // ones), without a copy of the state or a grid of its own. Not under shear (the images
  // slide: the caller uses max_overlap_sheared).
  double max_overlap_now() const;
  // Translational, of the velocities relative to the mean shear flow (Lees-Edwards); equal to
  // kinetic_energy() without shear.
  double peculiar_kinetic_energy() const;
  double rotational_energy() const;  // 0 unless particles rotate
  // Configurational energy of the stepped potentials (0 for hard spheres), exact: the sum of
  // the energies of the zones the pairs sit in. Soft spheres: the kinetic energy the frozen
  // contacts will give back at their release (what the contacts hold, so that kinetic +
  // potential + dissipated energy stays constant through a contact).
  double potential_energy() const {
    if (stepped_) return steps_.energy();
    return !soft_state_.defers() ? counters_.soft_contact_energy
                                 : counters_.soft_contact_energy + deferred_contact_energy();
  }
  bool soft() const { return soft_; }
  // How many particles sit in a frozen soft contact now.
  std::uint32_t frozen() const;
  // The degrees of freedom those contacts hold still: D per frozen pair (it moves as one
  // body), 1 per particle frozen against a wall (along its normal).
  double held_degrees_of_freedom() const;
  bool stepped() const { return stepped_; }
  // Pairs that crossed the outermost step of their potential inwards since this engine was
  // built (not part of the state): the contacts of a stepped soft potential (spring_dashpot).
  std::uint64_t step_captures() const { return step_captures_; }
  // Particles asleep now (the fixed grains aside), and the fixed grains.
  std::uint32_t sleeping() const { return resting_.sleepers(); }
  std::uint32_t fixed_grains() const { return resting_.fixed_count(); }
  // Cell crossings since this engine was built (not part of the state) that scanned only the
  // cells new to the particle's neighbourhood (EngineOptions::incremental_crossings).
  std::uint64_t incremental_crossing_scans() const { return incremental_scans_; }
  bool incremental_crossings() const { return incremental_crossings_; }
  // Two cell levels (EngineOptions::size_levels) are in use.
  bool two_level_cells() const { return cells_.two_level(); }
  // Whether the AVX-512 loops read candidates' records by rows (EngineOptions::record_loads).
  bool candidate_row_loads() const { return row_loads_; }
  Vec<D> momentum() const;
  // Sum over particles of m c_a c_b (row-major, D x D used), c the velocity now relative to the
  // centre-of-mass velocity: the kinetic part of the pressure tensor times V. Two passes over
  // the records in memory order, as kinetic_energy() sums (not under shear: the adapter takes
  // the velocities relative to the flow).
  std::array<double, 9> peculiar_kinetic_tensor() const;
  const Environment<D>& environment() const { return env_; }
  // Every wall as the engine meets it now (walls with mass where their motion put them).
  const Boundaries<D>& boundaries() const { return boundaries_; }
  // Positions at the current time, wrapped into the box, in the caller's numbering.
  std::vector<Vec<D>> current_positions() const;
  // Velocities at the current time, in the caller's numbering: export_state()'s
  // flight_velocity(i, time()) to the bit, without copying the rest of the state.
  std::vector<Vec<D>> current_velocities() const;
  std::vector<double> masses() const;  // in the caller's numbering
  // current_positions(), current_velocities() and the masses of the caller's particles, in
  // blocks of at most StateBlocks<D>::kBlock in the caller's order: f(first, x, v, m) for the
  // particles [first, first + x.size()). Sums over particles without a copy of every
  // particle's position or velocity (4 bytes per particle for the numbering's map).
  using BlockVisitor = std::function<void(std::size_t first, std::span<const Vec<D>> x,
                                          std::span<const Vec<D>> v, std::span<const double> m)>;
  // Without positions (x empty), a third cheaper.
  void for_each_block(const BlockVisitor& f, bool with_positions = true) const;
  // Drops the order in which blocks read the records (4 bytes per particle; blocks being
  // written keep their own reference): the run calls it when events resume after outputs, so
  // that the order is held only while outputs are written.
  void release_block_order() const { block_order_.reset(); }
  // Each particle's collision counter (particle and wall collisions; it wraps at 2^32), in the
  // caller's numbering: which particles took part in the events between two calls.
  std::vector<std::uint32_t> collision_counts() const {
    std::vector<std::uint32_t> out(size());
    for (std::uint32_t i = 0; i < size(); ++i) out[id_[i]] = hot_[i].collisions;
    return out;
  }

  // Debug: checks cell membership, queue order and the prediction invariant against brute
  // force; throws std::logic_error describing the first violation. O(N^2).
  void validate();

  double bytes_per_particle() const;
  const char* queue_name() const { return Queue::name(); }
  const CellGrid<D>& grid() const { return cells_.grid(); }

  // Growing particles (EngineOptions::growth_rate): the growth, and the last moment the cells
  // still hold every pair that can touch (kNever without growth); events must not be taken
  // beyond it (the caller rebuilds the engine with wider cells).
  const Growth& growth() const { return growth_; }
  double growth_fits_until() const { return growth_fits_until_; }
  // Multiplies every velocity by `factor` at time t (time() <= t <= next_event_time()), as a
  // thermostat's rescaling does, and predicts every particle again. Growing particles: a
  // growth_rate > 0 also sets the growth rate from t on (as set_growth_rate), in the same pass.
  void rescale_velocities(double t, double factor, double growth_rate = 0.0);
  // Sets every particle's velocity at time t (time() <= t <= next_event_time()), `velocity` in
  // the caller's numbering, and predicts every particle again. std::logic_error with soft
  // contacts, sleeping particles or the Helfand moments kept (their state follows the
  // velocities), or a velocity for a fixed grain.
  void set_velocities(double t, const std::vector<Vec<D>>& velocity);
  // Growing particles: from time t on (time() <= t <= next_event_time()) the diameters grow at
  // `rate` (relative to the radii at the engine's start; > 0); every particle is predicted again.
  // A collision beyond growth_fits_until() is refused (std::logic_error): the caller rebuilds.
  void set_growth_rate(double t, double rate);

 private:
  using Code = EventCode<D>;
  using PendingEvent = kairos::PendingEvent<D>;
  using CandidateList = kairos::CandidateList<D>;
  using Cells = CellNeighbourhood<D>;
  struct Crossing {
    double time;  // absolute
    int axis;     // -1: never
    int sign;     // +1 up, -1 down
  };

  // A soft contact's partner (SoftContactState): a particle, a wall (its event code's bits) or
  // kNoPartner.
  static constexpr std::uint32_t kFirstCode = Code::kFirstCode;
  static bool is_particle(std::uint32_t partner) { return partner < kFirstCode; }
  static std::uint32_t wall_partner(int face) { return Code::wall(face).bits(); }
  // Cells per particle allowed when some axis has walls or open faces (see setup_environment).
  static constexpr double kBoundedCellsPerParticle = 8.0;

  void build_kinds(const ParticleSystem<D>& s);
  bool index_kinds(const ParticleSystem<D>& s, bool with_radius);
  void setup_environment(const ParticleSystem<D>& s);
  std::uint32_t species_of(std::uint32_t i) const {
    return kinds_[kind_.empty() ? 0 : kind_[i]].species;
  }
  // Where a record's free flight (a straight line, or a parabola under gravity) is at time t:
  // the record alone, whether the particle sleeps or sits in a deferred contact or not.
  Vec<D> flight_position(const HotRecord<D>& h, double t) const;
  Vec<D> flight_velocity(const HotRecord<D>& h, double t) const;
  // The particle's soonest wall contact from time t before t + horizon: (relative time, face).
  std::pair<double, int> next_wall_contact(std::uint32_t i, double t, double horizon) const;
  // A wall event: the contact, or for an outlet the pass (the event's kind says which).
  EventKind hit_wall(std::uint32_t i, int surface, double t);
  // Outlets (boundaries/outlets.hpp; engine/outlet_passes.cpp): particle i crossed outlet
  // `surface` at time t and is put back at a free place of its insertion region.
  void pass_outlet(std::uint32_t i, int surface, double t);
  // Whether particle i (its radius) fits at x at time t: inside every wall, apart from every
  // other particle.
  bool free_place(std::uint32_t i, const Vec<D>& x, double t);
  // Translational and rotational energy plus the field's potential energy -m g.x.
  double mechanical_energy(std::uint32_t i, double t) const;
  // What outlets cannot be combined with (InputError naming the keys).
  void check_outlets(const ParticleSystem<D>& s) const;
  // Walls with mass (boundaries/wall_body.hpp): a wall event predicted before the wall's
  // motion last changed is stale; when the plane enters a new layer of cells, every particle
  // it can now reach gets the contact as its event if that comes first (wall_moved).
  bool stale_wall_event(const PendingEvent& e) const {
    const int f = e.code.wall_face();
    return boundaries_.massive(f) && e.partner_count != boundaries_.event_version(f);
  }
  void wall_moved(int surface, double t);
  void check_massive_walls(const ParticleSystem<D>& s, StartMode mode) const;
  void change_wall_layer(double t);  // the next change, due at t
  // Walls moving towards each other left no room for the particles (FaceWalls::squeeze_time).
  [[noreturn]] void throw_squeezed(double t) const;
  // Sleeping particles (gravity with walls): see Environment::sleep_speed.
  bool is_asleep(std::uint32_t i) const { return resting_.asleep(i); }
  void add_virial_tensor(const Vec<D>& r, const Vec<D>& impulse);
  // A pair event's velocities before and after, for the Helfand moments (when helfand_.on()).
  void start_helfand();
  double helfand_energy(std::uint32_t k) const;
  void helfand_before(std::uint32_t i, std::uint32_t j, double t);
  void helfand_after(std::uint32_t i, std::uint32_t j, const Vec<D>& r);
  // A soft contact moves a pair's records at once (placement, release, deferral): the moments
  // follow through the jump, r = r_i - r_j from the records continued to t (minimum image).
  Vec<D> record_separation(std::uint32_t i, std::uint32_t j, double t) const;
  void helfand_jump_before(std::uint32_t i, std::uint32_t j, double t);
  void helfand_jump_after(std::uint32_t i, std::uint32_t j, double t);
  void fix_grains(bool moving_surfaces);
  void fall_asleep(std::uint32_t i, double t);
  void wake(std::uint32_t i, double t);
  // Leaves a resting contact (normal n, gravity into it) asleep or with at least the sleep
  // speed along n: no endless cascade of ever smaller bounces. Returns the energy added.
  // `again`: the particle is wedged (see wedged()): it stops.
  double settle_after_contact(std::uint32_t i, const Vec<D>& n, const Vec<D>& support_velocity,
                              double t, bool again);
  double spin_energy(std::uint32_t i) const;
  bool wedged(std::uint32_t i, double t) const;
  bool resting_on_support(std::uint32_t i, double t);
  void collide_with_sleeper(std::uint32_t i, std::uint32_t j, double t, const Vec<D>& r, double r2,
                            bool again);
  std::uint32_t scan_with_sleepers(const CandidateList& list, std::uint32_t i, double t,
                                   double& best) const;
  void resolve_pair(std::uint32_t i, std::uint32_t j, double t, const Vec<D>& r, double r2);
  void collide_granular(std::uint32_t i, std::uint32_t j, double t, const Vec<D>& r, double r2);
  void separate(std::uint32_t i, std::uint32_t j, const Vec<D>& r, double r2);
  double radius_of(std::uint32_t i) const {
    return radius_.empty() ? kinds_[kind_.empty() ? 0 : kind_[i]].radius : radius_[i];
  }
  // The pair's contact distance at time t (radii grow with growth_).
  double contact_distance(std::uint32_t i, std::uint32_t j, double t) const {
    return (radius_of(i) + radius_of(j)) * growth_.scale(t);
  }
  // The particle's radius at time t (it grows with growth_).
  double radius_at(std::uint32_t i, double t) const { return radius_of(i) * growth_.scale(t); }
  void start_growth();
  void check_growth_boundaries() const;
  void update_growth_limit();
  // Advances every particle to t, gives it new_velocity(k, its velocity at t), predicts all anew.
  template <class NewVelocity>
  void change_velocities(double t, NewVelocity&& new_velocity);
  // Two cell levels for a wide size distribution (EngineOptions::size_levels), if they apply;
  // `room`: the cells' width over the contact distance they must hold (growth).
  // `stored`: a resumed state's cells (by the caller's numbering), which decide.
  void plan_size_levels(double room, double cells_per_particle,
                        const std::vector<CellCode>* stored);
  // Particle i's candidates into `list` (cells_.gather_particle: its level's neighbourhood).
  void gather_of(std::uint32_t i, CandidateList& list) {
    if (cells_.two_level()) [[unlikely]] {
      cells_.gather_particle(i, hot_[i].cell, list, hot_.data());
    } else {
      gather(hot_[i].cell, list);
    }
  }
  double mass_of(std::uint32_t i) const { return kinds_[kind_.empty() ? 0 : kind_[i]].mass; }
  void advance_to(std::uint32_t i, double t);
  Crossing next_crossing(const HotRecord<D>& h) const;
  [[gnu::noinline]] Crossing next_crossing_general(const HotRecord<D>& h) const;
  [[gnu::noinline]] void advance_accelerated(HotRecord<D>& h, double t) const;
  double predict(std::uint32_t i, double t);
  double predict_from(const CandidateList& list, std::uint32_t i, double t);
  double conclude_prediction(std::uint32_t i, double t, const Crossing& crossing,
                             std::uint32_t partner, double best);
  double predict_asleep(const CandidateList& list, std::uint32_t i, double t);
  // Incremental crossings: after a crossing, only the new layer of cells is scanned and the
  // result is merged with the contact the last prediction kept beyond the crossing (see
  // cross()).
  // The contact kept with particle p, from time t (kNever if the pair now misses); false if
  // the kept contact cannot be used (p has moved out of the neighbourhood, sits in a deferred
  // soft contact or sleeps, or some periodic axis is only 3 cells wide): then the crossing
  // scans every neighbour.
  bool kept_contact_time(std::uint32_t i, std::uint32_t p, double t, double& dt) const;
  double predict_after_crossing(std::uint32_t i, double t, std::uint32_t kept, double kept_dt);
  // The end of a prediction that looked at every contact (`soonest`, from t, with `partner`,
  // kNoPartner if none): the contact if it comes before the crossing, else the crossing with
  // the contact kept as the one beyond it.
  double conclude_unbounded(std::uint32_t i, double t, const Crossing& crossing,
                            std::uint32_t partner, double soonest);
  // The candidates of the 3^D cells around `cell` (cells_.gather, or through the sliding
  // images next to a sheared face).
  void gather(CellCode cell, CandidateList& list);
  std::uint32_t test_candidates(const CandidateList& list, std::uint32_t i, double t,
                                const Vec<D>& xi, double& best) const;
  CandidateScan<D> scan_of(const CandidateList& list, std::uint32_t i,
                           std::uint32_t* delayed) const;
  void collide(std::uint32_t i, std::uint32_t j, double t);
  // Stepped potentials: the zones of all pairs at the start, the candidate loop, and a pair
  // event at a step (false: the pair meets its hard core, an ordinary collision).
  void init_zones(const ParticleSystem<D>& s, StartMode mode);
  std::uint32_t scan_stepped(const CandidateList& list, std::uint32_t i, double t, double& best);
  bool step_pair(std::uint32_t i, std::uint32_t j, double t);
  // The pair's separation i - j under the box's boundaries (nearest image on periodic axes).
  Vec<D> separation(std::uint32_t i, std::uint32_t j, double t) const;
  std::uint32_t scan_stepped_sheared(const CandidateList& list, std::uint32_t i, double t,
                                     double& best) const;
  void predict_pair(std::uint32_t i, std::uint32_t j, double t);
  // Lees-Edwards shear (boundaries/lees_edwards.hpp).
  void shift_images();
  void gather_sheared(CellCode cell, CandidateList& list);
  std::uint32_t scan_sheared(const CandidateList& list, std::uint32_t i, double t,
                             double& best) const;
  // Separation of i from the image of j it meets (and that image's extra velocity).
  Vec<D> sheared_separation(std::uint32_t i, std::uint32_t j, double t,
                            Vec<D>& image_velocity) const;
  void collide_sheared(std::uint32_t i, std::uint32_t j, double t);
  void cross_shear_face(std::uint32_t i, int side, double t, std::array<int, D>& c);
  std::array<bool, D> periodic_axes() const {
    std::array<bool, D> p;
    for (int a = 0; a < D; ++a) p[a] = cells_.grid().periodic(a);
    return p;
  }
  void cross(std::uint32_t i, double t);
  // Soft spheres (docs/physics.md#event-driven-soft-contacts; engine/soft_contacts.cpp).
  void setup_soft(const ParticleSystem<D>& s);
  void restore_frozen(const ParticleSystem<D>& s, StartMode mode);
  void collide_soft(std::uint32_t i, std::uint32_t j, double t);
  void hit_wall_soft(std::uint32_t i, int surface, double t);
  // A soft contact with a wall (hit_wall_soft): the wall's normal n into the domain, the
  // particle's speed towards it vn, the gap, the velocity while frozen against it; a box face
  // (axis >= 0) keeps its one-axis arithmetic and wall_speed, another surface its velocity.
  struct SoftWallContact {
    Vec<D> normal{}, wall_velocity{}, frozen{};
    double vn = 0.0, gap = 0.0, wall_speed = 0.0;
    int axis = -1;
  };
  SoftWallContact soft_wall_contact(std::uint32_t i, int surface, double t) const;
  Vec<D> soft_wall_rebound(std::uint32_t i, const SoftWallContact& c, double e, double& work) const;
  // Gives the contact particle i is frozen in its post-contact velocities at time t (early:
  // before its release time, exception B). Returns the partner (a particle, whose prediction
  // is now the caller's business, or a wall code), kNoPartner if i is not frozen.
  std::uint32_t release(std::uint32_t i, double t, bool early);
  void release_event(std::uint32_t i, double t);
  // Deferred releases: the pair (or particle and wall) already moves as after the contact in its
  // record, whose local time is the release time; until then it is frozen (frozen_velocity_of).
  // Only its partner and deferred flag are written for it (release times and velocities
  // belong to frozen contacts with release events).
  // Only such a record has a local time after the present.
  bool in_deferred_contact(std::uint32_t i, double t) const {
    return soft_state_.defers() && t < hot_[i].time;
  }
  // In a soft contact now (frozen, or deferred and not yet over).
  bool in_soft_contact(std::uint32_t k) const;
  // A pair contact frozen at `velocity` until `until` (see try_place). With `predict` (a contact
  // that may be deferred), try_place also finds each particle's soonest event after the release
  // (post-contact velocity after[k], k = 0 for i, 1 for j): partner and time from t.
  struct FrozenWindow {
    Vec<D> velocity{};
    double until = 0.0;
    bool met = false;
    bool predict = false;
    Vec<D> after[2] = {};
    Crossing crossing[2] = {};
    std::uint32_t partner[2] = {EventSlot::kNoPartner, EventSlot::kNoPartner};
    double best[2] = {};
  };
  // Tries to defer the release of the placed pair i, j (frozen at window.velocity from time t
  // until window.until, then at window.after; try_place found no third body meeting it and
  // predicted both): true when the frozen path stays in its cells, meets no wall and both
  // events come after the release; then both are scheduled.
  bool try_defer(std::uint32_t i, std::uint32_t j, double t, const FrozenWindow& window);
  // The exact event time of particle i (at xi, vi at time t) with candidates in deferred
  // contacts (skipped by the loops): the contact while frozen, else after the release.
  // `count` of them, listed in list.delayed by the loop.
  // Events before `from` are not looked for (a particle at the start of its own deferred
  // contact moves as xi, vi say only from its release on).
  std::uint32_t scan_deferred(const CandidateList& list, std::uint32_t count, std::uint32_t i,
                              double t, const Vec<D>& xi, const Vec<D>& vi, double from,
                              double& best) const;
  // The centre-of-mass velocity of a deferred pair (its frozen motion), from the records after
  // the release: the same bits for both particles (summed in index order).
  Vec<D> frozen_velocity_of(std::uint32_t k) const {
    const std::uint32_t p = soft_state_.partner(k);
    const std::uint32_t a = std::min(k, p), b = std::max(k, p);
    const double ma = mass_of(a), mb = mass_of(b);
    return (1.0 / (ma + mb)) * (ma * hot_[a].vel + mb * hot_[b].vel);
  }
  double deferred_contact_energy() const;
  // A deferred pair's sum m |v - V|^2: what its records' kinetic trace holds beyond the frozen
  // motion until the release (the Helfand moments' temperature, helfand_moments.hpp).
  double deferred_excess(std::uint32_t i, std::uint32_t p) const {
    const Vec<D> v = frozen_velocity_of(i);
    return mass_of(i) * norm2(hot_[i].vel - v) + mass_of(p) * norm2(hot_[p].vel - v);
  }
  // The map from the table, or integrated directly outside it (counted).
  CollisionMap soft_map(const SoftMapTable* table, const CollisionUnits& units);
  // Places i at xi (and j at xj, unless j is kNoPartner) at time t unless that overlaps a third
  // particle or a wall (other than surface skip_surface; exception A): then nothing changes and the
  // result is false. Placed, the neighbourhoods of i and j are left gathered in cells_.list(0) and
  // (unless `shared`, one cell) cells_.list(1).
  // With a window, also sets window->met if a third particle meets the pair, frozen at
  // window->velocity, before window->until (and predicts, see FrozenWindow).
  bool try_place(std::uint32_t i, const Vec<D>& xi, std::uint32_t j, const Vec<D>& xj, double t,
                 int skip_surface, bool& shared, FrozenWindow* window = nullptr);
  // Moves particle i into the cell of its (changed) position.
  void relocate(std::uint32_t i);
  bool frozen_pair(std::uint32_t i, std::uint32_t j) const {
    return soft_ && soft_state_.partner(i) == j && soft_state_.partner(j) == i &&
           (!soft_state_.deferred(i) || in_deferred_contact(i, time_));
  }
  void renumber(bool queue_filled);
  ParticleSystem<D> export_globals(bool with_zones) const;
  struct BlockOrder {
    std::vector<std::uint32_t> members;  // internal indices, block by block
    std::vector<std::uint32_t> start;    // block b's members: [start[b], start[b + 1])
  };
  // Built at the first output of a moment (4 bytes per particle), kept until the next
  // renumbering or release_block_order().
  const BlockOrder& block_order() const;
  Vec<D> wrapped_position_now(std::uint32_t k) const;
  mutable std::shared_ptr<const BlockOrder> block_order_;
  void size_particle_arrays(ParticleSystem<D>& out, std::size_t n) const;
  void export_particle(std::uint32_t k, std::uint32_t c, ParticleSystem<D>& out,
                       unsigned fields) const;
  void check_restored_cell(std::uint32_t i) const;
  std::uint64_t next_renumber_after(std::uint64_t collisions) const;

  Vec<D> box_{};
  double time_ = 0.0;
  EventCounters counters_;
  std::vector<std::string> species_names_;
  EngineOptions options_;

  HugeVector<HotRecord<D>> hot_;
  HugeVector<PendingEvent> pending_;
  // Incremental crossings (see cross()): on unless a feature needs every crossing's full scan.
  bool incremental_crossings_ = false;
  bool three_cell_axis_ = false;    // some periodic axis is 3 cells wide: kept contacts unused
  HugeVector<std::uint16_t> kind_;  // per particle; empty when there is a single kind
  std::vector<ParticleKind> kinds_;
  bool uniform_radius_ = true;
  std::vector<double> kind_radius_;  // radius per kind, for the candidate loops
  // Per particle (EngineOptions::per_particle_radii), else empty; then a kind's radius is the
  // largest of its particles'.
  HugeVector<double> radius_;
  bool vector_scan_ = false;
  bool vector_gather_ = false;        // gather_lists_avx512 for the cell lists (cpu_gathers_fast)
  bool row_loads_ = false;            // CandidateScan::row_loads (RecordLoads, cpu_gathers_fast)
  HugeVector<std::uint32_t> id_;      // internal index -> the caller's particle number
  bool accelerated_ = false;          // uniform gravity
  bool vector_growing_ = false;       // the growing loop in AVX-512
  bool records_fit_32_bits_ = false;  // the vector loops index records with 32-bit offsets
  // plan_size_levels's room and cells per particle when two levels may apply (0: they do not).
  double levels_room_ = 0.0, levels_cells_per_particle_ = 0.0;
  bool growing_ = false;  // growth_.on(): growing particles
  Vec<D> half_gravity_{};
  bool walls_ = false;                   // boundaries_.any()
  bool massive_walls_ = false;           // some face wall has mass
  bool outlets_ = false;                 // some surface is an outlet (boundaries_.any_passes())
  bool bounded_ = false;                 // some axis has walls or open faces
  bool granular_contacts_ = false;       // some contact law is not elastic and smooth
  HugeVector<AngularVelocity<D>> spin_;  // rough particles only
  HugeVector<double> last_collision_;    // TC model only
  using Resting = RestingParticles<D>;
  Resting resting_;  // who sleeps (gravity with walls only; engine/resting_particles.hpp)
  Queue queue_;
  std::uint64_t renumber_period_ = 0, next_renumber_ = 0;  // in collisions
  bool sheared_ = false;                                   // shear_.on()
  bool stepped_ = false;  // some pair has a step potential, or there are bonds
  // The cell grid and the neighbourhood walk (engine/cell_neighbourhood.hpp); its large
  // candidate lists come last in it, so the hot members above share fewer cache lines.
  Cells cells_;
  PairSteps steps_;
  std::uint64_t step_captures_ = 0;      // see step_captures()
  std::uint64_t incremental_scans_ = 0;  // see incremental_crossing_scans()
  SteppedScanScratch step_scratch_;      // scan_stepped's
  std::vector<Bond> bonds_;              // the caller's numbering, kept for export
  std::vector<std::string> bond_types_;

  // Soft spheres: the contacts in progress (engine/soft_contact_state.hpp; empty unless soft_).
  bool soft_ = false;
  SoftContactState<D> soft_state_;

  Boundaries<D> boundaries_;  // every wall (model/boundaries.hpp: the face walls so far)
  LeesEdwards<D> shear_;      // Lees-Edwards images (boundaries/lees_edwards.hpp)
  Environment<D> env_;        // the hot members above share fewer cache lines
  ImageCounters<D> images_;   // cold: written at wraps, read at export
  // wake()'s lists, kept so that a wake allocates nothing.
  struct WakeScratch {
    std::vector<std::uint32_t> woken, touching;
  } wake_scratch_;
  HelfandMoments<D> helfand_;  // cold: pair events only, when a transport analysis asks
  Growth growth_;              // growing particles (compression) only
  double growth_fits_until_ = kNever;
};

// Small members every event path uses, visible to each of the engine's files.

template <int D, class Queue>
inline void EventEngine<D, Queue>::advance_to(std::uint32_t i, double t) {
  HotRecord<D>& h = hot_[i];
  if (accelerated_) [[unlikely]] {
    if (is_asleep(i)) {
      h.time = t;  // it does not move
    } else {
      advance_accelerated(h, t);
    }
    return;
  }
  const double dt = t - h.time;
  for (int a = 0; a < D; ++a) h.pos[a] += h.vel[a] * dt;
  h.time = t;
}

// Where a record's particle is at time t: a straight line, or a parabola under gravity. The
// candidate loops evaluate the same expressions in the same order.
template <int D, class Queue>
inline Vec<D> EventEngine<D, Queue>::flight_position(const HotRecord<D>& h, double t) const {
  const double dt = t - h.time;
  Vec<D> x;
  for (int a = 0; a < D; ++a) {
    x[a] = h.pos[a] + h.vel[a] * dt;
    if (accelerated_) x[a] = x[a] + (half_gravity_[a] * dt) * dt;
  }
  return x;
}

template <int D, class Queue>
inline Vec<D> EventEngine<D, Queue>::flight_velocity(const HotRecord<D>& h, double t) const {
  if (!accelerated_) return h.vel;
  const double dt = t - h.time;
  Vec<D> v;
  for (int a = 0; a < D; ++a) v[a] = h.vel[a] + env_.gravity[a] * dt;
  return v;
}

template <int D, class Queue>
inline void EventEngine<D, Queue>::add_virial_tensor(const Vec<D>& r, const Vec<D>& impulse) {
  for (int a = 0; a < D; ++a)
    for (int b = 0; b < D; ++b) counters_.virial_tensor[a * D + b] += r[a] * impulse[b];
}

template <int D, class Queue>
inline double EventEngine<D, Queue>::helfand_energy(std::uint32_t k) const {
  return helfand_.energy(k, mass_of(k), hot_[k].vel, spin_.empty() ? 0.0 : spin_energy(k));
}

template <int D, class Queue>
inline void EventEngine<D, Queue>::helfand_before(std::uint32_t i, std::uint32_t j, double t) {
  helfand_.before_pair(t, mass_of(i), hot_[i].vel, helfand_energy(i), mass_of(j), hot_[j].vel,
                       helfand_energy(j));
}

template <int D, class Queue>
inline Vec<D> EventEngine<D, Queue>::record_separation(std::uint32_t i, std::uint32_t j,
                                                       double t) const {
  const HotRecord<D>& hi = hot_[i];
  const HotRecord<D>& hj = hot_[j];
  Vec<D> r;
  for (int a = 0; a < D; ++a) {
    const double raw =
        (hi.pos[a] + (t - hi.time) * hi.vel[a]) - (hj.pos[a] + (t - hj.time) * hj.vel[a]);
    r[a] = !bounded_ || cells_.grid().periodic(a) ? minimum_image(raw, box_[a]) : raw;
  }
  return r;
}

template <int D, class Queue>
inline void EventEngine<D, Queue>::helfand_jump_before(std::uint32_t i, std::uint32_t j, double t) {
  helfand_.before_jump(t, record_separation(i, j, t), mass_of(i), hot_[i].vel, helfand_energy(i),
                       mass_of(j), hot_[j].vel, helfand_energy(j), counters_.virial_tensor);
}

template <int D, class Queue>
inline void EventEngine<D, Queue>::helfand_jump_after(std::uint32_t i, std::uint32_t j, double t) {
  helfand_.after_jump(record_separation(i, j, t), mass_of(i), hot_[i].vel, helfand_energy(i),
                      mass_of(j), hot_[j].vel, helfand_energy(j), counters_.virial_tensor);
}

template <int D, class Queue>
inline void EventEngine<D, Queue>::helfand_after(std::uint32_t i, std::uint32_t j,
                                                 const Vec<D>& r) {
  helfand_.after_pair(r, mass_of(i), hot_[i].vel, helfand_energy(i), mass_of(j), hot_[j].vel,
                      helfand_energy(j));
}

// New events for both partners of a collision. Both neighbourhoods are gathered (and their
// records prefetched) before either is tested; partners in one cell share one list.
template <int D, class Queue>
inline void EventEngine<D, Queue>::predict_pair(std::uint32_t i, std::uint32_t j, double t) {
  gather_of(i, cells_.list(0));
  const bool shared = hot_[j].cell == hot_[i].cell && cells_.big(i) == cells_.big(j);
  if (!shared) gather_of(j, cells_.list(1));
  queue_.update(i, predict_from(cells_.list(0), i, t));
  queue_.update(j, predict_from(cells_.list(shared ? 0 : 1), j, t));
}

}  // namespace kairos
