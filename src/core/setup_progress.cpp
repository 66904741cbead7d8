#include "core/setup_progress.hpp"

#include <utility>

namespace kairos {

namespace {
thread_local SetupListener t_listener;
}  // namespace

ScopedSetupListener::ScopedSetupListener(SetupListener listener)
    : previous_(std::exchange(t_listener, std::move(listener))) {}

ScopedSetupListener::~ScopedSetupListener() {
  t_listener = std::move(previous_);
}

bool setup_listened() noexcept {
  return static_cast<bool>(t_listener);
}

void report_setup_progress(const std::string& step, const std::string& detail) {
  if (t_listener) t_listener(step, detail);
}

}  // namespace kairos
