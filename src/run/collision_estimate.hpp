// A run measured in collisions in a system that can hardly collide (two particles in a box of
// 1e9, diameters of 1e-30) would run for ever: the ideal-gas estimate of its work refuses it
// before it starts (docs/guarantees.md, "Frozen clocks").
#pragma once

#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "core/error.hpp"

namespace kairos {

// The ideal-gas estimate of how far and how long a particle flies between collisions, from the
// mean density, the mean diameter and the rms speed (the Boltzmann mean free path
// 1 / (sqrt 2 n pi sigma^2) in 3D, 1 / (2 sqrt 2 n sigma) in 2D: Chapman and Cowling, The
// Mathematical Theory of Non-uniform Gases, 3rd ed. 1970, ch. 5). Without a field the
// density is never lower than the mean, so the estimate never makes a possible run look
// impossible by more than the estimate's own factor of order one.
struct FlightEstimate {
  double mean_free_path = 0.0, mean_free_time = 0.0;
};
// n particles in a volume, sigma: their mean diameter (or one of the same volume), v_rms.
template <int D>
FlightEstimate estimate_flight(double n, double volume, double sigma, double v_rms) {
  const double density = n / volume;
  FlightEstimate e;
  e.mean_free_path = D == 3 ? 1.0 / (std::sqrt(2.0) * density * M_PI * sigma * sigma)
                            : 1.0 / (2.0 * std::sqrt(2.0) * density * sigma);
  e.mean_free_time =
      v_rms > 0.0 ? e.mean_free_path / v_rms : std::numeric_limits<double>::infinity();
  return e;
}

// The diameter of the sphere (disk) of the mean particle volume (area).
template <int D>
double mean_volume_diameter(double particle_volume, double n) {
  const double v = particle_volume / n;
  return D == 3 ? std::cbrt(6.0 * v / M_PI) : std::sqrt(4.0 * v / M_PI);
}

// InputError when a phase of `collisions` (its target collision count) would take more than
// 1e13 units of work, or one collision more than 1e8, given the work one collision takes
// (events per collision, or DEM steps per collision).
inline void check_collisions_can_happen(double work_per_collision, double collisions,
                                        const FlightEstimate& flight, const char* unit) {
  // A month and more of events at ~10^7 per second, or a collision that takes 10^8 events
  // (minutes) however short the run: the largest sensible runs (10^7 particles, 10^4
  // collisions per particle) take some 10^11 events, a gas at packing fraction 10^-6 some 10^4
  // events per collision.
  if (!(work_per_collision * collisions > 1e13) && !(work_per_collision > 1e8)) return;
  throw InputError(fmt::format(
      "the run is measured in collisions, but this system hardly ever collides: the mean free "
      "path is about {:.3g} (mean free time {:.3g}), so each collision takes some {:.3g} {} and "
      "the run some {:.3g}; give its length in simulated time instead (run.time, "
      "run.equilibration_time), or check the box and the diameters",
      flight.mean_free_path, flight.mean_free_time, work_per_collision, unit,
      work_per_collision * collisions));
}

}  // namespace kairos
