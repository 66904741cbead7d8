// Fixed grains (docs/physics.md#fixed-grains): particles of a fixed species never move and have
// infinite mass, so a particle meets one as it meets a wall whose normal is the line of centres.
// Checked here: the analytic flight and bounce off a fixed grain (elastic and inelastic), a gas
// in a matrix of fixed grains (no overlap, the prediction invariant after every event, energy
// conserved to round-off, the grains untouched to the bit), a pile settling on a floor of fixed
// grains (every grain asleep above the floor, the energy budget closed), an exact resume, and
// the refusals (a moving fixed grain, every particle fixed, stepped potentials, a piston).
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "../interactions/input_error_matchers.hpp"
#include "../release_suite_only.hpp"
#include "core/error.hpp"
#include "engine/candidate_scan.hpp"
#include "engine/event_engine.hpp"
#include "engine_fixtures.hpp"
#include "scheduler/calendar_queue.hpp"

namespace kairos {
namespace {

template <int D>
using Engine = EventEngine<D, CalendarQueue>;

// Species 0 moves, species 1 is fixed; every pair collides with `law`.
template <int D>
Environment<D> with_fixed_species(const ContactModel& law) {
  Environment<D> env;
  env.species = 2;
  env.contact.assign(4, law);
  env.fixed = {0, 1};
  return env;
}

// The same under gravity -1 along the last axis, in a box with side walls, a floor and an open
// top, restitution e (and the TC model's tc).
template <int D>
Environment<D> box_with_floor(double e, double tc = 0.0) {
  Environment<D> env = testing::gravity_container<D>(e, tc, 2);
  env.fixed = {0, 1};
  return env;
}

// One sphere (species 0) aimed at a fixed one: it touches at t = 2 with the normal -x (the
// quadratic's discriminant is exactly 4), and leaves with its normal velocity reversed and
// scaled by e; at t = 4 it is where the straight flights say, and the fixed grain never moved.
void check_bounce_off_fixed_grain(double e, const Vec<3>& expected_at_4) {
  ParticleSystem<3> s;
  s.box = {10.0, 10.0, 10.0};
  s.kinematics = {{{2.0, 5.0, 5.0}, {1.0, 0.3, 0.0}, 0.0, 0.5},
                  {{5.0, 5.6, 5.0}, {0.0, 0.0, 0.0}, 0.0, 0.5}};
  s.mass = {1.0, 1.0};
  s.species = {0, 1};
  s.species_names = {"ball", "fixed"};
  ContactModel law;
  law.normal = NormalRestitution::constant(e);
  Engine<3> engine(s, StartMode::kPredict, EngineOptions{}, with_fixed_species<3>(law));
  EXPECT_EQ(engine.fixed_grains(), 1u);
  while (engine.next_event_time() <= 4.0) {
    engine.step();
    engine.validate();
  }
  engine.advance_clock(4.0);
  // A fixed grain's contact counts as a wall's (it moves one particle).
  EXPECT_EQ(engine.counters().collisions, 0u);
  EXPECT_EQ(engine.counters().wall_collisions, 1u);
  const std::vector<Vec<3>> x = engine.current_positions();
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(x[0][a], expected_at_4[a], 1e-12) << "axis " << a;
  EXPECT_EQ(x[1], s.kinematics[1].pos);  // bit for bit
  const std::vector<Vec<3>> v = engine.current_velocities();
  EXPECT_EQ(v[1], (Vec<3>{}));
  EXPECT_NEAR(v[0][0], -e, 1e-12);
  EXPECT_NEAR(v[0][1], 0.3, 1e-12);
  // The energy the contact took is the normal part's (1 - e^2) / 2.
  EXPECT_NEAR(engine.counters().dissipated_at_walls, 0.5 * (1.0 - e * e), 1e-12);
}

TEST(FixedGrains, ElasticBounceIsAWallsAlongTheLineOfCentres) {
  check_bounce_off_fixed_grain(1.0, {2.0, 6.2, 5.0});
}

TEST(FixedGrains, InelasticBounceLosesTheNormalPartOnly) {
  check_bounce_off_fixed_grain(0.5, {3.0, 6.2, 5.0});
}

// The fixture's lattice gas with its odd particles (species 1) fixed and at rest.
template <int D>
ParticleSystem<D> gas_in_matrix(int n, double eta, std::uint64_t seed) {
  ParticleSystem<D> s = testing::lattice_system<D>(n, eta, seed);
  for (std::size_t i = 0; i < s.size(); ++i)
    if (s.species[i] == 1) s.kinematics[i].vel = Vec<D>{};
  return s;
}

template <int D>
void check_gas_in_matrix(int n, double eta, int events, int validate_every) {
  const ParticleSystem<D> s = gas_in_matrix<D>(n, eta, 7);
  const ContactModel elastic;
  Engine<D> engine(s, StartMode::kPredict, EngineOptions{}, with_fixed_species<D>(elastic));
  EXPECT_EQ(engine.fixed_grains(), s.size() / 2);
  EXPECT_EQ(engine.sleeping(), 0u);
  const double ke0 = engine.kinetic_energy();
  ASSERT_GT(ke0, 0.0);
  for (int k = 0; k < events; ++k) {
    ASSERT_NE(engine.step(), EventKind::kNone);
    if (k % testing::validation_stride(validate_every) == 0) {
      ASSERT_NO_THROW(engine.validate()) << "event " << k;
    }
  }
  EXPECT_GT(engine.counters().collisions, static_cast<std::uint64_t>(events / 20));
  EXPECT_GT(engine.counters().wall_collisions, static_cast<std::uint64_t>(events / 20));
  EXPECT_NEAR(engine.kinetic_energy(), ke0, 1e-12 * ke0);
  EXPECT_LE(engine.max_overlap_now(), 1e-12);
  const std::vector<Vec<D>> x = engine.current_positions();
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.species[i] == 1) {
      EXPECT_EQ(x[i], s.kinematics[i].pos) << "fixed grain " << i << " moved";
    }
  }
}

