// The live progress line on stderr: phase, percentage, simulated time, event rate, ETA.
//
// On a terminal it redraws one line in place several times a second; otherwise (CI, a pipe)
// it prints a plain line every few seconds only when asked to (progress = "always").
#pragma once

#include <chrono>
#include <cstdint>
#include <string>

#include "io/config_choices.hpp"

namespace kairos {

struct ProgressInfo {
  std::string phase;   // "equilibration" / "production"
  double done = 0.0;   // collisions per particle (or time) done in this phase
  double total = 0.0;  // collisions per particle (or time) in this phase
  double sim_time = 0.0;
  std::uint64_t events = 0;  // cumulative; the line shows the rate since the previous draw
  bool in_time = false;      // done and total are simulated time (run.time), not collisions
};

// A phase's wall clock for progress lines (ProgressLine's and run.log's, each its own): when
// the phase began, and the event rate between readings.
class PhaseClock {
 public:
  using Clock = std::chrono::steady_clock;
  // Starts again when `info` names another phase than the last; returns whether it did.
  bool enter(const ProgressInfo& info, Clock::time_point now);
  double seconds_since_reading(Clock::time_point now) const;
  void forget() { phase_.clear(); }  // the next enter() starts again, whatever its phase
  // The line's text now (progress_text): the rate since the last reading (the last one's if no
  // time has passed), the ETA from the phase's wall time; now becomes the last reading.
  std::string read(const ProgressInfo& info, Clock::time_point now);

 private:
  std::string phase_;
  Clock::time_point start_{}, last_{};
  std::uint64_t last_events_ = 0;
  double rate_ = 0.0;
};

class ProgressLine {
 public:
  // output.progress: auto (only on a terminal), always or never.
  explicit ProgressLine(ProgressMode mode);
  bool enabled() const { return enabled_; }
  // Draws if enough wall time has passed since the last draw, or always when `force` is set
  // (the end of a phase).
  void update(const ProgressInfo& info, bool force = false);
  // Ends the line (a newline on terminals).
  void finish();

 private:
  bool enabled_ = false;
  bool tty_ = false;
  PhaseClock clock_;
  bool drawn_ = false;
};

std::string format_duration(double seconds);

// The line's text: phase, share done, simulated time, the event rate given, and the ETA from
// the phase's wall seconds so far (the progress line's, and run.log's: run/run_log.hpp).
std::string progress_text(const ProgressInfo& info, double events_per_second, double phase_seconds);

bool stderr_is_a_terminal();

}  // namespace kairos
