// [[potential]] kind = "spring_dashpot" (docs/physics.md#spring-dashpot-by-steps): its keys,
// their errors (each naming the key), and the round trip through the effective configuration.
#include <gtest/gtest.h>

#include <string>

#include "core/error.hpp"
#include "io/config.hpp"

namespace kairos {
namespace {

constexpr std::string_view kGas = R"([system]
particles = 500
packing_fraction = 0.05
)";

std::string with(std::string_view potential) {
  // Appended in place: GCC 12's -Warray-bounds misreads `std::string(kGas) + "..."` at -O1.
  std::string text(kGas);
  text += "[[potential]]\nkind = \"spring_dashpot\"\n";
  text += potential;
  text += "\n";
  return text;
}

std::string error_of(const std::string& text) {
  try {
    parse_config(text, "test.toml");
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError for:\n" << text;
  return {};
}

TEST(ConfigSpringDashpot, KeysAreReadAndRoundTrip) {
  const Config c = parse_config(
      with("stiffness = 1e4\nlength = 1.0\nsteps = 500\nrestitution = 0.8\nforce_zero = false"),
      "test.toml");
  ASSERT_EQ(c.potentials.size(), 1u);
  const PotentialSpec& p = c.potentials[0].potential;
  EXPECT_EQ(p.kind, "spring_dashpot");
  EXPECT_EQ(p.stiffness, 1e4);
  EXPECT_EQ(p.length, 1.0);
  EXPECT_EQ(p.steps, 500);
  EXPECT_EQ(p.restitution, 0.8);
  EXPECT_EQ(p.damping, 0.0);
  EXPECT_FALSE(p.force_zero);
  EXPECT_EQ(parse_config(to_toml(c), "effective.toml").potentials, c.potentials);
  const Config d = parse_config(with("stiffness = 1e4\nlength = 1.0\ndamping = 3.5"), "test.toml");
  EXPECT_EQ(d.potentials[0].potential.damping, 3.5);
  EXPECT_TRUE(d.potentials[0].potential.force_zero);
  EXPECT_EQ(parse_config(to_toml(d), "effective.toml").potentials, d.potentials);
}

TEST(ConfigSpringDashpot, ErrorsNameTheKey) {
  EXPECT_NE(error_of(with("stiffness = 1e4\nlength = 1\ndamping = 1\nrestitution = 0.9"))
                .find("potential[0].restitution: give damping or restitution, not both"),
            std::string::npos);
  EXPECT_NE(error_of(with("stiffness = 1e4\nlength = 1\nrestitution = 1.5"))
                .find("potential[0].restitution: must be in (0, 1]"),
            std::string::npos);
  EXPECT_NE(error_of(with("stiffness = 1e4\nlength = 1\ndamping = -1"))
                .find("potential[0].damping: must be >= 0"),
            std::string::npos);
  EXPECT_NE(error_of(with("stiffness = 1e4\nlength = 1\nplacement = \"energy\""))
                .find("potential[0].placement: spring_dashpot steps are always of equal width"),
            std::string::npos);
  EXPECT_NE(error_of(with("stiffness = 1e4\nlength = 1\nshell_energy = \"volume\""))
                .find("potential[0].shell_energy"),
            std::string::npos);
  // The dashpot keys belong to spring_dashpot only.
  const std::string well = std::string(kGas) + "[[potential]]\nkind = \"square_well\"\n";
  EXPECT_NE(error_of(well + "damping = 1\n")
                .find("potential[0].damping: applies to kind = \"spring_dashpot\" only"),
            std::string::npos);
  EXPECT_NE(error_of(well + "force_zero = false\n").find("potential[0].force_zero"),
            std::string::npos);
  EXPECT_NE(error_of(std::string(kGas) + "[[potential]]\nkind = \"springdashpot\"\n")
                .find("spring_dashpot"),
            std::string::npos);
}

}  // namespace
}  // namespace kairos
