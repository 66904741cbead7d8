// Run configuration: TOML parsing, command-line overrides, validation and serialisation.
//
// The schema (kSchema) drives the unknown-key checks, the "did you mean" suggestions and the
// override coercions; reading and range checks are spelled out per section below. Every error is
// an InputError with a one-line message "WHERE: KEY: PROBLEM", WHERE being "file:line:column",
// "file" or "override 'key=value'".
#include "io/config.hpp"

#include <fmt/format.h>

#include <toml++/toml.h>
#include <unistd.h>

#include <algorithm>
#include <array>
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

// kArray: an array of values (numbers, strings or number pairs), read as a whole.
enum class Kind { kTable, kTableArray, kInteger, kUnsigned, kFloat, kString, kBoolean, kArray };

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
    {"system.species[].inertia_factor", Kind::kFloat},
    {"system.initial_state", Kind::kString},
    {"system.box_scale", Kind::kArray},
    {"system.chain_length", Kind::kUnsigned},
    {"system.chain_spacing", Kind::kFloat},
    {"potential", Kind::kTableArray},
    {"potential[]", Kind::kTable},
    {"potential[].species", Kind::kArray},
    {"potential[].kind", Kind::kString},
    {"potential[].lambda", Kind::kFloat},
    {"potential[].depth", Kind::kFloat},
    {"potential[].boundaries", Kind::kArray},
    {"potential[].energies", Kind::kArray},
    {"potential[].epsilon", Kind::kFloat},
    {"potential[].sigma", Kind::kFloat},
    {"potential[].cutoff", Kind::kFloat},
    {"potential[].shifted", Kind::kBoolean},
    {"potential[].kappa", Kind::kFloat},
    {"potential[].alpha", Kind::kFloat},
    {"potential[].r_min", Kind::kFloat},
    {"potential[].file", Kind::kString},
    {"potential[].max_length", Kind::kFloat},
    {"potential[].stiffness", Kind::kFloat},
    {"potential[].length", Kind::kFloat},
    {"potential[].steps", Kind::kInteger},
    {"potential[].placement", Kind::kString},
    {"potential[].shell_energy", Kind::kString},
    {"potential[].temperature", Kind::kFloat},
    {"bond", Kind::kTableArray},
    {"bond[]", Kind::kTable},
    {"bond[].type", Kind::kString},
    {"bond[].kind", Kind::kString},
    {"bond[].lambda", Kind::kFloat},
    {"bond[].depth", Kind::kFloat},
    {"bond[].boundaries", Kind::kArray},
    {"bond[].energies", Kind::kArray},
    {"bond[].epsilon", Kind::kFloat},
    {"bond[].sigma", Kind::kFloat},
    {"bond[].cutoff", Kind::kFloat},
    {"bond[].shifted", Kind::kBoolean},
    {"bond[].kappa", Kind::kFloat},
    {"bond[].alpha", Kind::kFloat},
    {"bond[].r_min", Kind::kFloat},
    {"bond[].file", Kind::kString},
    {"bond[].max_length", Kind::kFloat},
    {"bond[].stiffness", Kind::kFloat},
    {"bond[].length", Kind::kFloat},
    {"bond[].steps", Kind::kInteger},
    {"bond[].placement", Kind::kString},
    {"bond[].shell_energy", Kind::kString},
    {"bond[].temperature", Kind::kFloat},
    {"contact", Kind::kTable},
    {"contact.restitution", Kind::kFloat},
    {"contact.restitution_model", Kind::kString},
    {"contact.restitution_speed", Kind::kFloat},
    {"contact.restitution_table", Kind::kArray},
    {"contact.tangential_restitution", Kind::kFloat},
    {"contact.friction", Kind::kFloat},
    {"contact.elastic_below_speed", Kind::kFloat},
    {"contact.tc", Kind::kFloat},
    {"contact.sleep_speed", Kind::kFloat},
    {"contact.pair", Kind::kTableArray},
    {"contact.pair[]", Kind::kTable},
    {"contact.pair[].species", Kind::kArray},
    {"contact.pair[].restitution", Kind::kFloat},
    {"contact.pair[].restitution_model", Kind::kString},
    {"contact.pair[].restitution_speed", Kind::kFloat},
    {"contact.pair[].restitution_table", Kind::kArray},
    {"contact.pair[].tangential_restitution", Kind::kFloat},
    {"contact.pair[].friction", Kind::kFloat},
    {"contact.pair[].elastic_below_speed", Kind::kFloat},
    {"boundary", Kind::kTable},
    {"boundary.open", Kind::kArray},
    {"boundary.shear_rate", Kind::kFloat},
    {"boundary.wall", Kind::kTableArray},
    {"boundary.wall[]", Kind::kTable},
    {"boundary.wall[].face", Kind::kString},
    {"boundary.wall[].restitution", Kind::kFloat},
    {"boundary.wall[].restitution_model", Kind::kString},
    {"boundary.wall[].restitution_speed", Kind::kFloat},
    {"boundary.wall[].restitution_table", Kind::kArray},
    {"boundary.wall[].tangential_restitution", Kind::kFloat},
    {"boundary.wall[].friction", Kind::kFloat},
    {"boundary.wall[].elastic_below_speed", Kind::kFloat},
    {"boundary.wall[].velocity", Kind::kArray},
    {"boundary.wall[].amplitude", Kind::kFloat},
    {"boundary.wall[].frequency", Kind::kFloat},
    {"boundary.wall[].phase", Kind::kFloat},
    {"driving", Kind::kTable},
    {"driving.kind", Kind::kString},
    {"driving.rate", Kind::kFloat},
    {"driving.temperature", Kind::kFloat},
    {"driving.strength", Kind::kFloat},
    {"field", Kind::kTable},
    {"field.gravity", Kind::kArray},
    {"run", Kind::kTable},
    {"run.equilibration_collisions_per_particle", Kind::kFloat},
    {"run.collisions_per_particle", Kind::kFloat},
    {"run.time", Kind::kFloat},
    {"run.equilibration_time", Kind::kFloat},
    {"run.event_queue", Kind::kString},
    {"run.max_wall_seconds", Kind::kFloat},
    {"run.validate", Kind::kBoolean},
    {"run.integrator", Kind::kString},
    {"run.time_step", Kind::kFloat},
    {"soft", Kind::kTable},
    {"soft.collisions", Kind::kString},
    {"soft.tables", Kind::kBoolean},
    {"soft.table_tolerance", Kind::kFloat},
    {"soft.table_cache", Kind::kString},
    {"soft.defer_releases", Kind::kBoolean},
    {"soft.model", Kind::kString},
    {"soft.stiffness", Kind::kFloat},
    {"soft.damping", Kind::kFloat},
    {"soft.young", Kind::kFloat},
    {"soft.poisson", Kind::kFloat},
    {"soft.dissipation", Kind::kFloat},
    {"soft.restitution", Kind::kFloat},
    {"soft.restitution_speed", Kind::kFloat},
    {"soft.friction", Kind::kFloat},
    {"soft.tangential_stiffness", Kind::kFloat},
    {"soft.tangential_damping", Kind::kFloat},
    {"soft.pair", Kind::kTableArray},
    {"soft.pair[]", Kind::kTable},
    {"soft.pair[].species", Kind::kArray},
    {"soft.pair[].model", Kind::kString},
    {"soft.pair[].stiffness", Kind::kFloat},
    {"soft.pair[].damping", Kind::kFloat},
    {"soft.pair[].young", Kind::kFloat},
    {"soft.pair[].poisson", Kind::kFloat},
    {"soft.pair[].dissipation", Kind::kFloat},
    {"soft.pair[].restitution", Kind::kFloat},
    {"soft.pair[].restitution_speed", Kind::kFloat},
    {"soft.pair[].friction", Kind::kFloat},
    {"soft.pair[].tangential_stiffness", Kind::kFloat},
    {"soft.pair[].tangential_damping", Kind::kFloat},
    {"output", Kind::kTable},
    {"output.directory", Kind::kString},
    {"output.thermo_interval", Kind::kFloat},
    {"output.trajectory_interval", Kind::kFloat},
    {"output.restart_interval", Kind::kFloat},
    {"output.interval_unit", Kind::kString},
    {"output.trajectory", Kind::kBoolean},
    {"output.progress", Kind::kString},
    {"output.profile_axis", Kind::kString},
    {"output.profile_bins", Kind::kInteger},
    // After contact.* and soft.*: an unknown 'restitution' elsewhere is suggested those first.
    {"potential[].damping", Kind::kFloat},
    {"potential[].restitution", Kind::kFloat},
    {"potential[].force_zero", Kind::kBoolean},
};

constexpr std::uint64_t kMaxParticles = (std::uint64_t{1} << 31) - 1;
constexpr std::string_view kLattices3D[] = {"fcc", "sc", "bcc", "random"};
constexpr std::string_view kLattices2D[] = {"hex", "square", "random"};
constexpr std::string_view kEventQueues[] = {"calendar", "heap", "tree"};
constexpr std::string_view kProgressModes[] = {"auto", "always", "never"};
constexpr std::string_view kIntervalUnits[] = {"collisions", "time"};
constexpr std::string_view kDrivingKinds[] = {"none", "andersen", "white_noise"};
constexpr std::string_view kIntegrators[] = {"event", "dem"};
constexpr std::string_view kSoftModels[] = {"dashpot", "hertz"};
constexpr std::string_view kSoftCollisions[] = {"mapped", "instantaneous"};
constexpr std::string_view kRestitutionModels[] = {"constant", "viscoelastic", "table"};
// Box faces: 2k is the low face of axis k, 2k + 1 the high one.
constexpr std::string_view kFaces[] = {"x-", "x+", "y-", "y+", "z-", "z+"};
constexpr std::string_view kAxes[] = {"x", "y", "z"};
constexpr std::string_view kPairPotentials[] = {
    "square_well", "square_shoulder", "steps",     "lennard_jones", "wca",
    "yukawa",      "morse",           "tabulated", "spring_dashpot"};
