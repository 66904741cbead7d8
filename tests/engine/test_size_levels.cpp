// Two cell levels for wide size distributions (EngineOptions::size_levels; the cell
// neighbourhood's use_levels): big particles in coarse cells, small ones in fine cells. The
// schedule checked against brute force after every event (no contact missed, none late) in 3D
// and 2D, with growth; the collisions the same as with one level; what keeps one level.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "../release_suite_only.hpp"
#include "core/error.hpp"
#include "engine/event_engine.hpp"
#include "scheduler/calendar_queue.hpp"

namespace kairos {
namespace {

// `bigs` particles of diameter `big` on a lattice and small ones of diameter 1 placed at random
// without overlap up to `small_fraction` of the box, in a periodic box of edge L; random
// velocities (zero momentum), masses by volume.
template <int D>
ParticleSystem<D> wide_mixture(double L, int bigs_along, double big, double small_fraction,
                               std::uint64_t seed, double big_mass = 0.0) {
  ParticleSystem<D> s;
  s.box.fill(L);
  s.species_names = {"small", "big"};
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0), v(-1.0, 1.0);
  const auto add = [&](const Vec<D>& x, double d, std::uint32_t species) {
    Kinematics<D> k{};
    k.pos = x;
    for (int a = 0; a < D; ++a) k.vel[a] = v(rng);
    k.radius = 0.5 * d;
    s.kinematics.push_back(k);
    s.mass.push_back(species == 1 && big_mass > 0.0 ? big_mass : std::pow(d, D));
    s.species.push_back(species);
  };
  int count = 1;
  for (int a = 0; a < D; ++a) count *= bigs_along;
  for (int b = 0; b < count; ++b) {
    Vec<D> x;
    int rem = b;
    for (int a = 0; a < D; ++a) {
      x[a] = (rem % bigs_along + 0.5) * L / bigs_along;
      rem /= bigs_along;
    }
    add(x, big, 1);
  }
  const double ball = D == 3 ? M_PI / 6.0 : M_PI / 4.0;
  const int smalls = static_cast<int>(small_fraction * std::pow(L, D) / ball);
  for (int tries = 0; static_cast<int>(s.size()) < count + smalls && tries < 1000000; ++tries) {
    Vec<D> x;
    for (int a = 0; a < D; ++a) x[a] = L * u(rng);
    bool free = true;
    for (const Kinematics<D>& k : s.kinematics) {
      double r2 = 0.0;
      for (int a = 0; a < D; ++a) {
        double d = x[a] - k.pos[a];
        d -= L * std::round(d / L);
        r2 += d * d;
      }
      const double sigma = 0.5 + k.radius;
      if (r2 < sigma * sigma * 1.0001) {
        free = false;
        break;
      }
    }
    if (free) add(x, 1.0, 0);
  }
  EXPECT_GT(static_cast<int>(s.size()), count + smalls * 9 / 10);  // nearly all placed
  Vec<D> p{};
  double m = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    p = p + s.mass[i] * s.kinematics[i].vel;
    m += s.mass[i];
  }
  for (std::size_t i = 0; i < s.size(); ++i)
    s.kinematics[i].vel = s.kinematics[i].vel - (1.0 / m) * p;
  return s;
}

// Steps `events` events validating the schedule after each; energy and momentum kept (or, when
// growing, energy only gained). Returns the collision times.
template <int D>
std::vector<double> run_validated(EventEngine<D, CalendarQueue>& engine, int events) {
  engine.validate();
  const Vec<D> p0 = engine.momentum();
  const double e0 = engine.kinetic_energy();
  std::vector<double> times;
  const bool growing = engine.growth().on();
  for (int e = 0; e < events; ++e) {
    if (growing && !(engine.next_event_time() < engine.growth_fits_until())) break;
    if (engine.step() == EventKind::kCollision) times.push_back(engine.time());
    if (e % testing::validation_stride(1) == 0) engine.validate();
  }
  for (int a = 0; a < D; ++a)
    EXPECT_NEAR(engine.momentum()[a], p0[a], 1e-10 * (1.0 + std::abs(p0[a])));
  if (growing) {
    EXPECT_GT(engine.kinetic_energy(), e0);
  } else {
    EXPECT_NEAR(engine.kinetic_energy(), e0, 1e-11 * e0);
  }
  EXPECT_LT(engine.max_overlap_now(), 1e-12);
  return times;
}

