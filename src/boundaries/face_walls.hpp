// The walls on the faces of the box, as the event engine meets them: the first boundary
// component (docs/extending.md, "A boundary geometry").
//
// It owns what the walls are and the rules of meeting them: when a particle (position x and
// velocity v at time t, under the uniform field) first touches a wall's plane, which layers of
// cells a wall can reach, the contact's response with its energy split, whether a start state
// overlaps a wall, and when approaching walls leave no room for the particles. It keeps no
// per-particle state: a wall's plane is a function of the time (boundaries/face_wall.hpp), so
// it adds nothing to restart files. The engine calls it and it never calls back.
//
// Conventions: face 2k is the low face of axis k, 2k + 1 the high one; normals point into the
// box; the particle's relative time to an event is returned (kNever: none before the horizon).
#pragma once

#include <array>
#include <string>
#include <utility>

#include "boundaries/face_wall.hpp"
#include "core/vec.hpp"
#include "dynamics/collision_time.hpp"
#include "interactions/granular_contact.hpp"
#include "scheduler/cell_grid.hpp"

namespace kairos {

// The energy a wall gave a particle in a contact: its work (the kinetic energy change plus
// what was dissipated).
template <int D>
double work_on_particle(const ContactResult<D>& r) {
  return r.translational_energy_change + r.rotational_energy_change + r.dissipated;
}

template <int D>
class FaceWalls {
 public:
  FaceWalls() = default;
  // The faces (only kWall ones are walls), the box and the uniform acceleration particles feel.
  FaceWalls(const std::array<Face<D>, 2 * D>& faces, const Vec<D>& box, const Vec<D>& gravity);

  bool any() const { return any_; }
  bool is_wall(int f) const { return faces_[f].kind == FaceKind::kWall; }
  const Wall<D>& wall(int f) const { return faces_[f].wall; }

  // The boundary interface (model/boundaries.hpp): the surfaces are the 2D faces, a
  // surface exists where the face is a wall.
  static constexpr int surfaces() { return 2 * D; }
  bool is_surface(int f) const { return is_wall(f); }
  Vec<D> normal(int f, const Vec<D>& /*x*/, double /*t*/) const { return face_normal<D>(f); }
  Vec<D> velocity(int f, const Vec<D>& /*x*/, double t) const {
    return faces_[f].wall.surface_velocity(f, t);
  }
  bool holds_still(int f) const {
    const Wall<D>& w = faces_[f].wall;
    return !w.vibrates() && norm2(w.velocity) == 0.0;
  }
  bool surface_moves(int f) const { return faces_[f].wall.plane_moves(f); }
  bool accelerates(int f) const { return faces_[f].wall.vibrates(); }
  bool flat(int /*f*/) const { return true; }
  std::string name(int f) const { return std::string{"xyz"[f / 2], f % 2 == 0 ? '-' : '+'}; }
  const ContactModel& contact(int f) const { return faces_[f].wall.contact; }
  // The speed at which wall f's plane moves into the box (its vibration aside).
  double approach_speed(int f) const {
    return (f % 2 == 0 ? 1.0 : -1.0) * faces_[f].wall.velocity[f / 2];
  }

  // Where the plane of wall f lies along its axis at time t.
  double position(int f, double t) const { return faces_[f].wall.plane_position(f, box_, t); }
  // The centre's distance from the plane of wall f at time t, positive inside the box.
  double gap(int f, const Vec<D>& x, double t) const {
    return face_gap(f, x[f / 2], position(f, t));
  }
  // Relative time from t of the contact of a particle of this radius (at x with velocity v at
  // t) with the plane of wall f; kNever if after t + horizon.
  double event_time(int f, const Vec<D>& x, const Vec<D>& v, double radius, double t,
                    double horizon) const;

  // The layers of cells next to each face that a fixed or vibrating wall can reach (the
  // particle's centre within its radius of the plane, which moves up to the amplitude into the
  // box), for cells of the grid's widths and particles up to rmax.
  void set_reach(const CellGrid<D>& grid, double rmax);
  // Whether a particle in cell c can touch face f before it leaves the cell: f has a wall, and
  // the cell is within reach of it (a piston, moving along its normal, reaches every layer).
  bool reaches(int f, CellCode c, const CellGrid<D>& grid) const;

  // A particle (velocity v, spin w, updated in place) meets wall f at time t: the wall is a
  // partner of infinite mass moving with its whole velocity (sliding, normal, vibrating), so
  // restitution acts on the normal velocity relative to the wall.
  ContactResult<D> resolve(int f, const Vec<D>& x, double t, double mass, double radius,
                           double inertia_factor, bool force_elastic, Vec<D>& v, Spin<D>& w) const;

  // A start state's particle `id` at x: throws InputError naming the particle and the wall it
  // overlaps (round-off contacts, 1e-12 of the radius, are contacts).
  void check_start(const Vec<D>& x, double radius, double t, std::uint64_t id) const;

  // The boundary interface's setup: the cells each wall reaches and the squeeze time, for
  // particles up to radius rmax, of total volume particle_volume, of `uniform` sizes.
  void prepare(const CellGrid<D>& grid, double rmax, double particle_volume, bool uniform) {
    set_reach(grid, rmax);
    find_squeeze_time(rmax, particle_volume, uniform);
  }
  // Walls approaching each other: the first time they leave no room for the particles (the
  // largest radius rmax, their total volume, `uniform` sizes), kNever if never.
  void find_squeeze_time(double rmax, double particle_volume, bool uniform);
  double squeeze_time() const { return squeeze_time_; }
  // The InputError of a run that reached the squeeze time (t), naming the walls.
  [[noreturn]] void throw_squeezed(double t, double dmax, bool uniform) const;

 private:
  std::array<Face<D>, 2 * D> faces_{};
  Vec<D> box_{};
  Vec<D> gravity_{};
  bool any_ = false;
  std::array<int, 2 * D> layers_{};  // see set_reach
  double squeeze_time_ = kNever;
  int squeeze_axis_ = -1;
  double squeeze_needed_ = 0.0;  // the room the particles need along squeeze_axis_
};

}  // namespace kairos
