// The text of the config: how keys and values are shown in messages, the "did you mean"
// suggestion for an unknown key, TOML values as config.toml writes them. Internal to src/io.
#pragma once

#include <toml++/toml.h>

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/choices.hpp"

namespace kairos::config_detail {

// A key or value as echoed in a message: at most kShownLength characters of it (a megabyte of
// key would flood the terminal), with its length when cut.
constexpr std::size_t kShownLength = 64;
std::string shown(std::string_view text);

std::string join_key(std::string_view prefix, std::string_view key);  // "a.b", or "b"
std::string join_words(std::span<const std::string_view> words);      // "a, b, c"
bool contains(std::span<const std::string_view> words, std::string_view w);
bool is_bare_key(std::string_view key);
bool is_digits(std::string_view s);

template <class E>
std::vector<std::string_view> choice_names(const Choices<E>& choices) {
  std::vector<std::string_view> out;
  for (const ChoiceEntry<E>& e : choices.entries()) out.push_back(e.name);
  return out;
}

// " (did you mean 'system.particles'?)" or "": the nearest declared key (io/config_keys.hpp).
std::string suggestion(std::string_view unknown);

// "a float (0.5)", "a table", ...: what a node is, for "expected X, found Y".
std::string describe(const toml::node& node);
std::string_view trim(std::string_view s);
std::string one_line(std::string_view text);

// TOML values as config.toml writes them: a double in shortest round-trip form (always a
// float), a quoted string, an unsigned integer (std::out_of_range beyond 2^63 - 1, naming
// `key`), an array of floats.
std::string toml_float(double v);
std::string toml_string(std::string_view s);
std::string toml_unsigned(std::uint64_t v, std::string_view key);
std::string toml_floats(const std::vector<double>& values);

}  // namespace kairos::config_detail
