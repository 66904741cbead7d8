// The [boundary] keys: walls, the container and outlets (the surface tables, planes, cylinders
// and spheres, declare theirs in io/tables/).
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

// ----- [boundary], [field], [driving]

const BoundaryConfig kBoundaryDefaults{};
constexpr KeyDecl kBoundary[] = {
    {.name = "open",
     .type = KeyType::kStrings,
     .member = field<&BoundaryConfig::open>,
     .range = {.by_rule = true},  // a face is a wall or open, not both
     .choices = &choices_in<&box_faces>,
     .default_text = "`[]`",
     .doc = "faces with no wall and no periodic image"},
    {.name = "shear_rate",
     .type = KeyType::kFloat,
     .member = field<&BoundaryConfig::shear_rate>,
     .range = {.lo = -1e6, .hi = 1e6, .scale = Scale::kRate},
     .unit = "1 / time",
     .doc = "Lees-Edwards shear rate (flow along x, gradient along y; 0: none)"},
};

const WallConfig kWallDefaults{};
constexpr KeyDecl kWall[] = {
    {.name = "velocity",
     .type = KeyType::kVector,
     .member = field<&WallConfig::velocity>,
     .range = {.lo = -1e9, .hi = 1e9, .scale = Scale::kSpeed},
     .default_text = "all `0.0`",
     .unit = "speed",
     .doc = "the wall's velocity: in its plane it slides, along its normal a piston"},
    {.name = "amplitude",
     .type = KeyType::kFloat,
     .member = field<&WallConfig::amplitude>,
     .range = up_to(1e6, Scale::kBoxEdge),
     .unit = "length",
     .doc = "vibration amplitude A along the normal"},
    {.name = "frequency",
     .type = KeyType::kFloat,
     .member = field<&WallConfig::frequency>,
     .range = up_to(1e9, Scale::kRate),
     .unit = "cycles per unit time",
     .doc = "vibration frequency f"},
    {.name = "phase",
     .type = KeyType::kFloat,
     .member = field<&WallConfig::phase>,
     .range = {.lo = -1e9, .hi = 1e9, .why = "(radians)"},
     .unit = "radians",
     .doc = "vibration phase"},
    {.name = "mass",
     .type = KeyType::kFloat,
     .member = field<&WallConfig::mass>,
     .range = {.lo = 0.0, .hi = 1e9},
     .unit = "mass",
     .doc = "a wall with mass M moves along its axis, pushed by the particles (0: infinite mass)"},
    {.name = "force",
     .type = KeyType::kFloat,
     .member = field<&WallConfig::force>,
     .range = {.lo = -1e9, .hi = 1e9},
     .unit = "force",
     .doc = "constant force on a wall with mass, along its normal into the box"},
};

const ContainerConfig kContainerDefaults{};
constexpr KeyDecl kContainer[] = {
    {.name = "axis",
     .type = KeyType::kString,
     .member = field<&ContainerConfig::axis>,
     .range = {.by_rule = true},  // "" is none; both faces of the axis must be walls
     .choices = &choices_in<&axes>,
     .doc = "the axis whose two walls are joined as the container (\"\": none)"},
    {.name = "mass",
     .type = KeyType::kFloat,
     .member = field<&ContainerConfig::mass>,
     .range = {.lo = 0.0, .hi = 1e9},
     .unit = "mass",
     .doc = "the container's mass M (required with an axis)"},
    {.name = "spring_stiffness",
     .type = KeyType::kFloat,
     .member = field<&ContainerConfig::spring_stiffness>,
     .range = {.lo = 0.0, .hi = 1e15},
     .unit = "force / length",
     .doc = "stiffness k of the spring to the anchor (0: no spring)"},
    {.name = "spring_damping",
     .type = KeyType::kFloat,
     .member = field<&ContainerConfig::spring_damping>,
     .range = {.lo = 0.0, .hi = 1e15, .by_rule = true},  // below 2 sqrt(k M)
     .unit = "force / speed",
     .doc = "damping c of the dashpot beside the spring (underdamped: c < 2 sqrt(k M))"},
    {.name = "drive_amplitude",
     .type = KeyType::kFloat,
     .member = field<&ContainerConfig::drive_amplitude>,
     .range = {.lo = 0.0, .hi = 1e9},
     .unit = "length",
     .doc = "the anchor's amplitude A: it moves as A sin(2 pi f t + phase)"},
    {.name = "drive_frequency",
     .type = KeyType::kFloat,
     .member = field<&ContainerConfig::drive_frequency>,
     .range = {.lo = 0.0, .hi = 1e9, .by_rule = true},  // not at an undamped resonance
     .unit = "cycles per unit time",
     .doc = "the anchor's frequency f"},
    {.name = "drive_phase",
     .type = KeyType::kFloat,
     .member = field<&ContainerConfig::drive_phase>,
     .range = {.lo = -1e9, .hi = 1e9, .why = "(radians)"},
     .unit = "radians",
     .doc = "the anchor's phase"},
};

const OutletConfig kOutletDefaults{};
constexpr KeyDecl kOutlet[] = {
    {.name = "normal",
     .type = KeyType::kVector,
     .member = field<&OutletConfig::normal>,
     .range = {.by_rule = true},  // not zero, no component along a periodic axis
     .default_text = "**required**",
     .doc = "the outlet plane's normal, pointing to the side the particles come from "
            "(normalised); a centre crossing the plane the other way passes"},
    {.name = "point",
     .type = KeyType::kVector,
     .member = field<&OutletConfig::point>,
     .range = {.by_rule = true},  // finite
     .default_text = "**required**",
     .unit = "length",
     .doc = "a point of the outlet's plane"},
    {.name = "insert_lower",
     .type = KeyType::kVector,
     .member = field<&OutletConfig::insert_lower>,
     .range = {.by_rule = true},  // finite, on the particles' side of the plane
     .default_text = "**required**",
     .unit = "length",
     .doc = "the low corner of the insertion region, where a particle that passed is put back "
            "(its centre, at a random free place)"},
    {.name = "insert_upper",
     .type = KeyType::kVector,
     .member = field<&OutletConfig::insert_upper>,
     .range = {.by_rule = true},  // finite, not below insert_lower
     .default_text = "**required**",
     .unit = "length",
     .doc = "the high corner of the insertion region"},
    {.name = "insert_velocity",
     .type = KeyType::kVector,
     .member = field<&OutletConfig::insert_velocity>,
     .range = {.by_rule = true},  // finite
     .default_text = "at rest",
     .unit = "length / time",
     .doc = "the velocity a particle is put back with (no spin)"},
    {.name = "seed",
     .type = KeyType::kUnsigned,
     .member = field<&OutletConfig::seed>,
     .doc = "seeds the places drawn in the insertion region"},
};

constexpr KeyDecl kWallFace[] = {
    {.name = "face",
     .type = KeyType::kString,
     .choices = &choices_in<&box_faces>,
     .default_text = "**required**",
     .doc = "which face of the box"},
};

}  // namespace

constexpr KeyGroup kBoundaryGroup{"boundary", kBoundary, &kBoundaryDefaults};
constexpr KeyGroup kWallGroup{"wall", kWall, &kWallDefaults};
constexpr KeyGroup kContainerGroup{"container", kContainer, &kContainerDefaults};
constexpr KeyGroup kOutletGroup{"outlet", kOutlet, &kOutletDefaults};
constexpr KeyGroup kWallFaceGroup{"wall face", kWallFace, nullptr};

}  // namespace kairos::key_tables
