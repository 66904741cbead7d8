// The spring-driven container (boundaries/wall_spring.hpp,
// docs/physics.md#the-spring-driven-container): both walls of the last axis joined as one body of
// mass M, tied by a spring and a dashpot to an anchor that moves sinusoidally, its motion changed
// by the grains it holds. Checked here: no contact is ever missed (validate() after every event
// compares each particle's event with brute-force contact times, while the container swings through
// layers of cells and comes back); the energy budget - grains, container (kinetic, spring, field),
// the anchor's work, the dashpot's and the collisions' dissipation - closes to round-off, elastic
// and inelastic, in 2D and 3D, under gravity; a lone grain that never touches leaves the container
// on the closed-form path of the spring alone; a free container (no spring); an exact resume, and a
// resume with a new drive frequency that continues from where the container is.
#include <gtest/gtest.h>

#include <cmath>
#include <tuple>
#include <vector>

#include "../boundaries/spring_reference.hpp"
#include "../release_suite_only.hpp"
#include "engine/event_engine.hpp"
#include "engine_fixtures.hpp"
#include "scheduler/calendar_queue.hpp"

namespace kairos {
namespace {

template <int D>
using Engine = EventEngine<D, CalendarQueue>;

// Walls on the faces of the last axis (the others periodic), joined as a container of mass M
// on `spring`; every contact of restitution e.
template <int D>
Environment<D> container(double mass, const WallSpring& spring, double e = 1.0,
                         double gravity = 0.0) {
  Environment<D> env = testing::walls_on_last_axis<D>(e, gravity);
  for (int f = 2 * D - 2; f < 2 * D; ++f) {
    env.faces[f].wall.mass = mass;
    env.faces[f].wall.joined = true;
    env.faces[f].wall.spring = spring;
  }
  return env;
}

using testing::gas_between_walls;

// Grains (kinetic, rotational, field) + the container's energy (at its low wall) + what the
// dashpot and the collisions dissipated - what the anchor put in: constant.
template <int D>
double budget(const Engine<D>& engine) {
  const double t = engine.time();
  const FaceWalls<D>& walls = engine.boundaries().faces();
  const int low = 2 * D - 2;
  const EventCounters& c = engine.counters();
  const SpringWork work = walls.body(low).work_at(t);
  double e = engine.kinetic_energy() + engine.rotational_energy() + walls.energy(low, t) +
             walls.energy(low + 1, t) + work.dashpot - work.drive + c.dissipated_in_collisions +
             c.dissipated_at_walls;
  const std::vector<Vec<D>> x = engine.current_positions();
  for (const Vec<D>& xi : x) e -= engine.environment().gravity[D - 1] * xi[D - 1];  // masses 1
  return e;
}

template <int D>
void check_container(int n, double eta, double mass, const WallSpring& spring, double e,
                     double gravity, int events, int validate_every) {
  const ParticleSystem<D> s = gas_between_walls<D>(n, eta, 7);
  Engine<D> engine(s, StartMode::kPredict, EngineOptions{}, container<D>(mass, spring, e, gravity));
  const FaceWalls<D>& walls = engine.boundaries().faces();
  const int low = 2 * D - 2;
  const double b0 = budget(engine);
  std::uint64_t layer_changes = 0, wall_hits = 0;
  double lowest = 0.0, highest = 0.0;
  for (int k = 0; k < events; ++k) {
    const EventKind kind = engine.step();
    ASSERT_NE(kind, EventKind::kNone);
    layer_changes += kind == EventKind::kWallLayer ? 1 : 0;
    wall_hits += kind == EventKind::kWallCollision ? 1 : 0;
    if (k % testing::validation_stride(validate_every) == 0) {
      ASSERT_NO_THROW(engine.validate()) << "event " << k;
    }
    lowest = std::min(lowest, walls.position(low, engine.time()));
    highest = std::max(highest, walls.position(low, engine.time()));
  }
  ASSERT_NO_THROW(engine.validate());
  EXPECT_LE(engine.max_overlap_now(), 1e-12);
  EXPECT_GE(layer_changes, 4u) << engine.time() << " " << lowest << " " << highest;
  EXPECT_GT(wall_hits, static_cast<std::uint64_t>(events / 50));
  EXPECT_LT(lowest, -0.5);  // it swung both ways
  EXPECT_GT(highest, 0.5);
  const SpringWork work = walls.body(low).work_at(engine.time());
  EXPECT_GT(work.dashpot, 0.0);
  EXPECT_NEAR(budget(engine), b0, 1e-11 * (std::abs(b0) + std::abs(work.drive)));
  // The walls move as one: the high wall stays the box's height above the low one.
  EXPECT_NEAR(walls.position(low + 1, engine.time()) - walls.position(low, engine.time()),
              s.box[D - 1], 1e-9);
  for (const Vec<D>& x : engine.current_positions()) {
    EXPECT_GE(x[D - 1], walls.position(low, engine.time()) + 0.5 - 1e-9);
    EXPECT_LE(x[D - 1], walls.position(low + 1, engine.time()) - 0.5 + 1e-9);
  }
}

// M = 20, k = 80 (w0 = 2), c = 2, anchor 1.5 sin(1.7 t): a swing of about 4 diameters.
const WallSpring kSpring{80.0, 2.0, 1.5, 1.7, 0.3};

TEST(SpringContainer, DiskGasMissesNoContact) {
  check_container<2>(10, 0.2, 20.0, kSpring, 1.0, 0.0, 8000, 1);
}

TEST(SpringContainer, InelasticDisksUnderGravityCloseTheBudget) {
  check_container<2>(10, 0.2, 20.0, kSpring, 0.7, -1.0, 8000, 1);
}

TEST(SpringContainer, SphereGasMissesNoContact) {
  check_container<3>(5, 0.1, 100.0, {400.0, 10.0, 3.0, 1.7, 0.3}, 0.9, 0.0, 8000, 3);
}

// A light container is thrown about by the grains: every contact changes its swing.
TEST(SpringContainer, LightContainerMissesNoContact) {
  check_container<2>(10, 0.15, 2.0, {8.0, 0.2, 4.0, 1.7, 0.0}, 1.0, 0.0, 8000, 1);
}

// A single wall on a spring (a sprung lid, not a container): after each contact the spring
// brings it back, so the particles near it are looked at again.
TEST(SpringContainer, ASprungLidMissesNoContact) {
  const ParticleSystem<2> s = gas_between_walls<2>(10, 0.2, 5);
  Environment<2> env = container<2>(5.0, {20.0, 0.5, 1.0, 1.3, 0.0});
  env.faces[2].wall.mass = 0.0;  // a fixed floor
  env.faces[2].wall.spring = WallSpring{};
  env.faces[2].wall.joined = false;
  env.faces[3].wall.joined = false;
  Engine<2> engine(s, StartMode::kPredict, EngineOptions{}, env);
  const FaceWalls<2>& walls = engine.boundaries().faces();
  const auto total = [&] {
    const SpringWork w = walls.body(3).work_at(engine.time());
    return engine.kinetic_energy() + walls.energy(3, engine.time()) + w.dashpot - w.drive;
  };
  const double e0 = total();
  std::uint64_t hits = 0;
  for (int k = 0; k < 6000; ++k) {
    hits += engine.step() == EventKind::kWallCollision ? 1 : 0;
    ASSERT_NO_THROW(engine.validate()) << "event " << k;
  }
  EXPECT_GT(hits, 100u);
  EXPECT_NEAR(total(), e0, 1e-11 * (std::abs(e0) + walls.body(3).work_at(engine.time()).drive));
}

// A free container (no spring): each contact moves both walls; the far wall comes nearer the
// particles beside it, which are looked at again.
TEST(SpringContainer, FreeContainerMissesNoContact) {
  const ParticleSystem<2> s = gas_between_walls<2>(10, 0.2, 3);
  Engine<2> engine(s, StartMode::kPredict, EngineOptions{}, container<2>(3.0, WallSpring{}));
  const double b0 = budget(engine);
  for (int k = 0; k < 6000; ++k) {
    ASSERT_NE(engine.step(), EventKind::kNone);
    ASSERT_NO_THROW(engine.validate()) << "event " << k;
  }
  EXPECT_NEAR(budget(engine), b0, 1e-11 * std::abs(b0));
}

// Two grains at rest in the middle, out of reach: the container follows the closed-form motion
// of the spring alone (against a Runge-Kutta integration of M X'' = -k (X - a) - c (X' - a'),
// from rest), changing layers and coming back without a contact.
TEST(SpringContainer, AnUntouchedContainerSwingsAsTheSpringAlone) {
  ParticleSystem<2> s;
  s.box = {10.0, 30.0};
  s.kinematics = {{{3.0, 15.0}, {0.0, 0.0}, 0.0, 0.5}, {{7.0, 15.0}, {0.0, 0.0}, 0.0, 0.5}};
  s.mass = {1.0, 1.0};
  s.species = {0, 0};
  const WallSpring spring{80.0, 2.0, 1.5, 1.7, 0.3};
  Engine<2> engine(s, StartMode::kPredict, EngineOptions{}, container<2>(20.0, spring));
  const FaceWalls<2>& walls = engine.boundaries().faces();
  double x = 0.0, v = 0.0, t = 0.0;
  std::uint64_t layers = 0;
  while (engine.time() < 30.0) {
    ASSERT_EQ(engine.step(), EventKind::kWallLayer);
    ++layers;
    const double t1 = engine.time();
    std::tie(x, v) = testing::integrate_spring(spring, 20.0, 0.0, t, x, v, t1, 2000);
    t = t1;
    ASSERT_NEAR(walls.position(2, t1), x, 1e-8) << t1;
    ASSERT_NEAR(walls.body(2).speed_at(t1), v, 1e-8) << t1;
    ASSERT_NO_THROW(engine.validate());
  }
  EXPECT_GT(layers, 10u);
  EXPECT_EQ(engine.counters().wall_collisions, 0u);
}

// A state exported mid-swing resumes bit for bit; one continued with another drive frequency
// keeps the container where it was, moving as fast, with its work sums.
TEST(SpringContainer, ResumesBitForBitAndWithANewDrive) {
  const ParticleSystem<3> s = gas_between_walls<3>(5, 0.1, 17);
  const Environment<3> env = container<3>(20.0, kSpring, 0.9);
  Engine<3> first(s, StartMode::kPredict, EngineOptions{}, env);
  for (int k = 0; k < 3000; ++k) first.step();
  const ParticleSystem<3> state = first.export_state();
  ASSERT_EQ(state.wall_motion.size(), 1u);  // one body, at its low wall
  EXPECT_TRUE(state.wall_motion[0].sprung());
  Engine<3> resumed(state, StartMode::kResume, EngineOptions{}, env);
  testing::expect_same_continuation(first, resumed, 3000);
  EXPECT_EQ(resumed.export_state().wall_motion, first.export_state().wall_motion);

  WallSpring faster = kSpring;
  faster.omega = 2.4;
  const double t = first.time();
  const ParticleSystem<3> later = first.export_state();
  Engine<3> next(later, StartMode::kPredict, EngineOptions{}, container<3>(20.0, faster, 0.9));
  const FaceWalls<3>& a = first.boundaries().faces();
  const FaceWalls<3>& b = next.boundaries().faces();
  EXPECT_NEAR(b.position(4, t), a.position(4, t), 1e-12);
  EXPECT_NEAR(b.body(4).speed_at(t), a.body(4).speed_at(t), 1e-12);
  EXPECT_NEAR(b.body(4).work_at(t).drive, a.body(4).work_at(t).drive, 1e-12);
  for (int k = 0; k < 2000; ++k) {
    ASSERT_NE(next.step(), EventKind::kNone);
    if (k % 5 == 0) {
      ASSERT_NO_THROW(next.validate()) << "event " << k;
    }
  }
}

}  // namespace
}  // namespace kairos
