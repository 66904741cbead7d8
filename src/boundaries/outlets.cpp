#include "boundaries/outlets.hpp"

#include <cmath>

#include <fmt/format.h>

#include "core/error.hpp"
#include "dynamics/trajectory_events.hpp"

namespace kairos {

namespace {

// SplitMix64's finaliser (Steele, Lea & Flood 2014): a well-mixed 64-bit hash of a counter.
std::uint64_t mix(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// A double in [0, 1) from the top 53 bits.
double unit_interval(std::uint64_t bits) {
  return static_cast<double>(bits >> 11) * 0x1.0p-53;
}

}  // namespace

// The centre's height above the plane is n.x - c, moving at n.v with acceleration n.g: the
// fixed plane's solver with the radius left out.
template <int D>
double Outlets<D>::event_time(int s, const Vec<D>& x, const Vec<D>& v, double /*radius*/,
                              double /*t*/, double horizon) const {
  const Outlet<D>& o = outlet(s);
  const NormalMotion m{dot(o.normal, x), dot(o.normal, v), dot(o.normal, gravity_)};
  return fixed_plane_event_time(m, o.offset, horizon);
}

// The lowest n.x over the cell reaches the plane (an outer layer along a bounded axis reaches to
// infinity).
template <int D>
bool Outlets<D>::reaches(int s, CellCode cell, const CellGrid<D>& grid) const {
  return grid.lowest_along(cell, outlet(s).normal) <= outlet(s).offset;
}

template <int D>
ContactResult<D> Outlets<D>::resolve(int /*s*/, const Vec<D>& /*x*/, double /*t*/, double /*mass*/,
                                     double /*radius*/, double /*inertia_factor*/,
                                     bool /*force_elastic*/, Vec<D>& /*v*/, Spin<D>& /*w*/) const {
  throw std::logic_error("Outlets::resolve: particles pass through an outlet");
}

template <int D>
void Outlets<D>::check_start(const Vec<D>& x, double /*radius*/, double t, std::uint64_t id) const {
  for (int s = 0; s < surfaces(); ++s) {
    const double g = gap(s, x, t);
    if (g < 0.0) {
      throw InputError(fmt::format(
          "particle {} starts beyond the outlet (boundary.outlet: its centre lies {:.6g} behind "
          "the plane, on the side away from the normal); start every particle on the normal's "
          "side",
          id, -g));
    }
  }
}

template <int D>
void Outlets<D>::throw_squeezed(double /*t*/, double /*dmax*/, bool /*uniform*/) const {
  throw std::logic_error("Outlets::throw_squeezed: an outlet never squeezes");
}

template <int D>
Vec<D> Outlets<D>::insertion_point(int s, std::uint64_t pass, std::uint32_t attempt) const {
  const Outlet<D>& o = outlet(s);
  std::uint64_t state = mix(o.seed ^ mix(pass ^ mix(attempt)));
  Vec<D> x;
  for (int a = 0; a < D; ++a) {
    state = mix(state);
    x[a] = o.insert_lower[a] + unit_interval(state) * (o.insert_upper[a] - o.insert_lower[a]);
  }
  return x;
}

template class Outlets<2>;
template class Outlets<3>;

}  // namespace kairos
