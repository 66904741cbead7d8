// Lees-Edwards images as a boundary component (boundaries/lees_edwards.hpp): the image offset and
// its steps, the image a pair meets, a particle crossing a sheared face, and the window of cells
// beyond a face.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <map>
#include <set>
#include <string>
#include <tuple>
#include <utility>

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

TEST(LeesEdwards, ChecksItsOwnStep) {
  const Vec<3> box{8.0, 6.0, 4.0};
  const CellGrid<3> grid(box, Vec<3>{1.0, 1.0, 1.0}, {true, true, true}, 1000);
  LeesEdwards<3> le(0.1, box, grid, 0.0);
  EXPECT_EQ(le.check(0.0), "");
  EXPECT_EQ(le.check(le.next_shift_time()), "");
  EXPECT_NE(le.check(le.next_shift_time() + 1e-6), "");  // a shift overdue
  le.shift();
  EXPECT_EQ(le.check(le.next_shift_time() - 1e-9), "");
}

// A step ahead of the time is caught too: the offset then sits a cell behind its step.
TEST(LeesEdwards, CheckCatchesAStepAheadOfTheTime) {
  const CellGrid<3> grid = grid_of(kBox);
  LeesEdwards<3> le(0.1, kBox, grid, 0.0);
  const double first = le.shift();  // the shift due at `first`, made at time 0
  EXPECT_NE(le.check(0.0), "");
  EXPECT_NE(le.check(0.5 * first), "");
  EXPECT_EQ(le.check(first), "");
  EXPECT_EQ(le.check(1.5 * first), "");
  EXPECT_EQ(LeesEdwards<3>(0.0, kBox, grid, 0.0).check(1e9), "");  // no shear: nothing to check
}

// Sheared the other way (images above moving to -x), the offset falls by a cell width per
// shift, at the same times as with the opposite rate, and stays consistent with its step.
TEST(LeesEdwards, NegativeShearShiftsTheOtherWay) {
  const CellGrid<3> grid = grid_of(kBox);
  LeesEdwards<3> down(-0.1, kBox, grid, 0.0), up(0.1, kBox, grid, 0.0);
  ASSERT_TRUE(down.on());
  EXPECT_DOUBLE_EQ(down.image_speed(), -0.1 * kBox[1]);
  const double w = grid.width(0), speed = 0.1 * kBox[1];
  EXPECT_NEAR(down.next_shift_time(), w / speed, 1e-12);
  double before = 0.0;
  for (int k = 1; k <= 2 * grid.cells_along(0) + 3; ++k) {
    const double middle = 0.5 * (before + down.next_shift_time());
    EXPECT_EQ(down.check(middle), "") << k;
    const double t = down.shift();
    EXPECT_NEAR(t, up.shift(), 1e-12) << k;
    EXPECT_NEAR(t, k * w / speed, 1e-12) << k;
    EXPECT_EQ(down.check(t), "") << k;
    const double offset = down.image_offset(t);
    EXPECT_GE(offset, -1e-12);
    EXPECT_LE(offset, kBox[0] + 1e-12);
    EXPECT_NEAR(std::remainder(offset + speed * t, kBox[0]), 0.0, 1e-12) << k;
    before = t;
  }
}

// Through the low face the image is the one below: y - L_y, x - Delta, moving at -U. Leaving
// through the top and coming back through the bottom at the same moment returns the particle.
TEST(LeesEdwards, TheLowFaceIsTheMirrorOfTheTopOne) {
  const CellGrid<3> grid = grid_of(kBox);
  const LeesEdwards<3> le(0.1, kBox, grid, 0.0);
  const double t = 1.75;
  const double offset = le.image_offset(t);
  // i near the bottom, j near the top: j's image below the box is at y - L_y, x - offset.
  const Vec<3> xi{2.0, 0.1, 1.0}, xj{1.5, 5.8, 1.0};
  Vec<3> u;
  const Vec<3> r = le.separation(xi - xj, t, {true, true, true}, u);
  EXPECT_NEAR(r[1], 0.1 - (5.8 - 6.0), 1e-14);
  EXPECT_NEAR(r[0], 2.0 - (1.5 - offset), 1e-14);
  EXPECT_DOUBLE_EQ(u[0], -le.image_speed());
  EXPECT_EQ(u[1], 0.0);
  // A pair not across a y face: the plain minimum image, no extra velocity.
  const Vec<3> near = le.separation(Vec<3>{7.5, 1.0, -3.5}, t, {true, true, true}, u);
  EXPECT_NEAR(near[0], -0.5, 1e-14);
  EXPECT_NEAR(near[1], 1.0, 1e-14);
  EXPECT_NEAR(near[2], 0.5, 1e-14);
  EXPECT_EQ(u[0], 0.0);
  // Up through the top face and straight back down through the bottom one.
  const Vec<3> x0{0.3, 0.0, 2.0}, v0{0.25, 0.5, -0.125};
  Vec<3> x = x0, v = v0;
  le.cross_face(x, v, +1, t, grid);
  const int column = le.cross_face(x, v, -1, t, grid);
  EXPECT_NEAR(x[0], x0[0], 1e-12);
  EXPECT_NEAR(v[0], v0[0], 1e-14);
  EXPECT_EQ(x[1], x0[1]);  // only x and v_x change
  EXPECT_EQ(v[1], v0[1]);
  EXPECT_EQ(column, 0);
  // Down through the bottom: x gains the offset (wrapped), v_x gains U.
  Vec<3> low{7.9, 6.0 - 1e-3, 1.0}, vlow{0.2, -0.3, 0.0};
  le.cross_face(low, vlow, -1, t, grid);
  EXPECT_NEAR(low[0], std::fmod(7.9 + offset, 8.0), 1e-12);
  EXPECT_NEAR(vlow[0], 0.2 + le.image_speed(), 1e-14);
}

