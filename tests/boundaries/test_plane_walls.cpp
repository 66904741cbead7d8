// Plane walls anywhere (boundaries/plane_walls): their event codes after the box faces', event
// times against the face walls' and against dense sampling, the cells they reach, the squeeze of
// a plane moving into the box, and the engine with planes: every prediction checked after every
// event, energy conserved, a resumed run identical bit for bit, grains at rest on a slope.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "../engine/engine_fixtures.hpp"
#include "boundaries/face_walls.hpp"
#include "boundaries/plane_walls.hpp"
#include "core/event_code.hpp"
#include "engine/event_engine.hpp"
#include "model/boundaries.hpp"
#include "sampling_checks.hpp"
#include "scheduler/calendar_queue.hpp"

namespace kairos {
namespace {

// ----- event codes

TEST(PlaneWallCodes, SurfacesAfterTheFacesHaveCodesOfTheirOwn) {
  using Code = EventCode<3>;
  // The faces keep the codes format-7 restart files store.
  for (int f = 0; f < 6; ++f) EXPECT_EQ(Code::wall(f).bits(), 0xffffffffu - 6u + f);
  for (const int s : {0, 5, 6, 7, 100, Code::kWallCodes - 1}) {
    const Code c = Code::wall(s);
    EXPECT_TRUE(c.is_wall()) << s;
    EXPECT_EQ(c.wall_face(), s);
    EXPECT_FALSE(c.is_collision());
    EXPECT_FALSE(c.is_crossing()) << s;
    EXPECT_FALSE(c.keeps_contact());
    EXPECT_FALSE(c.is_release());
    EXPECT_TRUE(Code::valid_bits(c.bits(), 10));
  }
  // The last particle a crossing can keep is still a kept partner, not a surface.
  const Code kept = Code::crossing_keeping(Code::kMaxParticles - 1);
  EXPECT_TRUE(kept.keeps_contact());
  EXPECT_TRUE(kept.is_crossing());
  EXPECT_FALSE(kept.is_wall());
  EXPECT_EQ(kept.kept_partner(), Code::kMaxParticles - 1);
  EXPECT_EQ(Code::wall(6).bits(), kept.bits() + 1);
  EXPECT_TRUE(Code::crossing_keeping_none().is_crossing());
  EXPECT_FALSE(Code::crossing_keeping_none().is_wall());
}

// ----- the component

template <int D>
PlaneWall<D> make_plane(const Vec<D>& normal, const Vec<D>& point) {
  PlaneWall<D> p;
  p.normal = (1.0 / std::sqrt(norm2(normal))) * normal;
  p.offset = dot(p.normal, point);
  return p;
}

std::array<Face<3>, 6> walled(std::initializer_list<int> faces) {
  std::array<Face<3>, 6> out{};
  for (const int f : faces) out[static_cast<std::size_t>(f)].kind = FaceKind::kWall;
  return out;
}

// An axis-aligned plane is the face wall it coincides with: the same event times and responses
// bit for bit, moving, sliding and vibrating.
TEST(PlaneWalls, AnAxisAlignedPlaneIsTheFaceWallBitForBit) {
  const Vec<3> box{6.0, 7.0, 9.0}, g{0.1, 0.0, -1.3};
  std::array<Face<3>, 6> faces = walled({4, 5});
  Wall<3> w;
  w.velocity = {0.2, -0.1, 0.05};
  w.amplitude = 0.3;
  w.angular_frequency = 2.0;
  w.phase = 0.4;
  w.contact.normal = NormalRestitution::constant(0.7);
  w.contact.tangential = TangentialModel::constant(0.3);
  faces[4].wall = w;
  const FaceWalls<3> face_walls(faces, box, g);
  PlaneWall<3> plane = make_plane<3>({0.0, 0.0, 1.0}, {});
  plane.wall = w;
  const PlaneWalls<3> planes({plane}, box, faces, g);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int k = 0; k < 200; ++k) {
    const Vec<3> x{3.0 + u(rng), 3.0 + u(rng), 2.0 + 1.5 * u(rng)}, v{u(rng), u(rng), u(rng)};
    const double t = 5.0 + 3.0 * u(rng);
    ASSERT_EQ(planes.event_time(0, x, v, 0.5, t, kNever),
              face_walls.event_time(4, x, v, 0.5, t, kNever));
    ASSERT_EQ(planes.gap(0, x, t), face_walls.gap(4, x, t));
    Vec<3> v1 = v, v2 = v;
    Spin<3> w1{}, w2{};
    planes.resolve(0, Vec<3>{}, t, 1.0, 0.5, 0.4, false, v1, w1);
    face_walls.resolve(4, Vec<3>{}, t, 1.0, 0.5, 0.4, false, v2, w2);
    ASSERT_EQ(v1, v2);
    ASSERT_EQ(w1, w2);
  }
}

// The first time the sampled gap n.x(t) - R - c(t) goes below zero, on a grid of step h: the
// event time lies in the step where it first does, never before.
template <int D>
double sampled_contact(const PlaneWalls<D>& planes, const Vec<D>& x, const Vec<D>& v,
                       const Vec<D>& g, double radius, double t0, double h, double until) {
  for (double tau = 0.0; tau < until; tau += h) {
    const Vec<D> at = x + tau * v + (0.5 * tau * tau) * g;
    if (planes.gap(0, at, t0 + tau) - radius < 0.0) return tau;
  }
  return kNever;
}

TEST(PlaneWalls, EventTimesAgreeWithDenseSampling) {
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Vec<3> box{10.0, 10.0, 10.0}, g{0.0, 0.0, -1.0};
  int met = 0;
  for (int k = 0; k < 60; ++k) {
    PlaneWall<3> p = make_plane<3>({u(rng), 0.3 * u(rng), 1.0}, {5.0, 5.0, 1.0});
    if (k % 3 == 1) p.wall.velocity = {0.3 * u(rng), 0.0, 0.2 * u(rng)};  // sliding, moving
    if (k % 3 == 2) {                                                     // vibrating
      p.wall.amplitude = 0.2;
      p.wall.angular_frequency = 4.0 + u(rng);
      p.wall.phase = u(rng);
    }
    const PlaneWalls<3> planes({p}, box, walled({0, 1, 4, 5}), g);
    const Vec<3> x{5.0 + u(rng), 5.0 + u(rng), 4.0 + u(rng)}, v{u(rng), u(rng), u(rng)};
    const double t0 = 2.0 + u(rng);
    const double h = 1e-5;
    const double sampled = sampled_contact(planes, x, v, g, 0.5, t0, h, 6.0);
    const double predicted = planes.event_time(0, x, v, 0.5, t0, 6.0);
    if (testing::agrees_with_sampling(predicted, sampled, h, k)) ++met;
  }
  EXPECT_GT(met, 40);
}

// A cell is reached exactly when its nearest point to the plane (the corner the normal points
// away from) lies within rmax of the plane's innermost position (the vibration counted), or when
// it extends without end towards the plane (an outer layer of a bounded axis); and no particle
// that can touch the plane sits in a cell that is not reached.
TEST(PlaneWalls, EveryCellThatCanTouchAPlaneIsReached) {
  const Vec<3> box{12.0, 6.0, 12.0};
  const CellGrid<3> grid(box, Vec<3>{1.0, 1.0, 1.0}, {false, true, false}, 1000);
  PlaneWall<3> p = make_plane<3>({1.0, 0.0, 2.0}, {6.0, 3.0, 3.0});
  p.wall.amplitude = 0.5;  // takes the reach over a row of cells
  p.wall.angular_frequency = 1.0;
  PlaneWalls<3> planes({p}, box, walled({0, 1, 4, 5}), {});
  const double rmax = 0.6;
  planes.prepare(grid, rmax, 0.0, true);
  int reached = 0, cells = 0;
  for (int i = 0; i < grid.cells_along(0); ++i)
    for (int j = 0; j < grid.cells_along(1); ++j)
      for (int k = 0; k < grid.cells_along(2); ++k) {
        const CellCode c = grid.code_at({i, j, k});
        const double wx = box[0] / grid.cells_along(0), wz = box[2] / grid.cells_along(2);
        // n has positive x and z components: the nearest corner is the cell's low one, and the
        // low layers (i = 0, k = 0) reach down without end.
        const bool unbounded = i == 0 || k == 0;
        const double nearest = p.normal[0] * i * wx + p.normal[2] * k * wz;
        const bool expected = unbounded || nearest - (p.offset + p.wall.amplitude) < rmax;
        ASSERT_EQ(planes.reaches(0, c, grid), expected) << i << " " << j << " " << k;
        ++cells;
        reached += expected ? 1 : 0;
      }
  EXPECT_GT(reached, 50);
  EXPECT_LT(reached, cells / 2);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int n = 0; n < 20000; ++n) {
    const Vec<3> x{12.0 * u(rng), 6.0 * u(rng), 12.0 * u(rng)};
    if (dot(p.normal, x) - (p.offset + p.wall.amplitude) < rmax) {
      ASSERT_TRUE(planes.reaches(0, grid.locate(x), grid)) << x[0] << " " << x[2];
    }
  }
}

