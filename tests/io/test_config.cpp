// Tests for the run configuration: defaults, every class of input error, overrides, round trip
// (the boundary geometries' tables: tests/io/test_surface_tables.cpp).
#include "io/config.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "config_testing.hpp"
#include "core/error.hpp"
#include "special_files.hpp"

namespace kairos {
namespace {

using namespace config_testing;

// ----- defaults and plain parsing

TEST(Config, MinimalConfigGetsDefaults) {
  const Config c = parse_config(kMinimal, "test.toml");
  EXPECT_EQ(c.system.dimension, 3);
  EXPECT_EQ(c.system.particles, 500u);
  EXPECT_EQ(c.system.packing_fraction, 0.3);
  EXPECT_EQ(c.system.lattice, "fcc");
  EXPECT_EQ(c.system.temperature, 1.0);
  EXPECT_EQ(c.system.seed, 1u);
  ASSERT_EQ(c.system.species.size(), 1u);
  EXPECT_EQ(c.system.species[0], SpeciesConfig{});
  EXPECT_EQ(c.system.species[0].name, "A");
  EXPECT_EQ(c.system.initial_state, "");
  EXPECT_EQ(c.run, RunConfig{});
  EXPECT_EQ(c.run.equilibration_collisions_per_particle, 20.0);
  EXPECT_EQ(c.run.collisions_per_particle, 100.0);
  EXPECT_EQ(c.run.event_queue, "calendar");
  EXPECT_EQ(c.run.max_wall_seconds, 0.0);
  EXPECT_FALSE(c.run.validate);
  OutputConfig defaults;
  defaults.interval_unit = "collisions";  // resolved: the production length's unit
  EXPECT_EQ(c.output, defaults);
  EXPECT_EQ(c.output.directory, "kairos-output");
  EXPECT_EQ(c.output.progress, "auto");
  EXPECT_TRUE(c.output.trajectory);
}

TEST(Config, TwoDimensionalDefaultLatticeIsHex) {
  const Config c =
      parse_config("[system]\ndimension = 2\nparticles = 100\npacking_fraction = 0.5", "t.toml");
  EXPECT_EQ(c.system.dimension, 2);
  EXPECT_EQ(c.system.lattice, "hex");
  EXPECT_EQ(default_lattice(2), "hex");
  EXPECT_EQ(default_lattice(3), "fcc");
  EXPECT_THROW(default_lattice(4), std::invalid_argument);
}

TEST(Config, ExplicitEmptyLatticeMeansDefault) {
  EXPECT_EQ(parse_config(minimal_plus("lattice = \"\""), "t.toml").system.lattice, "fcc");
}

TEST(Config, EveryValidLatticeIsAccepted) {
  for (const char* lattice : {"fcc", "sc", "bcc", "random"}) {
    const Config c = parse_config(kMinimal, "t.toml", {std::string("system.lattice=") + lattice});
    EXPECT_EQ(c.system.lattice, lattice);
  }
  for (const char* lattice : {"hex", "square", "random"}) {
    const Config c = parse_config(kMinimal, "t.toml",
                                  {"system.dimension=2", std::string("system.lattice=") + lattice});
    EXPECT_EQ(c.system.lattice, lattice);
  }
}

TEST(Config, FullConfigIsRead) {
  const Config c = parse_config(R"(
[system]
dimension = 3
particles = 4000
packing_fraction = 0.45
lattice = "bcc"
temperature = 2.5
seed = 12345

[[system.species]]
name = "big"
diameter = 1.4
mass = 2.744
fraction = 0.5

[[system.species]]
name = "small"
fraction = 0.5

[run]
equilibration_collisions_per_particle = 0
collisions_per_particle = 1e3
event_queue = "heap"
max_wall_seconds = 3600
validate = true

[output]
directory = "out/run 1"
thermo_interval = 0.5
trajectory_interval = 10
restart_interval = 250
trajectory = false
progress = "never"
)",
                                "full.toml");
  EXPECT_EQ(c.system.particles, 4000u);
  EXPECT_EQ(c.system.packing_fraction, 0.45);
  EXPECT_EQ(c.system.lattice, "bcc");
  EXPECT_EQ(c.system.temperature, 2.5);
  EXPECT_EQ(c.system.seed, 12345u);
  ASSERT_EQ(c.system.species.size(), 2u);
  EXPECT_EQ(c.system.species[0], (SpeciesConfig{"big", 1.4, 2.744, 0.5}));
  EXPECT_EQ(c.system.species[1], (SpeciesConfig{"small", 1.0, 1.0, 0.5}));
  EXPECT_EQ(c.run.equilibration_collisions_per_particle, 0.0);
  EXPECT_EQ(c.run.collisions_per_particle, 1000.0);
  EXPECT_EQ(c.run.event_queue, "heap");
  EXPECT_EQ(c.run.max_wall_seconds, 3600.0);
  EXPECT_TRUE(c.run.validate);
  EXPECT_EQ(c.output.directory, "out/run 1");
  EXPECT_EQ(c.output.thermo_interval, 0.5);
  EXPECT_EQ(c.output.trajectory_interval, 10.0);
  EXPECT_EQ(c.output.restart_interval, 250.0);
  EXPECT_FALSE(c.output.trajectory);
  EXPECT_EQ(c.output.progress, "never");
}

TEST(Config, SpeciesAsInlineArrayAndFractionsKeptAsWritten) {
  const Config c = parse_config(minimal_plus(R"(species = [{name = "A", fraction = 3},
                                                 {name = "B", diameter = 0.8, fraction = 1}])"),
                                "t.toml");
  ASSERT_EQ(c.system.species.size(), 2u);
  EXPECT_EQ(c.system.species[0].fraction, 3.0);
  EXPECT_EQ(c.system.species[1].diameter, 0.8);
  EXPECT_EQ(c.system.species[1].fraction, 1.0);
}

TEST(Config, EmptySpeciesArrayMeansDefaultSpecies) {
  const Config c = parse_config(minimal_plus("species = []"), "t.toml");
  ASSERT_EQ(c.system.species.size(), 1u);
  EXPECT_EQ(c.system.species[0], SpeciesConfig{});
}

TEST(Config, IntegersAreAcceptedForFloats) {
  const Config c =
      parse_config(minimal_plus("temperature = 2\n[run]\ncollisions_per_particle = 7"), "t.toml");
  EXPECT_EQ(c.system.temperature, 2.0);
  EXPECT_EQ(c.run.collisions_per_particle, 7.0);
}

TEST(Config, InitialStateMakesParticlesAndPackingFractionOptional) {
  const Config c = parse_config("[system]\ninitial_state = \"restart.gsd\"", "t.toml");
  EXPECT_EQ(c.system.initial_state, "restart.gsd");
  EXPECT_EQ(c.system.particles, 0u);
  EXPECT_EQ(c.system.packing_fraction, 0.0);
  EXPECT_EQ(parse_config(to_toml(c), "config.toml"), c);
}

// ----- unknown keys

TEST(ConfigErrors, UnknownKeySuggestsCloseKey) {
  const std::string m = expect_error(
      "[system]\nparticle = 500\npacking_fraction = 0.3",
      {"test.toml:2:1", "unknown key 'system.particle'", "did you mean 'system.particles'?"});
  EXPECT_EQ(m, "test.toml:2:1: unknown key 'system.particle' (did you mean 'system.particles'?)");
}

TEST(ConfigErrors, UnknownKeyWithoutCloseMatchHasNoSuggestion) {
  const std::string m = expect_error(minimal_plus("[run]\nfrobnicate = 1"),
                                     {"test.toml:5:1", "unknown key 'run.frobnicate'"});
  EXPECT_EQ(m.find("did you mean"), std::string::npos) << m;
}

TEST(ConfigErrors, UnknownTableAndMisplacedKeys) {
  expect_error("[sytem]\nparticles = 5", {"unknown key 'sytem'", "did you mean 'system'?"});
  expect_error(minimal_plus("[run]\nseed = 3"),
               {"unknown key 'run.seed'", "did you mean 'system.seed'?"});
  expect_error(std::string("particles = 5\n") + std::string(kMinimal),
               {"test.toml:1:1", "unknown key 'particles'", "did you mean 'system.particles'?"});
  expect_error(minimal_plus("[output]\nProgress = \"never\""),
               {"unknown key 'output.Progress'", "did you mean 'output.progress'?"});
}

TEST(ConfigErrors, UnknownKeyInSpecies) {
  expect_error(minimal_plus("[[system.species]]\nname = \"A\"\n[[system.species]]\nname = "
                            "\"B\"\ndiametre = 2"),
               {"test.toml:8:1", "unknown key 'system.species[1].diametre'",
                "did you mean 'system.species[1].diameter'?"});
}

