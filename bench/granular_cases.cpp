// Granular benchmark cases; see granular_cases.hpp and bench/README.md ("Granular").
//
// gas:  dilute inelastic gas (constant e = 0.9, periodic box, no gravity) against the elastic
//       fluid at the same N and packing fraction. Both start from one elastically equilibrated
//       state; every sample builds a fresh engine, warms it up, then times a fixed number of
//       collisions per particle. The granular gas cools (Haff's law) while it is timed, which
//       does not change the work per event; the kinetic energy ratio is reported.
// bed:  vibrated bed (gravity, vibrating floor, periodic sides, open top, e = 0.9, TC model)
//       against the elastic fluid at the same N and the packing fraction the bed starts at.
//       The bed is driven into its steady state once (untimed), then sampled like the gas.
// pile: particles dropped from a loose lattice onto a fixed floor (periodic sides, open top)
//       with sleeping particles; events and wall seconds per unit simulated time, per interval
//       of simulated time, until everything sleeps, then over a long interval afterwards.
#include "granular_cases.hpp"

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
#include "model/environment.hpp"
#include "scheduler/calendar_queue.hpp"

namespace kairos::bench {

namespace {

using Clock = std::chrono::steady_clock;
using Emit = std::function<void(const std::string&)>;
using Notes = std::vector<std::string>;  // printed after the tables
template <int D>
using Engine = EventEngine<D, CalendarQueue>;

// ---------------------------------------------------------------------------------------------
// The models (reduced units: diameter = mass = 1, g = 1, initial kT = 1 for the gas)

constexpr double kRestitution = 0.9;  // gas and bed: particle-particle and particle-wall
constexpr double kGravity = 1.0;      // bed and pile, along -e_{D-1}

constexpr std::uint64_t kGasParticles = 100000;
constexpr double kGasEta = 0.1;
constexpr double kGasTimed = 20;  // collisions per particle
constexpr double kWarmup = 1;     // untimed collisions per particle of every fresh engine

// A bed of kBedLayers (3D; 2D: twice as many) lattice layers at packing fraction kBedEta
// (also the elastic reference's), on a floor vibrating with amplitude kBedAmplitude at peak
// acceleration kBedGamma g; driven for kBedPeriods periods before it is sampled.
constexpr std::uint64_t kBedParticles = 10000;
constexpr int kBedLayers = 10;
constexpr double kBedEta = 0.3;
constexpr double kBedAmplitude = 0.5;
constexpr double kBedGamma = 4.0;
constexpr double kBedTc = 1e-4;
constexpr double kBedPeriods = 10;
constexpr double kBedTimed = 20;

// A pile of kPileLayers (3D; 2D: twice as many) layers dropped onto a fixed floor: square
// layers kPileSpacing apart, every other one shifted by half a spacing along each horizontal
// axis (a body-centred stacking, each particle above a pocket), kPileGap above the contact
// height; restitution kPileRestitution, TC model, sleep speed kPileSleepSpeed (a bounce of
// 0.02 diameters: the pile settles in a few time units; with the automatic 1.4e-3 it settles
// too, more slowly: see bench/README.md).
constexpr std::uint64_t kPileParticles = 100000;
constexpr int kPileLayers = 10;
constexpr double kPileSpacing = 1.05;
constexpr double kPileGap = 0.05;
constexpr double kPileRestitution = 0.5;
constexpr double kPileTc = 1e-4;
constexpr double kPileSleepSpeed = 0.2;
constexpr double kPileInterval = 1;      // simulated time per row while settling
constexpr double kPileMaxTime = 50;      // stop settling rows here even if some are awake
constexpr double kPileAfter = 1000;      // the interval after settling
constexpr double kPileWallBudget = 300;  // seconds for the settling rows, and for the last

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// ---------------------------------------------------------------------------------------------
// Measurements

struct Counts {
  std::uint64_t events = 0, collisions = 0, walls = 0, crossings = 0, stale = 0, elastic = 0;
};

Counts counts_of(const EventCounters& c) {
  return {c.events,         c.collisions,   c.wall_collisions,
          c.cell_crossings, c.stale_events, c.elastic_by_rule};
}

Counts operator-(const Counts& a, const Counts& b) {
  return {a.events - b.events,       a.collisions - b.collisions, a.walls - b.walls,
          a.crossings - b.crossings, a.stale - b.stale,           a.elastic - b.elastic};
}

// A timed stretch of one engine.
struct Sample {
  Counts n;
  double wall = 0;          // seconds
  double sim = 0;           // simulated time covered
  double energy_ratio = 1;  // kinetic energy at the end / at the start

