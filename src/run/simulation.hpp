// A simulation held in memory and advanced on request: the integrator of `kairos run` (the
// event engine, or the DEM with run.integrator = "dem") without its output files, for scripts
// (the Python module, python/kairos_module.cpp) and tests. It starts through the same setup
// chain as `kairos run` (run/setup_chain.hpp: the same start state, contact laws, soft-sphere
// tables and integrator), so its trajectory is the CLI's bit for bit, and save() writes a
// restart file that `kairos run --restart` continues.
//
// What only the event engine has (changing the state, image counters, the Helfand moments, the
// virial tensor, the time correlations) is refused under the DEM with an InputError naming the
// call (event_integrator).
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/particle_system.hpp"
#include "core/vec.hpp"
#include "engine/helfand_moments.hpp"
#include "io/config.hpp"
#include "run/integrator.hpp"
#include "run/run_progress.hpp"
#include "run/setup_chain.hpp"

namespace kairos {

template <int D, class Queue>
class EventEngineAdapter;
template <int D>
class EventIntegrator;
template <int D>
class DemAdapter;
class CalendarQueue;

template <int D>
class Simulation {
 public:
  // From a configuration (run.integrator "event": [driving] kicks as `kairos run` draws them,
  // their random stream and next kick time kept by save(); or "dem"), or from a restart file
  // with it. InputError for anything the user must fix.
  // `tracking`: image counters and Helfand moments the event engine keeps beyond what the
  // configuration asks for (the moments: InputError for a system transport_obstacle() names, as
  // analysis.transport, and under the DEM; the DEM keeps no image counters).
  explicit Simulation(const Config& config,
                      const std::optional<std::filesystem::path>& restart_file = {},
                      const EngineTracking& tracking = {});
  ~Simulation();
  Simulation(const Simulation&) = delete;
  Simulation& operator=(const Simulation&) = delete;

  // Events until the clock reaches t (>= time()), which it then shows exactly (no event needs
  // to happen at t); the DEM: time steps until the first step at or after t (reached(t): its
  // steps are dt apart, so the clock may stand up to a step past t). Returns false if stopped early
  // by `keep_going` returning false (asked every 16 384 events, e.g. to let Python handle Ctrl-C).
  // A frozen clock (run/frozen_clock.hpp) throws InputError saying who collides and what to change;
  // the state stays readable.
  using KeepGoing = std::function<bool()>;
  bool advance_to_time(double t, const KeepGoing& keep_going = {});
  // Until `count` more events / collisions have happened (or no event is left: then false).
  // The DEM: events are time steps, and collisions pairs entering contact (several may in one
  // step: the count may pass the target); a DEM at rest whose contacts no longer begin returns
  // false from advance_collisions, as the engine with no event left.
  bool advance_events(std::uint64_t count, const KeepGoing& keep_going = {});
  bool advance_collisions(std::uint64_t count, const KeepGoing& keep_going = {});
  // Calls sample() at each multiple of `interval` in simulated time after time() up to
  // time() + duration (the clock stopped there), as `kairos run` samples analysis.msd and
  // analysis.transport (run/trigger.hpp TimeTrigger: a multiple within round-off of the end is
  // taken at the end), and ends at time() + duration. False if stopped early by keep_going.
  bool sample_every(double interval, double duration, const std::function<void()>& sample,
                    const KeepGoing& keep_going = {});
  // The same on the collision clock: sample() each `step` collisions after collisions() (the
  // engine stopped right after that collision), as `kairos run` samples analysis.msd with
  // msd_time = "collisions" (run/trigger.hpp CollisionTrigger), and ends `count` collisions on.
  bool sample_every_collisions(std::uint64_t step, std::uint64_t count,
                               const std::function<void()>& sample,
                               const KeepGoing& keep_going = {});
  // The same on the event count: sample() each `step` events after events(), and ends `count`
  // events on (false if no event was left before).
  bool sample_every_events(std::uint64_t step, std::uint64_t count,
                           const std::function<void()>& sample, const KeepGoing& keep_going = {});

