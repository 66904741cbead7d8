#include "engine/event_engine.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "core/periodic.hpp"
#include "dynamics/collision_time.hpp"
#include "interactions/hard_sphere.hpp"
#include "scheduler/binary_heap_queue.hpp"
#include "scheduler/calendar_queue.hpp"

namespace kairos {

template <int D, class Queue>
EventEngine<D, Queue>::EventEngine(ParticleSystem<D> system, StartMode mode)
    : sys_(std::move(system)) {
  const std::size_t n = sys_.size();
  if (n < 2) throw InputError("a simulation needs at least 2 particles");
  double rmax = 0.0;
  for (const auto& k : sys_.kinematics) rmax = std::max(rmax, k.radius);
  grid_ = CellGrid<D>(sys_.box, 2.0 * rmax, n);
  if (sys_.collision_count.size() != n) sys_.collision_count.assign(n, 0);
  if (mode == StartMode::kResume) {
    if (sys_.events.size() != n || sys_.cell.size() != n) {
      throw InputError("cannot resume: the state carries no scheduler state (events, cells)");
    }
    for (std::uint32_t i = 0; i < n; ++i) {
      check_restored_cell(i);
      grid_.insert(i, sys_.cell[i]);
    }
    sys_.cell = {};  // the grid owns cell membership from here; export_state() writes it back
  } else {
    for (std::uint32_t i = 0; i < n; ++i) {
      advance_to(i, sys_.time);
      Vec<D>& x = sys_.kinematics[i].pos;
      for (int a = 0; a < D; ++a) x[a] = wrap_into_box(x[a], sys_.box[a]);
      grid_.insert(i, grid_.locate(x));
    }
    predict_all();
  }
  std::vector<double> times(n);
  for (std::uint32_t i = 0; i < n; ++i) times[i] = event_time(i);
  queue_.reset(times);
}

// A restored cell must exist and contain the particle's position (up to round-off): a damaged
// file, or one from a build with another grid sizing, must not silently mean other cells.
template <int D, class Queue>
void EventEngine<D, Queue>::check_restored_cell(std::uint32_t i) const {
  const std::uint32_t c = sys_.cell[i];
  bool ok = c < grid_.cell_count();
  for (int a = 0; ok && a < D; ++a) {
    const double x = sys_.kinematics[i].pos[a];
    const double tol = 1e-9 * sys_.box[a];
    ok = x >= grid_.lower(c, a) - tol && x <= grid_.upper(c, a) + tol;
  }
  if (!ok) {
    throw InputError("restart state is inconsistent: particle " + std::to_string(i) +
                     " is not inside its stored cell " + std::to_string(c));
  }
}

template <int D, class Queue>
void EventEngine<D, Queue>::predict_all() {
  sys_.events.assign(sys_.size(), EventSlot{});
  for (std::uint32_t i = 0; i < sys_.size(); ++i) {
    predict_collision(i, sys_.time);
    predict_crossing(i);
  }
}

template <int D, class Queue>
void EventEngine<D, Queue>::advance_to(std::uint32_t i, double t) {
  Kinematics<D>& k = sys_.kinematics[i];
  const double dt = t - k.time;
  for (int a = 0; a < D; ++a) k.pos[a] += k.vel[a] * dt;
  k.time = t;
}

// Collects the members of one neighbour cell as candidates, prefetching their records so the
// cache misses of a whole prediction overlap instead of queueing one after another.
template <int D, class Queue>
[[gnu::always_inline]] inline void EventEngine<D, Queue>::gather(
    const typename CellGrid<D>::Neighbour& nb) {
  const std::uint32_t count = grid_.count(nb.cell);
  if (count == 0) return;
  const std::uint32_t* members = grid_.members(nb.cell);
  for (std::uint32_t m = 0; m < count; ++m) {
    __builtin_prefetch(&sys_.kinematics[members[m]]);
    candidates_[n_candidates_] = members[m];
    candidate_shift_[n_candidates_++] = static_cast<std::uint8_t>(nb.shifted ? n_shifts_ : 0);
  }
  if (nb.shifted) shifts_[n_shifts_++] = nb.shift;
}

template <int D, class Queue>
void EventEngine<D, Queue>::reset_candidates() {
  n_candidates_ = 0;
  n_shifts_ = 1;  // shifts_[0] is the zero shift shared by all unshifted cells
  const std::size_t need = CellGrid<D>::kNeighbourCells * grid_.capacity();
  if (candidates_.size() < need) {
    candidates_.resize(need);
    candidate_shift_.resize(need);
  }
}

// Tests a particle (state xi, vi at time t) against the gathered candidates in one flat loop.
// The particle itself may be among them: r = g = 0 gives r.g = 0, which the root rejects
// without a branch.
template <int D, class Queue>
void EventEngine<D, Queue>::test_candidates(double t, const Vec<D>& xi, const Vec<D>& vi, double ri,
                                            EventSlot& slot) const {
  double best = slot.collision_time - t;  // soonest contact found so far, relative to t
  for (std::uint32_t k = 0; k < n_candidates_; ++k) {
    const std::uint32_t j = candidates_[k];
    const Vec<D>& shift = shifts_[candidate_shift_[k]];
    const Kinematics<D>& kj = sys_.kinematics[j];
    const double dtj = t - kj.time;
    double r2 = 0.0, rg = 0.0, g2 = 0.0;
    for (int a = 0; a < D; ++a) {
      const double r = xi[a] - (kj.pos[a] + kj.vel[a] * dtj + shift[a]);
      const double g = vi[a] - kj.vel[a];
      r2 += r * r;
      rg += r * g;
      g2 += g * g;
    }
    const double sigma = ri + kj.radius;
    // Cheap rejection before the square root: the contact time 2a/(-b + sqrt(D)) is at least
    // a/(-b) (b = 2 r.g < 0 when approaching), so a pair that cannot beat `best` is skipped.
    // Receding pairs (r.g >= 0, the particle itself included) fail the same test.
    const double gap = r2 - sigma * sigma;
    if (!(rg < 0.0) || gap > -2.0 * rg * best) continue;
    const double dt = HardSphere::contact_time(r2, rg, g2, sigma);
    if (dt < best) {
      best = dt;
      slot.collision_time = t + dt;
      slot.partner = j;
      slot.partner_count = sys_.collision_count[j];
    }
  }
}

template <int D, class Queue>
void EventEngine<D, Queue>::predict_collision(std::uint32_t i, double t) {
  EventSlot& slot = sys_.events[i];
  slot.collision_time = kNever;
  const Kinematics<D>& ki = sys_.kinematics[i];
  const Vec<D> xi = ki.pos + (t - ki.time) * ki.vel;
  reset_candidates();
  grid_.for_each_neighbour(grid_.cell_of(i),
                           [&](const typename CellGrid<D>::Neighbour& nb) { gather(nb); });
  test_candidates(t, xi, ki.vel, ki.radius, slot);
}

template <int D, class Queue>
void EventEngine<D, Queue>::predict_crossing(std::uint32_t i) {
  EventSlot& slot = sys_.events[i];
  const Kinematics<D>& k = sys_.kinematics[i];
  const std::uint32_t c = grid_.cell_of(i);
  slot.crossing_time = kNever;
  slot.crossing = -1;
  for (int a = 0; a < D; ++a) {
    const double dt = interval_exit_time(k.pos[a], k.vel[a], grid_.lower(c, a), grid_.upper(c, a));
    if (k.time + dt < slot.crossing_time) {
      slot.crossing_time = k.time + dt;
      slot.crossing = 2 * a + (k.vel[a] > 0.0 ? 1 : 0);
    }
  }
}

template <int D, class Queue>
void EventEngine<D, Queue>::collide(std::uint32_t i, std::uint32_t j, double t) {
  // Canonical order so that which of the pair was popped never changes the arithmetic.
  if (j < i) std::swap(i, j);
  advance_to(i, t);
  advance_to(j, t);
  Kinematics<D>& ki = sys_.kinematics[i];
  Kinematics<D>& kj = sys_.kinematics[j];
  Vec<D> r;
  double g_dot_r = 0.0, r2 = 0.0;
  for (int a = 0; a < D; ++a) {
    const double d = minimum_image(ki.pos[a] - kj.pos[a], sys_.box[a]);
    r[a] = d;
    r2 += d * d;
    g_dot_r += (ki.vel[a] - kj.vel[a]) * d;
  }
  const double mi = sys_.mass[i], mj = sys_.mass[j];
  const double s = HardSphere::impulse_factor(g_dot_r, r2, mi * mj / (mi + mj));  // J = s r
  for (int a = 0; a < D; ++a) {
    ki.vel[a] += s * r[a] / mi;
    kj.vel[a] -= s * r[a] / mj;
  }
  sys_.counters.virial += s * r2;
  ++sys_.counters.collisions;
  ++sys_.collision_count[i];
  ++sys_.collision_count[j];
  for (std::uint32_t p : {i, j}) {
    predict_collision(p, t);
    predict_crossing(p);
    queue_.update(p, event_time(p));
  }
}

template <int D, class Queue>
void EventEngine<D, Queue>::cross(std::uint32_t i, double t) {
  advance_to(i, t);
  EventSlot& slot = sys_.events[i];
  const int axis = slot.crossing / 2;
  const int sign = (slot.crossing % 2) ? 1 : -1;
  const std::uint32_t old_cell = grid_.cell_of(i);
  std::array<int, D> c;
  for (int a = 0; a < D; ++a) c[a] = grid_.coordinate(old_cell, a);
  c[axis] += sign;
  Kinematics<D>& k = sys_.kinematics[i];
  if (c[axis] < 0) {
    c[axis] += grid_.cells_along(axis);
    k.pos[axis] += sys_.box[axis];
  } else if (c[axis] >= grid_.cells_along(axis)) {
    c[axis] -= grid_.cells_along(axis);
    k.pos[axis] -= sys_.box[axis];
  }
  const std::uint32_t new_cell = grid_.cell_at(c);
  grid_.erase(i);
  grid_.insert(i, new_cell);
  ++sys_.counters.cell_crossings;
  reset_candidates();
  grid_.for_each_new_layer(new_cell, axis, sign,
                           [&](const typename CellGrid<D>::Neighbour& nb) { gather(nb); });
  test_candidates(t, k.pos, k.vel, k.radius, slot);
  predict_crossing(i);
  queue_.update(i, event_time(i));
}

template <int D, class Queue>
EventKind EventEngine<D, Queue>::step() {
  const std::uint32_t i = queue_.top();
  const double t = queue_.top_time();
  if (!std::isfinite(t)) return EventKind::kNone;
  sys_.time = t;
  ++sys_.counters.events;
  EventSlot& slot = sys_.events[i];
  if (slot.crossing_time <= slot.collision_time) {
    cross(i, t);
    return EventKind::kCellCrossing;
  }
  const std::uint32_t j = slot.partner;
  if (sys_.collision_count[j] != slot.partner_count) {
    ++sys_.counters.stale_events;
    predict_collision(i, t);
    queue_.update(i, event_time(i));
    return EventKind::kStale;
  }
  collide(i, j, t);
  return EventKind::kCollision;
}

template <int D, class Queue>
ParticleSystem<D> EventEngine<D, Queue>::export_state() const {
  ParticleSystem<D> out = sys_;
  out.cell.resize(sys_.size());
  for (std::uint32_t i = 0; i < sys_.size(); ++i) out.cell[i] = grid_.cell_of(i);
  return out;
}

template <int D, class Queue>
double EventEngine<D, Queue>::kinetic_energy() const {
  double ke = 0.0;
  for (std::size_t i = 0; i < sys_.size(); ++i) {
    ke += 0.5 * sys_.mass[i] * norm2(sys_.kinematics[i].vel);
  }
  return ke;
}

template <int D, class Queue>
Vec<D> EventEngine<D, Queue>::momentum() const {
  Vec<D> p{};
  for (std::size_t i = 0; i < sys_.size(); ++i) p = p + sys_.mass[i] * sys_.kinematics[i].vel;
  return p;
}

template <int D, class Queue>
std::vector<Vec<D>> EventEngine<D, Queue>::current_positions() const {
  std::vector<Vec<D>> out(sys_.size());
  for (std::size_t i = 0; i < sys_.size(); ++i) {
    Vec<D> x = sys_.position_at(i, sys_.time);
    for (int a = 0; a < D; ++a) x[a] = wrap_into_box(x[a], sys_.box[a]);
    out[i] = x;
  }
  return out;
}

template <int D, class Queue>
std::size_t EventEngine<D, Queue>::bytes_per_particle() const {
  // Per-particle arrays of the state, plus the grid's and the queue's own (cells and buckets
  // included, divided by N).
  return sizeof(Kinematics<D>) + sizeof(EventSlot) + sizeof(double) /*mass*/ +
         2 * sizeof(std::uint32_t) /*species, collision counter*/ + grid_.bytes_per_particle() +
         queue_.bytes_per_particle();
}

template <int D, class Queue>
void EventEngine<D, Queue>::validate() {
  const double t = sys_.time;
  const std::size_t n = sys_.size();
  auto fail = [&](const std::string& what) {
    std::ostringstream os;
    os << "engine validation failed at t=" << t << " after " << sys_.counters.events
       << " events: " << what;
    throw std::logic_error(os.str());
  };
  // Cell membership and the cell lists themselves.
  std::vector<std::uint32_t> listed(n, 0);
  for (std::uint32_t c = 0; c < grid_.cell_count(); ++c) {
    for (std::uint32_t m = 0; m < grid_.count(c); ++m) {
      const std::uint32_t j = grid_.members(c)[m];
      if (grid_.cell_of(j) != c) fail("particle " + std::to_string(j) + " listed in wrong cell");
      ++listed[j];
    }
  }
  for (std::uint32_t i = 0; i < n; ++i) {
    if (listed[i] != 1)
      fail("particle " + std::to_string(i) + " listed " + std::to_string(listed[i]) + " times");
    const Vec<D> x = sys_.position_at(i, t);
    const std::uint32_t c = grid_.cell_of(i);
    for (int a = 0; a < D; ++a) {
      const double tol = 1e-9 * sys_.box[a];
      if (x[a] < grid_.lower(c, a) - tol || x[a] > grid_.upper(c, a) + tol)
        fail("particle " + std::to_string(i) + " outside its cell");
    }
  }
  // Queue order: the top is the soonest stored event; nothing lies in the past.
  double tmin = kNever;
  for (std::uint32_t i = 0; i < n; ++i) {
    tmin = std::min(tmin, event_time(i));
    if (queue_.time_of(i) != event_time(i)) fail("queue key differs for " + std::to_string(i));
    if (event_time(i) < t) fail("event of " + std::to_string(i) + " lies in the past");
  }
  if (queue_.top_time() != tmin) fail("queue top is not the soonest event");
  // Prediction invariant and overlaps, brute force over all pairs.
  auto check_covered = [&](std::uint32_t i, std::uint32_t j, const Vec<D>& r, double bound,
                           const char* which) {
    const Vec<D> g = sys_.kinematics[i].vel - sys_.kinematics[j].vel;
    const double sigma = sys_.kinematics[i].radius + sys_.kinematics[j].radius;
    const double due = t + pair_contact_time<D>(r.data(), g.data(), sigma);
    if (std::isfinite(due) && bound > due * (1.0 + 1e-12) + 1e-12) {
      fail("pair " + std::to_string(i) + "," + std::to_string(j) + " (" + which + ") collides at " +
           std::to_string(due) + " but no stored event covers it");
    }
  };
  for (std::uint32_t i = 0; i < n; ++i) {
    const Vec<D> xi = sys_.position_at(i, t);
    const std::uint32_t ci = grid_.cell_of(i);
    for (std::uint32_t j = i + 1; j < n; ++j) {
      const EventSlot& si = sys_.events[i];
      const EventSlot& sj = sys_.events[j];
      const double collisions = std::min(si.collision_time, sj.collision_time);
      const double any = std::min({collisions, si.crossing_time, sj.crossing_time});
      const Vec<D> raw = xi - sys_.position_at(j, t);
      // The image the engine tests (neighbouring cells): the stored collisions must cover it.
      std::array<int, D> d;
      if (grid_.neighbour_offset(ci, grid_.cell_of(j), d)) {
        Vec<D> r = raw;
        for (int a = 0; a < D; ++a) {
          const int c = grid_.coordinate(ci, a) + d[a];
          if (c < 0) r[a] += sys_.box[a];
          if (c >= grid_.cells_along(a)) r[a] -= sys_.box[a];
        }
        check_covered(i, j, r, collisions, "neighbour-cell image");
      }
      // The nearest image: some stored event (a collision, or a crossing that changes which
      // cells the pair occupies) must come first.
      Vec<D> r = raw;
      for (int a = 0; a < D; ++a) r[a] = minimum_image(r[a], sys_.box[a]);
      const double sigma = sys_.kinematics[i].radius + sys_.kinematics[j].radius;
      if (norm2(r) < sigma * sigma * (1.0 - 1e-9)) {
        fail("particles " + std::to_string(i) + " and " + std::to_string(j) + " overlap");
      }
      check_covered(i, j, r, any, "nearest image");
    }
  }
}

template class EventEngine<2, BinaryHeapQueue>;
template class EventEngine<3, BinaryHeapQueue>;
template class EventEngine<2, CalendarQueue>;
template class EventEngine<3, CalendarQueue>;

}  // namespace kairos