  double rate(std::uint64_t k) const { return static_cast<double>(k) / wall; }
  double per_collision(std::uint64_t k) const {
    return n.collisions == 0 ? 0.0 : static_cast<double>(k) / static_cast<double>(n.collisions);
  }
  double events_per_second() const { return rate(n.events); }
};

// Steps the engine until it has done `per_particle` more collisions per particle.
template <int D>
void advance_collisions(Engine<D>& e, double per_particle) {
  const auto more = static_cast<std::uint64_t>(per_particle * static_cast<double>(e.size()) / 2);
  const std::uint64_t target = e.counters().collisions + more;
  while (e.counters().collisions < target) {
    if (e.step() == EventKind::kNone) throw std::runtime_error("the engine ran out of events");
  }
}

// Steps the engine through every event up to simulated time t, or until the wall clock passes
// `deadline` (checked every 4096 events). Returns whether it reached t.
template <int D>
bool advance_time(Engine<D>& e, double t, Clock::time_point deadline = Clock::time_point::max()) {
  for (std::uint64_t k = 1; e.next_event_time() <= t; ++k) {
    e.step();
    if (k % 4096 == 0 && Clock::now() > deadline) return false;
  }
  return true;
}

template <int D>
Sample timed_collisions(Engine<D>& e, double per_particle) {
  const Counts c0 = counts_of(e.counters());
  const double t0 = e.time(), ke0 = e.kinetic_energy();
  const auto w0 = Clock::now();
  advance_collisions(e, per_particle);
  Sample s;
  s.wall = seconds_since(w0);
  s.n = counts_of(e.counters()) - c0;
  s.sim = e.time() - t0;
  s.energy_ratio = ke0 > 0 ? e.kinetic_energy() / ke0 : 1.0;
  return s;
}

// The engine options of the timed samples (--crossings full: every crossing rescans).
EngineOptions options_of(const GranularPlan& p) {
  EngineOptions options;
  options.incremental_crossings = !p.full_crossing_scans;
  return options;
}

// A fresh engine from `start`, warmed up, then timed.
template <int D>
Sample sample(const ParticleSystem<D>& start, const Environment<D>& env, double timed,
              const EngineOptions& options) {
  Engine<D> e(start, StartMode::kPredict, options, env);
  advance_collisions(e, kWarmup);
  return timed_collisions(e, timed);
}

// A system measured several times, interleaved with the others of its case.
struct Variant {
  std::string label;
  std::function<Sample()> measure;
  std::vector<Sample> samples;

