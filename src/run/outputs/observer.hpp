// Outputs and analyses of a run as observers of the run driver (HOOMD's Writers and their
// Triggers): each output is one class, one file pair in src/run/outputs/, registered in one
// list (outputs/registry.cpp). docs/extending.md walks through adding one.
//
// The driver calls an observer at the moments of a run (every hook but name() may be left as
// it is):
//   open                  the run begins (files opened, a continued run's files cut back)
//   write                 its trigger fired: every interval() collisions per particle or unit
//                         of simulated time (output.interval_unit), counted per phase, or
//                         as spacing() says (log-spaced, at a phase's start)
//   sample                a production thermo row is written: analyses averaged over rows
//   equilibration_ends    the equilibration is over (or was stopped)
//   production_starts     production begins (also after an equilibration that was stopped)
//   close                 the run ends: last records, files closed
//   record                what the restart file keeps of it for a continued run
//   summarize             its part of summary.json
// write, equilibration_ends and close go through the run's OutputFailures under name(): an
// InputError thrown there (a full disk) stops the run, and the observer is not called for
// writing again, while the others still are. An InputError from open (a file there that is not
// this run's to continue) ends the run before its first event.
//
// An output that writes files into the output directory declares all it may write once, as
// `static constexpr std::array<std::string_view, N> kFiles`, and names them from there (name(),
// more_files(), its writes): registry.cpp collects them for the directory's guard and
// --overwrite (output_file_names()).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/config.hpp"
#include "run/integrator.hpp"
#include "run/output_directory.hpp"
#include "run/provenance.hpp"
#include "run/restart_plan.hpp"
#include "run/run_progress.hpp"
#include "run/trigger.hpp"

namespace kairos {

// What observers see of the run (the driver, run/run_driver.hpp).
template <int D>
class RunContext {
 public:
  virtual ~RunContext() = default;
  // The effective configuration (after a restart, RestartPlan::used).
  virtual const Config& config() const = 0;
  virtual const Integrator<D>& integrator() const = 0;
  virtual const std::filesystem::path& directory() const = 0;
  // Continued from a restart file, and what that file recorded (defaults for a new run).
  virtual bool restarted() const = 0;
  virtual const RunProgress& resumed() const = 0;
  virtual const std::optional<RestartPlan>& plan() const = 0;
  // Where a continued run picks up its lineage's files (output_directory.hpp).
  virtual const OutputContinuation& continuation() const = 0;
  virtual const std::string& run_id() const = 0;
  // Where the outputs came from (version, commit, date, host, command, restart file).
  virtual const Provenance& provenance() const = 0;
  // "equilibration" or "production": the phase running, or the last one run.
  virtual const std::string& phase() const = 0;
  // Some length or the output intervals are in simulated time: rows and frames are also due
  // when no collision happened since the last one.
  virtual bool timed() const = 0;
  // Collisions per particle of a collision count (c = 2 N_coll / N).
  virtual double per_particle(std::uint64_t collisions) const = 0;
  // Calls every observer's sample() (for a production thermo row).
  virtual void sample_production_row() const = 0;
  // The run's progress now, as the restart file records it (every observer's record()).
  virtual RunProgress progress_now() const = 0;
  // For summarize(): why the run stopped ("completed", "signal", ...), its error ("": none),
  // the wall-clock seconds of the run (the setup not counted) and of the setup before it
  // (from the origin of run.max_wall_seconds: their sum is what the limit compares).
  virtual const std::string& stop_reason() const = 0;
  virtual const std::string& error() const = 0;
  virtual double wall_seconds() const = 0;
  virtual double setup_wall_seconds() const = 0;
};

template <int D>
class Observer {
 public:
  virtual ~Observer() = default;
  // The file it writes in the output directory (or, for an analysis, what it is called): the
  // name of its writes in OutputFailures and in error messages.
  virtual std::string name() const = 0;
  // Whether name() is a file in the output directory (summary.json's "outputs" lists those
  // that exist at the end); false for parts of summary.json and other analyses.
  virtual bool writes_file() const { return true; }
  // Other files it writes in the output directory (listed in summary.json's "outputs" too).
  virtual std::vector<std::string> more_files() const { return {}; }
  // Its interval in collisions per particle or in simulated time (output.interval_unit), given
  // the production's length in that unit; 0: no trigger (write() is never called).
  virtual double interval(const Config& /*config*/, double /*production_length*/) const {
    return 0.0;
  }
  // How its writes are spaced in `phase` ("equilibration" or "production"): in it at all, once
  // at its start, log-spaced (run/trigger.hpp). The default: every interval() in every phase.
  virtual OutputSpacing spacing(const Config& /*config*/, const std::string& /*phase*/) const {
    return {};
  }
  // The restart file records the schedules of three outputs (kairos/run/schedule: 0 thermo, 1
  // trajectory, 2 restart), so that a continued run keeps them; -1: not recorded (a continued
  // run counts the interval afresh from its start).
  virtual int schedule_slot() const { return -1; }
  // Its interval is in simulated time whatever output.interval_unit says: an analysis that
  // samples at regular times (a time correlator); the clock stops at its samples.
  virtual bool samples_in_time() const { return false; }
  // Its interval is in collisions per particle whatever output.interval_unit says: an analysis
  // whose clock is the collision count (the MSD of a freely cooling gas, analysis.msd_time).
  virtual bool samples_in_collisions() const { return false; }
  // Its bit in RunProgress::owed_outputs when a write of it failed (kOwedRow, kOwedFrame): a
  // continued run writes it first. 0: nothing owed (written again at the next trigger).
  virtual unsigned owed_bit() const { return 0; }

  virtual void open(const RunContext<D>& /*run*/) {}
  virtual void write(const RunContext<D>& /*run*/) {}
  virtual void sample(const RunContext<D>& /*run*/) {}
  // stopped: the run stopped early (a signal, an error): a record written now is not kept (a
  // continued run writes the one an uninterrupted run would).
  virtual void equilibration_ends(const RunContext<D>& /*run*/, bool /*stopped*/) {}
  virtual void production_starts(const RunContext<D>& /*run*/) {}
  virtual void close(const RunContext<D>& /*run*/, bool /*stopped*/) {}
  virtual void record(RunProgress& /*progress*/) const {}
  virtual void summarize(nlohmann::json& /*summary*/, const RunContext<D>& /*run*/) const {}
};

}  // namespace kairos
