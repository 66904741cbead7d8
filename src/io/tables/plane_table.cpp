#include "io/tables/plane_table.hpp"

#include <fmt/format.h>

#include <cmath>
#include <tuple>

#include "io/config_choices.hpp"
#include "io/config_keys.hpp"
#include "io/config_models.hpp"
#include "io/keys/key_tables.hpp"
#include "io/range_checks.hpp"
#include "model/environment.hpp"

namespace kairos {

namespace {

using namespace key_tables;

bool span_given(const void* p) {
  return !static_cast<const PlaneConfig*>(p)->span_axis.empty();
}
bool span_min_given(const void* p) {
  return std::isfinite(static_cast<const PlaneConfig*>(p)->span_min);
}
bool span_max_given(const void* p) {
  return std::isfinite(static_cast<const PlaneConfig*>(p)->span_max);
}
bool hole_given(const void* p) {
  return static_cast<const PlaneConfig*>(p)->hole_radius > 0.0;
}
bool hole_center_given(const void* p) {
  return !static_cast<const PlaneConfig*>(p)->hole_center.empty();
}

const PlaneConfig kPlaneDefaults{};
constexpr KeyDecl kPlane[] = {
    {.name = "normal",
     .type = KeyType::kVector,
     .member = field<&PlaneConfig::normal>,
     .range = {.by_rule = true},  // not zero, no component along a periodic axis
     .default_text = "**required**",
     .doc = "the plane's normal, pointing into the domain (normalised)"},
    {.name = "point",
     .type = KeyType::kVector,
     .member = field<&PlaneConfig::point>,
     .range = {.by_rule = true},  // finite
     .default_text = "**required**",
     .unit = "length",
     .doc = "a point of the plane at t = 0"},
    {.name = "span_axis",
     .type = KeyType::kString,
     .member = field<&PlaneConfig::span_axis>,
     .range = {.by_rule = true},  // a bounded axis the plane runs along; a still plane
     .choices = &choices_in<&axes>,
     .doc = "cut the plane to a strip along this axis, with edges at its ends (a silo's floor "
            "beside its orifice, a hopper's side); \"\": the whole plane",
     .written = &span_given},
    {.name = "span_min",
     .type = KeyType::kFloat,
     .member = field<&PlaneConfig::span_min>,
     .range = {.by_rule = true},  // below span_max
     .default_text = "unbounded",
     .unit = "length",
     .doc = "the strip's low end along span_axis (of the plane's points)",
     .written = &span_min_given},
    {.name = "span_max",
     .type = KeyType::kFloat,
     .member = field<&PlaneConfig::span_max>,
     .range = {.by_rule = true},  // above span_min
     .default_text = "unbounded",
     .unit = "length",
     .doc = "the strip's high end along span_axis",
     .written = &span_max_given},
    {.name = "hole_radius",
     .type = KeyType::kFloat,
     .member = field<&PlaneConfig::hole_radius>,
     .range = {.lo = 0.0, .hi = 1e6, .scale = Scale::kLength},
     .default_text = "no hole",
     .unit = "length",
     .doc = "3D: a circular hole in the plane (a silo's or hopper's round orifice), larger "
            "than the particles; the plane is then a plate met on both faces, the hole's edge "
            "a ring (a still plane, not a strip)",
     .written = &hole_given},
    {.name = "hole_center",
     .type = KeyType::kVector,
     .member = field<&PlaneConfig::hole_center>,
     .range = {.by_rule = true},  // finite; with hole_radius
     .default_text = "`point`",
     .unit = "length",
     .doc = "the hole's centre (projected onto the plane)",
     .written = &hole_center_given},
};

constexpr KeyGroup kPlaneGroup{"plane", kPlane, &kPlaneDefaults};

}  // namespace

std::vector<PlacedGroup> PlaneTable::placement() {
  return {{&kPlaneGroup}, {&contact_law_keys(), "contact"}, {&wall_keys(), "boundary.wall"}};
}

// Its normal (not zero; kept as written, normalised by add) and point, then the contact law and
// the motion keys of a face wall. Whether it cuts a periodic axis is checked with the box
// (Environment::check).
void PlaneTable::read(const TableReading& r, PlaneConfig& plane) {
  const std::string& prefix = r.prefix();
  const int dimension = r.dimension();
  r.read_group(kPlaneGroup, &plane);
  r.require_vectors({"normal", "point"});
  r.require_nonzero("normal", plane.normal, "it points into the domain");
  r.read_contact(plane.wall.contact);
  r.read_group(wall_keys(), &plane.wall);
  // A strip: an axis of the box, and at least one end below the other.
  if (plane.span_axis.empty()) {
    for (const char* key : {"span_min", "span_max"}) {
      if (r.has(key)) {
        r.fail(key,
               fmt::format("{}.{}: a span needs its axis ({}.span_axis)", prefix, key, prefix));
      }
    }
  } else if (!axes(dimension).contains(plane.span_axis)) {
    r.fail("span_axis", fmt::format("{}.span_axis: '{}' is not an axis of the box ({})", prefix,
                                    plane.span_axis, axes(dimension).names(", ", " or ")));
  } else if (!(plane.span_min < plane.span_max)) {
    r.fail("span_max", fmt::format("{}.span_max: must be above span_min ({} <= {})", prefix,
                                   plane.span_max, plane.span_min));
  } else if (std::isinf(plane.span_min) && std::isinf(plane.span_max)) {
    r.fail("span_axis",
           fmt::format("{}.span_axis: give span_min, span_max or both (where the strip ends)",
                       prefix));
  }
  // A circular hole: in 3D, in a whole plane, its centre only with it.
  if (plane.hole_radius > 0.0) {
    if (dimension != 3) {
      r.fail("hole_radius",
             fmt::format("{}.hole_radius: a hole is for planes in 3D (in 2D cut the line into two "
                         "strips: span_axis)",
                         prefix));
    }
    if (!plane.span_axis.empty()) {
      r.fail("hole_radius",
             fmt::format("{}.hole_radius: a strip (span_axis) cannot also have a hole", prefix));
    }
  } else if (r.has("hole_center")) {
    r.fail("hole_center", fmt::format("{}.hole_center: give the hole's radius too ({}.hole_radius)",
                                      prefix, prefix));
  }
  for (const double c : plane.hole_center) {
    if (!std::isfinite(c)) r.fail("hole_center", prefix + ".hole_center: must be finite");
  }
  // Walls with mass are the faces' (boundaries/wall_body.hpp) for now.
  for (const char* key : {"mass", "force"}) {
    if ((key[0] == 'm' ? plane.wall.mass : plane.wall.force) == 0.0) continue;
    r.fail(key, fmt::format("{}.{}: only the walls on the box's faces ([[boundary.wall]]) can "
                            "have mass yet",
                            prefix, key));
  }
}

std::string PlaneTable::toml(const PlaneConfig& plane, std::size_t dimension) {
  constexpr std::string_view path = "boundary.plane";
  return group_toml(kPlaneGroup, &plane, path, dimension) +
         group_toml(contact_law_keys(), &plane.wall.contact, path, dimension) +
         group_toml(wall_keys(), &plane.wall, path, dimension);
}

// Its point lies within 1e6 box edges of the box (further, n.x loses the particles' digits),
// and its wall keys are a face wall's.
void PlaneTable::check_ranges(const PlaneConfig& plane, const std::string& prefix,
                              const RangeScales& s) {
  for (std::size_t a = 0; a < plane.point.size(); ++a)
    range_checks::length_within_box(fmt::format("{}.point[{}]", prefix, a), plane.point[a], s);
  range_checks::check_wall(plane.wall, prefix, s.longest_edge(), s);
  if (plane.hole_radius > 0.0) {
    range_checks::within_declared(prefix + ".hole_radius", plane.hole_radius, s.d_max,
                                  range_checks::length_unit(s));
  }
}

template <int D>
void PlaneTable::add(const PlaneConfig& pc, const std::string& prefix, Environment<D>& env) {
  PlaneWall<D> plane;
  std::tie(plane.normal, plane.offset) = plane_through<D>(pc.normal, pc.point);
  plane.wall = make_wall<D>(pc.wall, prefix);
  if (!pc.span_axis.empty()) {
    plane.span_axis = static_cast<int>(axes(D).at(pc.span_axis));
    plane.span_min = pc.span_min;
    plane.span_max = pc.span_max;
  }
  if (pc.hole_radius > 0.0) {
    plane.hole_radius = pc.hole_radius;
    const std::vector<double>& c = pc.hole_center.empty() ? pc.point : pc.hole_center;
    Vec<D> center{};
    for (int a = 0; a < D && a < static_cast<int>(c.size()); ++a) center[a] = c[a];
    plane.hole_center = center - (dot(plane.normal, center) - plane.offset) * plane.normal;
  }
  surface_specs<PlaneWalls<D>>(env).push_back(plane);
}

std::optional<TableObstacle> PlaneTable::motion(const PlaneConfig& plane) {
  if (wall_moves(plane.wall)) return TableObstacle{"", "a moving wall is not an equilibrium state"};
  return std::nullopt;
}

// A vibration, a mass or a velocity along its normal (fixed grains predict no wall contacts).
std::optional<TableObstacle> PlaneTable::normal_motion(const PlaneConfig& plane) {
  const char* why = "a fixed grain would not see the moving wall coming";
  if (plane.wall.amplitude > 0.0 && plane.wall.frequency > 0.0)
    return TableObstacle{".amplitude", why};
  if (plane.wall.mass > 0.0) return TableObstacle{".mass", why};
  double along = 0.0;
  for (std::size_t a = 0; a < plane.normal.size() && a < plane.wall.velocity.size(); ++a)
    along += plane.normal[a] * plane.wall.velocity[a];
  if (along != 0.0) return TableObstacle{".velocity", why};
  return std::nullopt;
}

template void PlaneTable::add<2>(const PlaneConfig&, const std::string&, Environment<2>&);
template void PlaneTable::add<3>(const PlaneConfig&, const std::string&, Environment<3>&);

}  // namespace kairos
