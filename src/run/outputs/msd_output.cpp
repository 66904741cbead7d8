#include "run/outputs/msd_output.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <fmt/format.h>

#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "io/config_choices.hpp"
#include "run/collision_estimate.hpp"
#include "run/outputs/sampling_interval.hpp"

namespace kairos {

namespace {

// Enskog's self-diffusion is off by more than the Sonine truncation beyond this packing fraction
// (correlated collisions: docs/validation.md, "Self-diffusion").
constexpr double kTheoryMaxPackingFraction = 0.1;

nlohmann::json finite_or_null(double x) {
  return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr);
}

}  // namespace

CollisionInterval collision_interval(double wanted, std::size_t particles) {
  CollisionInterval c;
  const double collisions = wanted * static_cast<double>(particles) / 2.0;
  c.step = std::max<std::uint64_t>(1, static_cast<std::uint64_t>(std::llround(collisions)));
  c.per_particle = 2.0 * static_cast<double>(c.step) / static_cast<double>(particles);
  return c;
}

std::uint64_t collisions_for(double per_particle, std::size_t mobile) {
  return static_cast<std::uint64_t>(std::llround(per_particle * static_cast<double>(mobile) / 2.0));
}

template <int D>
MsdOutput<D>::MsdOutput(const Config& config, const EventIntegrator<D>& engine)
    : engine_(engine),
      config_(config.analysis),
      stats_(D, engine.mobile(), engine.volume(), engine.mobile() < engine.size()) {
  const std::size_t n = engine.size();
  const auto wanted = static_cast<std::size_t>(config_.msd_particles);
  // Every step-th particle that moves (fixed grains are not followed).
  const std::size_t mobile = engine.mobile();
  const std::size_t step = msd_follow_step(mobile, wanted);
  slot_.assign(n, ~0u);  // not followed
  species_of_.assign(n, 0u);
  double radius = -1.0, mass = -1.0;
  bool equal_particles = true;
  const StateBlocks<D> state = engine.state_blocks();
  species_names_ = state.globals().species_names;
  std::vector<bool>& fixed = fixed_species_;  // as the model has them (matched by name)
  fixed.assign(species_names_.size(), false);
  for (std::size_t s = 0; s < species_names_.size(); ++s)
    fixed[s] = engine.environment().fixed_species(static_cast<std::uint32_t>(s));
  std::size_t moving = 0;  // particles that move, counted in order
  state.for_each(
      [&](const ParticleSystem<D>& part, std::size_t first) {
        for (std::size_t j = 0; j < part.size(); ++j) {
          const std::size_t id = first + j;
          const std::uint32_t species = part.species.empty() ? 0u : part.species[j];
          species_of_[id] = species;
          const double r = part.kinematics[j].radius, m = part.mass[j];
          if (radius < 0.0) {
            radius = r;
            mass = m;
          }
          equal_particles = equal_particles && r == radius && m == mass;
          if (species < fixed.size() && fixed[species]) continue;
          if (moving++ % step != 0) continue;
          slot_[id] = static_cast<std::uint32_t>(group_.size());
          group_.push_back(species);
        }
      },
      StateBlocks<D>::kKinematics | StateBlocks<D>::kIdentity);
  if (species_names_.empty()) species_names_ = {"A"};
  sample_.resize(group_.size());

  // The clock: collisions per particle for a freely cooling gas, whose D(t) decays with sqrt(T)
  // while D per collision is constant.
  const auto& kind = engine.kind();
  freely_cooling_ = freely_cooling<D>(kind);
  const MsdTime scale = msd_time_scales().at(config_.msd_time);
  in_collisions_ = msd_on_collision_clock<D>(scale, kind);
  time_scale_chosen_ = scale == MsdTime::kAuto;
  if (in_collisions_) {
    const char* why =
        " a freely cooling gas, the MSD's clock is collisions per particle (analysis.msd_time = "
        "\"auto\"); set analysis.msd_time = \"time\" to measure in simulated time";
    if (config_.vacf)
      throw InputError(std::string("analysis.vacf: no velocity autocorrelation in") + why);
    if (config_.msd_viscosity > 0.0)
      throw InputError(std::string("analysis.msd_viscosity: no finite-size correction in") + why);
  }

  interval_ = config_.msd_interval;
  automatic_interval_ = interval_ == 0.0;
  if (in_collisions_) {
    // Half a collision per particle, as half a mean free time in time.
    interval_ = collision_interval(automatic_interval_ ? 0.5 : interval_, mobile).per_particle;
  } else if (automatic_interval_) {
    interval_ = half_enskog_mean_free_time(engine, "analysis.msd_interval");
  }

  restitution_ = config.interactions.contact.restitution;
  number_density_ = static_cast<double>(mobile) / engine.volume();
  sigma_ = 2.0 * radius;
  if (in_collisions_) {
    theory_why_ = mobile < n        ? "fixed grains: the gas is not homogeneous"
                  : equal_particles ? theory_does_not_apply(config)
                                    : "the particles differ in diameter or mass (the theory is "
                                      "for equal particles)";
    if (theory_why_.empty()) theory_ = hcs_self_diffusion(D, restitution_, number_density_, sigma_);
  }

  if (config_.mutual_diffusion) {
    interdiffusion_.emplace(species_of_);
    if (interdiffusion_->count() == 0) {
      throw InputError(
          "analysis.mutual_diffusion: interdiffusion needs particles of two species or more");
    }
    every_slot_.resize(n);
    for (std::size_t id = 0; id < n; ++id) every_slot_[id] = static_cast<std::uint32_t>(id);
    every_position_.resize(n);
  }
}

