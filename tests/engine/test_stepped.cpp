// Stepped potentials in the engine: square wells and many-step tables in 2D and 3D checked by
// brute force after every event (zones, no missed step, no overlap), total energy (kinetic plus
// the capture map's potential energy) conserved to round-off, the bounce-or-cross decision of
// a head-on pair either side of the escape speed, bonded chains that never exceed their
// length, and exact resumes that carry the capture map.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "engine/candidate_scan.hpp"
#include "engine/event_engine.hpp"
#include "engine_fixtures.hpp"
#include "interactions/granular_contact.hpp"
#include "interactions/potential_spec.hpp"
#include "scheduler/binary_heap_queue.hpp"
#include "scheduler/calendar_queue.hpp"

namespace kairos {
namespace {

// One table for every species pair (two species in the fixtures).
template <int D>
Environment<D> with_table(const StepTable& table) {
  Environment<D> env;
  env.species = 2;
  env.tables = {table};
  env.pair_table = {0, 0, 0, 0};
  return env;
}

// A well of three steps and a shoulder inside it (contact distance 1).
StepTable staircase() {
  StepTable t;
  t.boundary = {1.6, 1.4, 1.2, 1.1, 1.0};
  t.energy = {-0.3, -0.7, -1.0, 0.5};
  return t;
}

// Beads of a square-well (depth 0.5) solvent, consecutive ones in each lattice row of 6 tethered
// between the core (1) and 1.3.
void bond_rows_of_six(ParticleSystem<3>& s) {
  for (std::uint32_t i = 0; i + 1 < s.size(); ++i)
    if ((i + 1) % 6 != 0) s.bonds.push_back({i, i + 1, 0});
  s.bond_types = {"backbone"};
}

Environment<3> tethered_in_square_well() {
  Environment<3> env = with_table<3>(square_well(1.0, 1.5, 0.5));
  env.tables.push_back({{1.3, 1.0}, {0.0}, std::numeric_limits<double>::infinity()});
  env.bond_table = {1};
  return env;
}

template <int D>
double total_energy(const EventEngine<D, CalendarQueue>& e) {
  return e.kinetic_energy() + e.potential_energy();
}

template <int D>
void run_checked(const ParticleSystem<D>& start, const Environment<D>& env, int events,
                 int validate_every) {
  EventEngine<D, CalendarQueue> engine(start, StartMode::kPredict, {}, env);
  ASSERT_TRUE(engine.stepped());
  engine.validate();
  const double e0 = total_energy(engine);
  const Vec<D> p0 = engine.momentum();
  for (int k = 0; k < events; ++k) {
    ASSERT_NE(engine.step(), EventKind::kNone);
    if (k % validate_every == 0) engine.validate();
  }
  engine.validate();
  EXPECT_NEAR(total_energy(engine), e0, 1e-11 * std::abs(e0));
  for (int a = 0; a < D; ++a) EXPECT_NEAR(engine.momentum()[a], p0[a], 1e-11);
  EXPECT_GT(engine.counters().step_crossings, 0u);
  EXPECT_GT(engine.counters().step_bounces, 0u);
}

TEST(Stepped, SquareWell3DValidatedEveryEvent) {
  run_checked<3>(testing::lattice_system<3>(5, 0.25, 1), with_table<3>(square_well(1.0, 1.5, 1.0)),
                 4000, 1);
}

TEST(Stepped, Staircase3DValidated) {
  run_checked<3>(testing::lattice_system<3>(6, 0.3, 2), with_table<3>(staircase()), 6000, 6);
}

TEST(Stepped, SquareWell2DValidated) {
  run_checked<2>(testing::lattice_system<2>(12, 0.35, 3), with_table<2>(square_well(1.0, 1.5, 1.0)),
                 6000, 2);
}

TEST(Stepped, SquareShoulderAndHardPairsMixed) {
  // Species A-A interact by a shoulder, A-B and B-B are hard spheres of unequal size and mass.
  const ParticleSystem<3> s = testing::lattice_system<3>(6, 0.3, 4, 2.0, 0.8);
  Environment<3> env;
  env.species = 2;
  env.tables = {square_well(1.0, 1.3, -0.8)};
  env.pair_table = {0, -1, -1, -1};
  run_checked<3>(s, env, 5000, 5);
}

// A box only 3 cells wide (each cell holds pairs that also meet through the periodic wrap):
// the other image of a listed pair must not disturb the zones.
TEST(Stepped, BoxOfThreeCellsValidated) {
  const ParticleSystem<3> s = testing::lattice_system<3>(3, 0.12, 10);
  Environment<3> env = with_table<3>(square_well(1.0, 1.5, 1.0));
  EventEngine<3, CalendarQueue> engine(s, StartMode::kPredict, {}, env);
  ASSERT_EQ(engine.grid().cells_along(0), 3);
  const double e0 = total_energy(engine);
  for (int k = 0; k < 5000; ++k) {
    ASSERT_NE(engine.step(), EventKind::kNone);
    engine.validate();
  }
  EXPECT_NEAR(total_energy(engine), e0, 1e-11 * std::abs(e0));
}

// Sticky grains: a square well around an inelastic core (e = 0.8), under gravity between a
// floor and a lid. Every event validated now and then; the budget K + U + gravitational
// energy + dissipated stays constant.
TEST(Stepped, InelasticWellsUnderGravityWithWalls) {
  ParticleSystem<3> s = testing::lattice_system<3>(5, 0.15, 11);
  Environment<3> env = with_table<3>(square_well(1.0, 1.3, 0.5));
  env.contact.assign(4, ContactModel{});
  for (ContactModel& c : env.contact) c.normal = NormalRestitution::constant(0.8);
  env.gravity = {0.0, 0.0, -0.5};
  env.faces[4].kind = FaceKind::kWall;
  env.faces[5].kind = FaceKind::kWall;
  // Shift the lattice up by half a diameter, so nothing touches the floor, and make room.
  for (auto& k : s.kinematics) k.pos[2] += 0.5;
  s.box[2] += 1.0;
  EventEngine<3, CalendarQueue> engine(s, StartMode::kPredict, {}, env);
  auto budget = [&] {
    double e = total_energy(engine) + engine.counters().dissipated_in_collisions;
    for (std::uint32_t i = 0; i < engine.size(); ++i)
      e += 0.5 * engine.position(i, engine.time())[2];
    return e;
  };
  const double b0 = budget();
  for (int k = 0; k < 8000; ++k) {
    ASSERT_NE(engine.step(), EventKind::kNone);
    if (k % 10 == 0) engine.validate();
  }
  EXPECT_GT(engine.counters().dissipated_in_collisions, 0.0);
  EXPECT_GT(engine.counters().step_crossings, 0u);
  EXPECT_NEAR(budget(), b0, 1e-9 * std::abs(b0));
}

TEST(Stepped, EnergyConservedOverAMillionEventsAtLiquidDensity) {
  // rho = 0.7 (eta = 0.367) square-well liquid, lambda = 1.5: K + U constant to round-off.
  EventEngine<3, CalendarQueue> engine(testing::lattice_system<3>(8, 0.367, 5), StartMode::kPredict,
                                       {}, with_table<3>(square_well(1.0, 1.5, 1.0)));
  const double e0 = total_energy(engine);
  double worst = 0.0;
  for (int k = 0; k < 1000000; ++k) {
    ASSERT_NE(engine.step(), EventKind::kNone);
    if (k % 1000 == 0) worst = std::max(worst, std::abs(total_energy(engine) - e0));
  }
  EXPECT_LT(worst, 1e-10 * std::abs(e0));
  EXPECT_LT(engine.potential_energy(),
            -1.0 * static_cast<double>(engine.size()));  // most pairs sit in the well
  engine.validate();                                     // no overlap, every pair in its zone
}

// Two particles head on along x through a shoulder of height h: below the speed that pays h
// they bounce off it, above it they cross (and slow down) and meet the core.
TEST(Stepped, HeadOnBounceOrCrossAtTheEscapeSpeed) {
  const double h = 0.5;
  const double critical = std::sqrt(4.0 * h);  // mu = 1/2: (mu/2) v^2 = h with v the closing speed
  for (const double factor : {1.0 - 1e-9, 1.0 + 1e-9}) {
    const double v = critical * factor;
    ParticleSystem<3> s;
    s.box = {20.0, 20.0, 20.0};
    s.kinematics = {{{5.0, 10.0, 10.0}, {0.5 * v, 0.0, 0.0}, 0.0, 0.5},
                    {{8.0, 10.0, 10.0}, {-0.5 * v, 0.0, 0.0}, 0.0, 0.5}};
    s.mass = {1.0, 1.0};
    s.species = {0, 0};
    s.species_names = {"A"};
    Environment<3> env;
    env.species = 1;
    env.tables = {square_well(1.0, 1.5, -h)};
    env.pair_table = {0};
    EventEngine<3, CalendarQueue> engine(s, StartMode::kPredict, {}, env);
    EventKind kind;
    while ((kind = engine.step()) != EventKind::kCollision) ASSERT_NE(kind, EventKind::kNone);
    EXPECT_NEAR(engine.time(), 1.5 / v, 1e-12);
    const double vx = engine.velocity(0, engine.time())[0];
    if (factor < 1.0) {
      EXPECT_EQ(engine.counters().step_bounces, 1u);
      EXPECT_NEAR(vx, -0.5 * v, 1e-12);
      EXPECT_EQ(engine.potential_energy(), 0.0);
    } else {
      EXPECT_EQ(engine.counters().step_crossings, 1u);
      EXPECT_NEAR(vx, 0.5 * std::sqrt(v * v - 4.0 * h), 1e-6);
      EXPECT_EQ(engine.potential_energy(), h);
    }
  }
}

// Chains of 6 beads tethered between the core (1) and 1.3 in a square-well solvent of their
// own kind: every bond stays within its limits, checked after every event.
TEST(Stepped, TetheredChainsKeepTheirBonds) {
  ParticleSystem<3> s = testing::lattice_system<3>(6, 0.3, 6);
  const double spacing = s.box[0] / 6.0;
  ASSERT_LT(spacing, 1.3);
  bond_rows_of_six(s);
  const Environment<3> env = tethered_in_square_well();
  EventEngine<3, CalendarQueue> engine(s, StartMode::kPredict, {}, env);
  const double e0 = total_energy(engine);
  for (int k = 0; k < 20000; ++k) {
    ASSERT_NE(engine.step(), EventKind::kNone);
    if (k % 20 == 0) engine.validate();
    if (k % 50 == 0) {
      const auto x = engine.current_positions();
      for (const Bond& b : s.bonds) {
        Vec<3> r = x[b.i] - x[b.j];
        for (int a = 0; a < 3; ++a) r[a] = minimum_image(r[a], s.box[a]);
        ASSERT_LE(std::sqrt(norm2(r)), 1.3 * (1.0 + 1e-12)) << "bond " << b.i << "-" << b.j;
        ASSERT_GE(std::sqrt(norm2(r)), 1.0 * (1.0 - 1e-12));
      }
    }
  }
  EXPECT_NEAR(total_energy(engine), e0, 1e-11 * std::abs(e0));
  EXPECT_GT(engine.counters().step_bounces, 0u);
}

// Bead-spring chains in 2D: harmonic springs (k = 50, rest length 1.1, at most 1.3) stepped in
// 8 equal-energy steps; no pair potential between beads. Bonds stay within [1, 1.3], energy is
// conserved, and the springs store energy (beads are not all at the rest length).
TEST(Stepped, SteppedSpringChains2D) {
  ParticleSystem<2> s = testing::lattice_system<2>(12, 0.5, 9);
  const double spacing = s.box[0] / 12.0;
  ASSERT_GT(spacing, 1.0);
  ASSERT_LT(spacing, 1.3);
  for (std::uint32_t i = 0; i + 1 < s.size(); ++i)
    if ((i + 1) % 12 != 0) s.bonds.push_back({i, i + 1, 0});
  s.bond_types = {"backbone"};
  PotentialSpec spring;
  spring.kind = "spring";
  spring.stiffness = 50.0;
  spring.length = 1.1;
  spring.max_length = 1.3;
  spring.steps = 8;
  Environment<2> env;
  env.tables = {make_step_table(spring, 1.0, 2)};
  env.bond_table = {0};
  ASSERT_GT(env.tables[0].energy.size(), 4u);
  EventEngine<2, CalendarQueue> engine(s, StartMode::kPredict, {}, env);
  const double e0 = engine.kinetic_energy() + engine.potential_energy();
  double u_max = 0.0;
  for (int k = 0; k < 20000; ++k) {
    ASSERT_NE(engine.step(), EventKind::kNone);
    if (k % 25 == 0) engine.validate();  // bonded pairs stay in their zones
    u_max = std::max(u_max, engine.potential_energy());
  }
  EXPECT_NEAR(engine.kinetic_energy() + engine.potential_energy(), e0, 1e-11 * std::abs(e0));
  EXPECT_GT(u_max, 0.0);
  EXPECT_GT(engine.counters().step_crossings, 0u);
  EXPECT_GT(engine.counters().step_bounces, 0u);
}

TEST(Stepped, StretchedBondIsAnInputError) {
  ParticleSystem<3> s = testing::lattice_system<3>(4, 0.05, 7);
  s.bonds = {{0, 2, 0}};  // two spacings apart
  s.bond_types = {"backbone"};
  const Environment<3> env = tethered_in_square_well();
  try {
    EventEngine<3, CalendarQueue> engine(s, StartMode::kPredict, {}, env);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bond 0-2 is stretched"), std::string::npos) << e.what();
  }
}

// Resuming from export_state() continues bit-identically: the zones travel with the state.
template <class Queue>
void expect_exact_resume() {
  ParticleSystem<3> s = testing::lattice_system<3>(6, 0.3, 8);
  Environment<3> env = with_table<3>(staircase());
  EventEngine<3, Queue> a(s, StartMode::kPredict, {}, env);
  for (int k = 0; k < 5000; ++k) a.step();
  const ParticleSystem<3> mid = a.export_state();
  ASSERT_TRUE(mid.zones.has_value());
  ASSERT_FALSE(mid.zones->empty());
  EventEngine<3, Queue> b(mid, StartMode::kResume, {}, env);
  for (int k = 0; k < 5000; ++k) {
    a.step();
    b.step();
  }
  const ParticleSystem<3> x = a.export_state(), y = b.export_state();
  EXPECT_EQ(a.time(), b.time());
  EXPECT_TRUE(*x.zones == *y.zones);
  for (std::size_t i = 0; i < x.size(); ++i) {
    EXPECT_EQ(x.kinematics[i].pos, y.kinematics[i].pos);
    EXPECT_EQ(x.kinematics[i].vel, y.kinematics[i].vel);
  }
  EXPECT_EQ(a.potential_energy(), b.potential_energy());
  // Without its zones the state cannot be resumed.
  ParticleSystem<3> bare = mid;
  bare.zones.reset();
  EXPECT_THROW((EventEngine<3, Queue>(bare, StartMode::kResume, {}, env)), InputError);
}

TEST(Stepped, ExactResumeCalendar) {
  expect_exact_resume<CalendarQueue>();
}
TEST(Stepped, ExactResumeHeap) {
  expect_exact_resume<BinaryHeapQueue>();
}

// The AVX-512 stepped loop (scan_stepped_avx512) against the scalar one: bit-identical runs
// (positions, velocities, zones, counters) for a square well, a many-zone table with shoulders,
// hard pairs of another size mixed in (per-kind rows), bonds (a second table), a box of three
// cells (periodic shifts), 2D, and gravity with walls (the accelerated loop).
template <int D>
void expect_stepped_loops_agree(const ParticleSystem<D>& start, const Environment<D>& env,
                                int events) {
  EngineOptions scalar;
  scalar.vector_scan = false;
  EventEngine<D, CalendarQueue> a(start, StartMode::kPredict, scalar, env);
  EventEngine<D, CalendarQueue> b(start, StartMode::kPredict, {}, env);
  for (int k = 0; k < events; ++k) {
    a.step();
    b.step();
  }
  const ParticleSystem<D> x = a.export_state(), y = b.export_state();
  ASSERT_EQ(a.time(), b.time());
  for (std::size_t i = 0; i < x.size(); ++i) {
    ASSERT_EQ(x.kinematics[i].pos, y.kinematics[i].pos) << "particle " << i;
    ASSERT_EQ(x.kinematics[i].vel, y.kinematics[i].vel) << "particle " << i;
  }
  EXPECT_TRUE(*x.zones == *y.zones);
  EXPECT_EQ(a.counters().step_crossings, b.counters().step_crossings);
  EXPECT_EQ(a.counters().step_bounces, b.counters().step_bounces);
  EXPECT_EQ(a.counters().stale_events, b.counters().stale_events);
  EXPECT_GT(a.counters().step_crossings, 0u);
}

TEST(Stepped, VectorAndScalarLoopsGiveBitIdenticalRuns) {
  if (!cpu_has_avx512()) GTEST_SKIP() << "this CPU has no AVX-512: only the scalar loop runs";
  expect_stepped_loops_agree<3>(testing::lattice_system<3>(8, 0.26, 31),
                                with_table<3>(square_well(1.0, 1.5, 1.0)), 60000);
  expect_stepped_loops_agree<3>(testing::lattice_system<3>(7, 0.3, 32), with_table<3>(staircase()),
                                40000);
  PotentialSpec lj;
  lj.kind = "lennard_jones";
  lj.cutoff = 2.0;
  lj.steps = 6;
  expect_stepped_loops_agree<3>(testing::lattice_system<3>(7, 0.3, 33),
                                with_table<3>(make_step_table(lj, 1.0)), 30000);
  {
    Environment<3> env;
    env.species = 2;
    env.tables = {square_well(1.0, 1.3, -0.8)};
    env.pair_table = {0, -1, -1, -1};
    expect_stepped_loops_agree<3>(testing::lattice_system<3>(7, 0.3, 34, 2.0, 0.8), env, 40000);
  }
  {
    ParticleSystem<3> s = testing::lattice_system<3>(6, 0.3, 35);
    bond_rows_of_six(s);
    expect_stepped_loops_agree<3>(s, tethered_in_square_well(), 40000);
  }
  expect_stepped_loops_agree<3>(testing::lattice_system<3>(3, 0.12, 36),
                                with_table<3>(square_well(1.0, 1.5, 1.0)), 20000);
  expect_stepped_loops_agree<2>(testing::lattice_system<2>(20, 0.35, 37),
                                with_table<2>(square_well(1.0, 1.5, 1.0)), 40000);
  {
    ParticleSystem<3> s = testing::lattice_system<3>(5, 0.15, 38);
    Environment<3> env = with_table<3>(square_well(1.0, 1.3, 0.5));
    env.gravity = {0.0, 0.0, -0.5};
    env.faces[4].kind = FaceKind::kWall;
    env.faces[5].kind = FaceKind::kWall;
    for (auto& k : s.kinematics) k.pos[2] += 0.5;
    s.box[2] += 1.0;
    expect_stepped_loops_agree<3>(s, env, 20000);
  }
}

}  // namespace
}  // namespace kairos
