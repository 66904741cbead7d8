// The pairs of a configuration closer than a cut-off, by cell lists (Allen & Tildesley,
// Computer Simulation of Liquids, 2nd ed. (2017), §5.3): O(N) per call at a fixed density.
// What the structure analyses (analysis/structure.hpp) are computed from; no run dependency.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "core/cell_rings.hpp"
#include "core/periodic.hpp"
#include "core/size_classes.hpp"
#include "core/vec.hpp"

namespace kairos {

// A configuration at one instant: positions wrapped into [0, L) along periodic axes (anywhere
// along bounded axes: walls or open faces), each particle's species (0 .. species - 1) and
// radius.
template <int D>
struct Configuration {
  Vec<D> box{};
  std::array<bool, D> periodic{};
  std::vector<Vec<D>> position;
  std::vector<std::uint32_t> species;
  std::vector<double> radius;

  std::size_t size() const { return position.size(); }
  double volume() const {
    double v = 1.0;
    for (int a = 0; a < D; ++a) v *= box[a];
    return v;
  }
};

// Cells at least `cutoff` wide along every axis, at most about two per particle; along a
// bounded axis the outer cells take the particles beyond the box. The particles sorted by cell
// (a counting sort): cell k holds members[start[k] .. start[k + 1]).
template <int D>
struct PairCells {
  std::array<std::size_t, D> cells{};
  std::array<double, D> inverse_width{};
  std::size_t count = 1;
  std::vector<std::uint32_t> start;
  std::vector<std::uint32_t> members;

  PairCells(const Configuration<D>& c, double cutoff) {
    const std::size_t n = c.size();
    double total = 1.0;
    for (int a = 0; a < D; ++a) {
      cells[a] = static_cast<std::size_t>(std::max(1.0, std::floor(c.box[a] / cutoff)));
      total *= static_cast<double>(cells[a]);
    }
    const double limit = 2.0 * static_cast<double>(n) + 8.0;
    if (total > limit) {
      const double shrink = std::pow(limit / total, 1.0 / D);
      for (int a = 0; a < D; ++a)
        cells[a] = std::max<std::size_t>(
            1, static_cast<std::size_t>(std::floor(static_cast<double>(cells[a]) * shrink)));
    }
    for (int a = 0; a < D; ++a) {
      inverse_width[a] = static_cast<double>(cells[a]) / c.box[a];
      count *= cells[a];
    }
    std::vector<std::uint32_t> cell_of(n);
    start.assign(count + 1, 0);
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t k = index(coords(c.position[i]));
      cell_of[i] = static_cast<std::uint32_t>(k);
      ++start[k + 1];
    }
    for (std::size_t k = 0; k < count; ++k) start[k + 1] += start[k];
    members.resize(n);
    std::vector<std::uint32_t> next(start.begin(), start.end() - 1);
    for (std::size_t i = 0; i < n; ++i) members[next[cell_of[i]]++] = static_cast<std::uint32_t>(i);
  }

  std::array<std::size_t, D> coords(const Vec<D>& x) const {
    std::array<std::size_t, D> out{};
    for (int a = 0; a < D; ++a) {
      const double u = std::floor(x[a] * inverse_width[a]);
      out[a] = static_cast<std::size_t>(std::clamp(u, 0.0, static_cast<double>(cells[a] - 1)));
    }
    return out;
  }
  std::size_t index(const std::array<std::size_t, D>& at) const {
    std::size_t k = 0;
    for (int a = D - 1; a >= 0; --a) k = k * cells[a] + at[a];
    return k;
  }
};

