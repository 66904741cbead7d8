// summary.json's pressure tensor over production (event engine): the kinetic part sum of
// m c_a c_b / V, sampled at the production thermo rows (c relative to the mean velocity, or
// under shear to the flow), plus the collisional part sum of r_a J_b / (V t) from the impulses.
// Under Lees-Edwards shear also the `shear` part: each row gives one sample of the stress P_xy
// (its kinetic part plus the collisional part since the previous row), blocked for its error,
// and the viscosity -P_xy / shear rate. docs/outputs.md.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "run/event_adapter.hpp"
#include "run/outputs/observer.hpp"
#include "run/outputs/thermo_output.hpp"

namespace kairos {

// Element k (row-major, D x D) of the pressure tensor over a span: the kinetic part averaged
// over `samples` rows (its sum `kinetic_sum`) plus the collisional part, the virial tensor's
// change over the span's `duration`, over the volume.
inline double pressure_tensor_element(double kinetic_sum, int samples, double virial_change,
                                      double duration, double volume) {
  return (kinetic_sum / samples + virial_change / duration) / volume;
}

// One row's shear stress P_xy: its kinetic xy part and the collisional xy virial since the
// previous row, over the volume.
inline double shear_stress_row(double kinetic_xy, double virial_xy_change, double row_duration,
                               double volume) {
  return (kinetic_xy + virial_xy_change / row_duration) / volume;
}

template <int D>
class PressureTensor final : public Observer<D> {
 public:
  // `thermo`: for the production temperature and the temperature now (the shear part).
  PressureTensor(const EventIntegrator<D>& engine, const ThermoOutput<D>& thermo)
      : engine_(engine), thermo_(thermo) {}
  std::string name() const override { return "summary.json (pressure tensor)"; }
  bool writes_file() const override { return false; }
  void production_starts(const RunContext<D>&) override;
  void sample(const RunContext<D>&) override;
  void summarize(nlohmann::json& summary, const RunContext<D>& run) const override;

 private:
  const EventIntegrator<D>& engine_;
  const ThermoOutput<D>& thermo_;
  double production_start_ = 0.0;
  std::array<double, 9> kinetic_sum_{}, virial_start_{};
  int samples_ = 0;
  struct ShearRowStart {
    double time = 0.0, virial_xy = 0.0;
  } shear_row_start_;
  std::vector<double> shear_stress_rows_;  // P_xy per production thermo row
};

}  // namespace kairos
