// Event times of accelerated trajectories: cell exits under gravity, sphere-plane contacts with
// fixed, moving and vibrated planes, and sphere pairs under a constant relative acceleration.
//
// Conventions follow collision_time.hpp and docs/physics.md#event-detection. Times are relative
// to the current state (t >= 0). For an overlap function f (f < 0 means an invalid, overlapping
// state) the event is the earliest t >= 0 with f(t) <= 0 and f'(t) < 0, where "earliest" is the
// infimum: a state touching with f = 0, f' = 0 and f'' < 0 has its event at t = 0, because
// f' < 0 holds for every later instant while f <= 0. Every solver takes a horizon t_max and
// returns kNever for an event after it; the engine never needs events beyond a particle's next
// cell exit.
//
// Resting contact. A sphere resting exactly on a fixed floor with gravity into it (f = 0,
// f' = 0, f'' < 0) has its event now. Reporting "never" would let it sink through the floor
// with nobody watching, the one failure an event-driven engine cannot recover from. Handling
// that event is the engine's job: the normal approach speed is zero, so a plain reflection
// changes nothing and would recur at the same instant forever. The engine needs a resting
// state (DynamO's sleeping particles) or a minimum rebound speed to break that loop.
#pragma once

#include <array>
#include <cmath>
#include <numbers>

#include "dynamics/collision_time.hpp"

