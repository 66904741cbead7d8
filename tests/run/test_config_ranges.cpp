// The ranges of the config's dimensional keys (src/run/config_ranges.hpp): the defaults and the
// examples' values pass, values out of range are InputErrors naming the key, the value and the
// range in the key's own units, and the scales come from the start state.
#include "run/config_ranges.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "core/error.hpp"
#include "io/config.hpp"

namespace kairos {
namespace {

constexpr std::string_view kBase = R"([system]
particles = 500
packing_fraction = 0.3
)";

// The message of the InputError that check_ranges throws for the config ("" if none), with a
// periodic box of edge 10.
std::string range_error(const std::string& extra, const std::vector<std::string>& overrides = {}) {
  const Config c = parse_config(std::string(kBase) + extra, "test.toml", overrides);
  RangeScales s = range_scales(c);
  s.box = {10.0, 10.0, 10.0};
  s.number_density = 0.5;
  try {
    check_ranges(c, s);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

void expect_range_error(const std::string& extra, const std::vector<std::string>& fragments) {
  const std::string m = range_error(extra);
  EXPECT_FALSE(m.empty()) << "no range error for:\n" << extra;
  for (const std::string& f : fragments) EXPECT_NE(m.find(f), std::string::npos) << m;
}

TEST(ConfigRanges, DefaultsAndTypicalValuesPass) {
  EXPECT_EQ(range_error(""), "");
  EXPECT_EQ(range_error("[soft]\nmodel = \"hertz\"\nyoung = 1e5\nrestitution = 0.3\n"), "");
  EXPECT_EQ(range_error("[soft]\nmodel = \"dashpot\"\nstiffness = 1e4\nrestitution = 0.9\n"), "");
  EXPECT_EQ(range_error("[[potential]]\nkind = \"lennard_jones\"\ncutoff = 2.5\n"), "");
  EXPECT_EQ(range_error("[driving]\nkind = \"andersen\"\nrate = 5.0\n"), "");
  EXPECT_EQ(range_error("[boundary]\nshear_rate = 0.5\n"), "");
}

TEST(ConfigRanges, KeysOutOfRangeNameKeyValueAndRange) {
  expect_range_error("[[potential]]\nkind = \"lennard_jones\"\ncutoff = 1e300\n",
                     {"potential[0]", "1e+300", "half the smallest box edge", "5"});
  expect_range_error("[[potential]]\nkind = \"lennard_jones\"\nepsilon = 1e300\n",
                     {"potential[0].epsilon", "must be in [1e-09, 1e+09]", "kT = 1"});
  expect_range_error("[driving]\nkind = \"andersen\"\nrate = 1e300\n",
                     {"driving.rate = 1e+300", "1e-9 to 1e3 times the collision rate"});
  expect_range_error("[driving]\nkind = \"white_noise\"\nstrength = 1e300\n",
                     {"driving.strength = 1e+300", "1e-9 to 1e9 times v^2 / tau"});
  expect_range_error(
      "[[boundary.wall]]\nface = \"z-\"\nfrequency = 1e300\n[[boundary.wall]]\n"
      "face = \"z+\"\n",
      {"boundary.wall[0].frequency", "up to 1e9 / tau"});
  expect_range_error("[driving]\nkind = \"andersen\"\ntemperature = 1e300\n",
                     {"driving.temperature = 1e+300", "[1e-09, 1e+09]"});
  expect_range_error(
      "[soft]\nmodel = \"hertz\"\nyoung = 1e5\nrestitution = 0.8\n"
      "restitution_speed = 1e-300\n",
      {"soft.restitution_speed = 1e-300", "[1e-06, 1e+06]", "thermal speed"});
  expect_range_error("[soft]\nmodel = \"hertz\"\nyoung = 1e300\n",
                     {"soft.young = 1e+300", "kT / d^3"});
  expect_range_error("[soft]\nmodel = \"dashpot\"\nstiffness = 1e300\n",
                     {"soft.stiffness = 1e+300", "kT / d^2"});
  expect_range_error("[boundary]\nshear_rate = 1e300\n", {"boundary.shear_rate", "1e6 / tau"});
  expect_range_error(
      "[[boundary.wall]]\nface = \"z-\"\namplitude = 1e300\n[[boundary.wall]]\n"
      "face = \"z+\"\n",
      {"boundary.wall[0].amplitude", "1e6 box edges"});
  expect_range_error("[run]\ntime = 1e300\n", {"run.time = 1e+300", "tau"});
  expect_range_error("[output]\nthermo_interval = 1e-300\n",
                     {"output.thermo_interval", "1e-6 of the production length"});
  expect_range_error("[contact]\ntc = 1e300\n", {"contact.tc", "tau"});
}

// Each surface table (io/surface_tables.hpp) checks its own keys, named by its entry: a plane's
// point and wall motion, a cylinder's or sphere's place, rotation and contact law.
TEST(ConfigRanges, SurfaceTablesCheckTheirOwnKeys) {
  const std::string walls =
      "[[boundary.wall]]\nface = \"z-\"\n[[boundary.wall]]\nface = \"z+\"\n"
      "[[boundary.wall]]\nface = \"x-\"\n[[boundary.wall]]\nface = \"x+\"\n"
      "[[boundary.wall]]\nface = \"y-\"\n[[boundary.wall]]\nface = \"y+\"\n";
  const std::string plane = "[[boundary.plane]]\nnormal = [0.0, 0.0, 1.0]\n";
  EXPECT_EQ(range_error(walls + plane + "point = [5.0, 5.0, 1.0]\n"), "");
  expect_range_error(walls + plane + "point = [5.0, 5.0, 1e300]\n",
                     {"boundary.plane[0].point[2] = 1e+300", "1e6 times the longest box edge"});
  expect_range_error(walls + plane + "point = [5.0, 5.0, 1.0]\nfrequency = 1e300\n",
                     {"boundary.plane[0].frequency", "up to 1e9 / tau"});
  const std::string drum = "[[boundary.cylinder]]\ncenter = [5.0, 5.0, 5.0]\nradius = 4.0\n";
  EXPECT_EQ(range_error(walls + drum), "");
  expect_range_error(walls + drum + "angular_velocity = 1e300\n",
                     {"boundary.cylinder[0].angular_velocity", "1e6 / tau"});
  // The round walls' contact law is checked in the run's units as a face wall's is.
  expect_range_error(walls + drum +
                         "restitution = 0.8\nrestitution_model = \"viscoelastic\"\n"
                         "restitution_speed = 1e-300\n",
                     {"boundary.cylinder[0].restitution_speed = 1e-300", "thermal speed"});
  expect_range_error(walls + "[[boundary.sphere]]\ncenter = [5.0, 5.0, 5.0]\nradius = 1e300\n",
                     {"boundary.sphere[0].radius = 1e+300", "1e6 times the longest box edge"});
}

TEST(ConfigRanges, OpenFacesNeedGravityPullingBack) {
  const std::string open = "[[boundary.wall]]\nface = \"z-\"\n[boundary]\nopen = [\"z+\"]\n";
  EXPECT_EQ(range_error(open + "[field]\ngravity = [0, 0, -1]\n"), "");
  expect_range_error(open, {"boundary.open", "z+", "fly off"});
  expect_range_error(open + "[field]\ngravity = [0, 0, 1e-12]\n", {"does not pull"});
  expect_range_error(open + "[field]\ngravity = [0, 0, -1e-12]\n",
                     {"field.gravity[2] = -1e-12", "too weak"});
}

TEST(ConfigRanges, ScalesFollowTheUnits) {
  // The same stiffness is fine for kT = 1 and out of range for kT = 1e-9 (k d^2 / kT = 1e19).
  const std::string soft = "[soft]\nmodel = \"dashpot\"\nstiffness = 1e10\n";
  EXPECT_EQ(range_error(soft), "");
  const Config c = parse_config(std::string(kBase) + soft, "t", {"system.temperature=1e-9"});
  EXPECT_THROW(check_ranges(c, range_scales(c)), InputError);
}

TEST(ConfigRanges, PotentialWithoutABoxIsBoundedByTheDiameter) {
  PotentialSpec p;
  p.kind = "lennard_jones";
  p.cutoff = 1e7;
  RangeScales s;  // no box: kairos steps
  EXPECT_THROW(check_potential_ranges(p, "potential[0]", s), InputError);
  p.cutoff = 50.0;
  EXPECT_NO_THROW(check_potential_ranges(p, "potential[0]", s));
}

}  // namespace
}  // namespace kairos
