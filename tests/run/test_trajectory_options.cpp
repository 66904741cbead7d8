// trajectory.gsd's options (output.trajectory_*; run/outputs/trajectory_output.hpp), under both
// integrators where they apply: production-only frames start at the production; the fields
// listed are the chunks of every frame; float64 frames hold the engine's positions and
// velocities bit for bit, with images that unwrap them; log-spaced frames fall on their exact
// times (and collision counts), cycles included; a run interrupted (a signal, or killed after a
// later restart file) and continued writes the frames of one uninterrupted run; bad values are
// refused naming the key.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/stop_flag.hpp"
#include "io/config.hpp"
#include "io/gsd_file.hpp"
#include "run/run.hpp"
#include "run/run_driver.hpp"
#include "run/run_progress.hpp"

namespace kairos {
namespace {

namespace fs = std::filesystem;

// One frame as read back: its log scalars, and its per-particle chunks as doubles with the
// type they were stored in.
struct Frame {
  double time = 0.0;
  std::uint64_t collisions = 0;
  gsd::Type position_type{};
  std::vector<double> position, velocity, box;
  std::vector<std::int32_t> image;
};

std::vector<double> reals(const gsd::Reader& r, std::uint64_t f, const char* name) {
  const auto info = r.find(f, name);
  if (!info) return {};
  if (info->type == gsd::Type::float64) return r.read<double>(f, name);
  const auto single = r.read<float>(f, name);
  return {single.begin(), single.end()};
}

std::vector<Frame> frames_of(const fs::path& file) {
  const gsd::Reader r(file);
  std::vector<Frame> out;
  for (std::uint64_t f = 0; f < r.frame_count(); ++f) {
    Frame frame;
    frame.time = r.read<double>(f, "log/time")[0];
    frame.collisions = r.read<std::uint64_t>(f, "log/collisions")[0];
    frame.position_type = r.find(f, "particles/position")->type;
    frame.position = reals(r, f, "particles/position");
    frame.velocity = reals(r, f, "particles/velocity");
    frame.box = reals(r, f, "configuration/box");
    if (r.find(f, "particles/image")) frame.image = r.read<std::int32_t>(f, "particles/image");
    out.push_back(std::move(frame));
  }
  return out;
}

std::vector<double> times_of(const std::vector<Frame>& frames) {
  std::vector<double> t;
  for (const Frame& f : frames) t.push_back(f.time);
  return t;
}

std::vector<std::uint64_t> collisions_of(const std::vector<Frame>& frames) {
  std::vector<std::uint64_t> c;
  for (const Frame& f : frames) c.push_back(f.collisions);
  return c;
}

// Frame for frame the same states: times, collision counts and every value bit for bit.
void expect_same_frames(const fs::path& a, const fs::path& b) {
  const std::vector<Frame> x = frames_of(a), y = frames_of(b);
  ASSERT_EQ(times_of(x), times_of(y));
  ASSERT_EQ(collisions_of(x), collisions_of(y));
  for (std::size_t f = 0; f < x.size(); ++f) {
    SCOPED_TRACE("frame " + std::to_string(f));
    EXPECT_EQ(x[f].position_type, y[f].position_type);
    EXPECT_EQ(x[f].position, y[f].position);
    EXPECT_EQ(x[f].velocity, y[f].velocity);
    EXPECT_EQ(x[f].image, y[f].image);
  }
}

// At its k-th write (1, 2, ...): asks the run to stop (a signal), or keeps a copy of the restart
// file written at the same moment (a later kill -9 leaves the run continued from it with the
// frames written after it).
template <int D>
class Interrupter final : public Observer<D> {
 public:
  enum Mode { kStop, kCopyRestart };
  Interrupter(double interval, int at, Mode mode) : interval_(interval), at_(at), mode_(mode) {}
  std::string name() const override { return "interrupter"; }
  bool writes_file() const override { return false; }
  double interval(const Config&, double) const override { return interval_; }
  void write(const RunContext<D>& run) override {
    if (++writes_ != at_) return;
    if (mode_ == kStop) {
      request_stop();
    } else {
      fs::copy_file(run.directory() / "restart.gsd", run.directory() / "early.gsd",
                    fs::copy_options::overwrite_existing);
    }
  }