// A plane moving into a closed box along (1, 0, 1) / sqrt 2: no particle fits once the plane is
// less than a diameter (times 1.001) from the box's far corner edge, n.(L_x, ., L_z).
TEST(PlaneWalls, APlaneMovingIntoTheBoxLeavesNoRoomAtTheSqueezeTime) {
  const Vec<3> box{8.0, 5.0, 10.0};
  PlaneWall<3> p = make_plane<3>({1.0, 0.0, 1.0}, {0.0, 0.0, 2.0});
  p.wall.velocity = {0.1, 0.0, 0.1};  // u = 0.1 sqrt 2 along the normal
  PlaneWalls<3> planes({p}, box, walled({0, 1, 4, 5}), {});
  const CellGrid<3> grid(box, Vec<3>{1.0, 1.0, 1.0}, {false, true, false}, 100);
  planes.prepare(grid, 0.5, 10.0, true);
  const double s = 1.0 / std::sqrt(2.0);
  const double far = s * (8.0 + 10.0), start = s * 2.0, u = 0.1 * std::sqrt(2.0);
  EXPECT_NEAR(planes.squeeze_time(), (far - start - 1.001) / u, 1e-12);
  EXPECT_THROW(planes.throw_squeezed(planes.squeeze_time(), 1.0, true), InputError);
  // With the far side open, the particles leave through it: no squeeze.
  std::array<Face<3>, 6> open_top = walled({0, 1, 4});
  open_top[5].kind = FaceKind::kOpen;
  PlaneWalls<3> escaping({p}, box, open_top, {});
  escaping.prepare(grid, 0.5, 10.0, true);
  EXPECT_EQ(escaping.squeeze_time(), kNever);
}