// Calls f(i, j, r_ij, r_ij^2) once for every unordered pair i != j closer than `cutoff`, with
// r_ij = r_i - r_j by the minimum image along periodic axes and the plain difference along
// bounded ones. The minimum image is unique only if the cut-off is at most half of every
// periodic edge: std::invalid_argument otherwise.
template <int D, class F>
void for_each_pair_within(const Configuration<D>& c, double cutoff, F&& f) {
  const std::size_t n = c.size();
  for (int a = 0; a < D; ++a) {
    if (c.periodic[a] && !(cutoff <= 0.5 * c.box[a]))
      throw std::invalid_argument("for_each_pair_within: cut-off beyond half a periodic edge");
  }
  if (n < 2 || !(cutoff > 0.0)) return;
  const PairCells<D> grid(c, cutoff);
  const auto& cells = grid.cells;
  const auto& start = grid.start;
  const auto& members = grid.members;
  const std::size_t count = grid.count;
  const double cutoff2 = cutoff * cutoff;
  // Along a periodic axis of at least 3 cells a neighbour cell's image is fixed by its offset:
  // r_j is seen shifted by ±L where the offset wraps (exact: a pair closer than the cut-off sits
  // in adjacent cells of the unwrapped axis). With 1 or 2 cells, the minimum image per pair.
  std::array<bool, D> per_pair_image{};
  for (int a = 0; a < D; ++a) per_pair_image[a] = c.periodic[a] && cells[a] < 3;
  std::array<std::array<std::size_t, 3>, D> near{};
  std::array<std::array<double, 3>, D> shift{};
  std::array<int, D> near_count{};
  std::array<std::size_t, D> index{};
  for (std::size_t k = 0; k < count; ++k) {
    {
      std::size_t rest = k;
      for (int a = 0; a < D; ++a) {
        index[a] = rest % cells[a];
        rest /= cells[a];
      }
    }
    // Per axis the distinct neighbour coordinates of the cell and their images' shifts; their
    // product lists each neighbour cell once.
    for (int a = 0; a < D; ++a) {
      int m = 0;
      const auto w = static_cast<long long>(cells[a]);
      for (int o = -1; o <= 1; ++o) {
        long long x = static_cast<long long>(index[a]) + o;
        double s = 0.0;
        if (c.periodic[a]) {
          if (x < 0) {
            x += w;
            s = -c.box[a];
          } else if (x >= w) {
            x -= w;
            s = c.box[a];
          }
          if (per_pair_image[a]) s = 0.0;
        } else if (x < 0 || x >= w) {
          continue;
        }
        bool seen = false;
        for (int q = 0; q < m; ++q) seen = seen || near[a][q] == static_cast<std::size_t>(x);
        if (seen) continue;
        near[a][m] = static_cast<std::size_t>(x);
        shift[a][m++] = s;
      }
      near_count[a] = m;
    }
    std::array<int, D> choice{};
    while (true) {
      std::size_t other = 0;
      Vec<D> s{};
      for (int a = D - 1; a >= 0; --a) {
        other = other * cells[a] + near[a][choice[a]];
        s[a] = shift[a][choice[a]];
      }
      if (other >= k) {
        const bool same = other == k;
        for (std::uint32_t p = start[k]; p < start[k + 1]; ++p) {
          const std::uint32_t i = members[p];
          const Vec<D>& xi = c.position[i];
          for (std::uint32_t q = same ? p + 1 : start[other]; q < start[other + 1]; ++q) {
            const std::uint32_t j = members[q];
            Vec<D> r;
            double r2 = 0.0;
            for (int a = 0; a < D; ++a) {
              double d = xi[a] - c.position[j][a] - s[a];
              if (per_pair_image[a]) d = minimum_image(d, c.box[a]);
              r[a] = d;
              r2 += d * d;
            }
            if (r2 < cutoff2) f(i, j, r, r2);
          }
        }
      }
      int a = 0;
      while (a < D && ++choice[a] == near_count[a]) choice[a++] = 0;
      if (a == D) break;
    }
  }
}

