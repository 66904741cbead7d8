// Granular matter in the event engine (docs/architecture.md, "Granular matter"): collisions
// under contact laws, wall contacts, and resting particles (engine/resting_particles.hpp decides,
// this file applies). The plain elastic path never comes here.
#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>
#include <string>
#include <string_view>

#include "core/error.hpp"
#include "core/periodic.hpp"
#include "dynamics/collision_time.hpp"
#include "dynamics/trajectory_events.hpp"
#include "engine/event_engine.hpp"
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
  // A particle frozen against a wall moves with it; round-off in a tilted normal must not make
  // it meet that wall again.
  int frozen_against = -1;
  if (soft_) [[unlikely]] {
    const Code partner = Code::from_bits(soft_state_.partner(i));
    if (partner.is_wall()) frozen_against = partner.wall_face();
  }
  if (growing_) [[unlikely]] {  // the radius at t, growing (flat surfaces only: start_growth)
    return boundaries_.next_contact(h.pos + (t - h.time) * h.vel, h.vel, radius_at(i, t), h.cell,
                                    cells_.grid(), t, horizon, -1, growth_.speed(radius_of(i)));
  }
  return boundaries_.next_contact(flight_position(h, t), flight_velocity(h, t), radius_of(i),
                                  h.cell, cells_.grid(), t, horizon, frozen_against);
}

// A particle meets a wall: the wall is a partner of infinite mass moving with its velocity
// (sliding and normal) plus its vibration velocity, so restitution applies to the normal
// velocity relative to the wall.
template <int D, class Queue>
EventKind EventEngine<D, Queue>::hit_wall(std::uint32_t i, int surface, double t) {
  if (t >= boundaries_.squeeze_time()) throw_squeezed(t);
  if (outlets_ && boundaries_.passes(surface)) [[unlikely]] {
    pass_outlet(i, surface, t);
    return EventKind::kOutletPass;
  }
  if (soft_) [[unlikely]] {
    hit_wall_soft(i, surface, t);
    return EventKind::kWallCollision;
  }
  const bool again = wedged(i, t);
  advance_to(i, t);
  HotRecord<D>& h = hot_[i];
  bool elastic = false;
  if (!last_collision_.empty()) {
    elastic = t - last_collision_[i] < env_.tc;
    last_collision_[i] = t;
  }
  Spin<D> wi{};
  if (!spin_.empty()) wi = to_spin<D>(spin_[i]);
  // A growing particle meets a plane (start_growth) as one of its radius at t whose velocity
  // is less the growth speed along the normal: the contact reverses that, so the particle
  // leaves at the growth speed beyond the mirror image of its own
  // (docs/physics.md#growing-spheres).
  const Vec<D> growth_velocity =
      growing_ ? growth_.speed(radius_of(i)) * boundaries_.normal(surface, h.pos, t) : Vec<D>{};
  if (growing_) [[unlikely]]
    h.vel = h.vel - growth_velocity;
  const ContactResult<D> res =
      boundaries_.resolve(surface, h.pos, t, mass_of(i), growing_ ? radius_at(i, t) : radius_of(i),
                          env_.inertia_factor_of(species_of(i)), elastic, h.vel, wi);
  // (The work of the growth, 2 m rdot (rdot - v.n), is not in work_by_walls: resolve saw
  // the shifted velocity, whose energy a still wall keeps. Growth's work on pairs is not
  // counted either; the compression's thermostat removes it.)
  if (growing_) [[unlikely]]
    h.vel = h.vel + growth_velocity;
  if (!spin_.empty()) spin_[i] = from_spin<D>(wi);
  if (surface < 2 * D) counters_.face_wall_impulse[surface] += res.normal_impulse;
  counters_.dissipated_at_walls += res.dissipated;
  counters_.work_by_walls += work_on_particle(res);
  if (resting_.on() && !boundaries_.accelerates(surface)) {
    counters_.dissipated_at_walls -=
        settle_after_contact(i, boundaries_.normal(surface, h.pos, t),
                             boundaries_.velocity(surface, h.pos, t), t, again);
  }
  counters_.elastic_by_rule += res.made_elastic ? 1u : 0u;
  counters_.sliding_collisions += res.slid ? 1u : 0u;
  ++counters_.wall_collisions;
  ++h.collisions;  // its velocity changed: partners' predictions with it are stale
  // A wall with mass recoils. The impulse on it points out of the box (J_n >= 0), so from
  // now on its plane lies, at every time, no nearer the particles than the old motion had it:
  // every other particle's contact with it comes later, if at all, and its pending event (at
  // most that old contact) still comes first; a wall event of the old motion is found stale
  // when it is due (stale_wall_event). So no other particle needs looking at here.
  // On a spring, or in a container, the push can bring a plane nearer the particles later on:
  // the particles near those planes are looked at again (wall_moved).
  if (massive_walls_ && boundaries_.massive(surface)) [[unlikely]] {
    boundaries_.push(surface, t, res.impulse);
    queue_.update(i, predict(i, t));
    boundaries_.for_each_disturbed(surface, [&](int s) { wall_moved(s, t); });
    return EventKind::kWallCollision;
  }
  queue_.update(i, predict(i, t));
  return EventKind::kWallCollision;
}