 private:
  double interval_;
  int at_, writes_ = 0;
  Mode mode_;
};

class TrajectoryOptions : public ::testing::TestWithParam<const char*> {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = info->name();
    for (char& c : name)
      if (c == '/') c = '_';
    dir_ = fs::temp_directory_path() / ("kairos_traj_" + std::to_string(::getpid()) + "_" + name);
    fs::remove_all(dir_);
    clear_stop_request();
  }
  void TearDown() override {
    clear_stop_request();
    fs::remove_all(dir_);
  }
  bool dem() const { return std::string(GetParam()) == "dem"; }

  // 256 particles at packing fraction 0.3 (soft spheres under the DEM); `run` and `output`:
  // keys of [run] and [output].
  Config config(const std::string& run, const std::string& output,
                const std::string& out = "out") const {
    std::string text = "[system]\nparticles = 256\npacking_fraction = 0.3\nseed = 3\n[run]\n" +
                       run + "\nintegrator = \"" + GetParam() +
                       "\"\n[output]\nprogress = \"never\"\ndirectory = \"" +
                       (dir_ / out).string() + "\"\n" + output + "\n";
    if (dem()) text += "[soft]\nmodel = \"dashpot\"\nstiffness = 10000.0\nrestitution = 0.9\n";
    return parse_config(text, "<test>");
  }
  fs::path file(const std::string& out) const { return dir_ / out / "trajectory.gsd"; }

  // The run of `c` uninterrupted into `out`; interrupted at the interrupter's `at`-th write and
  // continued into `out` from the restart file then written (kStop), or run whole and
  // continued from the restart file of that moment (kCopyRestart: frames written after it
  // are dropped).
  void run_whole(const Config& c) const {
    const RunOutcome outcome = run_simulation(c);
    ASSERT_TRUE(outcome.error.empty()) << outcome.error;
  }
  // `phase`: the one the restart file is written in (0 equilibration, 1 production).
  void run_interrupted(const Config& c, const std::string& out, double every, int at,
                       Interrupter<3>::Mode mode, int phase) const {
    {
      RunDriver<3> driver(c, std::nullopt, {});
      driver.add_observer(std::make_unique<Interrupter<3>>(every, at, mode));
      const RunOutcome outcome = driver.run();
      ASSERT_TRUE(outcome.error.empty()) << outcome.error;
      ASSERT_EQ(outcome.interrupted, mode == Interrupter<3>::kStop);
    }
    clear_stop_request();
    const fs::path restart =
        dir_ / out / (mode == Interrupter<3>::kStop ? "restart.gsd" : "early.gsd");
    ASSERT_TRUE(fs::exists(restart));
    std::mt19937_64 rng;
    RunProgress progress;
    read_restart_file<3>(restart, rng, progress, RunKind::kDem);
    ASSERT_EQ(progress.schedule_phase, phase);
    // Frames past the restart point are there to be dropped (the frame written at a stop,
    // those written after the restart file a kill left).
    if (fs::exists(file(out))) {
      ASSERT_GT(gsd::Reader(file(out)).frame_count(),
                static_cast<std::uint64_t>(std::max<std::int64_t>(0, progress.trajectory_frames)));
    }
    const RunOutcome continued = run_simulation(c, restart);
    ASSERT_TRUE(continued.error.empty()) << continued.error;
    ASSERT_FALSE(continued.interrupted);
  }

