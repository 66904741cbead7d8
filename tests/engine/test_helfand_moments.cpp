// The Helfand moments (engine/helfand_moments.hpp) are exact: for a cluster of particles in the
// middle of a large periodic box, where no particle meets a face so that every pair's minimum
// image is its plain separation, the moments equal the direct sums over particles,
//   G_ab(t) - G_ab(0) = [sum_i m_i x_ia v_ib]_0^t,   G_a(t) - G_a(0) = [sum_i x_ia e_i]_0^t,
// to round-off, for hard spheres and disks of two masses and sizes, rough spheres (the energy
// with its rotational part), a stepped potential (the energy with half of each pair's) and
// elastic soft spheres (the Müller–Pöschel map moves a pair at once: compared when no contact
// is in progress, with frozen and deferred releases). Keeping them changes no bit of the
// trajectory.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "engine/event_engine.hpp"
#include "engine_fixtures.hpp"
#include "interactions/granular_contact.hpp"
#include "interactions/soft_contact.hpp"
#include "interactions/step_potential.hpp"
#include "scheduler/calendar_queue.hpp"

namespace kairos {
namespace {

template <int D>
using Engine = EventEngine<D, CalendarQueue>;

// A lattice cluster at packing fraction eta in the middle of a box `factor` times its size.
template <int D>
ParticleSystem<D> cluster(int n, double eta, std::uint64_t seed, double mass_ratio,
                          double diameter_ratio, double factor = 5.0) {
  ParticleSystem<D> s = testing::lattice_system<D>(n, eta, seed, mass_ratio, diameter_ratio);
  const double shift = 0.5 * (factor - 1.0) * s.box[0];
  for (auto& k : s.kinematics)
    for (int a = 0; a < D; ++a) k.pos[a] += shift;
  s.box.fill(factor * s.box[0]);
  return s;
}

template <int D>
double spin_energy(const ParticleSystem<D>& s, const Environment<D>& env, std::size_t i) {
  if (s.angular_velocity.empty()) return 0.0;
  const double r = s.kinematics[i].radius;
  const std::uint32_t species = s.species.empty() ? 0u : s.species[i];
  return 0.5 * env.inertia_factor_of(species) * s.mass[i] * r * r * norm2(s.angular_velocity[i]);
}

// sum m x_a v_b (row-major) and sum x_a e_i, e_i with half of each listed pair's zone energy.
template <int D>
struct DirectSums {
  std::array<double, 9> momentum{};
  Vec<D> energy{};
  double scale = 0.0;  // of the terms, for the tolerance
};

template <int D>
DirectSums<D> direct_sums(const ParticleSystem<D>& s, const Environment<D>& env) {
  std::vector<double> share(s.size(), 0.0);
  if (s.zones) {
    for (const PairZone& z : *s.zones) {
      const double u = env.tables[0].energy[z.zone - 1];
      share[z.i] += 0.5 * u;
      share[z.j] += 0.5 * u;
    }
  }
  DirectSums<D> d;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const Vec<D> x = s.position(i, s.time), v = s.velocity(i, s.time);
    const double e = 0.5 * s.mass[i] * norm2(v) + spin_energy(s, env, i) + share[i];
    for (int a = 0; a < D; ++a) {
      EXPECT_TRUE(s.image.empty() || s.image[i][a] == 0) << "particle " << i << " wrapped";
      for (int b = 0; b < D; ++b) d.momentum[a * D + b] += s.mass[i] * x[a] * v[b];
      d.energy[a] += x[a] * e;
      d.scale = std::max(d.scale, std::abs(s.mass[i] * x[a] * v[a]) + std::abs(x[a] * e));
    }
  }
  d.scale *= static_cast<double>(s.size());
  return d;
}

// The sums as the moments count them while soft contacts are in progress (from the exported
// state's contacts): a deferred pair's records already move as after its release (back from
// its release position), a frozen pair moves with its centre of mass and holds its relative
// kinetic energy, m_k |v_k' - V|^2 / 2 per particle.
template <int D>
DirectSums<D> direct_sums_in_contact(ParticleSystem<D> s, const Environment<D>& env) {
  std::vector<double> held(s.size(), 0.0);
  for (const FrozenContact<D>& c : s.frozen) {
    EXPECT_NE(c.j, FrozenContact<D>::kWall);
    const std::uint32_t ids[2] = {c.i, c.j};
    const Vec<D> after[2] = {c.velocity_i, c.velocity_j};
    const Vec<D> at[2] = {c.release_position_i, c.release_position_j};
    for (int side = 0; side < 2; ++side) {
      Kinematics<D>& k = s.kinematics[ids[side]];
      if (c.deferred) {
        k = Kinematics<D>{at[side], after[side], c.release_time, k.radius};
      } else {
        held[ids[side]] = 0.5 * s.mass[ids[side]] * norm2(after[side] - k.vel);
      }
    }
  }
  DirectSums<D> d = direct_sums(s, env);
  for (std::size_t i = 0; i < s.size(); ++i) {
    const Vec<D> x = s.position(i, s.time);
    for (int a = 0; a < D; ++a) d.energy[a] += x[a] * held[i];
  }
  return d;
}

// Runs the cluster with the moments kept until its fastest particle could reach a face, and
// compares them with the sums. With `in_contact` the moments start from a state with soft
// contacts in progress: a run without them until some are, continued from its exported state.
template <int D>
void moments_equal_direct_sums(ParticleSystem<D> s, const Environment<D>& env,
                               EngineOptions options = {}, bool in_contact = false) {
  options.track_images = true;
  options.renumber_interval = 0.5;  // the per-particle shares follow the renumbering
  StartMode mode = StartMode::kPredict;
  if (in_contact) {
    Engine<D> before(s, StartMode::kPredict, options, env);
    for (int e = 0; e < 100000 && before.frozen() < 4; ++e) before.step();
    ASSERT_GE(before.frozen(), 4u) << "no contacts in progress to start from";
    s = before.export_state();
    mode = StartMode::kResume;
  }
  options.track_helfand = true;
  Engine<D> engine(s, mode, options, env);
  const ParticleSystem<D> first = engine.export_state();
  if (in_contact) {
    ASSERT_GE(first.frozen.size(), 2u);
  }
  const auto virial0 = engine.counters().virial_tensor;
  const auto m0 = engine.helfand_moments();
  const DirectSums<D> d0 =
      in_contact ? direct_sums_in_contact(first, env) : direct_sums(first, env);
  const std::uint64_t collisions0 = engine.counters().collisions;
  // Collisions can speed particles up: the positions are looked at every few events.
  const auto near_a_face = [&] {
    const ParticleSystem<D> now = engine.export_state(false);
    for (std::size_t i = 0; i < now.size(); ++i) {
      const Vec<D> x = now.position(i, now.time);
      for (int a = 0; a < D; ++a)
        if (x[a] < 4.0 || x[a] > now.box[a] - 4.0) return true;
    }
    return false;
  };
  for (int e = 1; e < 200000 && !(e % 32 == 0 && near_a_face()); ++e) engine.step();
  // Soft spheres: the moments are the sums once no contact is in progress.
  for (int e = 0; e < 1000 && engine.soft() && engine.frozen() > 0; ++e) engine.step();
  ASSERT_EQ(engine.frozen(), 0u);
  // Soft spheres: the mapped contacts happened (not only instantaneous fallbacks).
  if (engine.soft()) {
    EXPECT_GT(engine.counters().soft_contacts, s.size());
  }
  const ParticleSystem<D> last = engine.export_state();
  // Still clear of the faces: minimum images are plain separations.
  for (std::size_t i = 0; i < last.size(); ++i) {
    const Vec<D> x = last.position(i, last.time);
    for (int a = 0; a < D; ++a) {
      ASSERT_GT(x[a], 1.0) << "the cluster reached a face: fewer events";
      ASSERT_LT(x[a], last.box[a] - 1.0) << "the cluster reached a face: fewer events";
    }
  }
  EXPECT_GT(engine.counters().collisions - collisions0, static_cast<std::uint64_t>(s.size()));
  const DirectSums<D> d1 = direct_sums(last, env);
  const auto m1 = engine.helfand_moments();
  const auto& virial1 = engine.counters().virial_tensor;
  const double tolerance = 1e-12 * std::max(d0.scale, d1.scale);
  for (int a = 0; a < D; ++a) {
    for (int b = 0; b < D; ++b) {
      const int k = a * D + b;
      const double moment = m1.kinetic_stress[k] - m0.kinetic_stress[k] + virial1[k] - virial0[k] +
                            m1.jump_stress[k] - m0.jump_stress[k];
      EXPECT_NEAR(moment, d1.momentum[k] - d0.momentum[k], tolerance) << a << b;
    }
    const double energy = m1.kinetic_energy_flux[a] - m0.kinetic_energy_flux[a] +
                          m1.collisional_energy_flux[a] - m0.collisional_energy_flux[a];
    EXPECT_NEAR(energy, d1.energy[a] - d0.energy[a], tolerance) << a;
    // The moments moved: a test of something.
    EXPECT_GT(std::abs(d1.energy[a] - d0.energy[a]), 1e3 * tolerance);
  }
}

TEST(HelfandMoments, EqualTheDirectSumsHardSpheres3D) {
  moments_equal_direct_sums<3>(cluster<3>(6, 0.3, 11, 2.0, 1.3), Environment<3>{});
}

TEST(HelfandMoments, EqualTheDirectSumsHardDisks2D) {
  moments_equal_direct_sums<2>(cluster<2>(14, 0.4, 12, 0.5, 1.2), Environment<2>{});
}

TEST(HelfandMoments, EqualTheDirectSumsRoughSpheresWithTheirSpin) {
  Environment<3> env;
  env.species = 2;
  ContactModel rough;
  rough.tangential = TangentialModel::constant(1.0);  // perfectly rough, elastic
  env.contact.assign(4, rough);
  ParticleSystem<3> s = cluster<3>(6, 0.3, 13, 1.0, 1.0);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  s.angular_velocity.resize(s.size());
  for (auto& w : s.angular_velocity) w = {u(rng), u(rng), u(rng)};
  moments_equal_direct_sums<3>(s, env);
}

TEST(HelfandMoments, EqualTheDirectSumsWithTheShareOfEachPairsEnergy) {
  Environment<3> env;
  env.species = 2;
  StepTable steps;  // a well of two steps and a shoulder inside it (contact distance 1)
  steps.boundary = {1.6, 1.3, 1.1, 1.0};
  steps.energy = {-0.4, -1.0, 0.5};
  env.tables = {steps};
  env.pair_table = {0, 0, 0, 0};
  moments_equal_direct_sums<3>(cluster<3>(6, 0.3, 14, 1.0, 1.0), env);
  Environment<2> env2;
  env2.species = 2;
  env2.tables = {steps};
  env2.pair_table = {0, 0, 0, 0};
  moments_equal_direct_sums<2>(cluster<2>(14, 0.35, 15, 1.0, 1.0), env2);
}

// Elastic soft spheres (no table: every map integrated directly). The lever-arm virial alone
// misses the pair's displacement during a contact: the test fails without jump_stress.
template <int D>
Environment<D> elastic_soft(const SoftContactLaw& law) {
  Environment<D> env;
  env.species = 2;
  env.soft.assign(4, law);
  return env;
}

TEST(HelfandMoments, EqualTheDirectSumsSoftSpheresWithDeferredReleases) {
  const SoftContactLaw hertz = SoftContactLaw::viscoelastic_hertz(2.0e3, 0.0);
  moments_equal_direct_sums<3>(cluster<3>(6, 0.3, 16, 2.0, 1.3), elastic_soft<3>(hertz));
  const SoftContactLaw spring = SoftContactLaw::linear_dashpot(1.0e3, 0.0);
  moments_equal_direct_sums<2>(cluster<2>(14, 0.4, 17, 0.5, 1.2), elastic_soft<2>(spring));
}

TEST(HelfandMoments, StartedWithSoftContactsInProgressEqualTheDirectSums) {
  const SoftContactLaw hertz = SoftContactLaw::viscoelastic_hertz(2.0e3, 0.0);
  moments_equal_direct_sums<3>(cluster<3>(6, 0.3, 16, 2.0, 1.3), elastic_soft<3>(hertz), {}, true);
  EngineOptions frozen;
  frozen.defer_soft_releases = false;
  const SoftContactLaw spring = SoftContactLaw::linear_dashpot(1.0e3, 0.0);
  moments_equal_direct_sums<2>(cluster<2>(14, 0.4, 19, 0.5, 1.2), elastic_soft<2>(spring), frozen,
                               true);
}

TEST(HelfandMoments, EqualTheDirectSumsSoftSpheresWithReleaseEvents) {
  EngineOptions frozen;
  frozen.defer_soft_releases = false;  // every contact waits for its release event
  const SoftContactLaw hertz = SoftContactLaw::viscoelastic_hertz(2.0e3, 0.0);
  moments_equal_direct_sums<3>(cluster<3>(6, 0.3, 18, 2.0, 1.3), elastic_soft<3>(hertz), frozen);
  const SoftContactLaw spring = SoftContactLaw::linear_dashpot(1.0e3, 0.0);
  moments_equal_direct_sums<2>(cluster<2>(14, 0.4, 19, 0.5, 1.2), elastic_soft<2>(spring), frozen);
}

// Runs `events` events with and without the moments and compares the two runs bit for bit;
// returns the mapped soft contacts they had.
std::uint64_t same_run_with_and_without(const ParticleSystem<3>& s, const Environment<3>& env,
                                        int events) {
  EngineOptions kept;
  kept.track_helfand = true;
  Engine<3> with(s, StartMode::kPredict, kept, env);
  Engine<3> without(s, StartMode::kPredict, EngineOptions{}, env);
  for (int e = 0; e < events; ++e) {
    with.step();
    without.step();
  }
  const ParticleSystem<3> a = with.export_state(), b = without.export_state();
  EXPECT_EQ(a.time, b.time);
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a.kinematics[i].pos, b.kinematics[i].pos) << i;
    EXPECT_EQ(a.kinematics[i].vel, b.kinematics[i].vel) << i;
  }
  EXPECT_EQ(with.counters().virial_tensor, without.counters().virial_tensor);
  return with.counters().soft_contacts;
}

TEST(HelfandMoments, KeepingThemChangesNoBitOfTheRun) {
  same_run_with_and_without(testing::lattice_system<3>(6, 0.4, 21, 2.0, 1.3), Environment<3>{},
                            20000);
}

TEST(HelfandMoments, KeepingThemChangesNoBitOfASoftRun) {
  const Environment<3> env = elastic_soft<3>(SoftContactLaw::viscoelastic_hertz(2.0e3, 0.0));
  EXPECT_GT(same_run_with_and_without(testing::lattice_system<3>(6, 0.2, 22, 2.0, 1.3), env, 5000),
            1000u);
}

}  // namespace
}  // namespace kairos
