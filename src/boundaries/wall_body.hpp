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

#include <cstdint>
#include <string>

#include "core/particle_system.hpp"

namespace kairos {

struct WallBody {
  double mass = 0.0;
  double accel = 0.0;         // along the axis, constant
  double time = 0.0;          // when position and speed were last set
  double position = 0.0;      // of the plane along the axis, at `time`
  double speed = 0.0;         // along the axis, at `time`
  std::uint32_t version = 0;  // bumped whenever the motion changes

  double position_at(double t) const {
    const double dt = t - time;
    return position + speed * dt + 0.5 * accel * dt * dt;
  }
  double speed_at(double t) const { return speed + accel * (t - time); }
  // Its mechanical energy at time t, the constant force's potential counted from `reference`
  // (a position along the axis): M v^2 / 2 - M a (x - reference). Constant between contacts.
  double energy_at(double t, double reference) const {
    const double v = speed_at(t);
    return 0.5 * mass * v * v - mass * accel * (position_at(t) - reference);
  }
  // A particle's impulse on the wall, along the axis, at time t.
  void kick(double t, double impulse) {
    const double v = speed_at(t);
    position = position_at(t);
    speed = v + impulse / mass;
    time = t;
    ++version;
  }
  WallMotion state(int face, int layer) const {
    return {static_cast<std::uint32_t>(face), time, position, speed, version, accel, layer};
  }
};

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
  double pressure = 0.0;
};

}  // namespace kairos
