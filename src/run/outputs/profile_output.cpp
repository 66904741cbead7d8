#include "run/outputs/profile_output.hpp"

#include <numbers>
#include <vector>

namespace kairos {

template <int D>
void ProfileOutput<D>::open(const RunContext<D>& run) {
  const Config& config = run.config();
  if (config.output.profile_axis.empty()) return;
  const int axis = config.output.profile_axis[0] - 'x';
  const Vec<D>& box = run.integrator().box();
  double cross = 1.0;
  for (int a = 0; a < D; ++a)
    if (a != axis) cross *= box[a];
  profile_.emplace(axis, static_cast<int>(config.output.profile_bins), 0.0, box[axis], cross);
}

template <int D>
void ProfileOutput<D>::sample(const RunContext<D>& run) {
  if (!profile_) return;
  const ParticleSample<D> p = run.integrator().particles();
  std::vector<double> volume(p.radius.size());
  for (std::size_t i = 0; i < volume.size(); ++i) {
    const double r = p.radius[i];
    volume[i] = D == 3 ? 4.0 / 3.0 * std::numbers::pi * r * r * r : std::numbers::pi * r * r;
  }
  profile_->sample(p.position, p.velocity, p.mass, volume);
}

template class ProfileOutput<2>;
template class ProfileOutput<3>;

}  // namespace kairos
