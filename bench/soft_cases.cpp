// Soft-sphere benchmark cases; see soft_cases.hpp and bench/README.md ("Soft spheres").
//
// Reduced units: diameter sigma = 1, mass m = 1, 3D, periodic box. Per packing fraction the
// elastic hard-sphere fluid is started on the fcc lattice and equilibrated (untimed); its
// temperature T (per degree of freedom, measured) gives the mean free time
// tau = 1 / omega_E, with omega_E the Enskog collision frequency 4 sigma^2 n g(sigma)
// sqrt(pi T / m) (docs/physics.md#enskog-collision-frequency, analysis/granular_theory.hpp). For
// every contact law and ratio R = tau / t_c the law is chosen so that its head-on contact time is
// t_c = tau / R and its head-on restitution is e:
//   dashpot: zeta = gamma / (2 sqrt(k mu)) from e (closed form with the force-zero end,
//            docs/physics.md#dashpot-head-on), omega_0 = t_c~(zeta) / t_c, k = mu omega_0^2,
//            gamma = 2 zeta sqrt(k mu): t_c and e are the same at every impact speed;
//   hertz:   c_dis from e (exact map), rho and A from T = t_c / eps_t(c_dis) at the reference
//            speed v_ref = 2 sqrt(T/m) (the rms normal impact speed of a Maxwellian gas's
//            collisions, <g_n^2> = 4 T / m): t_c and e hold at v_ref only.
// Per case the lookup tables are built once (attach_soft_tables, a fresh cache directory unless
// one is given: the build time is reported on its own), then three variants are timed,
// interleaved (A B C A B C ...), each from the same equilibrated state:
//   hard spheres: the elastic hard-sphere engine, warmed up 1 collision per particle, then
//                 `timed` collisions per particle;
//   mapped:       the event-driven engine with the soft law and its tables, same lengths;
//   DEM:          DemIntegrator at its default time step t_c/50 (Hertz: the elastic contact
//                 time at v_ref, slightly longer than the damped one: in DEM's favour), warmed
//                 up a few steps, then `dem_steps` steps; its collisions are the pairs that
//                 entered contact (DemIntegrator::collisions), the Enskog expectation beside.
// Collisions per wall second of each; best of the repeats, ratios best/best with the range of
// the interleaved pairs.
#include "soft_cases.hpp"

#include <stdlib.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <optional>
#include <random>
#include <stdexcept>

#include <fmt/format.h>

#include "analysis/granular_theory.hpp"
#include "core/periodic.hpp"
#include "dem/dem_integrator.hpp"
#include "engine/event_engine.hpp"
#include "init/initial_state.hpp"
#include "interactions/soft_contact.hpp"
#include "io/atomic_file.hpp"
#include "model/environment.hpp"
#include "run/soft_tables_setup.hpp"
#include "scheduler/calendar_queue.hpp"

