// The MSD's clock (analysis.msd_time, run/outputs/msd_output.hpp): an interval in collisions per
// particle becomes a whole number of collisions and back exactly; a freely cooling gas is sampled
// on the collision clock by default (its D(t) decays), an elastic one in time, and a cooling gas
// measured in time gets no D; its lags are then whole multiples of the interval in collisions
// per particle.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/stop_flag.hpp"
#include "io/config.hpp"
#include "run/outputs/msd_output.hpp"
#include "run/run.hpp"

namespace kairos {
namespace {

namespace fs = std::filesystem;

TEST(MsdClock, AnIntervalInCollisionsPerParticleIsAWholeNumberOfCollisions) {
  // c = 2 N_coll / N: half a collision per particle of 2000 particles is 500 collisions.
  const CollisionInterval half = collision_interval(0.5, 2000);
  EXPECT_EQ(half.step, 500u);
  EXPECT_DOUBLE_EQ(half.per_particle, 0.5);
  // 0.3 per particle of 7 particles is 1.05 collisions: one, which is 2/7 per particle.
  const CollisionInterval few = collision_interval(0.3, 7);
  EXPECT_EQ(few.step, 1u);
  EXPECT_DOUBLE_EQ(few.per_particle, 2.0 / 7.0);
  // Never less than one collision.
  EXPECT_EQ(collision_interval(1e-9, 1000).step, 1u);
  EXPECT_EQ(collision_interval(2.6, 1000).step, 1300u);
}

class MsdClockRun : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("kairos_msd_clock_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    clear_stop_request();
  }
  void TearDown() override { fs::remove_all(dir_); }

  // 500 hard spheres at packing fraction 0.02, 2 collisions per particle of equilibration, 80 of
  // production.
  RunOutcome run(const std::string& extra) const {
    const std::string text =
        "[system]\nparticles = 500\npacking_fraction = 0.02\nlattice = \"random\"\nseed = 7\n"
        "[run]\nequilibration_collisions_per_particle = 2.0\ncollisions_per_particle = 80.0\n"
        "[output]\nprogress = \"never\"\ntrajectory = false\ndirectory = \"" +
        dir_.string() + "\"\n" + extra;
    return run_simulation(parse_config(text, "<test>"));
  }

  // The lag column of msd.tsv.
  std::vector<double> lags() const {
    std::ifstream in(dir_ / "msd.tsv");
    std::string line;
    std::getline(in, line);
    std::vector<double> out;
    while (std::getline(in, line)) out.push_back(std::stod(line.substr(0, line.find('\t'))));
    return out;
  }

  fs::path dir_;
};

TEST_F(MsdClockRun, ACoolingGasIsSampledPerCollisionAndCompared) {
  const RunOutcome o = run("[contact]\nrestitution = 0.9\n[analysis]\nmsd = true\n");
  ASSERT_TRUE(o.error.empty()) << o.error;
  const nlohmann::json& d = o.summary["diffusion"];
  EXPECT_EQ(d["time_scale"], "collisions");
  EXPECT_TRUE(d["time_scale_automatic"].get<bool>());
  EXPECT_TRUE(d["freely_cooling"].get<bool>());
  EXPECT_EQ(d["interval"], 0.5);
  // From the production's start at 2 to its end at 82 collisions per particle: 160 samples.
  EXPECT_EQ(d["samples"], 160);
  EXPECT_DOUBLE_EQ(d["sampled_from"].get<double>(), 2.5);
  EXPECT_DOUBLE_EQ(d["sampled_to"].get<double>(), 82.0);
  EXPECT_TRUE(d["mean_free_time"].is_null());
  for (const double lag : lags()) EXPECT_DOUBLE_EQ(lag / 0.5, std::round(lag / 0.5)) << lag;
  EXPECT_TRUE(d["theory"]["coefficient"].is_number());
  EXPECT_TRUE(d["species"]["A"]["coefficient_over_theory"].is_number());
}

TEST_F(MsdClockRun, ACoolingGasMeasuredInTimeHasNoDiffusionCoefficient) {
  const RunOutcome o =
      run("[contact]\nrestitution = 0.9\n[analysis]\nmsd = true\nmsd_time = \"time\"\n");
  ASSERT_TRUE(o.error.empty()) << o.error;
  const nlohmann::json& a = o.summary["diffusion"]["species"]["A"];
  EXPECT_EQ(o.summary["diffusion"]["time_scale"], "time");
  EXPECT_TRUE(a["coefficient"].is_null());
  EXPECT_NE(a["why"].get<std::string>().find("cools freely"), std::string::npos);
  EXPECT_TRUE(fs::exists(dir_ / "msd.tsv"));
}

TEST_F(MsdClockRun, AnElasticGasIsSampledInTimeUnlessAskedOtherwise) {
  const RunOutcome o = run("[analysis]\nmsd = true\n");
  ASSERT_TRUE(o.error.empty()) << o.error;
  EXPECT_EQ(o.summary["diffusion"]["time_scale"], "time");
  EXPECT_FALSE(o.summary["diffusion"]["freely_cooling"].get<bool>());
  EXPECT_TRUE(o.summary["diffusion"]["species"]["A"]["coefficient"].is_number());
  fs::remove_all(dir_);
  const RunOutcome c = run("[analysis]\nmsd = true\nmsd_time = \"collisions\"\n");
  ASSERT_TRUE(c.error.empty()) << c.error;
  EXPECT_EQ(c.summary["diffusion"]["time_scale"], "collisions");
  // Elastic: the theory is Enskog's D over its collision frequency.
  EXPECT_EQ(c.summary["diffusion"]["theory"]["restitution"], 1.0);
  EXPECT_EQ(c.summary["diffusion"]["theory"]["sonine_a2"], 0.0);
}

TEST_F(MsdClockRun, TheTheoryOfTheCoolingStateIsNotGivenWhereItDoesNotApply) {
  const RunOutcome o =
      run("[contact]\nrestitution = 0.9\ntangential_restitution = 0.5\n[analysis]\nmsd = true\n");
  ASSERT_TRUE(o.error.empty()) << o.error;
  const nlohmann::json& d = o.summary["diffusion"];
  EXPECT_EQ(d["time_scale"], "collisions");
  EXPECT_TRUE(d["theory"].is_null());
  EXPECT_NE(d["theory_why"].get<std::string>().find("rough"), std::string::npos);
}

}  // namespace
}  // namespace kairos
