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
#include "dynamics/collision_time.hpp"
#include "dynamics/trajectory_events.hpp"
#include "engine/candidate_scan.hpp"
#include "interactions/granular_contact.hpp"
#include "interactions/hard_sphere.hpp"
#include "scheduler/binary_heap_queue.hpp"
#include "scheduler/calendar_queue.hpp"
#include "scheduler/tournament_tree_queue.hpp"

namespace kairos {

namespace {
constexpr std::uint32_t kNoPartner = EventSlot::kNoPartner;

// The engine stores 2D spins as one-component vectors; the contact laws take a scalar.
template <int D>
Spin<D> to_spin(const AngularVelocity<D>& w) {
  if constexpr (D == 3) {
    return w;
  } else {
    return w[0];
  }
}

template <int D>
AngularVelocity<D> from_spin(const Spin<D>& w) {
  if constexpr (D == 3) {
    return w;
  } else {
    return {w};
  }
}
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
  if (n > kFirstCode - 16) throw InputError("too many particles (at most 2^31 - 16)");
  if (s.mass.size() != n || s.species.size() != n) {
    throw InputError("the state needs a mass and a species for every particle");
  }
  build_shapes(s);
  std::vector<double>().swap(s.mass);  // in shapes_ now
  std::vector<std::uint32_t>().swap(s.species);
  bonds_ = s.bonds;
  bond_types_ = s.bond_types;
  // The vector loop indexes records with 32-bit offsets.
  vector_scan_ = options_.vector_scan && cpu_has_avx512() &&
                 static_cast<double>(n) * sizeof(HotRecord<D>) < 2e9;
  vector_gather_ =
      vector_scan_ && (options_.list_gather == ListGather::kVector ||
                       (options_.list_gather == ListGather::kAuto && cpu_gathers_fast()));
  row_loads_ =
      vector_scan_ && (options_.record_loads == RecordLoads::kRows ||
                       (options_.record_loads == RecordLoads::kAuto && !cpu_gathers_fast()));
  setup_environment(s);
  setup_soft(s);

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
  HugeVector<std::uint16_t> shape_by_id = std::move(shape_);
  if (!shape_by_id.empty()) {
    shape_.resize(n + 1);  // one spare entry: the vector loop reads shapes 4 bytes at a time
    for (std::size_t k = 0; k < n; ++k) shape_[k] = shape_by_id[id_[k]];
  }
  for (const ParticleKind& sh : shapes_) shape_radius_.push_back(sh.radius);
  const bool has_counts = s.collision_count.size() == n;
  hot_.resize(n);
  for (std::uint32_t k = 0; k < n; ++k) {
    const Kinematics<D>& kin = s.kinematics[id_[k]];
    hot_[k] = {kin.pos, kin.vel, kin.time, has_counts ? s.collision_count[id_[k]] : 0u, 0u};
  }
  // Read (shapes_ hold the radii): released before the queue and the renumbering take their
  // memory (docs/performance.md, "Memory").
  std::vector<Kinematics<D>>().swap(s.kinematics);
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
  // Sleepers predict no events of their own, so a wall moving along its normal (vibrating or a
  // piston) could move into one unseen: then nothing sleeps (resting piles need the TC model).
  const bool moving = face_walls_.any_plane_moves();
  if (stepped_ && env_.sleep_speed > 0.0) {
    throw InputError(
        "contact.sleep_speed: resting particles cannot sleep under stepped potentials (a "
        "sleeper would miss its steps); set it to 0");
  }
  if (accelerated_ && walls_ && !moving && !stepped_) {
    double dmin = kNever;
    for (const ParticleKind& sh : shapes_) dmin = std::min(dmin, 2.0 * sh.radius);
    const double speed = Resting::speed_for(env_.sleep_speed, env_.gravity, dmin);
    if (speed > 0.0) {
      resting_ = Resting(n, speed, env_.gravity);
      resting_.restore(s.asleep, id_);
      for (std::uint32_t k = 0; k < n; ++k)
        if (resting_.asleep(k)) hot_[k].vel = Vec<D>{};
    }
  }
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
      for (int a = 0; a < D; ++a)
        if (cells_.grid().periodic(a)) hot_[k].pos[a] = wrap_into_box(hot_[k].pos[a], box_[a]);
      hot_[k].cell = cells_.grid().locate(hot_[k].pos);
      if (walls_ && !(soft_ && soft_state_.partner(k) != kNoPartner))  // a soft contact: pressed in
        face_walls_.check_start(hot_[k].pos, radius_of(k), time_, id_[k]);
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
}

// Distinct (radius, mass, species) triples; particles store a 2-byte index into them.
template <int D, class Queue>
void EventEngine<D, Queue>::build_shapes(const ParticleSystem<D>& s) {
  std::map<std::tuple<double, double, std::uint32_t>, std::uint16_t> index;
  HugeVector<std::uint16_t> shape(s.size());
  for (std::size_t i = 0; i < s.size(); ++i) {
    const double r = s.kinematics[i].radius, m = s.mass[i];
    if (!(r > 0.0) || !std::isfinite(r) || !(m > 0.0) || !std::isfinite(m)) {
      throw InputError("particle " + std::to_string(i) +
                       " needs a finite positive radius and mass");
    }
    const auto key = std::make_tuple(r, m, s.species[i]);
    auto it = index.find(key);
    if (it == index.end()) {
      if (shapes_.size() == 0x10000) {
        throw InputError(
            "more than 65536 distinct (diameter, mass, species) combinations: Kairos keeps a "
            "2-byte shape index per particle; round the diameters to fewer distinct values");
      }
      it = index.emplace(key, static_cast<std::uint16_t>(shapes_.size())).first;
      shapes_.push_back({r, m, s.species[i]});
    }
    shape[i] = it->second;
  }
  uniform_radius_ = std::all_of(shapes_.begin(), shapes_.end(), [&](const ParticleKind& sh) {
    return sh.radius == shapes_[0].radius;
  });
  if (shapes_.size() > 1) shape_ = std::move(shape);  // caller's numbering; permuted by caller
}

// Checks the environment against the particles and sizes the cell grid for it: periodic axes
// need 3 cells; along a wall axis, only the outer layer may touch a fixed or vibrating wall
// (cells at least a diameter plus the vibration amplitude wide; a piston reaches any layer).
template <int D, class Queue>
void EventEngine<D, Queue>::setup_environment(const ParticleSystem<D>& s) {
  env_.check();
  std::uint32_t species = 1;
  for (const ParticleKind& sh : shapes_) species = std::max(species, sh.species + 1);
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
  face_walls_ = FaceWalls<D>(env_.faces, box_, env_.gravity);
  walls_ = face_walls_.any();
  granular_contacts_ = !env_.plain() || env_.tc > 0.0;
  double rmax = 0.0;
  for (const ParticleKind& sh : shapes_) rmax = std::max(rmax, sh.radius);
  if (!bonds_.empty() && env_.bond_table.empty())
    throw InputError("the state has bonds but no bond potential is given ([bond])");
  stepped_ = env_.stepped();
  double range = 2.0 * rmax;
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
    min_width[a] = range;
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
  face_walls_.set_reach(cells_.grid(), rmax);
  shear_ = LeesEdwards<D>(env_.shear_rate, box_, cells_.grid(), time_);
  sheared_ = shear_.on();
  double particle_volume = 0.0;
  for (const Kinematics<D>& k : s.kinematics)
    particle_volume +=
        D == 3 ? 4.0 / 3.0 * M_PI * k.radius * k.radius * k.radius : M_PI * k.radius * k.radius;
  face_walls_.find_squeeze_time(rmax, particle_volume, uniform_radius_);
  if (time_ >= face_walls_.squeeze_time()) throw_squeezed(time_);
  // Shear (sliding images) and steps (zones) keep full scans.
  incremental_crossings_ = options_.incremental_crossings && !stepped_ && !sheared_;
  for (int a = 0; a < D; ++a)
    three_cell_axis_ =
        three_cell_axis_ || (cells_.grid().periodic(a) && cells_.grid().cells_along(a) == 3);
}

template <int D, class Queue>
void EventEngine<D, Queue>::throw_squeezed(double t) const {
  double dmax = 0.0;
  for (const ParticleKind& sh : shapes_) dmax = std::max(dmax, 2.0 * sh.radius);
  face_walls_.throw_squeezed(t, dmax, uniform_radius_);
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
                     " is not inside its stored cell " + std::to_string(c));
  }
}

