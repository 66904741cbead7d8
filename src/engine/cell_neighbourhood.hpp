// The neighbourhood walk of the event engine: the cell grid (scheduler/cell_grid.hpp) with the
// particles' cell lists, and the gathering of a particle's candidate partners from the 3^D cells
// around it into a flat list (with the periodic shift of each one's cell), their records
// prefetched so that the cache misses of a whole prediction overlap.
//
// It owns the grid and two candidate lists (so that both partners of a collision gather before
// either is tested); the particles' records stay the engine's and are passed in, for prefetching
// only. The cell each particle is in is kept in its record (HotRecord::cell), so restart files
// store it with the record; validate() checks the lists against the records. Hot code: every
// function is defined here, inline, for the engine's translation unit.
//
// Wide size distributions take two levels (use_levels): the small particles in the grid, sized
// for their contact distance, the big ones in a coarse grid whose cells group whole fine cells.
// A small particle's candidates are the 3^D fine cells around it and the 3^D coarse cells around
// the coarse cell holding its own; a big particle's, the fine cells within its reach (a block of
// (2 reach + 1)^D) and the same 3^D coarse cells. Every particle crosses fine cells only, so its
// coarse cell changes only at a crossing (Ogarko and Luding, Comput. Phys. Commun. 183, 931
// (2012), for the hierarchical grid; docs/performance.md#wide-size-distributions-the-limit).
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/vec.hpp"
#include "engine/candidate_scan.hpp"
#include "engine/hot_record.hpp"
#include "scheduler/cell_grid.hpp"

namespace kairos {

// Scratch of a prediction: candidate partners and the periodic shift of each one's cell.
// Under shear, the row of cells beyond a y face is searched 4 cells wide (its images slide),
// and images there also move at +-shear_rate L_y: `sheared` lists carry velocity shifts.
template <int D>
struct CandidateList {
  static constexpr int kMaxShifts = CellGrid<D>::kNeighbourCells * 4 / 3 + 1;
  std::vector<std::uint32_t> ids;
  std::vector<std::uint32_t> shift;  // per candidate, into shifts; read only if n_shifts > 1
  // Scratch of the candidate loops: which candidates sit in deferred soft contacts.
  mutable std::vector<std::uint32_t> delayed;
  Vec<D> shifts[kMaxShifts] = {};
  Vec<D> velocity_shifts[kMaxShifts] = {};  // read only if sheared
  std::uint32_t count = 0, n_shifts = 1;
  bool sheared = false;
};

template <int D>
class CellNeighbourhood {
 public:
  // Free candidate slots kept before each list is appended (its unconditional writes).
  static constexpr std::uint32_t kCandidateSlack = 4;
  static constexpr auto kAllNeighbours = [] {
    std::array<std::uint8_t, CellGrid<D>::kNeighbourCells> all{};
    for (int n = 0; n < CellGrid<D>::kNeighbourCells; ++n) all[n] = static_cast<std::uint8_t>(n);
    return all;
  }();

  CellNeighbourhood() = default;
  // vector_gather: gather the lists' heads sixteen at a time with AVX-512 (gather_lists_avx512)
  // instead of walking them one by one; the same candidates in the same order (walk_lists).
  CellNeighbourhood(const CellGrid<D>& grid, bool vector_gather)
      : grid_(grid), vector_gather_(vector_gather) {
    for (CandidateList<D>& list : lists_) size_list(list);
  }
  // A list's first storage (grow() doubles it when a neighbourhood is crowded).
  static void size_list(CandidateList<D>& list) {
    list.ids.resize(256);
    list.shift.resize(256);
    list.delayed.resize(256 + 8);
  }

  CellGrid<D>& grid() { return grid_; }
  const CellGrid<D>& grid() const { return grid_; }
  CandidateList<D>& list(int k) { return lists_[k]; }