TEST(ConfigErrors, HugeUnknownKeysAreCutInTheMessage) {
  // A megabyte of key: rejected at once (no edit distances with a key that long), and echoed as
  // its first characters and its length.
  const std::string key(1'000'000, 'k');
  const std::string m =
      expect_error(minimal_plus(key + " = 1"),
                   {"test.toml:4:1", "unknown key 'system.kkkk", "... (1000007 characters)"});
  EXPECT_LT(m.size(), 200u) << m.substr(0, 300);
  EXPECT_EQ(m.find("did you mean"), std::string::npos);
  const std::string o =
      expect_error(kMinimal, {"override 'system.", "characters)"}, {"system." + key + "=1"});
  EXPECT_LT(o.size(), 300u) << o.substr(0, 400);
  // A long value (a string where a number belongs) is cut too.
  const std::string v =
      expect_error(minimal_plus("temperature = \"" + key + "\""), {"system.temperature"});
  EXPECT_LT(v.size(), 200u) << v.substr(0, 300);
}

TEST(ConfigErrors, FirstUnknownKeyInFileOrderIsReported) {
  expect_error(minimal_plus("zzz = 1\naaa = 2"), {"unknown key 'system.zzz'"});
}

TEST(ConfigErrors, QuotedKeysThatLookLikePathsAreUnknown) {
  expect_error(minimal_plus("\"species[0].name\" = \"x\""),
               {"unknown key 'system.\"species[0].name\"'"});
  expect_error(minimal_plus("\"\" = 3"), {"test.toml:4:1", "unknown key 'system.\"\"'"});
}

// ----- wrong types

TEST(ConfigErrors, FloatForIntegerKey) {
  const std::string m = expect_error(
      "[system]\nparticles = 1.5\npacking_fraction = 0.3",
      {"test.toml:2:13", "system.particles", "expected an integer", "found a float (1.5)"});
  EXPECT_EQ(m, "test.toml:2:13: system.particles: expected an integer, found a float (1.5)");
  expect_error(minimal_plus("dimension = 3.0"),
               {"system.dimension", "expected an integer", "found a float (3.0)"});
}

TEST(ConfigErrors, StringForNumber) {
  expect_error(minimal_plus("temperature = \"hot\""),
               {"system.temperature", "expected a number", "found a string (\"hot\")"});
}

TEST(ConfigErrors, NumberForStringAndBoolean) {
  expect_error(minimal_plus("lattice = 3"),
               {"system.lattice", "expected a string", "found an integer (3)"});
  expect_error(minimal_plus("[run]\nvalidate = \"yes\""),
               {"run.validate", "expected a boolean", "found a string (\"yes\")"});
  expect_error(minimal_plus("[output]\ntrajectory = 1"),
               {"output.trajectory", "expected a boolean", "found an integer (1)"});
}

TEST(ConfigErrors, WrongStructure) {
  expect_error("system = 3", {"system", "expected a table", "found an integer (3)"});
  expect_error(minimal_plus("species = \"A\""),
               {"system.species", "expected an array of tables", "found a string"});
  expect_error(minimal_plus("[system.species]\nname = \"A\""),
               {"system.species", "expected an array of tables", "found a table"});
  expect_error(minimal_plus("species = [1, 2]"),
               {"system.species[0]", "expected a table", "found an integer (1)"});
}

TEST(ConfigErrors, NegativeIntegerForUnsignedKey) {
  expect_error(minimal_plus("seed = -1"),
               {"system.seed", "must be a non-negative integer", "got -1"});
  expect_error("[system]\nparticles = -5\npacking_fraction = 0.3",
               {"test.toml:2:13", "system.particles", "non-negative"});
}

TEST(ConfigErrors, NanAndInfinityAreRejected) {
  expect_error(minimal_plus("temperature = nan"),
               {"system.temperature", "must be a finite number", "nan"});
  expect_error("[system]\nparticles = 5\npacking_fraction = inf",
               {"test.toml:3:20", "system.packing_fraction", "finite"});
  expect_error(minimal_plus("[run]\nmax_wall_seconds = -inf"), {"run.max_wall_seconds", "finite"});
  expect_error(minimal_plus("[[system.species]]\ndiameter = nan"),
               {"system.species[0].diameter", "finite"});
}

// ----- syntax errors

TEST(ConfigErrors, SyntaxErrorNamesSourceLineAndColumn) {
  const std::string m = expect_error("[system]\nparticles = 500\npacking_fraction = = 0.3\n",
                                     {"test.toml:3:", "TOML syntax error"});
  EXPECT_EQ(m.rfind("test.toml:3:", 0), 0u) << m;
  expect_error("[system\nparticles = 5", {"test.toml:1:", "TOML syntax error"});
  expect_error("[system]\nparticles = 5\nparticles = 6", {"test.toml:3:", "TOML syntax error"});
  expect_error("[system]\nparticles = 99999999999999999999", {"test.toml:2:", "TOML syntax error"});
}

// ----- range checks

TEST(ConfigErrors, SystemRanges) {
  expect_error(minimal_plus("dimension = 4"), {"system.dimension", "must be in [2, 3]", "got 4"});
  expect_error("[system]\nparticles = 1\npacking_fraction = 0.3",
               {"test.toml:2:13", "system.particles", "at least 2", "got 1"});
  expect_error("[system]\nparticles = 0\npacking_fraction = 0.3", {"system.particles", "got 0"});
  expect_error("[system]\nparticles = 10\npacking_fraction = 0",
               {"system.packing_fraction", "(0, 1)", "got 0"});
  expect_error("[system]\nparticles = 10\npacking_fraction = 1.2",
               {"system.packing_fraction", "(0, 1)", "got 1.2"});
  // An integer is a float for a float key, and is then range-checked.
  expect_error("[system]\nparticles = 10\npacking_fraction = 1",
               {"test.toml:3:20", "system.packing_fraction", "(0, 1)", "got 1"});
  expect_error(minimal_plus("temperature = 0"),
               {"system.temperature", "must be in [1e-09, 1e+09]", "got 0"});
  expect_error(minimal_plus("temperature = -1.5"),
               {"system.temperature", "must be in [1e-09, 1e+09]", "got -1.5"});
  expect_error("[system]\ninitial_state = \"a.gsd\"\npacking_fraction = 1.5",
               {"system.packing_fraction", "(0, 1)"});
}

TEST(ConfigErrors, LatticeMustSuitDimension) {
  const std::string m = expect_error(
      minimal_plus("lattice = \"hex\""),
      {"test.toml:4:11", "system.lattice", "'hex'", "3D", "valid values: fcc, sc, bcc, random"});
  EXPECT_EQ(m,
            "test.toml:4:11: system.lattice: 'hex' is not a valid lattice in 3D; valid values: "
            "fcc, sc, bcc, random");
  expect_error(minimal_plus("dimension = 2\nlattice = \"fcc\""),
               {"system.lattice", "'fcc'", "2D", "valid values: hex, square, random"});
  expect_error(minimal_plus("lattice = \"FCC\""), {"system.lattice", "'FCC'"});
}

TEST(ConfigErrors, SpeciesRanges) {
  expect_error(
      minimal_plus("[[system.species]]\ndiameter = 0"),
      {"test.toml:5:12", "system.species[0].diameter", "must be in [1e-09, 1e+09]", "got 0"});
  expect_error(minimal_plus("[[system.species]]\nmass = -1"),
               {"system.species[0].mass", "must be in [1e-09, 1e+09]", "got -1"});
  expect_error(minimal_plus("[[system.species]]\nfraction = 0"),
               {"system.species[0].fraction", "must be in [1e-09, 1e+09]"});
  expect_error(minimal_plus("[[system.species]]\nname = \"\""),
               {"system.species[0].name", "must not be empty"});
  expect_error(minimal_plus("[[system.species]]\nname = \"A\"\n[[system.species]]\nname = \"A\""),
               {"test.toml:7:8", "system.species[1].name", "duplicate species name 'A'",
                "system.species[0]"});
  expect_error(minimal_plus("[[system.species]]\ndiameter = 1\n[[system.species]]\ndiameter = 2"),
               {"system.species[1].name", "duplicate species name 'A'", "its own name"});
}

TEST(ConfigErrors, RunRanges) {
  expect_error(minimal_plus("[run]\nequilibration_collisions_per_particle = -1"),
               {"run.equilibration_collisions_per_particle", "must be in [0, 1e+09]", "got -1"});
  expect_error(minimal_plus("[run]\ncollisions_per_particle = 0"),
               {"run.collisions_per_particle", "must be in (0, 1e+09]", "got 0"});
  expect_error(minimal_plus("[run]\nevent_queue = \"fifo\""),
               {"run.event_queue", "'fifo'", "valid values: calendar, heap"});
  expect_error(minimal_plus("[run]\nmax_wall_seconds = -1"),
               {"run.max_wall_seconds", "must be in [0, 1e+09]"});
}

TEST(ConfigErrors, OutputRanges) {
  expect_error(minimal_plus("[output]\ndirectory = \"\""),
               {"output.directory", "must not be empty"});
  expect_error(minimal_plus("[output]\nthermo_interval = -1"), {"output.thermo_interval", ">= 0"});
  expect_error(minimal_plus("[output]\ntrajectory_interval = -0.5"),
               {"output.trajectory_interval", ">= 0"});
  expect_error(minimal_plus("[output]\nrestart_interval = -2"),
               {"output.restart_interval", ">= 0"});
  expect_error(minimal_plus("[output]\nprogress = \"sometimes\""),
               {"output.progress", "'sometimes'", "valid values: auto, always, never"});
}

// ----- missing required keys

