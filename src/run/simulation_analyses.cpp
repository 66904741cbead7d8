#include "run/simulation_analyses.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>

#include "analysis/thermodynamics.hpp"
#include "core/error.hpp"
#include "run/event_adapter.hpp"
#include "run/outputs/bond_order_output.hpp"
#include "run/outputs/msd_output.hpp"
#include "run/outputs/pressure_tensor.hpp"
#include "run/outputs/rdf_output.hpp"
#include "run/outputs/sampling_interval.hpp"
#include "run/outputs/structure_factor_output.hpp"
#include "run/outputs/structure_snapshot.hpp"
#include "run/outputs/summary_values.hpp"
#include "run/outputs/transport_output.hpp"
#include "run/outputs/velocity_distribution_output.hpp"

namespace kairos {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The sampling interval asked for, or the automatic one (analysis.msd_interval = 0).
template <int D>
SampledSpan begin_span(const Simulation<D>& sim, const CorrelationRequest& request) {
  SampledSpan span;
  span.interval = request.interval;
  if (span.interval == 0.0) {
    span.interval_automatic = true;
    span.interval = half_enskog_mean_free_time(sim.event_integrator("the automatic interval"),
                                               request.interval_name);
  }
  span.start_time = sim.time();
  span.collisions = sim.collisions();
  return span;
}

// The span's end: its mean free time as thermo.tsv defines it, and the fit window over the
// sampled times.
template <int D>
void end_span(const Simulation<D>& sim, const CorrelationRequest& request, double sampled,
              SampledSpan& span) {
  span.end_time = sim.time();
  span.collisions = sim.collisions() - span.collisions;
  const std::size_t moving = sim.integrator().mobile();
  const Thermodynamics stats(D, moving, sim.integrator().volume(), moving < sim.size());
  span.mean_free_time = stats.mean_free_time(span.end_time - span.start_time, span.collisions);
  const auto [from, to] =
      correlation_fit_window(sampled, request.fit_from, request.fit_to, span.mean_free_time,
                             request.fit_to_mean_free_times);
  span.fit_from = from;
  span.fit_to = to;
}

}  // namespace

template <int D>
RdfNow<D> rdf_now(const Simulation<D>& sim, int bins, double max_distance) {
  StructureSnapshot<D> snapshot;
  const Configuration<D>& c = snapshot.at(sim.integrator());
  RdfPairs pairs = rdf_pairs(sim.integrator(), snapshot);
  if (max_distance == 0.0) max_distance = automatic_rdf_distance(snapshot, c);
  std::optional<PairCorrelation<D>> rdf;
  try {
    rdf.emplace(c.box, c.periodic, snapshot.counts(), max_distance, bins, pairs.contact);
  } catch (const std::invalid_argument&) {
    const double shortest = *std::min_element(c.box.begin(), c.box.end());
    throw InputError(fmt::format(
        "rdf: the box (shortest edge {:.6g}) is too small for g(r) up to r_max = {:.6g} and the "
        "contact windows (1.1 contact distances): both must stay within half of every edge",
        shortest, max_distance));
  }
  rdf->sample(c);
  RdfNow<D> out;
  out.max_distance = rdf->max_distance();
  out.bins = rdf->bins();
  out.pairs = std::move(pairs.names);
  out.no_contact = std::move(pairs.no_contact);
  const std::size_t n_pairs = out.pairs.size();
  out.g.assign(n_pairs, std::vector<double>(static_cast<std::size_t>(bins), kNaN));
  for (int k = 0; k < bins; ++k) {
    out.r.push_back((k + 0.5) * rdf->bin_width());
    for (std::size_t p = 0; p < n_pairs; ++p) {
      const BlockAverage v = rdf->g(p, k);
      if (v.samples > 0) out.g[p][static_cast<std::size_t>(k)] = v.mean;
    }
    out.g_all.push_back(rdf->g_all(k).mean);
  }
  for (std::size_t p = 0; p < n_pairs; ++p) {
    const BlockAverage v = rdf->contact(p);
    out.sigma.push_back(rdf->contact_distance(p));
    out.contact.push_back(v.samples > 0 ? v.mean : kNaN);
  }
  out.overlapping = rdf->overlapping();
  out.at_contact = rdf->at_contact();
  return out;
}