// The window beyond a y face holds every cell whose sliding image comes within a cell of the
// particle's column: by brute force over all columns and wraps, at several times (steps and
// fractions of a step), for both faces, columns at the x faces included.
TEST(LeesEdwards, TheWindowBeyondAFaceHoldsEveryImageInReach) {
  const CellGrid<3> grid = grid_of(kBox);
  const int nx = grid.cells_along(0), ny = grid.cells_along(1);
  const double w = grid.width(0), L = kBox[0];
  for (const double rate : {0.1, -0.1}) {
    const double speed = std::abs(rate) * kBox[1];
    for (const double cells_moved : {0.0, 0.25, 0.5, 1.0, 2.75, 7.5, 11.25}) {
      const double t = cells_moved * w / speed;
      const LeesEdwards<3> le(rate, kBox, grid, t);
      ASSERT_EQ(le.check(t), "") << t;
      const double offset = le.image_offset(t);
      for (const int y : {0, ny - 1}) {
        const int side = y == 0 ? -1 : 1;  // the face the window lies beyond
        for (const int c : {0, 1, 3, nx - 1}) {
          const CellCode cell = grid.code_at({c, y, 1});
          // Beyond the face, in the particle's own z layer: column -> x shift of its image.
          std::map<int, std::set<double>> window;
          int beyond = 0;
          le.for_each_neighbour_cell(
              cell, grid, t, [&](const std::array<int, 3>& at, const Vec<3>& s, const Vec<3>& vs) {
                if (s[1] == 0.0) return;
                ++beyond;
                EXPECT_EQ(s[1], side * kBox[1]);
                EXPECT_EQ(vs[0], side * le.image_speed());
                if (at[2] == 1) window[at[0]].insert(s[0]);
              });
          EXPECT_EQ(beyond, 4 * 3);
          for (int m = 0; m < nx; ++m) {
            for (int wraps = -2; wraps <= 2; ++wraps) {
              const double shift = side * offset + wraps * L;
              const double lo = m * w + shift, hi = lo + w;
              if (!(lo < (c + 2) * w - 1e-9 && hi > (c - 1) * w + 1e-9)) continue;
              bool found = false;
              if (window.count(m) != 0)
                for (const double s : window[m]) found = found || std::abs(s - shift) < 1e-9;
              EXPECT_TRUE(found) << "rate " << rate << " t " << t << " face " << side << " column "
                                 << c << " misses column " << m << " shifted " << shift;
            }
          }
        }
      }
    }
  }
}

// Walls along z: the window stops at them (no cell beyond, no z shift).
TEST(LeesEdwards, TheWindowStopsAtWallsAlongZ) {
  const CellGrid<3> grid(kBox, Vec<3>{1.0, 1.0, 1.0}, {true, true, false}, 1000);
  const LeesEdwards<3> le(0.1, kBox, grid, 0.0);
  const CellCode corner = grid.code_at({0, grid.cells_along(1) - 1, 0});
  int inside = 0, beyond = 0;
  le.for_each_neighbour_cell(corner, grid, 0.5,
                             [&](const std::array<int, 3>& at, const Vec<3>& s, const Vec<3>&) {
                               EXPECT_GE(at[2], 0);
                               EXPECT_LE(at[2], 1);
                               EXPECT_EQ(s[2], 0.0);
                               (s[1] != 0.0 ? beyond : inside) += 1;
                             });
  EXPECT_EQ(inside, 2 * 3 * 2);  // its own row and the inner one, 3 columns, 2 layers along z
  EXPECT_EQ(beyond, 4 * 2);
}

}  // namespace
}  // namespace kairos
