// Outputs in simulated time (run/run_support.hpp, TimeSchedule): due at the multiples k * step of
// each interval, once each, a multiple within round-off of the last output counting as it, and
// an interval below the clock's resolution still moving on.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "run/run_support.hpp"

namespace kairos::run_detail {
namespace {

OutputConfig every(double thermo) {
  OutputConfig out;
  out.thermo_interval = thermo;
  out.trajectory_interval = 10.0 * thermo;
  out.interval_unit = "time";
  return out;
}

TEST(TimeSchedule, DueOnceAtEachMultipleOfTheInterval) {
  TimeSchedule s(every(0.25), 100.0, 0.0);
  EXPECT_EQ(s.next(), 0.25);
  std::vector<double> due;
  for (double t : {0.1, 0.25, 0.25, 0.3, 0.8, 1.0, 1.0}) {
    if (s.thermo.due(t)) due.push_back(t);
  }
  // 0.8 passes both 0.5 and 0.75: one row then (the clock stops at each in the run driver).
  EXPECT_EQ(due, (std::vector<double>{0.25, 0.8, 1.0}));
  EXPECT_EQ(s.thermo.next, 1.25);
  EXPECT_EQ(s.trajectory.next, 2.5);
}

TEST(TimeSchedule, StartsAtTheFirstMultipleAfterThePhasesStart) {
  // A continued run from t = 0.3 with an interval of 0.1: the next output is 4 * 0.1, not
  // 3 * 0.1 = 0.30000000000000004 (the same time to round-off as the start).
  TimeSchedule s(every(0.1), 100.0, 0.3);
  EXPECT_EQ(s.thermo.next, 4 * 0.1);
  TimeSchedule exact(every(0.25), 100.0, 0.5);
  EXPECT_EQ(exact.thermo.next, 0.75);
}

TEST(TimeSchedule, AMultipleWithinRoundOffOfAnOutputIsThatOutput) {
  TimeSchedule s(every(0.1), 100.0, 0.0);
  EXPECT_TRUE(s.thermo.due(0.3));  // the clock stopped at 0.3 (a phase's end), not at 3 * 0.1
  EXPECT_FALSE(s.thermo.due(3 * 0.1));
  EXPECT_EQ(s.thermo.next, 4 * 0.1);
}

TEST(TimeSchedule, AnIntervalBelowTheClocksResolutionStillMovesOn) {
  TimeSchedule::Every e;
  e.step = 1e-10;
  const double t = 1e7;  // t / step = 1e17 > 2^53: k * step cannot move by one step
  const double next = e.after(t);
  EXPECT_GT(next, t);
  EXPECT_TRUE(std::isfinite(next));
}

}  // namespace
}  // namespace kairos::run_detail
