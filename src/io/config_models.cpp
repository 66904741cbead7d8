#include "io/config_models.hpp"

#include <fmt/format.h>

#include <cmath>
#include <numbers>
#include <utility>

#include "core/error.hpp"
#include "io/config_choices.hpp"

namespace kairos {

ContactModel make_contact_model(const ContactConfig& c, const std::string& where) {
  ContactModel m;
  try {
    switch (restitution_models().at(c.restitution_model)) {
      case RestitutionModel::kViscoelastic:
        m.normal = NormalRestitution::viscoelastic_at(c.restitution, c.restitution_speed);
        break;
      case RestitutionModel::kTable: {
        std::vector<double> speeds, values;
        for (const auto& row : c.restitution_table) {
          speeds.push_back(row[0]);
          values.push_back(row[1]);
        }
        m.normal = NormalRestitution::table(std::move(speeds), std::move(values));
        break;
      }
      case RestitutionModel::kConstant:
        m.normal = NormalRestitution::constant(c.restitution);
        break;
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

// A vector key (the reader made sure it has D components, or none: then zero).
template <int D>
Vec<D> to_vec(const std::vector<double>& v) {
  Vec<D> out{};
  for (int a = 0; a < D && a < static_cast<int>(v.size()); ++a) out[a] = v[a];
  return out;
}

// The plane through `point` with the given normal (not 0: the reader), as (unit normal, offset)
// of n . x = offset: a plane wall's or an outlet's.
template <int D>
std::pair<Vec<D>, double> plane_through(const std::vector<double>& normal,
                                        const std::vector<double>& point) {
  Vec<D> n = to_vec<D>(normal);
  n = (1.0 / std::sqrt(norm2(n))) * n;
  return {n, dot(n, to_vec<D>(point))};
}

// A wall's contact law and motion from its keys (a face wall's or a plane's).
template <int D>
Wall<D> make_wall(const WallConfig& wc, const std::string& where) {
  Wall<D> wall = wall_motion<D>(wc);
  wall.contact = make_contact_model(wc.contact, where);
  return wall;
}
template <int D>
Wall<D> wall_motion(const WallConfig& wc) {
  Wall<D> wall;
  wall.velocity = to_vec<D>(wc.velocity);
  wall.amplitude = wc.amplitude;
  wall.angular_frequency = 2.0 * std::numbers::pi * wc.frequency;
  wall.phase = wc.phase;
  wall.mass = wc.mass;
  wall.force = wc.force;
  return wall;
}

template Vec<2> to_vec<2>(const std::vector<double>&);
template Vec<3> to_vec<3>(const std::vector<double>&);
template std::pair<Vec<2>, double> plane_through<2>(const std::vector<double>&,
                                                    const std::vector<double>&);
template std::pair<Vec<3>, double> plane_through<3>(const std::vector<double>&,
                                                    const std::vector<double>&);
template Wall<2> make_wall<2>(const WallConfig&, const std::string&);
template Wall<3> make_wall<3>(const WallConfig&, const std::string&);
template Wall<2> wall_motion<2>(const WallConfig&);
template Wall<3> wall_motion<3>(const WallConfig&);

}  // namespace kairos
