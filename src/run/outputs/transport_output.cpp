#include "run/outputs/transport_output.hpp"

#include <cmath>
#include <string>

#include <fmt/format.h>

#include "io/atomic_file.hpp"
#include "run/outputs/sampling_interval.hpp"

namespace kairos {

namespace {

nlohmann::json finite_or_null(double x) {
  return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr);
}

}  // namespace

// G_ab = kinetic + collisional (the virial tensor, and soft contacts' jumps), the energy moment
// likewise.
template <int D>
MassMoments<D>::MassMoments(const EventIntegrator<D>& engine) {
  const std::size_t n = engine.size();
  moment_of_.assign(n, ~0u);
  mass_.assign(n, 0.0);
  // The components: particles of one species and one mass (a species whose particles differ
  // in mass is as many components: each carries its own energy per mass).
  std::vector<std::pair<std::uint32_t, double>> classes;
  std::vector<std::uint32_t> class_of(n, 0u);
  std::vector<double> class_mass;
  double total = 0.0;
  engine.state_blocks().for_each(
      [&](const ParticleSystem<D>& part, std::size_t first) {
        for (std::size_t j = 0; j < part.size(); ++j) {
          const std::pair<std::uint32_t, double> c{part.species.empty() ? 0u : part.species[j],
                                                   part.mass[j]};
          auto at = std::find(classes.begin(), classes.end(), c);
          if (at == classes.end()) {
            if (classes.size() > kMaxComponents) continue;  // too many: refused below
            classes.push_back(c);
            class_mass.push_back(0.0);
            at = classes.end() - 1;
          }
          const auto k = static_cast<std::uint32_t>(at - classes.begin());
          class_of[first + j] = k;
          mass_[first + j] = part.mass[j];
          class_mass[k] += part.mass[j];
          total += part.mass[j];
        }
      },
      StateBlocks<D>::kKinematics | StateBlocks<D>::kIdentity);
  if (classes.size() > kMaxComponents) {
    why_ = fmt::format(
        "more than {} components (distinct species and masses): the heat flux's interdiffusion "
        "part is not removed for so many",
        kMaxComponents);
    return;
  }
  if (classes.size() < 2) return;
  // In the order of the species (then of the masses); every component but the last: its moment
  // is minus the sum of the others'.
  std::vector<std::uint32_t> order(classes.size());
  for (std::uint32_t k = 0; k < order.size(); ++k) order[k] = k;
  std::sort(order.begin(), order.end(),
            [&](std::uint32_t a, std::uint32_t b) { return classes[a] < classes[b]; });
  order.pop_back();
  const std::vector<std::string> names = engine.state_blocks().globals().species_names;
  std::vector<std::uint32_t> moment(classes.size(), ~0u);
  for (const std::uint32_t k : order) {
    moment[k] = static_cast<std::uint32_t>(fraction_.size());
    fraction_.push_back(class_mass[k] / total);
    const auto [species, mass] = classes[k];
    std::string name = species < names.size() ? names[species] : std::to_string(species);
    const bool one_mass = std::count_if(classes.begin(), classes.end(),
                                        [&](const auto& c) { return c.first == species; }) == 1;
    if (!one_mass) name += fmt::format(" (m = {:.6g})", mass);
    names_.push_back(std::move(name));
  }
  for (std::size_t id = 0; id < n; ++id) moment_of_[id] = moment[class_of[id]];
  every_slot_.resize(n);
  for (std::size_t id = 0; id < n; ++id) every_slot_[id] = static_cast<std::uint32_t>(id);
  position_.resize(n);
  const std::array<double, 9> kinetic = engine.peculiar_kinetic_tensor();
  double twice_kinetic = 0.0;
  for (int a = 0; a < D; ++a) twice_kinetic += kinetic[a * D + a];
  if (twice_kinetic > 0.0) scale_ = twice_kinetic / (D * total);
}

template <int D>
void MassMoments<D>::sample(const EventIntegrator<D>& engine, std::vector<Vec<D>>& out) {
  out.assign(count(), Vec<D>{});
  if (count() == 0) return;
  engine.unwrapped_positions(every_slot_, position_);
  Vec<D> all{};
  for (std::size_t id = 0; id < position_.size(); ++id) {
    const Vec<D> p = mass_[id] * position_[id];
    all = all + p;
    if (moment_of_[id] != ~0u) out[moment_of_[id]] = out[moment_of_[id]] + p;
  }
  for (std::size_t k = 0; k < count(); ++k) out[k] = out[k] - fraction_[k] * all;
}

