// The boundary geometries' config tables (io/surface_tables.hpp): every table written and read
// back exactly, each entry's contact law starting from [contact]'s, in the order of
// docs/config.md; the tables' own refusals (a plane with mass) and what fixed grains refuse of
// them (a surface moving along its normal).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cstddef>
#include <string>

#include "config_testing.hpp"
#include "io/config.hpp"

namespace kairos {
namespace {

using namespace config_testing;

// Every surface table (io/surface_tables.hpp) writes its entries and reads them back exactly,
// each entry's contact law starting from [contact]'s.
TEST(SurfaceTables, RoundTripWithEverySurfaceTable) {
  std::string walls;
  for (const char* face : {"x-", "x+", "y-", "y+", "z-", "z+"})
    walls += fmt::format("[[boundary.wall]]\nface = \"{}\"\n", face);
  Config c = parse_config(R"([system]
particles = 200
packing_fraction = 0.2
box_scale = [1.0, 1.0, 3.0]
[contact]
restitution = 0.7
)" + walls + R"(
[[boundary.plane]]
normal = [0.0, 0.0, 1.0]
point = [0.0, 0.0, 0.5]
hole_radius = 1.5
restitution = 0.5
[[boundary.plane]]
normal = [0.0, 1.0, 1.0]
point = [0.0, 0.0, 3.0]
span_axis = "y"
span_max = 2.0
[[boundary.cylinder]]
axis = "x"
center = [0.0, 3.0, 3.0]
radius = 2.5
angular_velocity = 0.125
friction = 0.5
tangential_restitution = 0.2
[[boundary.sphere]]
center = [3.0, 3.0, 6.0]
radius = 0.75
inside = false
[boundary.outlet]
normal = [0.0, 0.0, 1.0]
point = [0.0, 0.0, 0.2]
insert_lower = [1.0, 1.0, 5.0]
insert_upper = [2.0, 2.0, 6.0]
)",
                          "surfaces.toml");
  const auto& planes = c.boundary.surfaces.of<PlaneTable>();
  const auto& cylinders = c.boundary.surfaces.of<CylinderTable>();
  const auto& spheres = c.boundary.surfaces.of<SphereTable>();
  ASSERT_EQ(planes.size(), 2u);
  ASSERT_EQ(cylinders.size(), 1u);
  ASSERT_EQ(spheres.size(), 1u);
  EXPECT_EQ(planes[0].wall.contact.restitution, 0.5);
  EXPECT_EQ(planes[1].wall.contact.restitution, 0.7);  // [contact]'s
  EXPECT_EQ(planes[1].span_max, 2.0);
  EXPECT_EQ(cylinders[0].contact.friction, 0.5);
  EXPECT_EQ(cylinders[0].contact.restitution, 0.7);
  EXPECT_FALSE(spheres[0].inside);
  const std::string text = to_toml(c);
  // Written in the order of docs/config.md: the outlet, then the tables of SurfaceTables.
  std::size_t at = 0;
  for (const char* table : {"[[boundary.wall]]", "[boundary.outlet]", "[[boundary.plane]]",
                            "[[boundary.cylinder]]", "[[boundary.sphere]]"}) {
    const std::size_t found = text.find(table);
    ASSERT_NE(found, std::string::npos) << table << "\n" << text;
    EXPECT_GE(found, at) << table << "\n" << text;
    at = found;
  }
  const Config back = parse_config(text, "config.toml");
  EXPECT_EQ(back, c) << text;
  EXPECT_EQ(to_toml(back), text);
}

TEST(SurfaceTables, APlaneWithMassIsAnError) {
  expect_error(minimal_plus("[[boundary.plane]]\nnormal = [0.0, 0.0, 1.0]\npoint = [0.0, 0.0, "
                            "1.0]\nmass = 5.0"),
               {"boundary.plane[0].mass", "only the walls on the box's faces"});
}

// A fixed grain predicts no wall contacts: every surface table says what moves it along its
// normal (PlaneTable::normal_motion), and only that is refused; a plane sliding in itself and a
// rotating drum are not.
TEST(SurfaceTables, FixedGrainsRefuseASurfaceMovingAlongItsNormal) {
  const std::string fixed = "species = [{name = \"g\"}, {name = \"f\", fixed = true}]\n";
  const std::string plane =
      "[[boundary.plane]]\nnormal = [0.0, 0.0, 1.0]\npoint = [0.0, 0.0, 1.0]\n";
  expect_error(minimal_plus(fixed + plane + "velocity = [0.0, 0.0, 0.5]"),
               {"boundary.plane[0].velocity", "would not see the moving wall coming"});
  expect_error(minimal_plus(fixed + plane + "amplitude = 0.1\nfrequency = 2.0"),
               {"boundary.plane[0].amplitude", "would not see the moving wall coming"});
  EXPECT_NO_THROW(parse_config(minimal_plus(fixed + plane + "velocity = [0.5, 0.0, 0.0]"), "t"));
  EXPECT_NO_THROW(parse_config(
      minimal_plus(fixed + "[[boundary.cylinder]]\ncenter = [5.0, 5.0, 5.0]\nradius = 4.0\n"
                           "angular_velocity = 0.5"),
      "t"));
}

}  // namespace
}  // namespace kairos
