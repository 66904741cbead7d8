// Bannerman's stepped spring-dashpot (docs/physics.md#spring-dashpot-by-steps, [[potential]]
// kind = "spring_dashpot") against the Müller-Pöschel collision map of the continuous
// spring-dashpot (docs/validation.md, "Stepped spring-dashpot (Bannerman) vs the mapping";
// bench/README.md).
//
//   1. Head-on restitution e(N) of the stepped model in the engine (two particles, m = 1 and 2)
//      against the closed forms of docs/physics.md#dashpot-head-on (force-zero end with the cap,
//      naive end without) and the map (exact to ~1e-13), beta/omega_0 = 0.1, core 1.5 v/omega_0
//      inside the contact.
//   2. One oblique collision (v_t / v_n = 1): the outgoing relative speed and its direction,
//      stepped (several N) vs the map vs an instantaneous hard-sphere collision with the same
//      head-on e.
//   3. Cost in one dilute gas (3D, N particles, packing fraction 0.05 of the contact diameter 1,
//      T = 1, contact time = mean free time / R, e = 0.9): the mapped event-driven soft spheres
//      (lookup tables) and the stepped model at a few N, same k and gamma, same start, timed
//      interleaved. Per contact: events and wall time.
//
// Usage: spring_dashpot_bench [particles (4000)] [contacts per particle timed (2)] [R (100)]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "analysis/granular_theory.hpp"
#include "engine/event_engine.hpp"
#include "init/initial_state.hpp"
#include "interactions/potential_spec.hpp"
#include "interactions/soft_contact.hpp"
#include "model/environment.hpp"
#include "run/soft_tables_setup.hpp"
#include "scheduler/calendar_queue.hpp"

