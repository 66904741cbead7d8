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

// Unit spheres on a count[0] x count[1] x count[2] lattice (first centre `first`, spacing
// `pitch`) with velocity components uniform in [-1, 1].
ParticleSystem<D> ball_lattice(const Vec<D>& box, const std::array<int, D>& count,
                               const Vec<D>& first, const Vec<D>& pitch, std::uint64_t seed) {
  ParticleSystem<D> s;
  s.box = box;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < count[0]; ++i)
    for (int j = 0; j < count[1]; ++j)
      for (int k = 0; k < count[2]; ++k) {
        s.kinematics.push_back(
            {{first[0] + pitch[0] * i, first[1] + pitch[1] * j, first[2] + pitch[2] * k},
             {u(rng), u(rng), u(rng)},
             0.0,
             0.5});
        s.mass.push_back(1.0);
        s.species.push_back(0);
      }
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
    const Vec<D> v = s.velocity(0, engine.time());
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
  const ParticleSystem<D> s =
      ball_lattice({6.0, 6.0, 9.0}, {4, 4, 5}, {0.75, 0.75, 0.9}, {1.5, 1.5, 1.6}, 3);
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
      e += now.mass[i] * 1.0 * now.position(i, engine.time())[2];  // only g_z: z is bounded
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

// Incremental crossings between walls and under gravity: a dilute inelastic gas falling onto a
// floor (walls on z, periodic x and y) keeps the scheduler invariant, by brute force, while
// most crossings scan only their new layer of cells.
TEST(WallsAndGravity, IncrementalCrossingsValidatedBetweenWalls) {
  const ParticleSystem<D> s =
      ball_lattice({12.0, 12.0, 20.0}, {6, 6, 6}, {1.0, 1.0, 1.0}, {2.0, 2.0, 3.0}, 5);
  Environment<D> env = box_with_floor(0.9, 0.2);
  ContactModel law;
  law.normal = NormalRestitution::constant(0.95);
  env.species = 1;
  env.contact.assign(1, law);
  Engine engine(s, StartMode::kPredict, EngineOptions{}, env);
  ASSERT_TRUE(engine.incremental_crossings());
  for (int k = 0; k < 4000; ++k) {
    ASSERT_NE(engine.step(), EventKind::kNone);
    if (k % 7 == 0) engine.validate();
  }
  EXPECT_GT(engine.counters().wall_collisions, 20u);
  EXPECT_GT(engine.counters().collisions, 200u);
  EXPECT_GT(engine.incremental_crossing_scans(), engine.counters().cell_crossings / 2);
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

namespace kairos {
namespace {

// Rough, inelastic disks/spheres with the TC model in a box with a vibrated floor, an open top,
// sliding side walls and gravity: resuming from export_state() continues bit for bit, sleepers,
// spins and TC times included; the energy budget closes to round-off.
template <int Dim>
void check_granular_resume() {
  ParticleSystem<Dim> s;
  for (int a = 0; a < Dim; ++a) s.box[a] = 8.0;
  s.box[Dim - 1] = 16.0;
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const int per_row = 5;
  int count = 1;
  for (int a = 0; a < Dim - 1; ++a) count *= per_row;
  for (int layer = 0; layer < 4; ++layer) {
    for (int c = 0; c < count; ++c) {
      Kinematics<Dim> k{};
      int rem = c;
      for (int a = 0; a < Dim - 1; ++a) {
        k.pos[a] = 0.8 + 1.5 * (rem % per_row);
        rem /= per_row;
      }
      k.pos[Dim - 1] = 0.7 + 1.5 * layer;
      for (int a = 0; a < Dim; ++a) k.vel[a] = u(rng);
      k.radius = 0.5;
      s.kinematics.push_back(k);
      s.mass.push_back(1.0);
      s.species.push_back(0);
    }
  }
  s.species_names = {"A"};
  Environment<Dim> env;
  env.gravity[Dim - 1] = -1.0;
  env.species = 1;
  ContactModel law;
  law.normal = NormalRestitution::constant(0.8);
  law.tangential = TangentialModel::constant(0.4);
  env.contact = {law};
  env.tc = 1e-3;
  Face<Dim> side;
  side.kind = FaceKind::kWall;
  side.wall.contact = law;
  side.wall.velocity[Dim - 1] = 0.3;  // sliding along the vertical
  env.faces[0] = side;
  env.faces[1] = side;
  env.faces[1].wall.velocity = Vec<Dim>{};
  Face<Dim> floor;
  floor.kind = FaceKind::kWall;
  floor.wall.contact.normal = NormalRestitution::constant(0.9);
  floor.wall.amplitude = 0.2;
  floor.wall.angular_frequency = 3.0;
  env.faces[2 * (Dim - 1)] = floor;
  env.faces[2 * (Dim - 1) + 1].kind = FaceKind::kOpen;

  using E = EventEngine<Dim, CalendarQueue>;
  E a(s, StartMode::kPredict, EngineOptions{}, env);
  const double e0 = a.kinetic_energy() + a.rotational_energy();
  for (int k = 0; k < 4000; ++k) ASSERT_NE(a.step(), EventKind::kNone);
  a.validate();
  E b(a.export_state(), StartMode::kResume, EngineOptions{}, env);
  for (int k = 0; k < 4000; ++k) {
    const EventKind ka = a.step();
    ASSERT_EQ(ka, b.step()) << "event " << k;
    ASSERT_EQ(a.time(), b.time()) << "event " << k;
  }
  const ParticleSystem<Dim> x = a.export_state(), y = b.export_state();
  for (std::size_t i = 0; i < x.size(); ++i) {
    ASSERT_EQ(x.kinematics[i].pos, y.kinematics[i].pos);
    ASSERT_EQ(x.kinematics[i].vel, y.kinematics[i].vel);
    ASSERT_EQ(x.angular_velocity[i], y.angular_velocity[i]);
  }
  EXPECT_GT(a.counters().wall_collisions, 100u);
  EXPECT_GT(a.counters().elastic_by_rule, 0u);
  // Energy budget: kinetic + rotational + potential changes by work minus dissipation.
  const std::vector<Vec<Dim>> pos0 = [&] {
    std::vector<Vec<Dim>> p;
    for (const auto& k : s.kinematics) p.push_back(k.pos);
    return p;
  }();
  double pe0 = 0.0, pe1 = 0.0;
  const std::vector<Vec<Dim>> pos1 = a.current_positions();
  for (std::size_t i = 0; i < pos0.size(); ++i) {
    pe0 += pos0[i][Dim - 1];
    pe1 += pos1[i][Dim - 1];
  }
  const auto& c = a.counters();
  const double balance = (a.kinetic_energy() + a.rotational_energy() + pe1) - (e0 + pe0) +
                         c.dissipated_in_collisions + c.dissipated_at_walls - c.work_by_walls;
  EXPECT_NEAR(balance, 0.0, 1e-9 * (e0 + c.dissipated_in_collisions));
}

TEST(WallsAndGravity, GranularRunResumesBitForBit3D) {
  check_granular_resume<3>();
}
TEST(WallsAndGravity, GranularRunResumesBitForBit2D) {
  check_granular_resume<2>();
}

}  // namespace
}  // namespace kairos

namespace kairos {
namespace {

// A vibrated bed in its steady state: the power the floor puts in equals the power the
// collisions dissipate, time-averaged. The difference over a window is the change of the
// total energy, which fluctuates but does not grow with the window; checked against 20
// blocks (a few standard errors) and against the input (within 3 %).
TEST(WallsAndGravity, VibratedBedBalancesPowerInAndDissipation) {
  constexpr int Dim = 2;
  ParticleSystem<Dim> s;
  s.box = {20.0, 60.0};
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int row = 0; row < 8; ++row)
    for (int col = 0; col < 15; ++col) {
      s.kinematics.push_back({{0.9 + 1.25 * col, 0.8 + 1.25 * row}, {u(rng), u(rng)}, 0.0, 0.5});
      s.mass.push_back(1.0);
      s.species.push_back(0);
    }
  s.species_names = {"A"};
  Environment<Dim> env;
  env.gravity = {0.0, -1.0};
  env.species = 1;
  env.contact = {ContactModel{NormalRestitution::constant(0.9), {}, 0.0}};
  env.tc = 1e-4;
  Face<Dim> side;
  side.kind = FaceKind::kWall;
  side.wall.contact.normal = NormalRestitution::constant(0.9);
  env.faces[0] = env.faces[1] = side;
  Face<Dim> floor = side;
  floor.wall.amplitude = 0.1;
  floor.wall.angular_frequency = 2.0 * M_PI * 1.0;  // Gamma = A w^2 / g = 3.9
  env.faces[2] = floor;
  env.faces[3].kind = FaceKind::kOpen;
  EventEngine<Dim, CalendarQueue> engine(s, StartMode::kPredict, EngineOptions{}, env);
  auto advance = [&](double until) {
    while (engine.time() < until) ASSERT_NE(engine.step(), EventKind::kNone);
  };
  advance(100.0);  // the steady state
  const int blocks = 20;
  std::vector<double> excess;
  double work = 0.0, dissipated = 0.0;
  for (int b = 0; b < blocks; ++b) {
    const auto c0 = engine.counters();
    advance(engine.time() + 25.0);
    const auto& c1 = engine.counters();
    const double w = c1.work_by_walls - c0.work_by_walls;
    const double q = (c1.dissipated_in_collisions - c0.dissipated_in_collisions) +
                     (c1.dissipated_at_walls - c0.dissipated_at_walls);
    work += w;
    dissipated += q;
    excess.push_back(w - q);
  }
  double mean = 0.0, var = 0.0;
  for (double x : excess) mean += x / blocks;
  for (double x : excess) var += (x - mean) * (x - mean) / (blocks - 1);
  const double stderr_ = std::sqrt(var / blocks);
  std::printf("vibrated bed: work %.6g, dissipated %.6g, (W - Q) per block %.4g +- %.4g\n", work,
              dissipated, mean, stderr_);
  EXPECT_GT(work, 0.0);
  EXPECT_LT(std::abs(mean), 4.0 * stderr_ + 1e-9 * work);
  EXPECT_NEAR(dissipated / work, 1.0, 0.03);
}

}  // namespace
}  // namespace kairos