  const Sample& best() const {
    return *std::max_element(samples.begin(), samples.end(), [](const Sample& a, const Sample& b) {
      return a.events_per_second() < b.events_per_second();
    });
  }
  double spread() const {
    double lo = best().events_per_second(), hi = lo;
    for (const Sample& s : samples) lo = std::min(lo, s.events_per_second());
    return hi > 0 ? (hi - lo) / hi : 0.0;
  }
};

// A B A B ...: machine noise hits every variant alike.
void interleave(std::vector<Variant>& variants, int repeat) {
  for (int r = 0; r < repeat; ++r)
    for (Variant& v : variants) v.samples.push_back(v.measure());
}

// ---------------------------------------------------------------------------------------------
// Systems

ContactModel constant_restitution(double e) {
  ContactModel m;
  m.normal = NormalRestitution::constant(e);
  return m;
}

template <int D>
Environment<D> inelastic_gas() {
  Environment<D> env;
  env.species = 1;
  env.contact = {constant_restitution(kRestitution)};
  return env;
}

// Gravity along -e_{D-1} onto a floor wall (vibrating if amplitude > 0), open top, periodic
// sides.
template <int D>
Environment<D> floor_environment(double e, double amplitude, double omega, double tc) {
  Environment<D> env;
  env.gravity[D - 1] = -kGravity;
  env.species = 1;
  env.contact = {constant_restitution(e)};
  env.tc = tc;
  Face<D>& floor = env.faces[2 * (D - 1)];
  floor.kind = FaceKind::kWall;
  floor.wall.contact = constant_restitution(e);
  floor.wall.amplitude = amplitude;
  floor.wall.angular_frequency = omega;
  env.faces[2 * (D - 1) + 1].kind = FaceKind::kOpen;
  env.check();
  return env;
}

// The elastic fluid on the fcc (hex) lattice, equilibrated by `collisions` per particle.
template <int D>
ParticleSystem<D> equilibrated_fluid(std::uint64_t n, double eta, double collisions) {
  SystemConfig sys;
  sys.dimension = D;
  sys.particles = n;
  sys.packing_fraction = eta;
  sys.lattice = D == 3 ? "fcc" : "hex";
  sys.seed = 1;
  std::mt19937_64 rng(sys.seed);
  Engine<D> e(to_particle_system<D>(make_initial_state<D>(sys, rng)));
  advance_collisions(e, collisions);
  return e.export_state();
}

// Particles on a simple-cubic (square) lattice of `side` sites per periodic axis and as many
// layers as needed, filled from the bottom; Gaussian velocities of deviation `speed`.
struct Column {
  std::uint64_t particles = 0;
  std::uint64_t side = 0;  // sites per horizontal axis
  double spacing = 1.0;
  double bottom = 0.0;  // height of the lowest particles' lowest point
  double height = 0.0;  // box height (the top is open)
  double speed = 0.0;
  double pitch = 1.0;    // vertical distance between layers
  bool stagger = false;  // shift every other layer by half a spacing horizontally
};

template <int D>
ParticleSystem<D> column_state(const Column& c) {
  ParticleSystem<D> s;
  for (int a = 0; a < D - 1; ++a) s.box[a] = static_cast<double>(c.side) * c.spacing;
  s.box[D - 1] = c.height;
  std::mt19937_64 rng(1);
  std::normal_distribution<double> gauss(0.0, c.speed);
  s.kinematics.resize(c.particles);
  for (std::uint64_t k = 0; k < c.particles; ++k) {
    Kinematics<D>& kin = s.kinematics[k];
    std::uint64_t site = k;
    for (int a = 0; a < D - 1; ++a) {
      kin.pos[a] = (static_cast<double>(site % c.side) + 0.5) * c.spacing;
      site /= c.side;
    }
    const double shift = c.stagger && site % 2 == 1 ? 0.5 * c.spacing : 0.0;
    for (int a = 0; a < D - 1; ++a) kin.pos[a] += shift;
    kin.pos[D - 1] = c.bottom + 0.5 + static_cast<double>(site) * c.pitch;
    for (int a = 0; a < D; ++a) kin.vel[a] = gauss(rng);
    kin.time = 0.0;
    kin.radius = 0.5;
  }
  s.mass.assign(c.particles, 1.0);
  s.species.assign(c.particles, 0);
  s.species_names = {"A"};
  return s;
}

// A column `layers` deep (3D; twice as deep in 2D) of about n particles.
template <int D>
Column column_of(std::uint64_t n, int layers) {
  const double per_layer = static_cast<double>(n) / (D == 3 ? layers : 2 * layers);
  Column c;
  c.particles = n;
  c.side = static_cast<std::uint64_t>(std::ceil(D == 3 ? std::sqrt(per_layer) : per_layer));
  return c;
}

template <int D>
double vertical_extent(const Column& c) {
  const double sites = std::pow(static_cast<double>(c.side), D - 1);
  return std::ceil(static_cast<double>(c.particles) / sites) * c.pitch;
}

// ---------------------------------------------------------------------------------------------
// Output

std::string steady_header() {
  return "| case | dim | N | system | coll/particle timed | sim. time | collisions/s | events/s | "
         "wall hits/event | crossings/coll | stale/coll | made elastic/coll | KE end/start | "
         "spread | events/s vs elastic | collisions/s vs elastic |\n"
         "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
}

// "best/best (lowest–highest of the interleaved pairs)"
std::string ratio_text(const Variant& v, const Variant& ref, bool events) {
  const auto rate = [&](const Sample& s) {
    return events ? s.events_per_second() : s.rate(s.n.collisions);
  };
  double lo = 1e300, hi = 0;
  for (std::size_t k = 0; k < v.samples.size() && k < ref.samples.size(); ++k) {
    const double r = rate(v.samples[k]) / rate(ref.samples[k]);
    lo = std::min(lo, r);
    hi = std::max(hi, r);
  }
  const double best = rate(v.best()) / rate(ref.best());
  if (v.samples.size() < 2) return fmt::format("{:.2f}", best);
  return fmt::format("**{:.2f}** ({:.2f}–{:.2f})", best, lo, hi);
}

std::string steady_row(const std::string& name, int dim, std::uint64_t n, const Variant& v,
                       const Variant& ref, double timed) {
  const Sample& b = v.best();
  const auto mega = [&](std::uint64_t k) { return fmt::format("{:.3f} M", b.rate(k) / 1e6); };
  const bool is_ref = &v == &ref;
  return fmt::format(
      "| {} | {}D | {} | {} | {:g} | {:.3g} | {} | {} | {:.3f} | {:.3f} | {:.3f} | {:.3f} | "
      "{:.3f} | {:.0f} % | {} | {} |\n",
      name, dim, n, v.label, timed, b.sim, mega(b.n.collisions), mega(b.n.events),
      static_cast<double>(b.n.walls) / static_cast<double>(b.n.events),
      b.per_collision(b.n.crossings), b.per_collision(b.n.stale), b.per_collision(b.n.elastic),
      b.energy_ratio, 100.0 * v.spread(), is_ref ? "1" : ratio_text(v, ref, true),
      is_ref ? "1" : ratio_text(v, ref, false));
}

// ---------------------------------------------------------------------------------------------
// Cases

template <int D>
void run_gas(const GranularPlan& p, const Emit& emit, Notes& notes) {
  const std::uint64_t n = p.particles > 0 ? p.particles : kGasParticles;
  const double eta = p.eta > 0 ? p.eta : kGasEta;
  const double timed = p.timed > 0 ? p.timed : kGasTimed;
  const auto w0 = Clock::now();
  const ParticleSystem<D> start = equilibrated_fluid<D>(n, eta, p.equilibrate);
  const double setup = seconds_since(w0);
  const Environment<D> elastic{}, inelastic = inelastic_gas<D>();
  std::vector<Variant> vs = {{fmt::format("elastic, η = {:g}", eta),
                              [&] { return sample<D>(start, elastic, timed, options_of(p)); },
                              {}},
                             {fmt::format("e = {:g}, η = {:g}", kRestitution, eta),
                              [&] { return sample<D>(start, inelastic, timed, options_of(p)); },
                              {}}};
  interleave(vs, p.repeat);
  for (const Variant& v : vs) emit(steady_row("gas", D, n, v, vs[0], timed));
  notes.push_back(fmt::format("gas {}D: the shared elastic start took {:.1f} s", D, setup));
}

template <int D>
Environment<D> bed_environment() {
  const double omega = std::sqrt(kBedGamma * kGravity / kBedAmplitude);
  return floor_environment<D>(kRestitution, kBedAmplitude, omega, kBedTc);
}

// The bed after kBedPeriods periods of driving from its lattice start.
template <int D>
ParticleSystem<D> driven_bed(std::uint64_t n, Notes& notes) {
  Column c = column_of<D>(n, kBedLayers);
  c.spacing = std::pow(particle_volume<D>(1.0) / kBedEta, 1.0 / D);
  c.pitch = c.spacing;
  c.bottom = kBedAmplitude + 0.05;
  c.height = 3 * (c.bottom + vertical_extent<D>(c));
  c.speed = 0.1;
  const Environment<D> env = bed_environment<D>();
  Engine<D> e(column_state<D>(c), StartMode::kPredict, EngineOptions{}, env);
  const double period = 2 * std::numbers::pi / env.faces[2 * (D - 1)].wall.angular_frequency;
  advance_time(e, kBedPeriods * period);
  double height = 0;
  for (const Vec<D>& x : e.current_positions()) height += x[D - 1];
  const double per_particle = 1.0 / static_cast<double>(e.size());
  notes.push_back(fmt::format(
      "bed {}D: box {:.1f} high (3 x the lattice bed), grid {} cells high; after driving: "
      "mean height {:.2f}, kinetic energy per particle {:.3f}",
      D, c.height, e.grid().cells_along(D - 1), height * per_particle,
      e.kinetic_energy() * per_particle));
  return e.export_state();
}

template <int D>
void run_bed(const GranularPlan& p, const Emit& emit, Notes& notes) {
  const std::uint64_t n = p.particles > 0 ? p.particles : kBedParticles;
  const double timed = p.timed > 0 ? p.timed : kBedTimed;
  const auto w0 = Clock::now();
  const ParticleSystem<D> fluid = equilibrated_fluid<D>(n, kBedEta, p.equilibrate);
  const ParticleSystem<D> bed = driven_bed<D>(n, notes);
  const double setup = seconds_since(w0);
  const Environment<D> elastic{}, driven = bed_environment<D>();
  std::vector<Variant> vs = {
      {fmt::format("elastic, η = {:g}", kBedEta),
       [&] { return sample<D>(fluid, elastic, timed, options_of(p)); },
       {}},
      {fmt::format("vibrated bed, e = {:g}, Γ = {:g}", kRestitution, kBedGamma),
       [&] { return sample<D>(bed, driven, timed, options_of(p)); },
       {}}};
  interleave(vs, p.repeat);
  for (const Variant& v : vs) emit(steady_row("bed", D, n, v, vs[0], timed));
  notes.push_back(
      fmt::format("bed {}D: the elastic start and {:g} periods of driving the bed took {:.1f} s", D,
                  kBedPeriods, setup));
}

std::string pile_header() {
  return "| dim | N | simulated time | events | collisions | wall hits | events per unit time | "
         "wall s per unit time | awake at the end | asleep at the end |\n"
         "|---|---|---|---|---|---|---|---|---|---|\n";
}

template <int D>
std::string pile_row(const Engine<D>& e, double from, double to, const Counts& c, double wall) {
  const double dt = to - from;
  return fmt::format("| {}D | {} | {:g}–{:g} | {} | {} | {} | {:.4g} | {:.3g} | {} | {} |\n", D,
                     e.size(), from, to, c.events, c.collisions, c.walls,
                     static_cast<double>(c.events) / dt, wall / dt, e.size() - e.sleeping(),
                     e.sleeping());
}

template <int D>
void run_pile(const GranularPlan& p, const Emit& emit, Notes& notes) {
  Column c = column_of<D>(p.particles > 0 ? p.particles : kPileParticles, kPileLayers);
  c.spacing = kPileSpacing;
  // Touching the particles of the pocket below, plus the gap.
  c.pitch = std::sqrt(1.0 - (D - 1) * 0.25 * c.spacing * c.spacing) + kPileGap;
  c.stagger = true;
  c.bottom = kPileGap;
  c.height = c.bottom + vertical_extent<D>(c);
  c.speed = 0.01;
  const auto w0 = Clock::now();
  Environment<D> env = floor_environment<D>(kPileRestitution, 0.0, 0.0, kPileTc);
  env.sleep_speed = kPileSleepSpeed;
  Engine<D> e(column_state<D>(c), StartMode::kPredict, options_of(p), env);
  notes.push_back(fmt::format("pile {}D: engine built in {:.2f} s", D, seconds_since(w0)));
  // Settling rows share one wall-clock budget; the last row (after settling) gets its own.
  const auto budget =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(kPileWallBudget));
  const auto settling_deadline = Clock::now() + budget;
  double t = 0;
  for (bool last = false; !last;) {
    last = t >= kPileMaxTime || e.sleeping() == e.size() || Clock::now() > settling_deadline;
    const double to = t + (last ? kPileAfter : kPileInterval);
    const Counts c0 = counts_of(e.counters());
    const auto w1 = Clock::now();
    const bool reached = advance_time(e, to, last ? w1 + budget : settling_deadline);
    const double end = reached ? to : e.time();
    emit(pile_row(e, t, end, counts_of(e.counters()) - c0, seconds_since(w1)));
    if (!reached) {
      notes.push_back(
          fmt::format("pile {}D: the wall-clock budget ({:g} s) ran out at simulated time {:.4g}",
                      D, kPileWallBudget, end));
    }
    t = end;
  }
}

template <int D>
void run_case(const std::string& name, const GranularPlan& p, const Emit& emit, Notes& notes) {
  if (name == "gas") run_gas<D>(p, emit, notes);
  if (name == "bed") run_bed<D>(p, emit, notes);
  if (name == "pile") run_pile<D>(p, emit, notes);
}

std::vector<int> dims_of(const std::string& name, const GranularPlan& p) {
  if (!p.dims.empty()) return p.dims;
  return name == "pile" ? std::vector<int>{3} : std::vector<int>{3, 2};
}

}  // namespace

