// A wall on a face of the box: what it is made of and how its plane moves. The one place the
// wall's kinematics is written; the event engine (boundaries/face_walls.hpp), the DEM and the
// outputs read it from here.
//
// Face 2k is the low face of axis k, 2k + 1 the high one. A wall at the low face of axis k is
// the plane x_k = u_k t + A sin(w t + phi) with normal +e_k, one at the high face the plane
// x_k = L_k + u_k t + A sin(w t + phi) with normal -e_k (u_k = A = 0: fixed), where u is the
// wall's velocity and t the absolute simulation time: the plane is a function of the state's
// time alone, so restarts need nothing more.
#pragma once

#include <cmath>
#include <limits>
#include <string>

#include "boundaries/wall_spring.hpp"
#include "core/error.hpp"
#include "core/vec.hpp"
#include "interactions/granular_contact.hpp"

namespace kairos {

enum class FaceKind { kPeriodic, kWall, kOpen };

template <int D>
struct Wall {
  ContactModel contact;  // restitution and roughness of particle-wall collisions
  // Velocity of the wall: the components in its plane slide it (a shear plate), the one along
  // its normal moves the plane at that constant speed (a piston).
  Vec<D> velocity{};
  double amplitude = 0.0;          // vibration along the normal: offset A sin(w t + phi)
  double angular_frequency = 0.0;  // w
  double phase = 0.0;              // phi
  // A wall with mass (a free piston, boundaries/wall_body.hpp; face walls only): its plane
  // moves along its axis under the impulses of the particles it meets, the constant `force`
  // along its normal (into the box) and the field. 0: a wall of infinite mass that moves as
  // prescribed above. Its plane is then state, not a function of the time: plane_position
  // below does not describe it (FaceWalls::position does).
  double mass = 0.0;
  double force = 0.0;
  // A wall with mass tied to a moving anchor by a spring and a dashpot (boundaries/
  // wall_spring.hpp), and whether it is joined to the wall on the other face of its axis as
  // one body, a container (both then have the same mass and spring).
  WallSpring spring{};
  bool joined = false;
  bool vibrates() const { return amplitude > 0.0 && angular_frequency > 0.0; }
  bool massive() const { return mass > 0.0; }
  // What pushes a wall with mass at `face` into the box: its force plus its weight along its
  // normal (the field g on M). At rest on average it holds the particles at this over its area.
  double inward_push(int face, const Vec<D>& gravity) const {
    return force + (face % 2 == 0 ? 1.0 : -1.0) * mass * gravity[face / 2];
  }
  // Whether the plane moves (a normal velocity, a vibration, or a mass) as the wall of `face`.
  bool plane_moves(int face) const { return velocity[face / 2] != 0.0 || vibrates() || massive(); }

  // Where the plane of the wall at `face` lies along its axis at time t, in a box of edges
  // `box` (the header's formula).
  double plane_position(int face, const Vec<D>& box, double t) const {
    double x = face % 2 == 0 ? 0.0 : box[face / 2];
    if (velocity[face / 2] != 0.0) x += velocity[face / 2] * t;
    return vibrates() ? x + amplitude * std::sin(angular_frequency * t + phase) : x;
  }
  // The plane's velocity along its axis at time t: u_k plus the vibration's.
  double plane_speed(int face, double t) const {
    const double u = velocity[face / 2];
    return vibrates() ? u + amplitude * angular_frequency * std::cos(angular_frequency * t + phase)
                      : u;
  }
  // The wall's whole velocity at time t (sliding, along the normal, vibrating).
  Vec<D> surface_velocity(int face, double t) const {
    Vec<D> v = velocity;
    if (vibrates())
      v[face / 2] += amplitude * angular_frequency * std::cos(angular_frequency * t + phase);
    return v;
  }
};

template <int D>
struct Face {
  FaceKind kind = FaceKind::kPeriodic;
  Wall<D> wall;  // used when kind == kWall
};

// A particle (velocity v, spin w, updated in place) meets a surface with unit normal n
// (towards the particle) moving at wall_velocity at the contact: every geometry's response
// (resolve_wall_contact with the surface's law). The surface has infinite mass unless given
// `wall_mass` (a wall with mass recoils along n).
template <int D>
ContactResult<D> resolve_surface_contact(
    const ContactModel& law, const Vec<D>& normal, const Vec<D>& wall_velocity, double mass,
    double radius, double inertia_factor, bool force_elastic, Vec<D>& v, Spin<D>& w,
    double wall_mass = std::numeric_limits<double>::infinity()) {
  WallContactInput<D> in;
  in.normal = normal;
  in.wall_velocity = wall_velocity;
  in.mass = mass;
  in.wall_mass = wall_mass;
  in.radius = radius;
  in.inertia_factor = inertia_factor;
  in.force_elastic = force_elastic;
  return resolve_wall_contact(law, in, v, w);
}

// The unit normal of a face's wall, into the box.
template <int D>
Vec<D> face_normal(int face) {
  Vec<D> n{};
  n[face / 2] = face % 2 == 0 ? 1.0 : -1.0;
  return n;
}

// The distance of a point (a particle's centre) from the plane of a face's wall at `plane`,
// positive inside the box.
inline double face_gap(int face, double x, double plane) {
  return face % 2 == 0 ? x - plane : plane - x;
}

// A wall's motion keys as the model takes them (a face wall's or a plane's, `name` in
// messages): finite, a vibration's amplitude and frequency not negative, a force only on a wall
// with mass and no motion of its own on one. Throws InputError.
template <int D>
void check_wall_motion(const Wall<D>& w, const std::string& name) {
  for (int a = 0; a < D; ++a) {
    if (!std::isfinite(w.velocity[a])) throw InputError(name + ": velocity must be finite");
  }
  if (!(w.amplitude >= 0.0) || !std::isfinite(w.amplitude)) {
    throw InputError(name + ": amplitude must be finite and >= 0");
  }
  if (!(w.angular_frequency >= 0.0) || !std::isfinite(w.angular_frequency) ||
      !std::isfinite(w.phase)) {
    throw InputError(name + ": frequency must be finite and >= 0 and the phase finite");
  }
  if (!(w.mass >= 0.0) || !std::isfinite(w.mass) || !std::isfinite(w.force))
    throw InputError(name + ": mass must be finite and >= 0 and the force finite");
  if (w.mass == 0.0 && w.force != 0.0)
    throw InputError(name + ": a force moves only a wall with mass");
  if (w.mass > 0.0 && (w.vibrates() || norm2(w.velocity) != 0.0))
    throw InputError(name +
                     ": a wall with mass moves as the impulses it takes say (no velocity "
                     "or vibration of its own)");
}

}  // namespace kairos
