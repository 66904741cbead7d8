#include "engine/event_engine.hpp"

#include <emmintrin.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <tuple>

#include "core/error.hpp"
#include "core/periodic.hpp"
#include "core/permutation.hpp"
#include "core/release_pages.hpp"
#include "dynamics/collision_time.hpp"
#include "dynamics/trajectory_events.hpp"
#include "engine/candidate_scan.hpp"
#include "engine/size_levels.hpp"
#include "interactions/granular_contact.hpp"
#include "interactions/hard_sphere.hpp"
#include "scheduler/binary_heap_queue.hpp"
#include "scheduler/calendar_queue.hpp"
#include "scheduler/tournament_tree_queue.hpp"

namespace kairos {

namespace {
constexpr std::uint32_t kNoPartner = EventSlot::kNoPartner;

}  // namespace

template <int D, class Queue>
EventEngine<D, Queue>::EventEngine(ParticleSystem<D> s, StartMode mode, EngineOptions options,
                                   const Environment<D>& environment)
    : box_(s.box),
      time_(s.time),
      counters_(s.counters),
      species_names_(s.species_names),
      options_(options),
      env_(environment) {
  const std::size_t n = s.size();
  if (n < 2) throw InputError("a simulation needs at least 2 particles");
  if (n > Code::kMaxParticles)
    throw InputError("too many particles (at most " + std::to_string(Code::kMaxParticles) + ")");
  if (s.mass.size() != n || s.species.size() != n) {
    throw InputError("the state needs a mass and a species for every particle");
  }
  build_kinds(s);
  std::vector<double>().swap(s.mass);  // in kinds_ now
  std::vector<std::uint32_t>().swap(s.species);
  bonds_ = s.bonds;
  bond_types_ = s.bond_types;
  // The vector loop indexes records with 32-bit offsets.
  records_fit_32_bits_ = static_cast<double>(n) * sizeof(HotRecord<D>) < 2e9;
  vector_scan_ =
      options_.vector_scan && cpu_has_avx512() && records_fit_32_bits_ && radius_.empty();
  vector_gather_ =
      vector_scan_ && (options_.list_gather == ListGather::kVector ||
                       (options_.list_gather == ListGather::kAuto && cpu_gathers_fast()));
  row_loads_ =
      vector_scan_ && (options_.record_loads == RecordLoads::kRows ||
                       (options_.record_loads == RecordLoads::kAuto && !cpu_gathers_fast()));
  setup_environment(s);
  setup_soft(s);
  if (massive_walls_) check_massive_walls(s, mode);
  if (outlets_) check_outlets(s);
  if (options_.growth_rate != 0.0) start_growth();

  // Internal numbering: the stored one when resuming, else the caller's (renumbered below).
  id_.resize(n);
  std::iota(id_.begin(), id_.end(), 0u);
  if (mode == StartMode::kResume && !s.order.empty()) {
    std::vector<char> seen(n, 0);
    bool ok = s.order.size() == n;
    for (std::size_t k = 0; ok && k < n; ++k) {
      ok = s.order[k] < n && !seen[s.order[k]];
      if (ok) seen[s.order[k]] = 1;
    }
    if (!ok) throw InputError("cannot resume: the stored particle order is not a permutation");
    id_.assign(s.order.begin(), s.order.end());
  }
  HugeVector<std::uint16_t> kind_by_id = std::move(kind_);
  if (!kind_by_id.empty()) {
    kind_.resize(n + 1);  // one spare entry: the vector loop reads kinds 4 bytes at a time
    for (std::size_t k = 0; k < n; ++k) kind_[k] = kind_by_id[id_[k]];
  }
  if (!radius_.empty()) {
    HugeVector<double> radius_by_id = std::move(radius_);
    radius_.resize(n);
    for (std::size_t k = 0; k < n; ++k) radius_[k] = radius_by_id[id_[k]];
  }
  for (const ParticleKind& sh : kinds_) kind_radius_.push_back(sh.radius);
  const bool has_counts = s.collision_count.size() == n;
  // Each record written once (reserve: no page touched before); read in the caller's order (a
  // fresh start), the state's pages are released as they are read.
  const bool in_order = mode != StartMode::kResume || s.order.empty();
  hot_.reserve(n);
  for (std::uint32_t k = 0; k < n; ++k) {
    const Kinematics<D>& kin = s.kinematics[id_[k]];
    hot_.push_back({kin.pos, kin.vel, kin.time, has_counts ? s.collision_count[id_[k]] : 0u, 0u});
    if (in_order) release_read_front(s.kinematics.data(), k + 1);
  }
  // Read (kinds_ hold the radii): released before the queue and the renumbering take their
  // memory (docs/performance.md, "Memory").
  std::vector<Kinematics<D>>().swap(s.kinematics);
  if (levels_room_ > 0.0) {
    plan_size_levels(levels_room_, levels_cells_per_particle_,
                     mode == StartMode::kResume && s.cell.size() == n ? &s.cell : nullptr);
    if (cells_.two_level()) {
      // A crossing rescans the whole neighbourhood: the coarse cell may change, and a big
      // particle's new layer is a slab of its block.
      incremental_crossings_ = false;
      if (growing_) update_growth_limit();
    }
  }
  restore_frozen(s, mode);
  // Spins are tracked when contacts can change them, or when the state carries them.
  if (env_.rotates() || !s.angular_velocity.empty()) {
    if (!s.angular_velocity.empty() && s.angular_velocity.size() != n) {
      throw InputError("the state has angular velocities for some particles but not all");
    }
    spin_.assign(n, AngularVelocity<D>{});
    if (!s.angular_velocity.empty())
      for (std::uint32_t k = 0; k < n; ++k) spin_[k] = s.angular_velocity[id_[k]];
  }
  if (options_.track_images || !s.image.empty()) {
    images_ = ImageCounters<D>(n);
    images_.restore(s.image, id_);
  }
  // Sleepers predict no events of their own, so a wall moving along its normal (vibrating or a
  // piston) could move into one unseen: then nothing sleeps (resting piles need the TC model).
  const bool moving = boundaries_.any_surface_moves();
  if (stepped_ && env_.sleep_speed > 0.0) {
    throw InputError(
        "contact.sleep_speed: resting particles cannot sleep under stepped potentials (a "
        "sleeper would miss its steps); set it to 0");
  }
  // Fixed grains are supports too: a floor of them sleeps grains without a wall.
  if (accelerated_ && (walls_ || env_.has_fixed_grains()) && !moving && !stepped_) {
    double dmin = kNever;
    for (const ParticleKind& sh : kinds_) dmin = std::min(dmin, 2.0 * sh.radius);
    for (const double r : radius_) dmin = std::min(dmin, 2.0 * r);
    const double speed = Resting::speed_for(env_.sleep_speed, env_.gravity, dmin);
    if (speed > 0.0) {
      resting_ = Resting(n, speed, env_.gravity);
      resting_.restore(s.asleep, id_);
      for (std::uint32_t k = 0; k < n; ++k)
        if (resting_.asleep(k)) hot_[k].vel = Vec<D>{};
    }
  }
  if (env_.has_fixed_grains()) fix_grains(moving);
  if (env_.tc > 0.0) {
    last_collision_.assign(n, -kNever);
    if (s.last_collision_time.size() == n)
      for (std::uint32_t k = 0; k < n; ++k) last_collision_[k] = s.last_collision_time[id_[k]];
  }
  std::vector<double> times(n);
  pending_.assign(n, {Code::crossing(), 0});
  if (mode == StartMode::kResume) {
    if (s.events.size() != n || s.cell.size() != n || !has_counts) {
      throw InputError("cannot resume: the state carries no scheduler state (events, cells)");
    }
    std::vector<std::uint32_t> internal(n);
    for (std::uint32_t k = 0; k < n; ++k) internal[id_[k]] = k;
    for (std::uint32_t k = 0; k < n; ++k) {
      const EventSlot& e = s.events[id_[k]];
      if (std::isnan(e.time) || e.time < time_) {
        throw InputError("cannot resume: the pending event of particle " + std::to_string(id_[k]) +
                         " is not at or after the state's time");
      }
      if (!Code::valid_bits(e.partner, static_cast<std::uint32_t>(n))) {
        throw InputError("cannot resume: particle " + std::to_string(id_[k]) +
                         " has an event partner code out of range");
      }
      const Code code =
          Code::from_bits(e.partner).renumbered([&](std::uint32_t p) { return internal[p]; });
      pending_[k] = {code, e.partner_count};
      // Files written with incremental crossings resumed without them: full scans.
      if (!incremental_crossings_ && code.is_crossing()) pending_[k] = {Code::crossing(), 0};
      times[k] = e.time;
      hot_[k].cell = s.cell[id_[k]];
      check_restored_cell(k);
    }
    cells_.insert_all(hot_.data(), static_cast<std::uint32_t>(size()));
    init_zones(s, mode);
  } else {
    for (std::uint32_t k = 0; k < n; ++k) {
      advance_to(k, time_);
      for (int a = 0; a < D; ++a) {
        if (!cells_.grid().periodic(a)) continue;
        const double x = hot_[k].pos[a];
        hot_[k].pos[a] = wrap_into_box(x, box_[a]);
        if (images_.on()) images_.wrapped(k, a, x, hot_[k].pos[a], box_[a]);
      }
      hot_[k].cell = cells_.grid().locate(hot_[k].pos);
      if (walls_ && !(soft_ && soft_state_.partner(k) != kNoPartner))  // a soft contact: pressed in
        boundaries_.check_start(hot_[k].pos, radius_of(k), time_, id_[k]);
    }
    if (options_.renumber_interval > 0.0) {
      renumber(/*queue_filled=*/false);  // fills the grid in the new numbering
    } else {
      cells_.insert_all(hot_.data(), static_cast<std::uint32_t>(size()));
    }
    init_zones(s, mode);
    for (std::uint32_t k = 0; k < n; ++k) times[k] = predict(k, time_);
  }
  queue_.reset(times);
  renumber_period_ =
      options_.renumber_interval > 0.0
          ? std::max<std::uint64_t>(1, static_cast<std::uint64_t>(options_.renumber_interval *
                                                                  static_cast<double>(n) / 2.0))
          : 0;
  next_renumber_ = next_renumber_after(counters_.collisions);
  if (options_.track_helfand) start_helfand();
}

// Fixed grains (docs/physics.md#fixed-grains): the particles of a fixed species become sleepers
// that never wake. They must start at rest, and the features whose rules would move them or
// that a resting particle would miss are refused.
template <int D, class Queue>
void EventEngine<D, Queue>::fix_grains(bool moving_surfaces) {
  const auto refuse = [](const std::string& what) {
    throw InputError("fixed grains (a species with fixed = true) cannot be combined with " + what);
  };
  if (soft_) refuse("soft spheres (soft.model)");
  if (stepped_) refuse("stepped potentials or bonds (a fixed grain would miss its steps)");
  if (sheared_) refuse("Lees-Edwards shear (boundary.shear_rate)");
  if (moving_surfaces) {
    refuse(
        "a wall that moves along its normal (a piston or a vibration): a fixed grain "
        "predicts no events of its own and would not see it coming");
  }
  const auto n = static_cast<std::uint32_t>(size());
  if (resting_.count() == 0 && !resting_.on()) resting_ = Resting(n, 0.0, env_.gravity);
  for (std::uint32_t k = 0; k < n; ++k) {
    if (!env_.fixed_species(species_of(k))) continue;
    const bool spins = !spin_.empty() && norm2(spin_[k]) != 0.0;
    if (norm2(hot_[k].vel) != 0.0 || spins) {
      throw InputError("particle " + std::to_string(id_[k]) +
                       " belongs to a fixed species (species " + std::to_string(species_of(k)) +
                       ") but " + (spins ? "rotates" : "has a velocity") +
                       ": a fixed grain starts at rest");
    }
    resting_.fix(k);
  }
  if (resting_.fixed_count() == n)
    throw InputError("every particle belongs to a fixed species: nothing would move");
}

// The Helfand moments from now (engine/helfand_moments.hpp): the centre of mass's velocity,
// each particle's share of its pairs' energies (half of each listed pair's zone energy), then
// every particle's rates.
template <int D, class Queue>
void EventEngine<D, Queue>::start_helfand() {
  const auto n = static_cast<std::uint32_t>(size());
  Vec<D> momentum{};
  double total = 0.0;
  for (std::uint32_t k = 0; k < n; ++k) {
    momentum = momentum + mass_of(k) * hot_[k].vel;
    total += mass_of(k);
  }
  helfand_.start(time_, (1.0 / total) * momentum, n);
  for (std::uint32_t k = 0; stepped_ && k < n; ++k) {
    const PairSteps::Entry* e = steps_.entries_begin(k);
    for (std::uint32_t m = 0; m < steps_.entry_count(k); ++m)
      helfand_.add_potential_share(k, 0.5 * steps_.table(e[m].zone.table).energy[e[m].zone.zone]);
  }
  // A frozen soft contact holds its relative kinetic energy until its release (the share
  // helfand_moments.hpp gives it; deferred contacts' records move as after the release).
  // The contacts in progress are counted as frozen pairs for the rest of their time.
  for (std::uint32_t k = 0; soft_ && k < n; ++k) {
    const std::uint32_t p = soft_state_.partner(k);
    if (!is_particle(p)) continue;
    if (soft_state_.awaits_release(k)) {
      const Vec<D>& after = soft_state_.release_velocity(k);
      helfand_.set_share(k, 0.5 * mass_of(k) * norm2(after - hot_[k].vel));
      if (k < p) helfand_.frozen_pair_for(soft_state_.release_time(k) - time_);
    } else if (in_deferred_contact(k, time_) && k < p) {
      const double rest = hot_[k].time - time_;
      helfand_.frozen_pair_for(rest);
      helfand_.records_ahead(deferred_excess(k, p), rest);
    }
  }
  // Velocities are constant in free flight (no field here): no record is advanced, so the
  // run's bits do not depend on whether the moments are kept.
  for (std::uint32_t k = 0; k < n; ++k)
    helfand_.add_particle(mass_of(k), hot_[k].vel, helfand_energy(k));
}

// Distinct (radius, mass, species) triples; particles store a 2-byte index into them. More
// than 65 536 of them (a continuous size distribution), or when asked: each particle keeps its
// radius, and the kinds are the (mass, species) pairs, with the largest radius of each.
template <int D, class Queue>
void EventEngine<D, Queue>::build_kinds(const ParticleSystem<D>& s) {
  for (std::size_t i = 0; i < s.size(); ++i) {
    const double r = s.kinematics[i].radius, m = s.mass[i];
    if (!(r > 0.0) || !std::isfinite(r) || !(m > 0.0) || !std::isfinite(m)) {
      throw InputError("particle " + std::to_string(i) +
                       " needs a finite positive radius and mass");
    }
  }
  bool per_particle = options_.per_particle_radii;
  if (!per_particle && !index_kinds(s, /*with_radius=*/true)) per_particle = true;
  if (per_particle) {
    kinds_.clear();
    if (!index_kinds(s, /*with_radius=*/false)) {
      throw InputError(
          "more than 65536 distinct (mass, species) combinations: Kairos keeps a 2-byte kind "
          "index per particle; use fewer distinct masses");
    }
    radius_.resize(s.size());  // the caller's numbering; permuted by the caller
    for (std::size_t i = 0; i < s.size(); ++i) radius_[i] = s.kinematics[i].radius;
    uniform_radius_ = false;
    return;
  }
  uniform_radius_ = std::all_of(kinds_.begin(), kinds_.end(), [&](const ParticleKind& sh) {
    return sh.radius == kinds_[0].radius;
  });
}

// Fills kinds_ and kind_ by (radius, mass, species), or by (mass, species) with each kind's
// largest radius; false (kinds_ partly filled) when there would be more than 65 536.
template <int D, class Queue>
bool EventEngine<D, Queue>::index_kinds(const ParticleSystem<D>& s, bool with_radius) {
  std::map<std::tuple<double, double, std::uint32_t>, std::uint16_t> index;
  HugeVector<std::uint16_t> kind(s.size());
  for (std::size_t i = 0; i < s.size(); ++i) {
    const double r = s.kinematics[i].radius, m = s.mass[i];
    const auto key = std::make_tuple(with_radius ? r : 0.0, m, s.species[i]);
    auto it = index.find(key);
    if (it == index.end()) {
      if (kinds_.size() == 0x10000) return false;
      it = index.emplace(key, static_cast<std::uint16_t>(kinds_.size())).first;
      kinds_.push_back({r, m, s.species[i]});
    }
    kind[i] = it->second;
    kinds_[it->second].radius = std::max(kinds_[it->second].radius, r);
  }
  kind_.clear();
  if (kinds_.size() > 1) kind_ = std::move(kind);  // caller's numbering; permuted by caller
  return true;
}

// Checks the environment against the particles and sizes the cell grid for it: periodic axes
// need 3 cells; along a wall axis, only the outer layer may touch a fixed or vibrating wall
// (cells at least a diameter plus the vibration amplitude wide; a piston reaches any layer).
template <int D, class Queue>
void EventEngine<D, Queue>::setup_environment(const ParticleSystem<D>& s) {
  env_.check();
  std::uint32_t species = 1;
  for (const ParticleKind& sh : kinds_) species = std::max(species, sh.species + 1);
  if (!env_.contact.empty() && env_.species < species) {
    throw InputError("the contact laws cover " + std::to_string(env_.species) +
                     " species but particles use " + std::to_string(species));
  }
  if (!env_.inertia_factor.empty() && env_.inertia_factor.size() < species) {
    throw InputError("an inertia factor is needed for each of the " + std::to_string(species) +
                     " species");
  }
  accelerated_ = env_.has_gravity();
  half_gravity_ = 0.5 * env_.gravity;
  boundaries_ = Boundaries<D>(env_, box_);
  if (boundaries_.surfaces() > Code::kWallCodes) {
    throw std::logic_error(
        "the boundary registry has more surfaces than EventCode has wall codes: widen them "
        "first (docs/extending.md, \"Adding a boundary geometry\")");
  }
  walls_ = boundaries_.any();
  granular_contacts_ = !env_.plain() || env_.tc > 0.0;
  double rmax = 0.0;
  for (const ParticleKind& sh : kinds_) rmax = std::max(rmax, sh.radius);
  if (!bonds_.empty() && env_.bond_table.empty())
    throw InputError("the state has bonds but no bond potential is given ([bond])");
  stepped_ = env_.stepped();
  double range = 2.0 * rmax;
  if (stepped_ && !radius_.empty()) {
    throw InputError(
        "stepped potentials need the particles' diameters as at most 65536 distinct values (one "
        "step table per pair of kinds); this state has more");
  }
  if (stepped_) {
    if (!env_.pair_table.empty() && env_.species < species) {
      throw InputError("the step potentials cover " + std::to_string(env_.species) +
                       " species but particles use " + std::to_string(species));
    }
    steps_ = PairSteps(env_.tables, env_.pair_table, env_.species, s.size());
    // Pairs interact up to the largest cut-off: neighbouring cells must hold every such pair.
    range = std::max(range, steps_.max_range());
  }
  Vec<D> min_width;
  std::array<bool, D> periodic;
  for (int a = 0; a < D; ++a) {
    periodic[a] = env_.periodic(a);
    min_width[a] = std::max(range, options_.min_cell_width);
  }
  // A box with walls or open faces is often mostly empty (a bed under open headroom, a pile):
  // the cap on cells per particle, meant to bound memory, would make the occupied cells wide.
  const bool bounded = std::find(periodic.begin(), periodic.end(), false) != periodic.end();
  const double cells_per_particle =
      bounded ? std::max(options_.max_cells_per_particle, kBoundedCellsPerParticle)
              : options_.max_cells_per_particle;
  cells_ =
      Cells(CellGrid<D>(box_, min_width, periodic, s.size(), cells_per_particle), vector_gather_);
  bounded_ = bounded;
  // Two cell levels are planned once the particles are read (plan_size_levels).
  if (options_.size_levels && !bounded && !walls_ && !stepped_ && bonds_.empty() &&
      !env_.soft_spheres() && env_.shear_rate == 0.0 && !env_.has_fixed_grains()) {
    levels_room_ = std::max(1.0, options_.min_cell_width / range);
    levels_cells_per_particle_ = cells_per_particle;
  }
  shear_ = LeesEdwards<D>(env_.shear_rate, box_, cells_.grid(), time_);
  sheared_ = shear_.on();
  double particle_volume = 0.0;
  for (const Kinematics<D>& k : s.kinematics) particle_volume += ball_volume<D>(k.radius);
  boundaries_.prepare(cells_.grid(), rmax, particle_volume, uniform_radius_);
  massive_walls_ = boundaries_.any_massive();
  outlets_ = boundaries_.any_passes();
  boundaries_.restore(s.wall_motion, time_);
  if (time_ >= boundaries_.squeeze_time()) throw_squeezed(time_);
  // Shear (sliding images) and steps (zones) keep full scans.
  incremental_crossings_ = options_.incremental_crossings && !stepped_ && !sheared_;
  for (int a = 0; a < D; ++a)
    three_cell_axis_ =
        three_cell_axis_ || (cells_.grid().periodic(a) && cells_.grid().cells_along(a) == 3);
}

template <int D, class Queue>
void EventEngine<D, Queue>::throw_squeezed(double t) const {
  double dmax = 0.0;
  for (const ParticleKind& sh : kinds_) dmax = std::max(dmax, 2.0 * sh.radius);
  boundaries_.throw_squeezed(t, dmax, uniform_radius_);
}

// A restored cell must exist and contain the particle's position (up to round-off): a damaged
// file, or one from a build with another grid sizing, must not silently mean other cells.
template <int D, class Queue>
void EventEngine<D, Queue>::check_restored_cell(std::uint32_t i) const {
  const CellCode c = hot_[i].cell;
  bool ok = cells_.grid().valid(c);
  for (int a = 0; ok && a < D; ++a) {
    const double x = hot_[i].pos[a];
    const double tol = 1e-9 * box_[a];
    ok = x >= cells_.grid().lower_bound(c, a) - tol && x <= cells_.grid().upper_bound(c, a) + tol;
  }
  if (!ok) {
    throw InputError("restart state is inconsistent: particle " + std::to_string(id_[i]) +
                     " is not inside its stored cell " + std::to_string(c) +
                     " (a file written on two cell levels continues only with run.size_levels = "
                     "true)");
  }
}

template <int D, class Queue>
std::uint64_t EventEngine<D, Queue>::next_renumber_after(std::uint64_t collisions) const {
  if (renumber_period_ == 0) return ~std::uint64_t{0};
  return (collisions / renumber_period_ + 1) * renumber_period_;
}

// Renumbers particles along the Morton order of their cells, so that the members of
// neighbouring cells sit close together in memory. Partners, ids, kinds and queue keys follow;
// the caller's numbering stays available through id_.
template <int D, class Queue>
void EventEngine<D, Queue>::renumber(bool queue_filled) {
  const auto n = static_cast<std::uint32_t>(size());
  block_order_.reset();  // id_ changes
  // order[k]: the present index of the particle that moves to k, sorted by (Morton rank of its
  // cell, present index). In place, with 16 bytes per particle of scratch at most: the arrays
  // are not copied (docs/performance.md, "Memory").
  std::vector<std::uint32_t> order(n);
  {
    std::uint64_t top = 0;
    for (std::uint32_t k = 0; k < n; ++k)
      top = std::max(top, cells_.grid().morton_rank(hot_[k].cell));
    if (top < (std::uint64_t{1} << 32)) {  // (rank, index) packed into one integer
      std::vector<std::uint64_t> key(n);
      for (std::uint32_t k = 0; k < n; ++k)
        key[k] = cells_.grid().morton_rank(hot_[k].cell) << 32 | k;
      std::sort(key.begin(), key.end());
      for (std::uint32_t k = 0; k < n; ++k) order[k] = static_cast<std::uint32_t>(key[k]);
    } else {
      std::vector<std::pair<std::uint64_t, std::uint32_t>> rank(n);
      for (std::uint32_t k = 0; k < n; ++k) rank[k] = {cells_.grid().morton_rank(hot_[k].cell), k};
      std::sort(rank.begin(), rank.end());
      for (std::uint32_t k = 0; k < n; ++k) order[k] = rank[k].second;
    }
  }
  std::vector<std::uint32_t> new_index(n);
  for (std::uint32_t k = 0; k < n; ++k) new_index[order[k]] = k;
  std::vector<double> times(queue_filled ? n : 0);
  for (std::uint32_t k = 0; queue_filled && k < n; ++k) times[k] = queue_.time_of(order[k]);
  for (PendingEvent& e : pending_)
    e.code = e.code.renumbered([&](std::uint32_t p) { return new_index[p]; });
  soft_state_.renumber_partners(new_index, kFirstCode);
  if (stepped_) steps_.renumber(new_index);
  std::vector<std::uint32_t>().swap(new_index);
  std::vector<bool> done;
  const auto permute = [&](auto& per_particle) {
    if (!per_particle.empty()) permute_in_place(per_particle, order, done);
  };
  permute(hot_);
  permute(pending_);
  permute(id_);
  if (cells_.two_level()) permute(cells_.big_flags());
  permute(kind_);  // its spare last entry stays
  permute(radius_);
  permute(spin_);
  permute(last_collision_);
  images_.permute(order, done);
  helfand_.permute(order, done);
  resting_.permute(order, done);
  soft_state_.permute(order, done);
  cells_.insert_all(hot_.data(), static_cast<std::uint32_t>(size()));
  if (queue_filled) queue_.reset(times);
}

template <int D, class Queue>
void EventEngine<D, Queue>::advance_accelerated(HotRecord<D>& h, double t) const {
  const Vec<D> x = flight_position(h, t);
  h.vel = flight_velocity(h, t);
  h.pos = x;
  h.time = t;
}

// When the particle leaves its cell, through which face. Always computed from the unchanged
// record, so the time a crossing was scheduled at and the face it is processed with agree.
// Branch-free (the signs of velocity components are random); the first axis wins ties.
template <int D, class Queue>
typename EventEngine<D, Queue>::Crossing EventEngine<D, Queue>::next_crossing(
    const HotRecord<D>& h) const {
  if (accelerated_ || bounded_) [[unlikely]] {
    return next_crossing_general(h);
  }
  // interval_exit_time's arithmetic, bit for bit, with its selects written as SSE2 masks: the
  // compiler turns the ternaries into branches, and a velocity component's sign is a coin toss.
  const __m128d zero = _mm_setzero_pd(), never = _mm_set_sd(kNever);
  const __m128d start = _mm_set_sd(h.time);
  __m128d soonest = never;
  int axis = -1, sign = 0;
  for (int a = 0; a < D; ++a) {
    const double v = h.vel[a];
    const int up = v > 0.0 ? 1 : 0;
    const __m128d vv = _mm_set_sd(v);
    const __m128d face =
        _mm_set_sd((cells_.grid().coordinate(h.cell, a) + up) * cells_.grid().width(a));
    // (face - x) / v, at least 0 (max_sd gives its second operand for NaN, as the ternary did);
    // never for v = 0.
    const __m128d dt = _mm_max_sd(_mm_div_sd(_mm_sub_sd(face, _mm_set_sd(h.pos[a])), vv), zero);
    const __m128d moving = _mm_cmpneq_sd(vv, zero);
    const __m128d when =
        _mm_add_sd(start, _mm_or_pd(_mm_and_pd(moving, dt), _mm_andnot_pd(moving, never)));
    const __m128d sooner = _mm_cmplt_sd(when, soonest);
    const int won = _mm_cvtsi128_si32(_mm_castpd_si128(sooner));  // 0 or all bits set
    soonest = _mm_or_pd(_mm_and_pd(sooner, when), _mm_andnot_pd(sooner, soonest));
    axis = (a & won) | (axis & ~won);
    sign = ((2 * up - 1) & won) | (sign & ~won);
  }
  return Crossing{_mm_cvtsd_f64(soonest), axis, sign};
}

// next_crossing() under gravity or with unbounded outer layers (walls, open faces).
template <int D, class Queue>
typename EventEngine<D, Queue>::Crossing EventEngine<D, Queue>::next_crossing_general(
    const HotRecord<D>& h) const {
  Crossing x{kNever, -1, 0};
  {
    for (int a = 0; a < D; ++a) {
      const double lo = cells_.grid().lower_bound(h.cell, a),
                   hi = cells_.grid().upper_bound(h.cell, a);
      const double g = env_.gravity[a];
      const double dt = interval_exit_time_accelerated(h.pos[a], h.vel[a], g, lo, hi);
      if (!(h.time + dt < x.time)) continue;
      // The face: the direction of motion when leaving (a thrown particle may fall back).
      const double v_exit = h.vel[a] + g * dt;
      const double x_exit = h.pos[a] + h.vel[a] * dt + (half_gravity_[a] * dt) * dt;
      x = {h.time + dt, a,
           v_exit > 0.0 ? 1 : (v_exit < 0.0 ? -1 : (x_exit > 0.5 * (lo + hi) ? 1 : -1))};
    }
  }
  return x;
}

template <int D, class Queue>
void EventEngine<D, Queue>::gather(CellCode cell, CandidateList& list) {
  if (sheared_) [[unlikely]] {
    list.sheared = shear_.next_to_face(cell, cells_.grid());
    if (list.sheared) {
      gather_sheared(cell, list);
      return;
    }
  }
  cells_.gather(cell, list, hot_.data());
}

// The candidate loops' view of a gathered list for particle i; candidates in deferred soft
// contacts go to list.delayed, counted in *delayed.
template <int D, class Queue>
CandidateScan<D> EventEngine<D, Queue>::scan_of(const CandidateList& list, std::uint32_t i,
                                                std::uint32_t* delayed) const {
  // Every field written once (designated initialisers): a default-constructed scan would be
  // zeroed first with a slow `rep stos`.
  const double r = radius_of(i);
  return CandidateScan<D>{.records = reinterpret_cast<const double*>(hot_.data()),
                          .stride = static_cast<int>(sizeof(HotRecord<D>) / sizeof(double)),
                          .row_loads = row_loads_,
                          .candidates = list.ids.data(),
                          .shift_index = list.shift.data(),
                          .shifts = list.shifts,
                          // else list.shift is stale and must not be read
                          .any_shift = list.n_shifts > 1,
                          .count = list.count,
                          .uniform = uniform_radius_,
                          .sigma = 2.0 * r,
                          .radius_i = r,
                          .kind = kind_.data(),
                          .kind_radius = kind_radius_.data(),
                          .particle_radius = radius_.empty() ? nullptr : radius_.data(),
                          .accel = accelerated_ ? env_.gravity.data() : nullptr,
                          .half_accel = accelerated_ ? half_gravity_.data() : nullptr,
                          .delayed = soft_ ? list.delayed.data() : nullptr,
                          .delayed_count = delayed};
}

// Tests particle i (at xi, time t) against a gathered candidate list; returns the partner of
// the soonest contact earlier than t + best (kNoPartner if none) and lowers `best` to it.
template <int D, class Queue>
std::uint32_t EventEngine<D, Queue>::test_candidates(const CandidateList& list, std::uint32_t i,
                                                     double t, const Vec<D>& xi,
                                                     double& best) const {
  std::uint32_t delayed = 0;  // candidates in deferred soft contacts, listed in list.delayed
  const CandidateScan<D> scan = scan_of(list, i, &delayed);
  std::uint32_t k;
  if (growing_) [[unlikely]] {
    k = vector_growing_ ? scan_candidates_growing_avx512<D>(scan, i, t, xi, hot_[i].vel,
                                                            growth_.scale(t), growth_.rate(), best)
                        : scan_candidates_growing<D>(scan, i, t, xi, hot_[i].vel, growth_.scale(t),
                                                     growth_.rate(), best);
  } else if (accelerated_) {
    const Vec<D> vi = flight_velocity(hot_[i], t);
    k = vector_scan_ ? scan_candidates_avx512<D, true>(scan, t, xi, vi, best)
                     : scan_candidates_scalar<D, true>(scan, t, xi, vi, best);
  } else {
    k = vector_scan_ ? scan_candidates_avx512<D>(scan, t, xi, hot_[i].vel, best)
                     : scan_candidates_scalar<D>(scan, t, xi, hot_[i].vel, best);
  }
  const std::uint32_t partner = k == kNoCandidate ? kNoPartner : list.ids[k];
  if (delayed > 0) [[unlikely]] {
    const std::uint32_t other = scan_deferred(list, delayed, i, t, xi, hot_[i].vel, t, best);
    if (other != kNoPartner) return other;
  }
  return partner;
}

// Finds the particle's next event from time t: the soonest collision with a neighbour, if it
// comes before the particle leaves its cell, else the crossing. Stores it; returns its time.
template <int D, class Queue>
double EventEngine<D, Queue>::predict(std::uint32_t i, double t) {
  gather_of(i, cells_.list(0));
  return predict_from(cells_.list(0), i, t);
}

// predict() with the candidates already gathered (from the particle's own cell).
template <int D, class Queue>
double EventEngine<D, Queue>::predict_from(const CandidateList& list, std::uint32_t i, double t) {
  const HotRecord<D>& h = hot_[i];
  if (resting_.count() > 0 && is_asleep(i)) [[unlikely]] {
    return predict_asleep(list, i, t);
  }
  const Crossing crossing = next_crossing(h);
  double best = crossing.time - t;
  const Vec<D> xi = accelerated_ ? flight_position(h, t) : h.pos + (t - h.time) * h.vel;
  std::uint32_t partner;
  if (stepped_ || (resting_.count() > 0 && resting_.any_of(list.ids.data(), list.count)) ||
      list.sheared) [[unlikely]] {
    partner = stepped_       ? scan_stepped(list, i, t, best)
              : list.sheared ? scan_sheared(list, i, t, best)
                             : scan_with_sleepers(list, i, t, best);
  } else if (incremental_crossings_) {
    // Unbounded: a contact after the crossing is kept for the crossing's own prediction.
    double soonest = kNever;
    partner = test_candidates(list, i, t, xi, soonest);
    return conclude_unbounded(i, t, crossing, partner, soonest);
  } else {
    partner = test_candidates(list, i, t, xi, best);
  }
  return conclude_prediction(i, t, crossing, partner, best);
}

// Stores particle i's next event from time t: the contact with `partner` at t + best if there
// is one (else the crossing), unless a wall or a frozen contact's release comes first.
template <int D, class Queue>
double EventEngine<D, Queue>::conclude_prediction(std::uint32_t i, double t,
                                                  const Crossing& crossing, std::uint32_t partner,
                                                  double best) {
  double when = crossing.time;
  if (partner != kNoPartner) {
    pending_[i] = {Code::collision(partner), hot_[partner].collisions};
    when = t + best;
  } else {
    pending_[i] = {Code::crossing(), 0};
  }
  if (walls_) {
    const auto [dt, face] = next_wall_contact(i, t, when - t);
    if (face >= 0) {
      pending_[i] = {Code::wall(face), massive_walls_ ? boundaries_.event_version(face) : 0u};
      when = t + dt;
    }
  }
  if (soft_ && soft_state_.awaits_release(i) && soft_state_.release_time(i) <= when) [[unlikely]] {
    pending_[i] = {Code::release(), 0};
    when = soft_state_.release_time(i);
  }
  return when > t ? when : t;  // never in the past, whatever the round-off
}

template <int D, class Queue>
double EventEngine<D, Queue>::conclude_unbounded(std::uint32_t i, double t,
                                                 const Crossing& crossing, std::uint32_t partner,
                                                 double soonest) {
  // The same choice as a scan bounded by the crossing: a contact strictly before it.
  if (partner != kNoPartner && soonest < crossing.time - t)
    return conclude_prediction(i, t, crossing, partner, soonest);
  const double when = conclude_prediction(i, t, crossing, kNoPartner, 0.0);
  if (pending_[i].code.is_full_scan_crossing()) {  // the crossing (no wall or release first)
    pending_[i] = partner == kNoPartner
                      ? PendingEvent{Code::crossing_keeping_none(), 0}
                      : PendingEvent{Code::crossing_keeping(partner), hot_[partner].collisions};
  }
  return when;
}

// After a crossing at time t (already in its new cell, the new layer of cells gathered
// into cells_.list(0) by cross()): the particle's old neighbours
// were all tested by the prediction that scheduled the crossing, and the soonest contact among
// them came after it (`kept`, due in kept_dt; kNoPartner: none). A neighbour whose motion
// changed since was predicted again then, against this particle's unchanged motion, so that
// pair is in the neighbour's own event; only the layer of cells new to the neighbourhood needs
// a scan.
template <int D, class Queue>
double EventEngine<D, Queue>::predict_after_crossing(std::uint32_t i, double t, std::uint32_t kept,
                                                     double kept_dt) {
  const HotRecord<D>& h = hot_[i];
  const CandidateList& list = cells_.list(0);
  // A sleeper in the new layer needs the loop of scan_with_sleepers: the full prediction.
  if (resting_.count() > 0 && resting_.any_of(list.ids.data(), list.count)) [[unlikely]]
    return predict(i, t);
  const Crossing crossing = next_crossing(h);
  const Vec<D> xi = accelerated_ ? flight_position(h, t) : h.pos + (t - h.time) * h.vel;
  double soonest = kNever;
  std::uint32_t partner = test_candidates(list, i, t, xi, soonest);
  if (kept != kNoPartner && kept_dt < soonest) {
    soonest = kept_dt;
    partner = kept;
  }
  ++incremental_scans_;
  return conclude_unbounded(i, t, crossing, partner, soonest);
}

// The kept pair's contact time from its present state, computed as the candidate loops do,
// with the periodic image of the cell offset (the pair's time does not change while neither
// motion does; recomputing it costs one record and keeps the pending event at 8 bytes).
template <int D, class Queue>
bool EventEngine<D, Queue>::kept_contact_time(std::uint32_t i, std::uint32_t p, double t,
                                              double& dt) const {
  const HotRecord<D>& hi = hot_[i];
  const HotRecord<D>& hp = hot_[p];
  std::array<int, D> d;
  if (!cells_.grid().neighbour_offset(hi.cell, hp.cell, d)) return false;
  // With a periodic axis only 3 cells wide, a crossing along it makes the old far layer the new
  // one, through the other image: a partner kept there had its contact through the old image,
  // which the new one does not give back, and that contact bounded the old neighbours' ones.
  // Fuzzing found a failure of the same kind in soft-sphere runs that a finer test (the crossing
  // axis only, the partner in the new layer) missed, so no kept contact is used in such a box.
  if (three_cell_axis_) return false;
  if (in_deferred_contact(p, t) || is_asleep(p)) [[unlikely]]
    return false;
  const Vec<D> xi = accelerated_ ? flight_position(hi, t) : hi.pos + (t - hi.time) * hi.vel;
  const Vec<D> vi = accelerated_ ? flight_velocity(hi, t) : hi.vel;
  Vec<D> shift;
  for (int a = 0; a < D; ++a) {
    const int c = cells_.grid().coordinate(hi.cell, a) + d[a];
    shift[a] = c < 0 ? -box_[a] : c >= cells_.grid().cells_along(a) ? box_[a] : 0.0;
  }
  const auto* rec = reinterpret_cast<const double*>(&hp);
  const RelativeMotion m =
      accelerated_ ? relative_motion_at<D, true>(xi, vi, rec, t - hp.time, shift,
                                                 half_gravity_.data(), env_.gravity.data())
                   : relative_motion_at<D>(xi, vi, rec, t - hp.time, shift);
  if (growing_) [[unlikely]] {
    const double sigma0 = radius_of(i) + radius_of(p);
    if (!growing_contact_before(m, sigma0 * growth_.scale(t), growth_.speed(sigma0), kNever, dt))
      dt = kNever;
    return true;
  }
  const double sigma = radius_of(i) + radius_of(p);
  if (!contact_before(m, sigma * sigma, kNever, dt)) dt = kNever;
  return true;
}

template <int D, class Queue>
void EventEngine<D, Queue>::collide(std::uint32_t i, std::uint32_t j, double t) {
  // Canonical order so that which of the pair was popped never changes the arithmetic.
  if (j < i) std::swap(i, j);
  if (soft_) [[unlikely]] {
    collide_soft(i, j, t);
    return;
  }
  if (sheared_) [[unlikely]] {
    if (!(stepped_ && step_pair(i, j, t))) collide_sheared(i, j, t);
    return;
  }
  if (resting_.count() > 0 && (is_asleep(i) || is_asleep(j))) [[unlikely]] {
    if (is_asleep(i)) std::swap(i, j);  // i is the awake one
    const bool again = wedged(i, t);
    advance_to(i, t);
    Vec<D> r = hot_[i].pos - hot_[j].pos;
    for (int a = 0; a < D; ++a)
      if (cells_.grid().periodic(a)) r[a] = minimum_image(r[a], box_[a]);
    collide_with_sleeper(i, j, t, r, norm2(r), again);
    return;
  }
  if (stepped_ && step_pair(i, j, t)) [[unlikely]]
    return;
  advance_to(i, t);
  advance_to(j, t);
  HotRecord<D>& hi = hot_[i];
  HotRecord<D>& hj = hot_[j];
  Vec<D> r;
  double g_dot_r = 0.0, r2 = 0.0;
  for (int a = 0; a < D; ++a) {
    const double raw = hi.pos[a] - hj.pos[a];
    const double d = !bounded_ || cells_.grid().periodic(a) ? minimum_image(raw, box_[a]) : raw;
    r[a] = d;
    r2 += d * d;
    g_dot_r += (hi.vel[a] - hj.vel[a]) * d;
  }
  if (helfand_.on()) [[unlikely]]
    helfand_before(i, j, t);
  if (granular_contacts_) {
    collide_granular(i, j, t, r, r2);
  } else {
    const double mi = mass_of(i), mj = mass_of(j);
    const double mu = mi * mj / (mi + mj);
    double s;  // J = s r
    if (growing_) [[unlikely]] {
      s = HardSphere::growing_impulse_factor(
          g_dot_r, r2, mu, growth_.speed(radius_of(i) + radius_of(j)), contact_distance(i, j, t));
    } else {
      s = HardSphere::impulse_factor(g_dot_r, r2, mu);
    }
    for (int a = 0; a < D; ++a) {
      hi.vel[a] += s * r[a] / mi;
      hj.vel[a] -= s * r[a] / mj;
    }
    counters_.virial += s * r2;
    add_virial_tensor(r, s * r);
  }
  if (helfand_.on()) [[unlikely]]
    helfand_after(i, j, r);
  ++counters_.collisions;
  ++hi.collisions;
  ++hj.collisions;
  predict_pair(i, j, t);
}

template <int D, class Queue>
void EventEngine<D, Queue>::set_velocity(std::uint32_t k, double t, const Vec<D>& v) {
  if (!(t >= time_) || !(t <= next_event_time()) || k >= size()) {
    throw std::logic_error(
        "set_velocity: time outside [time(), next_event_time()] or no such particle");
  }
  time_ = t;
  if (is_asleep(k)) wake(k, t);
  if (soft_) {  // a kick ends a soft contact in progress (exception B)
    const std::uint32_t partner = release(k, t, /*early=*/true);
    if (is_particle(partner)) queue_.update(partner, predict(partner, t));
  }
  advance_to(k, t);
  HotRecord<D>& h = hot_[k];
  counters_.work_by_driving += 0.5 * mass_of(k) * (norm2(v) - norm2(h.vel));
  h.vel = v;
  ++h.collisions;
  ++counters_.driving_kicks;
  queue_.update(k, predict(k, t));
}

template <int D, class Queue>
void EventEngine<D, Queue>::rescale_velocities(double t, double factor, double growth_rate) {
  if (!(t >= time_) || !(t <= next_event_time()))
    throw std::logic_error("rescale_velocities: time outside [time(), next_event_time()]");
  if (soft_ || resting_.count() > 0)
    throw std::logic_error("rescale_velocities: not with soft contacts or resting particles");
  if (growth_rate != 0.0 && (!growing_ || !(growth_rate > 0.0) || !std::isfinite(growth_rate)))
    throw std::logic_error("rescale_velocities: a growth rate while not growing, or not positive");
  time_ = t;
  if (growth_rate != 0.0) {
    growth_ = growth_.changed_at(t, growth_rate);
    update_growth_limit();
  }
  change_velocities(t, [factor](std::uint32_t, const Vec<D>& v) { return factor * v; });
}

template <int D, class Queue>
void EventEngine<D, Queue>::set_velocities(double t, const std::vector<Vec<D>>& velocity) {
  if (!(t >= time_) || !(t <= next_event_time()))
    throw std::logic_error("set_velocities: time outside [time(), next_event_time()]");
  if (velocity.size() != size())
    throw std::logic_error("set_velocities: one velocity per particle");
  if (soft_ || resting_.sleepers() > 0 || helfand_.on())
    throw std::logic_error(
        "set_velocities: not with soft contacts, sleeping particles or Helfand moments");
  for (std::uint32_t k = 0; k < size(); ++k) {
    if (resting_.fixed(k) && !(velocity[id_[k]] == Vec<D>{}))
      throw std::logic_error("set_velocities: a fixed grain must stay at rest");
  }
  time_ = t;
  change_velocities(t, [&](std::uint32_t k, const Vec<D>&) { return velocity[id_[k]]; });
}

template <int D, class Queue>
template <class NewVelocity>
void EventEngine<D, Queue>::change_velocities(double t, NewVelocity&& new_velocity) {
  const auto n = static_cast<std::uint32_t>(size());
  for (std::uint32_t k = 0; k < n; ++k) {
    advance_to(k, t);
    hot_[k].vel = new_velocity(k, hot_[k].vel);
    ++hot_[k].collisions;  // every prediction made against it is stale
  }
  std::vector<double> times(n);
  for (std::uint32_t k = 0; k < n; ++k) times[k] = predict(k, t);
  queue_.reset(times);
}

template <int D, class Queue>
void EventEngine<D, Queue>::set_growth_rate(double t, double rate) {
  if (!growing_ || !(rate > 0.0) || !std::isfinite(rate))
    throw std::logic_error("set_growth_rate: not growing, or not a positive rate");
  rescale_velocities(t, 1.0, rate);
}

template <int D, class Queue>
void EventEngine<D, Queue>::update_growth_limit() {
  double rmax = 0.0;
  for (const ParticleKind& sh : kinds_) rmax = std::max(rmax, sh.radius);
  double width = kNever;
  for (int a = 0; a < D; ++a) width = std::min(width, cells_.grid().width(a));
  double fits = growth_.fits_until(2.0 * rmax, width);
  if (cells_.two_level()) {
    // Small pairs within fine cells, any pair with a big one within coarse cells, a big one's
    // small partners within its reach.
    const auto& levels = cells_.levels();
    fits = kNever;
    for (int a = 0; a < D; ++a) {
      const double w = cells_.grid().width(a);
      fits = std::min({fits, growth_.fits_until(2.0 * levels.small_radius, w),
                       growth_.fits_until(2.0 * rmax, levels.group[a] * w),
                       growth_.fits_until(levels.small_radius + rmax, levels.reach[a] * w)});
    }
  }
  // Never before now by round-off: a rate changed at the old limit may round the new one just
  // below it. Further below, the limit stays passed (a collision beyond it is refused).
  growth_fits_until_ =
      fits >= time_ - 1e-12 * std::max(1.0, std::abs(time_)) ? std::max(time_, fits) : fits;
}

// Two cell levels when the size distribution is wide (EngineOptions::size_levels): the small
// particles (within twice the 10th percentile of the radii) in the fine grid sized for them,
// the others in a coarse grid whose cells group whole fine cells and hold the largest contact.
// Radii at the engine's start; `room` widens both (growth).
template <int D, class Queue>
void EventEngine<D, Queue>::plan_size_levels(double room, double cells_per_particle,
                                             const std::vector<CellCode>* stored) {
  const auto n = static_cast<std::uint32_t>(size());
  std::vector<double> radii(n);
  for (std::uint32_t k = 0; k < n; ++k) radii[k] = radius_of(k);
  std::optional<SizeLevelPlan<D>> plan = plan_cell_levels<D>(
      std::move(radii), box_, cells_.grid(), room, cells_per_particle, options_.force_size_levels);
  if (!plan) return;
  CellGrid<D>& fine = plan->fine;
  typename Cells::Levels& levels = plan->levels;
  levels.big.resize(n);
  for (std::uint32_t k = 0; k < n; ++k) levels.big[k] = radius_of(k) > levels.small_radius ? 1 : 0;
  // A resumed state keeps the cells it was written with: two levels only if every stored cell
  // is a fine cell holding its particle (a file written on one level continues on one).
  for (std::uint32_t k = 0; stored != nullptr && k < n; ++k) {
    const CellCode c = (*stored)[id_[k]];
    if (!fine.valid(c)) return;
    for (int a = 0; a < D; ++a) {
      const double x = hot_[k].pos[a], tol = 1e-9 * box_[a];
      if (x < fine.lower_bound(c, a) - tol || x > fine.upper_bound(c, a) + tol) return;
    }
  }
  cells_ = Cells(std::move(fine), vector_gather_);
  cells_.use_levels(std::move(levels));
}

// Growing particles (docs/physics.md#growing-spheres): what growth composes with, and how long
// the cells hold it.
template <int D, class Queue>
void EventEngine<D, Queue>::start_growth() {
  const auto refuse = [](const std::string& what) {
    throw InputError("growing particles (compression) cannot be combined with " + what);
  };
  if (!(options_.growth_rate > 0.0) || !std::isfinite(options_.growth_rate))
    throw InputError("the growth rate must be positive and finite");
  check_growth_boundaries();
  if (accelerated_) refuse("gravity (field.gravity)");
  if (sheared_) refuse("Lees-Edwards shear (boundary.shear_rate)");
  if (stepped_) refuse("stepped potentials or bonds");
  if (soft_) refuse("soft spheres (soft.model)");
  if (granular_contacts_) refuse("inelastic or rough contacts or the TC model ([contact])");
  if (env_.has_fixed_grains()) refuse("fixed grains");
  growth_ = Growth(options_.growth_rate, time_);
  growing_ = true;
  // The growing loop reads per-particle radii too (the other vector loops read kinds only).
  vector_growing_ = options_.vector_scan && cpu_has_avx512() && records_fit_32_bits_;
  row_loads_ =
      vector_growing_ && (options_.record_loads == RecordLoads::kRows ||
                          (options_.record_loads == RecordLoads::kAuto && !cpu_gathers_fast()));
  vector_scan_ = false;  // no other loop runs while growing
  update_growth_limit();
}

// Growing particles meet fixed, elastic, smooth walls on the box's faces only: a growing radius
// against a plane is a velocity along its normal (Boundaries::next_contact), which holds for
// no curved surface, and the contact must send the particle off at the growth speed (no
// dissipation, no spin). The cells need nothing more: a particle can touch a wall only from
// the outer layer while two grown radii fit a cell (update_growth_limit).
template <int D, class Queue>
void EventEngine<D, Queue>::check_growth_boundaries() const {
  const auto refuse = [](const std::string& what) {
    throw InputError("growing particles (compression) cannot be combined with " + what);
  };
  for (int a = 0; a < D; ++a) {
    for (int f = 2 * a; f < 2 * a + 2; ++f) {
      if (env_.faces[f].kind == FaceKind::kOpen)
        refuse("open faces (boundary.open): a growing packing needs walls or periodic faces");
    }
  }
  for (int s = 0; s < boundaries_.surfaces(); ++s) {
    if (!boundaries_.is_surface(s)) continue;
    const std::string name = "the wall " + boundaries_.name(s);
    if (s >= 2 * D || !boundaries_.flat(s) || boundaries_.passes(s))
      refuse(name + ": only walls on the box's faces (boundary.wall) grow a packing");
    if (boundaries_.surface_moves(s) || boundaries_.accelerates(s) || boundaries_.massive(s))
      refuse(name + ", which moves (a velocity along its normal, a vibration or a mass)");
    const ContactModel& law = boundaries_.contact(s);
    if (!law.normal.always_elastic() || !law.tangential.is_smooth())
      refuse(name + ", whose contact is inelastic or rough (its restitution)");
  }
}

template <int D, class Queue>
void EventEngine<D, Queue>::cross(std::uint32_t i, double t) {
  HotRecord<D>& h = hot_[i];
  const Crossing x = next_crossing(h);
  const PendingEvent e = pending_[i];
  // Whether the prediction that scheduled this crossing kept the contact beyond it, and whether
  // that is still good: its partner's motion unchanged (counter), read before i moves.
  std::uint32_t kept = kNoPartner;
  bool incremental = e.code.keeps_nothing();
  if (e.code.keeps_contact()) {
    kept = e.code.kept_partner();
    incremental = hot_[kept].collisions == e.partner_count;
  }
  advance_to(i, t);
  std::array<int, D> c;
  for (int a = 0; a < D; ++a) c[a] = cells_.grid().coordinate(h.cell, a);
  c[x.axis] += x.sign;
  if (!cells_.grid().periodic(x.axis)) {
    // Outer layers are unbounded, so a crossing never leaves the grid; round-off aside.
    c[x.axis] = std::clamp(c[x.axis], 0, cells_.grid().cells_along(x.axis) - 1);
  } else if (c[x.axis] < 0) {
    c[x.axis] += cells_.grid().cells_along(x.axis);
    h.pos[x.axis] += box_[x.axis];
    if (images_.on()) images_.wrapped(i, x.axis, 1);
    if (sheared_ && x.axis == 1) cross_shear_face(i, -1, t, c);
  } else if (c[x.axis] >= cells_.grid().cells_along(x.axis)) {
    c[x.axis] -= cells_.grid().cells_along(x.axis);
    h.pos[x.axis] -= box_[x.axis];
    if (images_.on()) images_.wrapped(i, x.axis, -1);
    if (sheared_ && x.axis == 1) cross_shear_face(i, 1, t, c);
  }
  const CellCode entered = cells_.grid().code_at(c);
  // The layer new to the neighbourhood, gathered first so that the misses on its records overlap
  // the list surgery and the kept contact's time (its cells are neither the old nor the new one).
  if (incremental)
    cells_.gather_cells(entered, cells_.grid().layer(x.axis, x.sign), CellGrid<D>::kLayerCells,
                        cells_.list(0), hot_.data());
  cells_.move(i, h.cell, entered);
  h.cell = entered;
  ++counters_.cell_crossings;
  double kept_dt = kNever;
  if (incremental && kept != kNoPartner) incremental = kept_contact_time(i, kept, t, kept_dt);
  queue_.update(i, incremental ? predict_after_crossing(i, t, kept, kept_dt) : predict(i, t));
}

template <int D, class Queue>
EventKind EventEngine<D, Queue>::step() {
  if (sheared_ && shear_.next_shift_time() <= queue_.top_time()) [[unlikely]] {
    shift_images();
    return EventKind::kImageShift;
  }
  if (massive_walls_) [[unlikely]] {
    // (A lid that never changes layer again has kNever: no event, whatever the queue holds.)
    const double change = boundaries_.next_layer_change();
    if (change < kNever && change <= queue_.top_time()) {
      change_wall_layer(change);
      return EventKind::kWallLayer;
    }
  }
  const std::uint32_t i = queue_.top();
  const double t = queue_.top_time();
  if (!std::isfinite(t)) return EventKind::kNone;
  // Growing: beyond this the cells may have missed a pair; refused before anything changes
  // (the caller rebuilds the engine first).
  if (growing_ && t > growth_fits_until_) [[unlikely]]
    throw std::logic_error("step: growing particles no longer fit the cells (growth_fits_until)");
  time_ = t;
  ++counters_.events;
  if constexpr (requires { queue_.likely_next(); }) {
    // Start the next event's memory accesses now, so they overlap with this one's work.
    const std::uint32_t k = queue_.likely_next();
    __builtin_prefetch(&hot_[k]);
    __builtin_prefetch(&pending_[k]);
  }
  const PendingEvent e = pending_[i];
  if (!e.code.is_collision()) {
    if (e.code.is_crossing()) [[likely]] {
      cross(i, t);
      return EventKind::kCellCrossing;
    }
    if (e.code.is_release()) {
      release_event(i, t);
      return EventKind::kSoftRelease;
    }
    if (massive_walls_ && stale_wall_event(e)) [[unlikely]] {
      ++counters_.stale_events;
      queue_.update(i, predict(i, t));
      return EventKind::kStale;
    }
    return hit_wall(i, e.code.wall_face(), t);
  }
  if (hot_[e.code.partner()].collisions != e.partner_count) {
    ++counters_.stale_events;
    queue_.update(i, predict(i, t));
    return EventKind::kStale;
  }
  collide(i, e.code.partner(), t);
  if (counters_.collisions >= next_renumber_) {
    renumber(/*queue_filled=*/true);
    next_renumber_ = next_renumber_after(counters_.collisions);
  }
  return EventKind::kCollision;
}

template <int D, class Queue>
double EventEngine<D, Queue>::kinetic_energy() const {
  double ke = 0.0;
  if (accelerated_ || soft_state_.defers()) {
    for (std::uint32_t i = 0; i < size(); ++i) ke += 0.5 * mass_of(i) * norm2(velocity(i, time_));
    return ke;
  }
  for (std::uint32_t i = 0; i < size(); ++i) ke += 0.5 * mass_of(i) * norm2(hot_[i].vel);
  return ke;
}

template <int D, class Queue>
double EventEngine<D, Queue>::peculiar_kinetic_energy() const {
  if (!sheared_) return kinetic_energy();
  double ke = 0.0;
  for (std::uint32_t i = 0; i < size(); ++i) {
    const Vec<D> u = env_.streaming_velocity(position(i, time_), box_);
    ke += 0.5 * mass_of(i) * norm2(velocity(i, time_) - u);
  }
  return ke;
}

template <int D, class Queue>
double EventEngine<D, Queue>::rotational_energy() const {
  double e = 0.0;
  for (std::uint32_t i = 0; i < spin_.size(); ++i) {
    const double r = radius_of(i);
    e += 0.5 * env_.inertia_factor_of(species_of(i)) * mass_of(i) * r * r * norm2(spin_[i]);
  }
  return e;
}

template <int D, class Queue>
Vec<D> EventEngine<D, Queue>::momentum() const {
  Vec<D> p{};
  for (std::uint32_t i = 0; i < size(); ++i) p = p + mass_of(i) * velocity(i, time_);
  return p;
}

template <int D, class Queue>
std::array<double, 9> EventEngine<D, Queue>::peculiar_kinetic_tensor() const {
  Vec<D> p{};
  double mass = 0.0;
  for (std::uint32_t i = 0; i < size(); ++i) {
    p = p + mass_of(i) * velocity(i, time_);
    mass += mass_of(i);
  }
  const Vec<D> mean = (1.0 / mass) * p;
  std::array<double, 9> tensor{};
  for (std::uint32_t i = 0; i < size(); ++i) {
    const Vec<D> c = velocity(i, time_) - mean;
    for (int a = 0; a < D; ++a)
      for (int b = 0; b < D; ++b) tensor[a * D + b] += mass_of(i) * c[a] * c[b];
  }
  return tensor;
}

template <int D, class Queue>
double EventEngine<D, Queue>::bytes_per_particle() const {
  // Per-particle arrays plus the grid's and the queue's own (cells and buckets included,
  // divided by N); the kind table is a few bytes in all.
  const double kinds =
      static_cast<double>(kinds_.size() * sizeof(ParticleKind)) / static_cast<double>(size());
  return static_cast<double>(sizeof(HotRecord<D>) + sizeof(PendingEvent) + sizeof(std::uint32_t) +
                             (kind_.empty() ? 0 : sizeof(std::uint16_t)) +
                             (radius_.empty() ? 0 : sizeof(double))) +
         kinds + cells_.grid().bytes_per_particle() +
         (cells_.two_level() ? cells_.levels().coarse.bytes_per_particle() + 1.0 : 0.0) +
         images_.bytes_per_particle() + helfand_.bytes_per_particle() +
         static_cast<double>(queue_.bytes_per_particle());
}

template class EventEngine<2, BinaryHeapQueue>;
template class EventEngine<3, BinaryHeapQueue>;
template class EventEngine<2, CalendarQueue>;
template class EventEngine<3, CalendarQueue>;
template class EventEngine<2, TournamentTreeQueue>;
template class EventEngine<3, TournamentTreeQueue>;

}  // namespace kairos
