#include "run/run_driver.hpp"

#include <sys/resource.h>
#include <cstdio>

#include <algorithm>
#include <cmath>
#include <utility>

#include <fmt/format.h>

#include "core/setup_progress.hpp"
#include "core/stop_flag.hpp"
#include "io/atomic_file.hpp"
#include "io/config_choices.hpp"
#include "run/output_directory.hpp"
#include "run/outputs/msd_output.hpp"
#include "run/setup_chain.hpp"

namespace kairos {

namespace {

// The file the driver writes from every observer's summarize().
const std::string kSummaryFile(kSummaryFileName);

namespace fs = std::filesystem;

constexpr std::uint64_t kNoTarget = ~std::uint64_t{0};

// The whole process's peak (getrusage), sampled after the restart file and the summary's own
// checks: the kernel's figure for the run (tests/python/test_memory.py).
std::uint64_t peak_rss_bytes() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<std::uint64_t>(usage.ru_maxrss) * 1024u;
}

}  // namespace

template <int D>
RunDriver<D>::RunDriver(const Config& config, const std::optional<fs::path>& restart_file,
                        const RunOptions& options) {
  // The log first: the set-up's long steps (random insertion, compression, soft tables) report
  // to it as they go ([output] is the given config's, a restart's too).
  const ProgressMode mode = progress_modes().at(config.output.progress);
  log_.emplace(config.output.log_interval, mode == ProgressMode::kAuto && !stderr_is_a_terminal());
  const ScopedSetupListener listen([this](const std::string& step, const std::string& detail) {
    log_->setup_step(step, detail);
  });
  RunStart<D> start =
      start_run<D>(config, restart_file,
                   integrators().is(config.run.integrator, IntegratorKind::kDem) ? "dem" : "event");
  config_ = start.config;
  restart_file_ = start.restart_file;
  resumed_ = start.resumed;
  plan_ = start.plan;
  const std::string restart_name = start.restart_name();
  SetupOutcome<D> setup;
  if (start.compression) {
    setup.compression = std::make_shared<const CompressionReport>(std::move(*start.compression));
    setup.packing = std::make_shared<const ParticleSystem<D>>(start.state);
  }
  // Soft spheres: the lookup tables of the collision map, built now or read from the cache.
  const bool tell = mode != ProgressMode::kOff;
  std::string building;
  integrator_ = start_integrator<D>(std::move(start), [&](const std::string& contact, double) {
    const std::string what = "building the soft-contact map table of " + contact;
    report_setup_progress(what, {});  // to run.log, as every long set-up step
    if (contact == building) return;
    building = contact;
    if (tell) std::fputs((what + " ...\n").c_str(), stderr);
  });
  timed_ =
      config_.run.time > 0.0 || config_.run.equilibration_time >= 0.0 || intervals_in_time(config_);
  // Phases measured in collisions need a system that collides.
  const PhaseLength equilibration = restarted()
                                        ? resumed_equilibration(config_.run, resumed_, restart_name)
                                        : equilibration_length(config_.run);
  double collisions = 0.0;
  for (const PhaseLength& p : {equilibration, production_length(config_.run)})
    if (!p.in_time && p.value > 0.0) collisions += static_cast<double>(collisions_for(p.value));
  if (collisions > 0.0) integrator_->check_collisions_can_happen(collisions);
  if (plan_) print_restart_note(*plan_, restart_name);
  // The end of the setup, before anything is written: a signal or run.max_wall_seconds that
  // came during a part that does not poll (the engine's first predictions) ends it here, as
  // an interrupted setup (nothing written; the limit an error), not as a run.
  throw_if_stop_requested();
  run_id_ = lineage_run_id(restart_file_, resumed_);
  std::optional<RestartLineage> lineage;
  if (restart_file_) lineage = RestartLineage{*restart_file_, resumed_.run_id};
  directory_.emplace(config_.output.directory, lineage, options.overwrite);
  // The effective configuration (after a restart, the configuration as run).
  // Its provenance on top: comments, which a restart (it stores to_toml alone) leaves out.
  provenance_ = provenance_now(options.command_line, restart_file_);
  write_text_atomically(directory_->path() / "config.toml",
                        toml_comment(provenance_) + to_toml(config_));
  observers_ = make_observers<D>(config_, *integrator_, setup);
}

