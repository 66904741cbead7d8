// The [analysis] analyses of `kairos run` on a Simulation (run/simulation.hpp) held in memory,
// for the Python module (docs/python.md): the same code as the CLI's observers
// (run/outputs/rdf_output.hpp and its neighbours), so that one sample gives the numbers one
// sample gives in rdf.tsv, sk.tsv, bond_order.tsv, velocity_distribution.tsv, msd.tsv and
// helfand.tsv.
//
//   structure of the present state   rdf_now, structure_factor_now, bond_order_now,
//                                    velocity_distribution_now
//   time correlations                measure_msd, measure_transport: they advance the
//                                    simulation, sampling at the multiples of an interval in
//                                    simulated time as `kairos run` does
//   pressure over a span              measure_pressure: Z and P as summary.json gives them
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "analysis/block_average.hpp"
#include "analysis/helfand_transport.hpp"
#include "analysis/interdiffusion.hpp"
#include "analysis/msd.hpp"
#include "analysis/structure.hpp"
#include "io/config_choices.hpp"
#include "run/simulation.hpp"

namespace kairos {

// ----- structure

// g(r) of the present state as rdf.tsv holds it after one sample (analysis.rdf).
template <int D>
struct RdfNow {
  double max_distance = 0.0;
  int bins = 0;
  std::vector<double> r;               // bin centres
  std::vector<std::string> pairs;      // "A-B", per species pair
  std::vector<std::vector<double>> g;  // [pair][bin] (NaN: a pair without pairs)
  std::vector<double> g_all;           // every pair whatever its species
  std::vector<double> sigma, contact;  // per pair: contact distance, g(sigma+) (NaN: none)
  std::string no_contact;              // why there are no contact values ("": there are)
  std::size_t overlapping = 0, at_contact = 0;
};
// bins > 0; max_distance 0: automatic (analysis.rdf_max_distance). InputError for a box too
// small for it.
template <int D>
RdfNow<D> rdf_now(const Simulation<D>& sim, int bins, double max_distance);

// S(k) of the present state as sk.tsv holds it after one sample (analysis.structure_factor).
struct StructureFactorNow {
  double k_max = 0.0;
  std::vector<double> k, s;
  std::vector<std::size_t> vectors, available;
  double s_zero = 0.0;  // extrapolated (NaN with fewer than 4 shells below fit_max)
  double fit_max = 0.0;
  std::size_t fit_shells = 0;
};
// k_max 0: automatic (analysis.sk_max). InputError for a box that is not periodic, or sheared.
template <int D>
StructureFactorNow structure_factor_now(const Simulation<D>& sim, double k_max);

// The bond order of the present state (analysis.bond_order's values of one sample). InputError
// for a cut-off reaching beyond half a periodic edge (named `key`).
template <int D>
BondOrderValues<D> bond_order_now(const Simulation<D>& sim, double cutoff, const std::string& key);

// The velocity distribution of the present state (analysis.velocity_distribution, one sample);
// no sample when the particles are at rest.
template <int D>
VelocityDistribution<D> velocity_distribution_now(const Simulation<D>& sim);

// ----- time correlations

// How a measurement in time is sampled: every `interval` (0: the automatic interval of
// analysis.msd_interval, half the Enskog mean free time now) for `duration`, fitted over the
// lags in [fit_from, fit_to] (0: analysis.msd_fit_from / msd_fit_to's automatic window).
struct CorrelationRequest {
  double interval = 0.0;
  double duration = 0.0;
  double fit_from = 0.0, fit_to = 0.0;
  // The default longest lag in mean free times (0: a quarter of the span, as the MSD's).
  double fit_to_mean_free_times = 0.0;
  // The key naming the interval in the message when none follows from a system at rest.
  std::string interval_name = "interval";
};

// What a measurement in time sampled.
struct SampledSpan {
  double interval = 0.0;
  bool interval_automatic = false;
  double start_time = 0.0, end_time = 0.0;  // the span advanced over
  std::uint64_t collisions = 0;             // collisions in it
  double mean_free_time = 0.0;              // over it (NaN without collisions)
  double fit_from = 0.0, fit_to = 0.0;      // the window used
  bool completed = true;                    // false: stopped early by keep_going
};

// The MSD of every particle's unwrapped positions (analysis.msd: groups = species), and with
// `vacf` the velocity autocorrelation; D per species as summary.json's `diffusion` gives it.
template <int D>
struct MsdMeasurement {
  SampledSpan span;
  std::vector<std::string> species;
  std::size_t followed = 0;  // particles followed
  std::optional<MsdCorrelator<D>> msd, vacf;
  double sampled_from = 0.0, sampled_to = 0.0;  // first and last sample's times
  std::vector<std::optional<typename MsdCorrelator<D>::Diffusion>> diffusion, green_kubo;
  bool in_collisions = false;  // the clock: collisions per particle
  std::string no_coefficient;  // why there is no D ("": there is one)
  // With `mutual`: the interdiffusion moments (analysis.mutual_diffusion), their correlator and
  // fits (none for a freely cooling gas in time).
  std::optional<InterdiffusionMoments<D>> interdiffusion;
  std::optional<MsdCorrelator<D>> mutual;
  std::vector<std::optional<typename MsdCorrelator<D>::Diffusion>> mutual_fits;
};
// Advances `sim` by request.duration. InputError without image counters or under shear.
// Follows every `step`-th particle that moves, at most `particles` of them (0: all), as
// analysis.msd_particles does; fixed grains are never followed. On the collision clock
// (analysis.msd_time: "auto" chooses it for a freely cooling gas) the interval, the duration,
// the lags and the fit window are in collisions per particle, the samples every
// collision_interval(interval).step collisions (interval 0: half a collision per particle).
template <int D>
MsdMeasurement<D> measure_msd(Simulation<D>& sim, const CorrelationRequest& request, bool vacf,
                              const typename Simulation<D>::KeepGoing& keep_going = {},
                              std::size_t particles = 0, MsdTime clock = MsdTime::kTime,
                              bool mutual = false);

// The Einstein-Helfand transport coefficients (analysis.transport), as summary.json's
// `transport` gives them.
template <int D>
struct TransportMeasurement {
  SampledSpan span;
  std::optional<HelfandTransport<D>> transport;
  std::array<typename HelfandTransport<D>::Fit, 3> einstein_helfand, green_kubo;
  std::string no_conductivity;  // why there is no thermal conductivity ("": there is)
  // A mixture: the species of the mass moments and the heat moment's projection.
  std::vector<std::string> mass_moment_species;
  std::optional<typename HelfandTransport<D>::HeatProjection> heat_projection;
};
// Advances `sim` by request.duration. InputError unless the Helfand moments are kept.
template <int D>
TransportMeasurement<D> measure_transport(Simulation<D>& sim, const CorrelationRequest& request,
                                          const typename Simulation<D>::KeepGoing& keep_going = {});

// The compressibility factor Z = PV / (N kT) and the pressure over a span of simulated time, as
// summary.json gives them for a production (run/outputs/thermo_output.cpp): Z from the virial
// over the whole span at the production temperature (the kinetic one at the span's start, or
// the rows' mean where kinetic energy is exchanged or dissipated: temperature_from_rows), and
// its blocked error over rows `interval` apart (thermo.tsv's rows: Flyvbjerg-Petersen with
// Jonsson's level). Bulk values only: `undefined` says why not (walls, open faces, a field,
// fixed grains; no time elapsed; particles at rest) and leaves them NaN.
struct PressureMeasurement {
  SampledSpan span;
  BlockAverage compressibility;  // mean over the span; stderr_ over the rows
  double pressure = 0.0, pressure_stderr = 0.0;
  double temperature = 0.0;  // the production temperature the Z is made with
  std::string undefined;
  // The event engine: the pressure tensor over the span (row-major D x D, as summary.json's
  // pressure_tensor: the kinetic part averaged over the rows plus the collisional part), and
  // under Lees-Edwards shear the shear stress P_xy over the rows (blocked) and the rate.
  std::optional<std::array<double, 9>> tensor;
  std::optional<BlockAverage> shear_stress;
  double shear_rate = 0.0;
};
// Advances `sim` by request.duration with rows every request.interval (> 0) in simulated time.
template <int D>
PressureMeasurement measure_pressure(Simulation<D>& sim, const CorrelationRequest& request,
                                     const typename Simulation<D>::KeepGoing& keep_going = {});

}  // namespace kairos
