#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "init/initial_state.hpp"

namespace kairos {
namespace {

TEST(InitSortSpatially, IsAPermutationInRowMajorCellOrder) {
  SystemConfig sys;
  sys.dimension = 3;
  sys.particles = 500;
  sys.packing_fraction = 0.2;
  sys.lattice = "random";
  sys.species = {{"A", 1.0, 1.0, 0.5}, {"B", 1.4, 2.0, 0.5}};
  std::mt19937_64 rng(3);
  const InitialState<3> s = make_initial_state<3>(sys, rng);
  // Row-major order of cells 1.4 wide: the key never decreases along the particle index.
  auto key = [&](std::size_t i) {
    double k = 0;
    for (int a = 2; a >= 0; --a) {
      const double along = std::floor(s.box[a] / 1.4);
      k = k * along + std::min(std::floor(s.position[i][a] / 1.4), along - 1);
    }
    return k;
  };
  for (std::size_t i = 1; i < s.position.size(); ++i) EXPECT_LE(key(i - 1), key(i));
  // Species, diameters and masses moved with their particles.
  std::size_t big = 0;
  for (std::size_t i = 0; i < s.position.size(); ++i) {
    const bool is_big = s.species[i] == 1;
    big += is_big;
    EXPECT_DOUBLE_EQ(s.diameter[i], is_big ? 1.4 : 1.0);
    EXPECT_DOUBLE_EQ(s.mass[i], is_big ? 2.0 : 1.0);
  }
  EXPECT_EQ(big, 250u);
  EXPECT_EQ(max_overlap_bruteforce<3>(s.box, s.position, s.diameter), 0.0);
}

}  // namespace
}  // namespace kairos