TEST(ConfigErrors, MissingRequiredKeys) {
  const std::string m = expect_error("[system]\npacking_fraction = 0.3",
                                     {"test.toml", "missing required key 'system.particles'"});
  EXPECT_EQ(m.rfind("test.toml: missing required key 'system.particles'", 0), 0u) << m;
  expect_error("[system]\nparticles = 10",
               {"test.toml", "missing required key 'system.packing_fraction'"});
  expect_error("", {"missing required key 'system.particles'"});
  expect_error("[run]\nvalidate = true", {"missing required key 'system.particles'"});
}

// ----- overrides

TEST(ConfigOverrides, NumbersBareStringsQuotedStringsAndBooleans) {
  const Config c = parse_config(kMinimal, "t.toml",
                                {"system.particles=4000", "system.packing_fraction = 0.45",
                                 "system.lattice=sc", "output.directory=\"quoted dir\"",
                                 "run.validate=true", "system.temperature=2", "system.seed=7"});
  EXPECT_EQ(c.system.particles, 4000u);
  EXPECT_EQ(c.system.packing_fraction, 0.45);
  EXPECT_EQ(c.system.lattice, "sc");
  EXPECT_EQ(c.output.directory, "quoted dir");
  EXPECT_TRUE(c.run.validate);
  EXPECT_EQ(c.system.temperature, 2.0);
  EXPECT_EQ(c.system.seed, 7u);
}

TEST(ConfigOverrides, BareTextForStringKeysIsKeptVerbatim) {
  const Config c = parse_config(
      kMinimal, "t.toml",
      {"output.directory=2024", "system.initial_state=runs/a b.gsd", "run.event_queue=heap"});
  EXPECT_EQ(c.output.directory, "2024");
  EXPECT_EQ(c.system.initial_state, "runs/a b.gsd");
  EXPECT_EQ(c.run.event_queue, "heap");
}

TEST(ConfigOverrides, CreateMissingSectionsAndLaterOverridesWin) {
  const Config c =
      parse_config(kMinimal, "t.toml", {"output.progress=never", "output.progress=always"});
  EXPECT_EQ(c.output.progress, "always");
  // Everything can come from overrides.
  const Config d =
      parse_config("", "t.toml", {"system.particles=10", "system.packing_fraction=0.1"});
  EXPECT_EQ(d.system.particles, 10u);
}

TEST(ConfigOverrides, UnknownOverrideKeyNamesTheOverride) {
  const std::string m = expect_error(kMinimal, {}, {"system.particle=4000"});
  EXPECT_EQ(m,
            "override 'system.particle=4000': unknown key 'system.particle' (did you mean "
            "'system.particles'?)");
  expect_error(kMinimal,
               {"override 'sytem.particles=3'", "unknown key 'sytem.particles'",
                "did you mean 'system.particles'?"},
               {"sytem.particles=3"});
  expect_error(kMinimal, {"override 'system.particles.x=3'", "unknown key 'system.particles.x'"},
               {"system.particles.x=3"});
  expect_error(kMinimal, {"override 'system={partcles=3}'", "unknown key 'system.partcles'"},
               {"system={partcles=3}"});
}

TEST(ConfigOverrides, MalformedOverrides) {
  expect_error(kMinimal, {"override 'system.particles'", "expected 'key=value'"},
               {"system.particles"});
  expect_error(kMinimal, {"override '=3'", "missing key"}, {"=3"});
  expect_error(kMinimal, {"override 'system..particles=3'", "invalid key"},
               {"system..particles=3"});
}

TEST(ConfigOverrides, OverrideValuesAreValidatedAndNameTheOverride) {
  expect_error(kMinimal,
               {"override 'system.particles=1.5'", "system.particles", "expected an integer",
                "found a float (1.5)"},
               {"system.particles=1.5"});
  expect_error(kMinimal,
               {"override 'system.particles=4k'", "expected an integer", "found a string (\"4k\")"},
               {"system.particles=4k"});
  expect_error(kMinimal, {"override 'system.packing_fraction=1'", "(0, 1)"},
               {"system.packing_fraction=1"});
  expect_error(kMinimal, {"override 'system.lattice=hex'", "valid values: fcc, sc, bcc, random"},
               {"system.lattice=hex"});
  expect_error(kMinimal, {"override 'system.temperature=nan'", "finite"},
               {"system.temperature=nan"});
  expect_error(kMinimal, {"override 'run.validate=yes'", "expected a boolean"},
               {"run.validate=yes"});
}

TEST(ConfigOverrides, SpeciesByIndex) {
  const std::string file = minimal_plus(
      "[[system.species]]\nname = \"A\"\n[[system.species]]\nname = \"B\"\ndiameter = 2");
  const Config c = parse_config(file, "t.toml",
                                {"system.species.0.diameter=1.4", "system.species[1].mass=3",
                                 "system.species.2.name=C", "system.species[2].fraction=0.25"});
  ASSERT_EQ(c.system.species.size(), 3u);
  EXPECT_EQ(c.system.species[0], (SpeciesConfig{"A", 1.4, 1.0, 1.0}));
  EXPECT_EQ(c.system.species[1], (SpeciesConfig{"B", 2.0, 3.0, 1.0}));
  EXPECT_EQ(c.system.species[2], (SpeciesConfig{"C", 1.0, 1.0, 0.25}));

  // Without species in the file, index 0 edits the default species.
  const Config d = parse_config(kMinimal, "t.toml", {"system.species.0.diameter=2"});
  ASSERT_EQ(d.system.species.size(), 1u);
  EXPECT_EQ(d.system.species[0], (SpeciesConfig{"A", 2.0, 1.0, 1.0}));
  // ... and index 1 appends a second species next to the default one.
  const Config d2 =
      parse_config(kMinimal, "t.toml", {"system.species.1.name=B", "system.species.1.mass=2"});
  ASSERT_EQ(d2.system.species.size(), 2u);
  EXPECT_EQ(d2.system.species[0], SpeciesConfig{});
  EXPECT_EQ(d2.system.species[1], (SpeciesConfig{"B", 1.0, 2.0, 1.0}));

  // A whole species list in TOML syntax.
  const Config e =
      parse_config(kMinimal, "t.toml", {R"(system.species=[{name="X"},{name="Y",diameter=0.5}])"});
  ASSERT_EQ(e.system.species.size(), 2u);
  EXPECT_EQ(e.system.species[1].diameter, 0.5);
}

TEST(ConfigOverrides, SpeciesErrors) {
  expect_error(kMinimal,
               {"override 'system.species.5.mass=2'", "index 5 is out of range",
                "'system.species' has 1 entries"},
               {"system.species.5.mass=2"});
  expect_error(kMinimal, {"index 99999999999999999999999 is out of range"},
               {"system.species.99999999999999999999999.mass=2"});
  expect_error(kMinimal,
               {"override 'system.species.0.diametr=2'", "unknown key 'system.species[0].diametr'",
                "did you mean 'system.species[0].diameter'?"},
               {"system.species.0.diametr=2"});
  expect_error(kMinimal,
               {"override 'system.species.name=B'", "unknown key 'system.species.name'",
                "did you mean 'system.species[0].name'?"},
               {"system.species.name=B"});
  expect_error(kMinimal,
               {"override 'system.species.0.diameter=-1'", "system.species[0].diameter",
                "must be in [1e-09, 1e+09]"},
               {"system.species.0.diameter=-1"});
  expect_error(kMinimal,
               {"override 'system.species.1.mass=2'", "system.species[1].name",
                "duplicate species name 'A'"},
               {"system.species.1.mass=2"});
  expect_error(
      minimal_plus("species = 3"),
      {"override 'system.species.0.mass=2'", "'system.species' is an integer (3)", "not an array"},
      {"system.species.0.mass=2"});
}

// ----- granular keys: species inertia, box_scale, [contact], [boundary], [field]

TEST(ConfigGranular, DefaultsAreThePlainHardSphereCase) {
  const Config c = parse_config(kMinimal, "t.toml");
  EXPECT_EQ(c.system.species[0].inertia_factor, 0.0);
  EXPECT_TRUE(c.system.box_scale.empty());
  EXPECT_EQ(c.interactions, InteractionConfig{});
  EXPECT_EQ(c.interactions.contact, ContactConfig{});
  EXPECT_EQ(c.interactions.contact.friction, std::numeric_limits<double>::infinity());
  EXPECT_EQ(c.boundary, BoundaryConfig{});
  EXPECT_EQ(c.field, FieldConfig{});
  // Empty sections are the defaults too.
  const Config d = parse_config(minimal_plus("[contact]\n[boundary]\n[field]"), "t.toml");
  EXPECT_EQ(d, c);
}