// Calls f(i, j, r_ij, r_ij^2) once for every unordered pair closer than factor (R_i + R_j),
// R the radii. With sizes within a factor 2 of each other this is for_each_pair_within at
// 2 factor R_max, which also calls f for farther pairs (callers measure). Over a wider distribution
// the particles are split into size classes (core/size_classes.hpp), each with cells sized for
// its own largest radius: the pairs inside a class by for_each_pair_within, and a particle of
// a larger class against the rings of a finer class's cells its reach covers, so that a few
// large particles do not make every small one search cells sized for them. The order of the
// calls is that of the classes, then of the cells.
template <int D, class F>
void for_each_pair_near_contact(const Configuration<D>& c, double factor, F&& f) {
  const SizeClasses classes = size_classes(c.radius);
  const double largest = classes.largest[0];
  if (classes.count() == 1) {
    for_each_pair_within(c, 2.0 * factor * largest, f);
    return;
  }
  for (int a = 0; a < D; ++a) {
    if (c.periodic[a] && !(2.0 * factor * largest <= 0.5 * c.box[a]))
      throw std::invalid_argument(
          "for_each_pair_near_contact: cut-off beyond half a periodic edge");
  }
  // Each class as a configuration of its own, its members' indices in `index_of`.
  std::vector<Configuration<D>> part(classes.count());
  std::vector<std::vector<std::uint32_t>> index_of(classes.count());
  for (std::size_t k = 0; k < classes.count(); ++k) {
    part[k].box = c.box;
    part[k].periodic = c.periodic;
  }
  for (std::size_t i = 0; i < c.size(); ++i) {
    const std::size_t k = classes.of[i];
    part[k].position.push_back(c.position[i]);
    part[k].radius.push_back(c.radius[i]);
    index_of[k].push_back(static_cast<std::uint32_t>(i));
  }
  for (std::size_t k = 0; k < classes.count(); ++k) {
    for_each_pair_within(part[k], 2.0 * factor * classes.largest[k],
                         [&](std::uint32_t i, std::uint32_t j, const Vec<D>& r, double r2) {
                           const double cut = factor * (part[k].radius[i] + part[k].radius[j]);
                           if (r2 < cut * cut) f(index_of[k][i], index_of[k][j], r, r2);
                         });
  }
  for (std::size_t m = 1; m < classes.count(); ++m) {
    // Cells for the class's contacts; for points (radius 0) as wide as the last class's.
    const double width = 2.0 * factor * std::max(classes.largest[m], largest / 256.0);
    const PairCells<D> grid(part[m], width);
    std::array<double, D> cell_width{};
    for (int a = 0; a < D; ++a) cell_width[a] = 1.0 / grid.inverse_width[a];
    for (std::size_t k = 0; k < m; ++k) {
      for (std::uint32_t p = 0; p < part[k].size(); ++p) {
        const Vec<D>& xi = part[k].position[p];
        const double ri = part[k].radius[p];
        const double reach = factor * (ri + classes.largest[m]);
        const std::array<std::size_t, D> at = grid.coords(xi);
        std::array<std::size_t, D> rings{};
        for (int a = 0; a < D; ++a)
          rings[a] = static_cast<std::size_t>(
              std::min(std::ceil(reach / cell_width[a]), static_cast<double>(grid.cells[a])));
        for_each_cell_in_rings<D>(at, rings, grid.cells, c.periodic, [&](std::size_t cell) {
          for (std::uint32_t q = grid.start[cell]; q < grid.start[cell + 1]; ++q) {
            const std::uint32_t j = grid.members[q];
            Vec<D> r;
            double r2 = 0.0;
            for (int a = 0; a < D; ++a) {
              double d = xi[a] - part[m].position[j][a];
              if (c.periodic[a]) d = minimum_image(d, c.box[a]);
              r[a] = d;
              r2 += d * d;
            }
            const double cut = factor * (ri + part[m].radius[j]);
            if (r2 < cut * cut) f(index_of[k][p], index_of[m][j], r, r2);
          }
          return false;
        });
      }
    }
  }
}

}  // namespace kairos
