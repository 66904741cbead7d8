// Tests for the soft-sphere keys ([soft], [[soft.pair]]) and run.integrator / run.time_step:
// values, inheritance, every error, overrides and the to_toml round trip.
#include <gtest/gtest.h>

#include <initializer_list>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.hpp"
#include "io/config.hpp"

namespace kairos {
namespace {

constexpr std::string_view kBase = R"([system]
particles = 500
packing_fraction = 0.1
[[system.species]]
name = "A"
[[system.species]]
name = "B"
diameter = 1.2
)";

std::string with(std::string_view extra) {
  return std::string(kBase) + std::string(extra) + "\n";
}

void expect_error(std::string_view text, std::initializer_list<std::string_view> fragments,
                  const std::vector<std::string>& overrides = {}) {
  try {
    parse_config(text, "test.toml", overrides);
    ADD_FAILURE() << "no InputError for:\n" << text;
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    for (const std::string_view f : fragments)
      EXPECT_NE(message.find(f), std::string::npos) << "lacks '" << f << "': " << message;
  }
}

TEST(ConfigSoft, AbsentMeansHardSpheresAndTheEventIntegrator) {
  const Config c = parse_config(kBase, "test.toml");
  EXPECT_FALSE(c.soft.enabled());
  const SoftConfig defaults;
  EXPECT_EQ(c.soft, defaults);
  EXPECT_EQ(c.run.integrator, "event");
  EXPECT_EQ(c.run.time_step, 0.0);
}

TEST(ConfigSoft, DashpotAndHertzKeysAndPairInheritance) {
  const Config c = parse_config(with(R"(
[soft]
model = "dashpot"
stiffness = 2e4
restitution = 0.9
collisions = "instantaneous"
[[soft.pair]]
species = ["A", "B"]
damping = 3.5
[[soft.pair]]
species = ["B", "B"]
model = "hertz"
young = 1e6
poisson = 0.25
restitution_speed = 2.0
[run]
integrator = "dem"
time_step = 1e-4
)"),
                                "test.toml");
  ASSERT_TRUE(c.soft.enabled());
  EXPECT_EQ(c.soft.law.model, "dashpot");
  EXPECT_EQ(c.soft.law.stiffness, 2e4);
  EXPECT_EQ(c.soft.law.restitution, 0.9);
  EXPECT_EQ(c.soft.law.damping, 0.0);
  EXPECT_EQ(c.soft.collisions, "instantaneous");
  ASSERT_EQ(c.soft.pairs.size(), 2u);
  // A pair's damping replaces the inherited restitution.
  EXPECT_EQ(c.soft.pairs[0].law.stiffness, 2e4);
  EXPECT_EQ(c.soft.pairs[0].law.damping, 3.5);
  EXPECT_EQ(c.soft.pairs[0].law.restitution, 0.0);
  // A pair of the other model keeps the inherited restitution (e at restitution_speed).
  EXPECT_EQ(c.soft.pairs[1].law.model, "hertz");
  EXPECT_EQ(c.soft.pairs[1].law.young, 1e6);
  EXPECT_EQ(c.soft.pairs[1].law.poisson, 0.25);
  EXPECT_EQ(c.soft.pairs[1].law.restitution, 0.9);
  EXPECT_EQ(c.soft.pairs[1].law.restitution_speed, 2.0);
  EXPECT_EQ(c.run.integrator, "dem");
  EXPECT_EQ(c.run.time_step, 1e-4);
}

TEST(ConfigSoft, NeitherDampingNorRestitutionIsElastic) {
  const Config c = parse_config(with("[soft]\nmodel = \"hertz\"\nyoung = 1e5"), "test.toml");
  EXPECT_EQ(c.soft.law.dissipation, 0.0);
  EXPECT_EQ(c.soft.law.restitution, 0.0);
  EXPECT_EQ(c.soft.law.poisson, 0.3);
}

TEST(ConfigSoft, ErrorsInTheLaw) {
  expect_error(with("[soft]\nstiffness = 1.0"), {"test.toml", "soft.model", "missing"});
  expect_error(with("[soft]\nmodel = \"spring\""), {"soft.model", "'spring'", "dashpot, hertz"});
  expect_error(with("[soft]\nmodel = \"dashpot\""), {"soft.stiffness", "missing"});
  expect_error(with("[soft]\nmodel = \"hertz\""), {"soft.young", "missing"});
  expect_error(with("[soft]\nmodel = \"dashpot\"\nstiffness = -1.0"),
               {"test.toml:11:", "soft.stiffness", "> 0"});
  expect_error(with("[soft]\nmodel = \"dashpot\"\nstiffness = nan"), {"soft.stiffness", "finite"});
  expect_error(with("[soft]\nmodel = \"dashpot\"\nstiffness = 1.0\ndamping = -2.0"),
               {"soft.damping", ">= 0"});
  expect_error(
      with("[soft]\nmodel = \"dashpot\"\nstiffness = 1.0\ndamping = 2.0\nrestitution = 0.9"),
      {"soft.restitution", "either soft.damping or restitution"});
  expect_error(with("[soft]\nmodel = \"dashpot\"\nstiffness = 1.0\nrestitution = 0.0"),
               {"soft.restitution", "(0, 1]"});
  expect_error(with("[soft]\nmodel = \"dashpot\"\nstiffness = 1.0\nrestitution = 1.5"),
               {"soft.restitution", "(0, 1]"});
  expect_error(with("[soft]\nmodel = \"dashpot\"\nstiffness = 1.0\nyoung = 1.0"),
               {"soft.young", "not a key of model \"dashpot\""});
  expect_error(with("[soft]\nmodel = \"hertz\"\nyoung = 1.0\nstiffness = 1.0"),
               {"soft.stiffness", "not a key of model \"hertz\""});
  expect_error(with("[soft]\nmodel = \"hertz\"\nyoung = 1.0\npoisson = 0.7"),
               {"soft.poisson", "(-1, 0.5]"});
  expect_error(with("[soft]\nmodel = \"hertz\"\nyoung = 1.0\ndissipation = -1.0"),
               {"soft.dissipation", ">= 0"});
  expect_error(with("[soft]\nmodel = \"hertz\"\nyoung = 1.0\nrestitution_speed = 0.0"),
               {"soft.restitution_speed", "> 0"});
  expect_error(with("[soft]\nmodel = \"hertz\"\nyoung = 1.0\ncollisions = \"mapping\""),
               {"soft.collisions", "mapped, instantaneous"});
  expect_error(with("[soft]\nmodel = \"dashpot\"\nstiffness = 1.0\nstifness = 2.0"),
               {"unknown key 'soft.stifness'", "did you mean 'soft.stiffness'"});
}

TEST(ConfigSoft, ErrorsInPairs) {
  const std::string soft = "[soft]\nmodel = \"dashpot\"\nstiffness = 1.0\n";
  expect_error(with(soft + "[[soft.pair]]\nrestitution = 0.5"),
               {"soft.pair[0].species", "missing"});
  expect_error(with(soft + "[[soft.pair]]\nspecies = [\"A\", \"C\"]"),
               {"soft.pair[0].species", "unknown species 'C'"});
  expect_error(with(soft + "[[soft.pair]]\nspecies = [\"A\", \"B\"]\n[[soft.pair]]\nspecies = "
                           "[\"B\", \"A\"]"),
               {"soft.pair[1].species", "already given by soft.pair[0]"});
  expect_error(with(soft + "[[soft.pair]]\nspecies = [\"A\", \"B\"]\nmodel = \"hertz\""),
               {"soft.pair[0].young", "missing"});
  expect_error(with(soft + "[[soft.pair]]\nspecies = [\"A\", \"B\"]\ncollisions = \"mapped\""),
               {"unknown key 'soft.pair[0].collisions'"});
}

TEST(ConfigSoft, ConflictsNameBothKeys) {
  const std::string soft = "[soft]\nmodel = \"dashpot\"\nstiffness = 1.0\n";
  expect_error(with(soft + "[contact]\nrestitution = 0.9"),
               {"contact.restitution", "soft.model", "replace the [contact] laws"});
  expect_error(with(soft + "[contact]\ntangential_restitution = 0.5"),
               {"contact.tangential_restitution", "soft.model", "frictionless"});
  expect_error(with(soft + "[[contact.pair]]\nspecies = [\"A\", \"B\"]"),
               {"contact.pair", "soft.model"});
  expect_error(with(soft + "[[potential]]\nkind = \"square_well\""), {"potential", "soft.model"});
  expect_error(with(soft + "[boundary]\nshear_rate = 0.1"), {"boundary.shear_rate", "soft.model"});
  expect_error(with(soft + "[field]\ngravity = [0, 0, -1]"),
               {"field.gravity", "soft.model", "run.integrator = \"dem\""});
  expect_error(with(soft + "[[boundary.wall]]\nface = \"z-\"\nrestitution = 0.5\n"
                           "[[boundary.wall]]\nface = \"z+\""),
               {"boundary.wall[0].restitution", "[soft] material"});
  // Walls with the default (elastic, smooth) contact keys are fine: they use [soft].
  EXPECT_NO_THROW(parse_config(
      with(soft + "[[boundary.wall]]\nface = \"z-\"\n[[boundary.wall]]\nface = \"z+\""),
      "test.toml"));
}

TEST(ConfigSoft, IntegratorErrors) {
  const std::string soft = "[soft]\nmodel = \"dashpot\"\nstiffness = 1.0\n";
  expect_error(with("[run]\nintegrator = \"md\""), {"run.integrator", "event, dem"});
  expect_error(with("[run]\nintegrator = \"dem\""), {"run.integrator", "[soft]"});
  expect_error(with(soft + "[run]\ntime_step = 0.01"), {"run.time_step", "DEM"});
  expect_error(with(soft + "[run]\nintegrator = \"dem\"\ntime_step = -0.01"),
               {"run.time_step", ">= 0"});
  expect_error(with(soft + "[run]\nintegrator = \"dem\"\n[boundary]\nopen = [\"z+\"]\n"
                           "[[boundary.wall]]\nface = \"z-\""),
               {"boundary.open", "not supported by the DEM integrator"});
  // Walls and gravity are the DEM's (the event-driven mapping refuses gravity, above).
  EXPECT_NO_THROW(parse_config(with(soft + "[run]\nintegrator = \"dem\"\n[[boundary.wall]]\n"
                                           "face = \"z-\"\n[[boundary.wall]]\nface = \"z+\"\n"
                                           "[field]\ngravity = [0, 0, -1]"),
                               "test.toml"));
  expect_error(with(soft + "[run]\nintegrator = \"dem\"\n[driving]\nkind = \"andersen\""),
               {"driving.kind", "not supported by the DEM integrator"});
}

TEST(ConfigSoft, OverridesReachTheSoftKeys) {
  const std::string soft =
      "[soft]\nmodel = \"dashpot\"\nstiffness = 1.0\n[[soft.pair]]\n"
      "species = [\"A\", \"B\"]\n";
  const Config c = parse_config(with(soft), "test.toml",
                                {"soft.stiffness=5.0", "soft.pair.0.restitution=0.7",
                                 "run.integrator=dem", "run.time_step=0.002"});
  EXPECT_EQ(c.soft.law.stiffness, 5.0);
  EXPECT_EQ(c.soft.pairs[0].law.stiffness, 5.0);  // inherited after the override
  EXPECT_EQ(c.soft.pairs[0].law.restitution, 0.7);
  EXPECT_EQ(c.run.integrator, "dem");
  EXPECT_EQ(c.run.time_step, 0.002);
  expect_error(with(soft), {"override 'soft.restitution=2'", "soft.restitution"},
               {"soft.restitution=2"});
}

TEST(ConfigSoft, MapTableKeys) {
  const std::string soft = "[soft]\nmodel = \"dashpot\"\nstiffness = 1e4\n";
  const Config d = parse_config(with(soft), "test.toml");
  EXPECT_TRUE(d.soft.tables);
  EXPECT_EQ(d.soft.table_tolerance, 1e-6);
  EXPECT_EQ(d.soft.table_cache, "");
  EXPECT_TRUE(d.soft.defer_releases);
  const Config c = parse_config(with(soft + "tables = false\ntable_tolerance = 1e-8\ntable_cache = "
                                            "\"/tmp/x\"\ndefer_releases = false\n"),
                                "test.toml");
  EXPECT_FALSE(c.soft.defer_releases);
  EXPECT_FALSE(c.soft.tables);
  EXPECT_EQ(c.soft.table_tolerance, 1e-8);
  EXPECT_EQ(c.soft.table_cache, "/tmp/x");
  EXPECT_EQ(parse_config(to_toml(c), "round trip"), c);
  expect_error(with(soft + "table_tolerance = 0.0\n"),
               {"soft.table_tolerance", "must be in [1e-10, 0.1)"});
  expect_error(with(soft + "table_tolerance = 0.5\n"),
               {"soft.table_tolerance", "must be in [1e-10, 0.1)", "a relative error"});
  expect_error(with(soft + "tables = 1\n"), {"soft.tables"});
  expect_error(with(soft + "defer_releases = \"no\"\n"), {"soft.defer_releases"});
  expect_error(with(soft + "table_cach = \"x\"\n"), {"soft.table_cach", "soft.table_cache"});
}

TEST(ConfigSoft, FrictionIsTheDems) {
  const std::string soft = "[soft]\nmodel = \"dashpot\"\nstiffness = 1.0\nfriction = 0.5\n";
  const Config c = parse_config(with(soft + "tangential_stiffness = 0.4\n[run]\n"
                                            "integrator = \"dem\""),
                                "test.toml");
  EXPECT_EQ(c.soft.law.friction, 0.5);
  EXPECT_EQ(c.soft.law.tangential_stiffness, 0.4);
  EXPECT_EQ(c.soft.law.tangential_damping, 0.5);  // the default, LAMMPS's gamma_t / gamma_n
  expect_error(with(soft), {"soft.friction", "run.integrator = \"dem\"", "smooth spheres"});
  expect_error(with("[soft]\nmodel = \"dashpot\"\nstiffness = 1.0\n[[soft.pair]]\n"
                    "species = [\"A\", \"B\"]\nfriction = 0.3\n"),
               {"soft.pair[0].friction", "run.integrator"});
  expect_error(with("[soft]\nmodel = \"dashpot\"\nstiffness = 1.0\nfriction = -1\n"),
               {"soft.friction", "must be in [0, 1e+09]"});
  expect_error(with("[soft]\nmodel = \"dashpot\"\nstiffness = 1.0\ntangential_stiffness = 0\n"),
               {"soft.tangential_stiffness", "must be in [1e-09, 10]"});
}

TEST(ConfigSoft, RoundTripIsExact) {
  for (const std::string_view text : {
           R"(
[soft]
model = "dashpot"
stiffness = 2e4
restitution = 0.9
friction = 0.4
[[soft.pair]]
species = ["A", "B"]
damping = 3.5
tangential_stiffness = 0.5
[[soft.pair]]
species = ["B", "B"]
model = "hertz"
young = 1e6
restitution_speed = 2.0
friction = 0.0
tangential_damping = 0.0
[run]
integrator = "dem"
time_step = 1.25e-4
)",
           R"(
[soft]
model = "hertz"
young = 3e5
poisson = 0.1
dissipation = 1e-3
collisions = "instantaneous"
[[soft.pair]]
species = ["A", "A"]
model = "dashpot"
stiffness = 1e4
)"}) {
    const Config c = parse_config(with(text), "test.toml");
    const std::string written = to_toml(c);
    const Config again = parse_config(written, "config.toml");
    EXPECT_EQ(again, c) << written;
    EXPECT_EQ(to_toml(again), written);
  }
}

}  // namespace
}  // namespace kairos