  // Two levels (see the file's comment): `coarse` lists the particles flagged in `big`; its cell
  // c holds fine cells group*c ... group*(c + 1) - 1 along each axis (the last also the rest);
  // a big particle searches `reach` fine cells around its own. `box`: the periodic shifts.
  struct Levels {
    CellGrid<D> coarse;
    std::array<int, D> group{};
    std::array<int, D> reach{};
    std::vector<std::uint8_t> big;  // per particle
    Vec<D> box{};
    double small_radius = 0.0;  // the largest radius in the fine cells
  };
  void use_levels(Levels levels) {
    levels_ = std::move(levels);
    two_level_ = true;
  }
  bool two_level() const { return two_level_; }
  bool big(std::uint32_t i) const { return two_level_ && levels_.big[i] != 0; }
  const Levels& levels() const { return levels_; }
  std::vector<std::uint8_t>& big_flags() { return levels_.big; }
  // The coarse cell holding fine cell `cell`.
  CellCode coarse_of(CellCode cell) const {
    std::array<int, D> c;
    for (int a = 0; a < D; ++a) {
      c[a] =
          std::min(grid_.coordinate(cell, a) / levels_.group[a], levels_.coarse.cells_along(a) - 1);
    }
    return levels_.coarse.code_at(c);
  }
  // Particle i's candidates (it sits in fine cell `cell`): gather() with one level.
  void gather_particle(std::uint32_t i, CellCode cell, CandidateList<D>& list,
                       const HotRecord<D>* hot) const {
    if (!two_level_) {
      gather(cell, list, hot);
      return;
    }
    if (levels_.big[i] != 0) {
      gather_block(cell, list, hot);
    } else {
      gather(cell, list, hot);
    }
    append_coarse(cell, list, hot);
  }

  // The members of the 3^D cells around `cell` as candidates. Cells away from the box faces
  // (most) need no periodic shifts and take a loop over fixed index offsets.
  void gather(CellCode cell, CandidateList<D>& list, const HotRecord<D>* hot) const {
    gather_cells(cell, kAllNeighbours.data(), CellGrid<D>::kNeighbourCells, list, hot);
  }
  // gather() for the cells numbered which[0 .. count) among the 3^D around `cell` (see
  // CellGrid::neighbour's numbering), in that order.
  void gather_cells(CellCode cell, const std::uint8_t* which, int count, CandidateList<D>& list,
                    const HotRecord<D>* hot) const;
  // Doubles a candidate list's storage (rare: a crowded neighbourhood); returns the new storage.
  static std::uint32_t* grow(CandidateList<D>& list) {
    list.ids.resize(2 * list.ids.size());
    list.shift.resize(list.ids.size());
    list.delayed.resize(list.ids.size() + 8);
    return list.ids.data();
  }

  // Fills the lists from the records' cells; inserting from the back leaves every cell's list
  // in increasing index order.
  void insert_all(const HotRecord<D>* hot, std::uint32_t n) {
    grid_.clear();
    if (two_level_) {
      levels_.coarse.clear();
      for (auto k = n; k-- > 0;) {
        if (levels_.big[k] != 0) {
          levels_.coarse.insert(k, coarse_of(hot[k].cell));
        } else {
          grid_.insert(k, hot[k].cell);
        }
      }
      return;
    }
    for (auto k = n; k-- > 0;) grid_.insert(k, hot[k].cell);
  }
  // Particle i moves from cell `from` to cell `to`.
  void move(std::uint32_t i, CellCode from, CellCode to) {
    if (two_level_ && levels_.big[i] != 0) [[unlikely]] {
      const CellCode a = coarse_of(from), b = coarse_of(to);
      if (a != b) {
        levels_.coarse.erase(i, a);
        levels_.coarse.insert(i, b);
      }
      return;
    }
    grid_.erase(i, from);
    grid_.insert(i, to);
  }
  // Every particle listed once, in the cell its record names; fail(message) otherwise. name(i)
  // names particle i in messages.
  template <class Fail, class Name>
  void validate(const HotRecord<D>* hot, std::uint32_t n, Fail&& fail, Name&& name) const;

 private:
  struct Links {
    const std::uint32_t* next;
    std::uint32_t end;
    const HotRecord<D>* hot;
  };
  void gather_vector(CellCode cell, const std::uint8_t* which, int count, CandidateList<D>& list,
                     const HotRecord<D>* hot) const;
  template <bool kTagged>
  void walk_lists(const std::uint32_t* cells, const std::uint32_t* tags, int count,
                  CandidateList<D>& list, const HotRecord<D>* hot) const;
  void append_members(std::uint32_t p, const Links& links, CandidateList<D>& list, std::uint32_t& n,
                      std::uint32_t*& cand, std::uint32_t& cap) const;

  // Two levels: the fine cells within a big particle's reach; the coarse 3^D cells around the
  // coarse cell of fine cell `cell`, appended (both with every candidate's shift written).
  void gather_block(CellCode cell, CandidateList<D>& list, const HotRecord<D>* hot) const;
  void append_coarse(CellCode cell, CandidateList<D>& list, const HotRecord<D>* hot) const;
  // The slot of periodic shift `shift` in list.shifts (added if new); a first nonzero shift
  // writes the zero slot into the candidates listed before it (their slots were not written).
  static std::uint32_t shift_slot(CandidateList<D>& list, const Vec<D>& shift);
  void append_list(std::uint32_t first, std::uint32_t slot, CandidateList<D>& list,
                   std::uint32_t end, const std::uint32_t* next, const HotRecord<D>* hot) const;