// The plane of wall `face` (with mass) entered another layer of cells at time t, or its
// motion changed so that it may come nearer the particles. A particle that cannot reach it
// (outside its band of cells) meets it only after a crossing into the band, or after the
// plane's next change of layer, and is predicted again then. Each particle in the band gets
// the contact as its event if the contact comes before its pending event; a pending wall event
// of an old motion that comes first is left in place and found stale when it is due
// (stale_wall_event): it is no later than the contact, since that did not replace it.
template <int D, class Queue>
void EventEngine<D, Queue>::wall_moved(int surface, double t) {
  const CellGrid<D>& grid = cells_.grid();
  const PendingEvent contact{Code::wall(surface), boundaries_.event_version(surface)};
  boundaries_.for_each_band_cell(surface, grid, [&](std::uint32_t cell) {
    for (std::uint32_t p = grid.first(cell); p != grid.end(); p = grid.next(p)) {
      const double due = queue_.time_of(p);
      const HotRecord<D>& h = hot_[p];
      const double dt = boundaries_.event_time(surface, flight_position(h, t),
                                               flight_velocity(h, t), radius_of(p), t, due - t);
      if (t + dt < due) {
        pending_[p] = contact;
        queue_.update(p, std::max(t, t + dt));
      }
    }
  });
}

template <int D, class Queue>
void EventEngine<D, Queue>::change_wall_layer(double t) {
  time_ = t;
  const int surface = boundaries_.change_layer(t);
  if (surface >= 0) wall_moved(surface, t);
}

