// Event times of ballistic pairs: the stable, cancellation-free quadratic root.
//
// For a pair with relative position r and relative velocity g (both of i minus j) and contact
// distance sigma, the overlap function is f(t) = |r + g t|^2 - sigma^2 = a + b t + c t^2 with
// a = r^2 - sigma^2, b = 2 r.g, c = g^2. The event is the earliest t >= 0 with f(t) <= 0 and
// f'(t) < 0 (Bannerman et al., Comput. Part. Mech. 1, 191 (2014);
// docs/physics.md#stable-event-rule): an overlapping, approaching pair collides now (t = 0), an
// overlapping, receding pair never does, a tangent pair never does. The root 2a / (-b + sqrt(D))
// avoids the cancellation of the textbook (-b - sqrt(D)) / 2c
// (docs/physics.md#hard-sphere-contact-time).
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/vec.hpp"

namespace kairos {

inline constexpr double kNever = std::numeric_limits<double>::infinity();

// Time until two spheres moving ballistically come into contact (a, b, c as above).
inline double quadratic_contact_time(double a, double b, double c) {
  if (b >= 0.0) return kNever;  // receding or tangent: no approach
  if (c <= 0.0) {
    // c = 0 with b < 0 cannot happen for real vectors (g = 0 gives b = 0); kept for safety.
    return a <= 0.0 ? 0.0 : kNever;
  }
  const double disc = b * b - 4.0 * a * c;
  if (disc <= 0.0) return kNever;  // near miss (a > 0) or, for a < 0, impossible
  const double t = 2.0 * a / (-b + std::sqrt(disc));
  return t > 0.0 ? t : 0.0;  // a <= 0: overlapping and approaching -> now
}

// Growing spheres (Lubachevsky-Stillinger compression): the contact distance grows as
// sigma + u t (u = d sigma / dt >= 0), so f(t) = |r + g t|^2 - (sigma + u t)^2 = a + 2 h t + c t^2
// with a = r^2 - sigma^2, h = r.g - sigma u (half of b) and c = g^2 - u^2, which is negative when
// the growth outruns the approach. The stable event rule (Bannerman et al. 2014;
// docs/physics.md#growing-spheres): the earliest t >= 0 with f <= 0 and f' < 0.
inline double growing_contact_time(double a, double h, double c) {
  if (c > 0.0) {  // the hard-sphere case: only an approach (h < 0) can meet
    if (h >= 0.0) return kNever;
    const double disc = h * h - a * c;
    if (disc <= 0.0) return kNever;
    const double t = a / (-h + std::sqrt(disc));
    return t > 0.0 ? t : 0.0;
  }
  if (c == 0.0) {  // f is linear
    if (h >= 0.0) return kNever;
    return a > 0.0 ? -a / (2.0 * h) : 0.0;
  }
  // c < 0: f ends negative whatever the pair does; it meets once f' < 0 with f <= 0.
  const double disc = h * h - a * c;
  if (disc <= 0.0) {  // f never positive (overlapping): the event is where f' turns negative
    const double t = -h / c;
    return t > 0.0 ? t : 0.0;
  }
  const double t = h > 0.0 ? (-h - std::sqrt(disc)) / c : a / (-h + std::sqrt(disc));
  return t > 0.0 ? t : 0.0;
}

// Convenience form from the relative state (vectors given as pointers to D components).
template <int D>
inline double pair_contact_time(const double* r, const double* g, double sigma) {
  double r2 = 0.0, rg = 0.0, g2 = 0.0;
  for (int k = 0; k < D; ++k) {
    r2 += r[k] * r[k];
    rg += r[k] * g[k];
    g2 += g[k] * g[k];
  }
  return quadratic_contact_time(r2 - sigma * sigma, 2.0 * rg, g2);
}

// Time until a point moving at velocity v along one axis leaves the interval [lo, hi].
// Returns 0 when it already sits outside the interval and moves further out (round-off at a
// boundary), never a negative time. Written with selects, not branches: the sign of v is
// random, so branches would mispredict half the time in the engine's crossing predictions.
inline double interval_exit_time(double x, double v, double lo, double hi) {
  const double face = v > 0.0 ? hi : lo;
  const double t = (face - x) / v;  // +-inf or NaN for v = 0: replaced below
  return v != 0.0 ? (t > 0.0 ? t : 0.0) : kNever;
}

// The first contact at or after `from` and before `until` (absolute times) of a pair whose
// separation is r at time t and whose relative velocity is g[p] until ends[p] (ascending, the
// last may be kNever); kNever if none. Each piece follows the hard-sphere rule of
// collision_time.hpp (an overlapping, receding pair does not collide). Soft spheres' deferred
// contacts.
template <int D>
inline double piecewise_contact_time(Vec<D> r, double t, const double* ends, const Vec<D>* g,
                                     int pieces, double from, double until, double sigma) {
  double start = t;
  for (int p = 0; p < pieces && start < until; ++p) {
    const double end = std::min(ends[p], until);
    if (end > from) {
      const double s0 = std::max(start, from);
      const Vec<D> r0 = r + (s0 - start) * g[p];
      const double dt =
          quadratic_contact_time(norm2(r0) - sigma * sigma, 2.0 * dot(r0, g[p]), norm2(g[p]));
      if (s0 + dt < end) return s0 + dt;
    }
    if (!(ends[p] < kNever)) break;
    r = r + (ends[p] - start) * g[p];
    start = ends[p];
  }
  return kNever;
}

}  // namespace kairos
