// Profiles along one axis of the box (vibrated beds, sedimentation, shear flows): the box is cut
// into slabs perpendicular to the axis; every sample adds each particle to the slab holding its
// centre. Averaged over the samples: number density, packing fraction (a particle's whole
// volume counts in its centre's slab), mean velocity and granular temperature (per degree of
// freedom, from the velocity fluctuations about the slab's mean velocity).
#pragma once

#include <array>
#include <filesystem>
#include <vector>

namespace kairos {

template <int D>
class AxisProfile {
 public:
  // `low`, `high`: the range of the axis that is binned (particles outside it are counted
  // apart); `cross_section`: the box area (3D) or length (2D) perpendicular to the axis.
  AxisProfile(int axis, int bins, double low, double high, double cross_section);

  void sample(const std::vector<std::array<double, D>>& position,
              const std::vector<std::array<double, D>>& velocity, const std::vector<double>& mass,
              const std::vector<double>& volume);

  int samples() const { return samples_; }
  // Tab-separated table, one row per slab, written atomically.
  void write(const std::filesystem::path& path) const;

 private:
  struct Slab {
    double count = 0.0, volume = 0.0, mass = 0.0, energy2 = 0.0;  // energy2: sum m v^2
    std::array<double, D> momentum{};
  };
  int axis_;
  double low_, width_, cross_section_;
  std::vector<Slab> slabs_;
  double outside_ = 0.0;
  int samples_ = 0;
};

}  // namespace kairos