  fs::path dir_;
};

// ----- output.trajectory_phases

TEST_P(TrajectoryOptions, ProductionOnlyFramesStartAtTheProduction) {
  // Equilibration 1 collision per particle (128 collisions), production 4; frames every 1.5.
  const std::string run =
      "equilibration_collisions_per_particle = 1.0\ncollisions_per_particle "
      "= 4.0";
  run_whole(config(run, "trajectory_interval = 1.5", "all"));
  run_whole(config(run, "trajectory_interval = 1.5\ntrajectory_phases = \"production\"", "prod"));
  const std::vector<Frame> all = frames_of(file("all")), prod = frames_of(file("prod"));
  // All: frame 0 at the start; production only: its first frame is the production's start
  // (the DEM: the step that ended the equilibration), then 2.5, 4.0 and the end, 5.0.
  EXPECT_EQ(all.front().collisions, 0u);
  ASSERT_EQ(prod.size(), 4u);
  EXPECT_GE(prod.front().collisions, 128u);
  if (!dem()) {
    EXPECT_EQ(prod.front().collisions, 128u);
  }
  EXPECT_LT(prod.front().collisions, 128u + 64u);
  for (const Frame& f : prod) EXPECT_GE(f.time, prod.front().time);
  // The production's frames are the same states in both.
  const std::vector<std::uint64_t> a = collisions_of(all);
  for (std::size_t k = 1; k < prod.size(); ++k) {
    EXPECT_NE(std::find(a.begin(), a.end(), prod[k].collisions), a.end()) << k;
  }
}

TEST_P(TrajectoryOptions, ProductionOnlyFramesInTimeStartAtTheProductionToo) {
  run_whole(config("equilibration_time = 0.5\ntime = 1.0",
                   "trajectory_interval = 0.25\ntrajectory_phases = \"production\""));
  const std::vector<Frame> f = frames_of(file("out"));
  ASSERT_EQ(f.size(), 5u);
  const double start = f.front().time;  // the equilibration's end
  if (!dem()) {
    EXPECT_EQ(start, 0.5);
    EXPECT_EQ(times_of(f), (std::vector<double>{0.5, 0.75, 1.0, 1.25, 1.5}));
  }
  for (const Frame& x : f) EXPECT_GE(x.time, 0.5);
}

// ----- output.trajectory_fields

TEST_P(TrajectoryOptions, TheFieldsListedAreTheChunksOfEveryFrame) {
  run_whole(config("equilibration_collisions_per_particle = 0.0\ncollisions_per_particle = 2.0",
                   "trajectory_interval = 1.0\ntrajectory_fields = [\"position\", \"mass\"]"));
  const gsd::Reader r(file("out"));
  ASSERT_EQ(r.frame_count(), 3u);
  for (std::uint64_t f = 0; f < r.frame_count(); ++f) {
    SCOPED_TRACE("frame " + std::to_string(f));
    EXPECT_TRUE(r.find(f, "particles/position"));
    EXPECT_TRUE(r.find(f, "particles/mass"));  // listed: in every frame
    EXPECT_FALSE(r.find(f, "particles/velocity"));
    EXPECT_FALSE(r.find(f, "particles/image"));
    EXPECT_TRUE(r.find(f, "configuration/box"));
    EXPECT_TRUE(r.find(f, "log/time"));
    // What readers need, in frame 0 only.
    EXPECT_EQ(r.find(f, "particles/types").has_value(), f == 0);
    EXPECT_EQ(r.find(f, "particles/typeid").has_value(), f == 0);
    EXPECT_EQ(r.find(f, "particles/diameter").has_value(), f == 0);
  }
  // The default: every field the state has (images: the event integrator), static ones in
  // frame 0 only.
  run_whole(config("equilibration_collisions_per_particle = 0.0\ncollisions_per_particle = 2.0",
                   "trajectory_interval = 1.0", "default"));
  const gsd::Reader d(file("default"));
  EXPECT_TRUE(d.find(1, "particles/velocity"));
  EXPECT_EQ(d.find(1, "particles/image").has_value(), !dem());
  EXPECT_FALSE(d.find(1, "particles/mass"));
}

TEST_P(TrajectoryOptions, FieldsTheStateLacksAreRefusedNamingTheKey) {
  // Smooth spheres do not spin.
  const Config c = config("collisions_per_particle = 1.0",
                          "trajectory_fields = [\"position\", \"angular_velocity\"]");
  try {
    run_simulation(c);
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("output.trajectory_fields"), std::string::npos) << m;
    EXPECT_NE(m.find("angular_velocity"), std::string::npos) << m;
  }
}

