// Every config key declared once: its dotted path, type, default, range, unit and one doc line,
// with the member of the Config structs it is stored in. The declarations drive
//   - the reader (io/config.cpp): unknown keys and their suggestions, the typed reading of every
//     key with a member, the range of every dimensionless key;
//   - `--set`: how a value given on the command line is coerced (a string key takes the text);
//   - to_toml (the written config.toml): each group's keys in declaration order;
//   - run/config_ranges.cpp: the ranges given in units of the start state's scales;
//   - docs/config.md: its key tables are checked against them (tests/io/test_config_keys.cpp),
//     and `kairos config-keys --markdown` prints them.
// Rules between keys (run.time vs run.collisions_per_particle, walls vs open faces, soft spheres
// vs [contact], ...) stay named functions of the reader.
//
// Adding a key: a member in io/config.hpp (its initialiser is the default), one KeyDecl in the
// group of its struct in io/keys/ (one file per part of the config; io/config_keys.cpp places
// the groups into tables), one row in the table of docs/config.md. The reader
// and the writer then handle it; a rule that involves other keys goes into the reader. A key of
// a boundary geometry's table goes into its table file pair instead (io/surface_table.hpp),
// which declares, reads and writes its own groups.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace kairos {

enum class KeyType {
  kTable,       // [name]
  kTableArray,  // [[name]]
  kInteger,     // std::int64_t or int
  kUnsigned,    // std::uint64_t, >= 0
  kFloat,       // double (an integer is accepted)
  kString,      // std::string; with choices: one of them
  kBoolean,
  kFloats,       // std::vector<double>: an array of numbers
  kVector,       // std::vector<double>: system.dimension numbers (empty = all `fill`)
  kStrings,      // std::vector<std::string>
  kSpeciesPair,  // two species names
  kSpeedTable,   // [[speed, e], ...]
};

// What a range is measured in. kNone: the key is dimensionless, or the unit itself (checked
// when the file is read); the others are scales of the start state, checked when the run
// starts (run/config_ranges.cpp); the reader checks only the sign then (lo is 0, or > 0).
enum class Scale {
  kNone,
  kEnergy,               // kT
  kSpeed,                // v = sqrt(kT / m)
  kTime,                 // tau = d_min / v
  kRate,                 // 1 / tau
  kLength,               // d, the largest diameter
  kInverseLength,        // 1 / d
  kStiffness,            // kT / d^2
  kModulus,              // kT / d^3
  kCollisionRate,        // omega, the dilute collision rate per particle
  kBoxEdge,              // the box edge along the key's axis
  kSpeedSquaredPerTime,  // v^2 / tau
};

struct Range {
  static constexpr double kInf = std::numeric_limits<double>::infinity();
  double lo = -kInf;
  double hi = kInf;
  bool lo_open = false;
  bool hi_open = false;
  Scale scale = Scale::kNone;
  // One more allowed value outside [lo, hi] (NaN: none), e.g. 0 for "the default", -1 for
  // "automatic".
  double also = std::numeric_limits<double>::quiet_NaN();
  std::string_view why = {};    // appended to the error, e.g. "(radians)"
  bool allow_infinity = false;  // +inf is a value (contact.friction)
  bool by_rule = false;         // checked by a named rule of the reader (it depends on a key)

  bool bounded() const { return std::isfinite(lo) || std::isfinite(hi); }
  bool contains(double v) const {
    if (v == also) return true;
    const bool above = lo_open ? v > lo : v >= lo;
    const bool below = hi_open ? v < hi : v <= hi;
    return above && below;
  }
};

// The C++ type of a member a key is stored in.
enum class CppType {
  kInt,
  kInt64,
  kUint64,
  kDouble,
  kBool,
  kString,
  kDoubles,
  kStrings,
  kSpeedTable
};

template <class T>
constexpr CppType cpp_type_of() {
  if constexpr (std::is_same_v<T, int>) return CppType::kInt;
  if constexpr (std::is_same_v<T, std::int64_t>) return CppType::kInt64;
  if constexpr (std::is_same_v<T, std::uint64_t>) return CppType::kUint64;
  if constexpr (std::is_same_v<T, double>) return CppType::kDouble;
  if constexpr (std::is_same_v<T, bool>) return CppType::kBool;
  if constexpr (std::is_same_v<T, std::string>) return CppType::kString;
  if constexpr (std::is_same_v<T, std::vector<double>>) return CppType::kDoubles;
  if constexpr (std::is_same_v<T, std::vector<std::string>>) return CppType::kStrings;
  if constexpr (std::is_same_v<T, std::vector<std::array<double, 2>>>) return CppType::kSpeedTable;
}