template <int D>
StructureFactorNow structure_factor_now(const Simulation<D>& sim, double k_max) {
  StructureSnapshot<D> snapshot;
  const Configuration<D>& c = snapshot.at(sim.integrator());
  if (const std::string why = structure_factor_unavailable(sim.integrator(), c); !why.empty())
    throw InputError("structure_factor: " + why);
  StructureFactorNow out;
  out.k_max = k_max > 0.0 ? k_max : automatic_sk_max(snapshot);
  StructureFactor<D> sk(c.box, out.k_max, sk_fit_max(snapshot));
  sk.sample(c);
  for (const auto& shell : sk.shells()) {
    out.k.push_back(shell.k);
    out.s.push_back(shell.s.mean);
    out.vectors.push_back(shell.vectors);
    out.available.push_back(shell.available);
  }
  out.fit_max = sk.fit_max();
  out.fit_shells = sk.fit_shells();
  out.s_zero = out.fit_shells > 0 ? sk.s_zero().mean : kNaN;
  return out;
}

template <int D>
BondOrderValues<D> bond_order_now(const Simulation<D>& sim, double cutoff, const std::string& key) {
  StructureSnapshot<D> snapshot;
  const Configuration<D>& c = snapshot.at(sim.integrator());
  check_bond_cutoff(cutoff, snapshot, c, key);
  return bond_order(c, cutoff);
}

template <int D>
VelocityDistribution<D> velocity_distribution_now(const Simulation<D>& sim) {
  VelocityDistribution<D> distribution;
  sample_velocity_distribution(sim.integrator(), distribution);
  return distribution;
}

