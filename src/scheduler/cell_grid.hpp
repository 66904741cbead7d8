// Cell grid for neighbour finding with cell-crossing events.
//
// The periodic box is cut into n_k >= 3 cells per axis, each at least as wide as the largest
// contact distance, so every pair that can collide before either particle leaves its cell sits in
// neighbouring cells.
//
// A particle's cell is named by a CellCode, its integer coordinates packed into 32 bits (10 bits
// per axis in 3D, 16 in 2D): bounds, neighbours and crossings then need no division. Cells are
// singly linked lists (a head per cell, a `next` per particle): 4 bytes per particle plus 4 per
// cell, the smallest structure with no capacity limit. The caller keeps each particle's code
// (the engine stores it in its hot record). With particles renumbered along morton_rank(), a
// cell's members and its neighbours' sit close together in memory. The image of a neighbouring
// cell is known from the cell offset (wrapping adds +-L), so pair tests never need a
// minimum-image rounding.
//
// An axis may be non-periodic (walls or open faces). Its outer layers of cells then extend to
// infinity (lower() of the first layer is -inf, upper() of the last +inf), so a particle can
// never leave the grid, whatever a vibrating wall or an open top lets it do; a neighbour beyond
// such a face is an always-empty sentinel cell, so the neighbour loops need no special case.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/error.hpp"
#include "core/huge_page_allocator.hpp"
#include "core/vec.hpp"

namespace kairos {

using CellCode = std::uint32_t;

template <int D>
class CellGrid {
 public:
  static constexpr int kNeighbourCells = D == 3 ? 27 : 9;
  // The cells a crossing adds to a particle's neighbourhood: one layer of 3^(D-1).
  static constexpr int kLayerCells = D == 3 ? 9 : 3;
  static constexpr int kBits = D == 3 ? 10 : 16;  // bits per coordinate in a CellCode
  static constexpr int kMaxCellsAlong = 1 << kBits;
  // Bounds the grid's memory (4 bytes per cell) at 5 bytes per particle; speed is flat between
  // 1 and 3 cells per particle (docs/performance.md).
  static constexpr double kDefaultCellsPerParticle = 1.25;

  CellGrid() = default;
  // Cells at least `min_width` wide, at least 3 per periodic axis (1 per non-periodic one), at
  // most `max_cells_per_particle` per particle (dilute systems get wider cells instead of a
  // large, mostly empty grid) and at most kMaxCellsAlong per axis.
  CellGrid(const Vec<D>& box, double min_width, std::size_t particles,
           double max_cells_per_particle = kDefaultCellsPerParticle)
      : CellGrid(box, uniform(min_width), all_periodic(), particles, max_cells_per_particle) {}
  CellGrid(const Vec<D>& box, const Vec<D>& min_width, const std::array<bool, D>& periodic,
           std::size_t particles, double max_cells_per_particle = kDefaultCellsPerParticle)
      : box_(box), periodic_(periodic) {
    double wanted[D];
    double product = 1.0;
    for (int k = 0; k < D; ++k) {
      if (!(box[k] > 0.0) || !std::isfinite(box[k])) {
        throw InputError("box edge " + std::to_string(box[k]) + " is not a finite positive length");
      }
      wanted[k] = std::min(std::floor(box[k] / min_width[k]), double{kMaxCellsAlong});
      if (periodic[k] && wanted[k] < 3.0) {
        throw InputError("box edge " + std::to_string(box[k]) +
                         " is shorter than 3 interaction ranges (" + std::to_string(min_width[k]) +
                         ": the largest contact distance or potential cut-off): use more "
                         "particles or a lower packing fraction");
      }
      if (!periodic[k] && wanted[k] < 1.0) {
        throw InputError("box edge " + std::to_string(box[k]) + " between walls is shorter than " +
                         std::to_string(min_width[k]) +
                         " (the interaction range: the largest diameter or potential cut-off)");
      }
      product *= wanted[k];
    }
    const double max_cells =
        std::max(27.0, max_cells_per_particle * static_cast<double>(particles));
    const double shrink = product > max_cells ? std::pow(max_cells / product, 1.0 / D) : 1.0;
    total_ = 1;
    for (int k = 0; k < D; ++k) {
      n_[k] = static_cast<int>(std::max(periodic[k] ? 3.0 : 1.0, std::floor(wanted[k] * shrink)));
      width_[k] = box[k] / n_[k];
      stride_[k] = total_;
      total_ *= static_cast<std::uint32_t>(n_[k]);
      constexpr double inf = std::numeric_limits<double>::infinity();
      low_edge_[k] = periodic[k] ? 0.0 : -inf;
      high_edge_[k] = periodic[k] ? n_[k] * width_[k] : inf;
    }
    std::array<int, D> off;
    off.fill(-1);
    int in_layer[D][2] = {};
    for (int n = 0; n < kNeighbourCells; ++n) {
      for (int k = 0; k < D; ++k) {
        if (off[k] != 0) {
          const int side = off[k] > 0 ? 1 : 0;
          layer_[k][side][in_layer[k][side]++] = static_cast<std::uint8_t>(n);
        }
      }
      std::int64_t delta = 0;
      for (int k = 0; k < D; ++k) delta += static_cast<std::int64_t>(off[k]) * stride_[k];
      neighbour_delta_[n] = static_cast<std::int32_t>(delta);
      for (int k = 0; k < D; ++k) {
        if (++off[k] <= 1) break;
        off[k] = -1;
      }
    }
    end_ = static_cast<std::uint32_t>(particles);
    head_.assign(total_ + 1, end_);  // + the empty cell beyond non-periodic faces
    next_.assign(particles + 1, end_);
  }

