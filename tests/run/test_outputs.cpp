// The registered outputs (run/outputs/), each as the driver runs it under both integrators:
// thermo.tsv has a row per trigger and one at each phase's end, trajectory.gsd a first frame,
// one per trigger and no second frame of the state it ends on, restart.gsd records the rows,
// frames and schedules a continued run picks up, profile.tsv samples every production row, and
// summary.json holds the parts of its integrator only.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "core/stop_flag.hpp"
#include "io/config.hpp"
#include "io/gsd_file.hpp"
#include "run/run.hpp"
#include "run/run_progress.hpp"

namespace kairos {
namespace {

namespace fs = std::filesystem;

class Outputs : public ::testing::TestWithParam<const char*> {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = info->name();
    for (char& c : name)
      if (c == '/') c = '_';
    dir_ =
        fs::temp_directory_path() / ("kairos_outputs_" + std::to_string(::getpid()) + "_" + name);
    fs::remove_all(dir_);
    clear_stop_request();
  }
  void TearDown() override { fs::remove_all(dir_); }

  // 256 particles at packing fraction 0.3, 1 collision per particle of equilibration, 4 of
  // production; thermo every 0.5, frames every 1.5 (so the last frame falls before the end).
  RunOutcome run(const std::vector<std::string>& overrides = {}) const {
    const bool dem = std::string(GetParam()) == "dem";
    std::string text =
        "[system]\nparticles = 256\npacking_fraction = 0.3\nseed = 3\n"
        "[run]\nintegrator = \"" +
        std::string(GetParam()) +
        "\"\nequilibration_collisions_per_particle = 1.0\ncollisions_per_particle = 4.0\n"
        "[output]\nprogress = \"never\"\nthermo_interval = 0.5\ntrajectory_interval = 1.5\n"
        "directory = \"" +
        dir_.string() + "\"\n";
    if (dem) text += "[soft]\nmodel = \"dashpot\"\nstiffness = 10000.0\nrestitution = 0.9\n";
    return run_simulation(parse_config(text, "<test>", overrides));
  }

  int rows(const std::string& phase) const {
    std::ifstream in(dir_ / "thermo.tsv");
    std::string line;
    int n = 0;
    std::getline(in, line);
    while (std::getline(in, line)) n += line.rfind(phase + "\t", 0) == 0 ? 1 : 0;
    return n;
  }

