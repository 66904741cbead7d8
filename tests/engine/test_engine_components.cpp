// The event engine's components, each alone: the typed event code (whose bits restart files
// store), the relative-motion helper of the candidate loops, the resting-particle rules, the
// soft contacts in progress and the neighbourhood walk.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "boundaries/lees_edwards.hpp"
#include "core/event_code.hpp"
#include "dynamics/collision_time.hpp"
#include "engine/cell_neighbourhood.hpp"
#include "engine/pair_steps.hpp"
#include "engine/relative_motion.hpp"
#include "engine/resting_particles.hpp"
#include "engine/soft_contact_state.hpp"

namespace kairos {
namespace {

// --- EventCode ------------------------------------------------------------------------------

TEST(EventCode, BitsAreTheStoredFormat) {
  using Code = EventCode<3>;
  EXPECT_EQ(Code::collision(5).bits(), 5u);
  EXPECT_EQ(Code::crossing().bits(), 0xffffffffu);
  EXPECT_EQ(Code::wall(0).bits(), 0xffffffffu - 6u);
  EXPECT_EQ(Code::wall(5).bits(), 0xffffffffu - 1u);
  EXPECT_EQ(Code::release().bits(), 0xffffffffu - 7u);
  EXPECT_EQ(Code::crossing_keeping_none().bits(), 0xffffffffu - 8u);
  EXPECT_EQ(Code::crossing_keeping(3).bits(), 0x80000003u);
  EXPECT_EQ(EventCode<2>::wall(3).bits(), 0xffffffffu - 1u);
  EXPECT_EQ(EventCode<2>::release().bits(), 0xffffffffu - 5u);
}

TEST(EventCode, PredicatesNameEachKindOnce) {
  using Code = EventCode<3>;
  const Code codes[] = {Code::collision(7),
                        Code::crossing(),
                        Code::crossing_keeping(7),
                        Code::crossing_keeping_none(),
                        Code::wall(2),
                        Code::release()};
  for (const Code c : codes) {
    const int kinds = c.is_collision() + c.is_crossing() + c.is_wall() + c.is_release();
    EXPECT_EQ(kinds, 1) << c.bits();
  }
  EXPECT_TRUE(Code::crossing_keeping(7).keeps_contact());
  EXPECT_EQ(Code::crossing_keeping(7).kept_partner(), 7u);
  EXPECT_TRUE(Code::crossing_keeping_none().keeps_nothing());
  EXPECT_TRUE(Code::crossing().is_full_scan_crossing());
  EXPECT_EQ(Code::wall(4).wall_face(), 4);
  EXPECT_EQ(Code::from_bits(Code::wall(4).bits()), Code::wall(4));
}

TEST(EventCode, RenumberingMovesParticlesOnly) {
  using Code = EventCode<3>;
  const auto plus_ten = [](std::uint32_t p) { return p + 10; };
  EXPECT_EQ(Code::collision(1).renumbered(plus_ten), Code::collision(11));
  EXPECT_EQ(Code::crossing_keeping(1).renumbered(plus_ten), Code::crossing_keeping(11));
  EXPECT_EQ(Code::wall(1).renumbered(plus_ten), Code::wall(1));
  EXPECT_EQ(Code::release().renumbered(plus_ten), Code::release());
  EXPECT_TRUE(Code::valid_bits(Code::collision(9).bits(), 10));
  EXPECT_FALSE(Code::valid_bits(Code::collision(10).bits(), 10));
  EXPECT_FALSE(Code::valid_bits(Code::crossing_keeping(10).bits(), 10));
  EXPECT_TRUE(Code::valid_bits(Code::wall(3).bits(), 10));
}

// --- relative motion ------------------------------------------------------------------------

TEST(RelativeMotion, ContactTimeOfAHeadOnPair) {
  // j at rest 3 to the right of i, i moving at 2: contact at distance 1 after 1.
  const double rec[7] = {3.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
  const RelativeMotion m = relative_motion_at<3>({0.0, 0.0, 0.0}, {2.0, 0.0, 0.0}, rec, 0.0, {});
  EXPECT_DOUBLE_EQ(m.r2, 9.0);
  EXPECT_DOUBLE_EQ(m.rg, -6.0);
  EXPECT_DOUBLE_EQ(m.g2, 4.0);
  double dt;
  ASSERT_TRUE(contact_before(m, 1.0, kNever, dt));
  EXPECT_DOUBLE_EQ(dt, 1.0);
  EXPECT_FALSE(contact_before(m, 1.0, 0.5, dt));  // not before the best so far
  // Receding: never.
  const RelativeMotion away =
      relative_motion_at<3>({0.0, 0.0, 0.0}, {-2.0, 0.0, 0.0}, rec, 0.0, {});
  EXPECT_FALSE(contact_before(away, 1.0, kNever, dt));
}

TEST(RelativeMotion, AgreesWithTheQuadraticOfCollisionTime) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int compared = 0;
  for (int k = 0; k < 20000; ++k) {
    const Vec<3> xi{u(rng), u(rng), u(rng)}, vi{u(rng), u(rng), u(rng)};
    const double rec[7] = {2 * u(rng), 2 * u(rng), 2 * u(rng), u(rng), u(rng), u(rng), 0.0};
    const double dtj = std::abs(u(rng));
    const Vec<3> shift{0.0, 0.0, 0.0};
    const RelativeMotion m = relative_motion_at<3>(xi, vi, rec, dtj, shift);
    Vec<3> r, g;
    for (int a = 0; a < 3; ++a) {
      r[a] = xi[a] - (rec[a] + rec[3 + a] * dtj);
      g[a] = vi[a] - rec[3 + a];
    }
    double dt;
    const double expected = pair_contact_time<3>(r.data(), g.data(), 0.5);
    if (contact_before(m, 0.25, kNever, dt)) {
      EXPECT_EQ(dt, expected);  // the same bits: the two forms differ by exact factors of 2
      ++compared;
    } else {
      EXPECT_EQ(expected, kNever);
    }
  }
  EXPECT_GT(compared, 200);
}

TEST(RelativeMotion, GravityLeavesThePairAStraightLine) {
  const double half_g[3] = {0.0, 0.0, -0.5}, g[3] = {0.0, 0.0, -1.0};
  const double rec[7] = {1.0, 2.0, 3.0, 0.5, -0.25, 0.75, 0.0};
  const double dtj = 0.8;
  const Vec<3> xi{0.0, 0.0, 0.0};
  // i under gravity too: its relative motion to j is that without gravity.
  const RelativeMotion with =
      relative_motion_at<3, true>(xi, {0.1, 0.2, 0.3 - dtj}, rec, dtj, {}, half_g, g);
  EXPECT_NEAR(with.rg, relative_motion_at<3>(xi, {0.1, 0.2, 0.3}, rec, dtj, {0.0, 0.0, -0.32}).rg,
              1e-12);
}

// --- resting particles ----------------------------------------------------------------------

TEST(RestingParticles, TheRulesAfterAContactWithASupport) {
  const Vec<3> g{0.0, 0.0, -1.0};
  const RestingParticles<3> rest(4, 0.1, g);
  const Vec<3> up{0.0, 0.0, 1.0}, side{1.0, 0.0, 0.0}, still{};
  auto never = [] { return false; };
  auto supported = [] { return true; };
  using Settle = RestingParticles<3>::Settle;
  // Slow on the floor: sleeps.
  EXPECT_EQ(rest.settle({0.01, 0.0, 0.02}, up, still, false, never).kind, Settle::kSleep);
  // A real bounce: nothing.
  EXPECT_EQ(rest.settle({0.0, 0.0, 0.5}, up, still, false, never).kind, Settle::kNothing);
  // Wedged: sleeps, however fast.
  EXPECT_EQ(rest.settle({0.0, 0.0, 0.5}, up, still, true, never).kind, Settle::kSleep);
  // Slow against a side support, something underneath holding it: sleeps; nothing under it and
  // gravity not pressing it into the side: nothing.
  EXPECT_EQ(rest.settle({0.05, 0.0, 0.0}, side, still, false, supported).kind, Settle::kSleep);
  EXPECT_EQ(rest.settle({0.05, 0.0, 0.0}, side, still, false, never).kind, Settle::kNothing);
  // On a sliding support, slow: leaves with half the sleep speed along the normal.
  const Settle s = rest.settle({0.2, 0.0, 0.0}, up, {0.2, 0.0, 0.0}, false, never);
  ASSERT_EQ(s.kind, Settle::kLift);
  EXPECT_DOUBLE_EQ(s.lift, 0.05);
  // Off: nothing ever.
  EXPECT_EQ(RestingParticles<3>().settle({0.0, 0.0, 0.0}, up, still, true, never).kind,
            Settle::kNothing);
  EXPECT_TRUE(rest.hit_wakes(-0.1));
  EXPECT_FALSE(rest.hit_wakes(-0.09));
  EXPECT_TRUE(rest.holds_up({0.0, 0.6, 0.8}));
  EXPECT_FALSE(rest.holds_up({0.0, 0.9, std::sqrt(0.19)}));
}

TEST(RestingParticles, StateFollowsRestoreAndRenumbering) {
  RestingParticles<3> rest(4, 0.1, {0.0, 0.0, -1.0});
  const std::vector<std::uint8_t> stored{0, 1, 0, 1};
  const std::vector<std::uint32_t> id{3, 2, 1, 0};  // engine k is the caller's id[k]
  rest.restore(stored, id);
  EXPECT_EQ(rest.count(), 2u);
  EXPECT_TRUE(rest.asleep(0));  // caller's 3
  EXPECT_TRUE(rest.asleep(2));  // caller's 1
  std::vector<bool> done;
  rest.permute({1, 0, 3, 2}, done);
  EXPECT_TRUE(rest.asleep(1));
  EXPECT_TRUE(rest.asleep(3));
  EXPECT_FALSE(rest.asleep(0));
  const std::uint32_t ids[2] = {0, 3};
  EXPECT_TRUE(rest.any_of(ids, 2));
  rest.wake(3);
  EXPECT_FALSE(rest.any_of(ids, 2));
  EXPECT_EQ(rest.count(), 1u);
}

// --- soft contacts in progress --------------------------------------------------------------

TEST(SoftContactState, ReleasesAndRenumbering) {
  SoftContactState<3> soft(100, /*defer=*/true);
  EXPECT_TRUE(soft.defers());
  soft.begin(5, 70);
  soft.begin(70, 5);
  soft.schedule_release(5, 2.0, {1.0, 0.0, 0.0});
  soft.schedule_release(70, 2.0, {-1.0, 0.0, 0.0});
  EXPECT_TRUE(soft.awaits_release(5));
  EXPECT_TRUE(soft.awaits_release(70));
  EXPECT_FALSE(soft.awaits_release(6));
  // Renumbered: 5 <-> 70 swap places.
  std::vector<std::uint32_t> order(100), new_index(100);
  std::iota(order.begin(), order.end(), 0u);
  std::swap(order[5], order[70]);
  for (std::uint32_t k = 0; k < 100; ++k) new_index[order[k]] = k;
  soft.renumber_partners(new_index, 0x80000000u);
  std::vector<bool> done;
  soft.permute(order, done);
  EXPECT_EQ(soft.partner(70), 5u);  // the old 5, now 70, is still with the old 70, now 5
  EXPECT_EQ(soft.partner(5), 70u);
  EXPECT_EQ(soft.release_velocity(70)[0], 1.0);
  EXPECT_TRUE(soft.awaits_release(70));
  soft.end_release(70);
  EXPECT_FALSE(soft.awaits_release(70));
  EXPECT_EQ(soft.partner(70), SoftContactState<3>::kNone);
  EXPECT_EQ(soft.release_time(70), kNever);
  // A deferred contact keeps no release bit.
  soft.set_deferred(5, true);
  soft.rebuild_awaiting_release();
  EXPECT_FALSE(soft.awaits_release(5));
}

// --- the neighbourhood walk -----------------------------------------------------------------

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

TEST(ComponentValidation, EachComponentChecksItsOwnState) {
  int failures = 0;
  auto fail = [&](const std::string&) { ++failures; };
  auto name = [](std::uint32_t k) { return std::to_string(k); };
  RestingParticles<3> rest(3, 0.1, {0.0, 0.0, -1.0});
  rest.fall_asleep(1);
  rest.validate([](std::uint32_t) { return Vec<3>{}; }, fail, name);
  EXPECT_EQ(failures, 0);
  rest.validate([](std::uint32_t k) { return Vec<3>{k == 1 ? 1e-9 : 0.0, 0.0, 0.0}; }, fail, name);
  EXPECT_EQ(failures, 1);  // a sleeper that moves

  failures = 0;
  auto live = [](std::uint32_t) { return false; };
  SoftContactState<3> soft(4, true);
  soft.begin(0, 2);
  soft.begin(2, 0);
  soft.schedule_release(0, 1.0, {});
  soft.schedule_release(2, 1.0, {});
  soft.validate(0x80000000u, live, fail, name);
  EXPECT_EQ(failures, 0);
  soft.begin(3, 1);  // one-sided, and no release bit for a frozen contact
  soft.validate(0x80000000u, live, fail, name);
  EXPECT_EQ(failures, 2);
}

// --- stepped zones: the capture map ---------------------------------------------------------

TEST(PairSteps, TheMapListsPairsUnderBothParticlesAndCountsTheEnergyExactly) {
  // One species, a square well of depth 1 from 1 to 1.5: zone 1 is inside the well.
  const PairSteps fresh({square_well(1.0, 1.5, 1.0)}, {0}, 1, 6);
  PairSteps steps = fresh;
  EXPECT_EQ(steps.check(), "");
  steps.set(0, 3, {0, 1});
  steps.set(2, 3, {0, 1});
  steps.set(4, 5, {0, 1});
  EXPECT_EQ(steps.check(), "");
  EXPECT_DOUBLE_EQ(steps.energy(), -3.0);
  EXPECT_EQ(steps.find(3, 0, PairSteps::kHard).zone, 1);
  EXPECT_EQ(steps.entry_count(3), 2u);
  // Leaving the well unlists the pair under both particles.
  steps.set(3, 0, {0, 0});
  EXPECT_EQ(steps.entry_count(0), 0u);
  EXPECT_EQ(steps.entry_count(3), 1u);
  EXPECT_DOUBLE_EQ(steps.energy(), -2.0);
  EXPECT_EQ(steps.check(), "");
  // Renumbered (reversed), the same pairs under their new numbers.
  steps.renumber({5, 4, 3, 2, 1, 0});
  EXPECT_EQ(steps.check(), "");
  EXPECT_EQ(steps.find(3, 2, PairSteps::kHard).zone, 1);  // was (2, 3)
  EXPECT_EQ(steps.find(1, 0, PairSteps::kHard).zone, 1);  // was (4, 5)
  steps.load(1);
  EXPECT_EQ(steps.lookup(0, PairSteps::kHard).zone, 1);
  EXPECT_EQ(steps.lookup(2, 0).zone, 0);  // not listed: zone 0 of the given table
  // Exported under the original numbers (internal k was particle 5 - k), sorted by them.
  const std::uint32_t id[6] = {5, 4, 3, 2, 1, 0};
  const std::vector<PairZone> zones = steps.export_zones(id);
  ASSERT_EQ(zones.size(), 2u);
  EXPECT_EQ(zones[0].i, 2u);
  EXPECT_EQ(zones[0].j, 3u);
  EXPECT_EQ(zones[1].i, 4u);
  EXPECT_EQ(zones[1].j, 5u);
}

TEST(LeesEdwards, ChecksItsOwnStep) {
  const Vec<3> box{8.0, 6.0, 4.0};
  const CellGrid<3> grid(box, Vec<3>{1.0, 1.0, 1.0}, {true, true, true}, 1000);
  LeesEdwards<3> le(0.1, box, grid, 0.0);
  EXPECT_EQ(le.check(0.0), "");
  EXPECT_EQ(le.check(le.next_shift_time()), "");
  EXPECT_NE(le.check(le.next_shift_time() + 1e-6), "");  // a shift overdue
  le.shift();
  EXPECT_EQ(le.check(le.next_shift_time() - 1e-9), "");
}

}  // namespace
}  // namespace kairos
