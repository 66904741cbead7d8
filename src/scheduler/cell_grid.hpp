// Cell grid for neighbour finding with cell-crossing events.
//
// The periodic box is cut into n_k >= 3 cells per axis, each at least as wide as the largest
// contact distance, so every pair that can collide before either particle leaves its cell sits in
// neighbouring cells. Each cell stores its particle indices inline in a fixed-stride slot array
// (count, then indices), so scanning a cell reads one cache line instead of chasing a linked
// list; the stride doubles (rare, O(N)) when a cell overflows, so there is no hard cap. The image
// of a neighbouring cell is known from the cell offset (wrapping adds +-L), so pair tests never
// need a minimum-image rounding.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/error.hpp"
#include "core/vec.hpp"

namespace kairos {

template <int D>
class CellGrid {
 public:
  static constexpr int kNeighbourCells = D == 3 ? 27 : 9;
  static constexpr int kLayerCells = D == 3 ? 9 : 3;

  CellGrid() = default;
  // Cells at least `min_width` wide, at least 3 per axis, and at most ~4 per particle (dilute
  // systems get wider cells instead of an unbounded, mostly empty grid).
  CellGrid(const Vec<D>& box, double min_width, std::size_t particles) : box_(box) {
    double wanted[D];
    double product = 1.0;
    for (int k = 0; k < D; ++k) {
      if (!(box[k] > 0.0) || !std::isfinite(box[k])) {
        throw InputError("box edge " + std::to_string(box[k]) + " is not a finite positive length");
      }
      wanted[k] = std::min(std::floor(box[k] / min_width), 1e6);
      if (wanted[k] < 3.0) {
        throw InputError("box edge " + std::to_string(box[k]) +
                         " is shorter than 3 contact distances (" + std::to_string(min_width) +
                         "): use more particles or a lower packing fraction");
      }
      product *= wanted[k];
    }
    const double max_cells = std::max(27.0, 4.0 * static_cast<double>(particles));
    const double shrink = product > max_cells ? std::pow(max_cells / product, 1.0 / D) : 1.0;
    total_ = 1;
    for (int k = 0; k < D; ++k) {
      n_[k] = static_cast<int>(std::max(3.0, std::floor(wanted[k] * shrink)));
      width_[k] = box[k] / n_[k];
      stride_[k] = total_;
      total_ *= static_cast<std::uint32_t>(n_[k]);
    }
    std::array<int, D> off;
    off.fill(-1);
    for (int n = 0; n < kNeighbourCells; ++n) {
      std::int64_t delta = 0;
      for (int k = 0; k < D; ++k) delta += static_cast<std::int64_t>(off[k]) * stride_[k];
      neighbour_delta_[n] = static_cast<std::int32_t>(delta);
      for (int k = 0; k < D; ++k) {
        if (++off[k] <= 1) break;
        off[k] = -1;
      }
    }
    stride_slots_ = 8;  // count + 7 particles: a 32-byte cell, ample at any hard-sphere density
    slots_.assign(static_cast<std::size_t>(total_) * stride_slots_, 0);
    cell_.assign(particles, 0);
  }

  std::uint32_t cell_count() const { return total_; }
  std::uint32_t capacity() const { return stride_slots_ - 1; }  // members a cell can hold now
  int cells_along(int k) const { return n_[k]; }
  std::uint32_t cell_of(std::uint32_t i) const { return cell_[i]; }
  // The particles of cell c: count(c) indices starting at members(c).
  std::uint32_t count(std::uint32_t c) const { return slots_[std::size_t(c) * stride_slots_]; }
  const std::uint32_t* members(std::uint32_t c) const {
    return slots_.data() + std::size_t(c) * stride_slots_ + 1;
  }

  int coordinate(std::uint32_t cell, int k) const {
    return static_cast<int>((cell / stride_[k]) % static_cast<std::uint32_t>(n_[k]));
  }
  std::uint32_t cell_at(const std::array<int, D>& c) const {
    std::uint32_t idx = 0;
    for (int k = 0; k < D; ++k) idx += static_cast<std::uint32_t>(c[k]) * stride_[k];
    return idx;
  }
  // Cell containing a position (clamped into the grid: positions may sit a round-off outside).
  std::uint32_t locate(const Vec<D>& x) const {
    std::array<int, D> c;
    for (int k = 0; k < D; ++k) {
      c[k] = static_cast<int>(std::floor(x[k] / width_[k]));
      if (c[k] < 0) c[k] = 0;
      if (c[k] >= n_[k]) c[k] = n_[k] - 1;
    }
    return cell_at(c);
  }
  double lower(std::uint32_t cell, int k) const { return coordinate(cell, k) * width_[k]; }
  double upper(std::uint32_t cell, int k) const { return (coordinate(cell, k) + 1) * width_[k]; }

