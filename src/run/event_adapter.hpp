// The event engine (engine/event_engine.hpp) under the run driver's Integrator interface, with
// what only an event-driven run has: driving kicks between events ([driving]), the frozen-clock
// watch after every event (run/frozen_clock.hpp), run.validate, the soft-sphere tables in use.
//
// EventIntegrator<D> is what the event engine's own outputs read (outputs/event_summary.hpp and
// its neighbours), whatever the queue; EventEngineAdapter<D, Queue> is the adapter itself.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "core/particle_system.hpp"
#include "engine/event_engine.hpp"
#include "io/config.hpp"
#include "io/config_choices.hpp"
#include "model/environment.hpp"
#include "run/frozen_clock.hpp"
#include "run/integrator.hpp"
#include "run/setup_chain.hpp"
#include "run/soft_tables_setup.hpp"

namespace kairos {

template <int D>
class EventIntegrator : public Integrator<D> {
 public:
  const char* name() const final { return "event"; }
  const EventIntegrator<D>* as_event() const final { return this; }

  virtual const EventCounters& counters() const = 0;
  virtual const Environment<D>& environment() const = 0;
  virtual const char* queue_name() const = 0;
  virtual double bytes_per_particle() const = 0;
  // Two cell levels for a wide size distribution (EngineOptions::size_levels).
  virtual bool two_level_cells() const = 0;
  virtual std::uint64_t incremental_crossing_scans() const = 0;
  virtual bool stepped() const = 0;            // [[potential]] or [[bond]]: stepped potentials
  virtual bool soft() const = 0;               // soft spheres by the collision map
  virtual std::uint32_t frozen() const = 0;    // soft contacts in progress
  virtual std::uint32_t sleeping() const = 0;  // particles asleep now
  virtual const std::vector<SoftTableUse>& tables() const = 0;  // soft spheres: in use

  // What the energy budget of summary.json's `granular` part covers (the CLI prints only the
  // lines that apply): any of walls, open faces, gravity, contact laws, driving, shear, soft
  // spheres, dissipative steps; particles that spin; dissipation; moving walls; driving.
  struct Kind {
    bool granular = false, rotating = false, dissipative = false, moving_walls = false;
    bool driven = false, sheared = false;
  };
  const Kind& kind() const { return kind_; }

  // Every particle's velocity relative to the mean (the centre-of-mass velocity, or under shear
  // the flow at its position) into `c`, and its mass into `m`, in the caller's numbering.
  virtual void peculiar_velocities(std::vector<Vec<D>>& c, std::vector<double>& m) const = 0;
  // The sum over particles of m c_a c_b (row-major, D x D used) with c as above (the kinetic
  // part of the pressure tensor times V), without a copy of the whole state where it can.
  virtual std::array<double, 9> peculiar_kinetic_tensor() const = 0;
  // The unwrapped positions now of the particles with slot[id] != ~0u, into out[slot[id]]
  // (engine/image_counters.hpp; the run keeps image counters when an analysis needs them).
  virtual void unwrapped_positions(const std::vector<std::uint32_t>& slot,
                                   std::vector<Vec<D>>& out) const = 0;
  virtual void velocities(const std::vector<std::uint32_t>& slot,
                          std::vector<Vec<D>>& out) const = 0;
  // The Helfand moments now (engine/helfand_moments.hpp; the run keeps them for
  // analysis.transport).
  virtual typename HelfandMoments<D>::Moments helfand_moments() const = 0;
  // Kinetic (translational and rotational) plus the stepped potentials' energy plus the
  // potential energy in the gravity field; NaN when the field has a component along a periodic
  // axis (unbounded there).
  virtual double total_energy() const = 0;
  // The potential energy in the gravity field alone (0 without one; NaN as above), the fixed
  // grains' left out as in total_energy().
  virtual double field_energy() const = 0;

 protected:
  using Integrator<D>::Integrator;
  Kind kind_;
};

template <int D, class Queue>
class EventEngineAdapter final : public EventIntegrator<D> {
 public:
  // Takes the start state over (resumed exactly when start.resumes(), else every event
  // predicted afresh), with its environment and the soft tables attached to it (setup chain).
  // InputError for a state the engine refuses, or one that overlaps under new physics.
  // `tracking`: what the engine keeps beyond what the configuration asks for.
  EventEngineAdapter(RunStart<D>&& start, const Environment<D>& environment,
                     std::vector<SoftTableUse> tables, const EngineTracking& tracking = {});

  double time() const override { return engine_.time(); }
  std::uint64_t collisions() const override { return engine_.counters().collisions; }
  std::uint64_t events() const override { return engine_.counters().events; }
  double virial() const override { return engine_.counters().virial; }

  Advance advance(const AdvanceLimits& limits) override;
  bool reached(double t) const override { return engine_.time() >= t; }
  double trigger_time() const override { return engine_.time(); }
  std::string frozen_at_end() const override;
  void check_collisions_can_happen(double collisions) const override;

