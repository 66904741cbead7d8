// Two proofs that the event-driven soft-sphere method (Müller–Pöschel collision mapping,
// docs/physics.md#event-driven-soft-contacts) reproduces force-based dynamics (issue 6, "Proof"):
// the measurements shared by the validation program (validation/soft_proofs.cpp) and the tests
// (tests/engine/test_soft_proofs.cpp).
//
// 1. Trajectory divergence of a dilute gas: the same initial state run by the mapped event-driven
//    engine, by the instantaneous hard-sphere model with the same head-on restitution, and by the
//    DEM integrator at a small time step (the reference); particle position differences (minimum
//    image, per radius) sampled in time.
// 2. Isolated binary collisions over v_t / v_n (docs/physics.md#hard-sphere-failure): the
//    outgoing relative velocity and the effective normal restitution against the initial normal
//    n0, for the hard model, the mapped engine, the DEM at a tiny time step and direct
//    integration of Newton's equations.
//
// Units: diameter 1 (gas), mass 1, kT = 1. A law is given by its reduced parameters (l~, c_dis)
// at normal impact speed 1 (law_with_reduced_parameters).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <random>
#include <stdexcept>
#include <vector>

#include "core/particle_system.hpp"
#include "dem/dem_integrator.hpp"
#include "engine/event_engine.hpp"
#include "init/initial_state.hpp"
#include "interactions/soft_contact.hpp"
#include "io/config.hpp"
#include "model/environment.hpp"
#include "run/soft_tables_setup.hpp"
#include "scheduler/calendar_queue.hpp"

namespace kairos::proofs {

using Engine = EventEngine<3, CalendarQueue>;

// The law of a pair (reduced mass mu, contact distance l) whose reduced parameters at normal
// impact speed v_n are l~ = l / (v_n T) and c_dis (docs/physics.md#reduced-units): dashpot
// T = sqrt(mu / k), c_dis = gamma / sqrt(k mu); Hertz T = (mu^2 / (rho^2 v_n))^(1/5),
// c_dis = A / T.
inline SoftContactLaw law_with_reduced_parameters(SoftModel model, double mu, double l,
                                                  double l_tilde, double c_dis, double v_n = 1.0) {
  const double T = l / (l_tilde * v_n);
  if (model == SoftModel::LinearDashpot) {
    const double k = mu / (T * T);
    return SoftContactLaw::linear_dashpot(k, c_dis * std::sqrt(k * mu));
  }
  const double rho = mu / (std::pow(T, 2.5) * std::sqrt(v_n));
  return SoftContactLaw::viscoelastic_hertz(rho, c_dis * T);
}

inline const char* model_name(SoftModel m) {
  return m == SoftModel::LinearDashpot ? "dashpot" : "hertz";
}

inline Vec<3> minimum_image(Vec<3> d, const Vec<3>& box) {
  for (int a = 0; a < 3; ++a) d[a] = std::remainder(d[a], box[a]);
  return d;
}

inline double angle_between(const Vec<3>& a, const Vec<3>& b) {
  const Vec<3> c{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
  return std::atan2(std::sqrt(norm2(c)), dot(a, b));
}

// 1 for every particle overlapping another (r < R_i + R_j, minimum image), found with a cell
// grid (brute force when the box is less than three cells wide).
inline std::vector<std::uint8_t> overlapping(const Vec<3>& box, const std::vector<Vec<3>>& pos,
                                             const std::vector<double>& radius) {
  const std::size_t n = pos.size();
  std::vector<std::uint8_t> mask(n, 0);
  const double dmax = 2.0 * *std::max_element(radius.begin(), radius.end());
  auto test = [&](std::size_t i, std::size_t j) {
    const double l = radius[i] + radius[j];
    if (norm2(minimum_image(pos[i] - pos[j], box)) < l * l) mask[i] = mask[j] = 1;
  };
  int cells[3];
  for (int a = 0; a < 3; ++a) cells[a] = static_cast<int>(std::floor(box[a] / dmax));
  if (cells[0] < 3 || cells[1] < 3 || cells[2] < 3) {
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t j = i + 1; j < n; ++j) test(i, j);
    return mask;
  }
  auto cell_of = [&](const Vec<3>& x, int a) {
    const double u = x[a] - box[a] * std::floor(x[a] / box[a]);
    return std::min(cells[a] - 1, static_cast<int>(u / box[a] * cells[a]));
  };
  const std::size_t n_cells = static_cast<std::size_t>(cells[0]) * cells[1] * cells[2];
  std::vector<std::vector<std::uint32_t>> members(n_cells);
  std::vector<std::array<int, 3>> where(n);
  auto index = [&](int x, int y, int z) {
    return (static_cast<std::size_t>(z) * cells[1] + static_cast<std::size_t>(y)) * cells[0] +
           static_cast<std::size_t>(x);
  };
  for (std::size_t i = 0; i < n; ++i) {
    where[i] = {cell_of(pos[i], 0), cell_of(pos[i], 1), cell_of(pos[i], 2)};
    members[index(where[i][0], where[i][1], where[i][2])].push_back(static_cast<std::uint32_t>(i));
  }
  for (std::size_t i = 0; i < n; ++i) {
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int x = (where[i][0] + dx + cells[0]) % cells[0];
          const int y = (where[i][1] + dy + cells[1]) % cells[1];
          const int z = (where[i][2] + dz + cells[2]) % cells[2];
          for (const std::uint32_t j : members[index(x, y, z)])
            if (j > i) test(i, j);
        }
  }
  return mask;
}

