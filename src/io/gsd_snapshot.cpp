#include "io/gsd_snapshot.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <sstream>
#include <string>

#include <fmt/format.h>

#include "core/error.hpp"
#include "core/event_code.hpp"
#include "core/memory_budget.hpp"
#include "core/periodic.hpp"
#include "io/atomic_file.hpp"
#include "io/gsd_reading.hpp"

namespace kairos {

namespace {

using gsd_read::check_positions_stored;
using gsd_read::check_rectangular_box;
using gsd_read::read_latest;
using gsd_read::require;
using gsd_read::unpack_type_names;

// 2: one event time per particle, order; 3: granular counters, spins, TC times, sleepers;
// 4: bonds, pair zones, step counters; 5: soft contacts in progress and soft counters (a
// format-4 reader would drop the contacts in progress silently, hence the new number); 6:
// deferred soft contacts (frozen_deferred: a format-5 reader would continue them frozen, not
// bit-identically); 7: kairos/checksum, the CRC-32 of the frame's other chunks (gsd_snapshot.hpp),
// required from 7 on. Versions 3 to 6 are still read: the chunks added since are optional.
constexpr std::uint32_t kRestartFormat = 7;
constexpr std::uint32_t kFirstChecksummedFormat = 7;
constexpr const char* kChecksumChunk = "kairos/checksum";
constexpr std::uint32_t kOldestRestartFormat = 3;

// HOOMD stores type names as an N_types x M int8 array of 0-padded strings.
std::vector<std::int8_t> pack_type_names(const std::vector<std::string>& names, std::uint32_t& m) {
  m = 1;
  for (const auto& n : names)
    m = std::max<std::uint32_t>(m, static_cast<std::uint32_t>(n.size() + 1));
  std::vector<std::int8_t> out(names.size() * m, 0);
  for (std::size_t t = 0; t < names.size(); ++t) {
    for (std::size_t c = 0; c < names[t].size(); ++c)
      out[t * m + c] = static_cast<std::int8_t>(names[t][c]);
  }
  return out;
}

// x as a float32 coordinate in HOOMD's centred box [-L/2, L/2). A coordinate just below L/2
// can round up to L/2 in float32; that point is the periodic image of -L/2. Along a
// non-periodic axis (walls, open faces) the coordinate is shifted, never wrapped.
// The same in float64 (output.trajectory_precision = "double"): the engine's wrapped
// coordinate less L/2, correctly rounded.
template <class T = float>
T hoomd_coordinate(double x, double L, bool periodic = true) {
  if (!periodic) return static_cast<T>(x - 0.5 * L);
  const T half = static_cast<T>(0.5 * L);
  const T c = static_cast<T>(wrap_into_box(x, L) - 0.5 * L);
  return c >= half ? -half : c;
}

// The bonds in HOOMD's schema (bonds/N, types, typeid, group), only when there are bonds or
// bond types (readers default to none).
template <int D>
void write_bonds(gsd::Writer& w, const ParticleSystem<D>& sys) {
  if (sys.bonds.empty() && sys.bond_types.empty()) return;
  const auto nb = static_cast<std::uint32_t>(sys.bonds.size());
  w.write_chunk("bonds/N", 1, 1, &nb);
  if (!sys.bond_types.empty()) {
    std::uint32_t m = 0;
    const auto names = pack_type_names(sys.bond_types, m);
    w.write_chunk("bonds/types", sys.bond_types.size(), m, names.data());
  }
  if (nb == 0) return;
  std::vector<std::uint32_t> type_id(nb), group(2 * std::size_t{nb});
  for (std::size_t b = 0; b < nb; ++b) {
    type_id[b] = sys.bonds[b].type;
    group[2 * b] = sys.bonds[b].i;
    group[2 * b + 1] = sys.bonds[b].j;
  }
  w.write_chunk("bonds/typeid", nb, 1, type_id.data());
  w.write_chunk("bonds/group", nb, 2, group.data());
}

// Chunk `name` of one row of M values of T per particle, written block by block:
// row(block, j, values) gives particle j's row of the block (values start zeroed).
// Only the arrays the chunk needs are read (fields_of).
unsigned fields_of(std::string_view name) {
  using F = StateBlocks<3>;
  if (name == "particles/typeid" || name == "particles/mass" || name == "kairos/mass")
    return F::kIdentity;
  if (name == "log/particles/angular_velocity" || name == "kairos/state/angular_velocity" ||
      name == "kairos/state/last_collision_time")
    return F::kExtras;
  if (name == "kairos/state/collision_count" || name == "kairos/state/event_time" ||
      name == "kairos/state/partner" || name == "kairos/state/partner_count" ||
      name == "kairos/state/cell" || name == "kairos/state/order")
    return F::kScheduler;
  return F::kKinematics;  // positions, velocities, radii, local times, asleep
}

template <class T, int D, class Row>
void write_particle_chunk(gsd::Writer& w, std::string_view name, std::uint32_t M,
                          const StateBlocks<D>& s, Row&& row) {
  w.begin_chunk(name, gsd::type_of<T>(), s.particles, M);
  std::vector<T> values;
  s.for_each(
      [&](const ParticleSystem<D>& part, std::size_t) {
        values.assign(part.size() * M, T{});
        for (std::size_t j = 0; j < part.size(); ++j) row(part, j, &values[j * M]);
        w.append_to_chunk(values.data(), values.size() * sizeof(T));
      },
      fields_of(name));
  w.end_chunk();
}

// Which per-particle arrays the state has (one particle's block tells).
template <int D>
ParticleSystem<D> probe(const StateBlocks<D>& s) {
  return s.block(0, s.particles == 0 ? 0 : 1);
}

// The standard chunks of a frame of `layout`'s fields, floating-point values as T (float or
// double); with_static: the file's first frame (types, typeid, diameter, mass, bonds).
template <class T, int D>
void write_standard_chunks(gsd::Writer& w, const StateBlocks<D>& s, bool with_static,
                           const TrajectoryLayout& layout) {
  const ParticleSystem<D>& sys = s.globals();
  const auto n = static_cast<std::uint32_t>(s.particles);
  const std::uint64_t step = sys.counters.events;
  const std::uint8_t dims = D;
  const T box[6] = {static_cast<T>(sys.box[0]),
                    static_cast<T>(sys.box[1]),
                    D == 3 ? static_cast<T>(sys.box[D - 1]) : T{0},
                    T{0},
                    T{0},
                    T{0}};
  using Part = const ParticleSystem<D>&;
  w.write_chunk("configuration/step", 1, 1, &step);
  w.write_chunk("configuration/dimensions", 1, 1, &dims);
  w.write_chunk("configuration/box", 6, 1, box);
  w.write_chunk("particles/N", 1, 1, &n);
  write_particle_chunk<T>(w, "particles/position", 3, s, [](Part p, std::size_t j, T* out) {
    const Vec<D> x = p.position(j, p.time);
    for (int a = 0; a < D; ++a) out[a] = hoomd_coordinate<T>(x[a], p.box[a], p.periodic[a]);
  });
  if (layout.velocity) {
    write_particle_chunk<T>(w, "particles/velocity", 3, s, [](Part p, std::size_t j, T* out) {
      const Vec<D> v = p.velocity(j, p.time);
      for (int a = 0; a < D; ++a) out[a] = static_cast<T>(v[a]);
    });
  }
  if (layout.image && !probe(s).image.empty()) {
    // HOOMD's image flags for the coordinate written above: unwrapped = position + image *
    // box (the engine's counters for its own coordinate, plus the box the coordinate was
    // wrapped by here). Under Lees-Edwards shear, x also needs image_y * shear_rate L_y t.
    write_particle_chunk<std::int32_t>(
        w, "particles/image", 3, s, [](Part p, std::size_t j, std::int32_t* out) {
          const Vec<D> x = p.position(j, p.time);
          for (int a = 0; a < D; ++a) {
            out[a] = p.image[j][a];
            if (!p.periodic[a]) continue;
            const double c = hoomd_coordinate<T>(x[a], p.box[a]);
            out[a] +=
                static_cast<std::int32_t>(std::lround((x[a] - 0.5 * p.box[a] - c) / p.box[a]));
          }
        });
  }
  if (layout.angular_velocity && !probe(s).angular_velocity.empty()) {
    // Per-particle log data: OVITO and python-gsd read log/particles/* as particle
    // properties. In 2D the spin is the z component.
    write_particle_chunk<T>(w, "log/particles/angular_velocity", 3, s,
                            [](Part p, std::size_t j, T* out) {
                              const auto& om = p.angular_velocity[j];
                              if constexpr (D == 3) {
                                for (int a = 0; a < 3; ++a) out[a] = static_cast<T>(om[a]);
                              } else {
                                out[2] = static_cast<T>(om[0]);
                              }
                            });
  }
  if (with_static) {
    std::uint32_t m = 0;
    const auto names = pack_type_names(sys.species_names, m);
    w.write_chunk("particles/types", sys.species_names.size(), m, names.data());
  }
  if (with_static || layout.typeid_every_frame) {
    write_particle_chunk<std::uint32_t>(
        w, "particles/typeid", 1, s,
        [](Part p, std::size_t j, std::uint32_t* out) { *out = p.species[j]; });
  }
  if (with_static || layout.diameter_every_frame) {
    write_particle_chunk<T>(w, "particles/diameter", 1, s, [](Part p, std::size_t j, T* out) {
      *out = static_cast<T>(2.0 * p.kinematics[j].radius);
    });
  }
  if (with_static || layout.mass_every_frame) {
    write_particle_chunk<T>(w, "particles/mass", 1, s, [](Part p, std::size_t j, T* out) {
      *out = static_cast<T>(p.mass[j]);
    });
  }
  if (with_static) write_bonds(w, sys);
  w.write_chunk("log/time", 1, 1, &sys.time);
  w.write_chunk("log/collisions", 1, 1, &sys.counters.collisions);
  w.write_chunk("log/events", 1, 1, &sys.counters.events);
}

// Every field the state has, in float32 (restart files: HOOMD's view of the state).
template <int D>
void write_standard_chunks(gsd::Writer& w, const StateBlocks<D>& s, bool with_static) {
  write_standard_chunks<float>(w, s, with_static, TrajectoryLayout{});
}

// A restart file of `format` carries kairos/checksum from format 7 on (older ones may not); when
// present it must match the frame's other chunks. A mismatch means the file was changed after
// Kairos wrote it (a flipped bit, a bad copy, an edit): its state cannot be trusted, even when
// every value is plausible.
void verify_checksum(const gsd::Reader& r, std::uint64_t f, std::uint32_t format,
                     const std::string& who) {
  const auto info = r.find(f, kChecksumChunk);
  if (!info) {
    if (format < kFirstChecksummedFormat) return;
    throw InputError(fmt::format(
        "{} is damaged: restart format {} but no {} chunk; use an intact copy of the file", who,
        format, kChecksumChunk));
  }
  const auto stored = r.read<std::uint32_t>(f, kChecksumChunk);
  const std::uint32_t computed = r.frame_checksum(f, kChecksumChunk);
  if (stored.size() == 1 && stored[0] == computed) return;
  throw InputError(fmt::format(
      "{} is damaged: checksum mismatch ({} holds {}, the file's chunks give {:#010x}); it was "
      "changed after Kairos wrote it: use an intact copy (e.g. an earlier restart file)",
      who, kChecksumChunk,
      stored.size() == 1 ? fmt::format("{:#010x}", stored[0])
                         : fmt::format("{} values", stored.size()),
      computed));
}

// A restart file without a checksum (formats 3 to 6) is at least plausible: the float32 copies
// a restart file's standard chunks hold of each particle's mass and diameter (particles/mass,
// particles/diameter, written from the float64 values) must be float(kairos/mass) and
// float(2 kairos/radius). A byte changed in either copy (a flipped bit, an edit) is refused,
// naming the particle; damage elsewhere is not seen (docs/guarantees.md).
void check_float32_copies(const gsd::Reader& r, std::uint64_t f, const std::filesystem::path& path,
                          std::uint32_t format, const std::vector<double>& mass,
                          const std::vector<double>& radius) {
  const std::size_t n = mass.size();
  const auto copy = [&](const char* name) {
    const auto info = r.find(f, name);
    if (!info || info->type != gsd::Type::float32 || info->N != n || info->M != 1)
      return std::vector<float>{};  // not there to compare (HOOMD's defaults apply)
    return r.read<float>(f, name);
  };
  const std::vector<float> m32 = copy("particles/mass"), d32 = copy("particles/diameter");
  for (std::size_t i = 0; i < n; ++i) {
    const bool mass_ok = m32.empty() || static_cast<float>(mass[i]) == m32[i];
    const bool diameter_ok = d32.empty() || static_cast<float>(2.0 * radius[i]) == d32[i];
    if (mass_ok && diameter_ok) continue;
    throw InputError(fmt::format(
        "restart file '{}' is damaged: particle {}: {} is {} but {} holds {} (its float32 copy); "
        "a restart file of format {} has no checksum, and its copies of the state disagree: use "
        "an intact copy (e.g. an earlier restart file)",
        path.string(), i, mass_ok ? "2 x kairos/radius" : "kairos/mass",
        mass_ok ? 2.0 * radius[i] : mass[i], mass_ok ? "particles/diameter" : "particles/mass",
        mass_ok ? d32[i] : m32[i], format));
  }
}

// A restart file is trusted to index arrays (partners, types); reject a damaged one with an
// InputError instead of crashing. Cell indices are left to the engine: their meaning depends on
// the grid it builds.
template <int D>
void validate_restart(const ParticleSystem<D>& s, const std::filesystem::path& path) {
  const auto bad = [&](const std::string& what) {
    return InputError("'" + path.string() + "' is not a valid restart file: " + what);
  };
  const std::size_t n = s.size();
  if (n < 2) throw bad("fewer than 2 particles");
  for (int a = 0; a < D; ++a) {
    if (!(s.box[a] > 0.0) || !std::isfinite(s.box[a]))
      throw bad("box edge is not a positive number");
  }
  if (!std::isfinite(s.time)) throw bad("kairos/time is not finite");
  if (s.species_names.empty()) throw bad("no particle types");
  for (std::size_t i = 0; i < n; ++i) {
    const auto& k = s.kinematics[i];
    const auto& e = s.events[i];
    const std::string who = " of particle " + std::to_string(i);
    for (int a = 0; a < D; ++a) {
      if (!std::isfinite(k.pos[a]) || !std::isfinite(k.vel[a]))
        throw bad("position or velocity" + who + " is not finite");
    }
    if (!std::isfinite(k.time)) throw bad("local time" + who + " is not finite");
    if (!(k.radius > 0.0) || !std::isfinite(k.radius))
      throw bad("radius" + who + " is not positive");
    if (!(s.mass[i] > 0.0) || !std::isfinite(s.mass[i]))
      throw bad("mass" + who + " is not positive");
    if (s.species[i] >= s.species_names.size()) throw bad("typeid" + who + " out of range");
    if (std::isnan(e.time)) throw bad("pending event time" + who + " is NaN");
    // The partner code (core/event_code.hpp): a particle it names must exist.
    if (!EventCode<D>::valid_bits(e.partner, static_cast<std::uint32_t>(n)))
      throw bad("collision partner" + who + " out of range");
  }
  std::vector<char> seen(n, 0);
  for (std::uint32_t k : s.order) {
    if (k >= n || seen[k]) throw bad("kairos/state/order is not a permutation");
    seen[k] = 1;
  }
  if (s.zones) {
    for (const PairZone& z : *s.zones) {
      if (!(z.i < z.j && z.j < n)) {
        throw bad("kairos/state/zones holds the pair (" + std::to_string(z.i) + ", " +
                  std::to_string(z.j) + "), not two particles i < j < " + std::to_string(n));
      }
    }
  }
}

}  // namespace

template <int D>
void append_trajectory_frame(gsd::Writer& writer, const StateBlocks<D>& state,
                             const TrajectoryLayout& layout) {
  const bool first = writer.frame_count() == 0;
  if (layout.double_precision) {
    write_standard_chunks<double>(writer, state, first, layout);
  } else {
    write_standard_chunks<float>(writer, state, first, layout);
  }
  writer.end_frame();
}

template <int D>
void append_trajectory_frame(gsd::Writer& writer, const ParticleSystem<D>& system,
                             const TrajectoryLayout& layout) {
  append_trajectory_frame(writer, StateBlocks<D>::of(system), layout);
}

template <int D>
void write_restart(const std::filesystem::path& path, const ParticleSystem<D>& full_state,
                   const std::mt19937_64& rng, const RestartChunks& more) {
  write_restart(path, StateBlocks<D>::of(full_state), rng, more);
}

template <int D>
void write_restart(const std::filesystem::path& path, const StateBlocks<D>& blocks,
                   const std::mt19937_64& rng, const RestartChunks& more) {
  replace_file_atomically(path, [&](const std::filesystem::path& tmp) {
    auto w = gsd::Writer::create(tmp, "kairos " KAIROS_VERSION);
    w.enable_checksums();
    write_standard_chunks(w, blocks, true);
    const ParticleSystem<D>& s = blocks.globals();
    const ParticleSystem<D> has = probe(blocks);
    const std::uint32_t format = kRestartFormat;
    const std::uint8_t dims = D;
    const std::uint64_t counters[4] = {s.counters.events, s.counters.collisions,
                                       s.counters.cell_crossings, s.counters.stale_events};
    std::ostringstream rng_text;
    rng_text << rng;
    const std::string rs = rng_text.str();
    std::vector<std::int8_t> rng_bytes(rs.begin(), rs.end());
    w.write_chunk("kairos/format", 1, 1, &format);
    w.write_chunk("kairos/dimension", 1, 1, &dims);
    w.write_chunk("kairos/box", D, 1, s.box.data());
    w.write_chunk("kairos/time", 1, 1, &s.time);
    using Part = const ParticleSystem<D>&;
    write_particle_chunk<double>(w, "kairos/position", D, blocks,  // at kairos/time, wrapped
                                 [](Part p, std::size_t j, double* out) {
                                   const Vec<D> x = p.position(j, p.time);
                                   for (int a = 0; a < D; ++a)
                                     out[a] = p.periodic[a] ? wrap_into_box(x[a], p.box[a]) : x[a];
                                 });
    write_particle_chunk<double>(w, "kairos/velocity", D, blocks,
                                 [](Part p, std::size_t j, double* out) {
                                   for (int a = 0; a < D; ++a) out[a] = p.kinematics[j].vel[a];
                                 });
    write_particle_chunk<double>(w, "kairos/mass", 1, blocks,
                                 [](Part p, std::size_t j, double* out) { *out = p.mass[j]; });
    write_particle_chunk<double>(
        w, "kairos/radius", 1, blocks,
        [](Part p, std::size_t j, double* out) { *out = p.kinematics[j].radius; });
    write_particle_chunk<double>(w, "kairos/state/position", D, blocks,  // at each local time
                                 [](Part p, std::size_t j, double* out) {
                                   for (int a = 0; a < D; ++a) out[a] = p.kinematics[j].pos[a];
                                 });
    write_particle_chunk<double>(
        w, "kairos/state/local_time", 1, blocks,
        [](Part p, std::size_t j, double* out) { *out = p.kinematics[j].time; });
    write_particle_chunk<std::uint32_t>(
        w, "kairos/state/collision_count", 1, blocks,
        [](Part p, std::size_t j, std::uint32_t* out) { *out = p.collision_count[j]; });
    write_particle_chunk<double>(
        w, "kairos/state/event_time", 1, blocks,
        [](Part p, std::size_t j, double* out) { *out = p.events[j].time; });
    write_particle_chunk<std::uint32_t>(
        w, "kairos/state/partner", 1, blocks,
        [](Part p, std::size_t j, std::uint32_t* out) { *out = p.events[j].partner; });
    write_particle_chunk<std::uint32_t>(
        w, "kairos/state/partner_count", 1, blocks,
        [](Part p, std::size_t j, std::uint32_t* out) { *out = p.events[j].partner_count; });
    write_particle_chunk<std::uint32_t>(
        w, "kairos/state/cell", 1, blocks,
        [](Part p, std::size_t j, std::uint32_t* out) { *out = p.cell[j]; });
    if (!has.order.empty()) {
      write_particle_chunk<std::uint32_t>(
          w, "kairos/state/order", 1, blocks,
          [](Part p, std::size_t j, std::uint32_t* out) { *out = p.order[j]; });
    }
    w.write_chunk("kairos/state/counters", 4, 1, counters);
    w.write_chunk("kairos/state/virial", 1, 1, &s.counters.virial);
    const std::uint64_t granular[5] = {s.counters.wall_collisions, s.counters.elastic_by_rule,
                                       s.counters.sliding_collisions, s.counters.fell_asleep,
                                       s.counters.driving_kicks};
    const double energies[4] = {s.counters.dissipated_in_collisions, s.counters.dissipated_at_walls,
                                s.counters.work_by_walls, s.counters.work_by_driving};
    w.write_chunk("kairos/state/virial_tensor", 9, 1, s.counters.virial_tensor.data());
    w.write_chunk("kairos/state/granular_counters", 5, 1, granular);
    w.write_chunk("kairos/state/granular_energies", 4, 1, energies);
    if (s.counters.work_by_shear != 0.0)
      w.write_chunk("kairos/state/shear_work", 1, 1, &s.counters.work_by_shear);
    const std::uint64_t steps[2] = {s.counters.step_crossings, s.counters.step_bounces};
    w.write_chunk("kairos/state/step_counters", 2, 1, steps);
    if (s.counters.outlet_passes > 0) {
      const double sums[2] = {s.counters.outlet_mass, s.counters.outlet_energy};
      w.write_chunk("kairos/state/outlet_passes", 1, 1, &s.counters.outlet_passes);
      w.write_chunk("kairos/state/outlet_sums", 2, 1, sums);
    }
    if (s.zones) {
      // The count marks the list as present (also when empty); the pairs follow when any.
      const std::uint64_t nz = s.zones->size();
      w.write_chunk("kairos/state/zone_count", 1, 1, &nz);
      if (nz > 0) {
        std::vector<std::uint32_t> flat(3 * nz);
        for (std::size_t z = 0; z < nz; ++z) {
          const PairZone& pz = (*s.zones)[z];
          flat[3 * z] = pz.i;
          flat[3 * z + 1] = pz.j;
          flat[3 * z + 2] = pz.zone;
        }
        w.write_chunk("kairos/state/zones", nz, 3, flat.data());
      }
    }
    const std::uint64_t soft[4] = {s.counters.soft_contacts, s.counters.soft_overlap_fallbacks,
                                   s.counters.soft_early_releases, s.counters.soft_direct_maps};
    w.write_chunk("kairos/state/soft_counters", 4, 1, soft);
    w.write_chunk("kairos/state/soft_contact_energy", 1, 1, &s.counters.soft_contact_energy);
    if (!s.frozen.empty()) {
      const std::uint64_t nf = s.frozen.size();
      std::vector<std::uint32_t> who(3 * nf);
      std::vector<double> when(nf * (1 + 2 * D));
      for (std::size_t k = 0; k < nf; ++k) {
        const FrozenContact<D>& c = s.frozen[k];
        who[3 * k] = c.i;
        who[3 * k + 1] = c.j;
        who[3 * k + 2] = c.face;
        double* row = &when[k * (1 + 2 * D)];
        row[0] = c.release_time;
        for (int a = 0; a < D; ++a) {
          row[1 + a] = c.velocity_i[a];
          row[1 + D + a] = c.velocity_j[a];
        }
      }
      w.write_chunk("kairos/state/frozen_contacts", nf, 3, who.data());
      w.write_chunk("kairos/state/frozen_release", nf, 1 + 2 * D, when.data());
      bool any_deferred = false;
      for (const FrozenContact<D>& c : s.frozen) any_deferred = any_deferred || c.deferred;
      if (any_deferred) {
        std::vector<double> deferred(nf * (1 + 2 * D), 0.0);
        for (std::size_t k = 0; k < nf; ++k) {
          const FrozenContact<D>& c = s.frozen[k];
          double* row = &deferred[k * (1 + 2 * D)];
          row[0] = c.deferred ? 1.0 : 0.0;
          for (int a = 0; a < D; ++a) {
            row[1 + a] = c.release_position_i[a];
            row[1 + D + a] = c.release_position_j[a];
          }
        }
        w.write_chunk("kairos/state/frozen_deferred", nf, 1 + 2 * D, deferred.data());
      }
    }
    if (!s.wall_motion.empty()) {
      // Walls with mass: face, time, position, speed, version, acceleration, layer.
      constexpr std::uint32_t kColumns = 7;
      const std::uint64_t nw = s.wall_motion.size();
      std::vector<double> rows(kColumns * nw);
      for (std::size_t k = 0; k < nw; ++k) {
        const WallMotion& m = s.wall_motion[k];
        double* row = &rows[kColumns * k];
        row[0] = m.face;
        row[1] = m.time;
        row[2] = m.position;
        row[3] = m.speed;
        row[4] = m.version;
        row[5] = m.accel;
        row[6] = m.layer;
      }
      w.write_chunk("kairos/state/wall_motion", nw, kColumns, rows.data());
      // Walls on a spring: face, mass, stiffness, damping, anchor amplitude, angular frequency,
      // phase, the anchor's work, the dashpot's dissipation.
      std::vector<double> springs;
      for (const WallMotion& m : s.wall_motion) {
        if (!m.sprung()) continue;
        springs.push_back(m.face);
        springs.insert(springs.end(), m.spring.begin(), m.spring.end());
        springs.push_back(m.drive_work);
        springs.push_back(m.dashpot);
      }
      if (!springs.empty()) {
        constexpr std::uint32_t kSpringColumns = 9;
        w.write_chunk("kairos/state/wall_spring", springs.size() / kSpringColumns, kSpringColumns,
                      springs.data());
      }
    }
    if (!has.angular_velocity.empty()) {
      constexpr std::uint32_t kSpin = D == 3 ? 3 : 1;
      write_particle_chunk<double>(w, "kairos/state/angular_velocity", kSpin, blocks,
                                   [](Part p, std::size_t j, double* out) {
                                     for (std::uint32_t a = 0; a < kSpin; ++a)
                                       out[a] = p.angular_velocity[j][a];
                                   });
    }
    if (!has.last_collision_time.empty()) {
      write_particle_chunk<double>(
          w, "kairos/state/last_collision_time", 1, blocks,
          [](Part p, std::size_t j, double* out) { *out = p.last_collision_time[j]; });
    }
    if (!s.dem.empty()) {  // the DEM's own state (DemIntegrator::checkpoint), chunks when any
      const DemResume& d = s.dem;
      w.write_chunk("kairos/dem/scalars", d.scalars.size(), 1, d.scalars.data());
      const auto put = [&](const char* name, const auto& v) {
        if (!v.empty()) w.write_chunk(name, v.size(), 1, v.data());
      };
      put("kairos/dem/particles", d.particles);
      put("kairos/dem/order", d.order);
      put("kairos/dem/list_start", d.list_start);
      put("kairos/dem/list", d.list);
      put("kairos/dem/springs", d.springs);
    }
    if (!has.image.empty()) {  // the engine's counters for kairos/state/position
      write_particle_chunk<std::int32_t>(w, "kairos/state/image", D, blocks,
                                         [](Part p, std::size_t j, std::int32_t* out) {
                                           for (int a = 0; a < D; ++a) out[a] = p.image[j][a];
                                         });
    }
    if (!has.asleep.empty()) {
      write_particle_chunk<std::uint8_t>(
          w, "kairos/state/asleep", 1, blocks,
          [](Part p, std::size_t j, std::uint8_t* out) { *out = p.asleep[j]; });
    }
    w.write_chunk("kairos/state/rng", rng_bytes.size(), 1, rng_bytes.data());
    if (more) more(w);  // the run's bookkeeping (run/run_progress.hpp)
    const std::uint32_t checksum = w.frame_checksum();  // of every chunk above: keep it last
    w.write_chunk(kChecksumChunk, 1, 1, &checksum);
    w.end_frame();
    w.close();
  });
}

void verify_restart_checksum(const gsd::Reader& r, std::uint64_t frame,
                             const std::filesystem::path& path, const std::string& who) {
  if (!r.find(frame, "kairos/format")) return;  // not a Kairos restart file: nothing to verify
  const auto format = require<std::uint32_t>(r, frame, "kairos/format", path, 1);
  verify_checksum(r, frame, format[0], who);
}

int gsd_dimension(const std::filesystem::path& path) {
  const gsd::Reader r(path);
  if (r.frame_count() == 0) throw InputError("'" + path.string() + "' holds no frame");
  const auto d = read_latest<std::uint8_t>(r, r.frame_count() - 1, "configuration/dimensions");
  return d && !d->empty() ? (*d)[0] : 3;
}

template <int D>
ParticleSystem<D> read_restart(const std::filesystem::path& path, std::mt19937_64& rng,
                               RunKind kind, const RestartChunkReader<D>& more) {
  const gsd::Reader r(path);
  const std::uint64_t f = r.frame_count() == 0 ? 0 : r.frame_count() - 1;
  if (r.frame_count() == 0 || !r.find(f, "kairos/format")) {
    throw InputError("'" + path.string() + "' is not a Kairos restart file (no kairos/format)");
  }
  const std::uint32_t format = require<std::uint32_t>(r, f, "kairos/format", path, 1)[0];
  if (format < kOldestRestartFormat || format > kRestartFormat) {
    throw InputError("'" + path.string() + "': restart format version " + std::to_string(format) +
                     ", this Kairos reads versions " + std::to_string(kOldestRestartFormat) +
                     " to " + std::to_string(kRestartFormat) +
                     " (restart files are not portable across other versions)");
  }
  verify_checksum(r, f, format, "restart file '" + path.string() + "'");
  const int dim = require<std::uint8_t>(r, f, "kairos/dimension", path, 1)[0];
  if (dim != D) {
    throw InputError("'" + path.string() + "' holds a " + std::to_string(dim) +
                     "D state but system.dimension = " + std::to_string(D));
  }
  const std::size_t n = require<std::uint32_t>(r, f, "particles/N", path, 1)[0];
  std::string quoted = "'";  // (not "'" + ...: a GCC 12 -Wrestrict false positive)
  quoted += path.string();
  quoted += '\'';
  check_positions_stored(r, f, n, "kairos/state/position", D, quoted);
  check_rectangular_box(r, f, quoted);
  require_memory(estimated_run_bytes(n, D, kind),
                 fmt::format("restart file '{}' ({} particles)", path.string(), n));
  ParticleSystem<D> s;
  const auto box = require<double>(r, f, "kairos/box", path, D);
  for (int a = 0; a < D; ++a) s.box[a] = box[a];
  s.time = require<double>(r, f, "kairos/time", path, 1)[0];
  const auto pos = require<double>(r, f, "kairos/state/position", path, n * D);
  const auto vel = require<double>(r, f, "kairos/velocity", path, n * D);
  const auto local = require<double>(r, f, "kairos/state/local_time", path, n);
  const auto radius = require<double>(r, f, "kairos/radius", path, n);
  s.mass = require<double>(r, f, "kairos/mass", path, n);
  if (format < kFirstChecksummedFormat) check_float32_copies(r, f, path, format, s.mass, radius);
  s.species = require<std::uint32_t>(r, f, "particles/typeid", path, n);
  const auto types = r.find(f, "particles/types");
  if (!types) throw InputError("'" + path.string() + "' has no chunk 'particles/types'");
  s.species_names = unpack_type_names(r.read<std::int8_t>(f, "particles/types"), types->M);
  s.collision_count = require<std::uint32_t>(r, f, "kairos/state/collision_count", path, n);
  s.cell = require<std::uint32_t>(r, f, "kairos/state/cell", path, n);
  const auto tevent = require<double>(r, f, "kairos/state/event_time", path, n);
  const auto partner = require<std::uint32_t>(r, f, "kairos/state/partner", path, n);
  const auto pcount = require<std::uint32_t>(r, f, "kairos/state/partner_count", path, n);
  if (r.find(f, "kairos/state/order"))
    s.order = require<std::uint32_t>(r, f, "kairos/state/order", path, n);
  const auto counters = require<std::uint64_t>(r, f, "kairos/state/counters", path, 4);
  s.counters = {counters[0], counters[1], counters[2], counters[3],
                require<double>(r, f, "kairos/state/virial", path, 1)[0]};
  const auto granular = require<std::uint64_t>(r, f, "kairos/state/granular_counters", path, 5);
  const auto energies = require<double>(r, f, "kairos/state/granular_energies", path, 4);
  s.counters.driving_kicks = granular[4];
  const auto tensor = require<double>(r, f, "kairos/state/virial_tensor", path, 9);
  std::copy(tensor.begin(), tensor.end(), s.counters.virial_tensor.begin());
  s.counters.work_by_driving = energies[3];
  s.counters.wall_collisions = granular[0];
  s.counters.elastic_by_rule = granular[1];
  s.counters.sliding_collisions = granular[2];
  s.counters.fell_asleep = granular[3];
  s.counters.dissipated_in_collisions = energies[0];
  s.counters.dissipated_at_walls = energies[1];
  s.counters.work_by_walls = energies[2];
  if (r.find(f, "kairos/state/shear_work"))
    s.counters.work_by_shear = require<double>(r, f, "kairos/state/shear_work", path, 1)[0];
  if (r.find(f, "kairos/state/step_counters")) {
    const auto steps = require<std::uint64_t>(r, f, "kairos/state/step_counters", path, 2);
    s.counters.step_crossings = steps[0];
    s.counters.step_bounces = steps[1];
  }
  if (r.find(f, "kairos/state/outlet_passes")) {
    s.counters.outlet_passes =
        require<std::uint64_t>(r, f, "kairos/state/outlet_passes", path, 1)[0];
    const auto sums = require<double>(r, f, "kairos/state/outlet_sums", path, 2);
    s.counters.outlet_mass = sums[0];
    s.counters.outlet_energy = sums[1];
  }
  if (r.find(f, "kairos/state/soft_counters")) {
    const auto soft = require<std::uint64_t>(r, f, "kairos/state/soft_counters", path, 4);
    s.counters.soft_contacts = soft[0];
    s.counters.soft_overlap_fallbacks = soft[1];
    s.counters.soft_early_releases = soft[2];
    s.counters.soft_direct_maps = soft[3];
    s.counters.soft_contact_energy =
        require<double>(r, f, "kairos/state/soft_contact_energy", path, 1)[0];
  }
  if (const auto chunk = r.find(f, "kairos/state/frozen_contacts")) {
    const std::size_t nf = chunk->N;
    const auto who = require<std::uint32_t>(r, f, "kairos/state/frozen_contacts", path, 3 * nf);
    const auto when = require<double>(r, f, "kairos/state/frozen_release", path, nf * (1 + 2 * D));
    s.frozen.resize(nf);
    for (std::size_t k = 0; k < nf; ++k) {
      FrozenContact<D>& c = s.frozen[k];
      c.i = who[3 * k];
      c.j = who[3 * k + 1];
      c.face = who[3 * k + 2];
      const double* row = &when[k * (1 + 2 * D)];
      c.release_time = row[0];
      for (int a = 0; a < D; ++a) {
        c.velocity_i[a] = row[1 + a];
        c.velocity_j[a] = row[1 + D + a];
      }
    }
    if (r.find(f, "kairos/state/frozen_deferred")) {
      const auto deferred =
          require<double>(r, f, "kairos/state/frozen_deferred", path, nf * (1 + 2 * D));
      for (std::size_t k = 0; k < nf; ++k) {
        FrozenContact<D>& c = s.frozen[k];
        const double* row = &deferred[k * (1 + 2 * D)];
        c.deferred = row[0] != 0.0;
        for (int a = 0; a < D; ++a) {
          c.release_position_i[a] = row[1 + a];
          c.release_position_j[a] = row[1 + D + a];
        }
      }
    }
  }
  if (const auto chunk = r.find(f, "kairos/state/wall_motion")) {
    constexpr std::size_t kColumns = 7;  // as written above
    const std::size_t nw = chunk->N;
    const auto rows = require<double>(r, f, "kairos/state/wall_motion", path, kColumns * nw);
    for (std::size_t k = 0; k < nw; ++k) {
      const double* row = &rows[kColumns * k];
      const bool whole = [&] {
        for (std::size_t c : {0u, 4u, 6u})
          if (row[c] != std::floor(row[c])) return false;
        return true;
      }();
      if (!whole || !(row[0] >= 0.0 && row[0] < 2 * D) ||
          !(row[4] >= 0.0 && row[4] <= 4294967295.0) || !(row[6] >= -1.0 && row[6] < 65536.0)) {
        throw InputError("'" + path.string() +
                         "' is not a valid restart file: " + "kairos/state/wall_motion row " +
                         std::to_string(k) + " names no face, version or layer");
      }
      s.wall_motion.push_back({static_cast<std::uint32_t>(row[0]), row[1], row[2], row[3],
                               static_cast<std::uint32_t>(row[4]), row[5],
                               static_cast<std::int32_t>(row[6])});
    }
    if (const auto springs = r.find(f, "kairos/state/wall_spring")) {
      constexpr std::size_t kSpringColumns = 9;  // as written above
      const std::size_t ns = springs->N;
      const auto values =
          require<double>(r, f, "kairos/state/wall_spring", path, kSpringColumns * ns);
      for (std::size_t k = 0; k < ns; ++k) {
        const double* row = &values[kSpringColumns * k];
        const auto m = std::find_if(s.wall_motion.begin(), s.wall_motion.end(),
                                    [&](const WallMotion& w) { return w.face == row[0]; });
        const bool valid = m != s.wall_motion.end() && row[1] > 0.0 && row[2] > 0.0;
        if (!valid) {
          throw InputError("'" + path.string() + "' is not a valid restart file: " +
                           "kairos/state/wall_spring row " + std::to_string(k) +
                           " names no wall with mass, or no mass and stiffness");
        }
        std::copy(row + 1, row + 7, m->spring.begin());
        m->drive_work = row[7];
        m->dashpot = row[8];
      }
    }
  }
  if (r.find(f, "kairos/state/zone_count")) {
    const std::uint64_t nz = require<std::uint64_t>(r, f, "kairos/state/zone_count", path, 1)[0];
    s.zones.emplace();
    if (nz > 0) {
      const auto flat = require<std::uint32_t>(r, f, "kairos/state/zones", path, 3 * nz);
      s.zones->resize(nz);
      for (std::size_t z = 0; z < nz; ++z)
        (*s.zones)[z] = {flat[3 * z], flat[3 * z + 1], flat[3 * z + 2]};
    }
  }
  {
    gsd_read::BondData bonds = gsd_read::read_bonds(r, f, path, n, quoted);
    s.bonds = std::move(bonds.bonds);
    s.bond_types = std::move(bonds.types);
  }
  constexpr std::size_t kSpin = D == 3 ? 3 : 1;
  if (r.find(f, "kairos/state/angular_velocity")) {
    const auto w = require<double>(r, f, "kairos/state/angular_velocity", path, n * kSpin);
    s.angular_velocity.resize(n);
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t a = 0; a < kSpin; ++a) s.angular_velocity[i][a] = w[i * kSpin + a];
  }
  if (r.find(f, "kairos/state/last_collision_time"))
    s.last_collision_time = require<double>(r, f, "kairos/state/last_collision_time", path, n);
  if (r.find(f, "kairos/dem/scalars")) {  // checked by the DEM that resumes from it
    s.dem.scalars = r.read<double>(f, "kairos/dem/scalars");
    const auto get = [&](const char* name, auto& v) {
      using T = typename std::decay_t<decltype(v)>::value_type;
      if (r.find(f, name)) v = r.read<T>(f, name);
    };
    get("kairos/dem/particles", s.dem.particles);
    get("kairos/dem/order", s.dem.order);
    get("kairos/dem/list_start", s.dem.list_start);
    get("kairos/dem/list", s.dem.list);
    get("kairos/dem/springs", s.dem.springs);
  }
  if (r.find(f, "kairos/state/asleep"))
    s.asleep = require<std::uint8_t>(r, f, "kairos/state/asleep", path, n);
  if (r.find(f, "kairos/state/image")) {
    const auto image = require<std::int32_t>(r, f, "kairos/state/image", path, n * D);
    s.image.resize(n);
    for (std::size_t i = 0; i < n; ++i)
      for (int a = 0; a < D; ++a) s.image[i][a] = image[i * D + a];
  }
  s.kinematics.resize(n);
  s.events.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    for (int a = 0; a < D; ++a) {
      s.kinematics[i].pos[a] = pos[i * D + a];
      s.kinematics[i].vel[a] = vel[i * D + a];
    }
    s.kinematics[i].time = local[i];
    s.kinematics[i].radius = radius[i];
    s.events[i] = {tevent[i], partner[i], pcount[i]};
  }
  validate_restart(s, path);
  const auto rng_bytes = r.read<std::int8_t>(f, "kairos/state/rng");
  std::istringstream rng_text(std::string(rng_bytes.begin(), rng_bytes.end()));
  rng_text >> rng;
  if (!rng_text) throw InputError("'" + path.string() + "': corrupt RNG state");
  if (more) more(r, f, s);  // the run's bookkeeping (run/run_progress.hpp)
  return s;
}

