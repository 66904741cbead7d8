// The automatic sampling interval of the time-correlation analyses (analysis.msd,
// analysis.transport): half the Enskog estimate of the mean free time at the start, the
// ideal-gas flight of the particles' rms speed over the contact value (docs/config.md).
#pragma once

#include <cmath>
#include <string>

#include "analysis/granular_theory.hpp"
#include "core/error.hpp"
#include "run/collision_estimate.hpp"
#include "run/event_adapter.hpp"

namespace kairos {

// `key`: the analysis's interval key, named when the particles do not move.
template <int D>
double half_enskog_mean_free_time(const EventIntegrator<D>& engine, const std::string& key) {
  const auto n = static_cast<double>(engine.size());
  double v2 = 0.0;
  engine.state_blocks().for_each(
      [&](const ParticleSystem<D>& part, std::size_t) {
        for (std::size_t j = 0; j < part.size(); ++j) v2 += norm2(part.velocity(j, part.time));
      },
      StateBlocks<D>::kKinematics);
  const double eta = engine.particle_volume() / engine.volume();
  const double sigma = mean_volume_diameter<D>(engine.particle_volume(), n);
  const FlightEstimate flight = estimate_flight<D>(n, engine.volume(), sigma, std::sqrt(v2 / n));
  // The Enskog factor (the contact value) that shortens the ideal-gas flight.
  const double enskog = eta > 0.0 && eta < 0.9 ? contact_value(D, eta) : 1.0;
  const double interval = 0.5 * flight.mean_free_time / enskog;
  if (!std::isfinite(interval) || !(interval > 0.0)) {
    throw InputError(
        "the particles do not move, so no sampling interval follows from their "
        "mean free time; give " +
        key);
  }
  return interval;
}

}  // namespace kairos
