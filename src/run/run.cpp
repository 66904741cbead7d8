#include "run/run.hpp"

#include <atomic>
#include <chrono>
#include <cmath>
#include <fstream>
#include <limits>
#include <numbers>

#include <fmt/format.h>

#include "analysis/profile.hpp"
#include "analysis/thermodynamics.hpp"
#include "core/error.hpp"
#include "core/periodic.hpp"
#include "core/stop_flag.hpp"
#include "engine/event_engine.hpp"
#include "init/initial_state.hpp"
#include "init/initial_state_file.hpp"
#include "io/atomic_file.hpp"
#include "io/gsd_snapshot.hpp"
#include "io/progress.hpp"
#include "run/environment_setup.hpp"
#include "run/frozen_clock.hpp"
#include "run/run_support.hpp"
#include "run/soft_tables_setup.hpp"
#include "scheduler/binary_heap_queue.hpp"
#include "scheduler/calendar_queue.hpp"
#include "scheduler/tournament_tree_queue.hpp"

namespace kairos {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// The axes with a wall or an open face (not periodic) in the config.
template <int D>
std::array<bool, D> periodic_axes(const Config& config) {
  std::array<bool, D> periodic;
  periodic.fill(true);
  const auto bound = [&](const std::string& face) {
    if (face.size() == 2 && face[0] - 'x' < D) periodic[face[0] - 'x'] = false;
  };
  for (const WallConfig& w : config.boundary.walls) bound(w.face);
  for (const std::string& f : config.boundary.open) bound(f);
  return periodic;
}

// The box of a state to check: finite edges > 0.
template <int D>
void check_box(const InitialState<D>& init, const std::string& source) {
  for (int a = 0; a < D; ++a) {
    if (!std::isfinite(init.box[a]) || !(init.box[a] > 0.0)) {
      throw InputError(
          fmt::format("{}: the box edge {} is {}: check system.particles, "
                      "system.packing_fraction and the species diameters",
                      source, a, init.box[a]));
    }
  }
}

// No pair overlaps by more than round-off. `exact`: float64 positions from a Kairos file, whose
// last event may have left a pair in contact to within round-off (relative 1e-12 of the contact
// distance): a contact, not an overlap. `why`: what the message says of overlaps.
template <int D>
void check_no_overlap(const InitialState<D>& init, const std::array<bool, D>& periodic,
                      const std::string& source, bool exact = false,
                      std::string_view why = "hard particles must not overlap") {
  check_box(init, source);
  std::uint32_t i = 0, j = 0;
  const double worst = max_overlap<D>(init.box, periodic, init.position, init.diameter, &i, &j,
                                      /*interruptible=*/true);
  double smallest = std::numeric_limits<double>::infinity();
  for (const double d : init.diameter) smallest = std::min(smallest, d);
  const double round_off = exact ? 1e-12 * smallest : 0.0;
  if (worst > round_off) {
    throw InputError(
        fmt::format("{}: particles {} and {} overlap by {:.6g} ({})", source, i, j, worst, why));
  }
}

// Soft spheres under the DEM may start overlapping (the force law pushes the pairs apart), by
// at most half the smaller radius of each pair: a deeper overlap is no contact the force laws
// are meant for (the spheres would be more inside each other than touching).
template <int D>
void check_soft_overlaps(const InitialState<D>& init, const std::array<bool, D>& periodic,
                         const std::string& source) {
  check_box(init, source);
  std::uint32_t i = 0, j = 0;
  const double worst = max_relative_overlap<D>(init.box, periodic, init.position, init.diameter, &i,
                                               &j, /*interruptible=*/true);
  if (worst > 0.5) {
    const double smaller = 0.5 * std::min(init.diameter[i], init.diameter[j]);
    throw InputError(fmt::format(
        "{}: particles {} and {} overlap by {:.6g}, more than half the smaller radius ({:.6g}): "
        "soft spheres may start overlapping by at most that; separate them further",
        source, i, j, worst * smaller, 0.5 * smaller));
  }
}

// A HOOMD file stores float32 positions. A frame written at a collision (Kairos writes its
// trajectory frames right after one) holds a pair in exact contact, which the rounding to float32
// turns into an overlap of ~1e-7 about half of the time. Overlaps within that round-off are
// removed by expanding the box and all positions uniformly by the smallest factor that clears
// them: every distance grows by that factor, the packing fraction shrinks by ~1e-7 relative, less
// than the file's precision. Larger overlaps are left for check_no_overlap to report.
template <int D>
void expand_away_rounding_overlaps(InitialState<D>& init, const std::array<bool, D>& periodic) {
  double edge = 0.0;
  for (int a = 0; a < D; ++a) edge = std::max(edge, init.box[a]);
  double smallest = std::numeric_limits<double>::infinity();
  for (const double d : init.diameter) smallest = std::min(smallest, d);
  const double tolerance =
      std::min(8.0 * std::numeric_limits<float>::epsilon() * edge, 1e-3 * smallest);
  for (int attempt = 0; attempt < 8; ++attempt) {
    const double worst = max_overlap<D>(init.box, periodic, init.position, init.diameter, nullptr,
                                        nullptr, /*interruptible=*/true);
    if (worst == 0.0 || worst > tolerance) return;
    // Every overlapping pair has r >= sigma - worst with sigma >= smallest.
    const double factor =
        (1.0 + 8.0 * std::numeric_limits<double>::epsilon()) / (1.0 - worst / smallest);
    for (int a = 0; a < D; ++a) init.box[a] *= factor;
    for (auto& x : init.position) {
      for (int a = 0; a < D; ++a) {
        x[a] *= factor;
        if (x[a] >= init.box[a]) x[a] -= init.box[a];
        if (x[a] < 0.0) x[a] = 0.0;
      }
    }
  }
}

// True when the last frame of a GSD file holds Kairos' float64 positions (a restart file).
bool holds_exact_positions(const fs::path& path) {
  const gsd::Reader r(path);
  return r.frame_count() > 0 && r.find(r.frame_count() - 1, "kairos/position").has_value();
}

// When the state comes from a file, the generating keys do not apply; say so if they disagree.
void note_ignored_system_keys(const Config& config, std::size_t n, const std::string& source) {
  if (config.system.particles != 0 && config.system.particles != n) {
    fmt::print(stderr,
               "kairos: note: {} holds {} particles; system.particles = {} and the other "
               "generating keys (packing_fraction, lattice, species) are not used\n",
               source, n, config.system.particles);
  }
}

// A generated state fills a periodic box. Along an axis with walls (or open faces) the box
// grows by the largest diameter, half on each side, so that no particle touches a wall; then
// system.box_scale stretches the box, leaving empty space at the high end of each axis.
template <int D>
void make_room_for_walls(const Config& config, InitialState<D>& init) {
  double dmax = 0.0;
  for (const double d : init.diameter) dmax = std::max(dmax, d);
  const std::array<bool, D> periodic = periodic_axes<D>(config);
  for (int a = 0; a < D; ++a) {
    if (periodic[a]) continue;
    init.box[a] += dmax;
    for (auto& x : init.position) x[a] += 0.5 * dmax;
  }
  for (int a = 0; a < D && a < static_cast<int>(config.system.box_scale.size()); ++a)
    init.box[a] *= config.system.box_scale[a];
}

// Velocities drawn from the temperature are peculiar: under Lees-Edwards shear the mean flow
// u_x = shear_rate (y - L_y / 2) is added, so the run starts in the shear flow.
template <int D>
void add_shear_flow(const Config& config, InitialState<D>& init) {
  const double rate = config.boundary.shear_rate;
  if (rate == 0.0) return;
  for (std::size_t i = 0; i < init.position.size(); ++i)
    init.velocity[i][0] += rate * (init.position[i][1] - 0.5 * init.box[1]);
}

}  // namespace