// ---------------------------------------------------------------------------------------------
// 1. Trajectory divergence of a dilute gas.

struct GasSpec {
  int particles = 1000;
  double packing_fraction = 0.05;
  std::uint64_t seed = 1;
  SoftModel model = SoftModel::ViscoelasticHertz;
  double l_tilde = 200.0;  // at normal impact speed 1 (a pair of the gas: mu = 1/2, l = 1)
  double c_dis = 0.1;      // at normal impact speed 1
};

struct GasRunOptions {
  double t_end = 8.0;
  int samples = 80;  // evenly spaced in (0, t_end]
  // DEM time step: the head-on contact time at normal speed 1 over this (rounded so that the
  // sample interval is a whole number of steps).
  double dem_steps_per_contact = 1000.0;
  bool dem_check = true;  // a second DEM run at twice the time step: the reference's own error
  bool tables = true;     // lookup tables for the mapped engine (else direct integration)
  double table_tolerance = 1e-6;
  std::function<void(double)> progress;  // fraction of t_end done
};

struct Divergence {
  double rms = 0.0, max = 0.0;  // of |x - x_ref| / radius over the compared particles
  double median = 0.0;          // the typical particle
  std::size_t compared = 0;     // particles in contact in neither run
};

struct GasSample {
  double time = 0.0;
  double collisions_per_particle = 0.0;  // 2 N_coll / N of the mapped engine
  double kinetic_energy = 0.0;           // per particle, DEM
  // Exceptions A and B of the mapped engine so far (docs/physics.md#event-driven-soft-contacts):
  // its approximations.
  std::uint64_t overlap_fallbacks = 0, early_releases = 0;
  Divergence mapped, hard, dem_coarse;  // each against the DEM reference
};

struct GasRun {
  SoftContactLaw law;
  double head_on_contact_time = 0.0;  // at normal speed 1
  double head_on_restitution = 0.0;   // at normal speed 1
  double dt = 0.0;                    // of the DEM reference
  double mean_free_time = 0.0;        // N t / (2 N_coll) of the mapped engine over the run
  EventCounters mapped, hard;
  std::vector<GasSample> samples;
};

inline ParticleSystem<3> dilute_gas(const GasSpec& spec) {
  SystemConfig system;
  system.dimension = 3;
  system.particles = static_cast<std::uint64_t>(spec.particles);
  system.packing_fraction = spec.packing_fraction;
  system.lattice = "random";
  system.temperature = 1.0;
  system.seed = spec.seed;
  std::mt19937_64 rng(spec.seed);
  InitialState<3> init = make_initial_state<3>(system, rng);
  return to_particle_system(init);
}

inline Divergence divergence(const Vec<3>& box, const std::vector<Vec<3>>& x,
                             const std::vector<std::uint8_t>& contact_x,
                             const std::vector<Vec<3>>& ref,
                             const std::vector<std::uint8_t>& contact_ref,
                             const std::vector<double>& radius) {
  Divergence d;
  double sum = 0.0;
  std::vector<double> e;
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (contact_x[i] || contact_ref[i]) continue;
    const double e2 = norm2(minimum_image(x[i] - ref[i], box)) / (radius[i] * radius[i]);
    sum += e2;
    e.push_back(std::sqrt(e2));
  }
  d.compared = e.size();
  if (e.empty()) return d;
  d.rms = std::sqrt(sum / static_cast<double>(e.size()));
  d.max = *std::max_element(e.begin(), e.end());
  auto mid = e.begin() + static_cast<std::ptrdiff_t>(e.size() / 2);
  std::nth_element(e.begin(), mid, e.end());
  d.median = *mid;
  return d;
}

