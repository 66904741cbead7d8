// Resting particles under gravity (engine/resting_particles.hpp): the sleep speed, the rules
// after a contact with a support (sleep, lift or nothing), who sleeps and how many, the restart
// flags, the renumbering and the component's own check.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/resting_particles.hpp"

namespace kairos {
namespace {

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

// The automatic sleep speed is that of a fall from a millionth of the smallest diameter under
// |g| (whatever g's direction); a configured speed is taken as it is, 0 meaning never.
TEST(RestingParticles, TheSleepSpeedOfARun) {
  const Vec<3> g{3.0, 0.0, -4.0};  // |g| = 5
  const double d_min = 0.5;
  const double v = RestingParticles<3>::speed_for(-1.0, g, d_min);
  EXPECT_NEAR(v * v / (2.0 * 5.0), 1e-6 * d_min, 1e-18);
  EXPECT_EQ(RestingParticles<3>::speed_for(0.25, g, d_min), 0.25);
  EXPECT_EQ(RestingParticles<3>::speed_for(0.0, g, d_min), 0.0);
  EXPECT_NEAR(RestingParticles<2>::speed_for(-1.0, {0.0, -5.0}, d_min), v, 1e-15);
  // Off unless made with a speed: no state, nothing asleep.
  const RestingParticles<3> off;
  EXPECT_FALSE(off.on());
  EXPECT_EQ(off.count(), 0u);
  EXPECT_FALSE(off.asleep(0));
  EXPECT_EQ(off.bytes_per_particle(), 0.0);
  const RestingParticles<3> on(5, v, g);
  EXPECT_TRUE(on.on());
  EXPECT_EQ(on.speed(), v);
  EXPECT_EQ(on.bytes_per_particle(), 1.0);
  for (std::uint32_t k = 0; k < 5; ++k) EXPECT_FALSE(on.asleep(k));
}

TEST(RestingParticles, TheCountFollowsSleepAndWake) {
  RestingParticles<3> rest(6, 0.1, {0.0, 0.0, -1.0});
  rest.fall_asleep(0);
  rest.fall_asleep(4);
  rest.fall_asleep(5);
  EXPECT_EQ(rest.count(), 3u);
  rest.wake(4);
  EXPECT_EQ(rest.count(), 2u);
  const std::vector<std::uint8_t> want{1, 0, 0, 0, 0, 1};
  for (std::uint32_t k = 0; k < 6; ++k) {
    EXPECT_EQ(rest.asleep(k), want[k] != 0) << k;
    EXPECT_EQ(rest.flag(k), want[k]) << k;  // the restart file's flag
  }
  const std::uint32_t awake[3] = {1, 2, 4}, some[2] = {3, 5};
  EXPECT_FALSE(rest.any_of(awake, 3));
  EXPECT_TRUE(rest.any_of(some, 2));
  EXPECT_FALSE(rest.any_of(some, 0));  // an empty list holds no sleeper
}

// validate(): the count is the number of flags, and sleepers do not move; awake particles may.
TEST(RestingParticles, ValidateCatchesACorruptedCount) {
  std::vector<std::string> faults;
  auto fail = [&](const std::string& what) { faults.push_back(what); };
  auto name = [](std::uint32_t k) { return std::to_string(k); };
  auto at_rest = [](std::uint32_t) { return Vec<3>{}; };
  auto awake_move = [](std::uint32_t k) { return k == 1 ? Vec<3>{} : Vec<3>{1.0, 2.0, 3.0}; };
  RestingParticles<3> rest(3, 0.1, {0.0, 0.0, -1.0});
  rest.fall_asleep(1);
  rest.validate(awake_move, fail, name);
  EXPECT_TRUE(faults.empty());
  // Put to sleep twice: one flag, a count of two.
  rest.fall_asleep(1);
  rest.validate(at_rest, fail, name);
  ASSERT_EQ(faults.size(), 1u);
  EXPECT_NE(faults[0].find("count"), std::string::npos) << faults[0];
  // Woken once: the flag is down, the count still one too many.
  faults.clear();
  rest.wake(1);
  rest.validate(at_rest, fail, name);
  ASSERT_EQ(faults.size(), 1u);
  EXPECT_NE(faults[0].find("count"), std::string::npos) << faults[0];
  faults.clear();
  // A moving sleeper is named.
  RestingParticles<3> other(3, 0.1, {0.0, 0.0, -1.0});
  other.fall_asleep(2);
  other.validate(
      [](std::uint32_t k) {
        return Vec<3>{0.0, 0.0, k == 2 ? -1e-12 : 0.0};
      },
      fail, name);
  ASSERT_EQ(faults.size(), 1u);
  EXPECT_NE(faults[0].find("particle 2 "), std::string::npos) << faults[0];
}

// supported() gathers the neighbourhood: settle() asks it only for a slow particle on a still
// support whose contact does not hold it up by itself.
TEST(RestingParticles, SettleAsksForASupportOnlyWhenItMatters) {
  const RestingParticles<3> rest(1, 0.1, {0.0, 0.0, -1.0});
  const Vec<3> up{0.0, 0.0, 1.0}, side{1.0, 0.0, 0.0}, still{}, moving{0.3, 0.0, 0.0};
  int asked = 0;
  auto count = [&] {
    ++asked;
    return false;
  };
  using Settle = RestingParticles<3>::Settle;
  rest.settle({0.01, 0.0, 0.0}, up, still, false, count);     // held up by this contact
  rest.settle({0.0, 0.0, 0.5}, up, still, true, count);       // wedged
  rest.settle({0.5, 0.0, 0.0}, side, still, false, count);    // too fast to sleep
  rest.settle({0.31, 0.0, 0.0}, side, moving, false, count);  // the support moves
  RestingParticles<3>().settle({0.0, 0.0, 0.0}, side, still, false, count);  // sleeping off
  EXPECT_EQ(asked, 0);
  EXPECT_EQ(rest.settle({0.05, 0.0, 0.0}, side, still, false, count).kind, Settle::kNothing);
  EXPECT_EQ(asked, 1);
}

// On a slope steeper than 60 degrees a slow particle rests only if something underneath holds
// it; otherwise gravity presses it into the slope and it leaves along the normal with half the
// sleep speed, whatever normal speed it had.
TEST(RestingParticles, ASlopeTooSteepToRestOnLiftsTheParticle) {
  const double speed = 0.1;
  const RestingParticles<3> rest(1, speed, {0.0, 0.0, -2.0});
  const double a = 70.0 * std::numbers::pi / 180.0;  // from the vertical
  const Vec<3> steep{std::sin(a), 0.0, std::cos(a)};
  ASSERT_FALSE(rest.holds_up(steep));
  auto never = [] { return false; };
  auto beneath = [] { return true; };
  using Settle = RestingParticles<3>::Settle;
  for (const double vn : {-0.02, 0.0, 0.03, 0.099}) {
    const Vec<3> v = vn * steep + Vec<3>{0.0, 0.01, 0.0};
    const Settle s = rest.settle(v, steep, {}, false, never);
    ASSERT_EQ(s.kind, Settle::kLift) << vn;
    EXPECT_NEAR(dot(v, steep) + s.lift, 0.5 * speed, 1e-15) << vn;
    EXPECT_EQ(rest.settle(v, steep, {}, false, beneath).kind, Settle::kSleep) << vn;
  }
  // Leaving it faster than the sleep speed: a real bounce.
  EXPECT_EQ(rest.settle(1.5 * speed * steep, steep, {}, false, never).kind, Settle::kNothing);
  // A gentler slope (50 degrees) holds it up by itself.
  const double b = 50.0 * std::numbers::pi / 180.0;
  const Vec<3> gentle{std::sin(b), 0.0, std::cos(b)};
  EXPECT_EQ(rest.settle(0.05 * gentle, gentle, {}, false, never).kind, Settle::kSleep);
  // A ceiling: gravity pulls it away; slow and unsupported it is left alone, no lift.
  EXPECT_EQ(rest.settle({0.0, 0.0, 0.0}, {0.0, 0.0, -1.0}, {}, false, never).kind,
            Settle::kNothing);
}

// The sleep speed itself is not slow: strict bounds, and a moving support never puts anything
// to sleep, not even a wedged particle.
TEST(RestingParticles, TheEdgesOfTheRules) {
  const double speed = 0.125;
  const RestingParticles<3> rest(1, speed, {0.0, 0.0, -1.0});
  const Vec<3> up{0.0, 0.0, 1.0};
  auto never = [] { return false; };
  using Settle = RestingParticles<3>::Settle;
  // Sliding along the floor at exactly the sleep speed: not asleep, lifted to half of it.
  const Settle slide = rest.settle({speed, 0.0, 0.0}, up, {}, false, never);
  ASSERT_EQ(slide.kind, Settle::kLift);
  EXPECT_EQ(slide.lift, 0.5 * speed);
  EXPECT_EQ(rest.settle({0.5 * speed, 0.0, 0.0}, up, {}, false, never).kind, Settle::kSleep);
  // Leaving the floor at exactly the sleep speed: a real bounce.
  EXPECT_EQ(rest.settle({0.0, 0.0, speed}, up, {}, false, never).kind, Settle::kNothing);
  // Wedged on a conveyor: carried, so lifted, not asleep.
  const Vec<3> belt{0.5, 0.0, 0.0};
  const Settle carried = rest.settle(belt, up, belt, true, never);
  ASSERT_EQ(carried.kind, Settle::kLift);
  EXPECT_EQ(carried.lift, 0.5 * speed);
  // Contacts within 60 degrees of straight up hold the particle, for gravity of any size and
  // direction (here 4 along -y, in 2D); exactly 60 degrees does not.
  const RestingParticles<2> flat(1, speed, {0.0, -4.0});
  EXPECT_TRUE(flat.holds_up({0.6, 0.8}));
  EXPECT_TRUE(flat.holds_up({-0.8, 0.6}));
  EXPECT_FALSE(flat.holds_up({std::sqrt(3.0) / 2.0, 0.5}));
  EXPECT_FALSE(flat.holds_up({0.0, -1.0}));
  // Wedged: moved at most 2e-9 of its radius since its previous event.
  EXPECT_TRUE(RestingParticles<3>::wedged(0.0, 0.5));
  EXPECT_TRUE(RestingParticles<3>::wedged(1e-9, 0.5));
  EXPECT_FALSE(RestingParticles<3>::wedged(1.01e-9, 0.5));
  // A sleeper is woken by a hit at the sleep speed or harder, approaching.
  EXPECT_TRUE(rest.hit_wakes(-speed));
  EXPECT_FALSE(rest.hit_wakes(speed));
}

// The support distance is a few (eight) bounce heights of the sleep speed, v^2 / (2 |g|) each,
// plus a round-off margin in the radius.
TEST(RestingParticles, TheSupportDistanceScalesAsABounceHeight) {
  const RestingParticles<3> rest(1, 0.1, {0.0, 0.0, -2.0});
  const double height = 0.1 * 0.1 / (2.0 * 2.0);
  EXPECT_NEAR(rest.support_distance(0.0), 8.0 * height, 1e-17);
  EXPECT_NEAR(rest.support_distance(1.0) - rest.support_distance(0.0), 1e-12, 1e-17);
  const RestingParticles<3> faster(1, 0.2, {0.0, 0.0, -2.0}), heavier(1, 0.1, {0.0, -8.0, 0.0});
  EXPECT_NEAR(faster.support_distance(0.0), 4.0 * rest.support_distance(0.0), 1e-17);
  EXPECT_NEAR(heavier.support_distance(0.0), 0.25 * rest.support_distance(0.0), 1e-17);
}

// Renumbering: afterwards particle k is the one that was order[k] (a longer cycle than a swap);
// the count is unchanged. Sleeping off: renumbering has nothing to move.
TEST(RestingParticles, RenumberingFollowsTheOrder) {
  RestingParticles<3> rest(6, 0.1, {0.0, 0.0, -1.0});
  rest.fall_asleep(1);
  rest.fall_asleep(3);
  rest.fall_asleep(4);
  const std::vector<std::uint32_t> order{4, 0, 3, 5, 1, 2};  // order[new] = old
  std::vector<bool> done;
  rest.permute(order, done);
  for (std::uint32_t k = 0; k < 6; ++k) {
    const bool was = order[k] == 1 || order[k] == 3 || order[k] == 4;
    EXPECT_EQ(rest.asleep(k), was) << k;
  }
  EXPECT_EQ(rest.count(), 3u);
  int faults = 0;
  rest.validate([](std::uint32_t) { return Vec<3>{}; }, [&](const std::string&) { ++faults; },
                [](std::uint32_t k) { return std::to_string(k); });
  EXPECT_EQ(faults, 0);
  RestingParticles<3> off;
  off.permute(order, done);
  EXPECT_EQ(off.count(), 0u);
  EXPECT_FALSE(off.asleep(0));
}

// A state without flags (empty `asleep`): nobody sleeps.
TEST(RestingParticles, AStateWithoutFlagsRestoresNobodyAsleep) {
  RestingParticles<3> rest(3, 0.1, {0.0, 0.0, -1.0});
  const std::vector<std::uint32_t> id{0, 1, 2};
  rest.restore({}, id);
  EXPECT_EQ(rest.count(), 0u);
  for (std::uint32_t k = 0; k < 3; ++k) EXPECT_FALSE(rest.asleep(k));
}

}  // namespace
}  // namespace kairos

