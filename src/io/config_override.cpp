#include "io/config_override.hpp"

#include <fmt/format.h>

#include <charconv>
#include <optional>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "io/config_keys.hpp"
#include "io/config_text.hpp"

namespace kairos::config_detail {

namespace {

struct PathToken {
  std::string key;  // table key, or the decimal index of an array element
  bool is_index = false;
};

// run.time and run.collisions_per_particle (and the equilibration pair) give one length in two
// units: the key an override of one of them replaces, else nullptr.
const char* other_unit_key(std::string_view path) {
  if (path == "run.time") return "collisions_per_particle";
  if (path == "run.collisions_per_particle") return "time";
  if (path == "run.equilibration_time") return "equilibration_collisions_per_particle";
  if (path == "run.equilibration_collisions_per_particle") return "equilibration_time";
  return nullptr;
}

}  // namespace

AppliedOverride apply_override(toml::table& root, const std::string& text) {
  const std::string label = fmt::format("override '{}'", shown(text));
  const auto error = [&](const std::string& message) {
    return InputError(fmt::format("{}: {}", label, message));
  };

  const auto eq = text.find('=');
  if (eq == std::string::npos) {
    throw error("expected 'key=value', e.g. 'system.particles=4000'");
  }
  const std::string_view key = trim(std::string_view(text).substr(0, eq));
  const std::string_view value = trim(std::string_view(text).substr(eq + 1));
  if (key.empty()) throw error("missing key before '='");

  // "system.species.0.diameter" and "system.species[0].diameter" name the same key.
  std::vector<PathToken> tokens;
  std::string canonical;
  std::size_t start = 0;
  while (true) {
    const auto dot = key.find('.', start);
    std::string_view part =
        key.substr(start, dot == std::string_view::npos ? std::string_view::npos : dot - start);
    if (!tokens.empty() && is_digits(part)) {
      tokens.push_back({std::string(part), true});
      canonical += fmt::format("[{}]", part);
    } else {
      const auto bracket = part.find('[');
      const std::string_view name = part.substr(0, bracket);
      if (!is_bare_key(name)) throw error(fmt::format("invalid key '{}'", shown(key)));
      tokens.push_back({std::string(name), false});
      if (!canonical.empty()) canonical += '.';  // appended, not rebuilt: linear in the key
      canonical += name;
      part = bracket == std::string_view::npos ? std::string_view() : part.substr(bracket);
      while (!part.empty()) {
        const auto close = part.find(']');
        if (part[0] != '[' || close == std::string_view::npos ||
            !is_digits(part.substr(1, close - 1))) {
          throw error(fmt::format("invalid key '{}'", shown(key)));
        }
        tokens.push_back({std::string(part.substr(1, close - 1)), true});
        canonical += part.substr(0, close + 1);
        part = part.substr(close + 1);
      }
    }
    if (dot == std::string_view::npos) break;
    start = dot + 1;
  }

  // Unknown keys are reported with the whole path the user typed.
  {
    std::string prefix;
    for (const PathToken& token : tokens) {
      prefix =
          token.is_index ? fmt::format("{}[{}]", prefix, token.key) : join_key(prefix, token.key);
      if (find_declared(prefix) == nullptr) {
        throw error(fmt::format("unknown key '{}'{}", shown(canonical), suggestion(canonical)));
      }
    }
  }

  // The value: TOML if it parses as one, else the bare text as a string. A string key always
  // gets the text as written unless it is a quoted TOML string (output.directory=2024 -> "2024").
  std::optional<toml::table> parsed;
  try {
    toml::table t = toml::parse(fmt::format("v = {}", value), label);
    if (t.size() == 1 && t.contains("v")) parsed = std::move(t);
  } catch (const toml::parse_error&) {
  }
  toml::node* parsed_value = parsed ? parsed->get("v") : nullptr;
  if (parsed_value != nullptr && find_declared(canonical)->type == KeyType::kString &&
      !parsed_value->is_string()) {
    parsed_value = nullptr;
  }
  const auto with_value = [&](auto&& store) {
    if (parsed_value != nullptr) {
      parsed_value->visit([&](auto& node) { store(std::move(node)); });
    } else {
      store(toml::value<std::string>(std::string(value)));
    }
  };

  toml::node* current = &root;
  std::string path;
  for (std::size_t k = 0; k < tokens.size(); ++k) {
    const PathToken& token = tokens[k];
    const bool last = k + 1 == tokens.size();
    if (!token.is_index) {
      toml::table* table = current->as_table();
      if (table == nullptr) {
        throw error(fmt::format("cannot set '{}': '{}' is {}, not a table", canonical, path,
                                describe(*current)));
      }
      if (last) {
        with_value([&](auto&& v) { table->insert_or_assign(token.key, std::move(v)); });
        // A phase's length set in one unit replaces the file's length in the other.
        if (const char* other = other_unit_key(canonical)) table->erase(other);
      } else {
        if (table->get(token.key) == nullptr) {
          if (tokens[k + 1].is_index) {
            // An absent species list stands for the one default species: index 0 edits it.
            toml::array elements;
            if (join_key(path, token.key) == "system.species") elements.push_back(toml::table{});
            table->insert(token.key, std::move(elements));
          } else {
            table->insert(token.key, toml::table{});
          }
        }
        current = table->get(token.key);
      }
      path = join_key(path, token.key);
    } else {
      toml::array* array = current->as_array();
      if (array == nullptr) {
        throw error(fmt::format("cannot set '{}': '{}' is {}, not an array", canonical, path,
                                describe(*current)));
      }
      std::size_t index = 0;
      const auto [end, ec] =
          std::from_chars(token.key.data(), token.key.data() + token.key.size(), index);
      if (ec != std::errc() || index > array->size()) {
        throw error(
            fmt::format("cannot set '{}': index {} is out of range ('{}' has {} entries; "
                        "index {} appends one)",
                        canonical, token.key, path, array->size(), array->size()));
      }
      if (last) {
        with_value([&](auto&& v) {
          if (index < array->size()) {
            array->replace(array->cbegin() + static_cast<std::ptrdiff_t>(index), std::move(v));
          } else {
            array->push_back(std::move(v));
          }
        });
      } else {
        if (index == array->size()) array->push_back(toml::table{});
        current = array->get(index);
      }
      path = fmt::format("{}[{}]", path, index);
    }
  }
  return {label, canonical};
}

}  // namespace kairos::config_detail
