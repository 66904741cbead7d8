// The memory available to the process and the up-front refusal of runs that cannot fit
// (core/memory_budget.hpp).
#include "core/memory_budget.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <random>
#include <string>

#include "core/error.hpp"
#include "init/initial_state.hpp"

namespace fs = std::filesystem;

namespace kairos {
namespace {

// Sets (or unsets, for nullopt) KAIROS_MEMORY_LIMIT_BYTES for the scope, then restores it.
class LimitVariable {
 public:
  explicit LimitVariable(const std::optional<std::string>& value) {
    if (const char* old = std::getenv(kName)) old_ = old;
    if (value)
      ::setenv(kName, value->c_str(), 1);
    else
      ::unsetenv(kName);
  }
  LimitVariable(const LimitVariable&) = delete;
  LimitVariable& operator=(const LimitVariable&) = delete;
  ~LimitVariable() {
    if (old_)
      ::setenv(kName, old_->c_str(), 1);
    else
      ::unsetenv(kName);
  }

 private:
  static constexpr const char* kName = "KAIROS_MEMORY_LIMIT_BYTES";
  std::optional<std::string> old_;
};

class MemoryBudget : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("kairos_memory_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    sources_.meminfo = dir_ / "meminfo";
    sources_.self_cgroup = dir_ / "cgroup";
    sources_.cgroup2_root = dir_ / "v2";
    sources_.cgroup1_memory_root = dir_ / "v1";
    write("meminfo", "MemTotal:       24683568 kB\nMemAvailable:    8000000 kB\n");
  }
  void TearDown() override { fs::remove_all(dir_); }

  void write(const fs::path& relative, const std::string& text) const {
    fs::create_directories((dir_ / relative).parent_path());
    std::ofstream(dir_ / relative) << text;
  }
  std::optional<AvailableMemory> available() const { return available_memory(sources_); }

  fs::path dir_;
  MemorySources sources_;
  LimitVariable unset_{std::nullopt};
};

TEST_F(MemoryBudget, MemAvailableWithoutCgroupLimits) {
  write("cgroup", "0::/\n");
  const auto a = available();
  ASSERT_TRUE(a);
  EXPECT_EQ(a->bytes, 8000000ull * 1024);
  EXPECT_EQ(a->source, "MemAvailable in " + sources_.meminfo.string());
}

// cgroup v2: the smallest room over the process's cgroup and its ancestors, usage less the
// inactive file cache (which the kernel reclaims first); "max" is no limit.
TEST_F(MemoryBudget, CgroupV2LimitsOfTheCgroupAndItsAncestors) {
  write("cgroup", "0::/job/step\n");
  write("v2/memory.max", "max\n");
  write("v2/job/memory.max", "3000000000\n");
  write("v2/job/memory.current", "1000000000\n");
  write("v2/job/memory.stat", "anon 5\ninactive_file 250000000\nactive_file 9\n");
  write("v2/job/step/memory.max", "max\n");
  write("v2/job/step/memory.current", "900000000\n");
  auto a = available();
  ASSERT_TRUE(a);
  EXPECT_EQ(a->bytes, 3000000000ull - (1000000000ull - 250000000ull));
  EXPECT_EQ(a->source, "the memory.max of cgroup /job/step");

  write("v2/job/step/memory.max", "1200000000\n");  // tighter below
  a = available();
  ASSERT_TRUE(a);
  EXPECT_EQ(a->bytes, 1200000000ull - 900000000ull);

  write("v2/job/step/memory.current", "1300000000\n");  // over the limit: nothing left
  EXPECT_EQ(available()->bytes, 0u);
}

// A container's own cgroup (namespace root "0::/") with a limit at /sys/fs/cgroup itself.
TEST_F(MemoryBudget, CgroupV2LimitAtTheRoot) {
  write("cgroup", "0::/\n");
  write("v2/memory.max", "2147483648\n");
  write("v2/memory.current", "1073741824\n");
  EXPECT_EQ(available()->bytes, 1073741824u);
}

// cgroup v1 (memory controller mounted on its own): limit_in_bytes, usage and the hierarchical
// total_inactive_file; 2^63 - 4096 is v1's "no limit".
TEST_F(MemoryBudget, CgroupV1MemoryController) {
  write("cgroup", "5:cpu,cpuacct:/\n4:memory:/batch/42\n0::/\n");
  write("v1/memory.limit_in_bytes", "9223372036854771712\n");
  write("v1/batch/42/memory.limit_in_bytes", "4000000000\n");
  write("v1/batch/42/memory.usage_in_bytes", "3000000000\n");
  write("v1/batch/42/memory.stat", "inactive_file 1\ntotal_inactive_file 500000000\n");
  const auto a = available();
  ASSERT_TRUE(a);
  EXPECT_EQ(a->bytes, 4000000000ull - 2500000000ull);
  EXPECT_EQ(a->source, "the memory.limit_in_bytes of cgroup /batch/42");
}

TEST_F(MemoryBudget, NothingReadableMeansNoCheck) {
  fs::remove(sources_.meminfo);
  EXPECT_FALSE(available());
  EXPECT_NO_THROW(require_memory(~std::uint64_t{0} >> 1, "anything", sources_));
}

TEST_F(MemoryBudget, EnvironmentVariableOverridesTheDetectedMemory) {
  {
    const LimitVariable limit("123456789");
    const auto a = available();
    ASSERT_TRUE(a);
    EXPECT_EQ(a->bytes, 123456789u);
    EXPECT_EQ(a->source, "KAIROS_MEMORY_LIMIT_BYTES");
  }
  const LimitVariable bad("8G");
  try {
    (void)available();
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("KAIROS_MEMORY_LIMIT_BYTES = '8G' is not a number"),
              std::string::npos)
        << e.what();
  }
}

