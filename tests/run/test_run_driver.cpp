// The one run driver (run/run_driver.hpp) with its observers (run/outputs/): an observer added
// to the list is called by both integrators, at the collisions or times its trigger says, at
// every production thermo row, and once at the end; a failed write stops the run, leaves the
// other outputs written and is not tried again; and the DEM, run by the same driver, records
// the row owed after a failed write as the event engine does.
#include "run/run_driver.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/stop_flag.hpp"
#include "io/config.hpp"
#include "run/run_progress.hpp"

namespace kairos {
namespace {

namespace fs = std::filesystem;

class RunDriverTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("kairos_run_driver_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    clear_stop_request();
  }
  void TearDown() override { fs::remove_all(dir_); }

  // 256 hard spheres (or soft spheres under the DEM) at packing fraction 0.3; `extra`: more
  // TOML (keys of [run] and [output] first, then tables).
  Config config(const std::string& integrator, const std::string& run, const std::string& output,
                const std::string& name = "out") const {
    std::string text =
        "[system]\nparticles = 256\npacking_fraction = 0.3\nseed = 5\n"
        "[run]\nintegrator = \"" +
        integrator + "\"\n" + run + "\n[output]\nprogress = \"never\"\ndirectory = \"" +
        (dir_ / name).string() + "\"\n" + output + "\n";
    if (integrator == "dem") {
      text += "[soft]\nmodel = \"dashpot\"\nstiffness = 10000.0\nrestitution = 0.9\n";
    }
    return parse_config(text, "<test>");
  }

  fs::path dir_;
};

// An output that records when the driver calls it.
template <int D>
class Recorder final : public Observer<D> {
 public:
  struct Calls {
    std::vector<std::uint64_t> collisions;  // at each write()
    std::vector<double> times;
    int samples = 0, closes = 0, opens = 0, production_starts = 0;
  };
  Recorder(Calls& calls, double interval, int fail_at = -1, bool in_collisions = false)
      : calls_(calls), interval_(interval), fail_at_(fail_at), in_collisions_(in_collisions) {}
  std::string name() const override { return "recorder.tsv"; }
  double interval(const Config&, double) const override { return interval_; }
  bool samples_in_collisions() const override { return in_collisions_; }
  void open(const RunContext<D>&) override { ++calls_.opens; }
  void write(const RunContext<D>& run) override {
    if (static_cast<int>(calls_.collisions.size()) == fail_at_) {
      calls_.collisions.push_back(~std::uint64_t{0});  // the failed call, marked
      throw InputError("recorder.tsv: no space left on device");
    }
    calls_.collisions.push_back(run.integrator().collisions());
    calls_.times.push_back(run.integrator().time());
  }
  void sample(const RunContext<D>&) override { ++calls_.samples; }
  void production_starts(const RunContext<D>&) override { ++calls_.production_starts; }
  void close(const RunContext<D>&, bool) override { ++calls_.closes; }
  void summarize(nlohmann::json& summary, const RunContext<D>&) const override {
    summary["recorder"] = {{"writes", calls_.collisions.size()}};
  }

