#include "run/compression.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>

#include <fmt/format.h>

#include "analysis/structure.hpp"
#include "analysis/thermodynamics.hpp"
#include "core/error.hpp"
#include "core/periodic.hpp"
#include "core/setup_progress.hpp"
#include "core/stop_flag.hpp"
#include "engine/event_engine.hpp"
#include "scheduler/calendar_queue.hpp"

namespace kairos {

namespace {

// The state at its present time as a fresh start: positions (wrapped) and velocities at time
// 0, no scheduler state, no counters.
template <int D>
void make_fresh_start(ParticleSystem<D>& state) {
  for (std::size_t i = 0; i < state.size(); ++i) {
    Kinematics<D>& k = state.kinematics[i];
    Vec<D> x = state.position(i, state.time);
    for (int a = 0; a < D; ++a) x[a] = wrap_into_box(x[a], state.box[a]);
    k.pos = x;
    k.vel = state.velocity(i, state.time);
    k.time = 0.0;
  }
  state.time = 0.0;
  state.events.clear();
  state.cell.clear();
  state.order.clear();
  state.collision_count.clear();
  state.counters = EventCounters{};
}

// Whether some axis lies between walls.
template <int D>
bool has_walls(const Environment<D>& environment) {
  for (int a = 0; a < D; ++a)
    if (!environment.periodic(a)) return true;
  return false;
}

template <int D>
Thermodynamics thermodynamics_of(const ParticleSystem<D>& state) {
  double volume = 1.0;
  for (int a = 0; a < D; ++a) volume *= state.box[a];
  return Thermodynamics(D, state.size(), volume);
}

// kT of the state by the run's one definition (analysis/thermodynamics; D (N - 1) degrees of
// freedom between walls too, as the run counts them), so that the run starts at the
// temperature the compression left.
template <int D>
double temperature_of(const ParticleSystem<D>& state) {
  double kinetic = 0.0;
  for (std::size_t i = 0; i < state.size(); ++i)
    kinetic += 0.5 * state.mass[i] * norm2(state.kinematics[i].vel);
  return thermodynamics_of(state).temperature(kinetic);
}

// What an interval of the compression sums for its pressure: the collisional virial (its
// trace and its diagonal), the impulse each face's wall took, and the collisions.
struct IntervalSums {
  double virial = 0.0;
  std::array<double, 3> virial_axis{};
  std::array<double, 6> wall_impulse{};
  double time = 0.0;
  std::uint64_t collisions = 0;