namespace kairos::bench {

namespace {

using Clock = std::chrono::steady_clock;
using Emit = std::function<void(const std::string&)>;
using Engine = EventEngine<3, CalendarQueue>;

constexpr std::uint64_t kParticles = 32000;
constexpr double kTimed = 4;               // event-driven timed collisions per particle
constexpr double kWarmup = 1;              // untimed collisions per particle of every fresh engine
constexpr long kDemSteps = 2000;           // DEM timed steps per sample
constexpr long kDemWarmup = 100;           // DEM untimed steps of every fresh integrator
constexpr double kMass = 1.0;              // every particle
constexpr double kDiameter = 1.0;          // every particle
constexpr double kMu = kMass / 2;          // reduced mass of a pair
constexpr double kStepsPerContact = 50.0;  // DEM's default

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// ---------------------------------------------------------------------------------------------
// The state and the laws

struct Gas {
  ParticleSystem<3> start;
  double eta = 0, density = 0, temperature = 0;
  double frequency = 0;  // Enskog collision frequency per particle at the start
  double tau() const { return 1.0 / frequency; }
};

Gas equilibrated_gas(std::uint64_t n, double eta, double collisions) {
  SystemConfig sys;
  sys.dimension = 3;
  sys.particles = n;
  sys.packing_fraction = eta;
  sys.lattice = "fcc";
  sys.seed = 1;
  std::mt19937_64 rng(sys.seed);
  Engine e(to_particle_system<3>(make_initial_state<3>(sys, rng)));
  const auto target = static_cast<std::uint64_t>(collisions * static_cast<double>(n) / 2);
  while (e.counters().collisions < target) {
    if (e.step() == EventKind::kNone) throw std::runtime_error("the engine ran out of events");
  }
  Gas g;
  g.start = e.export_state(false);
  g.start.counters = {};
  g.eta = eta;
  double volume = 1;
  for (double side : g.start.box) volume *= side;
  g.density = static_cast<double>(n) / volume;
  Vec<3> mean{};
  for (const auto& k : g.start.kinematics) mean = mean + k.vel;
  mean = (1.0 / static_cast<double>(n)) * mean;
  double sum = 0;
  for (const auto& k : g.start.kinematics) sum += kMass * norm2(k.vel - mean);
  g.temperature = sum / (3.0 * static_cast<double>(n));
  g.frequency = enskog_collision_frequency(3, g.density, kDiameter, g.temperature, kMass);
  return g;
}

struct Law {
  std::string name;  // "dashpot" / "hertz"
  SoftContactLaw law;
  double contact_time = 0;     // head-on (Hertz: at reference_speed)
  double reference_speed = 0;  // Hertz: v_ref; dashpot: 0 (t_c does not depend on it)
  double restitution = 0;      // head-on, checked
  std::string parameters;      // for the notes
};

Law make_law(const std::string& name, double contact_time, double e, double temperature) {
  Law l;
  l.name = name;
  l.contact_time = contact_time;
  if (name == "dashpot") {
    const double zeta = dashpot_zeta_for_restitution(e);
    const double omega0 = dashpot_head_on_reduced(zeta).contact_time / contact_time;
    const double k = kMu * omega0 * omega0;
    const double gamma = 2.0 * zeta * std::sqrt(k * kMu);
    l.law = SoftContactLaw::linear_dashpot(k, gamma);
    const HeadOn h = dashpot_head_on(kMu, k, gamma);
    l.restitution = h.restitution;
    l.parameters = fmt::format("k = {:.4g}, γ = {:.4g} (ζ = {:.4f}; t_c = {:.4g}, e = {:.4f})", k,
                               gamma, zeta, h.contact_time, h.restitution);
  } else {
    l.reference_speed = 2.0 * std::sqrt(temperature / kMass);
    const double c_dis = viscoelastic_c_dis_for_restitution(e);
    ReducedCollision head_on;
    head_on.model = SoftModel::ViscoelasticHertz;
    head_on.l_tilde = 100.0;  // head-on: the map does not depend on l~
    head_on.c_dis = c_dis;
    const CollisionMap map = collision_map(head_on);
    const double T = contact_time / map.eps_t;
    const double rho = kMu / std::sqrt(l.reference_speed * std::pow(T, 5.0));
    const double A = c_dis * T;
    l.law = SoftContactLaw::viscoelastic_hertz(rho, A);
    const CollisionUnits u = reduce_collision(l.law, kMu, kDiameter, l.reference_speed, 0.0);
    const CollisionMap check = collision_map(u.reduced);
    l.restitution = -check.eps_rdot;
    l.parameters = fmt::format(
        "ρ = {:.4g}, A = {:.4g} (c_dis = {:.4f}; at v_ref = {:.3f}: t_c = {:.4g}, e = {:.4f}; "
        "elastic t_H = {:.4g})",
        rho, A, c_dis, l.reference_speed, check.eps_t * u.time_unit, -check.eps_rdot,
        hertz_elastic_contact_time(kMu, rho, l.reference_speed));
  }
  return l;
}

// ---------------------------------------------------------------------------------------------
// Measurements

struct Sample {
  double wall = 0;  // seconds
  double sim = 0;   // simulated time covered
  double energy_ratio = 1;
  std::uint64_t collisions = 0, events = 0, contacts = 0, fallbacks = 0, early = 0, direct = 0;
  long steps = 0;  // DEM
  double dt = 0;   // DEM's time step