// ----- output.trajectory_precision

TEST_P(TrajectoryOptions, DoubleFramesHoldTheEnginesPositionsAndVelocitiesBitForBit) {
  const std::string run =
      "equilibration_collisions_per_particle = 0.0\ncollisions_per_particle = 6.0";
  run_whole(config(run, "trajectory_interval = 1.0\ntrajectory_precision = \"double\"", "double"));
  run_whole(config(run, "trajectory_interval = 1.0", "single"));
  const gsd::Reader r(file("double"));
  for (const char* chunk : {"configuration/box", "particles/position", "particles/velocity",
                            "particles/diameter", "particles/mass"}) {
    EXPECT_EQ(r.find(0, chunk)->type, gsd::Type::float64) << chunk;
  }
  // The last frame is the final state: that of the restart file, whose kairos/position holds
  // the engine's positions wrapped into [0, L) and kairos/velocity its velocities.
  const gsd::Reader restart(dir_ / "double" / "restart.gsd");
  const auto x = restart.read<double>(0, "kairos/position");
  const auto v = restart.read<double>(0, "kairos/velocity");
  const auto box = restart.read<double>(0, "kairos/box");
  const std::vector<Frame> d = frames_of(file("double")), s = frames_of(file("single"));
  const Frame& last = d.back();
  ASSERT_EQ(last.time, restart.read<double>(0, "kairos/time")[0]);
  ASSERT_EQ(last.position.size(), 3 * 256u);
  EXPECT_EQ(last.box[0], box[0]);
  for (std::size_t i = 0; i < 256; ++i) {
    for (int a = 0; a < 3; ++a) {
      const double half = 0.5 * box[a];
      double centred = x[3 * i + a] - half;  // HOOMD's centred box, [-L/2, L/2)
      if (centred >= half) centred = -half;
      ASSERT_EQ(last.position[3 * i + a], centred) << i << " " << a;
      ASSERT_EQ(last.velocity[3 * i + a], v[3 * i + a]) << i << " " << a;
    }
  }
  // Every frame: the same states as the float32 run's; the images unwrap the float64
  // coordinate to the float32 run's unwrapped position, within float32 rounding.
  ASSERT_EQ(times_of(d), times_of(s));
  for (std::size_t f = 0; f < d.size(); ++f) {
    ASSERT_EQ(d[f].image.empty(), dem());
    if (dem()) continue;
    for (std::size_t k = 0; k < d[f].position.size(); ++k) {
      const double L = box[k % 3];
      EXPECT_GE(d[f].position[k], -0.5 * L);
      EXPECT_LT(d[f].position[k], 0.5 * L);
      const double u64 = d[f].position[k] + d[f].image[k] * L;
      const double u32 =
          s[f].position[k] + s[f].image[k] * static_cast<double>(static_cast<float>(L));
      EXPECT_NEAR(u64, u32, 1e-5 * L) << "frame " << f << " value " << k;
    }
  }
}

// ----- output.trajectory_spacing = "log"

TEST_P(TrajectoryOptions, LogSpacedFramesInTimeFallOnTheirExactTimes) {
  run_whole(config("equilibration_time = 0.0\ntime = 10.0",
                   "interval_unit = \"time\"\nthermo_interval = 1.0\ntrajectory_interval = 0.01\n"
                   "trajectory_spacing = \"log\"\ntrajectory_frames_per_decade = 5"));
  const std::vector<double> t = times_of(frames_of(file("out")));
  // 0, then 0.01 * 10^(k/5) up to k = 15 (10: the end, no second frame of it).
  ASSERT_EQ(t.size(), 17u);
  EXPECT_EQ(t[0], 0.0);
  for (std::size_t k = 0; k + 1 < t.size(); ++k) {
    const double due = 0.01 * std::pow(10.0, static_cast<double>(k) / 5.0);
    if (dem()) {
      // At the first step at or after it.
      EXPECT_GE(t[k + 1], due - 1e-12) << k;
      EXPECT_LT(t[k + 1], due + 0.01) << k;
    } else {
      EXPECT_EQ(t[k + 1], due) << k;
    }
  }
}