  template <int D>
  static IntervalSums of(const EventCounters& c, double time) {
    IntervalSums s;
    s.virial = c.virial;
    for (int a = 0; a < D; ++a) s.virial_axis[a] = c.virial_tensor[a * D + a];
    s.wall_impulse = c.face_wall_impulse;
    s.time = time;
    s.collisions = c.collisions;
    return s;
  }
  // Adds what happened between `mark` and `now`.
  void add(const IntervalSums& now, const IntervalSums& mark) {
    virial += now.virial - mark.virial;
    for (std::size_t a = 0; a < 3; ++a) virial_axis[a] += now.virial_axis[a] - mark.virial_axis[a];
    for (std::size_t f = 0; f < 6; ++f)
      wall_impulse[f] += now.wall_impulse[f] - mark.wall_impulse[f];
    time += now.time - mark.time;
    collisions += now.collisions - mark.collisions;
  }
};

// The reduced pressure Z = P V / (N kT) over an interval. In a periodic box, from the virial.
// With walls, the mean of the pressure tensor's diagonal: Z_aa = 1 + W_aa / (N kT dt) along a
// periodic axis; along an axis between walls the pressure on them, Z_aa = (J_low + J_high) L_a /
// (2 N kT dt) (the virial alone misses the walls' part; docs/physics.md#growing-spheres).
template <int D>
double reduced_pressure(const IntervalSums& s, const Environment<D>& environment, const Vec<D>& box,
                        const Thermodynamics& thermo, double n, double kT) {
  if (!has_walls(environment)) return thermo.compressibility(s.virial, kT, s.time);
  if (!(s.time > 0.0) || !(kT > 0.0)) return std::nan("");
  double sum = 0.0;
  for (int a = 0; a < D; ++a) {
    sum += environment.periodic(a) ? 1.0 + s.virial_axis[a] / (n * kT * s.time)
                                   : (s.wall_impulse[2 * a] + s.wall_impulse[2 * a + 1]) * box[a] /
                                         (2.0 * n * kT * s.time);
  }
  return sum / D;
}

void check_settings(const CompressionSettings& s) {
  const auto positive = [](double v) { return v > 0.0 && std::isfinite(v); };
  if (!positive(s.growth_rate)) throw InputError("compress.growth_rate must be positive");
  if (!positive(s.temperature)) throw InputError("compress: the temperature must be positive");
  if (!positive(s.thermostat_interval))
    throw InputError("compress.thermostat_interval must be positive");
  if (!(s.jammed_pressure > 1.0)) throw InputError("compress.jammed_pressure must exceed 1");
  if (!(s.target_packing_fraction >= 0.0 && s.target_packing_fraction < 1.0))
    throw InputError("compress.packing_fraction must lie in [0, 1)");
  if (!(s.target_pressure >= 0.0) || !std::isfinite(s.target_pressure))
    throw InputError("compress.pressure must be 0 (none) or positive");
  if (!(s.cell_margin > 0.0)) throw std::logic_error("compress: cell_margin must be positive");
}

// The engine refuses what growth cannot meet (EventEngine::check_growth_boundaries: open faces,
// moving or inelastic walls, planes, curved ones); here what the protocol needs besides.
template <int D>
void check_state(const ParticleSystem<D>& state, const Environment<D>& environment) {
  for (int a = 0; a < D; ++a) {
    if (state.gravity[a] != 0.0 || environment.gravity[a] != 0.0)
      throw InputError("compression cannot run under gravity");
    // A generated start is periodic until the engine says otherwise; a state exported from a
    // run with walls or open faces must keep them.
    if (!state.periodic[a] && environment.periodic(a)) {
      throw InputError(
          fmt::format("compression: axis {} of the state is bounded (walls or open faces) but the "
                      "compression's faces along it are periodic",
                      "xyz"[a]));
    }
  }
  if (!state.bonds.empty()) throw InputError("compression cannot grow bonded particles");
}

}  // namespace

template <int D>
double state_packing_fraction(const ParticleSystem<D>& state) {
  double volume = 0.0;
  for (const Kinematics<D>& k : state.kinematics) volume += ball_volume<D>(k.radius);
  double box = 1.0;
  for (int a = 0; a < D; ++a) box *= state.box[a];
  return volume / box;
}

template <int D>
CompressionResult compress(ParticleSystem<D>& state, const CompressionSettings& settings,
                           const std::function<void(const CompressionRow&)>& row,
                           const Environment<D>& environment) {
  check_settings(settings);
  check_state(state, environment);
  CompressionResult out;
  const auto n = static_cast<double>(state.size());
  out.initial_packing_fraction = state_packing_fraction(state);
  if (settings.target_packing_fraction > 0.0 &&
      !(settings.target_packing_fraction > out.initial_packing_fraction)) {
    throw InputError(fmt::format(
        "compress.packing_fraction = {} is not above the start's packing fraction {:.6g}",
        settings.target_packing_fraction, out.initial_packing_fraction));
  }
  make_fresh_start(state);
  const Thermodynamics thermo = thermodynamics_of(state);  // the box never changes
  const double kT = settings.temperature;
  double mean_mass = 0.0;
  for (const double m : state.mass) mean_mass += m / n;
  {
    const double t0 = temperature_of(state);
    if (!(t0 > 0.0)) throw InputError("compression needs moving particles (the start is at rest)");
    const double f = std::sqrt(kT / t0);
    for (Kinematics<D>& k : state.kinematics) k.vel = f * k.vel;
  }
  const auto per_interval =
      static_cast<std::uint64_t>(std::max(1.0, std::round(settings.thermostat_interval * n / 2.0)));

  // The interval in progress (it may span a rebuild): its virial, wall impulses, time and
  // collisions.
  IntervalSums interval;
  double diameter_scale = 1.0;         // sigma(now) / sigma(0)
  double rate = settings.growth_rate;  // now: d sigma / dt over sigma(0)
  bool done = false;
  while (!done) {
    make_fresh_start(state);  // each engine starts at time 0 with its counters at zero
    double rmax = 0.0;
    double mean_diameter = 0.0;
    for (const Kinematics<D>& k : state.kinematics) {
      rmax = std::max(rmax, k.radius);
      mean_diameter += 2.0 * k.radius / n;
    }
    const double phi_start = state_packing_fraction(state);
    EngineOptions options;
    options.size_levels = settings.size_levels;
    // The starting diameters grow at a constant speed: relative to this engine's radii, slower.
    options.growth_rate = rate / diameter_scale;
    // Room to grow, but never less than 3 cells per axis (the cell list's minimum).
    double shortest = state.box[0];
    for (int a = 1; a < D; ++a) shortest = std::min(shortest, state.box[a]);
    const double room = std::min(settings.cell_margin, shortest / (6.0 * rmax) - 1.0);
    if (!(room > 1e-6)) {
      throw InputError(fmt::format(
          "compression: at packing fraction {:.6g} the box edge {:.6g} holds fewer than 3 of the "
          "grown diameter {:.6g} (the cell list needs 3 cells per axis): use more particles",
          state_packing_fraction(state), shortest, 2.0 * rmax));
    }
    options.min_cell_width = 2.0 * rmax * (1.0 + room);
    EventEngine<D, CalendarQueue> engine(std::move(state), StartMode::kPredict, options,
                                         environment);
    // The scale of this engine's radii at the target packing fraction.
    const double target_scale =
        settings.target_packing_fraction > 0.0
            ? std::pow(settings.target_packing_fraction / phi_start, 1.0 / D)
            : kNever;
    double target = kNever, limit = kNever;
    const auto update_limits = [&] {
      const Growth& g = engine.growth();
      target = target_scale < kNever ? g.origin() + (target_scale - g.scale(g.origin())) / g.rate()
                                     : kNever;
      // Never before now (a rate changed at the old limit may round it below).
      limit = std::max(engine.time(), std::min(engine.growth_fits_until(), target));
    };
    update_limits();
    IntervalSums mark;  // the counters where the interval's part in this engine began
    const auto phi_now = [&] {
      const double s = engine.growth().scale(engine.time());
      return phi_start * (D == 3 ? s * s * s : s * s);
    };
    while (true) {
      if (engine.next_event_time() > limit) {
        engine.advance_clock(limit);
        if (limit == target) {
          done = true;
          out.stop_reason = "packing_fraction";
        }
        break;
      }
      engine.step();
      const EventCounters& c = engine.counters();
      if (interval.collisions + (c.collisions - mark.collisions) < per_interval) continue;
      // An interval ends: its pressure, then the rescaling.
      const IntervalSums now = IntervalSums::of<D>(c, engine.time());
      interval.add(now, mark);
      const double kT_end = thermo.temperature(engine.kinetic_energy());
      const double kT_mean = 0.5 * (kT + kT_end);
      CompressionRow r;
      r.time = out.time + engine.time();
      r.packing_fraction = phi_now();
      if (!(interval.time > 0.0)) {
        throw InputError(fmt::format(
            "compression: {} collisions at one instant at packing fraction {:.9f}: the clock "
            "stopped (gaps below what double precision resolves); lower compress.jammed_pressure "
            "or compress.pressure",
            interval.collisions, phi_now()));
      }
      r.pressure = reduced_pressure<D>(interval, environment, engine.box(), thermo, n, kT_mean);
      r.temperature = kT_end;
      // Near jamming the mean free time falls towards 1e-12: rebuild (the clock starts at 0
      // again) before the clock's resolution comes within 1e-3 of it.
      const double mean_free_time =
          interval.time * n / (2.0 * static_cast<double>(interval.collisions));
      r.collision_rate = mean_diameter * engine.growth().scale(engine.time()) /
                         (mean_free_time * std::sqrt(kT_mean / mean_mass));
      const bool rebase =
          std::nextafter(engine.time(), kNever) - engine.time() > 1e-3 * mean_free_time;
      r.collisions = out.collisions + c.collisions;
      out.rows.push_back(r);
      out.pressure = r.pressure;
      out.collision_rate = r.collision_rate;
      if (row) row(r);
      throw_if_stop_requested();
      // Near jamming, slower growth (see CompressionSettings::slowdown_pressure), set with the
      // rescaling (one prediction of every particle for both).
      double new_rate = 0.0;
      if (settings.slowdown_pressure > 0.0 && r.pressure > settings.slowdown_pressure &&
          std::isfinite(r.pressure)) {
        const double wanted =
            settings.growth_rate *
            std::max(settings.slowdown_floor, std::sqrt(settings.slowdown_pressure / r.pressure));
        if (wanted < 0.8 * rate) {
          rate = wanted;
          new_rate = rate / diameter_scale;
        }
      }
      engine.rescale_velocities(engine.time(), std::sqrt(kT / kT_end), new_rate);
      if (new_rate > 0.0) update_limits();
      ++out.rescalings;
      interval = IntervalSums{};
      mark = now;
      if (r.pressure >= settings.jammed_pressure) {
        done = true;
        out.stop_reason = "jammed";
        break;
      }
      if (settings.jammed_collision_rate > 0.0 &&
          r.collision_rate >= settings.jammed_collision_rate) {
        done = true;
        out.stop_reason = "collision_rate";
        break;
      }
      if (settings.target_pressure > 0.0 && r.pressure >= settings.target_pressure) {
        done = true;
        out.stop_reason = "pressure";
        break;
      }
      if (rebase) break;  // a rebuild: the clock at 0
    }
    const EventCounters& c = engine.counters();
    interval.add(IntervalSums::of<D>(c, engine.time()), mark);
    out.time += engine.time();
    out.collisions += c.collisions;
    diameter_scale *= engine.growth().scale(engine.time());
    state = engine.export_state(/*with_zones=*/false);
    if (!done) ++out.rebuilds;
  }
  const bool jammed = out.stop_reason == "jammed" || out.stop_reason == "collision_rate";
  if (jammed && settings.target_packing_fraction > 0.0 && !settings.jammed_is_a_target) {
    throw InputError(fmt::format(
        "the packing jammed at packing fraction {:.6f} (reduced pressure {:.3g}) before reaching "
        "{}: that is beyond jamming at growth rate {}; ask for less, or grow more slowly "
        "(compress.growth_rate) to pack denser",
        state_packing_fraction(state), out.pressure, settings.target_packing_fraction,
        settings.growth_rate));
  }
  make_fresh_start(state);
  // Lengths back in the starting diameters: the box and the positions shrink by the growth
  // instead (the same packing; the configuration's diameters and potentials keep their
  // meaning).
  const double shrink = 1.0 / diameter_scale;
  for (int a = 0; a < D; ++a) state.box[a] *= shrink;
  for (Kinematics<D>& k : state.kinematics) {
    k.pos = shrink * k.pos;
    k.radius *= shrink;
    for (int a = 0; a < D; ++a) k.pos[a] = wrap_into_box(k.pos[a], state.box[a]);
  }
  out.diameter_scale = diameter_scale;
  const double f = std::sqrt(kT / temperature_of(state));
  for (Kinematics<D>& k : state.kinematics) k.vel = f * k.vel;
  out.packing_fraction = state_packing_fraction(state);
  return out;
}

template <int D>
Environment<D> growth_environment(const Environment<D>& run) {
  Environment<D> grown;
  for (int f = 0; f < 2 * D; ++f) grown.faces[f].kind = run.faces[f].kind;
  return grown;
}

CompressionSettings compression_settings(const CompressConfig& config, double temperature) {
  CompressionSettings s;
  s.growth_rate = config.growth_rate;
  s.temperature = temperature;
  s.thermostat_interval = config.thermostat_interval;
  s.target_packing_fraction = config.packing_fraction;
  s.target_pressure = config.pressure;
  s.jammed_pressure = config.jammed_pressure;
  s.jammed_collision_rate = config.jammed_collision_rate;
  s.slowdown_pressure = config.slowdown_pressure;
  s.slowdown_floor = config.slowdown_floor;
  s.jammed_is_a_target = config.jammed;
  return s;
}

template <int D>
CompressionReport compress_start(ParticleSystem<D>& state, const CompressConfig& config,
                                 double temperature, bool tell, bool size_levels,
                                 const Environment<D>& environment) {
  using Clock = std::chrono::steady_clock;
  CompressionReport report;
  report.settings = compression_settings(config, temperature);
  report.settings.size_levels = size_levels;
  const auto start = Clock::now();
  auto next_note = start + std::chrono::seconds(10);
  report.result = compress(
      state, report.settings,
      [&](const CompressionRow& r) {
        if (setup_listened()) {
          const double target = report.settings.target_packing_fraction;
          report_setup_progress(
              target > 0.0 ? fmt::format("compression to packing fraction {}", target)
                           : std::string("compression"),
              fmt::format("packing fraction {:.6f}, reduced pressure {:.4g}, {} collisions",
                          r.packing_fraction, r.pressure, r.collisions));
        }
        if (!tell || Clock::now() < next_note) return;
        next_note = Clock::now() + std::chrono::seconds(10);
        std::fputs(fmt::format("compressing: packing fraction {:.6f}, reduced pressure {:.4g}, "
                               "{} collisions\n",
                               r.packing_fraction, r.pressure, r.collisions)
                       .c_str(),
                   stderr);
      },
      environment);
  report.wall_seconds = std::chrono::duration<double>(Clock::now() - start).count();
  Configuration<D> c;
  c.box = state.box;
  for (int a = 0; a < D; ++a) c.periodic[a] = environment.periodic(a);
  c.position.reserve(state.size());
  for (std::size_t i = 0; i < state.size(); ++i) {
    c.position.push_back(state.kinematics[i].pos);
    c.species.push_back(state.species[i]);
    c.radius.push_back(state.kinematics[i].radius);
  }
  const double z = report.result.pressure;
  report.has_network = config.contact_gap > 0.0 || z >= 1e6;
  if (report.has_network) {
    const double tolerance =
        config.contact_gap > 0.0 ? config.contact_gap : std::min(1e-3, 1e4 / z);
    // Walls between which the packing grew hold it as its particles do.
    std::array<bool, 2 * D> walls{};
    for (int f = 0; f < 2 * D; ++f) walls[f] = environment.faces[f].kind == FaceKind::kWall;
    report.network = contact_network(c, tolerance, walls);
  }
  const BondOrderValues<D> order = bond_order(c, CompressionReport::kBondCutoff);
  report.order_names = order.names;
  report.order = order.global;
  return report;
}

template double state_packing_fraction<2>(const ParticleSystem<2>&);
template double state_packing_fraction<3>(const ParticleSystem<3>&);
template CompressionResult compress<2>(ParticleSystem<2>&, const CompressionSettings&,
                                       const std::function<void(const CompressionRow&)>&,
                                       const Environment<2>&);
template CompressionResult compress<3>(ParticleSystem<3>&, const CompressionSettings&,
                                       const std::function<void(const CompressionRow&)>&,
                                       const Environment<3>&);
template Environment<2> growth_environment<2>(const Environment<2>&);
template Environment<3> growth_environment<3>(const Environment<3>&);
template CompressionReport compress_start<2>(ParticleSystem<2>&, const CompressConfig&, double,
                                             bool, bool, const Environment<2>&);
template CompressionReport compress_start<3>(ParticleSystem<3>&, const CompressConfig&, double,
                                             bool, bool, const Environment<3>&);

}  // namespace kairos