template <int D>
RunDriver<D>::~RunDriver() = default;

template <int D>
void RunDriver<D>::add_observer(std::unique_ptr<Observer<D>> observer) {
  observers_.push_back(std::move(observer));
}

template <int D>
std::uint64_t RunDriver<D>::collisions_for(double per_particle) const {
  return kairos::collisions_for(per_particle, integrator_->mobile());
}

template <int D>
RunOutcome RunDriver<D>::run() {
  const auto wall_start = Clock::now();
  setup_wall_seconds_ = std::chrono::duration<double>(wall_start - created_).count();
  continuation_ = output_continuation(directory_->continues_outputs(), resumed_);
  for (auto& o : observers_) o->open(*this);
  open_log();
  ProgressLine progress(progress_modes().at(config_.output.progress));

  // A restart continues an interrupted equilibration, otherwise goes straight to production.
  const PhaseLength equilibration =
      restarted() ? resumed_equilibration(config_.run, resumed_, restart_file_->string())
                  : equilibration_length(config_.run);
  bool stopped = false;
  if (equilibration.value > 0.0) {
    stopped = run_phase("equilibration", equilibration, progress);
    for (auto& o : observers_)
      failures_.attempt(o->name(), [&] { o->equilibration_ends(*this, stopped); });
  }
  for (auto& o : observers_) o->production_starts(*this);
  if (!stopped) {
    const PhaseLength production =
        restarted() ? continued_production(config_.run, resumed_, plan_, integrator_->time(),
                                           integrator_->collisions())
                    : production_length(config_.run);
    stopped = run_phase("production", production, progress);
    production_done_ = !stopped;
  }
  progress.finish();
  if (!stopped) {
    if (std::string frozen = integrator_->frozen_at_end(); !frozen.empty()) {
      stopped = stopped_because("frozen_clock");
      error_ = std::move(frozen);
    }
  }
  // The last row and frame (kept unless the run stopped early: a continued run writes the ones
  // an uninterrupted run would), the restart file, the profile. Each is tried even if another
  // failed.
  for (auto& o : observers_) failures_.attempt(o->name(), [&] { o->close(*this, stopped); });
  wall_seconds_ = std::chrono::duration<double>(Clock::now() - wall_start).count();
  const std::string run_error = error_;  // why the run could not go on, before any write
  const auto with_outputs = [&] {
    return run_error.empty() ? failures_.error : run_error + "; " + failures_.error;
  };
  if (failures_.any()) {
    error_ = with_outputs();
    if (stop_reason_ == "completed" || stop_reason_ == "signal") stop_reason_ = "write_failed";
  }
  RunOutcome outcome;
  outcome.directory = directory_->path();
  outcome.interrupted = stopped && error_.empty();
  outcome.error = error_;
  for (const auto& o : observers_) o->summarize(outcome.summary, *this);
  outcome.summary["peak_rss_bytes"] = peak_rss_bytes();
  outcome.summary["outputs"] = outputs_present();
  failures_.attempt(kSummaryFile, [&] {
    write_text_atomically(directory_->path() / kSummaryFile, outcome.summary.dump(2) + "\n");
  });
  const std::string run_failed = failures_.any() ? with_outputs() : error_;
  log_->line(fmt::format("end: {} after {} of wall time; {} events, {} collisions, t = {:.10g}{}",
                         stop_reason_, format_duration(wall_seconds_), integrator_->events(),
                         integrator_->collisions(), integrator_->time(),
                         run_failed.empty() ? "" : "; error: " + run_failed));
  // failures_.error now ends with the summary's failure (error_ holds the earlier ones).
  if (failures_.failed_file(kSummaryFile)) {
    outcome.error = with_outputs();
    // What the console lists is what the directory holds: the summary is not among it.
    nlohmann::json& listed = outcome.summary["outputs"];
    listed.erase(std::remove(listed.begin(), listed.end(), nlohmann::json(kSummaryFile)),
                 listed.end());
  }
  return outcome;
}