TEST_F(MemoryBudget, RequireMemoryNamesTheEstimateAndTheMemoryAvailable) {
  const LimitVariable limit(std::to_string(std::uint64_t{3} << 30));
  EXPECT_NO_THROW(require_memory(std::uint64_t{3} << 30, "a run"));
  try {
    require_memory(std::uint64_t{45} << 29, "system.particles = 42");
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("system.particles = 42 needs about 22.5 GiB, this "
                                          "machine has 3 GiB available (KAIROS_MEMORY_LIMIT_BYTES)",
                                          0),
              0u)
        << e.what();
  }
  EXPECT_EQ(format_bytes(340u << 20), "340 MiB");
  EXPECT_EQ(format_bytes(1536), "1.5 kiB");
}

// The estimate grows with N at a few hundred bytes per particle (measured; see the .cpp) and is
// larger in 3D.
TEST_F(MemoryBudget, EstimateIsAFewHundredBytesPerParticle) {
  const std::uint64_t n = 10'000'000;
  for (const int d : {2, 3}) {
    const double per =
        static_cast<double>(estimated_run_bytes(2 * n, d) - estimated_run_bytes(n, d)) /
        static_cast<double>(n);
    EXPECT_GT(per, 300.0) << d;
    EXPECT_LT(per, 1000.0) << d;
  }
  EXPECT_GT(estimated_run_bytes(n, 3), estimated_run_bytes(n, 2));
  EXPECT_GT(estimated_run_bytes(100'000'000, 3), std::uint64_t{24} << 30);  // the case
}

// Generating a state checks the estimate first: system.particles = 100000 in 1 MB is refused
// at once, naming the key, the estimate and the memory available.
TEST_F(MemoryBudget, GeneratedStateIsRefusedBeforeAllocating) {
  const LimitVariable limit("1000000");
  SystemConfig sys;
  sys.dimension = 3;
  sys.particles = 100'000;
  sys.packing_fraction = 0.3;
  std::mt19937_64 rng(1);
  try {
    (void)make_initial_state<3>(sys, rng);
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("system.particles = 100000 needs about ", 0), 0u)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("this machine has 977 kiB available"), std::string::npos)
        << e.what();
  }
  const LimitVariable enough(std::to_string(estimated_run_bytes(100'000, 3)));
  EXPECT_EQ(make_initial_state<3>(sys, rng).position.size(), 100'000u);
}

}  // namespace
}  // namespace kairos
