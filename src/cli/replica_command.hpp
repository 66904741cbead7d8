// `kairos replica-exchange`: parallel tempering of one config (docs/replica_exchange.md).
//
//   kairos replica-exchange CONFIG.toml -o DIR --temperatures A:B:N[:log] --interval DT
//                           --exchanges ROUNDS [--equilibration ROUNDS] [--set KEY=VALUE ...]
//                           [--workers N] [--checkpoint-seconds S]
//   mpirun -np N kairos replica-exchange ...     (the replicas spread over the ranks)
#pragma once

#include <functional>
#include <memory>

namespace CLI {
class App;
}

namespace kairos::cli {

class ReplicaCommand {
 public:
  virtual ~ReplicaCommand() = default;
  virtual bool parsed() const = 0;
  // Runs or continues the ensemble; InputError for bad input. Returns the exit status: 0 when
  // every round is done or run.max_wall_seconds stopped it (the same command continues), 128 +
  // the signal when a stop was requested (`stop_signal`).
  virtual int run(int& argc, char**& argv, const std::function<int()>& stop_signal) = 0;
};

std::unique_ptr<ReplicaCommand> add_replica_command(CLI::App& app);

}  // namespace kairos::cli
