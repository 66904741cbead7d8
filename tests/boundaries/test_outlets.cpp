// Outlets and strips (boundaries/outlets, plane_walls' span): a silo's floor cut to two strips
// beside an orifice, with edges, and an outlet below it that puts every particle passing back
// at the top. Event times against dense sampling; in the engine, every prediction checked by
// brute force, no overlap ever, the energy budget with the outlet's share closed to round-off,
// each passed particle put back inside its region with its velocity, a bit-for-bit resume, and
// a full insertion region reported by name.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "../engine/engine_fixtures.hpp"
#include "boundaries/outlets.hpp"
#include "boundaries/plane_walls.hpp"
#include "core/error.hpp"
#include "engine/event_engine.hpp"
#include "model/boundaries.hpp"
#include "sampling_checks.hpp"
#include "scheduler/calendar_queue.hpp"

namespace kairos {
namespace {

template <int D>
std::array<Face<D>, 2 * D> side_walls_and_floor() {
  std::array<Face<D>, 2 * D> faces{};
  for (int f = 0; f < 2 * D; ++f) faces[static_cast<std::size_t>(f)].kind = FaceKind::kWall;
  return faces;
}

// A floor at height `level` along the last axis, cut to a strip along x: [lo, hi].
template <int D>
PlaneWall<D> floor_strip(double level, double lo, double hi) {
  PlaneWall<D> p;
  p.normal[D - 1] = 1.0;
  p.offset = level;
  p.span_axis = 0;
  p.span_min = lo;
  p.span_max = hi;
  return p;
}

// The first time the particle's surface reaches surface s, sampled in steps of h.
template <int D, class Component>
double sampled_contact(const Component& c, int s, const Vec<D>& x, const Vec<D>& v, const Vec<D>& g,
                       double radius, double h, double horizon) {
  for (double tau = h; tau <= horizon; tau += h) {
    const Vec<D> at = x + tau * v + (0.5 * tau * tau) * g;
    if (c.gap(s, at, 0.0) - radius < 0.0) return tau;
  }
  return kNever;
}

// The first time the particle's surface reaches any surface of the component, sampled in steps
// of h, and which (a strip's gap is the distance from the plate on either side).
template <int D, class Component>
std::pair<double, int> sampled_first_contact(const Component& c, const Vec<D>& x, const Vec<D>& v,
                                             const Vec<D>& g, double radius, double h,
                                             double horizon) {
  for (double tau = h; tau <= horizon; tau += h) {
    const Vec<D> at = x + tau * v + (0.5 * tau * tau) * g;
    for (int s = 0; s < c.surfaces(); ++s)
      if (c.gap(s, at, 0.0) - radius < 0.0) return {tau, s};
  }
  return {kNever, -1};
}

// Particles thrown from above the floor, from inside the orifice (their centre within a radius
// of the floor's level, beside the strip) and from under the floor: the soonest contact with
// the strip (a plate, met on either face) or either edge, as the engine takes it, against dense
// sampling of all three; the strip is met only where it is.
TEST(Strips, EventTimesOfTheStripAndItsEdgesAgreeWithDenseSampling) {
  const Vec<2> box{10.0, 10.0}, g{0.0, -1.0};
  const PlaneWalls<2> planes({floor_strip<2>(2.0, 4.0, 6.5)}, box, side_walls_and_floor<2>(), g);
  ASSERT_EQ(planes.surfaces(), 3);  // the strip and its two edges
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double r = 0.5, h = 2e-5;
  int met[3] = {0, 0, 0};
  int from_below = 0;
  for (int k = 0; k < 450; ++k) {
    Vec<2> x;
    if (k % 3 == 0) {
      x = {5.0 + 3.0 * u(rng), 3.5 + u(rng)};  // above the floor
    } else if (k % 3 == 2) {
      x = {5.0 + 3.0 * u(rng), 0.6 + 0.8 * std::abs(u(rng))};  // under it
    } else {
      // In the orifice beside either end, at least a radius from the edge.
      const bool left = u(rng) < 0.0;
      x = {left ? 3.4 - 0.4 * std::abs(u(rng)) : 7.1 + 0.4 * std::abs(u(rng)), 2.0 + 0.45 * u(rng)};
      if (std::hypot(x[0] - (left ? 4.0 : 6.5), x[1] - 2.0) < r) continue;
    }
    const Vec<2> v{1.5 * u(rng), k % 3 == 2 ? 3.0 * std::abs(u(rng)) : 2.0 * u(rng)};
    const auto [sampled, which] = sampled_first_contact<2>(planes, x, v, g, r, h, 4.0);
    double predicted = kNever;
    for (int s = 0; s < 3; ++s)
      predicted = std::min(predicted, planes.event_time(s, x, v, r, 0.0, 4.0));
    if (testing::agrees_with_sampling(predicted, sampled, h, k)) {
      ++met[which];
      from_below += k % 3 == 2 && which == 0 ? 1 : 0;
    }
  }
  EXPECT_GT(from_below, 20);  // the plate's back face
  EXPECT_GT(met[0], 40);
  EXPECT_GT(met[1], 10);
  EXPECT_GT(met[2], 10);
}

TEST(Strips, ThreeDimensionalEdgesRunAlongTheAxisTheNormalHasNoPartIn) {
  const Vec<3> box{10.0, 6.0, 10.0}, g{0.0, 0.0, -1.0};
  // A hopper side: tilted in x-z, cut along x; its edges run along y.
  PlaneWall<3> side;
  side.normal = {std::sqrt(0.5), 0.0, std::sqrt(0.5)};
  side.offset = side.normal[0] * 3.0 + side.normal[2] * 2.0;  // through (3, ., 2)
  side.span_axis = 0;
  side.span_min = 3.0;
  side.span_max = 6.0;
  const PlaneWalls<3> planes({side}, box, side_walls_and_floor<3>(), g);
  ASSERT_EQ(planes.surfaces(), 3);
  EXPECT_EQ(side.edge_axes(), std::make_pair(1, 2));
  // The low edge passes through (3, y, 2): its gap there is zero for any y.
  EXPECT_NEAR(planes.gap(1, {3.0, 0.7, 2.0}, 0.0), 0.0, 1e-12);
  EXPECT_NEAR(planes.gap(1, {3.0, 5.2, 3.0}, 0.0), 1.0, 1e-12);
  // A point above the strip (its foot at x = 4.5) has the plane's distance; beside it, none.
  const Vec<3> foot{4.5, 1.0, 0.5};  // x + z = 5: on the plane
  EXPECT_NEAR(planes.gap(0, foot + 1.5 * side.normal, 0.0), 1.5, 1e-12);
  EXPECT_EQ(planes.gap(0, {1.0, 1.0, 6.0}, 0.0), kNever);
}

TEST(Outlets, TheCentreCrossesThePlaneWhenSamplingSaysSo) {
  Outlet<2> o;
  o.normal = {0.0, 1.0};
  o.offset = 1.0;
  const Vec<2> g{0.0, -1.0};
  const Outlets<2> outlets({o}, g);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double h = 1e-5;
  int met = 0;
  for (int k = 0; k < 60; ++k) {
    const Vec<2> x{u(rng), 2.0 + u(rng)}, v{u(rng), 2.0 * u(rng)};
    // The radius does not count: the centre passes.
    const double sampled = sampled_contact<2>(outlets, 0, x, v, g, 0.0, h, 5.0);
    if (testing::agrees_with_sampling(outlets.event_time(0, x, v, 0.5, 0.0, 5.0), sampled, h, k))
      ++met;
  }
  EXPECT_GT(met, 30);
}

TEST(Outlets, InsertionPointsAreUniformInTheRegionAndRepeatable) {
  Outlet<3> o;
  o.normal = {0.0, 0.0, 1.0};
  o.insert_lower = {1.0, 2.0, 5.0};
  o.insert_upper = {3.0, 2.5, 9.0};
  o.seed = 11;
  const Outlets<3> outlets({o}, {});
  Vec<3> mean{};
  const int n = 20000;
  for (int k = 0; k < n; ++k) {
    const Vec<3> x = outlets.insertion_point(0, static_cast<std::uint64_t>(k), 0);
    for (int a = 0; a < 3; ++a) {
      ASSERT_GE(x[a], o.insert_lower[a]);
      ASSERT_LT(x[a], o.insert_upper[a]);
    }
    mean = mean + (1.0 / n) * x;
    ASSERT_EQ(x, outlets.insertion_point(0, static_cast<std::uint64_t>(k), 0));
  }
  // The mean of a uniform variable on [a, b]: (a + b) / 2 within 5 standard errors.
  for (int a = 0; a < 3; ++a) {
    const double width = o.insert_upper[a] - o.insert_lower[a];
    EXPECT_NEAR(mean[a], 0.5 * (o.insert_lower[a] + o.insert_upper[a]),
                5.0 * width / std::sqrt(12.0 * n));
  }
  EXPECT_NE(outlets.insertion_point(0, 7, 0), outlets.insertion_point(0, 7, 1));
}

// ----- a silo in the engine

constexpr int D = 2;
using Engine = EventEngine<D, CalendarQueue>;

// A 2D silo: box 16 x 30, a floor at y = 4 with an orifice [5.5, 10.5] (five diameters), an
// outlet a radius below the floor, the particles put back in the top third at rest. Rough,
// inelastic grains (TC model) under gravity -1.
Environment<D> silo(double e, double width = 5.0) {
  Environment<D> env = testing::silo_grains<D>(side_walls_and_floor<D>(), e);
  env.faces[3].kind = FaceKind::kOpen;
  const double c = 8.0;
  for (PlaneWall<D> p : {floor_strip<D>(4.0, -kNever, c - 0.5 * width),
                         floor_strip<D>(4.0, c + 0.5 * width, kNever)}) {
    p.wall.contact = env.contact[0];
    surface_specs<PlaneWalls<D>>(env).push_back(p);
  }
  Outlet<D> o;
  o.normal = {0.0, 1.0};
  o.offset = 3.5;
  o.insert_lower = {0.6, 20.0};
  o.insert_upper = {15.4, 29.0};
  o.seed = 4;
  env.outlets = {o};
  return env;
}

ParticleSystem<D> grains_above_the_floor(std::uint64_t seed) {
  ParticleSystem<D> s;
  s.box = {16.0, 30.0};
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 12; ++i)
    for (int j = 0; j < 12; ++j) {
      s.kinematics.push_back({{1.0 + 1.25 * i, 6.0 + 1.25 * j}, {u(rng), u(rng)}, 0.0, 0.5});
      s.mass.push_back(1.0);
      s.species.push_back(0);
    }
  s.species_names = {"A"};
  return s;
}

TEST(OutletsInTheEngine, GrainsDrainThroughTheOrificeAndComeBackAtTheTop) {
  const Environment<D> env = silo(0.8);
  Engine engine(grains_above_the_floor(1), StartMode::kPredict, EngineOptions{}, env);
  const double e0 = testing::silo_budget(engine);
  const Outlet<D>& o = env.outlets[0];
  int passes = 0, edge_hits = 0;
  for (int k = 0; k < 100000; ++k) {
    const std::vector<std::uint32_t> before = engine.collision_counts();
    const EventKind kind = engine.step();
    ASSERT_NE(kind, EventKind::kNone);
    if (kind == EventKind::kOutletPass) {
      ++passes;
      // The particle whose counter moved sits in the region, at rest.
      const std::vector<std::uint32_t> after = engine.collision_counts();
      const std::vector<Vec<D>> x = engine.current_positions();
      const std::vector<Vec<D>> v = engine.current_velocities();
      int moved = 0;
      for (std::size_t i = 0; i < x.size(); ++i) {
        if (after[i] == before[i]) continue;
        ++moved;
        for (int a = 0; a < D; ++a) {
          ASSERT_GE(x[i][a], o.insert_lower[a]);
          ASSERT_LE(x[i][a], o.insert_upper[a]);
        }
        ASSERT_EQ(v[i], Vec<D>{});
      }
      ASSERT_EQ(moved, 1);
    }
    if (kind == EventKind::kWallCollision) {
      // A contact with an edge: the particle touching one of the orifice's corners.
      for (const Vec<D>& p : engine.current_positions())
        for (const double corner : {5.5, 10.5})
          edge_hits += std::abs(std::hypot(p[0] - corner, p[1] - 4.0) - 0.5) < 1e-9 ? 1 : 0;
    }
    if (k % 97 == 0) engine.validate();  // every surface's prediction, by brute force
  }
  engine.validate();
  EXPECT_EQ(engine.counters().outlet_passes, static_cast<std::uint64_t>(passes));
  EXPECT_GT(passes, 30);
  EXPECT_GT(edge_hits, 5);
  const EventCounters& c = engine.counters();
  EXPECT_NEAR(testing::silo_budget(engine), e0,
              1e-12 * (std::abs(e0) + std::abs(c.outlet_energy) + c.dissipated_in_collisions));
  EXPECT_LT(engine.max_overlap_now(), 1e-10);
  // No centre ever below the outlet, none inside the floor.
  for (const Vec<D>& p : engine.current_positions()) {
    ASSERT_GT(p[1], o.offset);
    const bool beside = p[0] > 5.5 && p[0] < 10.5;
    if (!beside) {
      ASSERT_TRUE(p[1] >= 4.5 - 1e-9 || p[1] <= 3.5);
    }
  }
}

// The outlet three diameters below the floor: disks that leave the orifice spread under the
// floor and meet the plate's back face, never passing through it; every prediction checked.
TEST(OutletsInTheEngine, DisksUnderTheFloorMeetItsUnderside) {
  Environment<D> env = silo(0.8);
  env.outlets[0].offset = 1.0;
  Engine engine(grains_above_the_floor(5), StartMode::kPredict, EngineOptions{}, env);
  int under = 0;
  for (int k = 0; k < 60000; ++k) {
    ASSERT_NE(engine.step(), EventKind::kNone);
    if (k % 97 == 0) engine.validate();
    if (k % 1000 == 0) {
      for (const Vec<D>& p : engine.current_positions()) {
        const bool beside = p[0] > 5.5 && p[0] < 10.5;
        under += !beside && p[1] < 4.0 ? 1 : 0;
        if (!beside) {
          ASSERT_TRUE(p[1] >= 4.5 - 1e-9 || p[1] <= 3.5 + 1e-9) << p[0] << " " << p[1];
        }
      }
    }
  }
  engine.validate();
  EXPECT_GT(under, 0);  // some were under the floor, beside the orifice
  EXPECT_GT(engine.counters().outlet_passes, 10u);
}

TEST(OutletsInTheEngine, AResumedSiloContinuesBitForBit) {
  const Environment<D> env = silo(0.7);
  Engine a(grains_above_the_floor(2), StartMode::kPredict, EngineOptions{}, env);
  for (int k = 0; k < 30000; ++k) ASSERT_NE(a.step(), EventKind::kNone);
  ASSERT_GT(a.counters().outlet_passes, 10u);
  Engine b(a.export_state(), StartMode::kResume, EngineOptions{}, env);
  EXPECT_EQ(b.counters().outlet_passes, a.counters().outlet_passes);
  testing::expect_same_continuation(a, b, 20000);
  EXPECT_EQ(a.counters().outlet_passes, b.counters().outlet_passes);
  EXPECT_EQ(a.counters().outlet_energy, b.counters().outlet_energy);
}

TEST(OutletsInTheEngine, AFullInsertionRegionIsAnErrorNamingIt) {
  Environment<D> env = silo(0.8, 6.0);
  // A region no particle fits in: around a fixed grain.
  env.species = 2;
  env.contact.assign(4, env.contact[0]);
  env.fixed = {0, 1};
  env.outlets[0].insert_lower = {7.95, 24.95};
  env.outlets[0].insert_upper = {8.05, 25.05};
  ParticleSystem<D> s = grains_above_the_floor(3);
  s.kinematics[0].pos = {8.0, 25.0};
  s.kinematics[0].vel = {};
  s.species[0] = 1;
  s.species_names = {"A", "B"};
  try {
    Engine engine(std::move(s), StartMode::kPredict, EngineOptions{}, env);
    for (int k = 0; k < 200000; ++k) ASSERT_NE(engine.step(), EventKind::kNone);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("boundary.outlet"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("no free place"), std::string::npos) << e.what();
  }
}

TEST(OutletsInTheEngine, ARegionOutsideTheWallsIsRefusedAtTheStart) {
  Environment<D> env = silo(0.8);
  env.outlets[0].insert_lower = {17.0, 20.0};  // beyond the side wall at x = 16
  env.outlets[0].insert_upper = {19.0, 25.0};
  try {
    Engine engine(grains_above_the_floor(3), StartMode::kPredict, EngineOptions{}, env);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("inside the walls"), std::string::npos) << e.what();
  }
}

TEST(OutletsInTheEngine, AStartBeyondTheOutletIsRefused) {
  ParticleSystem<D> s = grains_above_the_floor(4);
  s.kinematics[5].pos = {8.0, 3.0};  // in the orifice, below the outlet
  EXPECT_THROW(Engine(std::move(s), StartMode::kPredict, EngineOptions{}, silo(0.8)), InputError);
}

}  // namespace
}  // namespace kairos