template <int D>
std::string MsdOutput<D>::theory_does_not_apply(const Config& config) const {
  const ContactConfig& contact = config.interactions.contact;
  const auto& kind = engine_.kind();
  if (!engine_.bulk()) return "walls, open faces or gravity: not a homogeneous periodic gas";
  if (kind.driven) return "driven ([driving]): not a freely cooling gas";
  if (config.soft.enabled()) return "soft spheres";
  if (!config.potentials.empty() || !config.bonds.empty()) return "stepped potentials or bonds";
  if (restitution_models().at(contact.restitution_model) != RestitutionModel::kConstant)
    return "the restitution depends on the impact speed (contact.restitution_model)";
  if (contact.tangential_restitution != -1.0)
    return "rough particles (contact.tangential_restitution)";
  if (contact.elastic_below_speed > 0.0 || config.interactions.tc > 0.0)
    return "collisions made elastic by rule (contact.elastic_below_speed, contact.tc)";
  for (const PairContactConfig& pair : config.interactions.pairs)
    if (!(pair.contact == contact))
      return "[[contact.pair]] gives some pairs their own contact law";
  if (restitution_ < kHcsTheoryMinRestitution) {
    return fmt::format(
        "contact.restitution < {}: the Sonine expansion of the theory is not converged there "
        "(and the cooling state is unstable in all but the smallest boxes)",
        kHcsTheoryMinRestitution);
  }
  const double eta = engine_.particle_volume() / engine_.volume();
  if (eta > kTheoryMaxPackingFraction) {
    return fmt::format(
        "packing fraction {:.4g} > {}: Enskog's theory misses the correlated collisions that "
        "change D by more than its Sonine truncation there",
        eta, kTheoryMaxPackingFraction);
  }
  return "";
}

template <int D>
std::vector<std::string> MsdOutput<D>::more_files() const {
  std::vector<std::string> files;
  if (config_.vacf) files.emplace_back(kVacfFile);
  if (config_.mutual_diffusion) files.emplace_back(kMutualFile);
  return files;
}

template <int D>
double MsdOutput<D>::clock() const {
  return in_collisions_ ? 2.0 * static_cast<double>(engine_.collisions()) /
                              static_cast<double>(engine_.mobile())
                        : engine_.time();
}

template <int D>
void MsdOutput<D>::production_starts(const RunContext<D>&) {
  const auto groups = static_cast<std::uint32_t>(species_names_.size());
  correlator_.emplace(group_, groups, interval_);
  if (config_.vacf) vacf_.emplace(group_, groups, interval_, MsdCorrelator<D>::Statistic::kProduct);
  if (config_.mutual_diffusion) {
    // One "particle" per moment, each its own group: its error comes from the time epochs.
    const auto moments = static_cast<std::uint32_t>(interdiffusion_->count());
    std::vector<std::uint32_t> own(moments);
    for (std::uint32_t k = 0; k < moments; ++k) own[k] = k;
    mutual_.emplace(own, moments, interval_);
  }
  start_time_ = engine_.time();
  start_collisions_ = engine_.collisions();
  start_wall_collisions_ = engine_.counters().wall_collisions;
}