namespace kairos {
namespace {

// Supports hold a particle together when straight up lies in the cone of their normals: two
// steep ones on either side of the vertical in 2D (a V), three around it in 3D; steep ones all
// on one side, or two in 3D, do not.
TEST(RestingParticles, SteepSupportsHoldTogetherWhenTheyEncloseTheVertical) {
  const double a = 75.0 * std::numbers::pi / 180.0;  // from the vertical: too steep alone
  const RestingParticles<2> disk(1, 0.01, {0.0, -3.0});
  const std::array<Vec<2>, 2> v{Vec<2>{std::sin(a), std::cos(a)},
                                Vec<2>{-std::sin(a), std::cos(a)}};
  ASSERT_FALSE(disk.holds_up(v[0]));
  ASSERT_FALSE(disk.holds_up(v[1]));
  EXPECT_TRUE(disk.hold_up(v.data(), 2));
  EXPECT_FALSE(disk.hold_up(v.data(), 1));
  const std::array<Vec<2>, 2> one_side{Vec<2>{std::sin(a), std::cos(a)},
                                       Vec<2>{std::sin(1.2 * a), std::cos(1.2 * a)}};
  EXPECT_FALSE(disk.hold_up(one_side.data(), 2));
  // A V that opens downwards (an overhang on either side) holds nothing.
  const std::array<Vec<2>, 2> under{Vec<2>{std::sin(a), -std::cos(a)},
                                    Vec<2>{-std::sin(a), -std::cos(a)}};
  EXPECT_FALSE(disk.hold_up(under.data(), 2));

  const RestingParticles<3> sphere(1, 0.01, {0.0, 0.0, -1.0});
  std::array<Vec<3>, 3> around{};
  for (int k = 0; k < 3; ++k) {
    const double phi = 2.0 * std::numbers::pi * k / 3.0;
    around[k] = {std::sin(a) * std::cos(phi), std::sin(a) * std::sin(phi), std::cos(a)};
  }
  EXPECT_TRUE(sphere.hold_up(around.data(), 3));
  EXPECT_FALSE(sphere.hold_up(around.data(), 2));  // two supports: a ridge it rolls off
  // ... unless the vertical lies in their plane: a level trough of two steep sides holds it,
  // a trough tilted by 1e-6 does not (it rolls along), nor one that opens downwards.
  const std::array<Vec<3>, 2> trough{Vec<3>{std::sin(a), 0.0, std::cos(a)},
                                     Vec<3>{-std::sin(a), 0.0, std::cos(a)}};
  EXPECT_TRUE(sphere.hold_up(trough.data(), 2));
  const double tilt = 1e-6;
  std::array<Vec<3>, 2> tilted = trough;
  for (Vec<3>& n : tilted) n = Vec<3>{n[0], std::cos(a) * std::sin(tilt), n[2] * std::cos(tilt)};
  EXPECT_FALSE(sphere.hold_up(tilted.data(), 2));
  const std::array<Vec<3>, 2> roof{Vec<3>{std::sin(a), 0.0, -std::cos(a)},
                                   Vec<3>{-std::sin(a), 0.0, -std::cos(a)}};
  EXPECT_FALSE(sphere.hold_up(roof.data(), 2));
  std::array<Vec<3>, 3> crowded{};
  for (int k = 0; k < 3; ++k) {
    const double phi = 0.5 * k;  // all within 60 degrees of azimuth of each other
    crowded[k] = {std::sin(a) * std::cos(phi), std::sin(a) * std::sin(phi), std::cos(a)};
  }
  EXPECT_FALSE(sphere.hold_up(crowded.data(), 3));
  // One support within 60 degrees is enough, among any others.
  std::array<Vec<3>, 2> mixed{crowded[0], Vec<3>{0.0, 0.0, 1.0}};
  EXPECT_TRUE(sphere.hold_up(mixed.data(), 2));
}

// Fixed grains: flag 2, counted apart from the sleepers, kept by a restore, never woken.
TEST(RestingParticles, FixedGrainsStayFixed) {
  RestingParticles<2> rest(4, 0.0, {0.0, -1.0});
  EXPECT_FALSE(rest.on());
  rest.fix(1);
  rest.fix(3);
  rest.fix(3);  // once is enough
  EXPECT_EQ(rest.count(), 2u);
  EXPECT_EQ(rest.fixed_count(), 2u);
  EXPECT_EQ(rest.sleepers(), 0u);
  EXPECT_TRUE(rest.fixed(1));
  EXPECT_TRUE(rest.asleep(1));
  EXPECT_FALSE(rest.fixed(0));
  EXPECT_THROW(rest.wake(1), std::logic_error);
  // A restart's flags replace the sleepers' but not the fixed grains'.
  const std::vector<std::uint8_t> stored{1, 0, 0, 0};
  const std::vector<std::uint32_t> id{0, 1, 2, 3};
  rest.restore(stored, id);
  EXPECT_TRUE(rest.asleep(0));
  EXPECT_TRUE(rest.fixed(1));
  EXPECT_TRUE(rest.fixed(3));
  EXPECT_EQ(rest.count(), 3u);
  EXPECT_EQ(rest.sleepers(), 1u);
  EXPECT_EQ(rest.flag(1), 1);  // exported as resting
  int failures = 0;
  std::string message;
  const auto fail = [&](const std::string& m) {
    ++failures;
    message = m;
  };
  const auto name = [](std::uint32_t k) { return std::to_string(k); };
  rest.validate([](std::uint32_t) { return Vec<2>{}; }, fail, name);
  EXPECT_EQ(failures, 0);
  rest.validate([](std::uint32_t k) { return k == 3 ? Vec<2>{0.1, 0.0} : Vec<2>{}; }, fail, name);
  EXPECT_EQ(failures, 1);
  EXPECT_NE(message.find("fixed particle 3 moves"), std::string::npos) << message;
}

}  // namespace
}  // namespace kairos