template <int D, class Queue>
std::uint64_t EventEngine<D, Queue>::next_renumber_after(std::uint64_t collisions) const {
  if (renumber_period_ == 0) return ~std::uint64_t{0};
  return (collisions / renumber_period_ + 1) * renumber_period_;
}

// Renumbers particles along the Morton order of their cells, so that the members of
// neighbouring cells sit close together in memory. Partners, ids, shapes and queue keys follow;
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
  permute(shape_);  // its spare last entry stays
  permute(spin_);
  permute(last_collision_);
  resting_.permute(order, done);
  soft_state_.permute(order, done);
  cells_.insert_all(hot_.data(), static_cast<std::uint32_t>(size()));
  if (queue_filled) queue_.reset(times);
}

template <int D, class Queue>
void EventEngine<D, Queue>::advance_to(std::uint32_t i, double t) {
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

template <int D, class Queue>
void EventEngine<D, Queue>::advance_accelerated(HotRecord<D>& h, double t) const {
  const Vec<D> x = position_at(h, t);
  h.vel = velocity_at(h, t);
  h.pos = x;
  h.time = t;
}

// Where a record's particle is at time t: a straight line, or a parabola under gravity. The
// candidate loops evaluate the same expressions in the same order.
template <int D, class Queue>
Vec<D> EventEngine<D, Queue>::position_at(const HotRecord<D>& h, double t) const {
  const double dt = t - h.time;
  Vec<D> x;
  for (int a = 0; a < D; ++a) {
    x[a] = h.pos[a] + h.vel[a] * dt;
    if (accelerated_) x[a] = x[a] + (half_gravity_[a] * dt) * dt;
  }
  return x;
}

template <int D, class Queue>
Vec<D> EventEngine<D, Queue>::velocity_at(const HotRecord<D>& h, double t) const {
  if (!accelerated_) return h.vel;
  const double dt = t - h.time;
  Vec<D> v;
  for (int a = 0; a < D; ++a) v[a] = h.vel[a] + env_.gravity[a] * dt;
  return v;
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
                          .shape = shape_.data(),
                          .shape_radius = shape_radius_.data(),
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
  if (accelerated_) {
    const Vec<D> vi = velocity_at(hot_[i], t);
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
  gather(hot_[i].cell, cells_.list(0));
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
  const Vec<D> xi = accelerated_ ? position_at(h, t) : h.pos + (t - h.time) * h.vel;
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
      pending_[i] = {Code::wall(face), 0};
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
  const Vec<D> xi = accelerated_ ? position_at(h, t) : h.pos + (t - h.time) * h.vel;
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
  const Vec<D> xi = accelerated_ ? position_at(hi, t) : hi.pos + (t - hi.time) * hi.vel;
  const Vec<D> xp = accelerated_ ? position_at(hp, t) : hp.pos + (t - hp.time) * hp.vel;
  const Vec<D> vi = accelerated_ ? velocity_at(hi, t) : hi.vel;
  const Vec<D> vp = accelerated_ ? velocity_at(hp, t) : hp.vel;
  Vec<D> r, g;
  for (int a = 0; a < D; ++a) {
    const int c = cells_.grid().coordinate(hi.cell, a) + d[a];
    const double shift = c < 0 ? -box_[a] : c >= cells_.grid().cells_along(a) ? box_[a] : 0.0;
    r[a] = xi[a] - (xp[a] + shift);
    g[a] = vi[a] - vp[a];
  }
  dt = pair_contact_time<D>(r.data(), g.data(), radius_of(i) + radius_of(p));
  return true;
}

// Whether some candidate sleeps: only then does a pair need the quartic of scan_with_sleepers;
// predictions away from the resting particles keep the vector loop.
// A sleeper moves on no event of its own (no crossing, no wall), but the awake particles around
// it were predicted while it still moved: its own scan keeps every pair (sleeper, awake) covered,
// as any particle's prediction covers its pairs after its motion changed. Among sleepers alone
// this is never.
template <int D, class Queue>
double EventEngine<D, Queue>::predict_asleep(const CandidateList& list, std::uint32_t i, double t) {
  double best = kNever;
  const std::uint32_t partner = scan_with_sleepers(list, i, t, best);
  pending_[i] = partner == kNoPartner
                    ? PendingEvent{Code::crossing(), 0}
                    : PendingEvent{Code::collision(partner), hot_[partner].collisions};
  return partner == kNoPartner ? kNever : t + best;
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
    collide_sheared(i, j, t);
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
  if (granular_contacts_) {
    collide_granular(i, j, t, r, r2);
  } else {
    const double mi = mass_of(i), mj = mass_of(j);
    const double s = HardSphere::impulse_factor(g_dot_r, r2, mi * mj / (mi + mj));  // J = s r
    for (int a = 0; a < D; ++a) {
      hi.vel[a] += s * r[a] / mi;
      hj.vel[a] -= s * r[a] / mj;
    }
    counters_.virial += s * r2;
    add_virial_tensor(r, s * r);
  }
  ++counters_.collisions;
  ++hi.collisions;
  ++hj.collisions;
  predict_pair(i, j, t);
}

// New events for both partners of a collision. Both neighbourhoods are gathered (and their
// records prefetched) before either is tested; partners in one cell share one list.
template <int D, class Queue>
inline void EventEngine<D, Queue>::predict_pair(std::uint32_t i, std::uint32_t j, double t) {
  gather(hot_[i].cell, cells_.list(0));
  const bool shared = hot_[j].cell == hot_[i].cell;
  if (!shared) gather(hot_[j].cell, cells_.list(1));
  queue_.update(i, predict_from(cells_.list(0), i, t));
  queue_.update(j, predict_from(cells_.list(shared ? 0 : 1), j, t));
}

// The impulse of a pair collision at separation r (i minus j) with the particles' present
// velocities: the contact law's, or the elastic one. For the rarer paths (a sleeper woken, a
// collision through a sheared face); collide() keeps its own one-pass elastic loop.
template <int D, class Queue>
void EventEngine<D, Queue>::resolve_pair(std::uint32_t i, std::uint32_t j, double t,
                                         const Vec<D>& r, double r2) {
  if (granular_contacts_) {
    collide_granular(i, j, t, r, r2);
    return;
  }
  HotRecord<D>& hi = hot_[i];
  HotRecord<D>& hj = hot_[j];
  const double mi = mass_of(i), mj = mass_of(j);
  const double s = HardSphere::impulse_factor(dot(hi.vel - hj.vel, r), r2, mi * mj / (mi + mj));
  hi.vel = hi.vel + (s / mi) * r;
  hj.vel = hj.vel - (s / mj) * r;
  counters_.virial += s * r2;
  add_virial_tensor(r, s * r);
}

// A collision under a granular contact law (restitution, roughness, TC model). The plain
// elastic case never comes here (collide() keeps its two-line impulse).
template <int D, class Queue>
void EventEngine<D, Queue>::collide_granular(std::uint32_t i, std::uint32_t j, double t,
                                             const Vec<D>& r, double r2) {
  HotRecord<D>& hi = hot_[i];
  HotRecord<D>& hj = hot_[j];
  bool elastic = false;
  if (!last_collision_.empty()) {
    elastic = t - last_collision_[i] < env_.tc || t - last_collision_[j] < env_.tc;
    last_collision_[i] = t;
    last_collision_[j] = t;
  }
  const std::uint32_t si = species_of(i), sj = species_of(j);
  ContactInput<D> in;
  in.normal = (1.0 / std::sqrt(r2)) * r;
  in.mass_i = mass_of(i);
  in.mass_j = mass_of(j);
  in.radius_i = radius_of(i);
  in.radius_j = radius_of(j);
  in.inertia_factor_i = env_.inertia_factor_of(si);
  in.inertia_factor_j = env_.inertia_factor_of(sj);
  in.force_elastic = elastic;
  Spin<D> wi{}, wj{};
  if (!spin_.empty()) {
    wi = to_spin<D>(spin_[i]);
    wj = to_spin<D>(spin_[j]);
  }
  const ContactResult<D> res =
      resolve_contact(*env_.contact_of(si, sj), in, hi.vel, hj.vel, wi, wj);
  if (!spin_.empty()) {
    spin_[i] = from_spin<D>(wi);
    spin_[j] = from_spin<D>(wj);
  }
  counters_.virial += dot(r, res.impulse);
  add_virial_tensor(r, res.impulse);
  counters_.dissipated_in_collisions += res.dissipated;
  counters_.elastic_by_rule += res.made_elastic ? 1u : 0u;
  counters_.sliding_collisions += res.slid ? 1u : 0u;
  separate(i, j, r, r2);
}

// After an inelastic collision the pair must recede as the candidate loops see it. A grazing
// pair whose approach speed is at round-off level may come out of the contact law still
// "approaching" in the loops' arithmetic (or not approaching in the law's, so no impulse), and
// would then collide again and again at one instant. A momentum-conserving nudge along r makes
// r.g slightly positive; its energy (round-off level) counts as dissipated with a minus sign.
template <int D, class Queue>
void EventEngine<D, Queue>::separate(std::uint32_t i, std::uint32_t j, const Vec<D>& r, double r2) {
  HotRecord<D>& hi = hot_[i];
  HotRecord<D>& hj = hot_[j];
  const double speed = std::sqrt(norm2(hi.vel)) + std::sqrt(norm2(hj.vel));
  const double wanted = 1e-12 * std::sqrt(r2) * speed;
  const double rg = dot(r, hi.vel - hj.vel);
  if (rg >= wanted) return;
  const double mi = mass_of(i), mj = mass_of(j);
  const double before = 0.5 * (mi * norm2(hi.vel) + mj * norm2(hj.vel));
  const double lambda = (wanted - rg) / (r2 * (1.0 / mi + 1.0 / mj));
  hi.vel = hi.vel + (lambda / mi) * r;
  hj.vel = hj.vel - (lambda / mj) * r;
  counters_.dissipated_in_collisions -= 0.5 * (mi * norm2(hi.vel) + mj * norm2(hj.vel)) - before;
  counters_.virial += lambda * r2;
  add_virial_tensor(r, lambda * r);
}

template <int D, class Queue>
std::pair<double, int> EventEngine<D, Queue>::next_wall_contact(std::uint32_t i, double t,
                                                                double horizon) const {
  const HotRecord<D>& h = hot_[i];
  return face_walls_.next_contact(position_at(h, t), velocity_at(h, t), radius_of(i), h.cell,
                                  cells_.grid(), t, horizon);
}

// A particle meets a wall: the wall is a partner of infinite mass moving with its velocity
// (sliding and normal) plus its vibration velocity, so restitution applies to the normal
// velocity relative to the wall.
template <int D, class Queue>
void EventEngine<D, Queue>::hit_wall(std::uint32_t i, int face, double t) {
  if (t >= face_walls_.squeeze_time()) throw_squeezed(t);
  if (soft_) [[unlikely]] {
    hit_wall_soft(i, face, t);
    return;
  }
  const bool again = wedged(i, t);
  advance_to(i, t);
  HotRecord<D>& h = hot_[i];
  const Wall<D>& w = face_walls_.wall(face);
  bool elastic = false;
  if (!last_collision_.empty()) {
    elastic = t - last_collision_[i] < env_.tc;
    last_collision_[i] = t;
  }
  Spin<D> wi{};
  if (!spin_.empty()) wi = to_spin<D>(spin_[i]);
  const ContactResult<D> res = face_walls_.resolve(
      face, t, mass_of(i), radius_of(i), env_.inertia_factor_of(species_of(i)), elastic, h.vel, wi);
  if (!spin_.empty()) spin_[i] = from_spin<D>(wi);
  counters_.dissipated_at_walls += res.dissipated;
  counters_.work_by_walls += FaceWalls<D>::work(res);
  if (resting_.on() && !w.vibrates()) {
    counters_.dissipated_at_walls -=
        settle_after_contact(i, face_normal<D>(face), w.velocity, t, again);
  }
  counters_.elastic_by_rule += res.made_elastic ? 1u : 0u;
  counters_.sliding_collisions += res.slid ? 1u : 0u;
  ++counters_.wall_collisions;
  ++h.collisions;  // its velocity changed: partners' predictions with it are stale
  queue_.update(i, predict(i, t));
}

template <int D, class Queue>
void EventEngine<D, Queue>::add_virial_tensor(const Vec<D>& r, const Vec<D>& impulse) {
  for (int a = 0; a < D; ++a)
    for (int b = 0; b < D; ++b) counters_.virial_tensor[a * D + b] += r[a] * impulse[b];
}

template <int D, class Queue>
void EventEngine<D, Queue>::fall_asleep(std::uint32_t i, double t) {
  HotRecord<D>& h = hot_[i];
  h.time = t;
  h.vel = Vec<D>{};
  if (!spin_.empty()) spin_[i] = AngularVelocity<D>{};
  resting_.fall_asleep(i);
  ++counters_.fell_asleep;
}

template <int D, class Queue>
void EventEngine<D, Queue>::wake(std::uint32_t i, double t) {
  resting_.wake(i);
  hot_[i].time = t;  // at rest where it slept
}

template <int D, class Queue>
double EventEngine<D, Queue>::settle_after_contact(std::uint32_t i, const Vec<D>& n,
                                                   const Vec<D>& support_velocity, double t,
                                                   bool again) {
  using Settle = typename Resting::Settle;
  HotRecord<D>& h = hot_[i];
  const Settle settle =
      resting_.settle(h.vel, n, support_velocity, again, [&] { return resting_on_support(i, t); });
  const double m = mass_of(i);
  if (settle.kind == Settle::kSleep) {
    const double before = 0.5 * m * norm2(h.vel) + spin_energy(i);
    fall_asleep(i, t);
    return -before;
  }
  if (settle.kind == Settle::kNothing) return 0.0;
  const double before = 0.5 * m * norm2(h.vel);
  h.vel = h.vel + settle.lift * n;
  return 0.5 * m * norm2(h.vel) - before;
}

// Whether particle i meets something again after moving less than 1e-9 of its diameter since
// its previous event: between resting things with no clearance (a gap of exactly its size, to
// round-off) the contacts would follow each other without end, at one instant or in a Zeno
// sequence. (Called before the particle is advanced to t.)
template <int D, class Queue>
bool EventEngine<D, Queue>::wedged(std::uint32_t i, double t) const {
  const double moved = (t - hot_[i].time) * std::sqrt(norm2(velocity_of(i, t)));
  return Resting::wedged(moved, radius_of(i));
}

template <int D, class Queue>
double EventEngine<D, Queue>::spin_energy(std::uint32_t i) const {
  if (spin_.empty()) return 0.0;
  const double r = radius_of(i);
  return 0.5 * env_.inertia_factor_of(species_of(i)) * mass_of(i) * r * r * norm2(spin_[i]);
}

// Whether particle i touches (within a few sleep-speed bounce heights) a fixed wall or a
// sleeper that gravity presses it onto.
template <int D, class Queue>
bool EventEngine<D, Queue>::resting_on_support(std::uint32_t i, double t) {
  const double eps = resting_.support_distance(radius_of(i));
  const Vec<D> x = position_of(i, t);
  for (int f = 0; f < 2 * D; ++f) {
    if (!face_walls_.is_wall(f)) continue;
    const Wall<D>& w = face_walls_.wall(f);
    if (w.vibrates() || norm2(w.velocity) != 0.0) continue;
    if (resting_.holds_up(face_normal<D>(f)) && face_walls_.gap(f, x, t) - radius_of(i) < eps)
      return true;
  }
  CandidateList& list = cells_.list(1);
  gather(hot_[i].cell, list);
  for (std::uint32_t k = 0; k < list.count; ++k) {
    const std::uint32_t j = list.ids[k];
    if (j == i || !is_asleep(j)) continue;
    Vec<D> r = x - hot_[j].pos;
    if (list.n_shifts > 1) r = r - list.shifts[list.shift[k]];
    const double dist = std::sqrt(norm2(r));
    if (resting_.holds_up((1.0 / dist) * r) && dist - (radius_of(i) + radius_of(j)) < eps)
      return true;
  }
  return false;
}

// An awake particle i meets a sleeping j. A gentle contact leaves j asleep (an immovable
// support, as a wall of infinite mass); a harder one wakes j for an ordinary collision.
template <int D, class Queue>
void EventEngine<D, Queue>::collide_with_sleeper(std::uint32_t i, std::uint32_t j, double t,
                                                 const Vec<D>& r, double r2, bool again) {
  HotRecord<D>& hi = hot_[i];
  const Vec<D> n = (1.0 / std::sqrt(r2)) * r;
  const double gn = dot(hi.vel, n);
  if (resting_.hit_wakes(gn)) {
    wake(j, t);
    resolve_pair(i, j, t, r, r2);
    ++hot_[j].collisions;
  } else {
    const ContactModel plain;
    WallContactInput<D> in;
    in.normal = n;
    in.mass = mass_of(i);
    in.radius = radius_of(i);
    in.inertia_factor = env_.inertia_factor_of(species_of(i));
    const ContactModel& law =
        env_.contact.empty() ? plain : *env_.contact_of(species_of(i), species_of(j));
    Spin<D> wi{};
    if (!spin_.empty()) wi = to_spin<D>(spin_[i]);
    const ContactResult<D> res = resolve_wall_contact(law, in, hi.vel, wi);
    if (!spin_.empty()) spin_[i] = from_spin<D>(wi);
    counters_.dissipated_in_collisions += res.dissipated;
    counters_.virial += dot(r, res.impulse);
    add_virial_tensor(r, res.impulse);
    counters_.dissipated_in_collisions -= settle_after_contact(i, n, Vec<D>{}, t, again);
  }
  ++counters_.collisions;
  ++hi.collisions;
  queue_.update(i, predict(i, t));
  queue_.update(j, predict(j, t));
}

// The candidate test when some particles sleep: a sleeping candidate does not fall, so the
// pair's relative acceleration is +-g and its contact time a quartic. Scalar; only gravity
// runs with resting particles take it.
template <int D, class Queue>
std::uint32_t EventEngine<D, Queue>::scan_with_sleepers(const CandidateList& list, std::uint32_t i,
                                                        double t, double& best) const {
  const Vec<D> xi = position_of(i, t), vi = velocity_of(i, t);
  const bool si = is_asleep(i);
  std::uint32_t found = kNoPartner;
  for (std::uint32_t k = 0; k < list.count; ++k) {
    const std::uint32_t j = list.ids[k];
    const bool sj = is_asleep(j);
    if (j == i || (si && sj)) continue;  // sleepers never meet each other
    Vec<D> r = xi - position_of(j, t);
    if (list.n_shifts > 1) r = r - list.shifts[list.shift[k]];
    const Vec<D> g = vi - velocity_of(j, t);
    // Relative acceleration: gravity acts on the awake one of a mixed pair.
    const Vec<D> accel = sj ? env_.gravity : (si ? -1.0 * env_.gravity : Vec<D>{});
    const double sigma = radius_of(i) + radius_of(j);
    const double dt =
        pair_contact_time_accelerated<D>(r.data(), g.data(), accel.data(), sigma, best);
    if (dt < best) {
      best = dt;
      found = j;
    }
  }
  return found;
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
    if (partner < kFirstCode) queue_.update(partner, predict(partner, t));
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
    if (sheared_ && x.axis == 1) cross_shear_face(i, -1, t, c);
  } else if (c[x.axis] >= cells_.grid().cells_along(x.axis)) {
    c[x.axis] -= cells_.grid().cells_along(x.axis);
    h.pos[x.axis] -= box_[x.axis];
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
  const std::uint32_t i = queue_.top();
  const double t = queue_.top_time();
  if (!std::isfinite(t)) return EventKind::kNone;
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
    hit_wall(i, e.code.wall_face(), t);
    return EventKind::kWallCollision;
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
    for (std::uint32_t i = 0; i < size(); ++i)
      ke += 0.5 * mass_of(i) * norm2(velocity_of(i, time_));
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
    const Vec<D> u = env_.streaming_velocity(position_of(i, time_), box_);
    ke += 0.5 * mass_of(i) * norm2(velocity_of(i, time_) - u);
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
  for (std::uint32_t i = 0; i < size(); ++i) p = p + mass_of(i) * velocity_of(i, time_);
  return p;
}

template <int D, class Queue>
double EventEngine<D, Queue>::bytes_per_particle() const {
  // Per-particle arrays plus the grid's and the queue's own (cells and buckets included,
  // divided by N); the shape table is a few bytes in all.
  const double shapes =
      static_cast<double>(shapes_.size() * sizeof(ParticleKind)) / static_cast<double>(size());
  return static_cast<double>(sizeof(HotRecord<D>) + sizeof(PendingEvent) + sizeof(std::uint32_t) +
                             (shape_.empty() ? 0 : sizeof(std::uint16_t))) +
         shapes + cells_.grid().bytes_per_particle() +
         static_cast<double>(queue_.bytes_per_particle());
}

// --- Lees-Edwards shear (boundaries/lees_edwards.hpp) ----------------------------------------

// The images moved on by a cell width: the particles of the two face rows (every (x, z) column
// at y = 0 and y = n_y - 1) are predicted again.
template <int D, class Queue>
void EventEngine<D, Queue>::shift_images() {
  time_ = shear_.shift();
  const int nx = cells_.grid().cells_along(0), ny = cells_.grid().cells_along(1);
  const int nz = D == 3 ? cells_.grid().cells_along(D - 1) : 1;
  for (const int y : {0, ny - 1}) {
    for (int column = 0; column < nx * nz; ++column) {
      std::array<int, D> at{};
      at[0] = column % nx;
      at[1] = y;
      if constexpr (D == 3) at[2] = column / nx;
      const std::uint32_t cell = cells_.grid().index(cells_.grid().code_at(at));
      for (std::uint32_t p = cells_.grid().first(cell); p != cells_.grid().end();
           p = cells_.grid().next(p))
        queue_.update(p, predict(p, time_));
    }
  }
}

// The neighbourhood of a cell in the first or last row along y: its own row and the inner one
// as usual, the row beyond the face through the sliding images.
template <int D, class Queue>
void EventEngine<D, Queue>::gather_sheared(CellCode cell, CandidateList& list) {
  std::uint32_t n = 0, n_shifts = 1;  // shifts[0]: none
  list.shifts[0] = Vec<D>{};
  list.velocity_shifts[0] = Vec<D>{};
  // Predictions happen at time_.
  shear_.for_each_neighbour_cell(
      cell, cells_.grid(), time_,
      [&](const std::array<int, D>& at, const Vec<D>& shift, const Vec<D>& vshift) {
        const std::uint32_t tag = n_shifts++;
        list.shifts[tag] = shift;
        list.velocity_shifts[tag] = vshift;
        for (std::uint32_t p = cells_.grid().first(cells_.grid().index(cells_.grid().code_at(at)));
             p != cells_.grid().end(); p = cells_.grid().next(p)) {
          if (list.ids.size() - n < Cells::kCandidateSlack) Cells::grow(list);
          list.ids[n] = p;
          list.shift[n++] = tag;
        }
      });
  list.count = n;
  list.n_shifts = n_shifts;
}

// The candidate test for a sheared list: like the scalar loop, with each image's velocity.
template <int D, class Queue>
std::uint32_t EventEngine<D, Queue>::scan_sheared(const CandidateList& list, std::uint32_t i,
                                                  double t, double& best) const {
  const Vec<D> xi = position_at(hot_[i], t), vi = hot_[i].vel;
  std::uint32_t found = kNoPartner;
  for (std::uint32_t k = 0; k < list.count; ++k) {
    const std::uint32_t j = list.ids[k];
    const std::uint32_t tag = list.shift[k];
    const Vec<D> r = xi - (position_at(hot_[j], t) + list.shifts[tag]);
    const Vec<D> g = vi - (hot_[j].vel + list.velocity_shifts[tag]);
    const double dt = pair_contact_time<D>(r.data(), g.data(), radius_of(i) + radius_of(j));
    if (dt < best) {
      best = dt;
      found = j;
    }
  }
  return found;
}

// Pairs in contact are closer than a third of the box along y, so the image is unambiguous.
template <int D, class Queue>
Vec<D> EventEngine<D, Queue>::sheared_separation(std::uint32_t i, std::uint32_t j, double t,
                                                 Vec<D>& image_velocity) const {
  return shear_.separation(position_of(i, t) - position_of(j, t), t, periodic_axes(),
                           image_velocity);
}

// A collision under shear: the impulse is the ordinary one between i and the image of j it
// meets; only the velocity j's image has beyond j's own is taken out again. The kinetic energy
// that adds in the box frame is work done by the shearing boundaries.
template <int D, class Queue>
void EventEngine<D, Queue>::collide_sheared(std::uint32_t i, std::uint32_t j, double t) {
  advance_to(i, t);
  advance_to(j, t);
  HotRecord<D>& hi = hot_[i];
  HotRecord<D>& hj = hot_[j];
  Vec<D> u;
  const Vec<D> r = sheared_separation(i, j, t, u);
  const double r2 = norm2(r);
  const Vec<D> vj_before = hj.vel;
  hj.vel = hj.vel + u;
  resolve_pair(i, j, t, r, r2);
  hj.vel = hj.vel - u;
  counters_.work_by_shear -= mass_of(j) * dot(u, hj.vel - vj_before);
  ++counters_.collisions;
  ++hi.collisions;
  ++hj.collisions;
  predict_pair(i, j, t);
}

// Particle i leaves through the high (side +1) or low (-1) y face and comes back as its image:
// its y is already wrapped; x and v_x follow the image, and its column is found again.
template <int D, class Queue>
void EventEngine<D, Queue>::cross_shear_face(std::uint32_t i, int side, double t,
                                             std::array<int, D>& c) {
  HotRecord<D>& h = hot_[i];
  const double ke = norm2(h.vel);
  c[0] = shear_.cross_face(h.pos, h.vel, side, t, cells_.grid());
  counters_.work_by_shear += 0.5 * mass_of(i) * (norm2(h.vel) - ke);
}

template <int D, class Queue>
void EventEngine<D, Queue>::validate() {
  const double t = time_;
  const auto n = static_cast<std::uint32_t>(size());
  auto fail = [&](const std::string& what) {
    std::ostringstream os;
    os << "engine validation failed at t=" << t << " after " << counters_.events
       << " events: " << what;
    throw std::logic_error(os.str());
  };
  auto name = [&](std::uint32_t i) { return std::to_string(id_[i]); };
  cells_.validate(hot_.data(), n, fail, name);  // the cell lists
  for (std::uint32_t i = 0; i < n; ++i) {
    const HotRecord<D>& h = hot_[i];
    const Vec<D> x = position_of(i, t);
    for (int f = 0; f < 2 * D; ++f) {
      if (!face_walls_.is_wall(f)) continue;
      const double gap = face_walls_.gap(f, x, t);
      if (gap >= radius_of(i) * (1.0 - 1e-9)) continue;
      // A soft contact overlaps its wall while frozen and after its release, leaving; turned
      // back towards the wall (by a third body), it meets the wall now.
      const double leaving = (f % 2 == 0 ? 1.0 : -1.0) *
                             (velocity_of(i, t)[f / 2] - face_walls_.wall(f).velocity[f / 2]);
      const bool soft_ok =
          soft_ && gap > 0.75 * radius_of(i) &&
          (soft_state_.partner(i) == wall_partner(f) || leaving >= 0.0 || queue_.time_of(i) <= t);
      if (!soft_ok) fail("particle " + name(i) + " overlaps a wall");
    }
    for (int a = 0; a < D; ++a) {
      const double tol = 1e-9 * box_[a];
      if (x[a] < cells_.grid().lower_bound(h.cell, a) - tol ||
          x[a] > cells_.grid().upper_bound(h.cell, a) + tol)
        fail("particle " + name(i) + " outside its cell");
    }
    const Code code = pending_[i].code;
    if (code.is_collision() && code.partner() >= n)
      fail("particle " + name(i) + " has a partner out of range");
    if (code.is_crossing() && !code.is_full_scan_crossing() && !incremental_crossings_)
      fail("particle " + name(i) + " keeps a contact beyond its crossing with full scans");
    if (code.keeps_contact() && code.kept_partner() >= n)
      fail("particle " + name(i) + " keeps a contact partner out of range");
  }
  // Whether a pending event lies after a contact due at `due`, beyond round-off: positions are
  // exact to ~1e-12 of the box, which a slow approach (speed) turns into a longer time.
  const double length = *std::max_element(box_.begin(), box_.end());
  auto late = [&](double pending, double due, double speed) {
    return pending > due * (1.0 + 1e-12) + 1e-12 + 1e-12 * length / speed;
  };
  // Wall contacts, brute force over all particles: none comes before the particle's event.
  for (std::uint32_t i = 0; walls_ && i < n; ++i) {
    if (is_asleep(i)) continue;
    if (in_deferred_contact(i, t)) {  // frozen until the release, then as its record says
      const HotRecord<D>& h = hot_[i];
      for (int f = 0; f < 2 * D; ++f) {
        if (!face_walls_.is_wall(f)) continue;
        if (face_walls_.event_time(f, position_of(i, t), frozen_velocity_of(i), radius_of(i), t,
                                   h.time - t) < h.time - t)
          fail("particle " + name(i) + " meets wall " + std::to_string(f) +
               " inside its deferred soft contact");
        const double due =
            h.time + face_walls_.event_time(f, h.pos, h.vel, radius_of(i), h.time, kNever);
        const double speed = std::abs(h.vel[f / 2] - face_walls_.wall(f).velocity[f / 2]);
        if (std::isfinite(due) && late(queue_.time_of(i), due, speed))
          fail("particle " + name(i) + " meets wall " + std::to_string(f) +
               " after its deferred release before its pending event");
      }
      continue;
    }
    const Vec<D> x = position_of(i, t), v = velocity_of(i, t);
    for (int f = 0; f < 2 * D; ++f) {
      if (!face_walls_.is_wall(f)) continue;
      const double due = t + face_walls_.event_time(f, x, v, radius_of(i), t, kNever);
      const int a = f / 2;
      const double speed_at_contact =
          std::abs(v[a] + env_.gravity[a] * (due - t) - face_walls_.wall(f).velocity[a]);
      if (std::isfinite(due) && late(queue_.time_of(i), due, speed_at_contact)) {
        fail("particle " + name(i) + " meets wall " + std::to_string(f) + " at " +
             std::to_string(due) + " before its pending event (at " +
             std::to_string(queue_.time_of(i)) + ", partner code " +
             std::to_string(pending_[i].code.bits()) + ", cell " + std::to_string(hot_[i].cell) +
             ", local time " + std::to_string(hot_[i].time) + ")");
      }
    }
  }
  // Queue order: the top is the soonest stored event; nothing lies in the past.
  double tmin = kNever;
  for (std::uint32_t i = 0; i < n; ++i) {
    tmin = std::min(tmin, queue_.time_of(i));
    if (queue_.time_of(i) < t) fail("event of " + name(i) + " lies in the past");
  }
  if (queue_.top_time() != tmin) fail("queue top is not the soonest event");
  // Prediction invariant and overlaps, brute force over all pairs: some pending event of the
  // pair (a collision, or a crossing that triggers a new scan) comes no later than its contact.
  // A pair under a step potential: its zone holds its distance, and its next boundary comes no
  // sooner than a pending event.
  auto check_step_covered = [&](std::uint32_t i, std::uint32_t j, const Vec<D>& r, const Vec<D>& g,
                                PairSteps::Zone z) {
    const ZoneTable& table = steps_.table(z.table);
    const double r2 = norm2(r), rg = dot(r, g), g2 = norm2(g);
    const double inner = std::sqrt(table.r2[z.zone]);
    const double outer = z.zone > 0 ? std::sqrt(table.r2[z.zone - 1]) : kNever;
    const double distance = std::sqrt(r2);
    auto describe = [&] {
      std::ostringstream os;
      os.precision(17);
      os << "pair " << name(i) << "," << name(j) << " in zone " << z.zone << " (between " << inner
         << " and " << outer << ") at distance " << distance;
      return os.str();
    };
    if (distance < inner * (1.0 - 1e-9) || distance > outer * (1.0 + 1e-9))
      fail(describe() + " is outside its zone");
    const double dt = table.event_time(z.zone, r2, rg, g2);
    if (!std::isfinite(dt)) return;
    const bool inward = rg < 0.0 && rg * rg - g2 * (r2 - table.r2[z.zone]) > 0.0;
    const double boundary = inward ? inner : outer;
    if (inward && g2 > 0.0) {  // a graze of the inner boundary may be a hit or a miss
      const double closest = std::sqrt(std::max(0.0, r2 - rg * rg / g2));
      if (boundary - closest < 1e-9 * boundary) return;
    }
    const double normal_speed = std::abs(dot(r + dt * g, g)) / boundary;
    const double bound = std::min(queue_.time_of(i), queue_.time_of(j));
    if (late(bound, t + dt, normal_speed)) {
      std::ostringstream os;
      os.precision(17);
      os << describe() << " meets its step at " << boundary << " at time " << t + dt
         << " but no pending event comes first (theirs: " << queue_.time_of(i) << ", "
         << queue_.time_of(j) << ")";
      fail(os.str());
    }
  };
  // A pair with a member in a deferred soft contact: piecewise straight lines (frozen, then
  // released), no gravity, no shear.
  auto check_deferred_covered = [&](std::uint32_t i, std::uint32_t j, Vec<D> r, double sigma,
                                    const char* which) {
    const std::uint32_t both[2] = {i, j};
    double ends[3];
    int pieces = 0;
    for (const std::uint32_t k : both)
      if (in_deferred_contact(k, t)) ends[pieces++] = hot_[k].time;
    if (pieces == 2 && ends[1] < ends[0]) std::swap(ends[0], ends[1]);
    ends[pieces++] = kNever;
    auto velocity = [&](std::uint32_t k, double when) {
      return in_deferred_contact(k, when) ? frozen_velocity_of(k) : hot_[k].vel;
    };
    Vec<D> g[3];
    double start = t;
    for (int p = 0; p < pieces; ++p) {
      g[p] = velocity(i, start) - velocity(j, start);
      start = ends[p];
    }
    const double due = piecewise_contact_time<D>(r, t, ends, g, pieces, t, kNever, sigma);
    if (!std::isfinite(due)) return;
    start = t;
    int p = 0;
    for (; ends[p] <= due; ++p) {  // r and g at the contact
      r = r + (ends[p] - start) * g[p];
      start = ends[p];
    }
    if (norm2(g[p]) > 0.0) {  // a graze at round-off level may be a hit or a miss
      const double rg = std::min(0.0, dot(r, g[p]));
      const double closest = std::sqrt(std::max(0.0, norm2(r) - rg * rg / norm2(g[p])));
      if (sigma - closest < 1e-9 * sigma) return;
    }
    const Vec<D> r_contact = r + (due - start) * g[p];
    const double normal_speed = std::abs(dot(r_contact, g[p])) / sigma;
    const double bound = std::min(queue_.time_of(i), queue_.time_of(j));
    if (late(bound, due, normal_speed)) {
      std::ostringstream os;
      os.precision(17);
      os << "pair " << name(i) << "," << name(j) << " (" << which << ", deferred soft contact) "
         << "collides at " << due
         << " but no pending event comes first (theirs: " << queue_.time_of(i) << ", "
         << queue_.time_of(j) << ")";
      fail(os.str());
    }
  };
  auto check_covered = [&](std::uint32_t i, std::uint32_t j, const Vec<D>& r, const char* which,
                           const Vec<D>& image_velocity = Vec<D>{}) {
    if (is_asleep(i) && is_asleep(j)) return;  // neither moves
    const Vec<D> g = velocity_of(i, t) - (velocity_of(j, t) + image_velocity);
    Vec<D> accel{};
    if (is_asleep(j)) accel = env_.gravity;
    if (is_asleep(i)) accel = -1.0 * env_.gravity;
    if (stepped_) {
      const PairSteps::Zone z = steps_.find(i, j, steps_.pair_table(species_of(i), species_of(j)));
      if (z.table != PairSteps::kHard) {
        // Within a cut-off (never more than a cell width) the nearest image is the one the
        // loops test; another image of a listed pair lies beyond its zone.
        if (std::string_view(which) == "nearest image") check_step_covered(i, j, r, g, z);
        return;
      }
    }
    const double sigma = radius_of(i) + radius_of(j);
    if (in_deferred_contact(i, t) || in_deferred_contact(j, t)) {
      if (!frozen_pair(i, j)) check_deferred_covered(i, j, r, sigma, which);
      return;
    }
    const double due =
        t + pair_contact_time_accelerated<D>(r.data(), g.data(), accel.data(), sigma);
    double bound = std::min(queue_.time_of(i), queue_.time_of(j));
    // Under shear the next image shift predicts the particles next to the y faces again.
    if (sheared_ && (shear_.next_to_face(hot_[i].cell, cells_.grid()) ||
                     shear_.next_to_face(hot_[j].cell, cells_.grid())))
      bound = std::min(bound, shear_.next_shift_time());
    // A straight-line pair that would only graze (its overlap at closest approach is at the
    // round-off level, as in the near-tangential contacts of a collapsing cluster) may be
    // called a hit or a near miss by round-off; either is right.
    if (norm2(accel) == 0.0 && norm2(g) > 0.0) {
      const double rg = std::min(0.0, dot(r, g));
      const double closest = std::sqrt(std::max(0.0, norm2(r) - rg * rg / norm2(g)));
      if (sigma - closest < 1e-9 * sigma) return;
    }
    // The normal approach speed at contact sets how much round-off moves the contact time.
    const double dt = due - t;
    const Vec<D> r_contact = r + dt * g + (0.5 * dt * dt) * accel;
    const double normal_speed = std::abs(dot(r_contact, g + dt * accel)) / sigma;
    if (std::isfinite(due) && late(bound, due, normal_speed)) {
      std::ostringstream os;
      os.precision(17);
      os << "pair " << name(i) << "," << name(j) << " (" << which << ") collides at " << due
         << " but no pending event comes first (theirs: " << queue_.time_of(i) << ", "
         << queue_.time_of(j) << "; asleep: " << is_asleep(i) << is_asleep(j)
         << "; distance - sigma: " << std::sqrt(norm2(r)) - sigma << ")";
      fail(os.str());
    }
  };
  for (std::uint32_t i = 0; i < n; ++i) {
    const Vec<D> xi = position_of(i, t);
    const std::uint32_t ci = hot_[i].cell;
    for (std::uint32_t j = i + 1; j < n; ++j) {
      const double sigma = radius_of(i) + radius_of(j);
      if (sheared_) {
        Vec<D> u;
        const Vec<D> r = sheared_separation(i, j, t, u);
        if (norm2(r) < sigma * sigma * (1.0 - 1e-9))
          fail("particles " + name(i) + " and " + name(j) + " overlap");
        check_covered(i, j, r, "sheared image", u);
        continue;
      }
      const Vec<D> raw = xi - position_of(j, t);
      // The image the engine tests (neighbouring cells).
      std::array<int, D> d;
      if (cells_.grid().neighbour_offset(ci, hot_[j].cell, d)) {
        Vec<D> r = raw;
        for (int a = 0; a < D; ++a) {
          const int c = cells_.grid().coordinate(ci, a) + d[a];
          if (cells_.grid().periodic(a) && c < 0) r[a] += box_[a];
          if (cells_.grid().periodic(a) && c >= cells_.grid().cells_along(a)) r[a] -= box_[a];
        }
        check_covered(i, j, r, "neighbour-cell image");
      }
      Vec<D> r = raw;
      for (int a = 0; a < D; ++a)
        if (cells_.grid().periodic(a)) r[a] = minimum_image(r[a], box_[a]);
      if (norm2(r) < sigma * sigma * (1.0 - 1e-9)) {
        // Soft spheres overlap while frozen in a contact and after its release, receding; an
        // approaching overlap must collide now (check_covered).
        const bool soft_ok =
            soft_ && norm2(r) > 0.5625 * sigma * sigma &&
            (frozen_pair(i, j) || dot(r, velocity_of(i, t) - velocity_of(j, t)) >= 0.0 ||
             std::min(queue_.time_of(i), queue_.time_of(j)) <= t);
        if (!soft_ok) fail("particles " + name(i) + " and " + name(j) + " overlap");
      }
      check_covered(i, j, r, "nearest image");
    }
  }
}

// --- Stepped potentials ----------------------------------------------------------------------

template <int D, class Queue>
Vec<D> EventEngine<D, Queue>::separation(std::uint32_t i, std::uint32_t j, double t) const {
  Vec<D> r = position_of(i, t) - position_of(j, t);
  for (int a = 0; a < D; ++a)
    if (cells_.grid().periodic(a)) r[a] = minimum_image(r[a], box_[a]);
  return r;
}

// The capture map at the start: bonds first (each always listed), then the stored zones, or,
// for a fresh state, every non-bonded pair's zone from its distance.
template <int D, class Queue>
void EventEngine<D, Queue>::init_zones(const ParticleSystem<D>& s, StartMode mode) {
  if (!stepped_) return;
  const auto n = static_cast<std::uint32_t>(size());
  std::vector<std::uint32_t> internal(n);
  for (std::uint32_t k = 0; k < n; ++k) internal[id_[k]] = k;
  auto pair_name = [](std::uint32_t a, std::uint32_t b) {
    return std::to_string(a) + "-" + std::to_string(b);
  };
  for (const Bond& b : bonds_) {
    if (b.i >= n || b.j >= n || b.i == b.j) {
      throw InputError("bond " + pair_name(b.i, b.j) + " names a particle that does not exist");
    }
    if (b.type >= env_.bond_table.size()) {
      throw InputError("bond " + pair_name(b.i, b.j) + " has type " + std::to_string(b.type) +
                       " but only " + std::to_string(env_.bond_table.size()) +
                       " bond potential(s) are given");
    }
    const auto table = static_cast<std::uint16_t>(env_.bond_table[b.type]);
    const std::uint32_t i = internal[b.i], j = internal[b.j];
    const double r2 = norm2(separation(i, j, time_));
    const std::uint16_t zone = steps_.table(table).zone_at(r2);
    if (zone == 0 && !s.zones) {
      throw InputError("bond " + pair_name(b.i, b.j) + " is stretched to " +
                       std::to_string(std::sqrt(r2)) + ", beyond its maximum length " +
                       std::to_string(std::sqrt(steps_.table(table).r2[0])));
    }
    steps_.set(i, j, {table, zone});
  }
  if (s.zones) {
    for (const PairZone& z : *s.zones) {
      if (z.i >= n || z.j >= n || z.i == z.j) {
        throw InputError("the zone of pair " + pair_name(z.i, z.j) +
                         " names a particle that does not exist");
      }
      const std::uint32_t i = internal[z.i], j = internal[z.j];
      const PairSteps::Zone now =
          steps_.find(i, j, steps_.pair_table(species_of(i), species_of(j)));
      if (now.table == PairSteps::kHard || z.zone > steps_.table(now.table).core_zone ||
          (z.zone == 0 && !steps_.bonded(now.table))) {
        throw InputError("the stored zone " + std::to_string(z.zone) + " of pair " +
                         pair_name(z.i, z.j) + " does not fit its step potential");
      }
      steps_.set(i, j, {now.table, static_cast<std::uint16_t>(z.zone)});
    }
    return;
  }
  if (mode == StartMode::kResume) {
    throw InputError("cannot resume: the state carries no pair zones of the stepped potentials");
  }
  const Vec<D> no_shift{};
  for (std::uint32_t i = 0; i < n; ++i) {
    gather(hot_[i].cell, cells_.list(0));
    const CandidateList& list = cells_.list(0);
    const Vec<D> xi = position_of(i, time_);
    for (std::uint32_t k = 0; k < list.count; ++k) {
      const std::uint32_t j = list.ids[k];
      if (j <= i) continue;
      const std::uint16_t table = steps_.pair_table(species_of(i), species_of(j));
      if (table == PairSteps::kHard ||
          steps_.find(i, j, PairSteps::kHard).table != PairSteps::kHard)
        continue;  // no steps, or bonded
      const Vec<D>& shift = list.n_shifts > 1 ? list.shifts[list.shift[k]] : no_shift;
      const double r2 = norm2(xi - (position_of(j, time_) + shift));
      const std::uint16_t zone = steps_.table(table).zone_at(r2);
      if (zone > 0) steps_.set(i, j, {table, zone});
    }
  }
}

// The candidate loop of stepped potentials: per candidate, the zone from the capture map and
// the time to the zone's next boundary (or, for a pair without steps, its contact). Most
// candidates sit beyond every step (zone 0): for them only an approach to the outermost
// boundary counts, and the hard-sphere loop's cheap bound rejects most before a square root.
// With AVX-512, scan_stepped_avx512 (candidate_scan.cpp) tests them eight at a time and the
// listed ones together at the end, with the same result as scan_stepped_loop.
template <int D, class Queue>
std::uint32_t EventEngine<D, Queue>::scan_stepped(const CandidateList& list, std::uint32_t i,
                                                  double t, double& best) {
  steps_.load(i);
  // Per shape of the candidate: its pair's table with i, and the squared distance of the
  // pair's outermost boundary (the contact distance of a pair without steps).
  const std::uint32_t si = species_of(i);
  const double ri = radius_of(i);
  const std::size_t shapes = shapes_.size();
  step_row_table_.resize(shapes);
  step_row_reach2_.resize(shapes);
  for (std::size_t k = 0; k < shapes; ++k) {
    const std::uint16_t table = steps_.pair_table(si, shapes_[k].species);
    const double sigma = ri + shapes_[k].radius;
    step_row_table_[k] = table;
    step_row_reach2_[k] = table == PairSteps::kHard ? sigma * sigma : steps_.table(table).r2[0];
  }
  if (!vector_scan_) {
    return accelerated_ ? scan_stepped_loop<true>(list, i, t, best)
                        : scan_stepped_loop<false>(list, i, t, best);
  }
  const std::size_t room = list.count + 8;
  if (step_held_index_.size() < room) {
    step_held_.resize(3 * room);
    step_held_stamp_.resize(room);
    step_held_index_.resize(room);
  }
  const HotRecord<D>& h = hot_[i];
  const SteppedScan<D> scan{
      .base = scan_of(list, i, nullptr),  // its contact distances are not read
      .self = i,
      .stamps = steps_.stamps(),
      .epoch = steps_.epoch(),
      .shape = shape_.empty() ? nullptr : shape_.data(),
      .row_reach2 = step_row_reach2_.data(),
      .flat_r2 = steps_.flat_r2(),
      .table_offset = steps_.tables() > 1 ? steps_.table_offset() : nullptr,
      .held_r2 = step_held_.data(),
      .held_rg = step_held_.data() + room,
      .held_g2 = step_held_.data() + 2 * room,
      .held_stamp = step_held_stamp_.data(),
      .held_index = step_held_index_.data()};
  const Vec<D> xi = position_at(h, t), vi = velocity_at(h, t);
  const std::uint32_t k = accelerated_ ? scan_stepped_avx512<D, true>(scan, t, xi, vi, best)
                                       : scan_stepped_avx512<D, false>(scan, t, xi, vi, best);
  return k == kNoCandidate ? kNoPartner : list.ids[k];
}

template <int D, class Queue>
template <bool kAccelerated>
std::uint32_t EventEngine<D, Queue>::scan_stepped_loop(const CandidateList& list, std::uint32_t i,
                                                       double t, double& best) const {
  const HotRecord<D>& h = hot_[i];
  const Vec<D> xi = position_at(h, t), vi = velocity_at(h, t);
  const HotRecord<D>* hot = hot_.data();
  const std::uint16_t* shape = shape_.empty() ? nullptr : shape_.data();
  const std::uint16_t* row_table = step_row_table_.data();
  const double* row_reach2 = step_row_reach2_.data();
  const Vec<D> no_shift{};
  std::uint32_t found = kNoPartner;
  for (std::uint32_t k = 0; k < list.count; ++k) {
    const std::uint32_t j = list.ids[k];
    if (j == i) continue;
    const Vec<D>& shift = list.n_shifts > 1 ? list.shifts[list.shift[k]] : no_shift;
    const HotRecord<D>& hj = hot[j];
    const double dtj = t - hj.time;
    double r2 = 0.0, rg = 0.0, g2 = 0.0;
    for (int a = 0; a < D; ++a) {
      double xj = hj.pos[a] + hj.vel[a] * dtj;
      double vj = hj.vel[a];
      if constexpr (kAccelerated) {
        xj = xj + (half_gravity_[a] * dtj) * dtj;
        vj = vj + env_.gravity[a] * dtj;
      }
      const double r = xi[a] - (xj + shift[a]);
      const double g = vi[a] - vj;
      r2 = r2 + r * r;
      rg = rg + r * g;
      g2 = g2 + g * g;
    }
    const std::uint16_t sj = shape != nullptr ? shape[j] : 0;
    const PairSteps::Zone z = steps_.lookup(j, row_table[sj]);
    double dt;
    if (z.zone == 0) {
      const double gap = r2 - row_reach2[sj];
      if (!(rg < 0.0) || gap > -2.0 * rg * best) continue;
      const double disc = rg * rg - g2 * gap;
      if (!(disc > 0.0)) continue;
      dt = gap / (-rg + std::sqrt(disc));
      if (!(dt > 0.0)) dt = 0.0;
    } else {
      dt = steps_.table(z.table).event_time(z.zone, r2, rg, g2);
    }
    if (dt < best) {
      best = dt;
      found = j;
    }
  }
  return found;
}

// A pair event under a stepped potential. Approaching, the pair meets its zone's inner boundary
// (the hard core in the innermost zone: returns false, an ordinary collision); receding, the
// outer one. It crosses into the next zone if its normal kinetic energy pays the step, else
// bounces (docs/physics.md#step-event); with a dashpot on the table the crossing also pays the
// dashpot's work, which counts as dissipated (docs/physics.md#spring-dashpot-by-steps).
template <int D, class Queue>
bool EventEngine<D, Queue>::step_pair(std::uint32_t i, std::uint32_t j, double t) {
  const PairSteps::Zone z = steps_.find(i, j, steps_.pair_table(species_of(i), species_of(j)));
  if (z.table == PairSteps::kHard) return false;
  advance_to(i, t);
  advance_to(j, t);
  HotRecord<D>& hi = hot_[i];
  HotRecord<D>& hj = hot_[j];
  const Vec<D> r = separation(i, j, t);
  const double r2 = norm2(r), rg = dot(r, hi.vel - hj.vel);
  const ZoneTable& table = steps_.table(z.table);
  std::uint16_t next;
  if (rg < 0.0) {
    if (z.zone == table.core_zone) return false;
    next = static_cast<std::uint16_t>(z.zone + 1);
  } else {
    if (z.zone == 0) {  // a graze of the cut-off that round-off calls a miss: nothing happens
      predict_pair(i, j, t);
      return true;
    }
    next = static_cast<std::uint16_t>(z.zone - 1);
  }
  const double distance = std::sqrt(r2);
  const double mi = mass_of(i), mj = mass_of(j);
  StepOutcome out;
  if (table.damping > 0.0) [[unlikely]] {  // docs/physics.md#spring-dashpot-by-steps
    const DissipativeStepOutcome d = dissipative_step_event(
        mi * mj / (mi + mj), rg / distance, table.energy[next] - table.energy[z.zone],
        table.damping, table.width[std::max(next, z.zone)], table.force_zero);
    out = {d.crosses, d.impulse};
    counters_.dissipated_in_collisions += d.dissipated;
  } else {
    out = step_event(mi * mj / (mi + mj), rg / distance, table.energy[next] - table.energy[z.zone]);
  }
  const Vec<D> impulse = (out.impulse / distance) * r;
  hi.vel = hi.vel + (1.0 / mi) * impulse;
  hj.vel = hj.vel - (1.0 / mj) * impulse;
  counters_.virial += out.impulse * distance;
  add_virial_tensor(r, impulse);
  if (out.crosses) {
    steps_.set(i, j, {z.table, next});
    ++counters_.step_crossings;
    step_captures_ += z.zone == 0 ? 1u : 0u;
  } else {
    ++counters_.step_bounces;
  }
  ++counters_.collisions;
  ++hi.collisions;
  ++hj.collisions;
  predict_pair(i, j, t);
  return true;
}

template class EventEngine<2, BinaryHeapQueue>;
template class EventEngine<3, BinaryHeapQueue>;
template class EventEngine<2, CalendarQueue>;
template class EventEngine<3, CalendarQueue>;
template class EventEngine<2, TournamentTreeQueue>;
template class EventEngine<3, TournamentTreeQueue>;

}  // namespace kairos
