// Soft spheres in the event-driven engine (docs/physics.md#event-driven-soft-contacts,
// Müller–Pöschel): an isolated oblique collision of unequal spheres ends where Newton's equations
// put it (direct integration, and the DEM integrator at a tiny time step); gases under both laws
// keep every invariant (brute-force validation after every event, the energy budget kinetic +
// contact + dissipated, momentum); both exceptions happen where constructed and are counted; a
// wall contact reproduces the closed-form dashpot; the instantaneous mode is the hard-sphere model
// with e(v_n); resumes with contacts in progress are bit-identical.
#include <gtest/gtest.h>
#include <cstdio>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "dem/dem_integrator.hpp"
#include "engine/event_engine.hpp"
#include "engine_fixtures.hpp"
#include "interactions/soft_contact.hpp"
#include "interactions/soft_map_table.hpp"
#include "io/gsd_snapshot.hpp"
#include "scheduler/binary_heap_queue.hpp"
#include "scheduler/calendar_queue.hpp"
#include "soft_wall_checks.hpp"

namespace kairos {
namespace {

using Engine3 = EventEngine<3, CalendarQueue>;

template <int D>
Environment<D> soft_environment(const SoftContactLaw& law, std::uint32_t species = 2) {
  Environment<D> env;
  env.species = species;
  env.soft.assign(static_cast<std::size_t>(species) * species, law);
  env.soft_wall.assign(species, law);
  return env;
}

// Two spheres (radii 0.5 and 0.7, masses 1 and 2.3) that first touch at t0 =
// 0.2, obliquely (v_t / v_n about 0.6), in a periodic box far larger than they are.
ParticleSystem<3> oblique_pair() {
  ParticleSystem<3> s;
  s.box = {12.0, 12.0, 12.0};
  const Vec<3> vi{1.0, 0.3, -0.1}, vj{-0.6, 0.1, 0.25};
  Vec<3> n{-1.0, -0.45, 0.2};  // from j to i at contact; g.n < 0
  n = (1.0 / std::sqrt(norm2(n))) * n;
  const double t0 = 0.2, l = 1.2;
  const Vec<3> ci{6.0, 6.0, 6.0};
  const Vec<3> cj = ci - l * n;
  s.kinematics = {{ci - t0 * vi, vi, 0.0, 0.5}, {cj - t0 * vj, vj, 0.0, 0.7}};
  s.mass = {1.0, 2.3};
  s.species = {0, 1};
  s.species_names = {"A", "B"};
  return s;
}

// The state at the end of the first soft contact: after its release event, or, for a deferred
// release (no event), built from the exported contact's release positions and velocities.
ParticleSystem<3> through_first_release(Engine3& engine) {
  for (int k = 0; k < 100000; ++k) {
    const EventKind kind = engine.step();
    if (kind == EventKind::kSoftRelease) return engine.export_state();
    if (kind == EventKind::kCollision && engine.counters().soft_contacts > 0) {
      ParticleSystem<3> s = engine.export_state();
      if (s.frozen.size() == 1 && s.frozen[0].deferred) {
        const FrozenContact<3> c = s.frozen[0];
        s.time = c.release_time;
        s.kinematics[c.i] = {c.release_position_i, c.velocity_i, c.release_time,
                             s.kinematics[c.i].radius};
        s.kinematics[c.j] = {c.release_position_j, c.velocity_j, c.release_time,
                             s.kinematics[c.j].radius};
        s.frozen.clear();
        return s;
      }
    }
    if (kind == EventKind::kNone) break;
  }
  ADD_FAILURE() << "no release";
  return engine.export_state();
}

class SoftBinary : public ::testing::TestWithParam<SoftModel> {
 protected:
  SoftContactLaw law() const {
    // Contact times of a few 0.01 at these speeds: l~ ~ 100 (dashpot) / ~ 50 (Hertz).
    return GetParam() == SoftModel::LinearDashpot ? SoftContactLaw::linear_dashpot(4.0e4, 30.0)
                                                  : SoftContactLaw::viscoelastic_hertz(2.0e5, 2e-3);
  }
};

TEST_P(SoftBinary, ObliqueUnequalPairEndsWhereNewtonPutsIt) {
  const ParticleSystem<3> start = oblique_pair();
  Engine3 engine(start, StartMode::kPredict, {}, soft_environment<3>(law()));
  const ParticleSystem<3> after = through_first_release(engine);
  EXPECT_EQ(after.counters.soft_contacts, 1u);
  EXPECT_EQ(after.counters.collisions, 1u);

  // Direct 3D integration of Newton's equations from first contact (t0 = 0.2).
  const double t0 = 0.2, t_end = 0.45;
  PairState at_contact;
  for (int k = 0; k < 2; ++k) {
    (k == 0 ? at_contact.r_i : at_contact.r_j) = start.position(k, t0);
    (k == 0 ? at_contact.v_i : at_contact.v_j) = start.kinematics[k].vel;
  }
  const SoftPair pair{1.0, 2.3, 0.5, 0.7};
  const DirectContact direct = integrate_contact_directly(law(), pair, at_contact);
  EXPECT_NEAR(after.time, t0 + direct.contact_time, 1e-9 * direct.contact_time);
  const double tc = direct.contact_time;
  ASSERT_LT(t0 + tc, t_end);
  const double free_time = t_end - t0 - tc;
  const Vec<3> xi = direct.state.r_i + free_time * direct.state.v_i;
  const Vec<3> xj = direct.state.r_j + free_time * direct.state.v_j;
  const double g0 = std::sqrt(norm2(start.kinematics[0].vel - start.kinematics[1].vel));
  auto image = [&](Vec<3> d) {
    for (int a = 0; a < 3; ++a) d[a] = std::remainder(d[a], start.box[a]);
    return d;
  };
  // The map is good to its integration tolerance: 1e-10 of the size and of the speed.
  EXPECT_LT(std::sqrt(norm2(image(after.position(0, t_end) - xi))), 1e-10);
  EXPECT_LT(std::sqrt(norm2(image(after.position(1, t_end) - xj))), 1e-10);
  EXPECT_LT(std::sqrt(norm2(after.kinematics[0].vel - direct.state.v_i)), 1e-10 * g0);
  EXPECT_LT(std::sqrt(norm2(after.kinematics[1].vel - direct.state.v_j)), 1e-10 * g0);

  // The DEM integrator at t_c / 50000 (the dashpot force jumps at first contact, which costs
  // DEM an error of first order in dt) from the same initial state to the same time.
  DemOptions options;
  const long steps = static_cast<long>(std::ceil(t_end / (tc / 50000.0)));
  options.dt = t_end / static_cast<double>(steps);
  DemIntegrator<3> dem(start, std::vector<SoftContactLaw>(4, law()), 2, options);
  dem.step(steps);
  ASSERT_NEAR(dem.time(), t_end, 1e-12);
  const double l = 1.2;
  for (int k = 0; k < 2; ++k) {
    const double dx = std::sqrt(norm2(image(dem.position(k) - after.position(k, t_end))));
    const double dv = std::sqrt(norm2(dem.velocity(k) - after.kinematics[k].vel));
    EXPECT_LT(dx / l, 1e-6) << "particle " << k;
    EXPECT_LT(dv / g0, 1e-6) << "particle " << k;
  }
}

// The same collision through a lookup table (tolerance 1e-6): no direct integration, and the state
// after the contact within the table's tolerance of the directly mapped one.
TEST_P(SoftBinary, LookupTableGivesTheMappedStateToItsTolerance) {
  const ParticleSystem<3> start = oblique_pair();
  Engine3 direct(start, StartMode::kPredict, {}, soft_environment<3>(law()));
  const ParticleSystem<3> exact = through_first_release(direct);
  SoftTableSpec spec;
  spec.law = law();
  spec.reduced_mass = reduced_mass(1.0, 2.3);
  spec.contact_distance = 1.2;
  spec.min_normal_speed = 1.0;
  spec.max_normal_speed = 2.5;
  spec.max_tangential_ratio = 3.0;
  SoftTableBuildOptions options;
  options.check_points = 200;
  Environment<3> env = soft_environment<3>(law());
  env.soft_tables.assign(4,
                         std::make_shared<const SoftMapTable>(SoftMapTable::build(spec, options)));
  Engine3 tabulated(start, StartMode::kPredict, {}, env);
  const ParticleSystem<3> after = through_first_release(tabulated);
  EXPECT_EQ(after.counters.soft_direct_maps, 0u);
  EXPECT_EQ(exact.counters.soft_direct_maps, 1u);
  EXPECT_NEAR(after.time, exact.time, 1e-6 * (exact.time - 0.2));
  const double g0 = std::sqrt(norm2(start.kinematics[0].vel - start.kinematics[1].vel));
  for (int k = 0; k < 2; ++k) {
    // Positions move by at most the end overlap and the rotation: 1e-6 of those, far below.
    EXPECT_LT(std::sqrt(norm2(after.position(k, 0.45) - exact.position(k, 0.45))), 1e-7);
    EXPECT_LT(std::sqrt(norm2(after.kinematics[k].vel - exact.kinematics[k].vel)), 1e-6 * g0);
  }
}

TEST_P(SoftBinary, InstantaneousModeIsTheHardSphereWithTheHeadOnRestitution) {
  const ParticleSystem<3> start = oblique_pair();
  Environment<3> env = soft_environment<3>(law());
  env.soft_collisions = SoftCollisions::kInstantaneous;
  Engine3 engine(start, StartMode::kPredict, {}, env);
  while (engine.counters().collisions == 0) ASSERT_NE(engine.step(), EventKind::kNone);
  const ParticleSystem<3> after = engine.export_state();
  EXPECT_EQ(after.counters.soft_contacts, 0u);
  EXPECT_DOUBLE_EQ(after.time, 0.2);
  // Normal relative velocity reversed and scaled by the head-on map's e, tangential kept.
  const Vec<3> r = after.position(0, 0.2) - after.position(1, 0.2);
  const Vec<3> n = (1.0 / std::sqrt(norm2(r))) * r;
  const Vec<3> g0 = start.kinematics[0].vel - start.kinematics[1].vel;
  const Vec<3> g1 = after.kinematics[0].vel - after.kinematics[1].vel;
  const double mu = reduced_mass(1.0, 2.3);
  const CollisionUnits units = reduce_collision(law(), mu, 1.2, -dot(g0, n), 0.0);
  const double e = -collision_map(units.reduced).eps_rdot;
  EXPECT_NEAR(dot(g1, n), -e * dot(g0, n), 1e-12);
  EXPECT_LT(std::sqrt(norm2((g1 - dot(g1, n) * n) - (g0 - dot(g0, n) * n))), 1e-12);
  if (GetParam() == SoftModel::LinearDashpot) {
    EXPECT_NEAR(e, dashpot_head_on(mu, law().stiffness, law().damping).restitution, 1e-10);
  }
}

INSTANTIATE_TEST_SUITE_P(BothLaws, SoftBinary,
                         ::testing::Values(SoftModel::LinearDashpot, SoftModel::ViscoelasticHertz),
                         [](const auto& p) {
                           return p.param == SoftModel::LinearDashpot ? "Dashpot" : "Hertz";
                         });

// Kinetic energy + what the frozen contacts hold + what was dissipated: constant.
template <int D>
double energy_budget(const EventEngine<D, CalendarQueue>& e) {
  return e.kinetic_energy() + e.potential_energy() + e.counters().dissipated_in_collisions +
         e.counters().dissipated_at_walls;
}

// Every event validated (the prediction invariant by brute force, piecewise for pairs inside
// deferred contacts), the energy budget and momentum after each. With deferred releases most
// contacts have no release event; the rest (a third body or a wall met during the contact, a
// cell left) are frozen as without them.
template <int D>
void run_validated_gas(ParticleSystem<D> s, const Environment<D>& env, int events,
                       bool deferred = true) {
  EngineOptions options;
  options.defer_soft_releases = deferred;
  EventEngine<D, CalendarQueue> engine(s, StartMode::kPredict, options, env);
  const double budget = energy_budget(engine);
  const Vec<D> p0 = engine.momentum();
  bool walls = env.has_walls();
  std::uint32_t most_frozen = 0;
  std::uint64_t release_events = 0;
  for (int k = 0; k < events; ++k) {
    const EventKind kind = engine.step();
    ASSERT_NE(kind, EventKind::kNone);
    release_events += kind == EventKind::kSoftRelease ? 1u : 0u;
    ASSERT_NO_THROW(engine.validate()) << "after event " << k;
    most_frozen = std::max(most_frozen, engine.frozen());
    ASSERT_NEAR(energy_budget(engine), budget, 1e-11 * budget) << "after event " << k;
    if (!walls) {
      const Vec<D> p = engine.momentum();
      for (int a = 0; a < D; ++a) ASSERT_NEAR(p[a], p0[a], 1e-11 * std::sqrt(budget));
    }
  }
  const EventCounters& c = engine.counters();
  EXPECT_GT(c.soft_contacts, 50u);
  EXPECT_GE(most_frozen, 2u);
  EXPECT_GT(c.dissipated_in_collisions, 0.0);
  if (deferred) {
    EXPECT_LT(release_events, c.soft_contacts / 2);
  } else {
    EXPECT_GE(release_events + c.soft_early_releases + 2, c.soft_contacts);
  }
  if (walls) {
    EXPECT_GT(c.wall_collisions, 0u);
  }
}

TEST(SoftGas, DashpotGasIn3DKeepsEveryInvariant) {
  run_validated_gas(testing::lattice_system<3>(5, 0.15, 3, 1.7, 1.3),
                    soft_environment<3>(SoftContactLaw::linear_dashpot(2.0e3, 8.0)), 3000);
}

TEST(SoftGas, DashpotGasIn3DWithEveryReleaseAnEventKeepsEveryInvariant) {
  run_validated_gas(testing::lattice_system<3>(5, 0.15, 3, 1.7, 1.3),
                    soft_environment<3>(SoftContactLaw::linear_dashpot(2.0e3, 8.0)), 3000,
                    /*deferred=*/false);
}

// Deferred or frozen until a release event, a contact ends in the same place with the same
// velocities; only round-off differs (predictions are made from other times), which the
// gas's chaos amplifies slowly over a few collisions per particle.
TEST(SoftGas, DeferredReleasesFollowTheFrozenContactsTrajectories) {
  const ParticleSystem<3> s = testing::lattice_system<3>(5, 0.2, 11, 1.5, 1.2);
  const Environment<3> env = soft_environment<3>(SoftContactLaw::linear_dashpot(3.0e3, 6.0));
  EngineOptions frozen_options;
  frozen_options.defer_soft_releases = false;
  Engine3 deferred(s, StartMode::kPredict, {}, env),
      frozen(s, StartMode::kPredict, frozen_options, env);
  const double t_end = 1.0;
  std::uint64_t releases = 0;
  while (deferred.next_event_time() < t_end) ASSERT_NE(deferred.step(), EventKind::kNone);
  while (frozen.next_event_time() < t_end) {
    releases += frozen.step() == EventKind::kSoftRelease ? 1u : 0u;
  }
  const std::uint64_t contacts = frozen.counters().soft_contacts;
  ASSERT_GT(contacts, 100u);
  EXPECT_EQ(deferred.counters().soft_contacts, contacts);
  EXPECT_GT(releases, contacts / 2);
  EXPECT_LT(deferred.counters().events, frozen.counters().events - contacts / 2);
  const ParticleSystem<3> a = deferred.export_state(), b = frozen.export_state();
  double worst = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    worst = std::max(worst, std::sqrt(norm2(a.position(i, t_end) - b.position(i, t_end))));
    worst =
        std::max(worst, std::sqrt(norm2(deferred.velocity(static_cast<std::uint32_t>(i), t_end) -
                                        frozen.velocity(static_cast<std::uint32_t>(i), t_end))));
  }
  std::printf(
      "deferred vs frozen releases: %llu contacts, %llu release events (frozen), events "
      "%llu vs %llu, largest position or velocity difference %.2e\n",
      static_cast<unsigned long long>(contacts), static_cast<unsigned long long>(releases),
      static_cast<unsigned long long>(deferred.counters().events),
      static_cast<unsigned long long>(frozen.counters().events), worst);
  EXPECT_LT(worst, 1e-10);
  EXPECT_NEAR(deferred.potential_energy(), frozen.potential_energy(), 1e-10);
  EXPECT_NEAR(deferred.counters().dissipated_in_collisions,
              frozen.counters().dissipated_in_collisions, 1e-10);
}

TEST(SoftGas, HertzGasIn2DKeepsEveryInvariant) {
  run_validated_gas(testing::lattice_system<2>(10, 0.2, 4, 0.6, 0.8),
                    soft_environment<2>(SoftContactLaw::viscoelastic_hertz(5.0e3, 5e-3)), 3000);
}

TEST(SoftGas, DashpotGasBetweenWallsKeepsEveryInvariant) {
  ParticleSystem<3> s = testing::lattice_system<3>(5, 0.15, 5);
  for (auto& k : s.kinematics) k.pos[2] += 0.3;  // clear of the walls at z = 0 and z = L
  Environment<3> env = soft_environment<3>(SoftContactLaw::linear_dashpot(2.0e3, 8.0));
  env.faces[4].kind = env.faces[5].kind = FaceKind::kWall;
  run_validated_gas(s, env, 3000);
}

TEST(SoftGas, ElasticDashpotConservesKineticEnergyOutsideContacts) {
  ParticleSystem<3> s = testing::lattice_system<3>(5, 0.15, 6);
  Engine3 engine(s, StartMode::kPredict, {},
                 soft_environment<3>(SoftContactLaw::linear_dashpot(2.0e3, 0.0)));
  const double ke0 = engine.kinetic_energy();
  for (int k = 0; k < 2000; ++k) ASSERT_NE(engine.step(), EventKind::kNone);
  EXPECT_NEAR(engine.counters().dissipated_in_collisions, 0.0, 1e-12 * ke0);
  EXPECT_NEAR(engine.kinetic_energy() + engine.potential_energy(), ke0, 1e-12 * ke0);
}

// 41 equal spheres placed at random in a periodic box whose x axis is 3 to 4 diameters long (so
// 3 cells wide), the other two sized for packing fraction eta: the construction of the soft-sphere
// fuzz that found the incremental crossings' failure on such axes (seed 18).
ParticleSystem<3> thin_soft_box(std::uint64_t seed, int n, double eta) {
  std::mt19937_64 rng(seed * 104729 + 17);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < n; ++i) u(rng);  // the generator's species draws (one species here)
  double volume = 0.0;  // summed as the generator did: the box's last bits decide the run
  for (int i = 0; i < n; ++i) volume += M_PI / 6.0;
  ParticleSystem<3> s;
  s.box[0] = 3.0 + 0.95 * u(rng);
  s.box[1] = s.box[2] = std::max(3.0, std::pow(volume / eta / s.box[0], 0.5));
  while (static_cast<int>(s.kinematics.size()) < n) {
    Kinematics<3> k{};
    k.radius = 0.5;
    for (bool placed = false; !placed;) {
      for (int a = 0; a < 3; ++a) k.pos[a] = u(rng) * s.box[a];
      placed = true;
      for (const auto& o : s.kinematics) {
        Vec<3> d = k.pos - o.pos;
        for (int a = 0; a < 3; ++a) d[a] -= s.box[a] * std::round(d[a] / s.box[a]);
        if (norm2(d) < 1.0001) placed = false;
      }
    }
    std::normal_distribution<double> normal(0.0, 1.0);  // a fresh one per particle, as there
    for (int a = 0; a < 3; ++a) k.vel[a] = normal(rng);
    s.kinematics.push_back(k);
    s.mass.push_back(1.0);
    s.species.push_back(0);
  }
  s.species_names = {"A", "B"};
  return s;
}