// ----- in the engine

constexpr int D = 3;
using Engine = EventEngine<D, CalendarQueue>;

// Unit spheres on a lattice above a V of two planes (a trough along y), walls on x and z,
// periodic y, velocity components uniform in [-1, 1].
ParticleSystem<D> balls_above_a_trough(std::uint64_t seed) {
  ParticleSystem<D> s;
  s.box = {8.0, 6.0, 12.0};
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 4; ++j)
      for (int k = 0; k < 4; ++k) {
        s.kinematics.push_back(
            {{1.0 + 1.5 * i, 0.75 + 1.5 * j, 6.0 + 1.5 * k}, {u(rng), u(rng), u(rng)}, 0.0, 0.5});
        s.mass.push_back(1.0);
        s.species.push_back(0);
      }
  s.species_names = {"A"};
  return s;
}

Environment<D> trough(double gravity) {
  Environment<D> env;
  env.gravity = {0.0, 0.0, -gravity};
  for (const int f : {0, 1, 4, 5}) env.faces[static_cast<std::size_t>(f)].kind = FaceKind::kWall;
  // The two sides meet at (4, ., 1), 45 degrees each.
  surface_specs<PlaneWalls<D>>(env) = {make_plane<D>({1.0, 0.0, 1.0}, {4.0, 0.0, 1.0}),
                                       make_plane<D>({-1.0, 0.0, 1.0}, {4.0, 0.0, 1.0})};
  return env;
}

// The number of wall contacts that were contacts with a plane (the particle touching one).
int plane_contact(const Engine& engine, const Environment<D>& env) {
  const std::vector<Vec<D>> x = engine.current_positions();
  int touching = 0;
  for (const Vec<D>& p : x)
    for (const PlaneWall<D>& plane : surface_specs<PlaneWalls<D>>(env))
      touching += std::abs(dot(plane.normal, p) - plane.offset - 0.5) < 1e-9 ? 1 : 0;
  return touching;
}