TEST(ConfigGranular, EveryKeyIsRead) {
  const Config c = parse_config(R"(
[system]
particles = 1000
packing_fraction = 0.2
box_scale = [1.0, 2, 4.5]

[[system.species]]
name = "A"
inertia_factor = 0.4

[[system.species]]
name = "B"
diameter = 2

[contact]
restitution = 0.9
restitution_model = "viscoelastic"
restitution_speed = 2.0
tangential_restitution = 0.3
friction = 0.5
elastic_below_speed = 1e-3
tc = 1e-4

[[contact.pair]]
species = ["A", "B"]
restitution = 0.8
restitution_model = "table"
restitution_table = [[0.0, 1.0], [1, 0.9], [2.5, 0.7]]

[[contact.pair]]
species = ["B", "B"]
restitution_model = "constant"
friction = inf
tangential_restitution = -1

[boundary]
open = ["z+"]

[[boundary.wall]]
face = "z-"
restitution = 0.7
velocity = [1.0, -0.5, 0.0]
amplitude = 0.05
frequency = 10
phase = 1.5

[[boundary.wall]]
face = "x-"
restitution_model = "constant"

[[boundary.wall]]
face = "x+"

[field]
gravity = [0.0, 0.0, -1.0]
)",
                                "granular.toml");
  EXPECT_EQ(c.system.box_scale, (std::vector<double>{1.0, 2.0, 4.5}));
  ASSERT_EQ(c.system.species.size(), 2u);
  EXPECT_EQ(c.system.species[0].inertia_factor, 0.4);
  EXPECT_EQ(c.system.species[1].inertia_factor, 0.0);

  const ContactConfig& law = c.interactions.contact;
  EXPECT_EQ(law.restitution, 0.9);
  EXPECT_EQ(law.restitution_model, "viscoelastic");
  EXPECT_EQ(law.restitution_speed, 2.0);
  EXPECT_TRUE(law.restitution_table.empty());
  EXPECT_EQ(law.tangential_restitution, 0.3);
  EXPECT_EQ(law.friction, 0.5);
  EXPECT_EQ(law.elastic_below_speed, 1e-3);
  EXPECT_EQ(c.interactions.tc, 1e-4);

  // A pair starts from [contact] and replaces the keys it sets.
  ASSERT_EQ(c.interactions.pairs.size(), 2u);
  const PairContactConfig& ab = c.interactions.pairs[0];
  EXPECT_EQ(ab.species, (std::array<std::string, 2>{"A", "B"}));
  EXPECT_EQ(ab.contact.restitution, 0.8);
  EXPECT_EQ(ab.contact.restitution_model, "table");
  EXPECT_EQ(ab.contact.restitution_table,
            (std::vector<std::array<double, 2>>{{0.0, 1.0}, {1.0, 0.9}, {2.5, 0.7}}));
  EXPECT_EQ(ab.contact.restitution_speed, 2.0);
  EXPECT_EQ(ab.contact.tangential_restitution, 0.3);
  EXPECT_EQ(ab.contact.friction, 0.5);
  EXPECT_EQ(ab.contact.elastic_below_speed, 1e-3);
  const PairContactConfig& bb = c.interactions.pairs[1];
  EXPECT_EQ(bb.species, (std::array<std::string, 2>{"B", "B"}));
  EXPECT_EQ(bb.contact.restitution_model, "constant");
  EXPECT_EQ(bb.contact.restitution, 0.9);
  EXPECT_EQ(bb.contact.friction, std::numeric_limits<double>::infinity());
  EXPECT_EQ(bb.contact.tangential_restitution, -1.0);

  EXPECT_EQ(c.boundary.open, (std::vector<std::string>{"z+"}));
  ASSERT_EQ(c.boundary.walls.size(), 3u);
  const WallConfig& floor = c.boundary.walls[0];
  EXPECT_EQ(floor.face, "z-");
  EXPECT_EQ(floor.contact.restitution, 0.7);
  EXPECT_EQ(floor.contact.restitution_model, "viscoelastic");  // from [contact]
  EXPECT_EQ(floor.contact.friction, 0.5);
  EXPECT_EQ(floor.velocity, (std::vector<double>{1.0, -0.5, 0.0}));
  EXPECT_EQ(floor.amplitude, 0.05);
  EXPECT_EQ(floor.frequency, 10.0);
  EXPECT_EQ(floor.phase, 1.5);
  EXPECT_EQ(c.boundary.walls[1].face, "x-");
  EXPECT_EQ(c.boundary.walls[1].contact.restitution_model, "constant");
  EXPECT_TRUE(c.boundary.walls[1].velocity.empty());
  EXPECT_EQ(c.boundary.walls[1].amplitude, 0.0);
  EXPECT_EQ(c.boundary.walls[2].contact, law);
  EXPECT_EQ(c.field.gravity, (std::vector<double>{0.0, 0.0, -1.0}));
}

TEST(ConfigGranular, TwoDimensionalVectors) {
  const Config c = parse_config(R"([system]
dimension = 2
particles = 500
packing_fraction = 0.5
box_scale = [1, 6]
[[boundary.wall]]
face = "y-"
velocity = [0.5, 0]
[boundary]
open = ["y+"]
[field]
gravity = [0, -1]
)",
                                "t.toml");
  EXPECT_EQ(c.system.box_scale, (std::vector<double>{1.0, 6.0}));
  EXPECT_EQ(c.boundary.walls[0].velocity, (std::vector<double>{0.5, 0.0}));
  EXPECT_EQ(c.field.gravity, (std::vector<double>{0.0, -1.0}));
}

TEST(ConfigGranular, DefaultValuedVectorsAreStoredEmpty) {
  const Config c = parse_config(minimal_plus(R"(box_scale = [1, 1.0, 1]
[[boundary.wall]]
face = "x-"
velocity = [0, 0, 0]
[[boundary.wall]]
face = "x+"
[field]
gravity = [0.0, 0.0, -0.0])"),
                                "t.toml");
  EXPECT_TRUE(c.system.box_scale.empty());
  EXPECT_TRUE(c.boundary.walls[0].velocity.empty());
  EXPECT_TRUE(c.field.gravity.empty());
  EXPECT_EQ(c.field, FieldConfig{});
}

TEST(ConfigGranular, ExplicitDefaultContactIsTheDefault) {
  const Config c = parse_config(minimal_plus(R"([contact]
restitution = 1
restitution_model = "constant"
restitution_speed = 1
tangential_restitution = -1
friction = inf
elastic_below_speed = 0
tc = 0)"),
                                "t.toml");
  EXPECT_EQ(c.interactions, InteractionConfig{});
}

TEST(ConfigGranular, InheritedTableIsDroppedByAnotherModel) {
  const Config c = parse_config(minimal_plus(R"([contact]
restitution_model = "table"
restitution_table = [[0, 0.8]]
[[contact.pair]]
species = ["A", "A"]
restitution_model = "constant"
restitution = 0.5
[[boundary.wall]]
face = "y-"
[[boundary.wall]]
face = "y+"
restitution = 0.2)"),
                                "t.toml");
  EXPECT_TRUE(c.interactions.pairs[0].contact.restitution_table.empty());
  EXPECT_EQ(c.interactions.pairs[0].contact.restitution, 0.5);
  // The walls keep the table law (an explicit restitution is unused by it, but kept).
  EXPECT_EQ(c.boundary.walls[0].contact, c.interactions.contact);
  EXPECT_EQ(c.boundary.walls[1].contact.restitution_table,
            (std::vector<std::array<double, 2>>{{0.0, 0.8}}));
}

TEST(ConfigGranular, BothFacesOfAnAxisOpenIsAllowed) {
  const Config c = parse_config(minimal_plus("[boundary]\nopen = [\"z-\", \"z+\"]"), "t.toml");
  EXPECT_EQ(c.boundary.open, (std::vector<std::string>{"z-", "z+"}));
}

TEST(ConfigGranularErrors, ContactRanges) {
  expect_error(minimal_plus("[contact]\nrestitution = 1.1"),
               {"test.toml:5:15", "contact.restitution", "[0, 1]", "got 1.1"});
  expect_error(minimal_plus("[contact]\nrestitution = -0.1"), {"contact.restitution", "[0, 1]"});
  expect_error(
      minimal_plus("[contact]\nrestitution_model = \"hertz\""),
      {"contact.restitution_model", "'hertz'", "valid values: constant, viscoelastic, table"});
  expect_error(minimal_plus("[contact]\nrestitution_speed = 0"),
               {"contact.restitution_speed", "> 0", "got 0"});
  expect_error(minimal_plus("[contact]\nrestitution_model = \"viscoelastic\"\nrestitution = 0"),
               {"contact.restitution", "(0, 1]", "viscoelastic", "got 0"});
  expect_error(minimal_plus("[contact]\ntangential_restitution = 1.5"),
               {"contact.tangential_restitution", "[-1, 1]", "got 1.5"});
  expect_error(minimal_plus("[contact]\ntangential_restitution = -2"),
               {"contact.tangential_restitution", "[-1, 1]"});
  expect_error(minimal_plus("[contact]\nfriction = -0.5"),
               {"test.toml:5:12", "contact.friction", ">= 0", "got -0.5"});
  expect_error(minimal_plus("[contact]\nfriction = -inf"),
               {"contact.friction", "finite number or inf", "got -inf"});
  expect_error(minimal_plus("[contact]\nfriction = nan"), {"contact.friction", "got nan"});
  expect_error(minimal_plus("[contact]\nelastic_below_speed = -1"),
               {"contact.elastic_below_speed", ">= 0"});
  expect_error(minimal_plus("[contact]\ntc = -1e-3"), {"contact.tc", ">= 0"});
  expect_error(minimal_plus("[contact]\ntc = inf"), {"contact.tc", "finite"});
  expect_error(minimal_plus("[driving]\nkind = \"langevin\""),
               {"driving.kind", "'langevin'", "none, andersen, white_noise"});
  expect_error(minimal_plus("[driving]\nkind = \"white_noise\""),
               {"driving.strength", "white_noise driving needs a strength > 0"});
  expect_error(minimal_plus("[driving]\nrate = 0"), {"driving.rate", "> 0"});
  expect_error(minimal_plus("[output]\nprofile_axis = \"w\""),
               {"output.profile_axis", "'w' is not an axis of a 3D box"});
  expect_error(minimal_plus("[output]\nprofile_bins = 0"), {"output.profile_bins", "got 0"});
  {
    const Config c = parse_config(
        minimal_plus("[driving]\nkind = \"andersen\"\ntemperature = 2.5\nrate = 0.1"), "test.toml");
    EXPECT_EQ(c.driving.kind, "andersen");
    EXPECT_EQ(c.driving.temperature, 2.5);
    EXPECT_EQ(c.driving.rate, 0.1);
    EXPECT_EQ(parse_config(to_toml(c), "round-trip"), c);
  }
  expect_error(minimal_plus("[contact]\nsleep_speed = -0.5"),
               {"contact.sleep_speed", ">= 0 (or -1 for automatic)", "got -0.5"});
  EXPECT_EQ(parse_config(minimal_plus("[contact]\nsleep_speed = 0.01"), "test.toml")
                .interactions.sleep_speed,
            0.01);
  EXPECT_EQ(parse_config(minimal_plus(""), "test.toml").interactions.sleep_speed, -1.0);
  expect_error(minimal_plus("[contact]\nrestitution = \"high\""),
               {"contact.restitution", "expected a number", "found a string"});
  // inf is only for friction.
  expect_error(minimal_plus("[contact]\nelastic_below_speed = inf"),
               {"contact.elastic_below_speed", "must be a finite number, got inf"});
}

