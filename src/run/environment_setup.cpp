#include "run/environment_setup.hpp"

#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "core/error.hpp"

namespace kairos {

namespace {

int face_index(const std::string& face, int dimension) {
  static const char* names[] = {"x-", "x+", "y-", "y+", "z-", "z+"};
  for (int f = 0; f < 2 * dimension; ++f)
    if (face == names[f]) return f;
  throw InputError(fmt::format("boundary: '{}' is not a face of a {}D box", face, dimension));
}

std::uint32_t species_index(const std::vector<std::string>& names, const std::string& name,
                            const std::string& where) {
  for (std::size_t k = 0; k < names.size(); ++k)
    if (names[k] == name) return static_cast<std::uint32_t>(k);
  throw InputError(fmt::format("{}: the system has no species '{}'", where, name));
}

}  // namespace

ContactModel make_contact_model(const ContactConfig& c, const std::string& where) {
  ContactModel m;
  try {
    if (c.restitution_model == "viscoelastic") {
      m.normal = NormalRestitution::viscoelastic_at(c.restitution, c.restitution_speed);
    } else if (c.restitution_model == "table") {
      std::vector<double> speeds, values;
      for (const auto& row : c.restitution_table) {
        speeds.push_back(row[0]);
        values.push_back(row[1]);
      }
      m.normal = NormalRestitution::table(std::move(speeds), std::move(values));
    } else {
      m.normal = NormalRestitution::constant(c.restitution);
    }
    m.tangential = std::isfinite(c.friction)
                       ? TangentialModel::walton(c.friction, c.tangential_restitution)
                       : TangentialModel::constant(c.tangential_restitution);
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: {}", where, e.what()));
  }
  m.elastic_below_speed = c.elastic_below_speed;
  return m;
}

template <int D>
Environment<D> make_environment(const Config& config,
                                const std::vector<std::string>& species_names) {
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
  for (std::size_t w = 0; w < config.boundary.walls.size(); ++w) {
    const WallConfig& wc = config.boundary.walls[w];
    const int f = face_index(wc.face, D);
    Face<D>& face = env.faces[f];
    face.kind = FaceKind::kWall;
    face.wall.contact = make_contact_model(wc.contact, fmt::format("boundary.wall[{}]", w));
    for (int a = 0; a < D && a < static_cast<int>(wc.velocity.size()); ++a)
      face.wall.velocity[a] = wc.velocity[a];
    face.wall.amplitude = wc.amplitude;
    face.wall.angular_frequency = 2.0 * std::numbers::pi * wc.frequency;
    face.wall.phase = wc.phase;
  }
  for (const std::string& open : config.boundary.open)
    env.faces[face_index(open, D)].kind = FaceKind::kOpen;
  for (int a = 0; a < D && a < static_cast<int>(config.field.gravity.size()); ++a)
    env.gravity[a] = config.field.gravity[a];
  env.shear_rate = config.boundary.shear_rate;
  env.check();
  return env;
}

template Environment<2> make_environment<2>(const Config&, const std::vector<std::string>&);
template Environment<3> make_environment<3>(const Config&, const std::vector<std::string>&);

}  // namespace kairos