  std::uint32_t cell_count() const { return total_; }
  int cells_along(int k) const { return n_[k]; }
  double width(int k) const { return width_[k]; }
  bool periodic(int k) const { return periodic_[k]; }
  // Whether the cell lies in an outer layer of a non-periodic axis k, on the side `sign`.
  bool at_face(CellCode c, int k, int sign) const {
    return !periodic_[k] && coordinate(c, k) == (sign < 0 ? 0 : n_[k] - 1);
  }

  // Codes and linear indices (the position of a cell's list head).
  int coordinate(CellCode c, int k) const {
    return static_cast<int>((c >> (kBits * k)) & (kMaxCellsAlong - 1));
  }
  CellCode code_at(const std::array<int, D>& c) const {
    CellCode code = 0;
    for (int k = 0; k < D; ++k) code |= static_cast<CellCode>(c[k]) << (kBits * k);
    return code;
  }
  std::uint32_t index(CellCode c) const {
    std::uint32_t idx = 0;
    for (int k = 0; k < D; ++k) idx += static_cast<std::uint32_t>(coordinate(c, k)) * stride_[k];
    return idx;
  }
  // Whether a code names a cell of this grid (restart files are checked with it).
  bool valid(CellCode c) const {
    if constexpr (D == 3) {
      if ((c >> (3 * kBits)) != 0) return false;
    }
    for (int k = 0; k < D; ++k)
      if (coordinate(c, k) >= n_[k]) return false;
    return true;
  }
  // Cell containing a position (clamped into the grid: positions may sit a round-off outside).
  CellCode locate(const Vec<D>& x) const {
    std::array<int, D> c;
    for (int k = 0; k < D; ++k) {
      c[k] = static_cast<int>(std::floor(x[k] / width_[k]));
      if (c[k] < 0) c[k] = 0;
      if (c[k] >= n_[k]) c[k] = n_[k] - 1;
    }
    return code_at(c);
  }
  // Cell bounds as if every axis were periodic (the hard-sphere fast path).
  double lower(CellCode c, int k) const { return coordinate(c, k) * width_[k]; }
  double upper(CellCode c, int k) const { return (coordinate(c, k) + 1) * width_[k]; }
  // Cell bounds with the outer layers of non-periodic axes extending to -inf / +inf.
  double lower_bound(CellCode c, int k) const {
    const int x = coordinate(c, k);
    return x == 0 ? low_edge_[k] : x * width_[k];
  }
  double upper_bound(CellCode c, int k) const {
    const int x = coordinate(c, k);
    return x == n_[k] - 1 ? high_edge_[k] : (x + 1) * width_[k];
  }
  // The least n . x over cell c (n need not be unit): where a plane of normal n reaches into it
  // first; -infinity for an outer layer extending without end against n.
  double lowest_along(CellCode c, const Vec<D>& n) const {
    double lowest = 0.0;
    for (int k = 0; k < D; ++k) {
      if (n[k] == 0.0) continue;
      const double edge = n[k] > 0.0 ? lower_bound(c, k) : upper_bound(c, k);
      if (!std::isfinite(edge)) return -std::numeric_limits<double>::infinity();
      lowest += n[k] * edge;
    }
    return lowest;
  }
  // Whether some axis is not periodic.
  bool bounded() const {
    for (int k = 0; k < D; ++k)
      if (!periodic_[k]) return true;
    return false;
  }

  // The particles of a cell (by linear index): first(), then next(i) until end(). The end
  // marker is the particle count, and next(end()) is end() again, so a loop may follow links
  // past the end without a branch.
  std::uint32_t end() const { return end_; }
  std::uint32_t first(std::uint32_t cell_index) const { return head_[cell_index]; }
  std::uint32_t next(std::uint32_t i) const { return next_[i]; }
  const std::uint32_t* heads() const { return head_.data(); }
  const std::uint32_t* links() const { return next_.data(); }

  void insert(std::uint32_t i, CellCode c) {
    const std::uint32_t h = index(c);
    next_[i] = head_[h];
    head_[h] = i;
  }
  // Removes i from cell c (where the caller says it is): a walk along a list of ~1 member.
  void erase(std::uint32_t i, CellCode c) {
    std::uint32_t* link = &head_[index(c)];
    while (*link != i) link = &next_[*link];
    *link = next_[i];
  }
  // Empties every cell (before particles are inserted again in a new numbering).
  void clear() {
    // The sentinel cell (index total_) stays empty: nothing is ever inserted there.
    std::fill(head_.begin(), head_.end(), end_);
    std::fill(next_.begin(), next_.end(), end_);
  }

