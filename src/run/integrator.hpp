// What the run driver (run/run_driver.hpp) runs: a small interface over the two integrators,
// the event engine (run/event_adapter.hpp) and the DEM (run/dem_adapter.hpp), as HOOMD's
// integrators sit under its Operations.
//
// The driver calls advance() once per batch of events or time steps, never per event: the
// adapter runs its events in a tight loop of its own (non-virtual) and returns when something
// the driver must see may have happened (a threshold of an output or of the phase, the stop
// flag, a poll of the progress line). Everything else here is asked once per output.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "analysis/thermodynamics.hpp"
#include "boundaries/wall_body.hpp"
#include "core/particle_system.hpp"
#include "core/state_blocks.hpp"
#include "core/vec.hpp"
#include "run/run_progress.hpp"

namespace kairos {

// What the driver asks of one call to Integrator::advance.
struct AdvanceLimits {
  static constexpr double kNoTime = std::numeric_limits<double>::infinity();
  // Return once the collision count has reached this (the phase's target, the next output due
  // in collisions).
  std::uint64_t collisions = ~std::uint64_t{0};
  // Return once the event count has reached this (an in-memory Simulation advancing by events;
  // the DEM's events are its time steps).
  std::uint64_t events = ~std::uint64_t{0};
  // The soonest output due in simulated time (infinity: none).
  double next_output_time = kNoTime;
  // A phase measured in simulated time: its end (else infinity).
  double phase_end_time = kNoTime;
  bool phase_in_time = false;
  // Outputs or the phase's end in simulated time: the event engine stops its clock at them
  // between two events (EventEngine::advance_clock), so that they fall on exact times.
  bool clock_stops = false;
};

// Why advance() stopped the phase (kNone: it did not).
enum class AdvanceStop {
  kNone,
  kNoMoreEvents,  // nothing moves or meets any more (a length in collisions would never end)
  kAtRest,        // DEM: no contact begins and the kinetic energy is gone (a settled pile)
  kFrozenClock,   // events go on but the clock does not (run/frozen_clock.hpp)
  kError,         // an event that cannot happen (walls that leave no room, a step too large)
};

// What one call to advance() did, and so what the driver checks now.
struct Advance {
  AdvanceStop stop = AdvanceStop::kNone;
  std::string error;  // kFrozenClock, kError: why, and what to change
  // Which triggers may be due: those in collisions (events or steps happened), those in time
  // (the clock stopped at an output time, or steps passed one).
  bool collision_triggers = false, time_triggers = false;
  bool update_progress = false;  // time to redraw the progress line
  bool check_wall_time = false;  // time to compare the wall clock with run.max_wall_seconds
};

// Every particle's present position (wrapped into the box along periodic axes), velocity, mass
// and radius, in the caller's numbering: what analyses over particles read (the profile).
template <int D>
struct ParticleSample {
  std::vector<Vec<D>> position, velocity;
  std::vector<double> mass, radius;
};

// The state a trajectory frame showed (outputs/trajectory_output.hpp).
struct StateMark {
  std::uint64_t events = 0, collisions = 0;
  double time = 0.0;
};

template <int D>
class EventIntegrator;
template <int D>
class DemAdapter;

template <int D>
class Integrator {
 public:
  virtual ~Integrator() = default;
  Integrator(const Integrator&) = delete;
  Integrator& operator=(const Integrator&) = delete;

  // run.integrator: "event" or "dem".
  virtual const char* name() const = 0;
  // The same object as its own kind, for the outputs only that kind has (outputs/registry.cpp);
  // null for the other kind.
  virtual const EventIntegrator<D>* as_event() const { return nullptr; }
  virtual const DemAdapter<D>* as_dem() const { return nullptr; }

  // The system, as it started (the box does not change).
  std::size_t size() const { return n_; }
  // The particles that move: all but the fixed grains (docs/physics.md#fixed-grains). The
  // temperature's degrees of freedom and the lengths per particle count these.
  std::size_t mobile() const { return n_ - fixed_; }
  const Vec<D>& box() const { return box_; }
  double volume() const { return volume_; }
  double particle_volume() const { return particle_volume_; }  // sum over particles

  // Counters since the simulation began (across restarts). events: the DEM's time steps.
  virtual double time() const = 0;
  virtual std::uint64_t collisions() const = 0;
  virtual std::uint64_t events() const = 0;
  virtual double virial() const = 0;
  ThermoPoint point() const { return {time(), virial(), events(), collisions()}; }