  double time() const;
  std::uint64_t events() const;
  std::uint64_t collisions() const;
  // The collisional virial W = sum r_ij . J_ij over the collisions since the state's start (a
  // restart's included; the DEM: the time integral of sum r_ij . F_ij), what thermo.tsv's Z is
  // made of (analysis/thermodynamics.hpp).
  double virial() const;
  std::size_t size() const { return n_; }
  const Vec<D>& box() const;
  // Per particle, in the numbering of the configuration (or the start file), at time():
  // positions wrapped into the periodic box, velocities.
  std::vector<Vec<D>> positions() const;
  std::vector<Vec<D>> velocities() const;
  // The DEM: set_velocities, set_positions and set_species are refused (InputError).
  // Gives every particle a new velocity now (in the numbering of positions()); the events are
  // predicted anew, so the run goes on from the new velocities exactly as one started with them.
  // InputError naming the particle for a count that differs, a velocity that is not finite or
  // a fixed grain given one; with soft contacts in progress, sleeping particles or the Helfand
  // moments kept (their state follows the velocities), InputError saying so.
  void set_velocities(const std::vector<Vec<D>>& velocities);
  // Moves every particle to a new place now (the numbering of positions(); wrapped into the
  // box along periodic axes), or gives particles new species (indices into species_names(): a
  // particle whose species changes takes the radius and mass of the configuration's species of
  // that name; the others keep theirs). Velocities, spins, counters,
  // image counters and the clock stay; every event is predicted anew from the new state, as a
  // run started from it would (the driving's next kick is drawn anew from its stream).
  // InputError naming the particle for a count that differs, a value that is not finite, a
  // species that is not in the configuration or a change to or from a fixed species; naming
  // the pair for an overlap; the engine's message for a wall or a bond the new state breaks.
  // Refused with soft spheres, sleeping particles, the Helfand moments kept, or under shear.
  void set_positions(const std::vector<Vec<D>>& positions);
  void set_species(const std::vector<std::uint32_t>& species);
  // [driving] kind "andersen": the thermostat's temperature from now on (the configuration's
  // driving.temperature, also as save() stores it). InputError without an Andersen thermostat
  // or for a temperature outside driving.temperature's range. The velocities are not changed.
  void set_thermostat_temperature(double temperature);
  const std::vector<double>& masses() const { return mass_; }
  const std::vector<double>& radii() const { return radius_; }
  const std::vector<std::uint32_t>& species() const { return species_; }
  const std::vector<std::string>& species_names() const { return species_names_; }
  double kinetic_energy() const;
  // kT as thermo.tsv gives it (analysis/thermodynamics: D (N - 1) degrees of freedom; under
  // shear, of the velocities relative to the flow).
  double temperature() const;
  // Of the stepped potentials, or the elastic energy of soft contacts in progress.
  double potential_energy() const;
  // The energies now and the work and dissipation since the state's start (a restart's
  // included), as summary.json's energy budget adds them up: kinetic (translational) and
  // rotational; potential (the stepped potentials', or the elastic energy of soft contacts);
  // field (in gravity, -sum m g.x over the particles that move; NaN along a periodic axis, 0
  // without); dissipated (in collisions and at walls; the DEM: the damping's and friction's
  // work); work_by_walls (what moving walls gave the particles), work_by_driving ([driving]
  // kicks), work_by_shear (Lees-Edwards images), taken_out (what particles took out through an
  // outlet). kinetic + rotational + potential + field + dissipated + taken_out - work_by_walls -
  // work_by_driving - work_by_shear is constant (to round-off for the event engine, to O(dt^2)
  // for the DEM; under shear with box-frame velocities).
  struct Energies {
    double kinetic = 0.0, rotational = 0.0, potential = 0.0, field = 0.0;
    double dissipated = 0.0, work_by_walls = 0.0, work_by_driving = 0.0, work_by_shear = 0.0;
    double taken_out = 0.0;
  };
  Energies energies() const;
  Vec<D> momentum() const;
  // The largest overlap of any pair now (0 for hard particles up to round-off).
  double max_overlap() const;
  // The walls with mass now (boundaries/wall_body.hpp): face, position, speed, energy.
  std::vector<WallReading> walls_with_mass() const;
  // The complete state (what a restart file holds).
  ParticleSystem<D> state() const;

