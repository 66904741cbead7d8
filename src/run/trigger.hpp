// When a periodic output is due (HOOMD's triggers): every so many collisions, or at the
// multiples of an interval in simulated time (output.interval_unit). The run driver builds one
// Trigger per output and phase from the output's interval (Observer::interval).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace kairos {

// Log-spaced outputs (output.trajectory_spacing = "log"), in the unit of a trigger (collisions
// or simulated time) relative to an origin: at 0 and at the lags first * 10^(k / per_decade),
// k = 0, 1, 2, ...; with period > 0 that sequence (its lags below period) starts again at every
// multiple of period. A pure function of the origin, so that a continued run finds the frames
// an uninterrupted run writes from the origin alone.
struct LogSpacing {
  double first = 0.0;       // the first lag; 0: not log-spaced
  double per_decade = 0.0;  // points per factor 10 of lag
  double period = 0.0;      // 0: one sequence
  bool active() const { return first > 0.0; }
  double lag(double k) const { return first * std::pow(10.0, k / per_decade); }
  // The smallest point above y (both relative to the origin).
  double after(double y) const {
    if (y < 0.0) return 0.0;
    double base = period > 0.0 ? std::floor(y / period) * period : 0.0;
    for (int cycles = 0; cycles < 4; ++cycles) {
      if (base > y) return base;  // a cycle's start
      const double r = y - base;
      double k =
          r < first ? 0.0 : std::max(0.0, std::floor(per_decade * std::log10(r / first)) - 1.0);
      for (int tries = 0; tries < 8 && base + lag(k) <= y; ++tries) k += 1.0;
      const double p = base + lag(k);
      if (p > y && (period <= 0.0 || lag(k) < period)) return p;
      if (period <= 0.0) break;
      base += period;
    }
    return std::nextafter(y, std::numeric_limits<double>::infinity());  // (not reached)
  }
};

// How an output's writes are spaced in a phase (Observer::spacing; trajectory.gsd's
// output.trajectory_phases and trajectory_spacing).
struct OutputSpacing {
  bool in_phase = true;   // false: no trigger in this phase
  bool at_start = false;  // a write when the phase starts (not when a continued run resumes it)
  // > 0: log-spaced from the phase's start, the output's interval() its first lag (LogSpacing),
  // the sequence started again every `period` (0: never), in the interval's unit.
  double per_decade = 0.0;
  double period = 0.0;
};

// Every `step` collisions from the phase's start (not time: the same schedule at any density).
// Step 0: never due.
// Log-spaced (log.active()): at the first collision count at or after origin + each point.
struct CollisionTrigger {
  std::uint64_t step = 0, next = ~0ull;
  LogSpacing log;
  std::uint64_t origin = 0;
  // True (once) when `collisions` has reached the next multiple (the next point).
  bool due(std::uint64_t collisions) {
    if (collisions < next) return false;
    next = log.active() ? log_after(collisions) : next + step;
    return true;
  }
  // The first threshold of the log-spaced sequence above c (none: ~0, a lag beyond counting).
  std::uint64_t log_after(std::uint64_t c) const {
    const auto threshold = [&](double p) {
      return p < 0x1p62 ? origin + static_cast<std::uint64_t>(std::ceil(p)) : ~std::uint64_t{0};
    };
    const double y = c >= origin ? static_cast<double>(c - origin) : -1.0;
    double p = log.after(y);
    for (int tries = 0; tries < 8 && threshold(p) <= c; ++tries) p = log.after(p);
    return threshold(p);
  }
};

// At the multiples of `step` in simulated time (k * step, k an integer), not at offsets from the
// phase's start, so that a continued run writes at the times one uninterrupted run would, and a
// vibrated wall is seen at the same phases in every frame. Step 0: never due.
//
// Log-spaced (log.active()): at origin + each point of the sequence, beyond the slack likewise.
struct TimeTrigger {
  double step = 0.0, next = std::numeric_limits<double>::infinity();
  LogSpacing log;
  double origin = 0.0;
  // k * step is not the decimal multiple (3 * 0.1 = 0.30000000000000004): a multiple within
  // this of t counts as t, so that no output follows another (or a phase's end) by 1e-16.
  static double slack(double t) { return 1e-12 * std::abs(t); }
  // The first multiple of step after t (beyond the slack).
  double after(double t) const {
    double k = std::floor(t / step) + 1.0;
    // A step below t's resolution (t / step > 2^53) would never move k: a few tries only.
    for (int tries = 0; tries < 4 && k * step <= t + slack(t); ++tries) k += 1.0;
    return std::max(k * step, std::nextafter(t + slack(t), kInfinity));
  }
  // The first point of the log-spaced sequence after t (beyond the slack).
  double log_after(double t) const {
    const double beyond = t + slack(t);
    double p = log.after(beyond - origin);
    for (int tries = 0; tries < 8 && origin + p <= beyond; ++tries) p = log.after(p);
    return std::max(origin + p, std::nextafter(beyond, kInfinity));
  }
  // True (once) when t has reached the next multiple (the next point).
  bool due(double t) {
    if (!(t >= next - slack(next))) return false;
    next = log.active() ? log_after(t) : after(t);
    return true;
  }
  static constexpr double kInfinity = std::numeric_limits<double>::infinity();
};

// One output's trigger in one phase: in collisions or in simulated time, the other part never
// due. Which part the driver asks depends on what just happened (Advance: events, or a stop of
// the clock at an output time).
struct Trigger {
  CollisionTrigger collisions;
  TimeTrigger time;

  Trigger() = default;  // never due
  // Every `step` collisions (at least 1) after `begin`; step 0: never.
  static Trigger every_collisions(std::uint64_t step, std::uint64_t begin) {
    Trigger t;
    if (step > 0) {
      t.collisions.step = step;
      t.collisions.next = begin + step;
    }
    return t;
  }
  // At the multiples of `step` after `begin_time`; step 0: never.
  static Trigger every_time(double step, double begin_time) {
    Trigger t;
    if (step > 0.0) {
      t.time.step = step;
      t.time.next = t.time.after(begin_time);
    }
    return t;
  }
  // Log-spaced in collisions (`log` in collisions) from `origin`, the first due after `now`.
  static Trigger log_collisions(const LogSpacing& log, std::uint64_t origin, std::uint64_t now) {
    Trigger t;
    t.collisions.log = log;
    t.collisions.origin = origin;
    t.collisions.next = t.collisions.log_after(now);
    return t;
  }
  // Log-spaced in simulated time from `origin`, the first due after `now`.
  static Trigger log_time(const LogSpacing& log, double origin, double now) {
    Trigger t;
    t.time.log = log;
    t.time.origin = origin;
    t.time.next = t.time.log_after(now);
    return t;
  }
};

}  // namespace kairos
