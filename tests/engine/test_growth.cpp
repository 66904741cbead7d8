// Growing particles (EngineOptions::growth_rate; docs/physics.md#growing-spheres): the engine's
// schedule checked against brute force after every event while the particles grow, in 2D and
// 3D, one size and two; momentum kept, energy only gained, radii exported as grown; what growth
// refuses.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "../release_suite_only.hpp"
#include "core/error.hpp"
#include "engine/event_engine.hpp"
#include "engine_fixtures.hpp"
#include "scheduler/calendar_queue.hpp"

namespace kairos {
namespace {

using testing::lattice_system;

template <int D>
EngineOptions growing(double rate, const ParticleSystem<D>& s, double room) {
  EngineOptions o;
  o.growth_rate = rate;
  double rmax = 0.0;
  for (const auto& k : s.kinematics) rmax = std::max(rmax, k.radius);
  o.min_cell_width = 2.0 * rmax * room;
  return o;
}

// Runs until `events` events or the cells' limit; validates after each. Returns the engine's
// time at the end.
template <int D>
double run_validated_growth(const ParticleSystem<D>& start, double rate, int events,
                            double room = 1.2, const Environment<D>& env = {}) {
  const EngineOptions o = growing<D>(rate, start, room);
  EventEngine<D, CalendarQueue> engine(start, StartMode::kPredict, o, env);
  engine.validate();
  const Vec<D> p0 = engine.momentum();
  double energy = engine.kinetic_energy();
  int e = 0;
  for (; e < events && engine.next_event_time() < engine.growth_fits_until(); ++e) {
    const std::uint64_t before = engine.counters().collisions + engine.counters().wall_collisions;
    engine.step();
    engine.validate();
    const double now = engine.kinetic_energy();
    if (engine.counters().collisions + engine.counters().wall_collisions > before) {
      EXPECT_GT(now, energy) << "a growing collision gives energy";
    } else {
      EXPECT_EQ(now, energy);
    }
    energy = now;
  }
  EXPECT_GT(engine.counters().collisions, 100u);
  // Momentum is kept along the periodic axes (walls take it up along theirs).
  for (int a = 0; a < D; ++a) {
    if (env.periodic(a)) {
      EXPECT_NEAR(engine.momentum()[a], p0[a], 1e-11);
    }
  }
  // Radii exported as grown, to the engine's time.
  const ParticleSystem<D> out = engine.export_state();
  const double scale = engine.growth().scale(engine.time());
  for (std::size_t i = 0; i < out.size(); ++i)
    EXPECT_DOUBLE_EQ(out.kinematics[i].radius, start.kinematics[i].radius * scale);
  EXPECT_LT(engine.max_overlap_now(), 1e-12);  // touching pairs: round-off only
  return engine.time();
}

TEST(Growth, ValidatedAgainstBruteForce3D) {
  run_validated_growth<3>(lattice_system<3>(5, 0.3, 11), 0.05, 3000);
}

TEST(Growth, ValidatedAgainstBruteForce2D) {
  run_validated_growth<2>(lattice_system<2>(9, 0.4, 12), 0.05, 3000);
}

TEST(Growth, ValidatedBinaryMixtureGrowingFast) {
  KAIROS_RELEASE_SUITE_ONLY();
  // Diameter ratio 1.4, fast growth: pairs are often reached by the growth alone.
  run_validated_growth<3>(lattice_system<3>(6, 0.2, 13, 1.0, 1.4), 0.5, 3000, 1.6);
  run_validated_growth<2>(lattice_system<2>(10, 0.3, 14, 2.0, 1.4), 0.5, 3000, 1.6);
}

// Growth between walls: a radius growing against a plane is a velocity towards it; checked
// against brute force (every wall contact, every pair) after every event.
TEST(Growth, ValidatedBetweenWalls3D) {
  const double t = run_validated_growth<3>(testing::gas_between_walls<3>(5, 0.3, 21), 0.05, 4000,
                                           1.2, testing::walls_on_last_axis<3>());
  EXPECT_GT(t, 0.0);
}

TEST(Growth, ValidatedInAClosedBox2D) {
  Environment<2> box;
  for (int f = 0; f < 4; ++f) box.faces[f].kind = FaceKind::kWall;
  run_validated_growth<2>(testing::gas_between_walls<2>(9, 0.4, 22), 0.5, 4000, 1.6, box);
}

// One sphere at rest, its surface reached by the growth alone: it touches the wall when its
// radius equals its centre's distance, and leaves at twice the growth speed (the mirror image
// of -r0 rate, plus the growth speed).
TEST(Growth, AWallSendsAGrowingParticleOffAtTwiceItsGrowthSpeed) {
  // Spheres 1.46 apart, the lowest layer 0.73 above the z- wall.
  ParticleSystem<3> s = testing::gas_between_walls<3>(3, 0.05, 23);
  for (Kinematics<3>& k : s.kinematics) k.vel = Vec<3>{};
  s.kinematics[0].pos[2] = 0.6;  // radius 0.5: touches the z- wall first, once grown by 0.1
  s.kinematics[1].vel = {0.01, 0.0, 0.0};  // something moves (the box is far from full)
  const double rate = 0.1;
  EventEngine<3, CalendarQueue> engine(s, StartMode::kPredict, growing<3>(rate, s, 1.2),
                                       testing::walls_on_last_axis<3>());
  const double contact = (0.6 / 0.5 - 1.0) / rate;  // 0.5 (1 + rate t) = 0.6
  bool met = false;
  while (!met && engine.next_event_time() < engine.growth_fits_until()) {
    const std::uint64_t walls = engine.counters().wall_collisions;
    engine.step();
    met = engine.counters().wall_collisions > walls;
  }
  ASSERT_TRUE(met);
  EXPECT_NEAR(engine.time(), contact, 1e-12);
  const ParticleSystem<3> out = engine.export_state();
  // The engine may renumber: the particle that was at z = 0.6 is the one now moving along z.
  int found = 0;
  for (std::size_t i = 0; i < out.size(); ++i) {
    if (out.kinematics[i].vel[2] == 0.0) continue;
    ++found;
    EXPECT_NEAR(out.kinematics[i].vel[2], 2.0 * 0.5 * rate, 1e-15);
    EXPECT_NEAR(out.kinematics[i].pos[2], out.kinematics[i].radius, 1e-12);
  }
  EXPECT_EQ(found, 1);
  EXPECT_NEAR(engine.counters().face_wall_impulse[4], 2.0 * 0.5 * rate, 1e-15);
}

TEST(Growth, StopsBeforeTheCellsAreTooNarrow) {
  // The cells are at least 1.2 diameters wide: growth at rate 1 fits until they are full.
  const auto s = lattice_system<3>(5, 0.2, 15);
  EventEngine<3, CalendarQueue> engine(s, StartMode::kPredict, growing<3>(1.0, s, 1.2));
  double width = kNever;
  for (int a = 0; a < 3; ++a) width = std::min(width, engine.grid().width(a));
  EXPECT_GE(width, 1.2);
  EXPECT_NEAR(engine.growth_fits_until(), width / 1.0 - 1.0, 1e-12);
}

TEST(Growth, NoCollisionBeyondTheCellsLimit) {
  // Fast growth in cells with little room: stepping on past growth_fits_until() is refused at
  // the first collision there (the cells may have missed a pair), never taken silently.
  const auto s = lattice_system<3>(5, 0.3, 17);
  EventEngine<3, CalendarQueue> engine(s, StartMode::kPredict, growing<3>(0.5, s, 1.05));
  const double limit = engine.growth_fits_until();
  ASSERT_LT(limit, 1.0);
  bool refused = false;
  for (int e = 0; e < 100000 && !refused; ++e) {
    const std::uint64_t collisions = engine.counters().collisions;
    const std::uint64_t events = engine.counters().events;
    const double before = engine.time();
    try {
      engine.step();
    } catch (const std::logic_error& error) {
      // Refused before anything changed: the caller can still stop the clock at the limit.
      EXPECT_GT(engine.next_event_time(), limit);
      EXPECT_EQ(engine.counters().collisions, collisions);
      EXPECT_EQ(engine.counters().events, events);
      EXPECT_EQ(engine.time(), before);
      engine.advance_clock(limit);
      engine.validate();
      refused = true;
    }
    if (!refused && engine.counters().collisions > collisions) {
      EXPECT_LE(engine.time(), limit);
    }
  }
  EXPECT_TRUE(refused);
}

TEST(Growth, RescaledVelocitiesAndANewRateInOnePass) {
  // rescale_velocities with a growth rate: the same schedule as a rescaling followed by
  // set_growth_rate at the same time (the protocol's slowdown), to the bit.
  const auto s = lattice_system<3>(5, 0.3, 18);
  EventEngine<3, CalendarQueue> a(s, StartMode::kPredict, growing<3>(0.05, s, 1.2));
  EventEngine<3, CalendarQueue> b(s, StartMode::kPredict, growing<3>(0.05, s, 1.2));
  for (int e = 0; e < 500; ++e) {
    a.step();
    b.step();
  }
  a.rescale_velocities(a.time(), 0.7);
  a.set_growth_rate(a.time(), 0.02);
  b.rescale_velocities(b.time(), 0.7, 0.02);
  EXPECT_EQ(a.growth_fits_until(), b.growth_fits_until());
  for (int e = 0; e < 2000 && a.next_event_time() < a.growth_fits_until(); ++e) {
    ASSERT_EQ(a.next_event_time(), b.next_event_time()) << "event " << e;
    a.step();
    b.step();
  }
  const ParticleSystem<3> xa = a.export_state(), xb = b.export_state();
  for (std::size_t i = 0; i < xa.size(); ++i) {
    for (int d = 0; d < 3; ++d) ASSERT_EQ(xa.kinematics[i].pos[d], xb.kinematics[i].pos[d]);
  }
  b.validate();
}

TEST(Growth, RescaledVelocitiesArePredictedAgain) {
  const auto s = lattice_system<3>(5, 0.3, 16);
  EventEngine<3, CalendarQueue> engine(s, StartMode::kPredict, growing<3>(0.05, s, 1.2));
  for (int e = 0; e < 500; ++e) engine.step();
  const double before = engine.kinetic_energy();
  engine.rescale_velocities(engine.time(), 0.5);
  EXPECT_NEAR(engine.kinetic_energy(), 0.25 * before, 1e-12 * before);
  engine.validate();
  for (int e = 0; e < 500 && engine.next_event_time() < engine.growth_fits_until(); ++e) {
    engine.step();
    engine.validate();
  }
}

TEST(Growth, RefusesWhatItCannotGrowIn) {
  const auto s = lattice_system<3>(5, 0.3, 17);
  const auto refused = [&](const Environment<3>& env, const char* what) {
    try {
      EventEngine<3, CalendarQueue> engine(s, StartMode::kPredict, growing<3>(0.1, s, 1.2), env);
      ADD_FAILURE() << "accepted " << what;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("growing particles"), std::string::npos) << e.what();
    }
  };
  Environment<3> inelastic = testing::walls_on_last_axis<3>(0.9);
  refused(inelastic, "inelastic walls and contacts");
  for (int f = 0; f < 6; ++f) inelastic.faces[f] = Environment<3>{}.faces[f];
  refused(inelastic, "inelastic contacts");
  Environment<3> lossy_wall = testing::walls_on_last_axis<3>();
  lossy_wall.faces[5].wall.contact.normal = NormalRestitution::constant(0.8);
  refused(lossy_wall, "an inelastic wall");
  Environment<3> piston = testing::walls_on_last_axis<3>();
  piston.faces[5].wall.velocity[2] = -0.1;
  refused(piston, "a piston");
  Environment<3> shaken = testing::walls_on_last_axis<3>();
  shaken.faces[4].wall.amplitude = 0.05;
  shaken.faces[4].wall.angular_frequency = 10.0;
  refused(shaken, "a vibrating wall");
  Environment<3> open = testing::walls_on_last_axis<3>();
  open.faces[5].kind = FaceKind::kOpen;
  refused(open, "an open face");
  Environment<3> plane;
  plane.faces[4].kind = plane.faces[5].kind = FaceKind::kWall;
  surface_specs<PlaneWalls<3>>(plane).push_back(PlaneWall<3>{});
  surface_specs<PlaneWalls<3>>(plane).back().normal = {0.0, 0.0, 1.0};
  surface_specs<PlaneWalls<3>>(plane).back().offset = 0.01;
  refused(plane, "a plane wall");
}

// Per-particle radii (EngineOptions::per_particle_radii, chosen by itself beyond 65 536 kinds):
// the same trajectory as with a kind per radius, to the bit, growing or not.
TEST(PerParticleRadii, SameTrajectoryAsKinds) {
  auto s = lattice_system<3>(6, 0.3, 18);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0.4, 0.55);
  for (auto& k : s.kinematics) k.radius = u(rng);  // 216 distinct radii
  for (const double rate : {0.0, 0.05}) {
    EngineOptions kinds = rate > 0.0 ? growing<3>(rate, s, 1.3) : EngineOptions{};
    EngineOptions own = kinds;
    own.per_particle_radii = true;
    EventEngine<3, CalendarQueue> a(s, StartMode::kPredict, kinds), b(s, StartMode::kPredict, own);
    for (int e = 0; e < 4000 && a.next_event_time() < a.growth_fits_until(); ++e) {
      ASSERT_EQ(a.step(), b.step()) << "event " << e;
      ASSERT_EQ(a.time(), b.time()) << "event " << e;
      if (e % 500 == 0) b.validate();
    }
    const auto x = a.export_state(), y = b.export_state();
    for (std::size_t i = 0; i < x.size(); ++i) {
      ASSERT_EQ(x.kinematics[i].pos, y.kinematics[i].pos) << i;
      ASSERT_EQ(x.kinematics[i].radius, y.kinematics[i].radius) << i;
    }
    EXPECT_GT(a.counters().collisions, 500u);
  }
}

}  // namespace
}  // namespace kairos