 private:
  Calls& calls_;
  double interval_;
  int fail_at_;
  bool in_collisions_;
};

// Rows of thermo.tsv by phase.
int rows_of(const fs::path& thermo, const std::string& phase) {
  std::ifstream in(thermo);
  std::string line;
  int rows = 0;
  std::getline(in, line);  // the header
  while (std::getline(in, line)) rows += line.rfind(phase + "\t", 0) == 0 ? 1 : 0;
  return rows;
}

TEST_F(RunDriverTest, ATriggerInCollisionsFiresAtEachThresholdOfThePhase) {
  // 0.5 collisions per particle = 64 collisions; the event engine meets each exactly.
  const Config c =
      config("event", "equilibration_collisions_per_particle = 1.0\ncollisions_per_particle = 3.0",
             "thermo_interval = 1.0");
  Recorder<3>::Calls calls;
  RunDriver<3> driver(c, std::nullopt, {});
  driver.add_observer(std::make_unique<Recorder<3>>(calls, 0.5));
  const RunOutcome outcome = driver.run();
  ASSERT_TRUE(outcome.error.empty()) << outcome.error;
  // Equilibration: 64, 128 (its end); production from 128: 192, ..., 512.
  EXPECT_EQ(calls.collisions, (std::vector<std::uint64_t>{64, 128, 192, 256, 320, 384, 448, 512}));
  EXPECT_EQ(calls.opens, 1);
  EXPECT_EQ(calls.closes, 1);
  EXPECT_EQ(calls.production_starts, 1);
  // Sampled at every production row of thermo.tsv.
  EXPECT_EQ(calls.samples, rows_of(dir_ / "out" / "thermo.tsv", "production"));
  EXPECT_EQ(calls.samples, 3);
  EXPECT_EQ(outcome.summary["recorder"]["writes"], 8);
}

TEST_F(RunDriverTest, ATriggerInTimeFiresAtTheMultiplesOfItsInterval) {
  const Config c =
      config("event", "equilibration_time = 0.0\ntime = 1.0", "interval_unit = \"time\"");
  Recorder<3>::Calls calls;
  RunDriver<3> driver(c, std::nullopt, {});
  driver.add_observer(std::make_unique<Recorder<3>>(calls, 0.25));
  ASSERT_TRUE(driver.run().error.empty());
  // The event engine stops its clock at each (no event needs to happen there).
  EXPECT_EQ(calls.times, (std::vector<double>{0.25, 0.5, 0.75, 1.0}));
}

TEST_F(RunDriverTest, AnObserverOnTheCollisionClockCountsCollisionsInARunMeasuredInTime) {
  // Phases and output intervals in time, the observer's interval in collisions per particle
  // (the MSD of a cooling gas): 0.5 per particle = 64 collisions, met exactly, from the
  // production's start.
  const Config c =
      config("event", "equilibration_time = 0.0\ntime = 2.0", "interval_unit = \"time\"");
  Recorder<3>::Calls calls;
  RunDriver<3> driver(c, std::nullopt, {});
  driver.add_observer(std::make_unique<Recorder<3>>(calls, 0.5, -1, /*in_collisions=*/true));
  const RunOutcome outcome = driver.run();
  ASSERT_TRUE(outcome.error.empty()) << outcome.error;
  ASSERT_GE(calls.collisions.size(), 3u);
  for (std::size_t k = 0; k < calls.collisions.size(); ++k)
    EXPECT_EQ(calls.collisions[k], 64 * (k + 1));
  // Every threshold the run passed: the last one within 64 collisions of the end.
  const auto total = static_cast<std::uint64_t>(
      std::llround(outcome.summary["production_collisions_per_particle"].get<double>() * 128.0));
  EXPECT_LT(total - calls.collisions.back(), 64u);
}

TEST_F(RunDriverTest, TheDemCallsTheSameObserversAtTheStepThatReachesTheirTriggers) {
  const Config c = config(
      "dem", "equilibration_collisions_per_particle = 0.0\ncollisions_per_particle = 4.0", "");
  Recorder<3>::Calls calls;
  RunDriver<3> driver(c, std::nullopt, {});
  driver.add_observer(std::make_unique<Recorder<3>>(calls, 1.0));
  const RunOutcome outcome = driver.run();
  ASSERT_TRUE(outcome.error.empty()) << outcome.error;
  EXPECT_EQ(outcome.summary["integrator"], "dem");
  // Several pairs may enter contact in one step: each threshold (128 collisions apart) is met
  // at or just past it, once.
  ASSERT_EQ(calls.collisions.size(), 4u);
  for (std::size_t k = 0; k < calls.collisions.size(); ++k) {
    EXPECT_GE(calls.collisions[k], 128 * (k + 1));
    EXPECT_LT(calls.collisions[k], 128 * (k + 1) + 64);
  }
  EXPECT_EQ(calls.samples, rows_of(dir_ / "out" / "thermo.tsv", "production"));
  EXPECT_GT(calls.samples, 0);
  EXPECT_EQ(calls.closes, 1);
}

TEST_F(RunDriverTest, TheDemMeetsTimeTriggersAtTheFirstStepAtOrAfterThem) {
  const Config c = config("dem", "equilibration_time = 0.0\ntime = 0.5",
                          "interval_unit = \"time\"\nthermo_interval = 0.1");
  Recorder<3>::Calls calls;
  RunDriver<3> driver(c, std::nullopt, {});
  driver.add_observer(std::make_unique<Recorder<3>>(calls, 0.125));
  const RunOutcome outcome = driver.run();
  ASSERT_TRUE(outcome.error.empty()) << outcome.error;
  const double dt = outcome.summary["dem"]["time_step"];
  ASSERT_EQ(calls.times.size(), 4u);
  for (std::size_t k = 0; k < calls.times.size(); ++k) {
    const double due = 0.125 * static_cast<double>(k + 1);
    EXPECT_GE(calls.times[k], due - 1e-9 * dt);
    EXPECT_LT(calls.times[k], due + dt);
  }
}

// A write that fails stops the run: the error is the run's, the restart file and summary.json
// are still written, and the observer that failed is not called for writing again.
template <int D>
void expect_a_failed_write_stops_the_run(const Config& c, const fs::path& out) {
  typename Recorder<D>::Calls calls;
  RunDriver<D> driver(c, std::nullopt, {});
  driver.add_observer(std::make_unique<Recorder<D>>(calls, 0.5, /*fail_at=*/2));
  const RunOutcome outcome = driver.run();
  EXPECT_NE(outcome.error.find("no space left on device"), std::string::npos) << outcome.error;
  EXPECT_EQ(outcome.summary["stop_reason"], "write_failed");
  EXPECT_FALSE(outcome.interrupted);
  EXPECT_EQ(calls.collisions.size(), 3u);  // two written, the third failed, no more
  EXPECT_EQ(calls.closes, 0);              // the failed output is not closed either
  EXPECT_TRUE(fs::exists(out / "restart.gsd"));
  EXPECT_TRUE(fs::exists(out / "summary.json"));
  // The run stopped at the failure, long before its end.
  EXPECT_LT(outcome.summary["production_collisions_per_particle"].get<double>(), 5.0);
}

TEST_F(RunDriverTest, AFailedWriteStopsTheEventRunWithEveryOtherOutputWritten) {
  expect_a_failed_write_stops_the_run<3>(
      config("event", "collisions_per_particle = 20.0", "", "event"), dir_ / "event");
}

TEST_F(RunDriverTest, AFailedWriteStopsTheDemRunWithEveryOtherOutputWritten) {
  expect_a_failed_write_stops_the_run<3>(config("dem", "collisions_per_particle = 20.0", "", "dem"),
                                         dir_ / "dem");
}

// Stops the run (as a signal would) at its k-th call.
template <int D>
class StopAt final : public Observer<D> {
 public:
  explicit StopAt(int k) : k_(k) {}
  std::string name() const override { return "stop.tsv"; }
  bool writes_file() const override { return false; }
  double interval(const Config&, double) const override { return 0.75; }
  void write(const RunContext<D>&) override {
    if (++calls_ == k_) request_stop();
  }

