// The generic part of the config reader: where an error is (file:line:column, or the override
// that made the node), the typed getters of TOML values, and the reading of a declared group of
// keys into its struct with their ranges and choices (io/config_keys.hpp). The reader of the
// sections and their rules (io/config.cpp) derives from it. Internal to src/io.
#pragma once

#include <fmt/format.h>

#include <toml++/toml.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "interactions/parameter_domain.hpp"
#include "io/config_keys.hpp"
#include "io/config_override.hpp"
#include "io/config_text.hpp"

namespace kairos::config_detail {

class KeyReader {
 public:
  KeyReader(std::string source, std::vector<AppliedOverride> overrides)
      : source_(std::move(source)), overrides_(std::move(overrides)) {}

 protected:
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
      if (is_bare_key(key.str()) && find_declared(join_key(prefix, key.str())) != nullptr) continue;
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

  // The declared range of a key that depends on another (Range::by_rule: a soft law's
  // stiffness is checked for model "dashpot" only), checked by the rule that knows it applies.
  void check_rule_range(const toml::node* node, const std::string& path, double value) const {
    Range range = find_declared(path)->decl->range;
    range.by_rule = false;
    check_range(node, path, value, range);
  }

  void require_choice(const toml::node* node, std::string_view path, const std::string& value,
                      const std::vector<std::string_view>& choices) const {
    if (!contains(choices, value)) {
      fail(node, path,
           fmt::format("{}: '{}' is not valid; valid values: {}", path, shown(value),
                       join_words(choices)));
    }
  }

  // A value against the declared range of its key: all of it for a dimensionless key, the sign
  // for one measured in a scale of the start state (the rest: run/config_ranges.cpp). `shown`
  // is how the value is echoed ("" = the double).
  void check_range(const toml::node* node, std::string_view path, double v, const Range& r,
                   const std::string& shown_value = {}) const {
    if (r.by_rule || !r.bounded()) return;
    const std::string value = shown_value.empty() ? fmt::format("{}", v) : shown_value;
    const std::string why = r.why.empty() ? std::string() : fmt::format(" {}", r.why);
    if (r.scale != Scale::kNone) {
      if (r.lo < 0.0) return;
      const bool strict = (r.lo > 0.0 || r.lo_open) && r.also != 0.0;
      if (v == r.also || (strict ? v > 0.0 : v >= 0.0)) return;
      fail(node, path,
           fmt::format("{}: must be {} 0{}, got {}", path, strict ? ">" : ">=", why, value));
    }
    if (r.contains(v)) return;
    if (!std::isfinite(r.hi)) {
      fail(node, path,
           fmt::format("{}: must be {} {:g}{}, got {}", path, r.lo_open ? ">" : ">=", r.lo, why,
                       value));
    }
    fail(node, path,
         fmt::format("{}: must be in {}{:g}, {:g}{}{}, got {}", path, r.lo_open ? "(" : "[", r.lo,
                     r.hi, r.hi_open ? ")" : "]", why, value));
  }

  // The keys of `group` present in `t` (at `prefix`) read into `object` (the group's struct),
  // each checked against its declared type, range and choices; keys without a member, and
  // ranges and choices that depend on another key, are left to the section's rules. A vector
  // of `*dimension` numbers equal to its fill everywhere is stored as the default, empty.
  void read_group(const toml::table& t, const std::string& prefix, const KeyGroup& group,
                  void* object, const int* dimension) const {
    for (const KeyDecl& d : group.keys) {
      const Field& f = d.member;
      const toml::node* node = t.get(d.name);
      if (!f || node == nullptr) continue;
      const std::string path = join_key(prefix, d.name);
      switch (f.cpp) {
        case CppType::kInt:
        case CppType::kInt64: {
          std::int64_t v = 0;
          get_integer(t, prefix, d.name, v);
          check_range(node, path, static_cast<double>(v), d.range, fmt::format("{}", v));
          if (f.cpp == CppType::kInt) {
            f.of<int>(object) = static_cast<int>(v);
          } else {
            f.of<std::int64_t>(object) = v;
          }
          break;
        }
        case CppType::kUint64: {
          std::uint64_t& v = f.of<std::uint64_t>(object);
          get_unsigned(t, prefix, d.name, v);
          check_range(node, path, static_cast<double>(v), d.range, fmt::format("{}", v));
          break;
        }
        case CppType::kDouble: {
          double& v = f.of<double>(object);
          get_number(t, prefix, d.name, v, d.range.allow_infinity);
          check_range(node, path, v, d.range);
          break;
        }
        case CppType::kBool:
          get_bool(t, prefix, d.name, f.of<bool>(object));
          break;
        case CppType::kString: {
          std::string& v = f.of<std::string>(object);
          get_string(t, prefix, d.name, v);
          if (d.choices != nullptr && !d.range.by_rule)
            require_choice(node, path, v, d.choices(dimension != nullptr ? *dimension : 3));
          break;
        }
        case CppType::kStrings:
          get_strings(t, prefix, d.name, f.of<std::vector<std::string>>(object));
          break;
        case CppType::kDoubles: {
          std::vector<double> v;
          if (d.type == KeyType::kVector) {
            get_vector(t, prefix, d.name, dimension != nullptr ? *dimension : 3, v);
          } else {
            get_numbers(t, prefix, d.name, v);
          }
          for (std::size_t i = 0; i < v.size(); ++i) {
            check_range(element_of(node, i), fmt::format("{}[{}]", path, i), v[i], d.range);
          }
          const bool all_fill =
              std::all_of(v.begin(), v.end(), [&](double x) { return x == d.fill; });
          if (d.type == KeyType::kVector && all_fill) v.clear();
          f.of<std::vector<double>>(object) = std::move(v);
          break;
        }
        case CppType::kSpeedTable:
          get_restitution_table(t, prefix, f.of<std::vector<std::array<double, 2>>>(object));
          break;
      }
    }
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
      const auto previous = out.empty() ? std::nullopt : std::optional<double>(out.back()[0]);
      if (const auto fault = restitution_table_row_fault(speed, previous, e)) {
        fail(row->get(fault->entry), row_path, fmt::format("{}: {}", row_path, fault->why));
      }
      out.push_back({speed, e});
    }
    return node;
  }

 private:
  std::string source_;
  std::vector<AppliedOverride> overrides_;
};

}  // namespace kairos::config_detail
