// What a boundary geometry's config table gives the config layer: the keys of one array of
// tables ([[boundary.plane]], [[boundary.cylinder]], ...) declared, read, written, checked and
// turned into the Environment in one file pair, io/tables/<geometry>_table.{hpp,cpp}, listed
// once in io/surface_tables.hpp. The reader, the writer, the range checks, the Environment's
// set-up, the obstacles of analyses and protocols, and the restart plan loop over that list
// and never name a geometry (docs/extending.md, "Adding a boundary geometry").
//
// A table is a struct with static members (checked by the concept SurfaceTable below):
//   using Config = ...;                          its keys' struct (defaults = the initialisers)
//   static constexpr std::string_view key;       "plane": the table is [[boundary.plane]]
//   static std::vector<PlacedGroup> placement(); its key groups, in the order of the docs
//   static void read(const TableReading&, Config&);   the groups read, then the rules between keys
//   static std::string toml(const Config&, std::size_t dimension);  the written table's body
//   static void check_ranges(const Config&, const std::string& prefix, const RangeScales&);
//   template <int D> static void add(const Config&, const std::string& prefix, Environment<D>&);
//   static const ContactConfig& contact_law(const Config&);
//   static std::optional<TableObstacle> motion(const Config&);  what moves it, if anything
//   static std::optional<TableObstacle> normal_motion(const Config&);  what moves it along its
//                                                 normal (fixed grains would not see it come)
// `prefix` is the entry's path in messages ("boundary.plane[2]").
#pragma once

#include <concepts>
#include <cstddef>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "io/config_keys.hpp"
#include "io/wall_config.hpp"

namespace kairos {

struct RangeScales;
template <int D>
struct Environment;

// A key group as a table places it (io/config_keys.cpp): `shared_from` names the table it is
// documented in; `last` puts its keys after every other in the suggestions.
struct PlacedGroup {
  const KeyGroup* group;
  std::string_view shared_from = {};
  bool last = false;
};

// The reader's services for one entry of a table (io/config.cpp implements them): errors
// located at a key's node in the file (or at the --set that made it), the typed reading of a
// declared group, and the checks every table needs.
class TableReading {
 public:
  virtual ~TableReading() = default;
  virtual const std::string& prefix() const = 0;  // "boundary.plane[2]"
  virtual int dimension() const = 0;
  virtual bool has(std::string_view key) const = 0;
  // An error at the node of `key` ("" or absent: the entry's table) for the path
  // prefix.key: "file:line:column: message".
  [[noreturn]] virtual void fail(std::string_view key, const std::string& message) const = 0;
  // The keys of `group` present in the entry read into `object` (the group's struct): types,
  // dimensionless ranges and choices checked (io/config_key_reader.hpp).
  virtual void read_group(const KeyGroup& group, void* object) const = 0;
  // The contact-law keys (those of [contact]) into `contact`, which starts as [contact]'s law,
  // with their rules (a table of e(v) only with restitution_model = "table", ...).
  virtual void read_contact(ContactConfig& contact) const = 0;
  // Vectors the entry must have: an error naming the first one missing.
  virtual void require_vectors(std::initializer_list<const char*> keys) const = 0;
  // A direction that must not be zero; `meaning` says which way it points.
  virtual void require_nonzero(const char* key, const std::vector<double>& v,
                               std::string_view meaning) const = 0;
};

// What keeps an entry from being still (a sliding, vibrating or rotating surface), or what
// moves it along its normal: the key that does it, after the entry's prefix ("" for the entry
// itself, ".angular_velocity"), and why that refuses a protocol.
struct TableObstacle {
  std::string key;
  std::string why;
};

template <class T>
concept SurfaceTable = requires(const typename T::Config& c, typename T::Config& m,
                                const TableReading& r, const std::string& prefix,
                                const RangeScales& s, Environment<2>& env2, Environment<3>& env3) {
  { T::key } -> std::convertible_to<std::string_view>;
  { T::placement() } -> std::same_as<std::vector<PlacedGroup>>;
  T::read(r, m);
  { T::toml(c, std::size_t{3}) } -> std::same_as<std::string>;
  T::check_ranges(c, prefix, s);
  T::template add<2>(c, prefix, env2);
  T::template add<3>(c, prefix, env3);
  { T::contact_law(c) } -> std::same_as<const ContactConfig&>;
  { T::motion(c) } -> std::same_as<std::optional<TableObstacle>>;
  { T::normal_motion(c) } -> std::same_as<std::optional<TableObstacle>>;
  requires std::equality_comparable<typename T::Config>;
};

}  // namespace kairos
