#include "interactions/potential_spec.hpp"

#include <cmath>
#include <limits>
#include <optional>
#include <span>
#include <utility>

#include <fmt/format.h>

#include "core/error.hpp"
#include "interactions/parameter_domain.hpp"
#include "interactions/soft_contact.hpp"

namespace kairos {

namespace {

constexpr ChoiceEntry<PotentialKind> kKinds[] = {
    {"square_well", PotentialKind::kSquareWell, "a square well of depth `depth` out to `lambda`"},
    {"square_shoulder", PotentialKind::kSquareShoulder,
     "a square shoulder of height `depth` out to `lambda`"},
    {"steps", PotentialKind::kSteps, "a step table: `boundaries` and `energies` as given"},
    {"lennard_jones", PotentialKind::kLennardJones, "Lennard-Jones, stepped"},
    {"wca", PotentialKind::kWca, "the purely repulsive WCA potential, stepped"},
    {"yukawa", PotentialKind::kYukawa, "screened Coulomb, stepped"},
    {"morse", PotentialKind::kMorse, "Morse, stepped"},
    {"tabulated", PotentialKind::kTabulated, "U(r) read from `file`, stepped"},
    {"spring_dashpot", PotentialKind::kSpringDashpot,
     "a repulsive spring in equal steps with a dashpot per step"},
    {"tether", PotentialKind::kTether, "bond: free up to `max_length`"},
    {"spring", PotentialKind::kSpring, "bond: a harmonic spring up to `max_length`, stepped"},
};
constexpr std::size_t kPairKinds = 9;  // the first nine; the bonds follow

constexpr ChoiceEntry<StepPlacement> kPlacements[] = {
    {"energy", StepPlacement::kEnergy, "steps of equal energy"},
    {"distance", StepPlacement::kDistance, "steps of equal width"},
    {"volume", StepPlacement::kVolume, "shells of equal volume"},
};

constexpr ChoiceEntry<StepEnergyRule> kEnergyRules[] = {
    {"midpoint", StepEnergyRule::kMidpoint, "U at the middle of the shell"},
    {"volume", StepEnergyRule::kVolumeAverage, "the volume average of U over the shell"},
    {"mid_volume", StepEnergyRule::kMidVolume, "U at the radius halving the shell's volume"},
    {"virial", StepEnergyRule::kVirial, "the shell's Boltzmann average at `temperature`"},
};

// The kind of a spec, if it is a registered name.
std::optional<PotentialKind> kind_of(const PotentialSpec& spec) {
  const ChoiceEntry<PotentialKind>* e = potential_kinds().find(spec.kind);
  return e != nullptr ? std::optional(e->value) : std::nullopt;
}

bool spec_is_bond(const PotentialSpec& spec) {
  const std::optional<PotentialKind> kind = kind_of(spec);
  return kind && is_bond(*kind);
}

// "potential lennard_jones: " or "bond spring: ".
std::string prefix(const PotentialSpec& spec) {
  return fmt::format("{} {}: ", spec_is_bond(spec) ? "bond" : "potential", spec.kind);
}

[[noreturn]] void fail(const PotentialSpec& spec, const std::string& message) {
  throw InputError(prefix(spec) + message);
}

void positive(const PotentialSpec& spec, const char* name, double value) {
  if (!kPositiveDomain.contains(value))
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

const Choices<PotentialKind>& potential_kinds() {
  static constexpr Choices<PotentialKind> kinds("potential kind", kKinds);
  return kinds;
}

const Choices<PotentialKind>& pair_potential_kinds() {
  static constexpr Choices<PotentialKind> kinds("pair potential kind",
                                                std::span(kKinds).first(kPairKinds));
  return kinds;
}

const Choices<PotentialKind>& bond_potential_kinds() {
  static constexpr Choices<PotentialKind> kinds("bond kind", std::span(kKinds).subspan(kPairKinds));
  return kinds;
}

const Choices<StepPlacement>& step_placements() {
  static constexpr Choices<StepPlacement> placements("step placement", kPlacements);
  return placements;
}

const Choices<StepEnergyRule>& step_energy_rules() {
  static constexpr Choices<StepEnergyRule> rules("shell energy rule", kEnergyRules);
  return rules;
}

bool is_bond(PotentialKind kind) {
  return kind == PotentialKind::kTether || kind == PotentialKind::kSpring;
}

bool is_continuous(PotentialKind kind) {
  switch (kind) {
    case PotentialKind::kLennardJones:
    case PotentialKind::kWca:
    case PotentialKind::kYukawa:
    case PotentialKind::kMorse:
    case PotentialKind::kTabulated:
    case PotentialKind::kSpring:
    case PotentialKind::kSpringDashpot:
      return true;
    case PotentialKind::kSquareWell:
    case PotentialKind::kSquareShoulder:
    case PotentialKind::kSteps:
    case PotentialKind::kTether:
      break;
  }
  return false;
}

bool uses_epsilon(PotentialKind kind) {
  return kind == PotentialKind::kLennardJones || kind == PotentialKind::kWca ||
         kind == PotentialKind::kYukawa || kind == PotentialKind::kMorse;
}

StepPlacement parse_step_placement(const std::string& name) {
  return step_placements().at(name);
}

StepEnergyRule parse_step_energy_rule(const std::string& name) {
  return step_energy_rules().at(name);
}

ContinuousPotential continuous_potential(const PotentialSpec& spec) {
  const PotentialKind kind = potential_kinds().at(spec.kind);  // rejects an unknown kind
  if (!is_continuous(kind)) return {};
  try {
    if (kind == PotentialKind::kLennardJones) {
      positive(spec, "epsilon", spec.epsilon);
      positive(spec, "sigma", spec.sigma);
      return lennard_jones(spec.epsilon, spec.sigma, cutoff_or(spec, 2.5 * spec.sigma),
                           spec.shifted);
    }
    if (kind == PotentialKind::kWca) {
      positive(spec, "epsilon", spec.epsilon);
      positive(spec, "sigma", spec.sigma);
      no_cutoff(spec, "2^(1/6) sigma");
      return wca(spec.epsilon, spec.sigma);
    }
    if (kind == PotentialKind::kYukawa) {
      if (!(spec.epsilon != 0.0) || !std::isfinite(spec.epsilon))
        fail(spec, fmt::format("epsilon must be finite and non-zero, not {}", spec.epsilon));
      positive(spec, "sigma", spec.sigma);
      if (!(spec.kappa >= 0.0) || !std::isfinite(spec.kappa))
        fail(spec, fmt::format("kappa must be finite and at least 0, not {}", spec.kappa));
      return yukawa(spec.epsilon, spec.sigma, spec.kappa, cutoff_or(spec, 3.0 * spec.sigma),
                    spec.shifted);
    }
    if (kind == PotentialKind::kMorse) {
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
    if (kind == PotentialKind::kTabulated) {
      if (spec.file.empty()) fail(spec, "file must name the table of r and U");
      no_cutoff(spec, "the file's last r");
      return tabulated(spec.file, spec.shifted);
    }
    if (kind == PotentialKind::kSpringDashpot) {
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
  switch (potential_kinds().at(spec.kind)) {  // rejects an unknown kind
    case PotentialKind::kSquareWell:
    case PotentialKind::kSquareShoulder:
      return spec.lambda * core;
    case PotentialKind::kSteps:
      return spec.boundaries.empty() ? 0.0 : spec.boundaries.front();
    case PotentialKind::kTether:
      return spec.max_length;
    default:
      return continuous_potential(spec).cutoff;
  }
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
  if (!kNonNegativeDomain.contains(spec.damping))
    fail(spec, fmt::format("damping must be {}, not {}", kNonNegativeDomain.text(), spec.damping));
  double gamma = spec.damping;
  if (spec.restitution != 0.0) {
    if (spec.damping != 0.0) fail(spec, "give damping or restitution, not both");
    if (!kSoftRestitutionDomain.contains(spec.restitution)) {
      fail(spec, fmt::format("restitution must be {}, not {}", kSoftRestitutionDomain.text(),
                             spec.restitution));
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
  const PotentialKind kind = potential_kinds().at(spec.kind);
  check_core(spec, core);
  if (dimension != 2 && dimension != 3)
    fail(spec, fmt::format("the dimension must be 2 or 3, not {}", dimension));
  if (kind != PotentialKind::kSpringDashpot) {
    for (const auto& [key, given] : {std::pair<const char*, bool>{"damping", spec.damping != 0.0},
                                     {"restitution", spec.restitution != 0.0},
                                     {"force_zero", !spec.force_zero}}) {
      if (given) fail(spec, fmt::format("{} applies to kind spring_dashpot only", key));
    }
  }
  try {
    if (kind == PotentialKind::kSpringDashpot)
      return spring_dashpot_table(spec, p, core, dimension, reduced_mass);
    if (kind == PotentialKind::kSquareWell || kind == PotentialKind::kSquareShoulder) {
      if (!(spec.lambda > 1.0) || !std::isfinite(spec.lambda))
        fail(spec, fmt::format("lambda must be greater than 1, not {}", spec.lambda));
      positive(spec, "depth", spec.depth);
      const double u = kind == PotentialKind::kSquareWell ? -spec.depth : spec.depth;
      StepTable t{{spec.lambda * core, core}, {u}};
      t.check();
      return t;
    }
    if (kind == PotentialKind::kSteps) {
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
    if (kind == PotentialKind::kTether) {
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
    if (kind == PotentialKind::kSpring && !(spec.length > core)) {
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
