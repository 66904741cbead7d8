// `kairos sweep`: a grid of runs of one config (docs/sweeps.md).
//
//   kairos sweep CONFIG.toml -o SWEEPDIR --vary KEY=VALUES [--vary ...] [--set KEY=VALUE ...]
//                [--workers N] [--dry-run]
//   mpirun -np N kairos sweep ...     (the runs spread over the ranks)
#pragma once

#include <functional>
#include <memory>

namespace CLI {
class App;
}

namespace kairos::cli {

class SweepCommand {
 public:
  virtual ~SweepCommand() = default;
  virtual bool parsed() const = 0;
  // Runs the sweep; InputError for bad input. Returns the exit status: 0 when every run has
  // finished, 2 when some failed, 128 + the signal when a stop was requested (`stop_signal`:
  // the signal that requested it).
  virtual int run(int& argc, char**& argv, const std::function<int()>& stop_signal) = 0;
};

std::unique_ptr<SweepCommand> add_sweep_command(CLI::App& app);

}  // namespace kairos::cli
