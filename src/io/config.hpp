// Run configuration: the TOML schema, its defaults and its validation.
//
// Every key is documented in docs/config.md. A config file holding only the keys of
// `examples/hard_spheres_3d.toml` is complete; everything else has a default here.
// Reduced units throughout: lengths in units of the first species' diameter is *not* assumed,
// the user chooses the unit (typically diameter = mass = kT = 1).
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "interactions/potential_spec.hpp"
#include "io/surface_tables.hpp"
#include "io/wall_config.hpp"

namespace kairos {

struct SpeciesConfig {
  std::string name = "A";
  double diameter = 1.0;
  double mass = 1.0;
  double fraction = 1.0;  // number fraction; fractions are normalised to sum 1
  // Moment of inertia I = q m R^2 (rough particles); 0 = default: 2/5 (spheres), 1/2 (disks).
  double inertia_factor = 0.0;
  // Fixed grains: particles of this species never move (infinite mass, at rest): rough floors,
  // obstacles, a porous matrix. docs/physics.md#fixed-grains.
  bool fixed = false;

  bool operator==(const SpeciesConfig&) const = default;
};

struct SystemConfig {
  int dimension = 3;                   // 2 or 3
  std::uint64_t particles = 0;         // required unless initial_state is given
  double packing_fraction = 0.0;       // required unless initial_state is given
  std::string lattice;                 // fcc|sc|bcc (3D), hex|square (2D), random; "" -> fcc / hex
  double temperature = 1.0;            // kT of the initial Maxwell-Boltzmann velocities
  std::uint64_t seed = 1;              // seeds all randomness of the run
  std::vector<SpeciesConfig> species;  // empty -> one species "A", diameter 1, mass 1
  std::string initial_state;           // GSD file to start from (last frame); "" -> generate
  // Generated states only: the box edges are multiplied by these factors (>= 1) after the
  // particles are placed, leaving empty space at the high end of each axis (e.g. a bed of
  // grains at the bottom of a tall box). Empty = all 1.
  std::vector<double> box_scale;
  // Generated states only: where the particles sit in the stretched box along each axis, as the
  // fraction of the added space below them: 0 at the low end (the default), 1 at the high end
  // (grains poured into a funnel from above), 0.5 centred. Empty = all 0.
  std::vector<double> box_place;
  // Generated states only: particles that a plane, cylinder or sphere wall cuts through, or
  // that lie beyond one, are moved to random free places inside every wall.
  bool fill_inside = false;
  // Molecules: with chain_length L > 0, the particles form N / L linear chains of L beads each
  // (consecutive particles bonded), generated on a simple cubic (3D) or square (2D) lattice of
  // spacing chain_spacing (0: the largest diameter) along a snake path. Bonds use [bond].
  std::uint64_t chain_length = 0;
  double chain_spacing = 0.0;
  // Per-particle diameters (docs/config.md): each particle's species diameter times a factor of
  // mean 1 and relative standard deviation `polydispersity`, drawn from this distribution.
  std::string size_distribution = "none";  // none | uniform | gaussian | lognormal
  double polydispersity = 0.0;

  bool operator==(const SystemConfig&) const = default;
};

struct PairContactConfig {
  std::array<std::string, 2> species;  // names
  ContactConfig contact;

  bool operator==(const PairContactConfig&) const = default;
};

struct InteractionConfig {
  ContactConfig contact;                 // [contact]: every pair without an override
  std::vector<PairContactConfig> pairs;  // [[contact.pair]]
  double tc = 0.0;                       // contact.tc: TC model duration (0 = off)
  // contact.sleep_speed: resting particles under gravity sleep below this speed; -1 = automatic
  // (sqrt(2 |g| 1e-6 d_min)), 0 = never.
  double sleep_speed = -1.0;

  bool operator==(const InteractionConfig&) const = default;
};

// The walls of one axis joined as a container of finite mass on a spring to a moving anchor
// ([boundary.container], boundaries/wall_spring.hpp): the spring-driven granular damper.
struct ContainerConfig {
  std::string axis;               // x, y or z; "": no container
  double mass = 0.0;              // M, > 0
  double spring_stiffness = 0.0;  // k (0: no spring, a free container)
  double spring_damping = 0.0;    // c, below 2 sqrt(k M)
  double drive_amplitude = 0.0;   // the anchor's A sin(2 pi f t + phase)
  double drive_frequency = 0.0;   // f, cycles per unit time
  double drive_phase = 0.0;       // radians

