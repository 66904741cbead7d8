// The soft-sphere proofs of issue 6, shortened (the full measurements: validation/soft_proofs,
// docs/validation.md "Soft spheres in the engine"):
// - a dilute gas run by the mapped event-driven engine follows the DEM reference (particle
//   positions) longer than the instantaneous hard-sphere model with the same head-on restitution;
// - grazing collisions (docs/physics.md#hard-sphere-failure): against the initial normal the
//   outgoing normal velocity keeps its sign (negative effective restitution) under the mapped
//   engine and the DEM, as Newton's equations say, while the hard model gives +e; its outgoing
//   direction is degrees off.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "../../validation/soft_proofs.hpp"

namespace kairos {
namespace {

using namespace proofs;

// N = 500 at packing fraction 0.05, viscoelastic Hertz with l~ = 200 and c_dis = 0.1 at normal
// speed 1 (head-on e = 0.85, contact time ~ mean free time / 100), DEM at t_c / 500, maps
// integrated directly (no tables: exact to ~1e-13). Measured at N = 1000 (docs/validation.md):
// until the first exception every particle is within a few 1e-6 radii of the DEM; the typical
// (median) particle stays below 1e-5 radius for more than a mean free time, while the hard
// model's median particle is off by ~5e-2 radius once it has collided.
TEST(SoftProofs, GasTrajectoriesFollowTheDemLongerThanHardSpheres) {
  GasSpec spec;
  spec.particles = 500;
  spec.model = SoftModel::ViscoelasticHertz;
  spec.l_tilde = 200.0;
  spec.c_dis = 0.1;
  spec.seed = 3;
  GasRunOptions options;
  options.t_end = 2.4;  // ~1.6 mean free times
  options.samples = 24;
  options.dem_steps_per_contact = 500.0;
  options.dem_check = false;
  options.tables = false;
  const GasRun run = run_gas_divergence(spec, options);

  int clean_samples = 0;  // with collisions, before the mapped engine's first exception
  const GasSample* late = nullptr;
  for (const GasSample& s : run.samples) {
    std::printf(
        "t = %.2f c = %.3f exceptions %llu+%llu | mapped rms %.2e median %.2e max %.2e | hard "
        "rms %.2e median %.2e max %.2e\n",
        s.time, s.collisions_per_particle, static_cast<unsigned long long>(s.overlap_fallbacks),
        static_cast<unsigned long long>(s.early_releases), s.mapped.rms, s.mapped.median,
        s.mapped.max, s.hard.rms, s.hard.median, s.hard.max);
    ASSERT_GT(s.mapped.compared, 0.9 * spec.particles);
    if (s.overlap_fallbacks + s.early_releases == 0 && s.collisions_per_particle > 0.0) {
      // Every collision so far was an isolated binary one, exact after its contact: every
      // particle agrees with the DEM to its integration error; the hard model's worst does not.
      ++clean_samples;
      EXPECT_LT(s.mapped.max, 1e-4) << "t = " << s.time;
      EXPECT_GT(s.hard.max, 1e-3) << "t = " << s.time;
    }
    if (late == nullptr && s.collisions_per_particle >= 1.2) late = &s;
  }
  EXPECT_GE(clean_samples, 1);
  // After 1.2 mean free times, most particles have collided: the typical particle still follows
  // the DEM closely under the mapping, and is far off under the hard model.
  ASSERT_NE(late, nullptr);
  EXPECT_LT(late->mapped.median, 1e-4);
  EXPECT_GT(late->hard.median, 3e-3);
  EXPECT_LT(late->mapped.rms, late->hard.rms);
}

struct GrazingCase {
  SoftModel model;
  double c_dis;
  // docs/physics.md#hard-sphere-failure at v_t / v_n = 20, l~ = 100 and 1000
  double e_eff_100, e_eff_1000;
};

class SoftGrazing : public ::testing::TestWithParam<GrazingCase> {};

// docs/physics.md#hard-sphere-failure: at l~ = 100 and 1000, v_t / v_n = 20,
// e_eff = -0.95 / -0.08 (dashpot, head-on e 0.74) and -0.99 / -0.11 (Hertz, 0.85); every method
// from the same state, unequal masses and radii, the centre of mass moving.
TEST_P(SoftGrazing, GrazingCollisionsReverseTheNormalVelocityUnlikeHardSpheres) {
  const GrazingCase c = GetParam();
  for (const double l_tilde : {100.0, 1000.0}) {
    BinarySpec spec;
    spec.model = c.model;
    spec.l_tilde = l_tilde;
    spec.c_dis = c.c_dis;
    spec.ratio = 20.0;
    spec.dem_steps_per_contact = 4000.0;
    const BinaryResult r = binary_collision(spec);
    const double quoted = l_tilde == 100.0 ? c.e_eff_100 : c.e_eff_1000;
    std::printf("%s l~ = %g: e_eff exact %.6f mapped %.6f DEM %.6f hard %.6f (head-on %.4f)\n",
                model_name(c.model), l_tilde, r.exact.e_eff, r.mapped.e_eff, r.dem.e_eff,
                r.hard.e_eff, r.head_on_restitution);
    EXPECT_NEAR(r.exact.e_eff, quoted, 0.005 + 0.005 * std::abs(quoted));
    EXPECT_LT(r.mapped.e_eff, 0.0);
    EXPECT_LT(r.dem.e_eff, 0.0);
    EXPECT_NEAR(r.mapped.e_eff, r.exact.e_eff, 1e-9);
    EXPECT_NEAR(r.dem.e_eff, r.exact.e_eff, 1e-5);
    EXPECT_NEAR(r.hard.e_eff, r.head_on_restitution, 1e-6);
    EXPECT_GT(r.hard.e_eff, 0.7);
  }
}

// Over v_t / v_n = 0.01 ... 100 at l~ = 100: the mapped engine's outgoing relative velocity is
// Newton's (direct integration) to round-off and the DEM's within its time-step error, while the
// hard model's direction is off by degrees for oblique collisions; e_eff falls from the head-on e
// through zero (at v_t / v_n ~ 6) to about -1, the hard model's stays +e.
TEST_P(SoftGrazing, OutgoingDirectionAgainstNewtonOverTheTangentialRatio) {
  const GrazingCase c = GetParam();
  double worst_hard = 0.0, previous = 2.0;
  for (int k = 0; k <= 8; ++k) {
    BinarySpec spec;
    spec.model = c.model;
    spec.l_tilde = 100.0;
    spec.c_dis = c.c_dis;
    spec.ratio = std::pow(10.0, -2.0 + 0.5 * k);
    spec.dem_steps_per_contact = 2000.0;
    const BinaryResult r = binary_collision(spec);
    const double deg = 180.0 / M_PI;
    const double hard = direction_error(r.hard, r.exact) * deg;
    const double mapped = direction_error(r.mapped, r.exact) * deg;
    const double dem = direction_error(r.dem, r.exact) * deg;
    std::printf(
        "%s v_t/v_n = %7.3f: e_eff %+.5f (hard %+.5f); direction error hard %.3e mapped %.1e DEM "
        "%.1e deg\n",
        model_name(c.model), spec.ratio, r.exact.e_eff, r.hard.e_eff, hard, mapped, dem);
    EXPECT_LT(mapped, 1e-8) << spec.ratio;
    EXPECT_LT(dem, 1e-4) << spec.ratio;
    EXPECT_NEAR(r.mapped.e_eff, r.exact.e_eff, 1e-9) << spec.ratio;
    EXPECT_NEAR(r.hard.e_eff, r.head_on_restitution, 1e-6) << spec.ratio;
    EXPECT_LT(r.exact.e_eff, previous) << spec.ratio;  // monotonic in the ratio
    previous = r.exact.e_eff;
    const Vec<3> box{12.0, 12.0, 12.0};
    EXPECT_LT(position_error(r.mapped, r.exact, box, 1.0), 1e-9) << spec.ratio;
    worst_hard = std::max(worst_hard, hard);
  }
  EXPECT_LT(previous, -0.95);  // at v_t / v_n = 100
  EXPECT_GT(worst_hard, 5.0);  // degrees, near v_t / v_n ~ 10
}

INSTANTIATE_TEST_SUITE_P(
    BothLaws, SoftGrazing,
    ::testing::Values(GrazingCase{SoftModel::LinearDashpot, 0.2, -0.95, -0.08},
                      GrazingCase{SoftModel::ViscoelasticHertz, 0.1, -0.99, -0.11}),
    [](const auto& p) { return p.param.model == SoftModel::LinearDashpot ? "Dashpot" : "Hertz"; });

}  // namespace
}  // namespace kairos
