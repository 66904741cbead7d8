// Stepped-potential benchmark cases; see stepped_cases.hpp and bench/README.md ("Stepped
// potentials").
//
// sw: the square-well fluid of the stepped-potentials issue (lambda = 1.5, depth 1, diameter
//     1) at number density 0.5 (packing fraction 0.2618) and kT = 1.5, against the hard-sphere
//     fluid at the same N, density and temperature.
// lj: Lennard-Jones (eps = sigma = 1, cut at 2.5 and shifted) stepped with equal energy steps
//     (`steps` on the attractive branch, the repulsive branch continuing in the same energy step
//     down to a hard core at 0.8; volume-averaged shell energies), density 0.8, kT = 2 (the
//     state point of docs/validation.md), for several step counts, against the hard-sphere
//     fluid of diameter 0.8 at the same N and density.
//
// Every system is equilibrated once, with its velocities rescaled to kT every 2 pair events per
// particle (the potential energy released or absorbed as pairs fall into the wells would
// otherwise heat or cool the fluid); the state (with the capture map) is exported after the
// last rescale. Hard spheres and the square well start on the fcc lattice; the coarsest
// Lennard-Jones table from the hard-sphere liquid of diameter 1 (its particles then shrunk to
// the core), each finer table from the previous table's state. Every sample builds a fresh engine
// from it, runs one event per particle untimed, then times a fixed number of events per particle
// (no thermostat while timed: the temperature at the start and the end of the timed part is
// printed).
#include "stepped_cases.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <numbers>
#include <random>
#include <stdexcept>

#include <fmt/format.h>

#include "engine/event_engine.hpp"
#include "init/initial_state.hpp"
#include "interactions/potential_spec.hpp"
#include "model/environment.hpp"
#include "scheduler/calendar_queue.hpp"

namespace kairos::bench {

namespace {

using Clock = std::chrono::steady_clock;
using Emit = std::function<void(const std::string&)>;
using Notes = std::vector<std::string>;
constexpr int D = 3;
using Engine = EventEngine<D, CalendarQueue>;

constexpr std::uint64_t kParticles = 32000;  // 4 * 20^3: a perfect fcc lattice

// Square well (the state point).
constexpr double kSwLambda = 1.5;
constexpr double kSwDepth = 1.0;
constexpr double kSwDensity = 0.5;
constexpr double kSwTemperature = 1.5;
constexpr double kSwTimed = 30;  // events per particle

// Stepped Lennard-Jones (docs/validation.md's state point and table recipe).
constexpr double kLjCutoff = 2.5;
constexpr double kLjCore = 0.8;
constexpr double kLjDensity = 0.8;
constexpr double kLjTemperature = 2.0;
constexpr double kLjTimed = 10;
constexpr double kLjStartDiameter = 1.0;  // the hard-sphere liquid it starts from

constexpr double kHardStart = 20;    // collisions per particle of the hard-sphere start
constexpr double kWarmup = 1;        // untimed events per particle of every fresh engine
constexpr double kRescaleEvery = 2;  // pair events per particle between rescales

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

double packing_fraction(double density, double diameter) {
  return density * std::numbers::pi / 6.0 * diameter * diameter * diameter;
}

// ---------------------------------------------------------------------------------------------
// Measurements

struct Counts {
  std::uint64_t events = 0, collisions = 0, crossings = 0, stale = 0, step_crossings = 0,
                step_bounces = 0;
};

Counts counts_of(const EventCounters& c) {
  return {c.events,       c.collisions,     c.cell_crossings,
          c.stale_events, c.step_crossings, c.step_bounces};
}

Counts operator-(const Counts& a, const Counts& b) {
  return {
      a.events - b.events, a.collisions - b.collisions,         a.crossings - b.crossings,
      a.stale - b.stale,   a.step_crossings - b.step_crossings, a.step_bounces - b.step_bounces};
}

struct Sample {
  Counts n;
  double wall = 0;                // seconds
  double sim = 0;                 // simulated time covered
  double t_start = 0, t_end = 0;  // kT at the start and the end of the timed part
  std::size_t particles = 0;

