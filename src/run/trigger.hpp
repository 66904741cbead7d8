// When a periodic output is due (HOOMD's triggers): every so many collisions, or at the
// multiples of an interval in simulated time (output.interval_unit). The run driver builds one
// Trigger per output and phase from the output's interval (Observer::interval).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace kairos {

// Every `step` collisions from the phase's start (not time: the same schedule at any density).
// Step 0: never due.
struct CollisionTrigger {
  std::uint64_t step = 0, next = ~0ull;
  // True (once) when `collisions` has reached the next multiple.
  bool due(std::uint64_t collisions) {
    if (collisions < next) return false;
    next += step;
    return true;
  }
};

// At the multiples of `step` in simulated time (k * step, k an integer), not at offsets from the
// phase's start, so that a continued run writes at the times one uninterrupted run would, and a
// vibrated wall is seen at the same phases in every frame. Step 0: never due.
struct TimeTrigger {
  double step = 0.0, next = std::numeric_limits<double>::infinity();
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
  // True (once) when t has reached the next multiple.
  bool due(double t) {
    if (!(t >= next - slack(next))) return false;
    next = after(t);
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
};

}  // namespace kairos
