#include "run/outputs/walls_with_mass_summary.hpp"

#include <cmath>
#include <string>

#include "analysis/block_average.hpp"
#include "run/outputs/summary_values.hpp"

namespace kairos {

template <int D>
void WallsWithMassSummary<D>::open(const RunContext<D>& run) {
  const std::vector<WallReading> walls = run.integrator().walls_with_mass();
  for (const WallReading& w : walls) {
    const auto* position = thermo_.earlier_production_column("wall_" + w.face + "_position");
    const auto* speed = thermo_.earlier_production_column("wall_" + w.face + "_speed");
    if (position == nullptr || speed == nullptr) return;  // a new production
    positions_.push_back(*position);
    speeds_.push_back(*speed);
  }
}

template <int D>
void WallsWithMassSummary<D>::sample(const RunContext<D>& run) {
  const std::vector<WallReading> walls = run.integrator().walls_with_mass();
  if (positions_.empty()) {
    positions_.resize(walls.size());
    speeds_.resize(walls.size());
  }
  for (std::size_t k = 0; k < walls.size() && k < positions_.size(); ++k) {
    positions_[k].push_back(walls[k].position);
    speeds_[k].push_back(walls[k].speed);
  }
}

template <int D>
void WallsWithMassSummary<D>::summarize(nlohmann::json& summary, const RunContext<D>& run) const {
  const std::vector<WallReading> now = run.integrator().walls_with_mass();
  if (now.empty()) return;
  nlohmann::json walls = nlohmann::json::array();
  for (std::size_t k = 0; k < now.size(); ++k) {
    nlohmann::json j;
    j["face"] = now[k].face;
    j["mass"] = now[k].mass;
    if (now[k].container) {
      j["container"] = true;
    } else {
      j["force"] = now[k].force;
      j["pressure"] = now[k].pressure;
    }
    if (now[k].sprung) {
      j["drive_work"] = now[k].drive_work;  // since the start of the simulation
      j["dashpot_dissipated"] = now[k].dashpot;
    }
    j["position"] = now[k].position;  // at the end
    j["energy"] = now[k].energy;
    const std::string key = "walls_with_mass[" + std::to_string(k) + "].position_mean";
    if (k < positions_.size() && positions_[k].size() >= 2) {
      const BlockAverage b = block_average(positions_[k]);
      j["position_mean"] = b.mean;
      j["position_stderr"] = b.stderr_;
      set_error_quality(j, "position_stderr", b);
      double var = 0.0, v2 = 0.0;
      for (const double x : positions_[k]) var += (x - b.mean) * (x - b.mean);
      for (const double v : speeds_[k]) v2 += v * v;
      j["position_rms"] = std::sqrt(var / static_cast<double>(positions_[k].size()));
      j["speed_rms"] = std::sqrt(v2 / static_cast<double>(speeds_[k].size()));
      j["samples"] = positions_[k].size();
    } else {
      set_or_explain(summary, j, "position_mean", NAN,
                     "fewer than 2 production thermo rows to average the wall's position over",
                     key);
      j["samples"] = k < positions_.size() ? positions_[k].size() : 0;
    }
    walls.push_back(std::move(j));
  }
  summary["walls_with_mass"] = std::move(walls);
}

template class WallsWithMassSummary<2>;
template class WallsWithMassSummary<3>;

}  // namespace kairos
