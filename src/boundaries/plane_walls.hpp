// Plane walls at any position and orientation ([[boundary.plane]]): the second boundary
// component (docs/extending.md, "Adding a boundary geometry"), beside the walls on the box's
// faces.
//
// A plane is the set n . x = c(t) with n the unit normal into the domain (the side the particles
// are on) and c(t) = c0 + u t + A sin(w t + phi), u = n . velocity: a plane has everything a face
// wall has: its own contact law, a velocity whose components in the plane slide its surface and
// whose normal component moves it (a piston), and a vibration along its normal. Like a face
// wall it is a function of the absolute time, so it adds nothing to restart files.
//
// The domain is the box less the half-spaces behind the planes. A plane must not cut a periodic
// axis (the normal's component along it is 0, checked by Environment::check): across a periodic
// face the plane would not meet its own image.
//
// A still plane may be cut to a strip (span_axis, span_min, span_max: it is there only where
// its points' coordinate along that axis lies in [span_min, span_max]): the floor of a silo
// beside its orifice, the sides of a hopper. Its ends are edges (lines along a box axis in 3D,
// points in 2D), surfaces of their own: a zero-radius outside cylinder each (RoundWalls), after
// all the planes in this component's numbering. A strip is a thin plate, met on both faces, and
// nothing beside it (docs/physics.md#outlets-and-strips).
//
// A still plane in 3D may have a circular hole instead (hole_radius, hole_center: a silo's or a
// hopper's round orifice): a plate met on both faces wherever the foot lies outside the hole,
// whose edge is a ring (boundaries/ring_edges.hpp), numbered after the strips' edges
// (docs/physics.md#circular-holes).
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "boundaries/cylinder_walls.hpp"
#include "boundaries/face_wall.hpp"
#include "boundaries/ring_edges.hpp"
#include "core/vec.hpp"
#include "dynamics/collision_time.hpp"
#include "interactions/granular_contact.hpp"
#include "scheduler/cell_grid.hpp"

namespace kairos {

// One plane wall: where it is, how it moves (velocity, vibration: the fields of Wall<D>, whose
// normal is n here instead of a box axis) and its contact law.
template <int D>
struct PlaneWall {
  Vec<D> normal{};      // unit, into the domain
  double offset = 0.0;  // c0: the plane is n . x = c0 at t = 0
  Wall<D> wall;         // contact law, velocity (sliding and along n), vibration along n
  // A strip: where the plane is, along a box axis (-1: everywhere).
  int span_axis = -1;
  double span_min = -kNever, span_max = kNever;
  // A circular hole (3D, a still plane): its radius (0: none) and centre, a point of the plane.
  double hole_radius = 0.0;
  Vec<D> hole_center{};

  bool spanned() const { return span_axis >= 0; }
  bool holed() const { return hole_radius > 0.0; }
  // A thin plate, met on both faces where it is: a strip, or a plane with a hole.
  bool plate() const { return spanned() || holed(); }
  // The axis a strip's edges run along (3D: the one besides the span axis the normal has no
  // component along; 2D: out of the plane, D - 1 by the cylinders' convention) and the axis
  // across it in the plane of the normal; -1 for either when there is none (Environment::check
  // refuses such a strip).
  std::pair<int, int> edge_axes() const {
    if constexpr (D == 2) {
      const int across = 1 - span_axis;
      return {D - 1, normal[across] != 0.0 ? across : -1};
    } else {
      for (int k = 0; k < 3; ++k) {
        if (k == span_axis || normal[k] != 0.0) continue;
        const int across = 3 - k - span_axis;
        return {k, normal[across] != 0.0 ? across : -1};
      }
      return {-1, -1};
    }
  }
  // Whether the foot of x on the plane (x less its distance along n) lies within the strip.
  bool covers(const Vec<D>& x, double distance) const {
    if (holed()) {
      const Vec<D> foot = x - distance * normal;
      return norm2(foot - hole_center) >= hole_radius * hole_radius;
    }
    if (span_axis < 0) return true;
    const double u = x[span_axis] - distance * normal[span_axis];
    return u >= span_min && u <= span_max;
  }

  double normal_speed() const { return dot(normal, wall.velocity); }
  // c(t): where the plane lies along its normal at time t.
  double position(double t) const {
    const double u = normal_speed();
    double c = offset;
    if (u != 0.0) c += u * t;
    return wall.vibrates() ? c + wall.amplitude * std::sin(wall.angular_frequency * t + wall.phase)
                           : c;
  }
  // The surface's whole velocity at time t: sliding and normal, plus the vibration's along n.
  Vec<D> surface_velocity(double t) const {
    if (!wall.vibrates()) return wall.velocity;
    return wall.velocity + (wall.amplitude * wall.angular_frequency *
                            std::cos(wall.angular_frequency * t + wall.phase)) *
                               normal;
  }
  bool plane_moves() const { return normal_speed() != 0.0 || wall.vibrates(); }
};

// A plane n.x = offset of a wall or an outlet (`name` in messages): a finite unit normal, a
// finite point, and not across a periodic axis. Throws InputError.
template <int D>
void check_plane_placement(const Vec<D>& normal, double offset, const std::string& name,
                           const std::array<bool, D>& periodic);

template <int D>
class PlaneWalls {
 public:
  PlaneWalls() = default;
  // The planes, the box (its faces bound the domain too) and which of its faces are open
  // (particles may leave through them), the uniform acceleration particles feel.
  PlaneWalls(std::vector<PlaneWall<D>> planes, const Vec<D>& box,
             const std::array<Face<D>, 2 * D>& faces, const Vec<D>& gravity);