namespace run_detail {

bool stop_requested() noexcept {
  return kairos::stop_requested();
}

template <int D>
ParticleSystem<D> build_start_state(const Config& config,
                                    const std::optional<fs::path>& restart_file,
                                    std::mt19937_64& rng, RunProgress& progress) {
  // The memory estimate checked before the state is built or read: the DEM's layout is larger.
  const RunKind kind = config.run.integrator == "dem" ? RunKind::kDem : RunKind::kEventDriven;
  if (restart_file) {
    if (!fs::exists(*restart_file)) {
      throw InputError("restart file '" + restart_file->string() + "' does not exist");
    }
    return read_restart_file<D>(*restart_file, rng, progress, kind);  // plan_continuation: the rest
  }
  if (!config.system.initial_state.empty()) {
    const fs::path path = config.system.initial_state;
    if (!fs::exists(path)) {
      throw InputError("system.initial_state: file '" + path.string() + "' does not exist");
    }
    bool has_velocities = false;
    InitialState<D> init = read_initial_state<D>(path, has_velocities, kind);
    const std::array<bool, D> periodic = periodic_axes<D>(config);
    const bool exact = holds_exact_positions(path);
    if (!exact) expand_away_rounding_overlaps<D>(init, periodic);
    const std::string source = "system.initial_state '" + path.string() + "'";
    if (config.soft.enabled() && config.run.integrator == "dem") {
      check_soft_overlaps<D>(init, periodic, source);
    } else if (config.soft.enabled()) {
      // The event integrator maps a soft contact from its first touch (Müller and Pöschel, Phys.
      // Rev. E 87, 033301 (2013)): a pair that starts inside one has no first touch, and would
      // collide instantaneously (its overlap's elastic energy lost), not as the force law says.
      check_no_overlap<D>(init, periodic, source, exact,
                          "the event integrator maps soft contacts from their first touch and "
                          "cannot start inside one: use run.integrator = \"dem\", which accepts "
                          "overlaps of up to half the smaller radius, or a state without overlaps");
    } else {
      check_no_overlap<D>(init, periodic, source, exact);
    }
    note_ignored_system_keys(config, init.position.size(), "system.initial_state");
    if (!has_velocities) {
      assign_maxwell_boltzmann_velocities(init, config.system.temperature, rng);
      add_shear_flow(config, init);
    }
    return to_particle_system<D>(std::move(init));
  }
  InitialState<D> init = make_initial_state<D>(config.system, rng, kind);
  std::array<bool, D> periodic;
  periodic.fill(true);  // generated in a periodic box; make_room_for_walls then adds the gaps
  // A lattice at its close packing has its neighbours in contact to within round-off.
  check_no_overlap<D>(init, periodic, "generated initial state", /*exact=*/true);
  make_room_for_walls(config, init);
  add_shear_flow(config, init);
  return to_particle_system<D>(std::move(init));
}

template ParticleSystem<2> build_start_state<2>(const Config&, const std::optional<fs::path>&,
                                                std::mt19937_64&, RunProgress&);
template ParticleSystem<3> build_start_state<3>(const Config&, const std::optional<fs::path>&,
                                                std::mt19937_64&, RunProgress&);

}  // namespace run_detail

namespace {

using run_detail::build_start_state;

using run_detail::OutputSchedule;
using run_detail::peak_rss_bytes;
using run_detail::PhaseLength;
using run_detail::ThermoWriter;
using run_detail::TimeSchedule;

template <int D, class Queue>
class RunDriver {
 public:
  RunDriver(const Config& config, const std::optional<fs::path>& restart_file,
            const RunOptions& run_options)
      : config_(config),
        restart_(restart_file.has_value()),
        restart_name_(restart_file ? restart_file->string() : ""),
        rng_(config.system.seed),
        restart_file_(restart_file) {
    ParticleSystem<D> start = build_start_state<D>(config, restart_file, rng_, resumed_);
    run_detail::check_restart_integrator(restart_file, resumed_, "event");
    if (restart_file) {
      plan_ = run_detail::plan_continuation<D>(config, start, resumed_, restart_name_);
      config_ = plan_->used;
    }
    const bool resume = restart_ && !plan_->repredict;
    n_ = start.size();
    volume_ = 1.0;
    for (int a = 0; a < D; ++a) volume_ *= start.box[a];
    particle_volume_ = 0.0;
    for (const auto& k : start.kinematics) {
      particle_volume_ += D == 3 ? 4.0 / 3.0 * std::numbers::pi * k.radius * k.radius * k.radius
                                 : std::numbers::pi * k.radius * k.radius;
    }
    thermo_stats_.emplace(D, n_, volume_);
    try {
      Environment<D> environment = make_environment<D>(config_, start);
      if (environment.soft_spheres() && config_.soft.tables) attach_tables(environment, start);
      EngineOptions options;
      options.defer_soft_releases = config_.soft.defer_releases;
      engine_.emplace(std::move(start), resume ? StartMode::kResume : StartMode::kPredict, options,
                      environment);
      if (restart_ && !resume) run_detail::check_no_overlap_after_new_physics(*engine_);
      driven_ = config_.driving.kind != "none";
      timed_ = config_.run.time > 0.0 || config_.run.equilibration_time >= 0.0 ||
               run_detail::intervals_in_time(config_);
      granular_ = !environment.plain() || environment.has_gravity() || driven_ ||
                  environment.sheared() || environment.soft_spheres() ||
                  environment.dissipative_steps();
      sheared_ = environment.sheared();
      for (int a = 0; a < D; ++a) granular_ = granular_ || !environment.periodic(a);
      bulk_ = !environment.has_gravity();
      for (int a = 0; a < D; ++a) bulk_ = bulk_ && environment.periodic(a);
      rotating_ = environment.rotates() || engine_->rotational_energy() > 0.0;
      dissipative_ = environment.tc > 0.0 || environment.dissipative_steps() ||
                     environment.soft_spheres() || !environment.plain();
      for (int f = 0; f < 2 * D; ++f)
        moving_walls_ =
            moving_walls_ ||
            (environment.faces[f].kind == FaceKind::kWall &&
             (environment.wall_moves(f) || norm2(environment.faces[f].wall.velocity) > 0.0));
    } catch (const InputError& e) {
      if (!restart_file) throw;
      throw run_detail::restart_setup_error(e, *restart_file, *plan_);
    }
    if (!config_.output.profile_axis.empty()) {
      const int axis = config_.output.profile_axis[0] - 'x';
      const Vec<D>& box = engine_->box();
      double cross = 1.0;
      for (int a = 0; a < D; ++a)
        if (a != axis) cross *= box[a];
      profile_.emplace(axis, static_cast<int>(config_.output.profile_bins), 0.0, box[axis], cross);
    }
    check_collisions_can_happen(
        {restart_ ? run_detail::resumed_equilibration(config_.run, resumed_, restart_name_)
                  : run_detail::equilibration_length(config_.run),
         run_detail::production_length(config_.run)});
    if (plan_) run_detail::print_restart_note(*plan_, restart_name_);
    // The end of the setup, before anything is written: a signal or run.max_wall_seconds that
    // came during a part that does not poll (the engine's first predictions) ends it here, as
    // an interrupted setup (nothing written; the limit an error), not as a run.
    throw_if_stop_requested();
    run_id_ = run_detail::lineage_run_id(restart_file, resumed_);
    out_dir_.emplace(
        run_detail::prepare_output_directory(config_, restart_file, resumed_.run_id, run_options));
    dir_ = out_dir_->path();
  }

