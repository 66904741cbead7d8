#include "run/event_adapter.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "core/error.hpp"
#include "core/periodic.hpp"
#include "core/stop_flag.hpp"
#include "init/initial_state.hpp"
#include "model/boundaries.hpp"
#include "run/collision_estimate.hpp"
#include "run/trigger.hpp"
#include "scheduler/binary_heap_queue.hpp"
#include "scheduler/calendar_queue.hpp"
#include "scheduler/tournament_tree_queue.hpp"

namespace kairos {

namespace {

// max_overlap() under Lees-Edwards shear: the particles within the largest diameter of the low
// y face are copied above the box as their images (displaced along x by `offset`), in a box
// tall enough that nothing else wraps around along y.
template <int D>
double max_overlap_sheared(const Vec<D>& box, std::vector<Vec<D>> x, std::vector<double> diameter,
                           double offset) {
  const double dmax = *std::max_element(diameter.begin(), diameter.end());
  const std::size_t n = x.size();
  for (std::size_t i = 0; i < n; ++i) {
    x[i][1] = wrap_into_box(x[i][1], box[1]);
    if (x[i][1] >= dmax) continue;
    Vec<D> image = x[i];
    image[0] = wrap_into_box(image[0] + offset, box[0]);
    image[1] += box[1];
    x.push_back(image);
    diameter.push_back(diameter[i]);
  }
  Vec<D> tall = box;
  tall[1] += 3.0 * dmax;
  return max_overlap<D>(tall, x, diameter);
}

// max_overlap of an engine's present positions: no image along bounded axes, Lees-Edwards
// images displaced by the shear's offset. `state`: its globals, `diameters` per particle.
template <class Engine, int D>
double current_max_overlap(const Engine& engine, const ParticleSystem<D>& state,
                           const std::vector<double>& diameters) {
  if (engine.environment().sheared()) {
    return max_overlap_sheared<D>(
        state.box, engine.current_positions(), diameters,
        std::fmod(engine.environment().shear_rate * state.box[1] * state.time, state.box[0]));
  }
  return max_overlap<D>(state.box, state.periodic, engine.current_positions(), diameters);
}

// A state continued under new physics may hold pairs that now overlap (a new potential's core,
// new images): InputError (the setup chain names the keys).
template <class Engine>
void check_no_overlap_after_new_physics(const Engine& engine) {
  const auto state = engine.export_state(/*with_zones=*/false);
  std::vector<double> diameters(state.size());
  for (std::size_t i = 0; i < state.size(); ++i) diameters[i] = 2.0 * state.kinematics[i].radius;
  const double smallest = *std::min_element(diameters.begin(), diameters.end());
  const double overlap = current_max_overlap(engine, state, diameters);
  if (overlap > 1e-12 * smallest) {
    throw InputError(fmt::format(
        "particles overlap by up to {:.6g} under the new physics; start a new run from the "
        "state with system.initial_state instead",
        overlap));
  }
}

EngineOptions engine_options(const Config& config, const EngineTracking& tracking) {
  EngineOptions options;
  options.defer_soft_releases = config.soft.defer_releases;
  // Trajectory frames carry particles/image (and so does the restart file, for the next run).
  options.track_images = config.output.trajectory || config.analysis.msd || tracking.images;
  options.track_helfand = config.analysis.transport || tracking.helfand;
  options.size_levels = config.run.size_levels;
  return options;
}

}  // namespace

template <int D, class Queue>
EventEngineAdapter<D, Queue>::EventEngineAdapter(RunStart<D>&& start,
                                                 const Environment<D>& environment,
                                                 std::vector<SoftTableUse> tables,
                                                 const EngineTracking& tracking)
    : EventIntegrator<D>(start.state),
      driving_(start.config.driving),
      driving_kind_(driving_kinds().at(driving_.kind)),
      validate_(start.config.run.validate),
      rng_(start.rng),
      tables_(std::move(tables)),
      engine_(std::move(start.state), start.resumes() ? StartMode::kResume : StartMode::kPredict,
              engine_options(start.config, tracking), environment),
      watch_(engine_) {
  if (start.restarted() && !start.resumes()) check_no_overlap_after_new_physics(engine_);
  auto& kind = this->kind_;
  kind.driven = driving_kind_ != DrivingKind::kNone;
  kind.sheared = environment.sheared();
  kind.granular = !environment.plain() || environment.has_gravity() || kind.driven ||
                  environment.sheared() || environment.soft_spheres() ||
                  environment.dissipative_steps();
  for (int a = 0; a < D; ++a) kind.granular = kind.granular || !environment.periodic(a);
  // Fixed grains: a matrix or a floor, not a bulk fluid; the temperature counts the others.
  this->set_fixed(engine_.fixed_grains());
  if (engine_.fixed_grains() > 0) {
    fixed_.assign(this->size(), 0);
    engine_.state_blocks(false).for_each(
        [&](const ParticleSystem<D>& part, std::size_t first) {
          for (std::size_t j = 0; j < part.size(); ++j)
            fixed_[first + j] =
                environment.fixed_species(part.species.empty() ? 0u : part.species[j]) ? 1 : 0;
        },
        StateBlocks<D>::kIdentity);
  }
  kind.granular = kind.granular || environment.has_fixed_grains();
  bulk_ = !environment.has_gravity() && !environment.has_fixed_grains();
  for (int a = 0; a < D; ++a) bulk_ = bulk_ && environment.periodic(a);
  kind.rotating = environment.rotates() || engine_.rotational_energy() > 0.0;
  kind.dissipative = environment.tc > 0.0 || environment.dissipative_steps() ||
                     environment.soft_spheres() || !environment.plain();
  kind.moving_walls = Boundaries<D>(environment, engine_.box()).any_surface_drives();
  if (kind.driven) {
    next_kick_ = start.restarted() && start.resumed.next_kick_time >= engine_.time()
                     ? start.resumed.next_kick_time
                     : engine_.time() + draw_kick_interval();
  }
}

template <int D, class Queue>
double EventEngineAdapter<D, Queue>::draw_kick_interval() {
  std::exponential_distribution<double> wait(driving_.rate * static_cast<double>(this->size()));
  return wait(rng_);
}

template <int D, class Queue>
void EventEngineAdapter<D, Queue>::set_driving_temperature(double temperature) {
  if (driving_kind_ != DrivingKind::kAndersen)
    throw std::logic_error("set_driving_temperature: the run has no Andersen thermostat");
  driving_.temperature = temperature;
}

// The kicks due up to the next event, and not after `limit`.
template <int D, class Queue>
void EventEngineAdapter<D, Queue>::apply_due_kicks(double limit) {
  while (next_kick_ <= std::min(engine_.next_event_time(), limit)) {
    std::uniform_int_distribution<std::uint32_t> pick(0,
                                                      static_cast<std::uint32_t>(this->size() - 1));
    const std::uint32_t k = pick(rng_);
    Vec<D> v{};
    if (driving_kind_ == DrivingKind::kAndersen) {
      std::normal_distribution<double> maxwell(
          0.0, std::sqrt(driving_.temperature / engine_.particle_mass(k)));
      for (int a = 0; a < D; ++a) v[a] = maxwell(rng_);
      if (this->kind_.sheared) {
        v = v + engine_.environment().streaming_velocity(engine_.position(k, next_kick_),
                                                         engine_.box());
      }
    } else {
      std::normal_distribution<double> kick(0.0, std::sqrt(driving_.strength / driving_.rate));
      v = engine_.velocity(k, next_kick_);
      for (int a = 0; a < D; ++a) v[a] += kick(rng_);
    }
    engine_.set_velocity(k, next_kick_, v);
    next_kick_ += draw_kick_interval();
  }
}

// The per-event loop. The driver checked, after every event, the collision count against its
// next thresholds, the stop flag, and every 16 384 events the progress line and the wall clock:
// this loop returns exactly where one of those can act, and otherwise goes on without leaving
// the engine. With outputs or the phase's end in time it first asks whether they come before
// the next event, and if so stops the engine's clock there (only the present moves).
template <int D, class Queue>
Advance EventEngineAdapter<D, Queue>::advance(const AdvanceLimits& limits) {
  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  const bool driven = this->kind_.driven;
  // The limits, in locals for the loop (the engine's calls cannot change them).
  const std::uint64_t threshold = limits.collisions;
  // The next event count to return at: the limit, or the next poll (every 16 384 events) of
  // the stop flag, the wall time and the progress line.
  const std::uint64_t next_poll = (engine_.counters().events | std::uint64_t{0x3fff}) + 1;
  const std::uint64_t check_at = std::min(limits.events, next_poll);
  const double end_time = limits.phase_end_time;
  const bool clock_stops = limits.clock_stops;
  double stop = std::min(limits.next_output_time, end_time);
  // An output within round-off of the phase's end comes at the end (one row, not two).
  if (limits.phase_in_time && stop >= end_time - TimeTrigger::slack(end_time)) stop = end_time;
  Advance result;
  engine_.release_block_order();  // the outputs of the moment before are written
  for (;;) {
    if (clock_stops) {
      if (driven) apply_due_kicks(stop);
      if (!limits.phase_in_time && !driven && !(engine_.next_event_time() < kInfinity)) {
        result.stop = AdvanceStop::kNoMoreEvents;  // the collision target would never come
        return result;
      }
      if (engine_.next_event_time() > stop) {
        engine_.advance_clock(stop);
        // A system at rest passes its output times without events: the stop checks too.
        result.time_triggers = true;
        result.check_wall_time = true;
        result.update_progress = (++clock_stops_ & 0x3ffu) == 0;
        return result;
      }
    } else if (driven) {
      apply_due_kicks(kInfinity);
    }
    EventKind kind{};
    try {
      kind = engine_.step();
    } catch (const InputError& e) {
      // The event cannot happen (walls leave the particles no room): the state is that of the
      // moment before it, every output is written, the message is the run's error.
      result.stop = AdvanceStop::kError;
      result.error = e.what();
      return result;
    }
    if (kind == EventKind::kNone) {
      result.stop = AdvanceStop::kNoMoreEvents;  // every particle at rest, or alone
      return result;
    }
    if (validate_) engine_.validate();
    if (watch_.frozen(engine_)) {
      result.stop = AdvanceStop::kFrozenClock;
      result.error = watch_.describe(engine_);
      return result;
    }
    const EventCounters& c = engine_.counters();
    if (c.collisions >= threshold || engine_.time() >= end_time || c.events >= check_at ||
        stop_requested()) {
      const bool poll = c.events >= next_poll;
      result.collision_triggers = true;
      result.update_progress = poll;
      result.check_wall_time = poll;
      return result;
    }
  }
}

template <int D, class Queue>
std::string EventEngineAdapter<D, Queue>::frozen_at_end() const {
  return watch_.frozen_at_end(engine_) ? watch_.describe(engine_) : std::string();
}

// Without a field (with gravity grains gather far denser than the mean), by the events a
// collision takes: the cell crossings of a mean free path.
template <int D, class Queue>
void EventEngineAdapter<D, Queue>::check_collisions_can_happen(double collisions) const {
  if (engine_.environment().has_gravity()) return;
  double mass = 0.0;
  engine_.for_each_block(
      [&](std::size_t, auto, auto, auto m) {
        for (const double mj : m) mass += mj;
      },
      /*with_positions=*/false);
  auto n = static_cast<double>(this->size());
  double particle_volume = this->particle_volume();
  if (this->mobile() < this->size()) {
    // With fixed grains, collisions are those between the particles that move (a contact with
    // a fixed grain is a wall collision): their density, size and mass.
    n = static_cast<double>(this->mobile());
    particle_volume = mass = 0.0;
    const Environment<D>& env = engine_.environment();
    engine_.state_blocks(false).for_each(
        [&](const ParticleSystem<D>& part, std::size_t) {
          for (std::size_t j = 0; j < part.size(); ++j) {
            if (env.fixed_species(part.species.empty() ? 0u : part.species[j])) continue;
            particle_volume += ball_volume<D>(part.kinematics[j].radius);
            mass += part.mass[j];
          }
        },
        StateBlocks<D>::kKinematics | StateBlocks<D>::kIdentity);
  }
  const FlightEstimate flight =
      estimate_flight<D>(n, this->volume(), mean_volume_diameter<D>(particle_volume, n),
                         std::sqrt(2.0 * engine_.kinetic_energy() / mass));
  double width = 0.0;
  for (int a = 0; a < D; ++a) width += engine_.grid().width(a) / D;
  kairos::check_collisions_can_happen(
      1.0 + 2.0 * std::sqrt(static_cast<double>(D)) * flight.mean_free_path / width, collisions,
      flight, "events");
}

template <int D, class Queue>
double EventEngineAdapter<D, Queue>::thermal_energy() const {
  return this->kind_.sheared ? engine_.peculiar_kinetic_energy() : engine_.kinetic_energy();
}

// From the engine's state in blocks: no copy of the whole state beside it.
template <int D, class Queue>
double EventEngineAdapter<D, Queue>::momentum_scale() const {
  double scale = 0.0;
  engine_.state_blocks(false).for_each(
      [&](const ParticleSystem<D>& part, std::size_t) {
        for (std::size_t j = 0; j < part.size(); ++j)
          scale += part.mass[j] * std::sqrt(norm2(part.kinematics[j].vel));
      },
      StateBlocks<D>::kKinematics | StateBlocks<D>::kIdentity);
  return scale;
}

template <int D, class Queue>
double EventEngineAdapter<D, Queue>::max_overlap() const {
  // From the engine's cells: no copy of the positions beside it (the whole process's peak).
  if (!this->kind_.sheared) return engine_.max_overlap_now();
  const StateBlocks<D> state = engine_.state_blocks(false);
  std::vector<double> diameters(this->size());
  state.for_each(
      [&](const ParticleSystem<D>& part, std::size_t first) {
        for (std::size_t j = 0; j < part.size(); ++j)
          diameters[first + j] = 2.0 * part.kinematics[j].radius;
      },
      StateBlocks<D>::kKinematics | StateBlocks<D>::kIdentity);
  return current_max_overlap(engine_, state.globals(), diameters);
}

template <int D, class Queue>
ParticleSample<D> EventEngineAdapter<D, Queue>::particles() const {
  const ParticleSystem<D> s = engine_.export_state(/*with_zones=*/false);
  const std::size_t n = s.size();
  ParticleSample<D> out;
  out.position.resize(n);
  out.velocity.resize(n);
  out.radius.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    out.position[i] = s.position(i, s.time);
    for (int a = 0; a < D; ++a)
      if (s.periodic[a]) out.position[i][a] = wrap_into_box(out.position[i][a], s.box[a]);
    out.velocity[i] = s.velocity(i, s.time);
    out.radius[i] = s.kinematics[i].radius;
  }
  out.mass = s.mass;
  return out;
}

