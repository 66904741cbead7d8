#include "io/progress.hpp"

#include <unistd.h>

#include <cmath>
#include <cstdio>

#include <fmt/format.h>

namespace kairos {

std::string format_duration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "--:--";
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

void ProgressLine::update(const ProgressInfo& info, bool force) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  if (info.phase != phase_) {
    if (drawn_ && tty_) std::fputc('\n', stderr);
    phase_ = info.phase;
    phase_start_ = last_ = now;
    last_events_ = info.events;
    drawn_ = false;
    return;  // nothing to show yet: the rate needs an interval
  }
  const double since = std::chrono::duration<double>(now - last_).count();
  if (!force && since < (drawn_ ? (tty_ ? 0.25 : 5.0) : 0.25)) return;
  if (since > 0.0) rate_ = static_cast<double>(info.events - last_events_) / since;
  last_ = now;
  last_events_ = info.events;
  const std::string line =
      progress_text(info, rate_, std::chrono::duration<double>(now - phase_start_).count());
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
  phase_.clear();
}

}  // namespace kairos