// Runs the three methods (four with dem_check) from the same state and samples the position
// differences. Particles in a contact at a sample time (overlapping in the DEM run, or frozen in
// a mapped contact) are left out of that sample: inside the contact window the mapped engine
// places the pair where the contact ends (docs/physics.md#event-driven-soft-contacts), by
// design.
inline GasRun run_gas_divergence(const GasSpec& spec, const GasRunOptions& options) {
  const ParticleSystem<3> start = dilute_gas(spec);
  const std::size_t n = start.size();
  GasRun run;
  run.law = law_with_reduced_parameters(spec.model, 0.5, 1.0, spec.l_tilde, spec.c_dis);
  const CollisionUnits units = reduce_collision(run.law, 0.5, 1.0, 1.0, 0.0);
  const CollisionMap head_on = collision_map(units.reduced);
  run.head_on_contact_time = head_on.eps_t * units.time_unit;
  run.head_on_restitution = -head_on.eps_rdot;

  Environment<3> env;
  env.species = 1;
  env.soft = {run.law};
  env.soft_wall = {run.law};
  if (options.tables) {
    SoftTableSettings settings;
    settings.tolerance = options.table_tolerance;
    attach_soft_tables(env, start, settings);
  }
  Environment<3> hard_env = env;
  hard_env.soft_collisions = SoftCollisions::kInstantaneous;
  Engine mapped(start, StartMode::kPredict, {}, env);
  Engine hard(start, StartMode::kPredict, {}, hard_env);

  const double interval = options.t_end / options.samples;
  const double dt_target = run.head_on_contact_time / options.dem_steps_per_contact;
  const long steps = std::max(1L, static_cast<long>(std::ceil(interval / dt_target)));
  DemOptions dem_options;
  dem_options.dt = interval / static_cast<double>(steps);
  run.dt = dem_options.dt;
  DemIntegrator<3> dem(start, run.law, dem_options);
  std::unique_ptr<DemIntegrator<3>> coarse;
  if (options.dem_check) {
    if (steps % 2 != 0) throw std::logic_error("dem_check needs an even number of steps");
    DemOptions c = dem_options;
    c.dt = 2.0 * dem_options.dt;
    coarse = std::make_unique<DemIntegrator<3>>(start, run.law, c);
  }

  std::vector<double> radius(n);
  for (std::size_t i = 0; i < n; ++i) radius[i] = start.kinematics[i].radius;
  auto engine_at = [&](Engine& e, double t, std::vector<std::uint8_t>& frozen) {
    while (e.next_event_time() <= t) {
      if (e.step() == EventKind::kNone) break;
    }
    const ParticleSystem<3> s = e.export_state(false);
    std::vector<Vec<3>> x(n);
    for (std::size_t i = 0; i < n; ++i) x[i] = s.position(i, t);
    frozen.assign(n, 0);
    for (const auto& f : s.frozen) {
      frozen[f.i] = 1;
      if (f.j != FrozenContact<3>::kWall) frozen[f.j] = 1;
    }
    return x;
  };
  auto dem_positions = [&](const DemIntegrator<3>& d) {
    std::vector<Vec<3>> x(n);
    for (std::size_t i = 0; i < n; ++i) x[i] = d.position(i);
    return x;
  };
  for (int k = 1; k <= options.samples; ++k) {
    const double t = k * interval;
    dem.step(steps);
    if (coarse) coarse->step(steps / 2);
    GasSample sample;
    sample.time = dem.time();
    std::vector<std::uint8_t> frozen_mapped, frozen_hard;
    const std::vector<Vec<3>> xm = engine_at(mapped, t, frozen_mapped);
    const std::vector<Vec<3>> xh = engine_at(hard, t, frozen_hard);
    const std::vector<Vec<3>> xd = dem_positions(dem);
    const std::vector<std::uint8_t> contact_d = overlapping(start.box, xd, radius);
    // The mapped engine's overlapping pairs are frozen or receding after their release; the
    // hard spheres never overlap.
    sample.mapped = divergence(start.box, xm, frozen_mapped, xd, contact_d, radius);
    sample.hard = divergence(start.box, xh, frozen_hard, xd, contact_d, radius);
    if (coarse) {
      const std::vector<Vec<3>> xc = dem_positions(*coarse);
      sample.dem_coarse =
          divergence(start.box, xc, overlapping(start.box, xc, radius), xd, contact_d, radius);
    }
    sample.collisions_per_particle =
        2.0 * static_cast<double>(mapped.counters().collisions) / static_cast<double>(n);
    sample.kinetic_energy = dem.kinetic_energy() / static_cast<double>(n);
    sample.overlap_fallbacks = mapped.counters().soft_overlap_fallbacks;
    sample.early_releases = mapped.counters().soft_early_releases;
    run.samples.push_back(sample);
    if (options.progress) options.progress(t / options.t_end);
  }
  run.mapped = mapped.counters();
  run.hard = hard.counters();
  run.mean_free_time = options.t_end / run.samples.back().collisions_per_particle;
  return run;
}

