// The [soft] and [[soft.pair]] keys.
//
// Each key's name, type, default, range and doc line (io/config_keys.hpp); io/config_keys.cpp
// places the groups into their tables.
#include <fmt/format.h>

#include <algorithm>
#include <cstdint>

#include "interactions/parameter_domain.hpp"
#include "interactions/potential_spec.hpp"
#include "io/config.hpp"
#include "io/config_choices.hpp"
#include "io/keys/key_tables.hpp"

namespace kairos::key_tables {

namespace {

// ----- [soft]

bool dashpot(const void* law) {
  return soft_models().is(static_cast<const SoftLawConfig*>(law)->model, SoftModel::LinearDashpot);
}
bool hertz(const void* law) {
  return !dashpot(law);
}
bool restitution_given(const void* law) {
  return static_cast<const SoftLawConfig*>(law)->restitution > 0.0;
}
bool dashpot_damping(const void* law) {
  return dashpot(law) && !restitution_given(law);
}
bool hertz_dissipation(const void* law) {
  return hertz(law) && !restitution_given(law);
}

const SoftLawConfig kSoftLawDefaults{};
constexpr KeyDecl kSoftLaw[] = {
    {.name = "model",
     .type = KeyType::kString,
     .member = field<&SoftLawConfig::model>,
     .choices = &choices_of<&soft_models>,
     .default_text = "**required**",
     .doc = "the force law"},
    {.name = "stiffness",
     .type = KeyType::kFloat,
     .member = field<&SoftLawConfig::stiffness>,
     .range = by_rule({.lo = 1e-9, .hi = 1e15, .scale = Scale::kStiffness}),
     .default_text = "**required** (dashpot)",
     .unit = "force / length",
     .doc = "dashpot: k",
     .written = &dashpot},
    {.name = "damping",
     .type = KeyType::kFloat,
     .member = field<&SoftLawConfig::damping>,
     .range = by_rule(domain(kNonNegativeDomain)),
     .unit = "force / speed",
     .doc = "dashpot: gamma",
     .written = &dashpot_damping},
    {.name = "young",
     .type = KeyType::kFloat,
     .member = field<&SoftLawConfig::young>,
     .range = by_rule({.lo = 1e-9, .hi = 1e15, .scale = Scale::kModulus}),
     .default_text = "**required** (hertz)",
     .unit = "force / area",
     .doc = "hertz: Young's modulus",
     .written = &hertz},
    {.name = "poisson",
     .type = KeyType::kFloat,
     .member = field<&SoftLawConfig::poisson>,
     .range = by_rule(domain(kPoissonRatioDomain)),
     .doc = "hertz: Poisson's ratio",
     .written = &hertz},
    {.name = "restitution",
     .type = KeyType::kFloat,
     .member = field<&SoftLawConfig::restitution>,
     .range = by_rule(domain(kSoftRestitutionDomain)),
     .default_text = "none",
     .doc = "head-on coefficient of restitution (instead of damping / dissipation)",
     .written = &restitution_given},
    {.name = "dissipation",
     .type = KeyType::kFloat,
     .member = field<&SoftLawConfig::dissipation>,
     .range = by_rule(non_negative),
     .unit = "time",
     .doc = "hertz: the dissipative time constant A",
     .written = &hertz_dissipation},
    {.name = "restitution_speed",
     .type = KeyType::kFloat,
     .member = field<&SoftLawConfig::restitution_speed>,
     .range = by_rule(between(1e-6, 1e6, Scale::kSpeed)),
     .unit = "speed",
     .doc = "hertz: the impact speed at which e = restitution",
     .written = &hertz},
    {.name = "friction",
     .type = KeyType::kFloat,
     .member = field<&SoftLawConfig::friction>,
     .range = {.lo = 0.0, .hi = 1e9},
     .doc = "dem: Coulomb coefficient (0: smooth)"},
    {.name = "tangential_stiffness",
     .type = KeyType::kFloat,
     .member = field<&SoftLawConfig::tangential_stiffness>,
     .range = {.lo = 1e-9, .hi = 10.0},
     .default_text = "`2/7`",
     .doc = "with friction: k_t / k_n"},
    {.name = "tangential_damping",
     .type = KeyType::kFloat,
     .member = field<&SoftLawConfig::tangential_damping>,
     .range = {.lo = 0.0, .hi = 1e3},
     .doc = "with friction: gamma_t / gamma_n"},
};

const SoftConfig kSoftDefaults{};
constexpr KeyDecl kSoft[] = {
    {.name = "collisions",
     .type = KeyType::kString,
     .member = field<&SoftConfig::collisions>,
     .choices = &choices_of<&soft_collision_modes>,
     .doc = "event integrator: the collision map, or instantaneous collisions"},
    {.name = "tables",
     .type = KeyType::kBoolean,
     .member = field<&SoftConfig::tables>,
     .doc = "event integrator: lookup tables of the collision map"},
    {.name = "table_tolerance",
     .type = KeyType::kFloat,
     .member = field<&SoftConfig::table_tolerance>,
     .range = {.lo = 1e-10, .hi = 0.1, .hi_open = true, .why = "(a relative error)"},
     .doc = "relative accuracy of the tables"},
    {.name = "table_cache",
     .type = KeyType::kString,
     .member = field<&SoftConfig::table_cache>,
     .doc = "directory of the table cache (\"\": the default)"},
    {.name = "defer_releases",
     .type = KeyType::kBoolean,
     .member = field<&SoftConfig::defer_releases>,
     .doc = "event integrator: release isolated contacts at once"},
};

}  // namespace

constexpr KeyGroup kSoftLawGroup{"soft law", kSoftLaw, &kSoftLawDefaults};
constexpr KeyGroup kSoftGroup{"soft", kSoft, &kSoftDefaults};

}  // namespace kairos::key_tables