  double rate(std::uint64_t k) const { return static_cast<double>(k) / wall; }
  double events_per_second() const { return rate(n.events); }
  double pair_events_per_second() const { return rate(n.collisions); }  // steps included
  double wall_per_time() const { return wall / sim; }
  double per_event(std::uint64_t k) const {
    return static_cast<double>(k) / static_cast<double>(n.events);
  }
};

double temperature(const Engine& e) {
  return 2.0 * e.kinetic_energy() / (D * static_cast<double>(e.size()));
}

void advance_events(Engine& e, double per_particle) {
  const auto more = static_cast<std::uint64_t>(per_particle * static_cast<double>(e.size()));
  const std::uint64_t target = e.counters().events + more;
  while (e.counters().events < target) {
    if (e.step() == EventKind::kNone) throw std::runtime_error("the engine ran out of events");
  }
}

void advance_pair_events(Engine& e, double per_particle) {
  const auto more = static_cast<std::uint64_t>(per_particle * static_cast<double>(e.size()) / 2);
  const std::uint64_t target = e.counters().collisions + more;
  while (e.counters().collisions < target) {
    if (e.step() == EventKind::kNone) throw std::runtime_error("the engine ran out of events");
  }
}

// Every velocity scaled so that the kinetic temperature is kT (all masses 1; the total
// momentum, zero from the start, stays zero).
void rescale(Engine& e, double kT) {
  const double factor = std::sqrt(kT / temperature(e));
  const double t = e.time();
  for (std::uint32_t k = 0; k < e.size(); ++k) e.set_velocity(k, t, factor * e.velocity(k, t));
}

// A model: the particles' diameter, the environment (hard spheres: the default), and the
// state point.
struct Model {
  std::string label;
  double diameter = 1.0;
  double density = 0.5;
  double kT = 1.0;
  Environment<D> env;
  // > 0: start from the hard-sphere liquid of this diameter at the same density (equilibrated
  // kHardStart collisions per particle), its particles then shrunk to `diameter`. A stepped
  // Lennard-Jones fluid costs ~500-3000 events per particle per unit time: from the lattice it
  // would take hours to melt, while the dense hard-sphere liquid has nearly its structure.
  double start_diameter = 0.0;
  // Start from the previous model's equilibrated state instead (same particles; the zones are
  // worked out afresh from the distances): the finer Lennard-Jones tables, which cover less
  // simulated time per event, inherit the coarser ones' equilibration.
  bool from_previous = false;
};

Environment<D> stepped_environment(const StepTable& table) {
  Environment<D> env;
  env.species = 1;
  env.tables = {table};
  env.pair_table = {0};
  env.check();
  return env;
}

// The model's fluid, started on the fcc lattice and equilibrated with rescaled velocities.
ParticleSystem<D> equilibrated(const Model& m, std::uint64_t n, double pair_events,
                               const ParticleSystem<D>* previous, Notes& notes) {
  const auto w0 = Clock::now();
  SystemConfig sys;
  sys.dimension = D;
  sys.particles = n;
  sys.packing_fraction = packing_fraction(m.density, m.diameter);
  sys.lattice = "fcc";
  sys.temperature = m.kT;
  sys.seed = 1;
  sys.species = {{"A", m.diameter, 1.0, 1.0}};
  if (m.start_diameter > 0) {
    sys.packing_fraction = packing_fraction(m.density, m.start_diameter);
    sys.species[0].diameter = m.start_diameter;
  }
  std::mt19937_64 rng(sys.seed);
  ParticleSystem<D> s;
  if (m.from_previous && previous != nullptr) {
    s = *previous;
    s.zones.reset();
    s.events.clear();
    s.cell.clear();
  } else {
    s = to_particle_system<D>(make_initial_state<D>(sys, rng));
  }
  if (m.start_diameter > 0 && !(m.from_previous && previous != nullptr)) {
    Engine hard(s);
    advance_pair_events(hard, kHardStart);
    s = hard.export_state();
    for (Kinematics<D>& k : s.kinematics) k.radius = 0.5 * m.diameter;
    s.events.clear();  // predicted afresh for the new diameter
    s.cell.clear();
  }
  Engine e(s, StartMode::kPredict, EngineOptions{}, m.env);
  double before_last = temperature(e), u_before = 0;
  for (double done = 0; done < pair_events; done += kRescaleEvery) {
    advance_pair_events(e, std::min(kRescaleEvery, pair_events - done));
    before_last = temperature(e);
    u_before = e.potential_energy() / static_cast<double>(e.size());
    rescale(e, m.kT);
  }
  const double width = e.grid().width(0);
  notes.push_back(fmt::format(
      "{}: equilibrated in {:.1f} s; before the last rescale kT = {:.4f}, U/N = {:.4f}; cells "
      "{:.3f} wide ({} per axis): {:.1f} candidates per prediction on average",
      m.label, seconds_since(w0), before_last, u_before, width, e.grid().cells_along(0),
      27.0 * m.density * width * width * width));
  return e.export_state();
}

Sample sample(const ParticleSystem<D>& start, const Environment<D>& env, bool vector_scan,
              double timed) {
  EngineOptions options;
  options.vector_scan = vector_scan;
  Engine e(start, StartMode::kPredict, options, env);
  advance_events(e, kWarmup);
  const Counts c0 = counts_of(e.counters());
  const double t0 = e.time();
  Sample s;
  s.particles = e.size();
  s.t_start = temperature(e);
  const auto w0 = Clock::now();
  advance_events(e, timed);
  s.wall = seconds_since(w0);
  s.n = counts_of(e.counters()) - c0;
  s.sim = e.time() - t0;
  s.t_end = temperature(e);
  return s;
}

struct Variant {
  std::string label, scan;
  std::function<Sample()> measure;
  std::vector<Sample> samples;
  const Variant* reference = nullptr;  // the hard-sphere fluid (same scan); null: this is one

