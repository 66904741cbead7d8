// Lees-Edwards images as a boundary component (boundaries/lees_edwards.hpp): the image offset and
// its steps, the image a pair meets, a particle crossing a sheared face, and the window of cells
// beyond a face.
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <tuple>

#include "boundaries/lees_edwards.hpp"

namespace kairos {
namespace {

const Vec<3> kBox{8.0, 6.0, 4.0};

CellGrid<3> grid_of(const Vec<3>& box) {
  return CellGrid<3>(box, Vec<3>{1.0, 1.0, 1.0}, {true, true, true}, 1000);
}

TEST(LeesEdwards, NoShearIsNoBoundary) {
  const LeesEdwards<3> none(0.0, kBox, grid_of(kBox), 0.0);
  EXPECT_FALSE(none.on());
  EXPECT_EQ(none.next_shift_time(), kNever);
}

TEST(LeesEdwards, TheOffsetAdvancesOneCellWidthPerShift) {
  const CellGrid<3> grid = grid_of(kBox);
  LeesEdwards<3> le(0.1, kBox, grid, 0.0);
  ASSERT_TRUE(le.on());
  EXPECT_DOUBLE_EQ(le.image_speed(), 0.1 * kBox[1]);
  const double w = grid.width(0);
  // Each shift comes when the offset U t has grown by one more cell width; the offset stays
  // within the box (wrapped by whole box lengths).
  for (int k = 1; k <= 3 * grid.cells_along(0); ++k) {
    const double t = le.shift();
    EXPECT_NEAR(t, k * w / le.image_speed(), 1e-12);
    const double offset = le.image_offset(t);
    EXPECT_GE(offset, -1e-12);
    EXPECT_LE(offset, kBox[0] + 1e-12);
    EXPECT_NEAR(std::remainder(offset - le.image_speed() * t, kBox[0]), 0.0, 1e-12);
  }
  // A component made at a later time continues with the same step (restarts).
  const double t = 2.5 * w / le.image_speed();
  LeesEdwards<3> fresh(0.1, kBox, grid, t);
  LeesEdwards<3> stepped(0.1, kBox, grid, 0.0);
  while (stepped.next_shift_time() <= t) stepped.shift();
  EXPECT_EQ(fresh.next_shift_time(), stepped.next_shift_time());
  EXPECT_EQ(fresh.image_offset(t), stepped.image_offset(t));
}

TEST(LeesEdwards, APairAcrossTheFaceMeetsTheShiftedImage) {
  const CellGrid<3> grid = grid_of(kBox);
  const LeesEdwards<3> le(0.1, kBox, grid, 0.0);
  const double t = 1.0;  // offset 0.6
  // i near the top, j near the bottom: j's image above the box is at y + L_y, x + offset.
  const Vec<3> xi{2.0, 5.8, 1.0}, xj{1.5, 0.1, 1.0};
  Vec<3> u;
  const Vec<3> r = le.separation(xi - xj, t, {true, true, true}, u);
  EXPECT_NEAR(r[1], 5.8 - (0.1 + 6.0), 1e-14);
  EXPECT_NEAR(r[0], 2.0 - (1.5 + le.image_offset(t)), 1e-14);
  EXPECT_DOUBLE_EQ(u[0], le.image_speed());
}

TEST(LeesEdwards, CrossingTheTopFaceGivesTheImagesPositionAndVelocity) {
  const CellGrid<3> grid = grid_of(kBox);
  const LeesEdwards<3> le(0.1, kBox, grid, 0.0);
  const double t = 1.0;
  Vec<3> x{7.9, 0.0, 1.0}, v{0.2, 0.3, 0.0};  // left through y+ and wrapped to y = 0
  const int column = le.cross_face(x, v, +1, t, grid);
  EXPECT_NEAR(x[0], std::fmod(7.9 - le.image_offset(t) + 8.0, 8.0), 1e-14);
  EXPECT_NEAR(v[0], 0.2 - le.image_speed(), 1e-15);
  EXPECT_EQ(column, static_cast<int>(std::floor(x[0] / grid.width(0))));
}

TEST(LeesEdwards, TheWindowBeyondAFaceIsFourColumnsWide) {
  const CellGrid<3> grid = grid_of(kBox);
  const LeesEdwards<3> le(0.1, kBox, grid, 0.0);
  const CellCode top = grid.code_at({3, grid.cells_along(1) - 1, 2});
  ASSERT_TRUE(le.next_to_face(top, grid));
  EXPECT_FALSE(le.next_to_face(grid.code_at({3, 2, 2}), grid));
  int inside = 0, beyond = 0;
  std::set<std::tuple<int, int, int>> cells;
  le.for_each_neighbour_cell(top, grid, 0.5,
                             [&](const std::array<int, 3>& at, const Vec<3>& shift, const Vec<3>&) {
                               (shift[1] != 0.0 ? beyond : inside) += 1;
                               cells.insert({at[0], at[1], at[2]});
                             });
  EXPECT_EQ(inside, 2 * 3 * 3);  // its own row and the inner one, 3 x 3 each
  EXPECT_EQ(beyond, 4 * 3);      // the row beyond the face: 4 columns, 3 along z
  EXPECT_EQ(cells.size(), static_cast<std::size_t>(inside + beyond));
}

}  // namespace
}  // namespace kairos
