// The declarations of every config key (io/config_keys.hpp), group by group.
#include "io/config_keys.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstdint>

#include "interactions/parameter_domain.hpp"
#include "interactions/potential_spec.hpp"
#include "io/config.hpp"
#include "io/config_choices.hpp"

namespace kairos {

namespace {

constexpr double kInf = Range::kInf;
constexpr double kMaxParticles = 2147483647.0;  // 2^31 - 1: the engine numbers in 31 bits

template <class E>
std::vector<std::string_view> names_of(const Choices<E>& choices) {
  std::vector<std::string_view> out;
  for (const ChoiceEntry<E>& e : choices.entries()) out.push_back(e.name);
  return out;
}
template <auto Registry>
std::vector<std::string_view> choices_of(int) {
  return names_of(Registry());
}
template <auto Registry>
std::vector<std::string_view> choices_in(int dimension) {
  return names_of(Registry(dimension));
}

// Ranges.
constexpr Range positive{.lo = 0.0, .lo_open = true};
constexpr Range non_negative{.lo = 0.0};
constexpr Range unit_range{.lo = 1e-9, .hi = 1e9};  // a key that is a unit: near 1
constexpr Range fraction{.lo = 0.0, .hi = 1.0};
constexpr Range counted{.lo = 1.0, .hi = 100000.0};
constexpr Range up_to(double hi, Scale scale) {
  return {.lo = 0.0, .hi = hi, .scale = scale};
}
constexpr Range between(double lo, double hi, Scale scale) {
  return {.lo = lo, .hi = hi, .scale = scale};
}
// A range that depends on another key (a potential's kind, a soft law's model): checked by the
// reader's rule for it, and by run/config_ranges.cpp for the kinds that use it.
// A physical domain of interactions/parameter_domain.hpp as a key's range.
constexpr Range domain(const ParameterDomain& d) {
  return {.lo = d.lo, .hi = d.hi, .lo_open = d.lo_open, .hi_open = d.hi_open};
}
constexpr Range by_rule(Range r) {
  r.by_rule = true;
  return r;
}

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

bool span_given(const void* p) {
  return !static_cast<const PlaneConfig*>(p)->span_axis.empty();
}
bool span_min_given(const void* p) {
  return std::isfinite(static_cast<const PlaneConfig*>(p)->span_min);
}
bool span_max_given(const void* p) {
  return std::isfinite(static_cast<const PlaneConfig*>(p)->span_max);
}

const PlaneConfig kPlaneDefaults{};
constexpr KeyDecl kPlane[] = {
    {.name = "normal",
     .type = KeyType::kVector,
     .member = field<&PlaneConfig::normal>,
     .range = {.by_rule = true},  // not zero, no component along a periodic axis
     .default_text = "**required**",
     .doc = "the plane's normal, pointing into the domain (normalised)"},
    {.name = "point",
     .type = KeyType::kVector,
     .member = field<&PlaneConfig::point>,
     .range = {.by_rule = true},  // finite
     .default_text = "**required**",
     .unit = "length",
     .doc = "a point of the plane at t = 0"},
    {.name = "span_axis",
     .type = KeyType::kString,
     .member = field<&PlaneConfig::span_axis>,
     .range = {.by_rule = true},  // a bounded axis the plane runs along; a still plane
     .choices = &choices_in<&axes>,
     .doc = "cut the plane to a strip along this axis, with edges at its ends (a silo's floor "
            "beside its orifice, a hopper's side); \"\": the whole plane",
     .written = &span_given},
    {.name = "span_min",
     .type = KeyType::kFloat,
     .member = field<&PlaneConfig::span_min>,
     .range = {.by_rule = true},  // below span_max
     .default_text = "unbounded",
     .unit = "length",
     .doc = "the strip's low end along span_axis (of the plane's points)",
     .written = &span_min_given},
    {.name = "span_max",
     .type = KeyType::kFloat,
     .member = field<&PlaneConfig::span_max>,
     .range = {.by_rule = true},  // above span_min
     .default_text = "unbounded",
     .unit = "length",
     .doc = "the strip's high end along span_axis",
     .written = &span_max_given},
};

const CylinderConfig kCylinderDefaults{};
constexpr KeyDecl kCylinder[] = {
    {.name = "axis",
     .type = KeyType::kString,
     .member = field<&CylinderConfig::axis>,
     .range = {.by_rule = true},  // x, y or z; 2D: z only
     .default_text = "`\"z\"`",
     .doc = "the direction of its axis: x, y or z (2D: z, the circle in the plane)"},
    {.name = "center",
     .type = KeyType::kVector,
     .member = field<&CylinderConfig::center>,
     .range = {.by_rule = true},  // finite
     .default_text = "**required**",
     .unit = "length",
     .doc = "a point of its axis"},
    {.name = "radius",
     .type = KeyType::kFloat,
     .member = field<&CylinderConfig::radius>,
     .range = {.lo = 0.0, .lo_open = true, .by_rule = true},
     .default_text = "**required**",
     .unit = "length",
     .doc = "its radius"},
    {.name = "inside",
     .type = KeyType::kBoolean,
     .member = field<&CylinderConfig::inside>,
     .doc = "the particles are inside it (a drum, a silo); false: outside (an obstacle)"},
    {.name = "angular_velocity",
     .type = KeyType::kFloat,
     .member = field<&CylinderConfig::angular_velocity>,
     .range = {.lo = -1e6, .hi = 1e6, .scale = Scale::kRate},
     .unit = "radians / time",
     .doc = "its rotation about the axis, right-handed (a rotating drum)"},
};

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

// ----- [run], [output]

bool equilibration_in_time(const void* r) {
  return static_cast<const RunConfig*>(r)->equilibration_time >= 0.0;
}
bool equilibration_in_collisions(const void* r) {
  return !equilibration_in_time(r);
}
bool production_in_time(const void* r) {
  return static_cast<const RunConfig*>(r)->time > 0.0;
}
bool production_in_collisions(const void* r) {
  return !production_in_time(r);
}

const RunConfig kRunDefaults{};
constexpr KeyDecl kRun[] = {
    {.name = "equilibration_time",
     .type = KeyType::kFloat,
     .member = field<&RunConfig::equilibration_time>,
     .range = up_to(1e9, Scale::kTime),
     .default_text = "none",
     .unit = "time",
     .doc = "equilibration length in simulated time (instead of collisions)",
     .written = &equilibration_in_time},
    {.name = "equilibration_collisions_per_particle",
     .type = KeyType::kFloat,
     .member = field<&RunConfig::equilibration_collisions_per_particle>,
     .range = {.lo = 0.0, .hi = 1e9},
     .unit = "collisions per particle",
     .doc = "equilibration length",
     .written = &equilibration_in_collisions},
    {.name = "time",
     .type = KeyType::kFloat,
     .member = field<&RunConfig::time>,
     .range = {.lo = 0.0, .hi = 1e9, .lo_open = true, .scale = Scale::kTime},
     .default_text = "none",
     .unit = "time",
     .doc = "production length in simulated time (instead of collisions)",
     .written = &production_in_time},
    {.name = "collisions_per_particle",
     .type = KeyType::kFloat,
     .member = field<&RunConfig::collisions_per_particle>,
     .range = {.lo = 0.0, .hi = 1e9, .lo_open = true},
     .unit = "collisions per particle",
     .doc = "production length",
     .written = &production_in_collisions},
    {.name = "event_queue",
     .type = KeyType::kString,
     .member = field<&RunConfig::event_queue>,
     .choices = &choices_of<&event_queues>,
     .doc = "event queue (bit-identical runs with any)"},
    {.name = "max_wall_seconds",
     .type = KeyType::kFloat,
     .member = field<&RunConfig::max_wall_seconds>,
     .range = {.lo = 0.0, .hi = 1e9, .why = "(seconds; 0: no limit)"},
     .unit = "seconds",
     .doc = "wall-clock limit (0: none)"},
    {.name = "size_levels",
     .type = KeyType::kBoolean,
     .member = field<&RunConfig::size_levels>,
     .doc = "two cell levels for wide size distributions when they apply (same physics)"},
    {.name = "validate",
     .type = KeyType::kBoolean,
     .member = field<&RunConfig::validate>,
     .doc = "debug: check the engine against brute force after every event"},
    {.name = "integrator",
     .type = KeyType::kString,
     .member = field<&RunConfig::integrator>,
     .choices = &choices_of<&integrators>,
     .doc = "event-driven engine or the DEM reference integrator"},
    {.name = "time_step",
     .type = KeyType::kFloat,
     .member = field<&RunConfig::time_step>,
     .range = {.lo = 1e-12, .hi = 1.0, .scale = Scale::kTime, .also = 0.0},
     .unit = "time",
     .doc = "dem: the time step (0: automatic)"},
};

bool has_interval_unit(const void* o) {
  return !static_cast<const OutputConfig*>(o)->interval_unit.empty();
}

// The keys of log-spaced frames are written (and act) only with them.
bool log_spaced(const void* o) {
  return static_cast<const OutputConfig*>(o)->trajectory_spacing == "log";
}

const OutputConfig kOutputDefaults{};
constexpr KeyDecl kOutput[] = {
    {.name = "directory",
     .type = KeyType::kString,
     .member = field<&OutputConfig::directory>,
     .doc = "output directory (-o replaces it)"},
    {.name = "thermo_interval",
     .type = KeyType::kFloat,
     .member = field<&OutputConfig::thermo_interval>,
     .range = non_negative,
     .unit = "interval_unit",
     .doc = "between thermo rows (0: automatic)"},
    {.name = "trajectory_interval",
     .type = KeyType::kFloat,
     .member = field<&OutputConfig::trajectory_interval>,
     .range = non_negative,
     .unit = "interval_unit",
     .doc = "between trajectory frames (0: automatic)"},
    {.name = "restart_interval",
     .type = KeyType::kFloat,
     .member = field<&OutputConfig::restart_interval>,
     .range = non_negative,
     .unit = "interval_unit",
     .doc = "between restart files (0: at the end only)"},
    {.name = "interval_unit",
     .type = KeyType::kString,
     .member = field<&OutputConfig::interval_unit>,
     .choices = &choices_of<&interval_units>,
     .default_text = "the production length's",
     .doc = "the unit of the three intervals",
     .written = &has_interval_unit},
    {.name = "trajectory",
     .type = KeyType::kBoolean,
     .member = field<&OutputConfig::trajectory>,
     .doc = "write trajectory.gsd"},
    {.name = "trajectory_phases",
     .type = KeyType::kString,
     .member = field<&OutputConfig::trajectory_phases>,
     .choices = &choices_of<&trajectory_phases>,
     .doc = "trajectory frames of every phase, or of the production only"},
    {.name = "trajectory_fields",
     .type = KeyType::kStrings,
     .member = field<&OutputConfig::trajectory_fields>,
     .range = {.by_rule = true},  // position required, no name twice, what the state has
     .choices = &choices_of<&trajectory_fields>,
     .default_text = "`[]`",
     .doc = "per-particle fields of every frame ([]: every field the state has)"},
    {.name = "trajectory_precision",
     .type = KeyType::kString,
     .member = field<&OutputConfig::trajectory_precision>,
     .choices = &choices_of<&trajectory_precisions>,
     .doc = "float32 or float64 floating-point chunks in trajectory.gsd"},
    {.name = "trajectory_spacing",
     .type = KeyType::kString,
     .member = field<&OutputConfig::trajectory_spacing>,
     .choices = &choices_of<&trajectory_spacings>,
     .doc = "trajectory frames evenly or logarithmically spaced"},
    {.name = "trajectory_frames_per_decade",
     .type = KeyType::kInteger,
     .member = field<&OutputConfig::trajectory_frames_per_decade>,
     .range = {.lo = 1.0, .hi = 1000.0},
     .doc = "log-spaced frames: frames per factor 10 of the lag",
     .written = &log_spaced},
    {.name = "trajectory_log_period",
     .type = KeyType::kFloat,
     .member = field<&OutputConfig::trajectory_log_period>,
     .range = non_negative,
     .unit = "interval_unit",
     .doc = "log-spaced frames: the sequence starts again every period (0: never)",
     .written = &log_spaced},
    {.name = "progress",
     .type = KeyType::kString,
     .member = field<&OutputConfig::progress>,
     .choices = &choices_of<&progress_modes>,
     .doc = "progress line on stderr"},
    {.name = "profile_axis",
     .type = KeyType::kString,
     .member = field<&OutputConfig::profile_axis>,
     .range = {.by_rule = true},  // "" is none; the message names the dimension
     .choices = &choices_in<&axes>,
     .doc = "profile.tsv along this axis (\"\": none)"},
    {.name = "profile_bins",
     .type = KeyType::kInteger,
     .member = field<&OutputConfig::profile_bins>,
     .range = counted,
     .doc = "slabs of the profile"},
};

// ----- [compress], [analysis]

const CompressConfig kCompressDefaults{};
constexpr KeyDecl kCompress[] = {
    {.name = "packing_fraction",
     .type = KeyType::kFloat,
     .member = field<&CompressConfig::packing_fraction>,
     .range = {.lo = 0.0, .hi = 1.0, .hi_open = true},
     .doc = "grow until this packing fraction (0: no such target)"},
    {.name = "pressure",
     .type = KeyType::kFloat,
     .member = field<&CompressConfig::pressure>,
     .range = up_to(1e13, Scale::kNone),
     .doc = "grow until the reduced pressure Z = PV/(NkT) reaches this (0: no such target)"},
    {.name = "jammed",
     .type = KeyType::kBoolean,
     .member = field<&CompressConfig::jammed>,
     .doc = "grow until jammed (Z above jammed_pressure)"},
    {.name = "growth_rate",
     .type = KeyType::kFloat,
     .member = field<&CompressConfig::growth_rate>,
     .range = {.lo = 1e-9, .hi = 10.0},
     .unit = "per unit time",
     .doc = "d sigma / dt over the starting diameter (diameters grow linearly)"},
    {.name = "thermostat_interval",
     .type = KeyType::kFloat,
     .member = field<&CompressConfig::thermostat_interval>,
     .range = {.lo = 1e-3, .hi = 1e6},
     .unit = "collisions per particle",
     .doc = "between rescalings of the velocities to system.temperature"},
    {.name = "jammed_pressure",
     .type = KeyType::kFloat,
     .member = field<&CompressConfig::jammed_pressure>,
     .range = {.lo = 10.0, .hi = 1e13},
     .doc = "the reduced pressure above which the packing is jammed"},
    {.name = "jammed_collision_rate",
     .type = KeyType::kFloat,
     .member = field<&CompressConfig::jammed_collision_rate>,
     .range = up_to(1e15, Scale::kNone),
     .unit = "per sqrt(kT/m)/sigma",
     .doc = "jammed also when the collisions per particle per unit time exceed this, in units "
            "of sqrt(kT/m) over the mean diameter (0: not used): the collision rate diverges at "
            "jamming"},
    {.name = "slowdown_pressure",
     .type = KeyType::kFloat,
     .member = field<&CompressConfig::slowdown_pressure>,
     .range = up_to(1e15, Scale::kNone),
     .doc = "above this reduced pressure the growth slows as sqrt(slowdown_pressure / Z), so "
            "that loose regions settle before jamming (0: never)"},
    {.name = "slowdown_floor",
     .type = KeyType::kFloat,
     .member = field<&CompressConfig::slowdown_floor>,
     .range = {.lo = 1e-6, .hi = 1.0},
     .doc = "the slowest growth, as a fraction of growth_rate"},
    {.name = "contact_gap",
     .type = KeyType::kFloat,
     .member = field<&CompressConfig::contact_gap>,
     .range = up_to(0.1, Scale::kNone),
     .doc = "contact network: pairs closer than this gap over their contact distance touch "
            "(0: 1e4 / Z, at most 1e-3, Z the final reduced pressure)"},
};

const AnalysisConfig kAnalysisDefaults{};
constexpr KeyDecl kAnalysis[] = {
    {.name = "msd",
     .type = KeyType::kBoolean,
     .member = field<&AnalysisConfig::msd>,
     .doc = "msd.tsv: mean-square displacement per species, self-diffusion coefficients"},
    {.name = "msd_time",
     .type = KeyType::kString,
     .member = field<&AnalysisConfig::msd_time>,
     .choices = &choices_of<&msd_time_scales>,
     .doc = "the MSD's clock: simulated time or collisions per particle (auto: collisions when "
            "the gas cools freely)"},
    {.name = "msd_interval",
     .type = KeyType::kFloat,
     .member = field<&AnalysisConfig::msd_interval>,
     .range = up_to(1e9, Scale::kNone),
     .unit = "msd_time",
     .doc = "between MSD samples (0: half the estimated mean free time, or half a collision per "
            "particle)"},
    {.name = "msd_particles",
     .type = KeyType::kInteger,
     .member = field<&AnalysisConfig::msd_particles>,
     .range = counted,
     .doc = "particles the MSD follows (evenly by number; all when fewer)"},
    {.name = "msd_fit_from",
     .type = KeyType::kFloat,
     .member = field<&AnalysisConfig::msd_fit_from>,
     .range = up_to(1e9, Scale::kNone),
     .unit = "msd_time",
     .doc = "shortest lag of the diffusion fit (0: automatic)"},
    {.name = "msd_fit_to",
     .type = KeyType::kFloat,
     .member = field<&AnalysisConfig::msd_fit_to>,
     .range = up_to(1e9, Scale::kNone),
     .unit = "msd_time",
     .doc = "longest lag of the diffusion fit (0: automatic)"},
    {.name = "vacf",
     .type = KeyType::kBoolean,
     .member = field<&AnalysisConfig::vacf>,
     .doc = "vacf.tsv: velocity autocorrelation on the MSD's lags, D by Green-Kubo"},
    {.name = "msd_viscosity",
     .type = KeyType::kFloat,
     .member = field<&AnalysisConfig::msd_viscosity>,
     .range = up_to(1e9, Scale::kNone),
     .unit = "viscosity",
     .doc = "shear viscosity for the Yeh-Hummer finite-size correction of D (0: none)"},
    {.name = "mutual_diffusion",
     .type = KeyType::kBoolean,
     .member = field<&AnalysisConfig::mutual_diffusion>,
     .doc = "mutual_diffusion.tsv: interdiffusion (Maxwell-Stefan) coefficients of a mixture"},
    {.name = "rdf",
     .type = KeyType::kBoolean,
     .member = field<&AnalysisConfig::rdf>,
     .doc = "rdf.tsv: g(r) per species pair, contact values"},
    {.name = "rdf_bins",
     .type = KeyType::kInteger,
     .member = field<&AnalysisConfig::rdf_bins>,
     .range = counted,
     .doc = "bins of g(r)"},
    {.name = "rdf_max_distance",
     .type = KeyType::kFloat,
     .member = field<&AnalysisConfig::rdf_max_distance>,
     .range = up_to(0.5, Scale::kBoxEdge),
     .unit = "length",
     .doc = "g(r) up to this distance (0: automatic)"},
    {.name = "structure_factor",
     .type = KeyType::kBoolean,
     .member = field<&AnalysisConfig::structure_factor>,
     .doc = "sk.tsv: S(k) on the box's wave vectors"},
    {.name = "sk_max",
     .type = KeyType::kFloat,
     .member = field<&AnalysisConfig::sk_max>,
     .range = up_to(100.0, Scale::kInverseLength),
     .unit = "1 / length",
     .doc = "S(k) up to this wave number (0: automatic)"},
    {.name = "bond_order",
     .type = KeyType::kBoolean,
     .member = field<&AnalysisConfig::bond_order>,
     .doc = "bond_order.tsv: Steinhardt q4, q6 (3D) or psi6 (2D)"},
    {.name = "bond_cutoff",
     .type = KeyType::kFloat,
     .member = field<&AnalysisConfig::bond_cutoff>,
     .range = {.lo = 1.0, .hi = 3.0},
     .unit = "contact distances",
     .doc = "neighbours of the bond order: closer than this"},
    {.name = "velocity_distribution",
     .type = KeyType::kBoolean,
     .member = field<&AnalysisConfig::velocity_distribution>,
     .doc = "velocity_distribution.tsv: one component in units of sqrt(kT / m)"},
    {.name = "interval",
     .type = KeyType::kFloat,
     .member = field<&AnalysisConfig::interval>,
     .range = non_negative,
     .unit = "interval_unit",
     .doc = "between samples of rdf, S(k), bond order, velocities (0: every thermo row)"},
    {.name = "transport",
     .type = KeyType::kBoolean,
     .member = field<&AnalysisConfig::transport>,
     .doc =
         "helfand.tsv: Einstein-Helfand viscosities and thermal conductivity, Green-Kubo beside"},
    {.name = "transport_interval",
     .type = KeyType::kFloat,
     .member = field<&AnalysisConfig::transport_interval>,
     .range = up_to(1e9, Scale::kTime),
     .unit = "time",
     .doc = "between samples of the Helfand moments, in simulated time (0: as the MSD's)"},
    {.name = "transport_fit_from",
     .type = KeyType::kFloat,
     .member = field<&AnalysisConfig::transport_fit_from>,
     .range = up_to(1e9, Scale::kTime),
     .unit = "time",
     .doc = "shortest lag of the Einstein-Helfand fits (0: automatic)"},
    {.name = "transport_fit_to",
     .type = KeyType::kFloat,
     .member = field<&AnalysisConfig::transport_fit_to>,
     .range = up_to(1e9, Scale::kTime),
     .unit = "time",
     .doc =
         "longest lag of the Einstein-Helfand fits and of the Green-Kubo integrals (0: automatic)"},
};

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

// Keys read by hand: the species of a pair, the face of a wall, the type of a bond.
constexpr KeyDecl kPairSpecies[] = {
    {.name = "species",
     .type = KeyType::kSpeciesPair,
     .default_text = "**required**",
     .doc = "the two species, by name"},
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
constexpr KeyDecl kWallFace[] = {
    {.name = "face",
     .type = KeyType::kString,
     .choices = &choices_in<&box_faces>,
     .default_text = "**required**",
     .doc = "which face of the box"},
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

constexpr KeyGroup kSystemGroup{"system", kSystem, &kSystemDefaults};
constexpr KeyGroup kSpeciesGroup{"species", kSpecies, &kSpeciesDefaults};
constexpr KeyGroup kContactLawGroup{"contact law", kContactLaw, &kContactDefaults};
constexpr KeyGroup kContactGroup{"contact", kContact, &kInteractionDefaults};
constexpr KeyGroup kBoundaryGroup{"boundary", kBoundary, &kBoundaryDefaults};
constexpr KeyGroup kWallGroup{"wall", kWall, &kWallDefaults};
constexpr KeyGroup kPlaneGroup{"plane", kPlane, &kPlaneDefaults};
constexpr KeyGroup kContainerGroup{"container", kContainer, &kContainerDefaults};
constexpr KeyGroup kOutletGroup{"outlet", kOutlet, &kOutletDefaults};
constexpr KeyGroup kCylinderGroup{"cylinder", kCylinder, &kCylinderDefaults};
constexpr KeyGroup kFieldGroup{"field", kField, &kFieldDefaults};
constexpr KeyGroup kDrivingGroup{"driving", kDriving, &kDrivingDefaults};
constexpr KeyGroup kRunGroup{"run", kRun, &kRunDefaults};
constexpr KeyGroup kOutputGroup{"output", kOutput, &kOutputDefaults};
constexpr KeyGroup kPotentialGroup{"potential", kPotential, &kPotentialDefaults};
constexpr KeyGroup kSpringDashpotGroup{"spring_dashpot", kSpringDashpot, &kPotentialDefaults};
constexpr KeyGroup kSoftLawGroup{"soft law", kSoftLaw, &kSoftLawDefaults};
constexpr KeyGroup kSoftGroup{"soft", kSoft, &kSoftDefaults};
constexpr KeyGroup kAnalysisGroup{"analysis", kAnalysis, &kAnalysisDefaults};
constexpr KeyGroup kCompressGroup{"compress", kCompress, &kCompressDefaults};
constexpr KeyGroup kPairSpeciesGroup{"pair", kPairSpecies, nullptr};
constexpr KeyGroup kPotentialSpeciesGroup{"potential species", kPotentialSpecies, nullptr};
constexpr KeyGroup kWallFaceGroup{"wall face", kWallFace, nullptr};
constexpr KeyGroup kBondTypeGroup{"bond type", kBondType, &kBondDefaults};

// Where each group appears: tables and their keys, in the order of the suggestions.
struct Placed {
  const KeyGroup* group;
  std::string_view shared_from = {};  // documented in that table
  bool last = false;  // suggested after every other key (an unknown 'restitution' elsewhere is
                      // offered contact.* and soft.* first)
};
struct Placement {
  std::string_view path;  // of the table
  KeyType type;           // kTable or kTableArray
  std::vector<Placed> groups;
};

std::vector<DeclaredKey> build() {
  const std::vector<Placement> placements = {
      {"system", KeyType::kTable, {{&kSystemGroup}}},
      {"system.species", KeyType::kTableArray, {{&kSpeciesGroup}}},
      {"potential",
       KeyType::kTableArray,
       {{&kPotentialSpeciesGroup}, {&kPotentialGroup}, {&kSpringDashpotGroup, {}, true}}},
      {"bond", KeyType::kTableArray, {{&kBondTypeGroup}, {&kPotentialGroup, "potential"}}},
      {"contact", KeyType::kTable, {{&kContactLawGroup}, {&kContactGroup}}},
      {"contact.pair",
       KeyType::kTableArray,
       {{&kPairSpeciesGroup}, {&kContactLawGroup, "contact"}}},
      {"boundary", KeyType::kTable, {{&kBoundaryGroup}}},
      {"boundary.wall",
       KeyType::kTableArray,
       {{&kWallFaceGroup}, {&kContactLawGroup, "contact"}, {&kWallGroup}}},
      {"boundary.container", KeyType::kTable, {{&kContainerGroup}}},
      {"boundary.outlet", KeyType::kTable, {{&kOutletGroup}}},
      {"boundary.plane",
       KeyType::kTableArray,
       {{&kPlaneGroup}, {&kContactLawGroup, "contact"}, {&kWallGroup, "boundary.wall"}}},
      {"boundary.cylinder",
       KeyType::kTableArray,
       {{&kCylinderGroup}, {&kContactLawGroup, "contact"}}},
      {"boundary.sphere",
       KeyType::kTableArray,
       {{&kCylinderGroup, "boundary.cylinder"}, {&kContactLawGroup, "contact"}}},
      {"driving", KeyType::kTable, {{&kDrivingGroup}}},
      {"field", KeyType::kTable, {{&kFieldGroup}}},
      {"run", KeyType::kTable, {{&kRunGroup}}},
      {"soft", KeyType::kTable, {{&kSoftGroup}, {&kSoftLawGroup}}},
      {"soft.pair", KeyType::kTableArray, {{&kPairSpeciesGroup}, {&kSoftLawGroup, "soft"}}},
      {"output", KeyType::kTable, {{&kOutputGroup}}},
      {"analysis", KeyType::kTable, {{&kAnalysisGroup}}},
      {"compress", KeyType::kTable, {{&kCompressGroup}}},
  };
  std::vector<DeclaredKey> out, last;
  for (const Placement& p : placements) {
    out.push_back({std::string(p.path), p.type, nullptr, nullptr, {}});
    const std::string prefix =
        p.type == KeyType::kTableArray ? std::string(p.path) + "[]" : std::string(p.path);
    if (p.type == KeyType::kTableArray)
      out.push_back({prefix, KeyType::kTable, nullptr, nullptr, {}});
    for (const Placed& g : p.groups) {
      for (const KeyDecl& d : g.group->keys) {
        (g.last ? last : out)
            .push_back(
                {prefix + "." + std::string(d.name), d.type, &d, g.group->defaults, g.shared_from});
      }
    }
  }
  out.insert(out.end(), last.begin(), last.end());
  return out;
}

// "system.species[3].name" -> "system.species[].name"
std::string schema_path(std::string_view path) {
  std::string out;
  for (std::size_t i = 0; i < path.size(); ++i) {
    out += path[i];
    if (path[i] == '[') {
      while (i + 1 < path.size() && path[i + 1] != ']') ++i;
    }
  }
  return out;
}

const char* const kSuperscripts[] = {"⁰", "¹", "²", "³", "⁴", "⁵", "⁶", "⁷", "⁸", "⁹"};

std::string scale_text(Scale scale) {
  switch (scale) {
    case Scale::kNone:
      return "";
    case Scale::kEnergy:
      return "kT";
    case Scale::kSpeed:
      return "v";
    case Scale::kTime:
      return "τ";
    case Scale::kRate:
      return "/ τ";
    case Scale::kLength:
      return "d";
    case Scale::kInverseLength:
      return "/ d";
    case Scale::kStiffness:
      return "kT / d²";
    case Scale::kModulus:
      return "kT / d³";
    case Scale::kCollisionRate:
      return "ω";
    case Scale::kBoxEdge:
      return "box edges";
    case Scale::kSpeedSquaredPerTime:
      return "v² / τ";
  }
  return "";
}

// The default of a key, as a TOML value in backquotes.
std::string doc_value(const KeyDecl& d, const void* defaults) {
  const Field& f = d.member;
  switch (f.cpp) {
    case CppType::kInt:
      return fmt::format("`{}`", f.of<int>(defaults));
    case CppType::kInt64:
      return fmt::format("`{}`", f.of<std::int64_t>(defaults));
    case CppType::kUint64:
      return fmt::format("`{}`", f.of<std::uint64_t>(defaults));
    case CppType::kDouble: {
      std::string s = fmt::format("{}", f.of<double>(defaults));
      if (s.find_first_of(".en") == std::string::npos) s += ".0";
      const auto e = s.find("e-0");  // 1e-06 -> 1e-6
      if (e != std::string::npos) s.erase(e + 2, 1);
      return fmt::format("`{}`", s);
    }
    case CppType::kString:
      return fmt::format("`\"{}\"`", f.of<std::string>(defaults));
    case CppType::kBool:
      return fmt::format("`{}`", f.of<bool>(defaults));
    case CppType::kDoubles:
    case CppType::kStrings:
    case CppType::kSpeedTable:
      break;
  }
  return "";
}

}  // namespace

const std::vector<DeclaredKey>& declared_keys() {
  static const std::vector<DeclaredKey> keys = build();
  return keys;
}

const DeclaredKey* find_declared(std::string_view path) {
  const std::string schema = schema_path(path);
  for (const DeclaredKey& k : declared_keys())
    if (k.path == schema) return &k;
  return nullptr;
}

const KeyGroup& system_keys() {
  return kSystemGroup;
}
const KeyGroup& species_keys() {
  return kSpeciesGroup;
}
const KeyGroup& contact_law_keys() {
  return kContactLawGroup;
}
const KeyGroup& contact_keys() {
  return kContactGroup;
}
const KeyGroup& boundary_keys() {
  return kBoundaryGroup;
}
const KeyGroup& wall_keys() {
  return kWallGroup;
}
const KeyGroup& plane_keys() {
  return kPlaneGroup;
}
const KeyGroup& container_keys() {
  return kContainerGroup;
}
const KeyGroup& outlet_keys() {
  return kOutletGroup;
}
const KeyGroup& cylinder_keys() {
  return kCylinderGroup;
}
const KeyGroup& field_keys() {
  return kFieldGroup;
}
const KeyGroup& driving_keys() {
  return kDrivingGroup;
}
const KeyGroup& run_keys() {
  return kRunGroup;
}
const KeyGroup& output_keys() {
  return kOutputGroup;
}
const KeyGroup& potential_keys() {
  return kPotentialGroup;
}
const KeyGroup& spring_dashpot_keys() {
  return kSpringDashpotGroup;
}
const KeyGroup& soft_law_keys() {
  return kSoftLawGroup;
}
const KeyGroup& soft_keys() {
  return kSoftGroup;
}
const KeyGroup& analysis_keys() {
  return kAnalysisGroup;
}
const KeyGroup& compress_keys() {
  return kCompressGroup;
}

std::string type_text(const KeyDecl& d) {
  switch (d.type) {
    case KeyType::kTable:
      return "table";
    case KeyType::kTableArray:
      return "array of tables";
    case KeyType::kInteger:
    case KeyType::kUnsigned:
      return "integer";
    case KeyType::kFloat:
      return "float";
    case KeyType::kString:
      return "string";
    case KeyType::kBoolean:
      return "boolean";
    case KeyType::kFloats:
      return "array of floats";
    case KeyType::kVector:
      return "array of D floats";
    case KeyType::kStrings:
      return "array of strings";
    case KeyType::kSpeciesPair:
      return "array of 2 strings";
    case KeyType::kSpeedTable:
      return "array of [speed, e] pairs";
  }
  return "";
}

std::string default_text(const DeclaredKey& key) {
  if (key.shared_from == "potential") return "as in `[[potential]]`";
  if (!key.shared_from.empty()) return fmt::format("from `[{}]`", key.shared_from);
  const KeyDecl& d = *key.decl;
  if (!d.default_text.empty() || key.defaults == nullptr || !d.member)
    return std::string(d.default_text);
  return doc_value(d, key.defaults);
}

std::string doc_number(double v) {
  if (v == kInf) return "∞";
  if (v < 0.0) return "−" + doc_number(-v);
  if (v == kMaxParticles) return "2³¹ − 1";
  if (v == 1e-12 || v == 1e-10 || v == 1e-9 || v == 1e-6 || v == 1e3 || v == 1e6 || v == 1e9 ||
      v == 1e13 || v == 1e15) {
    const int e = static_cast<int>(std::lround(std::log10(v)));
    std::string out = "10";
    if (e < 0) out += "⁻";
    for (const char c : std::to_string(std::abs(e))) out += kSuperscripts[c - '0'];
    return out;
  }
  if (v == 100000.0) return "100 000";
  return fmt::format("{}", v);
}

std::string range_text(const KeyDecl& d) {
  const Range& r = d.range;
  if (!r.bounded()) return "";
  const std::string unit = scale_text(r.scale);
  std::string out;
  if (!std::isfinite(r.hi)) {
    out = fmt::format("{} {}", r.lo_open ? ">" : "≥", doc_number(r.lo));
    if (!unit.empty() && r.lo != 0.0) out += " " + unit;
  } else {
    out = fmt::format("in {}{}, {}{}", r.lo_open ? "(" : "[", doc_number(r.lo), doc_number(r.hi),
                      r.hi_open ? ")" : "]");
    if (!unit.empty()) out += " " + unit;
  }
  if (r.also == r.also) out += fmt::format(", or {}", doc_number(r.also));
  return out;
}

namespace {

// The names a string key accepts, in a box of either dimension: "`fcc`, `sc`, ...".
std::string choices_text(const KeyDecl& d) {
  std::vector<std::string_view> names = d.choices(3);
  for (const std::string_view name : d.choices(2))
    if (std::find(names.begin(), names.end(), name) == names.end()) names.push_back(name);
  std::string out;
  for (const std::string_view name : names)
    out += fmt::format("{}`{}`", out.empty() ? "" : ", ", name);
  return out;
}

}  // namespace

std::string keys_text() {
  std::string out;
  for (const DeclaredKey& k : declared_keys()) {
    if (k.decl == nullptr) continue;
    const KeyDecl& d = *k.decl;
    out += fmt::format("{}  {}  default {}", k.path, type_text(d), default_text(k));
    if (!range_text(d).empty()) out += fmt::format("  {}", range_text(d));
    if (!d.unit.empty()) out += fmt::format("  [{}]", d.unit);
    out += fmt::format("  {}", d.doc);
    if (d.choices != nullptr) out += ": " + choices_text(d);
    out += "\n";
  }
  return out;
}

std::string keys_markdown() {
  std::string out =
      "| Key | Type | Default | Range | Unit | Meaning |\n|---|---|---|---|---|---|\n";
  for (const DeclaredKey& k : declared_keys()) {
    if (k.decl == nullptr) continue;
    const KeyDecl& d = *k.decl;
    out += fmt::format("| `{}` | {} | {} | {} | {} | {}{} |\n", k.path, type_text(d),
                       default_text(k), range_text(d), d.unit, d.doc,
                       d.choices != nullptr ? ": " + choices_text(d) : std::string());
  }
  return out;
}

}  // namespace kairos
