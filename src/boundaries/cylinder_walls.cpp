#include "boundaries/cylinder_walls.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

#include "core/error.hpp"
#include "dynamics/collision_time.hpp"
#include "dynamics/trajectory_events.hpp"
#include "interactions/parameter_domain.hpp"

namespace kairos {

template <int D, RoundShape S>
double RoundWalls<D, S>::gap(int s, const Vec<D>& x, double /*t*/) const {
  const CylinderWall<D>& c = cylinder(s);
  const double d = std::sqrt(norm2(c.across(x - c.center)));
  return c.inside ? c.radius - d : d - c.radius;
}

// Across the axis, towards it (inside) or away from it (outside). On the axis itself (only an
// outside cylinder of radius 0 would put a particle there) any direction across it will do.
template <int D, RoundShape S>
Vec<D> RoundWalls<D, S>::normal(int s, const Vec<D>& x, double /*t*/) const {
  const CylinderWall<D>& c = cylinder(s);
  Vec<D> r = c.across(x - c.center);
  const double d = std::sqrt(norm2(r));
  if (!(d > 0.0)) {
    r = Vec<D>{};
    r[(c.axis + 1) % D] = 1.0;
  } else {
    r = (1.0 / d) * r;
  }
  return c.inside ? -1.0 * r : r;
}

// omega e_axis x (p - c) at the surface point p nearest to x; in 2D omega (-y, x).
template <int D, RoundShape S>
Vec<D> RoundWalls<D, S>::velocity(int s, const Vec<D>& x, double t) const {
  if (cylinder(s).angular_velocity == 0.0) return Vec<D>{};
  return velocity_at(s, normal(s, x, t));
}

// The surface's velocity where its normal is n (the normal found once serves both).
template <int D, RoundShape S>
Vec<D> RoundWalls<D, S>::velocity_at(int s, const Vec<D>& n) const {
  const CylinderWall<D>& c = cylinder(s);
  if (c.angular_velocity == 0.0) return Vec<D>{};
  const Vec<D> p = (c.inside ? -c.radius : c.radius) * n;  // the surface point, from the axis
  Vec<D> u{};
  if constexpr (D == 2) {
    u = {-c.angular_velocity * p[1], c.angular_velocity * p[0]};
  } else {
    const int a = c.axis, b = (a + 1) % 3, e = (a + 2) % 3;
    u[b] = -c.angular_velocity * p[e];
    u[e] = c.angular_velocity * p[b];
  }
  return u;
}

// The distance across the axis at time t: r + v t + g t^2 / 2 (all across it), so
// f(t) = |r(t)|^2 - L^2 is a quartic (a quadratic without a field across the axis). Inside the
// valid side is |r| <= R_c - R, outside |r| >= R_c + R; f is signed so that f < 0 is the
// overlapping side, as the solvers want (docs/physics.md#cylinder-walls).
template <int D, RoundShape S>
double RoundWalls<D, S>::event_time(int s, const Vec<D>& x, const Vec<D>& v, double radius,
                                    double /*t*/, double horizon) const {
  const CylinderWall<D>& c = cylinder(s);
  const Vec<D> r = c.across(x - c.center);
  const Vec<D> u = c.across(v), a = c.across(gravity_);
  const double reach = c.inside ? c.radius - radius : c.radius + radius;
  const double sign = c.inside ? -1.0 : 1.0;
  const double rr = norm2(r), ru = dot(r, u), uu = norm2(u), ra = dot(r, a), ua = dot(u, a),
               aa = norm2(a);
  const std::array<double, 5> f{sign * (rr - reach * reach), sign * 2.0 * ru, sign * (uu + ra),
                                sign * ua, sign * 0.25 * aa};
  if (aa == 0.0) return within_horizon(quadratic_event_time(f[0], f[1], f[2]), horizon);
  return quartic_event_time(f, horizon);
}

// The cell's nearest and farthest points across the axis (its outer layers along a bounded
// axis reach to infinity: reached).
template <int D, RoundShape S>
bool RoundWalls<D, S>::reaches(int s, CellCode cell, const CellGrid<D>& grid) const {
  const CylinderWall<D>& c = cylinder(s);
  double near2 = 0.0, far2 = 0.0;
  for (int b = 0; b < D; ++b) {
    if (D == 3 && S == RoundShape::kCylinder && b == c.axis) continue;
    const double lo = grid.lower_bound(cell, b) - c.center[b];
    const double hi = grid.upper_bound(cell, b) - c.center[b];
    if (!std::isfinite(lo) || !std::isfinite(hi)) return true;
    const double near = lo > 0.0 ? lo : (hi < 0.0 ? -hi : 0.0);
    const double far = std::max(std::abs(lo), std::abs(hi));
    near2 += near * near;
    far2 += far * far;
  }
  if (c.inside) {
    const double from = c.radius - rmax_;
    return from <= 0.0 || far2 >= from * from;
  }
  const double to = c.radius + rmax_;
  return near2 <= to * to;
}

template <int D, RoundShape S>
ContactResult<D> RoundWalls<D, S>::resolve(int s, const Vec<D>& x, double t, double mass,
                                           double radius, double inertia_factor, bool force_elastic,
                                           Vec<D>& v, Spin<D>& w) const {
  const Vec<D> n = normal(s, x, t);
  return resolve_surface_contact<D>(cylinder(s).contact, n, velocity_at(s, n), mass, radius,
                                    inertia_factor, force_elastic, v, w);
}

template <int D, RoundShape S>
void RoundWalls<D, S>::check_start(const Vec<D>& x, double radius, double t,
                                   std::uint64_t id) const {
  for (int s = 0; s < surfaces(); ++s) {
    const double g = gap(s, x, t);
    if (g < radius * (1.0 - 1e-12)) {
      throw InputError(fmt::format(
          "particle {} overlaps the wall {} (centre {:.6g} from its surface{}, radius {:.6g})", id,
          name(s), g, g < 0.0 ? (cylinder(s).inside ? ", outside it" : ", inside it") : "",
          radius));
    }
  }
}

template <int D, RoundShape S>
void RoundWalls<D, S>::throw_squeezed(double /*t*/, double /*dmax*/, bool /*uniform*/) const {
  throw std::logic_error("RoundWalls::throw_squeezed: a round wall never squeezes");
}

template <int D, RoundShape Shape>
void RoundWalls<D, Shape>::check_specs(const std::vector<CylinderWall<D>>& walls,
                                       const std::array<bool, D>& periodic) {
  constexpr bool sphere = Shape == RoundShape::kSphere;
  for (std::size_t s = 0; s < walls.size(); ++s) {
    const CylinderWall<D>& c = walls[s];
    const std::string name =
        std::string(sphere ? "boundary.sphere[" : "boundary.cylinder[") + std::to_string(s) + "]";
    if (c.axis < 0 || c.axis >= D) throw InputError(name + ": axis must be a box axis");
    require_positive(c.radius, "radius", name + ": ");
    if (!std::isfinite(c.angular_velocity))
      throw InputError(name + ": angular_velocity must be finite");
    for (int a = 0; a < D; ++a) {
      if (!std::isfinite(c.center[a])) throw InputError(name + ": center must be finite");
      if ((sphere || D == 2 || a != c.axis) && periodic[a]) {
        throw InputError(
            name + ": the axis " + std::string(1, "xyz"[a]) +
            (sphere ? " is periodic: a sphere" : " across the cylinder is periodic: a cylinder") +
            " must not cross a periodic face (it would not meet its own periodic "
            "image); make that axis bounded (walls or open faces)");
      }
    }
  }
}

template class RoundWalls<2, RoundShape::kCylinder>;
template class RoundWalls<3, RoundShape::kCylinder>;
template class RoundWalls<2, RoundShape::kSphere>;
template class RoundWalls<3, RoundShape::kSphere>;

}  // namespace kairos