TEST(FixedGrains, DiskGasInAMatrixConservesEnergyAndNeverOverlaps) {
  check_gas_in_matrix<2>(10, 0.35, 20000, 1);
}

TEST(FixedGrains, SphereGasInAMatrixConservesEnergyAndNeverOverlaps) {
  check_gas_in_matrix<3>(6, 0.25, 20000, 10);
}

// A run resumed from an exported state continues bit for bit (the fixed grains are the
// model's, marked again from their species; the sleepers' flags come from the state).
TEST(FixedGrains, ResumeContinuesBitForBit) {
  constexpr int D = 3;
  const ParticleSystem<D> s = gas_in_matrix<D>(5, 0.3, 11);
  const ContactModel elastic;
  const Environment<D> env = with_fixed_species<D>(elastic);
  Engine<D> first(s, StartMode::kPredict, EngineOptions{}, env);
  for (int k = 0; k < 3000; ++k) first.step();
  Engine<D> resumed(first.export_state(), StartMode::kResume, EngineOptions{}, env);
  EXPECT_EQ(resumed.fixed_grains(), first.fixed_grains());
  testing::expect_same_continuation(first, resumed, 3000);
}

// Grains (diameter 1) dropped from a loose lattice onto a floor of fixed grains spaced 1/15 of
// a diameter apart, between side walls, e = 0.8: they come to rest, every one asleep, none below
// the floor grains' tops (none slipped through or tunnelled), and the potential energy lost is
// what the contacts dissipated.
TEST(FixedGrains, PileSettlesOnAFloorOfFixedGrains) {
  constexpr int D = 2;
  constexpr int kFloor = 12;
  ParticleSystem<D> s;
  s.box = {kFloor * 16.0 / 15.0, 14.0};
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int k = 0; k < kFloor; ++k) {
    s.kinematics.push_back({{(k + 0.5) * s.box[0] / kFloor, 0.5}, {0.0, 0.0}, 0.0, 0.5});
    s.species.push_back(1);
  }
  for (int layer = 0; layer < 5; ++layer) {
    for (int c = 0; c < 7; ++c) {
      s.kinematics.push_back(
          {{0.9 + 1.7 * c + 0.05 * u(rng), 2.2 + 1.6 * layer}, {u(rng), u(rng)}, 0.0, 0.5});
      s.species.push_back(0);
    }
  }
  s.mass.assign(s.kinematics.size(), 1.0);
  s.species_names = {"grain", "floor"};
  const Environment<D> env = box_with_floor<D>(0.8);
  Engine<D> engine(s, StartMode::kPredict, EngineOptions{}, env);
  double e0 = engine.kinetic_energy();
  for (std::size_t i = kFloor; i < s.size(); ++i) e0 += s.kinematics[i].pos[1];
  std::uint64_t events = 0;
  while (engine.step() != EventKind::kNone) {
    ASSERT_LT(++events, 2000000u) << "the pile never settles";
    ASSERT_NO_THROW(engine.validate()) << "event " << events;
  }
  EXPECT_EQ(engine.fixed_grains(), static_cast<std::uint32_t>(kFloor));
  EXPECT_EQ(engine.sleeping(), s.size() - kFloor);
  EXPECT_EQ(engine.kinetic_energy(), 0.0);
  const std::vector<Vec<D>> x = engine.current_positions();
  double e1 = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (i < kFloor) {
      EXPECT_EQ(x[i], s.kinematics[i].pos);
      continue;
    }
    // Resting in a dip of the floor: sqrt(1 - (8/15)^2) above its grains' centres at least.
    EXPECT_GT(x[i][1], 0.5 + 0.84) << "grain " << i << " below the floor's top";
    e1 += x[i][1];
  }
  const EventCounters& c = engine.counters();
  EXPECT_NEAR(e1 - e0, -(c.dissipated_in_collisions + c.dissipated_at_walls), 1e-9 * e0);
}

