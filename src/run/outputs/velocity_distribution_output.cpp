#include "run/outputs/velocity_distribution_output.hpp"

#include <cmath>
#include <vector>

#include <fmt/format.h>

#include "core/state_blocks.hpp"
#include "io/atomic_file.hpp"
#include "run/event_adapter.hpp"
#include "run/outputs/summary_values.hpp"

namespace kairos {

// The velocities relative to their mean (under Lees-Edwards shear: to the flow, from the event
// engine's peculiar velocities), kT = Σ m c² / (D N) of this sample.
template <int D>
bool sample_velocity_distribution(const Integrator<D>& integrator,
                                  VelocityDistribution<D>& distribution) {
  const auto n = static_cast<double>(integrator.size());
  if (const EventIntegrator<D>* engine = integrator.as_event(); engine && engine->kind().sheared) {
    std::vector<Vec<D>> c;
    std::vector<double> m;
    engine->peculiar_velocities(c, m);
    double sum = 0.0;
    for (std::size_t i = 0; i < c.size(); ++i) sum += m[i] * norm2(c[i]);
    if (!(sum > 0.0)) return false;
    distribution.begin(sum / (D * n));
    for (std::size_t i = 0; i < c.size(); ++i) distribution.add(c[i], m[i]);
    distribution.end();
    return true;
  }
  // Two passes over the blocks: the mean velocity and kT, then the histogram.
  const StateBlocks<D> state = integrator.state_blocks();
  constexpr unsigned kFields = StateBlocks<D>::kKinematics | StateBlocks<D>::kIdentity;
  double mass = 0.0, energy = 0.0;
  Vec<D> momentum{};
  state.for_each(
      [&](const ParticleSystem<D>& part, std::size_t) {
        for (std::size_t j = 0; j < part.size(); ++j) {
          const Vec<D> v = part.velocity(j, part.time);
          mass += part.mass[j];
          momentum = momentum + part.mass[j] * v;
          energy += part.mass[j] * norm2(v);
        }
      },
      kFields);
  const Vec<D> mean = (1.0 / mass) * momentum;
  const double kT = (energy - mass * norm2(mean)) / (D * n);
  if (!(kT > 0.0)) return false;  // at rest
  distribution.begin(kT);
  state.for_each(
      [&](const ParticleSystem<D>& part, std::size_t) {
        for (std::size_t j = 0; j < part.size(); ++j)
          distribution.add(part.velocity(j, part.time) - mean, part.mass[j]);
      },
      kFields);
  distribution.end();
  return true;
}

template <int D>
void VelocityDistributionOutput<D>::take(const RunContext<D>& run) {
  sample_velocity_distribution(run.integrator(), distribution_);
}

template <int D>
void VelocityDistributionOutput<D>::finish(const RunContext<D>& run) {
  const VelocityDistribution<D>& v = distribution_;
  std::string text = fmt::format(
      "# {} samples; w = c_a sqrt(m / kT), c the velocity relative to the mean (or the flow), kT "
      "the sample's; p: the probability density of one component (all axes pooled), with its "
      "standard error (blocking over the samples); p_x ...: of each axis; maxwellian: the unit "
      "Gaussian's mean over the bin; {:.3g} of the components fell outside the range\n",
      v.samples(), v.outside());
  text += "w\tp\tp_stderr";
  for (int a = 0; a < D; ++a) text += fmt::format("\tp_{}", "xyz"[a]);
  text += "\tmaxwellian\n";
  for (int k = 0; k < VelocityDistribution<D>::kBins; ++k) {
    const BlockAverage p = v.density(k);
    text += fmt::format("{:.6g}\t{:.10g}\t{:.4g}", 0.5 * (v.bin_low(k) + v.bin_low(k + 1)), p.mean,
                        p.stderr_);
    for (int a = 0; a < D; ++a) text += fmt::format("\t{:.10g}", v.density(k, a).mean);
    text += fmt::format("\t{:.10g}\n", v.maxwellian(k));
  }
  write_text_atomically(run.directory() / name(), text);
}

template <int D>
void VelocityDistributionOutput<D>::summarize(nlohmann::json& summary,
                                              const RunContext<D>& run) const {
  nlohmann::json* part = this->part(summary, "velocity_distribution", run);
  if (part == nullptr) return;
  nlohmann::json& j = *part;
  const VelocityDistribution<D>& v = distribution_;
  const std::string none = v.samples() == 0 ? "no sample (no production, or at rest)" : "";
  const std::string few = !none.empty() ? none : v.samples() < 2 ? "fewer than 2 samples" : "";
  const std::string base = "analysis.velocity_distribution.";
  for (const auto& [key, value] : {std::pair{"kurtosis", v.kurtosis()},
                                   {"sonine_a2", v.sonine_a2()},
                                   {"tail_ratio", v.tail_ratio()}}) {
    set_or_explain(summary, j, key, value.mean, none, base + key);
    set_or_explain(summary, j, std::string(key) + "_stderr", value.stderr_, few,
                   base + key + "_stderr");
  }
  j["tail_beyond"] = VelocityDistribution<D>::kTail;
  j["outside_range"] = v.outside();
}

template bool sample_velocity_distribution<2>(const Integrator<2>&, VelocityDistribution<2>&);
template bool sample_velocity_distribution<3>(const Integrator<3>&, VelocityDistribution<3>&);
template class VelocityDistributionOutput<2>;
template class VelocityDistributionOutput<3>;

}  // namespace kairos
