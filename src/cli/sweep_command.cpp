#include "cli/sweep_command.hpp"

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
#include "run/provenance.hpp"
#include "sweep/sweep_plan.hpp"
#include "sweep/sweep_results.hpp"
#include "sweep/sweep_runner.hpp"

namespace kairos::cli {
namespace {

class Sweep final : public SweepCommand {
 public:
  explicit Sweep(CLI::App& app) {
    command_ = app.add_subcommand(
        "sweep", "Run a grid of simulations of one config, locally or across MPI ranks.");
    command_->add_option("config", config_, "TOML configuration file (see docs/config.md)")
        ->required();
    command_->add_option("-o,--output", directory_,
                         "Sweep directory: one run directory per point, sweep.json, "
                         "results.tsv and results.json (default kairos-sweep)");
    command_
        ->add_option("--vary", vary_,
                     "KEY=VALUES, one axis of the grid (repeatable): A:B:N (N numbers from A to "
                     "B), A:B:N:log, I..J (integers), or V1,V2,... (TOML values)")
        ->take_all()
        ->allow_extra_args(false)
        ->required();
    command_->add_option("--set", overrides_, "Override a config key in every run (repeatable)")
        ->take_all()
        ->allow_extra_args(false);
    workers_option_ = command_->add_option(
        "--workers", workers_,
        "Runs at a time on this machine (default: its cores); under mpirun, per rank "
        "(default 1)");
    command_
        ->add_option("--status-interval", status_seconds_,
                     "Wall seconds between status lines (runs done, running, waiting, ETA) on "
                     "stdout and in sweep.log (default 60; 0: none)")
        ->check(CLI::Range(0.0, 1e9));
    command_->add_flag("--dry-run", dry_run_,
                       "List the runs and their commands; run nothing, write nothing");
    command_->footer(
        "Each run is `kairos run CONFIG -o SWEEPDIR/NAME --set ...` in a process of its own. "
        "Run the same command again to continue a sweep: finished runs are skipped, stopped "
        "ones continued from their restart files, failed ones run again. "
        "Under `mpirun -np N`, rank 0 hands the runs out to the ranks as they become free. "
        "See docs/sweeps.md.");
  }

  bool parsed() const override { return command_->parsed(); }

  int run(int& argc, char**& argv, const std::function<int()>& stop_signal) override {
    if (workers_option_->count() > 0 && (workers_ < 1 || workers_ > 4096)) {
      throw InputError(fmt::format("--workers: must be in [1, 4096], got {}", workers_));
    }
    if (directory_.empty()) throw InputError("-o/--output: the sweep directory must not be empty");
    if (dry_run_) return dry_run(plan_sweep(config_, overrides_, vary_, directory_));
    const int ranks = launcher_ranks();
    // mpirun -np 1 too: one run at a time, as on every rank (a kairos without MPI runs it
    // locally; with more ranks it refuses).
    if (ranks > 1 || (ranks == 1 && mpi_built())) return run_mpi(argc, argv, stop_signal);
    const SweepPlan plan = plan_sweep(config_, overrides_, vary_, directory_);
    const int workers = workers_option_->count() > 0
                            ? workers_
                            : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
    const LocalSweepOutcome outcome =
        run_local_sweep(plan, {this_executable(), workers, "", status_seconds_});
    return conclude(plan, outcome.tally, outcome.states, stop_signal);
  }

 private:
  int dry_run(const SweepPlan& plan) const {
    for (const SweepPoint& p : plan.points) {
      std::vector<std::string> words = {"kairos"};
      const auto args = plan.run_arguments(p);
      words.insert(words.end(), args.begin(), args.end());
      fmt::print("{}\n", shell_command_line(words));
    }
    fmt::print("kairos sweep: {} runs (dry run: nothing was run or written)\n", plan.points.size());
    return 0;
  }

