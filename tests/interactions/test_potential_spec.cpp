// PotentialSpec -> step table (src/interactions/potential_spec.hpp): every kind, its defaults,
// the 2D/3D forms, and the message of every bad value.
#include "interactions/potential_spec.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numbers>
#include <string>

#include "core/error.hpp"
#include "input_error_matchers.hpp"
#include "interactions/soft_contact.hpp"

namespace kairos {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

PotentialSpec spec_of(const std::string& kind) {
  PotentialSpec s;
  s.kind = kind;
  return s;
}

TEST(PotentialSpec, SquareWellAndShoulderScaleWithTheCore) {
  PotentialSpec s = spec_of("square_well");
  s.lambda = 1.5;
  s.depth = 1.0;
  const StepTable w = make_step_table(s, 1.0);
  EXPECT_EQ(w.boundary, (std::vector<double>{1.5, 1.0}));
  EXPECT_EQ(w.energy, (std::vector<double>{-1.0}));
  EXPECT_EQ(w.beyond, 0.0);
  // docs/physics.md#second-virial-coefficient
  EXPECT_NEAR(second_virial(w, 1.0), -6.4526623820, 1e-9);
  const StepTable w2 = make_step_table(s, 2.0);
  EXPECT_EQ(w2.boundary, (std::vector<double>{3.0, 2.0}));
  s.kind = "square_shoulder";
  s.depth = 0.5;
  EXPECT_EQ(make_step_table(s, 1.0).energy, (std::vector<double>{0.5}));
  // 2D B2 of the well: (pi/2) sigma^2 [1 - (lambda^2 - 1)(e^(eps/kT) - 1)].
  s.kind = "square_well";
  const double exact = std::numbers::pi / 2.0 * 4.0 * (1.0 - 1.25 * std::expm1(0.5 / 1.3));
  EXPECT_NEAR(second_virial(make_step_table(s, 2.0, 2), 1.3, 2), exact, 1e-13 * std::abs(exact));
}

TEST(PotentialSpec, StepsMustEndAtTheContactDistance) {
  PotentialSpec s = spec_of("steps");
  s.boundaries = {2.0, 1.5, 0.9};
  s.energies = {-0.5, -1.0};
  EXPECT_INPUT_ERROR(make_step_table(s, 1.0),
                     "potential steps: the step table's hard core is 0.9 but the pair's contact "
                     "distance (sum of the radii) is 1");
  s.boundaries.back() = 1.0 + 5e-13;
  const StepTable t = make_step_table(s, 1.0);
  EXPECT_EQ(t.core(), 1.0);
  EXPECT_EQ(t.energy, s.energies);
  s.boundaries = {2.0, 2.5, 1.0};
  EXPECT_INPUT_ERROR(make_step_table(s, 1.0), "potential steps: step radii must decrease");
  s.boundaries = {2.0, 1.0};
  EXPECT_INPUT_ERROR(make_step_table(s, 1.0), "potential steps: a step table with 2 boundaries");
}

TEST(PotentialSpec, ContinuousKindsUseTheirDefaults) {
  PotentialSpec lj = spec_of("lennard_jones");
  const StepTable t = make_step_table(lj, 1.0);
  EXPECT_EQ(t.cutoff(), 2.5);
  const StepTable direct =
      step_potential(lennard_jones(1.0, 1.0, 2.5, true), StepPlacement::kEnergy, 10, 1.0,
                     StepEnergyRule::kVolumeAverage, 1.0);
  EXPECT_EQ(t.boundary, direct.boundary);
  EXPECT_EQ(t.energy, direct.energy);
  lj.sigma = 1.2;
  EXPECT_DOUBLE_EQ(continuous_potential(lj).cutoff, 3.0);

  PotentialSpec w = spec_of("wca");
  EXPECT_DOUBLE_EQ(make_step_table(w, 1.0).cutoff(), std::pow(2.0, 1.0 / 6.0));
  PotentialSpec y = spec_of("yukawa");
  y.sigma = 0.8;
  EXPECT_DOUBLE_EQ(continuous_potential(y).cutoff, 2.4);
  y.epsilon = -1.0;
  EXPECT_LT(make_step_table(y, 1.0).energy.back(), 0.0);
  PotentialSpec m = spec_of("morse");
  m.alpha = 3.0;
  const ContinuousPotential mp = continuous_potential(m);
  EXPECT_DOUBLE_EQ(mp.r_min, 1.0);
  EXPECT_DOUBLE_EQ(mp.cutoff, 3.0);
  m.r_min = 1.1;
  EXPECT_DOUBLE_EQ(continuous_potential(m).cutoff, 3.1);

  for (const char* kind : {"square_well", "square_shoulder", "steps", "tether"})
    EXPECT_TRUE(continuous_potential(spec_of(kind)).name.empty()) << kind;
  EXPECT_FALSE(continuous_potential(lj).name.empty());
}

TEST(PotentialSpec, PlacementsRulesAndDimension) {
  PotentialSpec s = spec_of("morse");
  s.steps = 8;
  s.placement = "volume";
  s.shell_energy = "mid_volume";
  const StepTable t2 = make_step_table(s, 0.9, 2), t3 = make_step_table(s, 0.9);
  ASSERT_EQ(t2.boundary.size(), 9u);
  const double c = s.sigma + 6.0 / s.alpha;
  EXPECT_NEAR(t2.boundary[1] * t2.boundary[1], c * c - (c * c - 0.81) / 8, 1e-13);
  EXPECT_NEAR(std::pow(t3.boundary[1], 3), c * c * c - (c * c * c - 0.729) / 8, 1e-13);
  s.placement = "distance";
  s.shell_energy = "midpoint";
  const StepTable d = make_step_table(s, 0.9);
  EXPECT_NEAR(d.boundary[1], c - (c - 0.9) / 8, 1e-14);
  EXPECT_NEAR(d.energy[0], continuous_potential(s).u(0.5 * (c + d.boundary[1])), 1e-15);
}

// The virial rule keeps B2 for every continuous kind (and spring is a bond: B2 infinite).
TEST(PotentialSpec, VirialTablesKeepB2ForEveryKind) {
  const std::string file = (std::filesystem::path(testing::TempDir()) / "spec_u.table").string();
  {
    std::ofstream out(file);
    for (int i = 0; i <= 200; ++i) {
      const double r = 0.8 + 1.7 * i / 200;
      out << r << " " << 2.0 * std::exp(-3.0 * r) - std::exp(-3.0 * 2.5) * 2.0 << "\n";
    }
  }
  for (const char* kind : {"lennard_jones", "wca", "yukawa", "morse", "tabulated"}) {
    PotentialSpec s = spec_of(kind);
    s.file = file;
    s.shell_energy = "virial";
    s.temperature = 0.8;
    s.steps = 6;
    for (const char* placement : {"energy", "distance", "volume"}) {
      s.placement = placement;
      for (const int d : {2, 3}) {
        const double core = 0.96;
        const double b2 = second_virial(continuous_potential(s), core, 0.8, d);
        EXPECT_NEAR(second_virial(make_step_table(s, core, d), 0.8, d), b2, 1e-8 * std::abs(b2))
            << kind << " " << placement << " " << d;
      }
    }
  }
}

TEST(PotentialSpec, BondsAreTablesWithAnInfiniteOutside) {
  PotentialSpec t = spec_of("tether");
  t.max_length = 1.4;
  const StepTable tether = make_step_table(t, 1.0);
  EXPECT_EQ(tether.boundary, (std::vector<double>{1.4, 1.0}));
  EXPECT_EQ(tether.energy, (std::vector<double>{0.0}));
  EXPECT_EQ(tether.beyond, kInf);
  EXPECT_EQ(tether.energy_at(1.41), kInf);
  EXPECT_EQ(tether.energy_at(1.2), 0.0);
  t.max_length = 1.0;
  EXPECT_INPUT_ERROR(
      make_step_table(t, 1.0),
      "bond tether: max_length 1 must exceed the contact distance (sum of the radii) 1");

  PotentialSpec s = spec_of("spring");
  s.stiffness = 30.0;
  s.length = 1.2;
  s.max_length = 1.5;
  const StepTable spring = make_step_table(s, 1.0);
  EXPECT_EQ(spring.beyond, kInf);
  EXPECT_EQ(spring.energy_at(1.5 + 1e-9), kInf);
  EXPECT_EQ(spring.cutoff(), 1.5);
  EXPECT_EQ(spring.core(), 1.0);
  EXPECT_EQ(continuous_potential(s).beyond, kInf);
  s.length = 0.9;
  EXPECT_INPUT_ERROR(
      make_step_table(s, 1.0),
      "bond spring: length 0.9 must exceed the contact distance (sum of the radii) 1");
  s.length = 1.6;
  EXPECT_INPUT_ERROR(make_step_table(s, 1.0),
                     "bond spring: length 1.6 must be shorter than max_length 1.5");
  s.length = 1.2;
  s.stiffness = 0.0;
  EXPECT_INPUT_ERROR(make_step_table(s, 1.0), "bond spring: stiffness must be positive");
}

TEST(PotentialSpec, EveryBadValueIsNamed) {
  PotentialSpec s = spec_of("lennard_jones");
  s.steps = 0;
  EXPECT_INPUT_ERROR(make_step_table(s, 1.0), "potential lennard_jones: steps must be at least 1");
  s = spec_of("lennard_jones");
  s.placement = "log";
  EXPECT_INPUT_ERROR(make_step_table(s, 1.0),
                     "potential lennard_jones: placement: unknown step placement 'log' (energy, "
                     "distance or volume)");
  s = spec_of("lennard_jones");
  s.shell_energy = "average";
  EXPECT_INPUT_ERROR(make_step_table(s, 1.0),
                     "potential lennard_jones: shell_energy: unknown shell energy rule 'average'");
  s = spec_of("lennard_jones");
  s.temperature = -1.0;
  EXPECT_INPUT_ERROR(make_step_table(s, 1.0),
                     "potential lennard_jones: temperature must be positive");
  s = spec_of("lennard_jones");
  s.epsilon = 0.0;
  EXPECT_INPUT_ERROR(make_step_table(s, 1.0), "potential lennard_jones: epsilon must be positive");
  s = spec_of("lennard_jones");
  s.sigma = -1.0;
  EXPECT_INPUT_ERROR(make_step_table(s, 1.0), "potential lennard_jones: sigma must be positive");
  s = spec_of("lennard_jones");
  s.cutoff = 0.9;
  EXPECT_INPUT_ERROR(
      make_step_table(s, 1.0),
      "potential lennard_jones: the cut-off 0.9 must lie beyond the contact distance "
      "(sum of the radii) 1");
  s.cutoff = -2.0;
  EXPECT_INPUT_ERROR(make_step_table(s, 1.0), "potential lennard_jones: cutoff must be positive");
  s = spec_of("lennard_jones");
  EXPECT_INPUT_ERROR(make_step_table(s, 0.0),
                     "potential lennard_jones: the contact distance (sum of the radii) must be "
                     "positive");
  EXPECT_INPUT_ERROR(make_step_table(s, 1.0, 1),
                     "potential lennard_jones: the dimension must be 2 or 3");
  s.steps = 2000;
  EXPECT_INPUT_ERROR(make_step_table(s, 0.5),
                     "potential lennard_jones: the energy placement would need");

  s = spec_of("wca");
  s.cutoff = 2.0;
  EXPECT_INPUT_ERROR(make_step_table(s, 1.0),
                     "potential wca: the cut-off is 2^(1/6) sigma; leave cutoff unset");
  s = spec_of("wca");
  EXPECT_INPUT_ERROR(
      make_step_table(s, 1.2),
      "potential wca: the cut-off 1.122462048309373 must lie beyond the contact distance");
  s = spec_of("yukawa");
  s.epsilon = 0.0;
  EXPECT_INPUT_ERROR(make_step_table(s, 1.0),
                     "potential yukawa: epsilon must be finite and non-zero");
  s = spec_of("yukawa");
  s.kappa = -0.5;
  EXPECT_INPUT_ERROR(make_step_table(s, 1.0),
                     "potential yukawa: kappa must be finite and at least 0");
  s = spec_of("morse");
  s.alpha = 0.0;
  EXPECT_INPUT_ERROR(make_step_table(s, 1.0), "potential morse: alpha must be positive");
  s = spec_of("morse");
  s.r_min = 1.5;
  s.cutoff = 1.4;
  EXPECT_INPUT_ERROR(make_step_table(s, 1.0),
                     "potential morse: the cut-off 1.4 must lie beyond the minimum r_min = 1.5");
  s = spec_of("morse");
  s.epsilon = -1.0;
  EXPECT_INPUT_ERROR(make_step_table(s, 1.0), "potential morse: epsilon must be positive");

  s = spec_of("tabulated");
  EXPECT_INPUT_ERROR(make_step_table(s, 1.0), "potential tabulated: file must name");
  s.file = "/nonexistent/u.table";
  EXPECT_INPUT_ERROR(make_step_table(s, 1.0),
                     "potential tabulated: cannot read the potential file '/nonexistent/u.table'");
  s.cutoff = 3.0;
  EXPECT_INPUT_ERROR(make_step_table(s, 1.0),
                     "potential tabulated: the cut-off is the file's last r");
  const std::string file =
      (std::filesystem::path(testing::TempDir()) / "spec_short.table").string();
  std::ofstream(file) << "1.0 1\n2.0 0\n";
  s = spec_of("tabulated");
  s.file = file;
  EXPECT_INPUT_ERROR(make_step_table(s, 0.9),
                     "potential tabulated: U is not finite at the hard core r = 0.9");

  s = spec_of("square_well");
  s.lambda = 1.0;
  EXPECT_INPUT_ERROR(make_step_table(s, 1.0),
                     "potential square_well: lambda must be greater than 1");
  s = spec_of("square_shoulder");
  s.depth = -1.0;
  EXPECT_INPUT_ERROR(make_step_table(s, 1.0), "potential square_shoulder: depth must be positive");
  EXPECT_INPUT_ERROR(make_step_table(spec_of("soft"), 1.0), "unknown potential kind 'soft'");
  EXPECT_INPUT_ERROR(continuous_potential(spec_of("soft")), "unknown potential kind 'soft'");
}

// spring_dashpot (docs/physics.md#spring-dashpot-by-steps): the repulsive spring from `length`
// in, N equal steps to the core with midpoint energies, the dashpot on the table; its errors
// name the key.
TEST(PotentialSpec, SpringDashpot) {
  PotentialSpec s = spec_of("spring_dashpot");
  s.stiffness = 100.0;
  s.length = 1.2;
  s.steps = 4;
  s.damping = 0.5;
  const StepTable t = make_step_table(s, 1.0);
  EXPECT_EQ(t.boundary.size(), 5u);
  EXPECT_DOUBLE_EQ(t.cutoff(), 1.2);
  EXPECT_DOUBLE_EQ(t.core(), 1.0);
  EXPECT_NEAR(t.energy[0], 50.0 * 0.025 * 0.025, 1e-13);
  EXPECT_NEAR(t.energy[3], 50.0 * 0.175 * 0.175, 1e-13);
  EXPECT_EQ(t.damping, 0.5);
  EXPECT_TRUE(t.force_zero);
  EXPECT_EQ(continuous_potential(s).u(1.3), 0.0);
  EXPECT_NEAR(continuous_potential(s).u(1.1), 0.5, 1e-13);
  s.force_zero = false;
  EXPECT_FALSE(make_step_table(s, 1.0, 2).force_zero);
  // gamma from the restitution for the pair's reduced mass.
  s.damping = 0.0;
  s.restitution = 0.7;
  EXPECT_NEAR(make_step_table(s, 1.0, 3, 0.5).damping,
              dashpot_damping_for_restitution(0.5, 100.0, 0.7), 1e-15);
  EXPECT_INPUT_ERROR(make_step_table(s, 1.0),
                     "potential spring_dashpot: restitution needs the pair's masses");
  s.restitution = 0.0;
  EXPECT_EQ(make_step_table(s, 1.0).damping, 0.0);  // an elastic stepped spring
  s.restitution = 1.2;
  EXPECT_INPUT_ERROR(make_step_table(s, 1.0, 3, 0.5),
                     "potential spring_dashpot: restitution must be in (0, 1]");
  s.restitution = 0.7;
  s.damping = 1.0;
  EXPECT_INPUT_ERROR(make_step_table(s, 1.0, 3, 0.5),
                     "potential spring_dashpot: give damping or restitution, not both");
  s.restitution = 0.0;
  s.damping = -1.0;
  EXPECT_INPUT_ERROR(make_step_table(s, 1.0), "potential spring_dashpot: damping must be");
  s.damping = 0.0;
  EXPECT_INPUT_ERROR(make_step_table(s, 1.2), "potential spring_dashpot: length 1.2");
  s.stiffness = 0.0;
  EXPECT_INPUT_ERROR(make_step_table(s, 1.0), "potential spring_dashpot: stiffness must be");
  // The dashpot keys belong to spring_dashpot.
  PotentialSpec w = spec_of("square_well");
  w.damping = 1.0;
  EXPECT_INPUT_ERROR(make_step_table(w, 1.0),
                     "potential square_well: damping applies to kind spring_dashpot only");
  w.damping = 0.0;
  w.force_zero = false;
  EXPECT_INPUT_ERROR(make_step_table(w, 1.0), "force_zero applies to kind spring_dashpot only");
}

}  // namespace
}  // namespace kairos
