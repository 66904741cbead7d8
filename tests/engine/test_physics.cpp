// Physics against published reference values (docs/physics.md#validation-references), run
// through the whole pipeline (config -> initial state -> engine -> summary) on the configs in
// examples/validation/. Tolerances are 3 standard errors (block averaging) plus the stated
// systematic allowance.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>

#include "io/config.hpp"
#include "run/run.hpp"

namespace kairos {
namespace {

std::filesystem::path scratch_dir(const std::string& name) {
  auto dir = std::filesystem::temp_directory_path() /
             ("kairos-physics-" + name + "-" + std::to_string(std::random_device{}()));
  std::filesystem::remove_all(dir);
  return dir;
}

// Runs one of examples/validation/*.toml (the same files docs/validation.md cites).
nlohmann::json run(const std::string& example) {
  const auto dir = scratch_dir(example);
  Config config =
      load_config(std::filesystem::path(KAIROS_SOURCE_DIR) / "examples" / "validation" / example);
  config.output.directory = dir.string();
  config.output.trajectory = false;
  config.output.progress = "never";
  const RunOutcome outcome = run_simulation(config);
  std::filesystem::remove_all(dir);
  return outcome.summary;
}

// Kolafa-Labik-Malijevsky-form series for hard spheres, with the coefficients of Pieprzyk et al.,
// Phys. Chem. Chem. Phys. 21, 6886 (2019) (docs/physics.md#equations-of-state).
double z_hard_spheres(double eta) {
  const double x = eta / (1.0 - eta);
  return 1 + 4 * x + 6 * x * x + 2.3647684 * std::pow(x, 3) - 0.8698551 * std::pow(x, 4) +
         1.1062803 * std::pow(x, 5) - 1.1014221 * std::pow(x, 6) + 0.66605866 * std::pow(x, 7) -
         0.03633431 * std::pow(x, 8) - 0.20965164 * std::pow(x, 10) + 0.10555569 * std::pow(x, 14) -
         0.00872380 * std::pow(x, 22);
}

TEST(Physics, ReferenceSeriesReproducesTabulatedValues) {
  EXPECT_NEAR(z_hard_spheres(0.10), 1.52165, 1e-5);
  EXPECT_NEAR(z_hard_spheres(0.30), 3.98398, 1e-5);
  EXPECT_NEAR(z_hard_spheres(0.40), 6.94546, 1e-5);
}

TEST(Physics, HardSphereCompressibilityAndMeanFreeTimeAtEta030) {
  const auto s = run("hard_spheres_eta030.toml");
  const double z = s["compressibility"]["mean"], dz = s["compressibility"]["stderr"];
  const double z_ref = 3.98398;
  RecordProperty("Z", std::to_string(z) + " +- " + std::to_string(dz));
  EXPECT_GT(dz, 0.0);
  EXPECT_LT(dz, 0.01 * z_ref) << "run too short for a meaningful test";
  EXPECT_NEAR(z, z_ref, 3 * dz + 0.002 * z_ref) << "Z = " << z << " +- " << dz;
  const double mft = s["mean_free_time"], dmft = s["mean_free_time_stderr"];
  const double mft_ref = 0.098998;
  EXPECT_NEAR(mft, mft_ref, 3 * dmft + 0.002 * mft_ref) << "tau = " << mft << " +- " << dmft;
  // Exact identity of event-driven hard spheres: omega = (6/sigma)(Z-1)sqrt(kT/(pi m)).
  const double omega = 6.0 * (z - 1.0) / std::sqrt(M_PI);
  EXPECT_NEAR(mft * omega, 1.0, 0.02);
  EXPECT_LT(s["energy_drift_relative"].get<double>(), 1e-10);
  EXPECT_LT(s["momentum_drift"].get<double>(), 1e-10);
  EXPECT_LT(s["max_overlap"].get<double>(), 1e-10);
}

TEST(Physics, HardDiskCompressibilityAtEta020MatchesVirialSeries) {
  const auto s = run("hard_disks_eta020.toml");
  const double eta = 0.2;
  // Virial series to b5 (Clisby & McCoy 2006); the next term b6 eta^5 ~ 2e-3 bounds the
  // truncation error, so we allow 0.3 % on top of the statistics.
  const double z_ref = 1 + 2 * eta + 3.12801775 * eta * eta + 4.25785446 * std::pow(eta, 3) +
                       5.33690 * std::pow(eta, 4);
  const double z = s["compressibility"]["mean"], dz = s["compressibility"]["stderr"];
  EXPECT_LT(dz, 0.01 * z_ref);
  EXPECT_NEAR(z, z_ref, 3 * dz + 0.003 * z_ref) << "Z = " << z << " +- " << dz;
  // Exact 2D identity: omega = 2 n sigma g(sigma) sqrt(pi kT/m) with Z = 1 + 2 eta g(sigma).
  const double n = s["number_density"];
  const double g = (z - 1.0) / (2.0 * eta);
  EXPECT_NEAR(s["mean_free_time"].get<double>() * 2.0 * n * g * std::sqrt(M_PI), 1.0, 0.02);
  EXPECT_LT(s["energy_drift_relative"].get<double>(), 1e-10);
  EXPECT_LT(s["max_overlap"].get<double>(), 1e-10);
}

TEST(Physics, BinaryMixtureConservesAndNeverOverlaps) {
  const auto s = run("binary_mixture_eta035.toml");
  EXPECT_EQ(s["collisions"].get<std::uint64_t>(), 55000u);
  EXPECT_LT(s["energy_drift_relative"].get<double>(), 1e-10);
  EXPECT_LT(s["momentum_drift"].get<double>(), 1e-10);
  EXPECT_LT(s["max_overlap"].get<double>(), 1e-10);
  EXPECT_NEAR(s["temperature"].get<double>(), 1.0, 1e-10);
}

}  // namespace
}  // namespace kairos
