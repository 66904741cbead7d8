// EventEngine::validate(): the engine's state checked against brute force (debug, O(N^2);
// run.validate and the engine tests). Each component with state checks its own part (the cell
// lists, the sleepers, the soft contacts, the capture map, the shear images); this file checks
// what spans them: every particle against every wall surface (through the boundary interface)
// and the prediction invariant of docs/architecture.md over every pair.
#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <string_view>

#include "core/error.hpp"
#include "core/periodic.hpp"
#include "dynamics/collision_time.hpp"
#include "dynamics/trajectory_events.hpp"
#include "engine/event_engine.hpp"
#include "scheduler/binary_heap_queue.hpp"
#include "scheduler/calendar_queue.hpp"
#include "scheduler/tournament_tree_queue.hpp"

namespace kairos {

namespace {
constexpr std::uint32_t kNoPartner = EventSlot::kNoPartner;
}  // namespace

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
  resting_.validate([&](std::uint32_t k) { return hot_[k].vel; }, fail, name);
  if (stepped_) {
    const std::string bad = steps_.check();
    if (!bad.empty()) fail("capture map: " + bad);
  }
  if (sheared_) {
    const std::string bad = shear_.check(t);
    if (!bad.empty()) fail("Lees-Edwards images: " + bad);
  }
  if (soft_) {
    soft_state_.validate(
        kFirstCode,
        [&](std::uint32_t k) { return soft_state_.deferred(k) && !in_deferred_contact(k, t); },
        fail, name);
  }
  for (std::uint32_t i = 0; i < n; ++i) {
    const HotRecord<D>& h = hot_[i];
    const Vec<D> x = position(i, t);
    for (int f = 0; f < boundaries_.surfaces(); ++f) {
      if (!boundaries_.is_surface(f) || boundaries_.passes(f)) continue;
      const double gap = boundaries_.gap(f, x, t);
      if (gap >= radius_at(i, t) * (1.0 - 1e-9)) continue;
      // A soft contact overlaps its wall while frozen and after its release, leaving; turned
      // back towards the wall (by a third body), it meets the wall now.
      const double leaving =
          dot(velocity(i, t) - boundaries_.velocity(f, x, t), boundaries_.normal(f, x, t));
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
      for (int f = 0; f < boundaries_.surfaces(); ++f) {
        if (!boundaries_.is_surface(f)) continue;
        if (boundaries_.event_time(f, position(i, t), frozen_velocity_of(i), radius_of(i), t,
                                   h.time - t) < h.time - t)
          fail("particle " + name(i) + " meets wall " + std::to_string(f) +
               " inside its deferred soft contact");
        const double due =
            h.time + boundaries_.event_time(f, h.pos, h.vel, radius_of(i), h.time, kNever);
        const double speed = std::abs(
            dot(h.vel - boundaries_.velocity(f, h.pos, due), boundaries_.normal(f, h.pos, due)));
        // Beyond growth_fits_until_ the cells no longer hold the pairs: the caller stops there.
        if (std::isfinite(due) && due <= growth_fits_until_ && late(queue_.time_of(i), due, speed))
          fail("particle " + name(i) + " meets wall " + std::to_string(f) +
               " after its deferred release before its pending event");
      }
      continue;
    }
    const Vec<D> x = position(i, t), v = velocity(i, t);
    for (int f = 0; f < boundaries_.surfaces(); ++f) {
      if (!boundaries_.is_surface(f)) continue;
      // A growing radius is a velocity towards the plane (Boundaries::next_contact).
      const double radius_speed = growing_ ? growth_.speed(radius_of(i)) : 0.0;
      const double due =
          t + boundaries_.event_time(f, x, v, radius_at(i, t), t, kNever, radius_speed);
      const Vec<D> v_surface = v - radius_speed * boundaries_.normal(f, x, t);
      const Vec<D> x_due = x + (due - t) * v;  // near enough for the surface's normal there
      const double speed_at_contact =
          std::abs(dot(v_surface + (due - t) * env_.gravity - boundaries_.velocity(f, x_due, due),
                       boundaries_.normal(f, x_due, due)));
      // A wall with mass is looked for only by the particles in its band of cells until its
      // plane changes layer (EventEngine::wall_moved); a particle outside the band meets it
      // after that at the earliest.
      const bool massive = massive_walls_ && boundaries_.massive(f);
      const double pending = massive && !boundaries_.reaches(f, hot_[i].cell, cells_.grid())
                                 ? std::min(queue_.time_of(i), boundaries_.next_layer_change())
                                 : queue_.time_of(i);
      // A wall event of the wall's present motion is the contact itself, not an earlier time.
      if (massive && pending_[i].code.is_wall() && pending_[i].code.wall_face() == f &&
          !stale_wall_event(pending_[i]) && std::isfinite(due) &&
          late(due, queue_.time_of(i), speed_at_contact)) {
        fail("particle " + name(i) + " has an event with wall " + std::to_string(f) + " at " +
             std::to_string(queue_.time_of(i)) + " before its contact at " + std::to_string(due));
      }
      // Beyond growth_fits_until_ the cells no longer hold the pairs: the caller stops there.
      if (std::isfinite(due) && due <= growth_fits_until_ && late(pending, due, speed_at_contact)) {
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
    double bound = std::min(queue_.time_of(i), queue_.time_of(j));
    // Under shear the next image shift predicts the particles next to the y faces again.
    if (sheared_ && (shear_.next_to_face(hot_[i].cell, cells_.grid()) ||
                     shear_.next_to_face(hot_[j].cell, cells_.grid())))
      bound = std::min(bound, shear_.next_shift_time());
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
    const Vec<D> g = velocity(i, t) - (velocity(j, t) + image_velocity);
    Vec<D> accel{};
    if (is_asleep(j)) accel = env_.gravity;
    if (is_asleep(i)) accel = -1.0 * env_.gravity;
    if (stepped_) {
      const PairSteps::Zone z = steps_.find(i, j, steps_.pair_table(species_of(i), species_of(j)));
      if (z.table != PairSteps::kHard) {
        // Within a cut-off (never more than a cell width) the nearest image is the one the
        // loops test; another image of a listed pair lies beyond its zone.
        if (std::string_view(which) == "nearest image" ||
            std::string_view(which) == "sheared image")
          check_step_covered(i, j, r, g, z);
        return;
      }
    }
    const double sigma = contact_distance(i, j, t);
    if (growing_) {  // a straight-line pair whose contact distance grows
      const double u = growth_.speed(radius_of(i) + radius_of(j));
      const double due = t + growing_contact_time(norm2(r) - sigma * sigma, dot(r, g) - sigma * u,
                                                  norm2(g) - u * u);
      const double dt = due - t;
      const double normal_speed = std::abs(dot(r + dt * g, g) / (sigma + u * dt) - u);
      // Beyond growth_fits_until_ the cells no longer hold the pairs: the caller stops there.
      if (std::isfinite(due) && due <= growth_fits_until_ &&
          late(std::min(queue_.time_of(i), queue_.time_of(j)), due, normal_speed)) {
        std::ostringstream os;
        os.precision(17);
        os << "growing pair " << name(i) << "," << name(j) << " (" << which << ") meets at " << due
           << " but no pending event comes first (theirs: " << queue_.time_of(i) << ", "
           << queue_.time_of(j) << ")";
        fail(os.str());
      }
      return;
    }
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
    const Vec<D> xi = position(i, t);
    const std::uint32_t ci = hot_[i].cell;
    for (std::uint32_t j = i + 1; j < n; ++j) {
      const double sigma = contact_distance(i, j, t);
      if (sheared_) {
        Vec<D> u;
        const Vec<D> r = sheared_separation(i, j, t, u);
        if (norm2(r) < sigma * sigma * (1.0 - 1e-9))
          fail("particles " + name(i) + " and " + name(j) + " overlap");
        check_covered(i, j, r, "sheared image", u);
        continue;
      }
      const Vec<D> raw = xi - position(j, t);
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
        const bool soft_ok = soft_ && norm2(r) > 0.5625 * sigma * sigma &&
                             (frozen_pair(i, j) || dot(r, velocity(i, t) - velocity(j, t)) >= 0.0 ||
                              std::min(queue_.time_of(i), queue_.time_of(j)) <= t);
        if (!soft_ok) fail("particles " + name(i) + " and " + name(j) + " overlap");
      }
      check_covered(i, j, r, "nearest image");
    }
  }
}

template class EventEngine<2, BinaryHeapQueue>;
template class EventEngine<3, BinaryHeapQueue>;
template class EventEngine<2, CalendarQueue>;
template class EventEngine<3, CalendarQueue>;
template class EventEngine<2, TournamentTreeQueue>;
template class EventEngine<3, TournamentTreeQueue>;

}  // namespace kairos