template <int D>
void MsdOutput<D>::write(const RunContext<D>& run) {
  if (run.phase() != "production") return;
  if (!correlator_) production_starts(run);  // continued in its production
  if (mutual_) {
    engine_.unwrapped_positions(every_slot_, every_position_);
    for (std::size_t id = 0; id < every_position_.size(); ++id)
      if (slot_[id] != ~0u) sample_[slot_[id]] = every_position_[id];
    interdiffusion_->sample(every_position_, moments_);
    mutual_->add(moments_);
  } else {
    engine_.unwrapped_positions(slot_, sample_);
  }
  if (correlator_->samples() == 0) first_sample_ = clock();
  last_sample_ = clock();
  correlator_->add(sample_);
  if (vacf_) {
    engine_.velocities(slot_, sample_);
    vacf_->add(sample_);
  }
}

template <int D>
double MsdOutput<D>::mean_free_time() const {
  if (engine_.mobile() < engine_.size()) {
    // With fixed grains: between a moving particle's contacts of any kind (2 per collision, 1
    // per contact with a fixed grain or a wall).
    const double contacts =
        2.0 * static_cast<double>(engine_.collisions() - start_collisions_) +
        static_cast<double>(engine_.counters().wall_collisions - start_wall_collisions_);
    return contacts > 0.0
               ? static_cast<double>(engine_.mobile()) * (engine_.time() - start_time_) / contacts
               : std::nan("");
  }
  return stats_.mean_free_time(engine_.time() - start_time_,
                               engine_.collisions() - start_collisions_);
}

template <int D>
std::pair<double, double> MsdOutput<D>::fit_window() const {
  // Ten collisions per particle are about ten mean free times (the collision clock).
  return correlation_fit_window(last_sample_ - first_sample_, config_.msd_fit_from,
                                config_.msd_fit_to, in_collisions_ ? 1.0 : mean_free_time());
}

template <int D>
void MsdOutput<D>::close(const RunContext<D>& run, bool) {
  if (!correlator_ || correlator_->samples() < 2) return;
  std::string text = "lag\torigins";
  for (const std::string& s : species_names_) text += fmt::format("\tmsd_{0}\tnon_gaussian_{0}", s);
  text += "\n";
  for (const auto& lag : correlator_->lags()) {
    text += fmt::format("{:.10g}\t{}", lag.lag, lag.origins);
    for (std::size_t g = 0; g < species_names_.size(); ++g)
      text += fmt::format("\t{:.10g}\t{:.6g}", lag.mean[g], lag.non_gaussian[g]);
    text += "\n";
  }
  write_text_atomically(run.directory() / name(), text);
  if (mutual_) {
    // The moments' MSD over N x (1 - x): its slope over 2d is the interdiffusion coefficient.
    text = "lag\torigins";
    const InterdiffusionMoments<D>& moments = *interdiffusion_;
    for (std::size_t k = 0; k < moments.count(); ++k) {
      text += fmt::format("\tmsd_{}-{}", species_names_[moments.species(k)],
                          moments.binary() ? species_names_[moments.partner()] : "rest");
    }
    text += "\n";
    for (const auto& lag : mutual_->lags()) {
      text += fmt::format("{:.10g}\t{}", lag.lag, lag.origins);
      for (const double m : lag.mean) text += fmt::format("\t{:.10g}", m);
      text += "\n";
    }
    write_text_atomically(run.directory() / kMutualFile, text);
  }
  if (!vacf_) return;
  // The velocity autocorrelation and its running Green-Kubo integral (1/d) int_0^lag.
  text = "lag\torigins";
  for (const std::string& s : species_names_) text += fmt::format("\tvacf_{0}\tintegral_{0}", s);
  text += "\n";
  const auto lags = vacf_->lags();
  std::vector<double> integral(species_names_.size(), 0.0);
  for (std::size_t k = 0; k < lags.size(); ++k) {
    text += fmt::format("{:.10g}\t{}", lags[k].lag, lags[k].origins);
    for (std::size_t g = 0; g < species_names_.size(); ++g) {
      if (k > 0) {
        integral[g] +=
            0.5 * (lags[k].lag - lags[k - 1].lag) * (lags[k].mean[g] + lags[k - 1].mean[g]) / D;
      }
      text += fmt::format("\t{:.10g}\t{:.10g}", lags[k].mean[g], integral[g]);
    }
    text += "\n";
  }
  write_text_atomically(run.directory() / kVacfFile, text);
}