  double thermal_energy() const override;
  double kinetic_energy() const override { return engine_.kinetic_energy(); }
  double rotational_energy() const override { return engine_.rotational_energy(); }
  double potential_energy() const override { return engine_.potential_energy(); }
  double dissipated_energy() const override {
    return engine_.counters().dissipated_in_collisions + engine_.counters().dissipated_at_walls;
  }
  double work_by_walls() const override { return engine_.counters().work_by_walls; }
  std::vector<WallReading> walls_with_mass() const override {
    return engine_.boundaries().readings(engine_.time());
  }
  std::optional<typename Integrator<D>::OutletReading> outlet() const override {
    if (engine_.environment().outlets.empty()) return std::nullopt;
    const EventCounters& c = engine_.counters();
    return typename Integrator<D>::OutletReading{c.outlet_passes, c.outlet_mass, c.outlet_energy};
  }
  Vec<D> momentum() const override { return engine_.momentum(); }
  double momentum_scale() const override;
  double max_overlap() const override;
  bool bulk() const override { return bulk_; }
  bool temperature_from_rows() const override {
    // Soft contacts hold kinetic energy while they last, as steps do.
    return engine_.stepped() || engine_.soft() || this->kind_.driven;
  }
  double held_degrees_of_freedom() const override { return engine_.held_degrees_of_freedom(); }

  StateBlocks<D> state_blocks() const override { return engine_.state_blocks(false); }
  ParticleSample<D> particles() const override;
  bool shows_present_state(const StateMark& frame, bool timed) const override {
    return frame.collisions == collisions() && (!timed || frame.time == time());
  }
  void record(RunProgress& progress, std::uint64_t phase_target,
              double phase_end_time) const override;
  void write_restart(const std::filesystem::path& path, const RunProgress& progress) const override;

  const EventCounters& counters() const override { return engine_.counters(); }
  const Environment<D>& environment() const override { return engine_.environment(); }
  const char* queue_name() const override { return engine_.queue_name(); }
  double bytes_per_particle() const override { return engine_.bytes_per_particle(); }
  bool two_level_cells() const override { return engine_.two_level_cells(); }
  std::uint64_t incremental_crossing_scans() const override {
    return engine_.incremental_crossing_scans();
  }
  bool stepped() const override { return engine_.stepped(); }
  bool soft() const override { return engine_.soft(); }
  std::uint32_t frozen() const override { return engine_.frozen(); }
  std::uint32_t sleeping() const override { return engine_.sleeping(); }
  const std::vector<SoftTableUse>& tables() const override { return tables_; }
  void peculiar_velocities(std::vector<Vec<D>>& c, std::vector<double>& m) const override;
  std::array<double, 9> peculiar_kinetic_tensor() const override;
  void unwrapped_positions(const std::vector<std::uint32_t>& slot,
                           std::vector<Vec<D>>& out) const override {
    engine_.unwrapped_positions(slot, out);
  }
  void velocities(const std::vector<std::uint32_t>& slot, std::vector<Vec<D>>& out) const override {
    engine_.velocities(slot, out);
  }
  typename HelfandMoments<D>::Moments helfand_moments() const override {
    return engine_.helfand_moments();
  }
  double total_energy() const override;
  double field_energy() const override;

  // The engine and its watch, for callers that step it themselves (run/simulation.hpp).
  EventEngine<D, Queue>& engine() { return engine_; }
  const EventEngine<D, Queue>& engine() const { return engine_; }
  FrozenClockWatch& clock_watch() { return watch_; }
  // The driving's random stream (a new engine built from this one's state takes it over).
  const std::mt19937_64& rng() const { return rng_; }
  // The Andersen thermostat's temperature from now on (the kicks drawn after this call;
  // logic_error unless [driving] is andersen). Replica exchange moves a replica to another rung.
  void set_driving_temperature(double temperature);

 private:
  double less_field_term(double e) const;
  std::vector<std::uint8_t> fixed_;  // per particle (the caller's numbering): a fixed grain
  // Stochastic driving ([driving]): Poisson events at rate N * rate, each on one random
  // particle, applied between the engine's events. The RNG and the next event's time are in
  // the restart file, so a continued run draws the same kicks.
  double draw_kick_interval();
  void apply_due_kicks(double limit);

  DrivingConfig driving_;
  DrivingKind driving_kind_;
  bool validate_ = false;
  std::mt19937_64 rng_;
  std::vector<SoftTableUse> tables_;
  EventEngine<D, Queue> engine_;
  FrozenClockWatch watch_;
  bool bulk_ = true;
  double next_kick_ = 0.0;
  std::uint64_t clock_stops_ = 0;  // outputs in time passed without an event
};

}  // namespace kairos