template <int D, class Queue>
void EventEngine<D, Queue>::check_massive_walls(const ParticleSystem<D>& s, StartMode mode) const {
  const auto refuse = [](const std::string& why) {
    throw InputError("boundary.wall.mass: a wall with mass cannot be combined with " + why);
  };
  if (soft_) refuse("soft spheres yet (soft.model)");
  if (sheared_) refuse("Lees-Edwards shear yet (boundary.shear_rate)");
  if (mode != StartMode::kResume) return;
  // Every motion this run keeps (one per body: a container's is its low wall's).
  for (const WallMotion& own : boundaries_.motion()) {
    const bool held = std::any_of(s.wall_motion.begin(), s.wall_motion.end(),
                                  [&](const WallMotion& m) { return m.face == own.face; });
    if (!held) {
      throw InputError("cannot resume: the state holds no motion of the wall with mass at face " +
                       boundaries_.name(static_cast<int>(own.face)) +
                       " (it was written by a run without it; start from it afresh instead)");
    }
  }
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

// A sleeper that wakes may have held others up: every sleeping neighbour it touched that no
// longer rests on a support (a still surface, a fixed grain, the sleepers left) wakes too, at
// rest where it slept, and so on up the pile. Otherwise a sleeper whose support was knocked away
// (a grain above a silo's orifice) would hang in the air for good. Each one woken here is
// predicted afresh and its counter bumped (predictions against it as a sleeper are stale); the
// caller predicts i.
template <int D, class Queue>
void EventEngine<D, Queue>::wake(std::uint32_t i, double t) {
  resting_.wake(i);
  hot_[i].time = t;  // at rest where it slept
  std::vector<std::uint32_t>& woken = wake_scratch_.woken;
  std::vector<std::uint32_t>& touching = wake_scratch_.touching;
  woken.assign(1, i);
  while (!woken.empty()) {
    const std::uint32_t j = woken.back();
    woken.pop_back();
    CandidateList& list = cells_.list(1);
    gather(hot_[j].cell, list);
    touching.clear();
    for (std::uint32_t k = 0; k < list.count; ++k) {
      const std::uint32_t p = list.ids[k];
      if (p == j || !is_asleep(p) || resting_.fixed(p)) continue;
      Vec<D> r = hot_[p].pos - hot_[j].pos;
      if (list.n_shifts > 1) r = r - list.shifts[list.shift[k]];
      const double gap = std::sqrt(norm2(r)) - (radius_of(p) + radius_of(j));
      if (gap < resting_.support_distance(radius_of(p))) touching.push_back(p);
    }
    for (const std::uint32_t p : touching) {
      if (!is_asleep(p) || resting_on_support(p, t)) continue;
      resting_.wake(p);
      hot_[p].time = t;
      ++hot_[p].collisions;
      ++counters_.lost_support;
      queue_.update(p, predict(p, t));
      woken.push_back(p);
    }
  }
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
  const double moved = (t - hot_[i].time) * std::sqrt(norm2(velocity(i, t)));
  return Resting::wedged(moved, radius_of(i));
}

template <int D, class Queue>
double EventEngine<D, Queue>::spin_energy(std::uint32_t i) const {
  if (spin_.empty()) return 0.0;
  const double r = radius_of(i);
  return 0.5 * env_.inertia_factor_of(species_of(i)) * mass_of(i) * r * r * norm2(spin_[i]);
}

// Whether particle i touches (within a few sleep-speed bounce heights) fixed walls or sleepers
// that hold it up against gravity, one alone or together (RestingParticles::hold_up: a grain
// in a V of two steep supports rests there).
template <int D, class Queue>
bool EventEngine<D, Queue>::resting_on_support(std::uint32_t i, double t) {
  const double eps = resting_.support_distance(radius_of(i));
  const Vec<D> x = position(i, t);
  constexpr int kMaxSupports = 16;  // more touch no sphere; the first ones decide
  std::array<Vec<D>, kMaxSupports> normals;
  int count = 0;
  for (int s = 0; s < boundaries_.surfaces() && count < kMaxSupports; ++s) {
    if (!boundaries_.is_surface(s) || !boundaries_.holds_still(s) || boundaries_.passes(s))
      continue;
    if (boundaries_.gap(s, x, t) - radius_of(i) < eps) {
      normals[count++] = boundaries_.normal(s, x, t);
      if (resting_.holds_up(normals[count - 1])) return true;
    }
  }
  CandidateList& list = cells_.list(1);
  gather(hot_[i].cell, list);
  for (std::uint32_t k = 0; k < list.count && count < kMaxSupports; ++k) {
    const std::uint32_t j = list.ids[k];
    if (j == i || !is_asleep(j)) continue;
    Vec<D> r = x - hot_[j].pos;
    if (list.n_shifts > 1) r = r - list.shifts[list.shift[k]];
    const double dist = std::sqrt(norm2(r));
    if (dist - (radius_of(i) + radius_of(j)) < eps) {
      normals[count++] = (1.0 / dist) * r;
      if (resting_.holds_up(normals[count - 1])) return true;
    }
  }
  return resting_.hold_up(normals.data(), count);
}

// An awake particle i meets a sleeping j. A gentle contact leaves j asleep (an immovable
// support, as a wall of infinite mass); a harder one wakes j for an ordinary collision. A fixed
// grain is never woken: every contact with it is the support's. Nor is a sleeper that fell
// asleep at this instant, met again by a wedged particle (`again`: it has not moved since its
// previous event): between resting things that cannot give way a falling particle would wake
// its neighbours, which fall asleep again at once, again and again at one instant (the normal
// of a nearly level contact takes a little of its fall each time); it stops there. A blow
// still spreads through a pile: each sleeper it reaches has slept since before.
template <int D, class Queue>
void EventEngine<D, Queue>::collide_with_sleeper(std::uint32_t i, std::uint32_t j, double t,
                                                 const Vec<D>& r, double r2, bool again) {
  HotRecord<D>& hi = hot_[i];
  const Vec<D> n = (1.0 / std::sqrt(r2)) * r;
  const double gn = dot(hi.vel, n);
  // A sleeper that fell asleep at this very instant, met again by a particle that has not
  // moved since: a cascade at one instant, not a blow to pass on.
  const bool rewoken = again && hot_[j].time == t;
  if (!resting_.fixed(j) && !rewoken && resting_.hit_wakes(gn)) {
    wake(j, t);
    resolve_pair(i, j, t, r, r2);
    ++hot_[j].collisions;
    ++counters_.collisions;
  } else {
    const ContactModel plain;
    WallContactInput<D> in;
    in.normal = n;
    in.mass = mass_of(i);
    in.radius = radius_of(i);
    in.inertia_factor = env_.inertia_factor_of(species_of(i));
    // The TC model acts on a fixed grain's contacts as on a wall's (hit_wall).
    if (resting_.fixed(j) && !last_collision_.empty()) {
      in.force_elastic = t - last_collision_[i] < env_.tc;
      last_collision_[i] = t;
    }
    const ContactModel& law =
        env_.contact.empty() ? plain : *env_.contact_of(species_of(i), species_of(j));
    Spin<D> wi{};
    if (!spin_.empty()) wi = to_spin<D>(spin_[i]);
    const ContactResult<D> res = resolve_wall_contact(law, in, hi.vel, wi);
    if (!spin_.empty()) spin_[i] = from_spin<D>(wi);
    // A fixed grain is an immovable body, as a wall: its contacts count and dissipate as a
    // wall's (a collision moves two particles, this contact one).
    const bool fixed = resting_.fixed(j);
    double& dissipated = fixed ? counters_.dissipated_at_walls : counters_.dissipated_in_collisions;
    dissipated += res.dissipated;
    counters_.virial += dot(r, res.impulse);
    add_virial_tensor(r, res.impulse);
    dissipated -= settle_after_contact(i, n, Vec<D>{}, t, again);
    ++(fixed ? counters_.wall_collisions : counters_.collisions);
  }
  ++hi.collisions;
  queue_.update(i, predict(i, t));
  queue_.update(j, predict(j, t));
}

namespace {

// Whether a pair at separation r, relative velocity g and relative acceleration a stays apart
// (centres farther than sigma) for all of [0, horizon]: its distance can shrink by at most
// |g| t + |a| t^2 / 2, so a start beyond sigma plus that reach (with a relative margin of 1e-9
// against the rounding of both sides) rules out a contact before the horizon. Exact for the
// scan: a rejected pair's quartic would have found no event before the horizon either, so the
// scan picks the same partner and time (and stays independent of its candidates' order).
// `accel`: |a|, the same for every pair of a scan (|g| or 0), taken once by the caller.
template <int D>
bool out_of_reach(const Vec<D>& r, const Vec<D>& g, double accel, double sigma, double horizon) {
  if (!(horizon < kNever)) return false;
  const double reach = sigma + horizon * (std::sqrt(dot(g, g)) + 0.5 * horizon * accel);
  return dot(r, r) > reach * reach * (1.0 + 1e-9);
}

}  // namespace

// The candidate test when some particles sleep: a sleeping candidate does not fall, so the
// pair's relative acceleration is +-g and its contact time a quartic. Scalar; only gravity
// runs with resting particles take it.
template <int D, class Queue>
std::uint32_t EventEngine<D, Queue>::scan_with_sleepers(const CandidateList& list, std::uint32_t i,
                                                        double t, double& best) const {
  const Vec<D> xi = position(i, t), vi = velocity(i, t);
  const bool si = is_asleep(i);
  const double gravity = std::sqrt(dot(env_.gravity, env_.gravity));
  std::uint32_t found = kNoPartner;
  for (std::uint32_t k = 0; k < list.count; ++k) {
    const std::uint32_t j = list.ids[k];
    const bool sj = is_asleep(j);
    if (j == i || (si && sj)) continue;  // sleepers never meet each other
    Vec<D> r = xi - position(j, t);
    if (list.n_shifts > 1) r = r - list.shifts[list.shift[k]];
    const Vec<D> g = vi - velocity(j, t);
    // Relative acceleration: gravity acts on the awake one of a mixed pair.
    const Vec<D> accel = sj ? env_.gravity : (si ? -1.0 * env_.gravity : Vec<D>{});
    const double sigma = radius_of(i) + radius_of(j);
    if (out_of_reach<D>(r, g, sj || si ? gravity : 0.0, sigma, best)) continue;
    const double dt =
        pair_contact_time_accelerated<D>(r.data(), g.data(), accel.data(), sigma, best);
    if (dt < best) {
      best = dt;
      found = j;
    }
  }
  return found;
}

template class EventEngine<2, BinaryHeapQueue>;
template class EventEngine<3, BinaryHeapQueue>;
template class EventEngine<2, CalendarQueue>;
template class EventEngine<3, CalendarQueue>;
template class EventEngine<2, TournamentTreeQueue>;
template class EventEngine<3, TournamentTreeQueue>;

}  // namespace kairos
