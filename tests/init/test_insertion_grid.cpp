// The insertion grid's size classes (init/insertion_grid.hpp): a search around a point visits
// every inserted particle whose sphere may touch the given one, each once, over size
// distributions of one class and of several, in boxes of few and many cells per axis.
#include "init/insertion_grid.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>
#include <vector>

namespace kairos {
namespace {

template <int D>
void check_searches(std::mt19937_64& rng, const std::array<double, D>& box, std::size_t n,
                    double decades) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<std::array<double, D>> pos(n);
  std::vector<double> diameter(n);
  for (std::size_t i = 0; i < n; ++i) {
    for (int a = 0; a < D; ++a) pos[i][a] = unit(rng) * box[a];
    diameter[i] = std::pow(10.0, -decades * unit(rng));
  }
  InsertionGrid<D> grid(box, diameter);
  // Half inserted: a search sees only those.
  for (std::size_t i = 0; i < n; i += 2) grid.insert(static_cast<std::uint32_t>(i), pos[i]);
  for (int q = 0; q < 200; ++q) {
    std::array<double, D> x;
    for (int a = 0; a < D; ++a) x[a] = unit(rng) * box[a];
    const double d = std::pow(10.0, -decades * unit(rng)) * (q % 5 == 0 ? 3.0 : 1.0);
    std::multiset<std::uint32_t> seen;
    grid.for_each_near(x, d, [&](std::uint32_t j) {
      seen.insert(j);
      return false;
    });
    for (std::size_t j = 0; j < n; ++j) {
      double r2 = 0.0;
      for (int a = 0; a < D; ++a) {
        const double s = minimum_image(x[a] - pos[j][a], box[a]);
        r2 += s * s;
      }
      const double contact = 0.5 * (d + diameter[j]);
      const std::size_t visits = seen.count(static_cast<std::uint32_t>(j));
      ASSERT_LE(visits, 1u) << "particle " << j << " visited twice";
      if (j % 2 == 1) {
        ASSERT_EQ(visits, 0u) << "particle " << j << " was never inserted";
      } else if (r2 < contact * contact) {
        ASSERT_EQ(visits, 1u) << "particle " << j << " touches the sphere at " << x[0];
      }
    }
  }
}

TEST(InsertionGrid, SearchesFindEveryTouchingParticleOnce) {
  std::mt19937_64 rng(5);
  for (const double decades : {0.2, 1.0, 2.0}) {
    SCOPED_TRACE(decades);
    check_searches<3>(rng, {8.0, 6.0, 7.0}, 2000, decades);
    check_searches<3>(rng, {1.5, 9.0, 3.0}, 500, decades);  // one or two cells along an axis
    check_searches<2>(rng, {30.0, 20.0}, 3000, decades);
    check_searches<2>(rng, {2.5, 40.0}, 800, decades);
  }
}

// Inserted early or late, a search stops when asked to.
TEST(InsertionGrid, ASearchStopsWhenAsked) {
  InsertionGrid<2> grid({10.0, 10.0}, std::vector<double>{1.0, 1.0, 8.0});
  grid.insert(0, {5.0, 5.0});
  grid.insert(1, {5.5, 5.0});
  grid.insert(2, {1.0, 1.0});
  int calls = 0;
  EXPECT_TRUE(grid.for_each_near({5.2, 5.0}, 1.0, [&](std::uint32_t) { return ++calls == 1; }));
  EXPECT_EQ(calls, 1);
  calls = 0;
  EXPECT_FALSE(grid.for_each_near({5.2, 5.0}, 1.0, [&](std::uint32_t) { return ++calls > 5; }));
  EXPECT_EQ(calls, 3);  // the big one's grid is one cell wide along each axis
}

}  // namespace
}  // namespace kairos