template <int D, class Queue>
void EventEngineAdapter<D, Queue>::peculiar_velocities(std::vector<Vec<D>>& c,
                                                       std::vector<double>& m) const {
  const std::size_t n = this->size();
  if (this->kind_.sheared) {
    c = engine_.current_velocities();
    const ParticleSystem<D> s = engine_.export_state(/*with_zones=*/false);
    for (std::size_t i = 0; i < n; ++i)
      c[i] = c[i] - engine_.environment().streaming_velocity(s.position(i, s.time), s.box);
    m = s.mass;
    return;
  }
  // Whole copies of the velocities and masses (32 bytes per particle while they are used): for
  // the analyses that need every velocity at once; thermo rows use peculiar_kinetic_tensor().
  c = engine_.current_velocities();
  m = engine_.masses();
  Vec<D> mean{};
  double mass = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    mean = mean + m[i] * c[i];
    mass += m[i];
  }
  mean = (1.0 / mass) * mean;
  for (std::size_t i = 0; i < n; ++i) c[i] = c[i] - mean;
}

// Under shear relative to the flow at each position, from whole copies; otherwise the engine's
// two passes over its records (no copy: 32 bytes per particle at every thermo row before).
template <int D, class Queue>
std::array<double, 9> EventEngineAdapter<D, Queue>::peculiar_kinetic_tensor() const {
  if (!this->kind_.sheared) return engine_.peculiar_kinetic_tensor();
  std::vector<Vec<D>> c;
  std::vector<double> m;
  peculiar_velocities(c, m);
  std::array<double, 9> tensor{};
  for (std::size_t i = 0; i < c.size(); ++i)
    for (int a = 0; a < D; ++a)
      for (int b = 0; b < D; ++b) tensor[a * D + b] += m[i] * c[i][a] * c[i][b];
  return tensor;
}