void validate(const GranularPlan& p) {
  for (const std::string& c : p.cases) {
    if (c != "gas" && c != "bed" && c != "pile") {
      throw std::invalid_argument(
          fmt::format("--case \"{}\" is unknown; use gas, bed and/or pile", c));
    }
  }
  for (int d : p.dims) {
    if (d != 2 && d != 3) {
      throw std::invalid_argument(fmt::format("--dimension {} is invalid: use 2 or 3", d));
    }
  }
  if (p.particles != 0 && p.particles < 100) {
    throw std::invalid_argument("--particles: the granular cases need at least 100");
  }
  if (!(p.eta >= 0 && p.eta < 0.5)) {
    throw std::invalid_argument(
        fmt::format("--eta {} is invalid for the gas: use (0, 0.5)", p.eta));
  }
  if (!(p.equilibrate >= 0 && std::isfinite(p.equilibrate)) ||
      !(p.timed >= 0 && std::isfinite(p.timed))) {
    throw std::invalid_argument("--equilibrate and --timed must be finite and >= 0");
  }
  if (p.repeat < 1) throw std::invalid_argument("--repeat must be >= 1");
}

std::string granular_protocol(const GranularPlan& p) {
  return fmt::format(
      "Protocol (granular): calendar queue, {} cell crossings; each engine warmed up {:g} "
      "collision per particle before it is timed; variants of a case interleaved, best of {} "
      "(events/s) with the "
      "spread; ratios best/best and (in brackets) the range over the interleaved pairs. gas: "
      "e = {:g}, start equilibrated elastically {:g} collisions per particle; bed: gravity "
      "{:g}, periodic sides, open top, floor amplitude {:g}, Γ = {:g}, e = {:g}, tc = {:g}, {} "
      "layers (3D; 2D: {}) at η = {:g}, driven {:g} periods before it is timed; pile: {} "
      "body-centred layers (3D; 2D: {}), spacing {:g}, gap {:g}, e = {:g}, tc = {:g}, sleep "
      "speed {:g}, rows every {:g} time units until all sleep (or t = {:g}, or {:g} wall "
      "seconds), then one of {:g}.",
      p.full_crossing_scans ? "full-scan" : "incremental", kWarmup, p.repeat, kRestitution,
      p.equilibrate, kGravity, kBedAmplitude, kBedGamma, kRestitution, kBedTc, kBedLayers,
      2 * kBedLayers, kBedEta, kBedPeriods, kPileLayers, 2 * kPileLayers, kPileSpacing, kPileGap,
      kPileRestitution, kPileTc, kPileSleepSpeed, kPileInterval, kPileMaxTime, kPileWallBudget,
      kPileAfter);
}

void run_granular(const GranularPlan& plan, const std::function<void(const std::string&)>& emit) {
  Notes notes;
  std::string last_table;
  for (const std::string& name : plan.cases) {
    const std::string table = name == "pile" ? pile_header() : steady_header();
    if (table != last_table) emit("\n" + table);
    last_table = table;
    for (int d : dims_of(name, plan)) {
      if (d == 3) run_case<3>(name, plan, emit, notes);
      if (d == 2) run_case<2>(name, plan, emit, notes);
    }
  }
  emit("\n");
  for (const std::string& note : notes) emit("- " + note + "\n");
}

}  // namespace kairos::bench
