// Event detection edge cases of docs/physics.md#hard-sphere-contact-time (sigma = 1; R, V
// relative).
#include <gtest/gtest.h>

#include <cmath>

#include "dynamics/collision_time.hpp"

namespace kairos {
namespace {

double contact(std::array<double, 3> r, std::array<double, 3> v) {
  return pair_contact_time<3>(r.data(), v.data(), 1.0);
}

TEST(CollisionTime, HeadOnApproach) {
  EXPECT_DOUBLE_EQ(contact({3, 0, 0}, {-1, 0, 0}), 2.0);
}

TEST(CollisionTime, OverlappingApproachingCollidesNow) {
  // The textbook formula returns -0.001 here; the stable rule says "now".
  EXPECT_EQ(contact({0.999, 0, 0}, {-1, 0, 0}), 0.0);
}

TEST(CollisionTime, OverlappingRecedingNeverCollides) {
  EXPECT_EQ(contact({0.999, 0, 0}, {1, 0, 0}), kNever);
}

TEST(CollisionTime, NearMissNeverCollides) {
  EXPECT_EQ(contact({3, 1.5, 0}, {-1, 0, 0}), kNever);
}

TEST(CollisionTime, GrazingOffsetMatchesGeometry) {
  EXPECT_NEAR(contact({3, 0.5, 0}, {-1, 0, 0}), 2.1339745962155614, 1e-15);
}

TEST(CollisionTime, TinyGapIsTheExactRootOfTheRoundedInput) {
  // 2a/(-b + sqrt(D)) keeps full relative precision; the textbook root loses ~1e-9 of it.
  const double t = contact({1.0 + 1e-10, 0, 0}, {-1, 0, 0});
  EXPECT_NEAR(t, 1.000000082690371e-10, 1e-24);
}

TEST(CollisionTime, TouchingPairs) {
  EXPECT_EQ(contact({1, 0, 0}, {-1, 0, 0}), 0.0);    // touching, approaching: now
  EXPECT_EQ(contact({1, 0, 0}, {1, 0, 0}), kNever);  // touching, receding
  EXPECT_EQ(contact({1, 0, 0}, {0, 1, 0}), kNever);  // touching, tangential (f' = 0)
}

TEST(CollisionTime, AtRestNeverCollides) {
  EXPECT_EQ(contact({0.5, 0, 0}, {0, 0, 0}), kNever);
}

TEST(CollisionTime, NeverNegativeOverRandomStates) {
  // Sweep gaps from -1e-3 to 1e-3 around contact, all approach angles: t is >= 0 or never.
  for (int gi = -20; gi <= 20; ++gi) {
    const double gap = 1e-3 * std::pow(10.0, -std::abs(gi) / 4.0) * (gi < 0 ? -1 : 1);
    for (int k = 0; k < 36; ++k) {
      const double ang = k * M_PI / 18.0;
      const double t = contact({1.0 + gap, 0, 0}, {std::cos(ang), std::sin(ang), 0});
      EXPECT_TRUE(t >= 0.0) << gap << " " << ang;
      if (std::cos(ang) < -1e-12 && gap <= 0.0) {
        EXPECT_EQ(t, 0.0);
      }
      if (std::cos(ang) > 0.0) {
        EXPECT_EQ(t, kNever);
      }
    }
  }
}

TEST(CollisionTime, TwoDimensional) {
  const double r[2] = {0.0, 2.5}, g[2] = {0.0, -0.5};
  EXPECT_DOUBLE_EQ(pair_contact_time<2>(r, g, 1.5), 2.0);
}

TEST(IntervalExit, ExitTimesAndRoundOff) {
  EXPECT_DOUBLE_EQ(interval_exit_time(0.25, 0.5, 0.0, 1.0), 1.5);
  EXPECT_DOUBLE_EQ(interval_exit_time(0.25, -0.5, 0.0, 1.0), 0.5);
  EXPECT_EQ(interval_exit_time(0.25, 0.0, 0.0, 1.0), kNever);
  EXPECT_EQ(interval_exit_time(1.0 + 1e-16, 1.0, 0.0, 1.0), 0.0);  // just past: now, not < 0
}

}  // namespace
}  // namespace kairos
