// The edges of circular holes in plane walls ([[boundary.plane]] hole_radius: the orifice of a
// 3D silo or hopper): rings, each the circle of radius R about the plane's normal through the
// hole's centre, met as a curved edge of zero thickness. A particle of radius a touches the ring
// when its centre comes within a of the circle: its distance from the circle is
// sqrt((rho - R)^2 + z^2), rho its distance from the hole's axis and z its height above the
// plane. Under a field the contact time is a root of a degree-8 polynomial
// (dynamics/trajectory_events ring_contact_time), found by the certified search; the response
// is a wall collision along the normal from the circle's nearest point to the centre (a still
// edge of infinite mass). PlaneWalls owns them, numbered after its planes and strip edges
// (docs/physics.md#circular-holes). 3D only: in 2D a hole in a line is two strips.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/vec.hpp"
#include "dynamics/collision_time.hpp"
#include "interactions/granular_contact.hpp"
#include "scheduler/cell_grid.hpp"

namespace kairos {

template <int D>
struct RingEdge {
  Vec<D> center{};  // the hole's centre, on its plane
  Vec<D> axis{};    // the plane's unit normal
  double radius = 0.0;
  ContactModel contact;  // the plane's contact law
};

template <int D>
class RingEdges {
 public:
  RingEdges() = default;
  RingEdges(std::vector<RingEdge<D>> rings, const Vec<D>& gravity)
      : rings_(std::move(rings)), gravity_(gravity) {}

  int surfaces() const { return static_cast<int>(rings_.size()); }
  const RingEdge<D>& ring(int s) const { return rings_[static_cast<std::size_t>(s)]; }
  const ContactModel& contact(int s) const { return ring(s).contact; }
  // The distance of x from the circle where x lies over the hole (its distance from the axis
  // at most R; beside the hole the plate's face is nearer: kNever), and the unit vector from the
  // circle's nearest point to x.
  double gap(int s, const Vec<D>& x) const;
  Vec<D> normal(int s, const Vec<D>& x) const;
  // Relative time of the contact of a particle (at x, velocity v, under the field) of this
  // radius with ring s; kNever if after the horizon.
  double event_time(int s, const Vec<D>& x, const Vec<D>& v, double radius, double horizon) const;
  // Whether a particle in `cell` can touch ring s before it leaves the cell: the cell's box is
  // within rmax of the ring's bounding box.
  bool reaches(int s, CellCode cell, const CellGrid<D>& grid, double rmax) const;
  ContactResult<D> resolve(int s, const Vec<D>& x, double mass, double radius,
                           double inertia_factor, bool force_elastic, Vec<D>& v, Spin<D>& w) const;

 private:
  std::vector<RingEdge<D>> rings_;
  Vec<D> gravity_{};
};

}  // namespace kairos
