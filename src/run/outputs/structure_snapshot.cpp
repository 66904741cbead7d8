#include "run/outputs/structure_snapshot.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/periodic.hpp"
#include "core/state_blocks.hpp"

namespace kairos {

template <int D>
const Configuration<D>& StructureSnapshot<D>::at(const Integrator<D>& integrator) {
  if (read_ && integrator.time() == time_ && integrator.events() == events_ &&
      integrator.collisions() == collisions_)
    return configuration_;
  const StateBlocks<D> state = integrator.state_blocks();
  const ParticleSystem<D>& globals = state.globals();
  Configuration<D>& c = configuration_;
  c.box = globals.box;
  c.periodic = globals.periodic;
  c.position.resize(state.particles);
  c.species.resize(state.particles);
  c.radius.resize(state.particles);
  state.for_each(
      [&](const ParticleSystem<D>& part, std::size_t first) {
        for (std::size_t j = 0; j < part.size(); ++j) {
          Vec<D> x = part.position(j, part.time);
          for (int a = 0; a < D; ++a)
            if (c.periodic[a]) x[a] = wrap_into_box(x[a], c.box[a]);
          c.position[first + j] = x;
          c.species[first + j] = part.species.empty() ? 0 : part.species[j];
          c.radius[first + j] = part.kinematics[j].radius;
        }
      },
      StateBlocks<D>::kKinematics | StateBlocks<D>::kIdentity);
  std::size_t species = globals.species_names.size();
  for (const std::uint32_t s : c.species) species = std::max<std::size_t>(species, s + 1);
  names_.assign(species, "");
  for (std::size_t s = 0; s < species; ++s)
    names_[s] = s < globals.species_names.size() ? globals.species_names[s] : std::to_string(s);
  counts_.assign(species, 0);
  radius_.assign(species, -1.0);
  for (std::size_t i = 0; i < c.size(); ++i) {
    const std::uint32_t s = c.species[i];
    ++counts_[s];
    if (radius_[s] < 0.0) {
      radius_[s] = c.radius[i];
    } else if (radius_[s] != c.radius[i]) {
      radius_[s] = std::numeric_limits<double>::quiet_NaN();
    }
  }
  for (double& r : radius_)
    if (r < 0.0) r = std::numeric_limits<double>::quiet_NaN();  // no particle of it
  read_ = true;
  time_ = integrator.time();
  events_ = integrator.events();
  collisions_ = integrator.collisions();
  return configuration_;
}

template <int D>
double StructureSnapshot<D>::largest_radius() const {
  double r = 0.0;
  for (const double x : configuration_.radius) r = std::max(r, x);
  return r;
}

template class StructureSnapshot<2>;
template class StructureSnapshot<3>;

}  // namespace kairos
