// Cylinder and sphere walls (boundaries/cylinder_walls): the third and fourth boundary
// components, one implementation. Its gap, normal and
// surface velocity in closed form (inside and outside, 2D and 3D, the rotation's sense); event
// times against dense sampling under a field across the axis (a quartic), never after the
// sampled contact; every cell a particle can touch the cylinder from is reached; the engine in a
// rotating drum with every prediction checked by brute force and the energy budget closed (the
// drum's work counted); the DEM in a drum; soft spheres under the event integrator refused.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "boundaries/cylinder_walls.hpp"
#include "core/error.hpp"
#include "core/event_code.hpp"
#include "dem/dem_integrator.hpp"
#include "engine/event_engine.hpp"
#include "interactions/soft_contact.hpp"
#include "model/boundaries.hpp"
#include "sampling_checks.hpp"
#include "scheduler/calendar_queue.hpp"

namespace kairos {
namespace {

// e = 0.8, Walton friction mu = 0.5 with beta0 = 0.4 (rough, frictional grains).
ContactModel rough_law() {
  ContactModel m;
  m.normal = NormalRestitution::constant(0.8);
  m.tangential = TangentialModel::walton(0.5, 0.4);
  return m;
}

template <int D>
CylinderWall<D> drum(const Vec<D>& center, double radius, double omega = 0.0, int axis = D - 1) {
  CylinderWall<D> c;
  c.axis = axis;
  c.center = center;
  c.radius = radius;
  c.angular_velocity = omega;
  return c;
}

TEST(CylinderWalls, GapNormalAndSurfaceVelocityInClosedForm) {
  // 3D, axis along x through (0, 5, 5), radius 4, turning at 0.5 about +x.
  const CylinderWalls<3> in({drum<3>({0.0, 5.0, 5.0}, 4.0, 0.5, 0)}, {});
  const Vec<3> x{7.0, 5.0, 2.0};  // 3 below the axis: 1 from the wall
  EXPECT_NEAR(in.gap(0, x, 0.0), 1.0, 1e-15);
  const Vec<3> n = in.normal(0, x, 0.0);
  EXPECT_NEAR(n[2], 1.0, 1e-15);  // towards the axis, up
  EXPECT_EQ(n[0], 0.0);
  // The wall point below the axis, p - c = (0, 0, -4): omega e_x x (0, 0, -4) = (0, 2, 0).
  const Vec<3> u = in.velocity(0, x, 0.0);
  EXPECT_NEAR(u[1], 2.0, 1e-15);
  EXPECT_NEAR(u[2], 0.0, 1e-15);
  EXPECT_FALSE(in.holds_still(0));
  EXPECT_FALSE(in.flat(0));
  // Outside: the gap is the distance past the surface, the normal away from the axis.
  CylinderWall<3> post = drum<3>({0.0, 5.0, 5.0}, 1.0, 0.0, 0);
  post.inside = false;
  const CylinderWalls<3> out({post}, {});
  EXPECT_NEAR(out.gap(0, x, 0.0), 2.0, 1e-15);
  EXPECT_NEAR(out.normal(0, x, 0.0)[2], -1.0, 1e-15);
  EXPECT_TRUE(out.holds_still(0));
  // 2D: a circle turning counter-clockwise; at its right-most point the wall moves up.
  const CylinderWalls<2> circle({drum<2>({5.0, 5.0}, 4.0, 1.0)}, {});
  const Vec<2> right{8.5, 5.0};
  EXPECT_NEAR(circle.gap(0, right, 0.0), 0.5, 1e-15);
  EXPECT_NEAR(circle.normal(0, right, 0.0)[0], -1.0, 1e-15);
  EXPECT_NEAR(circle.velocity(0, right, 0.0)[1], 4.0, 1e-15);
  EXPECT_NEAR(circle.velocity(0, right, 0.0)[0], 0.0, 1e-15);
}

TEST(SphereWalls, GapNormalAndSurfaceVelocityInClosedForm) {
  // A spherical container of radius 4 about (5, 5, 5) turning at 0.5 about +z.
  const SphereWalls<3> in({drum<3>({5.0, 5.0, 5.0}, 4.0, 0.5, 2)}, {});
  const Vec<3> x{7.0, 5.0, 7.0};  // sqrt 8 from the centre, along (1, 0, 1)
  EXPECT_NEAR(in.gap(0, x, 0.0), 4.0 - std::sqrt(8.0), 1e-15);
  const Vec<3> n = in.normal(0, x, 0.0);
  EXPECT_NEAR(n[0], -std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(n[2], -std::sqrt(0.5), 1e-15);
  // The surface point c + 4 (1, 0, 1) / sqrt 2: omega e_z x (p - c) = (0, 0.5 * 4 / sqrt 2, 0).
  const Vec<3> u = in.velocity(0, x, 0.0);
  EXPECT_NEAR(u[1], std::sqrt(2.0), 1e-14);
  EXPECT_NEAR(u[0], 0.0, 1e-15);
  EXPECT_EQ(in.name(0), "boundary.sphere[0]");
  // The same point against a cylinder about z: only (x, y) counts.
  const CylinderWalls<3> cylinder({drum<3>({5.0, 5.0, 5.0}, 4.0, 0.0, 2)}, {});
  EXPECT_NEAR(cylinder.gap(0, x, 0.0), 2.0, 1e-15);
  CylinderWall<3> ball = drum<3>({5.0, 5.0, 5.0}, 1.0);
  ball.inside = false;
  const SphereWalls<3> out({ball}, {});
  EXPECT_NEAR(out.gap(0, x, 0.0), std::sqrt(8.0) - 1.0, 1e-15);
  EXPECT_NEAR(out.normal(0, x, 0.0)[2], std::sqrt(0.5), 1e-15);
}

// The first time the sampled gap falls below the radius (steps of h), kNever if none before
// t_max: the particle at x + v t + g t^2 / 2.
template <class Walls, std::size_t D>
double sampled_contact(const Walls& c, const std::array<double, D>& x,
                       const std::array<double, D>& v, const std::array<double, D>& g,
                       double radius, double h, double t_max) {
  for (double t = 0.0; t <= t_max; t += h) {
    const Vec<D> at = x + t * v + (0.5 * t * t) * g;
    if (c.gap(0, at, 0.0) < radius) return t;
  }
  return kNever;
}

TEST(CylinderWalls, EventTimesUnderAFieldAcrossTheAxisAgreeWithDenseSampling) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Vec<3> g{0.3, 0.0, -1.0};  // across the x axis (y, z) and along it (x: no effect)
  int met = 0;
  for (int k = 0; k < 80; ++k) {
    CylinderWall<3> c = drum<3>({0.0, 5.0, 5.0}, k % 2 == 0 ? 4.0 : 1.0, 0.0, 0);
    c.inside = k % 2 == 0;
    const CylinderWalls<3> walls({c}, g);
    // Inside: anywhere within 2.5 of the axis; outside: 2 to 3 from it.
    const double r = c.inside ? 2.5 * std::abs(u(rng)) : 2.0 + std::abs(u(rng));
    const double phi = 3.14159 * u(rng);
    const Vec<3> x{u(rng), 5.0 + r * std::cos(phi), 5.0 + r * std::sin(phi)};
    const Vec<3> v{u(rng), 2.0 * u(rng), 2.0 * u(rng)};
    const double h = 1e-5;
    const double sampled = sampled_contact(walls, x, v, g, 0.5, h, 4.0);
    const double predicted = walls.event_time(0, x, v, 0.5, 1.0, 4.0);
    if (testing::agrees_with_sampling(predicted, sampled, h, k)) ++met;
  }
  EXPECT_GT(met, 35);  // the obstacles are often missed
}

TEST(SphereWalls, EventTimesUnderAFieldAgreeWithDenseSampling) {
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Vec<3> g{0.3, 0.2, -1.0};
  int met = 0;
  for (int k = 0; k < 80; ++k) {
    CylinderWall<3> c = drum<3>({5.0, 5.0, 5.0}, k % 2 == 0 ? 4.0 : 1.0);
    c.inside = k % 2 == 0;
    const SphereWalls<3> walls({c}, g);
    const double r = c.inside ? 2.5 * std::abs(u(rng)) : 2.0 + std::abs(u(rng));
    Vec<3> dir{u(rng), u(rng), u(rng)};
    dir = (1.0 / std::sqrt(norm2(dir))) * dir;
    const Vec<3> x = Vec<3>{5.0, 5.0, 5.0} + r * dir;
    const Vec<3> v{2.0 * u(rng), 2.0 * u(rng), 2.0 * u(rng)};
    const double h = 1e-5;
    const double sampled = sampled_contact(walls, x, v, g, 0.5, h, 4.0);
    const double predicted = walls.event_time(0, x, v, 0.5, 1.0, 4.0);
    if (testing::agrees_with_sampling(predicted, sampled, h, k)) ++met;
  }
  EXPECT_GT(met, 35);
}

// Every particle that can touch the cylinder before leaving its cell sits in a reached cell;
// and the filter does leave cells out (the middle of a drum, far from an obstacle).
TEST(CylinderWalls, EveryCellThatCanTouchTheCylinderIsReached) {
  const Vec<2> box{20.0, 20.0};
  const CellGrid<2> grid(box, Vec<2>{1.0, 1.0}, {false, false}, 1000);
  const double rmax = 0.6;
  for (const bool inside : {true, false}) {
    CylinderWall<2> c = drum<2>({10.0, 10.0}, inside ? 9.0 : 3.0);
    c.inside = inside;
    CylinderWalls<2> walls({c}, {});
    walls.prepare(grid, rmax, 0.0, true);
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u(0.0, 20.0);
    int touching = 0;
    for (int n = 0; n < 40000; ++n) {
      const Vec<2> x{u(rng), u(rng)};
      if (walls.gap(0, x, 0.0) < rmax) {
        ++touching;
        ASSERT_TRUE(walls.reaches(0, grid.locate(x), grid)) << x[0] << " " << x[1];
      }
    }
    EXPECT_GT(touching, 1000);
    EXPECT_FALSE(
        walls.reaches(0, grid.locate(inside ? Vec<2>{10.0, 10.0} : Vec<2>{1.5, 1.5}), grid));
  }
}

// 2D: rough, inelastic disks in a drum turning at omega under gravity (the TC model keeps slow
// impacts elastic). After every few events the engine's predictions are checked by brute force
// (no contact with the drum missed); the budget kinetic + rotational + gravitational +
// dissipated - the drum's work is constant to round-off; no disk leaves the drum.
TEST(CylinderWallsInTheEngine, ARotatingDrumKeepsEveryPredictionAndClosesTheBudget) {
  ParticleSystem<2> s;
  s.box = {20.0, 20.0};
  s.periodic = {false, false};
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 8; ++i)
    for (int j = 0; j < 8; ++j) {
      const Vec<2> x{6.0 + 1.1 * i + 0.05 * u(rng), 6.0 + 1.1 * j + 0.05 * u(rng)};
      s.kinematics.push_back({x, {u(rng), u(rng)}, 0.0, 0.5});
      s.mass.push_back(1.0);
      s.species.push_back(0);
    }
  s.species_names = {"A"};
  Environment<2> env;
  for (int f = 0; f < 4; ++f) env.faces[static_cast<std::size_t>(f)].kind = FaceKind::kWall;
  env.gravity = {0.0, -1.0};
  CylinderWall<2> c = drum<2>({10.0, 10.0}, 9.5, 0.2);
  c.contact = rough_law();
  surface_specs<CylinderWalls<2>>(env) = {c};
  env.species = 1;
  env.contact = {rough_law()};
  env.tc = 1e-3;
  EventEngine<2, CalendarQueue> engine(s, StartMode::kPredict, {}, env);
  const auto budget = [&] {
    double e = engine.kinetic_energy() + engine.rotational_energy();
    for (const Vec<2>& p : engine.current_positions()) e += p[1];  // m g y, m = g = 1
    const EventCounters& k = engine.counters();
    return e + k.dissipated_in_collisions + k.dissipated_at_walls - k.work_by_walls;
  };
  const double e0 = budget();
  double mean_x = 0.0;  // of the centre of mass, over the second half
  int samples = 0;
  for (int k = 0; k < 20000; ++k) {
    ASSERT_NE(engine.step(), EventKind::kNone);
    if (k % 7 == 0) {
      ASSERT_NO_THROW(engine.validate()) << "after event " << k;
    }
    if (k >= 10000 && k % 50 == 0) {
      double sx = 0.0;
      for (const Vec<2>& p : engine.current_positions()) sx += p[0];
      mean_x += sx / 64.0;
      ++samples;
    }
  }
  EXPECT_NEAR(budget(), e0, 1e-10 * std::abs(e0));
  EXPECT_GT(engine.counters().wall_collisions, 1000u);
  EXPECT_GT(engine.counters().work_by_walls, 0.0);  // the turning drum drives the grains
  for (const Vec<2>& p : engine.current_positions())
    ASSERT_GT(9.5 - std::hypot(p[0] - 10.0, p[1] - 10.0), 0.5 - 1e-9);
  // Turning counter-clockwise, the drum carries the bed up on its right: the centre of mass
  // sits right of the axis (without rotation, symmetric grains would average at x = 10).
  EXPECT_GT(mean_x / samples, 10.5);
}

// 3D: elastic spheres in a spherical container under gravity: every prediction checked by brute
// force, the energy (kinetic + gravitational) conserved, nobody outside.
TEST(SphereWallsInTheEngine, AnElasticGasInASphericalContainerConservesEnergy) {
  ParticleSystem<3> s;
  s.box = {12.0, 12.0, 12.0};
  s.periodic = {false, false, false};
  std::mt19937_64 rng(6);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      for (int k = 0; k < 4; ++k) {
        const Vec<3> x{4.2 + 1.2 * i, 4.2 + 1.2 * j, 4.2 + 1.2 * k};
        s.kinematics.push_back({x, {u(rng), u(rng), u(rng)}, 0.0, 0.5});
        s.mass.push_back(1.0);
        s.species.push_back(0);
      }
  s.species_names = {"A"};
  Environment<3> env;
  for (int f = 0; f < 6; ++f) env.faces[static_cast<std::size_t>(f)].kind = FaceKind::kWall;
  env.gravity = {0.0, 0.0, -1.0};
  env.sleep_speed = 0.0;
  surface_specs<SphereWalls<3>>(env) = {drum<3>({6.0, 6.0, 6.0}, 5.5)};
  EventEngine<3, CalendarQueue> engine(s, StartMode::kPredict, {}, env);
  const auto energy = [&] {
    double e = engine.kinetic_energy();
    for (const Vec<3>& p : engine.current_positions()) e += p[2];
    return e;
  };
  const double e0 = energy();
  for (int k = 0; k < 8000; ++k) {
    ASSERT_NE(engine.step(), EventKind::kNone);
    if (k % 5 == 0) {
      ASSERT_NO_THROW(engine.validate()) << "after event " << k;
    }
  }
  EXPECT_NEAR(energy(), e0, 1e-10 * e0);
  EXPECT_GT(engine.counters().wall_collisions, 300u);
  for (const Vec<3>& p : engine.current_positions())
    ASSERT_GT(5.5 - std::sqrt(norm2(p - Vec<3>{6.0, 6.0, 6.0})), 0.5 - 1e-9);
}

// The DEM meets the drum through the same component: a disk dropped at the bottom of a fixed
// drum settles at its static overlap m g / k.
TEST(CylinderWallsInTheDem, ADiskRestsAtTheBottomOfTheDrum) {
  const SoftContactLaw law = SoftContactLaw::linear_dashpot(1e4, 50.0);
  Environment<2> env;
  env.species = 1;
  env.soft = {law};
  env.soft_wall = {law};
  for (int f = 0; f < 4; ++f) env.faces[static_cast<std::size_t>(f)].kind = FaceKind::kWall;
  env.gravity = {0.0, -1.0};
  surface_specs<CylinderWalls<2>>(env) = {drum<2>({10.0, 10.0}, 9.0)};
  ParticleSystem<2> s;
  s.box = {20.0, 20.0};
  s.periodic = {false, false};
  s.kinematics = {{{10.0, 1.6}, {}, 0.0, 0.5}};  // 0.1 above the lowest point
  s.mass = {1.0};
  s.species = {0};
  s.species_names = {"A"};
  DemIntegrator<2> dem(s, env);
  dem.step(static_cast<long>(40.0 / dem.dt()));
  const Vec<2> x = dem.position(0);
  EXPECT_NEAR(x[0], 10.0, 1e-12);  // straight down
  EXPECT_NEAR(9.0 - std::hypot(x[0] - 10.0, x[1] - 10.0), 0.5 - 1.0 / 1e4, 1e-6);
  EXPECT_GE(dem.wall_collisions(), 1u);
}

// More surfaces than the event codes hold is the user's error, named as such.
TEST(CylinderWalls, MoreSurfacesThanEventCodesAreAnInputError) {
  Environment<2> env;
  for (int f = 0; f < 4; ++f) env.faces[static_cast<std::size_t>(f)].kind = FaceKind::kWall;
  surface_specs<CylinderWalls<2>>(env).assign(EventCode<2>::kWallCodes - 4,
                                              drum<2>({10.0, 10.0}, 9.0));
  EXPECT_NO_THROW(env.check());
  surface_specs<SphereWalls<2>>(env) = {drum<2>({10.0, 10.0}, 9.0)};
  try {
    env.check();
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("at most 4092"), std::string::npos) << e.what();
  }
}

TEST(CylinderWallsInTheEngine, SoftSpheresUnderTheEventIntegratorAreRefusedNamingIt) {
  Environment<2> env;
  env.species = 1;
  env.soft = {SoftContactLaw::linear_dashpot(1e4, 5.0)};
  env.soft_wall = env.soft;
  for (int f = 0; f < 4; ++f) env.faces[static_cast<std::size_t>(f)].kind = FaceKind::kWall;
  surface_specs<CylinderWalls<2>>(env) = {drum<2>({10.0, 10.0}, 9.0)};
  ParticleSystem<2> s;
  s.box = {20.0, 20.0};
  s.periodic = {false, false};
  s.kinematics = {{{10.0, 10.0}, {1.0, 0.0}, 0.0, 0.5}, {{12.0, 10.0}, {}, 0.0, 0.5}};
  s.mass = {1.0, 1.0};
  s.species = {0, 0};
  s.species_names = {"A"};
  try {
    EventEngine<2, CalendarQueue> engine(s, StartMode::kPredict, {}, env);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("boundary.cylinder[0]"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("dem"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace kairos