  RunOutcome run() {
    const auto wall_start = Clock::now();
    continuation_ = run_detail::output_continuation(out_dir_->continues_outputs(), resumed_);
    thermo_.emplace(dir_ / "thermo.tsv", restart_, continuation_.thermo_rows);
    rows_kept_ = thermo_->rows();
    if (config_.output.trajectory) {
      const bool created = run_detail::open_trajectory<D>(
          trajectory_, dir_, restart_, n_, continuation_.trajectory_frames,
          [&] { return engine_->state_blocks(/*with_zones=*/false); });
      frames_kept_ = trajectory_->frame_count();
      // The state of the last frame kept: this one's, or, continuing the lineage's file, the
      // one the restart file recorded (a continued run with nothing left to do writes no
      // second frame of it).
      if (created && restart_) {
        frame_collisions_ = engine_->counters().collisions;
        frame_time_ = engine_->time();
      } else if (!created && continuation_.same_directory && resumed_.has_frame_mark) {
        frame_collisions_ = resumed_.frame_collisions;
        frame_time_ = resumed_.frame_time;
      }
      kept_frame_collisions_ = frame_collisions_;
      kept_frame_time_ = frame_time_;
    } else {
      frames_not_written_ =
          run_detail::cut_back_trajectory<D>(dir_, n_, continuation_.trajectory_frames);
    }
    ke_start_ = engine_->kinetic_energy();
    u_start_ = engine_->potential_energy();
    energy_start_ = total_energy();
    if (driven_) {
      next_kick_ = restart_ && resumed_.next_kick_time >= engine_->time()
                       ? resumed_.next_kick_time
                       : engine_->time() + draw_kick_interval();
    }
    counters_start_ = engine_->counters();
    p_start_ = engine_->momentum();
    events_start_ = engine_->counters().events;
    collisions_start_ = engine_->counters().collisions;
    // Continued in its own directory: the next row covers the interval from the last kept one.
    kept_mark_ = continuation_.same_directory && resumed_.has_thermo_mark
                     ? ThermoPoint{resumed_.mark_time, resumed_.mark_virial, resumed_.mark_events,
                                   resumed_.mark_collisions}
                     : point();
    thermo_stats_->mark(kept_mark_);
    clock_watch_.emplace(*engine_);
    ProgressLine progress(config_.output.progress);

    // A restart continues an interrupted equilibration, otherwise goes straight to production.
    const PhaseLength eq =
        restart_ ? run_detail::resumed_equilibration(config_.run, resumed_, restart_name_)
                 : run_detail::equilibration_length(config_.run);
    bool stopped = false;
    if (eq.value > 0.0) {
      stopped = run_phase("equilibration", eq, progress, wall_start);
      // Close the equilibration rows so no production row spans both phases (a stopped run's
      // last row is not kept: a continued run writes the rows an uninterrupted one would).
      if (row_pending())
        outputs_.attempt("thermo.tsv", [&] { write_thermo_row("equilibration", !stopped); });
    }
    prod_start_ = point();
    virial_tensor_start_ = engine_->counters().virial_tensor;
    prod_ke_ = thermal_energy();
    shear_row_start_ = {engine_->time(), engine_->counters().virial_tensor[1]};
    if (!stopped) {
      const PhaseLength production =
          restart_ ? run_detail::continued_production(config_.run, resumed_, plan_, engine_->time(),
                                                      engine_->counters().collisions)
                   : run_detail::production_length(config_.run);
      stopped = run_phase("production", production, progress, wall_start);
      production_done_ = !stopped;
    }
    progress.finish();
    if (!stopped && clock_watch_->never_moved(*engine_)) {
      stopped = true;
      stop_reason_ = "frozen_clock";
      error_ = clock_watch_->describe(*engine_);
    }
    finish_outputs(stopped);
    const double wall = std::chrono::duration<double>(Clock::now() - wall_start).count();
    const std::string run_error = error_;  // why the run could not go on, before any write
    const auto with_outputs = [&] {
      return run_error.empty() ? outputs_.error : run_error + "; " + outputs_.error;
    };
    if (outputs_.any()) {
      error_ = with_outputs();
      if (stop_reason_ == "completed" || stop_reason_ == "signal") stop_reason_ = "write_failed";
    }
    RunOutcome outcome;
    outcome.directory = dir_;
    outcome.interrupted = stopped && error_.empty();
    outcome.error = error_;
    outcome.summary = summary(wall);
    outcome.summary["outputs"] = run_detail::outputs_present(dir_);
    outputs_.attempt("summary.json", [&] {
      write_text_atomically(dir_ / "summary.json", outcome.summary.dump(2) + "\n");
    });
    // outputs_.error now ends with the summary's failure (error_ holds the earlier ones).
    if (outputs_.failed_file("summary.json")) outcome.error = with_outputs();
    return outcome;
  }

 private:
  // The last row and frame (kept unless the run stopped early: a continued run writes the
  // ones an uninterrupted run would), the restart file, the profile. Each write is tried even
  // if another failed; failures go into outputs_.
  void finish_outputs(bool stopped) {
    const bool kept = !stopped;
    if (row_pending()) outputs_.attempt("thermo.tsv", [&] { write_thermo_row(phase_, kept); });
    if (trajectory_) {
      outputs_.attempt("trajectory.gsd", [&] {
        if (frame_collisions_ != engine_->counters().collisions ||
            (timed_ && frame_time_ != engine_->time()))
          write_trajectory_frame(kept);
        trajectory_->close();
      });
    }
    outputs_.attempt("restart.gsd", [&] { write_restart_file(); });
    if (profile_) outputs_.attempt("profile.tsv", [&] { profile_->write(dir_ / "profile.tsv"); });
  }

  void write_restart_file() const {
    kairos::write_restart_file(dir_ / "restart.gsd", engine_->state_blocks(), rng_, progress_now());
  }