// Runs until `length` more collisions per particle or simulated time; returns true if stopped
// early. The integrator runs its events (steps) in batches (Integrator::advance) and returns
// when an output may be due, the phase may be over, or the stop flag, the progress line or the
// wall clock are to be looked at.
template <int D>
bool RunDriver<D>::run_phase(const std::string& phase, PhaseLength length, ProgressLine& progress) {
  Integrator<D>& integrator = *integrator_;
  phase_ = phase;
  std::uint64_t begin = integrator.collisions();
  double begin_time = integrator.time();
  integrator.count_phase_from(begin, begin_time, first_phase_, restarted(), resumed_,
                              phase_end_time_);
  const std::uint64_t target = length.in_time      ? kNoTarget
                               : length.target > 0 ? length.target
                                                   : begin + collisions_for(length.value);
  if (length.target > 0) length.value = per_particle(target > begin ? target - begin : 0);
  const double end_time = !length.in_time             ? AdvanceLimits::kNoTime
                          : std::isfinite(length.end) ? length.end
                                                      : begin_time + length.value;
  if (phase == "equilibration") {
    equilibration_target_ = target;
    equilibration_end_time_ = end_time;
  }
  phase_target_ = target;
  phase_end_time_ = end_time;
  schedule_phase_ = phase == "production" ? 1 : 0;
  // The phase the restart file was written in, resumed (else it starts now).
  const bool continued = restarted() && first_phase_ && resumed_.schedule_phase == schedule_phase_;
  start_triggers(begin, begin_time, continued);
  // Continued in its own directory from a state whose row or frame could not be written: they
  // come first.
  if (restarted() && first_phase_ && continuation_.same_directory && resumed_.owed_outputs != 0) {
    std::vector<std::size_t> owed;
    for (std::size_t k = 0; k < observers_.size(); ++k)
      if ((observers_[k]->owed_bit() & resumed_.owed_outputs) != 0) owed.push_back(k);
    if (!write_due(owed)) return stopped_because("write_failed");
  }
  first_phase_ = false;
  // The writes at the start of a phase (the first production frame, the origin of log-spaced
  // frames), unless a continued run resumes the phase.
  if (!continued) {
    std::vector<std::size_t> at_start;
    for (std::size_t k = 0; k < observers_.size(); ++k) {
      const OutputSpacing spacing = observers_[k]->spacing(config_, phase);
      if (spacing.in_phase && spacing.at_start) at_start.push_back(k);
    }
    if (!write_due(at_start)) return stopped_because("write_failed");
  }
  const auto report = [&](double done, bool force) {
    const ProgressInfo info{
        phase, done, length.value, integrator.time(), integrator.events(), length.in_time};
    progress.update(info, force);
    log_->progress(info, force);
  };
  report(0.0, false);
  AdvanceLimits limits;
  limits.phase_end_time = end_time;
  limits.phase_in_time = length.in_time;
  limits.clock_stops = length.in_time || intervals_in_time(config_) ||
                       std::any_of(observers_.begin(), observers_.end(),
                                   [](const auto& o) { return o->samples_in_time(); });
  std::vector<std::size_t> due;
  while (length.in_time ? !integrator.reached(end_time) : integrator.collisions() < target) {
    limits.collisions = target;
    limits.next_output_time = AdvanceLimits::kNoTime;
    for (const Trigger& t : triggers_) {
      limits.collisions = std::min(limits.collisions, t.collisions.next);
      limits.next_output_time = std::min(limits.next_output_time, t.time.next);
    }
    const Advance a = integrator.advance(limits);
    if (a.stop == AdvanceStop::kNoMoreEvents) {
      stop_reason_ = "no_more_events";
      break;
    }
    if (a.stop == AdvanceStop::kAtRest) {
      stop_reason_ = "at_rest";
      break;
    }
    if (a.stop == AdvanceStop::kFrozenClock || a.stop == AdvanceStop::kError) {
      // Every output is written, the message is the run's error.
      error_ = a.error;
      return stopped_because(a.stop == AdvanceStop::kError ? "error" : "frozen_clock");
    }
    const std::uint64_t c = integrator.collisions();
    const double t = integrator.trigger_time();
    due.clear();
    for (std::size_t k = 0; k < triggers_.size(); ++k) {
      if ((a.collision_triggers && triggers_[k].collisions.due(c)) ||
          (a.time_triggers && triggers_[k].time.due(t)))
        due.push_back(k);
    }
    if (!write_due(due)) return stopped_because("write_failed");
    if (stop_requested()) return stopped_because("signal");
    if (a.update_progress) {
      report(length.in_time ? integrator.time() - begin_time : per_particle(c - begin), false);
    }
    if (a.check_wall_time && wall_time_exceeded()) return stopped_because("wall_time_limit");
  }
  if (length.in_time) stop_reason_ = "completed";  // ran to its end, whatever came before
  report(length.value, true);
  return false;
}