TEST_P(TrajectoryOptions, LogSpacedCyclesStartAgainEveryPeriod) {
  run_whole(config("equilibration_time = 0.0\ntime = 3.0",
                   "interval_unit = \"time\"\nthermo_interval = 1.0\ntrajectory_interval = 0.1\n"
                   "trajectory_spacing = \"log\"\ntrajectory_frames_per_decade = 2\n"
                   "trajectory_log_period = 1.0"));
  std::vector<double> due;
  for (int m = 0; m < 3; ++m) {
    due.push_back(m * 1.0);
    for (int k = 0; k < 2; ++k) due.push_back(m * 1.0 + 0.1 * std::pow(10.0, k / 2.0));
  }
  due.push_back(3.0);
  const std::vector<double> t = times_of(frames_of(file("out")));
  if (!dem()) {
    EXPECT_EQ(t, due);
    return;
  }
  // The DEM writes at the first step at or after each time.
  ASSERT_EQ(t.size(), due.size());
  for (std::size_t k = 0; k < t.size(); ++k) {
    EXPECT_GE(t[k], due[k] - 1e-12) << k;
    EXPECT_LT(t[k], due[k] + 0.01) << k;
  }
}

TEST_P(TrajectoryOptions, LogSpacedFramesInCollisionsStartAtEachPhase) {
  // 256 particles: 1 collision per particle = 128 collisions; first lag 0.1 (12.8 collisions),
  // 4 per decade: thresholds at the phase's start + ceil(12.8 * 10^(k/4)).
  run_whole(config("equilibration_collisions_per_particle = 1.0\ncollisions_per_particle = 4.0",
                   "trajectory_interval = 0.1\ntrajectory_spacing = \"log\"\n"
                   "trajectory_frames_per_decade = 4"));
  std::vector<std::uint64_t> due = {0};
  const auto sequence = [&](std::uint64_t origin, std::uint64_t end) {
    for (int k = 0;; ++k) {
      const auto c = origin + static_cast<std::uint64_t>(
                                  std::ceil(12.8 * std::pow(10.0, static_cast<double>(k) / 4.0)));
      if (c > end) break;
      due.push_back(c);
    }
  };
  sequence(0, 128);
  if (due.back() != 128) due.push_back(128);  // the production's origin
  sequence(128, 640);
  if (due.back() != 640) due.push_back(640);  // the end
  const std::vector<std::uint64_t> got = collisions_of(frames_of(file("out")));
  if (!dem()) {
    EXPECT_EQ(got, due);
    return;
  }
  // The DEM meets each at the step that reaches it (several contacts may begin in a step, so
  // close thresholds may merge): increasing, every one at or past a threshold.
  for (std::size_t k = 1; k < got.size(); ++k) EXPECT_GT(got[k], got[k - 1]);
  EXPECT_GE(got.size(), due.size() - 4);
  EXPECT_LE(got.size(), due.size());
}

// ----- continued runs

// Log-spaced production-only frames in collisions. Restart files (and the interrupter) every
// 1.3 per phase: 1.3 in the equilibration, then 3.3, 4.6, ... in the production from 2.0. The
// run is stopped (a signal) or killed after a later restart file, in either phase.
constexpr const char* kRunInCollisions =
    "equilibration_collisions_per_particle = 2.0\ncollisions_per_particle = 8.0";
constexpr const char* kLogInCollisions =
    "trajectory_interval = 0.05\ntrajectory_spacing = \"log\"\ntrajectory_frames_per_decade = "
    "7\ntrajectory_phases = \"production\"\nrestart_interval = 1.3\nthermo_interval = 1.0";

TEST_P(TrajectoryOptions, ContinuedAfterAStopInTheEquilibrationInCollisions) {
  run_whole(config(kRunInCollisions, kLogInCollisions, "whole"));
  run_interrupted(config(kRunInCollisions, kLogInCollisions, "continued"), "continued", 1.3, 1,
                  Interrupter<3>::kStop, 0);
  expect_same_frames(file("whole"), file("continued"));
}

