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

#include "core/cell_rings.hpp"
#include "core/periodic.hpp"
#include "core/size_classes.hpp"
#include "init/initial_state.hpp"

namespace kairos {

template <int D>
double box_volume(const std::array<double, D>& box) {
  double v = 1.0;
  for (int k = 0; k < D; ++k) v *= box[k];
  return v;
}

// One periodic grid of cells per size class (core/size_classes.hpp), each at least as wide as
// its class's largest diameter along every axis (at least one cell per axis), with its number
// of cells capped near twice its members by widening the cells. Particles are kept in per-cell
// linked lists. A search around a point visits, in each class's grid, the cells that may hold
// a particle touching a sphere of the given diameter there: the 3^D cells around it when the
// diameters are within a factor 2 of each other (one class), more rings of the finer grids
// for a large sphere among small ones. Each cell is visited at most once per search.
template <int D>
class InsertionGrid {
 public:
  // `diameters` of every particle that may be inserted, by index.
  InsertionGrid(const std::array<double, D>& box, const std::vector<double>& diameters)
      : box_(box), classes_(size_classes(diameters)) {
    for (std::size_t k = 0; k < classes_.count(); ++k) grids_.push_back(make_grid(k));
    next_.assign(diameters.size(), kNoParticle);
  }

  void insert(std::uint32_t particle, const std::array<double, D>& x) {
    Grid& g = grids_[classes_.of[particle]];
    const std::size_t cell = g.index(g.coords(x, box_));
    next_[particle] = g.head[cell];
    g.head[cell] = particle;
  }

  // Calls f(particle) for every particle inserted so far that may touch a sphere of `diameter`
  // at x (a superset: callers measure the distance), until f returns true. Returns whether f
  // stopped the iteration.
  template <class F>
  [[gnu::always_inline]] bool for_each_near(const std::array<double, D>& x, double diameter,
                                            F&& f) const {
    for (std::size_t k = 0; k < grids_.size(); ++k) {
      const Grid& g = grids_[k];
      const std::array<std::size_t, D> c = g.coords(x, box_);
      const double reach = 0.5 * (diameter + classes_.largest[k]);
      // One ring exactly when a cell is as wide as the reach (the class's width is at most
      // the cells' own along every axis).
      const double r = reach <= g.width || !std::isfinite(reach) ? 1.0 : std::ceil(reach / g.width);
      std::array<std::size_t, D> rings{};
      rings.fill(static_cast<std::size_t>(std::min(r, static_cast<double>(g.head.size()))));
      const bool stopped =
          for_each_cell_in_rings<D>(c, rings, g.n, kAllPeriodic, [&](std::size_t cell) {
            for (std::uint32_t p = g.head[cell]; p != kNoParticle; p = next_[p]) {
              if (f(p)) return true;
            }
            return false;
          });
      if (stopped) return true;
    }
    return false;
  }

 private:
  struct Grid {
    double width = 0.0;  // at most a cell's width along every axis
    std::array<std::size_t, D> n{};
    std::vector<std::uint32_t> head;

    std::array<std::size_t, D> coords(const std::array<double, D>& x,
                                      const std::array<double, D>& box) const {
      std::array<std::size_t, D> c{};
      for (int k = 0; k < D; ++k) {
        const double u = wrap_into_box(x[k], box[k]) / box[k] * static_cast<double>(n[k]);
        c[k] = std::min(static_cast<std::size_t>(u), n[k] - 1);
      }
      return c;
    }
    std::size_t index(const std::array<std::size_t, D>& c) const {
      std::size_t idx = 0;
      for (int k = D - 1; k >= 0; --k) idx = idx * n[k] + c[k];
      return idx;
    }
  };

  Grid make_grid(std::size_t k) const {
    const std::size_t max_cells = std::max<std::size_t>(64, 2 * classes_.members[k]);
    double width = classes_.largest[k];
    double total = 1.0;
    for (int a = 0; a < D; ++a) total *= std::max(1.0, std::floor(box_[a] / width));
    if (total > static_cast<double>(max_cells)) {
      width = std::max(width, std::pow(box_volume<D>(box_) / static_cast<double>(max_cells),
                                       1.0 / static_cast<double>(D)));
    }
    Grid g;
    g.width = width;
    std::size_t cells = 1;
    for (int a = 0; a < D; ++a) {
      const double na =
          std::min(std::max(1.0, std::floor(box_[a] / width)), static_cast<double>(max_cells));
      g.n[a] = static_cast<std::size_t>(na);
      cells *= g.n[a];
    }
    g.head.assign(cells, kNoParticle);
    return g;
  }

  static constexpr std::array<bool, D> kAllPeriodic = [] {
    std::array<bool, D> all{};
    all.fill(true);
    return all;
  }();

  std::array<double, D> box_;
  SizeClasses classes_;
  std::vector<Grid> grids_;
  std::vector<std::uint32_t> next_;
};

}  // namespace kairos