// Incremental crossings in a box with a periodic axis 3 cells wide: a kept partner crossing that
// axis flips its image (seen from the other particle) without a new collision count, so its kept
// contact cannot be recomputed. This soft gas, kicked at random every 205 events, lost a
// collision after 2173 events when only kept partners in the new layer were refused (fuzz
// seed 18, before the rule that such boxes keep no contact at all; checked against that code).
// The failure needs this exact trajectory, which every build gives (no FMA contraction).
TEST(SoftGas, IncrementalCrossingsValidatedInABoxThreeCellsWide) {
  const ParticleSystem<3> s = thin_soft_box(18, 41, 0x1.2afa246c3620bp-3);
  Environment<3> env = soft_environment<3>(
      SoftContactLaw::viscoelastic_hertz(0x1.9b89e7f45b7b8p+13, 0x1.79a5ae11b0772p-8));
  EngineOptions options;
  options.max_cells_per_particle = 1000.0;
  options.renumber_interval = 0.0;
  options.vector_scan = false;
  EventEngine<3, BinaryHeapQueue> engine(s, StartMode::kPredict, options, env);
  ASSERT_EQ(engine.grid().cells_along(0), 3);
  std::mt19937_64 rng(18 + 99);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int k = 0; k < 3000; ++k) {
    ASSERT_NE(engine.step(), EventKind::kNone);
    if (k % 205 == 204) {
      const auto p = static_cast<std::uint32_t>(rng() % engine.size());
      Vec<3> v;
      for (int a = 0; a < 3; ++a) v[a] = normal(rng);
      engine.set_velocity(p, engine.time() + 0.5 * (engine.next_event_time() - engine.time()), v);
    }
    ASSERT_NO_THROW(engine.validate()) << "after event " << k;
  }
  EXPECT_GT(engine.counters().soft_contacts, 500u);
  EXPECT_GT(engine.incremental_crossing_scans(), 0u);  // crossings that kept nothing
}

