// The one run driver of `kairos run`, for both integrators (HOOMD's Simulation.run over its
// operations): the setup chain (run/setup_chain.hpp), then equilibration and production, each
// measured in collisions per particle or in simulated time, with the outputs and analyses as
// observers (run/outputs/) called when their triggers fire.
//
// What it keeps for every output (docs/guarantees.md): a failed write stops the run, the file
// that failed is not written again and the others still are (OutputFailures); the row and
// frame due at a failed write are owed, and a continued run writes them first; the restart
// file records the outputs' schedules and marks, so that a run continued into its own
// directory leaves the files as one uninterrupted run would; SIGINT/SIGTERM and
// run.max_wall_seconds stop the run with every output written; the output directory is locked
// and its lineage checked (run/output_directory.hpp).
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/stop_flag.hpp"
#include "io/config.hpp"
#include "io/progress.hpp"
#include "run/integrator.hpp"
#include "run/output_directory.hpp"
#include "run/output_failures.hpp"
#include "run/outputs/observer.hpp"
#include "run/outputs/registry.hpp"
#include "run/phase_length.hpp"
#include "run/run.hpp"
#include "run/run_log.hpp"
#include "run/trigger.hpp"

namespace kairos {

template <int D>
class RunDriver final : public RunContext<D> {
 public:
  // The setup: the start state, its integrator, the checks a run must pass before it costs
  // anything; then the output directory is claimed and config.toml written. InputError for
  // anything the user must fix; Interrupted for a signal or the wall-time limit during it.
  RunDriver(const Config& config, const std::optional<std::filesystem::path>& restart_file,
            const RunOptions& options);
  ~RunDriver() override;

  // Adds an observer after the registered ones (make_observers): tests, and outputs a caller
  // of the library adds for itself. Before run().
  void add_observer(std::unique_ptr<Observer<D>> observer);

  // Runs both phases and writes every output. InputError from an output that cannot be
  // continued (another system's trajectory in the directory) or a DEM step that cannot be
  // taken; every other failure ends the run with RunOutcome::error.
  RunOutcome run();

  // RunContext.
  const Config& config() const override { return config_; }
  const Integrator<D>& integrator() const override { return *integrator_; }
  const std::filesystem::path& directory() const override { return directory_->path(); }
  bool restarted() const override { return restart_file_.has_value(); }
  const RunProgress& resumed() const override { return resumed_; }
  const std::optional<RestartPlan>& plan() const override { return plan_; }
  const OutputContinuation& continuation() const override { return continuation_; }
  const std::string& run_id() const override { return run_id_; }
  const Provenance& provenance() const override { return provenance_; }
  const std::string& phase() const override { return phase_; }
  bool timed() const override { return timed_; }
  double per_particle(std::uint64_t collisions) const override {
    return 2.0 * static_cast<double>(collisions) / static_cast<double>(integrator_->size());
  }
  void sample_production_row() const override;
  RunProgress progress_now() const override;
  const std::string& stop_reason() const override { return stop_reason_; }
  const std::string& error() const override { return error_; }
  double wall_seconds() const override { return wall_seconds_; }
  double setup_wall_seconds() const override { return setup_wall_seconds_; }

 private:
  using Clock = std::chrono::steady_clock;

  std::uint64_t collisions_for(double per_particle) const;
  // Runs a phase of `length`; true if the run stopped early (stop_reason_ says why).
  bool run_phase(const std::string& phase, PhaseLength length, ProgressLine& progress);
  // The observers' triggers for a phase starting at `begin` collisions, `begin_time`, and, in
  // a phase a continued run resumes (`continued`), the schedules and the origin of log-spaced
  // frames its restart file recorded.
  void start_triggers(std::uint64_t begin, double begin_time, bool continued);
  // Writes the observers due now (their indices), in order: false when one could not be
  // written (the run then stops). What is due and not written is owed (RunProgress::owed).
  bool write_due(const std::vector<std::size_t>& due);
  // The run stops: why (stop_reason_), true.
  bool stopped_because(const char* reason);
  bool wall_time_exceeded() const;
  nlohmann::json outputs_present() const;
  void open_log();

  // The start of the set-up: the origin of run.max_wall_seconds (the front end's
  // ScopedStopDeadline, which also covers table builds before the driver exists).
  Clock::time_point created_ = wall_limit_origin();
  Config config_;
  std::optional<std::filesystem::path> restart_file_;
  RunProgress resumed_;
  std::optional<RestartPlan> plan_;
  std::unique_ptr<Integrator<D>> integrator_;
  std::string run_id_;  // the lineage of the outputs (kept by continued runs)
  Provenance provenance_;
  std::optional<OutputDirectory> directory_;  // claimed (locked) while the run lasts
  std::optional<RunLog> log_;                 // run.log (output.log_interval)
  OutputContinuation continuation_;
  ObserverList<D> observers_;
  std::vector<Trigger> triggers_;  // per observer, of the phase running
  OutputFailures failures_;
  bool timed_ = false;
  std::string phase_ = "production";
  bool first_phase_ = true, production_done_ = false;
  // The phase running (or last run): its target collision count and end time (infinity: in
  // collisions); the equilibration's; the schedule's phase (0 equilibration, 1 production, -1:
  // none yet) as the restart file records it.
  std::uint64_t phase_target_ = 0, equilibration_target_ = 0;
  double phase_end_time_ = AdvanceLimits::kNoTime, equilibration_end_time_ = 0.0;
  int schedule_phase_ = -1;
  // The origin of the log-spaced writes of the phase running (RunProgress::frame_origin_*);
  // NaN time: none.
  double log_origin_time_ = std::numeric_limits<double>::quiet_NaN();
  std::uint64_t log_origin_collisions_ = 0;
  unsigned owed_ = 0;  // RunProgress::owed_outputs of the present state
  std::string stop_reason_ = "completed";
  std::string error_;  // why the run could not go on (RunOutcome::error)
  double wall_seconds_ = 0.0;
  double setup_wall_seconds_ = 0.0;
};

}  // namespace kairos
