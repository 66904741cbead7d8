// Run configuration: TOML parsing, command-line overrides, validation and serialisation.
//
// The schema (kSchema) drives the unknown-key checks, the "did you mean" suggestions and the
// override coercions; reading and range checks are spelled out per section below. Every error is
// an InputError with a one-line message "WHERE: KEY: PROBLEM", WHERE being "file:line:column",
// "file" or "override 'key=value'".
#include "io/config.hpp"

#include <fmt/format.h>

#include <toml++/toml.h>
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include "core/error.hpp"

namespace kairos {
namespace {

// ---------------------------------------------------------------------------------------------
// Schema

enum class Kind { kTable, kTableArray, kInteger, kUnsigned, kFloat, kString, kBoolean };

struct KeySpec {
  std::string_view path;  // dotted; elements of an array of tables are written "[]"
  Kind kind;
};

constexpr KeySpec kSchema[] = {
    {"system", Kind::kTable},
    {"system.dimension", Kind::kInteger},
    {"system.particles", Kind::kUnsigned},
    {"system.packing_fraction", Kind::kFloat},
    {"system.lattice", Kind::kString},
    {"system.temperature", Kind::kFloat},
    {"system.seed", Kind::kUnsigned},
    {"system.species", Kind::kTableArray},
    {"system.species[]", Kind::kTable},
    {"system.species[].name", Kind::kString},
    {"system.species[].diameter", Kind::kFloat},
    {"system.species[].mass", Kind::kFloat},
    {"system.species[].fraction", Kind::kFloat},
    {"system.initial_state", Kind::kString},
    {"run", Kind::kTable},
    {"run.equilibration_collisions_per_particle", Kind::kFloat},
    {"run.collisions_per_particle", Kind::kFloat},
    {"run.event_queue", Kind::kString},
    {"run.max_wall_seconds", Kind::kFloat},
    {"run.validate", Kind::kBoolean},
    {"output", Kind::kTable},
    {"output.directory", Kind::kString},
    {"output.thermo_interval", Kind::kFloat},
    {"output.trajectory_interval", Kind::kFloat},
    {"output.restart_interval", Kind::kFloat},
    {"output.trajectory", Kind::kBoolean},
    {"output.progress", Kind::kString},
};

constexpr std::string_view kLattices3D[] = {"fcc", "sc", "bcc", "random"};
constexpr std::string_view kLattices2D[] = {"hex", "square", "random"};
constexpr std::string_view kEventQueues[] = {"calendar", "heap", "tree"};
constexpr std::string_view kProgressModes[] = {"auto", "always", "never"};

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

// "system.species[3].name" -> "system.species[].name"
std::string schema_path(std::string_view path) {
  std::string out;
  for (std::size_t i = 0; i < path.size(); ++i) {
    out += path[i];
    if (path[i] == '[') {
      while (i + 1 < path.size() && path[i + 1] != ']') ++i;
    }
  }
  return out;
}

const KeySpec* find_spec(std::string_view path) {
  const std::string schema = schema_path(path);
  for (const KeySpec& spec : kSchema) {
    if (spec.path == schema) return &spec;
  }
  return nullptr;
}

// Case-insensitive Levenshtein distance.
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

// " (did you mean 'system.particles'?)" or "".
std::string suggestion(std::string_view unknown) {
  // Inside a species table, offer that species' keys; "system.species.X" offers species 0.
  std::optional<std::string> index;
  constexpr std::string_view kSpecies = "system.species";
  if (unknown.starts_with(kSpecies) && unknown.size() > kSpecies.size()) {
    if (unknown[kSpecies.size()] == '[') {
      const auto close = unknown.find(']', kSpecies.size());
      if (close != std::string_view::npos) {
        index = std::string(unknown.substr(kSpecies.size(), close - kSpecies.size() + 1));
      }
    } else {
      index = "[0]";
    }
  }
  std::vector<std::string> candidates;
  for (const KeySpec& spec : kSchema) {
    std::string candidate(spec.path);
    const auto brackets = candidate.find("[]");
    if (brackets != std::string::npos) {
      if (!index) continue;
      candidate.replace(brackets, 2, *index);
    }
    candidates.push_back(std::move(candidate));
  }
  const std::string* best = nullptr;
  std::size_t best_distance = 4;  // suggest only within edit distance 3
  for (const std::string& c : candidates) {
    const std::size_t d = edit_distance(unknown, c);
    if (d < best_distance) {
      best_distance = d;
      best = &c;
    }
  }
  if (best == nullptr) {  // a known key in the wrong place: "particles" -> "system.particles"
    for (const std::string& c : candidates) {
      if (edit_distance(leaf(unknown), leaf(c)) == 0) {
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
      return fmt::format("a string (\"{}\")", node.as_string()->get());
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

// ---------------------------------------------------------------------------------------------
// Overrides

struct AppliedOverride {
  std::string label;  // "override 'system.particles=4000'"
  std::string path;   // canonical dotted path, e.g. "system.species[0].diameter"
};

struct PathToken {
  std::string key;  // table key, or the decimal index of an array element
  bool is_index = false;
};

AppliedOverride apply_override(toml::table& root, const std::string& text) {
  const std::string label = fmt::format("override '{}'", text);
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
      if (!is_bare_key(name)) throw error(fmt::format("invalid key '{}'", key));
      tokens.push_back({std::string(name), false});
      canonical = join_key(canonical, name);
      part = bracket == std::string_view::npos ? std::string_view() : part.substr(bracket);
      while (!part.empty()) {
        const auto close = part.find(']');
        if (part[0] != '[' || close == std::string_view::npos ||
            !is_digits(part.substr(1, close - 1))) {
          throw error(fmt::format("invalid key '{}'", key));
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
      if (find_spec(prefix) == nullptr) {
        throw error(fmt::format("unknown key '{}'{}", canonical, suggestion(canonical)));
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
  if (parsed_value != nullptr && find_spec(canonical)->kind == Kind::kString &&
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

// ---------------------------------------------------------------------------------------------
// Reading and validation

class Reader {
 public:
  Reader(std::string source, std::vector<AppliedOverride> overrides)
      : source_(std::move(source)), overrides_(std::move(overrides)) {}

  Config read(const toml::table& root) const {
    check_keys(root, "");
    const toml::table empty;
    Config config;
    read_system(section(root, "system", empty), config.system);
    read_run(section(root, "run", empty), config.run);
    read_output(section(root, "output", empty), config.output);
    return config;
  }

 private:
  // ----- error reporting

  // "file:line:col" for nodes from the file, the override's label for nodes an override made.
  std::string where(const toml::source_region& region, std::string_view path) const {
    if (region.path && region.begin.line > 0) {
      if (*region.path == source_) {
        return fmt::format("{}:{}:{}", source_, region.begin.line, region.begin.column);
      }
      return *region.path;
    }
    for (auto it = overrides_.rbegin(); it != overrides_.rend(); ++it) {
      if (is_within(path, it->path) || is_within(it->path, path)) return it->label;
    }
    return source_;
  }

  static bool is_within(std::string_view path, std::string_view prefix) {
    return path.starts_with(prefix) && (path.size() == prefix.size() ||
                                        path[prefix.size()] == '.' || path[prefix.size()] == '[');
  }

  [[noreturn]] void fail(const toml::node* node, std::string_view path,
                         const std::string& message) const {
    const toml::source_region none{};
    throw InputError(
        fmt::format("{}: {}", where(node != nullptr ? node->source() : none, path), message));
  }

  void check_keys(const toml::table& table, std::string_view prefix) const {
    const toml::key* unknown = nullptr;
    const toml::node* unknown_node = nullptr;
    const auto earlier = [](const toml::source_region& a, const toml::source_region& b) {
      if (a.begin.line == 0) return false;
      if (b.begin.line == 0) return true;
      return std::pair(a.begin.line, a.begin.column) < std::pair(b.begin.line, b.begin.column);
    };
    for (auto&& [key, node] : table) {
      if (is_bare_key(key.str()) && find_spec(join_key(prefix, key.str())) != nullptr) continue;
      if (unknown == nullptr || earlier(key.source(), unknown->source())) {
        unknown = &key;
        unknown_node = &node;
      }
    }
    if (unknown == nullptr) return;
    const std::string path = join_key(
        prefix, is_bare_key(unknown->str()) ? unknown->str() : toml_string(unknown->str()));
    const toml::source_region& region =
        unknown->source().begin.line > 0 ? unknown->source() : unknown_node->source();
    throw InputError(
        fmt::format("{}: unknown key '{}'{}", where(region, path), path, suggestion(path)));
  }

  const toml::table& section(const toml::table& root, std::string_view key,
                             const toml::table& empty) const {
    const toml::node* node = root.get(key);
    if (node == nullptr) return empty;
    const toml::table* table = node->as_table();
    if (table == nullptr) {
      fail(node, key,
           fmt::format("{}: expected a table ([{}]), found {}", key, key, describe(*node)));
    }
    check_keys(*table, key);
    return *table;
  }

  // ----- typed getters: return the node (for error locations), nullptr when the key is absent

  const toml::node* get_number(const toml::table& t, std::string_view prefix, std::string_view key,
                               double& out) const {
    const toml::node* node = t.get(key);
    if (node == nullptr) return nullptr;
    const std::string path = join_key(prefix, key);
    if (const auto* i = node->as_integer()) {
      out = static_cast<double>(i->get());
    } else if (const auto* f = node->as_floating_point()) {
      if (!std::isfinite(f->get())) {
        fail(node, path, fmt::format("{}: must be a finite number, got {}", path, f->get()));
      }
      out = f->get();
    } else {
      fail(node, path, fmt::format("{}: expected a number, found {}", path, describe(*node)));
    }
    return node;
  }

  // A value of exactly TOML type T (std::int64_t, std::string or bool), named `what` in errors.
  template <class T>
  const toml::node* get_exact(const toml::table& t, std::string_view prefix, std::string_view key,
                              T& out, std::string_view what) const {
    const toml::node* node = t.get(key);
    if (node == nullptr) return nullptr;
    const auto* v = node->as<T>();
    if (v == nullptr) {
      const std::string path = join_key(prefix, key);
      fail(node, path, fmt::format("{}: expected {}, found {}", path, what, describe(*node)));
    }
    out = v->get();
    return node;
  }

  const toml::node* get_integer(const toml::table& t, std::string_view prefix, std::string_view key,
                                std::int64_t& out) const {
    return get_exact(t, prefix, key, out, "an integer");
  }

  const toml::node* get_unsigned(const toml::table& t, std::string_view prefix,
                                 std::string_view key, std::uint64_t& out) const {
    std::int64_t value = 0;
    const toml::node* node = get_integer(t, prefix, key, value);
    if (node == nullptr) return nullptr;
    if (value < 0) {
      const std::string path = join_key(prefix, key);
      fail(node, path, fmt::format("{}: must be a non-negative integer, got {}", path, value));
    }
    out = static_cast<std::uint64_t>(value);
    return node;
  }

  const toml::node* get_string(const toml::table& t, std::string_view prefix, std::string_view key,
                               std::string& out) const {
    return get_exact(t, prefix, key, out, "a string");
  }

  const toml::node* get_bool(const toml::table& t, std::string_view prefix, std::string_view key,
                             bool& out) const {
    return get_exact(t, prefix, key, out, "a boolean (true or false)");
  }

  // ----- range checks

  void require_positive(const toml::node* node, std::string_view path, double value) const {
    if (!(value > 0.0)) fail(node, path, fmt::format("{}: must be > 0, got {}", path, value));
  }

  void require_non_negative(const toml::node* node, std::string_view path, double value) const {
    if (!(value >= 0.0)) fail(node, path, fmt::format("{}: must be >= 0, got {}", path, value));
  }

  void require_choice(const toml::node* node, std::string_view path, const std::string& value,
                      std::span<const std::string_view> choices) const {
    if (!contains(choices, value)) {
      fail(
          node, path,
          fmt::format("{}: '{}' is not valid; valid values: {}", path, value, join_words(choices)));
    }
  }

  // ----- sections

  void read_system(const toml::table& t, SystemConfig& s) const {
    constexpr std::string_view p = "system";

    std::int64_t dimension = s.dimension;
    const toml::node* n_dimension = get_integer(t, p, "dimension", dimension);
    if (dimension != 2 && dimension != 3) {
      fail(n_dimension, "system.dimension",
           fmt::format("system.dimension: must be 2 or 3, got {}", dimension));
    }
    s.dimension = static_cast<int>(dimension);

    const toml::node* n_particles = get_unsigned(t, p, "particles", s.particles);
    const toml::node* n_packing = get_number(t, p, "packing_fraction", s.packing_fraction);
    const toml::node* n_lattice = get_string(t, p, "lattice", s.lattice);
    const toml::node* n_temperature = get_number(t, p, "temperature", s.temperature);
    get_unsigned(t, p, "seed", s.seed);
    get_string(t, p, "initial_state", s.initial_state);
    read_species(t, s.species);

    const bool from_file = !s.initial_state.empty();
    if (!from_file) {
      if (n_particles == nullptr) {
        fail(nullptr, "system.particles",
             "missing required key 'system.particles' (or set system.initial_state to start from "
             "a GSD file)");
      }
      if (n_packing == nullptr) {
        fail(nullptr, "system.packing_fraction",
             "missing required key 'system.packing_fraction' (or set system.initial_state to "
             "start from a GSD file)");
      }
    }
    // With an initial_state, 0 (the default) leaves particles and packing fraction to the file.
    if (!(from_file && s.particles == 0) && s.particles < 2) {
      fail(n_particles, "system.particles",
           fmt::format("system.particles: must be at least 2, got {}", s.particles));
    }
    if (!(from_file && s.packing_fraction == 0.0) &&
        !(s.packing_fraction > 0.0 && s.packing_fraction < 1.0)) {
      fail(n_packing, "system.packing_fraction",
           fmt::format("system.packing_fraction: must be in (0, 1), got {}", s.packing_fraction));
    }

    if (s.lattice.empty()) {
      s.lattice = default_lattice(s.dimension);
    } else {
      const std::span<const std::string_view> valid =
          s.dimension == 2 ? std::span<const std::string_view>(kLattices2D)
                           : std::span<const std::string_view>(kLattices3D);
      if (!contains(valid, s.lattice)) {
        fail(n_lattice, "system.lattice",
             fmt::format("system.lattice: '{}' is not a valid lattice in {}D; valid values: {}",
                         s.lattice, s.dimension, join_words(valid)));
      }
    }

    require_positive(n_temperature, "system.temperature", s.temperature);
    if (s.species.empty()) s.species.emplace_back();
  }

  void read_species(const toml::table& system, std::vector<SpeciesConfig>& out) const {
    const toml::node* node = system.get("species");
    if (node == nullptr) return;
    const toml::array* array = node->as_array();
    if (array == nullptr) {
      fail(node, "system.species",
           fmt::format("system.species: expected an array of tables ([[system.species]]), found {}",
                       describe(*node)));
    }
    for (std::size_t i = 0; i < array->size(); ++i) {
      const toml::node* element = array->get(i);
      const std::string prefix = fmt::format("system.species[{}]", i);
      const toml::table* t = element->as_table();
      if (t == nullptr) {
        fail(element, prefix,
             fmt::format("{}: expected a table, found {}", prefix, describe(*element)));
      }
      check_keys(*t, prefix);

      SpeciesConfig s;
      const toml::node* n_name = get_string(*t, prefix, "name", s.name);
      const toml::node* n_diameter = get_number(*t, prefix, "diameter", s.diameter);
      const toml::node* n_mass = get_number(*t, prefix, "mass", s.mass);
      const toml::node* n_fraction = get_number(*t, prefix, "fraction", s.fraction);

      const std::string name_key = prefix + ".name";
      if (s.name.empty()) fail(n_name, name_key, fmt::format("{}: must not be empty", name_key));
      for (std::size_t j = 0; j < out.size(); ++j) {
        if (out[j].name == s.name) {
          fail(n_name != nullptr ? n_name : element, n_name != nullptr ? name_key : prefix,
               fmt::format("{}: duplicate species name '{}' (already used by system.species[{}]){}",
                           name_key, s.name, j,
                           n_name == nullptr ? "; give every species its own name" : ""));
        }
      }
      require_positive(n_diameter, prefix + ".diameter", s.diameter);
      require_positive(n_mass, prefix + ".mass", s.mass);
      require_positive(n_fraction, prefix + ".fraction", s.fraction);
      out.push_back(std::move(s));
    }
  }

  void read_run(const toml::table& t, RunConfig& r) const {
    constexpr std::string_view p = "run";
    const toml::node* n_equilibration = get_number(t, p, "equilibration_collisions_per_particle",
                                                   r.equilibration_collisions_per_particle);
    const toml::node* n_production =
        get_number(t, p, "collisions_per_particle", r.collisions_per_particle);
    const toml::node* n_queue = get_string(t, p, "event_queue", r.event_queue);
    const toml::node* n_wall = get_number(t, p, "max_wall_seconds", r.max_wall_seconds);
    get_bool(t, p, "validate", r.validate);

    require_non_negative(n_equilibration, "run.equilibration_collisions_per_particle",
                         r.equilibration_collisions_per_particle);
    require_positive(n_production, "run.collisions_per_particle", r.collisions_per_particle);
    require_choice(n_queue, "run.event_queue", r.event_queue, kEventQueues);
    require_non_negative(n_wall, "run.max_wall_seconds", r.max_wall_seconds);
  }

  void read_output(const toml::table& t, OutputConfig& o) const {
    constexpr std::string_view p = "output";
    const toml::node* n_directory = get_string(t, p, "directory", o.directory);
    const toml::node* n_thermo = get_number(t, p, "thermo_interval", o.thermo_interval);
    const toml::node* n_trajectory = get_number(t, p, "trajectory_interval", o.trajectory_interval);
    const toml::node* n_restart = get_number(t, p, "restart_interval", o.restart_interval);
    get_bool(t, p, "trajectory", o.trajectory);
    const toml::node* n_progress = get_string(t, p, "progress", o.progress);

    if (o.directory.empty()) {
      fail(n_directory, "output.directory", "output.directory: must not be empty");
    }
    require_non_negative(n_thermo, "output.thermo_interval", o.thermo_interval);
    require_non_negative(n_trajectory, "output.trajectory_interval", o.trajectory_interval);
    require_non_negative(n_restart, "output.restart_interval", o.restart_interval);
    require_choice(n_progress, "output.progress", o.progress, kProgressModes);
  }

  std::string source_;
  std::vector<AppliedOverride> overrides_;
};

// ---------------------------------------------------------------------------------------------
// Writing

std::string toml_unsigned(std::uint64_t v, std::string_view key) {
  if (v > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max())) {
    throw std::out_of_range(
        fmt::format("to_toml: {} = {} does not fit a TOML integer (at most 2^63 - 1)", key, v));
  }
  return fmt::format("{}", v);
}

}  // namespace

std::string default_lattice(int dimension) {
  if (dimension == 2) return "hex";
  if (dimension == 3) return "fcc";
  throw std::invalid_argument(
      fmt::format("default_lattice: dimension must be 2 or 3, got {}", dimension));
}

Config parse_config(std::string_view toml_text, std::string_view source_name,
                    const std::vector<std::string>& overrides) {
  const std::string source =
      source_name.empty() ? std::string("<config>") : std::string(source_name);
  toml::table root;
  try {
    root = toml::parse(toml_text, source);
  } catch (const toml::parse_error& e) {
    throw InputError(fmt::format("{}:{}:{}: TOML syntax error: {}", source, e.source().begin.line,
                                 e.source().begin.column, one_line(e.description())));
  }
  std::vector<AppliedOverride> applied;
  applied.reserve(overrides.size());
  for (const std::string& text : overrides) applied.push_back(apply_override(root, text));
  return Reader(source, std::move(applied)).read(root);
}

Config load_config(const std::filesystem::path& path, const std::vector<std::string>& overrides) {
  const auto cannot_read = [&](const std::string& reason) {
    return InputError(fmt::format("cannot read config file '{}': {}", path.string(), reason));
  };
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw cannot_read("Is a directory");

  const std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "rb"),
                                                             &std::fclose);
  if (!file) throw cannot_read(std::strerror(errno));
  std::string text;
  char buffer[1 << 16];
  std::size_t n = 0;
  while ((n = std::fread(buffer, 1, sizeof buffer, file.get())) > 0) text.append(buffer, n);
  if (std::ferror(file.get()) != 0) throw cannot_read(std::strerror(errno));
  return parse_config(text, path.string(), overrides);
}

std::string to_toml(const Config& config) {
  const SystemConfig& s = config.system;
  const RunConfig& r = config.run;
  const OutputConfig& o = config.output;

  std::string lattice = s.lattice;
  if (lattice.empty() && (s.dimension == 2 || s.dimension == 3)) {
    lattice = default_lattice(s.dimension);
  }
  std::vector<SpeciesConfig> species = s.species;
  if (species.empty()) species.emplace_back();

  std::string out;
  out += "# Kairos run configuration: the effective value of every key (see docs/config.md).\n";
  out += "\n[system]\n";
  out += fmt::format("dimension = {}\n", s.dimension);
  out += fmt::format("particles = {}\n", toml_unsigned(s.particles, "system.particles"));
  out += fmt::format("packing_fraction = {}\n", toml_float(s.packing_fraction));
  out += fmt::format("lattice = {}\n", toml_string(lattice));
  out += fmt::format("temperature = {}\n", toml_float(s.temperature));
  out += fmt::format("seed = {}\n", toml_unsigned(s.seed, "system.seed"));
  out += fmt::format("initial_state = {}\n", toml_string(s.initial_state));
  for (const SpeciesConfig& sp : species) {
    out += "\n[[system.species]]\n";
    out += fmt::format("name = {}\n", toml_string(sp.name));
    out += fmt::format("diameter = {}\n", toml_float(sp.diameter));
    out += fmt::format("mass = {}\n", toml_float(sp.mass));
    out += fmt::format("fraction = {}\n", toml_float(sp.fraction));
  }
  out += "\n[run]\n";
  out += fmt::format("equilibration_collisions_per_particle = {}\n",
                     toml_float(r.equilibration_collisions_per_particle));
  out += fmt::format("collisions_per_particle = {}\n", toml_float(r.collisions_per_particle));
  out += fmt::format("event_queue = {}\n", toml_string(r.event_queue));
  out += fmt::format("max_wall_seconds = {}\n", toml_float(r.max_wall_seconds));
  out += fmt::format("validate = {}\n", r.validate);
  out += "\n[output]\n";
  out += fmt::format("directory = {}\n", toml_string(o.directory));
  out += fmt::format("thermo_interval = {}\n", toml_float(o.thermo_interval));
  out += fmt::format("trajectory_interval = {}\n", toml_float(o.trajectory_interval));
  out += fmt::format("restart_interval = {}\n", toml_float(o.restart_interval));
  out += fmt::format("trajectory = {}\n", o.trajectory);
  out += fmt::format("progress = {}\n", toml_string(o.progress));
  return out;
}

}  // namespace kairos
