// run.integrator = "dem": the same run as the event-driven engine's (run/run.cpp), integrated by
// the force-based DemIntegrator (velocity Verlet, soft contact forces of [soft]).
//
// Run lengths and output intervals are in collisions per particle, a collision being a pair
// entering contact (DemIntegrator::collisions()); the integrator steps until the next output or
// the end of the phase is due. thermo.tsv has the event run's columns: `events` counts time
// steps, `potential_energy` is the elastic energy of the overlapping pairs and
// `dissipated_energy` the work of the damping forces. The restart file holds positions,
// velocities, time and counters in float64 and the time step (docs/outputs.md says what a
// continued run reproduces).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>

#include <nlohmann/json.hpp>

#include "analysis/block_average.hpp"
#include "analysis/profile.hpp"
#include "analysis/thermodynamics.hpp"
#include "core/error.hpp"
#include "core/periodic.hpp"
#include "core/stop_flag.hpp"
#include "dem/dem_integrator.hpp"
#include "init/initial_state.hpp"
#include "io/atomic_file.hpp"
#include "io/gsd_snapshot.hpp"
#include "io/progress.hpp"
#include "run/environment_setup.hpp"
#include "run/run_support.hpp"

namespace kairos::run_detail {

namespace {

using Clock = std::chrono::steady_clock;

template <int D>
class DemRunDriver {
 public:
  DemRunDriver(const Config& config, const std::optional<fs::path>& restart_file,
               const RunOptions& run_options)
      : config_(config),
        restart_(restart_file.has_value()),
        restart_name_(restart_file ? restart_file->string() : ""),
        rng_(config.system.seed),
        restart_file_(restart_file) {
    ParticleSystem<D> start = build_start_state<D>(config, restart_file, rng_, resumed_);
    check_restart_integrator(restart_file, resumed_, "dem");
    if (restart_file) {
      // New physics: the integrator starts afresh from the restored state (its lists and
      // tangential springs dropped).
      plan_ = plan_continuation<D>(config, start, resumed_, restart_name_);
      config_ = plan_->used;
    }
    n_ = start.size();
    base_events_ = start.counters.events;
    volume_ = 1.0;
    for (int a = 0; a < D; ++a) volume_ *= start.box[a];
    for (const auto& k : start.kinematics) {
      particle_volume_ += D == 3 ? 4.0 / 3.0 * std::numbers::pi * k.radius * k.radius * k.radius
                                 : std::numbers::pi * k.radius * k.radius;
    }
    thermo_stats_.emplace(D, n_, volume_);
    DemOptions options;
    // A continued run keeps its time step unless run.time_step sets one.
    options.dt = config_.run.time_step > 0.0 ? config_.run.time_step
                 : restart_                  ? resumed_.dem_time_step
                                             : 0.0;
    try {
      const Environment<D> env = make_environment<D>(config_, start);
      const auto damped = [](const SoftContactLaw& law) { return law.damping > 0.0; };
      // Walls and gravity, like damping, make the energy budget worth reporting.
      const auto rough = [](const SoftFriction& f) { return f.coefficient > 0.0; };
      granular_ = std::any_of(env.soft.begin(), env.soft.end(), damped) ||
                  std::any_of(env.soft_friction.begin(), env.soft_friction.end(), rough) ||
                  env.has_walls() || env.has_gravity();
      gravity_ = env.has_gravity();
      bulk_ = !gravity_ && !env.has_walls();
      dissipative_ = std::any_of(env.soft.begin(), env.soft.end(), damped);
      rotating_ = std::any_of(env.soft_friction.begin(), env.soft_friction.end(), rough);
      for (int f = 0; f < 2 * D; ++f)
        moving_walls_ =
            moving_walls_ || (env.faces[f].kind == FaceKind::kWall &&
                              (env.wall_moves(f) || norm2(env.faces[f].wall.velocity) > 0.0));
      dem_.emplace(start, env, options);
    } catch (const InputError& e) {
      if (!restart_file) throw;
      throw restart_setup_error(e, *restart_file, *plan_);
    }
    if (!config_.output.profile_axis.empty()) {
      const int axis = config_.output.profile_axis[0] - 'x';
      double cross = 1.0;
      for (int a = 0; a < D; ++a)
        if (a != axis) cross *= start.box[a];
      profile_.emplace(axis, static_cast<int>(config_.output.profile_bins), 0.0, start.box[axis],
                       cross);
    }
    timed_ = config_.run.time > 0.0 || config_.run.equilibration_time >= 0.0 ||
             intervals_in_time(config_);
    double mass = 0.0;
    for (const double m : start.mass) mass += m;
    check_collisions_happen(mass);
    if (plan_) print_restart_note(*plan_, restart_name_);
    // The end of the setup, before anything is written: a signal or run.max_wall_seconds that
    // came during a part that does not poll (the engine's first predictions) ends it here, as
    // an interrupted setup (nothing written; the limit an error), not as a run.
    throw_if_stop_requested();
    run_id_ = lineage_run_id(restart_file, resumed_);
    out_dir_.emplace(prepare_output_directory(config_, restart_file, resumed_.run_id, run_options));
    dir_ = out_dir_->path();
  }

