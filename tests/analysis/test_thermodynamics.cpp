#include <gtest/gtest.h>

#include <cmath>

#include "analysis/thermodynamics.hpp"

namespace kairos {
namespace {

TEST(Thermodynamics, DefinitionsWithHandComputedNumbers) {
  // 3D, N = 101, V = 1000: kT = 2K / (3 * 100).
  Thermodynamics th(3, 101, 1000.0);
  EXPECT_DOUBLE_EQ(th.temperature(150.0), 1.0);
  // Z = 1 + W / (D N kT t) = 1 + 606 / (3 * 101 * 1 * 2) = 2.
  EXPECT_DOUBLE_EQ(th.compressibility(606.0, 1.0, 2.0), 2.0);
  EXPECT_DOUBLE_EQ(th.pressure(2.0, 1.0), 2.0 * 101.0 / 1000.0);
  // Mean free time N t / (2 N_coll): 101 * 2 / 202 = 0.5.
  EXPECT_DOUBLE_EQ(th.mean_free_time(2.0, 202), 0.5);
  EXPECT_DOUBLE_EQ(th.per_particle(202), 4.0);
  EXPECT_TRUE(std::isnan(th.compressibility(1.0, 1.0, 0.0)));
  EXPECT_TRUE(std::isnan(th.mean_free_time(1.0, 0)));
}

TEST(Thermodynamics, RowsCoverTheIntervalSinceTheLastOne) {
  Thermodynamics th(2, 11, 100.0);  // kT = 2K / (2 * 10) = K / 10
  th.mark({1.0, 10.0, 5, 2});
  const ThermoRow r = th.row({3.0, 10.0 + 88.0, 25, 13}, 10.0, true);
  // Interval: dt = 2, dW = 88, dN_coll = 11; Z = 1 + 88 / (2 * 11 * 1 * 2) = 3.
  EXPECT_DOUBLE_EQ(r.temperature, 1.0);
  EXPECT_DOUBLE_EQ(r.compressibility, 3.0);
  EXPECT_DOUBLE_EQ(r.mean_free_time, 11.0 * 2.0 / 22.0);
  EXPECT_DOUBLE_EQ(r.collisions_per_particle, 26.0 / 11.0);
  EXPECT_EQ(th.last().collisions, 13u);
  // Only production rows feed the block averages.
  th.row({4.0, 98.0 + 44.0, 30, 24}, 10.0, false);
  EXPECT_EQ(th.compressibility_blocks().samples, 1u);
  EXPECT_DOUBLE_EQ(th.compressibility_blocks().mean, 3.0);
}

}  // namespace
}  // namespace kairos