TEST(PlaneWallsInTheEngine, ElasticGasInATroughConservesEnergyAndEveryPredictionHolds) {
  const Environment<D> env = [] {
    Environment<D> e = trough(1.0);
    e.sleep_speed = 0.0;  // elastic: nothing should settle
    return e;
  }();
  Engine engine(balls_above_a_trough(3), StartMode::kPredict, EngineOptions{}, env);
  auto energy = [&] {
    double e = engine.kinetic_energy();
    for (const Vec<D>& p : engine.current_positions()) e += p[2];  // m g z, m = g = 1
    return e;
  };
  const double e0 = energy();
  int plane_hits = 0;
  for (int k = 0; k < 6000; ++k) {
    const EventKind kind = engine.step();
    ASSERT_NE(kind, EventKind::kNone);
    if (kind == EventKind::kWallCollision) plane_hits += plane_contact(engine, env) > 0 ? 1 : 0;
    if (k % 5 == 0) engine.validate();  // every surface's prediction, by brute force
  }
  engine.validate();
  EXPECT_GT(plane_hits, 100);
  EXPECT_NEAR(energy(), e0, 1e-10 * e0);
  EXPECT_LT(engine.max_overlap_now(), 1e-10);
  for (const Vec<D>& p : engine.current_positions())
    for (const PlaneWall<D>& plane : surface_specs<PlaneWalls<D>>(env))
      ASSERT_GT(dot(plane.normal, p) - plane.offset, 0.5 - 1e-9);
}

// Inelastic, rough grains against a vibrating, sliding plane and a fixed one: a resumed run
// (its pending plane contacts included) continues bit for bit.
TEST(PlaneWallsInTheEngine, AResumedRunContinuesBitForBit) {
  Environment<D> env = trough(1.0);
  ContactModel law;
  law.normal = NormalRestitution::constant(0.8);
  law.tangential = TangentialModel::constant(0.4);
  env.species = 1;
  env.contact = {law};
  surface_specs<PlaneWalls<D>>(env)[0].wall.contact = law;
  surface_specs<PlaneWalls<D>>(env)[1].wall.amplitude = 0.2;
  surface_specs<PlaneWalls<D>>(env)[1].wall.angular_frequency = 5.0;
  surface_specs<PlaneWalls<D>>(env)[1].wall.velocity = {0.0, 0.3, 0.0};  // sliding along the trough
  Engine a(balls_above_a_trough(7), StartMode::kPredict, EngineOptions{}, env);
  for (int k = 0; k < 5000; ++k) ASSERT_NE(a.step(), EventKind::kNone);
  a.validate();
  Engine b(a.export_state(), StartMode::kResume, EngineOptions{}, env);
  testing::expect_same_continuation(a, b, 5000);
  EXPECT_GT(a.counters().wall_collisions, 200u);
}

// Inelastic grains dropped into the trough come to rest on its 45-degree sides (a support within
// 60 degrees of straight up) and fall asleep; none overlaps a plane.
TEST(PlaneWallsInTheEngine, GrainsComeToRestOnTheSlopesAndSleep) {
  Environment<D> env = trough(1.0);
  ContactModel law;
  law.normal = NormalRestitution::constant(0.5);
  env.species = 1;
  env.contact = {law};
  for (PlaneWall<D>& p : surface_specs<PlaneWalls<D>>(env)) p.wall.contact = law;
  for (const int f : {0, 1, 4, 5}) env.faces[static_cast<std::size_t>(f)].wall.contact = law;
  env.tc = 1e-4;
  Engine engine(balls_above_a_trough(11), StartMode::kPredict, EngineOptions{}, env);
  std::uint64_t steps = 0;
  while (engine.step() != EventKind::kNone) {
    ASSERT_LT(++steps, 3000000u) << "the grains never come to rest";
  }
  engine.validate();
  const ParticleSystem<D> s = engine.export_state();
  for (std::size_t i = 0; i < s.size(); ++i) EXPECT_TRUE(s.is_asleep(i)) << i;
  EXPECT_GT(engine.counters().fell_asleep, 0u);
  EXPECT_LT(engine.max_overlap_now(), 1e-9);
  int on_a_plane = 0;
  for (const Vec<D>& p : engine.current_positions())
    for (const PlaneWall<D>& plane : surface_specs<PlaneWalls<D>>(env)) {
      const double gap = dot(plane.normal, p) - plane.offset - 0.5;
      EXPECT_GT(gap, -1e-9);
      on_a_plane += gap < 1e-6 ? 1 : 0;
    }
  EXPECT_GT(on_a_plane, 4);
}

// A particle that starts behind a plane is named, with the plane.
TEST(PlaneWallsInTheEngine, AStartStateThroughAPlaneIsRefusedNamingBoth) {
  ParticleSystem<D> s = balls_above_a_trough(3);
  s.kinematics[5].pos = {0.8, 3.0, 2.0};  // below the left side x + z = 5 (by 2.2 / sqrt 2)
  try {
    Engine engine(s, StartMode::kPredict, EngineOptions{}, trough(1.0));
    FAIL() << "accepted a particle behind a plane";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("boundary.plane[0]"), std::string::npos) << what;
    EXPECT_NE(what.find("particle 5"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace kairos
