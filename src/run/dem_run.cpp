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
  DemRunDriver(const Config& config, const std::optional<fs::path>& restart_file)
      : config_(config),
        restart_(restart_file.has_value()),
        restart_name_(restart_file ? restart_file->string() : ""),
        rng_(config.system.seed) {
    ParticleSystem<D> start = build_start_state<D>(config, restart_file, rng_, resumed_);
    check_restart_integrator(restart_file, resumed_, "dem");
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
    options.dt = config.run.time_step > 0.0 ? config.run.time_step
                 : restart_                 ? resumed_.dem_time_step
                                            : 0.0;
    try {
      const Environment<D> env = make_environment<D>(config, start);
      const auto damped = [](const SoftContactLaw& law) { return law.damping > 0.0; };
      // Walls and gravity, like damping, make the energy budget worth reporting.
      const auto rough = [](const SoftFriction& f) { return f.coefficient > 0.0; };
      granular_ = std::any_of(env.soft.begin(), env.soft.end(), damped) ||
                  std::any_of(env.soft_friction.begin(), env.soft_friction.end(), rough) ||
                  env.has_walls() || env.has_gravity();
      dem_.emplace(start, env, options);
    } catch (const InputError& e) {
      if (!restart_file) throw;
      throw InputError("restart file '" + restart_file->string() + "': " + e.what());
    }
    if (!config.output.profile_axis.empty()) {
      const int axis = config.output.profile_axis[0] - 'x';
      double cross = 1.0;
      for (int a = 0; a < D; ++a)
        if (a != axis) cross *= start.box[a];
      profile_.emplace(axis, static_cast<int>(config.output.profile_bins), 0.0, start.box[axis],
                       cross);
    }
    timed_ =
        config.run.time > 0.0 || config.run.equilibration_time >= 0.0 || intervals_in_time(config);
    dir_ = prepare_output_directory(config);
  }

  RunOutcome run() {
    const auto wall_start = Clock::now();
    thermo_.emplace(dir_ / "thermo.tsv", restart_);
    if (config_.output.trajectory)
      open_trajectory<D>(trajectory_, dir_, restart_, n_, [&] { return dem_->export_state(); });
    ke_start_ = dem_->kinetic_energy();
    energy_start_ = total_energy();
    dissipated_start_ = dem_->dissipated_energy();
    dissipated_walls_start_ = dem_->dissipated_at_walls();
    work_walls_start_ = dem_->work_by_walls();
    p_start_ = dem_->momentum();
    collisions_start_ = dem_->collisions();
    thermo_stats_->mark(point());
    ProgressLine progress(config_.output.progress);

    const PhaseLength eq = restart_ ? resumed_equilibration(config_.run, resumed_, restart_name_)
                                    : equilibration_length(config_.run);
    bool stopped = false;
    if (eq.value > 0.0) {
      stopped = run_phase("equilibration", eq, progress, wall_start);
      if (row_pending()) write_thermo_row("equilibration");
    }
    prod_start_ = point();
    prod_ke_ = dem_->kinetic_energy();
    if (!stopped)
      stopped = run_phase("production", production_length(config_.run), progress, wall_start);
    progress.finish();
    if (row_pending()) write_thermo_row(phase_);
    const double wall = std::chrono::duration<double>(Clock::now() - wall_start).count();

    if (trajectory_) {
      if (frame_steps_ != dem_->steps())
        append_trajectory_frame(*trajectory_, dem_->export_state());
      trajectory_->close();
    }
    RunOutcome outcome;
    outcome.directory = dir_;
    outcome.interrupted = stopped;
    outcome.summary = summary(wall);
    write_restart_file();
    if (profile_) profile_->write(dir_ / "profile.tsv");
    write_text_atomically(dir_ / "summary.json", outcome.summary.dump(2) + "\n");
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
  void write_trajectory_frame() {
    append_trajectory_frame(*trajectory_, dem_->export_state());
    frame_steps_ = dem_->steps();
  }

  // Steps until `length` more collisions per particle or simulated time (then to the first
  // step at or after its end); true if stopped early. Outputs in time come at the first step at
  // or after each multiple of their interval.
  bool run_phase(const std::string& phase, PhaseLength length, ProgressLine& progress,
                 Clock::time_point wall_start) {
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
    first_phase_ = false;
    const std::uint64_t target =
        length.in_time ? ~std::uint64_t{0} : begin + collisions_for(length.value);
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
    auto [schedule, timed] =
        phase_schedules(config_, begin, begin_time, [&](double c) { return collisions_for(c); });
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
      if (schedule.thermo.due(c) || timed.thermo.due(t)) write_thermo_row(phase);
      if ((schedule.trajectory.due(c) || timed.trajectory.due(t)) && trajectory_)
        write_trajectory_frame();
      if (schedule.restart.due(c) || timed.restart.due(t)) write_restart_file();
      if (stop_requested()) {
        stop_reason_ = "signal";
        return true;
      }
      progress.update({phase, done(), length.value, dem_->time(), steps(), length.in_time});
      if (config_.run.max_wall_seconds > 0 &&
          std::chrono::duration<double>(Clock::now() - wall_start).count() >
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

  void write_thermo_row(const std::string& phase) {
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
    j["restarted"] = restart_;
    j["stop_reason"] = stop_reason_;
    // "events" are time steps.
    add_run_totals(j,
                   {steps, collisions, coll_prod, dem_->time(), t_prod, wall,
                    per_particle(coll_prod), kT, ke, kT_prod, z_mean},
                   th);
    j["energy_drift_relative"] = ke_start_ > 0 ? std::abs(energy - energy_start_) / ke_start_ : 0.0;
    j["momentum_drift"] = pscale > 0 ? std::sqrt(dp2) / pscale : 0.0;
    j["max_overlap"] = max_overlap<D>(state.box, x, diameters);
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
    d["field_energy"] = dem_->field_energy();
    d["wall_collisions"] = dem_->wall_collisions();
    d["dissipated_energy"] = dem_->dissipated_energy() - dissipated_start_;
    d["energy_start"] = energy_start_;
    d["energy_end"] = energy;
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
    g["rotational_temperature"] = rotational_temperature();
    g["sonine_a2"] = sonine_a2();
    g["dissipated_in_collisions"] = dissipated;
    g["dissipated_at_walls"] = at_walls;
    g["work_by_walls"] = by_walls;
    g["wall_collisions"] = dem_->wall_collisions();
    g["energy_start"] = energy_start_;
    g["energy_end"] = energy;
    g["energy_balance_relative"] = scale > 0.0 ? std::abs(energy - energy_start_) / scale : 0.0;
    j["granular"] = g;
    return j;
  }

  Config config_;
  bool restart_;
  std::string restart_name_;  // the restart file continued, for messages
  std::mt19937_64 rng_;
  RunProgress resumed_;
  std::optional<DemIntegrator<D>> dem_;
  std::size_t n_ = 0;
  double volume_ = 1.0, particle_volume_ = 0.0;
  bool granular_ = false;  // damping, walls or gravity: report the energy budget
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
RunOutcome run_dem(const Config& config, const std::optional<fs::path>& restart_file) {
  return DemRunDriver<D>(config, restart_file).run();
}

template RunOutcome run_dem<2>(const Config&, const std::optional<fs::path>&);
template RunOutcome run_dem<3>(const Config&, const std::optional<fs::path>&);

}  // namespace kairos::run_detail