template void append_trajectory_frame<2>(gsd::Writer&, const ParticleSystem<2>&,
                                         const TrajectoryLayout&);
template void append_trajectory_frame<3>(gsd::Writer&, const ParticleSystem<3>&,
                                         const TrajectoryLayout&);
template void append_trajectory_frame<2>(gsd::Writer&, const StateBlocks<2>&,
                                         const TrajectoryLayout&);
template void append_trajectory_frame<3>(gsd::Writer&, const StateBlocks<3>&,
                                         const TrajectoryLayout&);
template void write_restart<2>(const std::filesystem::path&, const StateBlocks<2>&,
                               const std::mt19937_64&, const RestartChunks&);
template void write_restart<3>(const std::filesystem::path&, const StateBlocks<3>&,
                               const std::mt19937_64&, const RestartChunks&);
template void write_restart<2>(const std::filesystem::path&, const ParticleSystem<2>&,
                               const std::mt19937_64&, const RestartChunks&);
template void write_restart<3>(const std::filesystem::path&, const ParticleSystem<3>&,
                               const std::mt19937_64&, const RestartChunks&);
template ParticleSystem<2> read_restart<2>(const std::filesystem::path&, std::mt19937_64&, RunKind,
                                           const RestartChunkReader<2>&);
template ParticleSystem<3> read_restart<3>(const std::filesystem::path&, std::mt19937_64&, RunKind,
                                           const RestartChunkReader<3>&);

}  // namespace kairos
