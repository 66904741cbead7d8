// The config of a contact law and of a wall's motion: the keys every wall table shares
// ([[boundary.wall]], [[boundary.plane]], the surface tables of io/surface_tables.hpp).
#pragma once

#include <array>
#include <limits>
#include <string>
#include <vector>

namespace kairos {

// A contact law (particle-particle for a species pair, or particle-wall):
// docs/physics.md#granular-contacts.
struct ContactConfig {
  double restitution = 1.0;                    // e_n (constant), or e at restitution_speed
  std::string restitution_model = "constant";  // constant | viscoelastic | table
  double restitution_speed = 1.0;              // viscoelastic: e(restitution_speed) = restitution
  std::vector<std::array<double, 2>> restitution_table;       // table: (impact speed, e) pairs
  double tangential_restitution = -1.0;                       // beta in [-1, 1]; -1 smooth
  double friction = std::numeric_limits<double>::infinity();  // Coulomb mu (Walton); inf = no limit
  double elastic_below_speed = 0.0;                           // |g_n| below this: elastic (0 = off)

  bool operator==(const ContactConfig&) const = default;
};

// A wall on a box face ([[boundary.wall]]), and the motion keys a plane shares with it.
struct WallConfig {
  std::string face;              // x- x+ y- y+ z- z+
  ContactConfig contact;         // restitution etc. of particle-wall collisions
  std::vector<double> velocity;  // in-plane sliding velocity (D components), empty = at rest
  double amplitude = 0.0;        // vibration along the normal: A sin(2 pi f t + phase)
  double frequency = 0.0;        // f, cycles per unit time
  double phase = 0.0;            // radians
  double mass = 0.0;             // > 0: a wall with mass (a free piston; 0: infinite mass)
  double force = 0.0;            // on a wall with mass, along its normal (into the box)

  bool operator==(const WallConfig&) const = default;
};

// Whether a wall's keys move it (it slides, vibrates or has mass): not an equilibrium
// boundary (replica exchange, io/config_obstacles.hpp).
inline bool wall_moves(const WallConfig& w) {
  bool sliding = false;
  for (const double v : w.velocity) sliding = sliding || v != 0.0;
  return sliding || w.amplitude != 0.0 || w.mass != 0.0;
}

}  // namespace kairos
