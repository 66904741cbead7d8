// The registry of the boundary geometries' config tables (io/surface_table.hpp): the one line a
// new geometry adds on the config side. Its order is the order of the tables in the written
// config.toml and in docs/config.md.
#pragma once

#include <cstddef>
#include <tuple>
#include <type_traits>
#include <vector>

#include "io/surface_table.hpp"
#include "io/tables/plane_table.hpp"
#include "io/tables/round_tables.hpp"

namespace kairos {

template <SurfaceTable... Tables>
struct SurfaceTableList {
  // f(Table{}) for each table, in order.
  template <class F>
  static void each(F&& f) {
    (f(Tables{}), ...);
  }
  template <class Table>
  static constexpr std::size_t index() {
    constexpr bool match[] = {std::is_same_v<Table, Tables>...};
    for (std::size_t i = 0; i < sizeof...(Tables); ++i)
      if (match[i]) return i;
    return sizeof...(Tables);
  }
  using Configs = std::tuple<std::vector<typename Tables::Config>...>;
};

using SurfaceTables = SurfaceTableList<PlaneTable, CylinderTable, SphereTable>;

// The entries of every table: config.boundary.surfaces.of<PlaneTable>().
struct SurfaceConfigs {
  SurfaceTables::Configs lists;

  template <class Table>
  std::vector<typename Table::Config>& of() {
    return std::get<SurfaceTables::index<Table>()>(lists);
  }
  template <class Table>
  const std::vector<typename Table::Config>& of() const {
    return std::get<SurfaceTables::index<Table>()>(lists);
  }
  bool empty() const {
    return std::apply([](const auto&... list) { return (list.empty() && ...); }, lists);
  }
  bool operator==(const SurfaceConfigs&) const = default;
};

// f(table, entries) for each table and its entries (const or not, as `surfaces`).
template <class Surfaces, class F>
void for_each_surface_table(Surfaces& surfaces, F&& f) {
  SurfaceTables::each([&](auto table) {
    using Table = decltype(table);
    f(table, surfaces.template of<Table>());
  });
}

}  // namespace kairos
