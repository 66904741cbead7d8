#include "run/outputs/granular_summary.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "run/outputs/summary_values.hpp"

namespace kairos {

template <int D>
void GranularSummary<D>::summarize(nlohmann::json& j, const RunContext<D>& /*run*/) const {
  const EventCounters& c = engine_.counters();
  const typename EventIntegrator<D>::Kind& kind = engine_.kind();
  const double dissipated = (c.dissipated_in_collisions - start_.dissipated_in_collisions) +
                            (c.dissipated_at_walls - start_.dissipated_at_walls);
  const double work = (c.work_by_walls - start_.work_by_walls) +
                      (c.work_by_driving - start_.work_by_driving) +
                      (c.work_by_shear - start_.work_by_shear);
  const double outlet_energy = c.outlet_energy - start_.outlet_energy;  // taken out
  const double energy = engine_.total_energy();
  const double balance = energy - energy_start_ + dissipated - work + outlet_energy;
  const double scale =
      std::max({std::abs(energy_start_), dissipated, std::abs(work), std::abs(outlet_energy)});
  nlohmann::json g;
  // What this run's granular lines mean (the CLI prints only those): spins, dissipation,
  // moving walls, driving.
  g["rotating"] = kind.rotating;
  g["dissipative"] = kind.dissipative;
  g["moving_walls"] = kind.moving_walls;
  g["driven"] = kind.driven;
  g["rotational_temperature"] = 2.0 * engine_.rotational_energy() /
                                ((D == 3 ? 3.0 : 1.0) * static_cast<double>(engine_.mobile()));
  // The Sonine coefficient of the velocities relative to the mean.
  std::vector<Vec<D>> u;
  std::vector<double> m;
  engine_.peculiar_velocities(u, m);
  double c2 = 0.0, c4 = 0.0;
  for (const Vec<D>& ui : u) {
    const double s = norm2(ui);
    c2 += s;
    c4 += s * s;
  }
  set_sonine_a2(j, g, sonine_a2<D>(c2, c4, static_cast<double>(engine_.size())), engine_.bulk(),
                engine_.mobile() < engine_.size());
  g["wall_collisions"] = c.wall_collisions - start_.wall_collisions;
  g["elastic_by_rule"] = c.elastic_by_rule - start_.elastic_by_rule;
  g["sliding_collisions"] = c.sliding_collisions - start_.sliding_collisions;
  g["fell_asleep"] = c.fell_asleep - start_.fell_asleep;
  g["woken_without_support"] = c.lost_support - start_.lost_support;
  g["sleeping_now"] = engine_.sleeping();
  if (engine_.mobile() < engine_.size()) g["fixed_grains"] = engine_.size() - engine_.mobile();
  g["dissipated_in_collisions"] = c.dissipated_in_collisions - start_.dissipated_in_collisions;
  g["dissipated_at_walls"] = c.dissipated_at_walls - start_.dissipated_at_walls;
  g["work_by_walls"] = c.work_by_walls - start_.work_by_walls;
  g["work_by_driving"] = c.work_by_driving - start_.work_by_driving;
  g["driving_kicks"] = c.driving_kicks - start_.driving_kicks;
  g["work_by_shear"] = c.work_by_shear - start_.work_by_shear;
  if (const auto outlet = engine_.outlet()) g["outlet"] = outlet_.summary(*outlet, engine_.time());
  const std::string unbounded =
      std::isfinite(energy) && std::isfinite(energy_start_)
          ? ""
          : "gravity along a periodic axis: the potential energy is unbounded";
  set_or_explain(j, g, "energy_start", energy_start_, unbounded, "granular.energy_start");
  set_or_explain(j, g, "energy_end", energy, unbounded, "granular.energy_end");
  set_or_explain(j, g, "energy_balance_relative", scale > 0.0 ? std::abs(balance) / scale : 0.0,
                 unbounded, "granular.energy_balance_relative");
  j["granular"] = g;
}

template class GranularSummary<2>;
template class GranularSummary<3>;

}  // namespace kairos
