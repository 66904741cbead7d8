#include "run/simulation.hpp"

#include <fmt/format.h>

#include <cmath>
#include <limits>

#include "analysis/thermodynamics.hpp"
#include "core/error.hpp"
#include "engine/event_engine.hpp"
#include "run/environment_setup.hpp"
#include "run/frozen_clock.hpp"
#include "run/run_support.hpp"
#include "run/soft_tables_setup.hpp"
#include "scheduler/calendar_queue.hpp"

namespace kairos {

template <int D>
Simulation<D>::Simulation(const Config& config,
                          const std::optional<std::filesystem::path>& restart_file)
    : config_(config), rng_(config.system.seed) {
  if (config.run.integrator != "event") {
    throw InputError(fmt::format(
        "run.integrator = \"{}\": an in-memory simulation drives the event integrator; run the "
        "DEM with `kairos run` (kairos.run in Python)",
        config.run.integrator));
  }
  if (config.driving.kind != "none") {
    throw InputError(
        "[driving]: an in-memory simulation applies no driving kicks; run driven systems with "
        "`kairos run` (kairos.run in Python)");
  }
  ParticleSystem<D> start = run_detail::build_start_state<D>(config, restart_file, rng_, progress_);
  run_detail::check_restart_integrator(restart_file, progress_, "event");
  std::optional<RestartPlan> plan;
  if (restart_file) {
    plan = run_detail::plan_continuation<D>(config, start, progress_, restart_file->string());
    config_ = plan->used;
  }
  const bool resume = plan && !plan->repredict;
  n_ = start.size();
  mass_ = start.mass;
  radius_.resize(n_);
  for (std::size_t i = 0; i < n_; ++i) radius_[i] = start.kinematics[i].radius;
  species_ = start.species;
  species_names_ = start.species_names;
  for (int a = 0; a < D; ++a) volume_ *= start.box[a];
  try {
    Environment<D> environment = make_environment<D>(config_, start);
    if (environment.soft_spheres() && config_.soft.tables) {
      // The tables `kairos run` would use (the same speeds covered: the same maps, bit for bit).
      SoftTableSettings settings;
      settings.tolerance = config_.soft.table_tolerance;
      settings.cache_dir = config_.soft.table_cache;
      settings.max_speed = progress_.soft_table_max_speed;
      const std::vector<SoftTableUse> tables = attach_soft_tables(environment, start, settings);
      if (!tables.empty()) progress_.soft_table_max_speed = tables.front().spec.max_normal_speed;
    }
    EngineOptions options;
    options.defer_soft_releases = config_.soft.defer_releases;
    engine_ = std::make_unique<EventEngine<D, CalendarQueue>>(
        std::move(start), resume ? StartMode::kResume : StartMode::kPredict, options, environment);
    progress_.config = to_toml(config_);
    progress_.run_id = run_detail::lineage_run_id(restart_file, progress_);
    if (plan && plan->repredict) run_detail::check_no_overlap_after_new_physics(*engine_);
  } catch (const InputError& e) {
    if (!plan) throw;
    throw run_detail::restart_setup_error(e, *restart_file, *plan);
  }
  if (plan) run_detail::print_restart_note(*plan, restart_file->string());
  clock_watch_ = std::make_unique<FrozenClockWatch>(*engine_);
  // A saved state continues with production.
  progress_.equilibration_remaining = 0.0;
  progress_.equilibration_end_time = std::numeric_limits<double>::quiet_NaN();
}

template <int D>
Simulation<D>::~Simulation() = default;

template <int D>
bool Simulation<D>::run_while(const std::function<bool()>& more, const KeepGoing& keep_going) {
  while (more()) {
    if (engine_->step() == EventKind::kNone) return false;
    if (clock_watch_->frozen(*engine_)) throw InputError(clock_watch_->describe(*engine_));
    if ((engine_->counters().events & 0x3fffu) == 0 && keep_going && !keep_going()) return false;
  }
  return true;
}

template <int D>
bool Simulation<D>::advance_to_time(double t, const KeepGoing& keep_going) {
  if (!(t >= engine_->time()) || !std::isfinite(t)) {
    throw InputError(
        fmt::format("advance to time {}: the simulation is at time {} already (or "
                    "the time is not finite)",
                    t, engine_->time()));
  }
  if (!run_while([&] { return engine_->next_event_time() <= t; }, keep_going)) {
    if (engine_->next_event_time() <= t) return false;  // stopped by keep_going
  }
  engine_->advance_clock(t);
  return true;
}

namespace {
// now + count, at most the largest count (no wrap-around).
std::uint64_t target_after(std::uint64_t now, std::uint64_t count) {
  return count > ~std::uint64_t{0} - now ? ~std::uint64_t{0} : now + count;
}
}  // namespace

template <int D>
bool Simulation<D>::advance_events(std::uint64_t count, const KeepGoing& keep_going) {
  const std::uint64_t target = target_after(engine_->counters().events, count);
  return run_while([&] { return engine_->counters().events < target; }, keep_going);
}

template <int D>
bool Simulation<D>::advance_collisions(std::uint64_t count, const KeepGoing& keep_going) {
  const std::uint64_t target = target_after(engine_->counters().collisions, count);
  return run_while([&] { return engine_->counters().collisions < target; }, keep_going);
}

template <int D>
double Simulation<D>::time() const {
  return engine_->time();
}
template <int D>
std::uint64_t Simulation<D>::events() const {
  return engine_->counters().events;
}
template <int D>
std::uint64_t Simulation<D>::collisions() const {
  return engine_->counters().collisions;
}
template <int D>
const Vec<D>& Simulation<D>::box() const {
  return engine_->box();
}
template <int D>
std::vector<Vec<D>> Simulation<D>::positions() const {
  return engine_->current_positions();
}
template <int D>
std::vector<Vec<D>> Simulation<D>::velocities() const {
  return engine_->current_velocities();
}
template <int D>
double Simulation<D>::kinetic_energy() const {
  return engine_->kinetic_energy();
}
template <int D>
double Simulation<D>::temperature() const {
  const double ke = engine_->environment().sheared() ? engine_->peculiar_kinetic_energy()
                                                     : engine_->kinetic_energy();
  return Thermodynamics(D, n_, volume_).temperature(ke);
}
template <int D>
double Simulation<D>::potential_energy() const {
  return engine_->potential_energy();
}
template <int D>
ParticleSystem<D> Simulation<D>::state() const {
  return engine_->export_state();
}
template <int D>
void Simulation<D>::save(const std::filesystem::path& path) const {
  write_restart_file(path, engine_->state_blocks(), rng_, progress_);
}

template class Simulation<2>;
template class Simulation<3>;

}  // namespace kairos