// The first sample time at which a divergence exceeds `level` (infinity: never).
inline double first_time_above(const std::vector<GasSample>& samples, Divergence GasSample::*method,
                               double level, double Divergence::*measure = &Divergence::rms) {
  for (const GasSample& s : samples)
    if ((s.*method).*measure > level) return s.time;
  return std::numeric_limits<double>::infinity();
}

// ---------------------------------------------------------------------------------------------
// 2. Isolated binary collisions (docs/physics.md#hard-sphere-failure).

struct BinarySpec {
  SoftModel model = SoftModel::LinearDashpot;
  double l_tilde = 100.0;  // at the normal impact speed v_n = 1 of these collisions
  double c_dis = 0.2;
  double ratio = 1.0;  // v_t / v_n
  double m_i = 1.0, m_j = 3.0, radius_i = 0.4, radius_j = 0.6;
  bool dem = true;
  double dem_steps_per_contact = 20000.0;  // of this collision's contact time
};

struct BinaryOutcome {
  Vec<3> g{};             // relative velocity after the contact
  Vec<3> x_i{}, x_j{};    // positions at the common time t_end after the contact
  double e_eff = 0.0;     // -(g . n0) / (g0 . n0): normal restitution against the initial normal
  double deflection = 0;  // angle between g0 and g [rad]
};

struct BinaryResult {
  BinarySpec spec;
  double head_on_restitution = 0.0;  // e at v_n (the hard model's e)
  double contact_time = 0.0;         // t_c of this collision (direct integration)
  double dem_dt = 0.0;
  BinaryOutcome exact, hard, mapped, dem;  // exact: direct integration of Newton's equations
};

namespace detail {

inline BinaryOutcome outcome(const Vec<3>& g0, const Vec<3>& n0, const Vec<3>& g, const Vec<3>& x_i,
                             const Vec<3>& x_j) {
  BinaryOutcome o;
  o.g = g;
  o.x_i = x_i;
  o.x_j = x_j;
  o.e_eff = -dot(g, n0) / dot(g0, n0);
  o.deflection = angle_between(g0, g);
  return o;
}

inline BinaryOutcome run_engine(const ParticleSystem<3>& start, const SoftContactLaw& law,
                                SoftCollisions mode, double t_end, const Vec<3>& g0,
                                const Vec<3>& n0) {
  Environment<3> env;
  env.species = 1;
  env.soft = {law};
  env.soft_wall = {law};
  env.soft_collisions = mode;
  EngineOptions options;
  options.renumber_interval = 0.0;  // engine indices are the caller's
  Engine engine(start, StartMode::kPredict, options, env);
  while (engine.next_event_time() <= t_end) {
    if (engine.step() == EventKind::kNone) break;
  }
  // A deferred release needs no event: the engine's motion at t_end is the one after it.
  if (engine.counters().collisions != 1 || engine.frozen() > (engine.time() < t_end ? 2u : 0u))
    throw std::logic_error("binary collision: expected one completed collision");
  return outcome(g0, n0, engine.velocity(0, t_end) - engine.velocity(1, t_end),
                 engine.position(0, t_end), engine.position(1, t_end));
}

}  // namespace detail

