// What the config tests share: a minimal config and a check that a text is refused with one
// line naming every fragment (tests/io/test_config.cpp, test_surface_tables.cpp).
#pragma once

#include <gtest/gtest.h>

#include <initializer_list>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.hpp"
#include "io/config.hpp"

namespace kairos::config_testing {

inline constexpr std::string_view kMinimal = R"([system]
particles = 500
packing_fraction = 0.3
)";

// kMinimal with extra lines appended inside [system] (or new tables after it).
inline std::string minimal_plus(std::string_view extra) {
  return std::string(kMinimal) + std::string(extra) + "\n";
}

// Parses `text` expecting an InputError; checks the message is one line and holds every fragment.
inline std::string expect_error(std::string_view text,
                                std::initializer_list<std::string_view> fragments,
                                const std::vector<std::string>& overrides = {}) {
  std::string message;
  try {
    parse_config(text, "test.toml", overrides);
    ADD_FAILURE() << "no InputError for:\n" << text;
    return {};
  } catch (const InputError& e) {
    message = e.what();
  }
  EXPECT_EQ(message.find('\n'), std::string::npos) << "not one line: " << message;
  for (const std::string_view fragment : fragments) {
    EXPECT_NE(message.find(fragment), std::string::npos)
        << "message lacks '" << fragment << "': " << message;
  }
  return message;
}

}  // namespace kairos::config_testing
