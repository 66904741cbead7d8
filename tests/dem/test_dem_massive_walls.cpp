// Walls with mass in the DEM (boundary.wall mass and force, [boundary.container];
// boundaries/wall_body.hpp, dem/dem_integrator.hpp): each step kicks a wall's body with the
// contacts' force (two half kicks, as the particles' velocity Verlet), and the body moves by its
// own closed-form motion in between. A sphere bouncing off a free lid leaves as from an elastic
// two-body collision (momentum to round-off, the velocities to second order in dt); a container
// on a spring with no grain touching it follows its closed form; the energy budgets with a heavy
// lid on a dissipative bed and with a driven container full of grains close to O(dt^2) (the
// error falls four times when dt halves); a resumed run continues bit for bit.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "boundaries/wall_body.hpp"
#include "core/error.hpp"
#include "dem/dem_integrator.hpp"
#include "dem_fixtures.hpp"
#include "interactions/soft_contact.hpp"

namespace kairos {
namespace {

using testing::one_sphere;

constexpr int kLid = 5;  // z+

// Walls at z = 0 and z = 20 (x, y periodic), the top one of mass M pushed down by `force`;
// a linear spring-dashpot of stiffness k and restitution e for pairs and walls.
Environment<3> lidded_box(double mass, double force, double k, double e, double g = 0.0) {
  Environment<3> env;
  env.species = 1;
  const double pair_damping = e < 1.0 ? dashpot_damping_for_restitution(0.5, k, e) : 0.0;
  const double wall_damping = e < 1.0 ? dashpot_damping_for_restitution(1.0, k, e) : 0.0;
  env.soft = {SoftContactLaw::linear_dashpot(k, pair_damping)};
  env.soft_wall = {SoftContactLaw::linear_dashpot(k, wall_damping)};
  env.gravity = {0.0, 0.0, -g};
  env.faces[4].kind = FaceKind::kWall;
  env.faces[5].kind = FaceKind::kWall;
  env.faces[5].wall.mass = mass;
  env.faces[5].wall.force = force;
  return env;
}

// A sphere (m = 1) rising at 1 meets a free lid of mass 4 at rest, through an undamped spring:
// an elastic collision, after which the sphere moves at (1 - 4) / 5 and the lid at 2 / 5.
// Velocity Verlet conserves the momentum of the pair exactly (each step's impulses on the two
// are equal and opposite) and the energy to O(dt^2): the velocities' error falls about four
// times when dt halves.
double bounce_error(double dt) {
  DemOptions options;
  options.dt = dt;
  DemIntegrator<3> dem(one_sphere({10.0, 10.0, 15.0}, {0.0, 0.0, 1.0}),
                       lidded_box(4.0, 0.0, 1e5, 1.0), options);
  // The contact begins at t = 4.5 and lasts pi sqrt(mu / k) = 0.008: run to t = 5.
  dem.step(std::lround(5.0 / dt));
  const double v = dem.velocity(0)[2];
  const std::vector<WallReading> lid = dem.walls_with_mass();
  EXPECT_EQ(lid.size(), 1u);
  const double V = lid.at(0).speed;
  EXPECT_NEAR(v + 4.0 * V, 1.0, 1e-12) << "momentum";
  EXPECT_EQ(dem.contact_count(), 0u);
  EXPECT_EQ(dem.wall_collisions(), 1u);
  return std::max(std::abs(v + 0.6), std::abs(V - 0.4));
}

TEST(DemMassiveWalls, ASphereBouncesOffAFreeLidAsAnElasticTwoBodyCollision) {
  // Where the contact's start falls within a step makes the error's decrease uneven from one
  // halving to the next (measured 1.3e-3, 4.9e-4, 6.3e-5, 2.6e-5 at dt = 4, 2, 1, 0.5 e-4): over
  // eight times smaller steps it falls 49 times, against 8 at first order.
  const double coarse = bounce_error(4e-4), fine = bounce_error(5e-5);
  EXPECT_LT(coarse, 2e-3);
  EXPECT_GT(coarse / fine, 25.0) << coarse << " " << fine;
}

// A damped contact (e = 0.5) with a free lid of mass M keeps the law's restitution as a two-body
// collision, the damping taken at the reduced mass: afterwards v' - V' = -e (v - V) and
// v' + M V' = 1 (the sphere's mass 1, rising at 1), with the e the same law gives against a
// fixed lid (0.4946 at this step: the DEM's own discretisation). At the particle's mass alone
// the damping would give e = 0.39 at M = 1.
TEST(DemMassiveWalls, ADampedBounceOffALightLidKeepsTheRestitution) {
  DemIntegrator<3> fixed(one_sphere({10.0, 10.0, 15.0}, {0.0, 0.0, 1.0}),
                         lidded_box(0.0, 0.0, 1e5, 0.5));
  fixed.step(std::lround(5.0 / fixed.dt()));
  const double e_fixed = -fixed.velocity(0)[2];
  EXPECT_NEAR(e_fixed, 0.5, 0.01);
  for (const double M : {1.0, 4.0, 100.0}) {
    DemIntegrator<3> dem(one_sphere({10.0, 10.0, 15.0}, {0.0, 0.0, 1.0}),
                         lidded_box(M, 0.0, 1e5, 0.5));
    dem.step(std::lround(5.0 / dem.dt()));
    const double v = dem.velocity(0)[2], V = dem.walls_with_mass().at(0).speed;
    EXPECT_NEAR(v + M * V, 1.0, 1e-12) << "M = " << M;
    EXPECT_NEAR(V - v, e_fixed, 1e-3) << "M = " << M;
    EXPECT_EQ(dem.contact_count(), 0u);
  }
}

// A sphere pressed against the floor by a lid (mass 10, force 20, gravity 1), a damped contact
// it never leaves: the lid's damping reads its predicted velocity, as the particles read each
// other's, so the budget closes to second order (with the velocity before the closing half
// kick it was first order: the error halved with dt).
double pressed_sphere_error(double dt) {
  ParticleSystem<3> s = one_sphere({10.0, 10.0, 0.5}, {0.0, 0.0, 0.0});
  s.box = {20.0, 20.0, 1.5};
  DemOptions options;
  options.dt = dt;
  DemIntegrator<3> dem(s, lidded_box(10.0, 20.0, 1e5, 0.5, 1.0), options);
  const auto budget = [&] {
    return dem.kinetic_energy() + dem.potential_energy() + dem.field_energy() +
           dem.dissipated_energy() + dem.dissipated_at_walls() + dem.walls_with_mass().at(0).energy;
  };
  const double e0 = budget();
  dem.step(std::lround(3.0 / dt));
  EXPECT_GT(dem.dissipated_at_walls(), 0.1);
  EXPECT_GE(dem.wall_collisions(), 2u);  // the floor and the lid (which may bounce first)
  return std::abs(budget() - e0) / (std::abs(e0) + dem.dissipated_at_walls());
}

TEST(DemMassiveWalls, APersistentDampedContactWithALidIsSecondOrder) {
  const double coarse = pressed_sphere_error(2e-4), fine = pressed_sphere_error(1e-4);
  EXPECT_GT(coarse / fine, 3.0) << coarse << " " << fine;
  EXPECT_LT(coarse / fine, 5.5) << coarse << " " << fine;
}

// Dissipative spheres (e = 0.7) on the floor under gravity, a lid of mass 20 pushed down by a
// force 30: kinetic + rotational + elastic + field energy of the spheres, the lid's mechanical
// energy, and what the damping took, constant to O(dt^2) (the floor does no work); and the
// spheres' own budget with the lid's work on them in place of its energy (work_by_walls, the
// summary's balance), likewise: counted at the lid's speed before its closing half kick it
// drifted by dt F^2 / 2M per step, first order.
struct BedErrors {
  double whole = 0.0, spheres = 0.0;
};

BedErrors bed_budget_error(double dt, std::uint64_t* contacts = nullptr) {
  ParticleSystem<3> s;
  s.box = {6.0, 6.0, 20.0};
  s.periodic = {true, true, false};
  testing::add_bed(s, {.count = {4, 4, 6},
                       .first = {0.75, 0.75, 1.0},
                       .spacing = {1.5, 1.5, 1.5},
                       .jitter = 0.1,
                       .seed = 3});
  DemOptions options;
  options.dt = dt;
  DemIntegrator<3> dem(s, lidded_box(20.0, 30.0, 1e5, 0.7, 1.0), options);
  const auto budget = [&] {
    return dem.kinetic_energy() + dem.rotational_energy() + dem.potential_energy() +
           dem.field_energy() + dem.dissipated_energy() + dem.dissipated_at_walls() +
           dem.walls_with_mass().at(0).energy;
  };
  const auto spheres = [&] {
    return dem.kinetic_energy() + dem.rotational_energy() + dem.potential_energy() +
           dem.field_energy() + dem.dissipated_energy() + dem.dissipated_at_walls() -
           dem.work_by_walls();
  };
  const double e0 = budget(), s0 = spheres();
  dem.step(std::lround(8.0 / dt));
  if (contacts != nullptr) *contacts = dem.wall_collisions();
  const std::vector<WallReading> lid = dem.walls_with_mass();
  EXPECT_LT(lid.at(0).position, 20.0 - 5.0);  // it came down onto the bed
  EXPECT_GT(dem.dissipated_energy(), 10.0);
  const double scale = std::abs(e0) + dem.dissipated_energy();
  EXPECT_GT(std::abs(dem.work_by_walls()), 10.0);
  return {std::abs(budget() - e0) / scale, std::abs(spheres() - s0) / scale};
}

TEST(DemMassiveWalls, AHeavyLidOnADissipativeBedClosesTheBudgetToSecondOrder) {
  // Measured 9.8e-3, 2.6e-3, 6.1e-4 at dt = 4, 2, 1 e-4 (the default step is 1.9e-4).
  std::uint64_t contacts = 0;
  const BedErrors coarse = bed_budget_error(2e-4, &contacts), fine = bed_budget_error(1e-4);
  EXPECT_GT(contacts, 20u);
  for (const auto& [a, b] :
       {std::pair{coarse.whole, fine.whole}, std::pair{coarse.spheres, fine.spheres}}) {
    EXPECT_LT(a, 5e-3);
    EXPECT_GT(a / b, 3.0) << a << " " << b;
    EXPECT_LT(a / b, 5.5) << a << " " << b;
  }
}

// Both walls of z joined as a container of mass 50 on a spring (k = 200, c = 10) whose anchor
// moves as 1.5 sin(2 t): with one sphere floating in the middle (it never touches a wall), the
// container's place is the closed form of the driven, damped oscillator.
Environment<3> container(double k_contact) {
  Environment<3> env = lidded_box(50.0, 0.0, k_contact, 0.8);
  env.faces[5].wall.mass = 0.0;
  for (const int f : {4, 5}) {
    Wall<3>& w = env.faces[static_cast<std::size_t>(f)].wall;
    w.mass = 50.0;
    w.joined = true;
    w.spring = WallSpring{200.0, 10.0, 1.5, 2.0, 0.3};
  }
  return env;
}

TEST(DemMassiveWalls, AnEmptyContainerFollowsItsClosedForm) {
  DemIntegrator<3> dem(one_sphere({10.0, 10.0, 10.0}, {0.0, 0.0, 0.0}), container(1e5));
  WallBody reference;
  reference.mass = 50.0;
  reference.spring = SpringMotion(WallSpring{200.0, 10.0, 1.5, 2.0, 0.3}, 50.0, 0.0);
  reference.set(0.0, 0.0, 0.0);
  for (int k = 0; k < 20; ++k) {
    dem.step(1000);
    const double t = dem.time();
    const std::vector<WallReading> walls = dem.walls_with_mass();
    ASSERT_EQ(walls.size(), 1u);
    EXPECT_TRUE(walls[0].container);
    ASSERT_NEAR(walls[0].position, reference.position_at(t), 1e-10) << "t = " << t;
    ASSERT_NEAR(walls[0].speed, reference.speed_at(t), 1e-10) << "t = " << t;
  }
  EXPECT_EQ(dem.wall_collisions(), 0u);
}

// 64 grains on a jittered lattice in a box 6 x 6 x 12 (z between the container's walls).
ParticleSystem<3> grains_in_a_box(std::uint64_t seed) {
  ParticleSystem<3> s;
  s.box = {6.0, 6.0, 12.0};
  s.periodic = {true, true, false};
  testing::add_bed(s, {.count = {4, 4, 4},
                       .first = {0.75, 0.75, 2.0},
                       .spacing = {1.5, 1.5, 1.5},
                       .jitter = 0.1,
                       .seed = seed});
  return s;
}

// The container under gravity -1 along z.
Environment<3> falling_into_the_container() {
  Environment<3> env = container(1e5);
  env.gravity = {0.0, 0.0, -1.0};
  return env;
}

// Grains in the driven container: the grains' energy, the container's (kinetic, spring, field),
// the damping's and the dashpot's dissipation less the anchor's work, constant to O(dt^2).
double container_budget_error(double dt) {
  const ParticleSystem<3> s = grains_in_a_box(5);
  const Environment<3> env = falling_into_the_container();
  DemOptions options;
  options.dt = dt;
  DemIntegrator<3> dem(s, env, options);
  const auto budget = [&] {
    const WallReading w = dem.walls_with_mass().at(0);
    return dem.kinetic_energy() + dem.rotational_energy() + dem.potential_energy() +
           dem.field_energy() + dem.dissipated_energy() + dem.dissipated_at_walls() + w.energy +
           w.dashpot - w.drive_work;
  };
  const double e0 = budget();
  dem.step(std::lround(6.0 / dt));
  const WallReading w = dem.walls_with_mass().at(0);
  EXPECT_GT(dem.wall_collisions(), 20u);
  EXPECT_GT(std::abs(w.drive_work), 1.0);
  return std::abs(budget() - e0) /
         (std::abs(e0) + dem.dissipated_energy() + std::abs(w.drive_work) + w.dashpot);
}

TEST(DemMassiveWalls, ADrivenContainerOfGrainsClosesTheBudgetToSecondOrder) {
  // Measured 8.4e-4 and 2.0e-4.
  const double coarse = container_budget_error(2e-4), fine = container_budget_error(1e-4);
  EXPECT_LT(coarse, 1e-3);
  EXPECT_GT(coarse / fine, 2.5) << coarse << " " << fine;
  EXPECT_LT(coarse / fine, 6.0) << coarse << " " << fine;
}

TEST(DemMassiveWalls, AResumedRunContinuesBitForBit) {
  const ParticleSystem<3> s = grains_in_a_box(7);
  const Environment<3> env = falling_into_the_container();
  DemIntegrator<3> a(s, env);
  a.step(5000);
  ParticleSystem<3> state = a.export_state();
  ASSERT_EQ(state.wall_motion.size(), 1u);
  state.dem = a.checkpoint();
  DemIntegrator<3> b(state, env);
  a.step(5000);
  b.step(5000);
  ASSERT_GT(a.wall_collisions(), 0u);
  const WallReading wa = a.walls_with_mass().at(0), wb = b.walls_with_mass().at(0);
  EXPECT_EQ(wa.position, wb.position);
  EXPECT_EQ(wa.speed, wb.speed);
  EXPECT_EQ(wa.drive_work, wb.drive_work);
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a.position(i), b.position(i)) << i;
    ASSERT_EQ(a.velocity(i), b.velocity(i)) << i;
  }
  // Continued without the integrator's own state: the walls from the state's motion, the
  // forces afresh (not bit for bit, but the same motion to O(dt^2)).
  ParticleSystem<3> plain = a.export_state();
  DemIntegrator<3> c(plain, env);
  EXPECT_NEAR(c.walls_with_mass().at(0).position, a.walls_with_mass().at(0).position, 1e-12);
}

TEST(DemMassiveWalls, AMotionForAFaceWithoutMassIsRefused) {
  ParticleSystem<3> s = one_sphere({10.0, 10.0, 10.0}, {0.0, 0.0, 0.0});
  WallMotion m;
  m.face = 4;  // z-: no mass in lidded_box
  s.wall_motion = {m};
  EXPECT_THROW(DemIntegrator<3>(s, lidded_box(4.0, 0.0, 1e5, 1.0)), InputError);
}

}  // namespace
}  // namespace kairos
