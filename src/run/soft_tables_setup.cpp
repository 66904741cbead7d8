#include "run/soft_tables_setup.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>

#include "core/error.hpp"
#include "core/stop_flag.hpp"

namespace kairos {

namespace {

struct SpeciesShape {
  std::optional<double> mass, radius;
  bool uniform = true;
};

template <int D>
std::vector<SpeciesShape> species_shapes(const ParticleSystem<D>& s, std::uint32_t species) {
  std::vector<SpeciesShape> shapes(species);
  for (std::size_t i = 0; i < s.size(); ++i) {
    SpeciesShape& sh = shapes.at(s.species[i]);
    if (!sh.mass) {
      sh.mass = s.mass[i];
      sh.radius = s.kinematics[i].radius;
    } else if (*sh.mass != s.mass[i] || *sh.radius != s.kinematics[i].radius) {
      sh.uniform = false;
    }
  }
  return shapes;
}

std::string species_name(const std::vector<std::string>& names, std::uint32_t s) {
  return s < names.size() ? names[s] : std::to_string(s);
}

}  // namespace

template <int D>
std::vector<SoftTableUse> attach_soft_tables(
    Environment<D>& env, const ParticleSystem<D>& state, const SoftTableSettings& settings,
    const std::function<void(const std::string&, double)>& progress) {
  std::vector<SoftTableUse> used;
  if (!env.soft_spheres()) return used;
  if (!(settings.tolerance > 0.0) || !(settings.speed_margin > 0.0) ||
      !(settings.speed_decades > 0.0)) {
    throw InputError("soft tables: tolerance, speed margin and speed decades must be > 0");
  }
  const std::uint32_t n_species = env.species;
  const std::vector<SpeciesShape> shapes = species_shapes(state, n_species);
  double fastest = 0.0;
  for (std::size_t i = 0; i < state.size(); ++i)
    fastest = std::max(fastest, std::sqrt(norm2(state.kinematics[i].vel)));
  if (settings.driving_temperature > 0.0) {
    double lightest = *std::min_element(state.mass.begin(), state.mass.end());
    fastest = std::max(fastest, 6.0 * std::sqrt(settings.driving_temperature / lightest));
  }
  if (!(fastest > 0.0) && !(settings.max_speed > 0.0)) return used;  // nothing moves
  // Relative speeds reach twice the fastest particle's speed.
  // Rounded up to a quarter decade, so that states alike (other seeds, a cooler restart
  // started afresh) share their tables through the cache.
  const double max_speed =
      settings.max_speed > 0.0
          ? settings.max_speed
          : std::pow(10.0,
                     std::ceil(4.0 * std::log10(2.0 * settings.speed_margin * fastest)) / 4.0);
  const double min_speed = max_speed * std::pow(10.0, -settings.speed_decades);
  const std::filesystem::path dir =
      settings.cache_dir.empty() ? default_soft_table_cache_dir() : settings.cache_dir;
  auto build = [&](const std::string& name, SoftTableSpec spec) {
    throw_if_stop_requested();  // between tables too (a cache load, a wall table after a pair's)
    spec.min_normal_speed = min_speed;
    spec.max_normal_speed = max_speed;
    spec.tolerance = settings.tolerance;
    SoftTableBuildOptions options;
    if (progress) options.progress = [&](double f) { progress(name, f); };
    auto table =
        std::make_shared<const SoftMapTable>(SoftMapTable::load_or_build(spec, dir, options));
    used.push_back({name, table->report(), spec});
    return table;
  };
  env.soft_tables.assign(static_cast<std::size_t>(n_species) * n_species, nullptr);
  for (std::uint32_t a = 0; a < n_species; ++a) {
    for (std::uint32_t b = a; b < n_species; ++b) {
      const SpeciesShape &sa = shapes[a], &sb = shapes[b];
      if (!sa.mass || !sb.mass || !sa.uniform || !sb.uniform) continue;
      SoftTableSpec spec;
      spec.law = env.soft[a * n_species + b];
      spec.reduced_mass = reduced_mass(*sa.mass, *sb.mass);
      spec.contact_distance = *sa.radius + *sb.radius;
      const auto table = build(
          species_name(state.species_names, a) + "-" + species_name(state.species_names, b), spec);
      env.soft_tables[a * n_species + b] = table;
      env.soft_tables[b * n_species + a] = table;
    }
  }
  if (env.has_walls()) {
    env.soft_wall_tables.assign(env.soft_wall.size(), nullptr);
    for (std::uint32_t a = 0; a < std::min<std::size_t>(n_species, env.soft_wall.size()); ++a) {
      const SpeciesShape& sa = shapes[a];
      if (!sa.mass || !sa.uniform) continue;
      SoftTableSpec spec;
      spec.law = env.soft_wall[a];
      spec.reduced_mass = *sa.mass;
      spec.contact_distance = *sa.radius;
      spec.head_on = true;
      env.soft_wall_tables[a] = build(species_name(state.species_names, a) + "-wall", spec);
    }
  }
  return used;
}

template std::vector<SoftTableUse> attach_soft_tables<2>(
    Environment<2>&, const ParticleSystem<2>&, const SoftTableSettings&,
    const std::function<void(const std::string&, double)>&);
template std::vector<SoftTableUse> attach_soft_tables<3>(
    Environment<3>&, const ParticleSystem<3>&, const SoftTableSettings&,
    const std::function<void(const std::string&, double)>&);

}  // namespace kairos
