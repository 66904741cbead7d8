#include "core/stop_flag.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>

#include <fmt/format.h>

#include "core/error.hpp"

namespace kairos {

namespace {

using Clock = std::chrono::steady_clock;

std::atomic<bool> g_stop{false};
static_assert(std::atomic<bool>::is_always_lock_free);  // what makes request_stop signal-safe

// The setup deadline in Clock ticks (0: none) and the limit it came from, for the message.
std::atomic<long long> g_deadline{0};
std::atomic<double> g_deadline_seconds{0.0};
std::atomic<long long> g_deadline_origin{0};  // when the deadline's clock started

long long now_ticks() {
  return static_cast<long long>(Clock::now().time_since_epoch().count());
}

}  // namespace

void request_stop() noexcept {
  g_stop.store(true, std::memory_order_relaxed);
}

void clear_stop_request() noexcept {
  g_stop.store(false, std::memory_order_relaxed);
}

bool stop_requested() noexcept {
  return g_stop.load(std::memory_order_relaxed);
}

ScopedStopDeadline::ScopedStopDeadline(double seconds) noexcept
    : previous_deadline_(g_deadline.load()),
      previous_origin_(g_deadline_origin.load()),
      previous_seconds_(g_deadline_seconds.load()) {
  if (!(seconds > 0.0)) return;
  const long long origin = now_ticks();
  const auto span = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(std::min(seconds, 1e9)));  // 1e9 s: no overflow of ticks
  g_deadline.store(origin + static_cast<long long>(span.count()));
  g_deadline_origin.store(origin);
  g_deadline_seconds.store(seconds);
}

ScopedStopDeadline::~ScopedStopDeadline() {
  g_deadline.store(previous_deadline_);
  g_deadline_origin.store(previous_origin_);
  g_deadline_seconds.store(previous_seconds_);
}

std::chrono::steady_clock::time_point wall_limit_origin() noexcept {
  const long long origin = g_deadline_origin.load();
  if (g_deadline.load() == 0 || origin == 0) return Clock::now();
  return Clock::time_point(Clock::duration(origin));
}

void throw_if_stop_requested() {
  if (stop_requested()) throw Interrupted(Interrupted::Cause::kStopRequest, "interrupted");
  const long long deadline = g_deadline.load(std::memory_order_relaxed);
  if (deadline != 0 && now_ticks() > deadline) {
    throw Interrupted(Interrupted::Cause::kWallTime,
                      fmt::format("the wall-time limit of {} s was reached",
                                  g_deadline_seconds.load(std::memory_order_relaxed)));
  }
}

}  // namespace kairos
