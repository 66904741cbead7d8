// Cylinder walls ([[boundary.cylinder]]): the third boundary component (docs/extending.md,
// "Adding a boundary geometry"). A cylinder of radius R_c about an axis along a box axis (in 2D a
// circle in the plane), holding the particles inside it (a drum, a silo) or outside it (an
// obstacle), fixed or rotating about its axis at angular velocity omega (a rotating drum: its
// surface moves at omega x (p - c), which a rough or frictional contact feels). It runs along
// its whole axis: through a periodic axis, or between the walls or planes that close it.
//
// Distances are measured in the plane across the axis: r_perp(x) = x - c less its component along
// the axis. Inside, the gap is R_c - |r_perp| and the normal into the domain points to the axis;
// outside, the gap is |r_perp| - R_c and the normal points away from it. Under a field across
// the axis a particle's |r_perp(t)|^2 is a quartic in t, solved by the certified search of
// dynamics/trajectory_events (quartic_event_time); along the axis the field does not matter.
// Like the planes it is a function of the time alone: nothing in restart files.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "boundaries/face_wall.hpp"
#include "core/vec.hpp"
#include "dynamics/collision_time.hpp"
#include "interactions/granular_contact.hpp"
#include "scheduler/cell_grid.hpp"

namespace kairos {

template <int D>
struct CylinderWall {
  int axis = D - 1;  // the axis's direction (3D: 0, 1 or 2; 2D: the circle's, out of the plane)
  Vec<D> center{};   // a point of the axis (its component along the axis does not matter)
  double radius = 1.0;
  bool inside = true;             // the particles are inside it
  double angular_velocity = 0.0;  // about the axis, right-handed (2D: counter-clockwise)
  ContactModel contact;           // its contact law

  // The centre's offset from the axis, across it.
  Vec<D> across(const Vec<D>& x) const {
    Vec<D> r = x - center;
    if constexpr (D == 3) r[axis] = 0.0;
    return r;
  }
};

template <int D>
class CylinderWalls {
 public:
  CylinderWalls() = default;
  // The cylinders and the uniform acceleration the particles feel.
  CylinderWalls(std::vector<CylinderWall<D>> cylinders, const Vec<D>& gravity)
      : cylinders_(std::move(cylinders)), gravity_(gravity) {}

  // The boundary interface (model/boundaries.hpp): surface s is cylinder s.
  bool any() const { return !cylinders_.empty(); }
  int surfaces() const { return static_cast<int>(cylinders_.size()); }
  bool is_surface(int /*s*/) const { return true; }
  const CylinderWall<D>& cylinder(int s) const { return cylinders_[static_cast<std::size_t>(s)]; }
  std::string name(int s) const { return "boundary.cylinder[" + std::to_string(s) + "]"; }
  const ContactModel& contact(int s) const { return cylinder(s).contact; }
  double approach_speed(int /*s*/) const { return 0.0; }
  bool flat(int /*s*/) const { return false; }

  double gap(int s, const Vec<D>& x, double t) const;
  Vec<D> normal(int s, const Vec<D>& x, double t) const;
  // The surface's velocity at the point of it nearest to x (its rotation).
  Vec<D> velocity(int s, const Vec<D>& x, double t) const;
  bool holds_still(int s) const { return cylinder(s).angular_velocity == 0.0; }
  bool surface_moves(int /*s*/) const { return false; }  // it turns in itself
  bool accelerates(int /*s*/) const { return false; }

  double event_time(int s, const Vec<D>& x, const Vec<D>& v, double radius, double t,
                    double horizon) const;
  // Whether a particle in `cell` can touch cylinder s before it leaves the cell: across the
  // axis, the cell's farthest point (inside) or nearest point (outside) is within the largest
  // radius of the surface.
  bool reaches(int s, CellCode cell, const CellGrid<D>& grid) const;
  ContactResult<D> resolve(int s, const Vec<D>& x, double t, double mass, double radius,
                           double inertia_factor, bool force_elastic, Vec<D>& v, Spin<D>& w) const;
  bool overlaps(const Vec<D>& x, double radius, double t, int skip = -1) const;
  // Throws InputError naming the particle and the cylinder it overlaps.
  void check_start(const Vec<D>& x, double radius, double t, std::uint64_t id) const;

  void prepare(const CellGrid<D>& /*grid*/, double rmax, double /*particle_volume*/,
               bool /*uniform*/) {
    rmax_ = rmax;
  }
  // A cylinder does not move: it never leaves the particles no room.
  double squeeze_time() const { return kNever; }
  [[noreturn]] void throw_squeezed(double t, double dmax, bool uniform) const;

 private:
  std::vector<CylinderWall<D>> cylinders_;
  Vec<D> gravity_{};
  double rmax_ = 0.0;
};

}  // namespace kairos
