// Lees–Edwards sliding-brick boundaries for simple shear (Lees and Edwards, J. Phys. C 5, 1921
// (1972)), as a boundary component of the event engine: flow along x, gradient along y.
//
// The periodic images above the box (y + L_y) sit displaced along x by the image offset
// Delta(t) = shear_rate L_y t (wrapped into the box) and move at U = shear_rate L_y; those below
// by the opposite. A particle leaving through a y face comes back as its image: x and v_x jump
// by the offset and U. Pairs across a y face are searched in the row of cells beyond the face,
// 4 cells wide in x around where the image of the particle's own column sits now; that window
// holds while the offset moves by less than a cell width, so each time it has moved one cell
// width on (an image shift, `step()` counts them, unwrapped) the particles next to the y faces
// are predicted again by the engine. The step follows from the time, so restarts need nothing.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <string>

#include "core/periodic.hpp"
#include "core/vec.hpp"
#include "dynamics/collision_time.hpp"
#include "scheduler/cell_grid.hpp"

namespace kairos {

template <int D>
class LeesEdwards {
 public:
  LeesEdwards() = default;
  // Shear at `shear_rate` (0: none) in a box of edges `box` cut into `grid`'s cells, at time t.
  LeesEdwards(double shear_rate, const Vec<D>& box, const CellGrid<D>& grid, double t);

  bool on() const { return speed_ != 0.0; }
  // U: the velocity (along x) of the images above the box relative to the box.
  double image_speed() const { return speed_; }
  // Delta(t), consistent with the present step: in [k w, (k + 1) w] up to round-off, where k
  // is the step modulo the cells along x and w their width.
  double image_offset(double t) const;
  // When the images move on by the next cell width (kNever without shear).
  double next_shift_time() const { return next_shift_; }
  // The images moved on by a cell width: returns the time of that shift.
  double shift();
  // Whether a cell lies in the first or last row along y (its neighbourhood crosses a y face).
  bool next_to_face(CellCode c, const CellGrid<D>& grid) const {
    const int y = grid.coordinate(c, 1);
    return y == 0 || y == grid.cells_along(1) - 1;
  }

  // The neighbourhood of a cell next to a y face at time t: its own row and the inner one as
  // usual, the row beyond the face through the sliding images. Calls
  // add_cell(cell coordinates, position shift, velocity shift) for each cell, in a fixed order.
  template <class AddCell>
  void for_each_neighbour_cell(CellCode cell, const CellGrid<D>& grid, double t,
                               AddCell&& add_cell) const;

  // The separation of i from the image of j it meets, from their raw separation r = x_i - x_j
  // (positions in the box) at time t, and that image's extra velocity. Pairs in contact are
  // closer than a third of the box along y, so the image is unambiguous.
  Vec<D> separation(Vec<D> r, double t, const std::array<bool, D>& periodic,
                    Vec<D>& image_velocity) const;

  // The images' own consistency at time t (no shift is overdue, and the offset sits in the
  // cell its step says): "" if so, else what is wrong.
  std::string check(double t) const;

  // A particle leaves through the high (side +1) or low (-1) y face at time t, its y already
  // wrapped: its x and v_x become its image's. Returns its new column along x.
  int cross_face(Vec<D>& position, Vec<D>& velocity, int side, double t,
                 const CellGrid<D>& grid) const;

 private:
  double shift_time(std::int64_t step) const;
  std::int64_t next_step(std::int64_t step) const { return step + (speed_ > 0 ? 1 : -1); }
  std::int64_t step_at(double t) const;

  Vec<D> box_{};
  double cell_width_ = 0.0;  // along x
  int cells_x_ = 0;
  double speed_ = 0.0;     // shear_rate * L_y
  std::int64_t step_ = 0;  // image offset in cell widths, rounded down (unwrapped)
  double next_shift_ = kNever;
};

// a / b rounded down (b > 0), for negative a too.
constexpr std::int64_t floor_div(std::int64_t a, std::int64_t b) {
  return a >= 0 ? a / b : -((-a + b - 1) / b);
}

template <int D>
template <class AddCell>
void LeesEdwards<D>::for_each_neighbour_cell(CellCode cell, const CellGrid<D>& grid, double t,
                                             AddCell&& add_cell) const {
  const int nx = grid.cells_along(0), ny = grid.cells_along(1);
  std::array<int, D> c;
  for (int a = 0; a < D; ++a) c[a] = grid.coordinate(cell, a);
  const std::int64_t k = step_ - floor_div(step_, nx) * nx;
  const double offset = image_offset(t);
  for (int dy = -1; dy <= 1; ++dy) {
    std::array<int, D> at = c;
    Vec<D> shift{}, vshift{};
    at[1] = c[1] + dy;
    const int side = at[1] < 0 ? -1 : (at[1] >= ny ? 1 : 0);
    at[1] -= side * ny;
    shift[1] = side * box_[1];
    vshift[0] = side * speed_;
    // Columns m (unwrapped) whose members, moved by the image offset, can reach column c[0].
    const int first =
        side == 0 ? c[0] - 1
                  : (side > 0 ? c[0] - static_cast<int>(k) - 2 : c[0] + static_cast<int>(k) - 1);
    const int columns = side == 0 ? 3 : 4;
    for (int q = 0; q < columns; ++q) {
      const int m = first + q;
      const int wraps = static_cast<int>(floor_div(m, nx));
      at[0] = m - wraps * nx;
      shift[0] = side * offset + wraps * box_[0];
      if constexpr (D == 3) {
        for (int dz = -1; dz <= 1; ++dz) {
          at[2] = c[2] + dz;
          Vec<D> s = shift;
          if (at[2] < 0 || at[2] >= grid.cells_along(2)) {
            if (!grid.periodic(2)) continue;  // beyond a wall or open face: nothing there
            const int wz = at[2] < 0 ? -1 : 1;
            at[2] -= wz * grid.cells_along(2);
            s[2] = wz * box_[2];
          }
          add_cell(at, s, vshift);
        }
      } else {
        add_cell(at, shift, vshift);
      }
    }
  }
}

}  // namespace kairos
