// The contact value g(σ⁺) of rdf.tsv's analysis (analysis.rdf) against the compressibility
// factor the collision virial measures, in one short run each of hard spheres and hard disks:
// Z = 1 + 4η g(σ⁺) in 3D, 1 + 2η g(σ⁺) in 2D (the contact theorem), within the two blocked
// errors. Both come out of the same production, through the whole pipeline (config ->
// engine -> observers -> summary.json). docs/validation.md has the long runs.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <string>

#include <fmt/format.h>

#include "core/stop_flag.hpp"
#include "io/config.hpp"
#include "run/run.hpp"

namespace kairos {
namespace {

namespace fs = std::filesystem;

// Deterministic (a fixed seed): the comparison passes or fails the same way on every run.
// Sampled at fixed times (output.interval_unit = "time"): a state taken when a collision count
// is reached is conditioned on a collision, which biases g(σ⁺) by O(1/N) (0.3 % at N = 1000;
// docs/outputs.md).
nlohmann::json run_fluid(int dimension, double eta, std::uint64_t particles,
                         const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("kairos_contact_" + std::to_string(::getpid()) + "_" + name);
  fs::remove_all(dir);
  clear_stop_request();
  const std::string text = fmt::format(
      "[system]\ndimension = {}\nparticles = {}\npacking_fraction = {}\nseed = 5\n"
      "[run]\nequilibration_collisions_per_particle = 100\ncollisions_per_particle = 400\n"
      "[output]\nprogress = \"never\"\ntrajectory = false\ninterval_unit = \"time\"\n"
      "thermo_interval = 0.1\ntrajectory_interval = 100\n"
      "directory = \"{}\"\n"
      "[analysis]\nrdf = true\nrdf_max_distance = 1.5\nrdf_bins = 30\n",
      dimension, particles, eta, dir.string());
  const RunOutcome outcome = run_simulation(parse_config(text, "<test>"));
  fs::remove_all(dir);
  EXPECT_TRUE(outcome.error.empty()) << outcome.error;
  return outcome.summary;
}

void expect_contact_theorem(const nlohmann::json& s, double eta, int dimension) {
  const nlohmann::json& rdf = s["analysis"]["rdf"];
  const double g = rdf["contact"]["A-A"]["g"], dg = rdf["contact"]["A-A"]["stderr"];
  const double zc = rdf["compressibility_from_contact"]["mean"];
  const double dzc = rdf["compressibility_from_contact"]["stderr"];
  const double z = s["compressibility"]["mean"], dz = s["compressibility"]["stderr"];
  const double factor = dimension == 3 ? 4.0 * eta : 2.0 * eta;
  ::testing::Test::RecordProperty("g_contact", std::to_string(g) + " +- " + std::to_string(dg));
  ::testing::Test::RecordProperty("Z_virial", std::to_string(z) + " +- " + std::to_string(dz));
  EXPECT_NEAR(zc, 1.0 + factor * g, 1e-9);
  EXPECT_NEAR(dzc, factor * dg, 1e-9);
  EXPECT_EQ(rdf["compressibility_virial"]["mean"].get<double>(), z);
  // A meaningful comparison: both errors below 2 % of Z - 1.
  EXPECT_GT(dg, 0.0);
  EXPECT_LT(dzc, 0.02 * (z - 1.0));
  EXPECT_LT(dz, 0.02 * (z - 1.0));
  EXPECT_NEAR(zc, z, 3.0 * std::hypot(dzc, dz)) << "g(sigma+) = " << g << " +- " << dg;
}

TEST(ContactTheorem, HardSpheresContactValueGivesTheVirialCompressibility) {
  const double eta = 0.35;
  expect_contact_theorem(run_fluid(3, eta, 1000, "spheres"), eta, 3);
}

TEST(ContactTheorem, HardDisksContactValueGivesTheVirialCompressibility) {
  const double eta = 0.55;
  expect_contact_theorem(run_fluid(2, eta, 1000, "disks"), eta, 2);
}

}  // namespace
}  // namespace kairos
