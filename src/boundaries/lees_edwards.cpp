#include "boundaries/lees_edwards.hpp"

#include <algorithm>
#include <cmath>

namespace kairos {

template <int D>
LeesEdwards<D>::LeesEdwards(double shear_rate, const Vec<D>& box, const CellGrid<D>& grid, double t)
    : box_(box), cell_width_(grid.width(0)), cells_x_(grid.cells_along(0)) {
  if (shear_rate == 0.0) return;
  speed_ = shear_rate * box_[1];
  step_ = step_at(t);
  next_shift_ = shift_time(step_);
}

template <int D>
double LeesEdwards<D>::image_offset(double t) const {
  const std::int64_t nx = cells_x_;
  const std::int64_t wraps = floor_div(step_, nx);
  return speed_ * t - static_cast<double>(wraps) * box_[0];
}

// When the image offset, now `step` cell widths (rounded down), reaches the next step.
template <int D>
double LeesEdwards<D>::shift_time(std::int64_t step) const {
  const double edge = static_cast<double>(speed_ > 0 ? step + 1 : step);
  return edge * cell_width_ / speed_;
}

// The image step at time t: every shift due at or before t has happened (as in a run that
// reached t), so a resumed run continues with the same step.
template <int D>
std::int64_t LeesEdwards<D>::step_at(double t) const {
  auto step = static_cast<std::int64_t>(std::floor(speed_ * t / cell_width_));
  const std::int64_t back = speed_ > 0 ? -1 : 1;
  while (shift_time(step) <= t) step = next_step(step);
  while (shift_time(step + back) > t) step += back;
  return step;
}

template <int D>
double LeesEdwards<D>::shift() {
  const double t = next_shift_;
  step_ = next_step(step_);
  next_shift_ = shift_time(step_);
  return t;
}

template <int D>
Vec<D> LeesEdwards<D>::separation(Vec<D> r, double t, const std::array<bool, D>& periodic,
                                  Vec<D>& image_velocity) const {
  image_velocity = Vec<D>{};
  const int side = r[1] > 0.5 * box_[1] ? 1 : (r[1] < -0.5 * box_[1] ? -1 : 0);
  r[1] -= side * box_[1];
  r[0] -= side * image_offset(t);
  image_velocity[0] = side * speed_;
  for (int a = 0; a < D; ++a)
    if (a != 1 && periodic[a]) r[a] = minimum_image(r[a], box_[a]);
  return r;
}

template <int D>
int LeesEdwards<D>::cross_face(Vec<D>& position, Vec<D>& velocity, int side, double t,
                               const CellGrid<D>& grid) const {
  position[0] = wrap_into_box(position[0] - side * image_offset(t), box_[0]);
  velocity[0] -= side * speed_;
  return std::clamp(static_cast<int>(std::floor(position[0] / grid.width(0))), 0,
                    grid.cells_along(0) - 1);
}

template <int D>
std::string LeesEdwards<D>::check(double t) const {
  if (!on()) return "";
  if (!(next_shift_ >= t)) return "an image shift is overdue";
  const std::int64_t k = step_ - floor_div(step_, cells_x_) * cells_x_;
  const double offset = image_offset(t), tol = 1e-9 * box_[0];
  if (offset < static_cast<double>(k) * cell_width_ - tol ||
      offset > static_cast<double>(k + 1) * cell_width_ + tol)
    return "the image offset is not in the cell its step says";
  return "";
}

template class LeesEdwards<2>;
template class LeesEdwards<3>;

}  // namespace kairos
