// The cells around a cell of a grid, `rings` deep along each axis, for the searches over size
// classes (core/size_classes.hpp: init/insertion_grid.hpp, analysis/neighbour_pairs.hpp).
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>

namespace kairos {

// Calls f(index) for each cell within rings[a] of cell c along every axis a of a grid of n[a]
// cells (index = c[0] + n[0] (c[1] + n[1] c[2]...), axis 0 fastest), until f returns true;
// returns whether it did. Along a periodic axis the rings wrap, each cell once (every cell of
// the axis where they would wrap onto themselves); along a bounded one they stop at its ends.
template <int D, class F>
[[gnu::always_inline]] inline bool for_each_cell_in_rings(const std::array<std::size_t, D>& c,
                                                          std::array<std::size_t, D> rings,
                                                          const std::array<std::size_t, D>& n,
                                                          const std::array<bool, D>& periodic,
                                                          F&& f) {
  std::array<std::size_t, D> first{}, span{};
  for (int a = 0; a < D; ++a) {
    const std::size_t r = std::min(rings[a], n[a]);
    if (periodic[a]) {
      const bool whole = n[a] < 2 * r + 1;
      first[a] = whole ? 0 : (c[a] + n[a] - r) % n[a];
      span[a] = whole ? n[a] : 2 * r + 1;
    } else {
      first[a] = c[a] >= r ? c[a] - r : 0;
      span[a] = std::min(c[a] + r, n[a] - 1) - first[a] + 1;
    }
  }
  std::array<std::size_t, D> pick{};
  while (true) {
    std::size_t index = 0;
    for (int a = D - 1; a >= 0; --a) {
      std::size_t along = first[a] + pick[a];  // < 2 n: one wrap at most
      if (along >= n[a]) along -= n[a];
      index = index * n[a] + along;
    }
    if (f(index)) return true;
    int a = 0;
    while (a < D && ++pick[a] == span[a]) pick[a++] = 0;
    if (a == D) return false;
  }
}

}  // namespace kairos