 private:
  int k_, calls_ = 0;
};

std::string text_of(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// A production stopped part-way and completed from its restart file in the same directory ends
// with summary.json's production averages of one uninterrupted run, bit for bit: Z with its
// blocked error, the pressure, the production time and temperature, the mean free time, the
// stepped energy per particle and a free lid's height (the thermo.tsv rows of the earlier
// invocation read back, its start from the restart file); `extra` gives the system, `run` more
// [run] keys.
void expect_stopped_production_averages_as_whole(const fs::path& dir, const std::string& extra,
                                                 const std::string& run = "") {
  const auto config = [&](const std::string& name) {
    return parse_config(
        "[system]\nparticles = 200\npacking_fraction = 0.2\nlattice = \"random\"\nseed = 3\n"
        "[run]\nequilibration_time = 0.0\ntime = 6.0\n" +
            run +
            "[output]\nprogress = \"never\"\n"
            "interval_unit = \"time\"\nthermo_interval = 0.25\ntrajectory = false\ndirectory = \"" +
            (dir / name).string() + "\"\n" + extra,
        "<test>");
  };
  const Config split = config("split"), whole = config("whole");
  {
    RunDriver<3> first(split, std::nullopt, {});
    first.add_observer(std::make_unique<StopAt<3>>(3));
    const RunOutcome outcome = first.run();
    ASSERT_EQ(outcome.summary["stop_reason"], "signal");
    ASSERT_LT(outcome.summary["production_time"].get<double>(), 3.0);
  }
  clear_stop_request();
  RunDriver<3> second(split, dir / "split" / "restart.gsd", {});
  const RunOutcome continued = second.run();
  ASSERT_EQ(continued.summary["stop_reason"], "completed") << continued.error;
  RunDriver<3> uninterrupted(whole, std::nullopt, {});
  const RunOutcome reference = uninterrupted.run();
  ASSERT_EQ(text_of(dir / "split" / "thermo.tsv"), text_of(dir / "whole" / "thermo.tsv"));
  const nlohmann::json& a = continued.summary;
  const nlohmann::json& b = reference.summary;
  EXPECT_NE(a["production_covers"].get<std::string>().find("whole production"), std::string::npos);
  for (const char* key :
       {"production_time", "production_collisions_per_particle", "production_temperature"})
    EXPECT_EQ(a[key], b[key]) << key;
  for (const char* key : {"mean", "stderr", "stderr_blocks"})
    EXPECT_EQ(a["compressibility"][key], b["compressibility"][key]) << key;
  EXPECT_EQ(a["compressibility"]["blocks"], b["compressibility"]["blocks"]);
  EXPECT_EQ(a["mean_free_time"], b["mean_free_time"]);
  EXPECT_EQ(a.value("pressure", nlohmann::json()), b.value("pressure", nlohmann::json()));
  if (b.contains("stepped")) {
    for (const char* key : {"potential_energy_per_particle_mean",
                            "potential_energy_per_particle_stderr", "potential_energy_rows"})
      EXPECT_EQ(a["stepped"][key], b["stepped"][key]) << key;
  }
  if (b.contains("walls_with_mass")) {
    for (const char* key : {"position_mean", "position_stderr", "speed_rms", "samples"})
      EXPECT_EQ(a["walls_with_mass"][0][key], b["walls_with_mass"][0][key]) << key;
  }
  // Without the restored rows the continued run would have averaged its own rows only.
  EXPECT_GT(a["compressibility"]["blocks"].get<int>(), 20);
}

TEST_F(RunDriverTest, AStoppedProductionCompletedInItsDirectoryAveragesAsOneUninterruptedRun) {
  expect_stopped_production_averages_as_whole(
      dir_,
      "[[potential]]\nkind = \"square_well\"\nlambda = 1.5\ndepth = 0.5\n"
      "[driving]\nkind = \"andersen\"\nrate = 1.0\ntemperature = 1.0\n");
}

TEST_F(RunDriverTest, AStoppedDemProductionAveragesAsOneUninterruptedRun) {
  expect_stopped_production_averages_as_whole(
      dir_, "[soft]\nmodel = \"dashpot\"\nstiffness = 10000.0\nrestitution = 0.9\n",
      "integrator = \"dem\"\n");
}

TEST_F(RunDriverTest, AStoppedProductionUnderAFreeLidAveragesItsHeightAsOneUninterruptedRun) {
  expect_stopped_production_averages_as_whole(
      dir_,
      "[[boundary.wall]]\nface = \"z-\"\n[[boundary.wall]]\nface = \"z+\"\n"
      "mass = 50.0\nforce = 20.0\n");
}

// What a write that failed leaves owed is recorded in the restart file, and a run continued
// in the same directory writes it first, before any event: for the DEM too, now that both run
// in one driver (the recorder stands in for the trajectory here: output.trajectory = false
// leaves the frame's bit to it).
template <int D>
class OwedRecorder final : public Observer<D> {
 public:
  OwedRecorder(std::vector<std::uint64_t>& writes, int fail_at)
      : writes_(writes), fail_at_(fail_at) {}
  std::string name() const override { return "owed.tsv"; }
  double interval(const Config&, double) const override { return 0.5; }
  unsigned owed_bit() const override { return RunProgress::kOwedFrame; }
  void write(const RunContext<D>& run) override {
    if (static_cast<int>(writes_.size()) == fail_at_) {
      fail_at_ = -1;
      throw InputError("owed.tsv: no space left on device");
    }
    writes_.push_back(run.integrator().collisions());
  }

 private:
  std::vector<std::uint64_t>& writes_;
  int fail_at_;
};

void expect_owed_output_written_first(const Config& c, const fs::path& out) {
  std::vector<std::uint64_t> first, second;
  {
    RunDriver<3> driver(c, std::nullopt, {});
    driver.add_observer(std::make_unique<OwedRecorder<3>>(first, /*fail_at=*/2));
    const RunOutcome outcome = driver.run();
    ASSERT_EQ(outcome.summary["stop_reason"], "write_failed") << outcome.error;
  }
  std::mt19937_64 rng;
  RunProgress progress;
  const ParticleSystem<3> state =
      read_restart_file<3>(out / "restart.gsd", rng, progress, RunKind::kDem);
  EXPECT_EQ(progress.owed_outputs, RunProgress::kOwedFrame);
  RunDriver<3> continued(c, out / "restart.gsd", {});
  continued.add_observer(std::make_unique<OwedRecorder<3>>(second, /*fail_at=*/-1));
  const RunOutcome outcome = continued.run();
  ASSERT_TRUE(outcome.error.empty()) << outcome.error;
  ASSERT_FALSE(second.empty());
  EXPECT_EQ(second.front(), state.counters.collisions);  // the owed write, before any event
  ASSERT_EQ(first.size(), 2u);
  EXPECT_GT(second.front(), first.back());
}

TEST_F(RunDriverTest, TheEventRunWritesWhatWasOwedFirst) {
  expect_owed_output_written_first(
      config("event", "collisions_per_particle = 20.0", "trajectory = false", "event"),
      dir_ / "event");
}

TEST_F(RunDriverTest, TheDemRecordsWhatIsOwedAndWritesItFirstToo) {
  expect_owed_output_written_first(
      config("dem", "collisions_per_particle = 20.0", "trajectory = false", "dem"), dir_ / "dem");
}

}  // namespace
}  // namespace kairos
