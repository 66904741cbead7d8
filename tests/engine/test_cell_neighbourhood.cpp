// The neighbourhood walk (engine/cell_neighbourhood.hpp): the candidates gathered from the 3^D
// cells around a particle (or some of them) with each one's periodic image, against brute force
// over every particle, by the scalar walk and the AVX-512 one; the lists' storage, particles
// moving between cells, and the component's own check.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/cell_neighbourhood.hpp"

namespace kairos {
namespace {

template <bool kVector>
void gathers_exactly_the_neighbour_cells() {
  const Vec<3> box{6.0, 5.0, 4.0};
  const CellGrid<3> grid(box, Vec<3>{1.0, 1.0, 1.0}, {true, true, true}, 400);
  CellNeighbourhood<3> cells(grid, kVector);
  std::mt19937_64 rng(5);
  std::vector<HotRecord<3>> hot(400);
  for (auto& h : hot) {
    for (int a = 0; a < 3; ++a) h.pos[a] = std::uniform_real_distribution<double>(0.0, box[a])(rng);
    h.cell = grid.locate(h.pos);
  }
  cells.insert_all(hot.data(), 400);
  for (std::uint32_t i = 0; i < 400; i += 7) {
    CandidateList<3>& list = cells.list(0);
    cells.gather(hot[i].cell, list, hot.data());
    std::multiset<std::uint32_t> got(list.ids.begin(), list.ids.begin() + list.count);
    std::multiset<std::uint32_t> expected;
    for (std::uint32_t j = 0; j < 400; ++j) {
      std::array<int, 3> d;
      if (grid.neighbour_offset(hot[i].cell, hot[j].cell, d)) expected.insert(j);
    }
    ASSERT_EQ(got, expected) << "particle " << i;
    // Each candidate's shift makes it the image next to i.
    for (std::uint32_t k = 0; k < list.count; ++k) {
      const Vec<3> shift = list.n_shifts > 1 ? list.shifts[list.shift[k]] : Vec<3>{};
      for (int a = 0; a < 3; ++a)
        EXPECT_LE(std::abs(hot[i].pos[a] - (hot[list.ids[k]].pos[a] + shift[a])), 2.0 + 1e-12);
    }
  }
  int failures = 0;
  auto fail = [&](const std::string&) { ++failures; };
  auto name = [](std::uint32_t i) { return std::to_string(i); };
  cells.validate(hot.data(), 400, fail, name);
  EXPECT_EQ(failures, 0);
  hot[3].cell = grid.locate({0.5, 0.5, 0.5}) == hot[3].cell ? grid.locate({5.5, 4.5, 3.5})
                                                            : grid.locate({0.5, 0.5, 0.5});
  cells.validate(hot.data(), 400, fail, name);
  EXPECT_GT(failures, 0);  // listed in a cell its record does not name
}

TEST(CellNeighbourhood, GathersExactlyTheNeighbourCellsWithTheirImages) {
  gathers_exactly_the_neighbour_cells<false>();
}

TEST(CellNeighbourhood, TheVectorGatherListsTheSameCandidates) {
  if (!cpu_has_avx512()) GTEST_SKIP() << "no AVX-512 on this CPU";
  gathers_exactly_the_neighbour_cells<true>();
}

// --- brute force ----------------------------------------------------------------------------

// Particles at random positions in `box`, each record naming its cell.
template <int D>
std::vector<HotRecord<D>> scattered(const CellGrid<D>& grid, const Vec<D>& box, std::uint32_t n,
                                    unsigned seed) {
  std::mt19937_64 rng(seed);
  std::vector<HotRecord<D>> hot(n);
  for (auto& h : hot) {
    for (int a = 0; a < D; ++a) h.pos[a] = std::uniform_real_distribution<double>(0.0, box[a])(rng);
    h.vel = Vec<D>{};
    h.time = 0.0;
    h.collisions = 0;
    h.cell = grid.locate(h.pos);
  }
  return hot;
}

// The candidates a gather around `cell` must list, by brute force over all particles: those in
// a neighbouring cell (offset d, each component in {-1, 0, 1} after wrapping periodic axes) for
// which keep(d) holds, each with the shift that carries its cell next to `cell`: L_a times the
// number of box lengths between the unwrapped neighbour (c_a + d_a) and the cell itself.
template <int D, class Keep>
std::map<std::uint32_t, Vec<D>> expected_candidates(const CellGrid<D>& grid, const Vec<D>& box,
                                                    const std::vector<HotRecord<D>>& hot,
                                                    CellCode cell, Keep&& keep) {
  std::map<std::uint32_t, Vec<D>> out;
  for (std::uint32_t j = 0; j < hot.size(); ++j) {
    std::array<int, D> d;
    if (!grid.neighbour_offset(cell, hot[j].cell, d) || !keep(d)) continue;
    Vec<D> shift{};
    for (int a = 0; a < D; ++a) {
      const int unwrapped = grid.coordinate(cell, a) + d[a];
      shift[a] = box[a] * ((unwrapped - grid.coordinate(hot[j].cell, a)) / grid.cells_along(a));
    }
    out[j] = shift;
  }
  return out;
}

// The list as candidate -> shift, failing on a candidate listed twice.
template <int D>
std::map<std::uint32_t, Vec<D>> listed(const CandidateList<D>& list) {
  std::map<std::uint32_t, Vec<D>> out;
  for (std::uint32_t k = 0; k < list.count; ++k) {
    const Vec<D> shift = list.n_shifts > 1 ? list.shifts[list.shift[k]] : Vec<D>{};
    EXPECT_TRUE(out.emplace(list.ids[k], shift).second) << "listed twice: " << list.ids[k];
  }
  return out;
}

template <int D>
void expect_same(const std::map<std::uint32_t, Vec<D>>& got,
                 const std::map<std::uint32_t, Vec<D>>& want, CellCode cell) {
  ASSERT_EQ(got.size(), want.size()) << "cell " << cell;
  for (const auto& [j, shift] : want) {
    const auto it = got.find(j);
    ASSERT_NE(it, got.end()) << "cell " << cell << " misses " << j;
    for (int a = 0; a < D; ++a) EXPECT_EQ(it->second[a], shift[a]) << "cell " << cell << " " << j;
  }
}

// The one order both walks list candidates in (engine/cell_neighbourhood.hpp, walk_lists):
// the head of each cell's list (cells in `which` order), then each list's second member, then
// the rest list by list. Candidate loops give a tie to the candidate listed first, so an order
// of its own in one walk would make runs differ between CPUs.
template <int D>
std::vector<std::uint32_t> walk_order(const CellGrid<D>& grid, CellCode cell,
                                      const std::uint8_t* which, int count) {
  std::vector<std::vector<std::uint32_t>> members(static_cast<std::size_t>(count));
  for (int c = 0; c < count; ++c)
    for (std::uint32_t p = grid.first(grid.neighbour(cell, which[c]).cell); p != grid.end();
         p = grid.next(p))
      members[c].push_back(p);
  std::vector<std::uint32_t> order;
  for (const std::size_t rank : {0u, 1u})
    for (const auto& m : members)
      if (m.size() > rank) order.push_back(m[rank]);
  for (const auto& m : members)
    order.insert(order.end(), m.begin() + std::min<std::size_t>(2, m.size()), m.end());
  return order;
}

template <int D>
void expect_walk_order(const CandidateList<D>& list, const std::vector<std::uint32_t>& order,
                       CellCode cell) {
  const std::vector<std::uint32_t> got(list.ids.begin(), list.ids.begin() + list.count);
  EXPECT_EQ(got, order) << "cell " << cell;
}

// Every cell of a grid (interior, faces, edges, corners) gathers by brute force's rule.
template <int D>
void every_cell_gathers_by_brute_force(const Vec<D>& box, const std::array<bool, D>& periodic,
                                       std::uint32_t n, bool vector_gather) {
  Vec<D> width;
  for (int a = 0; a < D; ++a) width[a] = 1.0;
  const CellGrid<D> grid(box, width, periodic, n, 10.0);
  CellNeighbourhood<D> cells(grid, vector_gather);
  const std::vector<HotRecord<D>> hot = scattered(grid, box, n, 23);
  cells.insert_all(hot.data(), n);
  const auto all = [](const std::array<int, D>&) { return true; };
  int shifted = 0;
  for (std::uint32_t c = 0; c < grid.cell_count(); ++c) {
    std::array<int, D> at;
    std::uint32_t rest = c;
    for (int a = 0; a < D; ++a) {
      at[a] = static_cast<int>(rest % static_cast<std::uint32_t>(grid.cells_along(a)));
      rest /= static_cast<std::uint32_t>(grid.cells_along(a));
    }
    const CellCode cell = grid.code_at(at);
    CandidateList<D>& list = cells.list(c % 2);
    cells.gather(cell, list, hot.data());
    const auto want = expected_candidates(grid, box, hot, cell, all);
    expect_same<D>(listed(list), want, cell);
    expect_walk_order<D>(list,
                         walk_order(cells.grid(), cell, CellNeighbourhood<D>::kAllNeighbours.data(),
                                    CellGrid<D>::kNeighbourCells),
                         cell);
    for (const auto& [j, shift] : want)
      for (int a = 0; a < D; ++a) shifted += shift[a] != 0.0;
  }
  EXPECT_GT(shifted, 0);  // images across the faces were compared
}

TEST(CellNeighbourhood, EveryCellOfAPeriodicBoxGathersByBruteForce) {
  // 5 x 4 x 3 cells, ~4 particles a cell (crowded cells walk past their second member).
  for (const bool vector : {false, true}) {
    if (vector && !cpu_has_avx512()) continue;
    SCOPED_TRACE(vector ? "vector" : "scalar");
    every_cell_gathers_by_brute_force<3>({5.0, 4.0, 3.0}, {true, true, true}, 240, vector);
    every_cell_gathers_by_brute_force<2>({7.0, 3.0}, {true, true}, 90, vector);
  }
}

// Beyond a wall (a non-periodic axis) there is nothing: no candidate from the far side, no
// image shifted along that axis.
TEST(CellNeighbourhood, NothingIsGatheredBeyondAWall) {
  for (const bool vector : {false, true}) {
    if (vector && !cpu_has_avx512()) continue;
    SCOPED_TRACE(vector ? "vector" : "scalar");
    every_cell_gathers_by_brute_force<3>({4.0, 4.0, 5.0}, {true, true, false}, 300, vector);
    every_cell_gathers_by_brute_force<2>({3.0, 6.0}, {false, true}, 80, vector);
  }
}

// After a crossing the engine gathers only the layer of cells new to the particle: the 3^(D-1)
// cells one step along the axis on the side it moved to.
TEST(CellNeighbourhood, ALayerGathersOnlyTheCellsOneStepAlongAnAxis) {
  const Vec<3> box{4.0, 5.0, 3.0};
  const CellGrid<3> grid(box, Vec<3>{1.0, 1.0, 1.0}, {true, true, true}, 200, 10.0);
  const std::vector<HotRecord<3>> hot = scattered(grid, box, 200, 29);
  for (const bool vector : {false, true}) {
    if (vector && !cpu_has_avx512()) continue;
    SCOPED_TRACE(vector ? "vector" : "scalar");
    CellNeighbourhood<3> cells(grid, vector);
    cells.insert_all(hot.data(), 200);
    for (const CellCode cell : {grid.code_at({0, 0, 0}), grid.code_at({1, 2, 1}),
                                grid.code_at({3, 4, 2}), grid.code_at({2, 0, 1})}) {
      for (int axis = 0; axis < 3; ++axis) {
        for (const int sign : {-1, 1}) {
          CandidateList<3>& list = cells.list(0);
          cells.gather_cells(cell, grid.layer(axis, sign), CellGrid<3>::kLayerCells, list,
                             hot.data());
          const auto want = expected_candidates(
              grid, box, hot, cell, [&](const std::array<int, 3>& d) { return d[axis] == sign; });
          expect_same<3>(listed(list), want, cell);
          expect_walk_order<3>(
              list,
              walk_order(cells.grid(), cell, grid.layer(axis, sign), CellGrid<3>::kLayerCells),
              cell);
        }
      }
    }
  }
}

// A list starts with room for 256 candidates; a crowded neighbourhood grows it, keeping the
// per-candidate arrays in step (the shift of each, and the scratch of the loops with 8 more).
TEST(CellNeighbourhood, ACrowdedNeighbourhoodGrowsTheList) {
  CandidateList<3> fresh;
  CellNeighbourhood<3>::size_list(fresh);
  EXPECT_EQ(fresh.ids.size(), 256u);
  EXPECT_EQ(fresh.shift.size(), fresh.ids.size());
  EXPECT_EQ(fresh.delayed.size(), fresh.ids.size() + 8);
  // 3 x 3 x 3 cells: every cell is a neighbour of every other, so every gather lists all 1000.
  const Vec<3> box{3.0, 3.0, 3.0};
  const std::uint32_t n = 1000;
  const CellGrid<3> grid(box, Vec<3>{1.0, 1.0, 1.0}, {true, true, true}, n);
  ASSERT_EQ(grid.cell_count(), 27u);
  const std::vector<HotRecord<3>> hot = scattered(grid, box, n, 31);
  const auto all = [](const std::array<int, 3>&) { return true; };
  for (const bool vector : {false, true}) {
    if (vector && !cpu_has_avx512()) continue;
    SCOPED_TRACE(vector ? "vector" : "scalar");
    CellNeighbourhood<3> cells(grid, vector);
    EXPECT_EQ(cells.list(0).ids.size(), 256u);  // the lists it owns start sized
    EXPECT_EQ(cells.list(1).delayed.size(), 256u + 8);
    cells.insert_all(hot.data(), n);
    for (const CellCode cell : {grid.code_at({0, 0, 0}), grid.code_at({1, 1, 1})}) {
      CandidateList<3>& list = cells.list(1);
      cells.gather(cell, list, hot.data());
      EXPECT_EQ(list.count, n);
      expect_same<3>(listed(list), expected_candidates(grid, box, hot, cell, all), cell);
      EXPECT_GE(list.ids.size(), list.count);
      EXPECT_EQ(list.shift.size(), list.ids.size());
      EXPECT_EQ(list.delayed.size(), list.ids.size() + 8);
    }
  }
}

// Filled from the records, every cell lists its members in increasing index order; a particle
// moved to another cell is gathered there and no longer where it was.
TEST(CellNeighbourhood, MovesKeepTheListsInStepWithTheRecords) {
  const Vec<3> box{6.0, 6.0, 6.0};
  const std::uint32_t n = 150;
  const CellGrid<3> grid(box, Vec<3>{1.0, 1.0, 1.0}, {true, true, true}, n, 10.0);
  CellNeighbourhood<3> cells(grid, false);
  std::vector<HotRecord<3>> hot = scattered(grid, box, n, 37);
  cells.insert_all(hot.data(), n);
  for (std::uint32_t c = 0; c < grid.cell_count(); ++c) {
    std::uint32_t previous = 0, members = 0;
    for (std::uint32_t p = cells.grid().first(c); p != cells.grid().end();
         p = cells.grid().next(p), ++members) {
      if (members > 0) {
        EXPECT_GT(p, previous) << "cell " << c;
      }
      previous = p;
    }
  }
  // Particle 7 moves to the cell opposite its own (3 cells away along every axis): out of its
  // old neighbourhood, into the new one.
  const CellCode from = hot[7].cell;
  std::array<int, 3> to_at;
  for (int a = 0; a < 3; ++a) to_at[a] = (grid.coordinate(from, a) + 3) % 6;
  const CellCode to = grid.code_at(to_at);
  cells.move(7, from, to);
  hot[7].cell = to;
  const auto gathered = [&](CellCode around) {
    CandidateList<3>& list = cells.list(0);
    cells.gather(around, list, hot.data());
    return listed(list);
  };
  EXPECT_EQ(gathered(to).count(7), 1u);
  EXPECT_EQ(gathered(from).count(7), 0u);
  int failures = 0;
  cells.validate(
      hot.data(), n, [&](const std::string&) { ++failures; },
      [](std::uint32_t i) { return std::to_string(i); });
  EXPECT_EQ(failures, 0);
}

// validate() names a particle missing from the lists, and a list that loops (the engine's
// fail() throws, which ends the walk).
TEST(CellNeighbourhood, ValidateCatchesAMissingParticleAndALoopingList) {
  const Vec<3> box{5.0, 5.0, 5.0};
  const std::uint32_t n = 100;
  const CellGrid<3> grid(box, Vec<3>{1.0, 1.0, 1.0}, {true, true, true}, n, 10.0);
  CellNeighbourhood<3> cells(grid, false);
  const std::vector<HotRecord<3>> hot = scattered(grid, box, n, 41);
  cells.insert_all(hot.data(), n);
  std::vector<std::string> faults;
  auto name = [](std::uint32_t i) { return std::to_string(i); };
  cells.validate(
      hot.data(), n, [&](const std::string& m) { faults.push_back(m); }, name);
  EXPECT_TRUE(faults.empty());
  cells.grid().erase(42, hot[42].cell);
  cells.validate(
      hot.data(), n, [&](const std::string& m) { faults.push_back(m); }, name);
  ASSERT_EQ(faults.size(), 1u);
  EXPECT_NE(faults[0].find("particle 42 listed 0 times"), std::string::npos) << faults[0];
  // The head of a cell's list, inserted there again, links to itself.
  cells.grid().insert(42, hot[42].cell);
  const std::uint32_t head = cells.grid().first(grid.index(hot[0].cell));
  cells.grid().insert(head, hot[head].cell);
  const auto throwing = [](const std::string& m) { throw std::runtime_error(m); };
  try {
    cells.validate(hot.data(), n, throwing, name);
    ADD_FAILURE() << "a looping list passed";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("broken list"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace kairos