  CellGrid<D> grid_;
  bool two_level_ = false;
  Levels levels_;
  bool vector_gather_ = false;
  CandidateList<D> lists_[2];  // last: large (their shift arrays), touched less than the grid
};

// Appends the members of the list starting at p to cand[n...]: walk_lists' rest of a crowded
// cell (from its third member on). The first two links are followed without a branch (an empty
// slot is written but not counted); only a further member takes the loop. Records are
// prefetched so that the cache misses of a whole prediction overlap.
template <int D>
[[gnu::always_inline]] inline void CellNeighbourhood<D>::append_members(
    std::uint32_t p, const Links& links, CandidateList<D>& list, std::uint32_t& n,
    std::uint32_t*& cand, std::uint32_t& cap) const {
  const std::uint32_t* next = links.next;
  const std::uint32_t end = links.end;
  const HotRecord<D>* hot = links.hot;
  for (int unrolled = 0; unrolled < 2; ++unrolled) {
    __builtin_prefetch(hot + p);
    cand[n] = p;
    n += p != end ? 1u : 0u;
    p = next[p];
  }
  for (; p != end; p = next[p]) {
    if (cap - n < kCandidateSlack) [[unlikely]] {
      cand = grow(list);
      cap = static_cast<std::uint32_t>(list.ids.size());
    }
    __builtin_prefetch(hot + p);
    cand[n++] = p;
  }
}

// gather() for the cells numbered which[0 .. count) among the 3^D around `cell` (see
// CellGrid::neighbour's numbering), in that order.
template <int D>
inline void CellNeighbourhood<D>::gather_cells(CellCode cell, const std::uint8_t* which, int count,
                                               CandidateList<D>& list,
                                               const HotRecord<D>* hot) const {
  if (vector_gather_) {
    gather_vector(cell, which, count, list, hot);
    return;
  }
  constexpr int kMost = CellGrid<D>::kNeighbourCells;
  std::uint32_t cells[kMost], tags[kMost];
  if (grid_.interior(cell)) {
    const std::uint32_t centre = grid_.index(cell);
    const std::int32_t* delta = grid_.neighbour_deltas();
    for (int c = 0; c < count; ++c) cells[c] = centre + static_cast<std::uint32_t>(delta[which[c]]);
    list.n_shifts = 1;
    walk_lists<false>(cells, nullptr, count, list, hot);  // no shifts: tags unread
  } else {
    std::uint32_t n_shifts = 1;  // shifts[0] is the zero shift
    for (int c = 0; c < count; ++c) {
      const typename CellGrid<D>::Neighbour nb = grid_.neighbour(cell, which[c]);
      cells[c] = nb.cell;
      tags[c] = nb.shifted ? n_shifts : 0;
      if (nb.shifted) list.shifts[n_shifts++] = nb.shift;
    }
    list.n_shifts = n_shifts;
    walk_lists<true>(cells, tags, count, list, hot);
  }
}

// The members of the lists of cells[0 .. count) as candidates (with their cells' shift numbers
// tags[] when kTagged): every list's head, then every list's second member, then the rest list
// by list, which is the order gather_lists_avx512 writes. Both walks must list the candidates in
// one order: the candidate loops give a tie between two event times (two contacts due at once,
// common in dense granular matter) to the one listed first, so a different order made runs
// differ between CPUs. The first three links of every list are loaded in three waves of
// independent loads (heads, second members, third links), not in a chain per cell, so that each
// wave's cache misses overlap; only crowded cells follow links further.
template <int D>
template <bool kTagged>
void CellNeighbourhood<D>::walk_lists(const std::uint32_t* cells, const std::uint32_t* tags,
                                      int count, CandidateList<D>& list,
                                      const HotRecord<D>* hot) const {
  const std::uint32_t* heads = grid_.heads();
  // Read once: the stores into the candidate list could alias them for the compiler.
  const Links links{grid_.links(), grid_.end(), hot};
  const std::uint32_t* next = links.next;
  const std::uint32_t end = links.end;
  constexpr int kMost = CellGrid<D>::kNeighbourCells;
  std::uint32_t first[kMost], second[kMost], third[kMost];
  for (int c = 0; c < count; ++c) first[c] = heads[cells[c]];
  for (int c = 0; c < count; ++c) second[c] = next[first[c]];  // next[end] is end
  for (int c = 0; c < count; ++c) third[c] = next[second[c]];
  // Two slots per cell are written unchecked (an empty one is overwritten).
  const auto room = [&](int cells_left) {
    return kCandidateSlack + 2 * static_cast<std::uint32_t>(cells_left);
  };
  std::uint32_t n = 0;
  auto cap = static_cast<std::uint32_t>(list.ids.size());
  std::uint32_t* cand = list.ids.data();
  while (cap < room(count)) [[unlikely]] {
      cand = grow(list);
      cap = static_cast<std::uint32_t>(list.ids.size());
    }
  for (const std::uint32_t* wave : {first, second}) {
    for (int c = 0; c < count; ++c) {
      __builtin_prefetch(links.hot + wave[c]);
      cand[n] = wave[c];
      if constexpr (kTagged) list.shift[n] = tags[c];
      n += wave[c] != end ? 1u : 0u;
    }
  }
  for (int c = 0; c < count; ++c) {
    if (third[c] != end) [[unlikely]] {  // a crowded cell: the rest by links
      while (cap - n < room(1)) {
        cand = grow(list);
        cap = static_cast<std::uint32_t>(list.ids.size());
      }
      const std::uint32_t from = n;
      append_members(third[c], links, list, n, cand, cap);
      if constexpr (kTagged) {
        for (std::uint32_t k = from; k < n; ++k) list.shift[k] = tags[c];
      }
    }
  }
  list.count = n;
}

// gather_cells() with AVX-512: the cells' list heads and their successors are fetched and
// compressed sixteen lists at a time; the rare third and later members follow by links.
template <int D>
inline void CellNeighbourhood<D>::gather_vector(CellCode cell, const std::uint8_t* which, int count,
                                                CandidateList<D>& list,
                                                const HotRecord<D>* hot) const {
  constexpr auto kCells = static_cast<std::uint32_t>(CellGrid<D>::kNeighbourCells);
  while (list.ids.size() < 2 * kCells + kCandidateSlack) grow(list);
  std::uint32_t cells[kCells], tags[kCells];
  const bool interior = grid_.interior(cell);
  std::uint32_t n_shifts = 1;  // shifts[0] is the zero shift
  if (interior) {
    const std::uint32_t centre = grid_.index(cell);
    const std::int32_t* delta = grid_.neighbour_deltas();
    for (int c = 0; c < count; ++c) cells[c] = centre + static_cast<std::uint32_t>(delta[which[c]]);
  } else {
    for (int c = 0; c < count; ++c) {
      const typename CellGrid<D>::Neighbour nb = grid_.neighbour(cell, which[c]);
      cells[c] = nb.cell;
      tags[c] = nb.shifted ? n_shifts : 0;
      if (nb.shifted) list.shifts[n_shifts++] = nb.shift;
    }
  }
  const Neighbourhood nb{
      grid_.heads(), grid_.links(), grid_.end(), cells, interior ? nullptr : tags, count};
  std::uint32_t third[kCells], third_tag[kCells];
  std::uint32_t n_third = 0;
  std::uint32_t n =
      gather_lists_avx512(nb, list.ids.data(), list.shift.data(), third, third_tag, n_third);
  for (std::uint32_t k = 0; k < n_third; ++k) {
    for (std::uint32_t p = third[k]; p != grid_.end(); p = grid_.next(p)) {
      if (list.ids.size() - n < kCandidateSlack) [[unlikely]]
        grow(list);
      list.ids[n] = p;
      list.shift[n++] = third_tag[k];
    }
  }
  const std::uint32_t* ids = list.ids.data();
  for (std::uint32_t k = 0; k < n; ++k) __builtin_prefetch(hot + ids[k]);
  list.count = n;
  list.n_shifts = n_shifts;
}

template <int D>
inline std::uint32_t CellNeighbourhood<D>::shift_slot(CandidateList<D>& list, const Vec<D>& shift) {
  bool zero = true;
  for (int a = 0; a < D; ++a) zero = zero && shift[a] == 0.0;
  if (zero) return 0;
  for (std::uint32_t k = 1; k < list.n_shifts; ++k) {
    bool same = true;
    for (int a = 0; a < D; ++a) same = same && list.shifts[k][a] == shift[a];
    if (same) return k;
  }
  if (list.n_shifts == 1) {  // the slots of the candidates so far were not written
    for (std::uint32_t k = 0; k < list.count; ++k) list.shift[k] = 0;
  }
  list.shifts[list.n_shifts] = shift;
  return list.n_shifts++;
}

template <int D>
inline void CellNeighbourhood<D>::append_list(std::uint32_t first, std::uint32_t slot,
                                              CandidateList<D>& list, std::uint32_t end,
                                              const std::uint32_t* next,
                                              const HotRecord<D>* hot) const {
  for (std::uint32_t p = first; p != end; p = next[p]) {
    if (list.ids.size() - list.count < kCandidateSlack) [[unlikely]]
      grow(list);
    __builtin_prefetch(hot + p);
    list.ids[list.count] = p;
    list.shift[list.count++] = slot;
  }
}

template <int D>
void CellNeighbourhood<D>::gather_block(CellCode cell, CandidateList<D>& list,
                                        const HotRecord<D>* hot) const {
  list.count = 0;
  list.n_shifts = 1;
  list.shifts[0] = Vec<D>{};
  std::array<int, D> base, off, at;
  for (int a = 0; a < D; ++a) {
    base[a] = grid_.coordinate(cell, a);
    off[a] = -levels_.reach[a];
  }
  while (true) {
    Vec<D> shift{};
    for (int a = 0; a < D; ++a) {
      const int n = grid_.cells_along(a);
      at[a] = base[a] + off[a];
      if (at[a] < 0) {
        at[a] += n;
        shift[a] = -levels_.box[a];
      } else if (at[a] >= n) {
        at[a] -= n;
        shift[a] = levels_.box[a];
      }
    }
    const std::uint32_t slot = shift_slot(list, shift);
    append_list(grid_.first(grid_.index(grid_.code_at(at))), slot, list, grid_.end(), grid_.links(),
                hot);
    int a = 0;
    for (; a < D; ++a) {
      if (++off[a] <= levels_.reach[a]) break;
      off[a] = -levels_.reach[a];
    }
    if (a == D) break;
  }
}

template <int D>
void CellNeighbourhood<D>::append_coarse(CellCode cell, CandidateList<D>& list,
                                         const HotRecord<D>* hot) const {
  const CellGrid<D>& coarse = levels_.coarse;
  const CellCode home = coarse_of(cell);
  for (int n = 0; n < CellGrid<D>::kNeighbourCells; ++n) {
    const typename CellGrid<D>::Neighbour nb = coarse.neighbour(home, n);
    const std::uint32_t first = coarse.first(nb.cell);
    if (first == coarse.end()) continue;
    const std::uint32_t slot = nb.shifted ? shift_slot(list, nb.shift) : 0;
    append_list(first, slot, list, coarse.end(), coarse.links(), hot);
  }
}

template <int D>
template <class Fail, class Name>
void CellNeighbourhood<D>::validate(const HotRecord<D>* hot, std::uint32_t n, Fail&& fail,
                                    Name&& name) const {
  std::vector<std::uint32_t> listed(n, 0);
  for (std::uint32_t c = 0; c < grid_.cell_count(); ++c) {
    std::uint32_t steps = 0;
    for (std::uint32_t p = grid_.first(c); p != grid_.end(); p = grid_.next(p)) {
      if (p >= n || ++steps > n) fail("cell " + std::to_string(c) + " has a broken list");
      if (grid_.index(hot[p].cell) != c)
        fail("particle " + name(p) + " listed in a cell it is not in");
      if (big(p)) fail("big particle " + name(p) + " listed in a fine cell");
      ++listed[p];
    }
  }
  const CellGrid<D>& coarse = levels_.coarse;
  for (std::uint32_t c = 0; two_level_ && c < coarse.cell_count(); ++c) {
    std::uint32_t steps = 0;
    for (std::uint32_t p = coarse.first(c); p != coarse.end(); p = coarse.next(p)) {
      if (p >= n || ++steps > n) fail("coarse cell " + std::to_string(c) + " has a broken list");
      if (!big(p)) fail("small particle " + name(p) + " listed in a coarse cell");
      if (coarse.index(coarse_of(hot[p].cell)) != c)
        fail("particle " + name(p) + " listed in a coarse cell it is not in");
      ++listed[p];
    }
  }
  for (std::uint32_t i = 0; i < n; ++i) {
    if (listed[i] != 1)
      fail("particle " + name(i) + " listed " + std::to_string(listed[i]) + " times");
  }
}

}  // namespace kairos
