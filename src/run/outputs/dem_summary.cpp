#include "run/outputs/dem_summary.hpp"

#include <algorithm>
#include <cmath>

#include "run/outputs/summary_values.hpp"

namespace kairos {

template <int D>
void DemSummary<D>::open(const RunContext<D>&) {
  const DemIntegrator<D>& dem = dem_.dem();
  kinetic_start_ = dem.kinetic_energy();
  energy_start_ = dem_.total_energy();
  dissipated_start_ = dem.dissipated_energy();
  dissipated_walls_start_ = dem.dissipated_at_walls();
  work_walls_start_ = dem.work_by_walls();
  outlet_energy_start_ = dem.outlet_energy();
  if (const auto outlet = dem_.outlet()) outlet_.open(*outlet, dem.time());
}

template <int D>
void DemSummary<D>::summarize(nlohmann::json& j, const RunContext<D>& run) const {
  const DemIntegrator<D>& dem = dem_.dem();
  const auto n = dem_.size();
  const auto steps = static_cast<std::uint64_t>(dem.steps());
  const double energy = dem_.total_energy();
  // E includes the gravitational energy: unbounded along a periodic axis (then null).
  const std::string field_unbounded =
      "gravity along a periodic axis: the potential energy is unbounded";
  const std::string unbounded =
      std::isfinite(energy) && std::isfinite(energy_start_) ? "" : field_unbounded;
  set_or_explain(j, j, "energy_drift_relative",
                 kinetic_start_ > 0 ? std::abs(energy - energy_start_) / kinetic_start_ : 0.0,
                 unbounded, "energy_drift_relative");
  const double wall = run.wall_seconds();
  nlohmann::json d;
  d["time_step"] = dem.dt();
  d["time_step_automatic"] = dem_.time_step_automatic();
  d["steps"] = steps;
  d["steps_since_start"] = dem_.base_events() + steps;
  d["collisions_since_start"] = dem.collisions();
  d["contacts_now"] = dem.contact_count();
  d["neighbour_list_builds"] = dem.neighbour_list_builds();
  d["ns_per_particle_step"] =
      steps > 0 ? 1e9 * wall / (static_cast<double>(steps) * static_cast<double>(n)) : 0.0;
  d["potential_energy"] = dem.potential_energy();
  const double field = dem.field_energy();
  set_or_explain(j, d, "field_energy", field, std::isfinite(field) ? "" : field_unbounded,
                 "dem.field_energy");
  d["wall_collisions"] = dem.wall_collisions();
  d["dissipated_energy"] = dem.dissipated_energy() - dissipated_start_;
  set_or_explain(j, d, "energy_start", energy_start_, unbounded, "dem.energy_start");
  set_or_explain(j, d, "energy_end", energy, unbounded, "dem.energy_end");
  j["dem"] = d;
  const typename DemAdapter<D>::Kind& kind = dem_.kind();
  if (!kind.granular) return;
  // Damping, walls or gravity: the energy budget, as the event engine reports it for granular
  // runs.
  const double dissipated = dem.dissipated_energy() - dissipated_start_;
  const double at_walls = dem.dissipated_at_walls() - dissipated_walls_start_;
  const double by_walls = dem.work_by_walls() - work_walls_start_;
  const double outlet_energy = dem.outlet_energy() - outlet_energy_start_;  // taken out
  const double scale = std::max({std::abs(energy_start_), dissipated + at_walls, std::abs(by_walls),
                                 std::abs(outlet_energy)});
  nlohmann::json g;
  g["rotating"] = kind.rotating;
  g["dissipative"] = kind.dissipative;
  g["moving_walls"] = kind.moving_walls;
  g["driven"] = false;
  g["rotational_temperature"] =
      2.0 * dem.rotational_energy() / ((D == 3 ? 3.0 : 1.0) * static_cast<double>(n));
  // The Sonine coefficient of the velocities relative to the centre of mass.
  const ParticleSystem<D> s = dem.export_state();
  Vec<D> mean{};
  double mass = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    mean = mean + s.mass[i] * s.kinematics[i].vel;
    mass += s.mass[i];
  }
  mean = (1.0 / mass) * mean;
  double c2 = 0.0, c4 = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double u2 = norm2(s.kinematics[i].vel - mean);
    c2 += u2;
    c4 += u2 * u2;
  }
  set_sonine_a2(j, g, sonine_a2<D>(c2, c4, static_cast<double>(n)), dem_.bulk());
  g["dissipated_in_collisions"] = dissipated;
  g["dissipated_at_walls"] = at_walls;
  g["work_by_walls"] = by_walls;
  g["wall_collisions"] = dem.wall_collisions();
  if (const auto outlet = dem_.outlet()) g["outlet"] = outlet_.summary(*outlet, dem.time());
  set_or_explain(j, g, "energy_start", energy_start_, unbounded, "granular.energy_start");
  set_or_explain(j, g, "energy_end", energy, unbounded, "granular.energy_end");
  set_or_explain(j, g, "energy_balance_relative",
                 scale > 0.0 ? std::abs(energy - energy_start_) / scale : 0.0, unbounded,
                 "granular.energy_balance_relative");
  j["granular"] = g;
}

template class DemSummary<2>;
template class DemSummary<3>;

}  // namespace kairos