// Exception B: a third sphere k meets i while i and j are frozen in their contact; the pair is
// released at once and k's collision follows.
TEST(SoftExceptions, ThirdBodyDuringTheContactReleasesThePairEarly) {
  const SoftContactLaw law = SoftContactLaw::linear_dashpot(400.0, 4.0);  // t_c ~ 0.1
  ParticleSystem<3> s;
  s.box = {10.0, 10.0, 10.0};
  // i at rest at the origin (shifted into the box), j coming along -x: contact at t0 = 0.5.
  const Vec<3> c{5.0, 5.0, 5.0};
  const double t0 = 0.5;
  s.kinematics = {{c, {0.0, 0.0, 0.0}, 0.0, 0.5},
                  {c + Vec<3>{1.0 + t0, 0.0, 0.0}, {-1.0, 0, 0}, 0.0, 0.5}};
  s.mass = {1.0, 1.0};
  // Where i sits frozen: pushed towards j by half the end overlap, then moving with V.
  const CollisionUnits units = reduce_collision(law, 0.5, 1.0, 1.0, 0.0);
  const CollisionMap map = collision_map(units.reduced);
  const double tc = map.eps_t * units.time_unit;
  const double th = t0 + 0.5 * tc;
  const double xi = c[0] + 0.5 * map.end_overlap * units.length_unit - 0.5 * (th - t0);
  // k comes up along +y, touching i at th.
  const double u = 2.0;
  s.kinematics.push_back({{xi, c[1] - 1.0 - u * th, c[2]}, {0.0, u, 0.0}, 0.0, 0.5});
  s.mass.push_back(1.0);
  s.species = {0, 0, 0};
  s.species_names = {"A"};
  Engine3 engine(s, StartMode::kPredict, {}, soft_environment<3>(law, 1));
  const Vec<3> p0 = engine.momentum();
  while (engine.next_event_time() < th + 0.5 * tc) {
    ASSERT_NE(engine.step(), EventKind::kNone);
    ASSERT_NO_THROW(engine.validate());
  }
  EXPECT_EQ(engine.counters().soft_early_releases, 1u);
  EXPECT_EQ(engine.counters().collisions, 2u);
  const Vec<3> p = engine.momentum();
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(p[a], p0[a], 1e-12);
}