  // As the event driver's: phases in collisions in a system that hardly collides refused, here
  // by the time steps a collision would take.
  void check_collisions_happen(double total_mass) const {
    if (gravity_) return;
    const PhaseLength eq = restart_ ? resumed_equilibration(config_.run, resumed_, restart_name_)
                                    : equilibration_length(config_.run);
    double collisions = 0.0;
    for (const PhaseLength& p : {eq, production_length(config_.run)})
      if (!p.in_time && p.value > 0.0) collisions += static_cast<double>(collisions_for(p.value));
    if (collisions == 0.0) return;
    const auto n = static_cast<double>(n_);
    const FlightEstimate flight =
        estimate_flight<D>(n, volume_, mean_volume_diameter<D>(particle_volume_, n),
                           std::sqrt(2.0 * dem_->kinetic_energy() / total_mass));
    check_collisions_can_happen(1.0 + flight.mean_free_time / dem_->dt(), collisions, flight,
                                "time steps");
  }

  RunOutcome run() {
    const auto wall_start = Clock::now();
    continuation_ = output_continuation(out_dir_->continues_outputs(), resumed_);
    thermo_.emplace(dir_ / "thermo.tsv", restart_, continuation_.thermo_rows);
    rows_kept_ = thermo_->rows();
    if (config_.output.trajectory) {
      const bool created =
          open_trajectory<D>(trajectory_, dir_, restart_, n_, continuation_.trajectory_frames,
                             [&] { return dem_->export_state(); });
      frames_kept_ = trajectory_->frame_count();
      // The present state's frame is there already (written now, or the last kept one the
      // restart file recorded): a continued run with nothing left to do writes no second one.
      if (restart_ && (created || (continuation_.same_directory && resumed_.has_frame_mark &&
                                   resumed_.frame_time == dem_->time())))
        frame_steps_ = dem_->steps();
      kept_frame_time_ = created || !resumed_.has_frame_mark ? dem_->time() : resumed_.frame_time;
    } else {
      frames_not_written_ = cut_back_trajectory<D>(dir_, n_, continuation_.trajectory_frames);
    }
    ke_start_ = dem_->kinetic_energy();
    energy_start_ = total_energy();
    dissipated_start_ = dem_->dissipated_energy();
    dissipated_walls_start_ = dem_->dissipated_at_walls();
    work_walls_start_ = dem_->work_by_walls();
    p_start_ = dem_->momentum();
    collisions_start_ = dem_->collisions();
    kept_mark_ = continuation_.same_directory && resumed_.has_thermo_mark
                     ? ThermoPoint{resumed_.mark_time, resumed_.mark_virial, resumed_.mark_events,
                                   resumed_.mark_collisions}
                     : point();
    thermo_stats_->mark(kept_mark_);
    ProgressLine progress(config_.output.progress);

    const PhaseLength eq = restart_ ? resumed_equilibration(config_.run, resumed_, restart_name_)
                                    : equilibration_length(config_.run);
    bool stopped = false;
    if (eq.value > 0.0) {
      stopped = run_phase("equilibration", eq, progress, wall_start);
      if (row_pending())
        outputs_.attempt("thermo.tsv", [&] { write_thermo_row("equilibration", !stopped); });
    }
    prod_start_ = point();
    prod_ke_ = dem_->kinetic_energy();
    if (!stopped) {
      const PhaseLength production =
          restart_
              ? continued_production(config_.run, resumed_, plan_, dem_->time(), dem_->collisions())
              : production_length(config_.run);
      stopped = run_phase("production", production, progress, wall_start);
      production_done_ = !stopped;
    }
    progress.finish();
    const bool kept = !stopped;
    if (row_pending()) outputs_.attempt("thermo.tsv", [&] { write_thermo_row(phase_, kept); });
    if (trajectory_) {
      outputs_.attempt("trajectory.gsd", [&] {
        if (frame_steps_ != dem_->steps()) write_trajectory_frame(kept);
        trajectory_->close();
      });
    }
    outputs_.attempt("restart.gsd", [&] { write_restart_file(); });
    if (profile_) outputs_.attempt("profile.tsv", [&] { profile_->write(dir_ / "profile.tsv"); });
    const double wall = std::chrono::duration<double>(Clock::now() - wall_start).count();
    if (outputs_.any() && (stop_reason_ == "completed" || stop_reason_ == "signal"))
      stop_reason_ = "write_failed";
    RunOutcome outcome;
    outcome.directory = dir_;
    outcome.interrupted = stopped && !outputs_.any();
    outcome.error = outputs_.error;
    outcome.summary = summary(wall);
    outcome.summary["outputs"] = outputs_present(dir_);
    outputs_.attempt("summary.json", [&] {
      write_text_atomically(dir_ / "summary.json", outcome.summary.dump(2) + "\n");
    });
    outcome.error = outputs_.error;
    return outcome;
  }

