#include "io/config_text.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <limits>
#include <stdexcept>

#include "io/config_keys.hpp"

namespace kairos::config_detail {

namespace {

bool same_ignoring_case(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) ==
                  std::tolower(static_cast<unsigned char>(y));
         });
}

// Case-insensitive Levenshtein distance; O(|a| |b|), so callers compare only keys of similar
// lengths (the distance is at least the difference of the lengths).
std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const bool same = std::tolower(static_cast<unsigned char>(a[i - 1])) ==
                        std::tolower(static_cast<unsigned char>(b[j - 1]));
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (same ? 0 : 1)});
    }
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

std::string_view leaf(std::string_view path) {
  const auto dot = path.find_last_of(".]");
  return dot == std::string_view::npos ? path : path.substr(dot + 1);
}

}  // namespace

std::string shown(std::string_view text) {
  if (text.size() <= kShownLength) return std::string(text);
  return fmt::format("{}... ({} characters)", text.substr(0, kShownLength - 4), text.size());
}

std::string join_key(std::string_view prefix, std::string_view key) {
  return prefix.empty() ? std::string(key) : fmt::format("{}.{}", prefix, key);
}

std::string join_words(std::span<const std::string_view> words) {
  std::string out;
  for (const std::string_view w : words) {
    if (!out.empty()) out += ", ";
    out += w;
  }
  return out;
}

bool contains(std::span<const std::string_view> words, std::string_view w) {
  return std::find(words.begin(), words.end(), w) != words.end();
}

bool is_bare_key(std::string_view key) {
  return !key.empty() && std::all_of(key.begin(), key.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_' || c == '-';
  });
}

bool is_digits(std::string_view s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) {
    return std::isdigit(static_cast<unsigned char>(c)) != 0;
  });
}

// " (did you mean 'system.particles'?)" or "".
std::string suggestion(std::string_view unknown) {
  // No key is near a very long one, and comparing with one costs its length squared.
  if (unknown.size() > 4 * kShownLength) return {};
  // Keys of an array of tables are offered for the element the unknown key is in
  // ("contact.pair[2].x" -> "contact.pair[2].*"), else for element 0 ("system.species.name" ->
  // "system.species[0].name").
  std::vector<std::string> candidates;
  for (const DeclaredKey& key : declared_keys()) {
    std::string candidate = key.path;
    const auto brackets = candidate.find("[]");
    if (brackets != std::string::npos) {
      const std::string_view array = std::string_view(key.path).substr(0, brackets);
      std::string index = "[0]";
      if (unknown.starts_with(array) && unknown.size() > array.size() &&
          unknown[array.size()] == '[') {
        const auto close = unknown.find(']', array.size());
        if (close != std::string_view::npos) {
          index = std::string(unknown.substr(array.size(), close - array.size() + 1));
        }
      }
      candidate.replace(brackets, 2, index);
    }
    candidates.push_back(std::move(candidate));
  }
  const std::string* best = nullptr;
  std::size_t best_distance = 4;  // suggest only within edit distance 3
  for (const std::string& c : candidates) {
    // The table holding the unknown key is no suggestion ("contact.pair[0].tc").
    if (unknown.starts_with(c) && unknown.size() > c.size() &&
        (unknown[c.size()] == '.' || unknown[c.size()] == '[')) {
      continue;
    }
    const std::size_t length_gap =
        unknown.size() > c.size() ? unknown.size() - c.size() : c.size() - unknown.size();
    if (length_gap >= best_distance) continue;  // the distance is at least the gap
    const std::size_t d = edit_distance(unknown, c);
    // ... nor one more edits away than the last part has letters ("tc" is no typo of "face").
    if (d < best_distance && d < leaf(unknown).size()) {
      best_distance = d;
      best = &c;
    }
  }
  if (best == nullptr) {  // a known key in the wrong place: "particles" -> "system.particles"
    for (const std::string& c : candidates) {
      if (same_ignoring_case(leaf(unknown), leaf(c))) {
        best = &c;
        break;
      }
    }
  }
  return best != nullptr ? fmt::format(" (did you mean '{}'?)", *best) : std::string();
}

// Shortest representation that reads back to the same double; always a TOML float.
std::string toml_float(double v) {
  std::string s = fmt::format("{}", v);
  if (s.find_first_of(".en") == std::string::npos) s += ".0";  // "inf"/"nan" contain an 'n'
  return s;
}

std::string describe(const toml::node& node) {
  switch (node.type()) {
    case toml::node_type::table:
      return "a table";
    case toml::node_type::array:
      return "an array";
    case toml::node_type::string:
      return fmt::format("a string (\"{}\")", shown(node.as_string()->get()));
    case toml::node_type::integer:
      return fmt::format("an integer ({})", node.as_integer()->get());
    case toml::node_type::floating_point:
      return fmt::format("a float ({})", toml_float(node.as_floating_point()->get()));
    case toml::node_type::boolean:
      return fmt::format("a boolean ({})", node.as_boolean()->get());
    case toml::node_type::date:
      return "a date";
    case toml::node_type::time:
      return "a time";
    case toml::node_type::date_time:
      return "a date-time";
    case toml::node_type::none:
      break;
  }
  return "nothing";
}

std::string_view trim(std::string_view s) {
  const auto first = s.find_first_not_of(" \t\r\n");
  if (first == std::string_view::npos) return {};
  const auto last = s.find_last_not_of(" \t\r\n");
  return s.substr(first, last - first + 1);
}

std::string one_line(std::string_view text) {
  std::string out(text);
  std::replace(out.begin(), out.end(), '\n', ' ');
  std::replace(out.begin(), out.end(), '\r', ' ');
  return out;
}

std::string toml_string(std::string_view s) {
  std::string out = "\"";
  for (const char c : s) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\b':
        out += "\\b";
        break;
      case '\t':
        out += "\\t";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\f':
        out += "\\f";
        break;
      case '\r':
        out += "\\r";
        break;
      default: {
        const auto u = static_cast<unsigned char>(c);
        if (u < 0x20 || u == 0x7f) {
          out += fmt::format("\\u{:04X}", static_cast<unsigned>(u));
        } else {
          out += c;
        }
      }
    }
  }
  out += '"';
  return out;
}

std::string toml_unsigned(std::uint64_t v, std::string_view key) {
  if (v > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max())) {
    throw std::out_of_range(
        fmt::format("to_toml: {} = {} does not fit a TOML integer (at most 2^63 - 1)", key, v));
  }
  return fmt::format("{}", v);
}

// "[1.0, 0.0, -1.0]"
std::string toml_floats(const std::vector<double>& values) {
  std::string out = "[";
  for (std::size_t i = 0; i < values.size(); ++i) {
    out += fmt::format("{}{}", i == 0 ? "" : ", ", toml_float(values[i]));
  }
  return out + "]";
}

}  // namespace kairos::config_detail