// Exception B where only the frozen path shows it: j (fast) hits i at rest, and k meets the
// frozen pair during the contact where neither the motion before the contact nor the one after
// it (extended backwards) would have met k, and k's own pending event comes later. Deferring
// this release would miss the meeting (found by a search over random third bodies: without the
// frozen-path test in try_place, validate() fails here).
TEST(SoftExceptions, ThirdBodyMeetingOnlyTheFrozenPairKeepsItFrozen) {
  const SoftContactLaw law = SoftContactLaw::linear_dashpot(400.0, 4.0);
  ParticleSystem<3> s;
  s.box = {10.0, 10.0, 10.0};
  const Vec<3> c{5.0, 5.0, 5.0};
  const double w = 26.173376944242733, t0 = 2.0 / w;
  s.kinematics = {{c, {0.0, 0.0, 0.0}, 0.0, 0.5},
                  {c + Vec<3>{1.0 + w * t0, 0.0, 0.0}, {-w, 0.0, 0.0}, 0.0, 0.5},
                  {{5.7243027976099397, 4.9600201278513474, 6.3304674741820604},
                   {-2.7375996905286977, -1.2700140892318039, -2.8692313406576182},
                   0.0,
                   0.5}};
  s.mass = {1.0, 1.0, 1.0};
  s.species = {0, 0, 0};
  s.species_names = {"A"};
  Engine3 engine(s, StartMode::kPredict, {}, soft_environment<3>(law, 1));
  while (engine.next_event_time() < 0.3) {
    ASSERT_NE(engine.step(), EventKind::kNone);
    ASSERT_NO_THROW(engine.validate());
  }
  EXPECT_GE(engine.counters().soft_contacts, 1u);
  EXPECT_EQ(engine.counters().soft_early_releases, 1u);
}

