// The cells within rings of a cell (core/cell_rings.hpp): each once, exactly those whose
// distance along every axis (wrapped on periodic axes) is at most the rings, in index order
// of axis 0 fastest when nothing wraps; a stop ends the walk.
#include "core/cell_rings.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <vector>

namespace kairos {
namespace {

TEST(CellRings, EveryCellWithinTheRingsOnce) {
  const std::array<std::size_t, 3> n = {5, 2, 7};
  for (const std::array<bool, 3> periodic :
       {std::array<bool, 3>{true, true, true}, std::array<bool, 3>{true, false, false}}) {
    for (std::size_t r = 0; r <= 4; ++r) {
      for (std::size_t c0 = 0; c0 < n[0]; ++c0) {
        const std::array<std::size_t, 3> c = {c0, 1, 6 - c0};
        std::vector<int> seen(n[0] * n[1] * n[2], 0);
        for_each_cell_in_rings<3>(c, {r, r, r}, n, periodic, [&](std::size_t i) {
          ++seen[i];
          return false;
        });
        for (std::size_t i = 0; i < seen.size(); ++i) {
          const std::array<std::size_t, 3> at = {i % n[0], (i / n[0]) % n[1], i / (n[0] * n[1])};
          bool within = true;
          for (int a = 0; a < 3; ++a) {
            long d = std::labs(static_cast<long>(at[a]) - static_cast<long>(c[a]));
            if (periodic[a]) d = std::min<long>(d, static_cast<long>(n[a]) - d);
            within = within && d <= static_cast<long>(r);
          }
          ASSERT_EQ(seen[i], within ? 1 : 0) << "cell " << i << ", rings " << r;
        }
      }
    }
  }
}

TEST(CellRings, InOrderAndStoppable) {
  std::vector<std::size_t> order;
  EXPECT_FALSE(
      for_each_cell_in_rings<2>({2, 2}, {1, 1}, {6, 6}, {false, false}, [&](std::size_t i) {
        order.push_back(i);
        return false;
      }));
  EXPECT_EQ(order, (std::vector<std::size_t>{7, 8, 9, 13, 14, 15, 19, 20, 21}));
  int calls = 0;
  EXPECT_TRUE(for_each_cell_in_rings<2>({0, 0}, {1, 1}, {6, 6}, {true, true},
                                        [&](std::size_t) { return ++calls == 4; }));
  EXPECT_EQ(calls, 4);
}

}  // namespace
}  // namespace kairos