template <int D>
MsdMeasurement<D> measure_msd(Simulation<D>& sim, const CorrelationRequest& request, bool vacf,
                              const typename Simulation<D>::KeepGoing& keep_going,
                              std::size_t particles, MsdTime clock, bool mutual) {
  const EventIntegrator<D>& engine = sim.event_integrator("msd");  // as analysis.msd
  if (!sim.tracks_images()) {
    throw InputError(
        "msd: the mean-square displacement needs image counters: this Simulation keeps none "
        "(created with images=False)");
  }
  if (engine.kind().sheared) {
    throw InputError(
        "msd: the mean-square displacement under Lees-Edwards shear is not measured yet (the "
        "streaming displacement would need subtracting), as analysis.msd");
  }
  MsdMeasurement<D> m;
  const auto& kind = engine.kind();
  const bool cooling = freely_cooling<D>(kind);
  m.in_collisions = msd_on_collision_clock<D>(clock, kind);
  if (m.in_collisions && vacf) {
    throw InputError(
        "msd: vacf: no velocity autocorrelation on the collision clock (the velocities of a "
        "cooling gas decay); pass clock=\"time\"");
  }
  if (!m.in_collisions) m.span = begin_span(sim, request);
  // Every step-th particle that moves, grouped by species (analysis.msd: at most
  // msd_particles of them; fixed grains never move).
  m.species = sim.species_names();
  if (m.species.empty()) m.species = {"A"};
  const std::size_t n = sim.size();
  const auto species_of = [&](std::size_t i) {
    return i < sim.species().size() ? sim.species()[i] : 0u;
  };
  const auto moves = [&](std::size_t i) {
    return !engine.environment().fixed_species(species_of(i));
  };
  std::size_t mobile = 0;
  for (std::size_t i = 0; i < n; ++i) mobile += moves(i) ? 1 : 0;
  const std::size_t step = msd_follow_step(mobile, particles);
  std::vector<std::uint32_t> group, slot(n, ~0u);  // slot: ~0u = not followed
  std::size_t moving = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!moves(i) || moving++ % step != 0) continue;
    slot[i] = static_cast<std::uint32_t>(group.size());
    group.push_back(species_of(i));
    while (group.back() >= m.species.size()) m.species.push_back(std::to_string(m.species.size()));
  }
  m.followed = group.size();
  // The collision clock: 2 collisions / moving particles, as MsdOutput's.
  const auto per_particle = [&] {
    return 2.0 * static_cast<double>(sim.collisions()) / static_cast<double>(mobile);
  };
  CollisionInterval every;
  if (m.in_collisions) {
    if (mobile == 0) throw InputError("msd: no particle moves: no collision clock");
    if (!(request.duration >= 0.0) || !std::isfinite(request.duration))
      throw InputError("msd: duration: collisions per particle, finite and not negative");
    every = collision_interval(request.interval == 0.0 ? 0.5 : request.interval, mobile);
    m.span.interval = every.per_particle;
    m.span.interval_automatic = request.interval == 0.0;
    m.span.start_time = sim.time();
    m.span.collisions = sim.collisions();
  }
  const auto groups = static_cast<std::uint32_t>(m.species.size());
  m.msd.emplace(group, groups, m.span.interval);
  std::vector<std::uint32_t> every_slot;
  std::vector<Vec<D>> every_position, moments;
  if (mutual) {  // every particle's species and position, as analysis.mutual_diffusion
    std::vector<std::uint32_t> species_of_particle(n);
    for (std::size_t i = 0; i < n; ++i) species_of_particle[i] = species_of(i);
    m.interdiffusion.emplace(species_of_particle);
    if (m.interdiffusion->count() == 0)
      throw InputError("msd: mutual: interdiffusion needs particles of two species or more");
    const auto count = static_cast<std::uint32_t>(m.interdiffusion->count());
    std::vector<std::uint32_t> own(count);
    for (std::uint32_t k = 0; k < count; ++k) own[k] = k;
    m.mutual.emplace(own, count, m.span.interval);
    every_slot.resize(n);
    for (std::size_t i = 0; i < n; ++i) every_slot[i] = static_cast<std::uint32_t>(i);
    every_position.resize(n);
  }
  if (vacf) m.vacf.emplace(group, groups, m.span.interval, MsdCorrelator<D>::Statistic::kProduct);
  std::vector<Vec<D>> sample(group.size());
  const auto take = [&] {
    if (m.mutual) {
      engine.unwrapped_positions(every_slot, every_position);
      for (std::size_t i = 0; i < n; ++i)
        if (slot[i] != ~0u) sample[slot[i]] = every_position[i];
      m.interdiffusion->sample(every_position, moments);
      m.mutual->add(moments);
    } else {
      engine.unwrapped_positions(slot, sample);
    }
    const double now = m.in_collisions ? per_particle() : sim.time();
    if (m.msd->samples() == 0) m.sampled_from = now;
    m.sampled_to = now;
    m.msd->add(sample);
    if (m.vacf) {
      engine.velocities(slot, sample);
      m.vacf->add(sample);
    }
  };
  if (m.in_collisions) {
    const bool countable = request.duration * static_cast<double>(mobile) / 2.0 < 0x1p62;
    const std::uint64_t collisions = countable ? collisions_for(request.duration, mobile) : ~0ull;
    m.span.completed = sim.sample_every_collisions(every.step, collisions, take, keep_going);
    // Per collision the mean free "time" is one collision per particle by definition.
    m.span.end_time = sim.time();
    m.span.collisions = sim.collisions() - m.span.collisions;
    m.span.mean_free_time = 1.0;
    const auto [from, to] = correlation_fit_window(m.sampled_to - m.sampled_from, request.fit_from,
                                                   request.fit_to, 1.0);
    m.span.fit_from = from;
    m.span.fit_to = to;
  } else {
    m.span.completed = sim.sample_every(m.span.interval, request.duration, take, keep_going);
    end_span(sim, request, m.sampled_to - m.sampled_from, m.span);
  }
  if (cooling && !m.in_collisions) {
    m.no_coefficient =
        "the gas cools freely: D(t) decays with sqrt(T) (Haff's law), so no constant D in time "
        "exists; clock=\"collisions\" (or \"auto\") measures the constant D per collision";
    m.diffusion.assign(groups, std::nullopt);
    if (m.mutual) m.mutual_fits.assign(m.interdiffusion->count(), std::nullopt);
  } else {
    m.diffusion = m.msd->diffusion(m.span.fit_from, m.span.fit_to);
    if (m.mutual) m.mutual_fits = m.mutual->diffusion(m.span.fit_from, m.span.fit_to);
  }
  m.green_kubo = m.vacf ? m.vacf->green_kubo(m.span.fit_to)
                        : std::vector<std::optional<typename MsdCorrelator<D>::Diffusion>>(groups);
  return m;
}