template <int D>
typename HelfandTransport<D>::Moments helfand_sample(const EventIntegrator<D>& engine,
                                                     MassMoments<D>* mass) {
  const typename HelfandMoments<D>::Moments m = engine.helfand_moments();
  const std::array<double, 9>& virial = engine.counters().virial_tensor;
  typename HelfandTransport<D>::Moments out;
  for (int a = 0; a < D; ++a)
    for (int b = 0; b < D; ++b)
      out.stress[a * D + b] =
          m.kinetic_stress[a * D + b] + virial[a * D + b] + m.jump_stress[a * D + b];
  for (int a = 0; a < D; ++a)
    out.energy[a] = m.kinetic_energy_flux[a] + m.collisional_energy_flux[a];
  double trace = 0.0;
  for (int a = 0; a < D; ++a) trace += m.kinetic_stress[a * D + a];
  out.kinetic_trace = trace + m.frozen_kinetic;
  out.frozen_pair_time = m.frozen_pair_time;
  if (mass != nullptr) mass->sample(engine, out.mass);
  return out;
}

template <int D>
TransportOutput<D>::TransportOutput(const Config& config, const EventIntegrator<D>& engine)
    : engine_(engine), config_(config.analysis), stats_(D, engine.size(), engine.volume()) {
  interval_ = config_.transport_interval;
  if (interval_ == 0.0) {
    automatic_interval_ = true;
    interval_ = half_enskog_mean_free_time(engine, "analysis.transport_interval");
  }
}

template <int D>
void TransportOutput<D>::production_starts(const RunContext<D>&) {
  mass_.emplace(engine_);
  transport_.emplace(interval_, engine_.size(), engine_.volume(), mass_->count(), mass_->scale());
  start_time_ = engine_.time();
  start_collisions_ = engine_.collisions();
}

template <int D>
void TransportOutput<D>::write(const RunContext<D>& run) {
  if (run.phase() != "production") return;
  if (!transport_) production_starts(run);  // continued in its production
  transport_->add(engine_.time(), helfand_sample(engine_, &*mass_));
}

template <int D>
std::pair<double, double> TransportOutput<D>::fit_window() const {
  const double sampled = transport_ ? transport_->last_time() - transport_->first_time() : 0.0;
  const double mft =
      stats_.mean_free_time(engine_.time() - start_time_, engine_.collisions() - start_collisions_);
  return correlation_fit_window(sampled, config_.transport_fit_from, config_.transport_fit_to, mft,
                                kTransportFitMeanFreeTimes);
}

template <int D>
void TransportOutput<D>::close(const RunContext<D>& run, bool) {
  if (!transport_ || transport_->samples() < 2) return;
  // Per lag: the mean-square moment (the pressure's about its drift, over 1 - lag / span) and
  // the running coefficient <dG^2> / (2 lag V kT) (kT^2 for the conductivity), whose plateau is
  // the Einstein-Helfand value.
  std::string text =
      "lag\torigins\tshear_moment\tbulk_moment\theat_moment\tshear_viscosity\tbulk_viscosity\t"
      "thermal_conductivity\n";
  const auto row = [](const typename Transport::Row& r) {
    return fmt::format("{:.10g}\t{}\t{:.10g}\t{:.10g}\t{:.10g}\t{:.10g}\t{:.10g}\t{:.10g}\n", r.lag,
                       r.origins, r.value[0], r.value[1], r.value[2], r.coefficient[0],
                       r.coefficient[1], r.coefficient[2]);
  };
  const auto [from, to] = fit_window();
  for (const auto& r : transport_->helfand_rows(from, to)) text += row(r);
  write_text_atomically(run.directory() / name(), text);
  // The flux autocorrelations (the pressure's about its mean) and their running integrals.
  text =
      "lag\torigins\tshear_flux_acf\tbulk_flux_acf\theat_flux_acf\tshear_viscosity\t"
      "bulk_viscosity\tthermal_conductivity\n";
  for (const auto& r : transport_->green_kubo_rows(from, to)) text += row(r);
  write_text_atomically(run.directory() / kGreenKuboFile, text);
}