  // Equilibration still owed if the run stops now (a restart file records it).
  RunProgress progress_now() const {
    RunProgress p;
    p.thermo_rows = static_cast<std::int64_t>(rows_kept_);
    p.trajectory_frames =
        trajectory_ ? static_cast<std::int64_t>(frames_kept_) : frames_not_written_;
    if (trajectory_) {
      p.has_frame_mark = true;
      p.frame_time = kept_frame_time_;
      p.frame_collisions = kept_frame_collisions_;
    }
    p.owed_outputs = owed_;
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
      if (std::isfinite(production_end_time_))
        p.production_end_time = production_end_time_;
      else
        p.production_target = production_target_;
    }
    const std::uint64_t c = engine_->counters().collisions;
    // In the unit of the config's equilibration length.
    if (phase_ == "equilibration" && config_.run.equilibration_time >= 0.0) {
      if (engine_->time() < equilibration_end_time_) {
        p.equilibration_remaining = equilibration_end_time_ - engine_->time();
        p.equilibration_end_time = equilibration_end_time_;
      }
    } else if (phase_ == "equilibration" && c < equilibration_target_) {
      p.equilibration_remaining = per_particle(equilibration_target_ - c);
    }
    p.next_kick_time = driven_ ? next_kick_ : -1.0;
    if (!tables_.empty()) p.soft_table_max_speed = tables_.front().spec.max_normal_speed;
    p.config = to_toml(config_);
    p.run_id = run_id_;
    return p;
  }

  // Phases measured in collisions need a system that collides: InputError if the ideal-gas
  // estimate says they would take practically for ever (without a field: with gravity grains
  // gather far denser than the mean).
  void check_collisions_can_happen(std::initializer_list<PhaseLength> phases) const {
    if (engine_->environment().has_gravity()) return;
    double collisions = 0.0;
    for (const PhaseLength& p : phases)
      if (!p.in_time && p.value > 0.0) collisions += static_cast<double>(collisions_for(p.value));
    if (collisions == 0.0) return;
    double mass = 0.0;
    engine_->for_each_block(
        [&](std::size_t, auto, auto, auto m) {
          for (const double mj : m) mass += mj;
        },
        /*with_positions=*/false);
    const auto n = static_cast<double>(n_);
    const run_detail::FlightEstimate flight = run_detail::estimate_flight<D>(
        n, volume_, run_detail::mean_volume_diameter<D>(particle_volume_, n),
        std::sqrt(2.0 * engine_->kinetic_energy() / mass));
    double width = 0.0;
    for (int a = 0; a < D; ++a) width += engine_->grid().width(a) / D;
    run_detail::check_collisions_can_happen(
        1.0 + 2.0 * std::sqrt(static_cast<double>(D)) * flight.mean_free_path / width, collisions,
        flight, "events");
  }

  // Stochastic driving ([driving]): Poisson events at rate N * rate, each on one random
  // particle, applied between the engine's events. The RNG and the next event's time are in
  // the restart file, so a continued run draws the same kicks.
  double draw_kick_interval() {
    std::exponential_distribution<double> wait(config_.driving.rate * static_cast<double>(n_));
    return wait(rng_);
  }
  // The kicks due up to the next event, and not after `limit`.
  void apply_due_kicks(double limit = std::numeric_limits<double>::infinity()) {
    while (next_kick_ <= std::min(engine_->next_event_time(), limit)) {
      std::uniform_int_distribution<std::uint32_t> pick(0, static_cast<std::uint32_t>(n_ - 1));
      const std::uint32_t k = pick(rng_);
      const DrivingConfig& d = config_.driving;
      Vec<D> v{};
      if (d.kind == "andersen") {
        std::normal_distribution<double> maxwell(
            0.0, std::sqrt(d.temperature / engine_->particle_mass(k)));
        for (int a = 0; a < D; ++a) v[a] = maxwell(rng_);
        if (sheared_) {
          v = v + engine_->environment().streaming_velocity(engine_->position(k, next_kick_),
                                                            engine_->box());
        }
      } else {
        std::normal_distribution<double> kick(0.0, std::sqrt(d.strength / d.rate));
        v = engine_->velocity(k, next_kick_);
        for (int a = 0; a < D; ++a) v[a] += kick(rng_);
      }
      engine_->set_velocity(k, next_kick_, v);
      next_kick_ += draw_kick_interval();
    }
  }

  ThermoPoint point() const {
    const auto& c = engine_->counters();
    return {engine_->time(), c.virial, c.events, c.collisions};
  }
  std::uint64_t collisions_for(double per_particle) const {
    return static_cast<std::uint64_t>(std::llround(per_particle * static_cast<double>(n_) / 2.0));
  }
  double per_particle(std::uint64_t collisions) const {
    return thermo_stats_->per_particle(collisions);
  }

  // A thermo row not yet written for the present: new collisions, or (with lengths or
  // intervals in time) time gone by.
  bool row_pending() const {
    return engine_->counters().collisions > thermo_stats_->last().collisions ||
           (timed_ && engine_->time() > thermo_stats_->last().time);
  }

  // kept: the frame belongs to the run as an uninterrupted one writes it (not the last frame
  // of a run stopped early).
  void write_trajectory_frame(bool kept = true) {
    append_trajectory_frame(*trajectory_, engine_->state_blocks(/*with_zones=*/false));
    frame_collisions_ = engine_->counters().collisions;
    frame_time_ = engine_->time();
    if (kept) {
      frames_kept_ = trajectory_->frame_count();
      kept_frame_collisions_ = frame_collisions_;
      kept_frame_time_ = frame_time_;
    }
  }

  // The periodic outputs due now, in order; false when one could not be written (the run then
  // stops). The row and frame due and not written are owed (RunProgress::owed_outputs): a run
  // continued in this directory writes them first, as one uninterrupted run has them.
  bool write_due_outputs(const std::string& phase, bool row, bool frame, bool restart) {
    owed_ = (row ? RunProgress::kOwedRow : 0) | (frame ? RunProgress::kOwedFrame : 0);
    if (row && !outputs_.attempt("thermo.tsv", [&] { write_thermo_row(phase); })) return false;
    owed_ &= ~RunProgress::kOwedRow;
    if (frame && !outputs_.attempt("trajectory.gsd", [&] { write_trajectory_frame(); }))
      return false;
    owed_ = 0;
    return !restart || outputs_.attempt("restart.gsd", [&] { write_restart_file(); });
  }

  // A periodic output could not be written: the run stops (outputs_ holds the error).
  bool write_failed() {
    stop_reason_ = "write_failed";
    return true;
  }

  // A stop asked by a signal or by run.max_wall_seconds, counted from the start of the set-up
  // (one limit for set-up and run; stop_reason_ set).
  bool interrupted(Clock::time_point) {
    if (kairos::stop_requested()) {
      stop_reason_ = "signal";
      return true;
    }
    if (config_.run.max_wall_seconds > 0 &&
        std::chrono::duration<double>(Clock::now() - created_).count() >
            config_.run.max_wall_seconds) {
      stop_reason_ = "wall_time_limit";
      return true;
    }
    return false;
  }

