// Piles settling under gravity with sleeping particles: they come to rest (the engine runs out
// of events), every particle ends asleep, nothing overlaps or tunnels on the way (the
// prediction invariant checked by brute force), and the energy budget closes. Also the
// degenerate cases that used to stall: a particle falling into a gap of exactly its own size
// between two sleepers, and a particle pressed into a steep slope.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "engine/event_engine.hpp"
#include "engine_fixtures.hpp"
#include "scheduler/calendar_queue.hpp"

namespace kairos {
namespace {

template <int D>
using Engine = EventEngine<D, CalendarQueue>;

// Particles of diameter 1 on a loose lattice (spacing 1.6) in a box with walls on the sides, a
// floor and an open top, random velocities; gravity -1 along the last axis.
template <int D>
ParticleSystem<D> loose_grains(int per_row, int layers, std::uint64_t seed) {
  ParticleSystem<D> s;
  for (int a = 0; a < D - 1; ++a) s.box[a] = 1.6 * per_row;
  s.box[D - 1] = 1.6 * layers + 4.0;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int count = 1;
  for (int a = 0; a < D - 1; ++a) count *= per_row;
  for (int layer = 0; layer < layers; ++layer) {
    for (int c = 0; c < count; ++c) {
      Kinematics<D> k{};
      int rem = c;
      for (int a = 0; a < D - 1; ++a) {
        k.pos[a] = 0.8 + 1.6 * (rem % per_row) + 0.05 * u(rng);
        rem /= per_row;
      }
      k.pos[D - 1] = 0.8 + 1.6 * layer;
      for (int a = 0; a < D; ++a) k.vel[a] = u(rng);
      k.radius = 0.5;
      s.kinematics.push_back(k);
      s.mass.push_back(1.0);
      s.species.push_back(0);
    }
  }
  s.species_names = {"A"};
  return s;
}

// Runs until nothing can happen; checks the invariants every `check_every` events.
template <int D>
void check_pile_settles(int per_row, int layers, double e, double tc, std::uint64_t seed,
                        int check_every, std::uint64_t max_events) {
  const ParticleSystem<D> s = loose_grains<D>(per_row, layers, seed);
  Engine<D> engine(s, StartMode::kPredict, EngineOptions{}, testing::gravity_container<D>(e, tc));
  double e0 = engine.kinetic_energy();
  for (const Kinematics<D>& k : s.kinematics) e0 += k.pos[D - 1];
  std::uint64_t events = 0;
  while (engine.step() != EventKind::kNone) {
    ASSERT_LT(++events, max_events) << "the pile never settles (t = " << engine.time() << ", "
                                    << engine.sleeping() << " of " << s.size() << " asleep)";
    if (events % check_every == 0) {
      ASSERT_NO_THROW(engine.validate()) << "event " << events;
    }
  }
  engine.validate();
  EXPECT_EQ(engine.sleeping(), s.size());
  EXPECT_EQ(engine.kinetic_energy(), 0.0);
  // Every grain rests on the floor or on others, below its starting layer's top.
  double e1 = 0.0;
  for (const Vec<D>& x : engine.current_positions()) {
    EXPECT_GE(x[D - 1], 0.5 * (1.0 - 1e-12));
    e1 += x[D - 1];
  }
  const EventCounters& c = engine.counters();
  EXPECT_NEAR(e1 - e0, -(c.dissipated_in_collisions + c.dissipated_at_walls), 1e-9 * e0);
}

TEST(SettlingPile, DisksComeToRestWithoutOverlap) {
  check_pile_settles<2>(8, 5, 0.8, 0.0, 1, 1, 2000000);
}
TEST(SettlingPile, VeryInelasticDisksWithTcComeToRest) {
  check_pile_settles<2>(8, 5, 0.3, 1e-4, 2, 1, 2000000);
}
TEST(SettlingPile, NearlyElasticDisksComeToRest) {
  check_pile_settles<2>(6, 4, 0.95, 0.0, 3, 1, 2000000);
}
TEST(SettlingPile, SpheresComeToRestWithoutOverlap) {
  check_pile_settles<3>(5, 4, 0.8, 0.0, 4, 50, 5000000);
}
TEST(SettlingPile, SpheresWithTcComeToRest) {
  check_pile_settles<3>(5, 4, 0.8, 1e-4, 5, 50, 5000000);
}

// A disk falls into the gap between two resting disks that is exactly its own diameter wide,
// its centre a hair above theirs: every contact then approaches one of them at once, without
// time passing. It must stop there, not stall the run.
TEST(SettlingPile, DiskWedgedInAGapOfItsOwnSizeStops) {
  constexpr int D = 2;
  ParticleSystem<D> s;
  s.box = {6.0, 6.0};
  s.kinematics = {{{1.5, 0.5}, {0.0, 0.0}, 0.0, 0.5},
                  {{3.5, 0.5}, {0.0, 0.0}, 0.0, 0.5},
                  {{2.5, 0.5 + 3e-7}, {1e-9, -4e-3}, 0.0, 0.5}};
  s.mass = {1.0, 1.0, 1.0};
  s.species = {0, 0, 0};
  s.species_names = {"A"};
  Engine<D> engine(s, StartMode::kPredict, EngineOptions{},
                   testing::gravity_container<D>(0.8, 0.0));
  int events = 0;
  while (engine.step() != EventKind::kNone) {
    ASSERT_LT(++events, 1000) << "stalled at t = " << engine.time();
    engine.validate();
  }
  EXPECT_EQ(engine.sleeping(), 3u);
}

// A disk falls into a slot between two chains of resting disks that reach the side walls; the
// slot is narrower than the disk, so it meets both sides 0.004 above the floor, through nearly
// level normals, at 0.18: fast enough for a normal speed above the sleep speed. It wakes the
// chains, which have nowhere to go, and everything must come to rest with the disk held in the
// slot. (The rule that a wedged particle does not wake a sleeper is guarded by the run of
// examples/fixed_obstacles_2d.toml in tests/python/test_examples.py: without it that run ends
// in a frozen clock at t = 53.6, a falling grain waking its blocked neighbours again and again
// at one instant; this smaller case comes to rest either way.)
TEST(SettlingPile, DiskFallingIntoANarrowSlotBetweenBlockedChainsStops) {
  constexpr int D = 2;
  ParticleSystem<D> s;
  const double lift = 0.004;
  const double half = std::sqrt(1.0 - lift * lift);  // the slot's half width at contact
  const double w = 3.0 + 2.0 * half;
  s.box = {w, 8.0};
  s.kinematics = {{{0.5, 0.5}, {0.0, 0.0}, 0.0, 0.5},
                  {{1.5, 0.5}, {0.0, 0.0}, 0.0, 0.5},
                  {{w - 1.5, 0.5}, {0.0, 0.0}, 0.0, 0.5},
                  {{w - 0.5, 0.5}, {0.0, 0.0}, 0.0, 0.5},
                  {{0.5 * w + 1e-7, 0.5 + lift + 0.016}, {0.0, 0.0}, 0.0, 0.5}};
  s.mass.assign(5, 1.0);
  s.species.assign(5, 0);
  s.species_names = {"A"};
  Engine<D> engine(s, StartMode::kPredict, EngineOptions{},
                   testing::gravity_container<D>(0.8, 0.0));
  int events = 0;
  while (engine.step() != EventKind::kNone) {
    ASSERT_LT(++events, 10000) << "stalled at t = " << engine.time();
    engine.validate();
  }
  EXPECT_EQ(engine.sleeping(), 5u);
  EXPECT_LE(engine.max_overlap_now(), 1e-12);
  EXPECT_GT(engine.current_positions()[4][1], 0.5);  // held in the slot, above the floor
}

// A sphere resting on a single sleeper 70 degrees off its top is pressed into a slope too
// steep to hold it: it slides off (hops of the sleep speed, not an endless cascade of ever
// smaller bounces) and comes to rest on the floor.
TEST(SettlingPile, SphereSlidesOffASteepSlope) {
  constexpr int D = 3;
  ParticleSystem<D> s;
  s.box = {8.0, 8.0, 8.0};
  const double angle = 70.0 * M_PI / 180.0;
  s.kinematics = {
      {{4.0, 4.0, 0.5}, {0.0, 0.0, 0.0}, 0.0, 0.5},
      {{4.0 + std::sin(angle), 4.0, 0.5 + std::cos(angle) + 1e-9}, {0.0, 0.0, 0.0}, 0.0, 0.5}};
  s.mass = {1.0, 1.0};
  s.species = {0, 0};
  s.species_names = {"A"};
  Engine<D> engine(s, StartMode::kPredict, EngineOptions{},
                   testing::gravity_container<D>(0.8, 0.0));
  int events = 0;
  while (engine.step() != EventKind::kNone) {
    ASSERT_LT(++events, 100000) << "stalled at t = " << engine.time();
    engine.validate();
  }
  EXPECT_EQ(engine.sleeping(), 2u);
  const std::vector<Vec<D>> x = engine.current_positions();
  EXPECT_NEAR(x[1][2], 0.5, 1e-5);                                  // on the floor
  EXPECT_GE(std::hypot(x[1][0] - 4.0, x[1][1] - 4.0), 1.0 - 1e-9);  // beside the other
}

// A tower of three disks on the floor, and a fourth beside it on the floor touching the bottom
// one, settle and sleep; a thermostat's kick then moves the bottom disk of the tower away (up a
// little: a kick along the floor is stopped at once by the wedged rule). The
// two above it have lost their support and must wake and fall (before, they hung in the air for
// good), the disk beside it still rests on the floor and stays asleep; all four end asleep on
// the floor or on each other, nothing overlapping, every prediction checked on the way.
TEST(SettlingPile, SleepersWhoseSupportWakesFallInsteadOfHanging) {
  constexpr int D = 2;
  ParticleSystem<D> s;
  s.box = {12.0, 8.0};
  s.kinematics = {{{4.0, 0.5}, {0.0, 0.0}, 0.0, 0.5},
                  {{4.0, 1.5 + 1e-6}, {0.0, 0.0}, 0.0, 0.5},
                  {{4.0, 2.5 + 3e-6}, {0.0, 0.0}, 0.0, 0.5},
                  {{5.0 + 1e-7, 0.5}, {0.0, 0.0}, 0.0, 0.5}};
  s.mass = {1.0, 1.0, 1.0, 1.0};
  s.species = {0, 0, 0, 0};
  s.species_names = {"A"};
  EngineOptions keep_order;
  keep_order.renumber_interval = 0.0;  // internal index = the caller's
  Engine<D> engine(s, StartMode::kPredict, keep_order, testing::gravity_container<D>(0.5, 0.0));
  for (int k = 0; k < 2000 && engine.sleeping() < 4; ++k)
    ASSERT_NE(engine.step(), EventKind::kNone);
  ASSERT_EQ(engine.sleeping(), 4u);
  const double t = engine.time();
  engine.set_velocity(0, t, {-3.0, 0.3});  // the tower's bottom disk, away from the fourth
  EXPECT_EQ(engine.counters().lost_support, 2u);
  EXPECT_EQ(engine.sleeping(), 1u);  // the disk beside it is still held by the floor
  int events = 0;
  while (engine.step() != EventKind::kNone) {
    ASSERT_LT(++events, 100000) << "stalled at t = " << engine.time();
    if (events % 7 == 0) engine.validate();
  }
  EXPECT_EQ(engine.sleeping(), 4u);
  EXPECT_LT(engine.max_overlap_now(), 1e-10);
  // The upper two have come down: no centre is left at the tower's top height.
  for (const Vec<D>& x : engine.current_positions()) EXPECT_LT(x[1], 2.0) << x[0];
}

}  // namespace
}  // namespace kairos
