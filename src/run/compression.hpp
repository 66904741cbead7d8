// Compression by growth (Lubachevsky-Stillinger; docs/physics.md#growing-spheres): every diameter
// grows as sigma_i(t) = sigma_i(0) (1 + rate t) in a periodic box (or between fixed walls on its
// faces) of elastic hard spheres, the velocities are rescaled to a set temperature at intervals,
// and the run stops at a target packing fraction, a target reduced pressure, or when the packing
// jams (the reduced pressure, or the collision rate, above a threshold). The event engine moves the
// particles (EngineOptions::growth_rate); this protocol owns the rescalings, the pressure per
// interval, the stopping rules, and rebuilds the engine with wider cells when the grown particles
// no longer fit its cells.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "analysis/contact_network.hpp"
#include "core/particle_system.hpp"
#include "io/config.hpp"
#include "model/environment.hpp"

namespace kairos {

struct CompressionSettings {
  double growth_rate = 0.01;             // relative growth of the starting diameters per unit time
  double temperature = 1.0;              // kT the velocities are rescaled to
  double thermostat_interval = 10.0;     // collisions per particle between rescalings
  double target_packing_fraction = 0.0;  // stop there (0: no target)
  double target_pressure = 0.0;          // stop at this reduced pressure Z = PV/(NkT) (0: none)
  double jammed_pressure = 1e12;         // jammed: Z above this
  // Jammed also when the collision rate per particle exceeds this, in units of sqrt(kT/m)/sigma
  // (sigma the mean diameter now, m the mean mass; 0: not used): near jamming it diverges as
  // the pressure does, while the packing fraction no longer grows.
  double jammed_collision_rate = 0.0;
  // Jamming is one of the targets: reaching it before target_packing_fraction is no error.
  bool jammed_is_a_target = false;
  // Above this reduced pressure the growth slows as sqrt(slowdown_pressure / Z) (0: never):
  // near jamming, loose regions need time to settle before the growth closes their gaps, or
  // the packing jams with fewer contacts than isostatic.
  double slowdown_pressure = 100.0;
  double slowdown_floor = 0.1;  // ... down to this fraction of growth_rate
  double cell_margin = 0.1;     // cells this fraction wider than the largest diameter: growth room
  bool size_levels = true;      // EngineOptions::size_levels (run.size_levels)
};

// One thermostat interval: the moment of its rescaling and what it measured.
struct CompressionRow {
  double time = 0.0;              // compression time at the interval's end
  double packing_fraction = 0.0;  // at its end
  double pressure = 0.0;          // reduced pressure Z = PV/(NkT) over the interval
  // Collisions per particle per unit time over the interval, in units of sqrt(kT/m)/sigma
  // (CompressionSettings::jammed_collision_rate).
  double collision_rate = 0.0;
  double temperature = 0.0;      // kT at its end, before the rescaling
  std::uint64_t collisions = 0;  // since the compression began
};

struct CompressionResult {
  std::vector<CompressionRow> rows;
  // "packing_fraction", "pressure", "jammed" (by the pressure) or "collision_rate" (jammed by
  // the collision rate)
  std::string stop_reason;
  double packing_fraction = 0.0;
  double pressure = 0.0;        // the last interval's (0 if it ended before the first)
  double collision_rate = 0.0;  // the last interval's (CompressionRow::collision_rate)
  double time = 0.0;
  std::uint64_t collisions = 0;
  std::uint64_t rebuilds = 0;  // engines built with wider cells after the first
  std::uint64_t rescalings = 0;
  double initial_packing_fraction = 0.0;
  // How much the diameters grew: the state comes back with its starting diameters in a box
  // (and positions) shrunk by this factor.
  double diameter_scale = 1.0;
};

// Sum of the particle volumes over the box volume.
template <int D>
double state_packing_fraction(const ParticleSystem<D>& state);

// Grows the particles of `state` (the start state of a run) until a stop rule holds, in a
// periodic box or one with fixed, elastic, smooth walls on some faces (`environment`; its other
// parts must be those of elastic hard spheres). With walls, the reduced pressure is the mean of
// the pressure tensor's diagonal: along a periodic axis from the virial, along an axis between
// walls from the impulse the walls take (docs/physics.md#growing-spheres). The state comes back as
// a fresh start: positions and velocities at time 0, grown packing and its starting diameters (the
// box and the positions shrunk by the growth, so that lengths keep their unit), no scheduler state,
// counters zero, velocities at `temperature`. InputError for a system growth cannot run (open
// faces, moving walls, a target below the start) or bad settings; polls the stop flag at every
// interval (Interrupted). `row` sees each interval as it ends.
template <int D>
CompressionResult compress(ParticleSystem<D>& state, const CompressionSettings& settings,
                           const std::function<void(const CompressionRow&)>& row = {},
                           const Environment<D>& environment = {});

// A run's compression ([compress]): what it was asked, what it did, and the contact network
// of the packing it left (docs/outputs.md, "Compression").
struct CompressionReport {
  CompressionSettings settings;
  CompressionResult result;
  // The contact network, when the packing is near jamming (Z at least 10^6) or contact_gap was
  // given: far from jamming touching and open pairs are not told apart by their gaps.
  bool has_network = false;
  ContactNetwork network;
  // The packing's global bond order (analysis/structure.hpp bond_order: q4, q6 in 3D, psi6 in
  // 2D), neighbours closer than kBondCutoff contact distances (analysis.bond_cutoff's default):
  // glass or crystal.
  static constexpr double kBondCutoff = 1.4;
  std::vector<std::string> order_names;
  std::vector<double> order;
  double wall_seconds = 0.0;
};

// Where a run's start grows: the run's box with its walls on the faces, each held still,
// elastic and smooth (what the walls do in the run, and every other part of `run`, starts
// after the compression); open faces kept (growth refuses them).
template <int D>
Environment<D> growth_environment(const Environment<D>& run);

// The settings of [compress] for a start at temperature kT.
CompressionSettings compression_settings(const CompressConfig& config, double temperature);

// Compresses the start state of a run as [compress] asks and analyses the packing. `tell`:
// a line on stderr every ten seconds (a long compression is not silent).
// size_levels: run.size_levels (EngineOptions::size_levels); environment: the run's walls.
template <int D>
CompressionReport compress_start(ParticleSystem<D>& state, const CompressConfig& config,
                                 double temperature, bool tell, bool size_levels = true,
                                 const Environment<D>& environment = {});

}  // namespace kairos
