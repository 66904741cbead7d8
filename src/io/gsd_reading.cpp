#include "io/gsd_reading.hpp"

#include <fmt/format.h>

namespace kairos::gsd_read {

std::vector<std::string> unpack_type_names(const std::vector<std::int8_t>& raw, std::uint32_t m) {
  std::vector<std::string> names;
  for (std::size_t t = 0; m > 0 && t < raw.size() / m; ++t) {
    std::string s;
    for (std::size_t c = 0; c < m && raw[t * m + c] != 0; ++c)
      s.push_back(static_cast<char>(raw[t * m + c]));
    names.push_back(s);
  }
  return names;
}

void check_positions_stored(const gsd::Reader& r, std::uint64_t f, std::size_t n,
                            std::string_view positions, std::uint64_t width,
                            const std::string& who) {
  const auto info = r.find(f, positions) ? r.find(f, positions) : r.find(0, positions);
  const std::string claim = who + ": particles/N = " + std::to_string(n) + " but ";
  if (!info) throw InputError(claim + "the file has no chunk '" + std::string(positions) + "'");
  if (info->N * info->M != n * width) {
    throw InputError(claim + "chunk '" + std::string(positions) + "' holds " +
                     std::to_string(info->N) + " x " + std::to_string(info->M) + " values, not " +
                     std::to_string(n) + " x " + std::to_string(width) + ": the file is damaged");
  }
}

void check_rectangular_box(const gsd::Reader& r, std::uint64_t f, const std::string& who) {
  const auto box = read_latest_real(r, f, "configuration/box");
  if (!box || box->size() != 6) return;  // (a missing or short box is reported where it is read)
  const double xy = (*box)[3], xz = (*box)[4], yz = (*box)[5];
  if (xy == 0.0 && xz == 0.0 && yz == 0.0) return;
  // Shown as stored (a float32 0.1 as 0.1).
  const auto info = r.find(f, "configuration/box") ? r.find(f, "configuration/box")
                                                   : r.find(0, "configuration/box");
  const auto shown = [&](double v) {
    return info->type == gsd::Type::float64 ? fmt::format("{}", v)
                                            : fmt::format("{}", static_cast<float>(v));
  };
  throw InputError(fmt::format(
      "{}: configuration/box has tilt factors xy = {}, xz = {}, yz = {}, a triclinic box; Kairos "
      "simulates rectangular boxes only: give a state in a box with xy = xz = yz = 0",
      who, shown(xy), shown(xz), shown(yz)));
}

// Default name of the one bond type of a file that has bonds but no bonds/types chunk (as
// HOOMD files written without types): that of generated chains.
namespace {
constexpr const char* kDefaultBondType = "backbone";
}  // namespace

BondData read_bonds(const gsd::Reader& r, std::uint64_t f, const std::filesystem::path& path,
                    std::size_t n, const std::string& what) {
  BondData out;
  const auto bad = [&](const std::string& why) { return InputError(what + ": " + why); };
  const std::uint64_t types_frame = r.find(f, "bonds/types") ? f : 0;
  if (const auto info = r.find(types_frame, "bonds/types")) {
    out.types = unpack_type_names(r.read<std::int8_t>(types_frame, "bonds/types"), info->M);
  }
  const auto count = read_latest<std::uint32_t>(r, f, "bonds/N");
  const std::size_t nb = count && !count->empty() ? (*count)[0] : 0;
  if (nb == 0) return out;
  const auto group = require<std::uint32_t>(r, f, "bonds/group", path, 2 * nb);
  std::vector<std::uint32_t> type_id(nb, 0);
  if (r.find(f, "bonds/typeid") || r.find(0, "bonds/typeid"))
    type_id = require<std::uint32_t>(r, f, "bonds/typeid", path, nb);
  if (out.types.empty()) out.types = {kDefaultBondType};
  out.bonds.resize(nb);
  for (std::size_t b = 0; b < nb; ++b) {
    const Bond bond{group[2 * b], group[2 * b + 1], type_id[b]};
    const std::string who = "bond " + std::to_string(b) + " (" + std::to_string(bond.i) + ", " +
                            std::to_string(bond.j) + ")";
    if (bond.i >= n || bond.j >= n) {
      throw bad(who + " names a particle beyond the " + std::to_string(n) +
                " particles (bonds/group)");
    }
    if (bond.i == bond.j) throw bad(who + " bonds a particle to itself (bonds/group)");
    if (bond.type >= out.types.size()) {
      throw bad(who + " has typeid " + std::to_string(bond.type) +
                ", which has no entry in bonds/types");
    }
    out.bonds[b] = bond;
  }
  return out;
}

std::vector<double> per_particle_property(const gsd::Reader& r, std::uint64_t f,
                                          const std::filesystem::path& path, std::size_t n,
                                          std::string_view exact, double scale,
                                          std::string_view hoomd) {
  std::vector<double> out;
  if (auto v = read_latest<double>(r, f, exact); v && v->size() == n) {
    for (double x : *v) out.push_back(scale * x);
  } else if (auto w = read_latest_real(r, f, hoomd)) {
    if (w->size() != n) {
      throw InputError("'" + path.string() + "': " + std::string(hoomd) + " has the wrong size");
    }
    out.assign(w->begin(), w->end());
  } else {
    out.assign(n, 1.0);
  }
  return out;
}

}  // namespace kairos::gsd_read