namespace kairos {

// kNever unless t lies within the horizon.
inline double within_horizon(double t, double t_max) {
  return t <= t_max ? t : kNever;
}

// Stable event time of f(t) = a + b t + c t^2 for any sign of c
// (docs/physics.md#accelerated-motion). For c > 0 this is quadratic_contact_time. For c < 0 (a
// gap that is eventually closed, e.g. by gravity) an event always exists; every branch uses the
// root formula free of cancellation.
inline double quadratic_event_time(double a, double b, double c) {
  if (c > 0.0) return quadratic_contact_time(a, b, c);
  if (c == 0.0) return b < 0.0 ? std::fmax(0.0, -a / b) : kNever;
  const double disc = b * b - 4.0 * a * c;
  // f <= 0 everywhere (a <= 0): the event is where f' turns negative, at the vertex.
  if (disc <= 0.0) return std::fmax(0.0, -b / (2.0 * c));
  const double root = std::sqrt(disc);
  // Rising first (b > 0): the later root, where f crosses zero downwards; b and root add.
  if (b > 0.0) return std::fmax(0.0, (-b - root) / (2.0 * c));
  return std::fmax(0.0, 2.0 * a / (-b + root));  // falling from the start; a <= 0 gives now
}

// First t >= 0 at which x + v t + a t^2/2 leaves [lo, hi] (a particle in a cell under a constant
// acceleration). lo = -inf or hi = +inf makes that side unreachable. Contract at the faces:
// - a point slightly outside (round-off after a crossing) is treated as lying on the nearer
//   face: it exits now if it moves outward (v, or a if v = 0) and is inside otherwise;
// - a point on a face moving outward exits at 0, one at rest on it exits at 0 iff a points out;
// - the result is never negative or NaN, and at the returned time the point is on a face up to
//   the round-off of the cancellation-free root.
// For a == 0 this is interval_exit_time itself, bit for bit. (That one does not clamp: a point
// slightly outside and moving inward exits through the far face later by the tiny offset.)
inline double interval_exit_time_accelerated(double x, double v, double a, double lo, double hi,
                                             double t_max = kNever) {
  if (a == 0.0) return within_horizon(interval_exit_time(x, v, lo, hi), t_max);
  const double xc = std::fmin(std::fmax(x, lo), hi);
  // Each face is a gap function that must stay positive: hi - x(t) and x(t) - lo.
  const double t_hi = std::isinf(hi) ? kNever : quadratic_event_time(hi - xc, -v, -0.5 * a);
  const double t_lo = std::isinf(lo) ? kNever : quadratic_event_time(xc - lo, v, 0.5 * a);
  return within_horizon(std::fmin(t_hi, t_lo), t_max);
}

// Motion of a sphere along a plane's unit normal n (pointing into the fluid side): its lowest
// point n.x - R, the normal velocity n.v and the normal acceleration n.g. In-plane motion never
// changes the gap, so this is all any plane event needs.
struct NormalMotion {
  double height = 0.0;
  double velocity = 0.0;
  double accel = 0.0;
};

template <int D>
NormalMotion normal_motion(const double* n, const double* x, const double* v, const double* g,
                           double radius) {
  NormalMotion m;
  for (int k = 0; k < D; ++k) {
    m.height += n[k] * x[k];
    m.velocity += n[k] * v[k];
    m.accel += n[k] * g[k];
  }
  m.height -= radius;
  return m;
}

// Contact with the fixed plane n.x = d: gap f(t) = height(t) - d, a quadratic.
inline double fixed_plane_event_time(const NormalMotion& m, double d, double t_max = kNever) {
  return within_horizon(quadratic_event_time(m.height - d, m.velocity, 0.5 * m.accel), t_max);
}

// Contact with a plane translating at constant velocity u: offset d(t) = d0 + u_n t with
// u_n = n.u. Only the relative normal velocity enters; the wall velocity at the event is u.
inline double moving_plane_event_time(const NormalMotion& m, double d0, double u_n,
                                      double t_max = kNever) {
  return within_horizon(quadratic_event_time(m.height - d0, m.velocity - u_n, 0.5 * m.accel),
                        t_max);
}

// A plane vibrated along its normal: offset d(t) = d0 + amplitude sin(omega t + phase), with t
// relative to the particle's current time (see rephased).
struct VibratedPlane {
  double d0 = 0.0;
  double amplitude = 0.0;
  double omega = 0.0;
  double phase = 0.0;
};

inline double vibrated_plane_offset(const VibratedPlane& p, double t) {
  return p.d0 + p.amplitude * std::sin(p.omega * t + p.phase);
}

// Normal velocity of the plane at relative time t: the wall velocity for the impulse is this
// times n.
inline double vibrated_plane_velocity(const VibratedPlane& p, double t) {
  return p.amplitude * p.omega * std::cos(p.omega * t + p.phase);
}

// The same plane with its time origin moved dt later. The phase is reduced to [-pi, pi] so
// that the sine's argument, and with it its round-off, stays small.
inline VibratedPlane rephased(const VibratedPlane& p, double dt) {
  VibratedPlane q = p;
  q.phase = std::remainder(p.phase + p.omega * dt, 2.0 * std::numbers::pi);
  return q;
}

// Stable event time of the gap f(t) = height(t) - d(t) against a vibrated plane. This is a
// transcendental equation. It is solved by stepping through intervals that are certified free
// of events: no event where f > 0 throughout (lower bounds from |f''| <= |g_n| + |A| w^2 and
// from |sin| <= 1) or where f' > 0 throughout (from |f'''| <= |A| w^3 and |cos| <= 1). So no
// event is ever skipped, up to the round-off of evaluating f, which the bounds include. The
// event is reported within that round-off of contact: at the returned time |f| is a few ulps
// of the sizes of its terms. Steps shrink towards a root as fast as Newton's method does. A
// tangency that touches within that round-off may be reported as an event with a tiny approach
// speed (as may the quartic's); that is harmless for the impulse.
//
// If a pathological near-tangency exhausted the step budget (never seen in the tests), the
// time reached is returned: a time no later than the event, never a skipped one.
double vibrated_plane_event_time(const NormalMotion& m, const VibratedPlane& p,
                                 double t_max = kNever);

// A plane moving along its normal as a driven, damped oscillator does between kicks (a wall of
// mass M on a spring to a sinusoidally moving anchor, boundaries/wall_body.hpp): offset
//   d(t) = d0 + e^(-gamma t) (u cos(wd t) + b sin(wd t)) + amplitude sin(omega t + phase),
// t relative to the particle's current time: the transient of the free oscillation (decay rate
// gamma = c / 2M, frequency wd = sqrt(w0^2 - gamma^2), w0^2 = k / M) and the steady response to
// the drive.
struct OscillatingPlane {
  double d0 = 0.0;
  double u = 0.0, b = 0.0;  // the transient's cosine and sine parts at t = 0
  double gamma = 0.0, wd = 0.0;
  double amplitude = 0.0, omega = 0.0, phase = 0.0;
  // A bound on the transient's size from t = 0 on (it only decays): sqrt(u^2 + b^2).
  double transient() const { return std::hypot(u, b); }
  // sqrt(gamma^2 + wd^2): the n-th derivative of the transient is at most transient() w0^n.
  double w0() const { return std::hypot(gamma, wd); }
};

// The offset d(t) and its first two derivatives.
struct OffsetJet {
  double d = 0.0, d1 = 0.0, d2 = 0.0;
};
OffsetJet oscillating_plane_offset(const OscillatingPlane& p, double t);

// Stable event time of the gap f(t) = height(t) - d(t) against an oscillating plane, by the
// vibrated plane's certified stepping (the same contract): the bounds |d''| <= T w0^2 + A w^2,
// |d'''| <= T w0^3 + A w^3 and |d - d0| <= T + A hold from t = 0 on (T = transient()).
double oscillating_plane_event_time(const NormalMotion& m, const OscillatingPlane& p,
                                    double t_max = kNever);

// Stable event time of the polynomial f(t) = c[0] + c[1] t + ... + c[4] t^4
// (docs/physics.md#quartic-pair-contact): f' vanishes on monotone pieces of f found from the
// roots of f'' (closed form) and a bracketed Newton search on f', so every piece is monotone,
// and the pieces are walked in time order. An event inside a piece is polished to a few ulps.
// Degree 2 or less is quadratic_event_time.
double quartic_event_time(const std::array<double, 5>& c, double t_max = kNever);

// The same for a polynomial of degree up to kMaxPolynomialDegree (a sphere falling towards a
// ring, a circular edge, is of degree 8: docs/physics.md#circular-holes): f(t) = c[0] + c[1] t +
// ... + c[degree] t^degree, f >= 0 the allowed side. Its monotone pieces are those between the
// real roots of f', found the same way recursively (f'', ..., down to a quadratic in closed
// form), each isolated on a monotone piece of its own and polished; the pieces are walked in
// time order and never cut at the horizon. The first time f falls through zero, kNever if none
// before t_max.
inline constexpr int kMaxPolynomialDegree = 8;
double polynomial_event_time(const double* c, int degree, double t_max = kNever);

// Contact time of a sphere of radius a with a ring: a circle of radius R > a about the unit axis
// n through the ring's centre (a circular hole's edge). The sphere's centre is at r from the
// ring's centre with velocity v and constant acceleration g (3D). With q = |r(t)|^2 and
// z = n . r(t), its distance from the circle obeys dist^2 = q - 2 R rho + R^2 (rho = sqrt(q -
// z^2), the distance from the axis), and f(t) = (q + R^2 - a^2)^2 - 4 R^2 (q - z^2) =
// (dist^2 - a^2) ((rho + R)^2 + z^2 - a^2) has the sign of dist^2 - a^2, the second factor being
// at least R^2 - a^2 > 0: a polynomial of degree 8 under a field, 4 without
// (docs/physics.md#circular-holes).
double ring_contact_time(const double* r, const double* v, const double* g, const double* n,
                         double ring_radius, double radius, double t_max = kNever);

// Contact time of a pair at relative position r, velocity v and constant relative acceleration
// a (gravity on one body only, e.g. a falling sphere against a resting one), contact distance
// sigma: f(t) = |r + v t + a t^2/2|^2 - sigma^2. With a = 0 this is pair_contact_time exactly.
template <int D>
double pair_contact_time_accelerated(const double* r, const double* v, const double* a,
                                     double sigma, double t_max = kNever) {
  double rr = 0.0, rv = 0.0, vv = 0.0, ra = 0.0, va = 0.0, aa = 0.0;
  for (int k = 0; k < D; ++k) {
    rr += r[k] * r[k];
    rv += r[k] * v[k];
    vv += v[k] * v[k];
    ra += r[k] * a[k];
    va += v[k] * a[k];
    aa += a[k] * a[k];
  }
  if (aa == 0.0) {
    return within_horizon(quadratic_contact_time(rr - sigma * sigma, 2.0 * rv, vv), t_max);
  }
  return quartic_event_time({rr - sigma * sigma, 2.0 * rv, vv + ra, va, 0.25 * aa}, t_max);
}

}  // namespace kairos