  double rate() const { return static_cast<double>(collisions) / wall; }
  double per_collision(std::uint64_t k) const {
    return collisions == 0 ? 0.0 : static_cast<double>(k) / static_cast<double>(collisions);
  }
};

void advance_collisions(Engine& e, double per_particle) {
  const auto more = static_cast<std::uint64_t>(per_particle * static_cast<double>(e.size()) / 2);
  const std::uint64_t target = e.counters().collisions + more;
  while (e.counters().collisions < target) {
    if (e.step() == EventKind::kNone) throw std::runtime_error("the engine ran out of events");
  }
}

// A fresh engine from `start`, warmed up, then timed. `deferred`: soft contacts get their
// post-contact motion at once where they can (the default), else each waits for its release
// event.
Sample event_driven(const ParticleSystem<3>& start, const Environment<3>& env, double timed,
                    bool full_scans, bool deferred = true) {
  EngineOptions options;
  options.defer_soft_releases = deferred;
  options.incremental_crossings = !full_scans;
  Engine e(start, StartMode::kPredict, options, env);
  advance_collisions(e, kWarmup);
  const EventCounters c0 = e.counters();
  const double t0 = e.time(), ke0 = e.kinetic_energy() + e.potential_energy();
  const auto w0 = Clock::now();
  advance_collisions(e, timed);
  Sample s;
  s.wall = seconds_since(w0);
  const EventCounters& c = e.counters();
  s.sim = e.time() - t0;
  s.energy_ratio = (e.kinetic_energy() + e.potential_energy()) / ke0;
  s.collisions = c.collisions - c0.collisions;
  s.events = c.events - c0.events;
  s.contacts = c.soft_contacts - c0.soft_contacts;
  s.fallbacks = c.soft_overlap_fallbacks - c0.soft_overlap_fallbacks;
  s.early = c.soft_early_releases - c0.soft_early_releases;
  s.direct = c.soft_direct_maps - c0.soft_direct_maps;
  return s;
}

// A fresh DEM integrator from `start` at its default time step, warmed up, then timed.
Sample dem(const ParticleSystem<3>& start, const Law& law, long steps) {
  DemOptions options;
  options.steps_per_contact = kStepsPerContact;
  options.reference_speed = law.reference_speed;  // Hertz: v_ref (dashpot: unused)
  DemIntegrator<3> d(start, law.law, options);
  d.step(kDemWarmup);
  const std::uint64_t c0 = d.collisions();
  const double t0 = d.time(), ke0 = d.kinetic_energy() + d.potential_energy();
  const auto w0 = Clock::now();
  d.step(steps);
  Sample s;
  s.wall = seconds_since(w0);
  s.sim = d.time() - t0;
  s.energy_ratio = (d.kinetic_energy() + d.potential_energy()) / ke0;
  s.collisions = d.collisions() - c0;
  s.steps = steps;
  s.dt = d.dt();
  return s;
}

struct Variant {
  std::string label;
  std::function<Sample()> measure;
  std::vector<Sample> samples;

