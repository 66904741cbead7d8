// The DEM between walls and under gravity: a wall contact reproduces the head-on restitution of
// its law with the particle's mass as reduced mass (the wall's is infinite), a vibrated, damped
// granular bed under gravity closes its energy budget (kinetic + elastic + gravitational +
// dissipated - work by the walls) to O(dt^2), the neighbour search between walls misses no
// contact, and what the DEM cannot integrate is refused with a clear error.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "core/error.hpp"
#include "dem/dem_integrator.hpp"
#include "dem_fixtures.hpp"
#include "interactions/soft_contact.hpp"

namespace kairos {
namespace {

// Walls at both faces of axis 2, periodic along 0 and 1; one species with `law` against the
// walls and each other.
Environment<3> walls_z(const SoftContactLaw& law, const Vec<3>& gravity = {}) {
  Environment<3> env;
  env.species = 1;
  env.soft = {law};
  env.soft_wall = {law};
  env.gravity = gravity;
  env.faces[4].kind = FaceKind::kWall;
  env.faces[5].kind = FaceKind::kWall;
  return env;
}

ParticleSystem<3> box_z(double side, const Vec<3>& gravity = {}) {
  ParticleSystem<3> s;
  s.box = {side, side, side};
  s.periodic = {true, true, false};
  s.gravity = gravity;
  return s;
}

// One particle (m = 2, R = 0.5) flying at speed v into the floor, starting half a step before
// first contact; returns the speed it leaves with over the speed it came with.
double wall_restitution(const SoftContactLaw& law, double v, double dt) {
  ParticleSystem<3> s = box_z(10.0);
  const Vec<3> vel{0.3, 0.0, -v};  // a sliding component: frictionless walls ignore it
  s.kinematics.push_back({Vec<3>{5.0, 5.0, 0.5} - (0.5 * dt) * vel, vel, 0.0, 0.5});
  s.mass = {2.0};
  DemOptions options;
  options.dt = dt;
  DemIntegrator<3> dem(s, walls_z(law), options);
  bool touched = false;
  for (long k = 0; k < 1000000; ++k) {
    dem.step();
    const double z = dem.position(0)[2];
    touched = touched || z < 0.5;
    if (touched && z >= 0.5) break;
  }
  EXPECT_TRUE(touched);
  EXPECT_EQ(dem.wall_collisions(), 1u);
  EXPECT_NEAR(dem.velocity(0)[0], 0.3, 1e-15);
  return dem.velocity(0)[2] / v;
}

TEST(DemWalls, WallContactHasTheHeadOnRestitutionOfItsLaw) {
  const SoftContactLaw dashpot = SoftContactLaw::linear_dashpot(1e4, 20.0);
  const HeadOn h = dashpot_head_on(2.0, 1e4, 20.0);  // reduced mass = the particle's mass
  const double e1 = wall_restitution(dashpot, 1.0, h.contact_time / 200);
  const double e2 = wall_restitution(dashpot, 1.0, h.contact_time / 400);
  EXPECT_NEAR(e2, h.restitution, 2e-5);
  // Second order: halving dt divides the error by about 4.
  EXPECT_GT(std::abs(e1 - h.restitution) / std::abs(e2 - h.restitution), 3.0);

  const SoftContactLaw hertz = SoftContactLaw::viscoelastic_hertz(2e4, 2e-3);
  const CollisionUnits u = reduce_collision(hertz, 2.0, 0.5, 1.5, 0.0);
  const CollisionMap map = collision_map(u.reduced);
  const double t_c = map.eps_t * u.time_unit;
  EXPECT_NEAR(wall_restitution(hertz, 1.5, t_c / 400), -map.eps_rdot, 1e-5);
}

// A bed of particles on a vibrated floor under gravity, damped contacts. Returns the largest
// deviation of the energy budget over the run, relative to the energy that flowed.
double bed_budget_error(double steps_per_contact, long contacts) {
  const double g = 1.0, side = 8.0;
  const Vec<3> gravity{0.0, 0.0, -g};
  ParticleSystem<3> s = box_z(side, gravity);
  testing::add_bed(s, {{6, 6, 4}, {0.7, 0.7, 0.8}, {1.2, 1.2, 1.3}, 0.05, 7});
  const SoftContactLaw law = SoftContactLaw::viscoelastic_hertz(1e4, 1e-3);
  Environment<3> env = walls_z(law, gravity);
  env.faces[4].wall.amplitude = 0.1;  // the floor shakes at 2.5 g
  env.faces[4].wall.angular_frequency = 5.0;
  DemOptions options;
  options.steps_per_contact = steps_per_contact;
  options.reference_speed = 2.0;
  DemIntegrator<3> dem(s, env, options);
  const auto budget = [&] {
    return dem.kinetic_energy() + dem.potential_energy() + dem.field_energy() +
           dem.dissipated_energy() + dem.dissipated_at_walls() - dem.work_by_walls();
  };
  const double e0 = budget();
  double worst = 0.0;
  const long chunk = static_cast<long>(steps_per_contact);
  for (long k = 0; k < contacts; ++k) {
    dem.step(chunk);
    worst = std::max(worst, std::abs(budget() - e0));
    for (std::size_t i = 0; i < dem.size(); ++i) {  // nobody leaves between the walls
      EXPECT_GT(dem.position(i)[2], -0.2);
      EXPECT_LT(dem.position(i)[2], side);
    }
  }
  EXPECT_GT(dem.wall_collisions(), 10u);
  EXPECT_GT(dem.collisions(), 10u);
  EXPECT_GT(dem.work_by_walls(), 0.0);  // the shaking floor drives the bed
  EXPECT_GT(dem.dissipated_energy() + dem.dissipated_at_walls(), 0.0);
  const double flowed = dem.work_by_walls() + dem.dissipated_energy() + dem.dissipated_at_walls();
  return worst / flowed;
}

TEST(DemWalls, VibratedBedUnderGravityClosesItsEnergyBudget) {
  const double coarse = bed_budget_error(25.0, 800);
  const double fine = bed_budget_error(50.0, 800);
  // Measured: 2.8e-3 at t_c/25 and 6.9e-4 at t_c/50 of the energy that flowed (ratio 3.98).
  EXPECT_LT(fine, 1e-3);
  EXPECT_GT(coarse / fine, 3.0);  // O(dt^2)
}

// Elastic Hertz spheres pressed together by gravity: every overlapping pair feels a force, so
// the integrator's contact count must equal the brute-force count of overlapping pairs (no
// periodic image between the walls, none missed at the outer cells).
TEST(DemWalls, NoContactIsMissedBetweenWalls) {
  const Vec<3> gravity{0.0, 0.0, -5.0};
  ParticleSystem<3> s = box_z(6.0, gravity);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  while (s.size() < 180) {  // random, non-overlapping, radii 0.35-0.5
    const double r = 0.35 + 0.15 * u(rng);
    const Vec<3> x{6.0 * u(rng), 6.0 * u(rng), r + (6.0 - 2.0 * r) * u(rng)};
    bool free = true;
    for (std::size_t j = 0; j < s.size() && free; ++j) {
      Vec<3> d = x - s.kinematics[j].pos;
      for (int k = 0; k < 2; ++k) d[k] -= 6.0 * std::round(d[k] / 6.0);
      free = norm2(d) > std::pow(r + s.kinematics[j].radius, 2);
    }
    if (free) {
      s.kinematics.push_back({x, Vec<3>{}, 0.0, r});
      s.mass.push_back(r * r * r);
    }
  }
  const SoftContactLaw elastic = SoftContactLaw::viscoelastic_hertz(1e3, 0.0);
  DemOptions options;
  options.reference_speed = 5.0;
  DemIntegrator<3> dem(s, walls_z(elastic, gravity), options);
  dem.step(3000);
  std::size_t overlapping = 0;
  for (std::size_t i = 0; i < dem.size(); ++i) {
    for (std::size_t j = i + 1; j < dem.size(); ++j) {
      Vec<3> d = dem.position(i) - dem.position(j);
      for (int k = 0; k < 2; ++k) d[k] -= 6.0 * std::round(d[k] / 6.0);
      const double l = s.kinematics[i].radius + s.kinematics[j].radius;
      if (norm2(d) < l * l) ++overlapping;
    }
  }
  EXPECT_GT(overlapping, 20u);  // the bottom layers are pressed together
  EXPECT_EQ(dem.contact_count(), overlapping);
  // Elastic: the budget holds without dissipation.
  EXPECT_NEAR(dem.dissipated_energy() + dem.dissipated_at_walls(), 0.0, 1e-12);
}

TEST(DemWalls, RefusesWhatItCannotIntegrate) {
  const SoftContactLaw law = SoftContactLaw::linear_dashpot(1e4, 1.0);
  ParticleSystem<3> s = box_z(10.0);
  s.kinematics.push_back({Vec<3>{5.0, 5.0, 5.0}, Vec<3>{}, 0.0, 0.5});
  s.mass = {1.0};
  const auto message = [&](const Environment<3>& env, const ParticleSystem<3>& state) {
    try {
      DemIntegrator<3> dem(state, env);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  Environment<3> open = walls_z(law);
  open.faces[5].kind = FaceKind::kOpen;
  EXPECT_NE(message(open, s).find("face 5 of the box is open"), std::string::npos);
  Environment<3> no_wall_law = walls_z(law);
  no_wall_law.soft_wall.clear();
  EXPECT_NE(message(no_wall_law, s).find("particle-wall laws"), std::string::npos);
  ParticleSystem<3> outside = s;
  outside.kinematics[0].pos[2] = -1.0;
  EXPECT_NE(message(walls_z(law), outside).find("overlaps the wall z-"), std::string::npos);
  // The law-only constructor knows no walls and no gravity (the environment's constructor
  // takes both from the environment, whatever flags the state carries).
  const auto law_only = [&](const ParticleSystem<3>& state) {
    try {
      DemIntegrator<3> dem(state, law);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(law_only(s).find("axis 2 is not periodic"), std::string::npos);
  ParticleSystem<3> falling = s;
  falling.periodic = {true, true, true};
  falling.gravity = {0.0, 0.0, -1.0};
  EXPECT_NE(law_only(falling).find("gravity needs the environment"), std::string::npos);
}

}  // namespace
}  // namespace kairos
