#include "run/dem_adapter.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <vector>

#include "core/periodic.hpp"
#include "init/initial_state.hpp"
#include "run/collision_estimate.hpp"

namespace kairos {

namespace {

template <int D>
DemOptions dem_options(const RunStart<D>& start) {
  DemOptions options;
  // A continued run keeps its time step unless run.time_step sets one.
  options.dt = start.config.run.time_step > 0.0 ? start.config.run.time_step
               : start.restarted()              ? start.resumed.dem_time_step
                                                : 0.0;
  return options;
}

}  // namespace

template <int D>
DemAdapter<D>::DemAdapter(RunStart<D>&& start, const Environment<D>& environment)
    : Integrator<D>(start.state),
      rng_(start.rng),
      dem_(start.state, environment, dem_options(start)),
      base_events_(start.state.counters.events),
      time_step_automatic_(start.config.run.time_step == 0.0) {
  const auto damped = [](const SoftContactLaw& law) { return law.damping > 0.0; };
  // Walls and gravity, like damping, make the energy budget worth reporting.
  const auto rough = [](const SoftFriction& f) { return f.coefficient > 0.0; };
  const Environment<D>& env = environment;
  kind_.dissipative = std::any_of(env.soft.begin(), env.soft.end(), damped);
  kind_.rotating = std::any_of(env.soft_friction.begin(), env.soft_friction.end(), rough);
  kind_.gravity = env.has_gravity();
  kind_.walls = env.has_walls();
  kind_.granular = kind_.dissipative || kind_.rotating || kind_.walls || kind_.gravity;
  for (int f = 0; f < 2 * D; ++f)
    kind_.moving_walls =
        kind_.moving_walls || (env.faces[f].kind == FaceKind::kWall &&
                               (env.wall_moves(f) || norm2(env.faces[f].wall.velocity) > 0.0));
  for (const double m : start.state.mass) total_mass_ += m;
  // About 2^20 particle-steps between checks of the clock and the stop flag.
  chunk_ =
      std::max<long>(1, (1l << 20) / static_cast<long>(std::max<std::size_t>(1, this->size())));
}

// Steps until the first step at or after time t (at least one).
template <int D>
long DemAdapter<D>::steps_to(double t) const {
  const double steps = std::ceil((t - dem_.time()) / dem_.dt() - 1e-9);
  return steps < 1.0 ? 1l
         : steps > static_cast<double>(std::numeric_limits<long>::max() / 2)
             ? std::numeric_limits<long>::max() / 2
             : static_cast<long>(steps);
}

template <int D>
Advance DemAdapter<D>::advance(const AdvanceLimits& limits) {
  long n = chunk_;
  if (limits.phase_in_time) n = std::min(n, steps_to(limits.phase_end_time));
  n = std::min(n, steps_to(limits.next_output_time));
  // A count of events (an in-memory Simulation advancing by time steps): up to it, and never
  // stopped for rest (steps always happen). The run driver never sets it.
  const bool by_events = limits.events != AdvanceLimits{}.events;
  if (by_events && limits.events > events())
    n = std::min<long>(n, static_cast<long>(std::min<std::uint64_t>(
                              limits.events - events(), static_cast<std::uint64_t>(chunk_))));
  const std::uint64_t before = dem_.collisions(), wall_before = dem_.wall_collisions();
  // A step the DEM cannot take (a pair overlapping by more than half its smaller radius: the
  // time step far too large) throws InputError out of the run: its state is no longer one to
  // write (the event engine's failed events leave the state before them).
  dem_.step_until(n, limits.collisions);
  const std::uint64_t c = dem_.collisions();
  const double ke = dem_.kinetic_energy();
  ke_peak_ = std::max(ke_peak_, ke);
  Advance result;
  // A length in collisions would never end once nothing moves or meets any more; a length in
  // time does.
  const bool counts_collisions = !limits.phase_in_time && !by_events;
  if (counts_collisions && c == before && dem_.contact_count() == 0 && ke == 0.0) {
    result.stop = AdvanceStop::kNoMoreEvents;  // everything at rest and apart
    return result;
  }
  // A settled packing (under gravity, between walls) meets no new contacts: the collision
  // target would never come. At rest: no contact began in this chunk and the kinetic energy
  // fell below 1e-12 of its peak.
  if (counts_collisions && c == before && dem_.wall_collisions() == wall_before &&
      ke <= 1e-12 * ke_peak_) {
    result.stop = AdvanceStop::kAtRest;
    return result;
  }
  result.collision_triggers = result.time_triggers = true;
  result.update_progress = result.check_wall_time = true;
  return result;
}

// The first phase of a continued run starts where the saved run nominally stopped; a phase
// after one in time from that phase's nominal end (its last step may have passed it).
template <int D>
void DemAdapter<D>::count_phase_from(std::uint64_t& collisions, double& time, bool first,
                                     bool restarted, const RunProgress& resumed,
                                     double previous_end_time) const {
  if (!first && std::isfinite(previous_end_time) && reached(previous_end_time) &&
      previous_end_time > time - dem_.dt())
    time = previous_end_time;
  if (restarted && first && resumed.dem_collision_mark > 0 &&
      resumed.dem_collision_mark <= collisions)
    collisions = resumed.dem_collision_mark;
  if (restarted && first && resumed.dem_time_mark <= time &&
      resumed.dem_time_mark > time - dem_.dt())
    time = resumed.dem_time_mark;
}

// As the event engine's: phases in collisions in a system that hardly collides refused, here by
// the time steps a collision would take.
template <int D>
void DemAdapter<D>::check_collisions_can_happen(double collisions) const {
  if (kind_.gravity) return;
  const auto n = static_cast<double>(this->size());
  const FlightEstimate flight =
      estimate_flight<D>(n, this->volume(), mean_volume_diameter<D>(this->particle_volume(), n),
                         std::sqrt(2.0 * dem_.kinetic_energy() / total_mass_));
  kairos::check_collisions_can_happen(1.0 + flight.mean_free_time / dem_.dt(), collisions, flight,
                                      "time steps");
}

template <int D>
double DemAdapter<D>::momentum_scale() const {
  const ParticleSystem<D> state = dem_.export_state();
  double scale = 0.0;
  for (std::size_t i = 0; i < state.size(); ++i)
    scale += state.mass[i] * std::sqrt(norm2(state.kinematics[i].vel));
  return scale;
}

template <int D>
double DemAdapter<D>::max_overlap() const {
  const ParticleSystem<D> state = dem_.export_state();
  std::vector<Vec<D>> x(state.size());
  std::vector<double> diameters(state.size());
  for (std::size_t i = 0; i < state.size(); ++i) {
    x[i] = dem_.position(i);
    diameters[i] = 2.0 * state.kinematics[i].radius;
  }
  return kairos::max_overlap<D>(state.box, state.periodic, x, diameters);
}

template <int D>
StateBlocks<D> DemAdapter<D>::state_blocks() const {
  auto whole = std::make_shared<ParticleSystem<D>>(dem_.export_state());
  StateBlocks<D> blocks = StateBlocks<D>::of(*whole);
  blocks.globals_ = whole;  // the blocks own the export they read
  return blocks;
}

template <int D>
ParticleSample<D> DemAdapter<D>::particles() const {
  const ParticleSystem<D> s = dem_.export_state();
  const std::size_t n = s.size();
  ParticleSample<D> out;
  out.position.resize(n);
  out.velocity.resize(n);
  out.radius.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    out.position[i] = dem_.position(i);
    out.velocity[i] = dem_.velocity(i);
    out.radius[i] = s.kinematics[i].radius;
  }
  out.mass = s.mass;
  return out;
}

