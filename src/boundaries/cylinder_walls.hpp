// Cylinder and sphere walls ([[boundary.cylinder]], [[boundary.sphere]]): the third and fourth
// boundary components (docs/extending.md, "Adding a boundary geometry"), one implementation
// (RoundWalls) for both. A cylinder of radius R_c about an axis along a box axis (in 2D a circle
// in the plane), or a sphere of radius R_c, holds the particles inside it (a drum, a silo, a
// spherical container) or outside it (an obstacle), fixed or rotating about an axis at angular
// velocity omega (a rotating drum: its surface moves at omega e x (p - c), which a rough or
// frictional contact feels). A cylinder runs along its whole axis: through a periodic axis, or
// between the walls or planes that close it.
//
// Distances are measured from the centre c: for a sphere r(x) = x - c, for a cylinder the same
// less its component along the axis. Inside, the gap is R_c - |r| and the normal into the domain
// points to the centre (axis); outside, the gap is |r| - R_c and the normal points away. Under a
// field a particle's |r(t)|^2 is a quartic in t, solved by the certified search of
// dynamics/trajectory_events (quartic_event_time); along a cylinder's axis the field does not
// matter. Like the planes they are functions of the time alone: nothing in restart files.
#pragma once

#include <array>
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

enum class RoundShape { kCylinder, kSphere };

template <int D>
struct CylinderWall {
  // The axis's direction (3D: 0, 1 or 2; 2D: the circle's, out of the plane); a sphere's
  // rotation axis.
  int axis = D - 1;
  Vec<D> center{};  // a point of the axis (its component along the axis does not matter), or a
                    // sphere's centre
  RoundShape shape = RoundShape::kCylinder;
  double radius = 1.0;
  bool inside = true;             // the particles are inside it
  double angular_velocity = 0.0;  // about the axis, right-handed (2D: counter-clockwise)
  ContactModel contact;           // its contact law

  // A vector measured from the centre (the axis): for a cylinder its component along the axis
  // dropped.
  Vec<D> across(Vec<D> r) const {
    if constexpr (D == 3)
      if (shape == RoundShape::kCylinder) r[axis] = 0.0;
    return r;
  }
};

template <int D, RoundShape Shape>
class RoundWalls {
 public:
  RoundWalls() = default;
  // The cylinders (spheres) and the uniform acceleration the particles feel.
  RoundWalls(std::vector<CylinderWall<D>> walls, const Vec<D>& gravity)
      : cylinders_(std::move(walls)), gravity_(gravity) {
    for (CylinderWall<D>& c : cylinders_) c.shape = Shape;
  }
  // As every geometry of the registry is built (model/boundaries.hpp): the box's faces bound
  // nothing a round wall needs.
  RoundWalls(std::vector<CylinderWall<D>> walls, const Vec<D>& /*box*/,
             const std::array<Face<D>, 2 * D>& /*faces*/, const Vec<D>& gravity)
      : RoundWalls(std::move(walls), gravity) {}

  // The model's side (model/environment.hpp): one wall's specification, the checks against the
  // box (a box axis, a radius > 0, finite; no periodic axis across it: periodic[a]), one event
  // code each, its contact law.
  using Spec = CylinderWall<D>;
  static void check_specs(const std::vector<CylinderWall<D>>& walls,
                          const std::array<bool, D>& periodic);
  static std::size_t codes(const std::vector<CylinderWall<D>>& walls) { return walls.size(); }
  static const ContactModel& contact_of(const CylinderWall<D>& c) { return c.contact; }

  // The boundary interface (model/boundaries.hpp): surface s is cylinder (sphere) s.
  bool any() const { return !cylinders_.empty(); }
  int surfaces() const { return static_cast<int>(cylinders_.size()); }
  bool is_surface(int /*s*/) const { return true; }
  const CylinderWall<D>& cylinder(int s) const { return cylinders_[static_cast<std::size_t>(s)]; }
  std::string name(int s) const {
    return (Shape == RoundShape::kSphere ? "boundary.sphere[" : "boundary.cylinder[") +
           std::to_string(s) + "]";
  }
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
  // Whether a particle in `cell` can touch surface s before it leaves the cell: the cell's
  // farthest point (inside) or nearest point (outside) from the centre (across the axis) is
  // within the largest radius of the surface.
  bool reaches(int s, CellCode cell, const CellGrid<D>& grid) const;
  ContactResult<D> resolve(int s, const Vec<D>& x, double t, double mass, double radius,
                           double inertia_factor, bool force_elastic, Vec<D>& v, Spin<D>& w) const;
  // Throws InputError naming the particle and the surface it overlaps.
  void check_start(const Vec<D>& x, double radius, double t, std::uint64_t id) const;

  void prepare(const CellGrid<D>& /*grid*/, double rmax, double /*particle_volume*/,
               bool /*uniform*/) {
    rmax_ = rmax;
  }
  // It does not move: it never leaves the particles no room.
  double squeeze_time() const { return kNever; }
  [[noreturn]] void throw_squeezed(double t, double dmax, bool uniform) const;

 private:
  Vec<D> velocity_at(int s, const Vec<D>& n) const;

  std::vector<CylinderWall<D>> cylinders_;
  Vec<D> gravity_{};
  double rmax_ = 0.0;
};

template <int D>
using CylinderWalls = RoundWalls<D, RoundShape::kCylinder>;
template <int D>
using SphereWalls = RoundWalls<D, RoundShape::kSphere>;

}  // namespace kairos
