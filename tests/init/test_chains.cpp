// Chain molecules generated on a simple cubic / square lattice along a snake path
// (system.chain_length, system.chain_spacing).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "init/initial_state.hpp"
#include "initial_state_errors.hpp"

namespace kairos {
namespace {

SystemConfig chain_system(int dimension, std::uint64_t particles, double eta,
                          std::uint64_t chain_length, double spacing = 0.0,
                          std::vector<SpeciesConfig> species = {}) {
  SystemConfig s;
  s.dimension = dimension;
  s.particles = particles;
  s.packing_fraction = eta;
  s.chain_length = chain_length;
  s.chain_spacing = spacing;
  s.species = std::move(species);
  return s;
}

template <int D>
std::string error_of(const SystemConfig& system) {
  return test_util::initial_state_error<D>(system);
}

// Particles i and j sit on neighbouring sites a apart, without wrapping across the boundary:
// exactly one coordinate differs, by a (the generator rounds up, never down, by at most a few
// units in the last place).
template <int D>
void expect_neighbours(const InitialState<D>& st, std::uint32_t i, std::uint32_t j, double a) {
  int differing = 0;
  for (int k = 0; k < D; ++k) {
    const double dx = st.position[j][k] - st.position[i][k];
    if (dx == 0.0) continue;
    ++differing;
    EXPECT_GE(std::abs(dx), a) << i << "-" << j << " axis " << k;
    EXPECT_LE(std::abs(dx), a * (1.0 + 1e-13)) << i << "-" << j << " axis " << k;
  }
  EXPECT_EQ(differing, 1) << i << "-" << j;
}

template <int D>
void expect_chains(const InitialState<D>& st, std::uint64_t n, std::uint64_t length, double a,
                   double eta) {
  ASSERT_EQ(st.position.size(), n);
  ASSERT_EQ(st.velocity.size(), n);
  ASSERT_EQ(st.species.size(), n);
  ASSERT_EQ(st.diameter.size(), n);
  ASSERT_EQ(st.mass.size(), n);
  EXPECT_EQ(st.bond_types, std::vector<std::string>{"backbone"});
  const std::uint64_t chains = n / length;
  ASSERT_EQ(st.bonds.size(), chains * (length - 1));
  std::size_t b = 0;
  for (std::uint64_t c = 0; c < chains; ++c) {
    for (std::uint64_t k = 0; k + 1 < length; ++k, ++b) {
      const auto i = static_cast<std::uint32_t>(c * length + k);
      EXPECT_EQ(st.bonds[b], (Bond{i, i + 1, 0}));
      expect_neighbours(st, i, i + 1, a);
    }
  }
  for (const auto& x : st.position) {
    for (int k = 0; k < D; ++k) {
      ASSERT_GE(x[k], 0.0);
      ASSERT_LT(x[k], st.box[k]);
    }
  }
  for (int k = 1; k < D; ++k) EXPECT_EQ(st.box[k], st.box[0]);
  EXPECT_EQ(max_overlap_bruteforce<D>(st.box, st.position, st.diameter), 0.0);
  EXPECT_NEAR(packing_fraction(st), eta, 1e-12);
}

TEST(InitChains, ThreeDimensionsDefaultSpacing) {
  std::mt19937_64 rng(7);
  const auto st = make_initial_state<3>(chain_system(3, 300, 0.1, 10), rng);
  expect_chains(st, 300, 10, 1.0, 0.1);
}

TEST(InitChains, TwoDimensionsGivenSpacing) {
  std::mt19937_64 rng(7);
  const auto st = make_initial_state<2>(chain_system(2, 240, 0.2, 12, 1.3), rng);
  expect_chains(st, 240, 12, 1.3, 0.2);
}

TEST(InitChains, ThreeDimensionsUnevenSpacing) {
  std::mt19937_64 rng(3);
  const auto st = make_initial_state<3>(chain_system(3, 1000, 0.05, 25, 1.1), rng);
  expect_chains(st, 1000, 25, 1.1, 0.05);
}

// A full grid (S = N): particle k sits on path site k, so even consecutive chains are
// neighbours, and the path never jumps.
TEST(InitChains, FullGridFollowsTheSnakePath) {
  std::mt19937_64 rng(5);
  const auto st3 = make_initial_state<3>(chain_system(3, 512, 0.52, 8), rng);
  expect_chains(st3, 512, 8, 1.0, 0.52);
  for (std::uint32_t i = 0; i + 1 < 512; ++i) expect_neighbours(st3, i, i + 1, 1.0);
  EXPECT_EQ(st3.position[0], (std::array<double, 3>{0.5, 0.5, 0.5}));

  const auto st2 = make_initial_state<2>(chain_system(2, 100, 0.78, 5), rng);
  expect_chains(st2, 100, 5, 1.0, 0.78);
  for (std::uint32_t i = 0; i + 1 < 100; ++i) expect_neighbours(st2, i, i + 1, 1.0);
}

TEST(InitChains, MixtureUsesTheLargestDiameterAndTheFractions) {
  std::vector<SpeciesConfig> mix = {{"S", 1.0, 1.0, 0.75}, {"L", 1.25, 2.0, 0.25}};
  std::mt19937_64 rng(11);
  const auto st = make_initial_state<3>(chain_system(3, 400, 0.15, 20, 0.0, mix), rng);
  expect_chains(st, 400, 20, 1.25, 0.15);
  std::size_t large = 0;
  for (std::size_t i = 0; i < st.species.size(); ++i) {
    large += st.species[i] == 1;
    EXPECT_EQ(st.diameter[i], st.species[i] == 1 ? 1.25 : 1.0);
    EXPECT_EQ(st.mass[i], st.species[i] == 1 ? 2.0 : 1.0);
  }
  EXPECT_EQ(large, 100u);
  EXPECT_EQ(st.species_names, (std::vector<std::string>{"S", "L"}));
}

TEST(InitChains, LengthOneMakesNoBonds) {
  std::mt19937_64 rng(1);
  const auto st = make_initial_state<3>(chain_system(3, 64, 0.2, 1), rng);
  EXPECT_TRUE(st.bonds.empty());
  EXPECT_EQ(max_overlap_bruteforce<3>(st.box, st.position, st.diameter), 0.0);
}

TEST(InitChains, ParticlesMustBeAMultipleOfTheChainLength) {
  EXPECT_EQ(error_of<3>(chain_system(3, 301, 0.1, 10)),
            "system.particles (301) must be a multiple of system.chain_length (10)");
  EXPECT_EQ(error_of<2>(chain_system(2, 5, 0.1, 10)),
            "system.particles (5) must be a multiple of system.chain_length (10)");
}

TEST(InitChains, SpacingBelowTheLargestDiameterIsRefused) {
  const std::string e =
      error_of<3>(chain_system(3, 300, 0.1, 10, 1.2, {{"S", 1.0, 1.0, 1.0}, {"L", 1.3, 1.0, 1.0}}));
  EXPECT_NE(e.find("system.chain_spacing = 1.2"), std::string::npos) << e;
  EXPECT_NE(e.find("1.3"), std::string::npos) << e;
  EXPECT_NE(error_of<3>(chain_system(3, 300, 0.1, 10, -1.0)).find("system.chain_spacing"),
            std::string::npos);
}

// The message gives the largest possible packing fraction; that one works, a little more not.
template <int D>
void check_packing_limit(std::uint64_t n, std::uint64_t length, double spacing, double eta) {
  const std::string e = error_of<D>(chain_system(D, n, eta, length, spacing));
  ASSERT_NE(e.find("system.packing_fraction = "), std::string::npos) << e;
  const std::string tag = "the largest possible is ";
  const auto at = e.find(tag);
  ASSERT_NE(at, std::string::npos) << e;
  const double largest = std::stod(e.substr(at + tag.size()));
  EXPECT_LT(largest, eta);
  EXPECT_EQ(error_of<D>(chain_system(D, n, largest, length, spacing)), "") << largest;
  EXPECT_NE(error_of<D>(chain_system(D, n, largest * (1.0 + 2e-5), length, spacing)), "")
      << largest;
}

TEST(InitChains, TooDenseNamesThePackingFractionAndItsLimit) {
  check_packing_limit<3>(300, 10, 0.0, 0.5);   // 7^3 = 343 sites needed: limit 0.457...
  check_packing_limit<3>(1000, 10, 1.5, 0.2);  // spacing 1.5: limit pi/6/1.5^3 = 0.155
  check_packing_limit<2>(240, 12, 0.0, 0.75);  // 16^2 sites: limit 0.736...
  check_packing_limit<2>(100, 10, 1.2, 0.6);   // 10^2 sites exactly
}

TEST(InitChains, TooFewParticlesForTheCellList) {
  const std::string e = error_of<3>(chain_system(3, 4, 0.3, 2));
  EXPECT_NE(e.find("system.particles = 4 is too few"), std::string::npos) << e;
  EXPECT_NE(e.find("at least"), std::string::npos) << e;
}

TEST(InitChains, LatticeKeyIsIgnored) {
  SystemConfig s = chain_system(2, 60, 0.2, 6);
  s.lattice = "fcc";  // not even a 2D lattice
  std::mt19937_64 rng(2);
  expect_chains(make_initial_state<2>(s, rng), 60, 6, 1.0, 0.2);
}

TEST(InitChains, ToParticleSystemCopiesTheBonds) {
  std::mt19937_64 rng(4);
  const auto st = make_initial_state<3>(chain_system(3, 120, 0.1, 6), rng);
  const auto sys = to_particle_system<3>(st);
  EXPECT_EQ(sys.bonds, st.bonds);
  EXPECT_EQ(sys.bond_types, st.bond_types);
  EXPECT_FALSE(sys.zones.has_value());
}

TEST(InitChains, SortSpatiallyRenumbersTheBonds) {
  std::mt19937_64 rng(9);
  auto st = make_initial_state<3>(chain_system(3, 300, 0.1, 10), rng);
  const auto before = st;
  sort_spatially(st);
  ASSERT_EQ(st.bonds.size(), before.bonds.size());
  for (std::size_t b = 0; b < st.bonds.size(); ++b) {
    EXPECT_EQ(st.position[st.bonds[b].i], before.position[before.bonds[b].i]);
    EXPECT_EQ(st.position[st.bonds[b].j], before.position[before.bonds[b].j]);
    expect_neighbours(st, st.bonds[b].i, st.bonds[b].j, 1.0);
  }
}

TEST(InitChains, Deterministic) {
  std::mt19937_64 a(42), b(42);
  const auto s = chain_system(3, 200, 0.1, 10, 0.0, {{"S", 1.0, 1.0, 0.5}, {"L", 1.1, 1.0, 0.5}});
  const auto x = make_initial_state<3>(s, a);
  const auto y = make_initial_state<3>(s, b);
  EXPECT_EQ(x.position, y.position);
  EXPECT_EQ(x.species, y.species);
  EXPECT_EQ(x.velocity, y.velocity);
}

}  // namespace
}  // namespace kairos
