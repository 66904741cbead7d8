// A frozen clock: events go on while the simulated time no longer advances beyond round-off.
//
// It happens in an inelastic collapse (granular particles, or grains and a wall, colliding ever
// faster: the times between collisions shrink geometrically towards a finite limit, which the
// event loop reaches only after infinitely many events), for resting grains under gravity that
// may not sleep, for a gas squeezed by a piston, and for particles that start exactly in
// contact. A run in collisions per particle would then "complete" at a frozen time and a run in
// time would never end. The event engine's adapter (run/event_adapter.cpp) and the Python
// module's Simulation watch the clock after every event (FrozenClockWatch) and stop with an
// error naming the particles or the wall and the remedies (describe()).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "core/vec.hpp"
#include "model/boundaries.hpp"
#include "model/environment.hpp"

namespace kairos {

// Two checks on the clock. Every window of events, that the window moved it by more than
// round-off (or, a collapse creeping, by more than a sliver of what windows moved it before); a
// frozen window is confirmed by a second. And every sixteenth of a window, how long the clock
// has stood still beyond round-off: a stall of a quarter window's events (5 per particle, at
// least 12 500) with a collision per particle is frozen however the windows fall on it (2D
// collapses at e = 0.1 that round-off resolved again after 23 to 50 events per particle at one
// instant fell between two windows). Each particle's collision counter is kept (4 bytes per
// particle) only while a frozen window is being confirmed or a stall has lasted an eighth of a
// window, so that the error can name who collides (describe()).
class FrozenClockWatch {
 public:
  // A window of 20 events per particle (at least 5 * 10^4): more than any burst of events at
  // one instant a valid run has (a chain started in contact: some 10 per particle), few enough
  // that a collapse is caught within seconds.
  template <class Engine>
  explicit FrozenClockWatch(const Engine& engine)
      : window_(std::max<std::uint64_t>(50000, 20 * static_cast<std::uint64_t>(engine.size()))),
        window_start_(mark(engine)),
        first_(window_start_) {
    still_since_ = window_start_;
    part_time_ = engine.time();
    next_part_ = engine.counters().events + part();
  }

  // After an event: true when the clock is frozen. A window (above) is frozen when it advanced
  // the clock by no more than round-off (1e-13 of the time: some 500 ulps, where a valid window
  // moves it by ~20 mean free times), or, a collapse in progress, when it moved the clock by
  // less than 1e-6 of the most a window of this run did and its events came less than 10^5
  // ulps of the clock apart on average (a 2D gas of 5000 disks at e = 0.1 crawled 6e-8 in 10^5
  // events at t = 10.9, 10 ulps per event, after windows of up to 2.3 time units; 100 spheres
  // jammed by a piston, 1800 ulps per event). Valid runs change their time per event by a few
  // orders of magnitude at most (a gas compressed or cooling); the ulps guard the rest. One
  // compare per event.
  template <class Engine>
  bool frozen(const Engine& engine) {
    if (engine.counters().events < next_part_) return false;
    if (stalled(engine)) return true;
    if (engine.counters().events < window_start_.events + window_) return false;
    if (window_frozen(engine.time(), window_)) {
      if (counting_ == Counting::kWindow) {  // the second frozen window in a row
        report_ = window_start_;
        return true;
      }
      window_start_ = mark(engine);
      keep_counts(engine, Counting::kWindow);
      return false;
    }
    most_ = std::max(most_, engine.time() - window_start_.time);
    window_start_ = mark(engine);
    if (counting_ == Counting::kWindow) drop_counts();
    return false;
  }

  // At the end of a run: the clock never moved since the watch began (never_moved); or a
  // window was found frozen and the one confirming it, cut short by the end, is frozen too so
  // far (a collapse the run's length ended would otherwise be "completed" at a frozen time).
  template <class Engine>
  bool frozen_at_end(const Engine& engine) const {
    const std::uint64_t events = engine.counters().events - window_start_.events;
    if (never_moved(engine) ||
        (counting_ == Counting::kWindow && events > 0 && window_frozen(engine.time(), events))) {
      report_ = window_start_;
      return true;
    }
    if (!stands_still(engine.time(), part_time_) || !stall_long(engine)) return false;
    report_ = still_since_;
    return true;
  }

