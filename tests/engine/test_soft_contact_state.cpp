// The soft contacts in progress (engine/soft_contact_state.hpp): partners, releases and their
// bits, deferred contacts, restored contacts, the renumbering and the component's own check.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <string>
#include <vector>

#include "core/event_code.hpp"
#include "engine/resting_particles.hpp"
#include "engine/soft_contact_state.hpp"

namespace kairos {
namespace {

constexpr std::uint32_t kFirstCode = 0x80000000u;  // partners from here on are walls

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

// Kept whole, as it was: a check of two components side by side (RestingParticles::validate and
// SoftContactState::validate).
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

// What validate() reports, message by message.
struct Faults {
  std::vector<std::string> messages;
  auto fail() {
    return [this](const std::string& what) { messages.push_back(what); };
  }
  static std::string name(std::uint32_t k) { return std::to_string(k); }
  // How many messages name particle k and contain `what`.
  int about(std::uint32_t k, const std::string& what) const {
    std::string particle = "particle ";
    particle += name(k);
    particle += ' ';
    int n = 0;
    for (const std::string& m : messages)
      n += m.find(particle) != std::string::npos && m.find(what) != std::string::npos;
    return n;
  }
};

const auto kNoneEnded = [](std::uint32_t) { return false; };
constexpr const char* kNotMutual = "partner is not in";
constexpr const char* kBadBit = "release bit";

TEST(SoftContactState, ValidateCatchesANonMutualContact) {
  SoftContactState<3> soft(4, true);
  soft.begin(0, 2);
  soft.begin(2, 0);
  soft.schedule_release(0, 1.0, {});
  soft.schedule_release(2, 1.0, {});
  Faults f;
  soft.validate(kFirstCode, kNoneEnded, f.fail(), Faults::name);
  EXPECT_TRUE(f.messages.empty());
  // 2 turns to 1, which is in no contact: neither 0 nor 2 is named back.
  soft.begin(2, 1);
  soft.validate(kFirstCode, kNoneEnded, f.fail(), Faults::name);
  EXPECT_EQ(f.messages.size(), 2u);
  EXPECT_EQ(f.about(0, kNotMutual), 1);
  EXPECT_EQ(f.about(2, kNotMutual), 1);
  // Contacts that are over (deferred and released, ended(k)) keep stale partners: not faults.
  f.messages.clear();
  soft.validate(
      kFirstCode, [](std::uint32_t k) { return k == 0 || k == 2; }, f.fail(), Faults::name);
  EXPECT_TRUE(f.messages.empty());
  // A partner number beyond the particles is caught, not followed.
  SoftContactState<3> beyond(4, false);
  beyond.begin(3, 7);
  beyond.schedule_release(3, 1.0, {});
  beyond.validate(kFirstCode, kNoneEnded, f.fail(), Faults::name);
  EXPECT_EQ(f.messages.size(), 1u);
  EXPECT_EQ(f.about(3, kNotMutual), 1);
}

TEST(SoftContactState, ValidateCatchesAStrayReleaseBit) {
  SoftContactState<3> soft(130, true);
  Faults f;
  // A release scheduled for a particle in no contact.
  soft.schedule_release(7, 1.0, {});
  soft.validate(kFirstCode, kNoneEnded, f.fail(), Faults::name);
  EXPECT_EQ(f.messages.size(), 1u);
  EXPECT_EQ(f.about(7, kBadBit), 1);
  soft.end_release(7);
  f.messages.clear();
  soft.validate(kFirstCode, kNoneEnded, f.fail(), Faults::name);
  EXPECT_TRUE(f.messages.empty());
  // A deferred pair waits for no release event: no bits. A bit on one of them is stray.
  soft.begin(64, 65);
  soft.begin(65, 64);
  soft.set_deferred(64, true);
  soft.set_deferred(65, true);
  soft.validate(kFirstCode, kNoneEnded, f.fail(), Faults::name);
  EXPECT_TRUE(f.messages.empty());
  soft.schedule_release(64, 2.0, {});
  soft.validate(kFirstCode, kNoneEnded, f.fail(), Faults::name);
  EXPECT_EQ(f.messages.size(), 1u);
  EXPECT_EQ(f.about(64, kBadBit), 1);
  // A frozen contact (not deferred) without its bit is caught too.
  f.messages.clear();
  soft.begin(129, EventCode<3>::wall(1).bits());
  soft.validate(kFirstCode, kNoneEnded, f.fail(), Faults::name);
  EXPECT_EQ(f.about(129, kBadBit), 1);
}

TEST(SoftContactState, ReleaseBitsAreOnePerParticleAcrossWords) {
  SoftContactState<2> soft(130, false);
  const std::vector<std::uint32_t> set{0, 62, 63, 64, 127, 128, 129};
  for (const std::uint32_t k : set) soft.schedule_release(k, 1.0, {});
  for (std::uint32_t k = 0; k < 130; ++k) {
    const bool want = std::find(set.begin(), set.end(), k) != set.end();
    EXPECT_EQ(soft.awaits_release(k), want) << k;
  }
  soft.end_release(63);
  soft.end_release(128);
  EXPECT_FALSE(soft.awaits_release(63));
  EXPECT_FALSE(soft.awaits_release(128));
  for (const std::uint32_t k : {0u, 62u, 64u, 127u, 129u}) EXPECT_TRUE(soft.awaits_release(k));
  EXPECT_FALSE(soft.awaits_release(65));
}

// Renumbering (new_index[old] = new for the partners, then order[new] = old for the arrays)
// carries every field with its particle: pairs stay pairs under their new numbers, walls stay
// walls, release times, velocities, deferral and release bits follow.
TEST(SoftContactState, RenumberingCarriesEveryFieldThroughAPermutation) {
  using State = SoftContactState<3>;
  const std::uint32_t wall = EventCode<3>::wall(4).bits();
  State soft(6, true);
  soft.begin(0, 3);  // a frozen pair
  soft.begin(3, 0);
  soft.schedule_release(0, 1.5, {1.0, 0.0, 0.0});
  soft.schedule_release(3, 1.5, {-1.0, 0.0, 0.0});
  soft.begin(1, 4);  // a deferred pair
  soft.begin(4, 1);
  soft.set_deferred(1, true);
  soft.set_deferred(4, true);
  soft.restore(1, 4, 2.5, {0.0, 2.0, 0.0});
  soft.restore(4, 1, 2.5, {0.0, -2.0, 0.0});
  soft.begin(5, wall);  // frozen against a wall
  soft.schedule_release(5, 3.5, {0.0, 0.0, 3.0});
  // Particle 2 is in no contact.
  struct Was {
    std::uint32_t partner;
    double time;
    Vec<3> velocity;
    bool deferred, awaits;
  };
  std::vector<Was> was;
  for (std::uint32_t k = 0; k < 6; ++k)
    was.push_back({soft.partner(k), soft.release_time(k), soft.release_velocity(k),
                   soft.deferred(k), soft.awaits_release(k)});
  const std::vector<std::uint32_t> order{5, 3, 0, 4, 2, 1};  // order[new] = old
  std::vector<std::uint32_t> new_index(6);
  for (std::uint32_t k = 0; k < 6; ++k) new_index[order[k]] = k;
  soft.renumber_partners(new_index, kFirstCode);
  std::vector<bool> done;
  soft.permute(order, done);
  for (std::uint32_t k = 0; k < 6; ++k) {
    const Was& w = was[order[k]];
    const std::uint32_t partner =
        w.partner < kFirstCode ? new_index[w.partner] : w.partner;  // walls and none unchanged
    EXPECT_EQ(soft.partner(k), partner) << k;
    EXPECT_EQ(soft.release_time(k), w.time) << k;
    EXPECT_EQ(soft.release_velocity(k)[0], w.velocity[0]) << k;
    EXPECT_EQ(soft.release_velocity(k)[1], w.velocity[1]) << k;
    EXPECT_EQ(soft.release_velocity(k)[2], w.velocity[2]) << k;
    EXPECT_EQ(soft.deferred(k), w.deferred) << k;
    EXPECT_EQ(soft.awaits_release(k), w.awaits) << k;
  }
  EXPECT_EQ(soft.partner(0), wall);          // the old 5
  EXPECT_EQ(soft.partner(4), State::kNone);  // the old 2
  Faults f;
  soft.validate(kFirstCode, kNoneEnded, f.fail(), Faults::name);
  EXPECT_TRUE(f.messages.empty()) << f.messages.front();
}

// Contacts read from a restart file come without their bits: the rebuild sets one for every
// contact that waits for a release (not the deferred ones).
TEST(SoftContactState, RestoredContactsGetTheirBitsFromTheRebuild) {
  SoftContactState<3> soft(5, true);
  const std::uint32_t wall = EventCode<3>::wall(0).bits();
  soft.restore(0, 1, 0.5, {1.0, 0.0, 0.0});
  soft.restore(1, 0, 0.5, {-1.0, 0.0, 0.0});
  soft.restore(2, 3, 0.75, {});
  soft.restore(3, 2, 0.75, {});
  soft.set_deferred(2, true);
  soft.set_deferred(3, true);
  soft.restore(4, wall, 0.25, {0.0, 1.0, 0.0});
  Faults f;
  soft.validate(kFirstCode, kNoneEnded, f.fail(), Faults::name);
  EXPECT_EQ(f.messages.size(), 3u);  // the frozen pair and the wall contact lack their bits
  EXPECT_EQ(f.about(0, kBadBit) + f.about(1, kBadBit) + f.about(4, kBadBit), 3);
  soft.rebuild_awaiting_release();
  const bool want[5] = {true, true, false, false, true};
  for (std::uint32_t k = 0; k < 5; ++k) EXPECT_EQ(soft.awaits_release(k), want[k]) << k;
  EXPECT_EQ(soft.partner(4), wall);
  EXPECT_EQ(soft.release_time(4), 0.25);
  EXPECT_EQ(soft.release_velocity(1)[0], -1.0);
  f.messages.clear();
  soft.validate(kFirstCode, kNoneEnded, f.fail(), Faults::name);
  EXPECT_TRUE(f.messages.empty());
}

// Without deferred releases every contact waits for its release event; a deferred contact given
// back early (forget) is in no contact, and a new contact starts not deferred.
TEST(SoftContactState, DeferringIsAnOption) {
  SoftContactState<3> plain(3, false);
  EXPECT_FALSE(plain.defers());
  plain.restore(0, 1, 1.0, {});
  plain.restore(1, 0, 1.0, {});
  plain.restore(2, EventCode<3>::wall(3).bits(), 1.0, {});
  plain.rebuild_awaiting_release();
  for (std::uint32_t k = 0; k < 3; ++k) {
    EXPECT_FALSE(plain.deferred(k));
    EXPECT_TRUE(plain.awaits_release(k)) << k;
  }
  // Memory: the flags of deferral are the one byte more per particle; none without the state.
  const SoftContactState<3> deferring(3, true);
  EXPECT_EQ(deferring.bytes_per_particle() - plain.bytes_per_particle(), 1.0);
  EXPECT_EQ(SoftContactState<3>().bytes_per_particle(), 0.0);
  EXPECT_EQ(SoftContactState<3>().size(), 0u);

  SoftContactState<3> soft(2, true);
  soft.begin(0, 1);
  soft.begin(1, 0);
  soft.set_deferred(0, true);
  soft.set_deferred(1, true);
  soft.forget(0);
  EXPECT_EQ(soft.partner(0), SoftContactState<3>::kNone);
  EXPECT_FALSE(soft.deferred(0));
  Faults f;
  soft.validate(kFirstCode, kNoneEnded, f.fail(), Faults::name);
  EXPECT_EQ(f.about(1, kNotMutual), 1);  // half given back
  soft.forget(1);
  f.messages.clear();
  soft.validate(kFirstCode, kNoneEnded, f.fail(), Faults::name);
  EXPECT_TRUE(f.messages.empty());
  soft.set_deferred(0, true);
  soft.begin(0, 1);
  EXPECT_FALSE(soft.deferred(0));
}

}  // namespace
}  // namespace kairos