  // Runs until `length` more collisions per particle or simulated time; returns true if stopped
  // early. Outputs come every so many collisions per particle, or (interval_unit = "time") at
  // the multiples of their intervals in time, for which the engine's clock is stopped there
  // between two events.
  bool run_phase(const std::string& phase, PhaseLength length, ProgressLine& progress,
                 Clock::time_point wall_start) {
    phase_ = phase;
    const std::uint64_t begin = engine_->counters().collisions;
    const double begin_time = engine_->time();
    const std::uint64_t target = length.in_time      ? begin
                                 : length.target > 0 ? length.target
                                                     : begin + collisions_for(length.value);
    if (length.target > 0) length.value = per_particle(target - begin);
    const double end_time = !length.in_time             ? kNever
                            : std::isfinite(length.end) ? length.end
                                                        : begin_time + length.value;
    if (phase == "equilibration") {
      equilibration_target_ = target;
      equilibration_end_time_ = end_time;
    } else {
      production_target_ = target;
      production_end_time_ = length.in_time ? end_time : kNever;
    }
    const bool time_outputs = run_detail::intervals_in_time(config_);
    auto [fresh, timed] = run_detail::phase_schedules(config_, begin, begin_time,
                                                      [&](double c) { return collisions_for(c); });
    schedule_ = fresh;
    schedule_phase_ = phase == "production" ? 1 : 0;
    OutputSchedule& schedule = schedule_;
    // The first phase of a continued run keeps the stored schedule of the same phase (the rows
    // an uninterrupted run would write), if its steps are unchanged.
    if (restart_ && first_phase_ && resumed_.schedule_phase == (phase == "production" ? 1 : 0)) {
      OutputSchedule::Every* e[3] = {&schedule.thermo, &schedule.trajectory, &schedule.restart};
      for (int k = 0; k < 3; ++k)
        if (e[k]->step > 0 && e[k]->step == resumed_.schedule_step[k] &&
            resumed_.schedule_next[k] > begin)
          e[k]->next = resumed_.schedule_next[k];
    }
    // Continued in its own directory from a state whose row or frame could not be written: they
    // come first.
    if (restart_ && first_phase_ && continuation_.same_directory && resumed_.owed_outputs != 0) {
      const bool row = (resumed_.owed_outputs & RunProgress::kOwedRow) != 0;
      const bool frame = (resumed_.owed_outputs & RunProgress::kOwedFrame) != 0 && trajectory_;
      if (!write_due_outputs(phase, row, frame, false)) return write_failed();
    }
    first_phase_ = false;
    const auto done = [&] {
      return length.in_time ? engine_->time() - begin_time
                            : per_particle(engine_->counters().collisions - begin);
    };
    progress.update(
        {phase, 0.0, length.value, engine_->time(), engine_->counters().events, length.in_time});
    while (length.in_time ? engine_->time() < end_time : engine_->counters().collisions < target) {
      if (length.in_time || time_outputs) {
        // Outputs due, and the phase's end, before the next event: the clock stops there.
        double stop = std::min(timed.next(), end_time);
        // An output within round-off of the phase's end comes at the end (one row, not two).
        if (length.in_time && stop >= end_time - TimeSchedule::Every::slack(end_time))
          stop = end_time;
        if (driven_) apply_due_kicks(stop);
        if (!length.in_time && !driven_ && !(engine_->next_event_time() < kNever)) {
          stop_reason_ = "no_more_events";  // the collision target would never come
          break;
        }
        if (engine_->next_event_time() > stop) {
          engine_->advance_clock(stop);
          const double t = engine_->time();
          const bool row = timed.thermo.due(t), frame = timed.trajectory.due(t) && trajectory_;
          if (!write_due_outputs(phase, row, frame, timed.restart.due(t))) return write_failed();
          // A system at rest passes its output times without events: the stop checks too.
          if (interrupted(wall_start)) return true;
          if ((++clock_stops_ & 0x3ffu) == 0) {
            progress.update({phase, done(), length.value, engine_->time(),
                             engine_->counters().events, length.in_time});
          }
          continue;
        }
      } else if (driven_) {
        apply_due_kicks();
      }
      EventKind kind{};
      try {
        kind = engine_->step();
      } catch (const InputError& e) {
        // The event cannot happen (walls leave the particles no room): the state is that of
        // the moment before it, every output is written, the message is the run's error.
        error_ = e.what();
        stop_reason_ = "error";
        return true;
      }
      if (kind == EventKind::kNone) {
        stop_reason_ = "no_more_events";  // every particle at rest, or alone
        break;
      }
      if (config_.run.validate) engine_->validate();
      if (clock_watch_->frozen(*engine_)) {
        error_ = clock_watch_->describe(*engine_);
        stop_reason_ = "frozen_clock";
        return true;
      }
      const std::uint64_t c = engine_->counters().collisions;
      const bool row = schedule.thermo.due(c), frame = schedule.trajectory.due(c) && trajectory_;
      if (!write_due_outputs(phase, row, frame, schedule.restart.due(c))) return write_failed();
      if (kairos::stop_requested()) {
        stop_reason_ = "signal";
        return true;
      }
      if ((engine_->counters().events & 0x3fffu) == 0) {
        progress.update({phase, done(), length.value, engine_->time(), engine_->counters().events,
                         length.in_time});
        if (interrupted(wall_start)) return true;
      }
    }
    if (length.in_time) stop_reason_ = "completed";  // ran to its end, whatever came before
    progress.update({phase, length.value, length.value, engine_->time(), engine_->counters().events,
                     length.in_time},
                    true);
    return false;
  }

  void sample_profile(const ParticleSystem<D>& s) {
    std::vector<Vec<D>> x(n_), v(n_);
    std::vector<double> volume(n_);
    for (std::size_t i = 0; i < n_; ++i) {
      x[i] = s.position_at(i, s.time);
      for (int a = 0; a < D; ++a)
        if (s.periodic[a]) x[i][a] = wrap_into_box(x[i][a], s.box[a]);
      v[i] = s.velocity_at(i, s.time);
      const double r = s.kinematics[i].radius;
      volume[i] = D == 3 ? 4.0 / 3.0 * std::numbers::pi * r * r * r : std::numbers::pi * r * r;
    }
    profile_->sample(x, v, s.mass, volume);
  }

  // Kinetic part of the pressure tensor, sum of m c_a c_b with c the velocity relative to the
  // mean (under shear: to the mean flow at the particle), sampled at production thermo rows.
  // Under shear each row also gives one sample of the shear stress P_xy: this kinetic part
  // plus the collisional one since the previous row.
  void sample_kinetic_tensor() {
    std::array<double, 9> sample{};
    for_each_peculiar_velocity([&](const Vec<D>& c, double m) {
      for (int a = 0; a < D; ++a)
        for (int b = 0; b < D; ++b) sample[a * D + b] += m * c[a] * c[b];
    });
    for (int k = 0; k < D * D; ++k) kinetic_tensor_sum_[k] += sample[k];
    ++kinetic_tensor_samples_;
    const double time = engine_->time();
    if (sheared_ && time > shear_row_start_.time) {
      const double virial_xy = engine_->counters().virial_tensor[1];  // row x, column y
      shear_stress_rows_.push_back(
          (sample[1] + (virial_xy - shear_row_start_.virial_xy) / (time - shear_row_start_.time)) /
          volume_);
      shear_row_start_ = {time, virial_xy};
    }
  }

