// The contact-law keys ([contact], [[contact.pair]], walls) and the species of a pair.
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

// ----- contact laws

bool has_restitution_table(const void* c) {
  return !static_cast<const ContactConfig*>(c)->restitution_table.empty();
}

const ContactConfig kContactDefaults{};
constexpr KeyDecl kContactLaw[] = {
    {.name = "restitution",
     .type = KeyType::kFloat,
     .member = field<&ContactConfig::restitution>,
     .range = domain(kRestitutionDomain),
     .doc = "normal coefficient of restitution e"},
    {.name = "restitution_model",
     .type = KeyType::kString,
     .member = field<&ContactConfig::restitution_model>,
     .choices = &choices_of<&restitution_models>,
     .doc = "how e depends on the impact speed"},
    {.name = "restitution_speed",
     .type = KeyType::kFloat,
     .member = field<&ContactConfig::restitution_speed>,
     .range = between(1e-6, 1e6, Scale::kSpeed),
     .unit = "speed",
     .doc = "viscoelastic: the impact speed at which e = restitution"},
    {.name = "restitution_table",
     .type = KeyType::kSpeedTable,
     .member = field<&ContactConfig::restitution_table>,
     .default_text = "none",
     .doc = "table: [impact speed, e] pairs",
     .written = &has_restitution_table},
    {.name = "tangential_restitution",
     .type = KeyType::kFloat,
     .member = field<&ContactConfig::tangential_restitution>,
     .range = domain(kTangentialRestitutionDomain),
     .doc = "tangential coefficient of restitution beta (-1: smooth)"},
    {.name = "friction",
     .type = KeyType::kFloat,
     .member = field<&ContactConfig::friction>,
     .range = {.lo = kNonNegativeDomain.lo, .allow_infinity = true},
     .doc = "Coulomb friction coefficient (Walton); inf: no limit"},
    {.name = "elastic_below_speed",
     .type = KeyType::kFloat,
     .member = field<&ContactConfig::elastic_below_speed>,
     .range = up_to(1e9, Scale::kSpeed),
     .unit = "speed",
     .doc = "collisions slower than this are elastic (0: off)"},
};

const InteractionConfig kInteractionDefaults{};
constexpr KeyDecl kContact[] = {
    {.name = "tc",
     .type = KeyType::kFloat,
     .member = field<&InteractionConfig::tc>,
     .range = up_to(1e9, Scale::kTime),
     .unit = "time",
     .doc = "TC model: a collision this soon after another is elastic (0: off)"},
    {.name = "sleep_speed",
     .type = KeyType::kFloat,
     .member = field<&InteractionConfig::sleep_speed>,
     .range = {.lo = 0.0,
               .hi = 1e9,
               .scale = Scale::kSpeed,
               .also = -1.0,
               .why = "(or -1 for automatic)"},
     .default_text = "`-1.0` (automatic)",
     .unit = "speed",
     .doc = "resting particles under gravity sleep below this speed (-1: automatic, 0: never)"},
};

// Keys read by hand: the species of a pair, the face of a wall, the type of a bond.
constexpr KeyDecl kPairSpecies[] = {
    {.name = "species",
     .type = KeyType::kSpeciesPair,
     .default_text = "**required**",
     .doc = "the two species, by name"},
};

}  // namespace

constexpr KeyGroup kContactLawGroup{"contact law", kContactLaw, &kContactDefaults};
constexpr KeyGroup kContactGroup{"contact", kContact, &kInteractionDefaults};
constexpr KeyGroup kPairSpeciesGroup{"pair", kPairSpecies, nullptr};

}  // namespace kairos::key_tables
