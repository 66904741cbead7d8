// Long physics comparisons that only the Release suite runs (`make test`), not the suite under
// AddressSanitizer and UBSan (`make asan`, 3-5x slower). A longer run of code paths that other
// tests of the same component already take under the sanitizers finds no further memory error;
// it only costs CI's budget (README, "Tests"). Mark a test with KAIROS_RELEASE_SUITE_ONLY() as its
// first statement; ctest then lists it as skipped in the sanitized suite.
#pragma once

#include <gtest/gtest.h>

namespace kairos::testing {

#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kSanitized = true;
#else
inline constexpr bool kSanitized = false;
#endif

// The tests that check the whole schedule against brute force after every event (validate():
// O(N^2) per call) spend most of their time there. Under the sanitizers they check after every
// 4th of the same events (`k % validation_stride(1) == 0`): every event is still taken, every
// physics check at the end still made, validate()'s own code still run; the Release suite
// checks after every one.
constexpr int validation_stride(int every) {
  return kSanitized ? 4 * every : every;
}

}  // namespace kairos::testing

#define KAIROS_RELEASE_SUITE_ONLY()                                                   \
  if (::kairos::testing::kSanitized)                                                  \
  GTEST_SKIP() << "a long physics comparison: run by the Release suite (make test), " \
                  "not under the sanitizers"
