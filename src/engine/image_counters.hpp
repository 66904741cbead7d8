// Image counters: how many times each particle has been wrapped through each periodic face, so
// that positions can be unwrapped (diffusion, trajectories read by OVITO, freud or MDAnalysis as
// HOOMD files are: particles/image). A cold array outside the 64-byte hot record, kept only
// when a run asks for it (EngineOptions::track_images): 4 D bytes per particle.
//
// Convention: the unwrapped position at a particle's local time is pos + image * box on every
// periodic axis. Under Lees-Edwards shear (boundaries/lees_edwards.hpp) a particle crossing a y
// face is also shifted along x by the images' offset; the counters then keep the lab-frame
// unwrapped x = x + image_x L_x + image_y * (shear_rate L_y t) continuous (docs/outputs.md).
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/huge_page_allocator.hpp"
#include "core/permutation.hpp"
#include "core/vec.hpp"

namespace kairos {

template <int D>
class ImageCounters {
 public:
  using Image = std::array<std::int32_t, D>;

  ImageCounters() = default;
  // n particles, all at image 0.
  explicit ImageCounters(std::size_t n) : image_(n, Image{}) {}
  bool on() const { return !image_.empty(); }

  // The state's counters (caller's numbering; empty: all 0) into the engine's numbering.
  template <class Ids>
  void restore(const std::vector<Image>& by_id, const Ids& id) {
    if (by_id.empty() || !on()) return;
    if (by_id.size() != image_.size())
      throw InputError("the state has image counters for some particles but not all");
    for (std::size_t k = 0; k < image_.size(); ++k) image_[k] = by_id[id[k]];
  }

  const Image& of(std::uint32_t k) const { return image_[k]; }
  // Particle k's position moved by `delta` boxes along `axis` (delta = -1: it was wrapped from
  // the high face to the low one), so its image moves the other way.
  // Particle k was put somewhere else (an outlet's insertion): it starts a new path.
  void reset(std::uint32_t k) { image_[k] = Image{}; }
  void wrapped(std::uint32_t k, int axis, int delta) {
    image_[k][axis] -= static_cast<std::int32_t>(delta);
  }
  // A coordinate x wrapped into the box as `inside` (any number of boxes).
  void wrapped(std::uint32_t k, int axis, double x, double inside, double box) {
    image_[k][axis] += static_cast<std::int32_t>(std::lround((x - inside) / box));
  }

  void permute(const std::vector<std::uint32_t>& order, std::vector<bool>& done) {
    if (on()) permute_in_place(image_, order, done);
  }
  double bytes_per_particle() const { return on() ? static_cast<double>(sizeof(Image)) : 0.0; }

 private:
  HugeVector<Image> image_;
};

}  // namespace kairos