  // f(c, m) for each particle in the caller's order: its velocity now relative to the mean (the
  // centre-of-mass velocity, or under shear the flow at its position) and its mass. From the
  // engine's records, without a copy of the whole state (a thermo row of a large, short run
  // spent 11 % of its time in export_state()).
  template <class F>
  void for_each_peculiar_velocity(F&& f) const {
    if (sheared_) {
      const std::vector<Vec<D>> v = engine_->current_velocities();
      const ParticleSystem<D> s = engine_->export_state(/*with_zones=*/false);
      for (std::size_t i = 0; i < n_; ++i)
        f(v[i] - engine_->environment().streaming_velocity(s.position_at(i, s.time), s.box),
          s.mass[i]);
      return;
    }
    // Whole copies of the velocities and masses (32 bytes per particle for the moment of a
    // thermo row, below the set-up's peak): read in the engine's memory order, twice as fast at
    // N = 10^6 as two passes over the blocks.
    const std::vector<Vec<D>> v = engine_->current_velocities();
    const std::vector<double> m = engine_->masses();
    Vec<D> mean{};
    double mass = 0.0;
    for (std::size_t i = 0; i < n_; ++i) {
      mean = mean + m[i] * v[i];
      mass += m[i];
    }
    mean = (1.0 / mass) * mean;
    for (std::size_t i = 0; i < n_; ++i) f(v[i] - mean, m[i]);
  }

  // The kinetic energy that makes the temperature: of the peculiar velocities under shear.
  double thermal_energy() const {
    return sheared_ ? engine_->peculiar_kinetic_energy() : engine_->kinetic_energy();
  }

  // kept: as write_trajectory_frame.
  void write_thermo_row(const std::string& phase, bool kept = true) {
    if (phase == "production") {
      if (profile_) sample_profile(engine_->export_state(/*with_zones=*/false));
      sample_kinetic_tensor();
    }
    const auto& c = engine_->counters();
    const double u = engine_->potential_energy();
    if (phase == "production" && engine_->stepped()) potential_rows_.push_back(u);
    const ThermoRow row = thermo_stats_->row(point(), thermal_energy(), phase == "production");
    if (phase == "production") production_temperatures_.push_back(row.temperature);
    thermo_->write(phase, row,
                   {rotational_temperature(), c.dissipated_in_collisions + c.dissipated_at_walls,
                    c.work_by_walls, u});
    if (kept) {
      rows_kept_ = thermo_->rows();
      kept_mark_ = row.at;
    }
  }

  // Per rotational degree of freedom (3 for spheres, 1 for disks); 0 without spins.
  double rotational_temperature() const {
    return 2.0 * engine_->rotational_energy() / ((D == 3 ? 3.0 : 1.0) * static_cast<double>(n_));
  }

  // Kinetic (translational and rotational) plus the stepped potentials' energy plus potential
  // energy in the gravity field, when the field has no component along a periodic axis (else
  // the potential is unbounded: NaN).
  double total_energy() const {
    const Environment<D>& env = engine_->environment();
    double e =
        engine_->kinetic_energy() + engine_->rotational_energy() + engine_->potential_energy();
    if (!env.has_gravity()) return e;
    for (int a = 0; a < D; ++a)
      if (env.periodic(a) && env.gravity[a] != 0.0) return std::nan("");
    engine_->for_each_block([&](std::size_t, auto x, auto, auto m) {
      for (std::size_t j = 0; j < x.size(); ++j) e -= m[j] * dot(env.gravity, x[j]);
    });
    return e;
  }

  // Sonine coefficient of the velocity distribution, a2 = d/(d+2) <v^4>/<v^2>^2 - 1, with
  // velocities taken relative to the mean.
  double sonine_a2_now() const {
    double m2 = 0.0, m4 = 0.0;
    for_each_peculiar_velocity([&](const Vec<D>& u, double) {
      const double c2 = norm2(u);
      m2 += c2;
      m4 += c2 * c2;
    });
    m2 /= static_cast<double>(n_);
    m4 /= static_cast<double>(n_);
    return m2 > 0.0 ? D / (D + 2.0) * m4 / (m2 * m2) - 1.0 : std::nan("");
  }