template <int D>
TransportMeasurement<D> measure_transport(Simulation<D>& sim, const CorrelationRequest& request,
                                          const typename Simulation<D>::KeepGoing& keep_going) {
  const EventIntegrator<D>& engine = sim.event_integrator("transport");  // as analysis.transport
  if (!sim.tracks_helfand()) {
    throw InputError(
        "transport: the Helfand moments are not kept: create the Simulation with helfand=True "
        "(a conservative periodic system)");
  }
  TransportMeasurement<D> m;
  m.span = begin_span(sim, request);
  MassMoments<D> mass(engine);  // a mixture's (the Simulation keeps images for them)
  m.transport.emplace(m.span.interval, sim.size(), engine.volume(), mass.count(), mass.scale());
  m.span.completed = sim.sample_every(
      m.span.interval, request.duration,
      [&] { m.transport->add(sim.time(), helfand_sample(engine, &mass)); }, keep_going);
  end_span(sim, request, m.transport->last_time() - m.transport->first_time(), m.span);
  m.einstein_helfand = m.transport->einstein_helfand(m.span.fit_from, m.span.fit_to);
  m.green_kubo = m.transport->green_kubo(m.span.fit_from, m.span.fit_to);
  if (!mass.why().empty()) {
    m.no_conductivity = mass.why();
  } else if (mass.count() > 0) {
    for (std::size_t k = 0; k < mass.count(); ++k) m.mass_moment_species.push_back(mass.name(k));
    m.heat_projection = m.transport->heat_projection(m.span.fit_from, m.span.fit_to);
    // The window holds enough lags (the shear viscosity has them) but no projection.
    if (!m.heat_projection && m.einstein_helfand[HelfandTransport<D>::kShearGroup])
      m.no_conductivity = kNotPositiveDefinite;
  }
  return m;
}

