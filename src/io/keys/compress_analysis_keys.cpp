// The [compress] and [analysis] keys.
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

}  // namespace

constexpr KeyGroup kCompressGroup{"compress", kCompress, &kCompressDefaults};
constexpr KeyGroup kAnalysisGroup{"analysis", kAnalysis, &kAnalysisDefaults};

}  // namespace kairos::key_tables
