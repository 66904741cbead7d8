// restart.gsd: the exact state, the RNG and the run's progress (run/run_progress.hpp), replaced
// atomically at the end and every output.restart_interval if set. Registered after the outputs
// whose records it keeps (thermo rows, trajectory frames), so that it records them written.
#pragma once

#include <array>
#include <string>
#include <string_view>

#include "run/output_directory.hpp"
#include "run/outputs/observer.hpp"

namespace kairos {

template <int D>
class RestartOutput final : public Observer<D> {
 public:
  static constexpr std::array<std::string_view, 1> kFiles{kRestartFileName};
  std::string name() const override { return std::string(kFiles[0]); }
  // Default 0: at the end only.
  double interval(const Config& config, double) const override {
    return config.output.restart_interval;
  }
  int schedule_slot() const override { return 2; }
  void write(const RunContext<D>& run) override {
    run.integrator().write_restart(run.directory() / name(), run.progress_now());
  }
  void close(const RunContext<D>& run, bool) override { write(run); }
};

}  // namespace kairos
