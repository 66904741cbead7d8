// Thermodynamics of a hard-particle run from its event counters (docs/outputs.md):
//   kT = 2 K / (D (N - 1) - H)             (total momentum fixed: D (N - 1) degrees of freedom;
//                                           D N with fixed grains, which take up momentum; H
//                                           held by soft contacts in progress, which the
//                                           event engine freezes: D per pair, 1 at a wall)
//   Z  = 1 + W / (D N kT t)                W = sum over collisions of r_ij . J_i
//   P  = Z N kT / V,  mean free time = N t / (2 N_coll),  c = 2 N_coll / N.
// Rows cover the interval since the previous row; production rows feed the block averages.
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "analysis/block_average.hpp"

namespace kairos {

// Cumulative counters at one instant.
struct ThermoPoint {
  double time = 0.0;
  double virial = 0.0;
  std::uint64_t events = 0;
  std::uint64_t collisions = 0;
};

struct ThermoRow {
  ThermoPoint at;
  double collisions_per_particle = 0.0;  // cumulative
  double temperature = 0.0;
  double pressure = 0.0;         // over the interval
  double compressibility = 0.0;  // over the interval (NaN for an empty interval)
  double kinetic_energy = 0.0;
  double mean_free_time = 0.0;  // over the interval (NaN without collisions)
};

class Thermodynamics {
 public:
  // held_frame: something immovable (fixed grains) takes up momentum, so all D N degrees of
  // freedom are free: kT = 2 K / (D N) (N: the particles that move).
  Thermodynamics(int dimension, std::size_t particles, double volume, bool held_frame = false);

  // `held`: degrees of freedom that contacts in progress hold still (Integrator::
  // held_degrees_of_freedom), not counted.
  double temperature(double kinetic_energy, double held = 0.0) const;
  // The temperature a span's Z and pressure are made with: the mean of its rows' temperatures
  // when the kinetic energy is not conserved (`from_rows`: Integrator::temperature_from_rows,
  // a thermostat or dissipation) and there are rows, else the span's start's (its kinetic
  // energy and held degrees of freedom then). The summary's and Simulation.pressure()'s rule.
  double span_temperature(bool from_rows, const std::vector<double>& row_temperatures,
                          double start_kinetic_energy, double start_held) const;
  double compressibility(double virial, double kT, double duration) const;
  double pressure(double compressibility, double kT) const;
  double mean_free_time(double duration, std::uint64_t collisions) const;
  double per_particle(std::uint64_t collisions) const;

  // Starts the next interval at `p` without a row (e.g. at the start of a run).
  void mark(const ThermoPoint& p) { last_ = p; }
  const ThermoPoint& last() const { return last_; }
  // The row for the interval from the last mark to `now`; starts the next interval at `now`.
  ThermoRow row(const ThermoPoint& now, double kinetic_energy, bool production, double held = 0.0);

  // The production rows' Z and mean free time of an earlier invocation of the same run (read
  // back from its thermo.tsv), before this one's: as if this object had made those rows.
  void restore_production_rows(std::vector<double> z, std::vector<double> mean_free_times) {
    z_samples_ = std::move(z);
    mft_samples_ = std::move(mean_free_times);
  }

  BlockAverage compressibility_blocks() const { return block_average(z_samples_); }
  BlockAverage mean_free_time_blocks() const { return block_average(mft_samples_); }

 private:
  double dimension_;
  double n_;
  double free_particles_;  // N - 1, or N in a held frame
  double volume_;
  ThermoPoint last_;
  std::vector<double> z_samples_, mft_samples_;
};

}  // namespace kairos
