#include "interactions/potential_spec.hpp"

#include <cmath>
#include <limits>
#include <utility>

#include <fmt/format.h>

#include "core/error.hpp"
#include "interactions/soft_contact.hpp"

namespace kairos {

namespace {

bool is_bond(const std::string& kind) {
  return kind == "tether" || kind == "spring";
}

bool is_continuous(const std::string& kind) {
  return kind == "lennard_jones" || kind == "wca" || kind == "yukawa" || kind == "morse" ||
         kind == "tabulated" || kind == "spring" || kind == "spring_dashpot";
}

bool is_known(const std::string& kind) {
  return is_continuous(kind) || kind == "square_well" || kind == "square_shoulder" ||
         kind == "steps" || kind == "tether";
}

// "potential lennard_jones: " or "bond spring: ".
std::string prefix(const PotentialSpec& spec) {
  return fmt::format("{} {}: ", is_bond(spec.kind) ? "bond" : "potential", spec.kind);
}

[[noreturn]] void fail(const PotentialSpec& spec, const std::string& message) {
  throw InputError(prefix(spec) + message);
}

void positive(const PotentialSpec& spec, const char* name, double value) {
  if (!(value > 0.0) || !std::isfinite(value))
    fail(spec, fmt::format("{} must be positive and finite, not {}", name, value));
}

// A cut-off of 0 means the kind's default; otherwise it must be positive and finite.
double cutoff_or(const PotentialSpec& spec, double fallback) {
  if (spec.cutoff == 0.0) return fallback;
  positive(spec, "cutoff", spec.cutoff);
  return spec.cutoff;
}

void no_cutoff(const PotentialSpec& spec, const char* where) {
  if (spec.cutoff != 0.0)
    fail(spec, fmt::format("the cut-off is {}; leave cutoff unset (it is {})", where, spec.cutoff));
}

void check_core(const PotentialSpec& spec, double core) {
  if (!(core > 0.0) || !std::isfinite(core)) {
    fail(spec,
         fmt::format("the contact distance (sum of the radii) must be positive, not {}", core));
  }
}

}  // namespace

StepPlacement parse_step_placement(const std::string& name) {
  if (name == "energy") return StepPlacement::kEnergy;
  if (name == "distance") return StepPlacement::kDistance;
  if (name == "volume") return StepPlacement::kVolume;
  throw InputError(fmt::format("unknown step placement '{}' (energy, distance or volume)", name));
}

StepEnergyRule parse_step_energy_rule(const std::string& name) {
  if (name == "midpoint") return StepEnergyRule::kMidpoint;
  if (name == "volume") return StepEnergyRule::kVolumeAverage;
  if (name == "mid_volume") return StepEnergyRule::kMidVolume;
  if (name == "virial") return StepEnergyRule::kVirial;
  throw InputError(
      fmt::format("unknown shell energy rule '{}' (midpoint, volume, mid_volume or virial)", name));
}

ContinuousPotential continuous_potential(const PotentialSpec& spec) {
  if (!is_known(spec.kind)) {
    throw InputError(fmt::format(
        "unknown potential kind '{}' (square_well, square_shoulder, steps, lennard_jones, wca, "
        "yukawa, morse, tabulated, spring_dashpot, tether or spring)",
        spec.kind));
  }
  if (!is_continuous(spec.kind)) return {};
  try {
    if (spec.kind == "lennard_jones") {
      positive(spec, "epsilon", spec.epsilon);
      positive(spec, "sigma", spec.sigma);
      return lennard_jones(spec.epsilon, spec.sigma, cutoff_or(spec, 2.5 * spec.sigma),
                           spec.shifted);
    }
    if (spec.kind == "wca") {
      positive(spec, "epsilon", spec.epsilon);
      positive(spec, "sigma", spec.sigma);
      no_cutoff(spec, "2^(1/6) sigma");
      return wca(spec.epsilon, spec.sigma);
    }
    if (spec.kind == "yukawa") {
      if (!(spec.epsilon != 0.0) || !std::isfinite(spec.epsilon))
        fail(spec, fmt::format("epsilon must be finite and non-zero, not {}", spec.epsilon));
      positive(spec, "sigma", spec.sigma);
      if (!(spec.kappa >= 0.0) || !std::isfinite(spec.kappa))
        fail(spec, fmt::format("kappa must be finite and at least 0, not {}", spec.kappa));
      return yukawa(spec.epsilon, spec.sigma, spec.kappa, cutoff_or(spec, 3.0 * spec.sigma),
                    spec.shifted);
    }
    if (spec.kind == "morse") {
      positive(spec, "epsilon", spec.epsilon);
      positive(spec, "alpha", spec.alpha);
      double r_min = spec.r_min;
      if (r_min == 0.0) {
        positive(spec, "sigma", spec.sigma);
        r_min = spec.sigma;
      }
      positive(spec, "r_min", r_min);
      const double rc = cutoff_or(spec, r_min + 6.0 / spec.alpha);
      if (!(rc > r_min)) {
        fail(spec, fmt::format("the cut-off {} must lie beyond the minimum r_min = {}", rc, r_min));
      }
      return morse(spec.epsilon, r_min, spec.alpha, rc, spec.shifted);
    }
    if (spec.kind == "tabulated") {
      if (spec.file.empty()) fail(spec, "file must name the table of r and U");
      no_cutoff(spec, "the file's last r");
      return tabulated(spec.file, spec.shifted);
    }
    if (spec.kind == "spring_dashpot") {
      positive(spec, "stiffness", spec.stiffness);
      positive(spec, "length", spec.length);
      return repulsive_spring(spec.stiffness, spec.length);
    }
    // spring
    positive(spec, "stiffness", spec.stiffness);
    positive(spec, "length", spec.length);
    positive(spec, "max_length", spec.max_length);
    if (!(spec.length < spec.max_length)) {
      fail(spec, fmt::format("length {} must be shorter than max_length {}", spec.length,
                             spec.max_length));
    }
    return harmonic_spring(spec.stiffness, spec.length, spec.max_length);
  } catch (const InputError& e) {
    const std::string message = e.what();
    if (message.starts_with(prefix(spec))) throw;
    fail(spec, message);
  }
}

StepTable make_step_table(const PotentialSpec& spec, double core) {
  return make_step_table(spec, core, 3);
}

double table_cutoff(const PotentialSpec& spec, double core) {
  if (spec.kind == "square_well" || spec.kind == "square_shoulder") return spec.lambda * core;
  if (spec.kind == "steps") return spec.boundaries.empty() ? 0.0 : spec.boundaries.front();
  if (spec.kind == "tether") return spec.max_length;
  return continuous_potential(spec).cutoff;  // also rejects an unknown kind
}

namespace {

// spring_dashpot: equal steps from `length` to the core, midpoint energies, the dashpot.
StepTable spring_dashpot_table(const PotentialSpec& spec, const ContinuousPotential& p, double core,
                               int dimension, double reduced_mass) {
  if (!(spec.length > core)) {
    fail(spec, fmt::format("length {} (where the contact begins) must exceed the contact "
                           "distance (sum of the radii) {}, which is the hard core inside",
                           spec.length, core));
  }
  if (spec.steps < 1) fail(spec, fmt::format("steps must be at least 1, not {}", spec.steps));
  if (!(spec.damping >= 0.0) || !std::isfinite(spec.damping))
    fail(spec, fmt::format("damping must be finite and at least 0, not {}", spec.damping));
  double gamma = spec.damping;
  if (spec.restitution != 0.0) {
    if (spec.damping != 0.0) fail(spec, "give damping or restitution, not both");
    if (!(spec.restitution > 0.0 && spec.restitution <= 1.0)) {
      fail(spec, fmt::format("restitution must be in (0, 1], not {}", spec.restitution));
    }
    if (!(reduced_mass > 0.0) || !std::isfinite(reduced_mass)) {
      fail(spec, "restitution needs the pair's masses (one mass per species); give damping");
    }
    gamma = dashpot_damping_for_restitution(reduced_mass, spec.stiffness, spec.restitution);
  }
  StepTable t = step_potential(p, StepPlacement::kDistance, spec.steps, core,
                               StepEnergyRule::kMidpoint, 1.0, dimension);
  t.damping = gamma;
  t.force_zero = spec.force_zero;
  t.check();
  return t;
}

}  // namespace

StepTable make_step_table(const PotentialSpec& spec, double core, int dimension,
                          double reduced_mass) {
  const ContinuousPotential p = continuous_potential(spec);  // also rejects an unknown kind
  check_core(spec, core);
  if (dimension != 2 && dimension != 3)
    fail(spec, fmt::format("the dimension must be 2 or 3, not {}", dimension));
  if (spec.kind != "spring_dashpot") {
    for (const auto& [key, given] : {std::pair<const char*, bool>{"damping", spec.damping != 0.0},
                                     {"restitution", spec.restitution != 0.0},
                                     {"force_zero", !spec.force_zero}}) {
      if (given) fail(spec, fmt::format("{} applies to kind spring_dashpot only", key));
    }
  }
  try {
    if (spec.kind == "spring_dashpot")
      return spring_dashpot_table(spec, p, core, dimension, reduced_mass);
    if (spec.kind == "square_well" || spec.kind == "square_shoulder") {
      if (!(spec.lambda > 1.0) || !std::isfinite(spec.lambda))
        fail(spec, fmt::format("lambda must be greater than 1, not {}", spec.lambda));
      positive(spec, "depth", spec.depth);
      const double u = spec.kind == "square_well" ? -spec.depth : spec.depth;
      StepTable t{{spec.lambda * core, core}, {u}};
      t.check();
      return t;
    }
    if (spec.kind == "steps") {
      StepTable t{spec.boundaries, spec.energies};
      t.check();
      if (!(std::abs(t.core() - core) <= 1e-12 * core)) {
        fail(spec, fmt::format("the step table's hard core is {} but the pair's contact distance "
                               "(sum of the radii) is {}",
                               t.core(), core));
      }
      t.boundary.back() = core;
      t.check();
      return t;
    }
    if (spec.kind == "tether") {
      positive(spec, "max_length", spec.max_length);
      if (!(spec.max_length > core)) {
        fail(spec,
             fmt::format("max_length {} must exceed the contact distance (sum of the radii) {}",
                         spec.max_length, core));
      }
      StepTable t{{spec.max_length, core}, {0.0}, std::numeric_limits<double>::infinity()};
      t.check();
      return t;
    }
    // The continuous kinds and spring.
    if (spec.kind == "spring" && !(spec.length > core)) {
      fail(spec, fmt::format("length {} must exceed the contact distance (sum of the radii) {}",
                             spec.length, core));
    }
    if (!(p.cutoff > core)) {
      fail(spec, fmt::format("the cut-off {} must lie beyond the contact distance (sum of the "
                             "radii) {}",
                             p.cutoff, core));
    }
    if (spec.steps < 1) fail(spec, fmt::format("steps must be at least 1, not {}", spec.steps));
    if (!(spec.temperature > 0.0) || !std::isfinite(spec.temperature)) {
      fail(spec, fmt::format("temperature must be positive and finite, not {}", spec.temperature));
    }
    StepPlacement placement{};
    StepEnergyRule rule{};
    try {
      placement = parse_step_placement(spec.placement);
    } catch (const InputError& e) {
      fail(spec, std::string("placement: ") + e.what());
    }
    try {
      rule = parse_step_energy_rule(spec.shell_energy);
    } catch (const InputError& e) {
      fail(spec, std::string("shell_energy: ") + e.what());
    }
    return step_potential(p, placement, spec.steps, core, rule, spec.temperature, dimension);
  } catch (const InputError& e) {
    const std::string message = e.what();
    if (message.starts_with(prefix(spec))) throw;
    fail(spec, message);
  }
}

}  // namespace kairos
