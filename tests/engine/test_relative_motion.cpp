// The state of a pair at time t (engine/relative_motion.hpp): r.r, r.g and g.g of a particle and
// a candidate read from its record (advanced to t, seen through its cell's periodic image, on a
// parabola under gravity), and the hard-sphere contact test of the candidate loops.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "dynamics/collision_time.hpp"
#include "engine/relative_motion.hpp"

namespace kairos {
namespace {

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

// r = x_i - (x_j + shift) and g = v_i - v_j, with j's record advanced by dtj: all values below
// are binary fractions, so every product and sum is exact and the bits can be compared.
TEST(RelativeMotion, TheCandidateIsAdvancedToTheTimeAndSeenThroughItsImage) {
  const Vec<3> xi{0.5, 0.25, 1.0}, vi{1.0, -0.5, 0.0};
  // j's record: at (7.5, 0.75, 1.5) moving at (-2, 0.5, 0.25); 0.5 later it is at
  // (6.5, 1, 1.625), and its image through the shift (-8, 0, 0) at (-1.5, 1, 1.625).
  const double rec[7] = {7.5, 0.75, 1.5, -2.0, 0.5, 0.25, 0.0};
  const Vec<3> shift{-8.0, 0.0, 0.0};
  const RelativeMotion m = relative_motion_at<3>(xi, vi, rec, 0.5, shift);
  // r = (2, -0.75, -0.625), g = (3, -1, -0.25).
  EXPECT_EQ(m.r2, 4.0 + 0.5625 + 0.390625);
  EXPECT_EQ(m.rg, 6.0 + 0.75 + 0.15625);
  EXPECT_EQ(m.g2, 9.0 + 1.0 + 0.0625);
  // The same pair from a record already at time t, and from the image itself, unshifted.
  const double now[7] = {6.5, 1.0, 1.625, -2.0, 0.5, 0.25, 0.0};
  const double image[7] = {-1.5, 1.0, 1.625, -2.0, 0.5, 0.25, 0.0};
  for (const RelativeMotion& same : {relative_motion_at<3>(xi, vi, now, 0.0, shift),
                                     relative_motion_at<3>(xi, vi, image, 0.0, {})}) {
    EXPECT_EQ(same.r2, m.r2);
    EXPECT_EQ(same.rg, m.rg);
    EXPECT_EQ(same.g2, m.g2);
  }
  // Without the shift j is seen where it sits in the box, 6 ahead of i along x.
  const RelativeMotion far = relative_motion_at<3>(xi, vi, rec, 0.5, {});
  EXPECT_EQ(far.r2, 36.0 + 0.5625 + 0.390625);
  EXPECT_EQ(far.rg, -18.0 + 0.75 + 0.15625);
}

TEST(RelativeMotion, UnderGravityTheCandidateFollowsItsParabola) {
  // 2D, g = (0, -2). j's record: at (1, 2) moving at (0.5, 1); one time unit later it is at
  // (1 + 0.5, 2 + 1 - 1) = (1.5, 2) moving at (0.5, 1 - 2) = (0.5, -1). i at rest at the origin.
  const double half_g[2] = {0.0, -1.0}, g[2] = {0.0, -2.0};
  const double rec[5] = {1.0, 2.0, 0.5, 1.0, 0.0};
  const RelativeMotion m =
      relative_motion_at<2, true>({0.0, 0.0}, {0.0, 0.0}, rec, 1.0, {}, half_g, g);
  // r = (-1.5, -2), g = (-0.5, 1).
  EXPECT_EQ(m.r2, 6.25);
  EXPECT_EQ(m.rg, 0.75 - 2.0);
  EXPECT_EQ(m.g2, 1.25);
  // At dtj = 0 gravity has not acted yet: the record as it stands.
  const RelativeMotion at_record =
      relative_motion_at<2, true>({0.0, 0.0}, {0.0, 0.0}, rec, 0.0, {}, half_g, g);
  const RelativeMotion plain = relative_motion_at<2>({0.0, 0.0}, {0.0, 0.0}, rec, 0.0, {});
  EXPECT_EQ(at_record.r2, plain.r2);
  EXPECT_EQ(at_record.rg, plain.rg);
  EXPECT_EQ(at_record.g2, plain.g2);
}

// The pair with relative position r and velocity g (j at rest at the origin).
RelativeMotion pair(const Vec<3>& r, const Vec<3>& g) {
  const double origin[7] = {};
  return relative_motion_at<3>(r, g, origin, 0.0, {});
}

// Under Lees-Edwards shear the image above moves at +U along x: the pair's relative velocity
// takes it out, and the sheared loops' quadratic rule gives pair_contact_time's bits.
TEST(RelativeMotion, AMovingImageAddsItsVelocity) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  for (int n = 0; n < 1000; ++n) {
    const Vec<2> xi{u(rng), u(rng)}, vi{u(rng), u(rng)}, shift{u(rng), 10.0};
    const Vec<2> image_velocity{3.0 * u(rng), 0.0};
    const double rec[4] = {u(rng), u(rng) - 10.0, u(rng), u(rng)};
    const double dtj = 0.5 * (u(rng) + 2.0);
    const RelativeMotion m = relative_motion_at<2, false, true>(xi, vi, rec, dtj, shift, nullptr,
                                                                nullptr, image_velocity.data());
    Vec<2> r, g;
    for (int a = 0; a < 2; ++a) {
      r[a] = xi[a] - ((rec[a] + rec[2 + a] * dtj) + shift[a]);
      g[a] = vi[a] - (rec[2 + a] + image_velocity[a]);
    }
    ASSERT_EQ(m.r2, norm2(r));
    ASSERT_EQ(m.rg, dot(r, g));
    ASSERT_EQ(m.g2, norm2(g));
    ASSERT_EQ(quadratic_contact_time(m, 1.3), pair_contact_time<2>(r.data(), g.data(), 1.3));
  }
}

TEST(RelativeMotion, ContactTestAtTheEdges) {
  double dt = -1.0;
  // Overlapping (distance 0.75 < 1) and approaching: they meet now.
  ASSERT_TRUE(contact_before(pair({0.75, 0.0, 0.0}, {-1.0, 0.0, 0.0}), 1.0, kNever, dt));
  EXPECT_EQ(dt, 0.0);
  // Overlapping and receding: never (they separate).
  EXPECT_FALSE(contact_before(pair({0.75, 0.0, 0.0}, {1.0, 0.0, 0.0}), 1.0, kNever, dt));
  // Touching and approaching: now; touching and receding, or sliding past: never.
  dt = -1.0;
  ASSERT_TRUE(contact_before(pair({1.0, 0.0, 0.0}, {-1.0, 0.0, 0.0}), 1.0, kNever, dt));
  EXPECT_EQ(dt, 0.0);
  EXPECT_FALSE(contact_before(pair({1.0, 0.0, 0.0}, {1.0, 0.0, 0.0}), 1.0, kNever, dt));
  EXPECT_FALSE(contact_before(pair({1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}), 1.0, kNever, dt));
  // A particle with itself: r = g = 0, never.
  const double self[7] = {0.25, 0.5, 0.75, 1.0, -1.0, 0.5, 0.0};
  EXPECT_FALSE(contact_before(
      relative_motion_at<3>({0.25, 0.5, 0.75}, {1.0, -1.0, 0.5}, self, 0.0, {}), 1.0, kNever, dt));
  // Passing at distance exactly sigma (a grazing line: r.g^2 = g.g (r.r - sigma^2)) and beyond
  // it: near misses, never.
  EXPECT_FALSE(contact_before(pair({3.0, 1.0, 0.0}, {-2.0, 0.0, 0.0}), 1.0, kNever, dt));
  EXPECT_FALSE(contact_before(pair({3.0, 1.5, 0.0}, {-2.0, 0.0, 0.0}), 1.0, kNever, dt));
  // Just inside the grazing line: a contact, after the time of closest approach (1.5) at most.
  ASSERT_TRUE(contact_before(pair({3.0, 0.9375, 0.0}, {-2.0, 0.0, 0.0}), 1.0, kNever, dt));
  EXPECT_GT(dt, 1.0);
  EXPECT_LT(dt, 1.5);
  // Nothing separated comes before now (best 0); an overlapping approaching pair still does.
  EXPECT_FALSE(contact_before(pair({3.0, 0.0, 0.0}, {-2.0, 0.0, 0.0}), 1.0, 0.0, dt));
  EXPECT_TRUE(contact_before(pair({0.75, 0.0, 0.0}, {-1.0, 0.0, 0.0}), 1.0, 0.0, dt));
}

// The cheap rejection before the square root only drops contacts after `best`: every contact
// sooner than best is found, with the time of the quadratic.
TEST(RelativeMotion, TheRejectionNeverDropsAnEarlierContact) {
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> u(-1.0, 1.0), b(0.0, 3.0);
  int sooner = 0, rejected = 0;
  for (int k = 0; k < 50000; ++k) {
    const Vec<3> r{2 * u(rng), 2 * u(rng), 2 * u(rng)}, g{u(rng), u(rng), u(rng)};
    const double best = b(rng);
    const double expected = pair_contact_time<3>(r.data(), g.data(), 1.0);
    double dt = -1.0;
    const bool found = contact_before(pair(r, g), 1.0, best, dt);
    if (expected < best) {
      ++sooner;
      ASSERT_TRUE(found) << "contact at " << expected << " dropped before best " << best;
    }
    if (found) {
      EXPECT_EQ(dt, expected);
    } else if (expected < kNever) {
      ++rejected;  // a contact there is, but not before best
    }
  }
  EXPECT_GT(sooner, 2000);  // both outcomes are well represented
  EXPECT_GT(rejected, 500);
}

}  // namespace
}  // namespace kairos
