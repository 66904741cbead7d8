// summary.json's `walls_with_mass` (docs/outputs.md): for each wall with mass (a free piston,
// docs/physics.md#walls-with-mass), the pressure its force imposes and where its plane stood
// over the production thermo rows, with a blocked error - what a constant-pressure run
// measures (the volume under the lid is its area times that height).
#pragma once

#include <string>
#include <vector>

#include "run/outputs/observer.hpp"
#include "run/outputs/thermo_output.hpp"

namespace kairos {

template <int D>
class WallsWithMassSummary final : public Observer<D> {
 public:
  explicit WallsWithMassSummary(const ThermoOutput<D>& thermo) : thermo_(thermo) {}
  std::string name() const override { return "summary.json (walls_with_mass)"; }
  bool writes_file() const override { return false; }
  // A continued production: the rows of the earlier invocations, from thermo.tsv's columns.
  void open(const RunContext<D>& run) override;
  // At each production thermo row: each wall's position and speed.
  void sample(const RunContext<D>& run) override;
  void summarize(nlohmann::json& summary, const RunContext<D>& run) const override;

 private:
  const ThermoOutput<D>& thermo_;
  std::vector<std::vector<double>> positions_, speeds_;  // per wall, per row
};

}  // namespace kairos
