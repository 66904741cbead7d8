// The [system] and [[system.species]] keys.
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

// ----- [system]

const SystemConfig kSystemDefaults{};
constexpr KeyDecl kSystem[] = {
    {.name = "dimension",
     .type = KeyType::kInteger,
     .member = field<&SystemConfig::dimension>,
     .range = {.lo = 2.0, .hi = 3.0},
     .doc = "spatial dimension"},
    {.name = "particles",
     .type = KeyType::kUnsigned,
     .member = field<&SystemConfig::particles>,
     .range = {.lo = 2.0, .hi = kMaxParticles, .by_rule = true},
     .default_text = "**required**",
     .doc = "number of particles N (optional with initial_state)"},
    {.name = "packing_fraction",
     .type = KeyType::kFloat,
     .member = field<&SystemConfig::packing_fraction>,
     .range = {.lo = 1e-9, .hi = 1.0, .hi_open = true, .by_rule = true},
     .default_text = "**required**",
     .doc = "fraction of the box covered by particles (optional with initial_state)"},
    {.name = "lattice",
     .type = KeyType::kString,
     .member = field<&SystemConfig::lattice>,
     .range = {.by_rule = true},  // "" is the default; the message names the dimension
     .choices = &choices_in<&lattices>,
     .default_text = "`\"fcc\"` in 3D, `\"hex\"` in 2D",
     .doc = "initial arrangement"},
    {.name = "temperature",
     .type = KeyType::kFloat,
     .member = field<&SystemConfig::temperature>,
     .range = {.lo = 1e-9,
               .hi = 1e9,
               .why = "(the unit of energy kT: reduced units keep it near 1)"},
     .unit = "kT",
     .doc = "kT of the initial Maxwell-Boltzmann velocities"},
    {.name = "seed",
     .type = KeyType::kUnsigned,
     .member = field<&SystemConfig::seed>,
     .doc = "seeds all randomness of the run"},
    {.name = "size_distribution",
     .type = KeyType::kString,
     .member = field<&SystemConfig::size_distribution>,
     .choices = &choices_of<&size_distributions>,
     .doc = "per-particle diameters: the species' diameter times a factor of mean 1"},
    {.name = "polydispersity",
     .type = KeyType::kFloat,
     .member = field<&SystemConfig::polydispersity>,
     .range = by_rule({.lo = 0.0, .hi = 1.0}),
     .doc = "the relative standard deviation of the diameters (size_distribution)"},
    {.name = "initial_state",
     .type = KeyType::kString,
     .member = field<&SystemConfig::initial_state>,
     .doc = "GSD file to start from (its last frame); \"\" generates the state"},
    {.name = "box_scale",
     .type = KeyType::kVector,
     .member = field<&SystemConfig::box_scale>,
     .range = {.lo = 1.0, .hi = 1e6},
     .default_text = "all `1.0`",
     .doc = "generated states: factors of the box edges, empty space at the high ends",
     .fill = 1.0},
    {.name = "box_place",
     .type = KeyType::kVector,
     .member = field<&SystemConfig::box_place>,
     .range = {.lo = 0.0, .hi = 1.0},
     .default_text = "all `0.0`",
     .doc = "generated states: where the particles sit in the box box_scale stretched, as the "
            "fraction of the added space below them (0: at the low end, 1: at the high end)",
     .fill = 0.0},
    {.name = "fill_inside",
     .type = KeyType::kBoolean,
     .member = field<&SystemConfig::fill_inside>,
     .doc = "generated states: particles outside a plane, cylinder or sphere wall are moved to "
            "random free places inside every wall"},
    {.name = "chain_length",
     .type = KeyType::kUnsigned,
     .member = field<&SystemConfig::chain_length>,
     .doc = "beads per linear chain (0: no chains)"},
    {.name = "chain_spacing",
     .type = KeyType::kFloat,
     .member = field<&SystemConfig::chain_spacing>,
     .range = non_negative,
     .unit = "length",
     .doc = "lattice spacing of the chains (0: between the diameter and the bond's range)"},
};

const SpeciesConfig kSpeciesDefaults{};
constexpr KeyDecl kSpecies[] = {
    {.name = "name",
     .type = KeyType::kString,
     .member = field<&SpeciesConfig::name>,
     .doc = "species name, unique and non-empty"},
    {.name = "diameter",
     .type = KeyType::kFloat,
     .member = field<&SpeciesConfig::diameter>,
     .range = unit_range,
     .unit = "length",
     .doc = "hard-core diameter"},
    {.name = "mass",
     .type = KeyType::kFloat,
     .member = field<&SpeciesConfig::mass>,
     .range = unit_range,
     .unit = "mass",
     .doc = "particle mass"},
    {.name = "fraction",
     .type = KeyType::kFloat,
     .member = field<&SpeciesConfig::fraction>,
     .range = unit_range,
     .doc = "relative number fraction"},
    {.name = "inertia_factor",
     .type = KeyType::kFloat,
     .member = field<&SpeciesConfig::inertia_factor>,
     .range = {.lo = 1e-9,
               .hi = 1.0,
               .also = 0.0,
               .why = "(I = q m R^2 with the mass within R; or 0 for the default: 2/5 for "
                      "spheres, 1/2 for disks)"},
     .doc = "q of the moment of inertia I = q m R^2 (0: 2/5 spheres, 1/2 disks)"},
    {.name = "fixed",
     .type = KeyType::kBoolean,
     .member = field<&SpeciesConfig::fixed>,
     .doc = "its particles never move (infinite mass, at rest): floors, obstacles"},
};

}  // namespace

constexpr KeyGroup kSystemGroup{"system", kSystem, &kSystemDefaults};
constexpr KeyGroup kSpeciesGroup{"species", kSpecies, &kSpeciesDefaults};

}  // namespace kairos::key_tables