  const Sample& best() const {
    return *std::max_element(samples.begin(), samples.end(),
                             [](const Sample& a, const Sample& b) { return a.rate() < b.rate(); });
  }
  double spread() const {
    double lo = best().rate(), hi = lo;
    for (const Sample& s : samples) lo = std::min(lo, s.rate());
    return hi > 0 ? (hi - lo) / hi : 0.0;
  }
};

// Three significant digits, no exponent: 217, 28.4, 0.500, 0.00241.
std::string three_digits(double x) {
  const int decimals = x > 0 ? std::max(0, 2 - static_cast<int>(std::floor(std::log10(x)))) : 0;
  return fmt::format("{:.{}f}", x, decimals);
}

struct Ratio {
  double best = 0, lo = 0, hi = 0;
  std::size_t pairs = 0;
  std::string text() const {
    if (pairs < 2) return three_digits(best);
    return fmt::format("**{}** ({}–{})", three_digits(best), three_digits(lo), three_digits(hi));
  }
};

// collisions/s of v over those of ref: best/best, and the range over the interleaved pairs.
Ratio ratio(const Variant& v, const Variant& ref) {
  Ratio r{v.best().rate() / ref.best().rate(), 1e300, 0, 0};
  for (std::size_t k = 0; k < v.samples.size() && k < ref.samples.size(); ++k) {
    const double x = v.samples[k].rate() / ref.samples[k].rate();
    r.lo = std::min(r.lo, x);
    r.hi = std::max(r.hi, x);
    ++r.pairs;
  }
  return r;
}

// Event-driven rates in millions, DEM rates (hundreds to thousands) in full.
std::string mega(double rate) {
  return rate >= 1e4 ? fmt::format("{:.3f} M", rate / 1e6) : fmt::format("{:.0f}", rate);
}

// ---------------------------------------------------------------------------------------------
// Output

std::string detail_header() {
  return "| η | law | τ/t_c | method | timed | sim. time | collisions/s | events/coll | "
         "exception A/coll | exception B/coll | direct maps/contact | KE end/start | spread | "
         "vs DEM | vs hard spheres |\n"
         "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
}

std::string summary_header() {
  return "| η | law | τ | t_c | τ/t_c | table build s (nodes) | mapped coll/s | DEM coll/s | "
         "**mapped / DEM** | hard-sphere coll/s | mapped / hard | exception A | exception B | "
         "direct maps | DEM ns/particle-step | DEM coll counted / Enskog |\n"
         "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
}

struct Case {
  double eta = 0, ratio = 0, tau = 0, contact_time = 0;
  Law law;
  double build_seconds = 0;
  std::string nodes;
  double dem_expected = 0;  // Enskog collisions in a DEM sample
};

std::string detail_row(const Case& c, const Variant& v, const Variant* dem_ref,
                       const Variant* hard_ref) {
  const Sample& b = v.best();
  const bool is_dem = b.steps > 0;
  const bool soft = !is_dem && b.contacts + b.fallbacks > 0;
  const std::string timed = is_dem ? fmt::format("{} steps, {} coll", b.steps, b.collisions)
                                   : fmt::format("{} coll", b.collisions);
  const auto frac = [&](std::uint64_t k, std::uint64_t of) {
    return of == 0 ? std::string("0")
                   : fmt::format("{:.2e}", static_cast<double>(k) / static_cast<double>(of));
  };
  return fmt::format(
      "| {:g} | {} | {:g} | {} | {} | {:.3g} | {} | {} | {} | {} | {} | {:.3f} | {:.0f} % | {} "
      "| {} |\n",
      c.eta, c.law.name, c.ratio, v.label, timed, b.sim, mega(b.rate()),
      is_dem ? "–" : fmt::format("{:.3f}", b.per_collision(b.events)),
      soft ? frac(b.fallbacks, b.collisions) : "–", soft ? frac(b.early, b.collisions) : "–",
      soft ? frac(b.direct, b.contacts + b.fallbacks) : "–", b.energy_ratio, 100.0 * v.spread(),
      dem_ref == nullptr ? "1" : ratio(v, *dem_ref).text(),
      hard_ref == nullptr ? "1" : ratio(v, *hard_ref).text());
}

std::string summary_row(const Case& c, const Variant& hard, const Variant& mapped,
                        const Variant& dem_v, std::uint64_t n) {
  const Sample& m = mapped.best();
  const Sample& d = dem_v.best();
  const double ns = d.wall / (static_cast<double>(d.steps) * static_cast<double>(n)) * 1e9;
  const auto pct = [](std::uint64_t k, std::uint64_t of) {
    return fmt::format("{:.2g} %",
                       of == 0 ? 0.0 : 100.0 * static_cast<double>(k) / static_cast<double>(of));
  };
  return fmt::format(
      "| {:g} | {} | {:.3g} | {:.3g} | {:g} | {:.1f} ({}) | {} | {} | {} | {} | {} | {} | {} | {} "
      "| {:.1f} | {} / {:.0f} |\n",
      c.eta, c.law.name, c.tau, c.contact_time, c.ratio, c.build_seconds, c.nodes, mega(m.rate()),
      mega(d.rate()), ratio(mapped, dem_v).text(), mega(hard.best().rate()),
      ratio(mapped, hard).text(), pct(m.fallbacks, m.collisions), pct(m.early, m.collisions),
      pct(m.direct, m.contacts + m.fallbacks), ns, d.collisions, c.dem_expected);
}

// A fresh temporary directory, removed with its tables when the object goes.
struct TempDir {
  std::filesystem::path path;
  TempDir() {
    std::string pattern =
        (std::filesystem::temp_directory_path() / "kairos-soft-bench-XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("cannot create a temp dir");
    path = pattern;
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
};

// The start state as a LAMMPS data file (atom_style sphere: diameter and density, so that the
// mass is m; angular velocities zero), for bench/lammps_soft.sh.
void write_lammps_data(const std::filesystem::path& file, const ParticleSystem<3>& s) {
  std::string text = fmt::format(
      "LAMMPS data file: kairos_bench --suite soft start state ({} spheres, d = {:g}, m = {:g})\n\n"
      "{} atoms\n1 atom types\n\n",
      s.size(), kDiameter, kMass, s.size());
  const char* axes[3] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a)
    text += fmt::format("0 {:.17g} {}lo {}hi\n", s.box[a], axes[a], axes[a]);
  const double density = kMass / (std::numbers::pi / 6.0 * kDiameter * kDiameter * kDiameter);
  text += "\nAtoms # sphere\n\n";
  for (std::size_t i = 0; i < s.size(); ++i) {
    Vec<3> x = s.position(i, s.time);
    for (int a = 0; a < 3; ++a) x[a] = wrap_into_box(x[a], s.box[a]);
    text += fmt::format("{} 1 {:g} {:.17g} {:.17g} {:.17g} {:.17g}\n", i + 1, kDiameter, density,
                        x[0], x[1], x[2]);
  }
  text += "\nVelocities\n\n";
  for (std::size_t i = 0; i < s.size(); ++i) {
    const Vec<3>& v = s.kinematics[i].vel;
    text += fmt::format("{} {:.17g} {:.17g} {:.17g} 0 0 0\n", i + 1, v[0], v[1], v[2]);
  }
  write_text_atomically(file, text);
}

// The same case for LAMMPS: the same contact law in its pair style's parameters (gran/hooke:
// F = kn d - m_eff gn v_n; gran/hertz/history: F = sqrt(d R_eff) (kn d - m_eff gn v_n), with
// R_eff = d/4, so kn = rho / sqrt(R_eff) and gn = 1.5 A rho / (m_eff sqrt(R_eff))), frictionless,
// DEM's time step, warm-up and timed steps.
void write_lammps_input(const std::filesystem::path& file, const std::string& data, const Case& c,
                        double dt, long steps) {
  std::string pair;
  const SoftContactLaw& law = c.law.law;
  if (c.law.name == "dashpot") {
    pair =
        fmt::format("gran/hooke {:.17g} 0.0 {:.17g} 0.0 0.0 0", law.stiffness, law.damping / kMu);
  } else {
    const double sqrt_r = std::sqrt(kDiameter / 4.0);
    pair = fmt::format("gran/hertz/history {:.17g} NULL {:.17g} NULL 0.0 0", law.stiffness / sqrt_r,
                       1.5 * law.damping * law.stiffness / (kMu * sqrt_r));
  }
  const std::string text = fmt::format(
      "# kairos_bench --suite soft, eta {:g}, {}, tau/t_c {:g}: DEM cost in LAMMPS "
      "(bench/lammps_soft.sh)\n"
      "units lj\natom_style sphere\ndimension 3\nboundary p p p\nnewton off\n"
      "comm_modify vel yes\nread_data {}\npair_style {}\npair_coeff * *\n"
      "neighbor 0.3 bin\nneigh_modify delay 0 every 1 check yes\ntimestep {:.17g}\n"
      "fix nve all nve/sphere\nthermo_modify norm no\nthermo 1000000\nrun {}\nrun {}\n",
      c.eta, c.law.name, c.ratio, data, pair, dt, kDemWarmup, steps);
  write_text_atomically(file, text);
}

}  // namespace

void validate(const SoftPlan& p) {
  for (const std::string& c : p.cases) {
    if (c != "dashpot" && c != "hertz") {
      throw std::invalid_argument(
          fmt::format("--case \"{}\" is unknown; use dashpot and/or hertz", c));
    }
  }
  if (p.particles != 0 && p.particles < 100) {
    throw std::invalid_argument("--particles: the soft cases need at least 100");
  }
  for (double eta : p.etas) {
    if (!(eta > 0 && eta < 0.5)) {
      throw std::invalid_argument(fmt::format("--eta {} is invalid: use (0, 0.5)", eta));
    }
  }
  for (double r : p.contact_ratios) {
    if (!(r >= 10 && std::isfinite(r))) {
      throw std::invalid_argument(
          fmt::format("--contact-ratio {} is invalid: mean free time / contact time >= 10", r));
    }
  }
  if (!(p.restitution > 0 && p.restitution <= 1)) {
    throw std::invalid_argument("the restitution must be in (0, 1]");
  }
  if (!(p.equilibrate >= 0 && std::isfinite(p.equilibrate)) ||
      !(p.timed >= 0 && std::isfinite(p.timed))) {
    throw std::invalid_argument("--equilibrate and --timed must be finite and >= 0");
  }
  if (p.dem_steps < 0) throw std::invalid_argument("--dem-steps must be >= 0");
  if (p.repeat < 1) throw std::invalid_argument("--repeat must be >= 1");
}

std::string soft_protocol(const SoftPlan& p) {
  return fmt::format(
      "Protocol (soft): 3D, N = {}, σ = m = 1, periodic; per η the elastic hard-sphere fluid "
      "from the fcc lattice equilibrated {:g} collisions per particle (untimed) is the start of "
      "every sample; τ = 1/ω_E (Enskog, measured T); laws with head-on restitution e = {:g} "
      "(Hertz: at v_ref = 2 sqrt(T/m)) and contact time t_c = τ/R; lookup tables built per case "
      "({}), timed apart; variants interleaved, best of {}: hard spheres (elastic) and mapped "
      "(tables) warmed up {:g} then timed {:g} collisions per particle (calendar queue, {} cell "
      "crossings), DEM at dt = t_c/{:g} warmed up {} then timed {} steps; ratios best/best and "
      "(in brackets) the range over the interleaved triples.",
      p.particles ? p.particles : kParticles, p.equilibrate, p.restitution,
      p.table_cache.empty() ? "fresh temporary cache" : "cache " + p.table_cache, p.repeat, kWarmup,
      p.timed > 0 ? p.timed : kTimed, p.full_crossing_scans ? "full-scan" : "incremental",
      kStepsPerContact, kDemWarmup, p.dem_steps > 0 ? p.dem_steps : kDemSteps);
}

void run_soft(const SoftPlan& plan, const std::function<void(const std::string&)>& emit) {
  const std::uint64_t n = plan.particles ? plan.particles : kParticles;
  const double timed = plan.timed > 0 ? plan.timed : kTimed;
  const long dem_steps = plan.dem_steps > 0 ? plan.dem_steps : kDemSteps;
  const bool full = plan.full_crossing_scans;
  std::optional<TempDir> temp;
  std::filesystem::path cache = plan.table_cache;
  if (cache.empty()) {
    temp.emplace();
    cache = temp->path;
  }
  std::vector<std::string> notes, summary;
  std::string lammps_cases =
      "input\teta\tlaw\tratio\tparticles\tsteps\tenskog_collisions\tmapped_coll_per_s\t"
      "dem_coll_per_s\tdem_ns_per_particle_step\tdem_energy_ratio\n";
  emit("\n" + detail_header());
  for (double eta : plan.etas) {
    const auto w0 = Clock::now();
    const Gas gas = equilibrated_gas(n, eta, plan.equilibrate);
    notes.push_back(fmt::format(
        "η = {:g}: box {:.4g}, n = {:.4g}, T = {:.4f} (measured), g(σ) = {:.4f}, ω_E = {:.4f}, "
        "τ = {:.4f}; start state in {:.1f} s",
        eta, gas.start.box[0], gas.density, gas.temperature, contact_value(3, eta), gas.frequency,
        gas.tau(), seconds_since(w0)));
    std::string data_name;
    if (!plan.lammps_dir.empty()) {
      std::filesystem::create_directories(plan.lammps_dir);
      data_name = fmt::format("eta{:g}.data", eta);
      write_lammps_data(std::filesystem::path(plan.lammps_dir) / data_name, gas.start);
    }
    for (const std::string& name : plan.cases) {
      for (double r : plan.contact_ratios) {
        Case c;
        c.eta = eta;
        c.ratio = r;
        c.tau = gas.tau();
        c.contact_time = gas.tau() / r;
        c.law = make_law(name, c.contact_time, plan.restitution, gas.temperature);
        Environment<3> env;
        env.species = 1;
        env.soft = {c.law.law};
        env.soft_wall = {c.law.law};
        env.soft_collisions = SoftCollisions::kMapped;
        SoftTableSettings settings;
        settings.cache_dir = cache;
        const std::vector<SoftTableUse> tables = attach_soft_tables(env, gas.start, settings);
        for (const SoftTableUse& t : tables) {
          c.build_seconds += t.report.build_seconds;
          std::string nodes;
          for (int k : t.report.nodes) nodes += (nodes.empty() ? "" : "×") + std::to_string(k);
          c.nodes += (c.nodes.empty() ? "" : ", ") + nodes;
          notes.push_back(fmt::format(
              "η = {:g}, {}, τ/t_c = {:g}: {}; table {} speeds {:.3g}–{:.3g}, {} nodes, built in "
              "{:.2f} s{} ({} refinements, max errors {:.1e} {:.1e} {:.1e} {:.1e})",
              eta, name, r, c.law.parameters, t.contact, t.spec.min_normal_speed,
              t.spec.max_normal_speed, nodes, t.report.build_seconds,
              t.report.from_cache ? " (from the cache)" : "", t.report.refinements,
              t.report.max_error[0], t.report.max_error[1], t.report.max_error[2],
              t.report.max_error[3]));
        }
        std::vector<Variant> vs;
        vs.push_back({"hard spheres, elastic",
                      [&] { return event_driven(gas.start, {}, timed, full); },
                      {}});
        vs.push_back(
            {"mapped (tables)", [&] { return event_driven(gas.start, env, timed, full); }, {}});
        vs.push_back({"DEM, dt = t_c/50", [&] { return dem(gas.start, c.law, dem_steps); }, {}});
        vs.push_back({"mapped, every release an event",
                      [&] { return event_driven(gas.start, env, timed, full, false); },
                      {}});
        for (int k = 0; k < plan.repeat; ++k)
          for (Variant& v : vs) v.samples.push_back(v.measure());
        const double dem_dt = vs[2].best().dt;
        c.dem_expected =
            0.5 * static_cast<double>(n) * gas.frequency * dem_dt * static_cast<double>(dem_steps);
        if (!plan.lammps_dir.empty()) {
          const std::string input = fmt::format("eta{:g}-{}-R{:g}.in", eta, name, r);
          write_lammps_input(std::filesystem::path(plan.lammps_dir) / input, data_name, c, dem_dt,
                             dem_steps);
          const Sample& dem_best = vs[2].best();
          lammps_cases += fmt::format(
              "{}\t{:g}\t{}\t{:g}\t{}\t{}\t{:.6g}\t{:.6g}\t{:.6g}\t{:.6g}\t{:.6f}\n", input, eta,
              name, r, n, dem_steps, c.dem_expected, vs[1].best().rate(), dem_best.rate(),
              1e9 * dem_best.wall / (static_cast<double>(n) * static_cast<double>(dem_steps)),
              dem_best.energy_ratio);
        }
        emit(detail_row(c, vs[0], &vs[2], nullptr) + detail_row(c, vs[1], &vs[2], &vs[0]) +
             detail_row(c, vs[3], &vs[2], &vs[0]) + detail_row(c, vs[2], nullptr, &vs[0]));
        summary.push_back(summary_row(c, vs[0], vs[1], vs[2], n));
      }
    }
  }
  if (!plan.lammps_dir.empty())
    write_text_atomically(std::filesystem::path(plan.lammps_dir) / "cases.tsv", lammps_cases);
  emit("\n" + summary_header());
  for (const std::string& row : summary) emit(row);
  emit("\n");
  for (const std::string& note : notes) emit("- " + note + "\n");
}

}  // namespace kairos::bench
