#include "init/initial_state_file.hpp"

#include <cmath>
#include <string>

#include <fmt/format.h>

#include "core/error.hpp"
#include "io/gsd_file.hpp"
#include "io/gsd_reading.hpp"
#include "io/gsd_snapshot.hpp"

namespace kairos {

using gsd_read::check_positions_stored;
using gsd_read::check_rectangular_box;
using gsd_read::per_particle_property;
using gsd_read::read_latest;
using gsd_read::require;
using gsd_read::unpack_type_names;

template <int D>
InitialState<D> read_initial_state(const std::filesystem::path& path, bool& has_velocities,
                                   RunKind kind) {
  const gsd::Reader r(path);
  if (r.frame_count() == 0) throw InputError("'" + path.string() + "' holds no frame");
  const std::uint64_t f = r.frame_count() - 1;
  const std::string who = "system.initial_state '" + path.string() + "'";
  verify_restart_checksum(r, f, path, who);  // a Kairos restart file: damaged?
  const int dim = gsd_dimension(path);
  if (dim != D) {
    throw InputError("system.initial_state '" + path.string() + "' is " + std::to_string(dim) +
                     "D but system.dimension = " + std::to_string(D));
  }
  const auto nv = read_latest<std::uint32_t>(r, f, "particles/N");
  const std::size_t n = nv && !nv->empty() ? (*nv)[0] : 0;
  if (n < 2)
    throw InputError("system.initial_state '" + path.string() + "' holds fewer than 2 particles");
  const bool exact = r.find(f, "kairos/position").has_value();
  check_positions_stored(r, f, n, exact ? "kairos/position" : "particles/position", exact ? D : 3,
                         who);
  check_rectangular_box(r, f, who);
  require_memory(estimated_run_bytes(n, D, kind), fmt::format("{} ({} particles)", who, n));
  InitialState<D> s;
  if (exact) {
    const auto box = require<double>(r, f, "kairos/box", path, D);
    for (int a = 0; a < D; ++a) s.box[a] = box[a];
  } else {
    const auto box = gsd_read::require_real(r, f, "configuration/box", path, 6);
    for (int a = 0; a < D; ++a) s.box[a] = box[a];
  }
  for (int a = 0; a < D; ++a) {
    if (!(s.box[a] > 0.0) || !std::isfinite(s.box[a])) {
      throw InputError("system.initial_state '" + path.string() + "': box edge " +
                       std::to_string(a) + " is not a positive number");
    }
  }
  s.position.resize(n);
  s.velocity.assign(n, Vec<D>{});
  auto check_finite = [&](double v, const char* what, std::size_t i) {
    if (!std::isfinite(v)) {
      throw InputError("system.initial_state '" + path.string() + "': " + what + " of particle " +
                       std::to_string(i) + " is not finite");
    }
  };
  if (exact) {
    const auto pos = require<double>(r, f, "kairos/position", path, n * D);
    for (std::size_t i = 0; i < n; ++i)
      for (int a = 0; a < D; ++a) s.position[i][a] = pos[i * D + a];
  } else {
    const auto pos = gsd_read::require_real(r, f, "particles/position", path, n * 3);
    for (std::size_t i = 0; i < n; ++i)
      for (int a = 0; a < D; ++a) s.position[i][a] = pos[i * 3 + a] + 0.5 * s.box[a];
  }
  for (std::size_t i = 0; i < n; ++i) {
    for (int a = 0; a < D; ++a) {
      check_finite(s.position[i][a], "position", i);
      double& x = s.position[i][a];
      x -= s.box[a] * std::floor(x / s.box[a]);
      if (x >= s.box[a]) x = 0.0;
    }
  }
  has_velocities = false;
  if (r.find(f, "kairos/velocity")) {
    const auto vel = require<double>(r, f, "kairos/velocity", path, n * D);
    for (std::size_t i = 0; i < n; ++i)
      for (int a = 0; a < D; ++a) s.velocity[i][a] = vel[i * D + a];
    has_velocities = true;
  } else if (auto vel = gsd_read::read_latest_real(r, f, "particles/velocity")) {
    if (vel->size() != n * 3)
      throw InputError("'" + path.string() + "': particles/velocity has the wrong size");
    for (std::size_t i = 0; i < n; ++i)
      for (int a = 0; a < D; ++a) s.velocity[i][a] = (*vel)[i * 3 + a];
    has_velocities = true;
  }
  for (std::size_t i = 0; i < n; ++i)
    for (int a = 0; a < D; ++a) check_finite(s.velocity[i][a], "velocity", i);
  s.diameter = per_particle_property(r, f, path, n, "kairos/radius", 2.0, "particles/diameter");
  s.mass = per_particle_property(r, f, path, n, "kairos/mass", 1.0, "particles/mass");
  for (std::size_t i = 0; i < n; ++i) {
    if (!(s.diameter[i] > 0.0) || !std::isfinite(s.diameter[i]))
      throw InputError("system.initial_state '" + path.string() + "': diameter of particle " +
                       std::to_string(i) + " is not a positive number");
    if (!(s.mass[i] > 0.0) || !std::isfinite(s.mass[i]))
      throw InputError("system.initial_state '" + path.string() + "': mass of particle " +
                       std::to_string(i) + " is not a positive number");
  }
  if (r.find(f, "particles/typeid") || r.find(0, "particles/typeid")) {
    s.species = require<std::uint32_t>(r, f, "particles/typeid", path, n);
  } else {
    s.species.assign(n, 0);
  }
  if (auto info = r.find(f, "particles/types") ? r.find(f, "particles/types")
                                               : r.find(0, "particles/types")) {
    const std::uint64_t frame = r.find(f, "particles/types") ? f : 0;
    s.species_names = unpack_type_names(r.read<std::int8_t>(frame, "particles/types"), info->M);
  }
  if (s.species_names.empty()) s.species_names = {"A"};
  for (std::size_t i = 0; i < n; ++i) {
    if (s.species[i] >= s.species_names.size())
      throw InputError("system.initial_state '" + path.string() + "': typeid of particle " +
                       std::to_string(i) + " has no entry in particles/types");
  }
  gsd_read::BondData bonds =
      gsd_read::read_bonds(r, f, path, n, "system.initial_state '" + path.string() + "'");
  s.bonds = std::move(bonds.bonds);
  s.bond_types = std::move(bonds.types);
  return s;
}

template InitialState<2> read_initial_state<2>(const std::filesystem::path&, bool&, RunKind);
template InitialState<3> read_initial_state<3>(const std::filesystem::path&, bool&, RunKind);

}  // namespace kairos
