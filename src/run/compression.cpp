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

template <int D>
Thermodynamics thermodynamics_of(const ParticleSystem<D>& state) {
  double volume = 1.0;
  for (int a = 0; a < D; ++a) volume *= state.box[a];
  return Thermodynamics(D, state.size(), volume);
}

// kT of the state by the run's one definition (analysis/thermodynamics).
template <int D>
double temperature_of(const ParticleSystem<D>& state) {
  double kinetic = 0.0;
  for (std::size_t i = 0; i < state.size(); ++i)
    kinetic += 0.5 * state.mass[i] * norm2(state.kinematics[i].vel);
  return thermodynamics_of(state).temperature(kinetic);
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

template <int D>
void check_state(const ParticleSystem<D>& state) {
  for (int a = 0; a < D; ++a) {
    if (!state.periodic[a])
      throw InputError("compression needs a periodic box: every face must be periodic");
    if (state.gravity[a] != 0.0) throw InputError("compression cannot run under gravity");
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
                           const std::function<void(const CompressionRow&)>& row) {
  check_settings(settings);
  check_state(state);
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
  {
    const double t0 = temperature_of(state);
    if (!(t0 > 0.0)) throw InputError("compression needs moving particles (the start is at rest)");
    const double f = std::sqrt(kT / t0);
    for (Kinematics<D>& k : state.kinematics) k.vel = f * k.vel;
  }
  const auto per_interval =
      static_cast<std::uint64_t>(std::max(1.0, std::round(settings.thermostat_interval * n / 2.0)));

  // The interval in progress (it may span a rebuild): its virial, time and collisions, and kT
  // at its start.
  double interval_virial = 0.0, interval_time = 0.0;
  std::uint64_t interval_collisions = 0;
  double diameter_scale = 1.0;         // sigma(now) / sigma(0)
  double rate = settings.growth_rate;  // now: d sigma / dt over sigma(0)
  bool done = false;
  while (!done) {
    make_fresh_start(state);  // each engine starts at time 0 with its counters at zero
    double rmax = 0.0;
    for (const Kinematics<D>& k : state.kinematics) rmax = std::max(rmax, k.radius);
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
    EventEngine<D, CalendarQueue> engine(std::move(state), StartMode::kPredict, options);
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
    double virial_mark = 0.0, time_mark = 0.0;
    std::uint64_t collision_mark = 0;
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
      if (interval_collisions + (c.collisions - collision_mark) < per_interval) continue;
      // An interval ends: its pressure, then the rescaling.
      interval_virial += c.virial - virial_mark;
      interval_time += engine.time() - time_mark;
      interval_collisions += c.collisions - collision_mark;
      const double kT_end = thermo.temperature(engine.kinetic_energy());
      const double kT_mean = 0.5 * (kT + kT_end);
      CompressionRow r;
      r.time = out.time + engine.time();
      r.packing_fraction = phi_now();
      if (!(interval_time > 0.0)) {
        throw InputError(fmt::format(
            "compression: {} collisions at one instant at packing fraction {:.9f}: the clock "
            "stopped (gaps below what double precision resolves); lower compress.jammed_pressure "
            "or compress.pressure",
            interval_collisions, phi_now()));
      }
      r.pressure = thermo.compressibility(interval_virial, kT_mean, interval_time);
      r.temperature = kT_end;
      // Near jamming the mean free time falls towards 1e-12: rebuild (the clock starts at 0
      // again) before the clock's resolution comes within 1e-3 of it.
      const double mean_free_time =
          interval_time * n / (2.0 * static_cast<double>(interval_collisions));
      const bool rebase =
          std::nextafter(engine.time(), kNever) - engine.time() > 1e-3 * mean_free_time;
      r.collisions = out.collisions + c.collisions;
      out.rows.push_back(r);
      out.pressure = r.pressure;
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
      interval_virial = interval_time = 0.0;
      interval_collisions = 0;
      virial_mark = c.virial;
      time_mark = engine.time();
      collision_mark = c.collisions;
      if (r.pressure >= settings.jammed_pressure) {
        done = true;
        out.stop_reason = "jammed";
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
    interval_virial += c.virial - virial_mark;
    interval_time += engine.time() - time_mark;
    interval_collisions += c.collisions - collision_mark;
    out.time += engine.time();
    out.collisions += c.collisions;
    diameter_scale *= engine.growth().scale(engine.time());
    state = engine.export_state(/*with_zones=*/false);
    if (!done) ++out.rebuilds;
  }
  if (out.stop_reason == "jammed" && settings.target_packing_fraction > 0.0 &&
      !settings.jammed_is_a_target) {
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

CompressionSettings compression_settings(const CompressConfig& config, double temperature) {
  CompressionSettings s;
  s.growth_rate = config.growth_rate;
  s.temperature = temperature;
  s.thermostat_interval = config.thermostat_interval;
  s.target_packing_fraction = config.packing_fraction;
  s.target_pressure = config.pressure;
  s.jammed_pressure = config.jammed_pressure;
  s.slowdown_pressure = config.slowdown_pressure;
  s.slowdown_floor = config.slowdown_floor;
  s.jammed_is_a_target = config.jammed;
  return s;
}

template <int D>
CompressionReport compress_start(ParticleSystem<D>& state, const CompressConfig& config,
                                 double temperature, bool tell, bool size_levels) {
  using Clock = std::chrono::steady_clock;
  CompressionReport report;
  report.settings = compression_settings(config, temperature);
  report.settings.size_levels = size_levels;
  const auto start = Clock::now();
  auto next_note = start + std::chrono::seconds(10);
  report.result = compress(state, report.settings, [&](const CompressionRow& r) {
    if (!tell || Clock::now() < next_note) return;
    next_note = Clock::now() + std::chrono::seconds(10);
    std::fputs(fmt::format("compressing: packing fraction {:.6f}, reduced pressure {:.4g}, "
                           "{} collisions\n",
                           r.packing_fraction, r.pressure, r.collisions)
                   .c_str(),
               stderr);
  });
  report.wall_seconds = std::chrono::duration<double>(Clock::now() - start).count();
  Configuration<D> c;
  c.box = state.box;
  c.periodic.fill(true);
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
    report.network = contact_network(c, tolerance);
  }
  const BondOrderValues<D> order = bond_order(c, CompressionReport::kBondCutoff);
  report.order_names = order.names;
  report.order = order.global;
  return report;
}

template double state_packing_fraction<2>(const ParticleSystem<2>&);
template double state_packing_fraction<3>(const ParticleSystem<3>&);
template CompressionResult compress<2>(ParticleSystem<2>&, const CompressionSettings&,
                                       const std::function<void(const CompressionRow&)>&);
template CompressionResult compress<3>(ParticleSystem<3>&, const CompressionSettings&,
                                       const std::function<void(const CompressionRow&)>&);
template CompressionReport compress_start<2>(ParticleSystem<2>&, const CompressConfig&, double,
                                             bool, bool);
template CompressionReport compress_start<3>(ParticleSystem<3>&, const CompressConfig&, double,
                                             bool, bool);

}  // namespace kairos