  // The model's side (model/environment.hpp): one plane's specification, the checks of the
  // planes against the box (periodic[a]: axis a is periodic), the event codes their surfaces
  // take (a strip's two edges and a hole's ring beside its plane), a plane's contact law.
  using Spec = PlaneWall<D>;
  static void check_specs(const std::vector<PlaneWall<D>>& planes,
                          const std::array<bool, D>& periodic);
  static std::size_t codes(const std::vector<PlaneWall<D>>& planes);
  static const ContactModel& contact_of(const PlaneWall<D>& p) { return p.wall.contact; }

  // The boundary interface (model/boundaries.hpp): surface s < planes() is plane s, then the
  // strips' edges (edges_, in the order of their planes, low end first), then the holes' rings
  // (rings_, in the order of their planes).
  bool any() const { return !planes_.empty(); }
  int surfaces() const { return planes() + edges_.surfaces() + rings_.surfaces(); }
  int planes() const { return static_cast<int>(planes_.size()); }
  // Surface s is a hole's ring (ring number s - first_ring()).
  int first_ring() const { return planes() + edges_.surfaces(); }
  bool is_ring(int s) const { return s >= first_ring(); }
  bool is_surface(int /*s*/) const { return true; }
  const PlaneWall<D>& plane(int s) const { return planes_[static_cast<std::size_t>(s)]; }
  std::string name(int s) const;
  const ContactModel& contact(int s) const {
    if (is_ring(s)) return rings_.contact(s - first_ring());
    return s < planes() ? plane(s).wall.contact : edges_.contact(s - planes());
  }
  double approach_speed(int s) const { return s < planes() ? plane(s).normal_speed() : 0.0; }

  // A strip is a plate with two faces: the distance from it on either side, and none beside it
  // (its foot outside it).
  double gap(int s, const Vec<D>& x, double t) const {
    if (is_ring(s)) return rings_.gap(s - first_ring(), x);
    if (s >= planes()) return edges_.gap(s - planes(), x, t);
    const double g = dot(plane(s).normal, x) - plane(s).position(t);
    if (!plane(s).plate()) return g;
    return plane(s).covers(x, g) ? std::abs(g) : kNever;
  }
  // A plate's normal points to the side x is on.
  Vec<D> normal(int s, const Vec<D>& x, double t) const {
    if (is_ring(s)) return rings_.normal(s - first_ring(), x);
    if (s >= planes()) return edges_.normal(s - planes(), x, t);
    const PlaneWall<D>& p = plane(s);
    return p.plate() && dot(p.normal, x) < p.offset ? -1.0 * p.normal : p.normal;
  }
  Vec<D> velocity(int s, const Vec<D>& /*x*/, double t) const {
    return s < planes() ? plane(s).surface_velocity(t) : Vec<D>{};
  }
  bool holds_still(int s) const {
    return s >= planes() || (!plane(s).wall.vibrates() && norm2(plane(s).wall.velocity) == 0.0);
  }
  bool surface_moves(int s) const { return s < planes() && plane(s).plane_moves(); }
  bool accelerates(int s) const { return s < planes() && plane(s).wall.vibrates(); }
  bool flat(int s) const { return s < planes(); }

  // Relative time from t of the contact of a particle of this radius (at x with velocity v at
  // t) with plane s; kNever if after t + horizon.
  double event_time(int s, const Vec<D>& x, const Vec<D>& v, double radius, double t,
                    double horizon) const;
  // Whether a particle in `cell` can touch plane s before it leaves the cell: the cell's nearest
  // point along the normal is within rmax (and the vibration's amplitude) of the plane; a plane
  // moving along its normal reaches every cell.
  bool reaches(int s, CellCode cell, const CellGrid<D>& grid) const;
  // A particle (velocity v, spin w, updated in place) meets plane s at time t: a partner of
  // infinite mass moving with its whole velocity.
  ContactResult<D> resolve(int s, const Vec<D>& x, double t, double mass, double radius,
                           double inertia_factor, bool force_elastic, Vec<D>& v, Spin<D>& w) const;
  // Throws InputError naming the particle and the plane it overlaps (round-off contacts, 1e-12
  // of the radius, are contacts).
  void check_start(const Vec<D>& x, double radius, double t, std::uint64_t id) const;

  // Set-up: the particles' largest radius (the cells' reach) and when a plane moving into the
  // domain leaves no room for one particle between it and the far side of the box.
  void prepare(const CellGrid<D>& grid, double rmax, double particle_volume, bool uniform);
  double squeeze_time() const { return squeeze_time_; }
  [[noreturn]] void throw_squeezed(double t, double dmax, bool uniform) const;

 private:
  // A strip's contact: with either face of the plate, where its foot lies within the strip (a
  // still plane); side +1 the front (n), -1 the back.
  double strip_event_time(const PlaneWall<D>& p, const Vec<D>& x, const Vec<D>& v, double radius,
                          double horizon) const;
  double face_event_time(const PlaneWall<D>& p, double side, const Vec<D>& x, const Vec<D>& v,
                         double radius, double horizon) const;
  // How far (in radii) a particle may sit inside a strip's face by round-off and still be in
  // front of it.
  static constexpr double kStripRoundOff = 1e-9;

  std::vector<PlaneWall<D>> planes_;
  CylinderWalls<D> edges_;  // the strips' ends: outside cylinders of radius 0
  std::vector<std::string> edge_names_;
  RingEdges<D> rings_;            // the holes' edges
  std::vector<int> ring_planes_;  // the plane of each ring
  Vec<D> box_{};
  std::array<Face<D>, 2 * D> faces_{};
  Vec<D> gravity_{};
  double rmax_ = 0.0;
  double squeeze_time_ = kNever;
  int squeeze_plane_ = -1;
};

}  // namespace kairos