  fs::path dir_;
};

TEST_P(Outputs, ThermoHasARowPerTriggerAndOneAtEachPhasesEnd) {
  const RunOutcome outcome = run();
  ASSERT_TRUE(outcome.error.empty()) << outcome.error;
  // Equilibration: 0.5, 1.0 (the trigger at its end: no second row); production from 1.0:
  // 1.5, ..., 5.0. The DEM meets each at the step that reaches it.
  EXPECT_EQ(rows("equilibration"), 2);
  EXPECT_EQ(rows("production"), 8);
  EXPECT_EQ(outcome.summary["compressibility"]["blocks"], 8);
}

TEST_P(Outputs, TrajectoryHasAFirstFrameOnePerTriggerAndALastOne) {
  ASSERT_TRUE(run().error.empty());
  // Frame 0, the triggers of the equilibration (1.5 > its 1.0: none) and of production from
  // 1.0 (2.5, 4.0), and the end (5.0).
  EXPECT_EQ(gsd::Reader(dir_ / "trajectory.gsd").frame_count(), 4u);
}

TEST_P(Outputs, NoSecondFrameOfTheStateARunEndsOn) {
  // Frames every 2.0 from 1.0: 3.0 and 5.0, the end itself.
  ASSERT_TRUE(run({"output.trajectory_interval=2.0"}).error.empty());
  EXPECT_EQ(gsd::Reader(dir_ / "trajectory.gsd").frame_count(), 3u);
}

TEST_P(Outputs, RestartRecordsTheRowsFramesAndSchedulesOfTheRun) {
  ASSERT_TRUE(run({"output.restart_interval=1.0"}).error.empty());
  std::mt19937_64 rng;
  RunProgress p;
  read_restart_file<3>(dir_ / "restart.gsd", rng, p, RunKind::kDem);
  EXPECT_EQ(p.integrator, GetParam());
  EXPECT_EQ(p.thermo_rows, 10);
  EXPECT_EQ(p.trajectory_frames, 4);
  ASSERT_NE(p.mark("thermo_mark"), nullptr);
  ASSERT_NE(p.mark("frame_mark"), nullptr);
  EXPECT_EQ(p.owed_outputs, 0u);
  // The production's schedules in collisions (256 particles: 0.5 per particle = 64): thermo,
  // trajectory, restart, as the triggers stand after the run.
  EXPECT_EQ(p.schedule_phase, 1);
  EXPECT_EQ(p.schedule_step[0], 64u);
  EXPECT_EQ(p.schedule_step[1], 192u);
  EXPECT_EQ(p.schedule_step[2], 128u);
  EXPECT_GT(p.schedule_next[0], 640u);  // beyond the end at 5 per particle
}

TEST_P(Outputs, ProfileSamplesEveryProductionRow) {
  ASSERT_TRUE(run({"output.profile_axis=\"z\"", "output.profile_bins=4"}).error.empty());
  std::ifstream in(dir_ / "profile.tsv");
  std::string comment;
  std::getline(in, comment);
  EXPECT_EQ(comment.rfind("# 8 samples;", 0), 0u) << comment;
}

TEST_P(Outputs, TheSummaryHasThePartsOfItsIntegrator) {
  const RunOutcome outcome = run();
  ASSERT_TRUE(outcome.error.empty()) << outcome.error;
  const nlohmann::json& s = outcome.summary;
  EXPECT_EQ(s["integrator"], GetParam());
  const bool dem = std::string(GetParam()) == "dem";
  EXPECT_EQ(s.contains("event_counts"), !dem);
  EXPECT_EQ(s.contains("pressure_tensor"), !dem);
  EXPECT_EQ(s.contains("dem"), dem);
  EXPECT_EQ(s.contains("granular"), dem);  // damping: the DEM's energy budget
  EXPECT_TRUE(s.contains("max_overlap"));
  EXPECT_TRUE(s.contains("peak_rss_bytes"));
  // The files written, in the list's order (no profile.tsv without a profile axis).
  EXPECT_EQ(s["outputs"], nlohmann::json({"summary.json", "thermo.tsv", "trajectory.gsd",
                                          "restart.gsd", "run.log", "config.toml"}));
}

// The structure analyses of [analysis] sample the production only: at its 8 thermo rows, or
// at their own interval; each writes its file and its part of summary.json (contact values
// only for the hard spheres of the event engine, the DEM's being soft).
TEST_P(Outputs, AnalysesSampleTheProductionAndWriteTheirFiles) {
  const std::vector<std::string> all = {"analysis.rdf=true", "analysis.structure_factor=true",
                                        "analysis.bond_order=true",
                                        "analysis.velocity_distribution=true"};
  const RunOutcome outcome = run(all);
  ASSERT_TRUE(outcome.error.empty()) << outcome.error;
  const nlohmann::json& s = outcome.summary;
  const nlohmann::json& a = s["analysis"];
  for (const char* key : {"rdf", "structure_factor", "bond_order", "velocity_distribution"})
    EXPECT_EQ(a[key]["samples"], 8) << key;
  EXPECT_EQ(a["covers"], "the production");
  EXPECT_EQ(s["outputs"], nlohmann::json({"summary.json", "thermo.tsv", "trajectory.gsd",
                                          "restart.gsd", "rdf.tsv", "sk.tsv", "bond_order.tsv",
                                          "velocity_distribution.tsv", "run.log", "config.toml"}));
  const bool dem = std::string(GetParam()) == "dem";
  EXPECT_EQ(a["rdf"]["contact"].is_null(), dem);
  EXPECT_EQ(a["rdf"]["compressibility_from_contact"]["mean"].is_null(), dem);
  if (dem) {
    EXPECT_TRUE(s["undefined"].contains("analysis.rdf.contact"));
  }
  EXPECT_TRUE(a["bond_order"]["q6"]["global"].is_number());
  EXPECT_TRUE(a["structure_factor"]["s_k_min"].is_number());
  EXPECT_NEAR(a["velocity_distribution"]["kurtosis"].get<double>(), 3.0, 0.5);
  std::ifstream rdf(dir_ / "rdf.tsv");
  std::string line;
  std::getline(rdf, line);
  EXPECT_EQ(line.rfind("# 8 samples;", 0), 0u) << line;
  // Every 1.5 collisions per particle of the production (from 1.0 to 5.0: 2.5 and 4.0).
  fs::remove_all(dir_);
  std::vector<std::string> timed = all;
  timed.push_back("analysis.interval=1.5");
  const RunOutcome every = run(timed);
  ASSERT_TRUE(every.error.empty()) << every.error;
  EXPECT_EQ(every.summary["analysis"]["rdf"]["samples"], 2);
  EXPECT_EQ(every.summary["analysis"]["velocity_distribution"]["samples"], 2);
}

TEST_P(Outputs, NoAnalysisNoTableNoFilesNoSummaryPart) {
  ASSERT_TRUE(run().error.empty());
  std::ifstream in(dir_ / "config.toml");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text.find("[analysis]"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir_ / "rdf.tsv"));
}

INSTANTIATE_TEST_SUITE_P(BothIntegrators, Outputs, ::testing::Values("event", "dem"));

}  // namespace
}  // namespace kairos