// Exception A: i's place at the end of its contact with j overlaps a resting third sphere k, which
// it does not touch at first contact; the contact is then instantaneous.
TEST(SoftExceptions, PlacementOverlappingAThirdBodyFallsBackToAnInstantaneousCollision) {
  const SoftContactLaw law = SoftContactLaw::linear_dashpot(100.0, 6.0);  // end overlap ~ 0.05
  ParticleSystem<3> s;
  s.box = {10.0, 10.0, 10.0};
  const Vec<3> c{5.0, 5.0, 5.0};
  const double t0 = 0.5;
  s.kinematics = {{c, {0.0, 0.0, 0.0}, 0.0, 0.5},
                  {c + Vec<3>{1.0 + t0, 0.0, 0.0}, {-1.0, 0, 0}, 0.0, 0.5}};
  s.mass = {1.0, 1.0};
  const CollisionUnits units = reduce_collision(law, 0.5, 1.0, 1.0, 0.0);
  const CollisionMap map = collision_map(units.reduced);
  const double shift = 0.5 * map.end_overlap * units.length_unit;  // i moves +x by this
  ASSERT_GT(shift, 0.01);
  // k (radius 0.1) at 60 degrees from +x, a quarter of the shift's approach beyond contact.
  const double d = 0.6 + 0.25 * shift;
  s.kinematics.push_back({c + Vec<3>{0.5 * d, std::sqrt(0.75) * d, 0.0}, {}, 0.0, 0.1});
  s.mass.push_back(0.2);
  s.species = {0, 0, 1};
  s.species_names = {"A", "B"};
  Engine3 engine(s, StartMode::kPredict, {}, soft_environment<3>(law));
  while (engine.counters().collisions == 0) {
    ASSERT_NE(engine.step(), EventKind::kNone);
    ASSERT_NO_THROW(engine.validate());
  }
  EXPECT_EQ(engine.counters().soft_overlap_fallbacks, 1u);
  EXPECT_EQ(engine.counters().soft_contacts, 0u);
  EXPECT_EQ(engine.frozen(), 0u);
  const ParticleSystem<3> after = engine.export_state();
  EXPECT_NEAR(after.kinematics[1].vel[0] - after.kinematics[0].vel[0], -map.eps_rdot, 1e-12);
}

