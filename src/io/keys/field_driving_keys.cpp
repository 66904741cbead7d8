// The [field] and [driving] keys.
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

// ----- [field], [driving]

const FieldConfig kFieldDefaults{};
constexpr KeyDecl kField[] = {
    {.name = "gravity",
     .type = KeyType::kVector,
     .member = field<&FieldConfig::gravity>,
     .default_text = "all `0.0` (none)",
     .unit = "acceleration",
     .doc = "uniform acceleration of every particle"},
};

const DrivingConfig kDrivingDefaults{};
constexpr KeyDecl kDriving[] = {
    {.name = "kind",
     .type = KeyType::kString,
     .member = field<&DrivingConfig::kind>,
     .choices = &choices_of<&driving_kinds>,
     .doc = "stochastic driving"},
    {.name = "rate",
     .type = KeyType::kFloat,
     .member = field<&DrivingConfig::rate>,
     .range = {.lo = 1e-9, .hi = 1e3, .scale = Scale::kCollisionRate},
     .unit = "per particle per unit time",
     .doc = "driving events per particle per unit time"},
    {.name = "temperature",
     .type = KeyType::kFloat,
     .member = field<&DrivingConfig::temperature>,
     .range = between(1e-9, 1e9, Scale::kEnergy),
     .unit = "energy",
     .doc = "andersen: the bath temperature"},
    {.name = "strength",
     .type = KeyType::kFloat,
     .member = field<&DrivingConfig::strength>,
     .range = {.lo = 1e-9, .hi = 1e9, .scale = Scale::kSpeedSquaredPerTime, .also = 0.0},
     .unit = "velocity variance per unit time",
     .doc = "white_noise: the velocity variance per unit time per component"},
};

}  // namespace

constexpr KeyGroup kFieldGroup{"field", kField, &kFieldDefaults};
constexpr KeyGroup kDrivingGroup{"driving", kDriving, &kDrivingDefaults};

}  // namespace kairos::key_tables
