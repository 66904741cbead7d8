#include "init/initial_state.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "initial_state_errors.hpp"

namespace kairos {
namespace {

SystemConfig make_system(int dimension, std::uint64_t particles, double eta, std::string lattice,
                         std::vector<SpeciesConfig> species = {}) {
  SystemConfig s;
  s.dimension = dimension;
  s.particles = particles;
  s.packing_fraction = eta;
  s.lattice = std::move(lattice);
  s.species = std::move(species);
  return s;
}

std::vector<SpeciesConfig> binary_mixture() {
  return {SpeciesConfig{"S", 1.0, 1.0, 0.5}, SpeciesConfig{"L", 1.4, 2.0, 0.5}};
}

template <int D>
std::string error_of(const SystemConfig& system) {
  return test_util::initial_state_error<D>(system);
}

template <int D>
void expect_valid(const InitialState<D>& st, std::uint64_t n, double eta) {
  ASSERT_EQ(st.position.size(), n);
  ASSERT_EQ(st.velocity.size(), n);
  ASSERT_EQ(st.species.size(), n);
  ASSERT_EQ(st.diameter.size(), n);
  ASSERT_EQ(st.mass.size(), n);
  for (const auto& x : st.position) {
    for (int k = 0; k < D; ++k) {
      ASSERT_GE(x[k], 0.0);
      ASSERT_LT(x[k], st.box[k]);
    }
  }
  for (std::uint32_t s : st.species) ASSERT_LT(s, st.species_names.size());
  EXPECT_EQ(max_overlap_bruteforce<D>(st.box, st.position, st.diameter), 0.0);
  EXPECT_NEAR(packing_fraction(st), eta, 1e-12);
  for (int k = 0; k < D; ++k) EXPECT_GE(st.box[k], 3.0 * 1.0);
}

// ---------------------------------------------------------------------------------------------

TEST(InitLargestRemainder, SumsExactlyAndRoundsByRemainder) {
  EXPECT_EQ(largest_remainder_counts({1, 1, 1}, 10), (std::vector<std::uint64_t>{4, 3, 3}));
  EXPECT_EQ(largest_remainder_counts({0.5, 0.5}, 1001), (std::vector<std::uint64_t>{501, 500}));
  EXPECT_EQ(largest_remainder_counts({0.2, 0.3, 0.5}, 7), (std::vector<std::uint64_t>{1, 2, 4}));
  EXPECT_EQ(largest_remainder_counts({3, 0, 1}, 4), (std::vector<std::uint64_t>{3, 0, 1}));
  EXPECT_EQ(largest_remainder_counts({2, 2}, 3), (std::vector<std::uint64_t>{2, 1}));
  for (std::uint64_t n = 0; n < 200; ++n) {
    const auto c = largest_remainder_counts({0.1, 0.7, 0.2, 1e-3}, n);
    EXPECT_EQ(c[0] + c[1] + c[2] + c[3], n);
  }
}

TEST(InitParticleVolume, SpheresAndDisks) {
  EXPECT_DOUBLE_EQ(particle_volume<3>(2.0), 4.0 / 3.0 * std::numbers::pi);
  EXPECT_DOUBLE_EQ(particle_volume<2>(2.0), std::numbers::pi);
}

struct LatticeCase {
  std::string lattice;
  std::uint64_t n;
};

class InitLattice3D : public ::testing::TestWithParam<LatticeCase> {};
class InitLattice2D : public ::testing::TestWithParam<LatticeCase> {};

TEST_P(InitLattice3D, RightCountInsideBoxNoOverlapExactPacking) {
  const auto& c = GetParam();
  const double eta = 0.35;
  std::mt19937_64 rng(7);
  const auto st = make_initial_state<3>(make_system(3, c.n, eta, c.lattice), rng);
  expect_valid(st, c.n, eta);
  EXPECT_EQ(st.box[0], st.box[1]);
  EXPECT_EQ(st.box[0], st.box[2]);
  ASSERT_EQ(st.species_names, std::vector<std::string>{"A"});
}

TEST_P(InitLattice2D, RightCountInsideBoxNoOverlapExactPacking) {
  const auto& c = GetParam();
  const double eta = 0.5;
  std::mt19937_64 rng(7);
  const auto st = make_initial_state<2>(make_system(2, c.n, eta, c.lattice), rng);
  expect_valid(st, c.n, eta);
  // Close to square: within a factor 1.2 once N is not tiny.
  const double aspect = st.box[1] / st.box[0];
  EXPECT_LT(aspect, 1.2);
  EXPECT_GT(aspect, 1.0 / 1.2);
}

INSTANTIATE_TEST_SUITE_P(All, InitLattice3D,
                         ::testing::Values(LatticeCase{"fcc", 500}, LatticeCase{"fcc", 1000},
                                           LatticeCase{"fcc", 1001}, LatticeCase{"fcc", 97},
                                           LatticeCase{"bcc", 432}, LatticeCase{"bcc", 1000},
                                           LatticeCase{"bcc", 1001}, LatticeCase{"sc", 1000},
                                           LatticeCase{"sc", 1001}, LatticeCase{"sc", 343},
                                           LatticeCase{"", 1000}),
                         [](const auto& param_info) {
                           return (param_info.param.lattice.empty() ? std::string("default")
                                                                    : param_info.param.lattice) +
                                  std::to_string(param_info.param.n);
                         });

INSTANTIATE_TEST_SUITE_P(All, InitLattice2D,
                         ::testing::Values(LatticeCase{"square", 1024}, LatticeCase{"square", 1000},
                                           LatticeCase{"square", 1001}, LatticeCase{"hex", 1000},
                                           LatticeCase{"hex", 1001}, LatticeCase{"hex", 780},
                                           LatticeCase{"hex", 97}, LatticeCase{"", 1000}),
                         [](const auto& param_info) {
                           return (param_info.param.lattice.empty() ? std::string("default")
                                                                    : param_info.param.lattice) +
                                  std::to_string(param_info.param.n);
                         });

TEST(InitLattice, PartialFillingIsUniform) {
  // 1000 particles on the 1372 sites of 7x7x7 fcc cells: every octant holds about 1/8.
  std::mt19937_64 rng(3);
  const auto st = make_initial_state<3>(make_system(3, 1000, 0.4, "fcc"), rng);
  std::vector<int> octant(8, 0);
  for (const auto& x : st.position) {
    int o = 0;
    for (int k = 0; k < 3; ++k) o = 2 * o + (x[k] >= 0.5 * st.box[k] ? 1 : 0);
    ++octant[static_cast<std::size_t>(o)];
  }
  for (int c : octant) {
    EXPECT_GT(c, 100);
    EXPECT_LT(c, 150);
  }
}

TEST(InitLattice, HexPerfectLatticeHasUnitNearestNeighbourRatio) {
  // 780 = 2 x 26 x 15 sites in a nearly square box (aspect 15 sqrt(3) / 26 = 0.999): fully
  // filled; at the close-packing limit pi / (2 sqrt 3) the disks touch.
  std::mt19937_64 rng(3);
  const double limit = std::numbers::pi / (2.0 * std::sqrt(3.0));
  const auto st = make_initial_state<2>(make_system(2, 780, limit * (1 - 1e-9), "hex"), rng);
  EXPECT_EQ(max_overlap_bruteforce<2>(st.box, st.position, st.diameter), 0.0);
  auto touching = st.diameter;
  for (double& d : touching) d *= 1.0 + 1e-6;
  EXPECT_GT(max_overlap_bruteforce<2>(st.box, st.position, touching), 0.0);
}

TEST(InitLattice, MixtureIsSpreadOverTheSites) {
  std::mt19937_64 rng(11);
  const auto st = make_initial_state<3>(make_system(3, 2000, 0.3, "fcc", binary_mixture()), rng);
  ASSERT_EQ(st.species_names, (std::vector<std::string>{"S", "L"}));
  EXPECT_EQ(std::count(st.species.begin(), st.species.end(), 0u), 1000);
  EXPECT_EQ(std::count(st.species.begin(), st.species.end(), 1u), 1000);
  // Each half of the particle list (= of the lattice) holds both species in similar numbers.
  const auto first_half = std::count(st.species.begin(), st.species.begin() + 1000, 1u);
  EXPECT_GT(first_half, 400);
  EXPECT_LT(first_half, 600);
  for (std::size_t i = 0; i < st.species.size(); ++i) {
    EXPECT_EQ(st.diameter[i], st.species[i] == 0 ? 1.0 : 1.4);
    EXPECT_EQ(st.mass[i], st.species[i] == 0 ? 1.0 : 2.0);
  }
  EXPECT_NEAR(packing_fraction(st), 0.3, 1e-12);
  EXPECT_EQ(max_overlap_bruteforce<3>(st.box, st.position, st.diameter), 0.0);
}

TEST(InitLattice, ImpossiblePackingFractionExactMessage) {
  EXPECT_EQ(error_of<3>(make_system(3, 1000, 0.6, "sc")),
            "system.packing_fraction = 0.6 is impossible on a sc lattice with 1000 particles "
            "(10x10x10 cells): the nearest-neighbour distance 0.955614 is smaller than the "
            "largest diameter 1; the largest possible is 0.523598");
  EXPECT_EQ(error_of<3>(make_system(3, 1000, 0.6, "fcc")),
            "system.packing_fraction = 0.6 is impossible on a fcc lattice with 1000 particles "
            "(7x7x7 cells, 1372 sites): the nearest-neighbour distance 0.965316 is smaller than "
            "the largest diameter 1; the largest possible is 0.539708 (0.74048 with 1372 "
            "particles, which fill the lattice)");
}

TEST(InitLattice, FccCloseToClosePacking) {
  EXPECT_EQ(error_of<3>(make_system(3, 500, 0.74, "fcc")), "");
  EXPECT_EQ(error_of<3>(make_system(3, 500, 0.74048, "fcc")), "");  // the printed limit works
  const std::string e = error_of<3>(make_system(3, 500, 0.75, "fcc"));
  EXPECT_NE(e.find("system.packing_fraction = 0.75"), std::string::npos) << e;
  EXPECT_NE(e.find("fcc"), std::string::npos) << e;
  EXPECT_NE(e.find("the largest possible is 0.74048"), std::string::npos) << e;

  std::mt19937_64 rng(5);
  const auto st = make_initial_state<3>(make_system(3, 864, 0.74, "fcc"), rng);
  expect_valid(st, 864, 0.74);
}

TEST(InitLattice, ImpossibleForEveryLattice) {
  EXPECT_NE(error_of<3>(make_system(3, 432, 0.69, "bcc")).find("system.packing_fraction"),
            std::string::npos);
  EXPECT_EQ(error_of<3>(make_system(3, 432, 0.68, "bcc")), "");
  EXPECT_NE(error_of<2>(make_system(2, 1024, 0.79, "square")).find("system.packing_fraction"),
            std::string::npos);
  EXPECT_EQ(error_of<2>(make_system(2, 1024, 0.78, "square")), "");
  EXPECT_NE(error_of<2>(make_system(2, 780, 0.91, "hex")).find("system.packing_fraction"),
            std::string::npos);
  EXPECT_EQ(error_of<2>(make_system(2, 780, 0.90, "hex")), "");
  // The largest diameter decides.
  EXPECT_NE(error_of<3>(make_system(3, 2048, 0.55, "fcc", binary_mixture())).find("1.4"),
            std::string::npos);
}

TEST(InitLattice, TooFewParticlesNamesTheMinimum) {
  const std::string e = error_of<3>(make_system(3, 10, 0.3, "sc"));
  ASSERT_NE(e.find("system.particles = 10"), std::string::npos) << e;
  const auto at = e.find("at least ");
  ASSERT_NE(at, std::string::npos) << e;
  const std::uint64_t needed = std::stoull(e.substr(at + 9));
  EXPECT_EQ(error_of<3>(make_system(3, needed, 0.3, "sc")), "");
  EXPECT_NE(error_of<3>(make_system(3, needed - 1, 0.3, "sc")), "");

  const std::string e2 = error_of<2>(make_system(2, 5, 0.5, "hex"));
  ASSERT_NE(e2.find("system.particles = 5"), std::string::npos) << e2;
  const auto at2 = e2.find("at least ");
  ASSERT_NE(at2, std::string::npos) << e2;
  EXPECT_EQ(error_of<2>(make_system(2, std::stoull(e2.substr(at2 + 9)), 0.5, "hex")), "");

  EXPECT_NE(error_of<3>(make_system(3, 5, 0.2, "random")).find("system.particles"),
            std::string::npos);
}

TEST(InitLattice, InvalidRequests) {
  EXPECT_NE(error_of<3>(make_system(3, 100, 0.3, "hex")).find("system.lattice"), std::string::npos);
  EXPECT_NE(error_of<2>(make_system(2, 100, 0.3, "fcc")).find("system.lattice"), std::string::npos);
  EXPECT_NE(error_of<3>(make_system(3, 0, 0.3, "fcc")).find("system.particles"), std::string::npos);
  EXPECT_NE(error_of<3>(make_system(3, 100, 0.0, "fcc")).find("system.packing_fraction"),
            std::string::npos);
  EXPECT_NE(error_of<3>(make_system(3, 100, 0.3, "fcc", {SpeciesConfig{"A", -1.0, 1.0, 1.0}}))
                .find("system.species[0].diameter"),
            std::string::npos);
  std::mt19937_64 rng(1);
  EXPECT_THROW((void)make_initial_state<2>(make_system(3, 100, 0.3, "fcc"), rng), std::logic_error);
}

TEST(InitRandom, BinaryMixture3D) {
  std::mt19937_64 rng(21);
  const auto st = make_initial_state<3>(make_system(3, 2000, 0.3, "random", binary_mixture()), rng);
  expect_valid(st, 2000, 0.3);
  EXPECT_EQ(std::count(st.species.begin(), st.species.end(), 0u), 1000);
  EXPECT_EQ(std::count(st.species.begin(), st.species.end(), 1u), 1000);
  EXPECT_EQ(max_overlap<3>(st.box, st.position, st.diameter), 0.0);
}

TEST(InitRandom, BinaryMixture2D) {
  std::mt19937_64 rng(22);
  const auto st = make_initial_state<2>(make_system(2, 2000, 0.4, "random", binary_mixture()), rng);
  expect_valid(st, 2000, 0.4);
  EXPECT_EQ(std::count(st.species.begin(), st.species.end(), 0u), 1000);
  EXPECT_EQ(std::count(st.species.begin(), st.species.end(), 1u), 1000);
  EXPECT_EQ(st.box[0], st.box[1]);
}

// Sizes 1 : 10 (insertion's grid in two size classes): no overlap, the counts and packing
// fraction asked for.
TEST(InitRandom, AsymmetricMixtureOneToTen) {
  const std::vector<SpeciesConfig> species = {SpeciesConfig{"small", 1.0, 1.0, 200.0},
                                              SpeciesConfig{"big", 10.0, 100.0, 1.0}};
  std::mt19937_64 rng(23);
  const auto st = make_initial_state<2>(make_system(2, 4020, 0.35, "random", species), rng);
  expect_valid(st, 4020, 0.35);
  EXPECT_EQ(std::count(st.species.begin(), st.species.end(), 1u), 20);
}

TEST(InitRandom, NearTheAllowedLimit) {
  std::mt19937_64 rng(23);
  expect_valid(make_initial_state<3>(make_system(3, 1000, 0.35, "random"), rng), 1000, 0.35);
  expect_valid(make_initial_state<2>(make_system(2, 1000, 0.5, "random"), rng), 1000, 0.5);
}

// The voxel-accelerated insertion must stay uniform: coordinate histograms along every axis
// are flat within a generous statistical margin (expected 250 per bin, sd ~ 15).
template <int D>
void expect_uniform(const InitialState<D>& st) {
  constexpr int kBins = 8;
  for (int k = 0; k < D; ++k) {
    std::vector<int> hist(kBins, 0);
    for (const auto& x : st.position) {
      ++hist[static_cast<std::size_t>(x[k] / st.box[k] * kBins)];
    }
    const double expected = static_cast<double>(st.position.size()) / kBins;
    for (int h : hist) EXPECT_NEAR(h, expected, 0.25 * expected) << "axis " << k;
  }
}

TEST(InitRandom, UniformNearTheLimit) {
  std::mt19937_64 rng(24);
  expect_uniform(make_initial_state<3>(make_system(3, 2000, 0.35, "random"), rng));
  expect_uniform(make_initial_state<2>(make_system(2, 2000, 0.5, "random"), rng));
}

TEST(InitRandom, RefusedAboveTheJammingMargin) {
  const std::string e3 = error_of<3>(make_system(3, 1000, 0.36, "random"));
  EXPECT_NE(e3.find("system.packing_fraction = 0.36"), std::string::npos) << e3;
  EXPECT_NE(e3.find("lattice"), std::string::npos) << e3;
  const std::string e2 = error_of<2>(make_system(2, 1000, 0.51, "random"));
  EXPECT_NE(e2.find("system.packing_fraction = 0.51"), std::string::npos) << e2;
  EXPECT_NE(e2.find("hex"), std::string::npos) << e2;
}

TEST(InitialState, DeterministicGivenTheSeed) {
  for (const char* lattice : {"fcc", "random"}) {
    const auto sys = make_system(3, 300, 0.3, lattice, binary_mixture());
    std::mt19937_64 a(99), b(99), c(100);
    const auto sa = make_initial_state<3>(sys, a);
    const auto sb = make_initial_state<3>(sys, b);
    const auto sc = make_initial_state<3>(sys, c);
    EXPECT_EQ(sa.position, sb.position);
    EXPECT_EQ(sa.velocity, sb.velocity);
    EXPECT_EQ(sa.species, sb.species);
    EXPECT_NE(sa.velocity, sc.velocity);
  }
}

// ---------------------------------------------------------------------------------------------

template <int D>
void check_velocities(std::size_t n, double kT, std::uint64_t seed) {
  InitialState<D> st;
  st.position.resize(n);
  st.mass.resize(n);
  for (std::size_t i = 0; i < n; ++i) st.mass[i] = i % 3 == 0 ? 1.0 : 3.5;
  std::mt19937_64 rng(seed);
  assign_maxwell_boltzmann_velocities(st, kT, rng);
  ASSERT_EQ(st.velocity.size(), n);
  // Accumulated in long double so that the check itself is accurate.
  std::array<long double, D> p{};
  long double twice_ke = 0.0L;
  for (std::size_t i = 0; i < n; ++i) {
    for (int k = 0; k < D; ++k) {
      p[k] += static_cast<long double>(st.mass[i] * st.velocity[i][k]);
      twice_ke += static_cast<long double>(st.mass[i] * st.velocity[i][k] * st.velocity[i][k]);
    }
  }
  for (int k = 0; k < D; ++k) EXPECT_NEAR(static_cast<double>(p[k]), 0.0, 1e-12);
  EXPECT_NEAR(static_cast<double>(twice_ke) / (D * static_cast<double>(n - 1)), kT, 1e-12 * kT);

  // Equipartition per species (statistical): <m v^2> / D close to kT for both masses.
  double light = 0.0, heavy = 0.0;
  std::size_t n_light = 0;
  for (std::size_t i = 0; i < n; ++i) {
    double e = 0.0;
    for (int k = 0; k < D; ++k) e += st.mass[i] * st.velocity[i][k] * st.velocity[i][k];
    (st.mass[i] == 1.0 ? light : heavy) += e / D;
    n_light += st.mass[i] == 1.0 ? 1 : 0;
  }
  EXPECT_NEAR(light / static_cast<double>(n_light), kT, 0.1 * kT);
  EXPECT_NEAR(heavy / static_cast<double>(n - n_light), kT, 0.1 * kT);
}

TEST(InitVelocities, ZeroMomentumExactTemperature) {
  check_velocities<3>(3000, 1.0, 1);
  check_velocities<3>(10000, 2.5, 2);
  check_velocities<2>(3000, 0.7, 3);
  check_velocities<2>(10000, 1.0, 4);
}

TEST(InitVelocities, DegenerateCases) {
  InitialState<3> one;
  one.position.resize(1);
  one.mass = {1.0};
  std::mt19937_64 rng(1);
  assign_maxwell_boltzmann_velocities(one, 1.0, rng);
  EXPECT_EQ(one.velocity, (std::vector<std::array<double, 3>>{{0.0, 0.0, 0.0}}));

  InitialState<2> cold;
  cold.position.resize(10);
  cold.mass.assign(10, 1.0);
  assign_maxwell_boltzmann_velocities(cold, 0.0, rng);
  for (const auto& v : cold.velocity) EXPECT_EQ(v, (std::array<double, 2>{0.0, 0.0}));
  EXPECT_THROW(assign_maxwell_boltzmann_velocities(cold, -1.0, rng), InputError);
}

TEST(InitVelocities, MakeInitialStateUsesTheTemperature) {
  auto sys = make_system(3, 500, 0.3, "fcc", binary_mixture());
  sys.temperature = 1.7;
  std::mt19937_64 rng(8);
  const auto st = make_initial_state<3>(sys, rng);
  double twice_ke = 0.0;
  for (std::size_t i = 0; i < st.mass.size(); ++i) {
    for (int k = 0; k < 3; ++k) twice_ke += st.mass[i] * st.velocity[i][k] * st.velocity[i][k];
  }
  EXPECT_NEAR(twice_ke / (3.0 * 499.0), 1.7, 1e-12);
}

// ---------------------------------------------------------------------------------------------

// Diameters uniform in [0.5, 1.5], or log-uniform over `decades` below 1.5 (many size
// classes: the grid's rings across classes).
template <int D>
void compare_overlaps(std::mt19937_64& rng, const std::array<double, D>& box, std::size_t n,
                      double decades = 0.0) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<std::array<double, D>> pos(n);
  std::vector<double> diameter(n);
  for (std::size_t i = 0; i < n; ++i) {
    for (int k = 0; k < D; ++k) pos[i][k] = unit(rng) * box[k];
    diameter[i] = decades > 0.0 ? 1.5 * std::pow(10.0, -decades * unit(rng)) : 0.5 + unit(rng);
  }
  std::uint32_t wi = 0, wj = 0;
  const double fast = max_overlap<D>(box, pos, diameter, &wi, &wj);
  const double slow = max_overlap_bruteforce<D>(box, pos, diameter);
  EXPECT_EQ(fast, slow) << "n = " << n << " box[0] = " << box[0];
  if (slow > 0.0) {
    ASSERT_LT(wi, wj);
    ASSERT_LT(wj, n);
    const std::vector<std::array<double, D>> pair = {pos[wi], pos[wj]};
    EXPECT_EQ(max_overlap_bruteforce<D>(box, pair, {diameter[wi], diameter[wj]}), slow);
  } else {
    EXPECT_EQ(wi, kNoParticle);
    EXPECT_EQ(wj, kNoParticle);
  }
}

TEST(InitMaxOverlap, AgreesWithBruteForce3D) {
  std::mt19937_64 rng(31);
  const std::vector<std::array<double, 3>> boxes = {
      {10.0, 10.0, 10.0}, {12.0, 7.3, 5.1},     {4.0, 4.0, 4.0}, {3.2, 3.2, 3.2},
      {2.5, 9.0, 9.0},    {1.6, 1.6, 8.0},      {1.2, 1.3, 1.4}, {0.9, 6.0, 6.0},
      {30.0, 30.0, 1.0},  {100.0, 100.0, 100.0}};
  for (const auto& box : boxes) {
    for (std::size_t n : {2u, 3u, 17u, 150u, 600u}) compare_overlaps<3>(rng, box, n);
  }
}

TEST(InitMaxOverlap, AgreesWithBruteForce2D) {
  std::mt19937_64 rng(32);
  const std::vector<std::array<double, 2>> boxes = {
      {20.0, 20.0}, {13.0, 4.2}, {3.1, 3.1}, {2.2, 2.2}, {1.5, 30.0}, {0.8, 0.8}, {400.0, 400.0}};
  for (const auto& box : boxes) {
    for (std::size_t n : {2u, 5u, 40u, 300u, 1000u}) compare_overlaps<2>(rng, box, n);
  }
}

TEST(InitMaxOverlap, AgreesWithBruteForceOverAWideSizeDistribution) {
  std::mt19937_64 rng(33);
  for (const double decades : {1.0, 2.0, 3.5}) {
    for (std::size_t n : {2u, 40u, 400u, 1500u}) {
      compare_overlaps<3>(rng, {6.0, 7.0, 5.0}, n, decades);
      compare_overlaps<3>(rng, {2.0, 9.0, 9.0}, n, decades);
      compare_overlaps<2>(rng, {12.0, 10.0}, n, decades);
      compare_overlaps<2>(rng, {40.0, 3.0}, n, decades);
    }
  }
}

TEST(InitMaxOverlap, KnownPairAcrossTheBoundary) {
  const std::array<double, 3> box = {10.0, 10.0, 10.0};
  std::vector<std::array<double, 3>> pos = {{5, 5, 5}, {0.2, 3, 3}, {9.5, 3, 3}, {5, 6.2, 5}};
  std::vector<double> diameter = {1.0, 1.0, 1.0, 1.0};
  std::uint32_t wi = 0, wj = 0;
  // Pair (1, 2) at distance 0.7 through the periodic boundary: overlap 0.3; pair (0, 3): 0.
  EXPECT_NEAR(max_overlap<3>(box, pos, diameter, &wi, &wj), 0.3, 1e-12);
  EXPECT_EQ(wi, 1u);
  EXPECT_EQ(wj, 2u);
  pos[2] = {8.0, 3, 3};
  EXPECT_EQ(max_overlap<3>(box, pos, diameter, &wi, &wj), 0.0);
  EXPECT_EQ(wi, kNoParticle);
  EXPECT_EQ(wj, kNoParticle);
  EXPECT_EQ(max_overlap<3>(box, {}, {}), 0.0);
  EXPECT_THROW((void)max_overlap<3>(box, pos, {1.0}), std::invalid_argument);
}

// Along an axis with walls or an open face there is no periodic image: particles at opposite
// faces are far apart (a pile's fcc start has its bottom and top layers a box height apart, and
// a minimum image on that axis reported them overlapping). The cell search must agree with
// the brute force in random boxes with every combination of bounded axes, positions beyond the
// box on the bounded axes included (grains thrown out of an open top).
TEST(MaxOverlap, BoundedAxesTakeNoMinimumImage) {
  const std::array<double, 3> box{4.0, 4.0, 6.0};
  std::vector<std::array<double, 3>> pos{{1.0, 1.0, 0.1}, {1.0, 1.0, 5.9}};
  const std::vector<double> d{1.0, 1.0};
  EXPECT_NEAR(max_overlap<3>(box, pos, d), 0.8, 1e-12);  // periodic z: 0.2 apart through it
  const std::array<bool, 3> open_z{true, true, false};
  EXPECT_EQ(max_overlap<3>(box, open_z, pos, d), 0.0);
  EXPECT_EQ(max_overlap_bruteforce<3>(box, open_z, pos, d), 0.0);
  pos[1][2] = 0.6;
  std::uint32_t i = 7, j = 7;
  EXPECT_NEAR(max_overlap<3>(box, open_z, pos, d, &i, &j), 0.5, 1e-12);
  EXPECT_EQ(i, 0u);
  EXPECT_EQ(j, 1u);
}

TEST(MaxOverlap, BoundedAxesAgreeWithBruteForce) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int trial = 0; trial < 64; ++trial) {
    std::array<bool, 3> periodic{(trial & 1) != 0, (trial & 2) != 0, (trial & 4) != 0};
    const std::array<double, 3> box{5.0 + 3.0 * u(rng), 4.0 + 2.0 * u(rng), 6.0 + 4.0 * u(rng)};
    std::vector<std::array<double, 3>> pos(60);
    std::vector<double> d(60);
    for (std::size_t k = 0; k < pos.size(); ++k) {
      for (int a = 0; a < 3; ++a) {
        // Bounded axes: some positions outside [0, L).
        pos[k][a] = periodic[a] ? u(rng) * box[a] : (1.4 * u(rng) - 0.2) * box[a];
      }
      d[k] = 0.3 + 0.5 * u(rng);
    }
    // The cell search shifts bounded axes (round-off in the differences only).
    EXPECT_NEAR(max_overlap<3>(box, periodic, pos, d),
                max_overlap_bruteforce<3>(box, periodic, pos, d), 1e-12)
        << "trial " << trial;
  }
}

}  // namespace
}  // namespace kairos