TEST_P(TrajectoryOptions, ContinuedAfterAStopInTheProductionInCollisions) {
  run_whole(config(kRunInCollisions, kLogInCollisions, "whole"));
  run_interrupted(config(kRunInCollisions, kLogInCollisions, "continued"), "continued", 1.3, 4,
                  Interrupter<3>::kStop, 1);
  expect_same_frames(file("whole"), file("continued"));
}

TEST_P(TrajectoryOptions, ContinuedAfterAKillInTheEquilibrationInCollisions) {
  // The killed run had production frames; its restart file none.
  run_whole(config(kRunInCollisions, kLogInCollisions, "whole"));
  run_interrupted(config(kRunInCollisions, kLogInCollisions, "continued"), "continued", 1.3, 1,
                  Interrupter<3>::kCopyRestart, 0);
  expect_same_frames(file("whole"), file("continued"));
}

TEST_P(TrajectoryOptions, ContinuedAfterAKillInTheProductionInCollisions) {
  run_whole(config(kRunInCollisions, kLogInCollisions, "whole"));
  run_interrupted(config(kRunInCollisions, kLogInCollisions, "continued"), "continued", 1.3, 3,
                  Interrupter<3>::kCopyRestart, 1);
  expect_same_frames(file("whole"), file("continued"));
}

// Log-spaced cycles in time, every phase, float64 frames of chosen fields. Restart files at the
// multiples of 0.35: 0.35 (the production from 0.3), 0.7, 1.05, ...
constexpr const char* kRunInTime = "equilibration_time = 0.3\ntime = 1.5";
constexpr const char* kLogInTime =
    "interval_unit = \"time\"\nthermo_interval = 0.25\ntrajectory_interval = 0.02\n"
    "trajectory_spacing = \"log\"\ntrajectory_log_period = 0.5\nrestart_interval = 0.35\n"
    "trajectory_precision = \"double\"\ntrajectory_fields = [\"position\", \"velocity\"]";

TEST_P(TrajectoryOptions, ContinuedAfterAStopInTime) {
  run_whole(config(kRunInTime, kLogInTime, "whole"));
  run_interrupted(config(kRunInTime, kLogInTime, "continued"), "continued", 0.35, 3,
                  Interrupter<3>::kStop, 1);
  expect_same_frames(file("whole"), file("continued"));
}

TEST_P(TrajectoryOptions, ContinuedAfterAKillInTime) {
  run_whole(config(kRunInTime, kLogInTime, "whole"));
  run_interrupted(config(kRunInTime, kLogInTime, "continued"), "continued", 0.35, 2,
                  Interrupter<3>::kCopyRestart, 1);
  expect_same_frames(file("whole"), file("continued"));
}