  // At the end of a run too short for a whole window: true when it made collisions (at least
  // 2, and one per 100 particles) but did not move the clock at all (a start in contact: all
  // its collisions at one instant, its pressure undefined).
  template <class Engine>
  bool never_moved(const Engine& engine) const {
    const std::uint64_t collisions = engine.counters().collisions - first_.collisions;
    return collisions >= std::max<std::uint64_t>(2, engine.size() / 100) &&
           engine.time() == first_.time;
  }

  // The error message for what frozen() or frozen_at_end() found: where the clock stopped, who
  // collided since it stopped (or in the frozen window) and against which walls, the remedies.
  template <class Engine>
  std::string describe(const Engine& engine) const;

 private:
  // Where a span of events began.
  struct Mark {
    std::uint64_t events = 0, collisions = 0, wall_collisions = 0;
    double time = 0.0;
  };
  template <class Engine>
  static Mark mark(const Engine& engine) {
    const auto& c = engine.counters();
    return {c.events, c.collisions, c.wall_collisions, engine.time()};
  }
  static bool stands_still(double time, double since) {
    return !(time - since > 1e-13 * std::abs(time));
  }
  std::uint64_t part() const { return std::max<std::uint64_t>(1, window_ / 16); }
  // A stall long enough to be frozen: a quarter window of events, a collision per particle.
  template <class Engine>
  bool stall_long(const Engine& engine) const {
    return engine.counters().events - still_since_.events >= window_ / 4 &&
           engine.counters().collisions - still_since_.collisions >=
               std::max<std::uint64_t>(2, engine.size());
  }

  // Every sixteenth of a window: the stall check.
  template <class Engine>
  bool stalled(const Engine& engine) {
    const double time = engine.time();
    if (!stands_still(time, part_time_)) {
      still_since_ = mark(engine);
      if (counting_ == Counting::kStall) drop_counts();
    }
    part_time_ = time;
    next_part_ = engine.counters().events + part();
    if (counting_ == Counting::kNone &&
        engine.counters().events - still_since_.events >= window_ / 8)
      keep_counts(engine, Counting::kStall);
    if (!stall_long(engine)) return false;
    report_ = still_since_;
    return true;
  }

  // Whether a window of `events` events that ends at `time` left the clock frozen (frozen()).
  bool window_frozen(double time, std::uint64_t events) const {
    const double advance = time - window_start_.time;
    const double ulps_per_event =
        advance / (static_cast<double>(events) * std::abs(time) * 0x1p-52);
    return !(advance > 1e-13 * std::abs(time)) || (ulps_per_event < 1e5 && advance < 1e-6 * most_);
  }

  enum class Counting { kNone, kWindow, kStall };
  template <class Engine>
  void keep_counts(const Engine& engine, Counting why) {
    counts_ = engine.collision_counts();
    counting_ = why;
  }
  void drop_counts() {
    counts_.clear();
    counts_.shrink_to_fit();
    counting_ = Counting::kNone;
  }

