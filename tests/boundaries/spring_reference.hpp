// An independent reference for a wall on a spring (boundaries/wall_spring.hpp): Runge-Kutta 4 of
// M X'' = -k (X - a) - c (X' - a') + M g, a(t) = A sin(W t + phi), written out here from the
// equation, not from the closed form it checks.
#pragma once

#include <cmath>
#include <utility>

#include "boundaries/wall_spring.hpp"

namespace kairos::testing {

// (X, X') at t1 from (x, v) at t0, in n steps, for a body of mass `mass` under the constant
// acceleration `accel` (its force over M plus the field).
inline std::pair<double, double> integrate_spring(const WallSpring& s, double mass, double accel,
                                                  double t0, double x, double v, double t1, int n) {
  const auto acceleration = [&](double t, double x_, double v_) {
    const double a = s.amplitude * std::sin(s.omega * t + s.phase);
    const double da = s.amplitude * s.omega * std::cos(s.omega * t + s.phase);
    return (-s.stiffness * (x_ - a) - s.damping * (v_ - da)) / mass + accel;
  };
  const double h = (t1 - t0) / n;
  for (int i = 0; i < n; ++i) {
    const double t = t0 + i * h;
    const double k1x = v, k1v = acceleration(t, x, v);
    const double k2x = v + 0.5 * h * k1v;
    const double k2v = acceleration(t + 0.5 * h, x + 0.5 * h * k1x, k2x);
    const double k3x = v + 0.5 * h * k2v;
    const double k3v = acceleration(t + 0.5 * h, x + 0.5 * h * k2x, k3x);
    const double k4x = v + h * k3v, k4v = acceleration(t + h, x + h * k3x, k4x);
    x += h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
    v += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
  }
  return {x, v};
}

}  // namespace kairos::testing
