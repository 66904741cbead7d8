// Triggers (run/trigger.hpp): in collisions, due once when the count reaches each next multiple
// of the step after the phase's start; in simulated time, due at the multiples k * step of the
// interval, once each, a multiple within round-off of the last output counting as it, and an
// interval below the clock's resolution still moving on.
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

}  // namespace
}  // namespace kairos
