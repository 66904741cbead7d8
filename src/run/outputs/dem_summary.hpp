// summary.json's parts of a DEM run (run.integrator = "dem"): the energy drift of
// E = K + U + the gravitational energy + what the damping and outlets took - the work of the walls
// (conserved to O(dt^2), not round-off), the `dem` block (time step, steps, contacts, lists),
// and with damping, friction, walls or gravity the `granular` energy budget. docs/outputs.md.
#pragma once

#include <string>

#include "run/dem_adapter.hpp"
#include "run/outputs/observer.hpp"
#include "run/outputs/outlet_tally.hpp"

namespace kairos {

template <int D>
class DemSummary final : public Observer<D> {
 public:
  explicit DemSummary(const DemAdapter<D>& dem) : dem_(dem) {}
  std::string name() const override { return "summary.json (dem)"; }
  bool writes_file() const override { return false; }
  void open(const RunContext<D>&) override;
  void production_starts(const RunContext<D>&) override {
    if (const auto outlet = dem_.outlet()) outlet_.production_starts(*outlet, dem_.time());
  }
  void summarize(nlohmann::json& summary, const RunContext<D>& run) const override;

 private:
  const DemAdapter<D>& dem_;
  double kinetic_start_ = 0.0, energy_start_ = 0.0, dissipated_start_ = 0.0;
  double dissipated_walls_start_ = 0.0, work_walls_start_ = 0.0, outlet_energy_start_ = 0.0;
  OutletTally<D> outlet_;
};

}  // namespace kairos
