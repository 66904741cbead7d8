#include "run/start_state.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <string_view>

#include <fmt/format.h>

#include "core/error.hpp"
#include "core/periodic.hpp"
#include "core/stop_flag.hpp"
#include "init/initial_state.hpp"
#include "init/initial_state_file.hpp"
#include "init/insertion_grid.hpp"
#include "io/config_choices.hpp"
#include "io/config_obstacles.hpp"
#include "io/gsd_file.hpp"
#include "model/boundaries.hpp"
#include "run/environment_setup.hpp"

namespace kairos {

namespace fs = std::filesystem;

namespace {

// The axes with a wall or an open face (not periodic) in the config.
template <int D>
std::array<bool, D> periodic_axes(const Config& config) {
  std::array<bool, D> periodic;
  periodic.fill(true);
  const auto bound = [&](const std::string& face) {
    if (face.size() == 2 && face[0] - 'x' < D) periodic[face[0] - 'x'] = false;
  };
  for (const WallConfig& w : config.boundary.walls) bound(w.face);
  for (const std::string& f : config.boundary.open) bound(f);
  return periodic;
}

// The box of a state to check: finite edges > 0.
template <int D>
void check_box(const InitialState<D>& init, const std::string& source) {
  for (int a = 0; a < D; ++a) {
    if (!std::isfinite(init.box[a]) || !(init.box[a] > 0.0)) {
      throw InputError(
          fmt::format("{}: the box edge {} is {}: check system.particles, "
                      "system.packing_fraction and the species diameters",
                      source, a, init.box[a]));
    }
  }
}

// No pair overlaps by more than round-off. `exact`: float64 positions from a Kairos file, whose
// last event may have left a pair in contact to within round-off (relative 1e-12 of the contact
// distance): a contact, not an overlap. `why`: what the message says of overlaps.
template <int D>
void check_no_overlap(const InitialState<D>& init, const std::array<bool, D>& periodic,
                      const std::string& source, bool exact = false,
                      std::string_view why = "hard particles must not overlap") {
  check_box(init, source);
  std::uint32_t i = 0, j = 0;
  const double worst = max_overlap<D>(init.box, periodic, init.position, init.diameter, &i, &j,
                                      /*interruptible=*/true);
  double smallest = std::numeric_limits<double>::infinity();
  for (const double d : init.diameter) smallest = std::min(smallest, d);
  const double round_off = exact ? 1e-12 * smallest : 0.0;
  if (worst > round_off) {
    throw InputError(
        fmt::format("{}: particles {} and {} overlap by {:.6g} ({})", source, i, j, worst, why));
  }
}

// Soft spheres under the DEM may start overlapping (the force law pushes the pairs apart), by
// at most half the smaller radius of each pair: a deeper overlap is no contact the force laws
// are meant for (the spheres would be more inside each other than touching).
template <int D>
void check_soft_overlaps(const InitialState<D>& init, const std::array<bool, D>& periodic,
                         const std::string& source) {
  check_box(init, source);
  std::uint32_t i = 0, j = 0;
  const double worst = max_relative_overlap<D>(init.box, periodic, init.position, init.diameter, &i,
                                               &j, /*interruptible=*/true);
  if (worst > 0.5) {
    const double smaller = 0.5 * std::min(init.diameter[i], init.diameter[j]);
    throw InputError(fmt::format(
        "{}: particles {} and {} overlap by {:.6g}, more than half the smaller radius ({:.6g}): "
        "soft spheres may start overlapping by at most that; separate them further",
        source, i, j, worst * smaller, 0.5 * smaller));
  }
}

// A HOOMD file stores float32 positions. A frame written at a collision (Kairos writes its
// trajectory frames right after one) holds a pair in exact contact, which the rounding to float32
// turns into an overlap of ~1e-7 about half of the time. Overlaps within that round-off are
// removed by expanding the box and all positions uniformly by the smallest factor that clears
// them: every distance grows by that factor, the packing fraction shrinks by ~1e-7 relative, less
// than the file's precision. Larger overlaps are left for check_no_overlap to report.
template <int D>
double expand_away_rounding_overlaps(InitialState<D>& init, const std::array<bool, D>& periodic) {
  double total = 1.0;  // the factor applied, returned
  double edge = 0.0;
  for (int a = 0; a < D; ++a) edge = std::max(edge, init.box[a]);
  double smallest = std::numeric_limits<double>::infinity();
  for (const double d : init.diameter) smallest = std::min(smallest, d);
  const double tolerance =
      std::min(8.0 * std::numeric_limits<float>::epsilon() * edge, 1e-3 * smallest);
  for (int attempt = 0; attempt < 8; ++attempt) {
    const double worst = max_overlap<D>(init.box, periodic, init.position, init.diameter, nullptr,
                                        nullptr, /*interruptible=*/true);
    if (worst == 0.0 || worst > tolerance) return total;
    // Every overlapping pair has r >= sigma - worst with sigma >= smallest.
    const double factor =
        (1.0 + 8.0 * std::numeric_limits<double>::epsilon()) / (1.0 - worst / smallest);
    total *= factor;
    for (int a = 0; a < D; ++a) init.box[a] *= factor;
    for (auto& x : init.position) {
      for (int a = 0; a < D; ++a) {
        x[a] *= factor;
        if (x[a] >= init.box[a]) x[a] -= init.box[a];
        if (x[a] < 0.0) x[a] = 0.0;
      }
    }
  }
  return total;
}

// True when the last frame of a GSD file holds float64 positions: Kairos' own (a restart file)
// or HOOMD's particles/position written in float64 (the schema's float32 is not enforced by
// every writer). Contacts are then exact to round-off of doubles (1e-12 relative), not floats.
bool holds_exact_positions(const fs::path& path) {
  const gsd::Reader r(path);
  if (r.frame_count() == 0) return false;
  const std::uint64_t last = r.frame_count() - 1;
  if (r.find(last, "kairos/position").has_value()) return true;
  const auto position = r.find(last, "particles/position");
  const auto first = r.find(0, "particles/position");  // a frame may inherit frame 0's
  const auto& info = position ? position : first;
  return info.has_value() && info->type == gsd::Type::float64;
}

// When the state comes from a file, the generating keys do not apply; say so if they disagree.
void note_ignored_system_keys(const Config& config, std::size_t n, const std::string& source) {
  if (config.system.size_distribution != "none") {
    std::fputs(fmt::format("kairos: note: {} gives every particle its diameter; "
                           "system.size_distribution and system.polydispersity are not used\n",
                           source)
                   .c_str(),
               stderr);
  }
  if (config.system.particles != 0 && config.system.particles != n) {
    std::fputs(
        fmt::format("kairos: note: {} holds {} particles; system.particles = {} and the other "
                    "generating keys (packing_fraction, lattice, the species' diameter, mass and "
                    "fraction) are not used\n",
                    source, n, config.system.particles)
            .c_str(),
        stderr);
  }
}

// A generated state fills a periodic box. Along an axis with walls (or open faces) the box
// grows by the largest diameter, half on each side, so that no particle touches a wall; then
// system.box_scale stretches the box, leaving empty space at the high end of each axis (or,
// with system.box_place, below the particles too).
template <int D>
void make_room_for_walls(const Config& config, InitialState<D>& init) {
  double dmax = 0.0;
  for (const double d : init.diameter) dmax = std::max(dmax, d);
  const std::array<bool, D> periodic = periodic_axes<D>(config);
  for (int a = 0; a < D; ++a) {
    if (periodic[a]) continue;
    init.box[a] += dmax;
    for (auto& x : init.position) x[a] += 0.5 * dmax;
  }
  for (int a = 0; a < D && a < static_cast<int>(config.system.box_scale.size()); ++a) {
    const double before = init.box[a];
    init.box[a] *= config.system.box_scale[a];
    // system.box_place: the share of the added space that lies below the particles.
    const double below = a < static_cast<int>(config.system.box_place.size())
                             ? config.system.box_place[a] * (init.box[a] - before)
                             : 0.0;
    if (below > 0.0)
      for (auto& x : init.position) x[a] += below;
  }
}

// Velocities drawn from the temperature are peculiar: under Lees-Edwards shear the mean flow
// u_x = shear_rate (y - L_y / 2) is added, so the run starts in the shear flow.
template <int D>
void add_shear_flow(const Config& config, InitialState<D>& init) {
  const double rate = config.boundary.shear_rate;
  if (rate == 0.0) return;
  for (std::size_t i = 0; i < init.position.size(); ++i)
    init.velocity[i][0] += rate * (init.position[i][1] - 0.5 * init.box[1]);
}

// system.fill_inside: every particle that a wall other than the box's faces (a plane, a
// cylinder, a sphere) cuts through, or that lies beyond one, is moved to a random free place
// inside every wall: uniform over the box, accepted where it is at least its radius from every
// surface and apart from every particle already in place (a cell grid as wide as the largest
// diameter finds them). InputError naming the key when some particle finds no such place.
template <int D>
void move_inside_walls(const Config& config, ParticleSystem<D>& s, std::mt19937_64& rng) {
  // Moved one by one, a chain's beads would leave their bonds; moved across the shear's
  // gradient, a particle would keep the flow velocity of its old height.
  if (!s.bonds.empty()) {
    throw InputError(
        "system.fill_inside: cannot move the beads of chains (system.chain_length) inside the "
        "walls one by one: their bonds would break; place the chains with system.box_scale and "
        "system.box_place instead");
  }
  if (config.boundary.shear_rate != 0.0) {
    throw InputError(
        "system.fill_inside: cannot be combined with Lees-Edwards shear (boundary.shear_rate): "
        "a moved particle would keep the flow velocity of its old height");
  }
  const Environment<D> env = make_environment<D>(config, s);
  const Boundaries<D> walls(env, s.box);
  const std::array<bool, D> periodic = periodic_axes<D>(config);
  const auto inside = [&](const Vec<D>& x, double r) {
    for (int k = 0; k < walls.surfaces(); ++k)
      if (walls.is_surface(k) && !(walls.gap(k, x, 0.0) >= r)) return false;
    return true;
  };
  std::vector<double> diameters;
  for (const Kinematics<D>& k : s.kinematics) diameters.push_back(2.0 * k.radius);
  // The particles in place, in random insertion's grid (cells per size class, capped in
  // number); those outside a wall are moved one by one.
  InsertionGrid<D> grid(s.box, diameters);
  std::vector<std::uint32_t> outside;
  for (std::uint32_t i = 0; i < s.kinematics.size(); ++i) {
    const Kinematics<D>& k = s.kinematics[i];
    if (inside(k.pos, k.radius)) {
      grid.insert(i, k.pos);
    } else {
      outside.push_back(i);
    }
  }
  // Apart from every particle in place (the grid's cells around x; the minimum image on
  // periodic axes only).
  const auto free_at = [&](const Vec<D>& x, double r) {
    return !grid.for_each_near(x, 2.0 * r, [&](std::uint32_t j) {
      double d2 = 0.0;
      for (int a = 0; a < D; ++a) {
        double dx = x[a] - s.kinematics[j].pos[a];
        if (periodic[a]) dx = minimum_image(dx, s.box[a]);
        d2 += dx * dx;
      }
      const double contact = r + s.kinematics[j].radius;
      return d2 < contact * contact;
    });
  };
  constexpr long kTries = 1000000;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (std::size_t moved = 0; moved < outside.size(); ++moved) {
    const std::uint32_t i = outside[moved];
    Kinematics<D>& k = s.kinematics[i];
    bool placed = false;
    for (long t = 0; t < kTries && !placed; ++t) {
      if ((t & 0xfff) == 0xfff) throw_if_stop_requested();
      Vec<D> x;
      for (int a = 0; a < D; ++a) x[a] = unit(rng) * s.box[a];
      if (!inside(x, k.radius) || !free_at(x, k.radius)) continue;
      k.pos = x;
      grid.insert(i, x);
      placed = true;
    }
    if (!placed) {
      throw InputError(fmt::format(
          "system.fill_inside: no free place inside the walls for particle {} after {} random "
          "tries ({} of the {} particles the walls cut off were moved inside): there is not "
          "enough room inside them at system.packing_fraction = {}; lower it (or give the "
          "walls more room inside)",
          i, kTries, moved, outside.size(), config.system.packing_fraction));
    }
  }
}

}  // namespace

bool grows_random_start(const Config& config) {
  const SystemConfig& s = config.system;
  const bool grows = s.initial_state.empty() && s.lattice == "random" &&
                     !compression_obstacle(config) &&
                     s.packing_fraction > random_insertion_limit(s.dimension);
  // [compress] with a packing fraction or pressure of its own would silently replace the
  // start's density (inserted at the limit, grown to the other target): refused.
  const CompressConfig& k = config.compress;
  if (grows && (k.packing_fraction > 0.0 || k.pressure > 0.0)) {
    throw InputError(fmt::format(
        "system.packing_fraction = {} is above what random insertion reaches ({}), so the start "
        "would be grown to it, but [compress] has its own target (compress.packing_fraction or "
        "compress.pressure): start at most at {} and let [compress] grow it, or drop [compress]",
        s.packing_fraction, random_insertion_limit(s.dimension),
        random_insertion_limit(s.dimension)));
  }
  return grows;
}

template <int D>
ParticleSystem<D> build_start_state(const Config& config,
                                    const std::optional<fs::path>& restart_file,
                                    std::mt19937_64& rng, RunProgress& progress) {
  // The memory estimate checked before the state is built or read: the DEM's layout is larger.
  const RunKind kind = integrators().is(config.run.integrator, IntegratorKind::kDem)
                           ? RunKind::kDem
                           : RunKind::kEventDriven;
  if (restart_file) {
    if (!fs::exists(*restart_file)) {
      throw InputError("restart file '" + restart_file->string() + "' does not exist");
    }
    return read_restart_file<D>(*restart_file, rng, progress, kind);  // the restart plan: the rest
  }
  if (!config.system.initial_state.empty()) {
    const fs::path path = config.system.initial_state;
    if (!fs::exists(path)) {
      throw InputError("system.initial_state: file '" + path.string() + "' does not exist");
    }
    bool has_velocities = false;
    InitialState<D> init = read_initial_state<D>(path, has_velocities, kind);
    const std::array<bool, D> periodic = periodic_axes<D>(config);
    const bool exact = holds_exact_positions(path);
    const std::string source = "system.initial_state '" + path.string() + "'";
    if (!exact) {
      const double factor = expand_away_rounding_overlaps<D>(init, periodic);
      if (factor != 1.0) {
        std::fputs(fmt::format("kairos: note: {}: the box and the positions were scaled by 1 + "
                               "{:.3g} to clear overlaps within its float32 round-off\n",
                               source, factor - 1.0)
                       .c_str(),
                   stderr);
      }
    }
    if (config.soft.enabled() && kind == RunKind::kDem) {
      check_soft_overlaps<D>(init, periodic, source);
    } else if (config.soft.enabled()) {
      // The event integrator maps a soft contact from its first touch (Müller and Pöschel, Phys.
      // Rev. E 87, 033301 (2013)): a pair that starts inside one has no first touch, and would
      // collide instantaneously (its overlap's elastic energy lost), not as the force law says.
      check_no_overlap<D>(init, periodic, source, exact,
                          "the event integrator maps soft contacts from their first touch and "
                          "cannot start inside one: use run.integrator = \"dem\", which accepts "
                          "overlaps of up to half the smaller radius, or a state without overlaps");
    } else {
      check_no_overlap<D>(init, periodic, source, exact);
    }
    note_ignored_system_keys(config, init.position.size(), "system.initial_state");
    if (config.system.fill_inside) {
      std::fputs(
          "kairos: note: system.fill_inside applies to generated states only; "
          "system.initial_state's particles are used where the file has them\n",
          stderr);
    }
    if (!has_velocities) {
      assign_maxwell_boltzmann_velocities(init, config.system.temperature, rng);
      std::vector<bool> fixed;
      for (const std::string& name : init.species_names) {
        bool f = false;
        for (const SpeciesConfig& sc : config.system.species)
          f = f || (sc.name == name && sc.fixed);
        fixed.push_back(f);
      }
      rest_fixed_grains(init, fixed, config.system.temperature);
      add_shear_flow(config, init);
    }
    return to_particle_system<D>(std::move(init));
  }
  // Denser than random insertion reaches: inserted at its limit, grown by start_run.
  SystemConfig system = config.system;
  if (grows_random_start(config)) system.packing_fraction = random_insertion_limit(D);
  InitialState<D> init = make_initial_state<D>(system, rng, kind);
  std::array<bool, D> periodic;
  periodic.fill(true);  // generated in a periodic box; make_room_for_walls then adds the gaps
  // A lattice at its close packing has its neighbours in contact to within round-off.
  check_no_overlap<D>(init, periodic, "generated initial state", /*exact=*/true);
  make_room_for_walls(config, init);
  add_shear_flow(config, init);
  ParticleSystem<D> state = to_particle_system<D>(std::move(init));
  if (config.system.fill_inside) move_inside_walls(config, state, rng);
  return state;
}

template ParticleSystem<2> build_start_state<2>(const Config&, const std::optional<fs::path>&,
                                                std::mt19937_64&, RunProgress&);
template ParticleSystem<3> build_start_state<3>(const Config&, const std::optional<fs::path>&,
                                                std::mt19937_64&, RunProgress&);

}  // namespace kairos
