#include "boundaries/plane_walls.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "core/error.hpp"
#include "dynamics/collision_time.hpp"
#include "dynamics/trajectory_events.hpp"

namespace kairos {

template <int D>
PlaneWalls<D>::PlaneWalls(std::vector<PlaneWall<D>> planes, const Vec<D>& box,
                          const std::array<Face<D>, 2 * D>& faces, const Vec<D>& gravity)
    : planes_(std::move(planes)), box_(box), faces_(faces), gravity_(gravity) {
  std::vector<CylinderWall<D>> edges;
  for (std::size_t k = 0; k < planes_.size(); ++k) {
    const PlaneWall<D>& p = planes_[k];
    if (!p.spanned()) continue;
    const auto [along, across] = p.edge_axes();
    if (along < 0 || across < 0) continue;  // refused by Environment::check
    const double ends[2] = {p.span_min, p.span_max};
    for (const double end : ends) {
      if (!std::isfinite(end)) continue;
      CylinderWall<D>& edge = edges.emplace_back();
      edge.axis = along;
      edge.center[p.span_axis] = end;
      edge.center[across] = (p.offset - p.normal[p.span_axis] * end) / p.normal[across];
      edge.radius = 0.0;
      edge.inside = false;
      edge.contact = p.wall.contact;
      edge_names_.push_back(
          fmt::format("boundary.plane[{}] edge at {} = {:.6g}", k, "xyz"[p.span_axis], end));
    }
  }
  edges_ = CylinderWalls<D>(std::move(edges), gravity);
  std::vector<RingEdge<D>> rings;
  for (std::size_t k = 0; k < planes_.size(); ++k) {
    const PlaneWall<D>& p = planes_[k];
    if (!p.holed()) continue;
    rings.push_back({p.hole_center, p.normal, p.hole_radius, p.wall.contact});
    ring_planes_.push_back(static_cast<int>(k));
  }
  rings_ = RingEdges<D>(std::move(rings), gravity);
}

template <int D>
std::string PlaneWalls<D>::name(int s) const {
  if (s < planes()) return "boundary.plane[" + std::to_string(s) + "]";
  if (is_ring(s)) {
    return "boundary.plane[" +
           std::to_string(ring_planes_[static_cast<std::size_t>(s - first_ring())]) +
           "] hole's edge";
  }
  return edge_names_[static_cast<std::size_t>(s - planes())];
}

// A strip is a thin plate with two faces, n.x = c met from the front and -n.x = -c from behind,
// each only where the foot lies within the strip (the edges close its ends). For one face (unit
// normal m towards the particle's side, offset d) the height h = m.x - R - d moves as
// h0 + b t + a t^2/2: from in front of the face (h0 >= 0, or round-off below it) the plane's
// own root; from behind it (a particle beside the strip: in an orifice, or past its other face)
// only a rise and fall back can meet it, the later root (a < 0 < b). A parabola crosses a face's
// level towards it once, so a crossing beside the strip means none with that face at all.
template <int D>
double PlaneWalls<D>::face_event_time(const PlaneWall<D>& p, double side, const Vec<D>& x,
                                      const Vec<D>& v, double radius, double horizon) const {
  const Vec<D> m = side * p.normal;
  const double d = side * p.offset;
  const double mx = dot(m, x), b = dot(m, v), a = dot(m, gravity_);
  const double height = mx - radius - d;
  double when = kNever;
  if (height >= -kStripRoundOff * radius) {
    when = fixed_plane_event_time(NormalMotion{mx - radius, b, a}, d, horizon);
  } else if (a < 0.0 && b > 0.0) {
    const double c = 0.5 * a, disc = b * b - 4.0 * height * c;
    if (disc > 0.0) when = within_horizon((-b - std::sqrt(disc)) / (2.0 * c), horizon);
  }
  if (!(when < kNever)) return kNever;
  const Vec<D> at = x + when * v + (0.5 * when * when) * gravity_;
  return p.covers(at, side * radius) ? when : kNever;
}

template <int D>
double PlaneWalls<D>::strip_event_time(const PlaneWall<D>& p, const Vec<D>& x, const Vec<D>& v,
                                       double radius, double horizon) const {
  return std::min(face_event_time(p, 1.0, x, v, radius, horizon),
                  face_event_time(p, -1.0, x, v, radius, horizon));
}

// Along the normal the particle's height above the plane is n.x - R, moving at n.v with
// acceleration n.g; the plane's offset moves at u = n.velocity (plus its vibration): the
// solvers of the face walls (dynamics/trajectory_events), on the projected motion
// (docs/physics.md#walls-at-any-orientation).
template <int D>
double PlaneWalls<D>::event_time(int s, const Vec<D>& x, const Vec<D>& v, double radius, double t,
                                 double horizon) const {
  if (is_ring(s)) return rings_.event_time(s - first_ring(), x, v, radius, horizon);
  if (s >= planes()) return edges_.event_time(s - planes(), x, v, radius, t, horizon);
  const PlaneWall<D>& p = plane(s);
  if (p.plate()) return strip_event_time(p, x, v, radius, horizon);
  const NormalMotion m{dot(p.normal, x) - radius, dot(p.normal, v), dot(p.normal, gravity_)};
  const double u = p.normal_speed();
  const double d = p.offset + (u != 0.0 ? u * t : 0.0);
  if (p.wall.vibrates()) {
    const NormalMotion rel{m.height, m.velocity - u, m.accel};
    const VibratedPlane vibrated{
        d, p.wall.amplitude, p.wall.angular_frequency,
        std::remainder(p.wall.angular_frequency * t + p.wall.phase, 2.0 * M_PI)};
    return vibrated_plane_event_time(rel, vibrated, horizon);
  }
  return moving_plane_event_time(m, d, u, horizon);
}

// The lowest n.x over the cell (its outer layers along a bounded axis reach to infinity).
template <int D>
bool PlaneWalls<D>::reaches(int s, CellCode cell, const CellGrid<D>& grid) const {
  if (is_ring(s)) return rings_.reaches(s - first_ring(), cell, grid, rmax_);
  if (s >= planes()) return edges_.reaches(s - planes(), cell, grid);
  const PlaneWall<D>& p = plane(s);
  if (p.normal_speed() != 0.0) return true;
  return grid.lowest_along(cell, p.normal) - (p.offset + p.wall.amplitude) < rmax_;
}

template <int D>
ContactResult<D> PlaneWalls<D>::resolve(int s, const Vec<D>& x, double t, double mass,
                                        double radius, double inertia_factor, bool force_elastic,
                                        Vec<D>& v, Spin<D>& w) const {
  if (is_ring(s)) {
    return rings_.resolve(s - first_ring(), x, mass, radius, inertia_factor, force_elastic, v, w);
  }
  if (s >= planes()) {
    return edges_.resolve(s - planes(), x, t, mass, radius, inertia_factor, force_elastic, v, w);
  }
  const PlaneWall<D>& p = plane(s);
  if (p.plate()) {  // a still plate, met on either face
    return resolve_surface_contact<D>(p.wall.contact, normal(s, x, t), Vec<D>{}, mass, radius,
                                      inertia_factor, force_elastic, v, w);
  }
  return resolve_surface_contact<D>(p.wall.contact, p.normal, p.surface_velocity(t), mass, radius,
                                    inertia_factor, force_elastic, v, w);
}

template <int D>
void PlaneWalls<D>::check_start(const Vec<D>& x, double radius, double t, std::uint64_t id) const {
  edges_.check_start(x, radius, t, id);
  for (int s = first_ring(); s < surfaces(); ++s) {
    const double g = gap(s, x, t);
    if (g < radius * (1.0 - 1e-12)) {
      throw InputError(fmt::format(
          "particle {} overlaps the wall {} (centre {:.6g} from the edge, radius {:.6g})", id,
          name(s), g, radius));
    }
  }
  for (int s = 0; s < planes(); ++s) {
    const double g = gap(s, x, t);
    if (g < radius * (1.0 - 1e-12)) {
      throw InputError(fmt::format(
          "particle {} overlaps the wall {} (centre {:.6g} from its plane{}, radius {:.6g})", id,
          name(s), g, g < 0.0 ? ", on the side away from its normal" : "", radius));
    }
  }
}

// As the face walls' (boundaries/face_walls.cpp): the relative margin keeps the run from
// spending 1e4 ever faster bounces on the last sliver of room.
constexpr double kPlaneSqueezeMargin = 1e-3;

// A plane moving into the domain (u = n.velocity > 0) sweeps it: the farthest a centre can be
// along n is the box's far side less a radius (max n.x over the box, the corner the normal points
// to), unless a face there is open (the particles leave through it: no squeeze). The first time
// the plane's innermost position (its vibration counted) leaves less than a diameter (times
// 1 + margin) before that side, no particle fits. Other planes are not counted: they can only
// squeeze the particles sooner, which the run drivers' frozen-clock watch reports.
template <int D>
void PlaneWalls<D>::prepare(const CellGrid<D>& grid, double rmax, double particle_volume,
                            bool uniform) {
  edges_.prepare(grid, rmax, particle_volume, uniform);
  rmax_ = rmax;
  // A ring's contact needs R > a (ring_contact_time); a narrower hole passes nothing anyway.
  for (const int k : ring_planes_) {
    const PlaneWall<D>& p = plane(k);
    if (!(p.hole_radius <= 2e6 * rmax)) {
      throw InputError(
          fmt::format("boundary.plane[{}].hole_radius: {:.6g} is beyond 10^6 particle diameters", k,
                      p.hole_radius));
    }
    if (!(p.hole_radius > rmax)) {
      throw InputError(fmt::format(
          "boundary.plane[{}].hole_radius: {:.6g} is not larger than the largest particle "
          "radius {:.6g}: no particle could pass the hole",
          k, p.hole_radius, rmax));
    }
    // Along a periodic axis the ring and the particles touching it stay inside the box: its
    // images are not followed.
    for (int a = 0; a < D; ++a) {
      if (faces_[static_cast<std::size_t>(2 * a)].kind != FaceKind::kPeriodic) continue;
      const double half = p.hole_radius * std::sqrt(std::max(0.0, 1.0 - p.normal[a] * p.normal[a]));
      if (p.hole_center[a] - half - rmax < 0.0 || p.hole_center[a] + half + rmax > box_[a]) {
        throw InputError(fmt::format(
            "boundary.plane[{}].hole_center: the hole's edge comes within a particle radius of "
            "the periodic faces along {} (its images are not followed); move it inside or make "
            "it smaller",
            k, "xyz"[a]));
      }
    }
  }
  squeeze_time_ = kNever;
  squeeze_plane_ = -1;
  for (int s = 0; s < planes(); ++s) {
    const PlaneWall<D>& p = plane(s);
    const double u = p.normal_speed();
    if (!(u > 0.0)) continue;
    double far = 0.0;
    bool escapes = false;
    for (int a = 0; a < D; ++a) {
      const double n = p.normal[a];
      if (n == 0.0) continue;
      const Face<D>& side = faces_[2 * a + (n > 0.0 ? 1 : 0)];
      escapes = escapes || side.kind == FaceKind::kOpen;
      if (n > 0.0) far += n * box_[a];
    }
    if (escapes) continue;
    const double room =
        far - p.offset - p.wall.amplitude - 2.0 * rmax * (1.0 + kPlaneSqueezeMargin);
    const double when = room / u;
    if (when < squeeze_time_) {
      squeeze_time_ = when;
      squeeze_plane_ = s;
    }
  }
}

template <int D>
void PlaneWalls<D>::throw_squeezed(double t, double dmax, bool /*uniform*/) const {
  const PlaneWall<D>& p = plane(squeeze_plane_);
  throw InputError(fmt::format(
      "boundary: at t = {:.10g} the wall {}, moving into the particles at {:.6g} along its "
      "normal, leaves less than the largest particle diameter {:.6g} between it and the far side "
      "of the box: there is no room left; end the run before t = {:.10g}, or move the plane more "
      "slowly or less far",
      t, name(squeeze_plane_), p.normal_speed(), dmax, squeeze_time_));
}

// The plane n.x = offset of a wall or an outlet (`name`): a finite unit normal, a finite point,
// and not across a periodic axis (it would not meet its own periodic image).
template <int D>
void check_plane_placement(const Vec<D>& normal, double offset, const std::string& name,
                           const std::array<bool, D>& periodic) {
  double n2 = 0.0;
  for (int a = 0; a < D; ++a) {
    if (!std::isfinite(normal[a])) throw InputError(name + ".normal must be finite");
    n2 += normal[a] * normal[a];
  }
  if (!(std::abs(n2 - 1.0) <= 1e-12)) throw InputError(name + ".normal must be a unit vector");
  if (!std::isfinite(offset)) throw InputError(name + ".point must be finite");
  for (int a = 0; a < D; ++a) {
    if (normal[a] != 0.0 && periodic[a]) {
      throw InputError(name + ".normal has a component along the periodic axis " +
                       std::string(1, "xyz"[a]) +
                       ": a plane must not cut a periodic axis (it would not meet its own "
                       "periodic image); make that axis bounded (walls or open faces) or the "
                       "normal perpendicular to it");
    }
  }
}

namespace {

// A plane cut to a strip (span_axis): still, across a bounded axis, with edges along a box axis.
template <int D>
void check_strip(const PlaneWall<D>& p, const std::string& name,
                 const std::array<bool, D>& periodic) {
  if (p.span_axis >= D) throw InputError(name + ".span_axis: not an axis of the box");
  const std::string axis(1, "xyz"[p.span_axis]);
  if (periodic[p.span_axis]) {
    throw InputError(name + ".span_axis: " + axis +
                     " is periodic; a strip must end across a bounded axis (walls or open faces)");
  }
  if (!(p.span_min < p.span_max) || std::isnan(p.span_min) || std::isnan(p.span_max))
    throw InputError(name + ": span_min must be below span_max");
  if (p.plane_moves() || norm2(p.wall.velocity) != 0.0) {
    throw InputError(name +
                     ": a strip (span_axis) must hold still: no velocity or vibration (its "
                     "edges do not move)");
  }
  const auto [along, across] = p.edge_axes();
  if (across < 0) {
    throw InputError(name + ".span_axis: the plane is perpendicular to " + axis +
                     ", so it cannot be cut along it; choose an axis the plane runs along");
  }
  if (along < 0) {
    throw InputError(name +
                     ".span_axis: in 3D a strip's edges run along a box axis, so the normal "
                     "must have no component along one of the two axes besides " +
                     axis);
  }
}

// A plane with a circular hole: 3D, still, not a strip; the hole's size and centre finite.
template <int D>
void check_hole(const PlaneWall<D>& p, const std::string& name) {
  if (D != 3) {
    throw InputError(name +
                     ".hole_radius: a hole is for planes in 3D (in 2D cut the line into "
                     "two strips: span_axis)");
  }
  if (p.spanned())
    throw InputError(name + ".hole_radius: a strip (span_axis) cannot also have a hole");
  if (!std::isfinite(p.hole_radius)) throw InputError(name + ".hole_radius: must be finite");
  for (int a = 0; a < D; ++a)
    if (!std::isfinite(p.hole_center[a])) throw InputError(name + ".hole_center: must be finite");
  if (p.plane_moves() || norm2(p.wall.velocity) != 0.0) {
    throw InputError(name +
                     ".hole_radius: a plane with a hole must hold still: no velocity or "
                     "vibration (its edge does not move)");
  }
}

}  // namespace

template <int D>
void PlaneWalls<D>::check_specs(const std::vector<PlaneWall<D>>& planes,
                                const std::array<bool, D>& periodic) {
  for (std::size_t s = 0; s < planes.size(); ++s) {
    const PlaneWall<D>& p = planes[s];
    const std::string name = "boundary.plane[" + std::to_string(s) + "]";
    check_wall_motion(p.wall, name);
    check_plane_placement<D>(p.normal, p.offset, name, periodic);
    if (p.spanned()) check_strip<D>(p, name, periodic);
    if (p.holed()) check_hole(p, name);
  }
}

template <int D>
std::size_t PlaneWalls<D>::codes(const std::vector<PlaneWall<D>>& planes) {
  std::size_t n = planes.size();
  for (const PlaneWall<D>& p : planes) n += (p.spanned() ? 2 : 0) + (p.holed() ? 1 : 0);
  return n;
}

template void check_plane_placement<2>(const Vec<2>&, double, const std::string&,
                                       const std::array<bool, 2>&);
template void check_plane_placement<3>(const Vec<3>&, double, const std::string&,
                                       const std::array<bool, 3>&);

template class PlaneWalls<2>;
template class PlaneWalls<3>;

}  // namespace kairos