// Where a key lives in its group's struct: the address of the member given the struct's, and
// the member's type.
struct Field {
  void* (*address)(void* object) = nullptr;
  CppType cpp = CppType::kDouble;
  explicit operator bool() const { return address != nullptr; }
  template <class T>
  T& of(void* object) const {
    return *static_cast<T*>(address(object));
  }
  template <class T>
  const T& of(const void* object) const {
    return *static_cast<const T*>(address(const_cast<void*>(object)));
  }
};

template <auto Member, class S>
void* member_address(void* object) {
  return &(static_cast<S*>(object)->*Member);
}

template <class S, class T>
S member_class(T S::*);
template <class S, class T>
T member_type(T S::*);

// field<&SystemConfig::particles>
template <auto Member>
inline constexpr Field field{&member_address<Member, decltype(member_class(Member))>,
                             cpp_type_of<decltype(member_type(Member))>()};

struct KeyDecl {
  std::string_view name = {};  // the last part of the path: "particles"
  KeyType type = KeyType::kFloat;
  Field member{};  // none: read and written by hand (the reader's rules)
  Range range{};
  // String keys with a fixed set of values: their names for a box of `dimension`.
  std::vector<std::string_view> (*choices)(int dimension) = nullptr;
  std::string_view default_text = {};  // as docs/config.md writes it; "" = the struct's default
  std::string_view unit = {};          // e.g. "radians", "collisions per particle"
  std::string_view doc = {};           // one line
  double fill = 0.0;                   // kVector: the value of each component when empty
  // to_toml writes the key only when this holds for the group's struct (nullptr: always).
  bool (*written)(const void* object) = nullptr;
};

// The keys of one struct, in the order to_toml writes them.
struct KeyGroup {
  std::string_view name = {};  // "contact law", for the docs
  std::span<const KeyDecl> keys;
  const void* defaults;  // a default-constructed struct of the group
};

// Every declared path (arrays of tables as "[]": "contact.pair[].restitution"), in the order
// the "did you mean" suggestions prefer them, with its declaration (nullptr for a table).
struct DeclaredKey {
  std::string path;
  KeyType type;
  const KeyDecl* decl = nullptr;
  const void* defaults = nullptr;  // the default-constructed struct of its group
  // The key comes from a group shared with another table ("contact.pair[].restitution" is a
  // key of [contact]): documented there.
  std::string_view shared_from = {};
};
const std::vector<DeclaredKey>& declared_keys();
// The keys of `group` that `object` (the group's struct) has, one per line "key = value", in
// declaration order (to_toml, io/config_writer.cpp); a vector left empty (the default) is
// written with its effective value, `dimension` components of its fill.
std::string group_toml(const KeyGroup& group, const void* object, std::string_view prefix,
                       std::size_t dimension);
// The declaration of a path ("system.species[2].name" or "system.species[].name"), or nullptr.
const DeclaredKey* find_declared(std::string_view path);

// The groups (for the reader and writer).
const KeyGroup& system_keys();          // [system]
const KeyGroup& species_keys();         // [[system.species]]
const KeyGroup& contact_law_keys();     // [contact], [[contact.pair]], [[boundary.wall]]
const KeyGroup& contact_keys();         // [contact] alone: tc, sleep_speed
const KeyGroup& boundary_keys();        // [boundary]
const KeyGroup& wall_keys();            // [[boundary.wall]] (after face and the contact law)
                                        // and [[boundary.plane]] (after its own keys)
const KeyGroup& container_keys();       // [boundary.container]
const KeyGroup& outlet_keys();          // [boundary.outlet]
const KeyGroup& field_keys();           // [field]
const KeyGroup& driving_keys();         // [driving]
const KeyGroup& run_keys();             // [run]
const KeyGroup& output_keys();          // [output]
const KeyGroup& potential_keys();       // [[potential]] and [[bond]], after species / type and kind
const KeyGroup& spring_dashpot_keys();  // [[potential]] with kind = "spring_dashpot"
const KeyGroup& soft_law_keys();        // [soft] and [[soft.pair]]
const KeyGroup& soft_keys();            // [soft] alone
const KeyGroup& analysis_keys();        // [analysis]
const KeyGroup& compress_keys();        // [compress]

// How docs/config.md writes a key's type, default and range ("float", "`1.0`", "in [0, 1]").
std::string type_text(const KeyDecl& decl);
std::string default_text(const DeclaredKey& key);
std::string range_text(const KeyDecl& decl);  // "" when the key has no range
// A number as the docs write it: 1e-9 -> "10⁻⁹", -1 -> "−1", 100000 -> "100 000".
std::string doc_number(double value);

// The markdown table of every key (`kairos config-keys --markdown`), or one line per key.
std::string keys_markdown();
std::string keys_text();

}  // namespace kairos