template <int D>
void RunDriver<D>::start_triggers(std::uint64_t begin, double begin_time, bool continued) {
  const double production = production_length(config_.run).value;
  const bool in_time = intervals_in_time(config_);
  triggers_.assign(observers_.size(), Trigger{});
  // Log-spaced writes count from the phase's start, or from the start a continued run's
  // restart file recorded for the phase it resumes.
  const ProgressMark* resumed_origin = continued ? resumed_.mark("frame_origin") : nullptr;
  const double origin_time = resumed_origin ? resumed_origin->values[0] : begin_time;
  const std::uint64_t origin = resumed_origin ? resumed_origin->counts[0] : begin;
  log_origin_time_ = std::numeric_limits<double>::quiet_NaN();
  for (std::size_t k = 0; k < observers_.size(); ++k) {
    const double interval = observers_[k]->interval(config_, production);
    const OutputSpacing spacing = observers_[k]->spacing(config_, phase_);
    if (!(interval > 0.0) || !spacing.in_phase) continue;
    const bool timed =
        !observers_[k]->samples_in_collisions() && (in_time || observers_[k]->samples_in_time());
    if (spacing.per_decade > 0.0) {
      // In collisions: the lags at their exact collision counts (the first count at or after
      // each), the period a whole number of collisions as a step is.
      const double per_collision = static_cast<double>(integrator_->mobile()) / 2.0;
      LogSpacing log{.first = timed ? interval : interval * per_collision,
                     .per_decade = spacing.per_decade,
                     .period = spacing.period > 0.0 && !timed
                                   ? static_cast<double>(
                                         std::max<std::uint64_t>(1, collisions_for(spacing.period)))
                                   : spacing.period};
      triggers_[k] = timed ? Trigger::log_time(log, origin_time, integrator_->trigger_time())
                           : Trigger::log_collisions(log, origin, integrator_->collisions());
      log_origin_time_ = origin_time;
      log_origin_collisions_ = origin;
      continue;
    }
    triggers_[k] = timed ? Trigger::every_time(interval, begin_time)
                         : Trigger::every_collisions(
                               std::max<std::uint64_t>(1, collisions_for(interval)), begin);
  }
  // The first phase of a continued run keeps the stored schedule of the same phase (the rows
  // an uninterrupted run would write), if its steps are unchanged.
  if (!continued) return;
  for (std::size_t k = 0; k < observers_.size(); ++k) {
    const int slot = observers_[k]->schedule_slot();
    if (slot < 0) continue;
    CollisionTrigger& e = triggers_[k].collisions;
    if (e.step > 0 && e.step == resumed_.schedule_step[slot] &&
        resumed_.schedule_next[slot] > begin)
      e.next = resumed_.schedule_next[slot];
  }
}

template <int D>
bool RunDriver<D>::write_due(const std::vector<std::size_t>& due) {
  owed_ = 0;
  for (const std::size_t k : due) owed_ |= observers_[k]->owed_bit();
  for (const std::size_t k : due) {
    Observer<D>& o = *observers_[k];
    if (!failures_.attempt(o.name(), [&] { o.write(*this); })) return false;
    owed_ &= ~o.owed_bit();
  }
  return true;
}