 private:
  std::uint64_t collisions_for(double per_particle) const {
    return static_cast<std::uint64_t>(std::llround(per_particle * static_cast<double>(n_) / 2.0));
  }
  double per_particle(std::uint64_t collisions) const {
    return thermo_stats_->per_particle(collisions);
  }
  ThermoPoint point() const {
    return {dem_->time(), dem_->virial(), base_events_ + static_cast<std::uint64_t>(dem_->steps()),
            dem_->collisions()};
  }
  // Kinetic plus elastic plus gravitational energy plus what the damping took, less what the
  // walls gave: constant to O(dt^2) (NaN with gravity along a periodic axis).
  double total_energy() const {
    return dem_->kinetic_energy() + dem_->rotational_energy() + dem_->potential_energy() +
           dem_->field_energy() + dem_->dissipated_energy() + dem_->dissipated_at_walls() -
           dem_->work_by_walls();
  }

  RunProgress progress_now() const {
    RunProgress p;
    const std::uint64_t c = dem_->collisions();
    const double t = dem_->time();
    if (phase_ == "equilibration" && config_.run.equilibration_time >= 0.0) {
      if (!reached(equilibration_end_time_)) {
        p.equilibration_remaining = equilibration_end_time_ - t;
        p.equilibration_end_time = equilibration_end_time_;
      }
    } else if (phase_ == "equilibration" && c < equilibration_target_) {
      p.equilibration_remaining = per_particle(equilibration_target_ - c);
    }
    p.integrator = "dem";
    p.config = to_toml(config_);
    p.run_id = run_id_;
    p.thermo_rows = static_cast<std::int64_t>(rows_kept_);
    p.trajectory_frames =
        trajectory_ ? static_cast<std::int64_t>(frames_kept_) : frames_not_written_;
    if (trajectory_) {
      p.has_frame_mark = true;
      p.frame_time = kept_frame_time_;
      p.frame_collisions = 0;  // the DEM's frames are told apart by their time
    }
    p.has_thermo_mark = true;
    p.mark_time = kept_mark_.time;
    p.mark_virial = kept_mark_.virial;
    p.mark_events = kept_mark_.events;
    p.mark_collisions = kept_mark_.collisions;
    if (schedule_phase_ >= 0) {
      p.schedule_phase = schedule_phase_;
      const OutputSchedule::Every* e[3] = {&schedule_.thermo, &schedule_.trajectory,
                                           &schedule_.restart};
      for (int k = 0; k < 3; ++k) {
        p.schedule_step[k] = e[k]->step;
        p.schedule_next[k] = e[k]->next;
      }
    }
    if (phase_ == "production" && !production_done_) {
      if (std::isfinite(phase_end_time_))
        p.production_end_time = phase_end_time_;
      else
        p.production_target = phase_target_;
    }
    p.dem_time_step = dem_->dt();
    // A completed phase ends at its target (the count may have passed it within the last step).
    p.dem_collision_mark = c >= phase_target_ ? phase_target_ : c;
    if (std::isfinite(phase_end_time_))
      p.dem_time_mark = reached(phase_end_time_) ? phase_end_time_ : t;
    return p;
  }

