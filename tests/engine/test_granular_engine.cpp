// Granular dynamics in the engine: inelastic and rough collisions against kinetic theory
// (docs/physics.md#rough-collision, docs/physics.md#granular-kinetic-theory), conservation laws
// and exactness.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "../release_suite_only.hpp"
#include "analysis/granular_theory.hpp"
#include "engine/event_engine.hpp"
#include "engine_fixtures.hpp"
#include "scheduler/calendar_queue.hpp"

namespace kairos {
namespace {

// A dilute gas of equal spheres, thermalised by elastic collisions from a lattice start: the
// velocities are Maxwellian when dissipation starts.
template <int D>
ParticleSystem<D> thermalised_gas(int n, double eta, std::uint64_t seed) {
  const ParticleSystem<D> lattice = testing::lattice_system<D>(n, eta, seed);
  EventEngine<D, CalendarQueue> engine(lattice);
  const std::uint64_t target = 10 * lattice.size() / 2;  // 10 collisions per particle
  while (engine.counters().collisions < target) engine.step();
  ParticleSystem<D> s = engine.export_state();
  s.events.clear();
  s.cell.clear();
  s.order.clear();
  s.counters = {};
  return s;
}

template <int D>
Environment<D> uniform_contact(const ContactModel& law) {
  Environment<D> env;
  env.species = 2;  // the fixture's two (identical) species
  env.contact.assign(4, law);
  return env;
}

ContactModel inelastic(double e) {
  ContactModel m;
  m.normal = NormalRestitution::constant(e);
  return m;
}

template <int D>
double collisions_per_particle(const EventEngine<D, CalendarQueue>& engine) {
  return 2.0 * static_cast<double>(engine.counters().collisions) /
         static_cast<double>(engine.size());
}

// T = T0 exp[-(1 - e^2) c / d] with c collisions per particle: exact for Maxwellian velocities
// whatever g(sigma) is; the Sonine correction changes the rate by ~0.3 % at e = 0.9.
template <int D>
void check_cooling_per_collision(int n, double eta, double e, double c_end, double tolerance) {
  double sum = 0.0, sum2 = 0.0;
  // 12 seeds: one run's ratio scatters by ~2 % in 2D, and the 2D mean sits ~1 % below 1
  // (velocity correlations), so fewer seeds made the verdict depend on the realisation.
  const int seeds = 12;
  double expected = 0.0;
  for (int seed = 1; seed <= seeds; ++seed) {
    const ParticleSystem<D> start = thermalised_gas<D>(n, eta, static_cast<std::uint64_t>(seed));
    EventEngine<D, CalendarQueue> engine(start, StartMode::kPredict, EngineOptions{},
                                         uniform_contact<D>(inelastic(e)));
    const double ke0 = engine.kinetic_energy();
    while (collisions_per_particle(engine) < c_end) ASSERT_NE(engine.step(), EventKind::kNone);
    const double c = collisions_per_particle(engine);
    expected = temperature_ratio_after_collisions(D, e, c);
    const double ratio = std::log(engine.kinetic_energy() / ke0) / std::log(expected);
    // Energy bookkeeping: what was lost is what the collisions dissipated.
    EXPECT_NEAR(ke0 - engine.kinetic_energy(), engine.counters().dissipated_in_collisions,
                1e-9 * ke0);
    sum += ratio;
    sum2 += ratio * ratio;
  }
  const double mean = sum / seeds;
  const double stderr_ = std::sqrt((sum2 / seeds - mean * mean) / (seeds - 1));
  ::testing::Test::RecordProperty("log_ratio_mean", std::to_string(mean));
  ::testing::Test::RecordProperty("log_ratio_stderr", std::to_string(stderr_));
  std::printf("D=%d e=%.2f: ln(T/T0) measured / predicted = %.5f +- %.5f\n", D, e, mean, stderr_);
  EXPECT_NEAR(mean, 1.0, tolerance + 3.0 * stderr_);
}

TEST(GranularEngine, CoolingPerCollisionFollowsTheExponentialLaw3D) {
  KAIROS_RELEASE_SUITE_ONLY();
  check_cooling_per_collision<3>(13, 0.02, 0.9, 10.0, 0.02);
  check_cooling_per_collision<3>(13, 0.02, 0.8, 5.0, 0.02);
}

TEST(GranularEngine, CoolingPerCollisionFollowsTheExponentialLaw2D) {
  check_cooling_per_collision<2>(32, 0.02, 0.9, 10.0, 0.02);
  check_cooling_per_collision<2>(32, 0.02, 0.8, 5.0, 0.02);
}

// Haff's law T(t) = T0 / (1 + t/tau0)^2 with the Enskog collision frequency (Carnahan–Starling
// g(sigma)) at T0. At eta = 0.02 Enskog is accurate to well below the statistics; the Sonine
// correction shifts T(tau0) by ~0.3 %.
TEST(GranularEngine, TemperatureFollowsHaffsLaw3D) {
  KAIROS_RELEASE_SUITE_ONLY();
  constexpr int D = 3;
  const double e = 0.9, eta = 0.02;
  std::vector<double> times, sum(4, 0.0);
  // 12 seeds: one run's ratio scatters by ~2 % in 2D, and the 2D mean sits ~1 % below 1
  // (velocity correlations), so fewer seeds made the verdict depend on the realisation.
  const int seeds = 12;
  double tau0 = 0.0;
  for (int seed = 1; seed <= seeds; ++seed) {
    const ParticleSystem<D> start = thermalised_gas<D>(13, eta, static_cast<std::uint64_t>(seed));
    const double n =
        static_cast<double>(start.size()) / (start.box[0] * start.box[1] * start.box[2]);
    EventEngine<D, CalendarQueue> engine(start, StartMode::kPredict, EngineOptions{},
                                         uniform_contact<D>(inelastic(e)));
    const double t0_temp =
        2.0 * engine.kinetic_energy() / (D * (static_cast<double>(engine.size()) - 1.0));
    tau0 = haff_time(D, e, enskog_collision_frequency(D, n, 1.0, t0_temp, 1.0));
    const double t_start = engine.time();
    for (int k = 0; k < 4; ++k) {
      const double t = t_start + 0.5 * (k + 1) * tau0;  // up to T = T0 / 9
      while (engine.time() < t) ASSERT_NE(engine.step(), EventKind::kNone);
      // Compare at the time of the event just processed (the temperature is piecewise
      // constant between collisions).
      const double temp =
          2.0 * engine.kinetic_energy() / (D * (static_cast<double>(engine.size()) - 1.0));
      sum[k] += temp / haff_temperature(t0_temp, tau0, engine.time() - t_start);
    }
  }
  for (int k = 0; k < 4; ++k) {
    std::printf("Haff 3D: t = %.2f tau0: T / T_Haff = %.4f\n", 0.5 * (k + 1), sum[k] / seeds);
    EXPECT_NEAR(sum[k] / seeds, 1.0, 0.03) << "at t = " << 0.5 * (k + 1) << " tau0";
  }
}

// The velocity distribution of the homogeneous cooling state: a2 = <c^4>/<c^2>^2 d/(d+2) - 1
// against van Noije–Ernst, averaged over snapshots one collision per particle apart. Its sign
// changes at e = 1/sqrt(2): positive at e = 0.5, negative at e = 0.9.
template <int D>
double measured_a2(int n, double eta, double e, int seeds) {
  double sum = 0.0;
  int samples = 0;
  for (int seed = 1; seed <= seeds; ++seed) {
    const ParticleSystem<D> start = thermalised_gas<D>(n, eta, static_cast<std::uint64_t>(seed));
    EventEngine<D, CalendarQueue> engine(start, StartMode::kPredict, EngineOptions{},
                                         uniform_contact<D>(inelastic(e)));
    for (int c = 4; c <= 12; ++c) {
      while (collisions_per_particle(engine) < c)
        if (engine.step() == EventKind::kNone) return std::nan("");
      const ParticleSystem<D> s = engine.export_state();
      double m2 = 0.0, m4 = 0.0;
      for (const auto& k : s.kinematics) {
        const double v2 = norm2(k.vel);
        m2 += v2;
        m4 += v2 * v2;
      }
      m2 /= static_cast<double>(s.size());
      m4 /= static_cast<double>(s.size());
      sum += m4 / (m2 * m2) * D / (D + 2.0) - 1.0;
      ++samples;
    }
  }
  return sum / samples;
}

TEST(GranularEngine, SonineCoefficientHasTheSignAndSizeOfVanNoijeErnst) {
  const double high = measured_a2<3>(16, 0.02, 0.5, 4);
  const double low = measured_a2<3>(16, 0.02, 0.9, 4);
  std::printf("a2(e=0.5) = %.4f (vNE %.4f); a2(e=0.9) = %.4f (vNE %.4f)\n", high, sonine_a2(3, 0.5),
              low, sonine_a2(3, 0.9));
  EXPECT_GT(high, 0.0);
  EXPECT_NEAR(high, sonine_a2(3, 0.5), 0.02);
  EXPECT_NEAR(low, sonine_a2(3, 0.9), 0.01);
}

ContactModel rough(double e, double beta) {
  ContactModel m;
  m.normal = NormalRestitution::constant(e);
  m.tangential = TangentialModel::constant(beta);
  return m;
}

template <int D>
double translational_temperature(const EventEngine<D, CalendarQueue>& engine) {
  return 2.0 * engine.kinetic_energy() / (D * (static_cast<double>(engine.size()) - 1.0));
}
template <int D>
double rotational_temperature(const EventEngine<D, CalendarQueue>& engine) {
  return 2.0 * engine.rotational_energy() /
         (rotational_degrees_of_freedom(D) * static_cast<double>(engine.size()));
}

// Mean-field temperature ratio R = T_rot / T_tr after c collisions per particle from R(0) = 0:
// the linear equations dT_tr/dc = -A T_tr + B T_rot, dT_rot/dc = B_rot T_tr - C T_rot
// (docs/theory-rough-hcs.md), integrated by RK4 in small steps.
double mean_field_ratio(int d, double e, double beta, double q, double c_end) {
  const RoughCoolingCoefficients k = rough_cooling_coefficients(d, e, beta, q);
  double tr = 1.0, rot = 0.0;
  const int steps = 20000;
  const double h = c_end / steps;
  auto f = [&](double x, double y) { return std::pair{-k.a * x + k.b * y, k.b_rot * x - k.c * y}; };
  for (int s = 0; s < steps; ++s) {
    const auto [a1, b1] = f(tr, rot);
    const auto [a2, b2] = f(tr + 0.5 * h * a1, rot + 0.5 * h * b1);
    const auto [a3, b3] = f(tr + 0.5 * h * a2, rot + 0.5 * h * b2);
    const auto [a4, b4] = f(tr + h * a3, rot + h * b3);
    tr += h / 6.0 * (a1 + 2 * a2 + 2 * a3 + a4);
    rot += h / 6.0 * (b1 + 2 * b2 + 2 * b3 + b4);
  }
  return rot / tr;
}

// Rough spheres starting without spin: T_rot / T_tr follows the mean-field theory of the
// cooling state (docs/theory-rough-hcs.md) towards its stationary value. The theory neglects
// correlations between spins and velocities; simulations are known to sit a few per cent below
// it, so the tolerance is 6 % plus three standard errors of the mean over seeds. Energy bookkeeping
// holds throughout and linear momentum is conserved to round-off.
template <int D>
void check_rough_cooling_state(int n, double e, double beta, double tolerance) {
  const double q = D == 3 ? 0.4 : 0.5;
  const int checkpoints[] = {5, 10, 20, 30};
  std::vector<double> ratio(4, 0.0), ratio2(4, 0.0);
  // 8 seeds: with 3 the mean at 30 collisions per particle scattered by ~3 % between
  // realisations, on top of the known few per cent below mean field.
  const int seeds = 8;
  for (int seed = 1; seed <= seeds; ++seed) {
    const ParticleSystem<D> start = thermalised_gas<D>(n, 0.02, static_cast<std::uint64_t>(seed));
    EventEngine<D, CalendarQueue> engine(start, StartMode::kPredict, EngineOptions{},
                                         uniform_contact<D>(rough(e, beta)));
    const double e0 = engine.kinetic_energy();
    for (int k = 0; k < 4; ++k) {
      while (collisions_per_particle(engine) < checkpoints[k])
        ASSERT_NE(engine.step(), EventKind::kNone);
      const double r = rotational_temperature(engine) / translational_temperature(engine);
      ratio[k] += r / seeds;
      ratio2[k] += r * r / seeds;
    }
    const double e_now = engine.kinetic_energy() + engine.rotational_energy();
    EXPECT_NEAR(e0 - e_now, engine.counters().dissipated_in_collisions, 1e-9 * e0);
    const Vec<D> p = engine.momentum();
    for (int a = 0; a < D; ++a) EXPECT_NEAR(p[a], 0.0, 1e-10 * std::sqrt(e0));
  }
  for (int k = 0; k < 4; ++k) {
    const double theory = mean_field_ratio(D, e, beta, q, checkpoints[k]);
    const double stderr_ = std::sqrt(std::max(0.0, ratio2[k] - ratio[k] * ratio[k]) / (seeds - 1));
    std::printf(
        "D=%d e=%.2f beta=%.2f c=%d: T_rot/T_tr = %.4f +- %.4f, mean field %.4f (stationary "
        "%.4f)\n",
        D, e, beta, checkpoints[k], ratio[k], stderr_, theory,
        rough_hcs_temperature_ratio(D, e, beta, q));
    EXPECT_NEAR(ratio[k] / theory, 1.0, tolerance + 3.0 * stderr_ / theory)
        << "after " << checkpoints[k] << " collisions";
  }
}

// Dilute inelastic and rough gases run with incremental crossings (most events are crossings);
// the scheduler invariant holds by brute force throughout the cooling.
template <int D>
void run_granular_validated(const ContactModel& model, std::uint64_t seed) {
  const ParticleSystem<D> start = thermalised_gas<D>(D == 3 ? 8 : 20, 0.02, seed);
  EventEngine<D, CalendarQueue> engine(start, StartMode::kPredict, EngineOptions{},
                                       uniform_contact<D>(model));
  ASSERT_TRUE(engine.incremental_crossings());
  for (int k = 0; k < 2000; ++k) {
    ASSERT_NE(engine.step(), EventKind::kNone);
    if (k % testing::validation_stride(11) == 0) engine.validate();
  }
  EXPECT_GT(engine.incremental_crossing_scans(), engine.counters().cell_crossings / 2);
}

TEST(GranularEngine, IncrementalCrossingsValidatedInCoolingGases) {
  run_granular_validated<2>(inelastic(0.8), 41);
  run_granular_validated<2>(rough(0.9, 0.5), 42);
  run_granular_validated<3>(inelastic(0.8), 43);
}

TEST(GranularEngine, RoughSpheresReachTheMeanFieldTemperatureRatio3D) {
  KAIROS_RELEASE_SUITE_ONLY();
  check_rough_cooling_state<3>(13, 0.9, 0.5, 0.06);
  check_rough_cooling_state<3>(13, 0.9, 0.0, 0.06);
}

TEST(GranularEngine, RoughDisksReachTheMeanFieldTemperatureRatio2D) {
  check_rough_cooling_state<2>(32, 0.9, 0.5, 0.06);
}

// beta = -1 leaves spins alone: a rough run with beta = -1 and spinning particles follows the
// smooth run exactly (positions and velocities bit for bit), and no spin changes.
TEST(GranularEngine, BetaMinusOneReproducesSmoothSpheresExactly) {
  constexpr int D = 3;
  ParticleSystem<D> start = thermalised_gas<D>(8, 0.1, 5);
  EventEngine<D, CalendarQueue> smooth(start, StartMode::kPredict, EngineOptions{},
                                       uniform_contact<D>(inelastic(0.8)));
  start.angular_velocity.resize(start.size());
  for (std::size_t i = 0; i < start.size(); ++i)
    start.angular_velocity[i] = {0.1 * static_cast<double>(i % 7), -0.3, 0.05};
  EventEngine<D, CalendarQueue> rough_run(start, StartMode::kPredict, EngineOptions{},
                                          uniform_contact<D>(rough(0.8, -1.0)));
  for (int k = 0; k < 20000; ++k) {
    ASSERT_EQ(smooth.step(), rough_run.step());
  }
  const ParticleSystem<D> a = smooth.export_state(), b = rough_run.export_state();
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a.kinematics[i].pos, b.kinematics[i].pos) << i;
    ASSERT_EQ(a.kinematics[i].vel, b.kinematics[i].vel) << i;
    ASSERT_EQ(b.angular_velocity[i], start.angular_velocity[i]) << i;
  }
}