// A disk dropped into the V between two fixed disks whose contacts are 72 degrees off the
// vertical, too steep for either to hold it alone: together they do, and it falls asleep there
// (before, it was lifted off one side and fell back onto the other for ever).
TEST(FixedGrains, DiskComesToRestInAVOfTwoSteepFixedGrains) {
  constexpr int D = 2;
  ParticleSystem<D> s;
  s.box = {8.0, 8.0};
  s.kinematics = {{{3.05, 2.0}, {0.0, 0.0}, 0.0, 0.5},
                  {{4.95, 2.0}, {0.0, 0.0}, 0.0, 0.5},
                  {{4.003, 4.0}, {0.0, 0.0}, 0.0, 0.5}};
  s.mass.assign(3, 1.0);
  s.species = {1, 1, 0};
  s.species_names = {"grain", "fixed"};
  const Environment<D> env = box_with_floor<D>(0.8);
  Engine<D> engine(s, StartMode::kPredict, EngineOptions{}, env);
  int events = 0;
  while (engine.step() != EventKind::kNone) {
    ASSERT_LT(++events, 100000) << "never comes to rest (t = " << engine.time() << ")";
    engine.validate();
  }
  EXPECT_EQ(engine.sleeping(), 1u);
  const Vec<D> x = engine.current_positions()[2];
  // In the V: its centre sqrt(1 - 0.95^2) = 0.31 above the fixed grains' centres.
  EXPECT_NEAR(x[1], 2.0 + std::sqrt(1.0 - 0.95 * 0.95), 1e-3);
  EXPECT_NEAR(x[0], 4.0, 1e-3);
}

// Under gravity with sleeping on, a state exported half-way (sleepers and fixed grains both
// flagged in it) resumes bit for bit: the fixed grains are marked again from their species and
// the sleepers' flags restored.
TEST(FixedGrains, SettlingOnFixedGrainsResumesBitForBit) {
  constexpr int D = 2;
  ParticleSystem<D> s;
  s.box = {12.0, 10.0};
  for (int k = 0; k < 12; ++k) {
    s.kinematics.push_back({{0.5 + k, 0.5}, {0.0, 0.0}, 0.0, 0.5});
    s.species.push_back(1);
  }
  for (int k = 0; k < 20; ++k) {
    s.kinematics.push_back({{0.9 + 1.1 * (k % 10), 2.5 + 1.5 * (k / 10)},
                            {0.3 * std::sin(k), 0.2 * std::cos(k)},
                            0.0,
                            0.5});
    s.species.push_back(0);
  }
  s.mass.assign(s.kinematics.size(), 1.0);
  s.species_names = {"grain", "fixed"};
  const Environment<D> env = box_with_floor<D>(0.7, 1e-4);
  Engine<D> first(s, StartMode::kPredict, EngineOptions{}, env);
  while (first.sleeping() < 5) ASSERT_NE(first.step(), EventKind::kNone);
  Engine<D> resumed(first.export_state(), StartMode::kResume, EngineOptions{}, env);
  EXPECT_EQ(resumed.sleeping(), first.sleeping());
  EXPECT_EQ(resumed.fixed_grains(), 12u);
  for (;;) {
    const EventKind a = first.step(), b = resumed.step();
    ASSERT_EQ(a, b);
    if (a == EventKind::kNone) break;
  }
  EXPECT_EQ(resumed.time(), first.time());
  EXPECT_EQ(resumed.sleeping(), 20u);
  EXPECT_EQ(resumed.current_positions(), first.current_positions());
}