TEST_P(TrajectoryOptions, AContinuedFileKeepsItsPrecisionAndFields) {
  const std::string run =
      "equilibration_collisions_per_particle = 0.0\ncollisions_per_particle "
      "= 1.0";
  run_whole(config(run, "trajectory_interval = 0.5"));
  const fs::path restart = dir_ / "out" / "restart.gsd";
  for (const std::string changed :
       {"trajectory_precision = \"double\"", "trajectory_fields = [\"position\"]"}) {
    SCOPED_TRACE(changed);
    try {
      run_simulation(config(run, "trajectory_interval = 0.5\n" + changed), restart);
      ADD_FAILURE() << "accepted";
    } catch (const InputError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find("trajectory.gsd, continued"), std::string::npos) << m;
      EXPECT_NE(m.find(changed.substr(0, changed.find(' '))), std::string::npos) << m;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(BothIntegrators, TrajectoryOptions, ::testing::Values("event", "dem"));

// ----- bad values

Config parsed(const std::string& output, const std::string& run = "") {
  return parse_config("[system]\nparticles = 256\npacking_fraction = 0.3\n[run]\n" + run +
                          "\n[output]\n" + output + "\n",
                      "t.toml");
}

std::string error_of(const std::string& output, const std::string& run = "") {
  try {
    parsed(output, run);
  } catch (const InputError& e) {
    return e.what();
  }
  return "accepted";
}

TEST(TrajectoryKeys, BadValuesAreRefusedNamingTheKey) {
  const struct {
    std::string output, run, expected;
  } cases[] = {
      {"trajectory_fields = [\"position\", \"orientation\"]", "",
       "output.trajectory_fields[1]: 'orientation' is not a trajectory field (a HOOMD field"},
      {"trajectory_fields = [\"position\", \"colour\"]", "",
       "valid values: position, velocity, image, angular_velocity, typeid, diameter, mass"},
      {"trajectory_fields = [\"position\", \"velocity\", \"velocity\"]", "",
       "output.trajectory_fields[2]: 'velocity' is listed twice"},
      {"trajectory_fields = [\"velocity\"]", "",
       "output.trajectory_fields: must include \"position\""},
      {"trajectory_fields = [\"position\", \"image\"]\n[soft]\nmodel = \"dashpot\"\nstiffness = "
       "1e4",
       "integrator = \"dem\"", "output.trajectory_fields[1]: \"image\" is not written by the DEM"},
      {"trajectory_precision = \"half\"", "", "output.trajectory_precision: 'half' is not valid"},
      {"trajectory_phases = \"equilibration\"", "", "output.trajectory_phases: 'equilibration'"},
      {"trajectory_spacing = \"log\"", "", "output.trajectory_interval: log-spaced frames"},
      {"trajectory_frames_per_decade = 5", "",
       "output.trajectory_frames_per_decade: acts only with output.trajectory_spacing = \"log\""},
      {"trajectory_log_period = 5.0", "", "output.trajectory_log_period: acts only with"},
      {"trajectory_spacing = \"log\"\ntrajectory_interval = 1.0\ntrajectory_log_period = 0.5", "",
       "output.trajectory_log_period = 0.5: the period of the log-spaced sequence must be "
       "longer than its first lag"},
      {"trajectory_spacing = \"log\"\ntrajectory_interval = 1.0\ntrajectory_frames_per_decade = "
       "0",
       "", "output.trajectory_frames_per_decade: must be in [1, 1000], got 0"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.output);
    const std::string m = error_of(c.output, c.run);
    EXPECT_NE(m.find(c.expected), std::string::npos) << m;
  }
  // Defaults and good values read; the log keys are written to config.toml only with log
  // spacing, and round-trip.
  const Config d = parsed("");
  EXPECT_EQ(d.output.trajectory_phases, "all");
  EXPECT_TRUE(d.output.trajectory_fields.empty());
  EXPECT_EQ(d.output.trajectory_precision, "single");
  EXPECT_EQ(d.output.trajectory_spacing, "linear");
  EXPECT_EQ(to_toml(d).find("trajectory_frames_per_decade"), std::string::npos);
  const Config c = parsed(
      "trajectory_spacing = \"log\"\ntrajectory_interval = 0.1\ntrajectory_frames_per_decade = "
      "3\ntrajectory_log_period = 10.0\ntrajectory_fields = [\"position\", \"typeid\"]");
  EXPECT_EQ(parse_config(to_toml(c), "config.toml"), c);
}

TEST(TrajectoryKeys, AMillionLogSpacedFramesAtMost) {
  // Checked against the production length when the run starts (the ranges of the intervals).
  const Config c = parsed(
      "trajectory_spacing = \"log\"\ntrajectory_interval = 0.001\ntrajectory_log_period = "
      "0.01\ntrajectory_frames_per_decade = 1000\ndirectory = \"" +
          (fs::temp_directory_path() / ("kairos_traj_keys_" + std::to_string(::getpid())))
              .string() +
          "\"",
      "collisions_per_particle = 1000.0");
  try {
    run_simulation(c);
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("output.trajectory_frames_per_decade = 1000 with "
                     "output.trajectory_log_period = 0.01"),
              std::string::npos)
        << m;
  }
}

}  // namespace
}  // namespace kairos
