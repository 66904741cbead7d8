// The plan of two cell levels for a wide size distribution (EngineOptions::size_levels;
// engine/cell_neighbourhood.hpp): which radii are small, the fine grid sized for them, the
// coarse cells (whole groups of fine cells) and a big particle's reach, and whether they pay
// against one level. The particles' own flags and a resumed state's cells are the engine's part.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

#include "core/vec.hpp"
#include "dynamics/collision_time.hpp"
#include "engine/cell_neighbourhood.hpp"
#include "scheduler/cell_grid.hpp"

namespace kairos {

template <int D>
struct SizeLevelPlan {
  CellGrid<D> fine;
  typename CellNeighbourhood<D>::Levels levels;  // without the per-particle flags
};

// Two levels for particles of `radii` (any order) in a periodic box, cells `room` times wider
// than the contacts they hold, or nullopt where they do not apply or (unless `force`) do not
// pay against `one_level`, the grid one level would use.
template <int D>
std::optional<SizeLevelPlan<D>> plan_cell_levels(std::vector<double> radii, const Vec<D>& box,
                                                 const CellGrid<D>& one_level, double room,
                                                 double cells_per_particle, bool force) {
  const auto n = static_cast<std::uint32_t>(radii.size());
  if (n < 2) return std::nullopt;
  // Sorted: the choice (sums over the radii included) does not depend on the particles' order,
  // so a resumed engine makes the one its run made.
  std::sort(radii.begin(), radii.end());
  const double split = 2.0 * radii[n / 10];
  double small = 0.0, largest = 0.0;
  for (const double r : radii) {
    largest = std::max(largest, r);
    if (r <= split) small = std::max(small, r);
  }
  if (!(largest > 2.5 * small)) return std::nullopt;
  std::array<bool, D> periodic;
  periodic.fill(true);
  Vec<D> fine_width;
  fine_width.fill(2.0 * small * room);
  // The big particles fill much of the box: up to 8 fine cells per particle (32 bytes) rather
  // than the one-level cap, which would widen the fine cells towards the big ones.
  SizeLevelPlan<D> plan{
      CellGrid<D>(box, fine_width, periodic, n, std::max(cells_per_particle, 8.0)), {}};
  const CellGrid<D>& fine = plan.fine;
  typename CellNeighbourhood<D>::Levels& levels = plan.levels;
  Vec<D> coarse_width;
  for (int a = 0; a < D; ++a) {
    const double w = fine.width(a);
    const double wanted = 2.0 * largest * room, reach = (small + largest) * room;
    levels.group[a] = static_cast<int>(std::ceil(wanted / w));
    while (levels.group[a] * w < wanted) ++levels.group[a];
    levels.reach[a] = static_cast<int>(std::ceil(reach / w));
    while (levels.reach[a] * w < reach) ++levels.reach[a];
    const int coarse = fine.cells_along(a) / levels.group[a];
    // Three coarse cells per axis, and a block that meets no cell twice; else one level.
    if (coarse < 3 || fine.cells_along(a) < 2 * levels.reach[a] + 1) return std::nullopt;
    coarse_width[a] = box[a] / (coarse + 0.5);  // exactly `coarse` cells
  }
  // Two levels only where they pay: the candidates and cells a prediction visits, weighted by
  // how often each particle is predicted (its collision rate, taken as (r + mean r)^2), against
  // one level's (measured: a uniform 1:14 distribution of diameters runs faster on one level,
  // most of its particles being mid-sized; docs/performance.md).
  double volume = 1.0, fine_volume = 1.0, coarse_volume = 1.0, block = 1.0, one_cell = 1.0;
  for (int a = 0; a < D; ++a) {
    volume *= box[a];
    fine_volume *= fine.width(a);
    coarse_volume *= levels.group[a] * fine.width(a);
    block *= 2 * levels.reach[a] + 1;
    one_cell *= one_level.width(a);
  }
  std::size_t bigs = 0;
  double mean = 0.0;
  for (const double r : radii) {
    bigs += r > small ? 1 : 0;
    mean += r / n;
  }
  const double per_fine = static_cast<double>(n - bigs) / volume * fine_volume;
  const double per_coarse = static_cast<double>(bigs) / volume * coarse_volume;
  const double around = CellGrid<D>::kNeighbourCells;
  const double coarse_cost = around * (1.0 + per_coarse);
  double one = 0.0, two = 0.0;
  for (const double r : radii) {
    const double often = (r + mean) * (r + mean);
    one += often * around * (1.0 + static_cast<double>(n) / volume * one_cell);
    two +=
        often * (coarse_cost + (r > small ? block * (1.0 + per_fine) : around * (1.0 + per_fine)));
  }
  if (!(two < 0.7 * one) && !force) return std::nullopt;
  levels.coarse = CellGrid<D>(box, coarse_width, periodic, n, kNever);  // no cap: few cells
  for (int a = 0; a < D; ++a) {
    if (levels.coarse.cells_along(a) != fine.cells_along(a) / levels.group[a]) return std::nullopt;
  }
  levels.box = box;
  levels.small_radius = small;
  return plan;
}

}  // namespace kairos
