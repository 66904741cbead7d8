// Soft spheres in the event-driven engine: the Müller–Pöschel algorithm (Phys. Rev. E 87, 033301
// (2013); docs/physics.md#event-driven-soft-contacts).
//
// At first contact (r = l, found by the ordinary hard-sphere prediction) the collision map
// gives where and how the contact ends. The pair is placed at once where it will be at the end
// of the contact, seen from its centre of mass (the line of centres rotated by phi_c, the
// separation eps_r l), and both particles move with the centre-of-mass velocity V: frozen, they
// cannot meet each other (g = 0 exactly). A release event eps_t T later gives them the
// post-contact velocities. Isolated binary collisions are then exact from the end of the
// contact on. Exceptions: (A) if the placed pair would overlap a third body or a wall, the
// contact is instantaneous at first contact with e = -eps_rdot; (B) a third body (or a wall)
// meeting a frozen particle before the release releases its pair first.
//
// A released pair still overlaps by the contact's end overlap and recedes: the hard-sphere
// prediction never sees an overlapping, receding pair collide (collision_time.hpp), which is
// the force-zero end of contact (docs/physics.md#force-zero-end-of-contact). Wall contacts are
// the head-on map with mu = m and l = R: the particle is pushed into the wall by the end overlap
// and keeps only its tangential velocity until its release.
#include <algorithm>
#include <cmath>
#include <functional>
#include <string>

#include "core/error.hpp"
#include "core/periodic.hpp"
#include "engine/candidate_scan.hpp"
#include "engine/event_engine.hpp"
#include "scheduler/binary_heap_queue.hpp"
#include "scheduler/calendar_queue.hpp"
#include "scheduler/tournament_tree_queue.hpp"

