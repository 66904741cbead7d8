// Gravity, walls and resting particles in the engine: exact parabolic flights, bounces with
// restitution, a bouncing ball that comes to rest in finite time, energy conservation with
// elastic walls, and the prediction invariant checked by brute force after every event.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "engine/event_engine.hpp"
#include "scheduler/calendar_queue.hpp"

namespace kairos {
namespace {

constexpr int D = 3;
using Engine = EventEngine<D, CalendarQueue>;

ParticleSystem<D> two_balls(double drop_height) {
  ParticleSystem<D> s;
  s.box = {10.0, 10.0, 10.0};
  // A dropped from rest; B resting exactly on the floor.
  s.kinematics = {{{2.0, 2.0, 0.5 + drop_height}, {0.0, 0.0, 0.0}, 0.0, 0.5},
                  {{7.0, 7.0, 0.5}, {0.0, 0.0, 0.0}, 0.0, 0.5}};
  s.mass = {1.0, 1.0};
  s.species = {0, 0};
  s.species_names = {"A"};
  return s;
}

Environment<D> box_with_floor(double e_floor, double g) {
  Environment<D> env;
  env.gravity = {0.0, 0.0, -g};
  env.faces[4].kind = FaceKind::kWall;
  env.faces[4].wall.contact.normal = NormalRestitution::constant(e_floor);
  env.faces[5].kind = FaceKind::kOpen;
  return env;
}

// Bounce k (k = 0, 1, ...) of a ball dropped from height h under gravity g onto a floor with
// restitution e happens at t_k = t_0 + 2 v_0 (e + ... + e^k) / g, t_0 = sqrt(2 h / g),
// v_0 = g t_0, and leaves with speed e^(k+1) v_0.
TEST(WallsAndGravity, BouncingBallFollowsTheAnalyticSequenceAndComesToRest) {
  const double h = 3.0, g = 2.0, e = 0.8;
  Engine engine(two_balls(h), StartMode::kPredict, EngineOptions{}, box_with_floor(e, g));
  const double t0 = std::sqrt(2.0 * h / g), v0 = g * t0;
  double expected_time = t0, speed = v0;
  int bounces = 0;
  EventKind kind;
  while ((kind = engine.step()) != EventKind::kNone) {
    ASSERT_LT(engine.counters().events, 100000u) << "the ball never comes to rest";
    if (kind != EventKind::kWallCollision) continue;
    const ParticleSystem<D> s = engine.export_state();
    if (s.is_asleep(0)) break;           // the last bounce put it to sleep
    if (engine.time() == 0.0) continue;  // B settling at t = 0
    speed *= e;
    const Vec<D> v = s.velocity_at(0, engine.time());
    ASSERT_NEAR(engine.time(), expected_time, 1e-12 * (1.0 + expected_time))
        << "bounce " << bounces;
    ASSERT_NEAR(v[2], speed, 1e-12 * v0) << "bounce " << bounces;
    ASSERT_EQ(v[0], 0.0);
    // Apex height of the next flight: v^2 / 2g above the floor contact.
    expected_time += 2.0 * speed / g;
    ++bounces;
  }
  // It rests after a finite time, close to the Zeno limit t0 + 2 v0 e / (g (1 - e)).
  const double zeno = t0 + 2.0 * v0 * e / (g * (1.0 - e));
  EXPECT_GT(bounces, 20);
  EXPECT_NEAR(engine.time(), zeno, 1e-3 * zeno);
  // Run on: nothing ever happens again, and both balls sit on the floor.
  while (engine.step() != EventKind::kNone) {
  }
  EXPECT_EQ(engine.sleeping(), 2u);
  const std::vector<Vec<D>> x = engine.current_positions();
  EXPECT_NEAR(x[0][2], 0.5, 1e-9);
  EXPECT_EQ(x[1][2], 0.5);  // B never moved
  EXPECT_EQ(x[1][0], 7.0);
}

// With elastic walls and collisions, kinetic plus potential energy is conserved to round-off
// by a gas under gravity in a closed box; the engine's invariants hold after every event.
TEST(WallsAndGravity, ElasticGasUnderGravityConservesEnergyAndKeepsInvariants) {
  ParticleSystem<D> s;
  s.box = {6.0, 6.0, 9.0};
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      for (int k = 0; k < 5; ++k) {
        s.kinematics.push_back(
            {{0.75 + 1.5 * i, 0.75 + 1.5 * j, 0.9 + 1.6 * k}, {u(rng), u(rng), u(rng)}, 0.0, 0.5});
        s.mass.push_back(1.0);
        s.species.push_back(0);
      }
  s.species_names = {"A"};
  Environment<D> env;
  env.gravity = {0.3, 0.0, -1.0};  // tilted: a component along a periodic axis too
  env.faces[4].kind = FaceKind::kWall;
  env.faces[5].kind = FaceKind::kWall;
  env.sleep_speed = 0.0;  // elastic: nothing should ever settle
  env.faces[0].kind = env.faces[1].kind = FaceKind::kPeriodic;
  Engine engine(s, StartMode::kPredict, EngineOptions{}, env);
  auto energy = [&] {
    double e = engine.kinetic_energy();
    const ParticleSystem<D> now = engine.export_state();
    for (std::size_t i = 0; i < now.size(); ++i)
      e += now.mass[i] * 1.0 * now.position_at(i, engine.time())[2];  // only g_z: z is bounded
    return e;
  };
  // The x component of gravity does work on an unbounded coordinate: compare with the
  // momentum it adds instead (x is periodic, walls exert no x impulse when smooth).
  const double e0 = energy();
  const double px0 = engine.momentum()[0];
  const double t_start = engine.time();
  for (int k = 0; k < 3000; ++k) {
    ASSERT_NE(engine.step(), EventKind::kNone);
    engine.validate();
  }
  EXPECT_GT(engine.counters().wall_collisions, 50u);
  EXPECT_NEAR(engine.momentum()[0], px0 + 0.3 * 80 * (engine.time() - t_start), 1e-9 * 80);
  // Energy: kinetic from the x-motion gains exactly the work of g_x; remove it.
  const double px = engine.momentum()[0];
  const double work_x = (px * px - px0 * px0) / (2.0 * 80);
  EXPECT_NEAR(energy() - work_x, e0, 1e-9 * e0);
}

// A resting ball (on the floor, at rest) stays at rest: no events, no motion.
TEST(WallsAndGravity, BallAtRestStaysAtRest) {
  ParticleSystem<D> s = two_balls(0.0);
  Engine engine(s, StartMode::kPredict, EngineOptions{}, box_with_floor(0.9, 1.0));
  int events = 0;
  while (engine.step() != EventKind::kNone) ++events;
  EXPECT_LE(events, 2);  // each settles once, at t = 0
  EXPECT_EQ(engine.time(), 0.0);
  const std::vector<Vec<D>> x = engine.current_positions();
  EXPECT_EQ(x[0][2], 0.5);
  EXPECT_EQ(x[1][2], 0.5);
}

}  // namespace
}  // namespace kairos
