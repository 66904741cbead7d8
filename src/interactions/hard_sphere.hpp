// Hard spheres / disks: the interaction's math only (prediction and collision rule).
//
// Pair quantities follow docs/physics.md#conventions: r = r_i - r_j, g = v_i - v_j, contact
// distance sigma = R_i + R_j, J the impulse on i (-J acts on j). The engine's loops call these; a
// new interaction supplies the same two functions.
#pragma once

#include <cmath>

#include "dynamics/collision_time.hpp"

namespace kairos {

struct HardSphere {
  // Time until contact (>= 0, or kNever) from r.r, r.g, g.g at the same instant.
  static double contact_time(double r2, double rg, double g2, double sigma) {
    return quadratic_contact_time(r2 - sigma * sigma, 2.0 * rg, g2);
  }

  // Elastic collision: J = s r with s = -2 mu (g.r) / r^2, i.e. g_n -> -g_n along the line of
  // centres. Written with r instead of the unit normal to avoid a square root.
  static double impulse_factor(double g_dot_r, double r2, double reduced_mass) {
    return -2.0 * reduced_mass * g_dot_r / r2;
  }

  // Growing spheres (Lubachevsky-Stillinger): the contact distance sigma grows at u, so the
  // pair leaves the contact as fast, relative to the growing surfaces, as it came:
  // g_n - u -> -(g_n - u), i.e. s = -2 mu (g.r - u sigma) / r^2 (sigma rather than |r|: then
  // r.g - sigma u changes sign exactly, so a pair a round-off inside its contact still leaves).
  // The kinetic energy grows by the work of the growth (docs/physics.md#growing-spheres).
  static double growing_impulse_factor(double g_dot_r, double r2, double reduced_mass, double u,
                                       double sigma) {
    return -2.0 * reduced_mass * (g_dot_r - u * sigma) / r2;
  }
};

}  // namespace kairos
