#include "run/outputs/pressure_tensor.hpp"

#include <cmath>

#include "analysis/block_average.hpp"

namespace kairos {

template <int D>
void PressureTensor<D>::production_starts(const RunContext<D>&) {
  production_start_ = engine_.time();
  virial_start_ = engine_.counters().virial_tensor;
  shear_row_start_ = {engine_.time(), engine_.counters().virial_tensor[1]};
}

template <int D>
void PressureTensor<D>::sample(const RunContext<D>&) {
  const std::array<double, 9> sample = engine_.peculiar_kinetic_tensor();
  for (int k = 0; k < D * D; ++k) kinetic_sum_[k] += sample[k];
  ++samples_;
  const double time = engine_.time();
  if (engine_.kind().sheared && time > shear_row_start_.time) {
    const double virial_xy = engine_.counters().virial_tensor[1];  // row x, column y
    shear_stress_rows_.push_back(shear_stress_row(sample[1], virial_xy - shear_row_start_.virial_xy,
                                                  time - shear_row_start_.time, engine_.volume()));
    shear_row_start_ = {time, virial_xy};
  }
}

template <int D>
void PressureTensor<D>::summarize(nlohmann::json& j, const RunContext<D>&) const {
  const EventCounters& c = engine_.counters();
  const double production_time = engine_.time() - production_start_;
  const double volume = engine_.volume();
  if (samples_ > 0 && production_time > 0.0) {
    // Kinetic part averaged over the production rows, collisional part from the impulses over
    // the production time.
    nlohmann::json tensor = nlohmann::json::array();
    for (int a = 0; a < D; ++a) {
      nlohmann::json row = nlohmann::json::array();
      for (int b = 0; b < D; ++b) {
        const int k = a * D + b;
        row.push_back(pressure_tensor_element(kinetic_sum_[k], samples_,
                                              c.virial_tensor[k] - virial_start_[k],
                                              production_time, volume));
      }
      tensor.push_back(row);
    }
    j["pressure_tensor"] = tensor;
  }
  if (!engine_.kind().sheared) return;
  const double rate = engine_.environment().shear_rate;
  const BlockAverage p = block_average(shear_stress_rows_);
  nlohmann::json s;
  s["shear_rate"] = rate;
  s["shear_stress"] = p.mean;  // P_xy
  s["shear_stress_stderr"] = p.stderr_;
  s["shear_stress_stderr_blocks"] = p.blocks;  // also those of viscosity_stderr
  s["shear_stress_stderr_reliable"] = p.reliable;
  s["viscosity"] = -p.mean / rate;
  s["viscosity_stderr"] = p.stderr_ / std::abs(rate);
  s["samples"] = p.samples;
  s["temperature_production_start"] = thermo_.production_temperature(engine_);
  s["temperature"] =
      thermo_.statistics().temperature(engine_.thermal_energy(), engine_.held_degrees_of_freedom());
  j["shear"] = s;
}

template class PressureTensor<2>;
template class PressureTensor<3>;

}  // namespace kairos
