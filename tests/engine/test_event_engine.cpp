// Engine correctness: conservation, no overlap, validated scheduler state, queue equivalence.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "../release_suite_only.hpp"
#include "core/error.hpp"
#include "engine/candidate_scan.hpp"
#include "engine/event_engine.hpp"
#include "engine_fixtures.hpp"
#include "init/initial_state.hpp"
#include "interactions/soft_contact.hpp"
#include "interactions/step_potential.hpp"
#include "scheduler/binary_heap_queue.hpp"
#include "scheduler/calendar_queue.hpp"
#include "scheduler/tournament_tree_queue.hpp"

namespace kairos {
namespace {

template <int D, class Q>
void run_validated(const ParticleSystem<D>& start, int events, int expect_cells = 0,
                   EngineOptions options = {}) {
  EventEngine<D, Q> engine(start, StartMode::kPredict, options);
  if (expect_cells > 0) {
    for (int k = 0; k < D; ++k) ASSERT_EQ(engine.grid().cells_along(k), expect_cells);
  }
  engine.validate();
  for (int e = 0; e < events; ++e) {
    ASSERT_NE(engine.step(), EventKind::kNone);
    if (e % testing::validation_stride(1) == 0) engine.validate();
  }
  engine.validate();
  EXPECT_GT(engine.counters().collisions, 0u);
}

TEST(EventEngine, ValidatedAgainstBruteForce3D) {
  run_validated<3, BinaryHeapQueue>(testing::lattice_system<3>(5, 0.4, 1), 3000);
  run_validated<3, CalendarQueue>(testing::lattice_system<3>(5, 0.4, 2), 3000);
}

TEST(EventEngine, ValidatedAgainstBruteForce2D) {
  run_validated<2, BinaryHeapQueue>(testing::lattice_system<2>(8, 0.5, 3), 3000);
  run_validated<2, CalendarQueue>(testing::lattice_system<2>(8, 0.5, 4), 3000);
}

TEST(EventEngine, ValidatedBinaryMixture) {
  // Unequal sizes and masses (4 and 6 cells wide).
  run_validated<3, CalendarQueue>(testing::lattice_system<3>(4, 0.3, 5, 3.0, 1.4), 3000, 4);
  run_validated<2, CalendarQueue>(testing::lattice_system<2>(6, 0.3, 6, 0.5, 1.4), 3000, 6);
}

TEST(EventEngine, ValidatedInABoxThreeCellsWide) {
  // The smallest grid: the far layer of a neighbourhood is the near layer's other image, so
  // every pair test relies on the cell-offset image shifts. Unequal masses, equal sizes.
  run_validated<3, CalendarQueue>(testing::lattice_system<3>(3, 0.3, 11, 2.0), 5000, 3);
  run_validated<3, BinaryHeapQueue>(testing::lattice_system<3>(3, 0.45, 12), 5000, 3);
  run_validated<2, CalendarQueue>(testing::lattice_system<2>(3, 0.5, 13, 0.5), 5000, 3);
}

template <int D>
void expect_bit_identical(const ParticleSystem<D>& a, const ParticleSystem<D>& b) {
  ASSERT_EQ(a.time, b.time);
  for (std::size_t i = 0; i < a.size(); ++i) {
    for (int k = 0; k < D; ++k) {
      ASSERT_EQ(a.kinematics[i].pos[k], b.kinematics[i].pos[k]) << "particle " << i;
      ASSERT_EQ(a.kinematics[i].vel[k], b.kinematics[i].vel[k]) << "particle " << i;
    }
  }
}

template <int D>
void expect_vector_and_scalar_loops_agree(const ParticleSystem<D>& start, int events) {
  EngineOptions scalar;
  scalar.vector_scan = false;
  EventEngine<D, CalendarQueue> a(start, StartMode::kPredict, scalar);
  EventEngine<D, CalendarQueue> b(start);  // AVX-512 loop when the CPU has it
  for (int e = 0; e < events; ++e) {
    a.step();
    b.step();
  }
  expect_bit_identical(a.export_state(), b.export_state());
  EXPECT_EQ(a.counters().stale_events, b.counters().stale_events);
  EXPECT_EQ(a.counters().cell_crossings, b.counters().cell_crossings);
}

TEST(EventEngine, VectorAndScalarCandidateLoopsGiveBitIdenticalRuns) {
  if (!cpu_has_avx512()) GTEST_SKIP() << "this CPU has no AVX-512: only the scalar loop runs";
  // Mono (uniform contact distance), a mixture (radii gathered per kind), 2D, and a box three
  // cells wide (every neighbour cell shifted by a periodic image).
  expect_vector_and_scalar_loops_agree(testing::lattice_system<3>(8, 0.45, 20), 100000);
  expect_vector_and_scalar_loops_agree(testing::lattice_system<3>(6, 0.3, 21, 2.0, 1.4), 50000);
  expect_vector_and_scalar_loops_agree(testing::lattice_system<2>(20, 0.6, 22, 0.5, 1.3), 50000);
  expect_vector_and_scalar_loops_agree(testing::lattice_system<3>(3, 0.45, 23), 50000);
}

// The AVX-512 list gather lists the same candidates as the scalar walk, in the same order (an
// order that differed decided exact ties differently): the lists and the runs agree bit for bit.
template <int D>
void expect_list_walks_agree(const ParticleSystem<D>& start, int events) {
  EngineOptions scalar, vector;
  scalar.list_gather = ListGather::kScalar;
  vector.list_gather = ListGather::kVector;
  EventEngine<D, CalendarQueue> a(start, StartMode::kPredict, scalar);
  EventEngine<D, CalendarQueue> b(start, StartMode::kPredict, vector);
  for (int e = 0; e < events; ++e) {
    a.step();
    b.step();
  }
  expect_bit_identical(a.export_state(), b.export_state());
  EXPECT_EQ(a.counters().stale_events, b.counters().stale_events);
}

TEST(EventEngine, VectorAndScalarListWalksGiveBitIdenticalRuns) {
  if (!cpu_has_avx512()) GTEST_SKIP() << "this CPU has no AVX-512: only the scalar walk runs";
  // Each kind of CPU uses one walk by default; this runs both on any AVX-512 machine. A mixture,
  // a box three cells wide (shifted neighbours), dilute gases (incremental crossings' 3^(D-1)-cell
  // layers) in 3D and 2D.
  expect_list_walks_agree(testing::lattice_system<3>(8, 0.3, 34, 2.0, 1.3), 50000);
  expect_list_walks_agree(testing::lattice_system<3>(3, 0.45, 35), 50000);
  expect_list_walks_agree(testing::lattice_system<3>(12, 0.05, 36), 50000);
  expect_list_walks_agree(testing::lattice_system<2>(30, 0.1, 37, 0.5, 1.3), 50000);
}

// The AVX-512 loops read eight candidates' records by one gather per field or by one load per
// record and a transpose (each kind of CPU uses one by default): the same values, so the runs
// agree bit for bit.
template <int D>
void expect_record_loads_agree(const ParticleSystem<D>& start, const Environment<D>& env,
                               int events) {
  EngineOptions gathers, rows;
  gathers.record_loads = RecordLoads::kGather;
  rows.record_loads = RecordLoads::kRows;
  EventEngine<D, CalendarQueue> a(start, StartMode::kPredict, gathers, env);
  EventEngine<D, CalendarQueue> b(start, StartMode::kPredict, rows, env);
  ASSERT_FALSE(a.candidate_row_loads());
  ASSERT_TRUE(b.candidate_row_loads());
  for (int e = 0; e < events; ++e) ASSERT_EQ(a.step(), b.step()) << "event " << e;
  expect_bit_identical(a.export_state(), b.export_state());
  EXPECT_EQ(a.counters().stale_events, b.counters().stale_events);
}

TEST(EventEngine, RecordRowLoadsAndGathersGiveBitIdenticalRuns) {
  if (!cpu_has_avx512()) GTEST_SKIP() << "this CPU has no AVX-512: the scalar loop runs";
  // The hard-sphere loop: mono, a mixture (radii per kind), 2D (48-byte records), a box three
  // cells wide (shifted neighbours).
  expect_record_loads_agree(testing::lattice_system<3>(8, 0.45, 40), {}, 50000);
  expect_record_loads_agree(testing::lattice_system<3>(6, 0.3, 41, 2.0, 1.4), {}, 50000);
  expect_record_loads_agree(testing::lattice_system<2>(20, 0.3, 42, 0.5, 1.3), {}, 50000);
  expect_record_loads_agree(testing::lattice_system<3>(3, 0.45, 43), {}, 50000);
  // Its gravity variant, between walls.
  ParticleSystem<3> between = testing::lattice_system<3>(5, 0.15, 44);
  for (auto& k : between.kinematics) k.pos[2] += 0.3;  // clear of the walls at z = 0 and z = L
  Environment<3> walls;
  walls.faces[4].kind = walls.faces[5].kind = FaceKind::kWall;
  walls.gravity = {0.0, 0.0, -0.5};
  expect_record_loads_agree(between, walls, 30000);
  // Soft spheres (the contact probe of a mapped contact reads records too).
  Environment<3> soft;
  soft.species = 2;
  soft.soft.assign(4, SoftContactLaw::linear_dashpot(2.0e3, 8.0));
  soft.soft_wall.assign(2, SoftContactLaw::linear_dashpot(2.0e3, 8.0));
  expect_record_loads_agree(testing::lattice_system<3>(5, 0.15, 45, 1.7, 1.3), soft, 20000);
  // The stepped loop: a square well.
  Environment<3> well;
  well.species = 2;
  well.tables = {square_well(1.0, 1.5, 1.0)};
  well.pair_table = {0, 0, 0, 0};
  expect_record_loads_agree(testing::lattice_system<3>(5, 0.25, 46), well, 20000);
}

// current_velocities() is what outputs read instead of export_state(): the same bits, in the
// caller's numbering, for particles in flight under gravity and inside deferred soft contacts.
template <int D>
void expect_current_velocities_exported(const ParticleSystem<D>& start, const Environment<D>& env,
                                        int events, bool soft) {
  EventEngine<D, CalendarQueue> engine(start, StartMode::kPredict, {}, env);
  std::uint32_t checked_frozen = 0;
  for (int e = 0; e < events; ++e) {
    ASSERT_NE(engine.step(), EventKind::kNone);
    if (e % 97 != 0) continue;
    const ParticleSystem<D> s = engine.export_state(/*with_zones=*/false);
    const std::vector<Vec<D>> v = engine.current_velocities();
    ASSERT_EQ(v.size(), s.size());
    for (std::size_t i = 0; i < s.size(); ++i) {
      const Vec<D> expected = s.velocity(i, s.time);
      for (int a = 0; a < D; ++a) {
        ASSERT_EQ(v[i][a], expected[a]) << "particle " << i;
      }
    }
    checked_frozen += engine.frozen();
  }
  if (soft) {
    EXPECT_GT(checked_frozen, 0u);  // contacts in progress were among the checked
  }
}

// max_overlap_now() from the engine's cells against every pair (init's brute force, the
// nearest image along periodic axes only): the same number, bit for bit, with overlaps placed
// by hand (the particles moved onto neighbours, across a periodic face too) and after events
// between walls under gravity (round-off contacts).
template <int D>
void expect_max_overlap_now_is_brute_force(ParticleSystem<D> start, const Environment<D>& env,
                                           int events,
                                           const std::vector<std::array<int, 3>>& moves) {
  const double spacing = start.box[0] / std::round(std::pow(start.size(), 1.0 / D));
  for (const auto& [i, j, percent] : moves) {  // i onto j, `percent` of a spacing along x
    start.kinematics[i].pos = start.kinematics[j].pos;
    start.kinematics[i].pos[0] += 0.01 * percent * spacing;
  }
  EventEngine<D, CalendarQueue> engine(start, StartMode::kPredict, {}, env);
  for (int e = 0; e < events; ++e) ASSERT_NE(engine.step(), EventKind::kNone);
  std::vector<double> diam;
  for (const auto& k : start.kinematics) diam.push_back(2.0 * k.radius);
  std::array<bool, D> periodic{};
  for (int a = 0; a < D; ++a) periodic[a] = env.periodic(a);
  const double brute =
      max_overlap_bruteforce<D>(engine.box(), periodic, engine.current_positions(), diam);
  EXPECT_EQ(engine.max_overlap_now(), brute);
  if (!moves.empty()) {
    EXPECT_GT(brute, 0.1 * spacing);
  }
}

TEST(EventEngine, MaxOverlapNowIsTheBruteForceOne) {
  // Overlaps placed by hand, the largest across the periodic face at x = 0 (the last particle
  // of the first row moved to just below particle 0, the first: wrapped to the high face).
  expect_max_overlap_now_is_brute_force(testing::lattice_system<3>(6, 0.3, 50), Environment<3>{}, 0,
                                        {{7, 8, 45}, {5, 0, -40}, {20, 21, 50}});
  expect_max_overlap_now_is_brute_force(testing::lattice_system<2>(12, 0.3, 51, 0.8, 1.2),
                                        Environment<2>{}, 0, {{3, 4, 45}, {11, 0, -40}});
  // Round-off contacts of grains between walls under gravity, the walls' axis bounded.
  ParticleSystem<3> between = testing::lattice_system<3>(5, 0.15, 52, 1.5, 1.2);
  for (auto& k : between.kinematics) k.pos[2] += 0.3;
  Environment<3> walls;
  walls.faces[4].kind = walls.faces[5].kind = FaceKind::kWall;
  walls.gravity = {0.0, 0.0, -0.5};
  expect_max_overlap_now_is_brute_force(between, walls, 20000, {});
  expect_max_overlap_now_is_brute_force(testing::lattice_system<3>(8, 0.45, 53), Environment<3>{},
                                        50000, {});
}

TEST(EventEngine, CurrentVelocitiesAreTheExportedOnes) {
  ParticleSystem<3> between = testing::lattice_system<3>(5, 0.15, 47, 1.5, 1.2);
  for (auto& k : between.kinematics) k.pos[2] += 0.3;  // clear of the walls at z = 0 and z = L
  Environment<3> walls;
  walls.faces[4].kind = walls.faces[5].kind = FaceKind::kWall;
  walls.gravity = {0.0, 0.0, -0.5};
  expect_current_velocities_exported(between, walls, 5000, false);
  Environment<3> soft;
  soft.species = 2;
  soft.soft.assign(4, SoftContactLaw::linear_dashpot(2.0e3, 8.0));
  soft.soft_wall.assign(2, SoftContactLaw::linear_dashpot(2.0e3, 8.0));
  expect_current_velocities_exported(testing::lattice_system<3>(5, 0.15, 48, 1.7, 1.3), soft, 5000,
                                     true);
  expect_current_velocities_exported(testing::lattice_system<2>(10, 0.2, 49), Environment<2>{},
                                     3000, false);
}

TEST(EventEngine, ValidatedWhileRenumberingEveryFewCollisions) {
  // Renumbering every 0.2 collisions per particle: partners, cells and queue keys must follow.
  EngineOptions often;
  often.renumber_interval = 0.2;
  run_validated<3, CalendarQueue>(testing::lattice_system<3>(4, 0.3, 16, 2.0, 1.3), 3000, 0, often);
  run_validated<2, BinaryHeapQueue>(testing::lattice_system<2>(7, 0.5, 17, 0.5), 3000, 0, often);
}

TEST(EventEngine, ValidatedWithoutRenumbering) {
  EngineOptions never;
  never.renumber_interval = 0.0;
  run_validated<3, CalendarQueue>(testing::lattice_system<3>(4, 0.4, 24), 3000, 0, never);
  run_validated<2, TournamentTreeQueue>(testing::lattice_system<2>(7, 0.5, 25), 3000, 0, never);
  // The caller's numbering is kept.
  const auto s = testing::lattice_system<3>(4, 0.3, 26);
  EventEngine<3, CalendarQueue> engine(s, StartMode::kPredict, never);
  for (int e = 0; e < 1000; ++e) engine.step();
  const auto state = engine.export_state();
  for (std::uint32_t i = 0; i < state.size(); ++i) ASSERT_EQ(state.order[i], i);
}

TEST(EventEngine, RenumberingKeepsTheCallersParticleNumbering) {
  auto s = testing::lattice_system<3>(5, 0.3, 18, 2.0, 1.4);
  EngineOptions often;
  often.renumber_interval = 0.5;
  EventEngine<3, CalendarQueue> engine(s, StartMode::kPredict, often);
  for (int e = 0; e < 5000; ++e) engine.step();
  const auto state = engine.export_state();
  ASSERT_EQ(state.size(), s.size());
  bool permuted = false;
  for (std::size_t i = 0; i < s.size(); ++i) {
    // Species, radius and mass are properties of the particle, whatever its internal slot.
    EXPECT_EQ(state.species[i], s.species[i]);
    EXPECT_EQ(state.kinematics[i].radius, s.kinematics[i].radius);
    EXPECT_EQ(state.mass[i], s.mass[i]);
    permuted = permuted || state.order[i] != i;
  }
  EXPECT_TRUE(permuted) << "the test should exercise a non-trivial internal order";
  // The collision counters of all particles add up to twice the collisions.
  std::uint64_t sum = 0;
  for (auto c : state.collision_count) sum += c;
  EXPECT_EQ(sum, 2 * engine.counters().collisions);
}

TEST(EventEngine, ResumingAcrossRenumberingIsBitIdentical) {
  const auto start = testing::lattice_system<3>(6, 0.45, 19, 1.0, 1.2);
  EngineOptions often;
  often.renumber_interval = 1.0;
  EventEngine<3, CalendarQueue> whole(start, StartMode::kPredict, often);
  for (int e = 0; e < 30000; ++e) whole.step();
  EventEngine<3, CalendarQueue> first(start, StartMode::kPredict, often);
  for (int e = 0; e < 12345; ++e) first.step();
  EventEngine<3, CalendarQueue> second(first.export_state(), StartMode::kResume, often);
  for (int e = 0; e < 30000 - 12345; ++e) second.step();
  const auto a = whole.export_state(), b = second.export_state();
  expect_bit_identical(a, b);
  EXPECT_EQ(a.order, b.order);
  EXPECT_EQ(a.counters.stale_events, b.counters.stale_events);
}

TEST(EventEngine, ResumingADiluteGasIsBitIdentical) {
  // Dilute: most events are crossings, most of them incremental, so the state carries many
  // contacts kept beyond a crossing (EventSlot::kKeptBase + partner); a resume restores them.
  const auto start = testing::lattice_system<3>(10, 0.05, 27, 1.0, 1.3);
  EventEngine<3, CalendarQueue> whole(start);
  for (int e = 0; e < 20000; ++e) whole.step();
  EventEngine<3, CalendarQueue> first(start);
  for (int e = 0; e < 7777; ++e) first.step();
  const auto middle = first.export_state();
  std::size_t kept = 0;
  for (const EventSlot& e : middle.events)
    kept += e.partner >= EventSlot::kKeptBase && e.partner - EventSlot::kKeptBase < middle.size();
  EXPECT_GT(kept, middle.size() / 10) << "the test should resume with contacts kept";
  EventEngine<3, CalendarQueue> second(middle, StartMode::kResume);
  for (int e = 0; e < 20000 - 7777; ++e) second.step();
  const auto a = whole.export_state(), b = second.export_state();
  expect_bit_identical(a, b);
  EXPECT_EQ(a.counters.stale_events, b.counters.stale_events);
  EXPECT_EQ(whole.incremental_crossing_scans(),
            first.incremental_crossing_scans() + second.incremental_crossing_scans());
}

// Incremental crossings (EngineOptions::incremental_crossings): the scheduler invariant holds
// after every event, by brute force, and the incremental path is the one taken.
template <int D>
void run_incremental_validated(const ParticleSystem<D>& start, int events, int check_every) {
  EventEngine<D, CalendarQueue> engine(start);
  ASSERT_TRUE(engine.incremental_crossings());
  for (int e = 0; e < events; ++e) {
    ASSERT_NE(engine.step(), EventKind::kNone);
    if (e % testing::validation_stride(check_every) == 0) engine.validate();
  }
  engine.validate();
  EXPECT_GT(engine.incremental_crossing_scans(), engine.counters().cell_crossings / 2);
}

TEST(EventEngine, IncrementalCrossingsValidatedAgainstBruteForce) {
  run_incremental_validated(testing::lattice_system<3>(8, 0.05, 28), 8000, 31);
  run_incremental_validated(testing::lattice_system<3>(6, 0.2, 29, 2.0, 1.4), 8000, 31);
  run_incremental_validated(testing::lattice_system<2>(20, 0.1, 30, 0.5, 1.3), 8000, 31);
}

// Disks at random in a box 3.3 x 40, so 3 cells along x: every crossing along x makes the old
// far layer the new layer, through the other periodic image.
ParticleSystem<2> thin_box_of_disks(std::uint64_t seed) {
  ParticleSystem<2> s;
  s.box = {3.3, 40.0};
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  while (s.size() < 40) {
    Kinematics<2> k{};
    for (int a = 0; a < 2; ++a) {
      k.pos[a] = u(rng) * s.box[a];
      k.vel[a] = 2.0 * u(rng) - 1.0;
    }
    k.radius = 0.5;
    bool free = true;
    for (const Kinematics<2>& o : s.kinematics) {
      double r2 = 0.0;
      for (int a = 0; a < 2; ++a) {
        double d = k.pos[a] - o.pos[a];
        d -= s.box[a] * std::round(d / s.box[a]);
        r2 += d * d;
      }
      free = free && r2 >= 1.0001;
    }
    if (!free) continue;
    s.kinematics.push_back(k);
    s.mass.push_back(1.0);
    s.species.push_back(0);
  }
  s.species_names = {"A"};
  return s;
}

TEST(EventEngine, IncrementalCrossingsValidatedOnAxesThreeCellsWide) {
  // A partner kept through the old image of the far layer must not be carried over (review
  // finding: these seeds lost collisions, one an overlap of 0.12 sigma, before the fix).
  for (const std::uint64_t seed : {5u, 77u, 121u}) {
    EventEngine<3, CalendarQueue> engine(testing::lattice_system<3>(3, 0.2, seed));
    ASSERT_EQ(engine.grid().cells_along(0), 3);
    for (int e = 0; e < 3000; ++e) {
      ASSERT_NE(engine.step(), EventKind::kNone);
      engine.validate();
    }
    EXPECT_GT(engine.incremental_crossing_scans(), 0u);
  }
  EngineOptions thin;
  thin.max_cells_per_particle = 1000.0;  // 3 x 40 cells
  thin.renumber_interval = 0.0;
  for (const std::uint64_t seed : {227u, 328u, 1u, 2u}) {
    EventEngine<2, CalendarQueue> engine(thin_box_of_disks(seed), StartMode::kPredict, thin);
    ASSERT_EQ(engine.grid().cells_along(0), 3);
    for (int e = 0; e < 3000; ++e) {
      ASSERT_NE(engine.step(), EventKind::kNone);
      engine.validate();
    }
    EXPECT_GT(engine.incremental_crossing_scans(), 0u);  // crossings that kept nothing
  }
}

// The same dynamics with and without incremental crossings: the same collisions at the same
// times up to round-off (a pair's contact time is computed from the other particle's side or at
// another moment, so bits may differ), over a stretch too short for chaos to amplify that.
template <int D>
void expect_incremental_and_full_scans_agree(const ParticleSystem<D>& start, double until) {
  EngineOptions full;
  full.incremental_crossings = false;
  EventEngine<D, CalendarQueue> a(start, StartMode::kPredict, full);
  EventEngine<D, CalendarQueue> b(start);
  ASSERT_FALSE(a.incremental_crossings());
  ASSERT_TRUE(b.incremental_crossings());
  while (a.next_event_time() < until) a.step();
  while (b.next_event_time() < until) b.step();
  EXPECT_EQ(a.counters().collisions, b.counters().collisions);
  EXPECT_EQ(a.counters().cell_crossings, b.counters().cell_crossings);
  EXPECT_GT(a.counters().collisions, start.size() / 2);
  EXPECT_EQ(a.incremental_crossing_scans(), 0u);
  EXPECT_GT(b.incremental_crossing_scans(), b.counters().cell_crossings / 2);
  const auto sa = a.export_state(), sb = b.export_state();
  double worst = 0.0;
  for (std::size_t i = 0; i < sa.size(); ++i) {
    const Vec<D> xa = sa.position(i, until), xb = sb.position(i, until);
    for (int k = 0; k < D; ++k) worst = std::max(worst, std::abs(xa[k] - xb[k]));
  }
  EXPECT_LT(worst, 1e-9);
}

TEST(EventEngine, IncrementalAndFullCrossingScansGiveTheSameCollisions) {
  expect_incremental_and_full_scans_agree(testing::lattice_system<3>(10, 0.05, 32, 2.0, 1.3), 4.0);
  expect_incremental_and_full_scans_agree(testing::lattice_system<2>(30, 0.1, 33), 4.0);
}

template <int D, class Q>
void check_conservation(const ParticleSystem<D>& start, std::uint64_t events) {
  EventEngine<D, Q> engine(start);
  const double ke0 = engine.kinetic_energy();
  const Vec<D> p0 = engine.momentum();
  double pscale = 0.0;
  for (std::size_t i = 0; i < engine.size(); ++i)
    pscale += start.mass[i] * std::sqrt(norm2(start.kinematics[i].vel));
  for (std::uint64_t e = 0; e < events; ++e) ASSERT_NE(engine.step(), EventKind::kNone);
  EXPECT_GE(engine.counters().events, events);
  EXPECT_NEAR(engine.kinetic_energy() / ke0, 1.0, 1e-10);
  const Vec<D> p1 = engine.momentum();
  for (int a = 0; a < D; ++a) EXPECT_NEAR((p1[a] - p0[a]) / pscale, 0.0, 1e-10);
  const auto pos = engine.current_positions();
  std::vector<double> diam;
  for (const auto& k : start.kinematics) diam.push_back(2.0 * k.radius);
  EXPECT_LT(max_overlap_bruteforce<D>(engine.box(), pos, diam), 1e-10);
}

TEST(EventEngine, ConservesEnergyAndMomentumOverAMillionEvents3D) {
  check_conservation<3, CalendarQueue>(testing::lattice_system<3>(10, 0.4, 7, 2.0, 1.2), 1000000);
}

TEST(EventEngine, ConservesEnergyAndMomentumOverAMillionEvents2D) {
  check_conservation<2, CalendarQueue>(testing::lattice_system<2>(32, 0.6, 8, 2.0, 1.2), 1000000);
}

TEST(EventEngine, HeapCalendarAndTreeQueuesGiveBitIdenticalRuns) {
  const auto start = testing::lattice_system<3>(8, 0.45, 9);
  EventEngine<3, BinaryHeapQueue> a(start);
  EventEngine<3, CalendarQueue> b(start);
  EventEngine<3, TournamentTreeQueue> c(start);
  for (int e = 0; e < 200000; ++e) {
    a.step();
    b.step();
    c.step();
  }
  expect_bit_identical(a.export_state(), b.export_state());
  expect_bit_identical(a.export_state(), c.export_state());
  EXPECT_EQ(a.counters().stale_events, c.counters().stale_events);
}

TEST(EventEngine, ContinuingFromExportedStateIsBitIdentical) {
  const auto start = testing::lattice_system<3>(6, 0.4, 10);
  EventEngine<3, CalendarQueue> whole(start);
  for (int e = 0; e < 20000; ++e) whole.step();
  EventEngine<3, CalendarQueue> first(start);
  for (int e = 0; e < 10000; ++e) first.step();
  EventEngine<3, CalendarQueue> second(first.export_state(), StartMode::kResume);
  for (int e = 0; e < 10000; ++e) second.step();
  expect_bit_identical(whole.export_state(), second.export_state());
}

TEST(EventEngine, ResumeNeedsSchedulerState) {
  const auto fresh = testing::lattice_system<3>(4, 0.3, 14);
  EXPECT_THROW((EventEngine<3, CalendarQueue>(fresh, StartMode::kResume)), InputError);
  // A stored cell that does not contain the particle is refused, not trusted.
  EventEngine<3, CalendarQueue> engine(fresh);
  ParticleSystem<3> state = engine.export_state();
  state.cell[0] = (state.cell[0] + 1) % engine.grid().cell_count();
  EXPECT_THROW((EventEngine<3, CalendarQueue>(state, StartMode::kResume)), InputError);
}

TEST(EventEngine, PositionsOutsideTheBoxAreWrappedIn) {
  auto s = testing::lattice_system<3>(5, 0.3, 15);
  for (auto& k : s.kinematics) k.pos[0] += 3.0 * s.box[0];  // three images away
  EventEngine<3, CalendarQueue> engine(s);
  const auto state = engine.export_state();
  for (std::size_t i = 0; i < engine.size(); ++i) {
    EXPECT_GE(state.kinematics[i].pos[0], 0.0);
    EXPECT_LT(state.kinematics[i].pos[0], s.box[0]);
  }
  for (int e = 0; e < 500; ++e) {
    engine.step();
    engine.validate();
  }
}

TEST(EventEngine, TwoParticlesHeadOnSwapVelocities) {
  ParticleSystem<3> s;
  s.box = {10, 10, 10};
  s.kinematics = {{{2, 5, 5}, {1, 0, 0}, 0.0, 0.5}, {{5, 5, 5}, {-1, 0, 0}, 0.0, 0.5}};
  s.mass = {1, 1};
  s.species = {0, 0};
  EventEngine<3, BinaryHeapQueue> engine(s);
  while (engine.counters().collisions == 0) engine.step();
  EXPECT_DOUBLE_EQ(engine.time(), 1.0);
  const auto state = engine.export_state();
  EXPECT_DOUBLE_EQ(state.kinematics[0].vel[0], -1.0);
  EXPECT_DOUBLE_EQ(state.kinematics[1].vel[0], 1.0);
  EXPECT_DOUBLE_EQ(engine.counters().virial, 2.0);  // r.J = sigma * 2 mu |g_n| = 1 * 2 * 0.5 * 2
}

}  // namespace
}  // namespace kairos
