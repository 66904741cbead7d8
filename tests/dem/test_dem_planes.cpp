// Plane walls anywhere in the DEM ([[boundary.plane]], the boundary component
// boundaries/plane_walls): the same force law as the box faces, through the boundary
// interface. An axis-aligned plane gives the face wall's trajectory (to round-off: the plane is
// one unit higher); a sphere on a frictionless slope slides at g sin(theta), and with friction
// rolls without slipping at (5/7) g sin(theta) (the textbook result for I = 2/5 m R^2 when
// mu > (2/7) tan(theta)); a round hole's rim (a ring) pushes a sphere falling on it through
// the hole with the energy budget closed; a piston plane's work closes the energy budget; a
// deep overlap names the plane.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "core/error.hpp"
#include "dem/dem_integrator.hpp"
#include "dem_fixtures.hpp"
#include "interactions/soft_contact.hpp"

namespace kairos {
namespace {

using testing::one_sphere;

const SoftContactLaw kLaw = SoftContactLaw::linear_dashpot(1e5, 20.0);

// A box periodic along x and y with walls at z = 0 and z = 20 (the DEM has no open faces).
Environment<3> closed_box(double g) {
  Environment<3> env;
  env.species = 1;
  env.soft = {kLaw};
  env.soft_wall = {kLaw};
  env.gravity = {0.0, 0.0, -g};
  env.faces[4].kind = FaceKind::kWall;
  env.faces[5].kind = FaceKind::kWall;
  return env;
}

PlaneWall<3> plane_through(const Vec<3>& normal, const Vec<3>& point) {
  PlaneWall<3> p;
  p.normal = normal;
  p.offset = dot(normal, point);
  return p;
}

// A sphere dropped onto a floor bounces the same on the face wall at z = 0 as on a plane at
// z = 1 (started one unit higher): the plane's generic loop is the faces' force law.
TEST(DemPlanes, AnAxisAlignedPlaneBouncesAsTheFloorFace) {
  const double g = 1.0;
  DemIntegrator<3> on_face(one_sphere({10.0, 10.0, 2.0}, {0.3, 0.0, -1.0}), closed_box(g));
  Environment<3> env = closed_box(g);
  surface_specs<PlaneWalls<3>>(env) = {plane_through({0.0, 0.0, 1.0}, {0.0, 0.0, 1.0})};
  DemIntegrator<3> on_plane(one_sphere({10.0, 10.0, 3.0}, {0.3, 0.0, -1.0}), env);
  ASSERT_EQ(on_face.dt(), on_plane.dt());
  for (int k = 0; k < 200; ++k) {
    on_face.step(100);
    on_plane.step(100);
    const Vec<3> a = on_face.position(0), b = on_plane.position(0);
    ASSERT_NEAR(b[2] - 1.0, a[2], 1e-10) << "after " << 100 * (k + 1) << " steps";
    ASSERT_NEAR(b[0], a[0], 1e-12);
    ASSERT_NEAR(on_plane.velocity(0)[2], on_face.velocity(0)[2], 1e-9);
  }
  EXPECT_EQ(on_plane.wall_collisions(), on_face.wall_collisions());
  EXPECT_GE(on_face.wall_collisions(), 1u);  // it did bounce
  EXPECT_NEAR(on_plane.dissipated_at_walls(), on_face.dissipated_at_walls(),
              1e-9 * on_face.dissipated_at_walls());
}

// A sphere falling onto the rim of a round hole (a plane with hole_radius: its edge a ring,
// boundaries/ring_edges) feels the ring's force along the normal from the circle's nearest
// point: falling just inside the rim it is pushed towards the axis and through the hole, its
// overlap with the circle small, the elastic energy budget closed to the Verlet accuracy; one
// on the hole's axis falls through untouched.
TEST(DemPlanes, ASphereOnARoundHolesRimIsPushedThroughItAndOneOnTheAxisFallsUntouched) {
  const double g = 1.0;
  Environment<3> env = closed_box(g);
  env.soft = {SoftContactLaw::linear_dashpot(1e5, 0.0)};  // elastic: the budget is exact
  env.soft_wall = env.soft;
  PlaneWall<3> floor = plane_through({0.0, 0.0, 1.0}, {10.0, 10.0, 5.0});
  floor.hole_radius = 1.0;
  floor.hole_center = {10.0, 10.0, 5.0};
  surface_specs<PlaneWalls<3>>(env) = {floor};
  // Its centre 0.2 inside the rim: it meets the ring (at height 0.458), not the plate.
  DemIntegrator<3> rim(one_sphere({10.8, 10.0, 7.0}, {}), env);
  const auto energy = [&](const DemIntegrator<3>& d) {
    return d.kinetic_energy() + d.potential_energy() + d.field_energy() + d.dissipated_energy() +
           d.dissipated_at_walls();
  };
  const double e0 = energy(rim);
  double closest = kNever, rho_through = kNever;
  while (rim.position(0)[2] > 4.0) {
    rim.step(10);
    const Vec<3> x = rim.position(0);
    const double rho = std::hypot(x[0] - 10.0, x[1] - 10.0);
    closest = std::min(closest, std::hypot(rho - 1.0, x[2] - 5.0));
    if (x[2] < 5.0 && rho_through == kNever) rho_through = rho;
    ASSERT_LT(rim.time(), 20.0) << "it never passed the hole";
  }
  EXPECT_GE(rim.wall_collisions(), 1u);  // the ring (then maybe the far side of the rim)
  EXPECT_LT(closest, 0.5);               // it touched the ring
  EXPECT_GT(closest, 0.5 - 0.01);        // with a small overlap
  EXPECT_LT(rho_through, 0.8);           // pushed towards the axis, through the hole
  EXPECT_NEAR(energy(rim), e0, 1e-4 * std::abs(e0));
  // On the axis: a radius of 0.5 passes a hole of radius 1 without a contact.
  DemIntegrator<3> axis(one_sphere({10.0, 10.0, 7.0}, {}), env);
  while (axis.position(0)[2] > 3.0) axis.step(10);
  EXPECT_EQ(axis.wall_collisions(), 0u);
}

struct Slope {
  double theta = std::numbers::pi / 6.0;  // 30 degrees
  Vec<3> normal() const { return {-std::sin(theta), 0.0, std::cos(theta)}; }
  Vec<3> down() const { return {-std::cos(theta), 0.0, -std::sin(theta)}; }  // along the slope
};

// A sphere resting on a slope through (10, 10, 5) at its static overlap m g cos(theta) / k.
ParticleSystem<3> on_slope(const Slope& slope, double g) {
  const Vec<3> contact{10.0, 10.0, 5.0};
  const double overlap = g * std::cos(slope.theta) / 1e5;
  return one_sphere(contact + (0.5 - overlap) * slope.normal(), {});
}

TEST(DemPlanes, AFrictionlessSphereSlidesDownASlopeAtGSinTheta) {
  const double g = 1.0;
  const Slope slope;
  Environment<3> env = closed_box(g);
  surface_specs<PlaneWalls<3>>(env) = {plane_through(slope.normal(), {10.0, 10.0, 5.0})};
  const ParticleSystem<3> s = on_slope(slope, g);
  DemIntegrator<3> dem(s, env);
  const double t = 2.0;
  dem.step(static_cast<long>(std::llround(t / dem.dt())));
  const Vec<3> moved = dem.position(0) - s.kinematics[0].pos;
  const double along = dot(moved, slope.down());
  EXPECT_NEAR(along, 0.5 * g * std::sin(slope.theta) * t * t, 1e-4);
  EXPECT_NEAR(dot(dem.velocity(0), slope.down()), g * std::sin(slope.theta) * t, 1e-4);
  EXPECT_NEAR(dot(moved, slope.normal()), 0.0, 1e-4);  // it stays on the slope
  // Energy: kinetic + gravity's + the contact's spring energy (at the start (1/2) k overlap^2),
  // what dissipated beside.
  const double overlap = g * std::cos(slope.theta) / 1e5;
  const double e0 = g * s.kinematics[0].pos[2] + 0.5 * 1e5 * overlap * overlap;
  const double e = dem.kinetic_energy() + dem.field_energy() + dem.potential_energy() +
                   dem.dissipated_at_walls();
  EXPECT_NEAR(e, e0, 1e-7 * e0);
}

TEST(DemPlanes, ARoughSphereRollsDownASlopeAtFiveSeventhsOfGSinTheta) {
  const double g = 1.0, mu = 0.5;  // mu > (2/7) tan 30 = 0.165: rolling, no slip
  const Slope slope;
  Environment<3> env = closed_box(g);
  surface_specs<PlaneWalls<3>>(env) = {plane_through(slope.normal(), {10.0, 10.0, 5.0})};
  env.soft_friction = {SoftFriction{mu, 2.0 / 7.0, 0.5}};
  env.soft_wall_friction = env.soft_friction;
  const ParticleSystem<3> s = on_slope(slope, g);
  DemIntegrator<3> dem(s, env);
  const double t = 2.0;
  dem.step(static_cast<long>(std::llround(t / dem.dt())));
  const double a = 5.0 / 7.0 * g * std::sin(slope.theta);
  const Vec<3> moved = dem.position(0) - s.kinematics[0].pos;
  EXPECT_NEAR(dot(moved, slope.down()), 0.5 * a * t * t, 2e-3 * 0.5 * a * t * t);
  const double v = dot(dem.velocity(0), slope.down());
  EXPECT_NEAR(v, a * t, 2e-3 * a * t);
  // Rolling: the contact point rests, omega_y R = v (rolling down -x turns it about -y... the
  // sign follows from omega x (-R n) = -v along the slope).
  const ParticleSystem<3> end = dem.export_state();
  const Vec<3> w = end.angular_velocity[0];
  const Vec<3> contact_velocity = dem.velocity(0) + cross(w, -0.5 * slope.normal());
  EXPECT_NEAR(std::sqrt(dot(contact_velocity, contact_velocity)), 0.0, 2e-3 * v);
  // No energy lost to slip once rolling (static friction does no work): the start-up transient
  // only.
  const double overlap = g * std::cos(slope.theta) / 1e5;
  const double e0 = g * s.kinematics[0].pos[2] + 0.5 * 1e5 * overlap * overlap;
  const double e = dem.kinetic_energy() + dem.rotational_energy() + dem.field_energy() +
                   dem.potential_energy() + dem.dissipated_at_walls();
  EXPECT_NEAR(e, e0, 1e-7 * e0);
  EXPECT_LT(dem.dissipated_at_walls(), 1e-3 * dem.kinetic_energy());
}

// A plane moving along its normal (a piston, tilted) pushes a sphere: its work is the energy
// the particle gains, to the integrator's O(dt^2) (the error falls about fourfold when dt halves).
double piston_budget_error(double steps_per_contact) {
  Environment<3> env = closed_box(0.0);
  const Vec<3> n{-std::sqrt(0.5), 0.0, std::sqrt(0.5)};
  PlaneWall<3> piston = plane_through(n, {10.0, 10.0, 5.0});
  piston.wall.velocity = 0.2 * n;  // into the domain
  surface_specs<PlaneWalls<3>>(env) = {piston};
  DemOptions options;
  options.steps_per_contact = steps_per_contact;
  DemIntegrator<3> dem(one_sphere(Vec<3>{10.0, 10.0, 5.0} + 2.0 * n, -0.1 * n), env, options);
  dem.step(static_cast<long>(std::llround(15.0 / dem.dt())));
  EXPECT_GE(dem.wall_collisions(), 1u);
  EXPECT_GT(dem.work_by_walls(), 0.01);
  // Pushed away faster than the piston moves (an infinitely heavy wall, e = 0.9 or so).
  EXPECT_GT(dot(dem.velocity(0), n), 0.2);
  const double e0 = 0.5 * 0.01;
  const double budget = dem.kinetic_energy() + dem.potential_energy() + dem.dissipated_at_walls() -
                        dem.work_by_walls();
  return std::abs(budget - e0);
}

TEST(DemPlanes, APistonPlanesWorkClosesTheEnergyBudget) {
  const double coarse = piston_budget_error(50.0), fine = piston_budget_error(100.0);
  EXPECT_LT(coarse, 1e-3 * 0.01);  // of the work done (measured 8.6e-6)
  EXPECT_GT(coarse / fine, 2.5);   // measured 3.07
}

TEST(DemPlanes, ADeepOverlapNamesThePlane) {
  Environment<3> env = closed_box(0.0);
  surface_specs<PlaneWalls<3>>(env) = {plane_through({0.0, 0.0, 1.0}, {0.0, 0.0, 5.0})};
  try {
    DemIntegrator<3> dem(one_sphere({10.0, 10.0, 5.1}, {}), env);
    dem.step(1);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("boundary.plane[0]"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace kairos
