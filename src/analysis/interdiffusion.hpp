// The collective moments of interdiffusion (analysis.mutual_diffusion and the Python module's
// Simulation.msd(mutual=True), docs/physics.md#mutual-diffusion): for each species a against
// the rest of the mixture
//   M_a = (sum_{i in a} r_i - x_a sum_i r_i) / sqrt(N x_a (1 - x_a)),
// whose mean-square displacement over 2 d t is D_a,rest (for two species the Maxwell-Stefan
// coefficient; one moment then, the second's being minus the first's).
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "core/vec.hpp"

namespace kairos {

template <int D>
class InterdiffusionMoments {
 public:
  // species_of: per particle (the numbering sample() is given); count() == 0 when fewer than
  // two species have particles.
  explicit InterdiffusionMoments(const std::vector<std::uint32_t>& species_of)
      : species_of_(species_of) {
    std::vector<std::uint64_t> count;
    for (const std::uint32_t s : species_of) {
      if (s >= count.size()) count.resize(s + 1, 0);
      ++count[s];
    }
    std::vector<std::uint32_t> present;
    for (std::uint32_t s = 0; s < count.size(); ++s)
      if (count[s] > 0) present.push_back(s);
    if (present.size() < 2) return;
    // Two species: one moment (the second's is minus the first's); more: each against the rest.
    if (present.size() == 2) {
      partner_ = present[1];
      present.pop_back();
    }
    species_ = present;
    const auto n = static_cast<double>(species_of.size());
    for (const std::uint32_t s : present) fraction_.push_back(static_cast<double>(count[s]) / n);
    sums_ = count.size();
  }

  std::size_t count() const { return species_.size(); }
  std::uint32_t species(std::size_t k) const { return species_[k]; }
  bool binary() const { return species_.size() == 1; }
  std::uint32_t partner() const { return partner_; }  // two species: the second
  double mole_fraction(std::size_t k) const { return fraction_[k]; }

  // The moments of the particles at `position` (unwrapped, every particle).
  void sample(const std::vector<Vec<D>>& position, std::vector<Vec<D>>& out) const {
    std::vector<Vec<D>> sum(sums_, Vec<D>{});
    Vec<D> total{};
    for (std::size_t id = 0; id < position.size(); ++id) {
      sum[species_of_[id]] = sum[species_of_[id]] + position[id];
      total = total + position[id];
    }
    const auto n = static_cast<double>(position.size());
    out.resize(species_.size());
    for (std::size_t k = 0; k < species_.size(); ++k) {
      const double x = fraction_[k];
      out[k] = (1.0 / std::sqrt(n * x * (1.0 - x))) * (sum[species_[k]] - x * total);
    }
  }

 private:
  std::vector<std::uint32_t> species_of_;
  std::vector<std::uint32_t> species_;  // per moment
  std::uint32_t partner_ = 0;
  std::vector<double> fraction_;  // per moment: its mole fraction
  std::size_t sums_ = 0;          // species indices in use
};

}  // namespace kairos
