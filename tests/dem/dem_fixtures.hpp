// Shared set-ups of the DEM tests.
#pragma once

#include <array>
#include <cstdint>
#include <random>

#include "core/particle_system.hpp"

namespace kairos::testing {

// A bed of spheres (R = 0.5, m = 1) on a jittered lattice: count per axis, the first site, the
// spacing per axis, positions and velocities each drawn uniformly in [-jitter, jitter].
struct JitteredBed {
  std::array<int, 3> count{};
  Vec<3> first{}, spacing{};
  double jitter = 0.1;
  std::uint64_t seed = 1;
};

inline void add_bed(ParticleSystem<3>& s, const JitteredBed& bed) {
  std::mt19937_64 rng(bed.seed);
  std::uniform_real_distribution<double> jitter(-bed.jitter, bed.jitter);
  for (int ix = 0; ix < bed.count[0]; ++ix)
    for (int iy = 0; iy < bed.count[1]; ++iy)
      for (int iz = 0; iz < bed.count[2]; ++iz) {
        const Vec<3> x{bed.first[0] + bed.spacing[0] * ix + jitter(rng),
                       bed.first[1] + bed.spacing[1] * iy + jitter(rng),
                       bed.first[2] + bed.spacing[2] * iz + jitter(rng)};
        s.kinematics.push_back({x, Vec<3>{jitter(rng), jitter(rng), jitter(rng)}, 0.0, 0.5});
        s.mass.push_back(1.0);
      }
}

// One sphere (R = 0.5, m = 1) at x with velocity v in a 20^3 box periodic along x and y.
inline ParticleSystem<3> one_sphere(const Vec<3>& x, const Vec<3>& v) {
  ParticleSystem<3> s;
  s.box = {20.0, 20.0, 20.0};
  s.periodic = {true, true, false};
  s.kinematics.push_back({x, v, 0.0, 0.5});
  s.mass = {1.0};
  return s;
}

}  // namespace kairos::testing
