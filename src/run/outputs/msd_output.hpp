// msd.tsv, vacf.tsv (analysis.vacf), mutual_diffusion.tsv (analysis.mutual_diffusion) and
// summary.json's `diffusion` (analysis.msd): the mean-square displacement of the unwrapped
// positions (engine/image_counters.hpp) on log-spaced lags with many time origins
// (analysis/msd.hpp), sampled at regular times during the production, or at regular collision
// counts (analysis.msd_time; a freely cooling gas by default), each species' self-diffusion
// coefficient from its long-time slope, with the kinetic theory of the homogeneous cooling state
// beside it where that applies, and the interdiffusion coefficients of a mixture from the
// species' collective Helfand moments (docs/outputs.md).
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "analysis/granular_theory.hpp"
#include "analysis/interdiffusion.hpp"
#include "analysis/msd.hpp"
#include "analysis/thermodynamics.hpp"
#include "io/config_choices.hpp"
#include "run/event_adapter.hpp"
#include "run/outputs/observer.hpp"

namespace kairos {

// The MSD's clock in collisions per particle: the trigger's step in collisions (at least 1) for
// a wanted interval of c collisions per particle among n particles, and the interval that step
// is exactly (2 step / n).
struct CollisionInterval {
  std::uint64_t step = 1;
  double per_particle = 0.0;
};
CollisionInterval collision_interval(double wanted, std::size_t particles);
// `per_particle` collisions per particle among `mobile` moving particles, in collisions.
std::uint64_t collisions_for(double per_particle, std::size_t mobile);

// A freely cooling gas: dissipative, with nothing feeding energy in; and whether the MSD's clock
// is collisions per particle (analysis.msd_time: "auto" chooses it for such a gas), for
// analysis.msd and the Python module's Simulation.msd alike.
template <int D>
bool freely_cooling(const typename EventIntegrator<D>::Kind& kind) {
  return kind.dissipative && !kind.driven && !kind.moving_walls && !kind.sheared;
}
template <int D>
bool msd_on_collision_clock(MsdTime clock, const typename EventIntegrator<D>::Kind& kind) {
  return clock == MsdTime::kCollisions || (clock == MsdTime::kAuto && freely_cooling<D>(kind));
}

template <int D>
class MsdOutput final : public Observer<D> {
 public:
  MsdOutput(const Config& config, const EventIntegrator<D>& engine);
  static constexpr std::string_view kMsdFile = "msd.tsv";
  static constexpr std::string_view kVacfFile = "vacf.tsv";                // analysis.vacf
  static constexpr std::string_view kMutualFile = "mutual_diffusion.tsv";  // .mutual_diffusion
  static constexpr std::array<std::string_view, 3> kFiles{kMsdFile, kVacfFile, kMutualFile};
  std::string name() const override { return std::string(kMsdFile); }
  std::vector<std::string> more_files() const override;
  bool samples_in_time() const override { return !in_collisions_; }
  bool samples_in_collisions() const override { return in_collisions_; }
  double interval(const Config&, double) const override { return interval_; }
  void production_starts(const RunContext<D>& run) override;
  void write(const RunContext<D>& run) override;
  void close(const RunContext<D>& run, bool stopped) override;
  void summarize(nlohmann::json& summary, const RunContext<D>& run) const override;

 private:
  using Fits = std::vector<std::optional<typename MsdCorrelator<D>::Diffusion>>;
  // The fit window: the configured one, or from ten mean free times (ten collisions per particle)
  // or a tenth of the longest lag, if later, to a quarter of the sampled time.
  std::pair<double, double> fit_window() const;
  double mean_free_time() const;
  // Now on the MSD's clock: simulated time, or collisions per particle.
  double clock() const;
  // Why the kinetic theory of the homogeneous cooling state does not apply ("": it does).
  std::string theory_does_not_apply(const Config& config) const;
  void summarize_mutual(nlohmann::json& d, const Fits& self, double from, double to) const;

  const EventIntegrator<D>& engine_;
  AnalysisConfig config_;
  Thermodynamics stats_;         // the temperature and mean free time, as thermo.tsv defines them
  bool in_collisions_ = false;   // the clock is collisions per particle
  bool freely_cooling_ = false;  // dissipative, nothing feeding energy in
  bool time_scale_chosen_ = false;  // analysis.msd_time = "auto" chose it
  double interval_ = 0.0;
  bool automatic_interval_ = false;
  std::vector<std::uint32_t> slot_;  // per particle: its place among the followed, or ~0u
  std::vector<std::uint32_t> group_;
  std::vector<std::string> species_names_;
  std::vector<Vec<D>> sample_;
  std::optional<MsdCorrelator<D>> correlator_;
  std::optional<MsdCorrelator<D>> vacf_;  // analysis.vacf
  // The kinetic theory of the cooling state (in collisions per particle), or why there is none.
  std::optional<HcsSelfDiffusion> theory_;
  std::string theory_why_;
  double restitution_ = 1.0, number_density_ = 0.0, sigma_ = 0.0;
  // analysis.mutual_diffusion: per particle its species; per moment (a species against the rest
  // of the mixture: one for two species) the species and its mole fraction; every particle's
  // unwrapped position; the moments' correlator.
  std::vector<std::uint32_t> species_of_;
  std::optional<InterdiffusionMoments<D>> interdiffusion_;
  std::vector<std::uint32_t> every_slot_;
  std::vector<Vec<D>> every_position_, moments_;
  std::optional<MsdCorrelator<D>> mutual_;
  double first_sample_ = 0.0, last_sample_ = 0.0;
  double start_time_ = 0.0;
  std::uint64_t start_collisions_ = 0;
  // Fixed grains (docs/physics.md#fixed-grains): which species are fixed, and the contacts with
  // immovable bodies at the start (a particle's contact with a fixed grain or a wall changes
  // its velocity as a collision does: the mean free time counts them).
  std::vector<bool> fixed_species_;
  std::uint64_t start_wall_collisions_ = 0;
};

}  // namespace kairos
