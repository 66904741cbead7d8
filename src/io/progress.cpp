#include "io/progress.hpp"

#include <unistd.h>

#include <cmath>
#include <cstdio>

#include <fmt/format.h>

namespace kairos {

std::string format_duration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0 || seconds > 1e15)
    return "--:--";  // unknown, or beyond 1e15 s (a long long holds it, with room)
  const auto s = static_cast<long long>(seconds + 0.5);
  return s >= 3600 ? fmt::format("{}:{:02}:{:02}", s / 3600, (s / 60) % 60, s % 60)
                   : fmt::format("{:02}:{:02}", s / 60, s % 60);
}

std::string progress_text(const ProgressInfo& info, double events_per_second,
                          double phase_seconds) {
  const double frac = info.total > 0 ? std::min(1.0, info.done / info.total) : 1.0;
  const double eta = frac > 1e-9 ? phase_seconds * (1.0 - frac) / frac : -1.0;
  const std::string done = info.in_time
                               ? fmt::format("{:.4g}/{:.4g} time", info.done, info.total)
                               : fmt::format("{:.1f}/{:.0f} coll/particle", info.done, info.total);
  return fmt::format("[{:<13} {:5.1f}%] {} | t = {:.6g} | {:.3g} M events/s | ETA {}", info.phase,
                     100.0 * frac, done, info.sim_time, events_per_second / 1e6,
                     format_duration(eta));
}

bool stderr_is_a_terminal() {
  return ::isatty(STDERR_FILENO) != 0;
}

ProgressLine::ProgressLine(ProgressMode mode) {
  tty_ = stderr_is_a_terminal();
  enabled_ = mode == ProgressMode::kAlways || (mode == ProgressMode::kAuto && tty_);
}

bool PhaseClock::enter(const ProgressInfo& info, Clock::time_point now) {
  if (info.phase == phase_) return false;
  phase_ = info.phase;
  start_ = last_ = now;
  last_events_ = info.events;
  rate_ = 0.0;
  return true;
}

double PhaseClock::seconds_since_reading(Clock::time_point now) const {
  return std::chrono::duration<double>(now - last_).count();
}

std::string PhaseClock::read(const ProgressInfo& info, Clock::time_point now) {
  const double since = seconds_since_reading(now);
  if (since > 0.0) rate_ = static_cast<double>(info.events - last_events_) / since;
  last_ = now;
  last_events_ = info.events;
  return progress_text(info, rate_, std::chrono::duration<double>(now - start_).count());
}

void ProgressLine::update(const ProgressInfo& info, bool force) {
  if (!enabled_) return;
  const auto now = PhaseClock::Clock::now();
  if (clock_.enter(info, now)) {
    if (drawn_ && tty_) std::fputc('\n', stderr);
    drawn_ = false;
    return;  // nothing to show yet: the rate needs an interval
  }
  const double since = clock_.seconds_since_reading(now);
  if (!force && since < (drawn_ ? (tty_ ? 0.25 : 5.0) : 0.25)) return;
  const std::string line = clock_.read(info, now);
  if (tty_) {
    std::fprintf(stderr, "\r%-100s", line.c_str());
  } else {
    std::fprintf(stderr, "%s\n", line.c_str());
  }
  std::fflush(stderr);
  drawn_ = true;
}

void ProgressLine::finish() {
  if (enabled_ && drawn_ && tty_) std::fputc('\n', stderr);
  drawn_ = false;
  clock_.forget();
}

}  // namespace kairos
