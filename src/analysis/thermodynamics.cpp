#include "analysis/thermodynamics.hpp"

#include <cmath>

namespace kairos {

Thermodynamics::Thermodynamics(int dimension, std::size_t particles, double volume, bool held_frame)
    : dimension_(dimension),
      n_(static_cast<double>(particles)),
      free_particles_(held_frame ? n_ : n_ - 1.0),
      volume_(volume) {}

double Thermodynamics::temperature(double kinetic_energy, double held) const {
  // Every degree of freedom held (two particles, one frozen pair): no temperature to count
  // them out of, so all of them are counted.
  const double moving = dimension_ * free_particles_ - held;
  return 2.0 * kinetic_energy / (moving > 0.0 ? moving : dimension_ * free_particles_);
}

double Thermodynamics::span_temperature(bool from_rows, const std::vector<double>& row_temperatures,
                                        double start_kinetic_energy, double start_held) const {
  if (from_rows && !row_temperatures.empty()) return block_average(row_temperatures).mean;
  return temperature(start_kinetic_energy, start_held);
}

double Thermodynamics::compressibility(double virial, double kT, double duration) const {
  if (!(duration > 0.0) || !(kT > 0.0)) return std::nan("");
  return 1.0 + virial / (dimension_ * n_ * kT * duration);
}

double Thermodynamics::pressure(double compressibility, double kT) const {
  return compressibility * n_ * kT / volume_;
}

double Thermodynamics::mean_free_time(double duration, std::uint64_t collisions) const {
  if (collisions == 0) return std::nan("");
  return n_ * duration / (2.0 * static_cast<double>(collisions));
}

double Thermodynamics::per_particle(std::uint64_t collisions) const {
  return 2.0 * static_cast<double>(collisions) / n_;
}

ThermoRow Thermodynamics::row(const ThermoPoint& now, double kinetic_energy, bool production,
                              double held) {
  ThermoRow r;
  r.at = now;
  r.collisions_per_particle = per_particle(now.collisions);
  r.kinetic_energy = kinetic_energy;
  r.temperature = temperature(kinetic_energy, held);
  const double duration = now.time - last_.time;
  r.compressibility = compressibility(now.virial - last_.virial, r.temperature, duration);
  r.pressure = pressure(r.compressibility, r.temperature);
  r.mean_free_time = mean_free_time(duration, now.collisions - last_.collisions);
  if (production && std::isfinite(r.compressibility)) z_samples_.push_back(r.compressibility);
  if (production && std::isfinite(r.mean_free_time)) mft_samples_.push_back(r.mean_free_time);
  last_ = now;
  return r;
}

}  // namespace kairos
