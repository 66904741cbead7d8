// Checked reads of a GSD frame, shared by the reader of restart files (io/gsd_snapshot) and that
// of initial states (init/initial_state_file): a chunk that is missing or of the wrong size is an
// InputError naming the file, never a crash or a silent default.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "core/particle_system.hpp"
#include "io/gsd_file.hpp"

namespace kairos::gsd_read {

// Chunk `name` of frame `frame`, else of frame 0 (HOOMD readers take missing chunks from frame
// 0), else nothing.
template <class T>
std::optional<std::vector<T>> read_latest(const gsd::Reader& r, std::uint64_t frame,
                                          std::string_view name) {
  if (r.find(frame, name)) return r.read<T>(frame, name);
  if (r.find(0, name)) return r.read<T>(0, name);
  return std::nullopt;
}

// As read_latest, but the chunk must be there and hold `expected` values.
template <class T>
std::vector<T> require(const gsd::Reader& r, std::uint64_t frame, std::string_view name,
                       const std::filesystem::path& path, std::size_t expected) {
  auto v = read_latest<T>(r, frame, name);
  if (!v) throw InputError("'" + path.string() + "' has no chunk '" + std::string(name) + "'");
  if (v->size() != expected) {
    throw InputError("'" + path.string() + "': chunk '" + std::string(name) + "' holds " +
                     std::to_string(v->size()) + " values, expected " + std::to_string(expected));
  }
  return std::move(*v);
}

// A floating-point chunk of frame `frame` (else of frame 0) as doubles, whether stored as
// float32 or float64 (HOOMD's precision "single" or "double", Kairos's
// output.trajectory_precision); InputError for another type.
inline std::optional<std::vector<double>> read_latest_real(const gsd::Reader& r,
                                                           std::uint64_t frame,
                                                           std::string_view name) {
  const std::uint64_t at = r.find(frame, name) ? frame : 0;
  const auto info = r.find(at, name);
  if (!info) return std::nullopt;
  if (info->type == gsd::Type::float64) return r.read<double>(at, name);
  const std::vector<float> single = r.read<float>(at, name);
  return std::vector<double>(single.begin(), single.end());
}

// As require, for a floating-point chunk of either precision.
inline std::vector<double> require_real(const gsd::Reader& r, std::uint64_t frame,
                                        std::string_view name, const std::filesystem::path& path,
                                        std::size_t expected) {
  auto v = read_latest_real(r, frame, name);
  if (!v) throw InputError("'" + path.string() + "' has no chunk '" + std::string(name) + "'");
  if (v->size() != expected) {
    throw InputError("'" + path.string() + "': chunk '" + std::string(name) + "' holds " +
                     std::to_string(v->size()) + " values, expected " + std::to_string(expected));
  }
  return std::move(*v);
}

// Before anything is allocated for the n particles that particles/N claims, the chunk holding
// their positions (`positions`, n rows of `width` values, in frame f or 0) must hold them: a
// damaged or hand-made file can claim any number, while the stored chunks are bounded by the
// file's size (gsd::Reader). `who` names the file in messages.
void check_positions_stored(const gsd::Reader& r, std::uint64_t f, std::size_t n,
                            std::string_view positions, std::uint64_t width,
                            const std::string& who);

// Kairos simulates rectangular boxes: a HOOMD box with tilt factors (configuration/box entries
// xy, xz, yz) would otherwise be run as the rectangular box of its edges, silently another
// system. `who` names the file in messages.
void check_rectangular_box(const gsd::Reader& r, std::uint64_t f, const std::string& who);

// HOOMD stores type names as an N_types x M int8 array of 0-padded strings.
std::vector<std::string> unpack_type_names(const std::vector<std::int8_t>& raw, std::uint32_t m);

struct BondData {
  std::vector<Bond> bonds;
  std::vector<std::string> types;
};

// The bonds of frame f (or frame 0) in HOOMD's schema. `what` names the file in messages.
// InputError when a chunk has the wrong size, a bond names a particle >= n or the same
// particle twice, or a typeid has no entry in bonds/types.
BondData read_bonds(const gsd::Reader& r, std::uint64_t f, const std::filesystem::path& path,
                    std::size_t n, const std::string& what);

// A per-particle property from the exact float64 chunk (times `scale`) when present, else from
// the HOOMD chunk (float32 or float64), else HOOMD's default of 1.
std::vector<double> per_particle_property(const gsd::Reader& r, std::uint64_t f,
                                          const std::filesystem::path& path, std::size_t n,
                                          std::string_view exact, double scale,
                                          std::string_view hoomd);

}  // namespace kairos::gsd_read
