// EXPECT_INPUT_ERROR(statement, substring): the statement throws an InputError whose message
// contains `substring`. Shared by the interaction tests.
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "core/error.hpp"

namespace kairos::test_util {

// The message of the InputError that `f` throws ("" if it throws none).
template <class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace kairos::test_util

#define EXPECT_INPUT_ERROR(statement, substring)                                                  \
  do {                                                                                            \
    const std::string message_ = ::kairos::test_util::error_of([&] { (void)(statement); });       \
    EXPECT_NE(message_.find(substring), std::string::npos)                                        \
        << "expected an InputError containing '" << (substring) << "', got '" << message_ << "'"; \
  } while (false)