  std::uint64_t window_;
  Mark window_start_;  // where the window now being watched began
  Mark first_;         // when the watch began
  double most_ = 0.0;  // the largest advance of a window so far
  // Per particle (caller's numbering), since a frozen window's confirmation began or a stall
  // reached an eighth of a window; empty otherwise.
  std::vector<std::uint32_t> counts_;
  Counting counting_ = Counting::kNone;
  // Sixteenths of a window: the next one's end, the time at the last one's, and where the
  // clock last moved beyond round-off.
  std::uint64_t next_part_ = 0;
  double part_time_ = 0.0;
  Mark still_since_;
  mutable Mark report_;  // the span describe() reports
};

namespace frozen_clock_detail {

// The boundary surfaces the particle at x (radius r) touches at time t.
template <int D>
std::vector<int> touched_walls(const Boundaries<D>& boundaries, const Vec<D>& box, const Vec<D>& x,
                               double r, double t) {
  double longest = 0.0;
  for (int a = 0; a < D; ++a) longest = std::max(longest, box[a]);
  std::vector<int> surfaces;
  for (int s = 0; s < boundaries.surfaces(); ++s) {
    if (!boundaries.is_surface(s)) continue;
    if (std::abs(boundaries.gap(s, x, t)) - r < 1e-6 * r + 1e-9 * longest) surfaces.push_back(s);
  }
  return surfaces;
}

// Why the clock froze and what changes it, from what collided in the window: the particles
// against walls (a wall of restitution 0 keeps every grain it meets; grains resting on a fixed
// floor need to sleep), among themselves (an inelastic collapse, or elastic particles jammed
// with no room to move), or squeezed by a wall moving inwards.
template <int D>
std::string cause(const Environment<D>& env, const Boundaries<D>& boundaries,
                  const std::vector<int>& walls, std::uint64_t pair_hits, std::uint64_t wall_hits,
                  const std::string& pistons) {
  if (!pistons.empty()) {
    return fmt::format(
        "squeezed by the wall {} moving into them, which leaves them no room (they jam); end "
        "the run earlier or move the wall more slowly",
        pistons);
  }
  if (wall_hits > pair_hits && !walls.empty()) {
    std::string sticky, resting, dragging, massive;
    for (const int s : walls) {
      if (boundaries.massive(s)) massive += (massive.empty() ? "" : ", ") + boundaries.name(s);
      if (boundaries.contact(s).normal(0.0) == 0.0)
        sticky += (sticky.empty() ? "" : ", ") + boundaries.name(s);
      else if (!boundaries.accelerates(s) && !boundaries.holds_still(s))
        dragging += (dragging.empty() ? "" : ", ") + boundaries.name(s);
      else if (!boundaries.accelerates(s))
        resting += (resting.empty() ? "" : ", ") + boundaries.name(s);
    }
    if (!sticky.empty()) {
      return fmt::format(
          "the wall {} has restitution 0 at slow impacts, so a grain it meets stays on it and "
          "is met again at once (no contact law, TC model or sleeping undoes that); give it a "
          "restitution above 0 (boundary.wall restitution)",
          sticky);
    }
    if (!massive.empty()) {
      return fmt::format(
          "grains pressed against the wall with mass {} are met again and again (an inelastic "
          "collapse against it, or grains coming to rest on it: sleeping is off with a moving "
          "wall); the TC model (contact.tc) or elastic slow impacts (the wall's "
          "elastic_below_speed) undo a collapse, but grains cannot rest on a wall with mass for "
          "long: keep them moving (a gas, driving) or the wall's load light",
          massive);
    }
    if (!dragging.empty() && env.has_gravity()) {
      return fmt::format(
          "grains pressed against the moving (sliding or turning) wall {} under gravity are met "
          "again and again, and sleeping needs a still wall; make their slow impacts elastic "
          "(contact.tc, the TC model, or the wall's elastic_below_speed)",
          dragging);
    }
    if (!resting.empty() && env.has_gravity()) {
      return env.sleep_speed == 0.0
                 ? "grains coming to rest on a fixed wall under gravity bounce ever lower; let "
                   "them sleep (contact.sleep_speed > 0, or -1 for the automatic speed)"
                 : "grains coming to rest on a fixed wall under gravity bounce ever lower; "
                   "raise contact.sleep_speed, or make their slow impacts elastic "
                   "(boundary.wall elastic_below_speed)";
    }
    return "grains pressed against the wall; give the wall a higher restitution or make slow "
           "impacts elastic (boundary.wall restitution, elastic_below_speed)";
  }
  bool inelastic = env.tc > 0.0 || env.dissipative_steps() || env.soft_spheres();
  for (const ContactModel& c : env.contact)
    inelastic = inelastic || c.normal(0.0) < 1.0 || c.normal(1.0) < 1.0;
  if (!inelastic) {
    return "elastic particles jammed, touching with no room to move (a packing too dense to "
           "move, or a start in contact); start from a lower packing fraction or with the "
           "particles apart";
  }
  return "an inelastic collapse; the TC model (contact.tc: a collision soon after a "
         "particle's previous one is elastic) or elastic slow impacts "
         "(contact.elastic_below_speed) prevent it";
}

}  // namespace frozen_clock_detail

template <class Engine>
std::string FrozenClockWatch::describe(const Engine& engine) const {
  constexpr int D = std::tuple_size_v<std::remove_cvref_t<decltype(engine.box())>>;
  const std::size_t n = engine.size();
  const std::vector<std::uint32_t> now = engine.collision_counts();
  const std::uint64_t wall_hits = engine.counters().wall_collisions - report_.wall_collisions;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> busy;  // (collisions, particle)
  // Without counters kept (a run too short for a window that never moved the clock), the
  // counts since the counters began: since the start of a fresh run.
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::uint32_t before = counts_.empty() ? 0u : counts_[i];
    if (now[i] != before) busy.push_back({now[i] - before, i});
  }
  std::sort(busy.begin(), busy.end(), [](const auto& a, const auto& b) {
    return a.first != b.first ? a.first > b.first : a.second < b.second;
  });