TEST(ConfigGranularErrors, RestitutionTable) {
  expect_error(minimal_plus("[contact]\nrestitution_model = \"table\""),
               {"test.toml:5:21", "missing required key 'contact.restitution_table'"});
  expect_error(minimal_plus("[contact]\nrestitution_model = \"table\"\nrestitution_table = []"),
               {"contact.restitution_table", "at least one"});
  expect_error(minimal_plus("[contact]\nrestitution_table = [[0.0, 1.0]]"),
               {"test.toml:5:21", "contact.restitution_table", "only allowed with",
                "restitution_model = \"table\"", "is \"constant\""});
  const std::string unsorted =
      "[contact]\nrestitution_model = \"table\"\nrestitution_table = [[0.0, 1.0], [2.0, 0.9], "
      "[1.0, 0.8]]";
  expect_error(minimal_plus(unsorted),
               {"contact.restitution_table[2]", "strictly increasing", "got 1 after 2"});
  expect_error(minimal_plus("[contact]\nrestitution_model = \"table\"\nrestitution_table = "
                            "[[1.0, 1.0], [1.0, 0.9]]"),
               {"contact.restitution_table[1]", "strictly increasing"});
  expect_error(minimal_plus("[contact]\nrestitution_model = \"table\"\nrestitution_table = "
                            "[[-1.0, 1.0]]"),
               {"contact.restitution_table[0]", "impact speed must be finite and >= 0"});
  expect_error(minimal_plus("[contact]\nrestitution_model = \"table\"\nrestitution_table = "
                            "[[0.0, 1.5]]"),
               {"contact.restitution_table[0]", "restitution must be in [0, 1]", "got 1.5"});
  expect_error(minimal_plus("[contact]\nrestitution_model = \"table\"\nrestitution_table = "
                            "[[0.0, 1.0, 2.0]]"),
               {"contact.restitution_table[0]", "expected a pair [speed, e]", "an array of 3"});
  expect_error(minimal_plus("[contact]\nrestitution_model = \"table\"\nrestitution_table = [0.5]"),
               {"contact.restitution_table[0]", "expected a pair", "a float (0.5)"});
  expect_error(minimal_plus("[contact]\nrestitution_model = \"table\"\nrestitution_table = "
                            "[[0.0, nan]]"),
               {"contact.restitution_table[0][1]", "finite"});
  expect_error(minimal_plus("[contact]\nrestitution_model = \"table\"\nrestitution_table = 0.9"),
               {"contact.restitution_table", "expected an array of [speed, e] pairs"});
  // Per pair and per wall the same.
  expect_error(minimal_plus("[[contact.pair]]\nspecies = [\"A\", \"A\"]\nrestitution_model = "
                            "\"table\""),
               {"missing required key 'contact.pair[0].restitution_table'"});
  expect_error(minimal_plus("[[boundary.wall]]\nface = \"x-\"\nrestitution_table = [[0, 1]]"),
               {"boundary.wall[0].restitution_table", "only allowed with"});
}

TEST(ConfigGranularErrors, SpeciesPairs) {
  const std::string species =
      "[[system.species]]\nname = \"A\"\n[[system.species]]\nname = \"B\"\n";
  const std::string m =
      expect_error(minimal_plus(species + "[[contact.pair]]\nspecies = [\"A\", \"C\"]"),
                   {"test.toml:9:17", "contact.pair[0].species", "unknown species 'C'",
                    "declared species: A, B"});
  EXPECT_EQ(
      m, "test.toml:9:17: contact.pair[0].species: unknown species 'C' (declared species: A, B)");
  expect_error(
      minimal_plus(species + "[[contact.pair]]\nspecies = [\"A\", \"B\"]\n[[contact.pair]]\n"
                             "species = [\"B\", \"A\"]\nrestitution = 0.5"),
      {"test.toml:11:11", "contact.pair[1].species", "the pair (B, A)",
       "already given by contact.pair[0]"});
  expect_error(minimal_plus(species + "[[contact.pair]]\nspecies = [\"A\"]"),
               {"contact.pair[0].species", "expected 2 species names, got 1"});
  expect_error(minimal_plus(species + "[[contact.pair]]\nspecies = [\"A\", 2]"),
               {"contact.pair[0].species[1]", "expected a string", "an integer (2)"});
  expect_error(minimal_plus(species + "[[contact.pair]]\nrestitution = 0.5"),
               {"missing required key 'contact.pair[0].species'"});
  expect_error(
      minimal_plus(species + "[[contact.pair]]\nspecies = [\"A\", \"B\"]\nrestitution = 2"),
      {"contact.pair[0].restitution", "[0, 1]"});
  expect_error(minimal_plus("[contact]\npair = 3"),
               {"contact.pair", "expected an array of tables ([[contact.pair]])"});
  // The default species is "A".
  expect_error(minimal_plus("[[contact.pair]]\nspecies = [\"A\", \"B\"]"),
               {"unknown species 'B'", "declared species: A"});
}

TEST(ConfigGranularErrors, TcOnlyInContact) {
  expect_error(minimal_plus("[[contact.pair]]\nspecies = [\"A\", \"A\"]\ntc = 1"),
               {"unknown key 'contact.pair[0].tc'", "did you mean 'contact.tc'?"});
  expect_error(minimal_plus("[[boundary.wall]]\nface = \"x-\"\ntc = 1"),
               {"unknown key 'boundary.wall[0].tc'", "did you mean 'contact.tc'?"});
}

TEST(ConfigGranularErrors, UnknownKeysGetSuggestions) {
  const std::string m =
      expect_error(minimal_plus("[[boundary.wall]]\nface = \"x-\"\n[[boundary.wall]]\nface = "
                                "\"x+\"\nrestitusion = 0.9"),
                   {"test.toml:8:1", "unknown key 'boundary.wall[1].restitusion'",
                    "did you mean 'boundary.wall[1].restitution'?"});
  EXPECT_EQ(m,
            "test.toml:8:1: unknown key 'boundary.wall[1].restitusion' (did you mean "
            "'boundary.wall[1].restitution'?)");
  expect_error(
      minimal_plus("[[boundary.wall]]\nface = \"x-\"\nvelocty = [0, 1, 0]"),
      {"unknown key 'boundary.wall[0].velocty'", "did you mean 'boundary.wall[0].velocity'?"});
  expect_error(minimal_plus("[contact]\nfrction = 0.5"),
               {"unknown key 'contact.frction'", "did you mean 'contact.friction'?"});
  expect_error(minimal_plus("[boundary]\nwalls = []"),
               {"unknown key 'boundary.walls'", "did you mean 'boundary.wall'?"});
  expect_error(minimal_plus("[field]\ngravty = [0, 0, -1]"),
               {"unknown key 'field.gravty'", "did you mean 'field.gravity'?"});
  expect_error(minimal_plus("gravity = [0, 0, -1]"),
               {"unknown key 'system.gravity'", "did you mean 'field.gravity'?"});
  expect_error(minimal_plus("restitution = 0.9"),
               {"unknown key 'system.restitution'", "did you mean 'contact.restitution'?"});
  expect_error(minimal_plus("[[system.species]]\ninertia = 0.4"),
               {"unknown key 'system.species[0].inertia'"});
  expect_error(minimal_plus("[[contact.pair]]\nspecies = [\"A\", \"A\"]\nrestitution_modle = 1"),
               {"unknown key 'contact.pair[0].restitution_modle'",
                "did you mean 'contact.pair[0].restitution_model'?"});
}

