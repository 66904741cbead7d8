// Step tables and the step event rule against the independent numbers of formulas.md: the step
// events of §7.7, the stepped Lennard-Jones table of §7.9 (boundaries, volume-averaged and
// virial energies) and the square-well B2 of §4.1 / §7.9.
#include <gtest/gtest.h>

#include <cmath>

#include "core/error.hpp"
#include "interactions/step_potential.hpp"

namespace kairos {
namespace {

// §7.7: m_i = 1, m_j = 3 (mu = 3/4), r along x, so v_n is the x component of g (r / |r| = +x).
TEST(StepEvent, CrossesOrBouncesWithTheReferenceImpulses) {
  const double mu = 0.75;
  const StepOutcome a = step_event(mu, -1.0, -1.0);
  EXPECT_TRUE(a.crosses);
  EXPECT_NEAR(a.impulse, -0.6861406616, 1e-10);
  const StepOutcome b = step_event(mu, -1.2, 0.5);
  EXPECT_TRUE(b.crosses);
  EXPECT_NEAR(b.impulse, 0.6550510257, 1e-10);
  const StepOutcome c = step_event(mu, -0.8, 0.5);
  EXPECT_FALSE(c.crosses);
  EXPECT_NEAR(c.impulse, 1.2, 1e-12);
  const StepOutcome d = step_event(mu, 0.9, 0.1);
  EXPECT_TRUE(d.crosses);
  EXPECT_NEAR(d.impulse, -0.1221663903, 1e-10);
}

// At the critical speed v_n^2 = 2 dU / mu the pair just crosses (to rest along n); a hair
// slower, it bounces. Energy is conserved either way.
TEST(StepEvent, ThresholdIsExactAndEnergyConserved) {
  const double mu = 0.5, du = 0.3;
  // The smallest speed whose square reaches 2 dU / mu in floating point.
  double critical = std::sqrt(2.0 * du / mu);
  while (critical * critical < 2.0 * du / mu) critical = std::nextafter(critical, 10.0);
  while (std::nextafter(critical, 0.0) * std::nextafter(critical, 0.0) >= 2.0 * du / mu)
    critical = std::nextafter(critical, 0.0);
  EXPECT_TRUE(step_event(mu, -critical, du).crosses);
  EXPECT_FALSE(step_event(mu, -std::nextafter(critical, 0.0), du).crosses);
  for (const double v : {-3.0, -1.2, 0.7, 2.5}) {
    const StepOutcome s = step_event(mu, v, du);
    const double after = v + s.impulse / mu;
    EXPECT_NEAR(0.5 * mu * after * after + (s.crosses ? du : 0.0), 0.5 * mu * v * v, 1e-13);
  }
}

// §7.9: shifted LJ cut at 3, 4 attractive equal-energy steps.
TEST(StepTableFromLennardJones, MatchesTheReferenceBoundariesAndEnergies) {
  const ContinuousPotential lj = lennard_jones(1.0, 1.0, 3.0, true);
  EXPECT_NEAR(lj.u(lj.r_min), -0.9945205583, 1e-10);
  const double boundaries[] = {3.0,          1.5645719186, 1.3758643336, 1.2593458744,
                               1.1224620483, 1.0492750505, 1.0269371209, 1.0118379421};
  const double volume[] = {-0.0321811894, -0.3533047721, -0.6121565654, -0.8891870058,
                           -0.9237530815, -0.6326889172, -0.3798908979};
  const double virial[] = {-0.0333958242, -0.3558458097, -0.6147469258, -0.8921877674,
                           -0.9262178250, -0.6352429381, -0.3824540247};
  const StepTable tv = step_by_energy(lj, 4, 5.0, StepEnergyRule::kVolumeAverage);
  const StepTable tb = step_by_energy(lj, 4, 5.0, StepEnergyRule::kVirial, 1.0);
  ASSERT_GE(tv.boundary.size(), 8u);
  for (int k = 0; k < 8; ++k) EXPECT_NEAR(tv.boundary[k], boundaries[k], 1e-9) << k;
  for (int k = 0; k < 7; ++k) {
    EXPECT_NEAR(tv.energy[k], volume[k], 1e-9) << k;
    EXPECT_NEAR(tb.energy[k], virial[k], 1e-9) << k;
  }
  // On up the repulsive branch in steps of dU to the core level.
  const double du = 0.9945205583 / 4;
  for (std::size_t k = 8; k + 1 < tv.boundary.size(); ++k)
    EXPECT_GT(lj.u(tv.boundary[k]), lj.u(tv.boundary[k - 1]) + 0.5 * du);
  EXPECT_NEAR(lj.u(tv.core()), 5.0, 1e-9);
}

// The virial rule keeps every shell's B2 contribution: the table's B2 equals the continuous
// potential's (outside the core) at that temperature.
TEST(StepTableFromLennardJones, VirialEnergiesKeepB2) {
  const ContinuousPotential lj = lennard_jones(1.0, 1.0, 3.0, true);
  const double kT = 1.5;
  const StepTable t = step_by_energy(lj, 6, 8.0, StepEnergyRule::kVirial, kT);
  // B2 of the continuous potential, with the same hard core, by quadrature.
  double integral = 0.0;
  const int n = 200000;
  const double a = t.core(), b = t.cutoff(), h = (b - a) / n;
  for (int i = 0; i < n; ++i) {
    const double r = a + (i + 0.5) * h;
    integral += -std::expm1(-lj.u(r) / kT) * r * r * h;
  }
  const double b2 = 2.0 * M_PI / 3.0 * a * a * a + 2.0 * M_PI * integral;
  EXPECT_NEAR(second_virial(t, kT), b2, 1e-6 * std::abs(b2));
}

TEST(SquareWell, SecondVirialCoefficientMatchesTheExactValues) {
  const StepTable sw = square_well(1.0, 1.5, 1.0);
  EXPECT_NEAR(second_virial(sw, 1.0), -6.4526623820, 1e-9);
  EXPECT_NEAR(second_virial(sw, 2.0), -1.1324666965, 1e-9);
  EXPECT_NEAR(second_virial(sw, 5.0), 0.9930960781, 1e-9);
  EXPECT_EQ(sw.energy_at(1.2), -1.0);
  EXPECT_EQ(sw.energy_at(1.6), 0.0);
  EXPECT_TRUE(std::isinf(sw.energy_at(0.9)));
}

TEST(StepTable, BadTablesAreRejectedWithAReason) {
  EXPECT_THROW((StepTable{{1.0, 1.5}, {-1.0}}.check()), InputError);          // increasing
  EXPECT_THROW((StepTable{{1.5, 1.0}, {-1.0, 2.0}}.check()), InputError);     // count
  EXPECT_THROW((StepTable{{1.5, 1.0}, {std::nan("")}}.check()), InputError);  // NaN
  EXPECT_THROW((StepTable{{1.5}, {}}.check()), InputError);                   // no core
  EXPECT_NO_THROW((StepTable{{2.0, 1.5, 1.0}, {-0.5, 1.0}}.check()));
}

}  // namespace
}  // namespace kairos
