// [[boundary.cylinder]] and [[boundary.sphere]]: round walls (boundaries/cylinder_walls.hpp),
// inside or outside, rotating about an axis (a drum). Both tables have the same keys; the
// table's keys, rules, writing, ranges and Environment entry (io/surface_table.hpp).
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "io/surface_table.hpp"
#include "io/wall_config.hpp"

namespace kairos {

// A cylinder or sphere wall ([[boundary.cylinder]], [[boundary.sphere]]: the axis is then
// only the rotation's).
struct CylinderConfig {
  std::string axis = "z";      // its axis's direction (2D: "z", the circle in the plane)
  std::vector<double> center;  // D components: a point of the axis
  double radius = 0.0;         // required
  bool inside = true;          // the particles are inside it (a drum), else outside (an obstacle)
  double angular_velocity = 0.0;  // about the axis, right-handed
  ContactConfig contact;          // its contact law: the keys of [contact]

  bool operator==(const CylinderConfig&) const = default;
};

template <bool Sphere>
struct RoundTable {
  using Config = CylinderConfig;
  static constexpr std::string_view key = Sphere ? "sphere" : "cylinder";

  static std::vector<PlacedGroup> placement();
  static void read(const TableReading& r, CylinderConfig& round);
  static std::string toml(const CylinderConfig& round, std::size_t dimension);
  static void check_ranges(const CylinderConfig& round, const std::string& prefix,
                           const RangeScales& s);
  template <int D>
  static void add(const CylinderConfig& round, const std::string& prefix, Environment<D>& env);
  static const ContactConfig& contact_law(const CylinderConfig& round) { return round.contact; }
  static std::optional<TableObstacle> motion(const CylinderConfig& round);
  static std::optional<TableObstacle> normal_motion(const CylinderConfig& round);
};

using CylinderTable = RoundTable<false>;
using SphereTable = RoundTable<true>;

}  // namespace kairos
