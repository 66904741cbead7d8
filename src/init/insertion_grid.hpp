// The cell grid of random insertion and overlap checks at set-up (init/initial_state.cpp,
// run/start_state.cpp's system.fill_inside): particles in per-cell linked lists, the cells
// adjacent to a point visited with periodic wrapping (callers on a bounded axis measure their
// distances without the minimum image; the wrapped cells only add candidates). Not the
// engine's grid (scheduler/cell_grid.hpp), which keeps moving particles.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/periodic.hpp"
#include "init/initial_state.hpp"

namespace kairos {

template <int D>
double box_volume(const std::array<double, D>& box) {
  double v = 1.0;
  for (int k = 0; k < D; ++k) v *= box[k];
  return v;
}

// A periodic grid of cells at least `min_width` wide along every axis (at least one cell per
// axis), with the total number of cells capped near `max_cells` by widening the cells.
// Particles are kept in per-cell linked lists.
template <int D>
class InsertionGrid {
 public:
  InsertionGrid(const std::array<double, D>& box, double min_width, std::size_t particles)
      : box_(box) {
    const std::size_t max_cells = std::max<std::size_t>(64, 2 * particles);
    double width = min_width;
    double total = 1.0;
    for (int k = 0; k < D; ++k) total *= std::max(1.0, std::floor(box[k] / width));
    if (total > static_cast<double>(max_cells)) {
      width = std::max(width, std::pow(box_volume<D>(box) / static_cast<double>(max_cells),
                                       1.0 / static_cast<double>(D)));
    }
    std::size_t cells = 1;
    for (int k = 0; k < D; ++k) {
      const double nk =
          std::min(std::max(1.0, std::floor(box[k] / width)), static_cast<double>(max_cells));
      n_[k] = static_cast<std::size_t>(nk);
      cells *= n_[k];
    }
    head_.assign(cells, kNoParticle);
    next_.assign(particles, kNoParticle);
  }

  std::array<std::size_t, D> coords(const std::array<double, D>& x) const {
    std::array<std::size_t, D> c{};
    for (int k = 0; k < D; ++k) {
      const double u = wrap_into_box(x[k], box_[k]) / box_[k] * static_cast<double>(n_[k]);
      c[k] = std::min(static_cast<std::size_t>(u), n_[k] - 1);
    }
    return c;
  }

  std::size_t index(const std::array<std::size_t, D>& c) const {
    std::size_t idx = 0;
    for (int k = D - 1; k >= 0; --k) idx = idx * n_[k] + c[k];
    return idx;
  }

  void insert(std::uint32_t particle, const std::array<double, D>& x) {
    const std::size_t cell = index(coords(x));
    next_[particle] = head_[cell];
    head_[cell] = particle;
  }

  // Calls f(particle) for every particle in the cells adjacent to (and including) the cell at
  // `c`, until f returns true. Along an axis with fewer than 3 cells every cell is visited
  // exactly once. Returns whether f stopped the iteration.
  template <class F>
  bool for_each_neighbour(const std::array<std::size_t, D>& c, F&& f) const {
    std::array<std::array<std::size_t, 3>, D> axis{};
    std::array<std::size_t, D> count{};
    for (int k = 0; k < D; ++k) {
      if (n_[k] >= 3) {
        axis[k] = {(c[k] + n_[k] - 1) % n_[k], c[k], (c[k] + 1) % n_[k]};
        count[k] = 3;
      } else {
        for (std::size_t m = 0; m < n_[k]; ++m) axis[k][m] = m;
        count[k] = n_[k];
      }
    }
    std::array<std::size_t, D> pick{};
    while (true) {
      std::array<std::size_t, D> cell{};
      for (int k = 0; k < D; ++k) cell[k] = axis[k][pick[k]];
      for (std::uint32_t p = head_[index(cell)]; p != kNoParticle; p = next_[p]) {
        if (f(p)) return true;
      }
      int k = 0;
      while (k < D && ++pick[k] == count[k]) pick[k++] = 0;
      if (k == D) return false;
    }
  }

 private:
  std::array<double, D> box_;
  std::array<std::size_t, D> n_{};
  std::vector<std::uint32_t> head_;
  std::vector<std::uint32_t> next_;
};

}  // namespace kairos
