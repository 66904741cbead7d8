// Stepped potentials inside the engine (engine/pair_steps.hpp): the zone tables the event loops
// read (zones, widths, the time to the next boundary) and the capture map (pairs listed under
// both particles, the exact energy, load/lookup, renumbering, export and its own check).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "engine/pair_steps.hpp"

namespace kairos {
namespace {

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

// --- the zone tables ------------------------------------------------------------------------

// Boundaries 2 > 1.5 > 1.25 > 1 (the core): zone 0 beyond 2, zones 1..3 inwards, zone 3 next to
// the core. All values are binary fractions: the squares and sums below are exact.
StepTable three_steps() {
  return StepTable{{2.0, 1.5, 1.25, 1.0}, {-3.0, -2.0, -1.0}};
}

TEST(PairSteps, AZoneTableNumbersItsZonesFromTheCutOffInwards) {
  const ZoneTable t(three_steps());
  EXPECT_EQ(t.core_zone, 3);
  EXPECT_EQ(t.r2, (std::vector<double>{4.0, 2.25, 1.5625, 1.0}));
  EXPECT_EQ(t.energy, (std::vector<double>{0.0, -3.0, -2.0, -1.0}));  // zone 0: beyond
  // width[z] = r_{z-1} - r_z, the dashpot's shell widths.
  ASSERT_EQ(t.width.size(), 4u);
  EXPECT_EQ(t.width[1], 0.5);
  EXPECT_EQ(t.width[2], 0.25);
  EXPECT_EQ(t.width[3], 0.25);
  // A pair on a boundary counts as outside it; inside the core is the core zone.
  EXPECT_EQ(t.zone_at(5.0), 0);
  EXPECT_EQ(t.zone_at(4.0), 0);
  EXPECT_EQ(t.zone_at(std::nextafter(4.0, 0.0)), 1);
  EXPECT_EQ(t.zone_at(2.25), 1);
  EXPECT_EQ(t.zone_at(2.0), 2);
  EXPECT_EQ(t.zone_at(1.5625), 2);
  EXPECT_EQ(t.zone_at(1.25), 3);
  EXPECT_EQ(t.zone_at(1.0), 3);
  EXPECT_EQ(t.zone_at(0.25), 3);
}

TEST(PairSteps, APairMeetsItsInnerBoundaryApproachingAndItsOuterOneReceding) {
  const ZoneTable t(three_steps());
  // Head-on along a line: r.r = r^2, r.g = r g, g.g = g^2.
  const auto time = [&](std::uint32_t zone, double r, double g) {
    return t.event_time(zone, r * r, r * g, g * g);
  };
  EXPECT_EQ(time(1, 1.75, -1.0), 0.25);    // in to 1.5
  EXPECT_EQ(time(1, 1.75, 1.0), 0.25);     // out to 2
  EXPECT_EQ(time(0, 3.0, -2.0), 0.5);      // from beyond the cut-off in to 2
  EXPECT_EQ(time(3, 1.125, -1.0), 0.125);  // next to the core: the hard core at 1
  EXPECT_EQ(time(3, 1.125, 0.5), 0.25);    // out to 1.25
  // Beyond the cut-off, receding or passing by: never. At rest inside a zone: never.
  EXPECT_EQ(time(0, 3.0, 2.0), kNever);
  EXPECT_EQ(t.event_time(0, 9.0, 0.0, 4.0), kNever);
  EXPECT_EQ(time(2, 1.375, 0.0), kNever);
  // Round-off put the pair past the boundary it moves towards: now.
  EXPECT_EQ(t.event_time(1, std::nextafter(4.0, 5.0), 2.0, 1.0), 0.0);
  EXPECT_EQ(t.event_time(1, std::nextafter(2.25, 0.0), -1.5, 1.0), 0.0);
}

// Approaching but missing the inner boundary, the pair leaves through the outer one: the later
// root, where |r + g t| is the outer radius, the pair staying inside the zone until then.
TEST(PairSteps, APairThatMissesItsInnerBoundaryLeavesThroughTheOuterOne) {
  const ZoneTable t(three_steps());
  const double r[2] = {1.75, 0.0}, g[2] = {-0.25, 1.0};  // closest approach 1.70 > 1.5
  const double r2 = r[0] * r[0], rg = r[0] * g[0], g2 = g[0] * g[0] + g[1] * g[1];
  const double dt = t.event_time(1, r2, rg, g2);
  ASSERT_GT(dt, 0.0);
  ASSERT_LT(dt, kNever);
  const auto distance2 = [&](double s) {
    return (r[0] + g[0] * s) * (r[0] + g[0] * s) + (r[1] + g[1] * s) * (r[1] + g[1] * s);
  };
  EXPECT_NEAR(distance2(dt), 4.0, 1e-12);
  for (int k = 1; k < 20; ++k) {
    const double d2 = distance2(dt * k / 20.0);
    EXPECT_GT(d2, 2.25) << k;
    EXPECT_LT(d2, 4.0) << k;
  }
}

// --- the capture map ------------------------------------------------------------------------

// The map's storage, written through its read-only view: check() must notice.
PairSteps::Entry* writable(const PairSteps& steps, std::uint32_t i) {
  return const_cast<PairSteps::Entry*>(steps.entries_begin(i));
}

TEST(PairSteps, CheckCatchesAnUnmirroredEntry) {
  // Two wells: zones 1 (from 2 to 1.5) and 2 (from 1.5 to the core at 1).
  PairSteps steps({StepTable{{2.0, 1.5, 1.0}, {-1.0, -2.0}}}, {0}, 1, 6);
  steps.set(0, 3, {0, 1});
  steps.set(0, 4, {0, 2});
  steps.set(2, 5, {0, 1});
  ASSERT_EQ(steps.check(), "");
  const auto fault = [](const PairSteps& broken, const std::string& what) {
    const std::string found = broken.check();
    EXPECT_NE(found.find(what), std::string::npos) << "got \"" << found << "\"";
  };
  {  // 0's entry for 3 turned to 5, which does not list 0
    PairSteps broken = steps;
    writable(broken, 0)[0].partner = 5;
    fault(broken, "pair 0,5 is listed under one particle only");
  }
  {  // 0 and 3 disagree on the zone
    PairSteps broken = steps;
    writable(broken, 0)[0].zone.zone = 2;
    fault(broken, "pair 0,3 has two different zones");
  }
  {  // 0 lists 3 twice
    PairSteps broken = steps;
    writable(broken, 0)[1].partner = 3;
    fault(broken, "pair 0,3 is listed twice");
  }
  {  // with itself, and with a particle that does not exist
    PairSteps self = steps, beyond = steps;
    writable(self, 0)[0].partner = 0;
    writable(beyond, 0)[0].partner = 6;
    fault(self, "particle 0 lists a bad partner");
    fault(beyond, "particle 0 lists a bad partner");
  }
  {  // a zone the table does not have, a table that does not exist
    PairSteps zone = steps, table = steps;
    writable(zone, 0)[0].zone.zone = 3;
    writable(table, 0)[0].zone.table = 1;
    fault(zone, "pair 0,3 has a zone outside its table");
    fault(table, "pair 0,3 has a zone outside its table");
  }
  {  // mirrored, but beyond the cut-off
    PairSteps broken = steps;
    writable(broken, 0)[0].zone.zone = 0;
    writable(broken, 3)[0].zone.zone = 0;
    fault(broken, "pair 0,3 is listed beyond its cut-off");
  }
  {  // mirrored and valid, but not where the counts (the energy) have it
    PairSteps broken = steps;
    writable(broken, 0)[0].zone.zone = 2;
    writable(broken, 3)[0].zone.zone = 2;
    fault(broken, "counts of pairs per zone");
  }
  {  // a count larger than a slab holds
    PairSteps broken = steps;
    (writable(broken, 0) - 1)->partner = 1000;
    fault(broken, "particle 0 lists more pairs than fit");
  }
  EXPECT_EQ(steps.check(), "");  // the copies were broken, not the map
}

// A particle in more pairs than its slab holds (8 slots: the count and 7 entries) moves every
// slab to a wider stride: nothing is lost, and the map stays consistent through removals and a
// renumbering.
TEST(PairSteps, ListsOutgrowTheirSlabs) {
  const std::uint32_t n = 30;
  PairSteps steps({square_well(1.0, 1.5, 1.0)}, {0}, 1, n);
  steps.set(5, 6, {0, 1});
  steps.set(21, 22, {0, 1});
  for (std::uint32_t j = 1; j <= 20; ++j) steps.set(0, j, {0, 1});
  ASSERT_EQ(steps.check(), "");
  EXPECT_EQ(steps.entry_count(0), 20u);
  EXPECT_EQ(steps.energy(), -22.0);
  for (std::uint32_t j = 1; j <= 20; ++j) {
    EXPECT_EQ(steps.find(0, j, PairSteps::kHard).zone, 1) << j;
    EXPECT_EQ(steps.find(j, 0, PairSteps::kHard).zone, 1) << j;
    EXPECT_EQ(steps.entry_count(j), j == 5 || j == 6 ? 2u : 1u) << j;
  }
  EXPECT_EQ(steps.find(5, 6, PairSteps::kHard).zone, 1);
  EXPECT_EQ(steps.find(22, 21, PairSteps::kHard).zone, 1);
  // Every pair once, i < j, by i then j.
  std::vector<std::uint32_t> id(n);
  for (std::uint32_t k = 0; k < n; ++k) id[k] = k;
  std::vector<PairZone> want;
  for (std::uint32_t j = 1; j <= 20; ++j) want.push_back({0, j, 1});
  want.push_back({5, 6, 1});
  want.push_back({21, 22, 1});
  EXPECT_EQ(steps.export_zones(id.data()), want);
  // Half of 0's pairs leave the well.
  for (std::uint32_t j = 2; j <= 20; j += 2) steps.set(j, 0, {0, 0});
  ASSERT_EQ(steps.check(), "");
  EXPECT_EQ(steps.entry_count(0), 10u);
  EXPECT_EQ(steps.energy(), -12.0);
  // Reversed numbering: old k is new n - 1 - k.
  std::vector<std::uint32_t> reversed(n);
  for (std::uint32_t k = 0; k < n; ++k) reversed[k] = n - 1 - k;
  steps.renumber(reversed);
  ASSERT_EQ(steps.check(), "");
  EXPECT_EQ(steps.entry_count(n - 1), 10u);
  for (std::uint32_t j = 1; j <= 20; ++j)
    EXPECT_EQ(steps.find(n - 1, n - 1 - j, PairSteps::kHard).zone, j % 2 == 1 ? 1 : 0) << j;
  EXPECT_EQ(steps.energy(), -12.0);
}

// Species pick tables; a bond (infinite energy beyond its cut-off) stays listed whatever its
// zone; the energy counts only zones that hold pairs, so an empty zone of infinite energy costs
// nothing.
TEST(PairSteps, TablesBySpeciesAndBonds) {
  const double inf = std::numeric_limits<double>::infinity();
  StepTable bond{{1.5, 1.0}, {0.0}};
  bond.beyond = inf;
  // Species 0 with 0: the well (table 0); 1 with 1: the bond (table 1); 0 with 1: hard.
  PairSteps steps({square_well(1.0, 1.6, 1.0), bond}, {0, -1, -1, 1}, 2, 4);
  EXPECT_EQ(steps.tables(), 2u);
  EXPECT_EQ(steps.pair_table(0, 0), 0);
  EXPECT_EQ(steps.pair_table(0, 1), PairSteps::kHard);
  EXPECT_EQ(steps.pair_table(1, 0), PairSteps::kHard);
  EXPECT_EQ(steps.pair_table(1, 1), 1);
  EXPECT_EQ(PairSteps().pair_table(0, 0), PairSteps::kHard);  // no steps: every pair hard
  EXPECT_FALSE(steps.bonded(0));
  EXPECT_TRUE(steps.bonded(1));
  EXPECT_DOUBLE_EQ(steps.max_range(), 1.6);
  // Every table's squared boundaries, back to back, for the vector loop.
  for (const std::uint16_t t : {std::uint16_t{0}, std::uint16_t{1}})
    for (std::size_t z = 0; z < steps.table(t).r2.size(); ++z)
      EXPECT_EQ(steps.flat_r2()[steps.table_offset()[t] + z], steps.table(t).r2[z]);

  steps.set(0, 1, {1, 1});  // bonded, inside
  steps.set(2, 3, {0, 1});  // in the well
  ASSERT_EQ(steps.check(), "");
  EXPECT_EQ(steps.energy(), -1.0);  // the bond's zone 0 (infinite) holds no pair
  // A bond pulled to its zone 0 stays listed, at infinite energy.
  steps.set(1, 0, {1, 0});
  EXPECT_EQ(steps.entry_count(0), 1u);
  EXPECT_EQ(steps.find(0, 1, PairSteps::kHard).table, 1);
  EXPECT_EQ(steps.find(0, 1, PairSteps::kHard).zone, 0);
  EXPECT_EQ(steps.check(), "");
  EXPECT_EQ(steps.energy(), inf);
  steps.set(0, 1, {1, 1});
  EXPECT_EQ(steps.energy(), -1.0);
}

// load(i) shows i's entries to lookup() and hides those of the particle loaded before; the
// stamps the vector loop reads hold epoch, table and zone.
TEST(PairSteps, LoadShowsTheLoadedParticlesPairsOnly) {
  PairSteps steps({square_well(1.0, 1.5, 1.0)}, {0}, 1, 6);
  steps.set(0, 3, {0, 1});
  steps.set(2, 3, {0, 1});
  steps.set(4, 5, {0, 1});
  const std::uint16_t fallback = 7;
  steps.load(3);
  for (const std::uint32_t j : {0u, 2u}) {
    EXPECT_EQ(steps.lookup(j, fallback).table, 0) << j;
    EXPECT_EQ(steps.lookup(j, fallback).zone, 1) << j;
    const std::uint64_t stamp = steps.stamps()[j];
    EXPECT_EQ(stamp >> 32, steps.epoch());
    EXPECT_EQ((stamp >> 16) & 0xffffu, 0u);
    EXPECT_EQ(stamp & 0xffffu, 1u);
  }
  EXPECT_EQ(steps.lookup(4, fallback).table, fallback);
  EXPECT_EQ(steps.lookup(4, fallback).zone, 0);
  steps.load(4);
  EXPECT_EQ(steps.lookup(5, fallback).zone, 1);
  for (const std::uint32_t j : {0u, 2u}) {  // 3's pairs, not 4's
    EXPECT_EQ(steps.lookup(j, fallback).table, fallback) << j;
    EXPECT_EQ(steps.lookup(j, fallback).zone, 0) << j;
  }
  // A pair that left the well is gone at the next load.
  steps.set(4, 5, {0, 0});
  steps.load(4);
  EXPECT_EQ(steps.lookup(5, fallback).table, fallback);
  // After a renumbering, loads see the new numbers (old 3 is new 2, old 0 new 5).
  steps.renumber({5, 4, 3, 2, 1, 0});
  steps.load(2);
  EXPECT_EQ(steps.lookup(5, fallback).zone, 1);
  EXPECT_EQ(steps.lookup(3, fallback).zone, 1);
  EXPECT_EQ(steps.lookup(0, fallback).table, fallback);
}

}  // namespace
}  // namespace kairos