  void write_restart_file() const {
    write_dem_restart(dir_ / "restart.gsd", *dem_, rng_, progress_now());
  }

  bool reached(double t) const { return dem_reached(*dem_, t); }
  long steps_to(double t) const { return dem_steps_to(*dem_, t); }
  bool row_pending() const {
    return dem_->collisions() > thermo_stats_->last().collisions ||
           (timed_ && dem_->time() > thermo_stats_->last().time);
  }
  // kept: the frame (row) belongs to the run as an uninterrupted one writes it (not the last
  // of a run stopped early).
  void write_trajectory_frame(bool kept = true) {
    append_trajectory_frame(*trajectory_, dem_->export_state());
    frame_steps_ = dem_->steps();
    if (kept) {
      frames_kept_ = trajectory_->frame_count();
      kept_frame_time_ = dem_->time();
    }
  }

  // Steps until `length` more collisions per particle or simulated time (then to the first
  // step at or after its end); true if stopped early. Outputs in time come at the first step at
  // or after each multiple of their interval.
  bool run_phase(const std::string& phase, PhaseLength length, ProgressLine& progress,
                 Clock::time_point /*wall_start*/) {
    phase_ = phase;
    // The first phase of a continued run starts where the saved run nominally stopped.
    std::uint64_t begin = dem_->collisions();
    double begin_time = dem_->time();
    // After a phase in time: from its nominal end (its last step may have passed it).
    if (!first_phase_ && std::isfinite(phase_end_time_) && reached(phase_end_time_) &&
        phase_end_time_ > begin_time - dem_->dt())
      begin_time = phase_end_time_;
    if (restart_ && first_phase_ && resumed_.dem_collision_mark > 0 &&
        resumed_.dem_collision_mark <= begin)
      begin = resumed_.dem_collision_mark;
    if (restart_ && first_phase_ && resumed_.dem_time_mark <= begin_time &&
        resumed_.dem_time_mark > begin_time - dem_->dt())
      begin_time = resumed_.dem_time_mark;
    const bool first = first_phase_;
    first_phase_ = false;
    const std::uint64_t target = length.in_time      ? ~std::uint64_t{0}
                                 : length.target > 0 ? length.target
                                                     : begin + collisions_for(length.value);
    if (length.target > 0) length.value = per_particle(target > begin ? target - begin : 0);
    const double end_time = !length.in_time             ? std::numeric_limits<double>::quiet_NaN()
                            : std::isfinite(length.end) ? length.end
                                                        : begin_time + length.value;
    if (phase == "equilibration") {
      equilibration_target_ = target;
      equilibration_end_time_ = end_time;
    }
    phase_target_ = target;
    phase_end_time_ = end_time;
    const bool time_outputs = intervals_in_time(config_);
    auto [fresh, timed] =
        phase_schedules(config_, begin, begin_time, [&](double c) { return collisions_for(c); });
    schedule_ = fresh;
    schedule_phase_ = phase == "production" ? 1 : 0;
    OutputSchedule& schedule = schedule_;
    if (restart_ && first && resumed_.schedule_phase == (phase == "production" ? 1 : 0)) {
      OutputSchedule::Every* e[3] = {&schedule.thermo, &schedule.trajectory, &schedule.restart};
      for (int k = 0; k < 3; ++k)
        if (e[k]->step > 0 && e[k]->step == resumed_.schedule_step[k] &&
            resumed_.schedule_next[k] > begin)
          e[k]->next = resumed_.schedule_next[k];
    }
    // About 2^20 particle-steps between checks of the clock and the stop flag.
    const long chunk =
        std::max<long>(1, (1l << 20) / static_cast<long>(std::max<std::size_t>(1, n_)));
    const auto steps = [&] { return base_events_ + static_cast<std::uint64_t>(dem_->steps()); };
    const auto done = [&] {
      return length.in_time ? dem_->time() - begin_time : per_particle(dem_->collisions() - begin);
    };
    progress.update({phase, 0.0, length.value, dem_->time(), steps(), length.in_time});
    while (length.in_time ? !reached(end_time) : dem_->collisions() < target) {
      const std::uint64_t stop_at =
          std::min({target, schedule.thermo.next, schedule.trajectory.next, schedule.restart.next});
      long n = chunk;
      if (length.in_time) n = std::min(n, steps_to(end_time));
      if (time_outputs) n = std::min(n, steps_to(timed.next()));
      const std::uint64_t before = dem_->collisions(), wall_before = dem_->wall_collisions();
      dem_->step_until(n, stop_at);
      const std::uint64_t c = dem_->collisions();
      const double ke = dem_->kinetic_energy();
      ke_peak_ = std::max(ke_peak_, ke);
      // A length in collisions would never end once nothing moves or meets any more; a length
      // in time does.
      if (!length.in_time && c == before && dem_->contact_count() == 0 && ke == 0.0) {
        stop_reason_ = "no_more_events";  // everything at rest and apart
        break;
      }
      // A settled packing (under gravity, between walls) meets no new contacts: the collision
      // target would never come. At rest: no contact began in this chunk and the kinetic energy
      // fell below 1e-12 of its peak.
      if (!length.in_time && c == before && dem_->wall_collisions() == wall_before &&
          ke <= 1e-12 * ke_peak_) {
        stop_reason_ = "at_rest";
        break;
      }
      const double t = dem_->time() + 1e-9 * dem_->dt();  // as reached()
      const auto failed = [&] {
        stop_reason_ = "write_failed";
        return true;
      };
      if ((schedule.thermo.due(c) || timed.thermo.due(t)) &&
          !outputs_.attempt("thermo.tsv", [&] { write_thermo_row(phase); }))
        return failed();
      if ((schedule.trajectory.due(c) || timed.trajectory.due(t)) && trajectory_ &&
          !outputs_.attempt("trajectory.gsd", [&] { write_trajectory_frame(); }))
        return failed();
      if ((schedule.restart.due(c) || timed.restart.due(t)) &&
          !outputs_.attempt("restart.gsd", [&] { write_restart_file(); }))
        return failed();
      if (stop_requested()) {
        stop_reason_ = "signal";
        return true;
      }
      progress.update({phase, done(), length.value, dem_->time(), steps(), length.in_time});
      if (config_.run.max_wall_seconds > 0 &&  // from the start of the set-up, as run.cpp's
          std::chrono::duration<double>(Clock::now() - created_).count() >
              config_.run.max_wall_seconds) {
        stop_reason_ = "wall_time_limit";
        return true;
      }
    }
    if (length.in_time) stop_reason_ = "completed";  // ran to its end, whatever came before
    progress.update({phase, length.value, length.value, dem_->time(), steps(), length.in_time},
                    true);
    return false;
  }

