#include "cli/replica_command.hpp"

#include <algorithm>
#include <cstdio>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "cli/sweep_mpi.hpp"
#include "core/error.hpp"
#include "replica/replica_exchange.hpp"
#include "run/provenance.hpp"
#include "sweep/sweep_plan.hpp"

namespace kairos::cli {
namespace {

// The ranks of an MPI job as the replicas' processes.
class MpiReplicaComm final : public ReplicaComm {
 public:
  explicit MpiReplicaComm(const MpiSession& session) : session_(session) {}
  int rank() const override { return session_.rank(); }
  int size() const override { return session_.size(); }
  void sum(std::vector<double>& values) const override { session_.sum(values); }
  bool any(bool yes) const override { return session_.any(yes); }

 private:
  const MpiSession& session_;
};

class ReplicaExchange final : public ReplicaCommand {
 public:
  explicit ReplicaExchange(CLI::App& app) {
    command_ = app.add_subcommand(
        "replica-exchange",
        "Parallel tempering: replicas of one config at a ladder of temperatures, swapped by the "
        "Metropolis rule.");
    command_
        ->add_option("config", settings_.config,
                     "TOML configuration file with [driving] kind = \"andersen\"")
        ->required();
    command_->add_option("-o,--output", directory_,
                         "Directory: exchange.tsv, checkpoint/, temperatures.tsv, summary.json "
                         "(default kairos-replicas)");
    command_
        ->add_option("--temperatures", settings_.temperatures,
                     "The ladder, ascending: A:B:N (N evenly spaced), A:B:N:log (geometric) or "
                     "T1,T2,...; one replica per temperature")
        ->required();
    command_->add_option("--interval", settings_.interval, "Simulated time between exchange rounds")
        ->required();
    command_->add_option("--exchanges", settings_.exchanges, "Exchange rounds in all")->required();
    command_->add_option("--equilibration", settings_.equilibration,
                         "First rounds left out of the statistics (default 0)");
    command_->add_option("--set", settings_.overrides, "Override a config key in every replica")
        ->take_all()
        ->allow_extra_args(false);
    workers_option_ = command_->add_option(
        "--workers", settings_.workers,
        "Replicas advanced at a time by this process (default: its cores; under mpirun 1)");
    command_->add_option("--checkpoint-seconds", settings_.checkpoint_seconds,
                         "Wall time between checkpoints (default 300; also at the end and on a "
                         "stop)");
    command_->footer(
        "Replica r runs CONFIG with system.seed = seed + r, starts at the r-th temperature and "
        "is held at its present rung's by the Andersen thermostat. Run the same command again "
        "(with more --exchanges to extend) to continue from the checkpoint, bit for bit. Under "
        "`mpirun -np N` the replicas spread over the ranks. See docs/replica_exchange.md.");
  }

  bool parsed() const override { return command_->parsed(); }

  int run(int& argc, char**& argv, const std::function<int()>& stop_signal) override {
    settings_.directory = directory_;
    settings_.command_line = shell_command_line(std::vector<std::string>(argv, argv + argc));
    const int ranks = launcher_ranks();
    if (ranks > 1 || (ranks == 1 && mpi_built())) return run_mpi(argc, argv, stop_signal);
    if (workers_option_->count() == 0)
      settings_.workers = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
    const ReplicaExchangePlan plan = plan_replica_exchange(settings_);
    std::filesystem::create_directories(plan.settings.directory);
    const SweepDirectoryLock lock(plan.settings.directory);
    claim_replica_directory(plan);
    return conclude(run_replica_exchange(plan, ReplicaComm{}), stop_signal);
  }

 private:
  int run_mpi(int& argc, char**& argv, const std::function<int()>& stop_signal) {
    MpiSession session(argc, argv);
    const bool root = session.rank() == 0;
    if (workers_option_->count() == 0) settings_.workers = 1;
    std::optional<ReplicaExchangePlan> plan;
    std::optional<SweepDirectoryLock> lock;
    std::string error;
    try {
      plan = plan_replica_exchange(settings_);
      if (root) {
        std::filesystem::create_directories(plan->settings.directory);
        lock.emplace(plan->settings.directory);
        claim_replica_directory(*plan);
      }
    } catch (const std::exception& e) {
      error = e.what();
    }
    if (!session.all_ready(error)) return 2;
    // From here on the ranks depend on each other: an error on one ends the whole job.
    try {
      const ReplicaExchangeOutcome outcome = run_replica_exchange(*plan, MpiReplicaComm(session));
      session.wait_for_all();
      return root ? conclude(outcome, stop_signal) : (outcome.stopped ? 128 + stop_signal() : 0);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "kairos: error: rank %d: %s (the MPI job is ended)\n", session.rank(),
                   e.what());
      session.abort(2);
    }
  }

  int conclude(const ReplicaExchangeOutcome& outcome, const std::function<int()>& stop_signal) {
    if (outcome.stopped || outcome.wall_limit) {
      std::fprintf(stderr,
                   "kairos replica-exchange: stopped after round %llu (%s); the same command "
                   "continues from the checkpoint\n",
                   static_cast<unsigned long long>(outcome.rounds),
                   outcome.wall_limit ? "run.max_wall_seconds" : "signal");
      return outcome.stopped ? 128 + stop_signal() : 0;
    }
    if (!outcome.summary.empty())
      fmt::print("kairos replica-exchange: {} rounds done; results in {}\n", outcome.rounds,
                 outcome.summary.string());
    std::fflush(stdout);
    return 0;
  }

  CLI::App* command_ = nullptr;
  CLI::Option* workers_option_ = nullptr;
  ReplicaExchangeSettings settings_;
  std::string directory_ = "kairos-replicas";
};

}  // namespace

std::unique_ptr<ReplicaCommand> add_replica_command(CLI::App& app) {
  return std::make_unique<ReplicaExchange>(app);
}

}  // namespace kairos::cli