  nlohmann::json summary(double wall) const {
    const auto& c = engine_->counters();
    const double ke = thermal_energy();
    const Thermodynamics& th = *thermo_stats_;
    const double kT = th.temperature(ke);
    const Vec<D> p = engine_->momentum();
    // From the engine's state in blocks: no copy of the whole state beside it.
    const StateBlocks<D> state = engine_->state_blocks(/*with_zones=*/false);
    double pscale = 0.0, dp2 = 0.0;
    std::vector<double> diameters(n_);
    state.for_each(
        [&](const ParticleSystem<D>& part, std::size_t first) {
          for (std::size_t j = 0; j < part.size(); ++j) {
            pscale += part.mass[j] * std::sqrt(norm2(part.kinematics[j].vel));
            diameters[first + j] = 2.0 * part.kinematics[j].radius;
          }
        },
        StateBlocks<D>::kKinematics | StateBlocks<D>::kIdentity);
    for (int a = 0; a < D; ++a) dp2 += (p[a] - p_start_[a]) * (p[a] - p_start_[a]);
    const double t_prod = engine_->time() - prod_start_.time;
    const std::uint64_t coll_prod = c.collisions - prod_start_.collisions;
    // The production temperature: constant kinetic energy for elastic hard spheres; with steps
    // (kinetic energy turns into potential) or a thermostat, the mean over the production rows.
    double kT_prod = th.temperature(prod_ke_);
    if ((engine_->stepped() || driven_) && !production_temperatures_.empty()) {
      kT_prod = block_average(production_temperatures_).mean;
    }
    const double z_mean = th.compressibility(c.virial - prod_start_.virial, kT_prod, t_prod);
    const double overlap = run_detail::current_max_overlap(*engine_, state.globals(), diameters);
    const std::uint64_t events = c.events - events_start_;
    const std::uint64_t collisions = c.collisions - collisions_start_;
    nlohmann::json j;
    j["kairos_version"] = KAIROS_VERSION;
    j["dimension"] = D;
    j["particles"] = n_;
    j["packing_fraction"] = particle_volume_ / volume_;
    j["number_density"] = static_cast<double>(n_) / volume_;
    j["integrator"] = "event";
    j["event_queue"] = engine_->queue_name();
    j["run_id"] = run_id_;
    j["restarted"] = restart_;
    if (plan_) j["restart"] = run_detail::restart_summary(*plan_);
    j["stop_reason"] = stop_reason_;
    if (!error_.empty()) j["error"] = error_;
    j["event_counts"] = {
        {"collisions", collisions},
        {"cell_crossings", c.cell_crossings},
        {"incremental_crossings_this_invocation", engine_->incremental_crossing_scans()},
        {"stale", c.stale_events},
        {"total_events_since_start", c.events},
        {"total_collisions_since_start", c.collisions}};
    run_detail::add_run_totals(j,
                               {events, collisions, coll_prod, engine_->time(), t_prod, wall,
                                per_particle(coll_prod), kT, ke, kT_prod, z_mean},
                               th, bulk_);
    if (kinetic_tensor_samples_ > 0 && t_prod > 0.0) {
      // Kinetic part averaged over the production rows, collisional part from the impulses
      // over the production time.
      nlohmann::json tensor = nlohmann::json::array();
      for (int a = 0; a < D; ++a) {
        nlohmann::json row = nlohmann::json::array();
        for (int b = 0; b < D; ++b) {
          const int k = a * D + b;
          row.push_back((kinetic_tensor_sum_[k] / kinetic_tensor_samples_ +
                         (c.virial_tensor[k] - virial_tensor_start_[k]) / t_prod) /
                        volume_);
        }
        tensor.push_back(row);
      }
      j["pressure_tensor"] = tensor;
    }
    // Kinetic plus stepped-potential energy against the starting kinetic energy.
    j["energy_drift_relative"] =
        ke_start_ > 0 ? std::abs(engine_->kinetic_energy() + engine_->potential_energy() -
                                 (ke_start_ + u_start_)) /
                            ke_start_
                      : 0.0;
    if (engine_->stepped()) j["stepped"] = stepped_summary(c);
    if (engine_->soft()) j["soft"] = soft_summary(c);
    j["momentum_drift"] = pscale > 0 ? std::sqrt(dp2) / pscale : 0.0;
    j["max_overlap"] = overlap;
    j["peak_rss_bytes"] = peak_rss_bytes();
    j["bytes_per_particle"] = engine_->bytes_per_particle();
    if (!granular_) return j;
    // Granular runs: where the energy went in this invocation, and the velocity statistics.
    const double dissipated =
        (c.dissipated_in_collisions - counters_start_.dissipated_in_collisions) +
        (c.dissipated_at_walls - counters_start_.dissipated_at_walls);
    const double work = (c.work_by_walls - counters_start_.work_by_walls) +
                        (c.work_by_driving - counters_start_.work_by_driving) +
                        (c.work_by_shear - counters_start_.work_by_shear);
    const double energy = total_energy();
    const double balance = energy - energy_start_ + dissipated - work;
    const double scale = std::max({std::abs(energy_start_), dissipated, std::abs(work)});
    nlohmann::json g;
    // What this run's granular lines mean (the CLI prints only those): spins, dissipation,
    // moving walls, driving.
    g["rotating"] = rotating_;
    g["dissipative"] = dissipative_;
    g["moving_walls"] = moving_walls_;
    g["driven"] = driven_;
    g["rotational_temperature"] = rotational_temperature();
    const double a2 = sonine_a2_now();
    run_detail::set_or_explain(j, g, "sonine_a2", a2,
                               !bulk_ ? "walls, open faces or a field: the gas is not homogeneous"
                               : !std::isfinite(a2) ? "every particle at rest"
                                                    : "",
                               "granular.sonine_a2");
    g["wall_collisions"] = c.wall_collisions - counters_start_.wall_collisions;
    g["elastic_by_rule"] = c.elastic_by_rule - counters_start_.elastic_by_rule;
    g["sliding_collisions"] = c.sliding_collisions - counters_start_.sliding_collisions;
    g["fell_asleep"] = c.fell_asleep - counters_start_.fell_asleep;
    g["sleeping_now"] = engine_->sleeping();
    g["dissipated_in_collisions"] =
        c.dissipated_in_collisions - counters_start_.dissipated_in_collisions;
    g["dissipated_at_walls"] = c.dissipated_at_walls - counters_start_.dissipated_at_walls;
    g["work_by_walls"] = c.work_by_walls - counters_start_.work_by_walls;
    g["work_by_driving"] = c.work_by_driving - counters_start_.work_by_driving;
    g["driving_kicks"] = c.driving_kicks - counters_start_.driving_kicks;
    g["work_by_shear"] = c.work_by_shear - counters_start_.work_by_shear;
    const std::string unbounded =
        std::isfinite(energy) && std::isfinite(energy_start_)
            ? ""
            : "gravity along a periodic axis: the potential energy is unbounded";
    run_detail::set_or_explain(j, g, "energy_start", energy_start_, unbounded,
                               "granular.energy_start");
    run_detail::set_or_explain(j, g, "energy_end", energy, unbounded, "granular.energy_end");
    run_detail::set_or_explain(j, g, "energy_balance_relative",
                               scale > 0.0 ? std::abs(balance) / scale : 0.0, unbounded,
                               "granular.energy_balance_relative");
    j["granular"] = g;
    if (sheared_) j["shear"] = shear_summary(kT_prod);
    return j;
  }

  // Soft spheres: the lookup tables of the collision map (built now or read from the cache).
  void attach_tables(Environment<D>& environment, const ParticleSystem<D>& start) {
    SoftTableSettings settings;
    settings.tolerance = config_.soft.table_tolerance;
    settings.cache_dir = config_.soft.table_cache;
    if (restart_) settings.max_speed = resumed_.soft_table_max_speed;
    if (config_.driving.kind == "andersen")
      settings.driving_temperature = config_.driving.temperature;
    const bool tell = config_.output.progress != "never";
    std::string building;
    auto progress = [&](const std::string& contact, double) {
      if (tell && contact != building) {
        building = contact;
        fmt::print(stderr, "building the soft-contact map table of {} ...\n", contact);
      }
    };
    tables_ = attach_soft_tables(environment, start, settings, progress);
  }

  // Soft spheres: how the contacts were carried out in this invocation (mapped, or one of the
  // two exceptions of formulas.md §1.6), where the maps came from, and the tables used.
  nlohmann::json soft_summary(const EventCounters& c) const {
    const std::uint64_t collisions = c.collisions - counters_start_.collisions;
    auto fraction = [&](std::uint64_t k) {
      return collisions > 0 ? static_cast<double>(k) / static_cast<double>(collisions) : 0.0;
    };
    const std::uint64_t a = c.soft_overlap_fallbacks - counters_start_.soft_overlap_fallbacks;
    const std::uint64_t b = c.soft_early_releases - counters_start_.soft_early_releases;
    const std::uint64_t direct = c.soft_direct_maps - counters_start_.soft_direct_maps;
    nlohmann::json s;
    s["collisions"] = config_.soft.collisions;
    s["defer_releases"] = config_.soft.defer_releases;
    s["mapped_contacts"] = c.soft_contacts - counters_start_.soft_contacts;
    s["exception_a_overlap_fallbacks"] = a;
    s["exception_b_early_releases"] = b;
    s["exception_a_fraction"] = fraction(a);
    s["exception_b_fraction"] = fraction(b);
    s["direct_maps"] = direct;
    s["direct_map_fraction"] = fraction(direct);
    s["frozen_now"] = engine_->frozen();
    s["contact_energy"] = engine_->potential_energy();
    nlohmann::json tables = nlohmann::json::array();
    for (const SoftTableUse& use : tables_) {
      nlohmann::json t;
      t["contact"] = use.contact;
      t["nodes"] = use.report.nodes;
      t["min_normal_speed"] = use.spec.min_normal_speed;
      t["max_normal_speed"] = use.spec.max_normal_speed;
      t["max_tangential_ratio"] = use.spec.max_tangential_ratio;
      t["tolerance"] = use.spec.tolerance;
      t["max_error"] = {{"eps_t", use.report.max_error[0]},
                        {"eps_rdot", use.report.max_error[1]},
                        {"eps_phi", use.report.max_error[2]},
                        {"end_overlap", use.report.max_error[3]}};
      t["from_cache"] = use.report.from_cache;
      t["build_seconds"] = use.report.build_seconds;
      t["cache_file"] = use.report.cache_file.string();
      tables.push_back(t);
    }
    s["tables"] = tables;
    return s;
  }