  void write_thermo_row(const std::string& phase, bool kept = true) {
    const double ke = dem_->kinetic_energy();
    const ThermoRow row = thermo_stats_->row(point(), ke, phase == "production");
    if (phase == "production") {
      production_temperatures_.push_back(row.temperature);
      if (profile_) sample_profile();
    }
    thermo_->write(
        phase, row,
        {rotational_temperature(), dem_->dissipated_energy() + dem_->dissipated_at_walls(),
         dem_->work_by_walls(), dem_->potential_energy()});
    if (kept) {
      rows_kept_ = thermo_->rows();
      kept_mark_ = row.at;
    }
  }

  void sample_profile() {
    std::vector<Vec<D>> x(n_), v(n_);
    std::vector<double> mass(n_), volume(n_);
    const ParticleSystem<D> s = dem_->export_state();
    for (std::size_t i = 0; i < n_; ++i) {
      x[i] = dem_->position(i);
      v[i] = dem_->velocity(i);
      mass[i] = s.mass[i];
      const double r = s.kinematics[i].radius;
      volume[i] = D == 3 ? 4.0 / 3.0 * std::numbers::pi * r * r * r : std::numbers::pi * r * r;
    }
    profile_->sample(x, v, mass, volume);
  }

  // Per rotational degree of freedom (3 for spheres, 1 for disks); 0 without friction.
  double rotational_temperature() const {
    return 2.0 * dem_->rotational_energy() / ((D == 3 ? 3.0 : 1.0) * static_cast<double>(n_));
  }

