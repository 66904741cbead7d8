// The process-wide request to stop, and the wall-time limit of a run's setup.
//
// SIGINT/SIGTERM handlers call request_stop() (async-signal-safe: one relaxed atomic store).
// The run loops poll stop_requested() after each event and stop cleanly, writing every output.
// Long setup loops (soft-sphere map tables, the collision-map integrator at setup, step tables
// and their quadratures, random insertion, every loop over all particles that generates, sorts
// or checks the start state) call throw_if_stop_requested() now and then, and the run drivers
// once more at the end of the setup, before anything is written: before
// the run has begun there is nothing to write, so they unwind with kairos::Interrupted, which
// the front ends turn into a one-line message (the CLI: exit status 128 + signal).
#pragma once

#include <chrono>

namespace kairos {

// Asks the run (or its setup) to stop; async-signal-safe.
void request_stop() noexcept;
void clear_stop_request() noexcept;
bool stop_requested() noexcept;

// While alive, throw_if_stop_requested() also throws once `seconds` (> 0; 0 or less: no limit)
// have passed since construction: run.max_wall_seconds covers the setup too. Nested scopes
// restore the enclosing limit.
class ScopedStopDeadline {
 public:
  explicit ScopedStopDeadline(double seconds) noexcept;
  ~ScopedStopDeadline();
  ScopedStopDeadline(const ScopedStopDeadline&) = delete;
  ScopedStopDeadline& operator=(const ScopedStopDeadline&) = delete;

 private:
  long long previous_deadline_;
  long long previous_origin_;
  double previous_seconds_;
};

// When the wall-time limit's clock started: the construction of the innermost live
// ScopedStopDeadline with a limit, or now if there is none. The run driver measures
// run.max_wall_seconds and the setup's wall time from here, so the limit and the reported times
// share one origin.
std::chrono::steady_clock::time_point wall_limit_origin() noexcept;

// Throws Interrupted (core/error.hpp) if a stop was requested or the setup deadline has passed.
// Cheap (an atomic load, and a clock read only while a deadline is set), but meant for loops
// whose iterations take microseconds or more, not for the engine's inner loops.
void throw_if_stop_requested();

}  // namespace kairos
