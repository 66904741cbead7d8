// The [[potential]] and [[bond]] keys.
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

// ----- [[potential]], [[bond]]

bool is_spring_dashpot(const void* p) {
  return potential_kinds().is(static_cast<const PotentialSpec*>(p)->kind,
                              PotentialKind::kSpringDashpot);
}
bool is_stepped(const void* p) {
  return !is_spring_dashpot(p);
}
bool spring_dashpot_damping(const void* p) {
  return is_spring_dashpot(p) && !(static_cast<const PotentialSpec*>(p)->restitution > 0.0);
}
bool spring_dashpot_restitution(const void* p) {
  return is_spring_dashpot(p) && static_cast<const PotentialSpec*>(p)->restitution > 0.0;
}

const PotentialSpec kPotentialDefaults{};
constexpr KeyDecl kPotential[] = {
    {.name = "lambda",
     .type = KeyType::kFloat,
     .member = field<&PotentialSpec::lambda>,
     .doc = "square_well, square_shoulder: range in units of the contact distance"},
    {.name = "depth",
     .type = KeyType::kFloat,
     .member = field<&PotentialSpec::depth>,
     .range = by_rule(between(1e-9, 1e9, Scale::kEnergy)),
     .unit = "energy",
     .doc = "square_well: depth; square_shoulder: height"},
    {.name = "epsilon",
     .type = KeyType::kFloat,
     .member = field<&PotentialSpec::epsilon>,
     .unit = "energy",
     .doc = "continuous kinds: energy scale"},
    {.name = "sigma",
     .type = KeyType::kFloat,
     .member = field<&PotentialSpec::sigma>,
     .range = by_rule(between(1e-9, 1e9, Scale::kLength)),
     .unit = "length",
     .doc = "continuous kinds: length scale"},
    {.name = "cutoff",
     .type = KeyType::kFloat,
     .member = field<&PotentialSpec::cutoff>,
     .default_text = "`0` (the kind's default)",
     .unit = "length",
     .doc = "continuous kinds: where the potential ends (0: the kind's default)"},
    {.name = "kappa",
     .type = KeyType::kFloat,
     .member = field<&PotentialSpec::kappa>,
     .range = by_rule(up_to(1e9, Scale::kInverseLength)),
     .unit = "1 / length",
     .doc = "yukawa: screening"},
    {.name = "alpha",
     .type = KeyType::kFloat,
     .member = field<&PotentialSpec::alpha>,
     .range = by_rule(between(1e-9, 1e9, Scale::kInverseLength)),
     .unit = "1 / length",
     .doc = "morse: stiffness of the well"},
    {.name = "r_min",
     .type = KeyType::kFloat,
     .member = field<&PotentialSpec::r_min>,
     .range = by_rule(between(1e-9, 1e9, Scale::kLength)),
     .default_text = "`0` (= σ)",
     .unit = "length",
     .doc = "morse: position of the minimum (0: sigma)"},
    {.name = "max_length",
     .type = KeyType::kFloat,
     .member = field<&PotentialSpec::max_length>,
     .unit = "length",
     .doc = "tether, spring: the longest the bond can stretch"},
    {.name = "stiffness",
     .type = KeyType::kFloat,
     .member = field<&PotentialSpec::stiffness>,
     .range = by_rule(between(1e-9, 1e15, Scale::kStiffness)),
     .default_text = "—",
     .unit = "energy / length^2",
     .doc = "spring, spring_dashpot: spring constant k"},
    {.name = "length",
     .type = KeyType::kFloat,
     .member = field<&PotentialSpec::length>,
     .default_text = "—",
     .unit = "length",
     .doc = "spring: rest length; spring_dashpot: where the contact begins"},
    {.name = "temperature",
     .type = KeyType::kFloat,
     .member = field<&PotentialSpec::temperature>,
     .range = between(1e-9, 1e9, Scale::kEnergy),  // the reader: > 0; the virial rule: all
     .unit = "energy",
     .doc = "kT of the virial shell-energy rule"},
    {.name = "boundaries",
     .type = KeyType::kFloats,
     .member = field<&PotentialSpec::boundaries>,
     .default_text = "none",
     .unit = "length",
     .doc = "steps: decreasing radii, the last the hard core"},
    {.name = "energies",
     .type = KeyType::kFloats,
     .member = field<&PotentialSpec::energies>,
     .default_text = "none",
     .unit = "energy",
     .doc = "steps: the energy of each shell"},
    {.name = "shifted",
     .type = KeyType::kBoolean,
     .member = field<&PotentialSpec::shifted>,
     .doc = "shift the potential to 0 at the cut-off"},
    {.name = "file",
     .type = KeyType::kString,
     .member = field<&PotentialSpec::file>,
     .doc = "tabulated: the file of r and U"},
    {.name = "steps",
     .type = KeyType::kInteger,
     .member = field<&PotentialSpec::steps>,
     .range = counted,
     .doc = "continuous kinds: number of steps"},
    {.name = "placement",
     .type = KeyType::kString,
     .member = field<&PotentialSpec::placement>,
     .choices = &choices_of<&step_placements>,
     .doc = "where the step boundaries go",
     .written = &is_stepped},
    {.name = "shell_energy",
     .type = KeyType::kString,
     .member = field<&PotentialSpec::shell_energy>,
     .choices = &choices_of<&step_energy_rules>,
     .doc = "the energy of each shell",
     .written = &is_stepped},
};
// [[potential]] only.
constexpr KeyDecl kSpringDashpot[] = {
    {.name = "restitution",
     .type = KeyType::kFloat,
     .member = field<&PotentialSpec::restitution>,
     .range = domain(kSoftRestitutionDomain),
     .default_text = "none",
     .doc = "spring_dashpot: head-on restitution (instead of damping)",
     .written = &spring_dashpot_restitution},
    {.name = "damping",
     .type = KeyType::kFloat,
     .member = field<&PotentialSpec::damping>,
     .range = domain(kNonNegativeDomain),
     .default_text = "`0`",
     .unit = "force / speed",
     .doc = "spring_dashpot: dashpot coefficient gamma",
     .written = &spring_dashpot_damping},
    {.name = "force_zero",
     .type = KeyType::kBoolean,
     .member = field<&PotentialSpec::force_zero>,
     .doc = "spring_dashpot: no net attraction while separating",
     .written = &is_spring_dashpot},
};

constexpr KeyDecl kPotentialSpecies[] = {
    {.name = "species",
     .type = KeyType::kSpeciesPair,
     .default_text = "none: every pair",
     .doc = "the two species, by name (none: every pair)"},
    {.name = "kind",
     .type = KeyType::kString,
     .choices = &choices_of<&pair_potential_kinds>,
     .default_text = "**required**",
     .doc = "the pair potential"},
};

const BondConfig kBondDefaults{};
constexpr KeyDecl kBondType[] = {
    {.name = "type",
     .type = KeyType::kString,
     .member = field<&BondConfig::type>,
     .doc = "the bond type it applies to"},
    {.name = "kind",
     .type = KeyType::kString,
     .choices = &choices_of<&bond_potential_kinds>,
     .default_text = "**required**",
     .doc = "the bond potential"},
};

}  // namespace

constexpr KeyGroup kPotentialGroup{"potential", kPotential, &kPotentialDefaults};
constexpr KeyGroup kSpringDashpotGroup{"spring_dashpot", kSpringDashpot, &kPotentialDefaults};
constexpr KeyGroup kPotentialSpeciesGroup{"potential species", kPotentialSpecies, nullptr};
constexpr KeyGroup kBondTypeGroup{"bond type", kBondType, &kBondDefaults};

}  // namespace kairos::key_tables