  void insert(std::uint32_t i, std::uint32_t c) {
    if (count(c) + 1 >= stride_slots_) grow();
    std::uint32_t* cell = slots_.data() + std::size_t(c) * stride_slots_;
    cell[1 + cell[0]++] = i;
    cell_[i] = c;
  }
  // Removes i from its cell; the last member takes its slot.
  void erase(std::uint32_t i) {
    std::uint32_t* cell = slots_.data() + std::size_t(cell_[i]) * stride_slots_;
    const std::uint32_t n = cell[0];
    for (std::uint32_t k = 1; k <= n; ++k) {
      if (cell[k] == i) {
        cell[k] = cell[n];
        --cell[0];
        return;
      }
    }
  }

  // A neighbouring cell and the periodic shift to add to positions of particles inside it;
  // `shifted` is false when the shift is zero (most cells: the caller can skip the copy).
  struct Neighbour {
    std::uint32_t cell;
    bool shifted;
    Vec<D> shift;
  };

  // Visits the 3^D cells around `cell` (itself included). Cells away from the box faces take a
  // fast path: fixed index offsets, no wrapping, no shift.
  template <class F>
  void for_each_neighbour(std::uint32_t cell, F&& f) const {
    std::array<int, D> base;
    bool interior = true;
    for (int k = 0; k < D; ++k) {
      base[k] = coordinate(cell, k);
      interior = interior && base[k] > 0 && base[k] < n_[k] - 1;
    }
    if (interior) {
      Neighbour nb{0, false, {}};
      for (int n = 0; n < kNeighbourCells; ++n) {
        nb.cell = cell + neighbour_delta_[n];
        f(nb);
      }
      return;
    }
    std::array<int, D> off;
    off.fill(-1);
    for (int n = 0; n < kNeighbourCells; ++n) {
      f(offset_cell(base, off));
      for (int k = 0; k < D; ++k) {
        if (++off[k] <= 1) break;
        off[k] = -1;
      }
    }
  }

  // Visits the 3^(D-1) cells that become neighbours when a particle enters `cell` moving in
  // direction `sign` (+1 or -1) along axis `axis`: the far layer beyond the new cell.
  template <class F>
  void for_each_new_layer(std::uint32_t cell, int axis, int sign, F&& f) const {
    std::array<int, D> base;
    for (int k = 0; k < D; ++k) base[k] = coordinate(cell, k);
    std::array<int, D> off;
    off.fill(-1);
    off[axis] = sign;
    for (int n = 0; n < kLayerCells; ++n) {
      f(offset_cell(base, off));
      for (int k = 0; k < D; ++k) {
        if (k == axis) continue;
        if (++off[k] <= 1) break;
        off[k] = -1;
      }
    }
  }

  // Memory of the grid divided by the number of particles.
  // Offset of cell b from cell a, each component wrapped into {-1, 0, 1}; false if the cells
  // are not neighbours.
  bool neighbour_offset(std::uint32_t a, std::uint32_t b, std::array<int, D>& d) const {
    for (int k = 0; k < D; ++k) {
      int diff = coordinate(b, k) - coordinate(a, k);
      if (diff > 1) diff -= n_[k];
      if (diff < -1) diff += n_[k];
      if (diff < -1 || diff > 1) return false;
      d[k] = diff;
    }
    return true;
  }

  std::size_t bytes_per_particle() const {
    return cell_.empty() ? 0
                         : (slots_.size() + cell_.size()) * sizeof(std::uint32_t) / cell_.size();
  }

 private:
  // Doubles the per-cell capacity, keeping every cell's members in order.
  void grow() {
    const std::uint32_t stride = 2 * stride_slots_;
    std::vector<std::uint32_t> wider(static_cast<std::size_t>(total_) * stride, 0);
    for (std::size_t c = 0; c < total_; ++c) {
      std::copy_n(slots_.data() + c * stride_slots_, stride_slots_, wider.data() + c * stride);
    }
    slots_.swap(wider);
    stride_slots_ = stride;
  }

  Neighbour offset_cell(const std::array<int, D>& base, const std::array<int, D>& off) const {
    Neighbour nb;
    nb.shifted = false;
    std::array<int, D> c;
    for (int k = 0; k < D; ++k) {
      c[k] = base[k] + off[k];
      nb.shift[k] = 0.0;
      if (c[k] < 0) {
        c[k] += n_[k];
        nb.shift[k] = -box_[k];
        nb.shifted = true;
      } else if (c[k] >= n_[k]) {
        c[k] -= n_[k];
        nb.shift[k] = box_[k];
        nb.shifted = true;
      }
    }
    nb.cell = cell_at(c);
    return nb;
  }

  Vec<D> box_{};
  std::array<int, D> n_{};
  Vec<D> width_{};
  std::array<std::uint32_t, D> stride_{};
  std::uint32_t total_ = 0;
  std::uint32_t stride_slots_ = 8;
  std::int32_t neighbour_delta_[kNeighbourCells] = {};  // index offsets of an interior cell
  std::vector<std::uint32_t> slots_;                    // per cell: count, then the member indices
  std::vector<std::uint32_t> cell_;                     // per particle: its cell
};

}  // namespace kairos
