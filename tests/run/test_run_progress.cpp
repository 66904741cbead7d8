// A restart file's record of where the run stood (run/run_progress.hpp): the marks its
// observers keep (kProgressMarks) are written and read back exactly, each under its own chunks,
// and a mark that is not finite or lies after the state is refused, naming its chunk.
#include "run/run_progress.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

#include "core/error.hpp"
#include "init/initial_state.hpp"
#include "io/gsd_file.hpp"

namespace kairos {
namespace {

namespace fs = std::filesystem;

ParticleSystem<3> small_state() {
  SystemConfig sys;
  sys.particles = 32;
  sys.packing_fraction = 0.1;
  std::mt19937_64 rng(5);
  ParticleSystem<3> s = to_particle_system<3>(make_initial_state<3>(sys, rng));
  s.events.assign(s.size(), EventSlot{});
  s.cell.assign(s.size(), 0);
  s.collision_count.assign(s.size(), 0);
  s.time = 2.5;
  s.counters.collisions = 1000;
  return s;
}

class RunProgressFile : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("kairos_run_progress_" +
            std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // The progress read back from a restart file written with `written`.
  RunProgress round_trip(const RunProgress& written) {
    const fs::path path = dir_ / "restart.gsd";
    std::mt19937_64 rng(1);
    write_restart_file<3>(path, state_, rng, written);
    RunProgress read;
    (void)read_restart_file<3>(path, rng, read, RunKind::kEventDriven);
    return read;
  }
  std::string refusal(const RunProgress& written) {
    try {
      (void)round_trip(written);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  }

  fs::path dir_;
  ParticleSystem<3> state_ = small_state();
};

TEST_F(RunProgressFile, EveryDeclaredMarkComesBackExactly) {
  RunProgress p;
  double x = 0.1;
  for (const ProgressMarkDecl& d : kProgressMarks) {
    ProgressMark m;
    for (std::size_t k = 0; k < d.values; ++k) m.values.push_back(x += 1.0 / 3.0);
    m.values[0] = 2.5 - 1.0 / 7.0;  // a time before the state's
    for (std::size_t k = 0; k < d.counts; ++k) m.counts.push_back(17 * (k + 1));
    p.marks[std::string(d.name)] = m;
  }
  const RunProgress back = round_trip(p);
  ASSERT_EQ(back.marks.size(), std::size(kProgressMarks));
  for (const ProgressMarkDecl& d : kProgressMarks) {
    const ProgressMark* m = back.mark(d.name);
    ASSERT_NE(m, nullptr) << d.name;
    EXPECT_EQ(m->values, p.mark(d.name)->values) << d.name;
    EXPECT_EQ(m->counts, p.mark(d.name)->counts) << d.name;
  }
  // Under its own chunks, the names earlier files have.
  gsd::Reader r(dir_ / "restart.gsd");
  EXPECT_TRUE(r.find(r.frame_count() - 1, "kairos/run/thermo_mark_counts").has_value());
  EXPECT_TRUE(r.find(r.frame_count() - 1, "kairos/run/frame_mark_collisions").has_value());
  // A file without marks has none.
  EXPECT_TRUE(round_trip(RunProgress{}).marks.empty());
}

TEST_F(RunProgressFile, AMarkAfterTheStateOrNotFiniteIsRefusedByName) {
  RunProgress late;
  late.marks["thermo_mark"] = {{3.0, 0.0}, {0, 10}};  // after t = 2.5
  EXPECT_NE(refusal(late).find("kairos/run/thermo_mark lies after the state"), std::string::npos)
      << refusal(late);
  RunProgress counted;
  counted.marks["frame_mark"] = {{1.0}, {1001}};  // more collisions than the state's 1000
  EXPECT_NE(refusal(counted).find("kairos/run/frame_mark lies after the state"), std::string::npos)
      << refusal(counted);
  RunProgress nan;
  nan.marks["production_start"] = {{1.0, std::numeric_limits<double>::quiet_NaN(), 1.0, 0.0},
                                   {0, 0}};
  EXPECT_NE(refusal(nan).find("kairos/run/production_start is not finite"), std::string::npos)
      << refusal(nan);
}

// A mark that is not declared, or not of its declared sizes, is the program's error: the
// writer throws rather than write a chunk no reader knows, or read past the values.
TEST_F(RunProgressFile, AnUndeclaredOrMisshapenMarkIsNotWritten) {
  std::mt19937_64 rng(1);
  RunProgress unknown;
  unknown.marks["thermo_mrak"] = {{1.0, 0.0}, {0, 1}};
  EXPECT_THROW(write_restart_file<3>(dir_ / "a.gsd", state_, rng, unknown), std::logic_error);
  RunProgress short_one;
  short_one.marks["thermo_mark"] = {{1.0}, {0, 1}};
  EXPECT_THROW(write_restart_file<3>(dir_ / "b.gsd", state_, rng, short_one), std::logic_error);
}

}  // namespace
}  // namespace kairos
