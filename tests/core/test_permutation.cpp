#include "core/permutation.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>
#include <vector>

using kairos::permute_in_place;

// In place, the result is the gathered copy values'[k] = values[order[k]], for permutations of
// every cycle structure (identity, one long cycle, random), and entries past order.size() stay.
TEST(Permutation, InPlaceEqualsTheGatheredCopy) {
  std::mt19937_64 rng(5);
  std::vector<bool> done;
  for (std::uint32_t n : {0u, 1u, 2u, 7u, 1000u, 65537u}) {
    std::vector<std::vector<std::uint32_t>> orders;
    std::vector<std::uint32_t> order(n);
    std::iota(order.begin(), order.end(), 0u);
    orders.push_back(order);  // identity
    if (n > 0) {
      std::vector<std::uint32_t> cycle(n);
      for (std::uint32_t k = 0; k < n; ++k) cycle[k] = (k + 1) % n;
      orders.push_back(cycle);
    }
    std::shuffle(order.begin(), order.end(), rng);
    orders.push_back(order);
    for (const auto& o : orders) {
      std::vector<double> values(n + 1);
      for (std::uint32_t k = 0; k <= n; ++k) values[k] = 0.25 * k * k + 1.0;
      std::vector<double> expected(values);
      for (std::uint32_t k = 0; k < n; ++k) expected[k] = values[o[k]];
      permute_in_place(values, o, done);
      EXPECT_EQ(values, expected) << "n = " << n;
    }
  }
}
