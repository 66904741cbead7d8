#include "boundaries/ring_edges.hpp"

#include <algorithm>
#include <cmath>

#include "boundaries/face_wall.hpp"
#include "dynamics/trajectory_events.hpp"

namespace kairos {

namespace {

// The offset of x from the ring's centre split into its height z along the axis and the part
// across it.
template <int D>
void split(const RingEdge<D>& r, const Vec<D>& x, double& z, Vec<D>& across) {
  const Vec<D> d = x - r.center;
  z = dot(d, r.axis);
  across = d - z * r.axis;
}

}  // namespace

// Only over the hole (the foot within it): beside it the plate's face is the nearer surface
// (its distance |z| is below the ring's), and a soft contact (the DEM) must meet one of the two,
// not both; at the rim the two distances agree, so the contact passes from one to the other
// without a jump.
template <int D>
double RingEdges<D>::gap(int s, const Vec<D>& x) const {
  const RingEdge<D>& r = ring(s);
  double z = 0.0;
  Vec<D> across{};
  split(r, x, z, across);
  const double rho = std::sqrt(norm2(across));
  if (rho > r.radius) return kNever;
  return std::hypot(rho - r.radius, z);
}

// From the circle's point nearest to x (on the axis every point of the circle is as near: any
// one will do) to x.
template <int D>
Vec<D> RingEdges<D>::normal(int s, const Vec<D>& x) const {
  const RingEdge<D>& r = ring(s);
  double z = 0.0;
  Vec<D> across{};
  split(r, x, z, across);
  const double rho = std::sqrt(norm2(across));
  Vec<D> radial{};
  if (rho > 0.0) {
    radial = (1.0 / rho) * across;
  } else {
    // A direction across the axis: the box axis least along it, made orthogonal.
    int k = 0;
    for (int a = 1; a < D; ++a)
      if (std::abs(r.axis[a]) < std::abs(r.axis[k])) k = a;
    radial[k] = 1.0;
    radial = radial - dot(radial, r.axis) * r.axis;
    radial = (1.0 / std::sqrt(norm2(radial))) * radial;
  }
  Vec<D> n = (x - r.center) - r.radius * radial;
  const double length = std::sqrt(norm2(n));
  return length > 0.0 ? (1.0 / length) * n : radial;
}

template <int D>
double RingEdges<D>::event_time(int s, const Vec<D>& x, const Vec<D>& v, double radius,
                                double horizon) const {
  if constexpr (D != 3) {
    (void)s, (void)x, (void)v, (void)radius, (void)horizon;
    return kNever;
  } else {
    const RingEdge<D>& r = ring(s);
    const Vec<D> d = x - r.center;
    return ring_contact_time(d.data(), v.data(), gravity_.data(), r.axis.data(), r.radius, radius,
                             horizon);
  }
}

template <int D>
bool RingEdges<D>::reaches(int s, CellCode cell, const CellGrid<D>& grid, double rmax) const {
  const RingEdge<D>& r = ring(s);
  double far2 = 0.0;
  for (int a = 0; a < D; ++a) {
    const double lo = grid.lower_bound(cell, a), hi = grid.upper_bound(cell, a);
    if (!std::isfinite(lo) || !std::isfinite(hi)) return true;
    // The circle's extent along axis a: R sqrt(1 - n_a^2) either side of its centre.
    const double half = r.radius * std::sqrt(std::max(0.0, 1.0 - r.axis[a] * r.axis[a]));
    const double gap = std::max({0.0, lo - (r.center[a] + half), (r.center[a] - half) - hi});
    far2 += gap * gap;
  }
  return far2 <= rmax * rmax;
}

template <int D>
ContactResult<D> RingEdges<D>::resolve(int s, const Vec<D>& x, double mass, double radius,
                                       double inertia_factor, bool force_elastic, Vec<D>& v,
                                       Spin<D>& w) const {
  return resolve_surface_contact<D>(ring(s).contact, normal(s, x), Vec<D>{}, mass, radius,
                                    inertia_factor, force_elastic, v, w);
}

template class RingEdges<2>;
template class RingEdges<3>;

}  // namespace kairos
