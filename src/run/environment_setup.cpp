#include "run/environment_setup.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <tuple>
#include <utility>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/error.hpp"
#include "io/config_choices.hpp"
#include "run/config_ranges.hpp"

namespace kairos {

namespace {

int face_index(const std::string& face, int dimension) {
  if (const ChoiceEntry<BoxFace>* f = box_faces(dimension).find(face)) return face_number(f->value);
  throw InputError(fmt::format("boundary: '{}' is not a face of a {}D box", face, dimension));
}

std::uint32_t species_index(const std::vector<std::string>& names, const std::string& name,
                            const std::string& where) {
  for (std::size_t k = 0; k < names.size(); ++k)
    if (names[k] == name) return static_cast<std::uint32_t>(k);
  throw InputError(fmt::format("{}: the system has no species '{}'", where, name));
}

// The diameter of each species of the state (NaN for a species whose particles differ in size).
template <int D>
std::vector<double> species_diameters(const ParticleSystem<D>& s, std::size_t species) {
  std::vector<double> d(species, 0.0);
  for (std::size_t i = 0; i < s.size(); ++i) {
    double& di = d[s.species[i]];
    const double here = 2.0 * s.kinematics[i].radius;
    di = di == 0.0 || di == here ? here : std::nan("");
  }
  return d;
}

// The mass of each species of the state (NaN for a species whose particles differ in mass).
template <int D>
std::vector<double> species_masses(const ParticleSystem<D>& s, std::size_t species) {
  std::vector<double> m(species, 0.0);
  for (std::size_t i = 0; i < s.size(); ++i) {
    double& mi = m[s.species[i]];
    mi = mi == 0.0 || mi == s.mass[i] ? s.mass[i] : std::nan("");
  }
  return m;
}

// A step higher than 1e9 kT is never climbed nor left once fallen into, and such energies
// swamp the kinetic energy in round-off (sigma = 1e6 with a core of 0.85 gave steps of 1e72):
// InputError naming the largest.
void check_step_energies(const StepTable& t, double kT, const std::string& where) {
  for (std::size_t k = 0; k < t.energy.size(); ++k) {
    if (!(std::abs(t.energy[k]) <= 1e9 * kT)) {
      throw InputError(fmt::format(
          "{}: the step table's shell between r = {:.6g} and {:.6g} has the energy {:.6g}, more "
          "than 1e9 times kT = {:.6g} (system.temperature) in magnitude; such a step is never "
          "crossed and its energy swamps the kinetic energy: lower epsilon (or depth), or move the "
          "hard core (the diameter) out where U is smaller",
          where, t.boundary[k + 1], t.boundary[k], t.energy[k], kT));
    }
  }
}

StepTable build_table(const PotentialSpec& spec, double core, int dimension,
                      const std::string& where, double kT, double reduced_mass = std::nan("")) {
  StepTable t;
  try {
    t = make_step_table(spec, core, dimension, reduced_mass);
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: {}", where, e.what()));
  }
  check_step_energies(t, kT, where);
  return t;
}

// The step tables of [[potential]] and [[bond]] for the state's sizes and bond types.
template <int D>
void add_step_potentials(const Config& config, const ParticleSystem<D>& s, Environment<D>& env) {
  const std::vector<std::string>& names = s.species_names;
  const auto n = static_cast<std::uint32_t>(std::max<std::size_t>(1, names.size()));
  if (!config.potentials.empty()) {
    const std::vector<double> diameter = species_diameters(s, n);
    const std::vector<double> mass = species_masses(s, n);
    env.pair_table.assign(static_cast<std::size_t>(n) * n, -1);
    // The entry without species first, so that named pairs override it.
    std::vector<std::size_t> order(config.potentials.size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_partition(order.begin(), order.end(),
                          [&](std::size_t p) { return config.potentials[p].species.empty(); });
    for (const std::size_t p : order) {
      const PairPotentialConfig& pc = config.potentials[p];
      const std::string where = fmt::format("potential[{}]", p);
      std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
      if (pc.species.empty()) {
        for (std::uint32_t a = 0; a < n; ++a)
          for (std::uint32_t b = a; b < n; ++b) pairs.emplace_back(a, b);
      } else {
        pairs.emplace_back(species_index(names, pc.species[0], where),
                           species_index(names, pc.species[1], where));
      }
      for (const auto& [a, b] : pairs) {
        const double core = 0.5 * (diameter[a] + diameter[b]);
        if (std::isnan(core)) {
          throw InputError(fmt::format(
              "{}: species {} and {} need one contact distance each; the particles of a species "
              "with a potential must all have the same diameter",
              where, names[a], names[b]));
        }
        if (core == 0.0) continue;  // a species without particles
        // The reduced mass (NaN if unknown): spring_dashpot's restitution needs it.
        const double mu = mass[a] * mass[b] / (mass[a] + mass[b]);
        env.tables.push_back(
            build_table(pc.potential, core, D, where, config.system.temperature, mu));
        const int t = static_cast<int>(env.tables.size()) - 1;
        env.pair_table[a * n + b] = t;
        env.pair_table[b * n + a] = t;
      }
    }
  }
  // Bonds: one table per type of the state; every bond of a type must have one contact distance.
  std::vector<double> bond_core(s.bond_types.size(), 0.0);
  for (const Bond& b : s.bonds) {
    if (b.type >= bond_core.size() || b.i >= s.size() || b.j >= s.size()) continue;  // engine
    const double core = s.kinematics[b.i].radius + s.kinematics[b.j].radius;
    double& c = bond_core[b.type];
    if (c != 0.0 && c != core) {
      throw InputError(fmt::format(
          "bonds of type '{}' join particles of different sizes; give each size pair its own bond "
          "type",
          s.bond_types[b.type]));
    }
    c = core;
  }
  for (std::size_t k = 0; k < s.bond_types.size(); ++k) {
    const auto it = std::find_if(config.bonds.begin(), config.bonds.end(),
                                 [&](const BondConfig& bc) { return bc.type == s.bond_types[k]; });
    if (it == config.bonds.end()) {
      throw InputError(fmt::format(
          "the state has bonds of type '{}' but no [[bond]] with type = \"{}\" is given",
          s.bond_types[k], s.bond_types[k]));
    }
    const std::string where = fmt::format("bond[{}]", it - config.bonds.begin());
    if (bond_core[k] == 0.0) bond_core[k] = 2.0 * s.kinematics[0].radius;  // type unused
    env.tables.push_back(
        build_table(it->potential, bond_core[k], D, where, config.system.temperature));
    env.bond_table.push_back(static_cast<int>(env.tables.size()) - 1);
  }
  if (!env.pair_table.empty()) env.species = n;
}

// Per species of the state: the mass and radius every particle of it has (NaN when its
// particles differ); a species without particles takes its [[system.species]] values.
struct SpeciesShape {
  double mass = 1.0, radius = 0.5;
};
template <int D>
std::vector<SpeciesShape> species_shapes(const Config& config, const ParticleSystem<D>& s,
                                         std::size_t species) {
  std::vector<SpeciesShape> shape(species, SpeciesShape{0.0, 0.0});
  for (std::size_t i = 0; i < s.size(); ++i) {
    SpeciesShape& sh = shape[s.species[i]];
    const double m = s.mass[i], r = s.kinematics[i].radius;
    sh.mass = sh.mass == 0.0 || sh.mass == m ? m : std::nan("");
    sh.radius = sh.radius == 0.0 || sh.radius == r ? r : std::nan("");
  }
  for (std::size_t k = 0; k < species; ++k) {
    if (shape[k].mass != 0.0) continue;
    shape[k] = SpeciesShape{};
    for (const SpeciesConfig& sc : config.system.species) {
      if (k < s.species_names.size() && sc.name == s.species_names[k])
        shape[k] = {sc.mass, 0.5 * sc.diameter};
    }
  }
  return shape;
}

// The force law a soft config describes for a pair of reduced mass mu and effective radius
// R_eff (NaN when the species' particles differ: an error if the law needs it). `what` names
// the pair in errors.
SoftContactLaw make_soft_law(const SoftLawConfig& c, double mu, double r_eff,
                             const std::string& where, const std::string& what) {
  const SoftModel model = soft_models().at(c.model);
  const auto need = [&](double value, const char* quantity) {
    if (std::isnan(value)) {
      throw InputError(fmt::format(
          "{}: {} needs one {} per species, but the particles of {} differ in size or mass; "
          "soft laws are set per species pair",
          where, model == SoftModel::ViscoelasticHertz ? "model = \"hertz\"" : "restitution",
          quantity, what));
    }
  };
  try {
    if (model == SoftModel::LinearDashpot) {
      double gamma = c.damping;
      if (c.restitution > 0.0) {
        need(mu, "mass");
        gamma = dashpot_damping_for_restitution(mu, c.stiffness, c.restitution);
      }
      return SoftContactLaw::linear_dashpot(c.stiffness, gamma);
    }
    need(r_eff, "radius");
    const double rho = hertz_rho_one_material(c.young, c.poisson, r_eff);
    double a = c.dissipation;
    if (c.restitution > 0.0) {
      need(mu, "mass");
      a = viscoelastic_dissipation_for_restitution(mu, rho, c.restitution, c.restitution_speed);
    }
    return SoftContactLaw::viscoelastic_hertz(rho, a);
  } catch (const InputError& e) {
    if (std::string(e.what()).starts_with(where + ": ")) throw;  // "soft contact: ..." is not
    throw InputError(fmt::format("{}: {}: {}", where, what, e.what()));
  }
}

SoftFriction soft_friction(const SoftLawConfig& c) {
  return {c.friction, c.tangential_stiffness, c.tangential_damping};
}

// [soft]: the law of every species pair (from [[soft.pair]] or [soft]) and, with walls, of
// every species against a wall ([soft] with R_eff = R and mu = m: a wall of the same material
// and infinite mass and radius).
template <int D>
void add_soft_laws(const Config& config, const ParticleSystem<D>& s, Environment<D>& env) {
  const SoftConfig& soft = config.soft;
  if (!soft.enabled()) return;
  const std::vector<std::string>& names = s.species_names;
  const auto n = static_cast<std::uint32_t>(std::max<std::size_t>(1, names.size()));
  const std::vector<SpeciesShape> shape = species_shapes(config, s, n);
  const auto name = [&](std::uint32_t a) { return a < names.size() ? names[a] : std::string("A"); };
  std::vector<int> pair_of(static_cast<std::size_t>(n) * n, -1);
  for (std::size_t p = 0; p < soft.pairs.size(); ++p) {
    const std::string where = fmt::format("soft.pair[{}]", p);
    const std::uint32_t a = species_index(names, soft.pairs[p].species[0], where);
    const std::uint32_t b = species_index(names, soft.pairs[p].species[1], where);
    pair_of[a * n + b] = pair_of[b * n + a] = static_cast<int>(p);
  }
  env.species = n;
  env.soft.assign(static_cast<std::size_t>(n) * n, SoftContactLaw{});
  env.soft_friction.assign(static_cast<std::size_t>(n) * n, SoftFriction{});
  for (std::uint32_t a = 0; a < n; ++a) {
    for (std::uint32_t b = a; b < n; ++b) {
      const int p = pair_of[a * n + b];
      const SoftLawConfig& c = p >= 0 ? soft.pairs[static_cast<std::size_t>(p)].law : soft.law;
      const std::string where = p >= 0 ? fmt::format("soft.pair[{}]", p) : std::string("soft");
      const auto known = [](double x, double y) { return !std::isnan(x) && !std::isnan(y); };
      const double mu = known(shape[a].mass, shape[b].mass)
                            ? reduced_mass(shape[a].mass, shape[b].mass)
                            : std::nan("");
      const double r_eff = known(shape[a].radius, shape[b].radius)
                               ? effective_radius(shape[a].radius, shape[b].radius)
                               : std::nan("");
      env.soft[a * n + b] = env.soft[b * n + a] =
          make_soft_law(c, mu, r_eff, where, fmt::format("species {} and {}", name(a), name(b)));
      env.soft_friction[a * n + b] = env.soft_friction[b * n + a] = soft_friction(c);
    }
  }
  if (!config.boundary.walls.empty()) {
    env.soft_wall.resize(n);
    env.soft_wall_friction.assign(n, soft_friction(soft.law));
    for (std::uint32_t a = 0; a < n; ++a) {
      env.soft_wall[a] = make_soft_law(soft.law, shape[a].mass, shape[a].radius, "soft",
                                       fmt::format("species {} against a wall", name(a)));
    }
  }
  env.soft_collisions = soft_collision_modes().at(soft.collisions);
}

}  // namespace

namespace {
// An outlet from its keys: the plane through `point` with the unit normal, and the insertion
// region (the reader made sure every vector has its D components; the velocity may be empty).
template <int D>
Outlet<D> make_outlet(const OutletConfig& oc) {
  Outlet<D> outlet;
  std::tie(outlet.normal, outlet.offset) = plane_through<D>(oc.normal, oc.point);
  outlet.insert_lower = to_vec<D>(oc.insert_lower);
  outlet.insert_upper = to_vec<D>(oc.insert_upper);
  outlet.insert_velocity = to_vec<D>(oc.insert_velocity);
  outlet.seed = oc.seed;
  return outlet;
}
}  // namespace

template <int D>
Environment<D> make_environment(const Config& config, const ParticleSystem<D>& state) {
  // Before anything is built from them (a cut-off of 1e300 would spin in the step tables).
  check_ranges(config, range_scales<D>(config, state));
  const std::vector<std::string>& species_names = state.species_names;
  Environment<D> env;
  const auto n = static_cast<std::uint32_t>(std::max<std::size_t>(1, species_names.size()));
  const InteractionConfig& in = config.interactions;
  if (!(in.contact == ContactConfig{}) || !in.pairs.empty() || in.tc > 0.0) {
    env.species = n;
    env.contact.assign(static_cast<std::size_t>(n) * n, make_contact_model(in.contact, "contact"));
    for (std::size_t p = 0; p < in.pairs.size(); ++p) {
      const std::string where = fmt::format("contact.pair[{}]", p);
      const std::uint32_t a = species_index(species_names, in.pairs[p].species[0], where);
      const std::uint32_t b = species_index(species_names, in.pairs[p].species[1], where);
      const ContactModel m = make_contact_model(in.pairs[p].contact, where);
      env.contact[a * n + b] = m;
      env.contact[b * n + a] = m;
    }
    env.tc = in.tc;
  }
  env.sleep_speed = in.sleep_speed;
  env.inertia_factor.assign(n, D == 3 ? kSolidSphereInertia : kDiskInertia);
  for (std::uint32_t s = 0; s < species_names.size(); ++s) {
    for (const SpeciesConfig& sc : config.system.species)
      if (sc.name == species_names[s] && sc.inertia_factor > 0.0)
        env.inertia_factor[s] = sc.inertia_factor;
  }
  for (std::size_t c = 0; c < config.system.species.size(); ++c) {
    const SpeciesConfig& sc = config.system.species[c];
    if (!sc.fixed) continue;
    const auto s = std::find(species_names.begin(), species_names.end(), sc.name);
    if (s == species_names.end()) {
      throw InputError(
          fmt::format("system.species[{}].fixed: the state has no species '{}' (its "
                      "species: {})",
                      c, sc.name, fmt::join(species_names, ", ")));
    }
    env.fixed.resize(n, 0);
    env.fixed[static_cast<std::size_t>(s - species_names.begin())] = 1;
  }
  for (std::size_t w = 0; w < config.boundary.walls.size(); ++w) {
    const WallConfig& wc = config.boundary.walls[w];
    const int f = face_index(wc.face, D);
    Face<D>& face = env.faces[f];
    face.kind = FaceKind::kWall;
    face.wall = make_wall<D>(wc, fmt::format("boundary.wall[{}]", w));
  }
  for_each_surface_table(config.boundary.surfaces, [&](auto table, const auto& entries) {
    for (std::size_t k = 0; k < entries.size(); ++k)
      table.add(entries[k], fmt::format("boundary.{}[{}]", table.key, k), env);
  });
  for (const std::string& open : config.boundary.open)
    env.faces[face_index(open, D)].kind = FaceKind::kOpen;
  if (const OutletConfig& oc = config.boundary.outlet; !oc.normal.empty())
    env.outlets.push_back(make_outlet<D>(oc));
  if (const ContainerConfig& box = config.boundary.container; !box.axis.empty()) {
    // Both walls of the axis become one body (boundaries/wall_spring.hpp).
    const int axis = static_cast<int>(axes(D).at(box.axis));
    for (int f = 2 * axis; f < 2 * axis + 2; ++f) {
      Wall<D>& w = env.faces[f].wall;
      w.mass = box.mass;
      w.joined = true;
      w.spring = {box.spring_stiffness, box.spring_damping, box.drive_amplitude,
                  2.0 * std::numbers::pi * box.drive_frequency, box.drive_phase};
    }
  }
  env.gravity = to_vec<D>(config.field.gravity);
  env.shear_rate = config.boundary.shear_rate;
  add_step_potentials(config, state, env);
  add_soft_laws(config, state, env);
  env.check();
  return env;
}

double face_wall_offset(const WallConfig& wc, int dimension, double t) {
  const auto offset = [&]<int D>() {
    return wall_motion<D>(wc).plane_position(face_index(wc.face, D), Vec<D>{}, t);
  };
  return dimension == 2 ? offset.template operator()<2>() : offset.template operator()<3>();
}

template Environment<2> make_environment<2>(const Config&, const ParticleSystem<2>&);
template Environment<3> make_environment<3>(const Config&, const ParticleSystem<3>&);

}  // namespace kairos