  const Sample& best() const {
    return *std::max_element(samples.begin(), samples.end(), [](const Sample& a, const Sample& b) {
      return a.events_per_second() < b.events_per_second();
    });
  }
  double spread() const {
    double lo = best().events_per_second();
    for (const Sample& s : samples) lo = std::min(lo, s.events_per_second());
    return (best().events_per_second() - lo) / best().events_per_second();
  }
};

void interleave(std::vector<Variant>& variants, int repeat) {
  for (int r = 0; r < repeat; ++r)
    for (Variant& v : variants) v.samples.push_back(v.measure());
}

// ---------------------------------------------------------------------------------------------
// Output

std::string header() {
  return "| case | system | N | ρ | kT start → end | scan | events/s | pair events/s | "
         "core coll./event | step crossings/event | step bounces/event | cell crossings/event | "
         "stale/event | events per particle per unit time | wall s per unit time | spread | "
         "events/s vs HS | pair events/s vs HS | wall s per unit time vs HS |\n"
         "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
}

// "best/best (lowest–highest over the interleaved pairs)" of f(sample) / f(reference sample).
std::string ratio_text(const Variant& v, const std::function<double(const Sample&)>& f,
                       bool best_is_max) {
  const Variant& ref = *v.reference;
  double lo = 1e300, hi = 0;
  for (std::size_t k = 0; k < v.samples.size() && k < ref.samples.size(); ++k) {
    const double r = f(v.samples[k]) / f(ref.samples[k]);
    lo = std::min(lo, r);
    hi = std::max(hi, r);
  }
  const auto pick = [&](const Variant& x) {
    double b = f(x.samples.front());
    for (const Sample& s : x.samples) b = best_is_max ? std::max(b, f(s)) : std::min(b, f(s));
    return b;
  };
  const double best = pick(v) / pick(ref);
  if (v.samples.size() < 2) return fmt::format("{:.3f}", best);
  return fmt::format("**{:.3f}** ({:.3f}–{:.3f})", best, lo, hi);
}

std::string row(const std::string& name, const Model& m, const Variant& v) {
  const Sample& b = v.best();
  const auto mega = [&](std::uint64_t k) { return fmt::format("{:.3f} M", b.rate(k) / 1e6); };
  const std::uint64_t core = b.n.collisions - b.n.step_crossings - b.n.step_bounces;
  const bool ref = v.reference == nullptr;
  const auto events = [](const Sample& s) { return s.events_per_second(); };
  const auto pairs = [](const Sample& s) { return s.pair_events_per_second(); };
  const auto wall = [](const Sample& s) { return s.wall_per_time(); };
  return fmt::format(
      "| {} | {} | {} | {:g} | {:.3f} → {:.3f} | {} | {} | {} | {:.3f} | {:.3f} | {:.3f} | "
      "{:.3f} | {:.3f} | {:.1f} | {:.3g} | {:.0f} % | {} | {} | {} |\n",
      name, v.label, b.particles, m.density, b.t_start, b.t_end, v.scan, mega(b.n.events),
      mega(b.n.collisions), b.per_event(core), b.per_event(b.n.step_crossings),
      b.per_event(b.n.step_bounces), b.per_event(b.n.crossings), b.per_event(b.n.stale),
      static_cast<double>(b.n.events) / static_cast<double>(b.particles) / b.sim, b.wall_per_time(),
      100.0 * v.spread(), ref ? "1" : ratio_text(v, events, true),
      ref ? "1" : ratio_text(v, pairs, true), ref ? "1" : ratio_text(v, wall, false));
}

// Runs the models interleaved (the first is the hard-sphere reference), one variant per model
// and scan, and emits their rows.
void run_models(const std::string& name, const std::vector<Model>& models, const SteppedPlan& p,
                double timed, const Emit& emit, Notes& notes) {
  const std::uint64_t n = p.particles > 0 ? p.particles : kParticles;
  std::vector<ParticleSystem<D>> starts;
  starts.reserve(models.size());
  for (const Model& m : models) {
    const ParticleSystem<D>* previous = starts.empty() ? nullptr : &starts.back();
    starts.push_back(equilibrated(m, n, p.equilibrate, previous, notes));
  }
  std::vector<Variant> vs;
  vs.reserve(models.size() * p.scans.size());
  for (std::size_t k = 0; k < models.size(); ++k) {
    for (std::size_t s = 0; s < p.scans.size(); ++s) {
      const bool vector_scan = p.scans[s] == "vector";
      const Model* m = &models[k];
      const ParticleSystem<D>* start = &starts[k];
      Variant v{m->label,
                p.scans[s],
                [=] { return sample(*start, m->env, vector_scan, timed); },
                {},
                k == 0 ? nullptr : &vs[s]};
      vs.push_back(std::move(v));
    }
  }
  interleave(vs, p.repeat);
  std::string text;
  for (std::size_t k = 0; k < vs.size(); ++k) text += row(name, models[k / p.scans.size()], vs[k]);
  emit(text);
}

void run_sw(const SteppedPlan& p, const Emit& emit, Notes& notes) {
  Model hs{"hard spheres", 1.0, kSwDensity, kSwTemperature, {}};
  Model sw{fmt::format("square well λ = {:g}, ε = {:g}", kSwLambda, kSwDepth), 1.0, kSwDensity,
           kSwTemperature, stepped_environment(square_well(1.0, kSwLambda, kSwDepth))};
  run_models("sw", {hs, sw}, p, p.timed > 0 ? p.timed : kSwTimed, emit, notes);
}

void run_lj(const SteppedPlan& p, const Emit& emit, Notes& notes) {
  std::vector<Model> models = {
      {fmt::format("hard spheres σ = {:g}", kLjCore), kLjCore, kLjDensity, kLjTemperature, {}}};
  std::vector<int> counts = p.lj_steps;
  std::sort(counts.begin(), counts.end());
  for (const int steps : counts) {
    PotentialSpec spec;
    spec.kind = "lennard_jones";
    spec.cutoff = kLjCutoff;
    spec.steps = steps;
    spec.placement = "energy";
    spec.shell_energy = "volume";
    const StepTable table = make_step_table(spec, kLjCore, D);
    models.push_back({fmt::format("LJ {} steps ({} shells)", steps, table.energy.size()), kLjCore,
                      kLjDensity, kLjTemperature, stepped_environment(table), kLjStartDiameter,
                      models.size() > 1});
  }
  run_models("lj", models, p, p.timed > 0 ? p.timed : kLjTimed, emit, notes);
}

}  // namespace

void validate(const SteppedPlan& p) {
  for (const std::string& c : p.cases) {
    if (c != "sw" && c != "lj")
      throw std::invalid_argument(fmt::format("--case \"{}\" is unknown; use sw and/or lj", c));
  }
  for (const std::string& s : p.scans) {
    if (s != "vector" && s != "scalar")
      throw std::invalid_argument(fmt::format("--scan \"{}\" is unknown; use vector, scalar", s));
  }
  if (p.scans.empty()) throw std::invalid_argument("--scan: give at least one loop");
  for (const int s : p.lj_steps)
    if (s < 1) throw std::invalid_argument("--steps: step counts must be >= 1");
  if (p.particles != 0 && p.particles < 100)
    throw std::invalid_argument("--particles: the stepped cases need at least 100");
  if (!(p.equilibrate >= 0 && std::isfinite(p.equilibrate)) ||
      !(p.timed >= 0 && std::isfinite(p.timed))) {
    throw std::invalid_argument("--equilibrate and --timed must be finite and >= 0");
  }
  if (p.repeat < 1) throw std::invalid_argument("--repeat must be >= 1");
}

std::string stepped_protocol(const SteppedPlan& p) {
  std::string steps;
  for (const int s : p.lj_steps) steps += (steps.empty() ? "" : ", ") + std::to_string(s);
  return fmt::format(
      "Protocol (stepped): 3D, calendar queue, N = {}; equilibrated {:g} pair events per "
      "particle with velocities rescaled to kT every {:g}, from the fcc lattice (hard spheres, "
      "sw), from the hard-sphere liquid of diameter {:g} at the same density ({:g} collisions "
      "per particle) shrunk to the core (the coarsest lj table), from the previous table's "
      "state (the finer lj tables); every sample a fresh engine from "
      "that state, {:g} event per particle untimed, then {} events per particle timed (no "
      "thermostat); variants interleaved, best of {} (events/s) with the spread; ratios "
      "best/best against the hard-sphere fluid of the same N, density, kT and scan, and (in "
      "brackets) the range over the interleaved pairs. sw: square well λ = {:g}, ε = {:g}, "
      "σ = 1, ρ = {:g} (η = {:.4f}), kT = {:g}. lj: Lennard-Jones ε = σ = 1 cut at {:g} and "
      "shifted, equal-energy steps ({} on the attractive branch), volume-averaged shell "
      "energies, hard core {:g}, ρ = {:g} (η = {:.4f}), kT = {:g}. A pair event is a core "
      "collision, a step crossing or a step bounce.",
      p.particles > 0 ? p.particles : kParticles, p.equilibrate, kRescaleEvery, kLjStartDiameter,
      kHardStart, kWarmup,
      p.timed > 0 ? fmt::format("{:g}", p.timed)
                  : fmt::format("{:g} (sw) / {:g} (lj)", kSwTimed, kLjTimed),
      p.repeat, kSwLambda, kSwDepth, kSwDensity, packing_fraction(kSwDensity, 1.0), kSwTemperature,
      kLjCutoff, steps, kLjCore, kLjDensity, packing_fraction(kLjDensity, kLjCore), kLjTemperature);
}

void run_stepped(const SteppedPlan& plan, const std::function<void(const std::string&)>& emit) {
  Notes notes;
  emit("\n" + header());
  for (const std::string& name : plan.cases) {
    if (name == "sw") run_sw(plan, emit, notes);
    if (name == "lj") run_lj(plan, emit, notes);
  }
  emit("\n");
  for (const std::string& note : notes) emit("- " + note + "\n");
}

}  // namespace kairos::bench