// A sphere meeting a fixed wall obliquely: after the contact its normal velocity is e v_n and it
// sits where the closed-form dashpot puts it; the tangential motion never changes.
TEST(SoftWalls, WallContactMatchesTheClosedFormDashpot) {
  const double k = 900.0, gamma = 9.0, m = 1.5;
  ParticleSystem<3> s;
  s.box = {10.0, 10.0, 10.0};
  const Vec<3> v{0.3, -0.2, -1.3};
  s.kinematics = {{{5.0, 5.0, 0.5 + 1.3 * 0.4}, v, 0.0, 0.5}, {{2.0, 2.0, 8.0}, {}, 0.0, 0.5}};
  s.mass = {m, m};
  s.species = {0, 0};
  s.species_names = {"A"};
  Environment<3> env = soft_environment<3>(SoftContactLaw::linear_dashpot(k, gamma), 1);
  env.faces[4].kind = env.faces[5].kind = FaceKind::kWall;
  Engine3 engine(s, StartMode::kPredict, {}, env);
  EventKind kind;
  while ((kind = engine.step()) != EventKind::kSoftRelease) ASSERT_NE(kind, EventKind::kNone);
  const HeadOn closed = dashpot_head_on(m, k, gamma);
  EXPECT_NEAR(engine.time(), 0.4 + closed.contact_time, 1e-10);
  const ParticleSystem<3> after = engine.export_state();
  EXPECT_NEAR(after.kinematics[0].vel[2], 1.3 * closed.restitution, 1e-10);
  EXPECT_EQ(after.kinematics[0].vel[0], v[0]);
  EXPECT_EQ(after.kinematics[0].vel[1], v[1]);
  const double t = engine.time();
  const Vec<3> x = after.position(0, t);
  EXPECT_NEAR(x[2], 0.5 - dashpot_end_overlap(m, k, gamma, 1.3), 1e-10);
  EXPECT_NEAR(x[0], 5.0 + v[0] * t, 1e-10);
  EXPECT_NEAR(x[1], 5.0 + v[1] * t, 1e-10);
  EXPECT_NEAR(after.counters.dissipated_at_walls,
              0.5 * m * 1.3 * 1.3 * (1.0 - closed.restitution * closed.restitution), 1e-10);
}