  int run_mpi(int& argc, char**& argv, const std::function<int()>& stop_signal) {
    MpiSession session(argc, argv);
    const bool root = session.rank() == 0;
    // Every rank plans (the same inputs give the same plan); rank 0 alone reports an error and
    // writes sweep.json.
    std::optional<SweepPlan> plan;
    std::optional<SweepDirectoryLock> lock;
    std::string error;
    try {
      plan = plan_sweep(config_, overrides_, vary_, directory_);
      if (root) {
        make_sweep_directory(*plan);
        lock.emplace(plan->directory);
        claim_sweep_directory(*plan);
      }
    } catch (const InputError& e) {
      error = e.what();
    }
    // Every rank's outcome counts (a config a node cannot read); rank 0's error is printed
    // once, another rank's with its rank.
    if (!session.all_ready(error)) return 2;
    // From here on the ranks depend on each other: an error on one ends the whole job
    // (MPI_Abort) instead of leaving the others waiting for it.
    try {
      const int workers = workers_option_->count() > 0 ? workers_ : 1;
      if (root) {
        announce(*plan, fmt::format("kairos sweep: {} runs in {}/ on {} MPI ranks, {} at a time on "
                                    "each",
                                    plan->points.size(), plan->directory.string(), session.size(),
                                    workers));
      }
      const std::unique_ptr<SweepWork> work = mpi_sweep_work(session, plan->points.size());
      const SweepTally tally = run_sweep(
          *plan, *work,
          {this_executable(), workers, fmt::format("rank {}: ", session.rank()), status_seconds_});
      // Rank 0's runner returned once every rank was told that nothing is left (or left): the
      // runs have ended, and the table can be written while the others wait.
      if (!root) {
        session.wait_for_all();
        return 0;
      }
      const int status =
          conclude(*plan, tally, write_sweep_results(plan->directory, plan->axes, plan->points),
                   stop_signal);
      session.wait_for_all();
      return status;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "kairos: error: rank %d: %s (the MPI job is ended)\n", session.rank(),
                   e.what());
      session.abort(2);
      return 2;
    }
  }

  // The last line (from the states of every run as the table has them) and the exit status.
  static int conclude(const SweepPlan& plan, const SweepTally& tally,
                      const std::vector<SweepRunState>& states,
                      const std::function<int()>& stop_signal) {
    auto count = [&](SweepRunState s) { return std::count(states.begin(), states.end(), s); };
    const auto failed = count(SweepRunState::kFailed);
    const auto finished = count(SweepRunState::kFinished);
    announce(plan,
             fmt::format("kairos sweep: {} of {} runs finished, {} failed, {} stopped, {} "
                         "not run; results in {}",
                         finished, states.size(), failed, count(SweepRunState::kStopped),
                         count(SweepRunState::kNotRun), (plan.directory / "results.tsv").string()));
    if (tally.interrupted) {
      announce(plan,
               "kairos sweep: stopped; the same command continues the sweep (stopped runs from "
               "their restart files)",
               stderr);
      return 128 + stop_signal();
    }
    if (failed > 0) {
      announce(plan,
               fmt::format("kairos: error: {} of {} runs failed (state 'failed' in {})", failed,
                           states.size(), (plan.directory / "results.tsv").string()),
               stderr);
      return 2;
    }
    if (finished < static_cast<long>(states.size())) {
      // Stopped by run.max_wall_seconds or by a signal sent to the runs themselves, or not
      // started (a process could not be made).
      announce(plan,
               fmt::format("kairos: error: {} of {} runs did not finish ({} stopped, {} not run: "
                           "{}); the same command continues them",
                           states.size() - static_cast<std::size_t>(finished), states.size(),
                           count(SweepRunState::kStopped), count(SweepRunState::kNotRun),
                           (plan.directory / "results.tsv").string()),
               stderr);
      return 2;
    }
    return 0;
  }

  CLI::App* command_ = nullptr;
  CLI::Option* workers_option_ = nullptr;
  std::string config_;
  std::string directory_ = "kairos-sweep";
  std::vector<std::string> vary_;
  std::vector<std::string> overrides_;
  int workers_ = 1;
  double status_seconds_ = 60.0;
  bool dry_run_ = false;
};

}  // namespace

std::unique_ptr<SweepCommand> add_sweep_command(CLI::App& app) {
  return std::make_unique<Sweep>(app);
}

}  // namespace kairos::cli
