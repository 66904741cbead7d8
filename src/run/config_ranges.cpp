#include "run/config_ranges.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "core/error.hpp"
#include "interactions/soft_contact.hpp"
#include "io/config_choices.hpp"
#include "io/config_keys.hpp"
#include "io/range_checks.hpp"

namespace kairos {

namespace {

using namespace range_checks;

void check_interactions(const InteractionConfig& in, const RangeScales& s) {
  check_contact(in.contact, "contact", s);
  for (std::size_t p = 0; p < in.pairs.size(); ++p)
    check_contact(in.pairs[p].contact, fmt::format("contact.pair[{}]", p), s);
  within_declared("contact.tc", in.tc, s.time(), time_unit(s));
  if (in.sleep_speed != -1.0) {
    within_declared("contact.sleep_speed", in.sleep_speed, s.speed(), speed_unit(s),
                    ", or -1 for automatic");
  }
}

// ----- box, walls, shear, gravity

void check_box(const RangeScales& s) {
  for (std::size_t a = 0; a < s.box.size(); ++a) {
    // Positions are doubles: at 1e9 diameters a contact is resolved to ~1e-7 of d_min.
    if (!(s.box[a] <= 1e9 * s.d_min)) {
      throw InputError(fmt::format(
          "the box edge along {} is {:.6g}, more than 1e9 times the smallest diameter {:.6g}: "
          "positions could no longer resolve a contact; raise system.packing_fraction, lower "
          "system.box_scale, or narrow the spread of the diameters",
          "xyz"[a], s.box[a], s.d_min));
    }
  }
}

void check_gravity(const Config& c, const RangeScales& s) {
  double g2 = 0.0;
  for (const double g : c.field.gravity) g2 += g * g;
  const double g_unit = s.kT / (s.mass * s.d_max);  // the acceleration of kT over a diameter
  magnitude_within("field.gravity", std::sqrt(g2), 1e9 * g_unit,
                   fmt::format("1e9 kT / (m d) = {:.6g} with {}, m = {:.6g} the smallest mass, {}",
                               1e9 * g_unit, energy_unit(s), s.mass, length_unit(s)));
  // An open face is for particles that gravity brings back: without a pull back (or with a push
  // out) they fly off for ever, and the clock and the positions grow without bound.
  for (const std::string& face : c.boundary.open) {
    const auto f = static_cast<std::size_t>(face_number(box_faces().at(face)));
    const std::size_t axis = f / 2;
    const double g = axis < c.field.gravity.size() ? c.field.gravity[axis] : 0.0;
    const double pull = f % 2 == 1 ? -g : g;  // towards the inside of the box
    const std::string key = fmt::format("field.gravity[{}]", axis);
    if (!(pull > 0.0)) {
      throw InputError(fmt::format(
          "boundary.open: face {} is open but {} = {} does not pull the particles back from it, "
          "so they would fly off for ever; give gravity a component towards {} (or put a wall "
          "there)",
          face, key, g, box_faces().entries()[f ^ 1u].name));
    }
    if (axis < s.box.size() && !(s.kT / (s.mass * pull) <= 1e6 * s.box[axis])) {
      throw InputError(fmt::format(
          "{} = {}: too weak for the open face {}: particles would rise kT / (m g) = {:.6g}, more "
          "than 1e6 box edges ({:.6g}) above it before falling back; raise it to at least {:.6g} "
          "(or put a wall there)",
          key, g, face, s.kT / (s.mass * pull), s.box[axis], s.kT / (s.mass * 1e6 * s.box[axis])));
    }
  }
}

void check_boundary(const Config& c, const RangeScales& s) {
  check_box(s);
  for (std::size_t w = 0; w < c.boundary.walls.size(); ++w) {
    const WallConfig& wall = c.boundary.walls[w];
    const ChoiceEntry<BoxFace>* face = box_faces().find(wall.face);
    const auto axis = face != nullptr ? static_cast<std::size_t>(face_axis(face->value)) : 3;
    check_wall(wall, fmt::format("boundary.wall[{}]", w),
               axis < s.box.size() ? s.box[axis] : std::numeric_limits<double>::quiet_NaN(), s);
  }
  for_each_surface_table(c.boundary.surfaces, [&](auto table, const auto& entries) {
    for (std::size_t k = 0; k < entries.size(); ++k)
      table.check_ranges(entries[k], fmt::format("boundary.{}[{}]", table.key, k), s);
  });
  // The images slide at gamma L_y; faster than 1e6 / tau the image shifts and the flow's heating
  // swamp every collision (and 1e300 overflows the positions).
  const double fastest = declared("boundary.shear_rate").hi;
  magnitude_within("boundary.shear_rate", c.boundary.shear_rate, fastest / s.time(),
                   short_number(fastest) + " / tau, " + time_unit(s));
  check_gravity(c, s);
}

// ----- driving

void check_driving(const DrivingConfig& d, const RangeScales& s) {
  const DrivingKind kind = driving_kinds().at(d.kind);
  if (kind == DrivingKind::kNone) return;
  const double omega = s.dilute_collision_rate();
  if (omega > 0.0) {
    // Every kick is an event like a collision: more than 1000 per collision and the run is
    // nothing but kicks (1e300 made them 1e-300 apart, so that time no longer advanced).
    within_declared("driving.rate", d.rate, omega,
                    fmt::format("the collision rate per particle of the start state, {:.6g} (a "
                                "dilute-gas estimate: Enskog with g = 1)",
                                omega));
  }
  if (kind == DrivingKind::kAndersen)
    within_declared("driving.temperature", d.temperature, s.kT, energy_unit(s));
  if (kind == DrivingKind::kWhiteNoise) {
    const double v2 = s.speed() * s.speed();
    within_declared("driving.strength", d.strength, v2 / s.time(), "v^2 / tau, " + time_unit(s));
    // One kick changes a velocity by sqrt(strength / rate): beyond 1000 thermal speeds the
    // noise is no diffusion any more but a few huge blows.
    if (!(d.strength / d.rate <= 1e6 * v2)) {
      throw InputError(fmt::format(
          "driving.rate = {}: too low for driving.strength = {}: each kick would change a "
          "velocity by sqrt(strength / rate) = {:.6g}, more than 1e3 times {}; raise the rate to "
          "at least {:.6g}",
          d.rate, d.strength, std::sqrt(d.strength / d.rate), speed_unit(s),
          d.strength / (1e6 * v2)));
    }
  }
}

// ----- run and output

void check_run(const Config& c, const RangeScales& s) {
  const double tau = s.time();
  if (c.run.time > 0.0) within_declared("run.time", c.run.time, tau, time_unit(s));
  if (c.run.equilibration_time >= 0.0)
    within_declared("run.equilibration_time", c.run.equilibration_time, tau, time_unit(s));
  if (c.run.time_step > 0.0) {
    within("run.time_step", c.run.time_step, 1e-12 * tau, tau,
           "1e-12 to 1 times " + time_unit(s) + "; longer steps let particles pass each other");
  }
}

// Log-spaced frames (output.trajectory_spacing = "log") over the production: a million at most,
// as for the intervals (counted when the intervals are in the production length's unit).
void check_log_frames(const Config& c, bool in_time) {
  const OutputConfig& o = c.output;
  if (!trajectory_spacings().is(o.trajectory_spacing, TrajectorySpacing::kLog)) return;
  const bool length_in_time = c.run.time > 0.0;
  if (in_time != length_in_time || !(o.trajectory_interval > 0.0)) return;
  const double length = length_in_time ? c.run.time : c.run.collisions_per_particle;
  const auto per_sequence = [&](double span) {
    return 1.0 +
           std::floor(static_cast<double>(o.trajectory_frames_per_decade) *
                      std::log10(std::max(1.0, span / o.trajectory_interval))) +
           1.0;
  };
  const double period = o.trajectory_log_period;
  const double frames =
      period > 0.0 ? std::ceil(length / period) * per_sequence(period) : per_sequence(length);
  if (frames <= 1e6) return;
  throw InputError(fmt::format(
      "output.trajectory_frames_per_decade = {}{}: about {:.3g} log-spaced frames over the "
      "production (first lag output.trajectory_interval = {}); at most 1e6: fewer frames per "
      "decade{}",
      o.trajectory_frames_per_decade,
      period > 0.0 ? fmt::format(" with output.trajectory_log_period = {}", period) : "", frames,
      o.trajectory_interval, period > 0.0 ? " or a longer period" : " or a longer first lag"));
}

void check_outputs(const Config& c, const RangeScales& s) {
  const bool length_in_time = c.run.time > 0.0;
  const ChoiceEntry<IntervalUnit>* unit = interval_units().find(c.output.interval_unit);
  const bool in_time = unit != nullptr && unit->value == IntervalUnit::kTime;
  const double length = length_in_time ? c.run.time : c.run.collisions_per_particle;
  for (const auto& [key, value] : {std::pair{"output.thermo_interval", c.output.thermo_interval},
                                   {"output.trajectory_interval", c.output.trajectory_interval},
                                   {"output.restart_interval", c.output.restart_interval},
                                   {"output.trajectory_log_period", c.output.trajectory_log_period},
                                   {"analysis.interval", c.analysis.interval}}) {
    if (value == 0.0) continue;  // automatic, or none
    const std::string path = key;
    if (in_time == length_in_time) {
      // A million outputs per production at most: more is no sampling but a log of every event.
      within(path, value, 1e-6 * length, 1e9 * (in_time ? s.time() : 1.0),
             "at least 1e-6 of the production length, at most 1e9 " +
                 (in_time ? "times " + time_unit(s) : std::string("collisions per particle")));
    } else if (in_time) {
      within(path, value, 1e-9 * s.time(), 1e9 * s.time(), "1e-9 to 1e9 times " + time_unit(s));
    } else {
      within(path, value, 1e-9, 1e9, "collisions per particle");
    }
  }
  check_log_frames(c, in_time);
}

// The analyses' lengths against the box (minimum images) and the diameters.
void check_analysis(const AnalysisConfig& a, const RangeScales& s) {
  if (!s.box.empty() && a.rdf_max_distance > 0.0) {
    const double shortest = *std::min_element(s.box.begin(), s.box.end());
    const double edges = declared("analysis.rdf_max_distance").hi;
    within("analysis.rdf_max_distance", a.rdf_max_distance, 0.0, edges * shortest,
           fmt::format("up to {} times the shortest box edge, {:.6g}: beyond, a pair has more "
                       "than one image within the distance",
                       short_number(edges), shortest));
  }
  within_declared("analysis.sk_max", a.sk_max, 1.0 / s.d_max, "1 / d, " + length_unit(s));
}

// ----- soft laws

void check_soft_law(const SoftLawConfig& law, const std::string& prefix, const RangeScales& s) {
  const double mu = 0.5 * s.mass;  // two of the lightest particles
  if (soft_models().at(law.model) == SoftModel::LinearDashpot) {
    // Softer and the particles interpenetrate at thermal speeds; stiffer and the overlap
    // (~ d sqrt(kT / (k d^2))) is below what doubles resolve within the box.
    const double k_unit = s.kT / (s.d_max * s.d_max);
    within_declared(prefix + ".stiffness", law.stiffness, k_unit,
                    fmt::format("kT / d^2 with {}, {}", energy_unit(s), length_unit(s)));
    const double c_dis = law.damping / std::sqrt(law.stiffness * mu);
    if (!(c_dis <= 1e6)) {
      throw InputError(fmt::format(
          "{}.damping = {}: out of range, gamma / sqrt(k mu) = {:.6g} must be at most 1e6 (mu = "
          "{:.6g}, two of the lightest particles): the contact is overdamped far beyond any "
          "material; at most {:.6g}",
          prefix, law.damping, c_dis, mu, 1e6 * std::sqrt(law.stiffness * mu)));
    }
    return;
  }
  const double y_unit = s.kT / (s.d_max * s.d_max * s.d_max);
  within_declared(prefix + ".young", law.young, y_unit,
                  fmt::format("kT / d^3 with {}, {}", energy_unit(s), length_unit(s)));
  if (law.restitution > 0.0) {
    // A is solved from e at this speed; A grows as restitution_speed^(-1/5), so a speed far
    // below the run's makes every contact overdamped (1e-300 made the table build spin).
    within_declared(prefix + ".restitution_speed", law.restitution_speed, s.speed(), speed_unit(s));
  }
  const double rho = hertz_rho_one_material(law.young, law.poisson, 0.25 * s.d_max);
  const double t = std::pow(mu * mu / (rho * rho * s.speed()), 0.2);  // Hertz's time at v
  if (!(law.dissipation <= 1e3 * t)) {
    throw InputError(fmt::format(
        "{}.dissipation = {}: out of range, A / T = {:.6g} must be at most 1e3, T = (mu^2 / (rho^2 "
        "v))^(1/5) = {:.6g} the Hertz time of a thermal collision ({}): the contact is overdamped "
        "far beyond any material; at most {:.6g}",
        prefix, law.dissipation, law.dissipation / t, t, speed_unit(s), 1e3 * t));
  }
}

void check_soft(const SoftConfig& soft, const RangeScales& s) {
  if (!soft.enabled()) return;
  check_soft_law(soft.law, "soft", s);
  for (std::size_t p = 0; p < soft.pairs.size(); ++p)
    check_soft_law(soft.pairs[p].law, fmt::format("soft.pair[{}]", p), s);
}

}  // namespace

template <int D>
RangeScales range_scales(const Config& config, const ParticleSystem<D>& state) {
  RangeScales s = range_scales(config);
  s.dimension = D;
  if (state.size() == 0) return s;
  s.d_min = s.d_max = 2.0 * state.kinematics[0].radius;
  s.mass = state.mass[0];
  for (std::size_t i = 0; i < state.size(); ++i) {
    s.d_min = std::min(s.d_min, 2.0 * state.kinematics[i].radius);
    s.d_max = std::max(s.d_max, 2.0 * state.kinematics[i].radius);
    s.mass = std::min(s.mass, state.mass[i]);
  }
  double volume = 1.0;
  s.box.assign(state.box.begin(), state.box.end());
  for (const double edge : s.box) volume *= edge;
  s.number_density = static_cast<double>(state.size()) / volume;
  return s;
}

template RangeScales range_scales<2>(const Config&, const ParticleSystem<2>&);
template RangeScales range_scales<3>(const Config&, const ParticleSystem<3>&);

RangeScales range_scales(const Config& config) {
  RangeScales s;
  s.dimension = config.system.dimension;
  s.kT = config.system.temperature;
  const auto& species = config.system.species;
  if (!species.empty()) {
    s.d_min = s.d_max = species[0].diameter;
    s.mass = species[0].mass;
  }
  for (const SpeciesConfig& sp : species) {
    s.d_min = std::min(s.d_min, sp.diameter);
    s.d_max = std::max(s.d_max, sp.diameter);
    s.mass = std::min(s.mass, sp.mass);
  }
  return s;
}

void check_potential_ranges(const PotentialSpec& spec, const std::string& prefix,
                            const RangeScales& s) {
  const auto key = [&](std::string_view k) { return fmt::format("{}.{}", prefix, k); };
  const std::string energies = "1e-9 to 1e9 times " + energy_unit(s);
  // An unknown kind is none of them: table_cutoff below says so.
  const auto kind = [&](PotentialKind k) { return potential_kinds().is(spec.kind, k); };
  const bool square = kind(PotentialKind::kSquareWell) || kind(PotentialKind::kSquareShoulder);
  const bool continuous = kind(PotentialKind::kLennardJones) || kind(PotentialKind::kWca) ||
                          kind(PotentialKind::kYukawa) || kind(PotentialKind::kMorse);
  // Zero, negative and non-finite values have their own errors (make_step_table); here the
  // ranges of valid ones.
  if (continuous && spec.epsilon != 0.0) {
    // |eps| / kT beyond 1e9: crossing a step gives speeds whose times the clock cannot resolve.
    within(key("epsilon") + " (magnitude)", std::abs(spec.epsilon), 1e-9 * s.kT, 1e9 * s.kT,
           energies);
  }
  if (continuous && (!kind(PotentialKind::kMorse) || spec.r_min == 0.0) && spec.sigma > 0.0)
    within_declared(key("sigma"), spec.sigma, s.d_max, length_unit(s));
  if (square && spec.depth > 0.0) within_declared(key("depth"), spec.depth, s.kT, energy_unit(s));
  // A well narrower than 1e-9 of the core is below what the positions resolve.
  if (square && spec.lambda > 1.0)
    within(key("lambda"), spec.lambda, 1.0 + 1e-9, 1e6, "in units of the contact distance");
  for (std::size_t k = 0; k < spec.energies.size(); ++k)
    magnitude_within(fmt::format("{}[{}]", key("energies"), k), spec.energies[k], 1e9 * s.kT,
                     "1e9 times " + energy_unit(s));
  if (kind(PotentialKind::kYukawa) && spec.kappa > 0.0)
    within(key("kappa"), spec.kappa, 0.0, declared(key("kappa")).hi / s.d_max,
           "up to " + short_number(declared(key("kappa")).hi) + " / d, " + length_unit(s));
  if (kind(PotentialKind::kMorse) && spec.alpha > 0.0) {
    const Range& r = declared(key("alpha"));
    within(key("alpha"), spec.alpha, r.lo / s.d_max, r.hi / s.d_max,
           fmt::format("{} to {} / d, {}", short_number(r.lo), short_number(r.hi), length_unit(s)));
  }
  if (kind(PotentialKind::kMorse) && spec.r_min > 0.0)
    within_declared(key("r_min"), spec.r_min, s.d_max, length_unit(s));
  const bool spring = kind(PotentialKind::kSpring) || kind(PotentialKind::kSpringDashpot);
  if (spring && spec.stiffness > 0.0) {
    within_declared(key("stiffness"), spec.stiffness, s.kT / (s.d_max * s.d_max),
                    fmt::format("kT / d^2 with {}, {}", energy_unit(s), length_unit(s)));
  }
  if (kind(PotentialKind::kSpringDashpot) && spec.damping > 0.0 && spec.stiffness > 0.0) {
    const double limit = 1e6 * std::sqrt(spec.stiffness * s.mass);
    within(key("damping"), spec.damping, 0.0, limit,
           fmt::format("gamma / sqrt(k m) up to 1e6, m = {:.6g} the smallest mass", s.mass));
  }
  if (step_energy_rules().is(spec.shell_energy, StepEnergyRule::kVirial) && spec.temperature > 0.0)
    within_declared(key("temperature"), spec.temperature, s.kT, energy_unit(s));
  // The table's outermost radius: a pair must meet one periodic image of its partner (and the
  // quadratures of the shell energies stay finite; a cut-off of 1e300 spun in them).
  double outer = 0.0;
  try {
    outer = table_cutoff(spec, s.d_max);
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: {}", prefix, e.what()));
  }
  const auto smallest = std::min_element(s.box.begin(), s.box.end());
  const double limit = smallest != s.box.end() ? 0.5 * *smallest : 1e6 * s.d_max;
  if (!(outer <= limit)) {
    throw InputError(fmt::format(
        "{}: the table reaches out to r = {:.6g} (its cut-off{}), beyond {}: {:.6g}; shorten it",
        prefix, outer,
        kind(PotentialKind::kTether) || kind(PotentialKind::kSpring) ? ", max_length" : "",
        smallest != s.box.end() ? "half the smallest box edge (a pair must meet one periodic "
                                  "image of its partner)"
                                : "1e6 times the largest diameter",
        limit));
  }
}

void check_ranges(const Config& config, const RangeScales& scales) {
  check_interactions(config.interactions, scales);
  check_boundary(config, scales);
  check_driving(config.driving, scales);
  check_run(config, scales);
  check_outputs(config, scales);
  check_analysis(config.analysis, scales);
  check_soft(config.soft, scales);
  for (std::size_t p = 0; p < config.potentials.size(); ++p)
    check_potential_ranges(config.potentials[p].potential, fmt::format("potential[{}]", p), scales);
  for (std::size_t b = 0; b < config.bonds.size(); ++b)
    check_potential_ranges(config.bonds[b].potential, fmt::format("bond[{}]", b), scales);
}

}  // namespace kairos
