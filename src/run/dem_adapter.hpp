// run.integrator = "dem": the force-based DemIntegrator (dem/dem_integrator.hpp: velocity
// Verlet, soft contact forces of [soft]) under the run driver's Integrator interface, so that
// it runs as the event engine does: the same outputs, lengths and intervals.
//
// A collision is a pair entering contact (DemIntegrator::collisions()); `events` are time
// steps. The integrator steps in chunks of about 2^20 particle-steps, stopping early at the
// step in which the next output or the phase's end is due: several pairs may enter contact in
// one step, so a count in collisions is met at or past its threshold, and a time at the first
// step at or after it (reached()).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <random>
#include <string>

#include "dem/dem_integrator.hpp"
#include "io/config.hpp"
#include "model/environment.hpp"
#include "run/integrator.hpp"
#include "run/setup_chain.hpp"

namespace kairos {

template <int D>
class DemAdapter final : public Integrator<D> {
 public:
  // A continued run keeps its time step unless run.time_step sets one; a re-predicted state
  // (new physics) starts the integrator afresh (its lists and tangential springs dropped).
  // InputError for what the DEM does not integrate.
  DemAdapter(RunStart<D>&& start, const Environment<D>& environment);

  const char* name() const override { return "dem"; }
  const DemAdapter<D>* as_dem() const override { return this; }

  double time() const override { return dem_.time(); }
  std::uint64_t collisions() const override { return dem_.collisions(); }
  std::uint64_t events() const override {
    return base_events_ + static_cast<std::uint64_t>(dem_.steps());
  }
  double virial() const override { return dem_.virial(); }

  Advance advance(const AdvanceLimits& limits) override;
  // A time is reached at the first step at or after it (round-off aside: time_at(steps) need
  // not hit a multiple of dt).
  bool reached(double t) const override { return dem_.time() >= t - 1e-9 * dem_.dt(); }
  double trigger_time() const override { return dem_.time() + 1e-9 * dem_.dt(); }
  void count_phase_from(std::uint64_t& collisions, double& time, bool first, bool restarted,
                        const RunProgress& resumed, double previous_end_time) const override;
  void check_collisions_can_happen(double collisions) const override;

  double thermal_energy() const override { return dem_.kinetic_energy(); }
  double kinetic_energy() const override { return dem_.kinetic_energy(); }
  double rotational_energy() const override { return dem_.rotational_energy(); }
  double potential_energy() const override { return dem_.potential_energy(); }
  double dissipated_energy() const override {
    return dem_.dissipated_energy() + dem_.dissipated_at_walls();
  }
  double work_by_walls() const override { return dem_.work_by_walls(); }
  std::vector<WallReading> walls_with_mass() const override { return dem_.walls_with_mass(); }
  std::optional<typename Integrator<D>::OutletReading> outlet() const override {
    if (!dem_.any_outlet()) return std::nullopt;
    return typename Integrator<D>::OutletReading{dem_.outlet_passes(), dem_.outlet_mass(),
                                                 dem_.outlet_energy(),
                                                 static_cast<std::int64_t>(dem_.outlet_waiting())};
  }
  Vec<D> momentum() const override { return dem_.momentum(); }
  double momentum_scale() const override;
  double max_overlap() const override;
  bool bulk() const override { return !kind_.gravity && !kind_.walls; }
  // Kinetic energy is exchanged with the overlaps.
  bool temperature_from_rows() const override { return true; }

  StateBlocks<D> state_blocks() const override;
  ParticleSample<D> particles() const override;
  // Every step moves the state: the frame shows it when no step came after it.
  bool shows_present_state(const StateMark& frame, bool) const override {
    return frame.events == events();
  }
  void record(RunProgress& progress, std::uint64_t phase_target,
              double phase_end_time) const override;
  void write_restart(const std::filesystem::path& path, const RunProgress& progress) const override;

  const DemIntegrator<D>& dem() const { return dem_; }
  // Time steps of the runs this one continues (the state's event counter at the start).
  std::uint64_t base_events() const { return base_events_; }
  bool time_step_automatic() const { return time_step_automatic_; }
  // Kinetic plus elastic plus gravitational energy plus what the damping took and the outlets
  // took out, less what the walls gave: constant to O(dt^2) (NaN with gravity along a periodic
  // axis).
  double total_energy() const;
  // What summary.json's energy budget covers: damping, friction, walls or gravity; particles
  // that spin (friction); damping; moving walls.
  struct Kind {
    bool granular = false, rotating = false, dissipative = false, moving_walls = false;
    bool gravity = false, walls = false;
  };
  const Kind& kind() const { return kind_; }

 private:
  long steps_to(double t) const;

  std::mt19937_64 rng_;
  DemIntegrator<D> dem_;
  std::uint64_t base_events_ = 0;
  double total_mass_ = 0.0;
  bool time_step_automatic_ = false;
  Kind kind_;
  long chunk_ = 1;        // time steps between the driver's checks
  double ke_peak_ = 0.0;  // the largest kinetic energy seen (the scale of "at rest")
};

}  // namespace kairos