TEST(SizeLevels, ValidatedAgainstBruteForce3D) {
  KAIROS_RELEASE_SUITE_ONLY();
  // Diameters 1 and 4: fine cells of about 1, coarse cells of about 4, a big one's reach 3.
  const auto s = wide_mixture<3>(13.0, 2, 4.0, 0.15, 21);
  EventEngine<3, CalendarQueue> engine(s, StartMode::kPredict);
  ASSERT_TRUE(engine.two_level_cells());
  EXPECT_FALSE(engine.incremental_crossings());
  const std::vector<double> times = run_validated(engine, 1500);
  EXPECT_GT(times.size(), 400u);
}

TEST(SizeLevels, ValidatedAgainstBruteForce2D) {
  // Diameters 1 and 10 (1:10) in 2D.
  const auto s = wide_mixture<2>(31.0, 2, 10.0, 0.3, 22);
  EventEngine<2, CalendarQueue> engine(s, StartMode::kPredict);
  ASSERT_TRUE(engine.two_level_cells());
  const std::vector<double> times = run_validated(engine, 2000);
  EXPECT_GT(times.size(), 500u);
}

TEST(SizeLevels, BigParticlesMeetEachOther) {
  // 16 light big disks (diameter 6, mass 1) 1.75 apart among a few small ones, on two levels
  // whatever their cost: big-big contacts through the coarse cells, validated after every event.
  const auto s = wide_mixture<2>(31.0, 4, 6.0, 0.05, 28, 1.0);
  EngineOptions o;
  o.force_size_levels = true;
  EventEngine<2, CalendarQueue> engine(s, StartMode::kPredict, o);
  ASSERT_TRUE(engine.two_level_cells());
  run_validated(engine, 3000);
  // Big pairs came close (they start 1.75 apart): within 0.5 of contact at the end.
  const ParticleSystem<2> out = engine.export_state();
  int touching = 0;
  for (std::size_t i = 0; i < out.size(); ++i) {
    for (std::size_t j = i + 1; j < out.size(); ++j) {
      if (out.species[i] != 1 || out.species[j] != 1) continue;
      double r2 = 0.0;
      for (int a = 0; a < 2; ++a) {
        double d = out.kinematics[i].pos[a] - out.kinematics[j].pos[a];
        d -= out.box[a] * std::round(d / out.box[a]);
        r2 += d * d;
      }
      touching += r2 < 6.5 * 6.5 ? 1 : 0;
    }
  }
  EXPECT_GT(touching, 0) << "no big pair came within reach";
}

TEST(SizeLevels, ResumedOnTheLevelsItWasWrittenWith) {
  // A state written on one level continues on one (bit for bit), whatever the default; a state
  // written on two refuses to continue on one, saying why.
  const auto s = wide_mixture<3>(13.0, 2, 4.0, 0.15, 29);
  EngineOptions one;
  one.size_levels = false;
  EventEngine<3, CalendarQueue> a(s, StartMode::kPredict, one);
  for (int e = 0; e < 2000; ++e) a.step();
  EventEngine<3, CalendarQueue> b(a.export_state(), StartMode::kResume);
  EXPECT_FALSE(b.two_level_cells());
  for (int e = 0; e < 2000; ++e) {
    ASSERT_EQ(a.step(), b.step()) << e;
    ASSERT_EQ(a.time(), b.time()) << e;
  }
  EventEngine<3, CalendarQueue> c(s, StartMode::kPredict);
  ASSERT_TRUE(c.two_level_cells());
  for (int e = 0; e < 2000; ++e) c.step();
  try {
    EventEngine<3, CalendarQueue> d(c.export_state(), StartMode::kResume, one);
    FAIL() << "a two-level state resumed on one level";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("run.size_levels"), std::string::npos) << e.what();
  }
}

