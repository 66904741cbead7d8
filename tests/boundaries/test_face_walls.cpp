// The face walls as a boundary component (boundaries/face_walls.hpp) and the registry that holds
// the boundary components (model/boundaries.hpp): event times against closed forms, the
// response and its energy split, the cells a wall reaches, start checks and the squeeze time.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "boundaries/face_walls.hpp"
#include "core/error.hpp"
#include "model/boundaries.hpp"
#include "model/environment.hpp"

namespace kairos {
namespace {

Environment<3> box_with_floor_and_lid(double lid_speed = 0.0) {
  Environment<3> env;
  env.faces[4].kind = FaceKind::kWall;  // z-: the floor
  env.faces[5].kind = FaceKind::kWall;  // z+: the lid, a piston when it moves
  env.faces[5].wall.velocity = {0.0, 0.0, lid_speed};
  return env;
}

FaceWalls<3> walls_of(const Environment<3>& env) {
  return FaceWalls<3>(env.faces, {10.0, 10.0, 10.0}, env.gravity);
}

TEST(FaceWalls, FallOntoTheFloorTakesTheFreeFallTime) {
  Environment<3> env = box_with_floor_and_lid();
  env.gravity = {0.0, 0.0, -2.0};
  const FaceWalls<3> walls = walls_of(env);
  // Centre at height 3, radius 0.5, at rest: the gap 2.5 closes as g t^2 / 2.
  const double dt = walls.event_time(4, {5.0, 5.0, 3.0}, {0.0, 0.0, 0.0}, 0.5, 0.0, kNever);
  EXPECT_NEAR(dt, std::sqrt(2.0 * 2.5 / 2.0), 1e-12);
  // Thrown up at 1: it rises for 0.5, then falls from 3.25.
  const double up = walls.event_time(4, {5.0, 5.0, 3.0}, {0.0, 0.0, 1.0}, 0.5, 0.0, kNever);
  EXPECT_NEAR(up, 0.5 + std::sqrt(2.0 * 2.75 / 2.0), 1e-12);
  // Not before the horizon.
  EXPECT_EQ(walls.event_time(4, {5.0, 5.0, 3.0}, {0.0, 0.0, 0.0}, 0.5, 0.0, 1.0), kNever);
}

TEST(FaceWalls, PistonMeetsAParticleAtTheClosingSpeed) {
  const FaceWalls<3> walls = walls_of(box_with_floor_and_lid(-0.5));
  // The lid starts at 10 and moves down at 0.5; the particle (radius 0.5, at 4) rises at 1.
  // The gap 10 - 4 - 0.5 closes at 1.5; at t0 = 2 the lid is already at 9.
  const double dt = walls.event_time(5, {1.0, 1.0, 4.0}, {0.0, 0.0, 1.0}, 0.5, 2.0, kNever);
  EXPECT_NEAR(dt, (9.0 - 4.0 - 0.5) / 1.5, 1e-12);
  EXPECT_NEAR(walls.position(5, 2.0), 9.0, 1e-15);
  EXPECT_TRUE(walls.surface_moves(5));
  EXPECT_FALSE(walls.holds_still(5));
  EXPECT_TRUE(walls.holds_still(4));
}

TEST(FaceWalls, ElasticContactReflectsTheRelativeNormalVelocityAndCountsTheWork) {
  const FaceWalls<3> walls = walls_of(box_with_floor_and_lid(-0.5));
  Vec<3> v{0.3, -0.2, 1.0};
  Spin<3> w{};
  const ContactResult<3> r = walls.resolve(5, Vec<3>{}, 1.0, 2.0, 0.5, 0.4, false, v, w);
  // Relative normal velocity 1.5 towards the lid becomes 1.5 away from it.
  EXPECT_NEAR(v[2], -0.5 - 1.5, 1e-14);
  EXPECT_DOUBLE_EQ(v[0], 0.3);
  EXPECT_DOUBLE_EQ(v[1], -0.2);
  EXPECT_NEAR(r.dissipated, 0.0, 1e-14);
  // The piston's work is the particle's kinetic energy change: m (v'^2 - v^2) / 2.
  EXPECT_NEAR(work_on_particle(r), 0.5 * 2.0 * (4.0 - 1.0), 1e-13);
}

TEST(FaceWalls, InelasticFloorDissipatesWhatTheParticleLoses) {
  Environment<3> env = box_with_floor_and_lid();
  env.faces[4].wall.contact.normal = NormalRestitution::constant(0.5);
  const FaceWalls<3> walls = walls_of(env);
  Vec<3> v{0.0, 0.0, -2.0};
  Spin<3> w{};
  const ContactResult<3> r = walls.resolve(4, Vec<3>{}, 0.0, 1.0, 0.5, 0.4, false, v, w);
  EXPECT_NEAR(v[2], 1.0, 1e-14);
  EXPECT_NEAR(r.dissipated, 0.5 * (4.0 - 1.0), 1e-14);
  EXPECT_NEAR(work_on_particle(r), 0.0, 1e-14);  // a fixed wall does no work
}

TEST(FaceWalls, OnlyTheLayersAWallReachesTestIt) {
  Environment<3> env = box_with_floor_and_lid();
  env.faces[4].wall.amplitude = 1.2;  // a vibrating floor reaches further up
  env.faces[4].wall.angular_frequency = 3.0;
  const FaceWalls<3> bare = walls_of(env);
  FaceWalls<3> walls = bare;
  const CellGrid<3> grid({10.0, 10.0, 10.0}, Vec<3>{1.0, 1.0, 1.0}, {true, true, false}, 1000);
  walls.set_reach(grid, 0.5);
  // Reach 1.2 + 0.5 over cells of width 1: layers 0 and 1 for the floor, the last for the lid.
  EXPECT_TRUE(walls.reaches(4, grid.code_at({3, 3, 1}), grid));
  EXPECT_FALSE(walls.reaches(4, grid.code_at({3, 3, 2}), grid));
  EXPECT_TRUE(walls.reaches(5, grid.code_at({3, 3, 9}), grid));
  EXPECT_FALSE(walls.reaches(5, grid.code_at({3, 3, 8}), grid));
  // A face without a wall reaches nothing; a piston (moving along its normal) reaches every
  // layer.
  EXPECT_FALSE(walls.reaches(0, grid.code_at({0, 3, 3}), grid));
  Environment<3> with_piston = env;
  with_piston.faces[5].wall.velocity[2] = -0.1;
  FaceWalls<3> piston = walls_of(with_piston);
  piston.set_reach(grid, 0.5);
  EXPECT_TRUE(piston.reaches(5, grid.code_at({3, 3, 0}), grid));
  EXPECT_FALSE(piston.reaches(4, grid.code_at({3, 3, 5}), grid));
  // A particle in a layer the floor cannot reach finds no contact, whatever its motion.
  const BoundarySet<3, FaceWalls<3>> set(walls);
  const auto far = set.next_contact({5.0, 5.0, 5.5}, {0.0, 0.0, -1.0}, 0.5, grid.code_at({5, 5, 5}),
                                    grid, 0.0, kNever);
  EXPECT_EQ(far.second, -1);
  const auto near = set.next_contact({5.0, 5.0, 1.5}, {0.0, 0.0, -1.0}, 0.5,
                                     grid.code_at({5, 5, 1}), grid, 0.0, kNever);
  EXPECT_EQ(near.second, 4);
}

TEST(FaceWalls, StartChecksNameTheParticleAndAcceptRoundOffContacts) {
  const FaceWalls<3> walls = walls_of(box_with_floor_and_lid());
  EXPECT_NO_THROW(walls.check_start({5.0, 5.0, 0.5 * (1.0 - 1e-13)}, 0.5, 0.0, 7));
  try {
    walls.check_start({5.0, 5.0, 9.7}, 0.5, 0.0, 42);
    FAIL() << "an overlap with the lid was accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("particle 42"), std::string::npos) << what;
    EXPECT_NE(what.find("high face of axis z"), std::string::npos) << what;
  }
  const BoundarySet<3, FaceWalls<3>> set(walls);
  EXPECT_TRUE(set.overlaps({5.0, 5.0, 0.4}, 0.5, 0.0));
  EXPECT_FALSE(set.overlaps({5.0, 5.0, 0.4}, 0.5, 0.0, 4));  // the floor skipped
}

TEST(FaceWalls, ApproachingWallsLeaveNoRoomAtTheSqueezeTime) {
  Environment<3> env = box_with_floor_and_lid(-0.25);
  env.faces[4].wall.velocity = {0.0, 0.0, 0.25};
  FaceWalls<3> walls = walls_of(env);
  walls.find_squeeze_time(0.5, 1.0, true);
  // Few particles: the largest diameter (1 + 1e-3) is the room needed; closing at 0.5.
  EXPECT_NEAR(walls.squeeze_time(), (10.0 - 1.0 * (1.0 + 1e-3)) / 0.5, 1e-12);
  EXPECT_THROW(walls.throw_squeezed(walls.squeeze_time(), 1.0, true), InputError);
}

TEST(Boundaries, TheRegistryNumbersSurfacesAndFindsTheSoonest) {
  Environment<3> env = box_with_floor_and_lid();
  env.gravity = {0.0, 0.0, -1.0};
  Boundaries<3> boundaries(env, {10.0, 10.0, 10.0});
  EXPECT_TRUE(boundaries.any());
  EXPECT_EQ(boundaries.surfaces(), 6);
  EXPECT_FALSE(boundaries.is_surface(0));  // x- is periodic
  EXPECT_TRUE(boundaries.is_surface(4));
  EXPECT_FALSE(boundaries.any_surface_moves());
  const CellGrid<3> grid({10.0, 10.0, 10.0}, Vec<3>{1.0, 1.0, 1.0}, {true, true, false}, 1000);
  boundaries.faces().set_reach(grid, 0.5);
  const auto [dt, surface] = boundaries.next_contact({5.0, 5.0, 0.7}, {0.0, 0.0, 0.0}, 0.5,
                                                     grid.code_at({5, 5, 0}), grid, 0.0, kNever);
  EXPECT_EQ(surface, 4);
  EXPECT_NEAR(dt, std::sqrt(2.0 * 0.2), 1e-12);
  const Vec<3> n = boundaries.normal(5, {1.0, 1.0, 1.0}, 0.0);
  EXPECT_EQ(n[2], -1.0);
  EXPECT_NEAR(boundaries.gap(5, {1.0, 1.0, 9.0}, 0.0), 1.0, 1e-15);
}

}  // namespace
}  // namespace kairos