  bool operator==(const ContainerConfig&) const = default;
};

// An outlet particles pass through, put back at once in an insertion region ([boundary.outlet],
// boundaries/outlets.hpp): the recirculating silo. Absent when normal is empty.
struct OutletConfig {
  std::vector<double> normal;           // D components, towards the particles (not normalised)
  std::vector<double> point;            // D components: a point of the plane
  std::vector<double> insert_lower;     // D components: the insertion region's low corner
  std::vector<double> insert_upper;     // D components: its high corner
  std::vector<double> insert_velocity;  // D components; empty: at rest
  std::uint64_t seed = 1;               // of the places drawn

  bool operator==(const OutletConfig&) const = default;
};

struct BoundaryConfig {
  std::vector<WallConfig> walls;  // [[boundary.wall]]
  ContainerConfig container;      // [boundary.container]
  OutletConfig outlet;            // [boundary.outlet]
  // [[boundary.plane]], [[boundary.cylinder]], ...: one list per table of io/surface_tables.hpp
  // (surfaces.of<PlaneTable>()).
  SurfaceConfigs surfaces;
  std::vector<std::string> open;  // boundary.open: faces with no wall (e.g. "z+")
  double shear_rate = 0.0;        // Lees-Edwards: flow along x, gradient along y; 0: none

  bool operator==(const BoundaryConfig&) const = default;
};

struct FieldConfig {
  std::vector<double> gravity;  // D components; empty = none

  bool operator==(const FieldConfig&) const = default;
};

struct RunConfig {
  double equilibration_collisions_per_particle = 20.0;
  double collisions_per_particle = 100.0;  // production length
  // Lengths in simulated time instead: production `time` (> 0; 0 = in collisions per particle)
  // and equilibration `equilibration_time` (>= 0; < 0 = in collisions per particle).
  double time = 0.0;
  double equilibration_time = -1.0;
  std::string event_queue = "calendar";  // calendar | heap | tree
  double max_wall_seconds = 0.0;         // 0 = no limit; stop cleanly when exceeded
  bool validate = false;    // debug: check neighbour structure and queue against brute force
  bool size_levels = true;  // two cell levels for wide size distributions (auto)
  // event: the event-driven engine; dem: the force-based velocity Verlet integrator (needs
  // [soft], periodic boxes only).
  std::string integrator = "event";
  double time_step = 0.0;  // dem: the time step; 0 = t_c / 50 of the stiffest, lightest pair

  bool operator==(const RunConfig&) const = default;
};

struct OutputConfig {
  std::string directory = "kairos-output";
  double thermo_interval = 0.0;      // collisions per particle between thermo rows; 0 = auto
  double trajectory_interval = 0.0;  // collisions per particle between GSD frames; 0 = auto
  double restart_interval = 0.0;     // collisions per particle between restart files; 0 = end
  // The unit of the three intervals: "collisions" (per particle) or "time" (simulated time;
  // outputs at the multiples of the interval). The reader resolves "" to the production
  // length's unit.
  std::string interval_unit;
  bool trajectory = true;  // write trajectory.gsd at all
  // What trajectory.gsd holds (run/outputs/trajectory_output.hpp, docs/outputs.md): the frames
  // of every phase ("all") or of the production only ("production"); the per-particle fields
  // of each frame (empty: every field the state has, static ones in frame 0 only); "single"
  // (float32) or "double" (float64) floating-point chunks; frames every trajectory_interval
  // ("linear") or at the phase's start + trajectory_interval * 10^(k / frames_per_decade)
  // ("log"), that sequence started again every trajectory_log_period (0: never).
  std::string trajectory_phases = "all";
  std::vector<std::string> trajectory_fields;
  std::string trajectory_precision = "single";
  std::string trajectory_spacing = "linear";
  std::int64_t trajectory_frames_per_decade = 10;
  double trajectory_log_period = 0.0;
  std::string progress = "auto";  // auto (when stderr is a terminal) | always | never
  // Wall seconds between the progress lines of run.log in the output directory (and of
  // stdout, when progress is auto and stderr no terminal); 0: no run.log.
  double log_interval = 60.0;
  // Profiles along an axis (profile.tsv), sampled at every production thermo row: "" = none,
  // else x, y or z, in profile_bins slabs.
  std::string profile_axis;
  std::int64_t profile_bins = 50;

