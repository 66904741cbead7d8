// Growing spheres' contact time (dynamics/collision_time.hpp growing_contact_time,
// docs/physics.md#growing-spheres) against the stable event rule evaluated by dense sampling,
// and the collision rule of interactions/hard_sphere.hpp against its defining property.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "dynamics/collision_time.hpp"
#include "interactions/hard_sphere.hpp"

namespace kairos {
namespace {

struct Pair {
  double r[3], g[3];
  double sigma, u;  // contact distance now, its growth speed
};

double f(const Pair& p, double t) {  // |r + g t|^2 - (sigma + u t)^2
  double d2 = 0.0;
  for (int a = 0; a < 3; ++a) d2 += (p.r[a] + p.g[a] * t) * (p.r[a] + p.g[a] * t);
  return d2 - (p.sigma + p.u * t) * (p.sigma + p.u * t);
}

double time_of(const Pair& p) {
  double r2 = 0, rg = 0, g2 = 0;
  for (int a = 0; a < 3; ++a) {
    r2 += p.r[a] * p.r[a];
    rg += p.r[a] * p.g[a];
    g2 += p.g[a] * p.g[a];
  }
  return growing_contact_time(r2 - p.sigma * p.sigma, rg - p.sigma * p.u, g2 - p.u * p.u);
}

TEST(GrowingContact, HeadOnPairMeetsWhereTheGrowingGapCloses) {
  // Gap 2 closing at speed 1 + 0.5: t = 2 / 1.5.
  const Pair p{{3, 0, 0}, {-1, 0, 0}, 1.0, 0.5};
  EXPECT_NEAR(time_of(p), 2.0 / 1.5, 1e-15);
}

TEST(GrowingContact, PairsAtRestAreReachedByTheGrowth) {
  const Pair p{{3, 0, 0}, {0, 0, 0}, 1.0, 0.25};
  EXPECT_NEAR(time_of(p), 8.0, 1e-14);
  // Receding slower than the growth: still met.
  const Pair q{{3, 0, 0}, {0.2, 0, 0}, 1.0, 0.25};
  EXPECT_NEAR(time_of(q), 2.0 / 0.05, 1e-12);
  // Receding faster than the growth: never.
  const Pair s{{3, 0, 0}, {0.3, 0, 0}, 1.0, 0.25};
  EXPECT_EQ(time_of(s), kNever);
}

TEST(GrowingContact, JustAfterACollisionThePairSeparates) {
  // At contact, leaving relative to the growing surfaces (g_n > u), a rounded gap of either
  // sign gives no event.
  for (const double gap : {-1e-15, 0.0, 1e-15}) {
    const Pair p{{1.0 + gap, 0, 0}, {0.6, 0.1, 0}, 1.0, 0.5};
    EXPECT_EQ(time_of(p), kNever) << gap;
  }
  // Approaching relative to the growth while touching: now.
  const Pair q{{1.0 - 1e-15, 0, 0}, {0.4, 0, 0}, 1.0, 0.5};
  EXPECT_EQ(time_of(q), 0.0);
}

TEST(GrowingContact, AgreesWithDenseSamplingOfTheEventRule) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  int met = 0, checked = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    Pair p{};
    for (int a = 0; a < 3; ++a) {
      p.r[a] = 2.0 * uni(rng);
      p.g[a] = uni(rng);
    }
    p.sigma = 1.0;
    p.u = 0.5 * (uni(rng) + 1.0);
    if (f(p, 0.0) <= 0.0) continue;  // starting apart
    ++checked;
    const double t = time_of(p);
    // The first sign change of f on a fine grid up to a horizon.
    constexpr double kHorizon = 20.0, kStep = 1e-3;
    double first = kNever;
    for (double s = kStep; s <= kHorizon; s += kStep) {
      if (f(p, s) <= 0.0) {
        first = s;
        break;
      }
    }
    if (first == kNever) {
      EXPECT_TRUE(!(t < kHorizon - kStep)) << "trial " << trial << ": t = " << t;
      continue;
    }
    ++met;
    ASSERT_LE(t, first) << "trial " << trial;
    ASSERT_GE(t, first - kStep) << "trial " << trial;
    EXPECT_NEAR(f(p, t), 0.0, 1e-9) << "trial " << trial;
  }
  EXPECT_GT(checked, 10000);
  EXPECT_GT(met, checked / 4);  // both outcomes are exercised
  EXPECT_LT(met, checked);
}

TEST(GrowingContact, ImpulseReversesTheApproachRelativeToTheGrowth) {
  // r along x at contact distance 1, g with normal part -0.7, growth speed 0.3: afterwards
  // g_n - u = +(0.7 + 0.3), i.e. g_n = 1.3; the tangential part is untouched.
  const double mi = 1.0, mj = 3.0, mu = mi * mj / (mi + mj);
  const double r[3] = {1.0, 0.0, 0.0}, g[3] = {-0.7, 0.2, 0.0};
  const double s = HardSphere::growing_impulse_factor(-0.7, 1.0, mu, 0.3, 1.0);
  double after[3];
  for (int a = 0; a < 3; ++a) after[a] = g[a] + s * r[a] * (1.0 / mi + 1.0 / mj);
  EXPECT_NEAR(after[0], 1.3, 1e-15);
  EXPECT_EQ(after[1], 0.2);
  // Without growth it is the elastic rule.
  EXPECT_EQ(HardSphere::growing_impulse_factor(-0.7, 1.0, mu, 0.0, 1.0),
            HardSphere::impulse_factor(-0.7, 1.0, mu));
}

}  // namespace
}  // namespace kairos
