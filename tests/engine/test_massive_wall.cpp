// Walls with mass (boundaries/wall_body.hpp, docs/physics.md#walls-with-mass): a face wall whose
// plane moves along its axis under a constant force, the field and the impulses of the
// particles. Checked here: the analytic first contact and its two-body impulse; gases under a
// free piston in 2D and 3D with the prediction invariant checked against brute force after
// every event (no contact missed while the wall moves through layers of cells), momentum and
// energy budgets closed to round-off (the wall's energy is what its work took from the
// particles); a heavy lid on an inelastic bed under gravity; two rough lids; a lid pushed out
// of the box, the gas following it; an exact resume; the errors (a motion for a face without
// mass, a resume without the motion).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <tuple>
#include <type_traits>
#include <vector>

#include "../interactions/input_error_matchers.hpp"
#include "../release_suite_only.hpp"
#include "core/error.hpp"
#include "engine/event_engine.hpp"
#include "engine_fixtures.hpp"
#include "scheduler/binary_heap_queue.hpp"
#include "scheduler/calendar_queue.hpp"

namespace kairos {
namespace {

template <int D>
using Engine = EventEngine<D, CalendarQueue>;

constexpr int kLid3 = 5;  // z+ in 3D

// Walls on the faces of the last axis (the others periodic), the high one (the lid) of mass M
// pushed into the box by `force`; every contact of restitution e.
template <int D>
Environment<D> piston(double mass, double force, double e = 1.0, double gravity = 0.0) {
  Environment<D> env = testing::walls_on_last_axis<D>(e, gravity);
  env.faces[2 * D - 1].wall.mass = mass;
  env.faces[2 * D - 1].wall.force = force;
  return env;
}

using testing::gas_between_walls;

// The wall's mechanical energy plus the particles' kinetic and field energy.
template <class EngineType>
double total_energy(const EngineType& engine, int lid) {
  constexpr int D = std::tuple_size_v<std::remove_cvref_t<decltype(engine.box())>>;
  double e = engine.kinetic_energy() + engine.boundaries().faces().energy(lid, engine.time());
  const std::vector<Vec<D>> x = engine.current_positions();
  for (std::size_t i = 0; i < x.size(); ++i)
    e -= engine.environment().gravity[D - 1] * x[i][D - 1];  // masses 1
  return e;
}

// One sphere (mass 1) rising at speed 1 from z = 5 towards a lid of mass 4 at z = 10 pushed
// down by a force 2 (acceleration 1/2): its top 5.5 + t meets the lid 10 - t^2 / 4 at
// t1 = 2 (sqrt(5.5) - 1). The relative speed is u = 1 + t1 / 2 = sqrt(5.5); an elastic contact
// of the reduced mass 4/5 gives the impulse J = 8u/5: the sphere leaves at 1 - J, the lid at
// -t1 / 2 + J / 4.
TEST(MassiveWall, FirstContactIsTheTwoBodyCollisionWithTheLid) {
  ParticleSystem<3> s;
  s.box = {10.0, 10.0, 10.0};
  s.kinematics = {{{3.0, 3.0, 5.0}, {0.0, 0.0, 1.0}, 0.0, 0.5},
                  {{7.0, 7.0, 2.0}, {0.0, 0.0, 0.0}, 0.0, 0.5}};
  s.mass = {1.0, 1.0};
  s.species = {0, 0};
  Engine<3> engine(s, StartMode::kPredict, EngineOptions{}, piston<3>(4.0, 2.0));
  const FaceWalls<3>& walls = engine.boundaries().faces();
  const double t1 = 2.0 * (std::sqrt(5.5) - 1.0);
  const double e0 = total_energy(engine, kLid3);
  EventKind kind = EventKind::kNone;
  while ((kind = engine.step()) != EventKind::kWallCollision) {
    ASSERT_NE(kind, EventKind::kNone);
    ASSERT_NO_THROW(engine.validate());
  }
  ASSERT_NO_THROW(engine.validate());
  EXPECT_NEAR(engine.time(), t1, 1e-12);
  const double u = std::sqrt(5.5), impulse = 1.6 * u;
  EXPECT_NEAR(engine.current_velocities()[0][2], 1.0 - impulse, 1e-12);
  EXPECT_NEAR(walls.body(kLid3).speed_at(engine.time()), -0.5 * t1 + impulse / 4.0, 1e-12);
  EXPECT_NEAR(walls.position(kLid3, engine.time()), 10.0 - 0.25 * t1 * t1, 1e-12);
  // Elastic: the sphere's energy gain is the lid's loss.
  EXPECT_NEAR(total_energy(engine, kLid3), e0, 1e-12);
  EXPECT_NEAR(walls.energy(kLid3, engine.time()), -engine.counters().work_by_walls, 1e-12);
}

// A gas under a free piston: every event keeps the prediction invariant (validate() compares
// each particle's event with brute-force contact times with every particle and wall), nothing
// overlaps, the lid moves through several layers of cells, and the energy of gas plus lid is
// conserved to round-off; the lid's energy change is minus the work it did on the gas. The
// momentum along the axis changes only by the impulses of the floor and the force on the lid.
template <int D, class Queue = CalendarQueue>
void check_gas_under_piston(int n, double eta, double mass, double force, int events,
                            int validate_every) {
  const ParticleSystem<D> s = gas_between_walls<D>(n, eta, 11);
  const double height = s.box[D - 1];
  EventEngine<D, Queue> engine(s, StartMode::kPredict, EngineOptions{}, piston<D>(mass, force));
  const int lid = 2 * D - 1;
  const FaceWalls<D>& walls = engine.boundaries().faces();
  const double e0 = total_energy(engine, lid);
  std::uint64_t layer_changes = 0, wall_hits = 0;
  for (int k = 0; k < events; ++k) {
    const EventKind kind = engine.step();
    ASSERT_NE(kind, EventKind::kNone);
    layer_changes += kind == EventKind::kWallLayer ? 1 : 0;
    wall_hits += kind == EventKind::kWallCollision ? 1 : 0;
    if (k % testing::validation_stride(validate_every) == 0) {
      ASSERT_NO_THROW(engine.validate()) << "event " << k;
    }
  }
  ASSERT_NO_THROW(engine.validate());
  EXPECT_LE(engine.max_overlap_now(), 1e-12);
  EXPECT_GE(layer_changes, 2u);
  EXPECT_GT(wall_hits, static_cast<std::uint64_t>(events / 50));
  EXPECT_NEAR(total_energy(engine, lid), e0, 1e-11 * e0);
  EXPECT_NEAR(walls.energy(lid, engine.time()), -engine.counters().work_by_walls, 1e-10 * e0);
  // The gas was compressed: the lid is below its face, and every particle below the lid.
  const double top = walls.position(lid, engine.time());
  EXPECT_LT(top, height);
  for (const Vec<D>& x : engine.current_positions()) EXPECT_LE(x[D - 1], top - 0.5 + 1e-9);
}

TEST(MassiveWall, DiskGasUnderAFreePistonMissesNoContact) {
  check_gas_under_piston<2>(12, 0.2, 10.0, 60.0, 8000, 1);
}

TEST(MassiveWall, SphereGasUnderAFreePistonMissesNoContact) {
  check_gas_under_piston<3>(6, 0.1, 10.0, 80.0, 10000, 4);
}

// The same with the binary heap (ties between equal times broken as the calendar does).
TEST(MassiveWall, DiskGasUnderAFreePistonWithTheHeapQueue) {
  check_gas_under_piston<2, BinaryHeapQueue>(10, 0.2, 10.0, 40.0, 5000, 1);
}

// A light lid is thrown about: many contacts per unit time, each changing its motion.
TEST(MassiveWall, LightLidBouncingOnAGasMissesNoContact) {
  check_gas_under_piston<2>(10, 0.15, 0.5, 12.0, 8000, 1);
}

// A heavy lid (mass 50, no extra force) on an inelastic bed under gravity: the lid falls with
// the field, the grains lose energy in collisions; the budget (kinetic + field energy of the
// grains + the lid's energy + what the collisions dissipated) stays constant to round-off, and
// no contact is missed.
TEST(MassiveWall, HeavyLidOnAnInelasticBedUnderGravityClosesTheBudget) {
  ParticleSystem<2> s = gas_between_walls<2>(10, 0.2, 3);
  Engine<2> engine(s, StartMode::kPredict, EngineOptions{}, piston<2>(50.0, 0.0, 0.9, -1.0));
  const int lid = 3;
  const double e0 = total_energy(engine, lid);
  for (int k = 0; k < 10000; ++k) {
    ASSERT_NE(engine.step(), EventKind::kNone);
    if (k % testing::validation_stride(1) == 0) {
      ASSERT_NO_THROW(engine.validate()) << "event " << k;
    }
  }
  const EventCounters& c = engine.counters();
  const double dissipated = c.dissipated_in_collisions + c.dissipated_at_walls;
  EXPECT_GT(dissipated, 0.01 * e0);
  EXPECT_NEAR(total_energy(engine, lid) + dissipated, e0, 1e-11 * std::abs(e0));
  EXPECT_LE(engine.max_overlap_now(), 1e-12);
}

// Two lids of mass 8 on the faces of the last axis squeeze a gas from both sides; rough
// inelastic contacts (e = 0.9, tangential restitution 0.5) everywhere, so spins are exchanged
// with the walls too. The budget (kinetic and rotational energy + both lids' energies + the
// dissipation) stays constant to round-off, no contact is missed, and the gas stays between
// the lids.
TEST(MassiveWall, TwoRoughLidsSqueezeAGasFromBothSides) {
  ParticleSystem<3> s = gas_between_walls<3>(5, 0.1, 23);
  Environment<3> env = piston<3>(8.0, 30.0);
  ContactModel rough;
  rough.normal = NormalRestitution::constant(0.9);
  rough.tangential = TangentialModel::constant(0.5);
  env.species = 2;
  env.contact.assign(4, rough);
  for (int f = 4; f < 6; ++f) {
    env.faces[f].wall.contact = rough;
    env.faces[f].wall.mass = 8.0;
    env.faces[f].wall.force = 30.0;
  }
  Engine<3> engine(s, StartMode::kPredict, EngineOptions{}, env);
  const FaceWalls<3>& walls = engine.boundaries().faces();
  const auto budget = [&] {
    const EventCounters& c = engine.counters();
    return engine.kinetic_energy() + engine.rotational_energy() + walls.energy(4, engine.time()) +
           walls.energy(5, engine.time()) + c.dissipated_in_collisions + c.dissipated_at_walls;
  };
  const double e0 = budget();
  for (int k = 0; k < 8000; ++k) {
    ASSERT_NE(engine.step(), EventKind::kNone);
    if (k % 4 == 0) {
      ASSERT_NO_THROW(engine.validate()) << "event " << k;
    }
  }
  EXPECT_GT(engine.rotational_energy(), 0.0);
  EXPECT_GT(engine.counters().dissipated_at_walls, 0.0);
  EXPECT_NEAR(budget(), e0, 1e-11 * e0);
  const double floor = walls.position(4, engine.time()), lid = walls.position(5, engine.time());
  EXPECT_GT(floor, 0.0);  // both came in
  EXPECT_LT(lid, s.box[2]);
  for (const Vec<3>& x : engine.current_positions()) {
    EXPECT_GE(x[2], floor + 0.5 - 1e-9);
    EXPECT_LE(x[2], lid - 0.5 + 1e-9);
  }
}

// A state exported mid-run (the lid moving) resumes bit for bit: the wall's motion and its
// version travel with the state.
TEST(MassiveWall, ResumesBitForBit) {
  const ParticleSystem<3> s = gas_between_walls<3>(5, 0.1, 17);
  const Environment<3> env = piston<3>(5.0, 40.0);
  Engine<3> first(s, StartMode::kPredict, EngineOptions{}, env);
  for (int k = 0; k < 3000; ++k) first.step();
  const ParticleSystem<3> state = first.export_state();
  ASSERT_EQ(state.wall_motion.size(), 1u);
  EXPECT_EQ(state.wall_motion[0].face, static_cast<std::uint32_t>(kLid3));
  EXPECT_GT(state.wall_motion[0].version, 0u);
  Engine<3> resumed(state, StartMode::kResume, EngineOptions{}, env);
  testing::expect_same_continuation(first, resumed, 3000);
  EXPECT_EQ(resumed.export_state().wall_motion, first.export_state().wall_motion);
}

// A state continued with another force (or mass, or field) keeps the lid where the state has it
// and moving as fast: its motion is moved on with the old acceleration to the state's time and
// from there with the new one; no contact is missed after.
TEST(MassiveWall, AnotherForceContinuesFromWhereTheLidIs) {
  const ParticleSystem<3> s = gas_between_walls<3>(5, 0.1, 29);
  Engine<3> first(s, StartMode::kPredict, EngineOptions{}, piston<3>(5.0, 40.0));
  for (int k = 0; k < 2000; ++k) first.step();
  const double t = first.time();
  const FaceWalls<3>& before = first.boundaries().faces();
  const ParticleSystem<3> state = first.export_state();
  ASSERT_LT(state.wall_motion[0].time, t);  // the last contact lies before the state's time
  Engine<3> next(state, StartMode::kPredict, EngineOptions{}, piston<3>(5.0, 400.0));
  const FaceWalls<3>& after = next.boundaries().faces();
  EXPECT_NEAR(after.position(kLid3, t), before.position(kLid3, t), 1e-12);
  EXPECT_NEAR(after.body(kLid3).speed_at(t), before.body(kLid3).speed_at(t), 1e-12);
  EXPECT_EQ(after.body(kLid3).accel, -400.0 / 5.0);
  for (int k = 0; k < 3000; ++k) {
    ASSERT_NE(next.step(), EventKind::kNone);
    if (k % 5 == 0) {
      ASSERT_NO_THROW(next.validate()) << "event " << k;
    }
  }
  EXPECT_LT(after.position(kLid3, next.time()), before.position(kLid3, t));  // pushed in harder
}

// The gas pushes a lid with too small a force out of the box: it moves on beyond the box's
// face (in the outermost layer of cells, which extends to infinity) and the gas follows it,
// with no contact missed and the energy of gas plus lid conserved.
TEST(MassiveWall, ALidPushedOutOfTheBoxMovesOnAndTheGasFollows) {
  const ParticleSystem<3> s = gas_between_walls<3>(5, 0.2, 5);
  Engine<3> engine(s, StartMode::kPredict, EngineOptions{}, piston<3>(1.0, 0.5));
  const FaceWalls<3>& walls = engine.boundaries().faces();
  const double e0 = total_energy(engine, kLid3);
  double highest = 0.0;
  for (int k = 0; k < 6000; ++k) {
    ASSERT_NE(engine.step(), EventKind::kNone);
    if (k % 3 == 0) {
      ASSERT_NO_THROW(engine.validate()) << "event " << k;
    }
    for (const Vec<3>& x : engine.current_positions()) highest = std::max(highest, x[2]);
  }
  EXPECT_GT(walls.position(kLid3, engine.time()), s.box[2] + 1.0);
  EXPECT_GT(highest, s.box[2]);  // particles followed it out of the box
  EXPECT_NEAR(total_energy(engine, kLid3), e0, 1e-11 * e0);
  EXPECT_LE(engine.max_overlap_now(), 1e-12);
}

TEST(MassiveWall, AMotionForAFaceWithoutMassIsAnError) {
  ParticleSystem<3> s = gas_between_walls<3>(4, 0.1, 5);
  s.wall_motion = {{4, 0.0, 0.0, 0.0, 0, 0.0, -1}};  // z-, which has no mass here
  EXPECT_INPUT_ERROR(Engine<3>(s, StartMode::kPredict, EngineOptions{}, piston<3>(2.0, 1.0)),
                     "face z- but this run gives that face no mass");
}

TEST(MassiveWall, AResumeWithoutTheWallsMotionIsAnError) {
  const ParticleSystem<3> s = gas_between_walls<3>(4, 0.1, 5);
  Environment<3> fixed_lid = piston<3>(2.0, 1.0);
  fixed_lid.faces[kLid3].wall.mass = 0.0;
  fixed_lid.faces[kLid3].wall.force = 0.0;
  Engine<3> first(s, StartMode::kPredict, EngineOptions{}, fixed_lid);
  for (int k = 0; k < 100; ++k) first.step();
  EXPECT_INPUT_ERROR(
      Engine<3>(first.export_state(), StartMode::kResume, EngineOptions{}, piston<3>(2.0, 1.0)),
      "holds no motion of the wall with mass at face z+");
}

}  // namespace
}  // namespace kairos