TEST(ConfigGranularErrors, WallFaces) {
  expect_error(minimal_plus("[[boundary.wall]]\nface = \"top\""),
               {"test.toml:5:8", "boundary.wall[0].face", "'top' is not a valid face",
                "valid values: x-, x+, y-, y+, z-, z+"});
  const std::string m = expect_error(
      "[system]\ndimension = 2\nparticles = 10\npacking_fraction = 0.3\n"
      "[[boundary.wall]]\nface = \"z-\"",
      {"test.toml:6:8", "boundary.wall[0].face", "'z-' is not a face of a 2D box",
       "valid values: x-, x+, y-, y+"});
  EXPECT_EQ(m.find("z+"), std::string::npos) << m;
  expect_error(
      "[system]\ndimension = 2\nparticles = 10\npacking_fraction = 0.3\n"
      "[boundary]\nopen = [\"z+\"]",
      {"boundary.open[0]", "'z+' is not a face of a 2D box"});
  expect_error(
      minimal_plus("[[boundary.wall]]\nface = \"z-\"\n[[boundary.wall]]\nface = \"z-\""),
      {"test.toml:7:8", "boundary.wall[1].face", "face z- is listed twice", "boundary.wall[0]"});
  expect_error(minimal_plus("[[boundary.wall]]\nrestitution = 0.9"),
               {"missing required key 'boundary.wall[0].face'", "x-, x+, y-, y+, z-, z+"});
  expect_error(minimal_plus("[[boundary.wall]]\nface = 1"),
               {"boundary.wall[0].face", "expected a string", "an integer (1)"});
  expect_error(minimal_plus("[boundary]\nwall = {face = \"z-\"}"),
               {"boundary.wall", "expected an array of tables ([[boundary.wall]])"});
}

TEST(ConfigGranularErrors, OpenFaces) {
  expect_error(
      minimal_plus("[[boundary.wall]]\nface = \"z-\"\n[boundary]\nopen = [\"z-\", \"z+\"]"),
      {"test.toml:7:9", "boundary.open[0]", "face z- is a wall (boundary.wall[0])", "not both"});
  expect_error(minimal_plus("[boundary]\nopen = [\"z+\", \"z-\", \"z+\"]"),
               {"boundary.open[2]", "face z+ is listed twice", "boundary.open[0]"});
  expect_error(minimal_plus("[boundary]\nopen = \"z+\""),
               {"boundary.open", "expected an array of strings", "found a string"});
}

TEST(ConfigGranularErrors, HalfPeriodicAxis) {
  const std::string m = expect_error(minimal_plus("[[boundary.wall]]\nface = \"z-\""),
                                     {"test.toml:5:8", "boundary:", "face z- is a wall",
                                      "z+ is neither a wall nor in boundary.open"});
  EXPECT_EQ(m,
            "test.toml:5:8: boundary: face z- is a wall but z+ is neither a wall nor in "
            "boundary.open; add one (or remove the wall to keep z periodic)");
  expect_error(minimal_plus("[boundary]\nopen = [\"y+\"]"),
               {"boundary: face y+ is open but y- is neither a wall nor in boundary.open",
                "remove y+ from boundary.open to keep y periodic"});
  expect_error(minimal_plus("[[boundary.wall]]\nface = \"x+\"\n[[boundary.wall]]\nface = \"y-\"\n"
                            "[[boundary.wall]]\nface = \"y+\""),
               {"boundary: face x+ is a wall but x- is neither"});
}

TEST(ConfigGranular, WallVelocityAlongTheNormalIsAPiston) {
  const Config c = parse_config(minimal_plus("[[boundary.wall]]\nface = \"z-\"\n"
                                             "[[boundary.wall]]\nface = \"z+\"\n"
                                             "velocity = [0.25, 0.0, -0.5]\namplitude = 0.1"),
                                "t.toml");
  EXPECT_TRUE(c.boundary.walls[0].velocity.empty());
  EXPECT_EQ(c.boundary.walls[1].velocity, (std::vector<double>{0.25, 0.0, -0.5}));
  EXPECT_EQ(c.boundary.walls[1].amplitude, 0.1);
}

TEST(ConfigGranularErrors, WallMotion) {
  expect_error(minimal_plus("[[boundary.wall]]\nface = \"z-\"\nvelocity = [0.0, 0.0, nan]\n"
                            "[[boundary.wall]]\nface = \"z+\""),
               {"test.toml:6:23", "boundary.wall[0].velocity[2]", "finite", "nan"});
  expect_error(minimal_plus("[[boundary.wall]]\nface = \"z-\"\n[[boundary.wall]]\nface = "
                            "\"z+\"\nvelocity = [0.0, 0.0, -inf]"),
               {"boundary.wall[1].velocity[2]", "finite"});
  expect_error(minimal_plus("[[boundary.wall]]\nface = \"x-\"\nvelocity = [1.0, 0.0]\n"
                            "[[boundary.wall]]\nface = \"x+\""),
               {"boundary.wall[0].velocity", "expected 3 numbers (system.dimension = 3), got 2"});
  expect_error(minimal_plus("[[boundary.wall]]\nface = \"x-\"\nvelocity = 1.0\n"
                            "[[boundary.wall]]\nface = \"x+\""),
               {"boundary.wall[0].velocity", "expected an array of numbers", "found a float"});
  expect_error(minimal_plus("[[boundary.wall]]\nface = \"x-\"\namplitude = -0.1\n"
                            "[[boundary.wall]]\nface = \"x+\""),
               {"boundary.wall[0].amplitude", ">= 0", "got -0.1"});
  expect_error(minimal_plus("[[boundary.wall]]\nface = \"x-\"\nfrequency = -1\n"
                            "[[boundary.wall]]\nface = \"x+\""),
               {"boundary.wall[0].frequency", ">= 0"});
  expect_error(minimal_plus("[[boundary.wall]]\nface = \"x-\"\nphase = inf\n"
                            "[[boundary.wall]]\nface = \"x+\""),
               {"boundary.wall[0].phase", "finite"});
  expect_error(minimal_plus("[[boundary.wall]]\nface = \"x-\"\nrestitution = 1.5\n"
                            "[[boundary.wall]]\nface = \"x+\""),
               {"boundary.wall[0].restitution", "[0, 1]"});
}

TEST(ConfigGranularErrors, FieldAndBoxScale) {
  const std::string m = expect_error(minimal_plus("[field]\ngravity = [0.0, -1.0]"),
                                     {"test.toml:5:11", "field.gravity"});
  EXPECT_EQ(m, "test.toml:5:11: field.gravity: expected 3 numbers (system.dimension = 3), got 2");
  expect_error(minimal_plus("[field]\ngravity = [0.0, \"down\", -1.0]"),
               {"field.gravity[1]", "expected a number", "found a string (\"down\")"});
  expect_error(minimal_plus("[field]\ngravity = [0.0, 0.0, nan]"),
               {"field.gravity[2]", "must be a finite number, got nan"});
  expect_error(minimal_plus("[field]\ngravity = [0.0, 0.0, -inf]"), {"field.gravity[2]", "finite"});
  expect_error(minimal_plus("[field]\ngravity = -1.0"),
               {"field.gravity", "expected an array of numbers", "found a float (-1.0)"});
  expect_error(
      "[system]\ndimension = 2\nparticles = 10\npacking_fraction = 0.3\n"
      "[field]\ngravity = [0.0, 0.0, -1.0]",
      {"field.gravity", "expected 2 numbers (system.dimension = 2), got 3"});

  expect_error(minimal_plus("box_scale = [1.0, 0.5, 2.0]"),
               {"test.toml:4:19", "system.box_scale[1]", "must be in [1, 1e+06]", "got 0.5"});
  expect_error(minimal_plus("box_scale = [1.0, 2.0]"),
               {"system.box_scale", "expected 3 numbers (system.dimension = 3), got 2"});
  expect_error(minimal_plus("box_scale = [1.0, 2.0, inf]"), {"system.box_scale[2]", "finite"});
  expect_error(minimal_plus("[[system.species]]\ninertia_factor = -0.4"),
               {"system.species[0].inertia_factor", "must be in [1e-09, 1]", "or 0 for the default",
                "got -0.4"});
  expect_error(minimal_plus("[contact]\nrestitution = 0.9\n[field]\ngravity = []"),
               {"field.gravity", "got 0"});
}

