#include "io/tables/round_tables.hpp"

#include <fmt/format.h>

#include <cmath>

#include "io/config_choices.hpp"
#include "io/config_keys.hpp"
#include "io/config_models.hpp"
#include "io/keys/key_tables.hpp"
#include "io/range_checks.hpp"
#include "model/environment.hpp"

namespace kairos {

namespace {

using namespace key_tables;

const CylinderConfig kCylinderDefaults{};
constexpr KeyDecl kCylinder[] = {
    {.name = "axis",
     .type = KeyType::kString,
     .member = field<&CylinderConfig::axis>,
     .range = {.by_rule = true},  // x, y or z; 2D: z only
     .default_text = "`\"z\"`",
     .doc = "the direction of its axis: x, y or z (2D: z, the circle in the plane)"},
    {.name = "center",
     .type = KeyType::kVector,
     .member = field<&CylinderConfig::center>,
     .range = {.by_rule = true},  // finite
     .default_text = "**required**",
     .unit = "length",
     .doc = "a point of its axis"},
    {.name = "radius",
     .type = KeyType::kFloat,
     .member = field<&CylinderConfig::radius>,
     .range = {.lo = 0.0, .lo_open = true},
     .default_text = "**required**",
     .unit = "length",
     .doc = "its radius"},
    {.name = "inside",
     .type = KeyType::kBoolean,
     .member = field<&CylinderConfig::inside>,
     .doc = "the particles are inside it (a drum, a silo); false: outside (an obstacle)"},
    {.name = "angular_velocity",
     .type = KeyType::kFloat,
     .member = field<&CylinderConfig::angular_velocity>,
     .range = {.lo = -1e6, .hi = 1e6, .scale = Scale::kRate},
     .unit = "radians / time",
     .doc = "its rotation about the axis, right-handed (a rotating drum)"},
};

constexpr KeyGroup kCylinderGroup{"cylinder", kCylinder, &kCylinderDefaults};

}  // namespace

template <bool Sphere>
std::vector<PlacedGroup> RoundTable<Sphere>::placement() {
  // A sphere's keys are documented with the cylinder's.
  return {{&kCylinderGroup, Sphere ? "boundary.cylinder" : ""}, {&contact_law_keys(), "contact"}};
}

// Its axis (2D: z), center and radius (required), the side the particles are on and its
// rotation, then its contact law. Whether it crosses a periodic face is checked with the box
// (Environment::check).
template <bool Sphere>
void RoundTable<Sphere>::read(const TableReading& r, CylinderConfig& round) {
  const std::string& prefix = r.prefix();
  r.read_group(kCylinderGroup, &round);
  for (const char* key : {"center", "radius"}) {
    if (!r.has(key)) {
      r.fail(key, fmt::format("missing required key '{}.{}'{}", prefix, key,
                              std::string_view(key) == "center"
                                  ? fmt::format(" ({} numbers)", r.dimension())
                                  : std::string(" (> 0)")));
    }
  }
  if (!axes(3).contains(round.axis)) {
    r.fail("axis", fmt::format("{}.axis: '{}' is not an axis (x, y or z)", prefix, round.axis));
  }
  if (r.dimension() == 2 && round.axis != "z") {
    r.fail("axis", fmt::format("{}.axis: '{}': in 2D a {} is a circle in the plane, its axis is z",
                               prefix, round.axis, key));
  }
  for (const double c : round.center) {
    if (!std::isfinite(c)) r.fail("center", prefix + ".center: must be finite");
  }
  r.read_contact(round.contact);
}

template <bool Sphere>
std::string RoundTable<Sphere>::toml(const CylinderConfig& round, std::size_t dimension) {
  const std::string path = fmt::format("boundary.{}", key);
  return group_toml(kCylinderGroup, &round, path, dimension) +
         group_toml(contact_law_keys(), &round.contact, path, dimension);
}

// Its center and radius lie within 1e6 box edges (further, |x - c| loses the particles'
// digits); its rotation as fast as a shear rate at most (faster, the surface's sweep swamps
// every collision); its contact law's speeds in the run's.
template <bool Sphere>
void RoundTable<Sphere>::check_ranges(const CylinderConfig& round, const std::string& prefix,
                                      const RangeScales& s) {
  using namespace range_checks;
  for (std::size_t a = 0; a < round.center.size(); ++a)
    length_within_box(fmt::format("{}.center[{}]", prefix, a), round.center[a], s);
  length_within_box(prefix + ".radius", round.radius, s);
  const double fastest = declared(prefix + ".angular_velocity").hi;
  magnitude_within(prefix + ".angular_velocity", round.angular_velocity, fastest / s.time(),
                   short_number(fastest) + " / tau, " + time_unit(s));
  check_contact(round.contact, prefix, s);
}

template <bool Sphere>
template <int D>
void RoundTable<Sphere>::add(const CylinderConfig& cc, const std::string& prefix,
                             Environment<D>& env) {
  CylinderWall<D> round;
  round.axis = D == 2 ? D - 1 : static_cast<int>(axes(3).at(cc.axis));
  round.center = to_vec<D>(cc.center);
  round.radius = cc.radius;
  round.inside = cc.inside;
  round.angular_velocity = cc.angular_velocity;
  round.contact = make_contact_model(cc.contact, prefix);
  constexpr RoundShape shape = Sphere ? RoundShape::kSphere : RoundShape::kCylinder;
  surface_specs<RoundWalls<D, shape>>(env).push_back(round);
}

template <bool Sphere>
std::optional<TableObstacle> RoundTable<Sphere>::motion(const CylinderConfig& round) {
  if (round.angular_velocity != 0.0)
    return TableObstacle{".angular_velocity", "a rotating wall is not an equilibrium state"};
  return std::nullopt;
}

// Its rotation moves it within its own surface, never along its normal.
template <bool Sphere>
std::optional<TableObstacle> RoundTable<Sphere>::normal_motion(const CylinderConfig& /*round*/) {
  return std::nullopt;
}

template struct RoundTable<false>;
template struct RoundTable<true>;
template void RoundTable<false>::add<2>(const CylinderConfig&, const std::string&, Environment<2>&);
template void RoundTable<false>::add<3>(const CylinderConfig&, const std::string&, Environment<3>&);
template void RoundTable<true>::add<2>(const CylinderConfig&, const std::string&, Environment<2>&);
template void RoundTable<true>::add<3>(const CylinderConfig&, const std::string&, Environment<3>&);

}  // namespace kairos