  // Velocities relative to the centre of mass.
  double sonine_a2() const {
    const ParticleSystem<D> s = dem_->export_state();
    Vec<D> mean{};
    double mass = 0.0;
    for (std::size_t i = 0; i < n_; ++i) {
      mean = mean + s.mass[i] * s.kinematics[i].vel;
      mass += s.mass[i];
    }
    mean = (1.0 / mass) * mean;
    double m2 = 0.0, m4 = 0.0;
    for (std::size_t i = 0; i < n_; ++i) {
      const double c2 = norm2(s.kinematics[i].vel - mean);
      m2 += c2;
      m4 += c2 * c2;
    }
    m2 /= static_cast<double>(n_);
    m4 /= static_cast<double>(n_);
    return m2 > 0.0 ? D / (D + 2.0) * m4 / (m2 * m2) - 1.0 : std::nan("");
  }

  nlohmann::json summary(double wall) const {
    const Thermodynamics& th = *thermo_stats_;
    const double ke = dem_->kinetic_energy();
    const double kT = th.temperature(ke);
    const ParticleSystem<D> state = dem_->export_state();
    const Vec<D> p = dem_->momentum();
    double pscale = 0.0, dp2 = 0.0;
    for (std::size_t i = 0; i < n_; ++i)
      pscale += state.mass[i] * std::sqrt(norm2(state.kinematics[i].vel));
    for (int a = 0; a < D; ++a) dp2 += (p[a] - p_start_[a]) * (p[a] - p_start_[a]);
    const double t_prod = dem_->time() - prod_start_.time;
    const std::uint64_t coll_prod = dem_->collisions() - prod_start_.collisions;
    // Kinetic energy turns into elastic energy and heat: the production temperature is the
    // mean over the production rows.
    const double kT_prod = production_temperatures_.empty()
                               ? th.temperature(prod_ke_)
                               : block_average(production_temperatures_).mean;
    const double z_mean = th.compressibility(dem_->virial() - prod_start_.virial, kT_prod, t_prod);
    std::vector<Vec<D>> x(n_);
    std::vector<double> diameters(n_);
    for (std::size_t i = 0; i < n_; ++i) {
      x[i] = dem_->position(i);
      diameters[i] = 2.0 * state.kinematics[i].radius;
    }
    const auto steps = static_cast<std::uint64_t>(dem_->steps());
    const std::uint64_t collisions = dem_->collisions() - collisions_start_;
    const double energy = total_energy();
    nlohmann::json j;
    j["kairos_version"] = KAIROS_VERSION;
    j["integrator"] = "dem";
    j["dimension"] = D;
    j["particles"] = n_;
    j["packing_fraction"] = particle_volume_ / volume_;
    j["number_density"] = static_cast<double>(n_) / volume_;
    j["run_id"] = run_id_;
    j["restarted"] = restart_;
    if (plan_) j["restart"] = restart_summary(*plan_);
    j["stop_reason"] = stop_reason_;
    if (outputs_.any()) j["error"] = outputs_.error;
    // "events" are time steps.
    add_run_totals(j,
                   {steps, collisions, coll_prod, dem_->time(), t_prod, wall,
                    per_particle(coll_prod), kT, ke, kT_prod, z_mean},
                   th, bulk_);
    // E includes the gravitational energy: unbounded along a periodic axis (then null).
    const std::string field_unbounded =
        "gravity along a periodic axis: the potential energy is unbounded";
    const std::string unbounded =
        std::isfinite(energy) && std::isfinite(energy_start_) ? "" : field_unbounded;
    set_or_explain(j, j, "energy_drift_relative",
                   ke_start_ > 0 ? std::abs(energy - energy_start_) / ke_start_ : 0.0, unbounded,
                   "energy_drift_relative");
    j["momentum_drift"] = pscale > 0 ? std::sqrt(dp2) / pscale : 0.0;
    j["max_overlap"] = max_overlap<D>(state.box, state.periodic, x, diameters);
    j["peak_rss_bytes"] = peak_rss_bytes();
    nlohmann::json d;
    d["time_step"] = dem_->dt();
    d["time_step_automatic"] = config_.run.time_step == 0.0;
    d["steps"] = steps;
    d["steps_since_start"] = base_events_ + steps;
    d["collisions_since_start"] = dem_->collisions();
    d["contacts_now"] = dem_->contact_count();
    d["neighbour_list_builds"] = dem_->neighbour_list_builds();
    d["ns_per_particle_step"] =
        steps > 0 ? 1e9 * wall / (static_cast<double>(steps) * static_cast<double>(n_)) : 0.0;
    d["potential_energy"] = dem_->potential_energy();
    const double field = dem_->field_energy();
    set_or_explain(j, d, "field_energy", field, std::isfinite(field) ? "" : field_unbounded,
                   "dem.field_energy");
    d["wall_collisions"] = dem_->wall_collisions();
    d["dissipated_energy"] = dem_->dissipated_energy() - dissipated_start_;
    set_or_explain(j, d, "energy_start", energy_start_, unbounded, "dem.energy_start");
    set_or_explain(j, d, "energy_end", energy, unbounded, "dem.energy_end");
    j["dem"] = d;
    if (!granular_) return j;
    // Damping, walls or gravity: the energy budget, as the event engine reports it for
    // granular runs.
    const double dissipated = dem_->dissipated_energy() - dissipated_start_;
    const double at_walls = dem_->dissipated_at_walls() - dissipated_walls_start_;
    const double by_walls = dem_->work_by_walls() - work_walls_start_;
    const double scale =
        std::max({std::abs(energy_start_), dissipated + at_walls, std::abs(by_walls)});
    nlohmann::json g;
    g["rotating"] = rotating_;
    g["dissipative"] = dissipative_;
    g["moving_walls"] = moving_walls_;
    g["driven"] = false;
    g["rotational_temperature"] = rotational_temperature();
    const double a2 = sonine_a2();
    set_or_explain(j, g, "sonine_a2", a2,
                   !bulk_               ? "walls, open faces or a field: the gas is not homogeneous"
                   : !std::isfinite(a2) ? "every particle at rest"
                                        : "",
                   "granular.sonine_a2");
    g["dissipated_in_collisions"] = dissipated;
    g["dissipated_at_walls"] = at_walls;
    g["work_by_walls"] = by_walls;
    g["wall_collisions"] = dem_->wall_collisions();
    set_or_explain(j, g, "energy_start", energy_start_, unbounded, "granular.energy_start");
    set_or_explain(j, g, "energy_end", energy, unbounded, "granular.energy_end");
    set_or_explain(j, g, "energy_balance_relative",
                   scale > 0.0 ? std::abs(energy - energy_start_) / scale : 0.0, unbounded,
                   "granular.energy_balance_relative");
    j["granular"] = g;
    return j;
  }

