// The walls on the faces of the box, as the event engine meets them: the first boundary
// component (docs/extending.md, "A boundary geometry").
//
// It owns what the walls are and the rules of meeting them: when a particle (position x and
// velocity v at time t, under the uniform field) first touches a wall's plane, which layers of
// cells a wall can reach, the contact's response with its energy split, whether a start state
// overlaps a wall, and when approaching walls leave no room for the particles. It keeps no
// per-particle state. A wall of infinite mass has its plane as a function of the time
// (boundaries/face_wall.hpp) and adds nothing to restart files; a wall with mass (a free
// piston, boundaries/wall_body.hpp) keeps its motion here, which the engine sets at each of
// its contacts (push) and exports for restarts (motion). The engine calls it and it never
// calls back.
//
// Conventions: face 2k is the low face of axis k, 2k + 1 the high one; normals point into the
// box; the particle's relative time to an event is returned (kNever: none before the horizon).
#pragma once

#include <array>
#include <string>
#include <utility>
#include <vector>

#include "boundaries/face_wall.hpp"
#include "boundaries/wall_body.hpp"
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
    if (massive(f)) [[unlikely]] {
      Vec<D> v{};
      v[f / 2] = body(f).speed_at(t);
      return v;
    }
    return faces_[f].wall.surface_velocity(f, t);
  }
  bool holds_still(int f) const {
    const Wall<D>& w = faces_[f].wall;
    return !w.vibrates() && norm2(w.velocity) == 0.0 && !w.massive();
  }
  bool surface_moves(int f) const { return faces_[f].wall.plane_moves(f); }
  // Its velocity changes (a vibration; a wall with mass, pushed by the particles).
  bool accelerates(int f) const { return faces_[f].wall.vibrates() || massive(f); }
  bool flat(int /*f*/) const { return true; }
  std::string name(int f) const { return std::string{"xyz"[f / 2], f % 2 == 0 ? '-' : '+'}; }
  const ContactModel& contact(int f) const { return faces_[f].wall.contact; }
  // The speed at which wall f's plane moves into the box (its vibration aside).
  double approach_speed(int f) const {
    return (f % 2 == 0 ? 1.0 : -1.0) * faces_[f].wall.velocity[f / 2];
  }

  // Where the plane of wall f lies along its axis at time t.
  double position(int f, double t) const {
    if (massive(f)) [[unlikely]]
      return body(f).position_at(t) + shift(f);
    return faces_[f].wall.plane_position(f, box_, t);
  }
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
  // the cell is within reach of it (a piston, moving along its normal, reaches every layer; a
  // wall with mass the layers of its band, while its plane stays in its layer of cells).
  bool reaches(int f, CellCode c, const CellGrid<D>& grid) const;

  // A particle (velocity v, spin w, updated in place) meets wall f at time t: the wall is a
  // partner of infinite mass moving with its whole velocity (sliding, normal, vibrating), so
  // restitution acts on the normal velocity relative to the wall.
  ContactResult<D> resolve(int f, const Vec<D>& x, double t, double mass, double radius,
                           double inertia_factor, bool force_elastic, Vec<D>& v, Spin<D>& w) const;

  // Walls with mass (boundaries/wall_body.hpp).
  bool any_massive() const { return any_massive_; }
  bool massive(int f) const { return faces_[f].wall.massive(); }
  // The body that moves wall f: its own, or for the high wall of a container (Wall::joined)
  // the low wall's, whose plane lies the box's edge below it (shift).
  const WallBody& body(int f) const { return bodies_[body_index(f)]; }
  // The version a wall event predicted now carries (0 for a wall of infinite mass): the event
  // is stale once the wall's motion has changed.
  std::uint32_t event_version(int f) const { return massive(f) ? body(f).version : 0u; }
  // Sets the walls' motion from a state at time t (`motion` empty: each wall with mass at rest
  // on its face). Throws InputError for a motion of a face without mass, or one that is not
  // finite. Call after prepare(), or without it where there are no cells (the DEM: no layers).
  void restore(const std::vector<WallMotion>& motion, double t);
  std::vector<WallMotion> motion() const;
  // The impulse a contact gave the particle (ContactResult::impulse) at time t moves wall f
  // (and the other wall of a container with it).
  void push(int f, double t, const Vec<D>& impulse_on_particle);
  // An impulse along its axis on wall f's body at time t, without the layers' bookkeeping of
  // push: for the DEM, which has no cells and kicks the walls with the contacts' forces at
  // every time step (dem/dem_integrator.hpp).
  void kick(int f, double t, double impulse_along_axis) {
    bodies_[body_index(f)].kick(t, impulse_along_axis);
  }
  // visit(s) for each wall whose plane a push on wall f may have brought nearer the particles
  // at some later time, so that particles near it must be looked at again: none for a free
  // lid (the push moves it away at every later time), the wall itself on a spring (which
  // brings it back), the other wall of a container.
  template <class F>
  void for_each_disturbed(int f, F&& visit) const {
    if (body(f).sprung()) visit(f);
    if (faces_[f].wall.joined) visit(f ^ 1);
  }
  // When the plane of a wall with mass next leaves its layer of cells (kNever if none has
  // mass), and that change made (at that time t): returns the face, or -1 if the time was only
  // the horizon of a spring's search (searched again from there). The outer layers extend
  // to infinity: a lid the particles push out of the box moves on in the outermost layer.
  double next_layer_change() const { return next_change_; }
  int change_layer(double t);
  // The layers of cells along wall f's axis (first, last) holding every particle that can
  // touch it while its plane stays in its layer (the cells reaches() accepts), and visit(cell
  // index) for each of their cells.
  std::pair<int, int> band(int f) const;
  template <class F>
  void for_each_band_cell(int f, const CellGrid<D>& grid, F&& visit) const {
    const int axis = f / 2;
    const auto [first, last] = band(f);
    std::array<int, D> lo{}, hi{};
    for (int a = 0; a < D; ++a) {
      lo[a] = a == axis ? first : 0;
      hi[a] = a == axis ? last : grid.cells_along(a) - 1;
    }
    std::array<int, D> c = lo;
    while (true) {
      visit(grid.index(grid.code_at(c)));
      int a = 0;
      while (a < D && ++c[a] > hi[a]) c[a] = lo[a], ++a;
      if (a == D) return;
    }
  }
  // What the outputs show of each wall with mass at time t (WallReading), faces in order; a
  // container once, named by its axis ("z"), at its low wall's place.
  std::vector<WallReading> readings(double t) const;
  // The mechanical energy of wall f with mass: M v^2 / 2 less the work of its constant force
  // and the field since it rested on its face (plus its spring's energy). A container's is
  // counted at its low wall (0 at the high one), so that the surfaces' energies add up.
  double energy(int f, double t) const {
    if (faces_[f].wall.joined && f % 2 == 1) return 0.0;
    return body(f).energy_at(t);
  }

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
  // Walls with mass: their motion, the layer of cells their plane is in, the grid's widths and
  // cells along each axis (set_reach), the next layer change.
  bool any_massive_ = false;
  std::array<WallBody, 2 * D> bodies_{};
  std::array<int, 2 * D> layer_{};
  Vec<D> widths_{};
  std::array<int, D> cells_along_{};
  double next_change_ = kNever;
  int next_change_face_ = -1;
  bool next_change_recheck_ = false;  // the due "change" only renews a spring's search
  double rest_position(int f) const { return f % 2 == 0 ? 0.0 : box_[f / 2]; }
  bool own_body(int f) const { return !faces_[f].wall.joined || f % 2 == 0; }
  int body_index(int f) const { return own_body(f) ? f : f - 1; }
  double shift(int f) const { return own_body(f) ? 0.0 : box_[f / 2]; }
  int layer_of(int f, double x) const;
  // Sets next_change_ from time t (the bodies' motion and layers).
  void find_next_change(double t);
};

}  // namespace kairos
