// Lees-Edwards shear in the engine: no collision across the sliding faces is ever missed and
// nothing overlaps (brute force after every event, many image shifts), a collision through
// the boundary happens at the time the image geometry gives, the box-frame energy budget
// closes, momentum across the flow is conserved, and a resumed run continues bit for bit; the
// same with stepped potentials (zones through the sliding images, bonds across the faces).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "engine/event_engine.hpp"
#include "engine_fixtures.hpp"
#include "interactions/step_potential.hpp"
#include "scheduler/calendar_queue.hpp"

namespace kairos {
namespace {

template <int D>
using Engine = EventEngine<D, CalendarQueue>;

// A lattice gas already moving with the shear flow u_x = rate (y - L_y / 2).
template <int D>
ParticleSystem<D> sheared_gas(int n, double eta, std::uint64_t seed, double rate) {
  ParticleSystem<D> s = testing::lattice_system<D>(n, eta, seed);
  for (auto& k : s.kinematics) k.vel[0] += rate * (k.pos[1] - 0.5 * s.box[1]);
  return s;
}

template <int D>
Environment<D> shear(double rate, bool granular) {
  Environment<D> env;
  env.shear_rate = rate;
  if (granular) {
    env.species = 2;
    ContactModel law;
    law.normal = NormalRestitution::constant(0.8);
    law.tangential = TangentialModel::constant(0.3);
    env.contact.assign(4, law);
  }
  return env;
}

template <int D>
void check_invariants(int n, double eta, double rate, bool granular, int events) {
  Engine<D> engine(sheared_gas<D>(n, eta, 3, rate), StartMode::kPredict, EngineOptions{},
                   shear<D>(rate, granular));
  int shifts = 0;
  for (int k = 0; k < events; ++k) {
    const EventKind kind = engine.step();
    ASSERT_NE(kind, EventKind::kNone);
    shifts += kind == EventKind::kImageShift ? 1 : 0;
    ASSERT_NO_THROW(engine.validate()) << "event " << k;
  }
  // The run crossed the sliding faces often and wrapped the image offset more than once.
  EXPECT_GT(shifts, 3 * engine.grid().cells_along(0));
  EXPECT_GT(engine.counters().collisions, static_cast<std::uint64_t>(events / 4));
}

TEST(LeesEdwards, NoMissedCollisionNoOverlap3D) {
  check_invariants<3>(4, 0.3, 2.0, false, 6000);
}
TEST(LeesEdwards, NoMissedCollisionNoOverlap2D) {
  check_invariants<2>(8, 0.4, 1.5, false, 6000);
}
TEST(LeesEdwards, NegativeShearRate) {
  check_invariants<3>(4, 0.3, -1.7, false, 4000);
}
TEST(LeesEdwards, RoughInelasticSpheres) {
  check_invariants<3>(4, 0.3, 2.0, true, 4000);
}
// Three cells along x: the 4-cell window across a face wraps onto itself.
TEST(LeesEdwards, NarrowBoxOfThreeCells) {
  check_invariants<2>(3, 0.5, 3.0, false, 3000);
}

// A resting disk under the high y face and a disk falling out through the low one: the
// falling disk's image comes down from above, displaced by rate L_y t and moving with rate L_y.
// The collision happens when that image touches the resting disk, found here by bisection.
TEST(LeesEdwards, CollisionThroughTheFaceMeetsTheImage) {
  constexpr int D = 2;
  const double L = 10.0, rate = 0.3, U = rate * L;
  ParticleSystem<D> s;
  s.box = {L, L};
  s.kinematics = {{{5.0, L - 0.8}, {0.0, 0.0}, 0.0, 0.5}, {{3.1, 0.6}, {0.0, -1.0}, 0.0, 0.5}};
  s.mass = {1.0, 1.0};
  s.species = {0, 0};
  s.species_names = {"A"};
  // Distance from the resting disk to the falling disk's image above, at time t.
  auto gap = [&](double t) {
    const double x = 3.1 + U * t, y = 0.6 + L - t;
    double dx = x - 5.0;
    dx -= L * std::round(dx / L);
    return std::hypot(dx, y - (L - 0.8)) - 1.0;
  };
  double lo = 0.0, hi = 0.5;
  ASSERT_GT(gap(lo), 0.0);
  ASSERT_LT(gap(hi), 0.0);
  for (int k = 0; k < 200; ++k) {
    const double mid = 0.5 * (lo + hi);
    (gap(mid) > 0.0 ? lo : hi) = mid;
  }
  Engine<D> engine(s, StartMode::kPredict, EngineOptions{}, shear<D>(rate, false));
  EventKind kind;
  while ((kind = engine.step()) != EventKind::kCollision) ASSERT_NE(kind, EventKind::kNone);
  EXPECT_NEAR(engine.time(), hi, 1e-12);
  // Elastic and equal masses: the image's relative velocity along the contact normal moves to
  // the resting disk; both energies in the image frame add up as before.
  const ParticleSystem<D> after = engine.export_state();
  const Vec<D> va = after.kinematics[0].vel, vb = after.kinematics[1].vel;
  const Vec<D> vb_image = {vb[0] + U, vb[1]};
  EXPECT_NEAR(norm2(va) + norm2(vb_image), U * U + 1.0, 1e-12);
  EXPECT_NEAR(va[0] + vb_image[0], U, 1e-12);
  EXPECT_NEAR(va[1] + vb_image[1], -1.0, 1e-12);
}

// Box-frame kinetic energy changes only by the shear work minus dissipation; momentum across
// the flow (y, z) is conserved because the faces only add x velocity.
template <int D>
void check_budget(bool granular) {
  Engine<D> engine(sheared_gas<D>(D == 3 ? 5 : 10, 0.25, 9, 0.8), StartMode::kPredict,
                   EngineOptions{}, shear<D>(0.8, granular));
  const double e0 = engine.kinetic_energy() + engine.rotational_energy();
  const Vec<D> p0 = engine.momentum();
  for (int k = 0; k < 30000; ++k) ASSERT_NE(engine.step(), EventKind::kNone);
  const EventCounters& c = engine.counters();
  const double e1 = engine.kinetic_energy() + engine.rotational_energy();
  EXPECT_NEAR(e1 - e0, c.work_by_shear - c.dissipated_in_collisions,
              1e-11 * (e0 + std::abs(c.work_by_shear) + c.dissipated_in_collisions));
  EXPECT_GT(std::abs(c.work_by_shear), 0.1 * e0);
  const Vec<D> p1 = engine.momentum();
  for (int a = 1; a < D; ++a) EXPECT_NEAR(p1[a], p0[a], 1e-10 * std::sqrt(2.0 * e0));
  if (granular) {
    EXPECT_GT(c.dissipated_in_collisions, 0.0);
  }
}

TEST(LeesEdwards, EnergyBudgetClosesElastic3D) {
  check_budget<3>(false);
}
TEST(LeesEdwards, EnergyBudgetClosesRough2D) {
  check_budget<2>(true);
}

template <int D>
void check_resume() {
  const Environment<D> env = shear<D>(1.1, true);
  Engine<D> a(sheared_gas<D>(D == 3 ? 5 : 10, 0.3, 21, 1.1), StartMode::kPredict, EngineOptions{},
              env);
  for (int k = 0; k < 7000; ++k) ASSERT_NE(a.step(), EventKind::kNone);
  Engine<D> b(a.export_state(), StartMode::kResume, EngineOptions{}, env);
  for (int k = 0; k < 7000; ++k) {
    const EventKind ka = a.step();
    ASSERT_EQ(ka, b.step()) << "event " << k;
    ASSERT_EQ(a.time(), b.time()) << "event " << k;
  }
  const ParticleSystem<D> x = a.export_state(), y = b.export_state();
  for (std::size_t i = 0; i < x.size(); ++i) {
    ASSERT_EQ(x.kinematics[i].pos, y.kinematics[i].pos);
    ASSERT_EQ(x.kinematics[i].vel, y.kinematics[i].vel);
  }
  EXPECT_EQ(a.counters().work_by_shear, b.counters().work_by_shear);
}

TEST(LeesEdwards, ResumesBitForBit3D) {
  check_resume<3>();
}
TEST(LeesEdwards, ResumesBitForBit2D) {
  check_resume<2>();
}

// Stepped potentials under shear: a well with a shoulder inside it for every pair (two species
// in the fixtures), bonds (tethers) between lattice neighbours, which cross the sliding faces.
template <int D>
Environment<D> sheared_steps(double rate) {
  Environment<D> env;
  env.shear_rate = rate;
  env.species = 2;
  StepTable steps;
  steps.boundary = {1.5, 1.25, 1.1, 1.0};
  steps.energy = {-0.6, -1.0, 0.4};
  StepTable tether;  // free between the core and 1.45
  tether.boundary = {1.45, 1.0};
  tether.energy = {0.0};
  tether.beyond = std::numeric_limits<double>::infinity();
  env.tables = {steps, tether};
  env.pair_table = {0, 0, 0, 0};
  env.bond_table = {1};
  return env;
}

template <int D>
ParticleSystem<D> sheared_steps_gas(int n, double eta, std::uint64_t seed, double rate) {
  ParticleSystem<D> s = sheared_gas<D>(n, eta, seed, rate);
  // Neighbours along y in the lattice (spacing below 1.45 at these densities) are bonded: the
  // last row's bond to the first goes through the sliding face.
  const auto count = static_cast<std::uint32_t>(s.size());
  const auto row = static_cast<std::uint32_t>(n);  // lattice index: x + n y + n^2 z
  for (std::uint32_t i = 0; i < count; i += 7) {
    const std::uint32_t y = (i / row) % row;
    const std::uint32_t j = i - y * row + ((y + 1) % row) * row;
    s.bonds.push_back({std::min(i, j), std::max(i, j), 0});
  }
  s.bond_types = {"tether"};
  return s;
}

template <int D>
void check_steps_invariants(int n, double eta, double rate, int events) {
  const Environment<D> env = sheared_steps<D>(rate);
  ParticleSystem<D> s = sheared_steps_gas<D>(n, eta, 5, rate);
  Engine<D> engine(s, StartMode::kPredict, EngineOptions{}, env);
  const double e0 = engine.kinetic_energy() + engine.potential_energy();
  int shifts = 0;
  for (int k = 0; k < events; ++k) {
    const EventKind kind = engine.step();
    ASSERT_NE(kind, EventKind::kNone);
    shifts += kind == EventKind::kImageShift ? 1 : 0;
    ASSERT_NO_THROW(engine.validate()) << "event " << k;
  }
  const EventCounters& c = engine.counters();
  // The images slid by at least the box's length along the flow.
  EXPECT_GE(shifts, engine.grid().cells_along(0));
  EXPECT_GT(c.step_crossings, static_cast<std::uint64_t>(events / 10));
  // The box-frame budget: kinetic plus potential energy grows by the work of the shear.
  const double e1 = engine.kinetic_energy() + engine.potential_energy();
  EXPECT_NEAR(e1 - e0, c.work_by_shear, 1e-11 * (std::abs(e0) + std::abs(c.work_by_shear)));
  EXPECT_GT(std::abs(c.work_by_shear), 1e-3 * std::abs(e0));
}

TEST(LeesEdwards, SteppedPotentialsNoMissedStepNoOverlap3D) {
  check_steps_invariants<3>(5, 0.3, 3.0, 3000);
}

TEST(LeesEdwards, SteppedPotentialsNoMissedStepNoOverlap2D) {
  check_steps_invariants<2>(10, 0.4, 3.0, 5000);
}

TEST(LeesEdwards, SteppedPotentialsResumeBitForBit) {
  const Environment<3> env = sheared_steps<3>(1.2);
  Engine<3> a(sheared_steps_gas<3>(5, 0.3, 8, 1.2), StartMode::kPredict, EngineOptions{}, env);
  for (int k = 0; k < 5000; ++k) ASSERT_NE(a.step(), EventKind::kNone);
  Engine<3> b(a.export_state(), StartMode::kResume, EngineOptions{}, env);
  testing::expect_same_continuation(a, b, 5000);
  EXPECT_EQ(a.counters().work_by_shear, b.counters().work_by_shear);
  EXPECT_EQ(a.potential_energy(), b.potential_energy());
}

TEST(LeesEdwards, RejectsWallsAcrossTheFlowAndGravity) {
  Environment<3> env = shear<3>(1.0, false);
  env.faces[2].kind = FaceKind::kWall;
  env.faces[3].kind = FaceKind::kWall;
  EXPECT_THROW(env.check(), InputError);
  Environment<3> g = shear<3>(1.0, false);
  g.gravity = {0.0, 0.0, -1.0};
  EXPECT_THROW(g.check(), InputError);
  Environment<3> z = shear<3>(1.0, false);  // walls along the vorticity axis are fine
  z.faces[4].kind = FaceKind::kWall;
  z.faces[5].kind = FaceKind::kWall;
  EXPECT_NO_THROW(z.check());
}

}  // namespace
}  // namespace kairos