namespace kairos {

namespace {
constexpr std::uint32_t kNone = EventSlot::kNoPartner;
}  // namespace

template <int D, class Queue>
void EventEngine<D, Queue>::setup_soft(const ParticleSystem<D>& s) {
  soft_ = env_.soft_spheres();
  if (!soft_) {
    if (!s.frozen.empty())
      throw InputError("the state has soft contacts in progress but no soft contact law ([soft])");
    return;
  }
  std::uint32_t species = 1;
  for (const ParticleKind& sh : kinds_) species = std::max(species, sh.species + 1);
  const std::size_t pairs = static_cast<std::size_t>(env_.species) * env_.species;
  if (env_.species < species || env_.soft.size() != pairs) {
    throw InputError("the soft contact laws cover " + std::to_string(env_.species) + " species (" +
                     std::to_string(env_.soft.size()) + " pair laws) but particles use " +
                     std::to_string(species));
  }
  if (!env_.soft_tables.empty() && env_.soft_tables.size() != pairs)
    throw InputError("soft spheres: one lookup table (or none) per species pair is needed");
  if (walls_ && env_.soft_wall.size() < species)
    throw InputError("soft spheres: walls need a soft contact law for every species");
  if (!env_.soft_wall_tables.empty() && env_.soft_wall_tables.size() != env_.soft_wall.size())
    throw InputError("soft spheres: one wall lookup table (or none) per species is needed");
  // Once here: collisions reduce their units unchecked (reduce_collision_unchecked).
  for (const SoftContactLaw& law : env_.soft) kairos::validate(law);
  for (const SoftContactLaw& law : env_.soft_wall) kairos::validate(law);
  // The map is exact for a free pair: the uniform field, steps, shear and instantaneous laws
  // would all act during the contact, where the algorithm has nothing to say.
  if (stepped_) throw InputError("soft spheres cannot be combined with stepped potentials");
  if (sheared_) throw InputError("soft spheres cannot be combined with Lees-Edwards shear");
  if (accelerated_) throw InputError("soft spheres cannot be combined with gravity (yet)");
  if (!env_.contact.empty() || env_.tc > 0.0) {
    throw InputError(
        "soft spheres replace the contact laws: [contact] restitution, roughness and tc must be "
        "left at their elastic defaults");
  }
  // A piston (a wall at constant velocity) is an inertial frame: the map holds in it, and the
  // frozen particle moves with the wall. A vibrated wall accelerates during the contact.
  for (int w = 0; w < boundaries_.surfaces(); ++w) {
    // The map's wall contact keeps one normal for the whole contact.
    if (boundaries_.is_surface(w) && !boundaries_.flat(w))
      throw InputError("soft spheres under the event integrator meet flat walls only, not " +
                       boundaries_.name(w) +
                       " (the map's wall contact keeps one normal); use run.integrator = \"dem\"");
    if (boundaries_.is_surface(w) && boundaries_.accelerates(w))
      throw InputError("soft spheres cannot meet the vibrating wall " + boundaries_.name(w) +
                       " (the wall accelerates during a contact; use run.integrator = \"dem\")");
  }
  const std::size_t n = s.size();
  soft_state_ = SoftContactState<D>(n, options_.defer_soft_releases);
}

// The contacts in progress of the state, in the engine's numbering (id_ is set, the hot
// records hold the frozen velocities). A deferred release resumes deferred, from the stored
// release positions (bit for bit); otherwise it continues as a frozen contact.
template <int D, class Queue>
void EventEngine<D, Queue>::restore_frozen(const ParticleSystem<D>& s, StartMode mode) {
  if (!soft_) return;
  const auto n = static_cast<std::uint32_t>(size());
  std::vector<std::uint32_t> internal(n);
  for (std::uint32_t k = 0; k < n; ++k) internal[id_[k]] = k;
  for (const FrozenContact<D>& c : s.frozen) {
    const bool wall = c.j == FrozenContact<D>::kWall;
    if (c.i >= n || (!wall && (c.j >= n || c.j == c.i)) ||
        (wall && c.face >= static_cast<std::uint32_t>(boundaries_.surfaces())) ||
        !(c.release_time >= s.time) || !std::isfinite(c.release_time)) {
      throw InputError("the state's soft contact of particle " + std::to_string(c.i) +
                       " is inconsistent (partner, face or release time)");
    }
    const std::uint32_t i = internal[c.i];
    if (soft_state_.partner(i) != kNone)
      throw InputError("particle " + std::to_string(c.i) + " is in two soft contacts");
    if (wall) {
      if (!boundaries_.is_surface(static_cast<int>(c.face)))
        throw InputError("particle " + std::to_string(c.i) +
                         " is in contact with a wall that this run does not have (surface " +
                         std::to_string(c.face) + ")");
      soft_state_.restore(i, wall_partner(static_cast<int>(c.face)), c.release_time, c.velocity_i);
    } else {
      const std::uint32_t j = internal[c.j];
      if (soft_state_.partner(j) != kNone)
        throw InputError("particle " + std::to_string(c.j) + " is in two soft contacts");
      soft_state_.restore(i, j, c.release_time, c.velocity_i);
      soft_state_.restore(j, i, c.release_time, c.velocity_j);
    }
    if (c.deferred && !wall && mode == StartMode::kResume && soft_state_.defers() &&
        c.release_time > s.time) {
      const std::uint32_t j = internal[c.j];
      const std::pair<std::uint32_t, Vec<D>> both[2] = {{i, c.release_position_i},
                                                        {j, c.release_position_j}};
      for (const auto& [k, x] : both) {
        hot_[k].pos = x;
        hot_[k].vel = soft_state_.release_velocity(k);
        hot_[k].time = c.release_time;
        soft_state_.set_deferred(k, true);
      }
    } else if (c.deferred) {  // continues frozen: the counter now holds what it will give back
      const std::uint32_t j = wall ? kNone : internal[c.j];
      for (const std::uint32_t k : {i, j}) {
        if (k != kNone)
          counters_.soft_contact_energy +=
              0.5 * mass_of(k) * (norm2(soft_state_.release_velocity(k)) - norm2(hot_[k].vel));
      }
    }
  }
  soft_state_.rebuild_awaiting_release();
}

template <int D, class Queue>
bool EventEngine<D, Queue>::in_soft_contact(std::uint32_t k) const {
  const bool stale = soft_state_.deferred(k) && !in_deferred_contact(k, time_);
  return soft_state_.partner(k) != kNone && !stale;
}

template <int D, class Queue>
std::uint32_t EventEngine<D, Queue>::frozen() const {
  std::uint32_t count = 0;
  for (std::uint32_t k = 0; k < soft_state_.size(); ++k) count += in_soft_contact(k) ? 1u : 0u;
  return count;
}

template <int D, class Queue>
double EventEngine<D, Queue>::held_degrees_of_freedom() const {
  double held = 0.0;
  for (std::uint32_t k = 0; k < soft_state_.size(); ++k) {
    if (in_soft_contact(k)) held += is_particle(soft_state_.partner(k)) ? 0.5 * D : 1.0;
  }
  return held;
}

template <int D, class Queue>
CollisionMap EventEngine<D, Queue>::soft_map(const SoftMapTable* table,
                                             const CollisionUnits& units) {
  CollisionMap map;
  if (table != nullptr && table->lookup(units, map)) return map;
  ++counters_.soft_direct_maps;
  return collision_map(units.reduced);
}

template <int D, class Queue>
void EventEngine<D, Queue>::relocate(std::uint32_t i) {
  HotRecord<D>& h = hot_[i];
  for (int a = 0; a < D; ++a) {
    if (!cells_.grid().periodic(a)) continue;
    const double x = h.pos[a];
    h.pos[a] = wrap_into_box(x, box_[a]);
    if (images_.on()) images_.wrapped(i, a, x, h.pos[a], box_[a]);
  }
  const CellCode c = cells_.grid().locate(h.pos);
  if (c == h.cell) return;
  cells_.move(i, h.cell, c);
  h.cell = c;
}

// The placed particles are moved first and their neighbourhoods gathered from their new cells:
// the same lists serve the overlap test and, when the placement stands, the predictions. With a
// window (a pair contact that may be deferred), the same loop also asks whether a third particle
// meets the frozen pair before the release (cheap rejection first, as in the candidate loops).
template <int D, class Queue>
bool EventEngine<D, Queue>::try_place(std::uint32_t i, const Vec<D>& xi, std::uint32_t j,
                                      const Vec<D>& xj, double t, int skip_surface, bool& shared,
                                      FrozenWindow* window) {
  const std::uint32_t both[2] = {i, j};
  const Vec<D> to[2] = {xi, xj};
  Vec<D> from[2];
  CellCode cell[2];
  const int count = j == kNone ? 1 : 2;
  for (int k = 0; k < count; ++k) {
    HotRecord<D>& h = hot_[both[k]];
    from[k] = h.pos;
    cell[k] = h.cell;
    h.pos = to[k];
    relocate(both[k]);
  }
  gather(hot_[i].cell, cells_.list(0));
  shared = count == 1 || hot_[j].cell == hot_[i].cell;
  if (!shared) gather(hot_[j].cell, cells_.list(1));
  const double span = window != nullptr ? window->until - t : 0.0;
  const Vec<D> velocity = window != nullptr ? window->velocity : Vec<D>{};
  auto overlaps = [&](std::uint32_t p, const CandidateList& list, int slot) {
    const Vec<D>& x = hot_[p].pos;
    const double radius = radius_of(p);
    if (walls_ && boundaries_.overlaps(x, radius, t, skip_surface)) return true;
    std::uint32_t delayed = 0;
    const CandidateScan<D> scan = scan_of(list, p, &delayed);
    ContactProbe<D> probe{x, velocity, span, i, j, false};
    // With `predict`, the particle's motion after the release as its record will hold it.
    Vec<D> x_after{}, v_after{};
    double best = 0.0;
    if (window != nullptr && window->predict) {
      HotRecord<D> after = hot_[p];
      for (int a = 0; a < D; ++a) after.pos[a] = x[a] + velocity[a] * (window->until - t);
      after.vel = window->after[slot];
      after.time = window->until;
      window->crossing[slot] = next_crossing(after);
      // Unbounded with incremental crossings: a contact after the crossing is kept for it.
      best = incremental_crossings_ ? kNever : window->crossing[slot].time - t;
      x_after = after.pos + (t - after.time) * after.vel;
      v_after = after.vel;
      probe.predict = true;
    }
    const ContactProbeResult check =
        vector_scan_ ? probe_contact_avx512<D>(scan, t, probe, x_after, v_after, best)
                     : probe_contact_scalar<D>(scan, t, probe, x_after, v_after, best);
    if (check.overlap) return true;
    if (window != nullptr && check.met) window->met = true;
    // Candidates in deferred contacts of their own: frozen until their release.
    for (std::uint32_t n = 0; n < delayed; ++n) {
      const std::uint32_t k = list.delayed[n];
      const HotRecord<D>& h = hot_[list.ids[k]];
      Vec<D> d = x - (h.pos - (h.time - t) * frozen_velocity_of(list.ids[k]));
      if (list.n_shifts > 1) d = d - list.shifts[list.shift[k]];
      const double sigma = radius + radius_of(list.ids[k]);
      if (norm2(d) < sigma * sigma) return true;
      if (window == nullptr || window->met) continue;
      const double ends[2] = {h.time, kNever};
      const Vec<D> g[2] = {velocity - frozen_velocity_of(list.ids[k]), velocity - h.vel};
      window->met =
          piecewise_contact_time<D>(d, t, ends, g, 2, t, window->until, sigma) < window->until;
    }
    if (probe.predict && !window->met) {
      std::uint32_t partner = check.found == kNoCandidate ? kNone : list.ids[check.found];
      if (delayed > 0) {
        const std::uint32_t other =
            scan_deferred(list, delayed, p, t, x_after, v_after, window->until, best);
        if (other != kNone) partner = other;
      }
      window->partner[slot] = partner;
      window->best[slot] = best;
    }
    return false;
  };
  if (!overlaps(i, cells_.list(0), 0) &&
      (count == 1 || !overlaps(j, cells_.list(shared ? 0 : 1), 1)))
    return true;
  for (int k = 0; k < count; ++k) {  // put back, cells included
    HotRecord<D>& h = hot_[both[k]];
    h.pos = from[k];
    if (h.cell != cell[k]) {
      cells_.move(both[k], h.cell, cell[k]);
      h.cell = cell[k];
    }
  }
  return false;
}

template <int D, class Queue>
std::uint32_t EventEngine<D, Queue>::release(std::uint32_t i, double t, bool early) {
  // Most particles are in no contact: the bit and the record (already read) say so, without a
  // (cache-missing) look at its partner. A deferred contact that is over keeps its flags.
  const bool deferred = in_deferred_contact(i, t);
  if (!soft_state_.awaits_release(i) && !deferred) [[likely]]
    return kNone;
  const std::uint32_t p = soft_state_.partner(i);
  // The pair's records jump (to the frozen path, or to the post-contact velocities).
  const bool moments = helfand_.on() && is_particle(p);
  if (moments) [[unlikely]] {
    helfand_jump_before(i, p, t);
    // The part of the contact that will not be spent frozen.
    const double rest = (deferred ? hot_[i].time : soft_state_.release_time(i)) - t;
    helfand_.frozen_pair_for(-rest);
    if (deferred) helfand_.records_ahead(deferred_excess(i, p), -rest);
  }
  const auto jumped = [&] {
    if (!moments) [[likely]]
      return;
    helfand_.set_share(i, 0.0);
    helfand_.set_share(p, 0.0);
    helfand_jump_after(i, p, t);
  };
  if (deferred) [[unlikely]] {
    // Early: from where the frozen pair is now, with the post-contact velocities.
    auto give_back = [&](std::uint32_t k) {
      HotRecord<D>& h = hot_[k];
      h.pos = h.pos - (h.time - t) * frozen_velocity_of(k);
      h.time = t;
      ++h.collisions;
      soft_state_.forget(k);
    };
    give_back(i);
    if (is_particle(p)) give_back(p);
    jumped();
    if (early) ++counters_.soft_early_releases;
    return p;
  }
  auto give_back = [&](std::uint32_t k) {
    advance_to(k, t);
    HotRecord<D>& h = hot_[k];
    counters_.soft_contact_energy -=
        0.5 * mass_of(k) * (norm2(soft_state_.release_velocity(k)) - norm2(h.vel));
    h.vel = soft_state_.release_velocity(k);
    ++h.collisions;
    soft_state_.end_release(k);
  };
  give_back(i);
  if (is_particle(p)) give_back(p);
  jumped();
  if (early) ++counters_.soft_early_releases;
  return p;
}

// The kinetic energy the deferred contacts in progress will give back (their records already
// move as after the release; the frozen motion is the physical one until then).
template <int D, class Queue>
double EventEngine<D, Queue>::deferred_contact_energy() const {
  double e = 0.0;
  for (std::uint32_t k = 0; soft_state_.defers() && k < soft_state_.size(); ++k) {
    if (in_deferred_contact(k, time_))
      e += 0.5 * mass_of(k) * (norm2(hot_[k].vel) - norm2(frozen_velocity_of(k)));
  }
  return e;
}

template <int D, class Queue>
std::uint32_t EventEngine<D, Queue>::scan_deferred(const CandidateList& list, std::uint32_t count,
                                                   std::uint32_t i, double t, const Vec<D>& xi,
                                                   const Vec<D>& vi, double from,
                                                   double& best) const {
  std::uint32_t found = kNone;
  for (std::uint32_t n = 0; n < count; ++n) {
    const std::uint32_t k = list.delayed[n];
    const std::uint32_t q = list.ids[k];
    const HotRecord<D>& h = hot_[q];
    if (q == i || (soft_state_.partner(i) == q && soft_state_.partner(q) == i))
      continue;  // its own pair
    Vec<D> xq = h.pos - (h.time - t) * frozen_velocity_of(q);
    if (list.n_shifts > 1) xq = xq + list.shifts[list.shift[k]];
    const double ends[2] = {h.time, kNever};
    const Vec<D> g[2] = {vi - frozen_velocity_of(q), vi - h.vel};
    const double when = piecewise_contact_time<D>(xi - xq, t, ends, g, 2, from, t + best,
                                                  radius_of(i) + radius_of(q));
    if (when - t < best) {
      best = when - t;
      found = q;
    }
  }
  return found;
}

// try_place has checked the third bodies and predicted both particles' motion after the
// release; here the frozen path must stay inside both cells and meet no wall, and both events
// after the release must come after it (an earlier one would be the post-contact motion extended
// backwards, which is not where the particle is).
template <int D, class Queue>
bool EventEngine<D, Queue>::try_defer(std::uint32_t i, std::uint32_t j, double t,
                                      const FrozenWindow& window) {
  const std::uint32_t both[2] = {i, j};
  const double until = window.until;
  Vec<D> start[2], end[2];
  for (int k = 0; k < 2; ++k) {
    const HotRecord<D>& h = hot_[both[k]];
    start[k] = h.pos;
    for (int a = 0; a < D; ++a) {
      end[k][a] = h.pos[a] + window.velocity[a] * (until - t);  // as advance_to() would move it
      if (!(cells_.grid().lower_bound(h.cell, a) < end[k][a] &&
            end[k][a] < cells_.grid().upper_bound(h.cell, a)))
        return false;
    }
    for (int f = 0; walls_ && f < boundaries_.surfaces(); ++f) {
      if (boundaries_.is_surface(f) &&
          boundaries_.event_time(f, h.pos, window.velocity, radius_of(both[k]), t, until - t) <
              until - t)
        return false;
    }
  }
  if (helfand_.on()) [[unlikely]]
    helfand_jump_before(i, j, t);
  for (int k = 0; k < 2; ++k) {
    HotRecord<D>& h = hot_[both[k]];
    h.pos = end[k];
    h.vel = window.after[k];
    h.time = until;
    soft_state_.set_deferred(both[k], true);
  }
  double when[2];
  for (int k = 0; k < 2; ++k)
    when[k] = incremental_crossings_ ? conclude_unbounded(both[k], t, window.crossing[k],
                                                          window.partner[k], window.best[k])
                                     : conclude_prediction(both[k], t, window.crossing[k],
                                                           window.partner[k], window.best[k]);
  if (when[0] >= until && when[1] >= until) {
    if (helfand_.on()) [[unlikely]] {  // the records move as after the release: no share held
      helfand_.records_ahead(2.0 * (helfand_.share(i) + helfand_.share(j)), until - t);
      helfand_.set_share(i, 0.0);
      helfand_.set_share(j, 0.0);
      helfand_jump_after(i, j, t);
    }
    queue_.update(i, when[0]);
    queue_.update(j, when[1]);
    return true;
  }
  for (int k = 0; k < 2; ++k) {  // back to the frozen pair at time t
    HotRecord<D>& h = hot_[both[k]];
    h.pos = start[k];
    h.vel = window.velocity;
    h.time = t;
    soft_state_.set_deferred(both[k], false);
  }
  if (helfand_.on()) [[unlikely]]
    helfand_jump_after(i, j, t);  // no jump after all
  return false;
}

template <int D, class Queue>
void EventEngine<D, Queue>::release_event(std::uint32_t i, double t) {
  const std::uint32_t p = release(i, t, /*early=*/false);
  if (is_particle(p)) {
    predict_pair(i, p, t);
  } else {
    queue_.update(i, predict(i, t));
  }
}

template <int D, class Queue>
void EventEngine<D, Queue>::collide_soft(std::uint32_t i, std::uint32_t j, double t) {
  // Exception B: a frozen particle met by another is released (with its partner) first.
  const std::uint32_t released[2] = {release(i, t, true), release(j, t, true)};
  advance_to(i, t);
  advance_to(j, t);
  HotRecord<D>& hi = hot_[i];
  HotRecord<D>& hj = hot_[j];
  auto predict_released = [&] {
    for (const std::uint32_t p : released)
      if (is_particle(p) && p != i && p != j) queue_.update(p, predict(p, t));
  };
  Vec<D> r;
  for (int a = 0; a < D; ++a) {
    const double raw = hi.pos[a] - hj.pos[a];
    r[a] = !bounded_ || cells_.grid().periodic(a) ? minimum_image(raw, box_[a]) : raw;
  }
  const Vec<D> g = hi.vel - hj.vel;
  const double r2 = norm2(r), rg = dot(r, g);
  if (!(rg < 0.0)) {  // the release turned them apart: no contact after all
    predict_pair(i, j, t);
    predict_released();
    return;
  }
  if (helfand_.on()) [[unlikely]]
    helfand_jump_before(i, j, t);
  const double mi = mass_of(i), mj = mass_of(j), total = mi + mj, mu = mi * mj / total;
  const double l = radius_of(i) + radius_of(j);
  const double distance = std::sqrt(r2);
  const Vec<D> n0 = (1.0 / distance) * r;
  const double vn = -rg / distance;
  const Vec<D> gt = g + vn * n0;
  const double vt = std::sqrt(norm2(gt));
  const std::size_t pair = static_cast<std::size_t>(species_of(i)) * env_.species + species_of(j);
  const SoftContactLaw& law = env_.soft[pair];
  const SoftMapTable* table = env_.soft_tables.empty() ? nullptr : env_.soft_tables[pair].get();
  // A pair found already overlapping (one just released, turned back by a third body) has no
  // first contact to start the map from: it collides instantaneously.
  const bool overlapping = distance < l * (1.0 - 1e-9);
  const bool mapped = env_.soft_collisions == SoftCollisions::kMapped && !overlapping;
  const CollisionUnits units = reduce_collision_unchecked(law, mu, l, vn, mapped ? vt : 0.0);
  const CollisionMap map = soft_map(table, units);
  const Vec<D> V = (1.0 / total) * (mi * hi.vel + mj * hj.vel);
  const double ke_before = 0.5 * (mi * norm2(hi.vel) + mj * norm2(hj.vel));
  bool placed = false;
  if (mapped) {
    const double phi = map.eps_phi * units.angle_unit;
    const Vec<D> t0 = vt > 0.0 ? (1.0 / vt) * gt : Vec<D>{};
    const double c = std::cos(phi), s = std::sin(phi);
    const Vec<D> nc = c * n0 + s * t0, tc = c * t0 - s * n0;
    const Vec<D> rc = (map.eps_r * l) * nc;
    // Each particle's displacement from its place at first contact (R stays): no images.
    const Vec<D> xi = hi.pos + (mj / total) * (rc - r), xj = hj.pos - (mi / total) * (rc - r);
    bool shared = false;
    const Vec<D> gc = (-map.eps_rdot * vn) * nc + (vt / map.eps_r) * tc;
    const Vec<D> after_i = V + (mj / total) * gc, after_j = V - (mi / total) * gc;
    FrozenWindow window;
    window.velocity = V;
    window.until = t + map.eps_t * units.time_unit;
    window.predict = soft_state_.defers();
    window.after[0] = after_i;
    window.after[1] = after_j;
    if (try_place(i, xi, j, xj, t, -1, shared, soft_state_.defers() ? &window : nullptr)) {
      const double until = window.until;
      const Vec<D> impulse = mi * (after_i - hi.vel);
      // The impulse acts while the line of centres turns from r to rc: the mean lever arm.
      const Vec<D> arm = 0.5 * (r + rc);
      counters_.virial += dot(arm, impulse);
      add_virial_tensor(arm, impulse);
      const double ke_after = 0.5 * (mi * norm2(after_i) + mj * norm2(after_j));
      counters_.dissipated_in_collisions += ke_before - ke_after;
      hi.vel = V;
      hj.vel = V;
      if (helfand_.on()) [[unlikely]] {  // the frozen pair holds its relative kinetic energy
        helfand_.set_share(i, 0.5 * mi * norm2(after_i - V));
        helfand_.set_share(j, 0.5 * mj * norm2(after_j - V));
        helfand_jump_after(i, j, t);
        helfand_.frozen_pair_for(until - t);
      }
      soft_state_.begin(i, j);
      soft_state_.begin(j, i);
      ++counters_.soft_contacts;
      ++counters_.collisions;
      ++hi.collisions;
      ++hj.collisions;
      if (soft_state_.defers() && !window.met && try_defer(i, j, t, window)) {
        predict_released();  // deferred: what the contact holds is in its records
        return;
      }
      soft_state_.schedule_release(i, until, after_i);
      soft_state_.schedule_release(j, until, after_j);
      counters_.soft_contact_energy += ke_after - 0.5 * total * norm2(V);
      queue_.update(i, predict_from(cells_.list(0), i, t));
      queue_.update(j, predict_from(cells_.list(shared ? 0 : 1), j, t));
      predict_released();
      return;
    } else {
      ++counters_.soft_overlap_fallbacks;  // exception A
    }
  } else if (overlapping) {
    ++counters_.soft_overlap_fallbacks;
  }
  if (!placed) {
    // Instantaneous, smooth: g.n -> -e g.n with e = -eps_rdot of this collision's map.
    const double e = -map.eps_rdot;
    const Vec<D> impulse = ((1.0 + e) * mu * vn) * n0;
    hi.vel = hi.vel + (1.0 / mi) * impulse;
    hj.vel = hj.vel - (1.0 / mj) * impulse;
    counters_.virial += dot(r, impulse);
    add_virial_tensor(r, impulse);
    counters_.dissipated_in_collisions += 0.5 * mu * vn * vn * (1.0 - e * e);
    separate(i, j, r, r2);
    if (helfand_.on()) [[unlikely]]
      helfand_jump_after(i, j, t);
  }
  ++counters_.collisions;
  ++hi.collisions;
  ++hj.collisions;
  predict_pair(i, j, t);
  predict_released();
}

// The map's wall contact in the wall's frame along its normal n (into the domain): the
// particle's normal speed vn towards the wall, its velocity after (the relative normal velocity
// reversed and scaled by e), while frozen (moving with the wall along n) and the work the wall's
// impulse does. A box face keeps its one-axis arithmetic (the bits of every earlier run).
template <int D, class Queue>
typename EventEngine<D, Queue>::SoftWallContact EventEngine<D, Queue>::soft_wall_contact(
    std::uint32_t i, int surface, double t) const {
  const HotRecord<D>& h = hot_[i];
  SoftWallContact c;
  if (surface < 2 * D) {
    const int a = surface / 2;
    const double sgn = surface % 2 == 0 ? 1.0 : -1.0;
    const double wall_speed = boundaries_.faces().wall(surface).velocity[a];
    c.normal[a] = sgn;
    c.vn = -sgn * (h.vel[a] - wall_speed);
    c.gap = sgn * (h.pos[a] - boundaries_.faces().position(surface, t));
    c.frozen = h.vel;
    c.frozen[a] = wall_speed;
    c.axis = a;
    c.wall_speed = wall_speed;
    return c;
  }
  c.normal = boundaries_.normal(surface, h.pos, t);
  c.wall_velocity = boundaries_.velocity(surface, h.pos, t);
  c.vn = -dot(h.vel - c.wall_velocity, c.normal);
  c.gap = boundaries_.gap(surface, h.pos, t);
  c.frozen = h.vel + c.vn * c.normal;
  return c;
}

// After the contact (restitution e): the velocity and the work the wall did on the particle.
template <int D, class Queue>
Vec<D> EventEngine<D, Queue>::soft_wall_rebound(std::uint32_t i, const SoftWallContact& c, double e,
                                                double& work) const {
  const HotRecord<D>& h = hot_[i];
  const double m = mass_of(i);
  Vec<D> after = h.vel;
  if (c.axis >= 0) {
    after[c.axis] = c.wall_speed + c.normal[c.axis] * e * c.vn;
    work = m * c.wall_speed * (after[c.axis] - h.vel[c.axis]);  // impulse . wall velocity
    return after;
  }
  after = h.vel + ((1.0 + e) * c.vn) * c.normal;
  work = m * dot(c.wall_velocity, after - h.vel);
  return after;
}

template <int D, class Queue>
void EventEngine<D, Queue>::hit_wall_soft(std::uint32_t i, int surface, double t) {
  const std::uint32_t partner = release(i, t, true);
  if (is_particle(partner)) queue_.update(partner, predict(partner, t));
  advance_to(i, t);
  HotRecord<D>& h = hot_[i];
  // The wall's velocity is constant (setup refuses vibrations), so the map holds in its frame;
  // the frozen particle moves with the wall.
  const SoftWallContact contact = soft_wall_contact(i, surface, t);
  const double vn = contact.vn;
  if (!(vn > 0.0)) {  // released early, it now leaves the wall
    ++h.collisions;
    queue_.update(i, predict(i, t));
    return;
  }
  const std::uint32_t s = species_of(i);
  const double m = mass_of(i), radius = radius_of(i);
  const SoftMapTable* table =
      env_.soft_wall_tables.empty() ? nullptr : env_.soft_wall_tables[s].get();
  const CollisionUnits units = reduce_collision_unchecked(env_.soft_wall[s], m, radius, vn, 0.0);
  const CollisionMap map = soft_map(table, units);
  const double e = -map.eps_rdot;
  double work = 0.0;
  const Vec<D> after = soft_wall_rebound(i, contact, e, work);
  counters_.dissipated_at_walls += 0.5 * m * vn * vn * (1.0 - e * e);
  counters_.work_by_walls += work;
  // Already overlapping the wall (released from it, then turned back by a third body): no
  // first contact to start the map from, so the contact is instantaneous.
  const bool overlapping = contact.gap < radius * (1.0 - 1e-9);
  if (overlapping) ++counters_.soft_overlap_fallbacks;
  bool placed = false;
  if (env_.soft_collisions == SoftCollisions::kMapped && !overlapping) {
    // Into the wall by the end overlap.
    Vec<D> x = h.pos;
    if (contact.axis >= 0) {
      x[contact.axis] -= contact.normal[contact.axis] * map.end_overlap * units.length_unit;
    } else {
      x = x - (map.end_overlap * units.length_unit) * contact.normal;
    }
    bool shared = true;
    if (try_place(i, x, kNone, x, t, surface, shared)) {
      counters_.soft_contact_energy += 0.5 * m * (norm2(after) - norm2(contact.frozen));
      h.vel = contact.frozen;
      soft_state_.begin(i, wall_partner(surface));
      soft_state_.schedule_release(i, t + map.eps_t * units.time_unit, after);
      ++counters_.soft_contacts;
      ++counters_.wall_collisions;
      ++h.collisions;
      queue_.update(i, predict_from(cells_.list(0), i, t));
      return;
    } else {
      ++counters_.soft_overlap_fallbacks;
    }
  }
  if (!placed) h.vel = after;
  ++counters_.wall_collisions;
  ++h.collisions;
  queue_.update(i, predict(i, t));
}

template class EventEngine<2, BinaryHeapQueue>;
template class EventEngine<3, BinaryHeapQueue>;
template class EventEngine<2, CalendarQueue>;
template class EventEngine<3, CalendarQueue>;
template class EventEngine<2, TournamentTreeQueue>;
template class EventEngine<3, TournamentTreeQueue>;

}  // namespace kairos
