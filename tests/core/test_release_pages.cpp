// core/release_pages.hpp: the pages of an array's front go back to the system as it is read
// front to back, the rest of the array is untouched.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdint>
#include <fstream>
#include <vector>

#include "core/release_pages.hpp"

namespace kairos {
namespace {

// Resident bytes of this process (/proc/self/statm: pages).
double resident_bytes() {
  std::ifstream statm("/proc/self/statm");
  long size = 0, resident = 0;
  statm >> size >> resident;
  return static_cast<double>(resident) * static_cast<double>(sysconf(_SC_PAGESIZE));
}

TEST(ReleasePages, AFrontReadIsGivenBackAndTheRestKept) {
  const std::size_t n = std::size_t{8} << 20;  // 64 MiB of doubles
  std::vector<double> values(n, 1.0);
  const double before = resident_bytes();
  const std::size_t read = n / 2;
  double sum = 0.0;
  for (std::size_t i = 0; i < read; ++i) {
    sum += values[i];
    release_read_front(values.data(), i + 1);
  }
  EXPECT_EQ(sum, static_cast<double>(read));
  const double released = before - resident_bytes();
  // The read half (32 MiB) but at most one stride (128 KiB) and a page is given back.
  EXPECT_GT(released, 31.0 * (1 << 20));
  EXPECT_LT(released, 33.0 * (1 << 20));
  for (std::size_t i = read; i < n; ++i) ASSERT_EQ(values[i], 1.0) << i;
}

TEST(ReleasePages, OnlyWholePagesInsideTheRange) {
  std::vector<char> bytes(std::size_t{1} << 20, 'x');
  const auto page = static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
  // Elements [1, 2 pages + 1): one whole page inside, the bytes around it kept.
  release_pages(bytes.data(), 1, 2 * page + 1);
  const std::size_t first =
      (reinterpret_cast<std::uintptr_t>(bytes.data()) + 1 + page - 1) / page * page -
      reinterpret_cast<std::uintptr_t>(bytes.data());
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    const bool released = i >= first && i < first + page;  // the one whole page inside
    ASSERT_EQ(bytes[i], released ? '\0' : 'x') << i;
  }
}

}  // namespace
}  // namespace kairos
