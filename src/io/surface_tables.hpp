// The registry of the boundary geometries' config tables (io/surface_table.hpp): the one line a
// new geometry adds on the config side. Its order is the order of the tables in the written
// config.toml and in docs/config.md (after [boundary.outlet]).
#pragma once

#include "core/type_list.hpp"
#include "io/surface_table.hpp"
#include "io/tables/plane_table.hpp"
#include "io/tables/round_tables.hpp"

namespace kairos {

using SurfaceTables = TypeList<PlaneTable, CylinderTable, SphereTable>;

template <class Table>
using TableConfig = typename Table::Config;
// The entries of every table: config.boundary.surfaces.of<PlaneTable>().
using SurfaceConfigs = VectorsOf<SurfaceTables, TableConfig>;

// f(table, entries) for each table (a value of its type) and its entries (const or not, as
// `surfaces`).
template <class Surfaces, class F>
void for_each_surface_table(Surfaces& surfaces, F&& f) {
  SurfaceTables::each([&](auto type) {
    using Table = typename decltype(type)::type;
    static_assert(SurfaceTable<Table>);
    f(Table{}, surfaces.template of<Table>());
  });
}

}  // namespace kairos