  // Runs events (time steps) until `limits` or something the driver must see (Advance).
  virtual Advance advance(const AdvanceLimits& limits) = 0;
  // Whether the clock has reached t: the event engine's exactly; the DEM's at the first step at
  // or after t (its steps are dt apart).
  virtual bool reached(double t) const = 0;
  // The time triggers in simulated time compare with (the DEM's within round-off of its step).
  virtual double trigger_time() const = 0;
  // Where a phase starts counting its length: from where the integrator stands (collisions,
  // time), unless its steps pass targets (the DEM), which count from the previous phase's
  // nominal end (previous_end_time) or, in a continued run's first phase (first, restarted),
  // from the marks its restart file recorded.
  virtual void count_phase_from(std::uint64_t& /*collisions*/, double& /*time*/, bool /*first*/,
                                bool /*restarted*/, const RunProgress& /*resumed*/,
                                double /*previous_end_time*/) const {}
  // At the end of a run too short for the frozen-clock watch: why the clock never moved (a
  // start in contact: run/frozen_clock.hpp), else "".
  virtual std::string frozen_at_end() const { return {}; }
  // Phases measured in collisions need a system that collides: InputError if the ideal-gas
  // estimate says `collisions` would take practically for ever (run/collision_estimate.hpp).
  virtual void check_collisions_can_happen(double collisions) const = 0;

  // Energies now. thermal: the kinetic energy that makes the temperature (under shear: of the
  // velocities relative to the flow). dissipated: in collisions and at walls since the
  // simulation began (the DEM: the work of the damping forces); work_by_walls likewise.
  virtual double thermal_energy() const = 0;
  // Degrees of freedom that contacts in progress hold still, which the temperature does not
  // count (the event engine's frozen soft contacts: D per pair, 1 against a wall; in
  // equilibrium the rest carry kT/2 each: docs/physics.md#temperature).
  virtual double held_degrees_of_freedom() const { return 0.0; }
  virtual double kinetic_energy() const = 0;
  virtual double rotational_energy() const = 0;
  virtual double potential_energy() const = 0;
  virtual double dissipated_energy() const = 0;
  virtual double work_by_walls() const = 0;
  // The walls with mass now (boundaries/wall_body.hpp), box faces in order: none by default.
  virtual std::vector<WallReading> walls_with_mass() const { return {}; }
  // Outlets (boundary.outlet): the particles that passed and were put back so far, their mass
  // and the energy they took out (EventCounters::outlet_*); nullopt without an outlet.
  struct OutletReading {
    std::uint64_t passes = 0;
    double mass = 0.0, energy = 0.0;
    // The DEM: particles beyond an outlet's plane that still touch something and wait to pass
    // (DemIntegrator::outlet_waiting); -1 for the event engine, which passes them at once.
    std::int64_t waiting = -1;
  };
  virtual std::optional<OutletReading> outlet() const { return std::nullopt; }
  virtual Vec<D> momentum() const = 0;
  // Sum of m |v| over the particles: the scale of the momentum drift.
  virtual double momentum_scale() const = 0;
  // The largest overlap of any pair now (no periodic image along bounded axes).
  virtual double max_overlap() const = 0;
  // Periodic without a field: Z, P and a2 are bulk values.
  virtual bool bulk() const = 0;
  // Kinetic energy turns into potential energy or heat, or a thermostat sets it: the production
  // temperature is the mean over the production rows, not the kinetic one at its start.
  virtual bool temperature_from_rows() const = 0;

  // The state in blocks (core/state_blocks.hpp), for trajectory frames and sums over particles.
  virtual StateBlocks<D> state_blocks() const = 0;
  virtual ParticleSample<D> particles() const = 0;
  // Whether `frame` (a trajectory frame's state) is the present state. timed: some length or
  // interval is in simulated time (states with the same collision count then differ).
  virtual bool shows_present_state(const StateMark& frame, bool timed) const = 0;
  // What the restart file records of the integrator (its RNG draws, time step, marks), given
  // the phase's target collision count and end time (infinity: in collisions).
  virtual void record(RunProgress& progress, std::uint64_t phase_target,
                      double phase_end_time) const = 0;
  // The restart file (atomically): the exact state, the RNG and `progress`.
  virtual void write_restart(const std::filesystem::path& path,
                             const RunProgress& progress) const = 0;

 protected:
  // The sizes of the start state (read before an engine takes the state over).
  // How many of the particles are fixed grains (set once by the integrator that knows).
  void set_fixed(std::size_t fixed) { fixed_ = fixed; }
  explicit Integrator(const ParticleSystem<D>& start) : n_(start.size()), box_(start.box) {
    for (int a = 0; a < D; ++a) volume_ *= start.box[a];
    for (const auto& k : start.kinematics) {
      particle_volume_ += D == 3 ? 4.0 / 3.0 * std::numbers::pi * k.radius * k.radius * k.radius
                                 : std::numbers::pi * k.radius * k.radius;
    }
  }

 private:
  std::size_t n_ = 0;
  std::size_t fixed_ = 0;
  Vec<D> box_{};
  double volume_ = 1.0, particle_volume_ = 0.0;
};

}  // namespace kairos