// A sphere meeting a piston (the lid, coming down at constant speed): the map holds in the
// wall's frame, so the particle leaves with the wall's velocity plus e v_n of the relative
// approach, where the DEM (same Hertz law, same piston, dt = t_c / 20 000) puts it; the wall's
// work is the impulse times its velocity, and the energy budget closes to round-off.
TEST(SoftWalls, PistonContactIsTheMapInTheWallsFrame) {
  const double m = 1.5, u = -0.4;
  ParticleSystem<3> s;
  s.box = {10.0, 10.0, 10.0};
  const Vec<3> v{0.2, -0.1, 1.3};
  s.kinematics = {{{5.0, 5.0, 8.5}, v, 0.0, 0.5}, {{2.0, 2.0, 3.0}, {}, 0.0, 0.5}};
  s.mass = {m, m};
  s.species = {0, 0};
  s.species_names = {"A"};
  const SoftContactLaw law = SoftContactLaw::viscoelastic_hertz(5e3, 1e-3);
  Environment<3> env = soft_environment<3>(law, 1);
  env.faces[4].kind = env.faces[5].kind = FaceKind::kWall;
  env.faces[5].wall.velocity[2] = u;
  Engine3 engine(s, StartMode::kPredict, {}, env);
  testing::step_to_release_keeping_the_wall_budget(engine);
  const double vn = v[2] - u;  // the approach speed in the wall's frame
  const CollisionUnits units = reduce_collision(law, m, 0.5, vn, 0.0);
  const CollisionMap map = collision_map(units.reduced);
  const ParticleSystem<3> after = engine.export_state();
  EXPECT_NEAR(after.kinematics[0].vel[2], u + map.eps_rdot * vn, 1e-12);
  EXPECT_EQ(after.kinematics[0].vel[0], v[0]);
  EXPECT_NEAR(after.counters.work_by_walls, m * u * (after.kinematics[0].vel[2] - v[2]), 1e-12);
  EXPECT_GT(after.counters.work_by_walls, 0.0);  // the lid coming down hits the sphere back
  testing::expect_the_dem_agrees(s, env, units, map, engine.time(), after);
}

