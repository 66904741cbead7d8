// A wall with mass: the plane of a face wall (a free piston, a lid) whose motion along its axis
// follows from the impulses of the particles it meets, a constant force along its normal and
// the field (docs/physics.md#walls-with-mass).
//
// Between contacts the plane moves with the constant acceleration a = (F n_a + M g_a) / M along
// the axis (n_a = +1 at a low face, -1 at a high one), so a particle's contact with it solves a
// quadratic, as with a fixed plane. At a contact the particle's impulse J changes the wall's
// velocity by -J_a / M, and the wall's motion is set afresh from that instant: every wall event
// predicted before is stale (`version`); as the impulse pushes the wall away from the
// particles, no other contact comes earlier (docs/physics.md#walls-with-mass). The motion is
// part of the state (WallMotion in restart files): a continued run is bit-identical.
#pragma once

#include <cmath>
#include <cstdint>
#include <string>
#include <tuple>

#include "boundaries/wall_spring.hpp"
#include "core/particle_system.hpp"
#include "dynamics/trajectory_events.hpp"

namespace kairos {

struct WallBody {
  double mass = 0.0;
  double accel = 0.0;         // along the axis, constant: its force over M plus the field
  double rest = 0.0;          // its rest place along the axis (its face); displacements from it
  double time = 0.0;          // when position and speed were last set
  double position = 0.0;      // of the plane along the axis, at `time`
  double speed = 0.0;         // along the axis, at `time`
  std::uint32_t version = 0;  // bumped whenever the motion changes
  // On a spring (boundaries/wall_spring.hpp): its motion between kicks, the transient's
  // coefficients since `time`, and the anchor's work and the dashpot's dissipation up to `time`.
  SpringMotion spring{};
  double h0 = 0.0, b0 = 0.0;
  SpringWork work{};

  bool sprung() const { return spring.on(); }
  double position_at(double t) const {
    const double dt = t - time;
    if (sprung()) [[unlikely]]
      return rest + spring.steady(t) + spring.transient(h0, b0, dt);
    return position + speed * dt + 0.5 * accel * dt * dt;
  }
  double speed_at(double t) const {
    if (sprung()) [[unlikely]]
      return spring.steady_speed(t) + spring.transient_speed(h0, b0, t - time);
    return speed + accel * (t - time);
  }
  // Its mechanical energy at time t: M v^2 / 2 - M a X (+ k (X - anchor)^2 / 2 on a spring),
  // X = x - rest; on a spring it changes between contacts by drive - dashpot (work_at).
  double energy_at(double t) const {
    const double v = speed_at(t);
    const double x = position_at(t) - rest;
    if (sprung()) [[unlikely]]
      return spring.energy(x, v, t);
    return 0.5 * mass * v * v - mass * accel * x;
  }
  // The anchor's work and the dashpot's dissipation from the start up to time t.
  SpringWork work_at(double t) const {
    if (!sprung()) return work;
    const SpringWork flight = spring.flight_work(time, h0, b0, t);
    return {work.drive + flight.drive, work.dashpot + flight.dashpot};
  }
  // Sets the motion from (position, speed) at time t.
  void set(double t, double x, double v) {
    time = t;
    position = x;
    speed = v;
    if (sprung()) std::tie(h0, b0) = spring.transient_at(x - rest, v, t);
  }
  // A particle's impulse on the wall, along the axis, at time t.
  void kick(double t, double impulse) {
    const double v = speed_at(t);
    const double x = position_at(t);
    work = work_at(t);
    set(t, x, v + impulse / mass);
    ++version;
  }
  // Its plane, moved by `shift` along the axis (a container's high wall), along a face's normal
  // (sgn = +1 at a low face, -1 at a high one) from time t on, as the event solvers take it
  // (times relative to t). On a spring only.
  OscillatingPlane plane(double t, double sgn, double shift = 0.0) const {
    const auto [u, b] = spring.transient_coefficients(h0, b0, t - time);
    return {sgn * (rest + shift + spring.sag()),
            sgn * u,
            sgn * b,
            spring.gamma(),
            spring.wd(),
            sgn * spring.response(),
            spring.spring().omega,
            spring.response_phase_at(t)};
  }
  // Its state for a restart file; spring_of below reads the spring back from it.
  WallMotion state(int face, int layer) const {
    WallMotion m{static_cast<std::uint32_t>(face), time, position, speed, version, accel, layer};
    if (sprung()) {
      const WallSpring& k = spring.spring();
      m.spring = {mass, k.stiffness, k.damping, k.amplitude, k.omega, k.phase};
      m.drive_work = work.drive;
      m.dashpot = work.dashpot;
    }
    return m;
  }
};

// The spring a WallMotion of WallBody::state was made with (its mass is spring[0]).
inline WallSpring spring_of(const WallMotion& m) {
  return {m.spring[1], m.spring[2], m.spring[3], m.spring[4], m.spring[5]};
}

// What outputs read of a wall with mass at some time: its face's name ("z+"), where its plane
// is along its axis, its speed along the axis, its mechanical energy (FaceWalls::energy), its
// mass and force, and the pressure it holds the particles at on average (Wall::inward_push over
// its area).
struct WallReading {
  std::string face;
  double position = 0.0;
  double speed = 0.0;
  double energy = 0.0;
  double mass = 0.0;
  double force = 0.0;
  double pressure = 0.0;  // 0 for a container
  // On a spring: the anchor's work and the dashpot's dissipation since the start.
  bool sprung = false;
  bool container = false;
  double drive_work = 0.0;
  double dashpot = 0.0;
};

}  // namespace kairos