template <int D, class Queue>
double EventEngineAdapter<D, Queue>::total_energy() const {
  return less_field_term(engine_.kinetic_energy() + engine_.rotational_energy() +
                         engine_.potential_energy());
}

template <int D, class Queue>
double EventEngineAdapter<D, Queue>::field_energy() const {
  return less_field_term(0.0);
}

// e less m g.x over the particles that move, one at a time (the order total_energy() has always
// summed in); NaN when the field has a component along a periodic axis.
template <int D, class Queue>
double EventEngineAdapter<D, Queue>::less_field_term(double e) const {
  const Environment<D>& env = engine_.environment();
  if (!env.has_gravity()) return e;
  for (int a = 0; a < D; ++a)
    if (env.periodic(a) && env.gravity[a] != 0.0) return std::nan("");
  if (!fixed_.empty()) {
    // The fixed grains' potential energy never changes: left out, so that it does not swell
    // the scale of the energy balance.
    engine_.for_each_block([&](std::size_t first, auto x, auto, auto m) {
      for (std::size_t j = 0; j < x.size(); ++j)
        if (fixed_[first + j] == 0) e -= m[j] * dot(env.gravity, x[j]);
    });
    return e;
  }
  engine_.for_each_block([&](std::size_t, auto x, auto, auto m) {
    for (std::size_t j = 0; j < x.size(); ++j) e -= m[j] * dot(env.gravity, x[j]);
  });
  return e;
}

template <int D, class Queue>
void EventEngineAdapter<D, Queue>::record(RunProgress& progress, std::uint64_t, double) const {
  progress.next_kick_time = this->kind_.driven ? next_kick_ : -1.0;
  if (!tables_.empty()) progress.soft_table_max_speed = tables_.front().spec.max_normal_speed;
}

template <int D, class Queue>
void EventEngineAdapter<D, Queue>::write_restart(const std::filesystem::path& path,
                                                 const RunProgress& progress) const {
  write_restart_file(path, engine_.state_blocks(), rng_, progress);
}

template class EventEngineAdapter<2, CalendarQueue>;
template class EventEngineAdapter<3, CalendarQueue>;
template class EventEngineAdapter<2, BinaryHeapQueue>;
template class EventEngineAdapter<3, BinaryHeapQueue>;
template class EventEngineAdapter<2, TournamentTreeQueue>;
template class EventEngineAdapter<3, TournamentTreeQueue>;

}  // namespace kairos
