// Runs a sweep's points as child processes (`kairos run`, one per run directory), a few at a
// time (docs/sweeps.md). Which point comes next is the work source's choice: all of them in
// order for a local sweep, or what the coordinating MPI rank hands out (cli/sweep_mpi.cpp), so
// that a rank that finishes early takes the next run (dynamic load balance).
//
// A finished run is skipped; a stopped one (signal, wall-time limit, killed with the sweep) is
// continued from its restart.gsd, which completes its planned production; any other one (a
// failed one too) is run afresh (--overwrite: an earlier attempt's outputs go). Each attempt's
// stdout and stderr are appended to the run's console.log. A stop request (SIGINT/SIGTERM to the
// sweep) is passed on to the running children as SIGTERM; they write their outputs and restart
// files, and the same sweep command later continues them.
#pragma once

#include <cstddef>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "sweep/sweep_plan.hpp"
#include "sweep/sweep_results.hpp"

namespace kairos {

class SweepWork {
 public:
  virtual ~SweepWork() = default;
  // The next point for this process to run, or nullopt: none left for it.
  virtual std::optional<std::size_t> next() = 0;
  // Called while the runner waits for its children (the coordinator answers other ranks).
  virtual void serve() {}
  // Other processes still depend on this one (the coordinator until every rank is answered).
  virtual bool serving() const { return false; }
  // No new work is to be handed out (a stop was requested).
  virtual void stop() {}
  // Points not handed out yet, when this process knows (for the ETA of the status lines).
  virtual std::optional<std::size_t> waiting() const { return std::nullopt; }
};

// Every point, in order: a sweep on this machine only.
class LocalSweepWork final : public SweepWork {
 public:
  explicit LocalSweepWork(std::size_t count) : count_(count) {}
  std::optional<std::size_t> next() override {
    if (stopped_ || next_ >= count_) return std::nullopt;
    return next_++;
  }
  void stop() override { stopped_ = true; }
  std::optional<std::size_t> waiting() const override { return stopped_ ? 0 : count_ - next_; }

 private:
  std::size_t count_;
  std::size_t next_ = 0;
  bool stopped_ = false;
};

struct SweepTally {
  std::size_t finished = 0;  // this invocation's runs that finished
  std::size_t skipped = 0;   // found finished before
  std::size_t failed = 0;
  std::size_t stopped = 0;      // stopped by the stop request (continued by the next invocation)
  std::size_t not_started = 0;  // its process could not be started (then no further one is)
  bool interrupted = false;     // a stop was requested
};

struct SweepRunnerOptions {
  std::filesystem::path executable;  // the kairos binary the children run
  int workers = 1;                   // children at a time
  std::string label;                 // prefix of the progress lines ("" or "rank 3: ")
  // Wall seconds between status lines (runs finished, running, waiting, elapsed, ETA); 0: none.
  double status_seconds = 60.0;
};

// The sweep's log in its directory: every line the sweep prints, stamped with the UTC time,
// appended by every invocation and every MPI rank (io/log_file.hpp).
inline constexpr const char* kSweepLogFile = "sweep.log";
// A line of the sweep's own (its banner, its last line, its errors) on `stream` and in the log.
void announce(const SweepPlan& plan, const std::string& line, std::FILE* stream = stdout);

// Runs the points `work` hands out until it has none left (or a stop is requested), printing one
// line per run to stdout and to sweep.log, and a status line every options.status_seconds.
SweepTally run_sweep(const SweepPlan& plan, SweepWork& work, const SweepRunnerOptions& options);

// A sweep on this machine from start to end: claims the directory (sweep.json, the lock), runs
// every point with `options.workers` at a time, writes the table. Returns each point's state.
struct LocalSweepOutcome {
  SweepTally tally;
  std::vector<SweepRunState> states;
};
LocalSweepOutcome run_local_sweep(const SweepPlan& plan, const SweepRunnerOptions& options);

// The running program (/proc/self/exe), for the children.
std::filesystem::path this_executable();

}  // namespace kairos
