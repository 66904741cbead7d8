// Circular holes in plane walls (boundaries/ring_edges, plane_walls' hole_radius): the holed
// plate met on both faces outside the hole and its ring edge, against dense sampling of the
// distances; in the engine, a 3D silo whose grains drain through a round orifice and come back
// at the top, every prediction checked by brute force, no overlap, the energy budget closed;
// the refusals.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "../release_suite_only.hpp"
#include "boundaries/outlets.hpp"
#include "boundaries/plane_walls.hpp"
#include "core/error.hpp"
#include "engine/event_engine.hpp"
#include "model/environment.hpp"
#include "sampling_checks.hpp"
#include "scheduler/calendar_queue.hpp"

namespace kairos {
namespace {

constexpr int D = 3;

std::array<Face<D>, 2 * D> walls_all_round() {
  std::array<Face<D>, 2 * D> faces{};
  for (Face<D>& f : faces) f.kind = FaceKind::kWall;
  return faces;
}

// A floor at z = level with a hole of radius `hole` about (cx, cy).
PlaneWall<D> holed_floor(double level, double hole, double cx, double cy) {
  PlaneWall<D> p;
  p.normal = {0.0, 0.0, 1.0};
  p.offset = level;
  p.hole_radius = hole;
  p.hole_center = {cx, cy, level};
  return p;
}

TEST(RingEdges, TheHoledPlateAndItsRingAgreeWithDenseSampling) {
  KAIROS_RELEASE_SUITE_ONLY();  // 10^8 sampled distances; the engine test below runs the ring
  const Vec<D> box{10.0, 10.0, 10.0}, g{0.0, 0.0, -1.0};
  PlaneWalls<D> planes({holed_floor(4.0, 1.5, 5.0, 5.0)}, box, walls_all_round(), g);
  ASSERT_EQ(planes.surfaces(), 2);  // the plate and its ring
  ASSERT_TRUE(planes.is_ring(1));
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double r = 0.5, h = 2e-5;
  int met[2] = {0, 0}, from_below = 0;
  for (int k = 0; k < 600; ++k) {
    Vec<D> x;
    if (k % 3 == 0) {  // above the floor, over the hole or beside it
      x = {5.0 + 2.5 * u(rng), 5.0 + 2.5 * u(rng), 5.0 + u(rng)};
    } else if (k % 3 == 2) {  // under it
      x = {5.0 + 2.5 * u(rng), 5.0 + 2.5 * u(rng), 2.6 + 0.8 * std::abs(u(rng))};
    } else {  // in the hole, at least a radius from its edge
      x = {5.0 + 0.9 * u(rng), 5.0 + 0.9 * u(rng), 4.0 + 0.45 * u(rng)};
    }
    if (planes.gap(1, x, 0.0) < r || planes.gap(0, x, 0.0) < r) continue;
    const Vec<D> v{1.5 * u(rng), 1.5 * u(rng), k % 3 == 2 ? 3.0 * std::abs(u(rng)) : 2.0 * u(rng)};
    double sampled = kNever;
    int which = -1;
    for (double tau = h; tau <= 3.0 && which < 0; tau += h) {
      const Vec<D> at = x + tau * v + (0.5 * tau * tau) * g;
      for (int s = 0; s < 2 && which < 0; ++s) {
        if (planes.gap(s, at, 0.0) - r < 0.0) {
          sampled = tau;
          which = s;
        }
      }
    }
    const double predicted =
        std::min(planes.event_time(0, x, v, r, 0.0, 3.0), planes.event_time(1, x, v, r, 0.0, 3.0));
    if (testing::agrees_with_sampling(predicted, sampled, h, k)) {
      ++met[which];
      from_below += k % 3 == 2 && which == 0 ? 1 : 0;
    }
  }
  EXPECT_GT(met[0], 100);
  EXPECT_GT(met[1], 20);      // the ring
  EXPECT_GT(from_below, 20);  // the plate's underside
  // Over the hole the ring's normal points from its nearest point to the centre and its gap is
  // that distance; beside the hole the plate is the nearer surface (its gap |z|), the ring's none
  // (a soft contact meets one of the two, and the distances agree at the rim).
  const Vec<D> over{5.0 + 1.5 - 0.3, 5.0, 4.0 + 0.4};
  EXPECT_NEAR(planes.gap(1, over, 0.0), 0.5, 1e-15);
  EXPECT_EQ(planes.gap(0, over, 0.0), kNever);
  const Vec<D> n = planes.normal(1, over, 0.0);
  EXPECT_NEAR(n[0], -0.6, 1e-15);
  EXPECT_NEAR(n[2], 0.8, 1e-15);
  const Vec<D> beside{5.0 + 1.5 + 0.3, 5.0, 4.0 + 0.4};
  EXPECT_EQ(planes.gap(1, beside, 0.0), kNever);
  EXPECT_NEAR(planes.gap(0, beside, 0.0), 0.4, 1e-15);
  const Vec<D> at_rim{5.0 + 1.5, 5.0, 4.0 + 0.4};
  EXPECT_NEAR(planes.gap(0, at_rim, 0.0), planes.gap(1, at_rim, 0.0), 1e-15);
}

using Engine = EventEngine<D, CalendarQueue>;

// A 3D silo: box 10 x 10 x 24, a floor at z = 4 with a round orifice of radius 2 (four grain
// diameters) in its middle, an outlet a radius below the floor, the grains put back in the top
// third at rest. Rough inelastic grains under gravity -1, no sleeping.
Environment<D> round_silo() {
  Environment<D> env = testing::silo_grains<D>(walls_all_round(), 0.8);
  env.faces[5].kind = FaceKind::kOpen;
  PlaneWall<D> floor = holed_floor(4.0, 2.0, 5.0, 5.0);
  floor.wall.contact = env.contact[0];
  surface_specs<PlaneWalls<D>>(env) = {floor};
  Outlet<D> o;
  o.normal = {0.0, 0.0, 1.0};
  o.offset = 3.5;
  o.insert_lower = {0.6, 0.6, 16.0};
  o.insert_upper = {9.4, 9.4, 23.0};
  o.seed = 3;
  env.outlets = {o};
  return env;
}

ParticleSystem<D> grains(std::uint64_t seed) {
  ParticleSystem<D> s;
  s.box = {10.0, 10.0, 24.0};
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 7; ++i)
    for (int j = 0; j < 7; ++j)
      for (int k = 0; k < 6; ++k) {
        s.kinematics.push_back(
            {{0.9 + 1.35 * i, 0.9 + 1.35 * j, 5.5 + 1.35 * k}, {u(rng), u(rng), u(rng)}, 0.0, 0.5});
        s.mass.push_back(1.0);
        s.species.push_back(0);
      }
  s.species_names = {"A"};
  return s;
}

TEST(RingEdgesInTheEngine, GrainsDrainThroughARoundOrificeAndMeetItsRim) {
  const Environment<D> env = round_silo();
  Engine engine(grains(2), StartMode::kPredict, EngineOptions{}, env);
  const double e0 = testing::silo_budget(engine);
  int rim_hits = 0;
  for (int k = 0; k < 120000; ++k) {
    const EventKind kind = engine.step();
    ASSERT_NE(kind, EventKind::kNone);
    if (kind == EventKind::kWallCollision) {
      for (const Vec<D>& p : engine.current_positions()) {
        const double rho = std::hypot(p[0] - 5.0, p[1] - 5.0);
        rim_hits += std::abs(std::hypot(rho - 2.0, p[2] - 4.0) - 0.5) < 1e-9 ? 1 : 0;
      }
    }
    // Every surface's prediction, by brute force.
    if (k % testing::validation_stride(199) == 0) engine.validate();
  }
  engine.validate();
  EXPECT_GT(engine.counters().outlet_passes, 20u);
  EXPECT_GT(rim_hits, 5);
  const EventCounters& c = engine.counters();
  EXPECT_NEAR(testing::silo_budget(engine), e0,
              1e-12 * (std::abs(e0) + std::abs(c.outlet_energy) + c.dissipated_in_collisions));
  EXPECT_LT(engine.max_overlap_now(), 1e-10);
  // No centre inside the plate outside the hole.
  for (const Vec<D>& p : engine.current_positions()) {
    const double rho = std::hypot(p[0] - 5.0, p[1] - 5.0);
    if (rho > 2.0) {
      ASSERT_TRUE(p[2] >= 4.5 - 1e-9 || p[2] <= 3.5) << p[0] << " " << p[1] << " " << p[2];
    }
  }
}

TEST(RingEdgesInTheEngine, AHoleTooNarrowForTheGrainsIsRefusedNamingIt) {
  Environment<D> env = round_silo();
  surface_specs<PlaneWalls<D>>(env)[0].hole_radius = 0.4;
  try {
    Engine engine(grains(2), StartMode::kPredict, EngineOptions{}, env);
    FAIL() << "a hole narrower than the grains was taken";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("boundary.plane[0].hole_radius"), std::string::npos)
        << e.what();
  }
  env = round_silo();
  surface_specs<PlaneWalls<D>>(env)[0].wall.velocity = {0.0, 0.0, 0.1};
  EXPECT_THROW(env.check(), InputError);
}

}  // namespace
}  // namespace kairos
