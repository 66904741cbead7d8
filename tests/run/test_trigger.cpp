// Triggers (run/trigger.hpp): in collisions, due once when the count reaches each next multiple
// of the step after the phase's start; in simulated time, due at the multiples k * step of the
// interval, once each, a multiple within round-off of the last output counting as it, and an
// interval below the clock's resolution still moving on; log-spaced, at the origin + first *
// 10^(k / per_decade), cycles starting again every period, found from any point alone.
#include "run/trigger.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

namespace kairos {
namespace {

TEST(CollisionTrigger, DueOnceWhenTheCountReachesEachThreshold) {
  Trigger t = Trigger::every_collisions(10, 5);  // a phase starting at 5 collisions
  EXPECT_EQ(t.collisions.next, 15u);
  std::vector<std::uint64_t> due;
  for (std::uint64_t c : {6, 14, 15, 15, 16, 24, 25, 40}) {
    if (t.collisions.due(c)) due.push_back(c);
  }
  // 40 passes 35 and 45 is next: a count that jumps (the DEM's several contacts per step) is
  // due once, and the next threshold stays on the phase's grid.
  EXPECT_EQ(due, (std::vector<std::uint64_t>{15, 25, 40}));
  EXPECT_EQ(t.collisions.next, 45u);
}

TEST(CollisionTrigger, StepZeroIsNeverDue) {
  Trigger t = Trigger::every_collisions(0, 0);
  EXPECT_FALSE(t.collisions.due(~std::uint64_t{0} - 1));
  EXPECT_FALSE(t.time.due(1e300));
  Trigger never;
  EXPECT_FALSE(never.collisions.due(1000));
  EXPECT_FALSE(never.time.due(1000.0));
}

TEST(TimeTrigger, DueOnceAtEachMultipleOfTheInterval) {
  Trigger thermo = Trigger::every_time(0.25, 0.0);
  Trigger trajectory = Trigger::every_time(2.5, 0.0);
  EXPECT_EQ(thermo.time.next, 0.25);
  EXPECT_EQ(thermo.collisions.next, ~std::uint64_t{0});  // the other part: never
  std::vector<double> due;
  for (double t : {0.1, 0.25, 0.25, 0.3, 0.8, 1.0, 1.0}) {
    if (thermo.time.due(t)) due.push_back(t);
  }
  // 0.8 passes both 0.5 and 0.75: one row then (the clock stops at each in the run driver).
  EXPECT_EQ(due, (std::vector<double>{0.25, 0.8, 1.0}));
  EXPECT_EQ(thermo.time.next, 1.25);
  EXPECT_EQ(trajectory.time.next, 2.5);
}

TEST(TimeTrigger, StartsAtTheFirstMultipleAfterThePhasesStart) {
  // A continued run from t = 0.3 with an interval of 0.1: the next output is 4 * 0.1, not
  // 3 * 0.1 = 0.30000000000000004 (the same time to round-off as the start).
  EXPECT_EQ(Trigger::every_time(0.1, 0.3).time.next, 4 * 0.1);
  EXPECT_EQ(Trigger::every_time(0.25, 0.5).time.next, 0.75);
}

TEST(TimeTrigger, AMultipleWithinRoundOffOfAnOutputIsThatOutput) {
  Trigger t = Trigger::every_time(0.1, 0.0);
  EXPECT_TRUE(t.time.due(0.3));  // the clock stopped at 0.3 (a phase's end), not at 3 * 0.1
  EXPECT_FALSE(t.time.due(3 * 0.1));
  EXPECT_EQ(t.time.next, 4 * 0.1);
}

TEST(TimeTrigger, AnIntervalBelowTheClocksResolutionStillMovesOn) {
  TimeTrigger e;
  e.step = 1e-10;
  const double t = 1e7;  // t / step = 1e17 > 2^53: k * step cannot move by one step
  const double next = e.after(t);
  EXPECT_GT(next, t);
  EXPECT_TRUE(std::isfinite(next));
}

TEST(LogSpacing, ThePointsAfterAnyValue) {
  const LogSpacing log{.first = 0.1, .per_decade = 2.0, .period = 0.0};
  EXPECT_EQ(log.after(-1.0), 0.0);  // the origin
  EXPECT_EQ(log.after(0.0), 0.1);
  EXPECT_EQ(log.after(0.05), 0.1);
  EXPECT_EQ(log.after(0.1), 0.1 * std::pow(10.0, 0.5));
  EXPECT_EQ(log.after(0.2), 0.1 * std::pow(10.0, 0.5));
  EXPECT_EQ(log.after(0.1 * std::pow(10.0, 0.5)), 0.1 * 10.0);
  EXPECT_EQ(log.after(5.0), 0.1 * std::pow(10.0, 4.0 / 2.0));
  EXPECT_EQ(log.after(1e6), 0.1 * std::pow(10.0, 15.0 / 2.0));  // 1e6 itself is k = 14
  // Walking from 0 meets every point once, in order.
  double p = 0.0;
  for (int k = 0; k < 40; ++k) {
    p = log.after(p);
    EXPECT_EQ(p, 0.1 * std::pow(10.0, k / 2.0)) << k;
  }
}

TEST(LogSpacing, CyclesStartAgainEveryPeriod) {
  const LogSpacing log{.first = 0.1, .per_decade = 1.0, .period = 5.0};
  // Each cycle: its start, then 0.1 and 1 (10 is beyond the period).
  std::vector<double> points;
  for (double p = -1.0; points.size() < 7;) points.push_back(p = log.after(p));
  EXPECT_EQ(points, (std::vector<double>{0.0, 0.1, 1.0, 5.0, 5.1, 6.0, 10.0}));
  EXPECT_EQ(log.after(2.0), 5.0);
  EXPECT_EQ(log.after(5.5), 6.0);
}

TEST(LogTrigger, InCollisionsAtTheFirstCountAtOrAfterEachPoint) {
  // A phase from 100 collisions, lags 12.8 collisions * 10^(k/4), met by a count that jumps.
  Trigger t = Trigger::log_collisions({.first = 12.8, .per_decade = 4.0}, 100, 100);
  EXPECT_EQ(t.collisions.next, 113u);  // ceil(12.8)
  std::vector<std::uint64_t> due;
  for (std::uint64_t c : {105, 113, 113, 120, 123, 200, 250}) {
    if (t.collisions.due(c)) due.push_back(c);
  }
  // 123 = 100 + ceil(22.76); 200 passes 141 and 172 (due once); then 100 + ceil(128) = 228.
  EXPECT_EQ(due, (std::vector<std::uint64_t>{113, 123, 200, 250}));
  // A continued run finds the next threshold from its origin and its count alone.
  EXPECT_EQ(Trigger::log_collisions({.first = 12.8, .per_decade = 4.0}, 100, 123).collisions.next,
            141u);
  // Lags beyond any count: never due.
  Trigger far = Trigger::log_collisions({.first = 1e30, .per_decade = 4.0}, 0, 0);
  EXPECT_EQ(far.collisions.next, ~std::uint64_t{0});
}

TEST(LogTrigger, InTimeAtOriginPlusEachPointOnce) {
  const LogSpacing log{.first = 0.01, .per_decade = 5.0};
  Trigger t = Trigger::log_time(log, 2.5, 2.5);
  EXPECT_EQ(t.time.next, 2.5 + 0.01);
  EXPECT_TRUE(t.time.due(2.5 + 0.01));
  EXPECT_FALSE(t.time.due(2.5 + 0.01));
  EXPECT_EQ(t.time.next, 2.5 + 0.01 * std::pow(10.0, 0.2));
  // From a continued run's time, the next point of the same sequence.
  EXPECT_EQ(Trigger::log_time(log, 2.5, 2.6).time.next, 2.5 + 0.01 * std::pow(10.0, 1.2));
}

}  // namespace
}  // namespace kairos