  // Image counters are kept (EngineTracking::images, output.trajectory or analysis.msd, or a
  // start state that carried them): 4 D bytes per particle.
  bool tracks_images() const;
  // Per particle, at time(): the positions unwrapped (position + image * box along periodic
  // axes), and the images of positions(), so that positions() + images() * box is the unwrapped
  // position up to round-off. InputError without image counters; unwrapped_positions() also
  // under Lees-Edwards shear (as analysis.msd).
  std::vector<Vec<D>> unwrapped_positions() const;
  std::vector<std::array<std::int32_t, D>> images() const;
  // The Helfand moments are kept (EngineTracking::helfand or analysis.transport).
  bool tracks_helfand() const;
  // The Helfand moments at time(), from the start of this Simulation (InputError unless kept),
  // and their collisional momentum part: the virial tensor sum r_ij,a dp_i,b (row-major D x D,
  // since the state's start: a restart's included).
  typename HelfandMoments<D>::Moments helfand_moments() const;
  const std::array<double, 9>& virial_tensor() const;
  // The integrator under the run driver's interface, for the analyses
  // (run/simulation_analyses.hpp).
  const Integrator<D>& integrator() const { return *integrator_; }
  // The event engine's; InputError naming `what` under the DEM.
  const EventIntegrator<D>& event_integrator(const char* what) const;
  bool dem() const { return dem_ != nullptr; }
  // The compression that made the start state ([compress], or a random start denser than
  // insertion reaches): what it did and the packing's contact network; null if none.
  const CompressionReport* compression() const { return compression_ ? &*compression_ : nullptr; }
  // The effective configuration (after a restart: as continued).
  const Config& config() const { return config_; }
  // A restart file (atomically) that `kairos run --restart` continues bit-identically.
  void save(const std::filesystem::path& path) const;

 private:
  // Advances within `limits` until done() holds: true then; false if no event was left or
  // keep_going said stop.
  bool advance_within(const AdvanceLimits& limits, const std::function<bool()>& done,
                      const KeepGoing& keep_going);
  // sample() every `step` of a count (collisions or events: `now`) for `count` more, each
  // stretch advanced by advance(n).
  bool sample_every_count(std::uint64_t step, std::uint64_t count,
                          const std::function<std::uint64_t()>& now,
                          const std::function<bool(std::uint64_t)>& advance,
                          const std::function<void()>& sample);

  // A new engine from the present state changed by `change` (set_positions, set_species).
  void rebuild(const char* what, const std::function<void(ParticleSystem<D>&)>& change);
  // The configuration's entry of each of the state's species names (nullptr: none).
  std::vector<const SpeciesConfig*> config_species() const;
  // The refusals set_velocities shares with rebuild.
  void check_state_can_change(const char* what) const;

  // The event engine's adapter, the non-owning view of integrator_ that the event-only calls
  // use (the refusal under the DEM).
  EventEngineAdapter<D, CalendarQueue>& event_engine(const char* what) const;

  Config config_;
  EngineTracking tracking_;
  std::unique_ptr<Integrator<D>> integrator_;
  EventEngineAdapter<D, CalendarQueue>* engine_ = nullptr;  // null under the DEM
  const DemAdapter<D>* dem_ = nullptr;                      // null under the event engine
  RunProgress progress_;
  std::optional<CompressionReport> compression_;
  std::size_t n_ = 0;
  std::vector<double> mass_, radius_;
  std::vector<std::uint32_t> species_;
  std::vector<std::string> species_names_;
};

}  // namespace kairos