TEST(SizeLevels, ValidatedWhileGrowing) {
  // Fast growth of a 1:5 mixture: the cells' room, the coarse cells and the reach all grow
  // short; the engine stops at growth_fits_until().
  for (const double rate : {0.05, 0.5}) {
    const auto s = wide_mixture<3>(20.0, 2, 5.0, 0.03, 23);
    EngineOptions o;
    o.growth_rate = rate;
    o.min_cell_width = 5.0 * 1.2;  // room: 1.2 times every contact distance
    EventEngine<3, CalendarQueue> engine(s, StartMode::kPredict, o);
    ASSERT_TRUE(engine.two_level_cells());
    run_validated(engine, 700);
    EXPECT_GT(engine.counters().collisions, 100u);
  }
}

TEST(SizeLevels, TheSameCollisionsAsOneLevel) {
  // One level and two see the same collisions at the same times until round-off (different
  // crossings) separates the trajectories: the first 300 agree to 1e-9.
  const auto s = wide_mixture<3>(19.0, 3, 6.0, 0.15, 24);
  EngineOptions one;
  one.size_levels = false;
  EventEngine<3, CalendarQueue> a(s, StartMode::kPredict, one);
  EventEngine<3, CalendarQueue> b(s, StartMode::kPredict);
  ASSERT_FALSE(a.two_level_cells());
  ASSERT_TRUE(b.two_level_cells());
  std::vector<double> ta, tb;
  while (ta.size() < 300) {
    if (a.step() == EventKind::kCollision) ta.push_back(a.time());
  }
  while (tb.size() < 300) {
    if (b.step() == EventKind::kCollision) tb.push_back(b.time());
  }
  for (std::size_t k = 0; k < 300; ++k) EXPECT_NEAR(ta[k], tb[k], 1e-9 * (1.0 + ta[k])) << k;
  EXPECT_EQ(a.counters().collisions, b.counters().collisions);
}

TEST(SizeLevels, NarrowDistributionsKeepOneLevel) {
  // 1:2 stays on one level (twice the cost at most: docs/performance.md).
  const auto s = wide_mixture<3>(14.0, 2, 2.0, 0.2, 25);
  EventEngine<3, CalendarQueue> engine(s, StartMode::kPredict);
  EXPECT_FALSE(engine.two_level_cells());
}

TEST(SizeLevels, MostlyMidSizedParticlesKeepOneLevel) {
  // Diameters uniform on [0.13, 1.87] (1:14): most particles are mid-sized, so a fine grid for
  // the smallest would put most of them in the coarse one; one level is cheaper (measured at
  // packing fraction 0.3: docs/performance.md) and the cost estimate keeps it.
  ParticleSystem<3> s;
  const int n = 16;
  s.box.fill(1.9 * n);
  std::mt19937_64 rng(27);
  std::uniform_real_distribution<double> d(0.13, 1.87), v(-1.0, 1.0);
  for (int i = 0; i < n * n * n; ++i) {
    Kinematics<3> k{};
    for (int a = 0, rem = i; a < 3; ++a, rem /= n) k.pos[a] = 1.9 * (rem % n) + 1.0;
    for (int a = 0; a < 3; ++a) k.vel[a] = v(rng);
    k.radius = 0.5 * d(rng);
    s.kinematics.push_back(k);
    s.mass.push_back(1.0);
    s.species.push_back(0);
  }
  s.species_names = {"A"};
  EventEngine<3, CalendarQueue> engine(s, StartMode::kPredict);
  EXPECT_FALSE(engine.two_level_cells());
}

TEST(SizeLevels, RenumberedAndResumedExactly) {
  // The big flags follow the renumbering; a resumed engine continues bit for bit.
  const auto s = wide_mixture<3>(19.0, 3, 6.0, 0.15, 26);
  EngineOptions o;
  o.renumber_interval = 0.5;  // renumber often
  EventEngine<3, CalendarQueue> a(s, StartMode::kPredict, o);
  ASSERT_TRUE(a.two_level_cells());
  for (int e = 0; e < 3000; ++e) a.step();
  a.validate();
  EventEngine<3, CalendarQueue> b(a.export_state(), StartMode::kResume, o);
  ASSERT_TRUE(b.two_level_cells());
  b.validate();
  for (int e = 0; e < 3000; ++e) {
    ASSERT_EQ(a.step(), b.step()) << e;
    ASSERT_EQ(a.time(), b.time()) << e;
  }
  a.validate();
}

}  // namespace
}  // namespace kairos