  bool operator==(const OutputConfig&) const = default;
};

// [analysis]: analyses of the production (docs/outputs.md), each written at the end to its own
// file and to summary.json.
struct AnalysisConfig {
  // msd.tsv: the mean-square displacement on log-spaced lags (analysis/msd.hpp), sampled every
  // msd_interval (0: automatic) of the MSD's clock, msd_time: simulated time, or collisions per
  // particle ("auto": collisions for a freely cooling gas, whose D(t) decays); of msd_particles
  // particles at most; D fitted over lags [msd_fit_from, msd_fit_to] (0: automatic).
  bool msd = false;
  std::string msd_time = "auto";  // auto | time | collisions
  double msd_interval = 0.0;
  std::int64_t msd_particles = 4096;
  double msd_fit_from = 0.0;
  double msd_fit_to = 0.0;
  // vacf.tsv: the velocity autocorrelation on the same lags, and D by Green-Kubo.
  bool vacf = false;
  // The shear viscosity, when known (0: not): D is also corrected to an infinite system.
  double msd_viscosity = 0.0;
  // mutual_diffusion.tsv: the interdiffusion (Maxwell-Stefan) coefficient of each species against
  // the rest of the mixture from its collective Helfand moment, on the MSD's samples and lags.
  bool mutual_diffusion = false;
  // The structure analyses (analysis/structure.hpp): rdf.tsv, sk.tsv, bond_order.tsv,
  // velocity_distribution.tsv, sampled over the production.
  bool rdf = false;                    // rdf.tsv: g(r) per species pair, contact values
  std::int64_t rdf_bins = 200;         // bins of g(r) over [0, rdf_max_distance]
  double rdf_max_distance = 0.0;       // 0: automatic, min(5 d, half the shortest box edge)
  bool structure_factor = false;       // sk.tsv: S(k) on the box's wave vectors (periodic boxes)
  double sk_max = 0.0;                 // the largest |k|; 0: automatic, 15 / d
  bool bond_order = false;             // bond_order.tsv: Steinhardt q4, q6 (3D), psi6 (2D)
  double bond_cutoff = 1.4;            // neighbours: closer than this many contact distances
  bool velocity_distribution = false;  // velocity_distribution.tsv
  // Between their samples, in output.interval_unit; 0: at every production thermo row.
  double interval = 0.0;
  // helfand.tsv, green_kubo.tsv: the Einstein-Helfand shear and bulk viscosities and thermal
  // conductivity (engine/helfand_moments.hpp), Green-Kubo beside them, sampled every
  // transport_interval of simulated time (0: automatic), fitted over lags [transport_fit_from,
  // transport_fit_to] (0: automatic).
  bool transport = false;
  double transport_interval = 0.0;
  double transport_fit_from = 0.0;
  double transport_fit_to = 0.0;

  bool operator==(const AnalysisConfig&) const = default;
};

// Stochastic driving: random events at `rate` per particle per unit time, each acting on one
// random particle. andersen: a new Maxwell-Boltzmann velocity at `temperature` (a thermostat);
// white_noise: a Gaussian velocity kick whose variance per component is strength / rate, so
// that the velocity diffuses with variance `strength` per unit time (energy input D m
// strength / 2 per particle per unit time).
struct DrivingConfig {
  std::string kind = "none";  // none | andersen | white_noise
  double rate = 1.0;          // > 0
  double temperature = 1.0;   // andersen: > 0
  double strength = 0.0;      // white_noise: > 0

  bool operator==(const DrivingConfig&) const = default;
};

// [[potential]]: the stepped potential of a species pair (both names), or of every pair not
// named by another entry (species empty). Pairs without a potential are hard spheres.
struct PairPotentialConfig {
  std::vector<std::string> species;
  PotentialSpec potential;

  bool operator==(const PairPotentialConfig&) const = default;
};

// [[bond]]: the potential of the bonds of one type (tether or spring;
// docs/physics.md#continuous-potentials).
struct BondConfig {
  std::string type = "backbone";
  PotentialSpec potential;

  bool operator==(const BondConfig&) const = default;
};

// A soft contact law, [soft] or [[soft.pair]] (docs/physics.md#soft-contact-laws,
// docs/config.md). The keys of the other model are kept (inherited by pairs) but not used.
struct SoftLawConfig {
  std::string model;               // dashpot | hertz; "" only when there is no [soft]
  double stiffness = 0.0;          // dashpot: k > 0 (required)
  double damping = 0.0;            // dashpot: gamma >= 0 (when restitution is 0)
  double young = 0.0;              // hertz: Young's modulus Y > 0 (required)
  double poisson = 0.3;            // hertz: Poisson's ratio in (-1, 0.5]
  double dissipation = 0.0;        // hertz: the dissipative time constant A >= 0
  double restitution = 0.0;        // head-on e in (0, 1] fixing gamma or A per pair; 0 = not given
  double restitution_speed = 1.0;  // hertz: the impact speed at which e = restitution
  // Coulomb friction (DEM only; interactions/soft_contact.hpp SoftFriction): mu >= 0 (0:
  // smooth), k_t / k_n > 0, gamma_t / gamma_n >= 0.
  double friction = 0.0;
  double tangential_stiffness = 2.0 / 7.0;
  double tangential_damping = 0.5;