template <int D>
void TransportOutput<D>::summarize(nlohmann::json& summary, const RunContext<D>&) const {
  nlohmann::json j;
  j["interval"] = interval_;
  j["interval_automatic"] = automatic_interval_;
  j["samples"] = transport_ ? transport_->samples() : 0;
  j["memory_bytes"] = transport_ ? transport_->bytes() : 0;
  const double first = transport_ ? transport_->first_time() : 0.0;
  const double last = transport_ ? transport_->last_time() : 0.0;
  j["sampled_from"] = first;
  j["sampled_to"] = last;
  const double kt = transport_ ? transport_->temperature() : std::nan("");
  j["temperature"] = finite_or_null(kt);
  j["volume"] = engine_.volume();
  const auto [from, to] = fit_window();
  j["fit_from"] = from;
  j["fit_to"] = to;
  const bool reliable = last - first >= 20.0 * to;
  std::array<Fit, 3> eh, gk;
  if (transport_) {
    eh = transport_->einstein_helfand(from, to);
    gk = transport_->green_kubo(from, to);
  }
  const char* names[3] = {"shear_viscosity", "bulk_viscosity", "thermal_conductivity"};
  for (int g = 0; g < 3; ++g) {
    nlohmann::json c;
    const double scale = transport_ ? transport_->scale(g) : std::nan("");
    if (eh[g]) {
      c["value"] = eh[g]->coefficient / scale;
      c["stderr"] = finite_or_null(eh[g]->stderr_ / scale);
      c["stderr_epochs"] = finite_or_null(eh[g]->epoch_stderr / scale);
      c["stderr_components"] = finite_or_null(eh[g]->particle_stderr / scale);
      c["epochs_fitted"] = eh[g]->epochs;
      c["lags_fitted"] = eh[g]->lags;
      // As the MSD's: few independent windows of the longest lag make the bars too small.
      c["stderr_reliable"] = reliable;
    } else {
      c["value"] = nullptr;
      c["why"] = fmt::format(
          "fewer than 3 lags in the fit window [{:.4g}, {:.4g}]: the production is too short "
          "(or set analysis.transport_fit_from / transport_fit_to)",
          from, to);
    }
    if (gk[g]) {
      c["green_kubo"] = gk[g]->coefficient / scale;
      c["green_kubo_stderr"] = finite_or_null(gk[g]->stderr_ / scale);
    }
    if (g == Transport::kHeatGroup && mass_ && !mass_->why().empty()) {
      c = {{"value", nullptr}, {"why", mass_->why()}};
    } else if (g == Transport::kHeatGroup && mass_ && mass_->count() > 0) {
      c["interdiffusion"] = interdiffusion(from, to);
      // The window holds enough lags (the shear viscosity has them) but no projection.
      if (!eh[g] && eh[Transport::kShearGroup]) c["why"] = kNotPositiveDefinite;
    }
    j[names[g]] = c;
  }
  summary["transport"] = j;
}

// A mixture's heat moment G_e - sum_a beta_a G_a: beta per component (each but the last
// present) and the fraction of the energy moment's slope that interdiffusion carried.
template <int D>
nlohmann::json TransportOutput<D>::interdiffusion(double from, double to) const {
  nlohmann::json d;
  d["frame"] = kMassMomentFrame;
  const auto p = transport_ ? transport_->heat_projection(from, to) : std::nullopt;
  nlohmann::json beta = nlohmann::json::object();
  for (std::size_t k = 0; k < mass_->count(); ++k) {
    beta[mass_->name(k)] = p ? finite_or_null(p->beta[k]) : nullptr;
  }
  d["energy_per_mass"] = beta;
  d["removed_fraction"] = p ? finite_or_null(p->removed) : nullptr;
  return d;
}

template typename HelfandTransport<2>::Moments helfand_sample<2>(const EventIntegrator<2>&,
                                                                 MassMoments<2>*);
template typename HelfandTransport<3>::Moments helfand_sample<3>(const EventIntegrator<3>&,
                                                                 MassMoments<3>*);
template class MassMoments<2>;
template class MassMoments<3>;
template class TransportOutput<2>;
template class TransportOutput<3>;

}  // namespace kairos
