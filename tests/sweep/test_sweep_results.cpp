// A sweep's record of its runs (sweep/sweep_results.hpp): the state read from each run
// directory, and the table written from them.
#include "sweep/sweep_results.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace kairos {
namespace {

namespace fs = std::filesystem;

class SweepResults : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("kairos_sweep_results_" +
            std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path run(const std::string& name) {
    fs::create_directories(dir_ / name);
    return dir_ / name;
  }
  static void write(const fs::path& file, const std::string& text) { std::ofstream(file) << text; }
  static std::string read(const fs::path& file) {
    std::ifstream in(file);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
  }

  fs::path dir_;
};

TEST_F(SweepResults, TheStateComesFromTheSummaryAndTheConsole) {
  EXPECT_EQ(read_sweep_run(run("empty")).state, SweepRunState::kNotRun);

  const fs::path done = run("done");
  write(done / "summary.json", R"({"stop_reason": "completed", "sim_time": 2.5})");
  EXPECT_EQ(read_sweep_run(done).state, SweepRunState::kFinished);
  write(done / "summary.json", R"({"stop_reason": "at_rest"})");
  EXPECT_EQ(read_sweep_run(done).state, SweepRunState::kFinished);

  const fs::path stopped = run("stopped");
  write(stopped / "summary.json", R"({"stop_reason": "signal"})");
  write(stopped / "restart.gsd", "x");
  const SweepRunRecord s = read_sweep_run(stopped);
  EXPECT_EQ(s.state, SweepRunState::kStopped);
  EXPECT_TRUE(s.has_restart);

  // Killed before any summary: its restart file continues it.
  const fs::path killed = run("killed");
  write(killed / "restart.gsd", "x");
  EXPECT_EQ(read_sweep_run(killed).state, SweepRunState::kStopped);

  const fs::path broken = run("broken");
  write(broken / "summary.json", R"({"stop_reason": "error", "error": "walls leave no room"})");
  const SweepRunRecord b = read_sweep_run(broken);
  EXPECT_EQ(b.state, SweepRunState::kFailed);
  EXPECT_EQ(b.error, "walls leave no room");

  // Refused at set-up: no summary, the console's last attempt says why. An earlier attempt's
  // error does not count once a later attempt has begun.
  const fs::path refused = run("refused");
  write(refused / kSweepConsoleFile,
        "kairos sweep: attempt: kairos run a.toml\nkairos: error: system.particles: must be > 0\n");
  const SweepRunRecord r = read_sweep_run(refused);
  EXPECT_EQ(r.state, SweepRunState::kFailed);
  EXPECT_EQ(r.error, "system.particles: must be > 0");
  write(refused / kSweepConsoleFile,
        read(refused / kSweepConsoleFile) + "kairos sweep: attempt: kairos run a.toml\n");
  EXPECT_EQ(read_sweep_run(refused).state, SweepRunState::kNotRun);

  const fs::path crashed = run("crashed");
  write(crashed / kSweepConsoleFile,
        "kairos sweep: attempt: x\nkairos sweep: error: the run was killed by SIGSEGV\n");
  EXPECT_EQ(read_sweep_run(crashed).error, "the run was killed by SIGSEGV");

  // A torn summary (the run killed while... it is written atomically, but a user may edit it).
  write(done / "summary.json", "{\"stop_reason\": ");
  EXPECT_EQ(read_sweep_run(done).state, SweepRunState::kNotRun);
}

TEST_F(SweepResults, FlattenedSummariesNameEveryValue) {
  const auto flat = flattened_summary(nlohmann::json::parse(
      R"({"a": 1.5, "b": {"mean": 2, "stderr": null}, "t": [[1, 2], [3, 4]], "o": ["x", "y"],
          "s": "one\ttwo", "e": []})"));
  const std::vector<std::pair<std::string, std::string>> want = {
      {"a", "1.5"},     {"b.mean", "2"}, {"b.stderr", "nan"}, {"e", ""},      {"o", "x,y"},
      {"s", "one two"}, {"t.0.0", "1"},  {"t.0.1", "2"},      {"t.1.0", "3"}, {"t.1.1", "4"}};
  EXPECT_EQ(flat, want);
}

TEST_F(SweepResults, TheTableHasOneRowPerRunAndEveryKey) {
  const std::vector<SweepAxis> axes = {parse_sweep_axis("system.packing_fraction=0.1,0.2"),
                                       parse_sweep_axis("system.lattice=fcc")};
  const std::vector<SweepPoint> points = sweep_points(axes);
  write(run(points[0].name) / "summary.json",
        R"({"stop_reason": "completed", "compressibility": {"mean": 1.5, "stderr": 0.01}})");
  write(run(points[1].name) / "summary.json",
        R"({"stop_reason": "completed", "compressibility": {"mean": 2.5}, "extra": true})");
  const std::vector<SweepRunState> states = write_sweep_results(dir_, axes, points);
  EXPECT_EQ(states,
            (std::vector<SweepRunState>{SweepRunState::kFinished, SweepRunState::kFinished}));
  const std::string tsv = read(dir_ / "results.tsv");
  EXPECT_EQ(tsv,
            "run\tdirectory\tstate\terror\tsystem.packing_fraction\tsystem.lattice\t"
            "compressibility.mean\tcompressibility.stderr\textra\tstop_reason\n"
            "0\t" +
                points[0].name +
                "\tfinished\t\t0.1\tfcc\t1.5\t0.01\t\tcompleted\n"
                "1\t" +
                points[1].name + "\tfinished\t\t0.2\tfcc\t2.5\t\ttrue\tcompleted\n");
  const nlohmann::json json = nlohmann::json::parse(read(dir_ / "results.json"));
  ASSERT_EQ(json["runs"].size(), 2u);
  EXPECT_EQ(json["runs"][1]["values"]["system.packing_fraction"], 0.2);
  EXPECT_EQ(json["runs"][1]["values"]["system.lattice"], "fcc");
  EXPECT_EQ(json["runs"][1]["summary"]["compressibility"]["mean"], 2.5);
  EXPECT_EQ(json["vary"][0]["key"], "system.packing_fraction");
}

}  // namespace
}  // namespace kairos
