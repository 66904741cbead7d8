// The structure analyses (analysis/structure.hpp) against exact and published values: the pair
// search against brute force, g(r) = 1 of an ideal gas (periodic and bounded boxes) within its
// Poisson error, the species-pair normalisation by coordination numbers of a binary lattice,
// the contact extrapolation, Bragg peaks of S(k), Steinhardt's q4 and q6 of fcc, bcc and hcp,
// ψ6 of the hexagonal and square lattices, and the velocity distribution's moments.
#include "analysis/structure.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <set>
#include <utility>

namespace kairos {
namespace {

constexpr double kPi = std::numbers::pi;

template <int D>
Configuration<D> ideal_gas(std::size_t n, const Vec<D>& box, const std::array<bool, D>& periodic,
                           std::mt19937_64& rng, std::size_t species = 1) {
  Configuration<D> c;
  c.box = box;
  c.periodic = periodic;
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (std::size_t i = 0; i < n; ++i) {
    Vec<D> x;
    for (int a = 0; a < D; ++a) x[a] = u(rng) * box[a];
    c.position.push_back(x);
    c.species.push_back(static_cast<std::uint32_t>(i % species));
    c.radius.push_back(0.5);
  }
  return c;
}

// Sites of a lattice given by its basis in a cell, repeated cells[a] times; all periodic.
template <int D>
Configuration<D> lattice(const std::vector<Vec<D>>& basis, const Vec<D>& cell,
                         const std::array<int, D>& cells, double radius,
                         const std::vector<std::uint32_t>& species = {}) {
  Configuration<D> c;
  for (int a = 0; a < D; ++a) {
    c.box[a] = cell[a] * cells[a];
    c.periodic[a] = true;
  }
  std::array<int, D> i{};
  while (true) {
    for (std::size_t b = 0; b < basis.size(); ++b) {
      Vec<D> x;
      for (int a = 0; a < D; ++a) x[a] = (i[a] + basis[b][a]) * cell[a];
      c.position.push_back(x);
      c.species.push_back(species.empty() ? 0 : species[b]);
      c.radius.push_back(radius);
    }
    int a = 0;
    while (a < D && ++i[a] == cells[a]) i[a++] = 0;
    if (a == D) break;
  }
  return c;
}

TEST(StreamingBlocks, EqualsBlockAverageOfTheWholeSeries) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> gauss(5.0, 0.3);
  for (const double a : {0.0, 0.8, 0.98}) {
    for (const std::size_t n : {1, 2, 7, 8, 100, 1023, 4096, 20000}) {
      std::vector<double> x(n);
      double v = 0.0;
      for (double& s : x) s = 5.0 + (v = a * v + gauss(rng) - 5.0);  // AR(1)
      StreamingBlocks s;
      for (const double value : x) s.add(value);
      const BlockAverage want = block_average(x), got = s.result();
      SCOPED_TRACE(::testing::Message() << "a = " << a << ", n = " << n);
      EXPECT_EQ(got.samples, want.samples);
      EXPECT_EQ(got.levels, want.levels);
      EXPECT_EQ(got.level, want.level);
      EXPECT_EQ(got.blocks, want.blocks);
      EXPECT_EQ(got.reliable, want.reliable);
      EXPECT_NEAR(got.mean, want.mean, 1e-12);
      EXPECT_NEAR(got.stderr_, want.stderr_, 1e-12 + 1e-9 * want.stderr_);
      EXPECT_NEAR(got.correlation_time, want.correlation_time, 1e-9 * want.correlation_time);
    }
  }
  // A constant series: exact mean, reliable.
  StreamingBlocks constant;
  for (int k = 0; k < 50; ++k) constant.add(2.5);
  EXPECT_TRUE(constant.result().reliable);
  EXPECT_EQ(constant.result().mean, 2.5);
}

TEST(Structure, SpeciesPairsAreNumberedOnce) {
  for (std::size_t s = 1; s <= 4; ++s) {
    std::set<std::size_t> seen;
    for (std::size_t a = 0; a < s; ++a)
      for (std::size_t b = a; b < s; ++b) {
        EXPECT_EQ(species_pair_index(a, b, s), species_pair_index(b, a, s));
        seen.insert(species_pair_index(a, b, s));
      }
    EXPECT_EQ(seen.size(), species_pairs(s));
    EXPECT_EQ(*seen.rbegin(), species_pairs(s) - 1);
  }
}

// The tests' reference: r_i - r_j by the minimum image along periodic axes.
template <int D>
Vec<D> separation(const Configuration<D>& c, std::uint32_t i, std::uint32_t j) {
  Vec<D> r;
  for (int a = 0; a < D; ++a) {
    r[a] = c.position[i][a] - c.position[j][a];
    if (c.periodic[a]) r[a] -= c.box[a] * std::round(r[a] / c.box[a]);
  }
  return r;
}

// Every pair i < j with within(i, j, r²), by brute force.
template <int D, class Within>
std::set<std::pair<std::uint32_t, std::uint32_t>> brute_force_pairs(const Configuration<D>& c,
                                                                    Within within) {
  std::set<std::pair<std::uint32_t, std::uint32_t>> pairs;
  for (std::uint32_t i = 0; i < c.size(); ++i)
    for (std::uint32_t j = i + 1; j < c.size(); ++j)
      if (within(i, j, norm2(separation(c, i, j)))) pairs.insert({i, j});
  return pairs;
}

template <int D>
void check_pairs(const Configuration<D>& c, double cutoff) {
  std::set<std::pair<std::uint32_t, std::uint32_t>> found;
  for_each_pair_within(
      c, cutoff, [&](std::uint32_t i, std::uint32_t j, const Vec<D>& r, double r2) {
        EXPECT_TRUE(found.insert({std::min(i, j), std::max(i, j)}).second) << "pair twice";
        EXPECT_NEAR(norm2(r), r2, 1e-12);
      });
  const auto want = brute_force_pairs(
      c, [&](std::uint32_t, std::uint32_t, double r2) { return r2 < cutoff * cutoff; });
  EXPECT_EQ(found, want);
  EXPECT_FALSE(want.empty());
}

TEST(Structure, PairSearchFindsEveryPairOnceAsBruteForce) {
  std::mt19937_64 rng(11);
  // Cells 1, 2 and 3 wide along periodic axes, bounded axes, particles beyond a bounded edge.
  for (const double cutoff : {1.0, 2.5, 3.3, 5.0}) {
    check_pairs<3>(ideal_gas<3>(300, {10.0, 7.0, 12.0}, {true, true, true}, rng), cutoff * 0.7);
    auto open = ideal_gas<3>(300, {10.0, 10.0, 10.0}, {true, false, false}, rng);
    for (std::size_t i = 0; i < 20; ++i) open.position[i][2] += 12.0;  // above an open top
    check_pairs<3>(open, cutoff);
    check_pairs<2>(ideal_gas<2>(300, {11.0, 10.0}, {true, false}, rng), cutoff);
  }
  EXPECT_THROW(check_pairs<3>(ideal_gas<3>(10, {4.0, 4.0, 4.0}, {true, true, true}, rng), 2.5),
               std::invalid_argument);
}

// The size-aware search: every pair closer than factor (R_i + R_j) once, over size
// distributions of several classes (and points of radius 0), against brute force; with one
// class, exactly the calls of for_each_pair_within at 2 factor R_max, in its order.
template <int D>
void check_pairs_near_contact(Configuration<D> c, double factor, double decades,
                              std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (std::size_t i = 0; i < c.size(); ++i)
    c.radius[i] = i % 17 == 3 ? 0.0 : 0.5 * std::pow(10.0, -decades * u(rng));
  std::set<std::pair<std::uint32_t, std::uint32_t>> found;
  for_each_pair_near_contact(
      c, factor, [&](std::uint32_t i, std::uint32_t j, const Vec<D>& r, double r2) {
        EXPECT_TRUE(found.insert({std::min(i, j), std::max(i, j)}).second) << "pair twice";
        EXPECT_NEAR(norm2(r), r2, 1e-12);
        EXPECT_LT(norm2(separation(c, i, j) - r), 1e-20);  // r is r_i - r_j
      });
  const auto want = brute_force_pairs(c, [&](std::uint32_t i, std::uint32_t j, double r2) {
    const double cut = factor * (c.radius[i] + c.radius[j]);
    return r2 < cut * cut;
  });
  // The points (radius 0) make several classes: exactly the pairs within reach.
  EXPECT_EQ(found, want);
  EXPECT_FALSE(want.empty());
}

TEST(Structure, SizeAwarePairSearchFindsEveryPairNearContactOnce) {
  std::mt19937_64 rng(12);
  for (const double decades : {0.2, 1.0, 2.5}) {
    SCOPED_TRACE(decades);
    check_pairs_near_contact<3>(ideal_gas<3>(1500, {10.0, 7.0, 12.0}, {true, true, true}, rng), 1.3,
                                decades, rng);
    auto open = ideal_gas<3>(1500, {10.0, 10.0, 10.0}, {true, false, false}, rng);
    for (std::size_t i = 0; i < 40; ++i) open.position[i][2] += 3.0;  // above an open top
    check_pairs_near_contact<3>(open, 2.0, decades, rng);
    check_pairs_near_contact<2>(ideal_gas<2>(1500, {11.0, 10.0}, {true, false}, rng), 1.5, decades,
                                rng);
    check_pairs_near_contact<2>(ideal_gas<2>(800, {2.2, 30.0}, {true, true}, rng), 1.1, decades,
                                rng);
  }
  // Sizes within a factor 2: the plain search's calls, in its order.
  auto c = ideal_gas<3>(500, {8.0, 8.0, 8.0}, {true, true, true}, rng);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (double& r : c.radius) r = 0.3 + 0.29 * u(rng);
  std::vector<std::pair<std::uint32_t, std::uint32_t>> plain, aware;
  for_each_pair_within(
      c, 2.0 * 1.2 * *std::max_element(c.radius.begin(), c.radius.end()),
      [&](std::uint32_t i, std::uint32_t j, const Vec<3>&, double) { plain.emplace_back(i, j); });
  for_each_pair_near_contact(c, 1.2, [&](std::uint32_t i, std::uint32_t j, const Vec<3>&, double) {
    aware.emplace_back(i, j);
  });
  EXPECT_EQ(aware, plain);
  EXPECT_FALSE(plain.empty());
}

// g(r) of uniform random points is 1 in every bin within its error (Poisson, 1/sqrt(expected
// pairs), in a periodic box), and in boxes with bounded axes, where the box's pair fraction
// makes it so: without it the largest distances fall ~r/(2L) short, 20 % at r = 4 in a box 9
// wide.
template <int D>
void check_ideal_gas(const Vec<D>& box, const std::array<bool, D>& periodic, std::size_t species,
                     unsigned seed) {
  std::mt19937_64 rng(seed);
  const std::size_t n = D == 3 ? 1500 : 1200;
  const double max_distance = 4.0;
  const int bins = 20;
  std::vector<std::size_t> counts(species, 0);
  for (std::size_t i = 0; i < n; ++i) ++counts[i % species];
  PairCorrelation<D> g(box, periodic, counts, max_distance, bins,
                       std::vector<double>(species_pairs(species), 1.0));
  const int samples = 40;
  for (int s = 0; s < samples; ++s) g.sample(ideal_gas<D>(n, box, periodic, rng, species));
  double volume = 1.0;
  bool bounded = false;
  for (int a = 0; a < D; ++a) {
    volume *= box[a];
    bounded = bounded || !periodic[a];
  }
  double chi2 = 0.0;
  int points = 0;
  for (std::size_t p = 0; p < species_pairs(species); ++p) {
    for (int k = 0; k < bins; ++k) {
      const double r0 = k * g.bin_width(), r1 = r0 + g.bin_width();
      const double shell = D == 3 ? 4.0 / 3.0 * kPi * (std::pow(r1, 3) - std::pow(r0, 3))
                                  : kPi * (r1 * r1 - r0 * r0);
      // Expected pairs of this species pair in the bin over all samples.
      const double na = static_cast<double>(n) / static_cast<double>(species);
      const double pairs =
          species == 1 ? 0.5 * na * (na - 1.0) : (p == 1 ? na * na : 0.5 * na * (na - 1.0));
      const double expected =
          samples * pairs * shell * box_pair_fraction<D>(box, periodic, r0, r1) / volume;
      if (expected < 20.0) continue;
      const BlockAverage v = g.g(p, k);
      // Periodic: pair counts are Poisson. Bounded: pairs that share a particle near a wall
      // are correlated (its shell is cut by the wall), so the spread over the (independent)
      // samples is the error.
      const double sigma = bounded ? v.stderr_ : 1.0 / std::sqrt(expected);
      EXPECT_NEAR(v.mean, 1.0, 5.0 * sigma) << "pair " << p << " bin " << k;
      chi2 += (v.mean - 1.0) * (v.mean - 1.0) / (sigma * sigma);
      ++points;
    }
  }
  ASSERT_GT(points, 10);
  EXPECT_LT(chi2 / points, 1.6);  // ~1 for an unbiased estimate; a biased one grows with N
  // The blocked error agrees with the Poisson one (independent samples).
  const BlockAverage last = g.g(0, bins - 1);
  EXPECT_GT(last.stderr_, 0.0);
}

TEST(PairCorrelation, IdealGasIsOneInAPeriodicBox) {
  check_ideal_gas<3>({12.0, 12.0, 12.0}, {true, true, true}, 1, 1);
  check_ideal_gas<2>({30.0, 30.0}, {true, true}, 1, 2);
}

TEST(PairCorrelation, IdealGasIsOneWithWallsOrOpenFaces) {
  check_ideal_gas<3>({12.0, 12.0, 9.0}, {true, true, false}, 1, 3);
  check_ideal_gas<3>({10.0, 12.0, 9.0}, {false, false, false}, 1, 4);
  check_ideal_gas<2>({30.0, 20.0}, {false, false}, 1, 5);
}

TEST(PairCorrelation, IdealBinaryMixtureIsOneForEveryPair) {
  check_ideal_gas<3>({12.0, 12.0, 12.0}, {true, true, true}, 2, 6);
}

TEST(PairCorrelation, BoxPairFractionIsTheCovarianceOfTheBox) {
  // A bounded axis of length L: 1 - r <|n_x|> / L for a thin shell (<|n_x|> = 1/2 in 3D,
  // 2/π in 2D); periodic axes do not count.
  EXPECT_NEAR((box_pair_fraction<3>({10.0, 10.0, 10.0}, {true, true, false}, 2.0, 2.0 + 1e-6)),
              1.0 - 2.0 * 0.5 / 10.0, 1e-6);
  EXPECT_NEAR((box_pair_fraction<2>({10.0, 10.0}, {false, true}, 2.0, 2.0 + 1e-6)),
              1.0 - 2.0 * 2.0 / kPi / 10.0, 1e-6);
  EXPECT_DOUBLE_EQ((box_pair_fraction<3>({10.0, 10.0, 10.0}, {true, true, true}, 1.0, 3.0)), 1.0);
  // Fully bounded unit-free check by Monte Carlo: pairs of uniform points in a 2 x 3 box.
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double r0 = 0.5, r1 = 0.7;
  double inside = 0.0;
  const int trials = 2000000;
  for (int t = 0; t < trials; ++t) {
    const double dx = 2.0 * (u(rng) - u(rng)), dy = 3.0 * (u(rng) - u(rng));
    const double r = std::hypot(dx, dy);
    inside += r >= r0 && r < r1 ? 1.0 : 0.0;
  }
  const double ideal = kPi * (r1 * r1 - r0 * r0) / 6.0;  // unbounded: shell / area
  const double want = inside / trials / ideal;
  EXPECT_NEAR((box_pair_fraction<2>({2.0, 3.0}, {false, false}, r0, r1)), want,
              4.0 * std::sqrt(want / (trials * ideal)));
}

// Fluorite (CaF2, 1:2): each Ca has 8 F at √3 a/4 and 12 Ca at a/√2, each F 4 Ca and 6 F at
// a/2. The coordination number n_ab = ρ_b ∫ g_ab 4π r² dr over the first peak checks the
// normalisation of unlike (N_a N_b) and like (N_a (N_a - 1) / 2) pairs with unequal counts;
// for like pairs ρ_a is (N_a - 1) / V, the partners a particle can have.
TEST(PairCorrelation, SpeciesPairsOfABinaryLatticeHaveTheirCoordinationNumbers) {
  const double a = 2.0;
  std::vector<Vec<3>> basis = {{0, 0, 0}, {0, 0.5, 0.5}, {0.5, 0, 0.5}, {0.5, 0.5, 0}};
  std::vector<std::uint32_t> species(4, 0);
  for (const double x : {0.25, 0.75})
    for (const double y : {0.25, 0.75})
      for (const double z : {0.25, 0.75}) {
        basis.push_back({x, y, z});
        species.push_back(1);
      }
  const Configuration<3> c = lattice<3>(basis, {a, a, a}, {4, 4, 4}, 0.2, species);
  const std::vector<std::size_t> counts = {256, 512};
  const double max_distance = 1.6;
  const int bins = 160;
  PairCorrelation<3> g(c.box, c.periodic, counts, max_distance, bins, {0.4, 0.4, 0.4});
  g.sample(c);
  const double volume = c.volume();
  const auto coordination = [&](std::size_t pair, double density, double r_low, double r_high) {
    double n = 0.0;
    for (int k = 0; k < bins; ++k) {
      const double r0 = k * g.bin_width(), r1 = r0 + g.bin_width();
      if (r1 <= r_low || r0 >= r_high) continue;
      n += density * g.g(pair, k).mean * 4.0 / 3.0 * kPi * (r1 * r1 * r1 - r0 * r0 * r0);
    }
    return n;
  };
  const double rho_ca = 256.0 / volume, rho_f = 512.0 / volume;
  const double others_ca = 255.0 / volume, others_f = 511.0 / volume;
  const std::size_t ca_ca = species_pair_index(0, 0, 2), ca_f = species_pair_index(0, 1, 2),
                    f_f = species_pair_index(1, 1, 2);
  // Peaks at √3 a/4 = 0.866, a/2 = 1, a/√2 = 1.414.
  EXPECT_NEAR(coordination(ca_f, rho_f, 0.8, 0.95), 8.0, 1e-9);
  EXPECT_NEAR(coordination(ca_f, rho_ca, 0.8, 0.95), 4.0, 1e-9);
  EXPECT_NEAR(coordination(f_f, others_f, 0.95, 1.05), 6.0, 1e-9);
  EXPECT_NEAR(coordination(ca_ca, others_ca, 1.35, 1.45), 12.0, 1e-9);
  EXPECT_NEAR(coordination(ca_ca, others_ca, 0.0, 1.35), 0.0, 1e-12);
}

TEST(PairCorrelation, ContactWeightsReproduceCubicsExactly) {
  // The bins' r^(D-1)-weighted averages of a cubic in x = r/σ - 1 give back its value at 0.
  const auto weights = PairCorrelation<3>::contact_weights();
  const double w = PairCorrelation<3>::kContactWindow;
  const int bins = PairCorrelation<3>::kContactBins;
  const auto bin_average = [&](auto&& g, int k) {
    double num = 0.0, den = 0.0;
    const int steps = 2000;
    for (int s = 0; s < steps; ++s) {
      const double x = w * (k + (s + 0.5) / steps) / bins;
      num += g(x) * (1 + x) * (1 + x);
      den += (1 + x) * (1 + x);
    }
    return num / den;
  };
  const auto cubic = [](double x) { return 2.0 - 3.0 * x + 5.0 * x * x - 40.0 * x * x * x; };
  double value = 0.0;
  for (int k = 0; k < bins; ++k) value += weights[k] * bin_average(cubic, k);
  EXPECT_NEAR(value, 2.0, 1e-7);
  // An exponential decay as steep as hard spheres' at η = 0.45: the stated bias.
  for (const double alpha : {3.0, 8.0}) {
    const auto decay = [&](double x) { return std::exp(-alpha * x); };
    double g0 = 0.0;
    for (int k = 0; k < bins; ++k) g0 += weights[k] * bin_average(decay, k);
    EXPECT_NEAR(g0, 1.0, 2e-4) << alpha;
    EXPECT_GT(std::abs(g0 - 1.0), 1e-8);  // a fit, not exact
  }
}

TEST(PairCorrelation, IdealGasContactValueAndItsContactTheorem) {
  // Points that ignore their "contact": g(σ⁺) = 1 and Z = 1 + (2π/3) ρ σ³ (the formula only).
  std::mt19937_64 rng(12);
  const Vec<3> box{14.0, 14.0, 14.0};
  PairCorrelation<3> g(box, {true, true, true}, {2000}, 3.0, 30, {1.2});
  for (int s = 0; s < 40; ++s) g.sample(ideal_gas<3>(2000, box, {true, true, true}, rng));
  const BlockAverage g0 = g.contact(0), z = g.contact_compressibility();
  EXPECT_NEAR(g0.mean, 1.0, 4.0 * g0.stderr_);
  EXPECT_LT(g0.stderr_, 0.05);
  const double rho = 2000.0 / (14.0 * 14.0 * 14.0);
  const double prefactor = 2.0 * kPi / 3.0 * rho * 1.2 * 1.2 * 1.2;
  EXPECT_NEAR(z.mean, 1.0 + prefactor * g0.mean, 1e-9);
  EXPECT_NEAR(z.stderr_, prefactor * g0.stderr_, 1e-9);
  EXPECT_GT(g.overlapping(), 0u);  // ideal points overlap
}

// ----- S(k)

TEST(StructureFactor, PerfectLatticesHaveBraggPeaksOfNAndNothingElsewhere) {
  // Simple cubic, 6 cells: k = 2π n / L is a reciprocal lattice vector when every n_a is a
  // multiple of 6.
  const Configuration<3> sc = lattice<3>({{0, 0, 0}}, {1.3, 1.3, 1.3}, {6, 6, 6}, 0.5);
  EXPECT_NEAR((StructureFactor<3>::at(sc, {6, 0, 0})), 216.0, 1e-9);
  EXPECT_NEAR((StructureFactor<3>::at(sc, {6, -12, 6})), 216.0, 1e-9);
  EXPECT_NEAR((StructureFactor<3>::at(sc, {1, 0, 0})), 0.0, 1e-20);
  EXPECT_NEAR((StructureFactor<3>::at(sc, {3, 2, 5})), 0.0, 1e-20);
  // fcc in its conventional cell, 4 cells: (h k l) = n / 4 reflects when all even or all odd.
  const Configuration<3> fcc = lattice<3>({{0, 0, 0}, {0, 0.5, 0.5}, {0.5, 0, 0.5}, {0.5, 0.5, 0}},
                                          {1.5, 1.5, 1.5}, {4, 4, 4}, 0.5);
  EXPECT_NEAR((StructureFactor<3>::at(fcc, {4, 4, 4})), 256.0, 1e-9);  // (111)
  EXPECT_NEAR((StructureFactor<3>::at(fcc, {8, 0, 0})), 256.0, 1e-9);  // (200)
  EXPECT_NEAR((StructureFactor<3>::at(fcc, {4, 0, 0})), 0.0, 1e-18);   // (100): extinct
  EXPECT_NEAR((StructureFactor<3>::at(fcc, {4, 4, 0})), 0.0, 1e-18);   // (110): extinct
  // The shell averages by the phase tables: the (111) shell of fcc holds 4 of the half space's
  // vectors of |n|² = 48, and nothing below it scatters.
  StructureFactor<3> s(fcc.box, 2.0 * kPi * std::sqrt(48.0) / fcc.box[0] * 1.001, 0.0);
  s.sample(fcc);
  const auto shells = s.shells();
  ASSERT_FALSE(shells.empty());
  for (const auto& shell : shells) {
    if (shell.k * fcc.box[0] / (2.0 * kPi) < 6.6) {
      EXPECT_NEAR(shell.s.mean, 0.0, 1e-18) << shell.k;
    } else {
      // Its shell also holds |n|² = 44 (6 2 2 permutations: mixed parity), extinct.
      EXPECT_GT(shell.s.mean, 1.0);
      EXPECT_NEAR(shell.s.mean * static_cast<double>(shell.vectors), 4 * 256.0, 1e-6);
    }
  }
  // 2D: a square lattice.
  const Configuration<2> sq = lattice<2>({{0, 0}}, {1.0, 1.0}, {10, 10}, 0.5);
  EXPECT_NEAR((StructureFactor<2>::at(sq, {10, 20})), 100.0, 1e-9);
  EXPECT_NEAR((StructureFactor<2>::at(sq, {1, 3})), 0.0, 1e-20);
}

TEST(StructureFactor, ShellAveragesMatchSingleVectorsAndIdealGasIsOne) {
  std::mt19937_64 rng(21);
  const Vec<3> box{9.0, 9.0, 20.0};
  const Configuration<3> c = ideal_gas<3>(500, box, {true, true, true}, rng);
  StructureFactor<3> s(box, 4.0, 1.5);
  s.sample(c);
  // The smallest |k| (2π / 20, along z) is a shell of its own: one vector of the half space.
  const auto shells = s.shells();
  ASSERT_GE(shells.size(), 4u);
  EXPECT_NEAR(shells[0].k, 2.0 * kPi / 20.0, 1e-12);
  EXPECT_EQ(shells[0].vectors, 1u);
  EXPECT_NEAR(shells[0].s.mean, (StructureFactor<3>::at(c, {0, 0, 1})), 1e-9);
  EXPECT_GE(s.fit_shells(), 4u);
  // Averaged over shells and samples, an ideal gas has S = 1.
  for (int k = 0; k < 30; ++k) s.sample(ideal_gas<3>(500, box, {true, true, true}, rng));
  double sum = 0.0, vectors = 0.0;
  for (const auto& shell : s.shells()) {
    sum += shell.s.mean * static_cast<double>(shell.vectors);
    vectors += static_cast<double>(shell.vectors);
    EXPECT_LE(shell.vectors, StructureFactor<3>::kMaxVectorsPerShell);
  }
  EXPECT_NEAR(sum / vectors, 1.0, 4.0 / std::sqrt(31.0 * vectors));
  EXPECT_NEAR(s.s_zero().mean, 1.0, 4.0 * s.s_zero().stderr_ + 0.05);
}

// ----- bond order

TEST(BondOrder, SphericalHarmonicsMatchClosedForms) {
  const Vec<3> n{0.48, -0.6, 0.64};  // unit
  const double theta = std::acos(n[2]), phi = std::atan2(n[1], n[0]);
  const auto y2 = spherical_harmonics(2, n);
  EXPECT_NEAR(y2[0].real(), std::sqrt(5.0 / (16.0 * kPi)) * (3.0 * n[2] * n[2] - 1.0), 1e-14);
  const std::complex<double> y21 = -std::sqrt(15.0 / (8.0 * kPi)) * std::sin(theta) *
                                   std::cos(theta) * std::exp(std::complex<double>(0.0, phi));
  EXPECT_NEAR(std::abs(y2[1] - y21), 0.0, 1e-14);
  const auto y4 = spherical_harmonics(4, n);
  const std::complex<double> y44 = 3.0 / 16.0 * std::sqrt(35.0 / (2.0 * kPi)) *
                                   std::pow(std::sin(theta), 4) *
                                   std::exp(std::complex<double>(0.0, 4.0 * phi));
  EXPECT_NEAR(std::abs(y4[4] - y44), 0.0, 1e-14);
  // The addition theorem: Σ_m |Y_lm|² = (2l + 1) / 4π.
  for (const int l : {4, 6, 8}) {
    const auto y = spherical_harmonics(l, n);
    double sum = std::norm(y[0]);
    for (std::size_t m = 1; m < y.size(); ++m) sum += 2.0 * std::norm(y[m]);
    EXPECT_NEAR(sum, (2.0 * l + 1.0) / (4.0 * kPi), 1e-13) << l;
  }
}

// Steinhardt, Nelson & Ronchetti (1983), Table I (fcc, hcp, bcc with its 14 neighbours of the
// first two shells); the same five digits in Lechner & Dellago, J. Chem. Phys. 129, 114707
// (2008), Table I.
void expect_every_particle(const BondOrderValues<3>& v, double q4, double q6) {
  for (std::size_t i = 0; i < v.local[0].size(); ++i) {
    ASSERT_NEAR(v.local[0][i], q4, 5e-6) << i;
    ASSERT_NEAR(v.local[1][i], q6, 5e-6) << i;
  }
  EXPECT_NEAR(v.global[0], q4, 5e-6);  // a perfect crystal: every particle alike
  EXPECT_NEAR(v.global[1], q6, 5e-6);
  EXPECT_EQ(v.isolated, 0u);
}

TEST(BondOrder, SteinhardtValuesOfFccBccHcp) {
  // fcc: nearest neighbours at a/√2, radius half of that; 12 neighbours within 1.2 contacts.
  const double a = 1.6;
  const Configuration<3> fcc = lattice<3>({{0, 0, 0}, {0, 0.5, 0.5}, {0.5, 0, 0.5}, {0.5, 0.5, 0}},
                                          {a, a, a}, {4, 4, 4}, 0.5 * a / std::sqrt(2.0));
  const BondOrderValues<3> f = bond_order<3>(fcc, 1.2);
  EXPECT_EQ(f.bonds, fcc.size() * 12 / 2);
  expect_every_particle(f, 0.19094, 0.57452);
  // bcc: 8 at √3 a/2 and 6 at a (1.155 contacts), the next at 1.633 contacts.
  const Configuration<3> bcc =
      lattice<3>({{0, 0, 0}, {0.5, 0.5, 0.5}}, {a, a, a}, {5, 5, 5}, 0.25 * std::sqrt(3.0) * a);
  const BondOrderValues<3> b = bond_order<3>(bcc, 1.3);
  EXPECT_EQ(b.bonds, bcc.size() * 14 / 2);
  expect_every_particle(b, 0.03637, 0.51069);
  // hcp with the ideal c/a = √(8/3), in an orthorhombic cell of 4 particles.
  const double s = 1.0;  // nearest-neighbour distance
  const double c_over_a = std::sqrt(8.0 / 3.0);
  const Configuration<3> hcp =
      lattice<3>({{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 1.0 / 6.0, 0.5}, {0, 2.0 / 3.0, 0.5}},
                 {s, s * std::sqrt(3.0), s * c_over_a}, {6, 4, 4}, 0.5 * s);
  const BondOrderValues<3> h = bond_order<3>(hcp, 1.2);
  EXPECT_EQ(h.bonds, hcp.size() * 12 / 2);
  expect_every_particle(h, 0.09722, 0.48476);
}

TEST(BondOrder, Psi6IsOneOnTheHexagonalLatticeAndZeroOnTheSquareOne) {
  // Hexagonal: a rectangular cell of 2 particles, 1 x √3.
  const Configuration<2> hex =
      lattice<2>({{0, 0}, {0.5, 0.5}}, {1.0, std::sqrt(3.0)}, {10, 6}, 0.5);
  const BondOrderValues<2> h = bond_order<2>(hex, 1.2);
  EXPECT_EQ(h.bonds, hex.size() * 6 / 2);
  for (const double v : h.local[0]) ASSERT_NEAR(v, 1.0, 1e-12);
  EXPECT_NEAR(h.global[0], 1.0, 1e-12);
  // Square: 4 neighbours at 90° (1.2 contacts), or 8 with the diagonals (1.5): ψ6 = 0 both.
  const Configuration<2> square = lattice<2>({{0, 0}}, {1.0, 1.0}, {12, 12}, 0.5);
  for (const double cutoff : {1.2, 1.5}) {
    const BondOrderValues<2> q = bond_order<2>(square, cutoff);
    EXPECT_EQ(q.bonds, square.size() * (cutoff < 1.4 ? 4 : 8) / 2);
    for (const double v : q.local[0]) ASSERT_NEAR(v, 0.0, 1e-12);
    EXPECT_NEAR(q.global[0], 0.0, 1e-12);
  }
}

TEST(BondOrder, AccumulatorAveragesAndHistogramsTheLocalValues) {
  std::mt19937_64 rng(5);
  BondOrder<3> order(1.4);
  const Vec<3> box{10.0, 10.0, 10.0};
  for (int s = 0; s < 10; ++s) order.sample(ideal_gas<3>(1000, box, {true, true, true}, rng));
  ASSERT_EQ(order.names(), (std::vector<std::string>{"q4", "q6"}));
  // Random directions: the global Q6 falls as 1 / sqrt(bonds); local q6 of a handful of random
  // neighbours is large (~ 1 / sqrt(N_b)), and the density integrates to 1.
  EXPECT_LT(order.global(1).mean, 0.05);
  EXPECT_GT(order.local_mean(1).mean, 0.2);
  double integral = 0.0;
  for (int k = 0; k < BondOrder<3>::kBins; ++k)
    integral += order.density(1, k) / BondOrder<3>::kBins;
  EXPECT_NEAR(integral, 1.0, 1e-12);
  // 1.4 contacts (σ = 1): (4π/3) 1.4³ ρ neighbours.
  EXPECT_NEAR(order.mean_neighbours(), 4.0 / 3.0 * kPi * std::pow(1.4, 3) * 1.0, 0.25);
}

// ----- velocity distribution

TEST(VelocityDistribution, MaxwellianMomentsAndALaplaceDistribution) {
  std::mt19937_64 rng(8);
  std::normal_distribution<double> gauss(0.0, 1.0);
  VelocityDistribution<3> maxwell;
  for (int s = 0; s < 20; ++s) {
    maxwell.begin(2.0);  // kT = 2, m = 0.5: w = c sqrt(m / kT) = c / 2
    for (int i = 0; i < 5000; ++i)
      maxwell.add({2.0 * gauss(rng), 2.0 * gauss(rng), 2.0 * gauss(rng)}, 0.5);
    maxwell.end();
  }
  EXPECT_NEAR(maxwell.kurtosis().mean, 3.0, 5.0 * maxwell.kurtosis().stderr_);
  EXPECT_NEAR(maxwell.sonine_a2().mean, 0.0, 5.0 * maxwell.sonine_a2().stderr_);
  EXPECT_NEAR(maxwell.tail_ratio().mean, 1.0, 5.0 * maxwell.tail_ratio().stderr_);
  EXPECT_LT(maxwell.kurtosis().stderr_, 0.02);
  double integral = 0.0, model = 0.0;
  for (int k = 0; k < VelocityDistribution<3>::kBins; ++k) {
    const double width = maxwell.bin_low(k + 1) - maxwell.bin_low(k);
    integral += maxwell.density(k).mean * width;
    model += maxwell.maxwellian(k) * width;
    const double p = maxwell.maxwellian(k);
    EXPECT_NEAR(maxwell.density(k).mean, p, 5.0 * std::sqrt(p / (300000.0 * width)) + 1e-12);
  }
  EXPECT_NEAR(integral, 1.0, 1e-12);
  EXPECT_NEAR(model, 1.0, 1e-12);
  // Components drawn from a Laplace distribution: kurtosis 6, a2 = (6 - 3) / (D + 2).
  std::exponential_distribution<double> exponential(1.0);
  std::bernoulli_distribution sign(0.5);
  const auto laplace = [&] { return (sign(rng) ? 1.0 : -1.0) * exponential(rng); };
  VelocityDistribution<2> heavy;
  for (int s = 0; s < 20; ++s) {
    heavy.begin(2.0);
    for (int i = 0; i < 20000; ++i) heavy.add({laplace(), laplace()}, 1.0);
    heavy.end();
  }
  EXPECT_NEAR(heavy.kurtosis().mean, 6.0, 0.15);
  EXPECT_NEAR(heavy.sonine_a2().mean, 3.0 / 4.0, 0.04);
  EXPECT_GT(heavy.tail_ratio().mean, 2.0);  // exp(-|w| sqrt 2) tails above the Maxwellian's
}

}  // namespace
}  // namespace kairos