// The output files in the directory after the run, summary.json (about to be written) first,
// config.toml last (summary.json's "outputs").
template <int D>
nlohmann::json RunDriver<D>::outputs_present() const {
  nlohmann::json list = nlohmann::json::array({kSummaryFile});
  std::error_code ec;
  for (const auto& o : observers_) {
    if (o->writes_file() && fs::exists(directory() / o->name(), ec)) list.push_back(o->name());
    for (const std::string& more : o->more_files())
      if (fs::exists(directory() / more, ec)) list.push_back(more);
  }
  if (fs::exists(directory() / RunLog::kFile, ec)) list.push_back(RunLog::kFile);
  if (fs::exists(directory() / "config.toml", ec)) list.push_back("config.toml");
  return list;
}

// run.log's header: the program and how it was invoked, what it continued; then the set-up's
// noted steps and its wall time (RunLog::open).
template <int D>
void RunDriver<D>::open_log() {
  std::vector<std::string> header = {fmt::format(
      "start: kairos {} (commit {}) on {}: {}", provenance_.version, provenance_.commit,
      provenance_.host,
      provenance_.command_line.empty() ? "(no command line)" : provenance_.command_line)};
  if (!provenance_.restart_file.empty())
    header.push_back(
        fmt::format("continues {} at t = {:.10g}", provenance_.restart_file, integrator_->time()));
  log_->open(directory() / RunLog::kFile, header,
             {fmt::format("setup: {} particles in {}D, {:.3g} s of wall time",
                          integrator_->mobile(), D, setup_wall_seconds_)});
}

template <int D>
void RunDriver<D>::sample_production_row() const {
  for (const auto& o : observers_) o->sample(*this);
}

// What a restart file written now records: each observer's part, what is owed, the schedules,
// what is left of the phases, the integrator's part, the configuration and the run id.
template <int D>
RunProgress RunDriver<D>::progress_now() const {
  RunProgress p;
  for (const auto& o : observers_) o->record(p);
  p.owed_outputs = owed_;
  if (std::isfinite(log_origin_time_))
    p.marks["frame_origin"] = {{log_origin_time_}, {log_origin_collisions_}};
  if (schedule_phase_ >= 0) {
    p.schedule_phase = schedule_phase_;
    for (std::size_t k = 0; k < observers_.size(); ++k) {
      const int slot = observers_[k]->schedule_slot();
      if (slot < 0) continue;
      p.schedule_step[slot] = triggers_[k].collisions.step;
      p.schedule_next[slot] = triggers_[k].collisions.next;
    }
  }
  if (phase_ == "production" && !production_done_) {
    if (std::isfinite(phase_end_time_))
      p.production_end_time = phase_end_time_;
    else
      p.production_target = phase_target_;
  } else {
    p.marks.erase("production_start");  // only an unfinished production is continued
  }
  // Equilibration still owed if the run stops now, in the unit of the config's length.
  const std::uint64_t c = integrator_->collisions();
  if (phase_ == "equilibration" && config_.run.equilibration_time >= 0.0) {
    if (!integrator_->reached(equilibration_end_time_)) {
      p.equilibration_remaining = equilibration_end_time_ - integrator_->time();
      p.equilibration_end_time = equilibration_end_time_;
    }
  } else if (phase_ == "equilibration" && c < equilibration_target_) {
    p.equilibration_remaining = per_particle(equilibration_target_ - c);
  }
  integrator_->record(p, phase_target_, phase_end_time_);
  p.config = to_toml(config_);
  p.run_id = run_id_;
  return p;
}

template <int D>
bool RunDriver<D>::stopped_because(const char* reason) {
  stop_reason_ = reason;
  return true;
}

// run.max_wall_seconds counts from the start of the set-up (one limit for set-up and run).
template <int D>
bool RunDriver<D>::wall_time_exceeded() const {
  return config_.run.max_wall_seconds > 0 &&
         std::chrono::duration<double>(Clock::now() - created_).count() >
             config_.run.max_wall_seconds;
}

template class RunDriver<2>;
template class RunDriver<3>;

}  // namespace kairos
