#include "run/simulation.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "analysis/thermodynamics.hpp"
#include "core/error.hpp"
#include "core/periodic.hpp"
#include "core/state_blocks.hpp"
#include "core/stop_flag.hpp"
#include "init/initial_state.hpp"
#include "io/config_choices.hpp"
#include "io/config_obstacles.hpp"
#include "run/dem_adapter.hpp"
#include "run/event_adapter.hpp"
#include "run/output_directory.hpp"
#include "run/setup_chain.hpp"
#include "run/trigger.hpp"
#include "scheduler/calendar_queue.hpp"

namespace kairos {

template <int D>
Simulation<D>::Simulation(const Config& config,
                          const std::optional<std::filesystem::path>& restart_file,
                          const EngineTracking& tracking)
    : config_(config), tracking_(tracking) {
  const bool dem = integrators().at(config.run.integrator) == IntegratorKind::kDem;
  if (dem && tracking.helfand) {
    throw InputError(
        "the Helfand moments (helfand=True): the event integrator only, not run.integrator = "
        "\"dem\" (as analysis.transport)");
  }
  RunStart<D> start = start_run<D>(config, restart_file, dem ? "dem" : "event");
  config_ = start.config;
  if (tracking.helfand) {
    if (const std::optional<TransportObstacle> obstacle = transport_obstacle(config_)) {
      throw InputError(
          fmt::format("the Helfand moments: {} ({}): they need a conservative periodic system",
                      obstacle->why, obstacle->key));
    }
  }
  progress_ = start.resumed;
  compression_ = start.compression;
  const std::optional<RestartPlan> plan = start.plan;
  n_ = start.state.size();
  mass_ = start.state.mass;
  radius_.resize(n_);
  for (std::size_t i = 0; i < n_; ++i) radius_[i] = start.state.kinematics[i].radius;
  species_ = start.state.species;
  species_names_ = start.state.species_names;
  if (dem) {
    integrator_ = start_integrator<D>(std::move(start));
    dem_ = integrator_->as_dem();
  } else {
    // The tables `kairos run` would use (the same speeds covered: the same maps, bit for bit).
    auto engine = start_event_engine<D, CalendarQueue>(std::move(start), {}, tracking);
    engine_ = engine.get();
    integrator_ = std::move(engine);
    const std::vector<SoftTableUse>& tables = engine_->tables();
    if (!tables.empty()) progress_.soft_table_max_speed = tables.front().spec.max_normal_speed;
  }
  progress_.config = to_toml(config_);
  progress_.run_id = lineage_run_id(restart_file, progress_);
  if (plan) print_restart_note(*plan, restart_file->string());
  // A saved state continues with production.
  progress_.equilibration_remaining = 0.0;
  progress_.equilibration_end_time = std::numeric_limits<double>::quiet_NaN();
}

template <int D>
Simulation<D>::~Simulation() = default;

template <int D>
EventEngineAdapter<D, CalendarQueue>& Simulation<D>::event_engine(const char* what) const {
  if (engine_ == nullptr) {
    throw InputError(fmt::format(
        "{}: the event integrator only, not run.integrator = \"dem\" (docs/python.md)", what));
  }
  return *engine_;
}

template <int D>
const EventIntegrator<D>& Simulation<D>::event_integrator(const char* what) const {
  return event_engine(what);
}

// The run driver's loop (EventEngineAdapter::advance, as `kairos run` advances), with the
// Simulation's stop rules: an event, a state or a frozen clock that cannot go on is the
// caller's InputError; keep_going is asked at the adapter's polls (every 16 384 events).
template <int D>
bool Simulation<D>::advance_within(const AdvanceLimits& limits, const std::function<bool()>& done,
                                   const KeepGoing& keep_going) {
  while (!done()) {
    const Advance a = integrator_->advance(limits);
    switch (a.stop) {
      case AdvanceStop::kNone:
        break;
      case AdvanceStop::kFrozenClock:
      case AdvanceStop::kError:
        throw InputError(a.error);
      default:
        return false;  // no event left
    }
    if (done()) return true;
    if ((a.update_progress || stop_requested()) && keep_going && !keep_going()) return false;
  }
  return true;
}

template <int D>
bool Simulation<D>::advance_to_time(double t, const KeepGoing& keep_going) {
  if (!(t >= time()) || !std::isfinite(t)) {
    throw InputError(
        fmt::format("advance to time {}: the simulation is at time {} already (or "
                    "the time is not finite)",
                    t, time()));
  }
  // The clock stops at t, as at the end of a phase measured in time.
  AdvanceLimits limits;
  limits.next_output_time = t;
  limits.phase_end_time = t;
  limits.phase_in_time = true;
  limits.clock_stops = true;
  if (engine_ == nullptr)
    return advance_within(
        limits, [&] { return integrator_->reached(t); }, keep_going);
  EventEngine<D, CalendarQueue>& engine = engine_->engine();
  return advance_within(
      limits, [&] { return engine.time() == t && !(engine.next_event_time() <= t); }, keep_going);
}

namespace {
// now + count, at most the largest count (no wrap-around).
std::uint64_t target_after(std::uint64_t now, std::uint64_t count) {
  return count > ~std::uint64_t{0} - now ? ~std::uint64_t{0} : now + count;
}
}  // namespace

template <int D>
bool Simulation<D>::advance_events(std::uint64_t count, const KeepGoing& keep_going) {
  AdvanceLimits limits;
  limits.events = target_after(events(), count);
  return advance_within(
      limits, [&] { return events() >= limits.events; }, keep_going);
}

template <int D>
bool Simulation<D>::advance_collisions(std::uint64_t count, const KeepGoing& keep_going) {
  AdvanceLimits limits;
  limits.collisions = target_after(collisions(), count);
  return advance_within(
      limits, [&] { return collisions() >= limits.collisions; }, keep_going);
}

template <int D>
bool Simulation<D>::sample_every(double interval, double duration,
                                 const std::function<void()>& sample, const KeepGoing& keep_going) {
  const double end = time() + duration;
  if (!(interval > 0.0) || !std::isfinite(interval) || !(duration >= 0.0) || !std::isfinite(end))
    throw InputError(
        fmt::format("sampling every {} for {}: both must be finite, the interval "
                    "positive and the duration not negative",
                    interval, duration));
  // As the run driver's loop (run_driver.cpp run_phase) with one trigger in time.
  TimeTrigger trigger;
  trigger.step = interval;
  // The clock triggers compare with (the DEM's within round-off of its step).
  const auto now = [&] { return integrator_->trigger_time(); };
  trigger.next = trigger.after(now());
  while (!integrator_->reached(end)) {
    double stop = std::min(trigger.next, end);
    if (stop >= end - TimeTrigger::slack(end)) stop = end;
    if (!advance_to_time(std::max(stop, time()), keep_going)) return false;
    if (trigger.due(now())) sample();
  }
  return true;
}

template <int D>
bool Simulation<D>::sample_every_count(std::uint64_t step, std::uint64_t count,
                                       const std::function<std::uint64_t()>& now,
                                       const std::function<bool(std::uint64_t)>& advance,
                                       const std::function<void()>& sample) {
  const std::uint64_t end = target_after(now(), count);
  // As the run driver's loop with one trigger in collisions (every step from the start).
  CollisionTrigger trigger;
  trigger.step = step;
  trigger.next = target_after(now(), step);
  while (now() < end) {
    const std::uint64_t stop = std::min(trigger.next, end);
    if (now() < stop && !advance(stop - now())) return false;
    if (trigger.due(now())) sample();
  }
  return true;
}

template <int D>
bool Simulation<D>::sample_every_collisions(std::uint64_t step, std::uint64_t count,
                                            const std::function<void()>& sample,
                                            const KeepGoing& keep_going) {
  if (step == 0) throw InputError("sampling every 0 collisions: the step must be at least 1");
  return sample_every_count(
      step, count, [&] { return collisions(); },
      [&](std::uint64_t n) { return advance_collisions(n, keep_going); }, sample);
}

template <int D>
bool Simulation<D>::sample_every_events(std::uint64_t step, std::uint64_t count,
                                        const std::function<void()>& sample,
                                        const KeepGoing& keep_going) {
  if (step == 0) throw InputError("sampling every 0 events: the step must be at least 1");
  return sample_every_count(
      step, count, [&] { return events(); },
      [&](std::uint64_t n) { return advance_events(n, keep_going); }, sample);
}

template <int D>
double Simulation<D>::time() const {
  return integrator_->time();
}
template <int D>
std::uint64_t Simulation<D>::events() const {
  return integrator_->events();
}
template <int D>
std::uint64_t Simulation<D>::collisions() const {
  return integrator_->collisions();
}
template <int D>
double Simulation<D>::virial() const {
  return integrator_->virial();
}
template <int D>
const Vec<D>& Simulation<D>::box() const {
  return integrator_->box();
}
template <int D>
std::vector<Vec<D>> Simulation<D>::positions() const {
  if (engine_ == nullptr) return integrator_->particles().position;
  return engine_->engine().current_positions();
}
template <int D>
std::vector<Vec<D>> Simulation<D>::velocities() const {
  if (engine_ == nullptr) return integrator_->particles().velocity;
  return engine_->engine().current_velocities();
}
template <int D>
void Simulation<D>::set_velocities(const std::vector<Vec<D>>& velocities) {
  EventEngine<D, CalendarQueue>& engine = event_engine("set_velocities").engine();
  if (velocities.size() != n_) {
    throw InputError(
        fmt::format("set_velocities: {} velocities for {} particles", velocities.size(), n_));
  }
  const std::vector<const SpeciesConfig*> entry = config_species();
  for (std::size_t i = 0; i < n_; ++i) {
    for (int a = 0; a < D; ++a) {
      if (!std::isfinite(velocities[i][a])) {
        throw InputError(fmt::format("set_velocities: particle {}: velocity not finite", i));
      }
    }
    const std::uint32_t k = species_.empty() ? 0 : species_[i];
    const SpeciesConfig* own = k < entry.size() ? entry[k] : nullptr;
    if (own != nullptr && own->fixed && !(velocities[i] == Vec<D>{})) {
      throw InputError(fmt::format(
          "set_velocities: particle {} is a fixed grain (species {}): its velocity stays 0", i,
          own->name));
    }
  }
  check_state_can_change("set_velocities");
  engine.set_velocities(engine.time(), velocities);
}

template <int D>
std::vector<const SpeciesConfig*> Simulation<D>::config_species() const {
  std::vector<const SpeciesConfig*> entry(species_names_.size(), nullptr);
  for (std::size_t k = 0; k < species_names_.size(); ++k)
    for (const SpeciesConfig& c : config_.system.species)
      if (c.name == species_names_[k]) entry[k] = &c;
  return entry;
}

template <int D>
void Simulation<D>::check_state_can_change(const char* what) const {
  const EventEngine<D, CalendarQueue>& engine = event_engine(what).engine();
  if (engine.soft() || engine.sleeping() > 0 || engine.tracks_helfand()) {
    throw InputError(
        fmt::format("{}: not with soft spheres, sleeping particles or the Helfand moments kept "
                    "(helfand=True): their state follows the particles'",
                    what));
  }
}

template <int D>
void Simulation<D>::rebuild(const char* what,
                            const std::function<void(ParticleSystem<D>&)>& change) {
  check_state_can_change(what);
  if (engine_->kind().sheared) {
    throw InputError(fmt::format(
        "{}: not under Lees-Edwards shear (the images slide: a new place needs the flow's "
        "offset and velocity)",
        what));
  }
  const EventEngine<D, CalendarQueue>& engine = engine_->engine();
  const double now = engine.time();
  ParticleSystem<D> s = engine.export_state(/*with_zones=*/false);
  // Every particle at the present time; the scheduler's state is predicted anew.
  for (std::size_t i = 0; i < s.size(); ++i) {
    Kinematics<D>& k = s.kinematics[i];
    const Vec<D> v = s.velocity(i, now);
    k.pos = s.position(i, now);
    k.vel = v;
    k.time = now;
  }
  s.events.clear();
  s.cell.clear();
  s.order.clear();
  s.zones.reset();
  change(s);
  std::vector<Vec<D>> position(s.size());
  std::vector<double> diameter(s.size());
  for (std::size_t i = 0; i < s.size(); ++i) {
    position[i] = s.kinematics[i].pos;
    diameter[i] = 2.0 * s.kinematics[i].radius;
  }
  std::uint32_t i = 0, j = 0;
  const double overlap = kairos::max_overlap<D>(s.box, s.periodic, position, diameter, &i, &j);
  if (overlap > 1e-12 * *std::min_element(diameter.begin(), diameter.end())) {
    throw InputError(fmt::format("{}: particles {} and {} overlap by {:.6g}", what, i, j, overlap));
  }
  RunStart<D> start;
  start.config = config_;
  start.rng = engine_->rng();
  start.resumed = progress_;
  start.state = std::move(s);
  try {
    auto fresh = start_event_engine<D, CalendarQueue>(std::move(start), {}, tracking_);
    engine_ = fresh.get();
    integrator_ = std::move(fresh);
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: {}", what, e.what()));
  }
  const ParticleSystem<D>& now_state = engine_->engine().export_state(false);
  mass_ = now_state.mass;
  for (std::size_t k = 0; k < n_; ++k) radius_[k] = now_state.kinematics[k].radius;
  species_ = now_state.species;
}

template <int D>
void Simulation<D>::set_positions(const std::vector<Vec<D>>& positions) {
  if (positions.size() != n_) {
    throw InputError(
        fmt::format("set_positions: {} positions for {} particles", positions.size(), n_));
  }
  for (std::size_t i = 0; i < n_; ++i) {
    for (int a = 0; a < D; ++a) {
      if (!std::isfinite(positions[i][a])) {
        throw InputError(fmt::format("set_positions: particle {}: position not finite", i));
      }
    }
  }
  rebuild("set_positions", [&](ParticleSystem<D>& s) {
    for (std::size_t i = 0; i < n_; ++i) {
      Vec<D> x = positions[i];
      for (int a = 0; a < D; ++a)
        if (s.periodic[a]) x[a] = wrap_into_box(x[a], s.box[a]);
      s.kinematics[i].pos = x;
    }
  });
}

template <int D>
void Simulation<D>::set_species(const std::vector<std::uint32_t>& species) {
  if (species.size() != n_) {
    throw InputError(fmt::format("set_species: {} species for {} particles", species.size(), n_));
  }
  const std::vector<const SpeciesConfig*> entry = config_species();
  for (std::size_t i = 0; i < n_; ++i) {
    const std::uint32_t k = species[i];
    if (k >= species_names_.size() || entry[k] == nullptr) {
      throw InputError(fmt::format(
          "set_species: particle {}: species {} is not one of the configuration's species", i, k));
    }
    const std::uint32_t now = species_.empty() ? 0 : species_[i];
    const SpeciesConfig* was = now < entry.size() ? entry[now] : nullptr;
    if (entry[k]->fixed != (was != nullptr && was->fixed)) {
      throw InputError(fmt::format(
          "set_species: particle {}: from species {} to {}: a particle cannot become or stop "
          "being a fixed grain",
          i, now < species_names_.size() ? species_names_[now] : "?", species_names_[k]));
    }
  }
  rebuild("set_species", [&](ParticleSystem<D>& s) {
    if (s.species.empty()) s.species.assign(n_, 0);
    for (std::size_t i = 0; i < n_; ++i) {
      if (s.species[i] == species[i]) continue;  // its own size and mass stay
      s.species[i] = species[i];
      s.kinematics[i].radius = 0.5 * entry[species[i]]->diameter;
      s.mass[i] = entry[species[i]]->mass;
    }
  });
}

template <int D>
std::vector<WallReading> Simulation<D>::walls_with_mass() const {
  return integrator_->walls_with_mass();
}

template <int D>
typename Simulation<D>::Energies Simulation<D>::energies() const {
  Energies e;
  const Integrator<D>& in = *integrator_;
  e.kinetic = in.kinetic_energy();
  e.rotational = in.rotational_energy();
  e.potential = in.potential_energy();
  e.field = dem_ != nullptr ? dem_->dem().field_energy() : engine_->field_energy();
  e.dissipated = in.dissipated_energy();
  e.work_by_walls = in.work_by_walls();
  if (engine_ != nullptr) {
    e.work_by_driving = engine_->counters().work_by_driving;
    e.work_by_shear = engine_->counters().work_by_shear;
  }
  if (const auto outlet = in.outlet()) e.taken_out = outlet->energy;
  return e;
}
template <int D>
Vec<D> Simulation<D>::momentum() const {
  return integrator_->momentum();
}
template <int D>
double Simulation<D>::max_overlap() const {
  return integrator_->max_overlap();
}

template <int D>
double Simulation<D>::kinetic_energy() const {
  return integrator_->kinetic_energy();
}
template <int D>
double Simulation<D>::temperature() const {
  // kT as thermo.tsv gives it (under shear: of the velocities relative to the flow).
  const std::size_t moving = integrator_->mobile();
  return Thermodynamics(D, moving, integrator_->volume(), moving < n_)
      .temperature(integrator_->thermal_energy(), integrator_->held_degrees_of_freedom());
}
template <int D>
double Simulation<D>::potential_energy() const {
  return integrator_->potential_energy();
}
template <int D>
ParticleSystem<D> Simulation<D>::state() const {
  if (dem_ != nullptr) return dem_->dem().export_state();
  return engine_->engine().export_state();
}
template <int D>
bool Simulation<D>::tracks_images() const {
  return engine_ != nullptr && engine_->engine().tracks_images();
}
template <int D>
bool Simulation<D>::tracks_helfand() const {
  return engine_ != nullptr && engine_->engine().tracks_helfand();
}

template <int D>
std::vector<Vec<D>> Simulation<D>::unwrapped_positions() const {
  event_engine("unwrapped positions");
  if (!tracks_images()) {
    throw InputError(
        "unwrapped positions need image counters: this Simulation keeps none (created with "
        "images=False)");
  }
  if (engine_->kind().sheared) {
    throw InputError(
        "unwrapped positions under Lees-Edwards shear are not provided (the images across the "
        "y faces move along x: docs/outputs.md); images() gives the counters");
  }
  std::vector<std::uint32_t> slot(n_);
  for (std::size_t i = 0; i < n_; ++i) slot[i] = static_cast<std::uint32_t>(i);
  std::vector<Vec<D>> out(n_);
  engine_->unwrapped_positions(slot, out);
  return out;
}

template <int D>
std::vector<std::array<std::int32_t, D>> Simulation<D>::images() const {
  event_engine("images");
  if (!tracks_images()) {
    throw InputError("images: this Simulation keeps no image counters (created with images=False)");
  }
  std::vector<std::array<std::int32_t, D>> out(n_);
  const StateBlocks<D> state = engine_->state_blocks();
  const ParticleSystem<D>& globals = state.globals();
  state.for_each(
      [&](const ParticleSystem<D>& part, std::size_t first) {
        for (std::size_t j = 0; j < part.size(); ++j) {
          // The counters count the wraps of the engine's position; positions() may wrap it
          // once more (a particle at a face, not yet wrapped by its crossing).
          const Vec<D> x = part.position(j, part.time);
          std::array<std::int32_t, D> image = part.image[j];
          for (int a = 0; a < D; ++a) {
            if (!globals.periodic[a]) continue;
            const double inside = wrap_into_box(x[a], globals.box[a]);
            image[a] += static_cast<std::int32_t>(std::lround((x[a] - inside) / globals.box[a]));
          }
          out[first + j] = image;
        }
      },
      StateBlocks<D>::kKinematics);
  return out;
}

template <int D>
typename HelfandMoments<D>::Moments Simulation<D>::helfand_moments() const {
  event_engine("the Helfand moments");
  if (!tracks_helfand()) {
    throw InputError(
        "the Helfand moments are not kept: create the Simulation with helfand=True (a "
        "conservative periodic system)");
  }
  return engine_->engine().helfand_moments();
}
template <int D>
const std::array<double, 9>& Simulation<D>::virial_tensor() const {
  return event_engine("the virial tensor").engine().counters().virial_tensor;
}

template <int D>
void Simulation<D>::set_thermostat_temperature(double temperature) {
  EventEngineAdapter<D, CalendarQueue>& engine = event_engine("set_thermostat_temperature");
  if (!driving_kinds().is(config_.driving.kind, DrivingKind::kAndersen)) {
    throw InputError(fmt::format(
        "set_thermostat_temperature: the simulation has no Andersen thermostat (driving.kind = "
        "\"{}\"; set [driving] kind = \"andersen\")",
        config_.driving.kind));
  }
  // driving.temperature's range (docs/config.md), in units of system.temperature.
  const double kT = config_.system.temperature;
  if (!std::isfinite(temperature) || !(temperature >= 1e-9 * kT) || !(temperature <= 1e9 * kT)) {
    throw InputError(fmt::format(
        "set_thermostat_temperature: driving.temperature = {} must be finite, in [1e-09, 1e+09] "
        "times system.temperature = {}",
        temperature, kT));
  }
  engine.set_driving_temperature(temperature);
  config_.driving.temperature = temperature;
  progress_.config = to_toml(config_);  // what save() stores: a restart continues at it
}

template <int D>
void Simulation<D>::save(const std::filesystem::path& path) const {
  // The driving's next kick time, as `kairos run` records it before its restart file; the
  // DEM's time step and marks where it stands (no phase target: a saved state continues with
  // production from here).
  RunProgress progress = progress_;
  integrator_->record(progress, ~std::uint64_t{0}, std::numeric_limits<double>::infinity());
  integrator_->write_restart(path, progress);
}

template class Simulation<2>;
template class Simulation<3>;

}  // namespace kairos
