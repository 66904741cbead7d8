// Soft spheres against plane walls anywhere in the event-driven engine: the map's wall contact
// along the plane's normal (docs/physics.md#event-driven-soft-contacts). A sphere meeting a
// tilted plane leaves with e v_n of the closed-form dashpot along the normal, its tangential
// motion untouched, at the end overlap the closed form gives; a tilted piston's contact is the
// map in the wall's frame, where the DEM (same law, same plane) puts it, with the energy budget
// closed; a gas in a box with a slope keeps every invariant (brute-force validation after every
// event); a restart with a contact against a plane in progress resumes bit for bit.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>
#include <string>

#include "dem/dem_integrator.hpp"
#include "engine/event_engine.hpp"
#include "engine_fixtures.hpp"
#include "interactions/soft_contact.hpp"
#include "io/gsd_snapshot.hpp"
#include "scheduler/calendar_queue.hpp"
#include "soft_wall_checks.hpp"

namespace kairos {
namespace {

using Engine3 = EventEngine<3, CalendarQueue>;

// A box with walls on the x and z faces (a plane tilted in x-z must not cut a periodic axis).
Environment<3> walled(const SoftContactLaw& law, std::uint32_t species = 1) {
  Environment<3> env;
  env.species = species;
  env.soft.assign(static_cast<std::size_t>(species) * species, law);
  env.soft_wall.assign(species, law);
  for (int f : {0, 1, 4, 5}) env.faces[static_cast<std::size_t>(f)].kind = FaceKind::kWall;
  return env;
}

// The slope: normal (-sin 30, 0, cos 30) into the domain, through (5, 0, 3).
const Vec<3> kNormal{-0.5, 0.0, std::sqrt(3.0) / 2.0};
const Vec<3> kPoint{5.0, 0.0, 3.0};

PlaneWall<3> slope() {
  PlaneWall<3> p;
  p.normal = kNormal;
  p.offset = dot(kNormal, kPoint);
  return p;
}

// One sphere (m, R = 0.5) whose centre reaches R from the slope at time t0 moving at v, and a
// bystander far away.
ParticleSystem<3> towards_slope(const Vec<3>& v, double t0, double m) {
  ParticleSystem<3> s;
  s.box = {10.0, 10.0, 10.0};
  s.periodic = {false, true, false};
  const Vec<3> touch = kPoint + 0.5 * kNormal + Vec<3>{0.0, 5.0, 0.0};
  s.kinematics = {{touch - t0 * v, v, 0.0, 0.5}, {{8.5, 2.0, 8.5}, {}, 0.0, 0.5}};
  s.mass = {m, m};
  s.species = {0, 0};
  s.species_names = {"A"};
  return s;
}

TEST(SoftPlanes, ATiltedPlaneContactIsTheClosedFormDashpotAlongItsNormal) {
  const double k = 900.0, gamma = 9.0, m = 1.5, vn = 1.3;
  const Vec<3> tangential{0.3 * std::sqrt(3.0) / 2.0, -0.2, 0.3 * 0.5};  // along the slope, and y
  ASSERT_NEAR(dot(tangential, kNormal), 0.0, 1e-15);
  const Vec<3> v = tangential - vn * kNormal;
  Environment<3> env = walled(SoftContactLaw::linear_dashpot(k, gamma));
  surface_specs<PlaneWalls<3>>(env) = {slope()};
  Engine3 engine(towards_slope(v, 0.4, m), StartMode::kPredict, {}, env);
  EventKind kind;
  while ((kind = engine.step()) != EventKind::kSoftRelease) ASSERT_NE(kind, EventKind::kNone);
  const HeadOn closed = dashpot_head_on(m, k, gamma);
  EXPECT_NEAR(engine.time(), 0.4 + closed.contact_time, 1e-10);
  const ParticleSystem<3> after = engine.export_state();
  const Vec<3> u = after.kinematics[0].vel;
  EXPECT_NEAR(dot(u, kNormal), vn * closed.restitution, 1e-12);
  const Vec<3> slid = u - dot(u, kNormal) * kNormal;
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(slid[a], tangential[a], 1e-12) << a;
  // Released at the end overlap along the normal, having slid with its tangential velocity.
  const Vec<3> x = after.position(0, engine.time());
  EXPECT_NEAR(dot(x - kPoint, kNormal), 0.5 - dashpot_end_overlap(m, k, gamma, vn), 1e-10);
  EXPECT_NEAR(after.counters.dissipated_at_walls,
              0.5 * m * vn * vn * (1.0 - closed.restitution * closed.restitution), 1e-10);
  EXPECT_EQ(after.counters.wall_collisions, 1u);
}

// The slope moving along its normal at u (a tilted piston): the map in the wall's frame, the
// DEM's trajectory (same Hertz law and plane, dt = t_c / 20 000), the budget to round-off.
TEST(SoftPlanes, ATiltedPistonIsTheMapInTheWallsFrameAndAgreesWithTheDem) {
  const double m = 1.5, u = 0.4, vn = 1.1;
  const SoftContactLaw law = SoftContactLaw::viscoelastic_hertz(5e3, 1e-3);
  Environment<3> env = walled(law);
  PlaneWall<3> piston = slope();
  piston.wall.velocity = u * kNormal;
  surface_specs<PlaneWalls<3>>(env) = {piston};
  // Along the slope and along y, then towards it at vn relative to it.
  const Vec<3> tangential{0.1 * std::sqrt(3.0) / 2.0, 0.2, 0.1 * 0.5};
  const Vec<3> v = tangential - vn * kNormal + u * kNormal;
  ParticleSystem<3> s = towards_slope(v, 0.3, m);
  // The plane moves: at t0 = 0.3 it is u t0 further along the normal.
  s.kinematics[0].pos = s.kinematics[0].pos + (u * 0.3) * kNormal;
  Engine3 engine(s, StartMode::kPredict, {}, env);
  testing::step_to_release_keeping_the_wall_budget(engine);
  EXPECT_NEAR(engine.time(), 0.3, 0.3);  // met near t0, released after the contact time
  const CollisionUnits units = reduce_collision(law, m, 0.5, vn, 0.0);
  const CollisionMap map = collision_map(units.reduced);
  const ParticleSystem<3> after = engine.export_state();
  const Vec<3> w = after.kinematics[0].vel;
  EXPECT_NEAR(dot(w, kNormal), u - map.eps_rdot * vn, 1e-12);
  EXPECT_GT(after.counters.work_by_walls, 0.0);  // the piston pushes the sphere back
  testing::expect_the_dem_agrees(s, env, units, map, engine.time(), after);
}

// A soft gas above a slope, inside walls: the engine's state checked against brute force
// after every event (no contact with the plane missed, none placed through it), the energy
// budget to round-off, contacts with the plane made.
TEST(SoftPlanes, AGasAboveASlopeKeepsEveryInvariant) {
  ParticleSystem<3> s = testing::lattice_system<3>(5, 0.12, 3);
  s.periodic = {false, true, false};
  // Clear of the faces (walls on x and z), and the slope 0.6 below the lowest centre.
  for (auto& k : s.kinematics)
    for (int a : {0, 2}) k.pos[a] = 0.6 + k.pos[a] * (s.box[a] - 1.2) / s.box[a];
  double lowest = s.box[0];
  for (const auto& k : s.kinematics) lowest = std::min(lowest, dot(k.pos, kNormal));
  Environment<3> env = walled(SoftContactLaw::linear_dashpot(2.0e3, 8.0), 2);
  PlaneWall<3> p;
  p.normal = kNormal;
  p.offset = lowest - 0.6;
  surface_specs<PlaneWalls<3>>(env) = {p};
  Engine3 engine(s, StartMode::kPredict, {}, env);
  const auto budget = [&] {
    const EventCounters& c = engine.counters();
    return engine.kinetic_energy() + engine.potential_energy() + c.dissipated_in_collisions +
           c.dissipated_at_walls;
  };
  const double e0 = budget();
  std::uint64_t on_plane = 0;
  for (int k = 0; k < 3000; ++k) {
    ASSERT_NE(engine.step(), EventKind::kNone);
    ASSERT_NO_THROW(engine.validate()) << "after event " << k;
    ASSERT_NEAR(budget(), e0, 1e-11 * e0) << "after event " << k;
    for (const FrozenContact<3>& c : engine.export_state().frozen)
      on_plane += c.j == FrozenContact<3>::kWall && c.face == 6 ? 1u : 0u;
  }
  EXPECT_GT(engine.counters().wall_collisions, 10u);
  EXPECT_GT(on_plane, 0u);  // contacts with the slope (surface 6, after the six faces) held
}

TEST(SoftPlanes, ARestartWithAContactAgainstAPlaneResumesBitForBit) {
  const double k = 900.0, gamma = 2.0, m = 1.5;
  Environment<3> env = walled(SoftContactLaw::linear_dashpot(k, gamma));
  surface_specs<PlaneWalls<3>>(env) = {slope()};
  Engine3 a(towards_slope(Vec<3>{0.1, 0.0, 0.0} - 1.3 * kNormal, 0.4, m), StartMode::kPredict, {},
            env);
  const auto against_plane = [&] {
    for (const FrozenContact<3>& c : a.export_state().frozen)
      if (c.j == FrozenContact<3>::kWall && c.face == 6) return true;
    return false;
  };
  while (!against_plane()) ASSERT_NE(a.step(), EventKind::kNone);
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() /
      ("kairos_soft_plane_resume_" + std::to_string(::getpid()) + ".gsd");
  std::mt19937_64 rng(5);
  write_restart(file, a.export_state(), rng);
  const ParticleSystem<3> mid = read_restart<3>(file, rng);
  std::filesystem::remove(file);
  EXPECT_EQ(mid.frozen, a.export_state().frozen);
  Engine3 b(mid, StartMode::kResume, {}, env);
  for (int n = 0; n < 50; ++n) {
    const EventKind ka = a.step(), kb = b.step();
    ASSERT_EQ(ka, kb);
    if (ka == EventKind::kNone) break;
  }
  const ParticleSystem<3> ea = a.export_state(), eb = b.export_state();
  EXPECT_EQ(ea.time, eb.time);
  for (std::size_t i = 0; i < ea.size(); ++i) {
    ASSERT_EQ(ea.kinematics[i].pos, eb.kinematics[i].pos) << i;
    ASSERT_EQ(ea.kinematics[i].vel, eb.kinematics[i].vel) << i;
  }
  EXPECT_EQ(ea.counters.dissipated_at_walls, eb.counters.dissipated_at_walls);
  EXPECT_GT(ea.counters.dissipated_at_walls, 0.0);  // the contact ended after the restart
}

}  // namespace
}  // namespace kairos
