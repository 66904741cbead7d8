// Step tables and the step event rule against independent numbers: the step events of
// docs/physics.md#step-event, the stepped Lennard-Jones table of
// docs/physics.md#stepping-continuous-potentials (boundaries, volume-averaged and virial
// energies) and the square-well B2 of docs/physics.md#second-virial-coefficient; then the
// continuous potentials, the three placements (against closed-form level crossings, equal widths
// and volumes), the energy rules in 2D and 3D against closed-form integrals, B2 of tables against
// B2 of their potentials, tabulated files and their errors, bonds, and the report.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <limits>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "input_error_matchers.hpp"
#include "interactions/step_potential.hpp"

namespace kairos {
namespace {

// docs/physics.md#step-event: m_i = 1, m_j = 3 (mu = 3/4), r along x, so v_n is the x component
// of g (r / |r| = +x).
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

// docs/physics.md#stepping-continuous-potentials: shifted LJ cut at 3, 4 attractive
// equal-energy steps.
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

// ---------------------------------------------------------------------------------------------
// Helpers.

constexpr double kPi = std::numbers::pi;
constexpr double kInf = std::numeric_limits<double>::infinity();

// Unshifted Lennard-Jones, written out here independently of the library.
double lj(double r) {
  return 4.0 * (std::pow(r, -12) - std::pow(r, -6));
}

// Where unshifted LJ (eps = sigma = 1) equals v: r = (2 / (1 -+ sqrt(1 + v)))^(1/6), the outer
// root with the minus sign (v < 0 only), the inner one with the plus sign.
double lj_outer_root(double v) {
  return std::pow(2.0 / (1.0 - std::sqrt(1.0 + v)), 1.0 / 6.0);
}
double lj_inner_root(double v) {
  return std::pow(2.0 / (1.0 + std::sqrt(1.0 + v)), 1.0 / 6.0);
}

// B2 of U with a hard core below `core` by a plain midpoint sum, independent of the library's
// quadrature: (S_d / 2) [core^d / d + int (1 - exp(-U/kT)) r^(d-1) dr].
double brute_b2(const std::function<double(double)>& u, double core, double cutoff, double kT,
                int d) {
  const int n = 400000;
  const double h = (cutoff - core) / n;
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    const double r = core + (i + 0.5) * h;
    sum += -std::expm1(-u(r) / kT) * std::pow(r, d - 1) * h;
  }
  return (d == 3 ? 2.0 * kPi : kPi) * (std::pow(core, d) / d + sum);
}

std::string write_file(const std::string& name, const std::string& text) {
  const std::string path = (std::filesystem::path(testing::TempDir()) / name).string();
  std::ofstream(path) << text;
  return path;
}

// ---------------------------------------------------------------------------------------------
// Continuous potentials.

TEST(ContinuousPotentials, FactoriesGiveTheirFormulas) {
  const double root6 = std::pow(2.0, 1.0 / 6.0);
  const ContinuousPotential w = wca(2.0, 1.5);
  EXPECT_DOUBLE_EQ(w.cutoff, root6 * 1.5);
  EXPECT_EQ(w.r_min, 0.0);
  EXPECT_NEAR(w.u(1.5), 2.0, 1e-12);       // 4 eps (1 - 1) + eps
  EXPECT_NEAR(w.u(w.cutoff), 0.0, 1e-12);  // -eps + eps
  EXPECT_NEAR(w.u(1.2), 8.0 * (std::pow(1.25, 12) - std::pow(1.25, 6)) + 2.0, 1e-9);

  const ContinuousPotential y = yukawa(3.0, 1.0, 2.0, 2.5, false);
  EXPECT_NEAR(y.u(1.0), 3.0, 1e-14);
  EXPECT_NEAR(y.u(2.0), 3.0 / 2.0 * std::exp(-2.0), 1e-14);
  const ContinuousPotential ys = yukawa(-1.0, 1.0, 0.5, 3.0, true);
  EXPECT_NEAR(ys.u(3.0), 0.0, 1e-15);
  EXPECT_NEAR(ys.u(1.5), -std::exp(-0.25) / 1.5 + std::exp(-1.0) / 3.0, 1e-14);
  EXPECT_EQ(ys.r_min, 0.0);

  const ContinuousPotential m = morse(2.0, 1.2, 3.0, 4.0, false);
  EXPECT_DOUBLE_EQ(m.r_min, 1.2);
  EXPECT_NEAR(m.u(1.2), -2.0, 1e-14);
  EXPECT_NEAR(m.u(1.0), 2.0 * (std::pow(1.0 - std::exp(0.6), 2) - 1.0), 1e-12);
  const ContinuousPotential ms = morse(2.0, 1.2, 3.0, 4.0, true);
  EXPECT_NEAR(ms.u(4.0), 0.0, 1e-15);
  EXPECT_NEAR(ms.u(1.2) - m.u(1.2), -m.u(4.0), 1e-15);

  const ContinuousPotential s = harmonic_spring(10.0, 1.3, 1.6);
  EXPECT_NEAR(s.u(1.5), 5.0 * 0.04, 1e-14);
  EXPECT_EQ(s.beyond, kInf);
  EXPECT_DOUBLE_EQ(s.r_min, 1.3);
  EXPECT_DOUBLE_EQ(s.cutoff, 1.6);
}

TEST(ContinuousPotentials, BadParametersAreRejected) {
  EXPECT_INPUT_ERROR(wca(0.0, 1.0), "wca: eps must be finite and > 0");
  EXPECT_INPUT_ERROR(lennard_jones(1.0, -1.0, 2.5, true),
                     "lennard_jones: sigma must be finite and > 0");
  EXPECT_INPUT_ERROR(yukawa(0.0, 1.0, 1.0, 3.0, true), "yukawa: eps must be finite and non-zero");
  EXPECT_INPUT_ERROR(yukawa(1.0, 1.0, -1.0, 3.0, true), "yukawa: kappa");
  EXPECT_INPUT_ERROR(morse(1.0, 1.0, 0.0, 3.0, true), "morse: alpha must be finite and > 0");
  EXPECT_INPUT_ERROR(harmonic_spring(1.0, 2.0, 1.5), "spring: length 2 must be shorter");
}

// ---------------------------------------------------------------------------------------------
// Placements.

TEST(StepPlacement, EqualDistanceGivesEqualWidths) {
  const ContinuousPotential p = lennard_jones(1.0, 1.0, 2.5, true);
  const StepTable t =
      step_potential(p, StepPlacement::kDistance, 12, 0.95, StepEnergyRule::kMidpoint);
  ASSERT_EQ(t.boundary.size(), 13u);
  EXPECT_EQ(t.cutoff(), 2.5);
  EXPECT_EQ(t.core(), 0.95);
  for (std::size_t k = 0; k + 1 < t.boundary.size(); ++k)
    EXPECT_NEAR(t.boundary[k] - t.boundary[k + 1], (2.5 - 0.95) / 12, 1e-14) << k;
  // Midpoint energies are U at the middle of each shell.
  for (std::size_t k = 0; k < t.energy.size(); ++k) {
    EXPECT_NEAR(t.energy[k], lj(0.5 * (t.boundary[k] + t.boundary[k + 1])) - lj(2.5), 1e-12);
  }
}

TEST(StepPlacement, EqualVolumeGivesEqualShellVolumesIn3DAnd2D) {
  const ContinuousPotential p = morse(1.0, 1.1, 4.0, 2.6, true);
  for (const int d : {3, 2}) {
    const StepTable t =
        step_potential(p, StepPlacement::kVolume, 9, 1.0, StepEnergyRule::kVolumeAverage, 1.0, d);
    ASSERT_EQ(t.boundary.size(), 10u);
    EXPECT_EQ(t.cutoff(), 2.6);
    EXPECT_EQ(t.core(), 1.0);
    const double shell = (std::pow(2.6, d) - 1.0) / 9;
    for (std::size_t k = 0; k + 1 < t.boundary.size(); ++k) {
      EXPECT_NEAR(std::pow(t.boundary[k], d) - std::pow(t.boundary[k + 1], d), shell, 1e-12)
          << d << " " << k;
    }
  }
}

// Equal energy steps down to a core distance: shifted LJ cut at 3 with 4 steps reproduces the
// boundaries and volume energies of docs/physics.md#stepping-continuous-potentials, and every
// boundary sits on the closed-form crossing of its level.
TEST(StepPlacement, EqualEnergyDownToACoreDistanceMatchesClosedFormCrossings) {
  const ContinuousPotential p = lennard_jones(1.0, 1.0, 3.0, true);
  const StepTable t =
      step_potential(p, StepPlacement::kEnergy, 4, 1.0, StepEnergyRule::kVolumeAverage);
  const double reference[] = {3.0,          1.5645719186, 1.3758643336, 1.2593458744,
                              1.1224620483, 1.0492750505, 1.0269371209, 1.0118379421};
  const double volume[] = {-0.0321811894, -0.3533047721, -0.6121565654, -0.8891870058,
                           -0.9237530815, -0.6326889172, -0.3798908979};
  // Levels 0 (just above r = 1, since the shift makes U(1) > 0) then the core.
  ASSERT_EQ(t.boundary.size(), 10u);
  for (int k = 0; k < 8; ++k) EXPECT_NEAR(t.boundary[k], reference[k], 1e-9) << k;
  for (int k = 0; k < 7; ++k) EXPECT_NEAR(t.energy[k], volume[k], 1e-9) << k;
  const double shift = lj(3.0), u_min = -1.0 - shift, du = -u_min / 4;
  for (int k = 1; k < 4; ++k) EXPECT_NEAR(t.boundary[k], lj_outer_root(-k * du + shift), 1e-12);
  EXPECT_NEAR(t.boundary[4], std::pow(2.0, 1.0 / 6.0), 1e-15);
  for (int j = 1; j <= 4; ++j)
    EXPECT_NEAR(t.boundary[4 + j], lj_inner_root(u_min + j * du + shift), 1e-12) << j;
  EXPECT_EQ(t.core(), 1.0);

  // A deeper core: the inner branch goes on in the same dU while the levels lie below U(core).
  const StepTable deep =
      step_potential(p, StepPlacement::kEnergy, 4, 0.9, StepEnergyRule::kMidpoint);
  const int levels = static_cast<int>(std::floor((lj(0.9) - shift - u_min) / du));
  ASSERT_EQ(deep.boundary.size(), static_cast<std::size_t>(4 + 1 + levels + 1));
  for (int j = 1; j <= levels; ++j)
    EXPECT_NEAR(deep.boundary[4 + j], lj_inner_root(u_min + j * du + shift), 1e-12) << j;
  EXPECT_EQ(deep.core(), 0.9);
}

// An unshifted potential: the levels are counted down from U(cutoff), not from 0.
TEST(StepPlacement, EqualEnergyOfAnUnshiftedWellStartsAtTheCutoffValue) {
  const ContinuousPotential p = lennard_jones(1.0, 1.0, 2.5, false);
  const StepTable t = step_potential(p, StepPlacement::kEnergy, 5, 1.0, StepEnergyRule::kMidpoint);
  const double du = (lj(2.5) + 1.0) / 5;
  for (int k = 1; k < 5; ++k) EXPECT_NEAR(t.boundary[k], lj_outer_root(lj(2.5) - k * du), 1e-12);
  EXPECT_NEAR(t.boundary[5], std::pow(2.0, 1.0 / 6.0), 1e-15);
}

// Purely repulsive (WCA) and purely attractive (Yukawa eps < 0) potentials: exactly `steps`
// shells, dU = |U(core) - U(cutoff)| / steps.
TEST(StepPlacement, EqualEnergyOfMonotonePotentials) {
  const ContinuousPotential w = wca(1.0, 1.0);
  const double core = 0.95, u_core = lj(core) + 1.0;
  const StepTable t = step_potential(w, StepPlacement::kEnergy, 6, core, StepEnergyRule::kMidpoint);
  ASSERT_EQ(t.boundary.size(), 7u);
  EXPECT_DOUBLE_EQ(t.cutoff(), std::pow(2.0, 1.0 / 6.0));
  EXPECT_EQ(t.core(), core);
  for (int k = 1; k < 6; ++k)
    EXPECT_NEAR(t.boundary[k], lj_inner_root(k * u_core / 6 - 1.0), 1e-12) << k;

  // U = -exp(-(r - 1)) / r + exp(-2) / 3, shifted at 3: U(b_k) = k U(core) / steps.
  const ContinuousPotential y = yukawa(-1.0, 1.0, 1.0, 3.0, true);
  const StepTable a = step_potential(y, StepPlacement::kEnergy, 5, 1.0, StepEnergyRule::kMidpoint);
  ASSERT_EQ(a.boundary.size(), 6u);
  const double y_core = -1.0 + std::exp(-2.0) / 3.0;
  for (int k = 1; k < 5; ++k) {
    const double r = a.boundary[k];
    EXPECT_NEAR(-std::exp(-(r - 1.0)) / r + std::exp(-2.0) / 3.0, k * y_core / 5, 1e-13) << k;
  }
}

TEST(StepPlacement, TooManyShellsOrAnUnsteppableCoreAreRejected) {
  const ContinuousPotential p = lennard_jones(1.0, 1.0, 2.5, true);
  EXPECT_INPUT_ERROR(step_potential(p, StepPlacement::kEnergy, 0, 1.0, StepEnergyRule::kMidpoint),
                     "steps must be at least 1");
  EXPECT_INPUT_ERROR(step_potential(p, StepPlacement::kEnergy, 4, 2.5, StepEnergyRule::kMidpoint),
                     "hard core 2.5 must be positive and inside the cut-off 2.5");
  EXPECT_INPUT_ERROR(
      step_potential(p, StepPlacement::kEnergy, 4, 1.0, StepEnergyRule::kMidpoint, 1.0, 4),
      "dimension must be 2 or 3");
  EXPECT_INPUT_ERROR(
      step_potential(p, StepPlacement::kEnergy, 4, 1.0, StepEnergyRule::kVirial, 0.0),
      "kT must be positive");
  // U(0.5) = 16128: 64 000 levels of dU = 0.25, too many with 1000 steps on the well.
  EXPECT_INPUT_ERROR(
      step_potential(p, StepPlacement::kEnergy, 1000, 0.5, StepEnergyRule::kMidpoint),
      "more than 100000 shells");
}

// ---------------------------------------------------------------------------------------------
// Shell energies: U = 2 - r on (1, 2) (one shell), against the closed-form integrals.

TEST(StepEnergyRules, OneShellAgainstClosedFormsIn3DAnd2D) {
  const ContinuousPotential p{"line", [](double r) { return 2.0 - r; }, 0.0, 2.0, 0.0};
  auto one = [&](StepEnergyRule rule, int d) {
    const StepTable t = step_potential(p, StepPlacement::kDistance, 1, 1.0, rule, 1.0, d);
    EXPECT_EQ(t.energy.size(), 1u);
    return t.energy[0];
  };
  for (const int d : {2, 3}) EXPECT_NEAR(one(StepEnergyRule::kMidpoint, d), 0.5, 1e-15);
  // 3 / 7 int_1^2 (2 - r) r^2 dr = 11 / 28; 2 / 3 int_1^2 (2 - r) r dr = 4 / 9.
  EXPECT_NEAR(one(StepEnergyRule::kVolumeAverage, 3), 11.0 / 28.0, 1e-13);
  EXPECT_NEAR(one(StepEnergyRule::kVolumeAverage, 2), 4.0 / 9.0, 1e-13);
  EXPECT_NEAR(one(StepEnergyRule::kMidVolume, 3), 2.0 - std::cbrt(4.5), 1e-15);
  EXPECT_NEAR(one(StepEnergyRule::kMidVolume, 2), 2.0 - std::sqrt(2.5), 1e-15);
  // int_1^2 e^(r-2) r dr = 1; int_1^2 e^(r-2) r^2 dr = 2 - 1/e.
  EXPECT_NEAR(one(StepEnergyRule::kVirial, 2), -std::log(2.0 / 3.0), 1e-13);
  EXPECT_NEAR(one(StepEnergyRule::kVirial, 3), -std::log(3.0 / 7.0 * (2.0 - std::exp(-1.0))),
              1e-13);
}

// ---------------------------------------------------------------------------------------------
// B2.

TEST(SecondVirial, SquareWellIn2DMatchesTheClosedForm) {
  const StepTable sw = square_well(1.0, 1.5, 1.0);
  for (const double kT : {0.7, 1.0, 2.0, 5.0}) {
    const double exact = kPi / 2.0 * (1.0 - (1.5 * 1.5 - 1.0) * std::expm1(1.0 / kT));
    EXPECT_NEAR(second_virial(sw, kT, 2), exact, 1e-13 * std::abs(exact)) << kT;
  }
  // Hard disks / spheres of diameter 2: pi/2 4, 2pi/3 8.
  const StepTable hard{{3.0, 2.0}, {0.0}};
  EXPECT_NEAR(second_virial(hard, 1.0, 2), 2.0 * kPi, 1e-14);
  EXPECT_NEAR(second_virial(hard, 1.0, 3), 16.0 * kPi / 3.0, 1e-13);
}

TEST(SecondVirial, OfAContinuousPotentialMatchesABruteForceSum) {
  const ContinuousPotential p = lennard_jones(1.0, 1.0, 2.5, true);
  for (const int d : {2, 3}) {
    const double reference = brute_b2(p.u, 0.9, 2.5, 1.3, d);
    EXPECT_NEAR(second_virial(p, 0.9, 1.3, d), reference, 1e-8 * std::abs(reference)) << d;
  }
  EXPECT_EQ(second_virial(harmonic_spring(1.0, 1.2, 1.5), 1.0, 1.0), kInf);
  EXPECT_INPUT_ERROR(second_virial(p, 3.0, 1.0), "inside the cut-off");
}

// The virial rule keeps B2, for every potential, placement and dimension.
TEST(SecondVirial, VirialTablesKeepTheB2OfTheirPotential) {
  const std::vector<ContinuousPotential> potentials = {
      lennard_jones(1.0, 1.0, 2.5, true),
      lennard_jones(1.0, 1.0, 2.5, false),
      wca(1.0, 1.0),
      yukawa(2.0, 1.0, 1.5, 3.0, true),
      yukawa(-0.8, 1.0, 1.0, 3.0, false),
      morse(1.0, 1.1, 5.0, 2.4, true),
  };
  for (const auto& p : potentials) {
    for (const auto placement :
         {StepPlacement::kEnergy, StepPlacement::kDistance, StepPlacement::kVolume}) {
      for (const int d : {2, 3}) {
        const double kT = 1.7, core = 0.97;
        const StepTable t = step_potential(p, placement, 5, core, StepEnergyRule::kVirial, kT, d);
        const double b2 = second_virial(p, core, kT, d);
        EXPECT_NEAR(second_virial(t, kT, d), b2, 1e-8 * std::abs(b2))
            << p.name << " placement " << static_cast<int>(placement) << " d " << d;
        // The other rules do not keep it (a control that the comparison can fail).
        const StepTable mid =
            step_potential(p, placement, 5, core, StepEnergyRule::kMidpoint, kT, d);
        EXPECT_GT(std::abs(second_virial(mid, kT, d) - b2), 1e-6 * std::abs(b2)) << p.name;
      }
    }
  }
}

// Finer tables converge to the continuous B2: midpoint energies on equal widths, error ~ 1/N^2.
TEST(SecondVirial, FineTablesConvergeToTheContinuousB2) {
  const ContinuousPotential p = lennard_jones(1.0, 1.0, 2.5, true);
  const double kT = 1.2, core = 0.95, b2 = second_virial(p, core, kT);
  double previous = kInf;
  for (const int n : {10, 40, 160, 640}) {
    const StepTable t =
        step_potential(p, StepPlacement::kDistance, n, core, StepEnergyRule::kMidpoint, kT);
    const double error = std::abs(second_virial(t, kT) - b2);
    EXPECT_LT(error, previous / 8.0) << n;
    previous = error;
  }
  EXPECT_LT(previous, 1e-4 * std::abs(b2));
}

// ---------------------------------------------------------------------------------------------
// Tabulated potentials.

TEST(Tabulated, AFileOfLennardJonesReproducesTheLennardJonesTable) {
  // A grid through the minimum 2^(1/6) (where a tabulated minimum lies), unshifted values.
  std::ostringstream text;
  text << "# r U (Lennard-Jones, unshifted)\n\n";
  const double r_min = std::pow(2.0, 1.0 / 6.0);
  const int inner = 800, outer = 4000;
  for (int i = 0; i < inner; ++i) {
    const double r = 0.9 + (r_min - 0.9) * i / inner;
    text << std::setprecision(17) << r << " " << lj(r) << "\n";
  }
  for (int i = 0; i <= outer; ++i) {
    const double r = i == outer ? 3.0 : r_min + (3.0 - r_min) * i / outer;
    text << std::setprecision(17) << r << "\t" << lj(r) << "   # comment\n";
  }
  const ContinuousPotential tab = tabulated(write_file("lj.table", text.str()), true);
  EXPECT_EQ(tab.cutoff, 3.0);
  EXPECT_NEAR(tab.r_min, r_min, 1e-15);
  EXPECT_EQ(tab.u(3.0), 0.0);
  EXPECT_TRUE(std::isnan(tab.u(0.8)));
  const ContinuousPotential p = lennard_jones(1.0, 1.0, 3.0, true);
  for (const double r : {0.93, 1.0, 1.05, 1.3, 2.0, 2.9}) EXPECT_NEAR(tab.u(r), p.u(r), 1e-6) << r;
  const StepTable a =
      step_potential(tab, StepPlacement::kEnergy, 4, 1.0, StepEnergyRule::kVolumeAverage);
  const StepTable b =
      step_potential(p, StepPlacement::kEnergy, 4, 1.0, StepEnergyRule::kVolumeAverage);
  ASSERT_EQ(a.boundary.size(), b.boundary.size());
  for (std::size_t k = 0; k < a.boundary.size(); ++k)
    EXPECT_NEAR(a.boundary[k], b.boundary[k], 1e-6) << k;
  for (std::size_t k = 0; k < a.energy.size(); ++k)
    EXPECT_NEAR(a.energy[k], b.energy[k], 1e-6) << k;
  // And its virial table keeps its own B2.
  const StepTable v =
      step_potential(tab, StepPlacement::kVolume, 7, 0.95, StepEnergyRule::kVirial, 1.4, 2);
  const double b2 = second_virial(tab, 0.95, 1.4, 2);
  EXPECT_NEAR(second_virial(v, 1.4, 2), b2, 1e-8 * std::abs(b2));
  EXPECT_NEAR(b2, second_virial(p, 0.95, 1.4, 2), 1e-5 * std::abs(b2));
}

TEST(Tabulated, InterpolationIsMonotoneAndThroughThePoints) {
  const ContinuousPotential tab =
      tabulated(write_file("rough.table", "1 5\n1.1 1\n1.5 0.9\n1.6 -2\n2 -1.9\n3 0\n"), false);
  const double xs[] = {1, 1.1, 1.5, 1.6, 2, 3}, ys[] = {5, 1, 0.9, -2, -1.9, 0};
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(tab.u(xs[i]), ys[i], 1e-15) << i;
  EXPECT_DOUBLE_EQ(tab.r_min, 1.6);
  for (int i = 0; i < 5; ++i) {
    double previous = ys[i];
    for (int j = 1; j <= 100; ++j) {
      const double u = tab.u(xs[i] + (xs[i + 1] - xs[i]) * j / 100);
      EXPECT_LE(u, std::max(ys[i], ys[i + 1]) + 1e-15);
      EXPECT_GE(u, std::min(ys[i], ys[i + 1]) - 1e-15);
      EXPECT_TRUE(ys[i + 1] >= ys[i] ? u >= previous - 1e-15 : u <= previous + 1e-15);
      previous = u;
    }
  }
}

TEST(Tabulated, BadFilesNameTheFileAndLine) {
  EXPECT_INPUT_ERROR(tabulated("/nonexistent/u.table", false),
                     "cannot read the potential file '/nonexistent/u.table'");
  const std::string down = write_file("down.table", "# r U\n1 2\n1.5 1\n1.4 0\n");
  EXPECT_INPUT_ERROR(tabulated(down, false),
                     "potential file '" + down + "', line 4: r = 1.4 does not increase");
  EXPECT_INPUT_ERROR(tabulated(write_file("three.table", "1 2 3\n2 0\n"), false),
                     "line 1: expected two columns");
  EXPECT_INPUT_ERROR(tabulated(write_file("one.table", "1 2\n2\n"), false),
                     "line 2: expected two columns");
  EXPECT_INPUT_ERROR(tabulated(write_file("word.table", "1 2\n2 zero\n"), false),
                     "line 2: 'zero' is not a finite number");
  EXPECT_INPUT_ERROR(tabulated(write_file("inf.table", "1 inf\n2 0\n"), false),
                     "line 1: 'inf' is not a finite number");
  EXPECT_INPUT_ERROR(tabulated(write_file("nan.table", "1 1\n2 nan\n"), false),
                     "line 2: 'nan' is not a finite number");
  EXPECT_INPUT_ERROR(tabulated(write_file("neg.table", "-1 1\n2 0\n"), false),
                     "line 1: r = -1 is not positive");
  EXPECT_INPUT_ERROR(tabulated(write_file("short.table", "# nothing\n1 0\n"), false),
                     "has 1 points (r U); it needs at least 2");
  EXPECT_INPUT_ERROR(tabulated(write_file("tail.table", "1 1\n2 -0.5\n3 -0.1\n"), false),
                     "U at the cut-off (the last r, 3) is -0.1, not 0");
  EXPECT_NO_THROW(tabulated(write_file("tail2.table", "1 1\n2 -0.5\n3 -0.1\n"), true));
  // A core below the table, and two wells for the energy placement.
  const ContinuousPotential two =
      tabulated(write_file("two.table", "1 3\n1.2 -1\n1.4 0.5\n1.6 -1\n2 0\n"), false);
  EXPECT_INPUT_ERROR(step_potential(two, StepPlacement::kEnergy, 4, 0.9, StepEnergyRule::kMidpoint),
                     "U is not finite at the hard core r = 0.9");
  EXPECT_INPUT_ERROR(step_potential(two, StepPlacement::kEnergy, 4, 1.0, StepEnergyRule::kMidpoint),
                     "use the distance or volume placement");
  EXPECT_NO_THROW(step_potential(two, StepPlacement::kDistance, 4, 1.0, StepEnergyRule::kMidpoint));
}

// ---------------------------------------------------------------------------------------------
// Bonds.

TEST(Bonds, ASteppedSpringIsABondWithClosedFormBoundaries) {
  const double k = 20.0, length = 1.2, max_length = 1.5, core = 1.0;
  const ContinuousPotential s = harmonic_spring(k, length, max_length);
  const StepTable t = step_potential(s, StepPlacement::kEnergy, 6, core, StepEnergyRule::kMidpoint);
  EXPECT_EQ(t.beyond, kInf);
  EXPECT_EQ(t.energy_at(1.5000001), kInf);
  EXPECT_EQ(t.energy_at(0.999), kInf);
  EXPECT_EQ(second_virial(t, 1.0), kInf);
  // Outer branch: U(b_k) = U(max) (1 - k/6); inner branch: levels j dU below U(core).
  const double u_max = 0.5 * k * 0.09, du = u_max / 6, u_core = 0.5 * k * 0.04;
  for (int i = 1; i < 6; ++i)
    EXPECT_NEAR(t.boundary[i], length + 0.3 * std::sqrt(1.0 - i / 6.0), 1e-13) << i;
  EXPECT_NEAR(t.boundary[6], length, 1e-15);
  const int inner = static_cast<int>(std::ceil(u_core / du)) - 1;  // levels strictly below
  ASSERT_EQ(t.boundary.size(), static_cast<std::size_t>(6 + 1 + inner + 1));
  for (int j = 1; j <= inner; ++j)
    EXPECT_NEAR(t.boundary[6 + j], length - std::sqrt(2.0 * j * du / k), 1e-13) << j;
  EXPECT_EQ(t.core(), core);
}

// ---------------------------------------------------------------------------------------------
// The report.

TEST(Report, HeaderAndTableReadBack) {
  const ContinuousPotential p = lennard_jones(1.0, 1.0, 2.5, true);
  const StepTable t =
      step_potential(p, StepPlacement::kEnergy, 3, 1.0, StepEnergyRule::kVirial, 1.5);
  const std::string report = step_table_report(t, &p, 1.5);
  EXPECT_NE(report.find(fmt::format("# step table: {} shells", t.energy.size())),
            std::string::npos);
  EXPECT_NE(report.find("lennard-jones (shifted)"), std::string::npos);
  EXPECT_NE(report.find(fmt::format("table {:.10g}", second_virial(t, 1.5))), std::string::npos);
  EXPECT_NE(report.find(fmt::format("continuous {:.10g}", second_virial(p, 1.0, 1.5))),
            std::string::npos);
  std::istringstream in(report);
  std::string line;
  std::vector<std::vector<double>> rows;
  bool header = false;
  while (std::getline(in, line)) {
    if (line.starts_with("#")) continue;
    if (!header) {
      EXPECT_EQ(line, "r_outer\tr_inner\tU_step\tU_continuous");
      header = true;
      continue;
    }
    std::istringstream fields(line);
    std::vector<double> row(4);
    for (double& x : row) fields >> x;
    rows.push_back(row);
  }
  ASSERT_EQ(rows.size(), t.energy.size());
  for (std::size_t k = 0; k < rows.size(); ++k) {
    EXPECT_NEAR(rows[k][0], t.boundary[k], 1e-11);
    EXPECT_NEAR(rows[k][1], t.boundary[k + 1], 1e-11);
    EXPECT_NEAR(rows[k][2], t.energy[k], 1e-11);
    EXPECT_NEAR(rows[k][3], p.u(0.5 * (t.boundary[k] + t.boundary[k + 1])), 1e-11);
  }
  const std::string bond = step_table_report(StepTable{{1.5, 1.0}, {0.0}, kInf}, nullptr, 1.0);
  EXPECT_NE(bond.find("B2: not defined for a bond"), std::string::npos);
  EXPECT_NE(bond.find("\tnan\n"), std::string::npos);

  const std::string curve = continuous_curve_tsv(p, 1.0, 2.5, 4);
  EXPECT_EQ(curve, fmt::format("r\tU\n1\t{:.12g}\n1.5\t{:.12g}\n2\t{:.12g}\n2.5\t0\n", p.u(1.0),
                               p.u(1.5), p.u(2.0)));
}

// docs/physics.md#spring-dashpot-by-steps: a crossing pays the dashpot's work gamma |v_n| width
// at the speed before it. Approaching: cross if the energy pays step + work, else bounce with
// nothing dissipated. Separating down a step: with the cap the pair gains max(0, -dU - work) and
// always crosses; without, it is charged dU + work and may be pulled back. No damping:
// step_event bit for bit.
TEST(DissipativeStepEvent, PaysTheDashpotWorkAndCapsTheGain) {
  const double mu = 0.75, gamma = 2.0, width = 0.01;
  for (const double v : {-3.0, -1.2, 0.7, 2.5}) {
    for (const double du : {0.3, -0.2, 0.0}) {
      const StepOutcome plain = step_event(mu, v, du);
      const DissipativeStepOutcome none = dissipative_step_event(mu, v, du, 0.0, width, true);
      EXPECT_EQ(none.crosses, plain.crosses);
      EXPECT_EQ(none.impulse, plain.impulse);
      EXPECT_EQ(none.dissipated, 0.0);
      for (const bool cap : {true, false}) {
        const DissipativeStepOutcome d = dissipative_step_event(mu, v, du, gamma, width, cap);
        const double work = gamma * std::abs(v) * width;
        const double k0 = 0.5 * mu * v * v;
        const double after = v + d.impulse / mu;
        const double k1 = 0.5 * mu * after * after;
        if (!d.crosses) {  // a bounce: reversed, nothing lost
          EXPECT_NEAR(after, -v, 1e-14);
          EXPECT_EQ(d.dissipated, 0.0);
          EXPECT_LT(k0, du + work);
          continue;
        }
        EXPECT_GT(after * v, 0.0);  // same direction
        EXPECT_NEAR(k0 - k1, du + d.dissipated, 1e-13) << v << " " << du;
        if (cap && du < 0.0) {
          EXPECT_NEAR(d.dissipated, std::min(work, -du), 1e-15);
          EXPECT_GE(k1, k0 - 1e-15);  // never slower down a step: no net attraction
        } else {
          EXPECT_NEAR(d.dissipated, work, 1e-15);
        }
      }
    }
  }
  // Slow, separating down a small step: the cap lets it leave unchanged; without the cap the
  // dashpot's work exceeds the step and the pair is pulled back.
  const DissipativeStepOutcome capped = dissipative_step_event(mu, 0.1, -0.001, 5.0, 0.01, true);
  EXPECT_TRUE(capped.crosses);
  EXPECT_EQ(capped.impulse, 0.0);
  EXPECT_NEAR(capped.dissipated, 0.001, 1e-18);
  const DissipativeStepOutcome naive = dissipative_step_event(mu, 0.1, -0.001, 5.0, 0.01, false);
  EXPECT_FALSE(naive.crosses);
  EXPECT_NEAR(naive.impulse, -2.0 * mu * 0.1, 1e-15);
}

}  // namespace
}  // namespace kairos