  // Stepped potentials: the configurational energy over the production rows (blocked for its
  // error) and how the pair events split between the hard cores and the steps.
  nlohmann::json stepped_summary(const EventCounters& c) const {
    const BlockAverage u = block_average(potential_rows_);
    const auto n = static_cast<double>(n_);
    const std::uint64_t steps = (c.step_crossings - counters_start_.step_crossings) +
                                (c.step_bounces - counters_start_.step_bounces);
    nlohmann::json s;
    s["potential_energy"] = engine_->potential_energy();
    s["potential_energy_per_particle_mean"] = u.mean / n;
    s["potential_energy_per_particle_stderr"] = u.stderr_ / n;
    s["potential_energy_rows"] = potential_rows_.size();
    s["total_energy"] = engine_->kinetic_energy() + engine_->potential_energy();
    s["step_crossings"] = c.step_crossings - counters_start_.step_crossings;
    s["step_bounces"] = c.step_bounces - counters_start_.step_bounces;
    s["core_collisions"] = (c.collisions - counters_start_.collisions) - steps;
    return s;
  }

  // Simple shear: the stress P_xy from the production rows (blocked for its error) and the
  // viscosity -P_xy / shear_rate.
  nlohmann::json shear_summary(double temperature_at_production_start) const {
    const double rate = engine_->environment().shear_rate;
    const BlockAverage p = block_average(shear_stress_rows_);
    nlohmann::json s;
    s["shear_rate"] = rate;
    s["shear_stress"] = p.mean;  // P_xy
    s["shear_stress_stderr"] = p.stderr_;
    s["viscosity"] = -p.mean / rate;
    s["viscosity_stderr"] = p.stderr_ / std::abs(rate);
    s["samples"] = p.samples;
    s["temperature_production_start"] = temperature_at_production_start;
    s["temperature"] = thermo_stats_->temperature(thermal_energy());
    return s;
  }

  Clock::time_point created_ = Clock::now();  // the start of the set-up
  Config config_;
  bool restart_;
  std::string restart_name_;  // the restart file continued, for messages
  std::mt19937_64 rng_;
  std::optional<EventEngine<D, Queue>> engine_;
  std::vector<SoftTableUse> tables_;  // soft spheres: the map tables in use
  std::size_t n_ = 0;
  double volume_ = 1.0, particle_volume_ = 0.0;
  fs::path dir_;
  std::optional<ThermoWriter> thermo_;
  std::optional<gsd::Writer> trajectory_;
  std::uint64_t frame_collisions_ = 0;
  double frame_time_ = 0.0;
  unsigned owed_ = 0;                        // RunProgress::owed_outputs of the present state
  std::uint64_t kept_frame_collisions_ = 0;  // of the last frame kept (frames_kept_)
  double kept_frame_time_ = 0.0;
  // Some length or the output intervals in simulated time: rows and frames also when no
  // collision happened since the last.
  bool timed_ = false;
  std::optional<Thermodynamics> thermo_stats_;
  ThermoPoint prod_start_;
  double ke_start_ = 0.0, prod_ke_ = 0.0, energy_start_ = 0.0, u_start_ = 0.0;
  std::vector<double> potential_rows_;
  std::vector<double> production_temperatures_;  // at each production thermo row  // stepped
                                                 // potentials: U at each production thermo row
  EventCounters counters_start_;
  bool granular_ = false;  // walls, gravity or contact laws: report the energy budget
  bool bulk_ = true;       // periodic without a field: Z, P and a2 are bulk values
  bool rotating_ = false, dissipative_ = false, moving_walls_ = false;  // granular lines shown
  bool driven_ = false;   // [driving]: thermostat or random kicks
  bool sheared_ = false;  // Lees-Edwards boundaries
  struct ShearRowStart {
    double time = 0.0, virial_xy = 0.0;
  } shear_row_start_;
  std::vector<double> shear_stress_rows_;  // P_xy per production thermo row
  std::optional<AxisProfile<D>> profile_;  // output.profile_axis
  std::array<double, 9> kinetic_tensor_sum_{}, virial_tensor_start_{};
  int kinetic_tensor_samples_ = 0;
  double next_kick_ = 0.0;
  Vec<D> p_start_{};
  std::uint64_t events_start_ = 0, collisions_start_ = 0;
  std::string phase_ = "production";
  std::uint64_t equilibration_target_ = 0;
  double equilibration_end_time_ = 0.0;  // with run.equilibration_time
  std::uint64_t clock_stops_ = 0;        // outputs in time passed without an event
  RunProgress resumed_;                  // progress recorded in the restart file this run continues
  std::string stop_reason_ = "completed";
  std::optional<FrozenClockWatch> clock_watch_;
  std::optional<RestartPlan> plan_;  // a restart: how it used the changed configuration
  std::optional<fs::path> restart_file_;
  std::string run_id_;                      // the lineage of the outputs (kept by continued runs)
  std::optional<OutputDirectory> out_dir_;  // claimed (locked) while the run lasts
  run_detail::OutputContinuation continuation_;
  run_detail::OutputFailures outputs_;
  // Rows and frames of this directory's files that an uninterrupted run also writes, and the
  // point the last kept row ended at (what a restart file records for a continued run).
  std::uint64_t rows_kept_ = 0, frames_kept_ = 0;
  // output.trajectory = false: the frames of the lineage's trajectory.gsd, cut back to the
  // restart point (-1: none).
  std::int64_t frames_not_written_ = -1;
  ThermoPoint kept_mark_;
  // The output schedule in collisions of the phase running (or last run: a restart file written
  // when it stopped records it), and that phase (0 equilibration, 1 production; -1: none yet).
  OutputSchedule schedule_;
  int schedule_phase_ = -1;
  bool first_phase_ = true;
  bool production_done_ = false;
  std::uint64_t production_target_ = 0;
  double production_end_time_ = kNever;
  std::string error_;  // why the run could not go on (RunOutcome::error)
};

template <int D>
RunOutcome run_with_dimension(const Config& config, const std::optional<fs::path>& restart,
                              const RunOptions& options) {
  if (config.run.integrator == "dem") return run_detail::run_dem<D>(config, restart, options);
  if (config.run.event_queue == "heap")
    return RunDriver<D, BinaryHeapQueue>(config, restart, options).run();
  if (config.run.event_queue == "tree")
    return RunDriver<D, TournamentTreeQueue>(config, restart, options).run();
  return RunDriver<D, CalendarQueue>(config, restart, options).run();
}

}  // namespace

RunOutcome run_simulation(const Config& config, const std::optional<fs::path>& restart_file,
                          const RunOptions& options) {
  int dimension = config.system.dimension;
  if (restart_file && fs::exists(*restart_file)) {
    const int stored = gsd_dimension(*restart_file);
    if (stored != dimension) {
      throw InputError(fmt::format("restart file '{}' holds a {}D state but system.dimension = {}",
                                   restart_file->string(), stored, dimension));
    }
  }
  return dimension == 2 ? run_with_dimension<2>(config, restart_file, options)
                        : run_with_dimension<3>(config, restart_file, options);
}

}  // namespace kairos