namespace {

using namespace kairos;
using Engine = EventEngine<3, CalendarQueue>;
using Clock = std::chrono::steady_clock;

// ---------------------------------------------------------------------------------------------
// 1 and 2: two particles

constexpr double kMassI = 1.0, kMassJ = 2.0, kMu = kMassI * kMassJ / (kMassI + kMassJ);
constexpr double kPenetration = 0.02;  // v / omega_0 at v = 1
constexpr double kCore = 1.0 - 1.5 * kPenetration;
const double kK = kMu / (kPenetration * kPenetration);

StepTable pair_table(int steps, double zeta, bool force_zero) {
  PotentialSpec p;
  p.kind = "spring_dashpot";
  p.stiffness = kK;
  p.length = 1.0;
  p.steps = steps;
  p.damping = 2.0 * zeta * std::sqrt(kK * kMu);
  p.force_zero = force_zero;
  return make_step_table(p, kCore, 3);
}

struct PairResult {
  Vec<3> g_in{}, g_out{};
  std::uint64_t events = 0;
};

PairResult two_body(const StepTable& table, double v_n, double v_t, double m_i = kMassI,
                    double m_j = kMassJ) {
  const double g = std::hypot(v_n, v_t), b = v_t / g;
  ParticleSystem<3> s;
  s.box = {40.0, 40.0, 40.0};
  const Vec<3> vi{-g * m_j / (m_i + m_j), 0.0, 0.0};
  const Vec<3> vj{g * m_i / (m_i + m_j), 0.0, 0.0};
  const double core = table.core();
  s.kinematics = {{{20.0 + std::sqrt(1.0 - b * b) + 0.01, 20.0 + b, 20.0}, vi, 0.0, 0.5 * core},
                  {{20.0, 20.0, 20.0}, vj, 0.0, 0.5 * core}};
  s.mass = {m_i, m_j};
  s.species = {0, 0};
  s.species_names = {"A"};
  Environment<3> env;
  env.species = 1;
  env.tables = {table};
  env.pair_table = {0};
  Engine e(s, StartMode::kPredict, {}, env);
  while (e.step() != EventKind::kNone) {
    if (e.step_captures() > 0 && e.potential_energy() == 0.0) break;
  }
  if (e.counters().collisions != e.counters().step_crossings + e.counters().step_bounces)
    throw std::runtime_error("the pair reached the hard core");
  return {vi - vj, e.velocity(0, e.time()) - e.velocity(1, e.time()),
          e.counters().step_crossings + e.counters().step_bounces};
}

void restitution_vs_steps() {
  const double zeta = 0.1;
  const double sp = dashpot_head_on_reduced(zeta).restitution;
  const double naive = dashpot_head_on_naive_reduced(zeta).restitution;
  const SoftContactLaw law = SoftContactLaw::linear_dashpot(kK, 2.0 * zeta * std::sqrt(kK * kMu));
  ReducedCollision head_on = reduce_collision(law, kMu, 1.0, 1.0, 0.0).reduced;
  const double mapped = -collision_map(head_on).eps_rdot;
  fmt::print("## 1. Head-on restitution, beta/omega_0 = {}, core 1.5 v/omega_0 deep\n\n", zeta);
  fmt::print(
      "closed form (force-zero end) e_SP = {:.7f}; naive end {:.7f}; the map: {:.7f} "
      "(|map - e_SP| = {:.1e})\n\n",
      sp, naive, mapped, std::abs(mapped - sp));
  fmt::print(
      "| N | e (cap) | N (e_SP - e) | e (no cap) | N (e_naive - e) | step events per "
      "contact |\n|---:|---:|---:|---:|---:|---:|\n");
  for (const int n : {10, 30, 100, 300, 1000, 4000, 10000}) {
    const PairResult c = two_body(pair_table(n, zeta, true), 1.0, 0.0);
    const PairResult u = two_body(pair_table(n, zeta, false), 1.0, 0.0);
    const double ec = -c.g_out[0] / c.g_in[0], eu = -u.g_out[0] / u.g_in[0];
    fmt::print("| {} | {:.7f} | {:.4f} | {:.7f} | {:.4f} | {} |\n", n, ec, n * (sp - ec), eu,
               n * (naive - eu), c.events);
  }
  fmt::print("\n");
}

void oblique() {
  const double zeta = 0.1, v_n = 1.0, v_t = 1.0;
  const SoftContactLaw law = SoftContactLaw::linear_dashpot(kK, 2.0 * zeta * std::sqrt(kK * kMu));
  const double g = std::hypot(v_n, v_t), b = v_t / g;
  PairState at;
  at.r_i = {std::sqrt(1.0 - b * b), b, 0.0};
  at.v_i = {-g * kMassJ / (kMassI + kMassJ), 0.0, 0.0};
  at.v_j = {g * kMassI / (kMassI + kMassJ), 0.0, 0.0};
  const SoftCollision m = soft_collision(law, {kMassI, kMassJ, 0.5, 0.5}, at);
  const Vec<3> g_in = at.v_i - at.v_j, g_map = m.state.v_i - m.state.v_j;
  const double e = dashpot_head_on_reduced(zeta).restitution;
  const Vec<3> n = at.r_i;
  const Vec<3> g_hard = g_in - ((1.0 + e) * dot(g_in, n)) * n;
  const auto deflection = [&](const Vec<3>& out) {
    return std::acos(std::clamp(dot(out, g_in) / std::sqrt(norm2(out) * norm2(g_in)), -1.0, 1.0)) *
           180.0 / M_PI;
  };
  const auto ratio = [&](const Vec<3>& out) { return std::sqrt(norm2(out) / norm2(g_in)); };
  fmt::print("## 2. Oblique collision, v_t / v_n = {}, beta/omega_0 = {}\n\n", v_t / v_n, zeta);
  fmt::print(
      "| model | \\|g'\\| / \\|g\\| | deflection (deg) | vs map: speed | vs map: angle "
      "(deg) |\n|---|---:|---:|---:|---:|\n");
  const double d_map = deflection(g_map), r_map = ratio(g_map);
  fmt::print("| map (exact) | {:.6f} | {:.4f} | – | – |\n", r_map, d_map);
  for (const int steps : {30, 100, 1000, 4000}) {
    const PairResult c = two_body(pair_table(steps, zeta, true), v_n, v_t);
    fmt::print("| steps, N = {} | {:.6f} | {:.4f} | {:+.1e} | {:+.1e} |\n", steps, ratio(c.g_out),
               deflection(c.g_out), ratio(c.g_out) - r_map, deflection(c.g_out) - d_map);
  }
  fmt::print("| hard sphere, same head-on e | {:.6f} | {:.4f} | {:+.1e} | {:+.1e} |\n\n",
             ratio(g_hard), deflection(g_hard), ratio(g_hard) - r_map, deflection(g_hard) - d_map);
}

// ---------------------------------------------------------------------------------------------
// 3: the gas

struct Sample {
  double wall = 0;
  std::uint64_t contacts = 0, events = 0;
  double per_contact_us() const { return 1e6 * wall / static_cast<double>(contacts); }
  double events_per_contact() const {
    return static_cast<double>(events) / static_cast<double>(contacts);
  }
};

// Runs until `contacts` more contacts happened (after a warm-up of `warm`), timed.
template <class Contacts>
Sample timed(const ParticleSystem<3>& start, const Environment<3>& env, std::uint64_t warm,
             std::uint64_t contacts, Contacts count) {
  Engine e(start, StartMode::kPredict, {}, env);
  while (count(e) < warm) e.step();
  const std::uint64_t c0 = count(e), ev0 = e.counters().events;
  const auto t0 = Clock::now();
  while (count(e) < c0 + contacts) e.step();
  Sample s;
  s.wall = std::chrono::duration<double>(Clock::now() - t0).count();
  s.contacts = count(e) - c0;
  s.events = e.counters().events - ev0;
  return s;
}

void gas(std::uint64_t n, double per_particle, double ratio) {
  SystemConfig sys;
  sys.dimension = 3;
  sys.particles = n;
  sys.packing_fraction = 0.05;
  sys.lattice = "fcc";
  sys.seed = 1;
  std::mt19937_64 rng(sys.seed);
  Engine hs(to_particle_system<3>(make_initial_state<3>(sys, rng)));
  while (hs.counters().collisions < 10 * n) hs.step();  // 20 collisions per particle
  ParticleSystem<3> start = hs.export_state(false);
  start.counters = {};
  double volume = 1, ke = 0;
  for (const double side : start.box) volume *= side;
  for (const auto& k : start.kinematics) ke += 0.5 * norm2(k.vel);
  const double temperature = 2.0 * ke / (3.0 * static_cast<double>(n));
  const double tau =
      1.0 / enskog_collision_frequency(3, static_cast<double>(n) / volume, 1.0, temperature, 1.0);
  const double mu = 0.5, e = 0.9;
  const double zeta = dashpot_zeta_for_restitution(e);
  const double omega0 = dashpot_head_on_reduced(zeta).contact_time / (tau / ratio);
  const double k = mu * omega0 * omega0, gamma = 2.0 * zeta * std::sqrt(k * mu);
  // The core: 1.5 times the elastic penetration at a closing speed of 8 sqrt(T / m) (no pair
  // of this gas comes close: the fastest closing speeds are ~6; a damped pair penetrates less).
  const double v_max = 8.0 * std::sqrt(temperature);
  const double depth = 1.5 * v_max / omega0;
  fmt::print("## 3. Cost in a dilute gas\n\n");
  fmt::print(
      "N = {}, packing fraction 0.05 (contact diameter 1), T = {:.4f}, mean free time "
      "tau = {:.4g}, contact time tau/{} (k = {:.4g}, gamma = {:.4g}, e = {}); steps "
      "from r = 1 to the core 1 - {:.4g} (1.5 v_max/omega_0, v_max = 8 sqrt(T)); "
      "{} contacts per particle timed after 0.5 of warm-up, interleaved, best of 3.\n\n",
      n, temperature, tau, ratio, k, gamma, e, depth, per_particle);

  Environment<3> mapped;
  mapped.species = 1;
  mapped.soft = {SoftContactLaw::linear_dashpot(k, gamma)};
  mapped.soft_collisions = SoftCollisions::kMapped;
  SoftTableSettings settings;
  settings.cache_dir = std::filesystem::temp_directory_path() / "kairos-spring-dashpot-bench";
  const auto t_build = Clock::now();
  attach_soft_tables(mapped, start, settings);
  fmt::print("(map table built or loaded in {:.1f} s, not timed below)\n\n",
             std::chrono::duration<double>(Clock::now() - t_build).count());

  ParticleSystem<3> cored = start;
  for (auto& kin : cored.kinematics) kin.radius = 0.5 * (1.0 - depth);
  struct Case {
    std::string label;
    Environment<3> env;
    const ParticleSystem<3>* start;
    bool steps;
    std::vector<Sample> samples;
  };
  std::vector<Case> cases;
  cases.push_back({"mapped (tables)", mapped, &start, false, {}});
  for (const int steps : {30, 100, 300, 1000}) {
    PotentialSpec p;
    p.kind = "spring_dashpot";
    p.stiffness = k;
    p.length = 1.0;
    p.steps = steps;
    p.damping = gamma;
    Environment<3> env;
    env.species = 1;
    env.tables = {make_step_table(p, 1.0 - depth, 3)};
    env.pair_table = {0};
    // Head-on e of this table at the rms normal impact speed 2 sqrt(T) and at half of it.
    const double v_rms = 2.0 * std::sqrt(temperature);
    const PairResult at = two_body(env.tables[0], v_rms, 0.0, 1.0, 1.0);
    const PairResult slow = two_body(env.tables[0], 0.5 * v_rms, 0.0, 1.0, 1.0);
    cases.push_back({fmt::format("steps, N = {} (head-on e {:.4f} at v_n = 2√T, {:.4f} at √T)",
                                 steps, at.g_out[0] / -at.g_in[0], slow.g_out[0] / -slow.g_in[0]),
                     env,
                     &cored,
                     true,
                     {}});
  }
  const auto warm = static_cast<std::uint64_t>(0.25 * static_cast<double>(n));
  const auto contacts = static_cast<std::uint64_t>(per_particle * static_cast<double>(n) / 2);
  for (int r = 0; r < 3; ++r) {
    for (Case& c : cases) {
      c.samples.push_back(c.steps ? timed(*c.start, c.env, warm, contacts,
                                          [](const Engine& en) { return en.step_captures(); })
                                  : timed(*c.start, c.env, warm, contacts, [](const Engine& en) {
                                      return en.counters().collisions;
                                    }));
    }
  }
  fmt::print(
      "| model | events per contact | wall per contact (µs) | contacts per second | "
      "vs mapped |\n|---|---:|---:|---:|---:|\n");
  double best_mapped = 0;
  for (const Case& c : cases) {
    const Sample& b = *std::min_element(
        c.samples.begin(), c.samples.end(),
        [](const Sample& x, const Sample& y) { return x.per_contact_us() < y.per_contact_us(); });
    if (!c.steps) best_mapped = b.per_contact_us();
    fmt::print("| {} | {:.2f} | {:.3f} | {:.3g} | {:.1f}x |\n", c.label, b.events_per_contact(),
               b.per_contact_us(), 1e6 / b.per_contact_us(), b.per_contact_us() / best_mapped);
  }
  fmt::print("\n");
}

}  // namespace

int main(int argc, char** argv) {
  const std::uint64_t n = argc > 1 ? std::strtoull(argv[1], nullptr, 10) : 4000;
  const double per_particle = argc > 2 ? std::atof(argv[2]) : 2.0;
  const double ratio = argc > 3 ? std::atof(argv[3]) : 100.0;
  restitution_vs_steps();
  oblique();
  gas(n, per_particle, ratio);
  return 0;
}