  std::string who;
  const std::size_t named = std::min<std::size_t>(busy.size(), 6);
  for (std::size_t k = 0; k < named; ++k)
    who += fmt::format("{}{}", k == 0 ? "" : k + 1 == named ? " and " : ", ", busy[k].second);
  if (busy.size() > named) who += fmt::format(" (of {} particles)", busy.size());

  const auto& env = engine.environment();
  const Boundaries<D>& boundaries = engine.boundaries();  // walls with mass where they are now
  std::vector<int> walls;
  if (wall_hits > 0) {
    const auto state = engine.export_state(/*with_zones=*/false);
    for (std::size_t k = 0; k < named; ++k) {
      const std::uint32_t i = busy[k].second;
      for (const int s : frozen_clock_detail::touched_walls<D>(
               boundaries, state.box, state.position(i, state.time), state.kinematics[i].radius,
               state.time))
        if (std::find(walls.begin(), walls.end(), s) == walls.end()) walls.push_back(s);
    }
  }
  std::string where;
  for (std::size_t k = 0; k < walls.size(); ++k)
    where += fmt::format("{}{}", k == 0 ? "" : ", ", boundaries.name(walls[k]));

  // A wall moving inwards (a piston) squeezes the particles whether it touches the busiest.
  std::string pistons;
  for (int s = 0; s < boundaries.surfaces(); ++s) {
    if (boundaries.is_surface(s) && boundaries.approach_speed(s) > 0.0)
      pistons += (pistons.empty() ? "" : ", ") + boundaries.name(s);
  }
  const std::uint64_t events = engine.counters().events - report_.events;
  const double advance = engine.time() - report_.time;
  std::string message = fmt::format(
      "the simulated clock is frozen at t = {:.17g}: the last {} events ({:.3g} per particle) "
      "moved it by {:.3g}",
      engine.time(), events, static_cast<double>(events) / static_cast<double>(n), advance);
  if (most_ > 0.0) message += fmt::format(" (earlier windows as long: up to {:.3g})", most_);
  if (busy.empty()) return message + "; no particle collided";
  const std::uint64_t pair_hits = engine.counters().collisions - report_.collisions;
  const std::string cause =
      frozen_clock_detail::cause(env, boundaries, walls, pair_hits, wall_hits, pistons);
  message += fmt::format(
      "; particle{} {} collide{} again and again{}{}: {}", busy.size() == 1 ? "" : "s", who,
      busy.size() == 1 ? "s" : "", advance > 0.0 ? ", ever faster" : " at one instant",
      walls.empty() ? ""
                    : fmt::format(", against the wall{} {}", walls.size() == 1 ? "" : "s", where),
      cause);
  return message;
}

}  // namespace kairos