  bool operator==(const SoftLawConfig&) const = default;
};

struct SoftPairConfig {
  std::array<std::string, 2> species;  // names
  SoftLawConfig law;

  bool operator==(const SoftPairConfig&) const = default;
};

// [soft]: soft spheres. Every contact (pairs and walls) is soft when law.model is set.
struct SoftConfig {
  SoftLawConfig law;                  // every pair without an override, and the walls
  std::vector<SoftPairConfig> pairs;  // [[soft.pair]]
  std::string collisions = "mapped";  // event integrator: mapped | instantaneous
  // Event integrator: lookup tables of the collision map (interactions/soft_map_table.hpp),
  // accurate to table_tolerance (relative), cached in table_cache ("" = the default cache
  // directory). false: every collision integrates the map directly (slow, exact).
  bool tables = true;
  double table_tolerance = 1e-6;
  std::string table_cache;
  // Event integrator, mapped contacts: a contact that can meet nothing before its end gets its
  // post-contact motion at once (EngineOptions::defer_soft_releases). false: every contact
  // waits for a release event (same physics, slower; for comparison).
  bool defer_releases = true;

  bool enabled() const { return !law.model.empty(); }
  bool operator==(const SoftConfig&) const = default;
};

// [compress]: before the run, the particles of a generated start grow (Lubachevsky-Stillinger,
// docs/physics.md#growing-spheres) until a packing fraction, a reduced pressure or jamming.
struct CompressConfig {
  double packing_fraction = 0.0;  // grow to this packing fraction (0: no such target)
  double pressure = 0.0;          // until the reduced pressure Z = PV/(NkT) reaches this (0: none)
  bool jammed = false;            // until jammed (Z above jammed_pressure)
  double growth_rate = 0.01;      // d sigma / dt over the starting diameter
  double thermostat_interval = 10.0;  // collisions per particle between velocity rescalings
  double jammed_pressure = 1e12;
  double jammed_collision_rate = 0.0;  // also jammed above this collision rate (0: not used)
  double slowdown_pressure = 100.0;    // above it the growth slows as sqrt(slowdown / Z) (0: never)
  double slowdown_floor = 0.1;         // ... to at least this fraction of growth_rate
  double contact_gap = 0.0;            // contact network: relative gap tolerance (0: 1e4 / Z)

  bool on() const { return packing_fraction > 0.0 || pressure > 0.0 || jammed; }
  bool operator==(const CompressConfig&) const = default;
};

struct Config {
  SystemConfig system;
  std::vector<PairPotentialConfig> potentials;  // [[potential]]
  std::vector<BondConfig> bonds;                // [[bond]]
  RunConfig run;
  OutputConfig output;
  InteractionConfig interactions;  // TOML section [contact]
  BoundaryConfig boundary;         // [boundary]
  FieldConfig field;               // [field]
  DrivingConfig driving;           // [driving]
  SoftConfig soft;                 // [soft]
  AnalysisConfig analysis;         // [analysis]
  CompressConfig compress;         // [compress]

  bool operator==(const Config&) const = default;  // memberwise (exact doubles)
};

// Parses TOML text, applies the `key=value` overrides (dotted paths, values in TOML syntax;
// a bare word is taken as a string), then validates. Throws InputError with a one-line message
// naming the source and the key on unknown keys, wrong types, NaN/inf, out-of-range values.
// The result has its defaults resolved: system.lattice is never "" (default_lattice()) and
// system.species is never empty (one species "A"); species fractions are kept as written.
// Override paths index species as `system.species.0.diameter` or `system.species[0].diameter`;
// index N == current count appends a species.
Config parse_config(std::string_view toml_text, std::string_view source_name,
                    const std::vector<std::string>& overrides = {});

// A config file's text: InputError naming the file if it is missing, unreadable or not a
// regular file (a FIFO would block).
std::string read_config_text(const std::filesystem::path& path);

// Reads the file (read_config_text) and calls parse_config.
Config load_config(const std::filesystem::path& path,
                   const std::vector<std::string>& overrides = {});

// The effective configuration (all defaults filled in) as TOML text; parse_config of the result
// gives back an equal Config (for a Config from parse_config; otherwise its resolved form).
// Doubles are written in shortest round-trip form. Throws std::out_of_range if particles or seed
// exceed 2^63 - 1 (not representable in TOML). Written as OUTDIR/config.toml so a run documents
// itself.
std::string to_toml(const Config& config);

// Default lattice for a dimension: "fcc" in 3D, "hex" in 2D; std::invalid_argument otherwise.
std::string default_lattice(int dimension);

}  // namespace kairos