TEST(ConfigGranularOverrides, ScalarsAndArrays) {
  const Config c = parse_config(
      kMinimal, "t.toml",
      {"contact.restitution=0.8", "field.gravity=[0,0,-2]", "contact.friction=inf",
       "contact.tc=1e-5", "system.box_scale=[1, 1, 3]", "system.species.0.inertia_factor=0.35",
       "contact.restitution_model=table", "contact.restitution_table=[[0, 1], [1, 0.8]]",
       "boundary.wall.0.face=z-", "boundary.wall[0].amplitude=0.1", "boundary.open=[\"z+\"]"});
  EXPECT_EQ(c.interactions.contact.restitution, 0.8);
  EXPECT_EQ(c.interactions.contact.friction, std::numeric_limits<double>::infinity());
  EXPECT_EQ(c.interactions.contact.restitution_model, "table");
  EXPECT_EQ(c.interactions.contact.restitution_table,
            (std::vector<std::array<double, 2>>{{0.0, 1.0}, {1.0, 0.8}}));
  EXPECT_EQ(c.interactions.tc, 1e-5);
  EXPECT_EQ(c.field.gravity, (std::vector<double>{0.0, 0.0, -2.0}));
  EXPECT_EQ(c.system.box_scale, (std::vector<double>{1.0, 1.0, 3.0}));
  EXPECT_EQ(c.system.species[0].inertia_factor, 0.35);
  ASSERT_EQ(c.boundary.walls.size(), 1u);
  EXPECT_EQ(c.boundary.walls[0].face, "z-");
  EXPECT_EQ(c.boundary.walls[0].amplitude, 0.1);
  EXPECT_EQ(c.boundary.walls[0].contact, c.interactions.contact);
  EXPECT_EQ(c.boundary.open, (std::vector<std::string>{"z+"}));

  // An override of [contact] reaches the pairs and walls that do not set the key themselves.
  const Config d = parse_config(
      minimal_plus("[[boundary.wall]]\nface = \"x-\"\n[[boundary.wall]]\nface = \"x+\"\n"
                   "restitution = 1.0\n[[contact.pair]]\nspecies = [\"A\", \"A\"]"),
      "t.toml", {"contact.restitution=0.8", "boundary.wall.1.friction=0.2"});
  EXPECT_EQ(d.boundary.walls[0].contact.restitution, 0.8);
  EXPECT_EQ(d.boundary.walls[1].contact.restitution, 1.0);
  EXPECT_EQ(d.boundary.walls[1].contact.friction, 0.2);
  EXPECT_EQ(d.interactions.pairs[0].contact.restitution, 0.8);
}

TEST(ConfigGranularOverrides, ErrorsNameTheOverride) {
  expect_error(kMinimal,
               {"override 'field.gravity=[0,-1]'",
                "field.gravity: expected 3 numbers (system.dimension = 3), got 2"},
               {"field.gravity=[0,-1]"});
  expect_error(kMinimal, {"override 'field.gravity=[0,0,x]'", "expected an array of numbers"},
               {"field.gravity=[0,0,x]"});
  expect_error(kMinimal, {"override 'contact.restitution=1.2'", "contact.restitution", "[0, 1]"},
               {"contact.restitution=1.2"});
  expect_error(kMinimal,
               {"override 'contact.restituion=0.9'", "did you mean 'contact.restitution'?"},
               {"contact.restituion=0.9"});
  expect_error(
      kMinimal,
      {"override 'boundary.wall.0.restitutoin=0.9'", "unknown key 'boundary.wall[0].restitutoin'",
       "did you mean 'boundary.wall[0].restitution'?"},
      {"boundary.wall.0.restitutoin=0.9"});
  expect_error(kMinimal, {"override 'boundary.wall.0.face=z-'", "face z- is a wall but z+"},
               {"boundary.wall.0.face=z-"});
  // Setting the dimension re-checks the vectors of the file.
  expect_error(minimal_plus("[field]\ngravity = [0, 0, -1]"),
               {"test.toml:5:11", "field.gravity", "expected 2 numbers (system.dimension = 2)"},
               {"system.dimension=2"});
}

// ----- to_toml

TEST(ConfigToToml, RoundTripIsExact) {
  Config c;
  c.system.dimension = 2;
  c.system.particles = 12345;
  c.system.packing_fraction = 1.0 / 3.0;
  c.system.lattice = "square";
  c.system.temperature = 0.1 + 0.2;  // 0.30000000000000004
  c.system.seed = static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max());
  c.system.species = {{"big \"one\"", 1.4, 2.744, 1e-7},
                      // The ends of the ranges, one ulp inside.
                      {"small\\path\ttab\nnewline ünï", std::nextafter(1e-9, 1.0),
                       std::nextafter(1e9, 0.0), 123456.0}};
  c.system.initial_state = "";
  c.run.equilibration_collisions_per_particle = 0.0;
  c.run.collisions_per_particle = 1e9;  // the most a run may ask for
  c.run.event_queue = "heap";
  c.run.max_wall_seconds = 86400.5;
  c.run.validate = true;
  c.output.directory = "C:\\runs\\x";
  c.output.thermo_interval = 2.0 / 7.0;
  c.output.trajectory_interval = 10.0;
  c.output.restart_interval = 0.1;
  c.output.trajectory = false;
  c.output.progress = "never";
  c.output.interval_unit = "collisions";

  const std::string text = to_toml(c);
  const Config back = parse_config(text, "config.toml");
  EXPECT_EQ(back, c) << text;
  EXPECT_EQ(to_toml(back), text);
}

TEST(ConfigToToml, RoundTripWithEveryGranularKey) {
  Config c;
  c.system.dimension = 3;
  c.system.particles = 2000;
  c.system.packing_fraction = 0.1;
  c.system.lattice = "random";
  c.system.box_scale = {1.0, 1.5, 4.0 / 3.0};
  c.system.species = {
      {"A", 1.0, 1.0, 1.0, 0.4}, {"B", 1.4, 2.0, 0.5, 0.0}, {"C", 0.5, 0.1, 0.1, 1.0 / 3.0}};
  c.interactions.contact.restitution = 0.9;
  c.interactions.contact.restitution_model = "viscoelastic";
  c.interactions.contact.restitution_speed = 0.7;
  c.interactions.contact.tangential_restitution = 0.1 + 0.2;
  c.interactions.contact.friction = 0.25;
  c.interactions.contact.elastic_below_speed = 1e-6;
  c.interactions.tc = 1e-4;
  PairContactConfig ab;
  ab.species = {"A", "B"};
  ab.contact.restitution = 0.8;
  ab.contact.restitution_model = "table";
  ab.contact.restitution_table = {{0.0, 1.0}, {0.5, 0.95}, {2.0 / 3.0, 0.1 + 0.7}};
  ab.contact.tangential_restitution = -0.5;
  PairContactConfig cc;
  cc.species = {"C", "C"};  // everything default, friction inf
  c.interactions.pairs = {ab, cc};
  WallConfig floor;
  floor.face = "z-";
  floor.contact.restitution = 0.95;
  floor.contact.friction = 0.0;
  floor.velocity = {0.5, -1.0 / 3.0, 0.0};
  floor.amplitude = 0.05;
  floor.frequency = 12.5;
  floor.phase = -1.0 / 7.0;
  WallConfig left;
  left.face = "x-";
  left.contact = c.interactions.contact;
  WallConfig right;
  right.face = "x+";
  right.contact.restitution_model = "table";
  right.contact.restitution_table = {{1.0, 0.5}};
  c.boundary.walls = {floor, left, right};
  c.boundary.open = {"z+"};
  c.field.gravity = {0.0, 1e-3, -9.81};
  c.output.interval_unit = "collisions";

  const std::string text = to_toml(c);
  const Config back = parse_config(text, "config.toml");
  EXPECT_EQ(back, c) << text;
  EXPECT_EQ(to_toml(back), text);
  EXPECT_NE(text.find("friction = inf"), std::string::npos) << text;
  EXPECT_NE(text.find("restitution_table = [[0.0, 1.0], [0.5, 0.95], ["), std::string::npos)
      << text;

  // The same in 2D.
  Config d;
  d.system.dimension = 2;
  d.system.particles = 500;
  d.system.packing_fraction = 0.5;
  d.system.box_scale = {1.0, 6.0};
  WallConfig bottom;
  bottom.face = "y-";
  bottom.velocity = {0.25, 0.0};
  bottom.amplitude = 0.1;
  bottom.frequency = 0.87;
  d.boundary.walls = {bottom};
  d.boundary.open = {"y+"};
  d.field.gravity = {0.0, -1.0};
  const Config d_back = parse_config(to_toml(d), "config.toml");
  EXPECT_EQ(d_back.system.box_scale, d.system.box_scale);
  EXPECT_EQ(d_back.boundary, d.boundary);
  EXPECT_EQ(d_back.field, d.field);
  EXPECT_EQ(parse_config(to_toml(d_back), "config.toml"), d_back);
}

