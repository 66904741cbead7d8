// The worked example of docs/extending.md, "Adding a boundary geometry": fixed planes at any
// position and orientation, n.x = offset with n the unit normal into the domain. Test-only: it
// shows (and tests/boundaries/test_boundary_set.cpp checks) that a geometry is one class with
// the boundary interface, plugged into a BoundarySet beside the face walls.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "dynamics/collision_time.hpp"
#include "dynamics/trajectory_events.hpp"
#include "interactions/granular_contact.hpp"
#include "scheduler/cell_grid.hpp"

namespace kairos {

template <int D>
class PlaneWalls {
 public:
  struct Plane {
    Vec<D> normal;  // unit, into the domain
    double offset;  // the plane is normal . x = offset
    ContactModel contact;
  };
  PlaneWalls(std::vector<Plane> planes, const Vec<D>& gravity)
      : planes_(std::move(planes)), gravity_(gravity) {}
  bool any() const { return !planes_.empty(); }
  int surfaces() const { return static_cast<int>(planes_.size()); }
  bool is_surface(int) const { return true; }
  double gap(int s, const Vec<D>& x, double) const {
    return dot(planes_[s].normal, x) - planes_[s].offset;
  }
  Vec<D> normal(int s, const Vec<D>&, double) const { return planes_[s].normal; }
  Vec<D> velocity(int, const Vec<D>&, double) const { return {}; }
  bool holds_still(int) const { return true; }
  bool surface_moves(int) const { return false; }
  bool accelerates(int) const { return false; }
  // Along the normal the particle moves as height n.x - R, speed n.v, acceleration n.g: the
  // fixed-plane quadratic of dynamics/trajectory_events.
  double event_time(int s, const Vec<D>& x, const Vec<D>& v, double radius, double,
                    double horizon) const {
    const Plane& p = planes_[s];
    const NormalMotion m{dot(p.normal, x) - radius, dot(p.normal, v), dot(p.normal, gravity_)};
    return moving_plane_event_time(m, p.offset, 0.0, horizon);
  }
  std::pair<double, int> next_contact(const Vec<D>& x, const Vec<D>& v, double radius, CellCode,
                                      const CellGrid<D>&, double t, double horizon) const {
    std::pair<double, int> best{horizon, -1};  // no filter by cells: every plane is tested
    for (int s = 0; s < surfaces(); ++s) {
      const double dt = event_time(s, x, v, radius, t, best.first);
      if (dt < best.first) best = {dt, s};
    }
    return best;
  }
  ContactResult<D> resolve(int s, double, double mass, double radius, double inertia_factor,
                           bool force_elastic, Vec<D>& v, Spin<D>& w) const {
    WallContactInput<D> in;
    in.normal = planes_[s].normal;  // a fixed plane: wall_velocity stays 0
    in.mass = mass;
    in.radius = radius;
    in.inertia_factor = inertia_factor;
    in.force_elastic = force_elastic;
    return resolve_wall_contact(planes_[s].contact, in, v, w);
  }
  bool overlaps(const Vec<D>& x, double radius, double t) const {
    for (int s = 0; s < surfaces(); ++s)
      if (gap(s, x, t) < radius) return true;
    return false;
  }
  void check_start(const Vec<D>& x, double radius, double t, std::uint64_t id) const {
    for (int s = 0; s < surfaces(); ++s)
      if (gap(s, x, t) < radius * (1.0 - 1e-12))
        throw InputError("particle " + std::to_string(id) + " overlaps plane " + std::to_string(s));
  }
  double squeeze_time() const { return kNever; }
  [[noreturn]] void throw_squeezed(double, double, bool) const {
    throw std::logic_error("fixed planes never leave no room");
  }
  void prepare(const CellGrid<D>&, double, double, bool) {}  // every plane is tested anywhere

 private:
  std::vector<Plane> planes_;
  Vec<D> gravity_{};
};

}  // namespace kairos
