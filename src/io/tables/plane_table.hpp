// [[boundary.plane]]: a plane wall at any position and orientation (boundaries/plane_walls.hpp),
// a strip of one (span_axis) or a plate with a round hole (hole_radius). The table's keys,
// rules, writing, ranges and Environment entry (io/surface_table.hpp).
#pragma once

#include <cstddef>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "io/surface_table.hpp"
#include "io/wall_config.hpp"

namespace kairos {

// A plane wall anywhere ([[boundary.plane]], boundaries/plane_walls.hpp).
struct PlaneConfig {
  std::vector<double> normal;  // D components, into the domain (not normalised)
  std::vector<double> point;   // D components: a point of the plane at t = 0
  WallConfig wall;             // its contact law and motion: the keys of [[boundary.wall]]
                               // but face
  // A strip: the plane only where its points' coordinate along span_axis lies in
  // [span_min, span_max] ("": everywhere; an end left out is unbounded).
  std::string span_axis;
  double span_min = -std::numeric_limits<double>::infinity();
  double span_max = std::numeric_limits<double>::infinity();
  // A circular hole (3D; 0: none) and its centre (empty: `point`), projected onto the plane.
  double hole_radius = 0.0;
  std::vector<double> hole_center;

  bool operator==(const PlaneConfig&) const = default;
};

struct PlaneTable {
  using Config = PlaneConfig;
  static constexpr std::string_view key = "plane";

  static std::vector<PlacedGroup> placement();
  static void read(const TableReading& r, PlaneConfig& plane);
  static std::string toml(const PlaneConfig& plane, std::size_t dimension);
  static void check_ranges(const PlaneConfig& plane, const std::string& prefix,
                           const RangeScales& s);
  template <int D>
  static void add(const PlaneConfig& plane, const std::string& prefix, Environment<D>& env);
  static const ContactConfig& contact_law(const PlaneConfig& plane) { return plane.wall.contact; }
  static std::optional<TableObstacle> motion(const PlaneConfig& plane);
  static std::optional<TableObstacle> normal_motion(const PlaneConfig& plane);
};

}  // namespace kairos