TEST(ConfigToToml, MinimalConfigWritesEveryKeyWithResolvedDefaults) {
  const Config c = parse_config(kMinimal, "t.toml");
  const std::string text = to_toml(c);
  EXPECT_EQ(parse_config(text, "config.toml"), c) << text;
  for (const char* key : {"[system]",
                          "dimension = 3",
                          "particles = 500",
                          "packing_fraction = 0.3",
                          "lattice = \"fcc\"",
                          "temperature = 1.0",
                          "seed = 1",
                          "initial_state = \"\"",
                          "[[system.species]]",
                          "name = \"A\"",
                          "diameter = 1.0",
                          "mass = 1.0",
                          "fraction = 1.0",
                          "[run]",
                          "equilibration_collisions_per_particle = 20.0",
                          "collisions_per_particle = 100.0",
                          "event_queue = \"calendar\"",
                          "max_wall_seconds = 0.0",
                          "validate = false",
                          "[output]",
                          "directory = \"kairos-output\"",
                          "thermo_interval = 0.0",
                          "trajectory_interval = 0.0",
                          "restart_interval = 0.0",
                          "trajectory = true",
                          "progress = \"auto\"",
                          "box_scale = [1.0, 1.0, 1.0]",
                          "inertia_factor = 0.0",
                          "[contact]",
                          "restitution = 1.0",
                          "restitution_model = \"constant\"",
                          "restitution_speed = 1.0",
                          "tangential_restitution = -1.0",
                          "friction = inf",
                          "elastic_below_speed = 0.0",
                          "tc = 0.0",
                          "[boundary]",
                          "open = []",
                          "[field]",
                          "gravity = [0.0, 0.0, 0.0]"}) {
    EXPECT_NE(text.find(key), std::string::npos) << "missing '" << key << "' in:\n" << text;
  }
  // Only the pairs, walls and tables that exist.
  for (const char* absent : {"[[contact.pair]]", "[[boundary.wall]]", "restitution_table"}) {
    EXPECT_EQ(text.find(absent), std::string::npos) << "unexpected '" << absent << "' in:\n"
                                                    << text;
  }
}

TEST(ConfigToToml, ResolvesDefaultsOfHandBuiltConfig) {
  Config c;
  c.system.dimension = 2;
  c.system.particles = 10;
  c.system.packing_fraction = 0.5;
  const Config back = parse_config(to_toml(c), "config.toml");
  EXPECT_EQ(back.system.lattice, "hex");
  ASSERT_EQ(back.system.species.size(), 1u);
  EXPECT_EQ(back.system.species[0], SpeciesConfig{});
}

TEST(ConfigToToml, RoundTripWithLengthsAndIntervalsInTime) {
  Config c = parse_config(kMinimal, "t.toml");
  c.run.time = 2.5;
  c.run.equilibration_time = 0.0;  // in time, and none
  c.output.interval_unit = "time";
  c.output.thermo_interval = 0.1;
  const std::string text = to_toml(c);
  EXPECT_EQ(text.find("collisions_per_particle"), std::string::npos) << text;
  const Config back = parse_config(text, "config.toml");
  EXPECT_EQ(back, c) << text;
  // Without an explicit unit the intervals follow the production length's.
  c.output.interval_unit.clear();
  c.output.trajectory_interval = 0.0;  // automatic: a tenth of run.time
  EXPECT_EQ(parse_config(to_toml(c), "config.toml").output.interval_unit, "time");
}

TEST(ConfigToToml, SeedBeyondTomlRangeThrows) {
  Config c = parse_config(kMinimal, "t.toml");
  c.system.seed = std::numeric_limits<std::uint64_t>::max();
  EXPECT_THROW(to_toml(c), std::out_of_range);
}

// ----- load_config

class ConfigFile : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ =
        std::filesystem::temp_directory_path() /
        ("kairos_test_config_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
         "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path dir_;
};

TEST_F(ConfigFile, LoadsFileAndNamesItInErrors) {
  const auto path = dir_ / "run.toml";
  std::ofstream(path) << kMinimal << "temperature = -1\n";
  try {
    load_config(path);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(path.string() + ":4:15: system.temperature", 0), 0u)
        << e.what();
  }
  const Config c = load_config(path, {"system.temperature=3"});
  EXPECT_EQ(c.system.temperature, 3.0);
}

TEST_F(ConfigFile, MissingFileIsAnInputError) {
  const auto path = dir_ / "nope.toml";
  try {
    load_config(path);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "cannot read config file '" + path.string() + "': No such file or directory");
  }
  try {
    load_config(dir_);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("is not a regular file (it is a directory)"),
              std::string::npos)
        << e.what();
  }
}

// A FIFO or a device given as the config file is refused at once: reading a FIFO would wait for
// a writer forever, and /dev/null would read as an empty config.
TEST_F(ConfigFile, SpecialFilesAreRefusedWithoutBlocking) {
  const auto fifo = dir_ / "run.toml";
  kairos::testing::make_fifo(fifo);
  for (const auto& [path, kind] :
       {std::pair<std::filesystem::path, std::string>{fifo, "a FIFO"}, {"/dev/null", "a device"}}) {
    const std::string message =
        kairos::testing::refusal_without_blocking(path, [&] { (void)load_config(path); });
    EXPECT_EQ(message, "config file '" + path.string() + "' is not a regular file (it is " + kind +
                           "): give the path of a TOML file");
  }
}

// Every example shipped in examples/ (and its subdirectories) is a valid configuration.
TEST(ConfigExamples, EveryExampleParses) {
  const std::filesystem::path root = std::filesystem::path(KAIROS_SOURCE_DIR) / "examples";
  std::size_t count = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(root)) {
    if (!entry.is_regular_file() || entry.path().extension() != ".toml") continue;
    ++count;
    try {
      const Config c = load_config(entry.path());
      EXPECT_EQ(parse_config(to_toml(c), "config.toml"), c) << entry.path();
    } catch (const InputError& e) {
      ADD_FAILURE() << e.what();
    }
  }
  EXPECT_GE(count, 5u);
}

TEST(ConfigExamples, GranularExamples) {
  const std::filesystem::path dir = std::filesystem::path(KAIROS_SOURCE_DIR) / "examples";
  const Config cooling = load_config(dir / "granular_cooling_3d.toml");
  EXPECT_EQ(cooling.system.dimension, 3);
  EXPECT_EQ(cooling.system.particles, 4000u);
  EXPECT_EQ(cooling.system.packing_fraction, 0.05);
  EXPECT_EQ(cooling.interactions.contact.restitution, 0.9);
  EXPECT_EQ(cooling.boundary, BoundaryConfig{});
  EXPECT_EQ(cooling.field, FieldConfig{});

  const Config bed = load_config(dir / "vibrated_bed_2d.toml");
  EXPECT_EQ(bed.system.dimension, 2);
  EXPECT_EQ(bed.system.particles, 500u);
  EXPECT_EQ(bed.system.box_scale, (std::vector<double>{1.0, 6.0}));
  EXPECT_EQ(bed.field.gravity, (std::vector<double>{0.0, -1.0}));
  EXPECT_EQ(bed.boundary.open, (std::vector<std::string>{"y+"}));
  ASSERT_EQ(bed.boundary.walls.size(), 3u);
  for (const WallConfig& w : bed.boundary.walls) EXPECT_EQ(w.contact.restitution, 0.9) << w.face;
  EXPECT_EQ(bed.interactions.contact.restitution, 0.9);
  const WallConfig& floor = bed.boundary.walls[2];
  EXPECT_EQ(floor.face, "y-");
  // Dimensionless peak acceleration of the floor, Gamma = A (2 pi f)^2 / g, about 3.
  const double omega = 2.0 * 3.141592653589793 * floor.frequency;
  EXPECT_NEAR(floor.amplitude * omega * omega / 1.0, 3.0, 0.05);
}

}  // namespace
}  // namespace kairos

// ----- walls with mass (boundary.wall.mass, .force)

namespace kairos {
namespace {

constexpr std::string_view kLid = R"(
[[boundary.wall]]
face = "z-"
[[boundary.wall]]
face = "z+"
mass = 20.0
force = 100.0
)";

TEST(ConfigWallMass, MassAndForceAreRead) {
  const Config c = parse_config(minimal_plus(kLid), "t.toml");
  ASSERT_EQ(c.boundary.walls.size(), 2u);
  EXPECT_EQ(c.boundary.walls[1].mass, 20.0);
  EXPECT_EQ(c.boundary.walls[1].force, 100.0);
  EXPECT_EQ(c.boundary.walls[0].mass, 0.0);
}

TEST(ConfigWallMass, ForceWithoutMassIsAnError) {
  expect_error(minimal_plus("[[boundary.wall]]\nface = \"z-\"\n[[boundary.wall]]\nface = "
                            "\"z+\"\nforce = 3.0"),
               {"boundary.wall[1].force", "a force moves only a wall with mass"});
}

TEST(ConfigWallMass, MassWithAVelocityOrVibrationIsAnError) {
  expect_error(minimal_plus(std::string(kLid) + "velocity = [0.0, 0.0, -0.1]"),
               {"boundary.wall[1].velocity", "a wall with mass"});
  expect_error(minimal_plus(std::string(kLid) + "amplitude = 0.1\nfrequency = 2.0"),
               {"boundary.wall[1].amplitude", "a wall with mass"});
}

TEST(ConfigWallMass, NegativeMassIsAnError) {
  expect_error(minimal_plus("[[boundary.wall]]\nface = \"z-\"\n[[boundary.wall]]\nface = "
                            "\"z+\"\nmass = -1.0"),
               {"boundary.wall[1].mass", "must be in [0, 1e+09]"});
}

TEST(ConfigWallMass, SoftSpheresShearAndFixedGrainsAreRefused) {
  expect_error(minimal_plus(std::string(kLid) + "[soft]\nmodel = \"dashpot\"\nstiffness = 1e4"),
               {"soft.model", "a wall with mass"});
  expect_error(minimal_plus("species = [{name = \"g\"}, {name = \"f\", fixed = true}]\n" +
                            std::string(kLid)),
               {"boundary.wall[1].mass", "fixed grains"});
}

}  // namespace
}  // namespace kairos