// The collisional pressure tensor: its trace is the scalar virial to round-off; for smooth
// particles (impulses along the line of centres) it is symmetric, for rough ones its
// antisymmetric part carries the torques.
TEST(GranularEngine, VirialTensorTraceIsTheVirial) {
  constexpr int D = 3;
  for (const double beta : {-1.0, 0.6}) {
    const ParticleSystem<D> start = thermalised_gas<D>(8, 0.2, 9);
    EventEngine<D, CalendarQueue> engine(start, StartMode::kPredict, EngineOptions{},
                                         uniform_contact<D>(rough(0.9, beta)));
    for (int k = 0; k < 20000; ++k) ASSERT_NE(engine.step(), EventKind::kNone);
    const auto& c = engine.counters();
    const auto& w = c.virial_tensor;
    EXPECT_NEAR(w[0] + w[4] + w[8], c.virial, 1e-10 * std::abs(c.virial));
    const double asym = std::abs(w[1] - w[3]) + std::abs(w[2] - w[6]) + std::abs(w[5] - w[7]);
    if (beta == -1.0) {
      EXPECT_LT(asym, 1e-10 * std::abs(c.virial));
    } else {
      EXPECT_GT(asym, 1e-6 * std::abs(c.virial));
    }
  }
}

}  // namespace
}  // namespace kairos
