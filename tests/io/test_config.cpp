// Tests for the run configuration: defaults, every class of input error, overrides, round trip.
#include "io/config.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.hpp"

namespace kairos {
namespace {

constexpr std::string_view kMinimal = R"([system]
particles = 500
packing_fraction = 0.3
)";

// kMinimal with extra lines appended inside [system] (or new tables after it).
std::string minimal_plus(std::string_view extra) {
  return std::string(kMinimal) + std::string(extra) + "\n";
}

// Parses `text` expecting an InputError; checks the message is one line and holds every fragment.
std::string expect_error(std::string_view text, std::initializer_list<std::string_view> fragments,
                         const std::vector<std::string>& overrides = {}) {
  std::string message;
  try {
    parse_config(text, "test.toml", overrides);
    ADD_FAILURE() << "no InputError for:\n" << text;
    return {};
  } catch (const InputError& e) {
    message = e.what();
  }
  EXPECT_EQ(message.find('\n'), std::string::npos) << "not one line: " << message;
  for (const std::string_view fragment : fragments) {
    EXPECT_NE(message.find(fragment), std::string::npos)
        << "message lacks '" << fragment << "': " << message;
  }
  return message;
}

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
  EXPECT_EQ(c.output, OutputConfig{});
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
  expect_error(minimal_plus("dimension = 4"), {"system.dimension", "must be 2 or 3", "got 4"});
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
  expect_error(minimal_plus("temperature = 0"), {"system.temperature", "> 0", "got 0"});
  expect_error(minimal_plus("temperature = -1.5"), {"system.temperature", "> 0", "got -1.5"});
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
  expect_error(minimal_plus("[[system.species]]\ndiameter = 0"),
               {"test.toml:5:12", "system.species[0].diameter", "> 0", "got 0"});
  expect_error(minimal_plus("[[system.species]]\nmass = -1"),
               {"system.species[0].mass", "> 0", "got -1"});
  expect_error(minimal_plus("[[system.species]]\nfraction = 0"),
               {"system.species[0].fraction", "> 0"});
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
               {"run.equilibration_collisions_per_particle", ">= 0", "got -1"});
  expect_error(minimal_plus("[run]\ncollisions_per_particle = 0"),
               {"run.collisions_per_particle", "> 0", "got 0"});
  expect_error(minimal_plus("[run]\nevent_queue = \"fifo\""),
               {"run.event_queue", "'fifo'", "valid values: calendar, heap"});
  expect_error(minimal_plus("[run]\nmax_wall_seconds = -1"), {"run.max_wall_seconds", ">= 0"});
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
               {"override 'system.species.0.diameter=-1'", "system.species[0].diameter", "> 0"},
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
                      {"small\\path\ttab\nnewline ünï", 5e-324, 1.7976931348623157e308, 123456.0}};
  c.system.initial_state = "";
  c.run.equilibration_collisions_per_particle = 0.0;
  c.run.collisions_per_particle = 1e22;
  c.run.event_queue = "heap";
  c.run.max_wall_seconds = 86400.5;
  c.run.validate = true;
  c.output.directory = "C:\\runs\\x";
  c.output.thermo_interval = 2.0 / 7.0;
  c.output.trajectory_interval = 10.0;
  c.output.restart_interval = 0.1;
  c.output.trajectory = false;
  c.output.progress = "never";

  const std::string text = to_toml(c);
  const Config back = parse_config(text, "config.toml");
  EXPECT_EQ(back, c) << text;
  EXPECT_EQ(to_toml(back), text);
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
                          "progress = \"auto\""}) {
    EXPECT_NE(text.find(key), std::string::npos) << "missing '" << key << "' in:\n" << text;
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
    EXPECT_NE(std::string(e.what()).find("Is a directory"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace kairos