constexpr std::string_view kBondPotentials[] = {"tether", "spring"};
constexpr std::string_view kPlacements[] = {"energy", "distance", "volume"};
constexpr std::string_view kShellEnergies[] = {"midpoint", "volume", "mid_volume", "virial"};

// A key or value as echoed in a message: at most kShownLength characters of it (a megabyte of
// key would flood the terminal), with its length when cut.
constexpr std::size_t kShownLength = 64;
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

// " (did you mean 'system.particles'?)" or "".
std::string suggestion(std::string_view unknown) {
  // No key is near a very long one, and comparing with one costs its length squared.
  if (unknown.size() > 4 * kShownLength) return {};
  // Keys of an array of tables are offered for the element the unknown key is in
  // ("contact.pair[2].x" -> "contact.pair[2].*"), else for element 0 ("system.species.name" ->
  // "system.species[0].name").
  std::vector<std::string> candidates;
  for (const KeySpec& spec : kSchema) {
    std::string candidate(spec.path);
    const auto brackets = candidate.find("[]");
    if (brackets != std::string::npos) {
      const std::string_view array = spec.path.substr(0, brackets);
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

// run.time and run.collisions_per_particle (and the equilibration pair) give one length in two
// units: the key an override of one of them replaces, else nullptr.
const char* other_unit_key(std::string_view path) {
  if (path == "run.time") return "collisions_per_particle";
  if (path == "run.collisions_per_particle") return "time";
  if (path == "run.equilibration_time") return "equilibration_collisions_per_particle";
  if (path == "run.equilibration_collisions_per_particle") return "equilibration_time";
  return nullptr;
}

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
      if (find_spec(prefix) == nullptr) {
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
    read_interactions(section(root, "contact", empty), config.system.species, config.interactions);
    read_boundary(section(root, "boundary", empty), config.system.dimension,
                  config.interactions.contact, config.boundary);
    read_field(section(root, "field", empty), config.system.dimension, config.field);
    read_driving(section(root, "driving", empty), config.driving);
    read_run(section(root, "run", empty), config.run);
    read_output(section(root, "output", empty), config.system.dimension, config.output);
    resolve_interval_unit(section(root, "output", empty), config.run, config.output);
    read_potentials(root, config.system.species, config.potentials);
    read_bonds(root, config.bonds);
    if (root.contains("soft")) {
      read_soft(section(root, "soft", empty), config.system.species, config.soft);
    }
    check_soft_and_dem(root, config);
    if (config.system.chain_length > 0 && config.bonds.empty()) {
      fail(nullptr, "system.chain_length",
           "system.chain_length: chains need a bond potential ([[bond]] with kind = \"tether\" "
           "or \"spring\")");
    }
    resolve_chain_spacing(config);
    return config;
  }

 private:
  // system.chain_spacing = 0: halfway between the contact distance and the backbone bond's
  // range, so that bonded beads start apart (at a spacing of one diameter they start exactly in
  // contact, and a short run makes all its collisions at t = 0: its clock never moves).
  static void resolve_chain_spacing(Config& config) {
    SystemConfig& s = config.system;
    if (s.chain_length == 0 || s.chain_spacing != 0.0) return;
    double dmax = 0.0;
    for (const SpeciesConfig& sp : s.species) dmax = std::max(dmax, sp.diameter);
    for (const BondConfig& b : config.bonds) {
      if (b.type != "backbone") continue;
      const double range = table_cutoff(b.potential, dmax);
      if (std::isfinite(range) && range > dmax) s.chain_spacing = 0.5 * (dmax + range);
    }
  }

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
        fmt::format("{}: unknown key '{}'{}", where(region, path), shown(path), suggestion(path)));
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

  // The value of a number node (an integer or a float) named `path`: finite, or +inf too when
  // allow_infinity.
  double number_value(const toml::node& node, const std::string& path,
                      bool allow_infinity = false) const {
    if (const auto* i = node.as_integer()) return static_cast<double>(i->get());
    const auto* f = node.as_floating_point();
    if (f == nullptr) {
      fail(&node, path, fmt::format("{}: expected a number, found {}", path, describe(node)));
    }
    const double v = f->get();
    if (!std::isfinite(v) && !(allow_infinity && v > 0.0)) {
      fail(&node, path,
           fmt::format("{}: must be a finite number{}, got {}", path,
                       allow_infinity ? " or inf" : "", v));
    }
    return v;
  }

  const toml::node* get_number(const toml::table& t, std::string_view prefix, std::string_view key,
                               double& out, bool allow_infinity = false) const {
    const toml::node* node = t.get(key);
    if (node == nullptr) return nullptr;
    out = number_value(*node, join_key(prefix, key), allow_infinity);
    return node;
  }

  // The array at `key` (nullptr when the key is absent; `node` receives its node); anything
  // else is an error expecting an array of `what`.
  const toml::array* get_array(const toml::table& t, std::string_view prefix, std::string_view key,
                               std::string_view what, const toml::node*& node) const {
    node = t.get(key);
    if (node == nullptr) return nullptr;
    const toml::array* array = node->as_array();
    if (array == nullptr) {
      const std::string path = join_key(prefix, key);
      fail(node, path,
           fmt::format("{}: expected an array of {}, found {}", path, what, describe(*node)));
    }
    return array;
  }

  // An array of finite numbers (elements named "key[i]" in errors).
  const toml::node* get_numbers(const toml::table& t, std::string_view prefix, std::string_view key,
                                std::vector<double>& out) const {
    const toml::node* node = nullptr;
    const toml::array* array = get_array(t, prefix, key, "numbers", node);
    if (array == nullptr) return nullptr;
    const std::string path = join_key(prefix, key);
    out.clear();
    for (std::size_t i = 0; i < array->size(); ++i) {
      out.push_back(number_value(*array->get(i), fmt::format("{}[{}]", path, i)));
    }
    return node;
  }

  // An array of exactly `dimension` finite numbers (a vector in space).
  const toml::node* get_vector(const toml::table& t, std::string_view prefix, std::string_view key,
                               int dimension, std::vector<double>& out) const {
    const toml::node* node = get_numbers(t, prefix, key, out);
    if (node != nullptr && out.size() != static_cast<std::size_t>(dimension)) {
      const std::string path = join_key(prefix, key);
      fail(node, path,
           fmt::format("{}: expected {} numbers (system.dimension = {}), got {}", path, dimension,
                       dimension, out.size()));
    }
    return node;
  }

  // An array of strings.
  const toml::node* get_strings(const toml::table& t, std::string_view prefix, std::string_view key,
                                std::vector<std::string>& out) const {
    const toml::node* node = nullptr;
    const toml::array* array = get_array(t, prefix, key, "strings", node);
    if (array == nullptr) return nullptr;
    const std::string path = join_key(prefix, key);
    out.clear();
    for (std::size_t i = 0; i < array->size(); ++i) {
      const toml::node* element = array->get(i);
      const auto* v = element->as_string();
      if (v == nullptr) {
        const std::string element_path = fmt::format("{}[{}]", path, i);
        fail(element, element_path,
             fmt::format("{}: expected a string, found {}", element_path, describe(*element)));
      }
      out.push_back(v->get());
    }
    return node;
  }

  // Element i of an array node returned by the getters above.
  static const toml::node* element_of(const toml::node* array, std::size_t i) {
    return array->as_array()->get(i);
  }

  // The tables of the array of tables prefix.key (none when absent), keys checked.
  std::vector<const toml::table*> table_array(const toml::table& parent, std::string_view prefix,
                                              std::string_view key) const {
    std::vector<const toml::table*> out;
    const toml::node* node = parent.get(key);
    if (node == nullptr) return out;
    const std::string path = join_key(prefix, key);
    const toml::array* array = node->as_array();
    if (array == nullptr) {
      fail(node, path,
           fmt::format("{}: expected an array of tables ([[{}]]), found {}", path, path,
                       describe(*node)));
    }
    for (std::size_t i = 0; i < array->size(); ++i) {
      const toml::node* element = array->get(i);
      const std::string element_path = fmt::format("{}[{}]", path, i);
      const toml::table* table = element->as_table();
      if (table == nullptr) {
        fail(element, element_path,
             fmt::format("{}: expected a table, found {}", element_path, describe(*element)));
      }
      check_keys(*table, element_path);
      out.push_back(table);
    }
    return out;
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

  // value in [lo, hi]; `why` (may be empty) says where the bounds come from.
  void require_range(const toml::node* node, std::string_view path, double value, double lo,
                     double hi, std::string_view why = {}) const {
    if (!(value >= lo && value <= hi)) {
      fail(node, path,
           fmt::format("{}: must be in [{:g}, {:g}]{}{}, got {}", path, lo, hi,
                       why.empty() ? "" : " ", why, value));
    }
  }

  void require_choice(const toml::node* node, std::string_view path, const std::string& value,
                      std::span<const std::string_view> choices) const {
    if (!contains(choices, value)) {
      fail(node, path,
           fmt::format("{}: '{}' is not valid; valid values: {}", path, shown(value),
                       join_words(choices)));
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
    const toml::node* n_chain = get_unsigned(t, p, "chain_length", s.chain_length);
    const toml::node* n_spacing = get_number(t, p, "chain_spacing", s.chain_spacing);
    require_non_negative(n_spacing, "system.chain_spacing", s.chain_spacing);
    if (s.chain_length == 1) {
      fail(n_chain, "system.chain_length",
           "system.chain_length: a chain needs at least 2 beads (0: no chains)");
    }
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
    // The engine numbers particles in 31 bits (docs/architecture.md).
    if (s.particles > kMaxParticles) {
      fail(n_particles, "system.particles",
           fmt::format("system.particles: must be at most {} (2^31 - 1), got {}", kMaxParticles,
                       s.particles));
    }
    // Whether the state fits in memory is checked before it is built (core/memory_budget).
    if (!(from_file && s.packing_fraction == 0.0) &&
        !(s.packing_fraction > 0.0 && s.packing_fraction < 1.0)) {
      fail(n_packing, "system.packing_fraction",
           fmt::format("system.packing_fraction: must be in (0, 1), got {}", s.packing_fraction));
    }
    // More dilute, and neighbours sit more than ~1e3 diameters apart: the box outgrows what
    // positions resolve before the gas is any different from one at 1e-9.
    if (!(from_file && s.packing_fraction == 0.0) && s.packing_fraction < 1e-9) {
      fail(n_packing, "system.packing_fraction",
           fmt::format("system.packing_fraction: must be at least 1e-9, got {}",
                       s.packing_fraction));
    }
    if (s.chain_length > 0 && s.particles > 0 && s.chain_length > s.particles) {
      fail(n_chain, "system.chain_length",
           fmt::format("system.chain_length: must be at most system.particles = {}, got {}",
                       s.particles, s.chain_length));
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
                         shown(s.lattice), s.dimension, join_words(valid)));
      }
    }

    // kT is the unit of energy (and with the masses, of speed) that every other range refers to.
    require_positive(n_temperature, "system.temperature", s.temperature);
    require_range(n_temperature, "system.temperature", s.temperature, 1e-9, 1e9,
                  "(the unit of energy kT: reduced units keep it near 1)");
    if (s.species.empty()) s.species.emplace_back();
    double largest = 0.0;
    for (const SpeciesConfig& sp : s.species) largest = std::max(largest, sp.diameter);
    if (s.chain_spacing > 0.0) {
      require_range(n_spacing, "system.chain_spacing", s.chain_spacing, 0.0, 1e6 * largest,
                    "(0, or up to 1e6 times the largest diameter)");
    }

    std::vector<double> box_scale;
    const toml::node* n_box_scale = get_vector(t, p, "box_scale", s.dimension, box_scale);
    for (std::size_t i = 0; i < box_scale.size(); ++i) {
      if (!(box_scale[i] >= 1.0)) {
        fail(element_of(n_box_scale, i), "system.box_scale",
             fmt::format("system.box_scale[{}]: must be >= 1, got {}", i, box_scale[i]));
      }
      if (!(box_scale[i] <= 1e6)) {
        fail(element_of(n_box_scale, i), "system.box_scale",
             fmt::format("system.box_scale[{}]: must be at most 1e6, got {}", i, box_scale[i]));
      }
    }
    // All 1 is the same as no scaling: stored as the default, empty.
    if (std::any_of(box_scale.begin(), box_scale.end(), [](double f) { return f != 1.0; })) {
      s.box_scale = std::move(box_scale);
    }
  }

  void read_species(const toml::table& system, std::vector<SpeciesConfig>& out) const {
    const std::vector<const toml::table*> tables = table_array(system, "system", "species");
    for (std::size_t i = 0; i < tables.size(); ++i) {
      const toml::table* t = tables[i];
      const toml::node* element = t;
      const std::string prefix = fmt::format("system.species[{}]", i);

      SpeciesConfig s;
      const toml::node* n_name = get_string(*t, prefix, "name", s.name);
      const toml::node* n_diameter = get_number(*t, prefix, "diameter", s.diameter);
      const toml::node* n_mass = get_number(*t, prefix, "mass", s.mass);
      const toml::node* n_fraction = get_number(*t, prefix, "fraction", s.fraction);
      const toml::node* n_inertia = get_number(*t, prefix, "inertia_factor", s.inertia_factor);

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
      // Diameter and mass are units (reduced units keep them near 1); a fraction is relative.
      require_positive(n_diameter, prefix + ".diameter", s.diameter);
      require_positive(n_mass, prefix + ".mass", s.mass);
      require_positive(n_fraction, prefix + ".fraction", s.fraction);
      require_range(n_diameter, prefix + ".diameter", s.diameter, 1e-9, 1e9);
      require_range(n_mass, prefix + ".mass", s.mass, 1e-9, 1e9);
      require_range(n_fraction, prefix + ".fraction", s.fraction, 1e-9, 1e9);
      // I = q m R^2 with the mass inside the radius: q <= 1 (all of it at R: a ring).
      if (!(s.inertia_factor >= 0.0)) {
        fail(n_inertia, prefix + ".inertia_factor",
             fmt::format("{}.inertia_factor: must be > 0 (or 0 for the default: 2/5 for spheres, "
                         "1/2 for disks), got {}",
                         prefix, s.inertia_factor));
      }
      if (!(s.inertia_factor == 0.0 || (s.inertia_factor >= 1e-9 && s.inertia_factor <= 1.0))) {
        fail(n_inertia, prefix + ".inertia_factor",
             fmt::format("{}.inertia_factor: must be in [1e-9, 1] (I = q m R^2 with the mass "
                         "within R; or 0 for the default: 2/5 for spheres, 1/2 for disks), got {}",
                         prefix, s.inertia_factor));
      }
      out.push_back(std::move(s));
    }
  }

  // A contact law at `prefix` ("contact", "contact.pair[i]", "boundary.wall[i]"). On entry `c`
  // holds the law inherited from [contact] (the defaults for [contact] itself); the keys present
  // replace its values.
  void read_contact(const toml::table& t, const std::string& prefix, ContactConfig& c) const {
    const auto path = [&](std::string_view key) { return join_key(prefix, key); };
    const toml::node* n_restitution = get_number(t, prefix, "restitution", c.restitution);
    const toml::node* n_model = get_string(t, prefix, "restitution_model", c.restitution_model);
    const toml::node* n_speed = get_number(t, prefix, "restitution_speed", c.restitution_speed);
    const toml::node* n_table = get_restitution_table(t, prefix, c.restitution_table);
    const toml::node* n_beta =
        get_number(t, prefix, "tangential_restitution", c.tangential_restitution);
    const toml::node* n_friction =
        get_number(t, prefix, "friction", c.friction, /*allow_infinity=*/true);
    const toml::node* n_elastic =
        get_number(t, prefix, "elastic_below_speed", c.elastic_below_speed);

    if (!(c.restitution >= 0.0 && c.restitution <= 1.0)) {
      fail(n_restitution, path("restitution"),
           fmt::format("{}: must be in [0, 1], got {}", path("restitution"), c.restitution));
    }
    require_choice(n_model, path("restitution_model"), c.restitution_model, kRestitutionModels);
    require_positive(n_speed, path("restitution_speed"), c.restitution_speed);
    if (c.restitution_model == "viscoelastic" && !(c.restitution > 0.0)) {
      fail(n_restitution != nullptr ? n_restitution : n_model, path("restitution"),
           fmt::format("{}: must be in (0, 1] with restitution_model = \"viscoelastic\" (it is "
                       "e at restitution_speed), got {}",
                       path("restitution"), c.restitution));
    }
    if (c.restitution_model == "table") {
      if (n_table == nullptr && c.restitution_table.empty()) {
        fail(n_model, path("restitution_table"),
             fmt::format("missing required key '{}' (restitution_model = \"table\" needs "
                         "[speed, e] pairs, e.g. [[0.0, 1.0], [1.0, 0.9]])",
                         path("restitution_table")));
      }
      if (c.restitution_table.empty()) {
        fail(n_table, path("restitution_table"),
             fmt::format("{}: needs at least one [speed, e] pair", path("restitution_table")));
      }
    } else if (n_table != nullptr) {
      fail(n_table, path("restitution_table"),
           fmt::format("{}: only allowed with restitution_model = \"table\" (restitution_model "
                       "is \"{}\")",
                       path("restitution_table"), c.restitution_model));
    } else {
      c.restitution_table.clear();  // an inherited table does not apply to another model
    }
    if (!(c.tangential_restitution >= -1.0 && c.tangential_restitution <= 1.0)) {
      fail(n_beta, path("tangential_restitution"),
           fmt::format("{}: must be in [-1, 1], got {}", path("tangential_restitution"),
                       c.tangential_restitution));
    }
    require_non_negative(n_friction, path("friction"), c.friction);
    require_non_negative(n_elastic, path("elastic_below_speed"), c.elastic_below_speed);
  }

  // restitution_table: [[speed, e], ...], speeds >= 0 strictly increasing, e in [0, 1].
  const toml::node* get_restitution_table(const toml::table& t, std::string_view prefix,
                                          std::vector<std::array<double, 2>>& out) const {
    const toml::node* node = t.get("restitution_table");
    if (node == nullptr) return nullptr;
    const std::string path = join_key(prefix, "restitution_table");
    const toml::array* rows = node->as_array();
    if (rows == nullptr) {
      fail(node, path,
           fmt::format("{}: expected an array of [speed, e] pairs, found {}", path,
                       describe(*node)));
    }
    out.clear();
    for (std::size_t i = 0; i < rows->size(); ++i) {
      const toml::node* row_node = rows->get(i);
      const std::string row_path = fmt::format("{}[{}]", path, i);
      const toml::array* row = row_node->as_array();
      if (row == nullptr || row->size() != 2) {
        fail(row_node, row_path,
             fmt::format("{}: expected a pair [speed, e], found {}", row_path,
                         row == nullptr ? describe(*row_node)
                                        : fmt::format("an array of {}", row->size())));
      }
      const double speed = number_value(*row->get(0), row_path + "[0]");
      const double e = number_value(*row->get(1), row_path + "[1]");
      if (!(speed >= 0.0)) {
        fail(row->get(0), row_path,
             fmt::format("{}: impact speed must be >= 0, got {}", row_path, speed));
      }
      if (!out.empty() && !(speed > out.back()[0])) {
        fail(row->get(0), row_path,
             fmt::format("{}: impact speeds must be strictly increasing, got {} after {}", row_path,
                         speed, out.back()[0]));
      }
      if (!(e >= 0.0 && e <= 1.0)) {
        fail(row->get(1), row_path,
             fmt::format("{}: restitution must be in [0, 1], got {}", row_path, e));
      }
      out.push_back({speed, e});
    }
    return node;
  }

  void read_interactions(const toml::table& t, const std::vector<SpeciesConfig>& species,
                         InteractionConfig& in) const {
    constexpr std::string_view p = "contact";
    read_contact(t, std::string(p), in.contact);
    const toml::node* n_tc = get_number(t, p, "tc", in.tc);
    require_non_negative(n_tc, "contact.tc", in.tc);
    const toml::node* n_sleep = get_number(t, p, "sleep_speed", in.sleep_speed);
    if (!(in.sleep_speed >= 0.0 || in.sleep_speed == -1.0)) {
      fail(n_sleep, "contact.sleep_speed",
           fmt::format("contact.sleep_speed: must be >= 0 (or -1 for automatic), got {}",
                       in.sleep_speed));
    }

    const std::vector<const toml::table*> tables = table_array(t, p, "pair");
    for (std::size_t i = 0; i < tables.size(); ++i) {
      const std::string prefix = fmt::format("contact.pair[{}]", i);
      std::vector<std::array<std::string, 2>> given;
      for (const PairContactConfig& other : in.pairs) given.push_back(other.species);
      PairContactConfig pair;
      pair.species = read_species_pair(*tables[i], prefix, "contact.pair", species, given);
      pair.contact = in.contact;
      read_contact(*tables[i], prefix, pair.contact);
      in.pairs.push_back(std::move(pair));
    }
  }

  // The `species` key of a [[contact.pair]] / [[soft.pair]] table at `prefix`: two declared
  // species names, a pair not already among `given` (the earlier tables of `list`).
  std::array<std::string, 2> read_species_pair(
      const toml::table& t, const std::string& prefix, std::string_view list,
      const std::vector<SpeciesConfig>& species,
      const std::vector<std::array<std::string, 2>>& given) const {
    const std::string species_key = prefix + ".species";
    std::vector<std::string> names;
    const toml::node* n_species = get_strings(t, prefix, "species", names);
    if (n_species == nullptr) {
      fail(&t, species_key,
           fmt::format("missing required key '{}' (the pair's two species, e.g. species = "
                       "[\"A\", \"B\"])",
                       species_key));
    }
    if (names.size() != 2) {
      fail(n_species, species_key,
           fmt::format("{}: expected 2 species names, got {}", species_key, names.size()));
    }
    for (std::size_t k = 0; k < 2; ++k) {
      const bool declared = std::any_of(species.begin(), species.end(),
                                        [&](const SpeciesConfig& s) { return s.name == names[k]; });
      if (!declared) {
        std::vector<std::string_view> known;
        for (const SpeciesConfig& s : species) known.push_back(s.name);
        fail(element_of(n_species, k), species_key,
             fmt::format("{}: unknown species '{}' (declared species: {})", species_key, names[k],
                         join_words(known)));
      }
    }
    for (std::size_t j = 0; j < given.size(); ++j) {
      const auto& other = given[j];
      if ((other[0] == names[0] && other[1] == names[1]) ||
          (other[0] == names[1] && other[1] == names[0])) {
        fail(n_species, species_key,
             fmt::format("{}: the pair ({}, {}) is already given by {}[{}]", species_key, names[0],
                         names[1], list, j));
      }
    }
    return {names[0], names[1]};
  }

  // The index in kFaces of a face name valid in `dimension`.
  int face_index(const toml::node* node, const std::string& path, const std::string& face,
                 int dimension) const {
    const std::span<const std::string_view> valid(kFaces, 2 * static_cast<std::size_t>(dimension));
    const auto it = std::find(valid.begin(), valid.end(), face);
    if (it == valid.end()) {
      const bool other_dimension = contains(kFaces, face);
      fail(node, path,
           fmt::format("{}: '{}' is not {}; valid values: {}", path, face,
                       other_dimension ? fmt::format("a face of a {}D box", dimension)
                                       : std::string("a valid face"),
                       join_words(valid)));
    }
    return static_cast<int>(it - valid.begin());
  }

  void read_boundary(const toml::table& t, int dimension, const ContactConfig& contact,
                     BoundaryConfig& b) const {
    constexpr std::string_view p = "boundary";
    // Who claims each face: the node (for error locations), its key, and what it makes it.
    struct Claim {
      const toml::node* node = nullptr;
      std::string key;
      bool wall = false;
    };
    std::array<Claim, 6> claims{};

    const std::vector<const toml::table*> tables = table_array(t, p, "wall");
    for (std::size_t i = 0; i < tables.size(); ++i) {
      const toml::table& wt = *tables[i];
      const std::string prefix = fmt::format("boundary.wall[{}]", i);
      const std::string face_key = prefix + ".face";
      WallConfig w;
      w.contact = contact;
      const toml::node* n_face = get_string(wt, prefix, "face", w.face);
      if (n_face == nullptr) {
        fail(tables[i], face_key,
             fmt::format("missing required key '{}' (one of {})", face_key,
                         join_words(std::span(kFaces, 2 * static_cast<std::size_t>(dimension)))));
      }
      const int f = face_index(n_face, face_key, w.face, dimension);
      if (claims[static_cast<std::size_t>(f)].node != nullptr) {
        fail(n_face, face_key,
             fmt::format("{}: face {} is listed twice (already {})", face_key, w.face,
                         claims[static_cast<std::size_t>(f)].key));
      }
      claims[static_cast<std::size_t>(f)] = {n_face, prefix, true};

      read_contact(wt, prefix, w.contact);

      // In-plane components slide the wall, the normal one moves it as a piston; finite (the
      // getter says so), and whether approaching walls leave room is checked as the run goes.
      std::vector<double> velocity;
      get_vector(wt, prefix, "velocity", dimension, velocity);
      // At rest is stored as the default, empty.
      if (std::any_of(velocity.begin(), velocity.end(), [](double v) { return v != 0.0; })) {
        w.velocity = std::move(velocity);
      }

      const toml::node* n_amplitude = get_number(wt, prefix, "amplitude", w.amplitude);
      const toml::node* n_frequency = get_number(wt, prefix, "frequency", w.frequency);
      const toml::node* n_phase = get_number(wt, prefix, "phase", w.phase);
      // Beyond 1e9 rad a double no longer resolves the phase to 1e-7.
      require_range(n_phase, prefix + ".phase", w.phase, -1e9, 1e9, "(radians)");
      require_non_negative(n_amplitude, prefix + ".amplitude", w.amplitude);
      require_non_negative(n_frequency, prefix + ".frequency", w.frequency);
      b.walls.push_back(std::move(w));
    }

    const toml::node* n_open = get_strings(t, p, "open", b.open);
    for (std::size_t i = 0; i < b.open.size(); ++i) {
      const std::string& face = b.open[i];
      const toml::node* node = element_of(n_open, i);
      const std::string key = fmt::format("boundary.open[{}]", i);
      const auto f = static_cast<std::size_t>(face_index(node, key, face, dimension));
      if (claims[f].node != nullptr) {
        fail(node, "boundary.open",
             claims[f].wall
                 ? fmt::format("{}: face {} is a wall ({}); a face is a wall or open, not both",
                               key, face, claims[f].key)
                 : fmt::format("{}: face {} is listed twice (already {})", key, face,
                               claims[f].key));
      }
      claims[f] = {node, key, false};
    }

    const toml::node* n_shear = get_number(t, p, "shear_rate", b.shear_rate);
    for (std::size_t f = 0; n_shear != nullptr && b.shear_rate != 0.0 && f < 4; ++f) {
      if (claims[f].node != nullptr) {
        fail(n_shear, "boundary.shear_rate",
             fmt::format("boundary.shear_rate: Lees-Edwards shear needs periodic x (flow) and y "
                         "(gradient) axes, but face {} is {} ({})",
                         kFaces[f], claims[f].wall ? "a wall" : "open", claims[f].key));
      }
    }

    // An axis is periodic (no wall, not open) or bounded at both ends.
    for (std::size_t axis = 0; axis < static_cast<std::size_t>(dimension); ++axis) {
      for (std::size_t side = 0; side < 2; ++side) {
        const Claim& here = claims[2 * axis + side];
        const Claim& there = claims[2 * axis + 1 - side];
        if (here.node == nullptr || there.node != nullptr) continue;
        const std::string_view face = kFaces[2 * axis + side];
        const std::string_view other = kFaces[2 * axis + 1 - side];
        fail(here.node, here.wall ? here.key + ".face" : std::string("boundary.open"),
             fmt::format(
                 "boundary: face {} is {} but {} is neither a wall nor in boundary.open; "
                 "add one (or {} to keep {} periodic)",
                 face, here.wall ? "a wall" : "open", other,
                 here.wall ? "remove the wall" : fmt::format("remove {} from boundary.open", face),
                 kAxes[axis]));
      }
    }
  }

  // The keys of a potential at `prefix` ("potential[i]", "bond[i]"), its kind among `kinds`.
  void read_potential_spec(const toml::table& t, const std::string& prefix,
                           std::span<const std::string_view> kinds, PotentialSpec& spec) const {
    const toml::node* n_kind = get_string(t, prefix, "kind", spec.kind);
    if (n_kind == nullptr) {
      fail(&t, prefix + ".kind",
           fmt::format("missing required key '{}.kind' (one of: {})", prefix, join_words(kinds)));
    }
    require_choice(n_kind, prefix + ".kind", spec.kind, kinds);
    for (const auto& [key, value] : {std::pair<std::string_view, double*>{"lambda", &spec.lambda},
                                     {"depth", &spec.depth},
                                     {"epsilon", &spec.epsilon},
                                     {"sigma", &spec.sigma},
                                     {"cutoff", &spec.cutoff},
                                     {"kappa", &spec.kappa},
                                     {"alpha", &spec.alpha},
                                     {"r_min", &spec.r_min},
                                     {"max_length", &spec.max_length},
                                     {"stiffness", &spec.stiffness},
                                     {"length", &spec.length},
                                     {"temperature", &spec.temperature}}) {
      get_number(t, prefix, key, *value);
    }
    get_numbers(t, prefix, "boundaries", spec.boundaries);
    get_numbers(t, prefix, "energies", spec.energies);
    get_bool(t, prefix, "shifted", spec.shifted);
    get_string(t, prefix, "file", spec.file);
    std::int64_t steps = spec.steps;
    const toml::node* n_steps = get_integer(t, prefix, "steps", steps);
    if (steps < 1 || steps > 100000) {
      fail(n_steps, prefix + ".steps",
           fmt::format("{}.steps: must be in [1, 100000], got {}", prefix, steps));
    }
    spec.steps = static_cast<int>(steps);
    const toml::node* n_placement = get_string(t, prefix, "placement", spec.placement);
    require_choice(n_placement, prefix + ".placement", spec.placement, kPlacements);
    const toml::node* n_shell = get_string(t, prefix, "shell_energy", spec.shell_energy);
    require_choice(n_shell, prefix + ".shell_energy", spec.shell_energy, kShellEnergies);
    require_positive(t.get("temperature"), prefix + ".temperature", spec.temperature);
    if (spec.kind == "spring_dashpot") {
      // Equal steps with midpoint energies always: the dashpot per step assumes them.
      for (const auto& [node, key] :
           {std::pair{n_placement, "placement"}, std::pair{n_shell, "shell_energy"}}) {
        if (node != nullptr) {
          fail(node, prefix + "." + key,
               fmt::format("{}.{}: spring_dashpot steps are always of equal width with the "
                           "spring's energy at each step's middle; remove the key",
                           prefix, key));
        }
      }
    }
    const toml::node* n_damping = get_number(t, prefix, "damping", spec.damping);
    const toml::node* n_restitution = get_number(t, prefix, "restitution", spec.restitution);
    const toml::node* n_force_zero = get_bool(t, prefix, "force_zero", spec.force_zero);
    for (const auto& [node, key] :
         {std::pair{n_damping, "damping"}, std::pair{n_restitution, "restitution"},
          std::pair{n_force_zero, "force_zero"}}) {
      if (node != nullptr && spec.kind != "spring_dashpot") {
        fail(node, prefix + "." + key,
             fmt::format("{}.{}: applies to kind = \"spring_dashpot\" only", prefix, key));
      }
    }
    if (n_damping != nullptr && n_restitution != nullptr) {
      fail(n_restitution, prefix + ".restitution",
           fmt::format("{}.restitution: give damping or restitution, not both", prefix));
    }
    if (n_damping != nullptr && !(spec.damping >= 0.0)) {
      fail(n_damping, prefix + ".damping",
           fmt::format("{}.damping: must be at least 0, got {}", prefix, spec.damping));
    }
    if (n_restitution != nullptr && !(spec.restitution > 0.0 && spec.restitution <= 1.0)) {
      fail(n_restitution, prefix + ".restitution",
           fmt::format("{}.restitution: must be in (0, 1], got {}", prefix, spec.restitution));
    }
  }

  void read_potentials(const toml::table& root, const std::vector<SpeciesConfig>& species,
                       std::vector<PairPotentialConfig>& out) const {
    const std::vector<const toml::table*> tables = table_array(root, "", "potential");
    for (std::size_t i = 0; i < tables.size(); ++i) {
      const std::string prefix = fmt::format("potential[{}]", i);
      const std::string species_key = prefix + ".species";
      PairPotentialConfig pc;
      const toml::node* n_species = get_strings(*tables[i], prefix, "species", pc.species);
      if (n_species != nullptr && pc.species.size() != 2) {
        fail(n_species, species_key,
             fmt::format("{}: expected 2 species names (or no key: every pair), got {}",
                         species_key, pc.species.size()));
      }
      for (std::size_t k = 0; k < pc.species.size(); ++k) {
        const bool declared =
            std::any_of(species.begin(), species.end(),
                        [&](const SpeciesConfig& s) { return s.name == pc.species[k]; });
        if (!declared) {
          std::vector<std::string_view> known;
          for (const SpeciesConfig& s : species) known.push_back(s.name);
          fail(element_of(n_species, k), species_key,
               fmt::format("{}: unknown species '{}' (declared species: {})", species_key,
                           pc.species[k], join_words(known)));
        }
      }
      for (std::size_t j = 0; j < out.size(); ++j) {
        const auto& other = out[j].species;
        const bool same =
            other.size() == pc.species.size() &&
            (other.empty() || (other[0] == pc.species[0] && other[1] == pc.species[1]) ||
             (other[0] == pc.species[1] && other[1] == pc.species[0]));
        if (same) {
          fail(n_species != nullptr ? n_species : tables[i], species_key,
               fmt::format("{}: the same pair{} is already given by potential[{}]", prefix,
                           pc.species.empty() ? "s (all)" : "", j));
        }
      }
      read_potential_spec(*tables[i], prefix, kPairPotentials, pc.potential);
      out.push_back(std::move(pc));
    }
  }

  void read_bonds(const toml::table& root, std::vector<BondConfig>& out) const {
    const std::vector<const toml::table*> tables = table_array(root, "", "bond");
    for (std::size_t i = 0; i < tables.size(); ++i) {
      const std::string prefix = fmt::format("bond[{}]", i);
      BondConfig bc;
      const toml::node* n_type = get_string(*tables[i], prefix, "type", bc.type);
      for (std::size_t j = 0; j < out.size(); ++j) {
        if (out[j].type == bc.type) {
          fail(n_type != nullptr ? n_type : tables[i], prefix + ".type",
               fmt::format("{}.type: bond type '{}' is already given by bond[{}]", prefix, bc.type,
                           j));
        }
      }
      bc.potential.kind = "";
      read_potential_spec(*tables[i], prefix, kBondPotentials, bc.potential);
      out.push_back(std::move(bc));
    }
  }

  // A soft law at `prefix` ("soft", "soft.pair[i]"). On entry `law` holds the law inherited
  // from [soft] (the defaults for [soft] itself); the keys present replace its values. A pair
  // that gives damping / dissipation drops an inherited restitution and vice versa.
  void read_soft_law(const toml::table& t, const std::string& prefix, SoftLawConfig& law) const {
    const auto path = [&](std::string_view key) { return join_key(prefix, key); };
    const bool pair = prefix != "soft";
    const toml::node* n_model = get_string(t, prefix, "model", law.model);
    const toml::node* n_k = get_number(t, prefix, "stiffness", law.stiffness);
    const toml::node* n_gamma = get_number(t, prefix, "damping", law.damping);
    const toml::node* n_young = get_number(t, prefix, "young", law.young);
    const toml::node* n_poisson = get_number(t, prefix, "poisson", law.poisson);
    const toml::node* n_a = get_number(t, prefix, "dissipation", law.dissipation);
    const toml::node* n_e = get_number(t, prefix, "restitution", law.restitution);
    const toml::node* n_speed = get_number(t, prefix, "restitution_speed", law.restitution_speed);
    const toml::node* n_mu = get_number(t, prefix, "friction", law.friction);
    const toml::node* n_kt =
        get_number(t, prefix, "tangential_stiffness", law.tangential_stiffness);
    const toml::node* n_gt = get_number(t, prefix, "tangential_damping", law.tangential_damping);
    require_non_negative(n_mu, path("friction"), law.friction);
    require_range(n_mu, path("friction"), law.friction, 0.0, 1e9);
    // Ratios to the normal law: a tangential spring much stiffer than the normal one would be
    // unstable at the time step chosen for the normal one (physical ratios are 2/3 to 4/3).
    require_positive(n_kt, path("tangential_stiffness"), law.tangential_stiffness);
    require_range(n_kt, path("tangential_stiffness"), law.tangential_stiffness, 1e-9, 10.0);
    require_non_negative(n_gt, path("tangential_damping"), law.tangential_damping);
    require_range(n_gt, path("tangential_damping"), law.tangential_damping, 0.0, 1e3);
    if (n_model == nullptr && law.model.empty()) {
      fail(&t, path("model"),
           fmt::format("missing required key '{}' (\"dashpot\" or \"hertz\"): [soft] makes every "
                       "contact soft",
                       path("model")));
    }
    require_choice(n_model, path("model"), law.model, kSoftModels);
    const bool dashpot = law.model == "dashpot";
    // Keys of the other model given here are an error (inherited ones are just not used).
    const std::pair<const toml::node*, std::string_view> foreign[] = {
        {n_young, "young"},   {n_poisson, "poisson"},
        {n_a, "dissipation"}, {n_speed, "restitution_speed"},
        {n_k, "stiffness"},   {n_gamma, "damping"}};
    for (const auto& [node, key] :
         dashpot ? std::span(foreign).first(4) : std::span(foreign).last(2)) {
      if (node != nullptr) {
        fail(node, path(key),
             fmt::format("{}: not a key of model \"{}\" (dashpot: stiffness, damping or "
                         "restitution; hertz: young, poisson, dissipation or restitution with "
                         "restitution_speed)",
                         path(key), law.model));
      }
    }
    const toml::node* n_dissipative = dashpot ? n_gamma : n_a;
    const std::string_view dissipative_key = dashpot ? "damping" : "dissipation";
    double& dissipative = dashpot ? law.damping : law.dissipation;
    if (n_dissipative != nullptr && n_e != nullptr && dissipative > 0.0 && law.restitution > 0.0) {
      fail(n_e, path("restitution"),
           fmt::format("{}: give either {} or restitution, not both", path("restitution"),
                       path(dissipative_key)));
    }
    if (pair && n_dissipative != nullptr && n_e == nullptr) law.restitution = 0.0;
    if (pair && n_e != nullptr && n_dissipative == nullptr) dissipative = 0.0;
    // Only positive finite parameters make a contact law.
    if (dashpot) {
      if (n_k == nullptr && law.stiffness == 0.0) {
        fail(n_model != nullptr ? n_model : &t, path("stiffness"),
             fmt::format("missing required key '{}' (the spring constant k of model "
                         "\"dashpot\", > 0)",
                         path("stiffness")));
      }
      require_positive(n_k, path("stiffness"), law.stiffness);
      require_non_negative(n_gamma, path("damping"), law.damping);
    } else {
      if (n_young == nullptr && law.young == 0.0) {
        fail(n_model != nullptr ? n_model : &t, path("young"),
             fmt::format("missing required key '{}' (Young's modulus of model \"hertz\", > 0)",
                         path("young")));
      }
      require_positive(n_young, path("young"), law.young);
      if (!(law.poisson > -1.0 && law.poisson <= 0.5)) {
        fail(n_poisson, path("poisson"),
             fmt::format("{}: must be in (-1, 0.5], got {}", path("poisson"), law.poisson));
      }
      require_non_negative(n_a, path("dissipation"), law.dissipation);
      require_positive(n_speed, path("restitution_speed"), law.restitution_speed);
    }
    if (!(law.restitution == 0.0 || (law.restitution > 0.0 && law.restitution <= 1.0)) ||
        (n_e != nullptr && law.restitution == 0.0)) {
      fail(n_e, path("restitution"),
           fmt::format("{}: must be in (0, 1] (the head-on coefficient of restitution{}), got {}",
                       path("restitution"), dashpot ? "" : " at restitution_speed",
                       law.restitution));
    }
  }

  void read_soft(const toml::table& t, const std::vector<SpeciesConfig>& species,
                 SoftConfig& soft) const {
    constexpr std::string_view p = "soft";
    read_soft_law(t, std::string(p), soft.law);
    const toml::node* n_collisions = get_string(t, p, "collisions", soft.collisions);
    require_choice(n_collisions, "soft.collisions", soft.collisions, kSoftCollisions);
    get_bool(t, p, "tables", soft.tables);
    const toml::node* n_tolerance = get_number(t, p, "table_tolerance", soft.table_tolerance);
    require_positive(n_tolerance, "soft.table_tolerance", soft.table_tolerance);
    if (n_tolerance != nullptr && !(soft.table_tolerance < 0.1)) {
      fail(n_tolerance, "soft.table_tolerance",
           fmt::format("soft.table_tolerance: must be below 0.1 (a relative error), got {}",
                       soft.table_tolerance));
    }
    // The nodes are integrated to 1e-13: below 1e-10 no table can be checked to its tolerance.
    if (!(soft.table_tolerance >= 1e-10)) {
      fail(n_tolerance, "soft.table_tolerance",
           fmt::format("soft.table_tolerance: must be at least 1e-10, got {}",
                       soft.table_tolerance));
    }
    get_string(t, p, "table_cache", soft.table_cache);
    get_bool(t, p, "defer_releases", soft.defer_releases);
    const std::vector<const toml::table*> tables = table_array(t, p, "pair");
    for (std::size_t i = 0; i < tables.size(); ++i) {
      const std::string prefix = fmt::format("soft.pair[{}]", i);
      std::vector<std::array<std::string, 2>> given;
      for (const SoftPairConfig& other : soft.pairs) given.push_back(other.species);
      SoftPairConfig pair;
      pair.species = read_species_pair(*tables[i], prefix, "soft.pair", species, given);
      pair.law = soft.law;
      read_soft_law(*tables[i], prefix, pair.law);
      soft.pairs.push_back(std::move(pair));
    }
  }

  // The first key of a contact law that differs from the elastic, smooth default ("" if none).
  static std::string_view non_default_contact_key(const ContactConfig& c) {
    const ContactConfig hard{};
    if (c.restitution != hard.restitution) return "restitution";
    if (c.restitution_model != hard.restitution_model) return "restitution_model";
    if (c.restitution_speed != hard.restitution_speed) return "restitution_speed";
    if (!c.restitution_table.empty()) return "restitution_table";
    if (c.tangential_restitution != hard.tangential_restitution) return "tangential_restitution";
    if (c.friction != hard.friction) return "friction";
    if (c.elastic_below_speed != hard.elastic_below_speed) return "elastic_below_speed";
    return {};
  }

  // The node at a dotted path of plain tables ("contact.restitution"), or nullptr.
  static const toml::node* node_at(const toml::table& root, std::string_view path) {
    return root.at_path(path).node();
  }

  // What soft spheres and the DEM integrator cannot be combined with (yet).
  void check_soft_and_dem(const toml::table& root, const Config& c) const {
    const toml::node* n_model = node_at(root, "soft.model");
    if (c.soft.enabled()) {
      const auto conflict = [&](std::string_view key, std::string_view why) {
        const toml::node* n = node_at(root, key);
        fail(n != nullptr ? n : n_model, key,
             fmt::format("{}: not allowed with soft spheres (soft.model = \"{}\"): {}", key,
                         c.soft.law.model, why));
      };
      const std::string_view laws =
          "soft contacts replace the [contact] laws (set the dissipation in [soft])";
      if (const std::string_view key = non_default_contact_key(c.interactions.contact);
          !key.empty()) {
        const bool rough = key == "tangential_restitution" || key == "friction";
        conflict(join_key("contact", key), rough ? "soft spheres are frictionless (smooth)" : laws);
      }
      if (c.interactions.tc != 0.0) conflict("contact.tc", laws);
      if (!c.interactions.pairs.empty()) conflict("contact.pair", "use [[soft.pair]] instead");
      for (std::size_t w = 0; w < c.boundary.walls.size(); ++w) {
        if (const std::string_view key = non_default_contact_key(c.boundary.walls[w].contact);
            !key.empty()) {
          conflict(fmt::format("boundary.wall[{}].{}", w, key),
                   "soft contacts with walls use the [soft] material");
        }
      }
      if (!c.potentials.empty())
        conflict("potential", "stepped potentials and soft spheres do not mix");
      if (!c.bonds.empty()) conflict("bond", "stepped potentials and soft spheres do not mix");
      if (c.boundary.shear_rate != 0.0) {
        conflict("boundary.shear_rate",
                 "Lees-Edwards shear is not supported with soft spheres yet");
      }
      if (c.run.integrator != "dem") {
        const auto rough = [&](const SoftLawConfig& law, const std::string& prefix) {
          if (law.friction > 0.0) {
            const std::string key = prefix + ".friction";
            const toml::node* n = node_at(root, key);
            fail(n != nullptr ? n : n_model, key,
                 fmt::format("{}: friction is integrated by the DEM alone (the collision map is "
                             "that of smooth spheres); set run.integrator = \"dem\" or friction "
                             "= 0",
                             key));
          }
        };
        rough(c.soft.law, "soft");
        for (std::size_t p = 0; p < c.soft.pairs.size(); ++p)
          rough(c.soft.pairs[p].law, fmt::format("soft.pair[{}]", p));
      }
      if (!c.field.gravity.empty() && c.run.integrator != "dem") {
        conflict("field.gravity",
                 "the collision mapping is not defined under gravity (a soft contact under a "
                 "load does not end); use run.integrator = \"dem\"");
      }
    }
    if (c.run.integrator != "dem") return;
    const toml::node* n_integrator = node_at(root, "run.integrator");
    const auto unsupported = [&](std::string_view key, std::string_view what) {
      const toml::node* n = node_at(root, key);
      fail(n != nullptr ? n : n_integrator, key,
           fmt::format("{}: {} not supported by the DEM integrator (run.integrator = \"dem\")", key,
                       what));
    };
    if (!c.soft.enabled()) {
      fail(n_integrator, "run.integrator",
           "run.integrator: \"dem\" integrates soft contact forces and needs a [soft] table "
           "(model = \"dashpot\" or \"hertz\")");
    }
    if (!c.boundary.open.empty()) unsupported("boundary.open", "open faces are");
    if (c.driving.kind != "none") unsupported("driving.kind", "driving is");
    if (c.run.validate) unsupported("run.validate", "engine validation is");
  }

  void read_field(const toml::table& t, int dimension, FieldConfig& f) const {
    std::vector<double> gravity;
    get_vector(t, "field", "gravity", dimension, gravity);
    // No field is stored as the default, empty.
    if (std::any_of(gravity.begin(), gravity.end(), [](double g) { return g != 0.0; })) {
      f.gravity = std::move(gravity);
    }
  }

  void read_driving(const toml::table& t, DrivingConfig& d) const {
    constexpr std::string_view p = "driving";
    const toml::node* n_kind = get_string(t, p, "kind", d.kind);
    const toml::node* n_rate = get_number(t, p, "rate", d.rate);
    const toml::node* n_temperature = get_number(t, p, "temperature", d.temperature);
    const toml::node* n_strength = get_number(t, p, "strength", d.strength);
    require_choice(n_kind, "driving.kind", d.kind, kDrivingKinds);
    require_positive(n_rate, "driving.rate", d.rate);
    require_positive(n_temperature, "driving.temperature", d.temperature);
    require_non_negative(n_strength, "driving.strength", d.strength);
    if (d.kind == "white_noise" && !(d.strength > 0.0)) {
      fail(n_strength != nullptr ? n_strength : n_kind, "driving.strength",
           "driving.strength: white_noise driving needs a strength > 0 (velocity variance per "
           "unit time)");
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

    const toml::node* n_time = get_number(t, p, "time", r.time);
    const toml::node* n_equilibration_time =
        get_number(t, p, "equilibration_time", r.equilibration_time);
    // Up to 1e9 collisions per particle: 1e18 collisions of the largest system still count in
    // 64 bits, and no run gets that far.
    require_non_negative(n_equilibration, "run.equilibration_collisions_per_particle",
                         r.equilibration_collisions_per_particle);
    require_range(n_equilibration, "run.equilibration_collisions_per_particle",
                  r.equilibration_collisions_per_particle, 0.0, 1e9);
    require_positive(n_production, "run.collisions_per_particle", r.collisions_per_particle);
    require_range(n_production, "run.collisions_per_particle", r.collisions_per_particle, 0.0, 1e9);
    if (n_time != nullptr) require_positive(n_time, "run.time", r.time);
    if (n_equilibration_time != nullptr)
      require_non_negative(n_equilibration_time, "run.equilibration_time", r.equilibration_time);
    // One length per phase: in collisions per particle or in simulated time, not both.
    if (n_time != nullptr && n_production != nullptr) {
      fail(n_time, "run.time",
           "run.time and run.collisions_per_particle both give the production length: keep one");
    }
    if (n_equilibration_time != nullptr && n_equilibration != nullptr) {
      fail(n_equilibration_time, "run.equilibration_time",
           "run.equilibration_time and run.equilibration_collisions_per_particle both give the "
           "equilibration length: keep one");
    }
    require_choice(n_queue, "run.event_queue", r.event_queue, kEventQueues);
    require_non_negative(n_wall, "run.max_wall_seconds", r.max_wall_seconds);
    require_range(n_wall, "run.max_wall_seconds", r.max_wall_seconds, 0.0, 1e9,
                  "(seconds; 0: no limit)");
    const toml::node* n_integrator = get_string(t, p, "integrator", r.integrator);
    const toml::node* n_step = get_number(t, p, "time_step", r.time_step);
    require_choice(n_integrator, "run.integrator", r.integrator, kIntegrators);
    require_non_negative(n_step, "run.time_step", r.time_step);
    if (r.time_step > 0.0 && r.integrator != "dem") {
      fail(n_step, "run.time_step",
           fmt::format("run.time_step: only used by the DEM integrator (run.integrator = \"dem\"; "
                       "it is \"{}\"), which has a time step",
                       r.integrator));
    }
  }

  void read_output(const toml::table& t, int dimension, OutputConfig& o) const {
    constexpr std::string_view p = "output";
    const toml::node* n_directory = get_string(t, p, "directory", o.directory);
    const toml::node* n_thermo = get_number(t, p, "thermo_interval", o.thermo_interval);
    const toml::node* n_trajectory = get_number(t, p, "trajectory_interval", o.trajectory_interval);
    const toml::node* n_restart = get_number(t, p, "restart_interval", o.restart_interval);
    const toml::node* n_unit = get_string(t, p, "interval_unit", o.interval_unit);
    if (n_unit != nullptr)
      require_choice(n_unit, "output.interval_unit", o.interval_unit, kIntervalUnits);
    get_bool(t, p, "trajectory", o.trajectory);
    const toml::node* n_progress = get_string(t, p, "progress", o.progress);
    const toml::node* n_axis = get_string(t, p, "profile_axis", o.profile_axis);
    const toml::node* n_bins = get_integer(t, p, "profile_bins", o.profile_bins);
    if (!(o.profile_axis.empty() || o.profile_axis == "x" || o.profile_axis == "y" ||
          (o.profile_axis == "z" && dimension == 3))) {
      fail(n_axis, "output.profile_axis",
           fmt::format("output.profile_axis: '{}' is not an axis of a {}D box (x, y{}, or \"\" for "
                       "no profile)",
                       o.profile_axis, dimension, dimension == 3 ? ", z" : ""));
    }
    if (o.profile_bins < 1 || o.profile_bins > 100000) {
      fail(n_bins, "output.profile_bins",
           fmt::format("output.profile_bins: must be in [1, 100000], got {}", o.profile_bins));
    }

    if (o.directory.empty()) {
      fail(n_directory, "output.directory", "output.directory: must not be empty");
    }
    require_non_negative(n_thermo, "output.thermo_interval", o.thermo_interval);
    require_non_negative(n_trajectory, "output.trajectory_interval", o.trajectory_interval);
    require_non_negative(n_restart, "output.restart_interval", o.restart_interval);
    require_choice(n_progress, "output.progress", o.progress, kProgressModes);
  }

  // The intervals' unit defaults to the production length's; automatic intervals (0) are
  // fractions of the production length, so they need the same unit.
  void resolve_interval_unit(const toml::table& t, const RunConfig& r, OutputConfig& o) const {
    const std::string length_unit = r.time > 0.0 ? "time" : "collisions";
    if (o.interval_unit.empty()) o.interval_unit = length_unit;
    if (o.interval_unit == length_unit) return;
    const char* automatic = !(o.thermo_interval > 0.0)       ? "thermo_interval"
                            : !(o.trajectory_interval > 0.0) ? "trajectory_interval"
                                                             : nullptr;
    if (automatic != nullptr) {
      fail(t.get("interval_unit"), "output.interval_unit",
           fmt::format("output.interval_unit = \"{}\" but the production length is in {} "
                       "(run.{}): the automatic output.{} (a fraction of that length) cannot be "
                       "converted; give it explicitly",
                       o.interval_unit, length_unit == "time" ? "simulated time" : "collisions",
                       length_unit == "time" ? "time" : "collisions_per_particle", automatic));
    }
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

// "[1.0, 0.0, -1.0]"
std::string toml_floats(const std::vector<double>& values) {
  std::string out = "[";
  for (std::size_t i = 0; i < values.size(); ++i) {
    out += fmt::format("{}{}", i == 0 ? "" : ", ", toml_float(values[i]));
  }
  return out + "]";
}

// The keys of a contact law, one per line (restitution_table only when there is one).
std::string contact_toml(const ContactConfig& c) {
  std::string out;
  out += fmt::format("restitution = {}\n", toml_float(c.restitution));
  out += fmt::format("restitution_model = {}\n", toml_string(c.restitution_model));
  out += fmt::format("restitution_speed = {}\n", toml_float(c.restitution_speed));
  if (!c.restitution_table.empty()) {
    out += "restitution_table = [";
    for (std::size_t i = 0; i < c.restitution_table.size(); ++i) {
      out += fmt::format("{}[{}, {}]", i == 0 ? "" : ", ", toml_float(c.restitution_table[i][0]),
                         toml_float(c.restitution_table[i][1]));
    }
    out += "]\n";
  }
  out += fmt::format("tangential_restitution = {}\n", toml_float(c.tangential_restitution));
  out += fmt::format("friction = {}\n", toml_float(c.friction));
  out += fmt::format("elastic_below_speed = {}\n", toml_float(c.elastic_below_speed));
  return out;
}

// The keys of a soft law that its model uses, one per line: restitution when given, else the
// damping (dissipation).
std::string soft_law_toml(const SoftLawConfig& law) {
  std::string out = fmt::format("model = {}\n", toml_string(law.model));
  if (law.model == "dashpot") {
    out += fmt::format("stiffness = {}\n", toml_float(law.stiffness));
    out += law.restitution > 0.0 ? fmt::format("restitution = {}\n", toml_float(law.restitution))
                                 : fmt::format("damping = {}\n", toml_float(law.damping));
  } else {
    out += fmt::format("young = {}\n", toml_float(law.young));
    out += fmt::format("poisson = {}\n", toml_float(law.poisson));
    out += law.restitution > 0.0 ? fmt::format("restitution = {}\n", toml_float(law.restitution))
                                 : fmt::format("dissipation = {}\n", toml_float(law.dissipation));
    out += fmt::format("restitution_speed = {}\n", toml_float(law.restitution_speed));
  }
  out += fmt::format("friction = {}\n", toml_float(law.friction));
  out += fmt::format("tangential_stiffness = {}\n", toml_float(law.tangential_stiffness));
  out += fmt::format("tangential_damping = {}\n", toml_float(law.tangential_damping));
  return out;
}

// The keys of a potential, one per line.
std::string potential_toml(const PotentialSpec& p) {
  std::string out;
  out += fmt::format("kind = {}\n", toml_string(p.kind));
  for (const auto& [key, value] : {std::pair<const char*, double>{"lambda", p.lambda},
                                   {"depth", p.depth},
                                   {"epsilon", p.epsilon},
                                   {"sigma", p.sigma},
                                   {"cutoff", p.cutoff},
                                   {"kappa", p.kappa},
                                   {"alpha", p.alpha},
                                   {"r_min", p.r_min},
                                   {"max_length", p.max_length},
                                   {"stiffness", p.stiffness},
                                   {"length", p.length},
                                   {"temperature", p.temperature}}) {
    out += fmt::format("{} = {}\n", key, toml_float(value));
  }
  out += fmt::format("boundaries = {}\n", toml_floats(p.boundaries));
  out += fmt::format("energies = {}\n", toml_floats(p.energies));
  out += fmt::format("shifted = {}\n", p.shifted);
  out += fmt::format("file = {}\n", toml_string(p.file));
  out += fmt::format("steps = {}\n", p.steps);
  if (p.kind != "spring_dashpot") {
    out += fmt::format("placement = {}\n", toml_string(p.placement));
    out += fmt::format("shell_energy = {}\n", toml_string(p.shell_energy));
  } else {
    out += p.restitution > 0.0 ? fmt::format("restitution = {}\n", toml_float(p.restitution))
                               : fmt::format("damping = {}\n", toml_float(p.damping));
    out += fmt::format("force_zero = {}\n", p.force_zero);
  }
  return out;
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

namespace {

// Only a regular file is read: reading a FIFO would block until another process writes to it,
// and a directory or a device is never a config file. (A missing file is left to fopen.)
void require_regular_file(const std::filesystem::path& path) {
  using std::filesystem::file_type;
  std::error_code ec;
  const file_type type = std::filesystem::status(path, ec).type();
  if (ec || type == file_type::regular || type == file_type::not_found) return;
  const char* kind = type == file_type::directory                               ? "a directory"
                     : type == file_type::fifo                                  ? "a FIFO"
                     : type == file_type::character || type == file_type::block ? "a device"
                                                                                : "a special file";
  throw InputError(
      fmt::format("config file '{}' is not a regular file (it is {}): give the path of a TOML file",
                  path.string(), kind));
}

}  // namespace

Config load_config(const std::filesystem::path& path, const std::vector<std::string>& overrides) {
  const auto cannot_read = [&](const std::string& reason) {
    return InputError(fmt::format("cannot read config file '{}': {}", path.string(), reason));
  };
  require_regular_file(path);

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
  const InteractionConfig& in = config.interactions;

  std::string lattice = s.lattice;
  if (lattice.empty() && (s.dimension == 2 || s.dimension == 3)) {
    lattice = default_lattice(s.dimension);
  }
  std::vector<SpeciesConfig> species = s.species;
  if (species.empty()) species.emplace_back();
  // Vectors left empty (the defaults) are written with their effective values.
  const std::size_t dimension = s.dimension == 2 ? 2 : 3;
  const auto vector_or = [&](const std::vector<double>& v, double fill) {
    return toml_floats(v.empty() ? std::vector<double>(dimension, fill) : v);
  };

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
  out += fmt::format("box_scale = {}\n", vector_or(s.box_scale, 1.0));
  out += fmt::format("chain_length = {}\n", toml_unsigned(s.chain_length, "system.chain_length"));
  out += fmt::format("chain_spacing = {}\n", toml_float(s.chain_spacing));
  for (const SpeciesConfig& sp : species) {
    out += "\n[[system.species]]\n";
    out += fmt::format("name = {}\n", toml_string(sp.name));
    out += fmt::format("diameter = {}\n", toml_float(sp.diameter));
    out += fmt::format("mass = {}\n", toml_float(sp.mass));
    out += fmt::format("fraction = {}\n", toml_float(sp.fraction));
    out += fmt::format("inertia_factor = {}\n", toml_float(sp.inertia_factor));
  }
  for (const PairPotentialConfig& pc : config.potentials) {
    out += "\n[[potential]]\n";
    if (!pc.species.empty()) {
      out += fmt::format("species = [{}, {}]\n", toml_string(pc.species[0]),
                         toml_string(pc.species[1]));
    }
    out += potential_toml(pc.potential);
  }
  for (const BondConfig& bc : config.bonds) {
    out += "\n[[bond]]\n";
    out += fmt::format("type = {}\n", toml_string(bc.type));
    out += potential_toml(bc.potential);
  }
  out += "\n[contact]\n";
  out += contact_toml(in.contact);
  out += fmt::format("tc = {}\n", toml_float(in.tc));
  out += fmt::format("sleep_speed = {}\n", toml_float(in.sleep_speed));
  for (const PairContactConfig& pair : in.pairs) {
    out += "\n[[contact.pair]]\n";
    out += fmt::format("species = [{}, {}]\n", toml_string(pair.species[0]),
                       toml_string(pair.species[1]));
    out += contact_toml(pair.contact);
  }
  out += "\n[boundary]\n";
  out += "open = [";
  for (std::size_t i = 0; i < config.boundary.open.size(); ++i) {
    out += fmt::format("{}{}", i == 0 ? "" : ", ", toml_string(config.boundary.open[i]));
  }
  out += "]\n";
  out += fmt::format("shear_rate = {}\n", toml_float(config.boundary.shear_rate));
  for (const WallConfig& w : config.boundary.walls) {
    out += "\n[[boundary.wall]]\n";
    out += fmt::format("face = {}\n", toml_string(w.face));
    out += contact_toml(w.contact);
    out += fmt::format("velocity = {}\n", vector_or(w.velocity, 0.0));
    out += fmt::format("amplitude = {}\n", toml_float(w.amplitude));
    out += fmt::format("frequency = {}\n", toml_float(w.frequency));
    out += fmt::format("phase = {}\n", toml_float(w.phase));
  }
  out += "\n[driving]\n";
  out += fmt::format("kind = {}\n", toml_string(config.driving.kind));
  out += fmt::format("rate = {}\n", toml_float(config.driving.rate));
  out += fmt::format("temperature = {}\n", toml_float(config.driving.temperature));
  out += fmt::format("strength = {}\n", toml_float(config.driving.strength));
  out += "\n[field]\n";
  out += fmt::format("gravity = {}\n", vector_or(config.field.gravity, 0.0));
  const SoftConfig& soft = config.soft;
  if (soft.enabled()) {
    out += "\n[soft]\n";
    out += soft_law_toml(soft.law);
    out += fmt::format("collisions = {}\n", toml_string(soft.collisions));
    out += fmt::format("tables = {}\n", soft.tables);
    out += fmt::format("table_tolerance = {}\n", toml_float(soft.table_tolerance));
    out += fmt::format("table_cache = {}\n", toml_string(soft.table_cache));
    out += fmt::format("defer_releases = {}\n", soft.defer_releases);
    for (const SoftPairConfig& pair : soft.pairs) {
      out += "\n[[soft.pair]]\n";
      out += fmt::format("species = [{}, {}]\n", toml_string(pair.species[0]),
                         toml_string(pair.species[1]));
      out += soft_law_toml(pair.law);
    }
  }
  out += "\n[run]\n";
  // Each phase's length in its one unit (both would be refused when the file is read back).
  if (r.equilibration_time >= 0.0) {
    out += fmt::format("equilibration_time = {}\n", toml_float(r.equilibration_time));
  } else {
    out += fmt::format("equilibration_collisions_per_particle = {}\n",
                       toml_float(r.equilibration_collisions_per_particle));
  }
  if (r.time > 0.0) {
    out += fmt::format("time = {}\n", toml_float(r.time));
  } else {
    out += fmt::format("collisions_per_particle = {}\n", toml_float(r.collisions_per_particle));
  }
  out += fmt::format("event_queue = {}\n", toml_string(r.event_queue));
  out += fmt::format("max_wall_seconds = {}\n", toml_float(r.max_wall_seconds));
  out += fmt::format("validate = {}\n", r.validate);
  out += fmt::format("integrator = {}\n", toml_string(r.integrator));
  out += fmt::format("time_step = {}\n", toml_float(r.time_step));
  out += "\n[output]\n";
  out += fmt::format("directory = {}\n", toml_string(o.directory));
  out += fmt::format("thermo_interval = {}\n", toml_float(o.thermo_interval));
  out += fmt::format("trajectory_interval = {}\n", toml_float(o.trajectory_interval));
  out += fmt::format("restart_interval = {}\n", toml_float(o.restart_interval));
  if (!o.interval_unit.empty())  // "" (a config built in code): the reader's default
    out += fmt::format("interval_unit = {}\n", toml_string(o.interval_unit));
  out += fmt::format("trajectory = {}\n", o.trajectory);
  out += fmt::format("progress = {}\n", toml_string(o.progress));
  out += fmt::format("profile_axis = {}\n", toml_string(o.profile_axis));
  out += fmt::format("profile_bins = {}\n", o.profile_bins);
  return out;
}

}  // namespace kairos
