// The spring-dashpot by steps (docs/physics.md#spring-dashpot-by-steps) in the engine: a
// repulsive linear spring in N equal steps with the dashpot's work taken at every crossing.
// Head-on restitution against the closed forms of docs/physics.md#dashpot-head-on (force-zero end
// with the cap, naive end without), converging as 1/N;
// the cap never lets a pair leave faster than it came nor pulls it back; an oblique collision
// against the Müller-Pöschel map; kinetic + potential + dissipated energy constant in a gas,
// checked by brute force after every event.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "../release_suite_only.hpp"
#include "engine/event_engine.hpp"
#include "engine_fixtures.hpp"
#include "interactions/potential_spec.hpp"
#include "interactions/soft_contact.hpp"
#include "scheduler/calendar_queue.hpp"

namespace kairos {
namespace {

using Engine = EventEngine<3, CalendarQueue>;

// A pair of masses 1 and 2 (mu = 2/3), contact (spring) length 1, approaching at closing speed
// v = 1. Stiffness from the elastic penetration v / omega_0 = 0.02; the hard core (the sum of the
// radii) sits 1.5 v / omega_0 inside the contact, as in the 1-D tests of
// docs/physics.md#spring-dashpot-by-steps, deeper than any pair of this file gets (a damped pair
// penetrates less than an elastic one).
constexpr double kMassI = 1.0, kMassJ = 2.0;
constexpr double kMu = kMassI * kMassJ / (kMassI + kMassJ);
constexpr double kLength = 1.0;
constexpr double kPenetration = 0.02;  // v / omega_0 at v = 1
constexpr double kCore = kLength - 1.5 * kPenetration;
const double kStiffness = kMu / (kPenetration * kPenetration);  // k = mu omega_0^2

PotentialSpec spring_dashpot(int steps, double zeta, bool force_zero = true) {
  PotentialSpec p;
  p.kind = "spring_dashpot";
  p.stiffness = kStiffness;
  p.length = kLength;
  p.steps = steps;
  p.damping = 2.0 * zeta * std::sqrt(kStiffness * kMu);  // gamma = 2 zeta sqrt(k mu)
  p.force_zero = force_zero;
  return p;
}

struct Outcome {
  Vec<3> g_before{}, g_after{};  // relative velocity v_i - v_j before and after the contact
  std::uint64_t events = 0;      // step events of the contact (crossings and bounces)
  std::uint64_t bounces = 0;
  std::uint64_t core_hits = 0;  // collisions with the hard core (none expected)
  double dissipated = 0.0;
  double energy_error = 0.0;  // |K + U + dissipated - K0| / K0 at the end
};

// Two particles meeting with closing normal speed v_n and tangential relative speed v_t (along
// y), from just outside the contact; run until they have left it (or `max_events`).
Outcome collide(const StepTable& table, double v_n, double v_t, int max_events = 2000000) {
  ParticleSystem<3> s;
  s.box = {40.0, 40.0, 40.0};
  // j at rest at the centre; i approaches along -x with impact parameter b such that the
  // straight-line contact happens at distance kLength with normal speed v_n.
  const double g = std::hypot(v_n, v_t);
  const double b = kLength * v_t / g;
  const Vec<3> xj{20.0, 20.0, 20.0};
  // Relative velocity along -x of magnitude g; i offset by b along y, 0.01 before contact.
  const double x0 = std::sqrt(kLength * kLength - b * b) + 0.01;
  const Vec<3> vi{-g * kMassJ / (kMassI + kMassJ), 0.0, 0.0};
  const Vec<3> vj{g * kMassI / (kMassI + kMassJ), 0.0, 0.0};
  s.kinematics = {{{xj[0] + x0, xj[1] + b, xj[2]}, vi, 0.0, 0.5 * kCore},
                  {xj, vj, 0.0, 0.5 * kCore}};
  s.mass = {kMassI, kMassJ};
  s.species = {0, 0};
  s.species_names = {"A"};
  Environment<3> env;
  env.species = 1;
  env.tables = {table};
  env.pair_table = {0};
  Engine engine(s, StartMode::kPredict, {}, env);
  Outcome out;
  out.g_before = vi - vj;
  const double k0 = engine.kinetic_energy();
  for (int k = 0; k < max_events; ++k) {
    const EventKind kind = engine.step();
    if (kind == EventKind::kNone) break;
    if (engine.step_captures() > 0 && engine.potential_energy() == 0.0) break;  // left
    // A pair that bounced off the outermost step without entering has left too.
    if (engine.step_captures() == 0 && engine.counters().step_bounces > 0) break;
  }
  const EventCounters& c = engine.counters();
  out.events = c.step_crossings + c.step_bounces;
  out.bounces = c.step_bounces;
  out.core_hits = c.collisions - out.events;
  out.dissipated = c.dissipated_in_collisions;
  out.g_after = engine.velocity(0, engine.time()) - engine.velocity(1, engine.time());
  out.energy_error =
      std::abs(engine.kinetic_energy() + engine.potential_energy() + out.dissipated - k0) / k0;
  return out;
}

double head_on_restitution(const StepTable& table, double v = 1.0) {
  const Outcome o = collide(table, v, 0.0);
  EXPECT_EQ(o.core_hits, 0u);
  EXPECT_LT(o.energy_error, 1e-12);
  return -o.g_after[0] / o.g_before[0];
}

TEST(SpringDashpot, TableIsTheSteppedRepulsiveSpringWithItsDashpot) {
  PotentialSpec p = spring_dashpot(300, 0.1);
  const StepTable t = make_step_table(p, kCore, 3);
  ASSERT_EQ(t.boundary.size(), 301u);
  EXPECT_DOUBLE_EQ(t.cutoff(), kLength);
  EXPECT_DOUBLE_EQ(t.core(), kCore);
  EXPECT_EQ(t.beyond, 0.0);
  EXPECT_DOUBLE_EQ(t.damping, p.damping);
  for (std::size_t k = 0; k < t.energy.size(); ++k) {
    const double mid = 0.5 * (t.boundary[k] + t.boundary[k + 1]);
    EXPECT_NEAR(t.energy[k], 0.5 * kStiffness * (kLength - mid) * (kLength - mid),
                1e-12 * t.energy.back());
    EXPECT_NEAR(t.boundary[k] - t.boundary[k + 1], (kLength - kCore) / 300, 1e-15);
  }
  // restitution instead of damping: gamma from the closed form for the pair's reduced mass.
  p.damping = 0.0;
  p.restitution = 0.8;
  const StepTable r = make_step_table(p, kCore, 3, kMu);
  EXPECT_NEAR(dashpot_head_on(kMu, kStiffness, r.damping).restitution, 0.8, 1e-12);
}

// docs/physics.md#spring-dashpot-by-steps: e(N) -> the force-zero e of
// docs/physics.md#dashpot-head-on as 1/N, from below; 0.744051 at N = 4000 for
// beta/omega_0 = 0.1 (the closed form is 0.744079) with the core 1.5 v/omega_0 deep.
TEST(SpringDashpot, HeadOnRestitutionConvergesAsOneOverNToTheForceZeroClosedForm) {
  const double zeta = 0.1;
  const double exact = dashpot_head_on_reduced(zeta).restitution;
  ASSERT_NEAR(exact, 0.744079, 5e-7);
  std::vector<double> scaled;
  for (const int n : {250, 1000, 4000}) {
    const double e = head_on_restitution(make_step_table(spring_dashpot(n, zeta), kCore, 3));
    EXPECT_LT(e, exact) << n;
    scaled.push_back(n * (exact - e));
    if (n == 4000) {
      EXPECT_NEAR(e, 0.744051, 1.5e-6);
    }
  }
  // N |e - e_SP| roughly constant: first-order convergence.
  for (const double s : scaled) EXPECT_NEAR(s / scaled.back(), 1.0, 0.1) << s;
}

// Without the cap the pair feels the dashpot's pull on the way out: e -> the naive
// exp(-pi beta / omega) (0.729248; the stepped value is 0.729181 at N = 4000).
TEST(SpringDashpot, WithoutTheCapRestitutionConvergesToTheNaiveEnd) {
  const double zeta = 0.1;
  const double naive = dashpot_head_on_naive_reduced(zeta).restitution;
  std::vector<double> scaled;
  for (const int n : {250, 1000, 4000}) {
    const double e = head_on_restitution(make_step_table(spring_dashpot(n, zeta, false), kCore, 3));
    scaled.push_back(n * (naive - e));
    if (n == 4000) {
      EXPECT_NEAR(e, 0.729181, 1.5e-6);
    }
  }
  for (const double s : scaled) EXPECT_NEAR(s / scaled.back(), 1.0, 0.1) << s;
}

// The restitution key gives the same e for any reduced mass, and e does not depend on the
// impact speed once the steps resolve the penetration (a linear spring-dashpot).
TEST(SpringDashpot, RestitutionKeyHoldsAcrossSpeeds) {
  PotentialSpec p = spring_dashpot(2000, 0.0);
  p.damping = 0.0;
  p.restitution = 0.9;
  const StepTable t = make_step_table(p, kCore, 3, kMu);
  for (const double v : {0.5, 1.0}) {
    const double e = head_on_restitution(t, v);
    // Coarser resolution at lower speed: the 1/N error scales with the steps per penetration.
    EXPECT_NEAR(e, 0.9, 0.05 / (2000 * v)) << v;
  }
}

// The cap (force-zero rule): a pair never leaves faster than it came and the steps never pull
// it back (no bounce on the way out: exactly one bounce, at the turning point). Coarse steps and
// slow approaches, where a single step is a large part of the energy. Without the cap, some of
// these approaches are pulled back in.
TEST(SpringDashpot, CapForbidsNetAttraction) {
  const StepTable capped = make_step_table(spring_dashpot(6, 0.3), kCore, 3);
  const StepTable naive = make_step_table(spring_dashpot(6, 0.3, false), kCore, 3);
  int pulled_back = 0;
  for (int k = 1; k <= 40; ++k) {
    const double v = 0.02 * k;  // up to 0.8 of the speed the core is tuned for
    const Outcome o = collide(capped, v, 0.0);
    EXPECT_EQ(o.core_hits, 0u);
    EXPECT_LE(o.g_after[0], v * (1.0 + 1e-14)) << v;  // g_before = (-v, 0, 0)
    EXPECT_GT(o.g_after[0], 0.0) << v;
    EXPECT_EQ(o.bounces, 1u) << v;
    EXPECT_LT(o.energy_error, 1e-12);
    const Outcome n = collide(naive, v, 0.0, 20000);
    EXPECT_LE(std::sqrt(norm2(n.g_after)), v * (1.0 + 1e-14)) << v;
    pulled_back += n.bounces > 1 ? 1 : 0;
  }
  EXPECT_GT(pulled_back, 0);
}

// An oblique collision (v_t / v_n = 1) against the Müller-Pöschel map of the continuous
// spring-dashpot (exact): the normal restitution of the outgoing relative velocity and its
// direction agree to O(1/N).
TEST(SpringDashpot, ObliqueCollisionAgreesWithTheMap) {
  const double zeta = 0.1, v_n = 1.0, v_t = 1.0;
  const SoftContactLaw law =
      SoftContactLaw::linear_dashpot(kStiffness, 2.0 * zeta * std::sqrt(kStiffness * kMu));
  const Outcome o = collide(make_step_table(spring_dashpot(4000, zeta), kCore, 3), v_n, v_t);
  EXPECT_EQ(o.core_hits, 0u);
  EXPECT_LT(o.energy_error, 1e-12);
  // The map from first contact, same geometry.
  const double g = std::hypot(v_n, v_t);
  const double b = kLength * v_t / g;
  PairState at;
  at.r_j = {0.0, 0.0, 0.0};
  at.r_i = {std::sqrt(kLength * kLength - b * b), b, 0.0};
  at.v_i = {-g * kMassJ / (kMassI + kMassJ), 0.0, 0.0};
  at.v_j = {g * kMassI / (kMassI + kMassJ), 0.0, 0.0};
  const SoftCollision m = soft_collision(law, {kMassI, kMassJ, 0.5, 0.5}, at);
  const Vec<3> g_map = m.state.v_i - m.state.v_j;
  const double angle_map = std::atan2(g_map[1], g_map[0]);
  const double angle_steps = std::atan2(o.g_after[1], o.g_after[0]);
  EXPECT_NEAR(angle_steps, angle_map, 1e-3);
  EXPECT_NEAR(std::sqrt(norm2(o.g_after)) / std::sqrt(norm2(g_map)), 1.0, 1e-4);
  // The hard-sphere collision with the same head-on e deflects differently (the contact's
  // rotation is what the steps reproduce).
  const double e = dashpot_head_on_reduced(zeta).restitution;
  const Vec<3> n = (1.0 / kLength) * at.r_i;
  const Vec<3> g0 = at.v_i - at.v_j;
  const Vec<3> g_hard = g0 - ((1.0 + e) * dot(g0, n)) * n;
  EXPECT_GT(std::abs(std::atan2(g_hard[1], g_hard[0]) - angle_map), 1e-2);
}

// A small gas of spring-dashpot spheres (core 1, contact 1.1): every event validated (zones,
// predictions, no overlap of the cores), kinetic + potential + dissipated energy constant to
// round-off while the gas cools, momentum conserved, the core never reached.
TEST(SpringDashpot, GasValidatedEveryEventAndEnergyBudgetCloses) {
  const ParticleSystem<3> s = testing::lattice_system<3>(4, 0.12, 21);
  PotentialSpec p;
  p.kind = "spring_dashpot";
  p.stiffness = 2.0e4;
  p.length = 1.1;
  p.steps = 20;
  p.restitution = 0.8;
  Environment<3> env;
  env.species = 2;
  env.tables = {make_step_table(p, 1.0, 3, 0.5)};
  env.pair_table = {0, 0, 0, 0};
  ASSERT_TRUE(env.dissipative_steps());
  Engine engine(s, StartMode::kPredict, {}, env);
  engine.validate();
  const double e0 = engine.kinetic_energy() + engine.potential_energy();
  const Vec<3> p0 = engine.momentum();
  double worst = 0.0;
  for (int k = 0; k < 20000; ++k) {
    ASSERT_NE(engine.step(), EventKind::kNone);
    if (k % testing::validation_stride(1) == 0) engine.validate();
    const double budget = engine.kinetic_energy() + engine.potential_energy() +
                          engine.counters().dissipated_in_collisions;
    worst = std::max(worst, std::abs(budget - e0));
  }
  const EventCounters& c = engine.counters();
  EXPECT_LT(worst, 1e-12 * e0);
  EXPECT_GT(c.dissipated_in_collisions, 0.05 * e0);  // it cooled
  EXPECT_GT(engine.step_captures(), 100u);
  EXPECT_EQ(c.collisions, c.step_crossings + c.step_bounces);  // no hard-core collision
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(engine.momentum()[a], p0[a], 1e-12);
}

}  // namespace
}  // namespace kairos
