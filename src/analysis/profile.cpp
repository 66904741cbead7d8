#include "analysis/profile.hpp"

#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "io/atomic_file.hpp"

namespace kairos {

template <int D>
AxisProfile<D>::AxisProfile(int axis, int bins, double low, double high, double cross_section)
    : axis_(axis),
      low_(low),
      width_((high - low) / bins),
      cross_section_(cross_section),
      slabs_(static_cast<std::size_t>(bins)) {
  if (axis < 0 || axis >= D || bins < 1 || !(high > low) || !(cross_section > 0.0)) {
    throw std::invalid_argument("AxisProfile: bad axis, bins or range");
  }
}

template <int D>
void AxisProfile<D>::sample(const std::vector<std::array<double, D>>& position,
                            const std::vector<std::array<double, D>>& velocity,
                            const std::vector<double>& mass, const std::vector<double>& volume) {
  for (std::size_t i = 0; i < position.size(); ++i) {
    const double x = (position[i][axis_] - low_) / width_;
    if (!(x >= 0.0) || x >= static_cast<double>(slabs_.size())) {
      outside_ += 1.0;
      continue;
    }
    Slab& s = slabs_[static_cast<std::size_t>(x)];
    s.count += 1.0;
    s.volume += volume[i];
    s.mass += mass[i];
    for (int a = 0; a < D; ++a) {
      s.momentum[a] += mass[i] * velocity[i][a];
      s.energy2 += mass[i] * velocity[i][a] * velocity[i][a];
    }
  }
  ++samples_;
}

template <int D>
void AxisProfile<D>::write(const std::filesystem::path& path) const {
  std::string text = fmt::format(
      "# {} samples; particles outside the binned range per sample: {:.6g}\n"
      "position\tnumber_density\tpacking_fraction\ttemperature",
      samples_, samples_ > 0 ? outside_ / samples_ : 0.0);
  for (int a = 0; a < D; ++a) text += fmt::format("\tvelocity_{}", "xyz"[a]);
  text += "\n";
  const double slab_volume = width_ * cross_section_;
  const double n = samples_ > 0 ? samples_ : 1.0;
  for (std::size_t k = 0; k < slabs_.size(); ++k) {
    const Slab& s = slabs_[k];
    double p2 = 0.0;
    for (int a = 0; a < D; ++a) p2 += s.momentum[a] * s.momentum[a];
    const double temperature =
        s.count > 1.0 ? (s.energy2 - p2 / s.mass) / (D * (s.count - 1.0)) : std::nan("");
    text += fmt::format("{:.10g}\t{:.10g}\t{:.10g}\t{:.10g}",
                        low_ + (static_cast<double>(k) + 0.5) * width_, s.count / (n * slab_volume),
                        s.volume / (n * slab_volume), temperature);
    for (int a = 0; a < D; ++a)
      text += fmt::format("\t{:.10g}", s.mass > 0.0 ? s.momentum[a] / s.mass : std::nan(""));
    text += "\n";
  }
  write_text_atomically(path, text);
}

template class AxisProfile<2>;
template class AxisProfile<3>;

}  // namespace kairos