template <int D>
double DemAdapter<D>::total_energy() const {
  return dem_.kinetic_energy() + dem_.rotational_energy() + dem_.potential_energy() +
         dem_.field_energy() + dem_.dissipated_energy() + dem_.dissipated_at_walls() +
         dem_.outlet_energy() - dem_.work_by_walls();
}

template <int D>
void DemAdapter<D>::record(RunProgress& progress, std::uint64_t phase_target,
                           double phase_end_time) const {
  progress.integrator = "dem";
  progress.dem_time_step = dem_.dt();
  // A completed phase ends at its target (the count may have passed it within the last step).
  const std::uint64_t c = dem_.collisions();
  progress.dem_collision_mark = c >= phase_target ? phase_target : c;
  if (std::isfinite(phase_end_time))
    progress.dem_time_mark = reached(phase_end_time) ? phase_end_time : dem_.time();
}

// With the integrator's checkpoint (a bit-identical continuation) and no scheduler state.
template <int D>
void DemAdapter<D>::write_restart(const std::filesystem::path& path,
                                  const RunProgress& progress) const {
  ParticleSystem<D> s = dem_.export_state();
  s.dem = dem_.checkpoint();
  const std::size_t n = s.size();
  s.events.assign(n, EventSlot{});  // a DEM state has no scheduler: empty event slots, never read
  s.cell.assign(n, 0);
  s.collision_count.resize(n, 0);
  write_restart_file(path, s, rng_, progress);
}

template class DemAdapter<2>;
template class DemAdapter<3>;

}  // namespace kairos