template <int D>
void MsdOutput<D>::summarize(nlohmann::json& summary, const RunContext<D>&) const {
  nlohmann::json d;
  d["time_scale"] = in_collisions_ ? "collisions" : "time";
  d["time_scale_automatic"] = time_scale_chosen_;
  d["freely_cooling"] = freely_cooling_;
  d["interval"] = interval_;
  d["interval_automatic"] = automatic_interval_;
  d["particles_followed"] = group_.size();
  d["samples"] = correlator_ ? correlator_->samples() : 0;
  d["memory_bytes"] = (correlator_ ? correlator_->bytes() : 0) + (vacf_ ? vacf_->bytes() : 0) +
                      (mutual_ ? mutual_->bytes() : 0);
  d["sampled_from"] = first_sample_;
  d["sampled_to"] = last_sample_;
  // Per collision the mean free "time" is one collision per particle by definition.
  d["mean_free_time"] = in_collisions_ ? nlohmann::json(nullptr) : finite_or_null(mean_free_time());
  const auto [from, to] = fit_window();
  d["fit_from"] = from;
  d["fit_to"] = to;
  // A freely cooling gas has no constant D in time: D(t) ~ sqrt(T(t)) decays (Haff's law).
  const bool no_coefficient = freely_cooling_ && !in_collisions_;
  const double reduce = number_density_ * (D == 3 ? sigma_ * sigma_ : sigma_) * number_density_ *
                        (D == 3 ? sigma_ * sigma_ : sigma_);
  if (in_collisions_) {
    if (theory_) {
      nlohmann::json t;
      t["coefficient"] = theory_->per_collision;
      t["coefficient_reduced"] = theory_->reduced;
      t["coefficient_first_sonine"] = theory_->first_sonine;
      t["coefficient_maxwellian"] = theory_->maxwellian;
      t["sonine_factor"] = theory_->sonine_factor;
      t["sonine_a2"] = theory_->a2;
      t["contact_value"] = theory_->contact_value;
      t["restitution"] = restitution_;
      t["packing_fraction"] = engine_.particle_volume() / engine_.volume();
      t["number_density"] = number_density_;
      t["diameter"] = sigma_;
      d["theory"] = t;
    } else {
      d["theory"] = nullptr;
      d["theory_why"] = theory_why_;
    }
  }
  nlohmann::json species = nlohmann::json::object();
  const Fits none(species_names_.size());
  const Fits gk = vacf_ ? vacf_->green_kubo(to) : none;
  const Fits fits = correlator_ && !no_coefficient ? correlator_->diffusion(from, to) : none;
  // The Yeh-Hummer correction's viscosity: the one given, or the one analysis.transport
  // measured in this run (its part of the summary comes first).
  double viscosity = config_.msd_viscosity;
  if (viscosity == 0.0 && !in_collisions_ && summary.contains("transport")) {
    const nlohmann::json& eta = summary["transport"]["shear_viscosity"]["value"];
    if (eta.is_number()) viscosity = eta.get<double>();
  }
  for (std::size_t g = 0; g < species_names_.size(); ++g) {
    nlohmann::json s;
    if (g < fixed_species_.size() && fixed_species_[g]) {
      s["coefficient"] = nullptr;
      s["why"] = "a fixed species: its particles never move (not followed)";
      species[species_names_[g]] = s;
      continue;
    }
    if (g < fits.size() && fits[g]) {
      s["coefficient"] = fits[g]->coefficient;
      s["coefficient_stderr"] = finite_or_null(fits[g]->stderr_);
      s["lags_fitted"] = fits[g]->lags;
      s["coefficient_stderr_particles"] = finite_or_null(fits[g]->particle_stderr);
      s["coefficient_stderr_epochs"] = finite_or_null(fits[g]->epoch_stderr);
      s["epochs_fitted"] = fits[g]->epochs;
      // Runs hold few independent windows of the fit's longest lag: the error bars of the
      // subsets and epochs then miss the scatter between runs (docs/validation.md found up to
      // 3x with the automatic window, fit_to = a quarter of the run).
      s["coefficient_stderr_reliable"] = last_sample_ - first_sample_ >= 20.0 * to;
      if (in_collisions_ && sigma_ > 0.0) {
        s["coefficient_reduced"] = fits[g]->coefficient * reduce;
        if (theory_) {
          s["coefficient_over_theory"] = fits[g]->coefficient / theory_->per_collision;
          s["coefficient_over_theory_stderr"] =
              finite_or_null(fits[g]->stderr_ / theory_->per_collision);
        }
      }
    } else if (no_coefficient) {
      s["coefficient"] = nullptr;
      s["why"] =
          "the gas cools freely: D(t) decays with sqrt(T) (Haff's law), so no constant D in "
          "time exists; analysis.msd_time = \"collisions\" (or \"auto\") measures the constant D "
          "per collision of the homogeneous cooling state";
    } else if (std::count(group_.begin(), group_.end(), static_cast<std::uint32_t>(g)) == 0) {
      s["coefficient"] = nullptr;
      s["why"] = "no particle of this species is followed (analysis.msd_particles)";
    } else {
      s["coefficient"] = nullptr;
      s["why"] = fmt::format(
          "fewer than 3 lags in the fit window [{:.4g}, {:.4g}]: the production is too short "
          "for the diffusive regime (or set analysis.msd_fit_from / msd_fit_to)",
          from, to);
    }
    if (fits.size() > g && fits[g] && viscosity > 0.0) {
      // Yeh and Hummer, J. Phys. Chem. B 108, 15873 (2004): a cubic periodic box in 3D.
      const Vec<D>& box = engine_.box();
      bool cubic = D == 3;
      for (int a = 1; a < D; ++a) cubic = cubic && box[a] == box[0];
      if (cubic) {
        constexpr double kXi = 2.837297;
        const double kt =
            stats_.temperature(engine_.thermal_energy(), engine_.held_degrees_of_freedom());
        s["coefficient_infinite_size"] =
            fits[g]->coefficient + kXi * kt / (6.0 * M_PI * viscosity * box[0]);
        s["infinite_size_temperature"] = kt;
        s["infinite_size_viscosity"] = viscosity;
      } else {
        s["coefficient_infinite_size"] = nullptr;
        s["infinite_size_why"] = "the Yeh-Hummer correction is for a cubic periodic box in 3D";
      }
    }
    if (g < gk.size() && gk[g]) {
      s["green_kubo_coefficient"] = gk[g]->coefficient;
      s["green_kubo_coefficient_stderr"] = finite_or_null(gk[g]->stderr_);
    }
    species[species_names_[g]] = s;
  }
  d["species"] = species;
  if (mutual_) summarize_mutual(d, fits, from, to);
  summary["diffusion"] = d;
}