  Clock::time_point created_ = Clock::now();  // the start of the set-up
  Config config_;
  bool restart_;
  std::string restart_name_;  // the restart file continued, for messages
  std::mt19937_64 rng_;
  RunProgress resumed_;
  std::optional<RestartPlan> plan_;  // a restart: how it used the changed configuration
  std::optional<fs::path> restart_file_;
  std::string run_id_;                      // the lineage of the outputs (kept by continued runs)
  std::optional<OutputDirectory> out_dir_;  // claimed (locked) while the run lasts
  OutputContinuation continuation_;
  OutputFailures outputs_;
  // As the event driver's (run/run.cpp).
  std::uint64_t rows_kept_ = 0, frames_kept_ = 0;
  std::int64_t frames_not_written_ = -1;  // output.trajectory = false: as the event driver's
  ThermoPoint kept_mark_;
  OutputSchedule schedule_;  // as the event driver's (run/run.cpp)
  int schedule_phase_ = -1;
  bool production_done_ = false;
  std::optional<DemIntegrator<D>> dem_;
  std::size_t n_ = 0;
  double volume_ = 1.0, particle_volume_ = 0.0;
  bool granular_ = false;  // damping, walls or gravity: report the energy budget
  bool gravity_ = false;
  bool bulk_ = true;  // periodic without a field: Z, P and a2 are bulk values
  bool rotating_ = false, dissipative_ = false, moving_walls_ = false;  // granular lines shown
  fs::path dir_;
  std::optional<ThermoWriter> thermo_;
  std::optional<gsd::Writer> trajectory_;
  std::optional<Thermodynamics> thermo_stats_;
  std::optional<AxisProfile<D>> profile_;
  ThermoPoint prod_start_;
  double ke_start_ = 0.0, prod_ke_ = 0.0, energy_start_ = 0.0, dissipated_start_ = 0.0;
  double dissipated_walls_start_ = 0.0, work_walls_start_ = 0.0;
  double ke_peak_ = 0.0;  // the largest kinetic energy seen (the scale of "at rest")
  Vec<D> p_start_{};
  long frame_steps_ = 0;
  double kept_frame_time_ = 0.0;  // of the last frame kept (frames_kept_)
  // Time steps of the runs this one continues (the state's event counter at the start).
  std::uint64_t collisions_start_ = 0, base_events_ = 0;
  std::vector<double> production_temperatures_;
  std::string phase_ = "production";
  std::uint64_t equilibration_target_ = 0;
  std::uint64_t phase_target_ = 0;  // the collision count the present phase runs to
  // Lengths in time: the present phase's end time (NaN: in collisions), the equilibration's.
  double phase_end_time_ = std::numeric_limits<double>::quiet_NaN();
  double equilibration_end_time_ = 0.0;
  bool timed_ = false;  // some length or the intervals in time (see RunDriver)
  bool first_phase_ = true;
  std::string stop_reason_ = "completed";
};

}  // namespace

template <int D>
RunOutcome run_dem(const Config& config, const std::optional<fs::path>& restart_file,
                   const RunOptions& options) {
  return DemRunDriver<D>(config, restart_file, options).run();
}

template RunOutcome run_dem<2>(const Config&, const std::optional<fs::path>&, const RunOptions&);
template RunOutcome run_dem<3>(const Config&, const std::optional<fs::path>&, const RunOptions&);

}  // namespace kairos::run_detail
