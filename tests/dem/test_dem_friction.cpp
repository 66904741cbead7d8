// Coulomb friction in the DEM (tangential springs, torques, rotation): a sphere launched
// sliding along a floor decelerates at mu g until it rolls without slipping at 5/7 of its
// launch speed (the textbook result for I = 2/5 m R^2, whatever mu and the springs), a
// frictional pile closes its energy budget (rotation and tangential springs included) to
// O(dt^2), an oblique frictional collision conserves angular momentum and turns both spheres,
// and a frictionless law leaves everything as without friction; disks (2D) roll at 2/3.
#include <gtest/gtest.h>

#include <cmath>

#include "core/error.hpp"
#include "dem/dem_integrator.hpp"
#include "dem_fixtures.hpp"
#include "interactions/soft_contact.hpp"

namespace kairos {
namespace {

using testing::one_sphere;

Environment<3> rough_floor(const SoftContactLaw& law, const SoftFriction& friction, double g) {
  Environment<3> env;
  env.species = 1;
  env.soft = {law};
  env.soft_wall = {law};
  env.soft_friction = {friction};
  env.soft_wall_friction = {friction};
  env.gravity = {0.0, 0.0, -g};
  env.faces[4].kind = FaceKind::kWall;
  env.faces[5].kind = FaceKind::kWall;
  return env;
}

TEST(DemFriction, SlidingSphereEndsRollingAtFiveSevenths) {
  const double g = 1.0, v0 = 2.0, mu = 0.3;
  const SoftContactLaw law = SoftContactLaw::linear_dashpot(1e5, 50.0);
  const SoftFriction friction{mu, 2.0 / 7.0, 0.5};
  // Resting on the floor at its static overlap m g / k, sliding along x without spin.
  ParticleSystem<3> s = one_sphere({10.0, 10.0, 0.5 - g / 1e5}, {v0, 0.0, 0.0});
  DemIntegrator<3> dem(s, rough_floor(law, friction, g));
  const double t_roll = 2.0 * v0 / (7.0 * mu * g);  // sliding time at deceleration mu g
  const auto steps = [&](double t) { return static_cast<long>(std::llround(t / dem.dt())); };
  dem.step(steps(0.5 * t_roll));
  // Half way: slowed by mu g t (to the spring's start-up transient).
  EXPECT_NEAR(dem.velocity(0)[0], v0 - mu * g * 0.5 * t_roll, 1e-4 * v0);  // measured 1e-5
  dem.step(steps(1.5 * t_roll));
  const ParticleSystem<3> end = dem.export_state();
  const double vx = end.kinematics[0].vel[0], wy = end.angular_velocity[0][1];
  EXPECT_NEAR(vx, 5.0 / 7.0 * v0, 1e-4 * v0);  // measured 0.714278 v0
  EXPECT_NEAR(wy * 0.5, vx, 1e-4 * v0);        // rolling: the contact point rests
  EXPECT_NEAR(end.angular_velocity[0][0], 0.0, 1e-12);
  EXPECT_NEAR(end.kinematics[0].vel[1], 0.0, 1e-12);
  // Energy: (1/2) v0^2 = kinetic + rotational (5/7 of it left: (1/2)(5/7) v0^2) + heat.
  const double heat = dem.dissipated_at_walls();
  EXPECT_NEAR(heat, 0.5 * v0 * v0 * (1.0 - 5.0 / 7.0), 1e-4 * 0.5 * v0 * v0);
  EXPECT_NEAR(dem.kinetic_energy() + dem.rotational_energy(), 0.5 * v0 * v0 * 5.0 / 7.0,
              1e-4 * 0.5 * v0 * v0);
}

// The same in 2D: a disk (I = 1/2 m R^2) ends rolling at v0 / (1 + 1/2) = 2/3 v0, turning
// clockwise (omega_z < 0) as it rolls along +x.
TEST(DemFriction, SlidingDiskEndsRollingAtTwoThirds) {
  const double g = 1.0, v0 = 1.5, mu = 0.4;
  Environment<2> env;
  env.species = 1;
  env.soft = {SoftContactLaw::linear_dashpot(1e5, 50.0)};
  env.soft_wall = env.soft;
  env.soft_friction = {SoftFriction{mu, 2.0 / 7.0, 0.5}};
  env.soft_wall_friction = env.soft_friction;
  env.gravity = {0.0, -g};
  env.faces[2].kind = FaceKind::kWall;
  env.faces[3].kind = FaceKind::kWall;
  ParticleSystem<2> s;
  s.box = {20.0, 20.0};
  s.periodic = {true, false};
  s.kinematics.push_back({{10.0, 0.5 - g / 1e5}, {v0, 0.0}, 0.0, 0.5});
  s.mass = {1.0};
  DemIntegrator<2> dem(s, env);
  const double t_roll = v0 / (3.0 * mu * g);  // sliding ends when v0 - mu g t = omega R = 2 mu g t
  dem.step(static_cast<long>(std::llround(3.0 * t_roll / dem.dt())));
  const ParticleSystem<2> end = dem.export_state();
  const double vx = end.kinematics[0].vel[0], wz = end.angular_velocity[0][0];
  EXPECT_NEAR(vx, 2.0 / 3.0 * v0, 1e-4 * v0);
  EXPECT_NEAR(-wz * 0.5, vx, 1e-4 * v0);
  EXPECT_NEAR(dem.dissipated_at_walls(), 0.5 * v0 * v0 / 3.0, 1e-4 * 0.5 * v0 * v0);
}

// A frictional pile settling between walls under gravity (Hertz, mu = 0.5 against particles
// and walls). Returns the largest deviation of the energy budget over the run relative to the
// energy dissipated.
double frictional_pile_error(double steps_per_contact, long contacts) {
  ParticleSystem<3> s;
  s.box = {6.0, 6.0, 10.0};
  s.periodic = {true, true, false};
  testing::add_bed(s, {{4, 4, 5}, {0.75, 0.75, 1.0}, {1.5, 1.5, 1.6}, 0.1, 11});
  const SoftContactLaw law = SoftContactLaw::viscoelastic_hertz(2e4, 1e-3);
  DemOptions options;
  options.steps_per_contact = steps_per_contact;
  options.reference_speed = 4.0;
  DemIntegrator<3> dem(s, rough_floor(law, SoftFriction{0.5, 2.0 / 7.0, 0.5}, 1.0), options);
  const auto budget = [&] {
    return dem.kinetic_energy() + dem.rotational_energy() + dem.potential_energy() +
           dem.field_energy() + dem.dissipated_energy() + dem.dissipated_at_walls();
  };
  const double e0 = budget();
  double worst = 0.0;
  for (long k = 0; k < contacts; ++k) {
    dem.step(static_cast<long>(steps_per_contact));
    worst = std::max(worst, std::abs(budget() - e0));
  }
  EXPECT_GT(dem.rotational_energy(), 0.0);  // friction turned the spheres
  EXPECT_GT(dem.collisions(), 50u);
  EXPECT_EQ(dem.work_by_walls(), 0.0);
  return worst / (dem.dissipated_energy() + dem.dissipated_at_walls());
}

TEST(DemFriction, FrictionalPileClosesItsEnergyBudget) {
  const double coarse = frictional_pile_error(25.0, 600);
  const double fine = frictional_pile_error(50.0, 600);
  // Measured: 2.4e-3 (t_c/25) and 5.3e-4 (t_c/50) of the energy dissipated, ratio 4.5.
  EXPECT_LT(fine, 1e-3);
  EXPECT_GT(coarse / fine, 3.0);  // O(dt^2)
}

// Two spheres (m 1 and 2, R 0.5 and 0.7) meeting obliquely with friction in a periodic box, far
// from its faces: linear and angular momentum (orbital + spin) are conserved, the spheres turn.
TEST(DemFriction, ObliqueCollisionConservesAngularMomentum) {
  ParticleSystem<3> s;
  s.box = {30.0, 30.0, 30.0};
  s.kinematics.push_back({{14.0, 15.3, 15.1}, {1.0, 0.0, 0.1}, 0.0, 0.5});
  s.kinematics.push_back({{16.0, 15.0, 15.0}, {-0.5, 0.0, 0.0}, 0.0, 0.7});
  s.mass = {1.0, 2.0};
  s.angular_velocity = {{0.0, 0.0, 0.5}, {0.2, 0.0, 0.0}};
  Environment<3> env;
  env.species = 1;
  env.soft = {SoftContactLaw::linear_dashpot(1e4, 10.0)};
  env.soft_friction = {SoftFriction{0.8, 2.0 / 7.0, 0.5}};
  DemOptions options;
  options.steps_per_contact = 200.0;
  DemIntegrator<3> dem(s, env, options);
  const auto angular_momentum = [&](const ParticleSystem<3>& state) {
    Vec<3> l{};
    for (std::size_t i = 0; i < 2; ++i) {
      const auto& k = state.kinematics[i];
      const double inertia = 0.4 * state.mass[i] * k.radius * k.radius;
      l = l + state.mass[i] * cross(k.pos, k.vel) + inertia * state.angular_velocity[i];
    }
    return l;
  };
  const Vec<3> l0 = angular_momentum(dem.export_state()), p0 = dem.momentum();
  dem.step(static_cast<long>(2.0 / dem.dt()));  // through the contact and apart again
  const ParticleSystem<3> end = dem.export_state();
  EXPECT_EQ(dem.collisions(), 1u);
  EXPECT_EQ(dem.contact_count(), 0u);
  const Vec<3> l1 = angular_momentum(end), p1 = dem.momentum();
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(l1[a], l0[a], 1e-10 * std::sqrt(norm2(l0))) << a;  // measured 6e-12
    EXPECT_NEAR(p1[a], p0[a], 1e-13) << a;
  }
  // The tangential impulse changed both spins.
  EXPECT_GT(std::sqrt(norm2(end.angular_velocity[0] - s.angular_velocity[0])), 0.05);
  EXPECT_GT(std::sqrt(norm2(end.angular_velocity[1] - s.angular_velocity[1])), 0.01);
}

// A frictional bed on a vibrated floor under gravity: how the steps are split into calls does
// not change a bit, and an integrator built from export_state() + checkpoint() continues bit for
// bit (positions, velocities, spins, springs, counters), as a restart file's run does.
TEST(DemFriction, SplitCallsAndCheckpointsContinueBitForBit) {
  ParticleSystem<3> s;
  s.box = {5.0, 5.0, 8.0};
  s.periodic = {true, true, false};
  testing::add_bed(s, {{4, 4, 3}, {0.6, 0.6, 0.7}, {1.2, 1.2, 1.2}, 0.1, 5});
  Environment<3> env = rough_floor(SoftContactLaw::viscoelastic_hertz(2e4, 1e-3),
                                   SoftFriction{0.5, 2.0 / 7.0, 0.5}, 1.0);
  env.faces[4].wall.amplitude = 0.05;
  env.faces[4].wall.angular_frequency = 7.0;
  DemIntegrator<3> whole(s, env), split(s, env);
  whole.step(3000);
  for (const long part : {1000L, 1L, 999L, 1000L}) split.step(part);
  const auto same = [](const DemIntegrator<3>& a, const DemIntegrator<3>& b) {
    const ParticleSystem<3> x = a.export_state(), y = b.export_state();
    for (std::size_t i = 0; i < x.size(); ++i) {
      if (x.kinematics[i].pos != y.kinematics[i].pos ||
          x.kinematics[i].vel != y.kinematics[i].vel ||
          x.angular_velocity[i] != y.angular_velocity[i])
        return false;
    }
    return x.time == y.time && a.dissipated_energy() == b.dissipated_energy() &&
           a.dissipated_at_walls() == b.dissipated_at_walls() &&
           a.work_by_walls() == b.work_by_walls() && a.collisions() == b.collisions() &&
           a.potential_energy() == b.potential_energy();
  };
  EXPECT_TRUE(same(whole, split));
  EXPECT_GT(whole.collisions(), 20u);
  EXPECT_GT(whole.rotational_energy(), 0.0);

  ParticleSystem<3> saved = whole.export_state();
  saved.dem = whole.checkpoint();
  DemIntegrator<3> resumed(saved, env);
  whole.step(4000);
  resumed.step(4000);
  EXPECT_TRUE(same(whole, resumed));
  // Without the checkpoint the forces are recomputed: the run continues, but not bit for bit.
  ParticleSystem<3> bare = saved;
  bare.dem = DemResume{};
  DemIntegrator<3> afresh(bare, env), again(saved, env);
  afresh.step(10);
  again.step(10);
  EXPECT_NEAR(afresh.kinetic_energy(), again.kinetic_energy(), 0.05 * again.kinetic_energy());
  EXPECT_FALSE(same(afresh, again));
  // A checkpoint of another system is refused.
  ParticleSystem<3> wrong = saved;
  wrong.dem.order.pop_back();
  EXPECT_THROW(DemIntegrator<3>(wrong, env), InputError);
}

TEST(DemFriction, ZeroFrictionIsSmoothAndBadLawsAreRefused) {
  // mu = 0 everywhere: the smooth loops, bit for bit, no rotation.
  ParticleSystem<3> s = one_sphere({10.0, 10.0, 3.0}, {1.0, 0.3, -2.0});
  s.kinematics.push_back({{10.4, 10.1, 1.0}, {0.0, 0.0, 0.0}, 0.0, 0.5});
  s.mass.push_back(1.0);
  const SoftContactLaw law = SoftContactLaw::linear_dashpot(1e4, 5.0);
  Environment<3> smooth = rough_floor(law, SoftFriction{}, 1.0);
  Environment<3> none = smooth;
  none.soft_friction.clear();
  none.soft_wall_friction.clear();
  DemIntegrator<3> a(s, smooth), b(s, none);
  a.step(4000);
  b.step(4000);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(a.position(i), b.position(i));
    EXPECT_EQ(a.velocity(i), b.velocity(i));
  }
  EXPECT_EQ(a.rotational_energy(), 0.0);
  EXPECT_GT(a.wall_collisions(), 0u);
  Environment<3> bad = rough_floor(law, SoftFriction{-0.1, 2.0 / 7.0, 0.5}, 1.0);
  EXPECT_THROW(DemIntegrator<3>(s, bad), InputError);
  bad = rough_floor(law, SoftFriction{0.5, 0.0, 0.5}, 1.0);
  EXPECT_THROW(DemIntegrator<3>(s, bad), InputError);
}

}  // namespace
}  // namespace kairos
