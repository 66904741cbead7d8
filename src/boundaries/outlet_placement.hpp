// Where an outlet puts a particle back (boundaries/outlets.hpp,
// docs/physics.md#outlets-and-strips): the one rule both integrators follow, so that the event
// engine (engine/outlet_passes.cpp) and the DEM (dem/dem_integrator.cpp) draw the same places from
// the same numbers. Each integrator supplies only its own test of a free place (its neighbourhood
// search).
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include <fmt/format.h>

#include "boundaries/outlets.hpp"
#include "core/error.hpp"
#include "core/periodic.hpp"
#include "core/vec.hpp"

namespace kairos {

// Draws of the insertion region for one pass before it is declared full.
inline constexpr std::uint32_t kOutletInsertionAttempts = 100000;
// Draws of the region at the start, looking for room inside the walls.
inline constexpr std::uint32_t kOutletRegionProbes = 1000;

// The attempt-th draw for pass `pass` of outlet k, wrapped into the box along its periodic axes.
template <int D>
Vec<D> outlet_candidate(const Outlets<D>& outlets, int k, std::uint64_t pass, std::uint32_t attempt,
                        const std::array<bool, D>& periodic, const Vec<D>& box) {
  Vec<D> x = outlets.insertion_point(k, pass, attempt);
  for (int a = 0; a < D; ++a)
    if (periodic[static_cast<std::size_t>(a)]) x[a] = wrap_into_box(x[a], box[a]);
  return x;
}

// A region outside the walls (or behind a plane) would only show at the first pass, after every
// draw failed: draws of each outlet's region must find room for the largest particle (radius
// rmax) inside the walls of `boundaries` (a Boundaries<D>: overlaps(x, radius, t)).
template <int D, class Bounds>
void check_outlet_regions(const Bounds& boundaries, double rmax, double t,
                          const std::array<bool, D>& periodic, const Vec<D>& box) {
  const Outlets<D>& outlets = boundaries.outlets();
  for (int k = 0; k < outlets.surfaces(); ++k) {
    bool inside = false;
    for (std::uint32_t attempt = 0; attempt < kOutletRegionProbes && !inside; ++attempt) {
      const Vec<D> x = outlet_candidate<D>(outlets, k, ~std::uint64_t{0}, attempt, periodic, box);
      inside = !boundaries.overlaps(x, rmax, t);
    }
    if (!inside) {
      throw InputError(fmt::format(
          "boundary.outlet: no place in the insertion region (insert_lower to insert_upper) "
          "leaves room for a particle of radius {:.6g} inside the walls ({} draws): the region "
          "lies outside the box's walls or behind a plane; move it inside",
          rmax, kOutletRegionProbes));
    }
  }
}

// The place of particle `id` after pass number `pass` through outlet k at time t: the first draw
// that free(x) accepts (free of walls and of every other particle at its position now).
// InputError naming the particle when kOutletInsertionAttempts draws all fail.
template <int D, class Free>
Vec<D> outlet_place(const Outlets<D>& outlets, int k, std::uint64_t pass,
                    const std::array<bool, D>& periodic, const Vec<D>& box, double t,
                    std::uint64_t id, Free&& free) {
  for (std::uint32_t attempt = 0; attempt < kOutletInsertionAttempts; ++attempt) {
    const Vec<D> x = outlet_candidate<D>(outlets, k, pass, attempt, periodic, box);
    if (free(x)) return x;
  }
  throw InputError(fmt::format(
      "boundary.outlet: at t = {:.10g} particle {} passed the outlet, but no free place for it "
      "was found in the insertion region (insert_lower to insert_upper) in {} tries: the "
      "region is full, or lies outside the walls; make it larger, or place it inside the walls "
      "where the particles leave room",
      t, id, kOutletInsertionAttempts));
}

}  // namespace kairos
