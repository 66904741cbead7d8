// summary.json's `walls_with_mass` (docs/outputs.md): for each wall with mass (a free piston,
// docs/physics.md#walls-with-mass), the pressure its force imposes and where its plane stood
// over the production thermo rows, with a blocked error - what a constant-pressure run
// measures (the volume under the lid is its area times that height).
#pragma once

#include <string>
#include <vector>

#include "run/outputs/observer.hpp"

namespace kairos {

template <int D>
class WallsWithMassSummary final : public Observer<D> {
 public:
  std::string name() const override { return "summary.json (walls_with_mass)"; }
  bool writes_file() const override { return false; }
  // At each production thermo row: each wall's position and speed.
  void sample(const RunContext<D>& run) override;
  void summarize(nlohmann::json& summary, const RunContext<D>& run) const override;

 private:
  std::vector<std::vector<double>> positions_, speeds_;  // per wall, per row
};

}  // namespace kairos