TEST(SoftResume, ResumingFromARestartFileWithContactsInProgressIsBitIdentical) {
  const ParticleSystem<3> s = testing::lattice_system<3>(5, 0.15, 7, 1.4, 1.2);
  const Environment<3> env = soft_environment<3>(SoftContactLaw::viscoelastic_hertz(3.0e3, 4e-3));
  Engine3 a(s, StartMode::kPredict, {}, env);
  auto kinds = [&] {  // contacts in progress: deferred ones and frozen ones
    std::pair<int, int> n{0, 0};
    for (const FrozenContact<3>& c : a.export_state().frozen) ++(c.deferred ? n.first : n.second);
    return n;
  };
  for (int k = 0; k < 800 || kinds().first == 0; ++k) ASSERT_NE(a.step(), EventKind::kNone);
  ASSERT_GT(kinds().first, 0);
  // Through a restart file: the contacts in progress and the soft counters survive it.
  const std::filesystem::path file = std::filesystem::temp_directory_path() /
                                     ("kairos_soft_resume_" + std::to_string(::getpid()) + ".gsd");
  std::mt19937_64 rng(5);
  write_restart(file, a.export_state(), rng);
  const ParticleSystem<3> mid = read_restart<3>(file, rng);
  std::filesystem::remove(file);
  EXPECT_EQ(mid.frozen, a.export_state().frozen);
  EXPECT_EQ(mid.counters.soft_contacts, a.counters().soft_contacts);
  EXPECT_EQ(mid.counters.soft_contact_energy, a.counters().soft_contact_energy);
  // Started afresh (predicting), the deferred contacts continue frozen, holding the same energy.
  const Engine3 fresh(mid, StartMode::kPredict, {}, env);
  EXPECT_NEAR(fresh.potential_energy(), a.potential_energy(), 1e-12 * a.kinetic_energy());
  EXPECT_NEAR(fresh.kinetic_energy(), a.kinetic_energy(), 1e-12 * a.kinetic_energy());
  EXPECT_GT(a.potential_energy(), 0.0);
  Engine3 b(mid, StartMode::kResume, {}, env);
  for (int k = 0; k < 3000; ++k) {
    ASSERT_NE(a.step(), EventKind::kNone);
    ASSERT_NE(b.step(), EventKind::kNone);
  }
  const ParticleSystem<3> ea = a.export_state(), eb = b.export_state();
  EXPECT_EQ(ea.time, eb.time);
  for (std::size_t i = 0; i < ea.size(); ++i) {
    ASSERT_EQ(ea.kinematics[i].pos, eb.kinematics[i].pos) << i;
    ASSERT_EQ(ea.kinematics[i].vel, eb.kinematics[i].vel) << i;
  }
  EXPECT_EQ(ea.frozen, eb.frozen);
  EXPECT_EQ(ea.counters.soft_contacts, eb.counters.soft_contacts);
  EXPECT_EQ(ea.counters.dissipated_in_collisions, eb.counters.dissipated_in_collisions);
}

TEST(SoftErrors, UnsupportedCombinationsAreRefusedByName) {
  const ParticleSystem<3> s = testing::lattice_system<3>(4, 0.1, 1);
  const SoftContactLaw law = SoftContactLaw::linear_dashpot(1e3, 1.0);
  auto refused = [&](const Environment<3>& env, const std::string& word) {
    try {
      Engine3 e(s, StartMode::kPredict, {}, env);
      ADD_FAILURE() << "accepted: " << word;
    } catch (const InputError& err) {
      EXPECT_NE(std::string(err.what()).find(word), std::string::npos) << err.what();
    }
  };
  Environment<3> env = soft_environment<3>(law);
  env.gravity = {0.0, 0.0, -1.0};
  refused(env, "gravity");
  env = soft_environment<3>(law);
  env.shear_rate = 0.1;
  refused(env, "shear");
  env = soft_environment<3>(law);
  env.contact.assign(4, ContactModel{});
  refused(env, "contact");
  env = soft_environment<3>(law);
  env.soft.resize(1);
  refused(env, "soft contact laws");
  env = soft_environment<3>(law);
  env.faces[4].kind = env.faces[5].kind = FaceKind::kWall;
  env.faces[4].wall.amplitude = 0.01;
  env.faces[4].wall.angular_frequency = 3.0;
  refused(env, "vibrating wall");
  // Collisions reduce their units unchecked: a bad law is refused when the engine starts.
  env = soft_environment<3>(law);
  env.soft[1].stiffness = 0.0;
  refused(env, "spring constant");
  env = soft_environment<3>(law);
  env.soft_wall[0].damping = std::nan("");
  refused(env, "dashpot coefficient");
}

}  // namespace
}  // namespace kairos