// One collision: the pair touches at t0 with normal n0 (from j to i), normal approach speed
// v_n = 1 and tangential speed ratio * v_n, centre of mass moving; every method starts from the
// same state at time 0 and its outcome is compared at t_end, after the contact in all of them.
inline BinaryResult binary_collision(const BinarySpec& spec) {
  BinaryResult res;
  res.spec = spec;
  const double l = spec.radius_i + spec.radius_j;
  const double mu = reduced_mass(spec.m_i, spec.m_j), M = spec.m_i + spec.m_j;
  const SoftContactLaw law =
      law_with_reduced_parameters(spec.model, mu, l, spec.l_tilde, spec.c_dis);
  const CollisionUnits head_on = reduce_collision(law, mu, l, 1.0, 0.0);
  res.head_on_restitution = -collision_map(head_on.reduced).eps_rdot;

  // A generic orientation: n0 and t0 orthonormal, neither along an axis.
  Vec<3> n0{0.48, -0.36, 0.8};
  n0 = (1.0 / std::sqrt(norm2(n0))) * n0;
  Vec<3> t0{0.6, 0.8, 0.0};
  t0 = t0 - dot(t0, n0) * n0;
  t0 = (1.0 / std::sqrt(norm2(t0))) * t0;
  const Vec<3> g0 = -1.0 * n0 + spec.ratio * t0;
  const Vec<3> V{0.12, -0.07, 0.05};
  const Vec<3> v_i = V + (spec.m_j / M) * g0, v_j = V - (spec.m_i / M) * g0;
  // Contact at t_contact after the relative motion covered l/4; t_end as long again after the end.
  const double speed = std::sqrt(norm2(g0));
  const double t_contact = 0.25 * l / speed;
  const Vec<3> c{6.0, 6.0, 6.0};
  const Vec<3> ci = c + (spec.m_j / M * l) * n0, cj = c - (spec.m_i / M * l) * n0;

  PairState at_contact{ci, cj, v_i, v_j};
  const DirectContact direct = integrate_contact_directly(
      law, SoftPair{spec.m_i, spec.m_j, spec.radius_i, spec.radius_j}, at_contact);
  res.contact_time = direct.contact_time;
  const double t_end = t_contact + direct.contact_time + 0.25 * l / speed;
  const double after = t_end - t_contact - direct.contact_time;
  res.exact = detail::outcome(g0, n0, direct.state.v_i - direct.state.v_j,
                              direct.state.r_i + after * direct.state.v_i,
                              direct.state.r_j + after * direct.state.v_j);

  ParticleSystem<3> s;
  s.box = {12.0, 12.0, 12.0};
  s.kinematics = {{ci - t_contact * v_i, v_i, 0.0, spec.radius_i},
                  {cj - t_contact * v_j, v_j, 0.0, spec.radius_j}};
  s.mass = {spec.m_i, spec.m_j};
  s.species = {0, 0};
  s.species_names = {"A"};
  res.hard = detail::run_engine(s, law, SoftCollisions::kInstantaneous, t_end, g0, n0);
  res.mapped = detail::run_engine(s, law, SoftCollisions::kMapped, t_end, g0, n0);

  if (spec.dem) {
    // The contact starts in the middle of a step (a dashpot's force jumps there: a first-order
    // error otherwise), and the DEM runs on past the end, then moves on in free flight.
    const double dt_target = direct.contact_time / spec.dem_steps_per_contact;
    const long before = static_cast<long>(std::ceil(t_contact / dt_target));
    DemOptions options;
    options.dt = t_contact / (static_cast<double>(before) + 0.5);
    res.dem_dt = options.dt;
    DemIntegrator<3> dem(s, law, options);
    const long total =
        static_cast<long>(std::ceil((t_contact + direct.contact_time * 1.01) / options.dt + 10.0));
    dem.step(total);
    if (dem.contact_count() != 0 || dem.collisions() != 1)
      throw std::logic_error("binary collision: the DEM contact has not ended");
    const double rest = t_end - dem.time();
    const Vec<3> vi = dem.velocity(0), vj = dem.velocity(1);
    res.dem =
        detail::outcome(g0, n0, vi - vj, dem.position(0) + rest * vi, dem.position(1) + rest * vj);
  }
  return res;
}

// Differences of an outcome against the exact one: the angle between the outgoing relative
// velocities [rad], and the largest position offset at t_end per contact distance l.
inline double direction_error(const BinaryOutcome& o, const BinaryOutcome& exact) {
  return angle_between(o.g, exact.g);
}
inline double position_error(const BinaryOutcome& o, const BinaryOutcome& exact, const Vec<3>& box,
                             double l) {
  return std::max(std::sqrt(norm2(minimum_image(o.x_i - exact.x_i, box))),
                  std::sqrt(norm2(minimum_image(o.x_j - exact.x_j, box)))) /
         l;
}

}  // namespace kairos::proofs