// The interdiffusion coefficient of species a against the rest of the mixture,
// D_a = lim <|M_a(t + lag) - M_a(t)|^2> / (2 d N x_a (1 - x_a) lag), M_a = sum_{i in a} r_i -
// x_a sum_i r_i: for two species the Maxwell-Stefan diffusivity (docs/physics.md), with the
// Darken estimate x_b D_a,self + x_a D_b,self beside it.
template <int D>
void MsdOutput<D>::summarize_mutual(nlohmann::json& d, const Fits& self, double from,
                                    double to) const {
  nlohmann::json m;
  m["frame"] = "number-averaged (Galilean invariant)";
  const bool no_coefficient = freely_cooling_ && !in_collisions_;
  const InterdiffusionMoments<D>& moments = *interdiffusion_;
  const Fits fits = no_coefficient ? Fits(moments.count()) : mutual_->diffusion(from, to);
  nlohmann::json pairs = nlohmann::json::object();
  for (std::size_t k = 0; k < moments.count(); ++k) {
    const std::uint32_t a = moments.species(k);
    const bool binary = moments.binary();
    const std::uint32_t b = binary ? moments.partner() : a;
    nlohmann::json p;
    p["mole_fraction"] = moments.mole_fraction(k);
    if (fits[k]) {
      p["coefficient"] = fits[k]->coefficient;
      p["coefficient_stderr"] = finite_or_null(fits[k]->epoch_stderr);
      p["epochs_fitted"] = fits[k]->epochs;
      p["lags_fitted"] = fits[k]->lags;
      p["coefficient_stderr_reliable"] = last_sample_ - first_sample_ >= 20.0 * to;
    } else {
      p["coefficient"] = nullptr;
      p["why"] = no_coefficient ? "the gas cools freely: no constant coefficient in time"
                                : "fewer than 3 lags in the fit window";
    }
    if (binary && self.size() > std::max(a, b) && self[a] && self[b]) {
      const double x = moments.mole_fraction(k);
      p["darken"] = (1.0 - x) * self[a]->coefficient + x * self[b]->coefficient;
    }
    pairs[species_names_[a] + "-" + (binary ? species_names_[b] : std::string("rest"))] = p;
  }
  m["pairs"] = pairs;
  d["mutual"] = m;
}

template class MsdOutput<2>;
template class MsdOutput<3>;

}  // namespace kairos