template <int D>
PressureMeasurement measure_pressure(Simulation<D>& sim, const CorrelationRequest& request,
                                     const typename Simulation<D>::KeepGoing& keep_going) {
  const Integrator<D>& integrator = sim.integrator();
  PressureMeasurement m;
  m.span.interval = request.interval;
  m.span.start_time = sim.time();
  m.span.collisions = sim.collisions();
  const std::size_t moving = integrator.mobile();
  Thermodynamics stats(D, moving, integrator.volume(), moving < sim.size());
  const ThermoPoint start = integrator.point();
  stats.mark(start);
  const double start_ke = integrator.thermal_energy();
  const double start_held = integrator.held_degrees_of_freedom();
  std::vector<double> temperatures;
  // The event engine's pressure tensor and shear stress, as outputs/pressure_tensor.cpp.
  const EventIntegrator<D>* engine = integrator.as_event();
  std::array<double, 9> kinetic_sum{}, virial_start{};
  if (engine != nullptr) virial_start = engine->counters().virial_tensor;
  double row_start = sim.time(), row_virial_xy = virial_start[1];
  std::vector<double> shear_rows;
  int rows = 0;
  m.span.completed = sim.sample_every(
      request.interval, request.duration,
      [&] {
        const ThermoRow r = stats.row(integrator.point(), integrator.thermal_energy(), true,
                                      integrator.held_degrees_of_freedom());
        temperatures.push_back(r.temperature);
        if (engine == nullptr) return;
        const std::array<double, 9> kinetic = engine->peculiar_kinetic_tensor();
        for (int k = 0; k < D * D; ++k) kinetic_sum[k] += kinetic[k];
        ++rows;
        if (engine->kind().sheared && sim.time() > row_start) {
          const double virial_xy = engine->counters().virial_tensor[1];
          shear_rows.push_back(shear_stress_row(kinetic[1], virial_xy - row_virial_xy,
                                                sim.time() - row_start, engine->volume()));
          row_start = sim.time();
          row_virial_xy = virial_xy;
        }
      },
      keep_going);
  const double duration = sim.time() - m.span.start_time;
  m.span.end_time = sim.time();
  m.span.collisions = sim.collisions() - m.span.collisions;
  m.span.mean_free_time = stats.mean_free_time(duration, m.span.collisions);
  m.temperature = stats.span_temperature(integrator.temperature_from_rows(), temperatures, start_ke,
                                         start_held);
  if (engine != nullptr && rows > 0 && duration > 0.0) {
    std::array<double, 9> tensor{};
    for (int k = 0; k < D * D; ++k) {
      tensor[k] = pressure_tensor_element(kinetic_sum[k], rows,
                                          engine->counters().virial_tensor[k] - virial_start[k],
                                          duration, engine->volume());
    }
    m.tensor = tensor;
  }
  if (engine != nullptr && engine->kind().sheared) {
    m.shear_stress = block_average(shear_rows);
    m.shear_rate = engine->environment().shear_rate;
  }
  m.compressibility = stats.compressibility_blocks();
  m.compressibility.mean =
      stats.compressibility(integrator.virial() - start.virial, m.temperature, duration);
  m.undefined = pressure_undefined_reason(integrator.bulk(), moving < sim.size(), duration,
                                          m.temperature, "time");
  if (!m.undefined.empty()) {
    m.compressibility.mean = m.compressibility.stderr_ = kNaN;
    m.pressure = m.pressure_stderr = kNaN;
    return m;
  }
  m.pressure = stats.pressure(m.compressibility.mean, m.temperature);
  m.pressure_stderr = stats.pressure(m.compressibility.stderr_, m.temperature);
  return m;
}

#define KAIROS_SIMULATION_ANALYSES(D)                                                              \
  template RdfNow<D> rdf_now<D>(const Simulation<D>&, int, double);                                \
  template StructureFactorNow structure_factor_now<D>(const Simulation<D>&, double);               \
  template BondOrderValues<D> bond_order_now<D>(const Simulation<D>&, double, const std::string&); \
  template VelocityDistribution<D> velocity_distribution_now<D>(const Simulation<D>&);             \
  template MsdMeasurement<D> measure_msd<D>(Simulation<D>&, const CorrelationRequest&, bool,       \
                                            const typename Simulation<D>::KeepGoing&, std::size_t, \
                                            MsdTime, bool);                                        \
  template TransportMeasurement<D> measure_transport<D>(Simulation<D>&, const CorrelationRequest&, \
                                                        const typename Simulation<D>::KeepGoing&); \
  template PressureMeasurement measure_pressure<D>(Simulation<D>&, const CorrelationRequest&,      \
                                                   const typename Simulation<D>::KeepGoing&);
KAIROS_SIMULATION_ANALYSES(2)
KAIROS_SIMULATION_ANALYSES(3)
#undef KAIROS_SIMULATION_ANALYSES

}  // namespace kairos
