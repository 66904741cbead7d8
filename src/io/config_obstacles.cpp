#include "io/config_obstacles.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "interactions/potential_spec.hpp"
#include "io/config_choices.hpp"

namespace kairos {

namespace {

// The first surface table with entries ("boundary.plane"; io/surface_tables.hpp), if any.
std::optional<std::string> first_surface_table(const Config& c) {
  std::optional<std::string> first;
  for_each_surface_table(c.boundary.surfaces, [&](auto table, const auto& entries) {
    if (!first && !entries.empty()) first = fmt::format("boundary.{}", table.key);
  });
  return first;
}

}  // namespace

std::optional<TransportObstacle> compression_obstacle(const Config& c) {
  const auto refuse = [](std::string key, std::string why) {
    return TransportObstacle{std::move(key), std::move(why)};
  };
  const char* box = "the particles grow in a periodic box or between walls on its faces";
  if (const std::optional<std::string> table = first_surface_table(c)) return refuse(*table, box);
  if (!c.boundary.open.empty()) return refuse("boundary.open", box);
  if (c.boundary.shear_rate != 0.0) return refuse("boundary.shear_rate", box);
  if (std::any_of(c.field.gravity.begin(), c.field.gravity.end(),
                  [](double g) { return g != 0.0; }))
    return refuse("field.gravity", box);
  if (!c.bonds.empty() || c.system.chain_length > 0)
    return refuse("bond", "bonded particles would stretch their bonds as they grow");
  for (const SpeciesConfig& sp : c.system.species)
    if (sp.fixed) return refuse("system.species.fixed", "fixed grains cannot be pushed aside");
  return std::nullopt;
}

std::optional<TransportObstacle> transport_obstacle(const Config& c) {
  const auto refuse = [](std::string key, std::string why) {
    return TransportObstacle{std::move(key), std::move(why)};
  };
  if (integrators().is(c.run.integrator, IntegratorKind::kDem))
    return refuse("run.integrator", "the DEM integrator is not event-driven");
  if (c.boundary.shear_rate != 0.0)
    return refuse("boundary.shear_rate", "Lees-Edwards shear is a non-equilibrium state");
  if (!c.boundary.walls.empty()) return refuse("boundary.wall", "walls do not conserve momentum");
  if (const std::optional<std::string> table = first_surface_table(c))
    return refuse(*table, "walls do not conserve momentum");
  if (!c.boundary.open.empty())
    return refuse("boundary.open", "open faces lose particles' momentum");
  for (double g : c.field.gravity)
    if (g != 0.0) return refuse("field.gravity", "a field does not conserve momentum");
  if (!driving_kinds().is(c.driving.kind, DrivingKind::kNone))
    return refuse("driving.kind", "driving does not conserve energy");
  // Soft contacts: elastic laws only (the key that makes one dissipative, if any).
  const auto dissipative = [](const SoftLawConfig& law) -> const char* {
    if (law.damping != 0.0) return "damping";
    if (law.dissipation != 0.0) return "dissipation";
    if (law.restitution != 0.0 && law.restitution != 1.0) return "restitution";
    if (law.friction != 0.0) return "friction";
    return nullptr;
  };
  if (c.soft.enabled()) {
    if (const char* key = dissipative(c.soft.law))
      return refuse(fmt::format("soft.{}", key), "a dissipative soft contact law");
    for (std::size_t p = 0; p < c.soft.pairs.size(); ++p)
      if (const char* key = dissipative(c.soft.pairs[p].law))
        return refuse(fmt::format("soft.pair[{}].{}", p, key), "a dissipative soft contact law");
  }
  for (std::size_t s = 0; s < c.system.species.size(); ++s)
    if (c.system.species[s].fixed)
      return refuse(fmt::format("system.species[{}].fixed", s),
                    "fixed grains do not conserve momentum");
  const auto conservative = [](const ContactConfig& k) {
    const bool elastic =
        restitution_models().is(k.restitution_model, RestitutionModel::kConstant) &&
        k.restitution == 1.0;
    const bool tangential = k.tangential_restitution == -1.0 || k.friction == 0.0 ||
                            (k.tangential_restitution == 1.0 && std::isinf(k.friction));
    return elastic && tangential;
  };
  for (const PairPotentialConfig& p : c.potentials)
    if (potential_kinds().is(p.potential.kind, PotentialKind::kSpringDashpot))
      return refuse("potential.kind", "a spring-dashpot by steps dissipates energy");
  if (!conservative(c.interactions.contact))
    return refuse("contact.restitution", "inelastic or frictional contacts dissipate energy");
  for (const PairContactConfig& p : c.interactions.pairs)
    if (!conservative(p.contact))
      return refuse("contact.pair", "inelastic or frictional contacts dissipate energy");
  return std::nullopt;
}

std::optional<TransportObstacle> replica_exchange_obstacle(const Config& c) {
  const auto refuse = [](std::string key, std::string why) {
    return TransportObstacle{std::move(key), std::move(why)};
  };
  // A conservative system in the transport sense is canonical under the thermostat, but for
  // its static walls (allowed here) and the driving (the thermostat itself).
  Config conservative = c;
  conservative.driving = DrivingConfig{};
  conservative.boundary.walls.clear();
  conservative.boundary.surfaces = SurfaceConfigs{};
  if (std::optional<TransportObstacle> o = transport_obstacle(conservative)) return o;
  // Elastic rough contacts conserve energy but exchange it with the spins, which neither the
  // thermostat nor a swap's scaling touches.
  const auto rough = [](const ContactConfig& k) {
    return k.tangential_restitution != -1.0 && k.friction != 0.0;
  };
  if (rough(c.interactions.contact))
    return refuse("contact.tangential_restitution", "rough particles' spins are not thermalised");
  for (const PairContactConfig& p : c.interactions.pairs)
    if (rough(p.contact))
      return refuse("contact.pair", "rough particles' spins are not thermalised");
  if (c.soft.enabled())
    return refuse("soft", "soft contacts in progress cannot have their velocities scaled");
  if (c.analysis.transport)
    return refuse("analysis.transport", "the Helfand moments cannot follow a velocity scaling");
  if (!c.boundary.container.axis.empty())
    return refuse("boundary.container", "a driven container is not an equilibrium state");
  if (!c.boundary.outlet.normal.empty())
    return refuse("boundary.outlet", "an outlet moves particles: not an equilibrium state");
  const auto still = [&](const WallConfig& w,
                         const std::string& key) -> std::optional<TransportObstacle> {
    if (wall_moves(w)) return refuse(key, "a moving wall is not an equilibrium state");
    Config probe;
    probe.interactions.contact = w.contact;
    if (transport_obstacle(probe))
      return refuse(key + ".restitution", "the wall dissipates energy");
    if (rough(w.contact))
      return refuse(key + ".tangential_restitution", "a rough wall spins the particles");
    return std::nullopt;
  };
  for (std::size_t k = 0; k < c.boundary.walls.size(); ++k)
    if (auto o = still(c.boundary.walls[k], fmt::format("boundary.wall[{}]", k))) return o;
  std::optional<TransportObstacle> surface;
  for_each_surface_table(c.boundary.surfaces, [&](auto table, const auto& entries) {
    for (std::size_t k = 0; k < entries.size() && !surface; ++k) {
      const std::string key = fmt::format("boundary.{}[{}]", table.key, k);
      if (const std::optional<TableObstacle> moving = table.motion(entries[k])) {
        surface = refuse(key + moving->key, moving->why);
      } else {
        WallConfig w;
        w.contact = table.contact_law(entries[k]);
        surface = still(w, key);
      }
    }
  });
  return surface;
}

}  // namespace kairos