// Grains falling onto fixed grains (a quartic per pair next to a sleeper) give the same run to
// the bit whichever candidate loop and list walk the CPU chooses: the loops list candidates in
// different orders, and an event time that depended on the running best it was searched under
// once made runs differ between CPUs (docs/physics.md#quartic-pair-contact).
TEST(FixedGrains, FallingOntoFixedGrainsIsTheSameRunWhateverTheCandidateOrder) {
  if (!cpu_has_avx512()) GTEST_SKIP() << "this CPU has no AVX-512: only the scalar loops run";
  constexpr int D = 2;
  ParticleSystem<D> s;
  s.box = {24.0, 16.0};
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int k = 0; k < 24; ++k) {  // a floor, and fixed obstacles above it
    s.kinematics.push_back({{0.5 + k, 0.5}, {0.0, 0.0}, 0.0, 0.5});
    s.species.push_back(1);
  }
  for (int k = 0; k < 6; ++k) {
    s.kinematics.push_back({{2.0 + 4.0 * k, 4.0}, {0.0, 0.0}, 0.0, 0.5});
    s.species.push_back(1);
  }
  for (int k = 0; k < 60; ++k) {
    s.kinematics.push_back(
        {{0.7 + 1.9 * (k % 12), 6.0 + 1.8 * (k / 12)}, {u(rng), u(rng)}, 0.0, 0.5});
    s.species.push_back(0);
  }
  s.mass.assign(s.kinematics.size(), 1.0);
  s.species_names = {"grain", "fixed"};
  const Environment<D> env = box_with_floor<D>(0.8, 1e-4);
  std::vector<EngineOptions> variants(4);
  variants[1].vector_scan = false;
  variants[2].list_gather = ListGather::kScalar;
  variants[3].list_gather = ListGather::kVector;
  std::vector<std::unique_ptr<Engine<D>>> engines;
  for (const EngineOptions& o : variants)
    engines.push_back(std::make_unique<Engine<D>>(s, StartMode::kPredict, o, env));
  for (int k = 0; k < 20000; ++k)
    for (auto& e : engines) e->step();
  ASSERT_GT(engines[0]->counters().wall_collisions, 1000u);  // grains met the fixed ones
  for (std::size_t v = 1; v < engines.size(); ++v) {
    EXPECT_EQ(engines[v]->time(), engines[0]->time()) << "variant " << v;
    EXPECT_EQ(engines[v]->current_positions(), engines[0]->current_positions()) << "variant " << v;
  }
}

// What the engine refuses, with errors that name the problem.
using test_util::error_of;

TEST(FixedGrains, RefusesAMovingFixedGrainAndAllFixed) {
  constexpr int D = 2;
  ParticleSystem<D> s = gas_in_matrix<D>(4, 0.3, 3);
  s.kinematics[3].vel = {0.1, 0.0};  // particle 3 is of species 1
  const ContactModel elastic;
  const std::string moving =
      error_of([&] { Engine<D> e(s, StartMode::kPredict, {}, with_fixed_species<D>(elastic)); });
  EXPECT_NE(moving.find("particle 3"), std::string::npos) << moving;
  EXPECT_NE(moving.find("at rest"), std::string::npos) << moving;

  ParticleSystem<D> all = gas_in_matrix<D>(4, 0.3, 3);
  for (auto& k : all.kinematics) k.vel = Vec<D>{};
  Environment<D> env = with_fixed_species<D>(elastic);
  env.fixed = {1, 1};
  const std::string none = error_of([&] { Engine<D> e(all, StartMode::kPredict, {}, env); });
  EXPECT_NE(none.find("nothing would move"), std::string::npos) << none;
}

TEST(FixedGrains, RefusesStepsAndPistons) {
  constexpr int D = 2;
  const ParticleSystem<D> s = gas_in_matrix<D>(4, 0.3, 3);
  const ContactModel elastic;
  Environment<D> stepped = with_fixed_species<D>(elastic);
  StepTable well;
  well.boundary = {1.5, 1.0};
  well.energy = {-1.0};
  stepped.tables = {well};
  stepped.pair_table = {0, 0, 0, 0};
  const std::string steps = error_of([&] { Engine<D> e(s, StartMode::kPredict, {}, stepped); });
  EXPECT_NE(steps.find("stepped potentials"), std::string::npos) << steps;

  Environment<D> piston = with_fixed_species<D>(elastic);
  for (int f = 0; f < 2 * D; ++f) piston.faces[f].kind = FaceKind::kWall;
  piston.faces[3].wall.velocity[1] = -0.01;
  ParticleSystem<D> boxed = s;
  const std::string moving = error_of([&] { Engine<D> e(boxed, StartMode::kPredict, {}, piston); });
  EXPECT_NE(moving.find("moves along its normal"), std::string::npos) << moving;
}

}  // namespace
}  // namespace kairos