  // A neighbouring cell (linear index) and the periodic shift to add to positions of particles
  // inside it; `shifted` is false when the shift is zero (most cells).
  struct Neighbour {
    std::uint32_t cell;
    bool shifted;
    Vec<D> shift;
  };

  // Whether all 3^D cells around `c` lie inside the grid without wrapping: then they sit at
  // index(c) + neighbour_deltas()[n], and none needs a periodic shift.
  bool interior(CellCode c) const {
    bool in = true;
    for (int k = 0; k < D; ++k) in = in && coordinate(c, k) > 0 && coordinate(c, k) < n_[k] - 1;
    return in;
  }
  const std::int32_t* neighbour_deltas() const { return neighbour_delta_; }
  // The neighbour numbers n (as neighbour() and neighbour_deltas() count them, in increasing
  // order) of the kLayerCells cells one step along axis k on the side `sign` (+1, -1): after a
  // crossing, the layer that is new to the particle's neighbourhood.
  const std::uint8_t* layer(int k, int sign) const { return layer_[k][sign > 0 ? 1 : 0]; }
  // Neighbour number n (0 .. 3^D - 1, axis 0 fastest: n = sum (off_k + 1) 3^k) of cell c, itself
  // included: its linear index and periodic shift; beyond a wall or open face the empty sentinel
  // cell.
  Neighbour neighbour(CellCode c, int n) const {
    std::array<int, D> base, off;
    for (int k = 0; k < D; ++k) {
      base[k] = coordinate(c, k);
      off[k] = n % 3 - 1;
      n /= 3;
    }
    return bounded() ? offset_cell<true>(base, off) : offset_cell<false>(base, off);
  }

  // Offset of cell b from cell a, each component wrapped into {-1, 0, 1} (periodic axes);
  // false if the cells are not neighbours.
  bool neighbour_offset(CellCode a, CellCode b, std::array<int, D>& d) const {
    for (int k = 0; k < D; ++k) {
      int diff = coordinate(b, k) - coordinate(a, k);
      if (periodic_[k] && diff > 1) diff -= n_[k];
      if (periodic_[k] && diff < -1) diff += n_[k];
      if (diff < -1 || diff > 1) return false;
      d[k] = diff;
    }
    return true;
  }

  // The grid's memory (cell heads and particle links) divided by the number of particles.
  double bytes_per_particle() const {
    return next_.empty()
               ? 0.0
               : static_cast<double>((head_.size() + next_.size()) * sizeof(std::uint32_t)) /
                     static_cast<double>(next_.size());
  }

  // Rank of a cell along a Morton (Z-order) curve through the grid: numbering particles by it
  // keeps the members of neighbouring cells close in memory in every direction.
  std::uint64_t morton_rank(CellCode c) const {
    std::uint64_t code = 0;
    for (int bit = 0; bit < kBits; ++bit) {
      for (int k = 0; k < D; ++k) {
        const auto x = static_cast<std::uint64_t>(coordinate(c, k));
        code |= ((x >> bit) & 1u) << (D * bit + k);
      }
    }
    return code;
  }

 private:
  static Vec<D> uniform(double w) {
    Vec<D> v;
    for (int k = 0; k < D; ++k) v[k] = w;
    return v;
  }
  static std::array<bool, D> all_periodic() {
    std::array<bool, D> p;
    p.fill(true);
    return p;
  }

  template <bool kBounded>
  Neighbour offset_cell(const std::array<int, D>& base, const std::array<int, D>& off) const {
    Neighbour nb;
    nb.shifted = false;
    std::uint32_t idx = 0;
    for (int k = 0; k < D; ++k) {
      int c = base[k] + off[k];
      nb.shift[k] = 0.0;
      if (kBounded && !periodic_[k] && (c < 0 || c >= n_[k])) {
        return {total_, false, {}};  // beyond a wall or open face: the empty sentinel cell
      }
      if (c < 0) {
        c += n_[k];
        nb.shift[k] = -box_[k];
        nb.shifted = true;
      } else if (c >= n_[k]) {
        c -= n_[k];
        nb.shift[k] = box_[k];
        nb.shifted = true;
      }
      idx += static_cast<std::uint32_t>(c) * stride_[k];
    }
    nb.cell = idx;
    return nb;
  }

  Vec<D> box_{};
  std::array<bool, D> periodic_{};
  Vec<D> low_edge_{}, high_edge_{};  // bounds of the outer layers (+-inf when not periodic)
  std::array<int, D> n_{};
  Vec<D> width_{};
  std::array<std::uint32_t, D> stride_{};
  std::uint32_t total_ = 0;
  std::uint32_t end_ = 0;  // the list end marker: the number of particles
  std::int32_t neighbour_delta_[kNeighbourCells] = {};  // index offsets of an interior cell
  std::uint8_t layer_[D][2][kLayerCells] = {};          // see layer()
  HugeVector<std::uint32_t> head_;                      // per cell: first member or end_
  HugeVector<std::uint32_t> next_;                      // per particle (+ end_): next or end_
};

}  // namespace kairos
