// Event solvers that need iteration: the vibrated plane (transcendental) and the quartic pair
// contact (docs/physics.md#quartic-pair-contact). See trajectory_events.hpp for the contracts.
#include "dynamics/trajectory_events.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

namespace kairos {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// ---------------------------------------------------------------------------------------------
// Vibrated plane

// A bound on the number of certified steps: searches take a few, near-tangencies a few dozen.
constexpr int kMaxVibratedSteps = 1 << 20;

// Gap f against a vibrated plane and its first two derivatives at one time, each with a bound
// on its round-off, plus the particle's own (polynomial) part of f and f'.
struct GapJet {
  double f, f1, f2;
  double err0, err1, err2;
  double poly, poly1, poly1_err;
};

GapJet vibrated_gap(const NormalMotion& m, const VibratedPlane& p, double p0, double t) {
  const double arg = p.omega * t + p.phase;
  const double s = std::sin(arg);
  const double c = std::cos(arg);
  const double aw = p.amplitude * p.omega;
  const double aw2 = aw * p.omega;
  GapJet j{};
  j.poly = p0 + (m.velocity + 0.5 * m.accel * t) * t;
  j.poly1 = m.velocity + m.accel * t;
  j.f = j.poly - p.amplitude * s;
  j.f1 = j.poly1 - aw * c;
  j.f2 = m.accel + aw2 * s;
  // A few ulps per term; the sine's argument is itself rounded by |arg| ulps.
  const double u = 8.0 * kEps;
  const double trig = 2.0 + std::fabs(arg);
  const double g = std::fabs(m.accel);
  j.poly1_err = u * (std::fabs(m.velocity) + g * t);
  j.err0 = u * (std::fabs(p0) + std::fabs(m.velocity) * t + g * t * t) +
           u * std::fabs(p.amplitude) * trig;
  j.err1 = j.poly1_err + u * std::fabs(aw) * trig;
  j.err2 = u * (g + std::fabs(aw2) * trig);
  return j;
}

// Length of [0, h) on which q0 + q1 s - k s^2/2 > 0 (q0 > 0, k >= 0): the first positive root.
double positive_span(double q0, double q1, double k) {
  return quadratic_event_time(q0, q1, -0.5 * k);
}

// Certified event-free length while the gap is clearly open (f > 2 err0): the larger of the
// local bound f + f' s - k2 s^2/2 and the global one, particle height minus the plane's top.
double open_gap_span(const GapJet& j, double accel, double amp, double k2) {
  const double local = positive_span(j.f - j.err0, j.f1 - j.err1, k2);
  const double above = j.poly - amp - j.err0;
  if (!(above > 0.0)) return local;
  return std::fmax(local, quadratic_event_time(above, j.poly1 - j.poly1_err, 0.5 * accel));
}

// Certified event-free length while the gap clearly opens (f' > 2 err1): f only grows, so no
// event until f' can reach zero. Local bound from |f'''| <= k3, global one from |cos| <= 1.
double opening_span(const GapJet& j, double accel, double amp_w, double k3) {
  const double local = positive_span(j.f1 - j.err1, j.f2 - j.err2, k3);
  const double ahead = j.poly1 - j.poly1_err - amp_w;
  if (!(ahead > 0.0)) return local;
  return std::fmax(local, accel < 0.0 ? ahead / -accel : kNever);
}

// What the certified stepping needs to know of a plane's motion from t = 0 on: |d - d0| <=
// reach, |d'| <= speed, and bounds k2 >= |f''|, k3 >= |f'''| on the gap (with their round-off).
struct PlaneBounds {
  double reach, speed, k2, k3;
};

// The certified stepping of vibrated_plane_event_time (trajectory_events.hpp) for any plane
// motion: jet(t) gives the gap's GapJet at relative time t.
template <class Jet>
double certified_plane_event_time(const NormalMotion& m, const PlaneBounds& b, Jet jet,
                                  double t_max) {
  double t = 0.0;
  for (int step = 0; step < kMaxVibratedSteps; ++step) {
    const GapJet j = jet(t);
    const bool touching = j.f <= 2.0 * j.err0;       // in contact up to round-off, or overlapping
    if (touching && j.f1 < -2.0 * j.err1) return t;  // ... and approaching
    double h = touching ? 0.0 : open_gap_span(j, m.accel, b.reach, b.k2);
    if (j.f1 > 2.0 * j.err1) {
      h = std::fmax(h, opening_span(j, m.accel, b.speed, b.k3));
    } else if (touching) {
      // Touching at zero relative speed (up to round-off): f' is about to turn negative
      // unless f'' > 0, which keeps f' from decreasing for (f'' - err) / k3.
      if (j.f2 - j.err2 <= 0.0) return t;
      h = (j.f2 - j.err2) / b.k3;
    }
    const double next = std::fmax(t + h, std::nextafter(t, kNever));  // always make progress
    if (!(next <= t_max) || std::isinf(next)) return kNever;  // event-free up to the horizon
    t = next;
  }
  return t;
}

// The oscillating plane's offset less d0, and its derivatives. The transient's coefficients
// after a derivative: (u, b) -> (-gamma u + wd b, -gamma b - wd u).
OffsetJet displacement_jet(const OscillatingPlane& p, double t) {
  const double e = std::exp(-p.gamma * t);
  const double c = std::cos(p.wd * t);
  const double s = std::sin(p.wd * t);
  const double u1 = -p.gamma * p.u + p.wd * p.b, b1 = -p.gamma * p.b - p.wd * p.u;
  const double u2 = -p.gamma * u1 + p.wd * b1, b2 = -p.gamma * b1 - p.wd * u1;
  const double arg = p.omega * t + p.phase;
  const double sa = std::sin(arg);
  const double ca = std::cos(arg);
  const double aw = p.amplitude * p.omega;
  return {e * (p.u * c + p.b * s) + p.amplitude * sa, e * (u1 * c + b1 * s) + aw * ca,
          e * (u2 * c + b2 * s) - aw * p.omega * sa};
}

// tr and w0: p.transient() and p.w0(), computed once per search.
GapJet oscillating_gap(const NormalMotion& m, const OscillatingPlane& p, double p0, double tr,
                       double w0, double t) {
  const OffsetJet o = displacement_jet(p, t);
  GapJet j{};
  j.poly = p0 + (m.velocity + 0.5 * m.accel * t) * t;
  j.poly1 = m.velocity + m.accel * t;
  j.f = j.poly - o.d;
  j.f1 = j.poly1 - o.d1;
  j.f2 = m.accel - o.d2;
  // A few ulps per term; the arguments of the sines and the exponential are rounded by a few
  // ulps of their size, and the transient is at most transient() w0^n in its n-th derivative.
  const double u = 8.0 * kEps;
  const double trig = 2.0 + std::fabs(p.omega * t + p.phase);
  const double decay = 4.0 + (p.gamma + p.wd) * t;
  const double amp = std::fabs(p.amplitude), w = std::fabs(p.omega);
  const double g = std::fabs(m.accel);
  j.poly1_err = u * (std::fabs(m.velocity) + g * t);
  j.err0 =
      u * (std::fabs(p0) + std::fabs(m.velocity) * t + g * t * t) + u * (amp * trig + tr * decay);
  j.err1 = j.poly1_err + u * (amp * w * trig + tr * w0 * decay);
  j.err2 = u * (g + amp * w * w * trig + tr * w0 * w0 * decay);
  return j;
}

// ---------------------------------------------------------------------------------------------
// Quartic

struct Quartic {
  std::array<double, 5> c;
  double f(double t) const { return c[0] + t * (c[1] + t * (c[2] + t * (c[3] + t * c[4]))); }
  double df(double t) const {
    return c[1] + t * (2.0 * c[2] + t * (3.0 * c[3] + t * (4.0 * c[4])));
  }
  double d2f(double t) const { return 2.0 * c[2] + t * (6.0 * c[3] + t * (12.0 * c[4])); }
};

// Real roots of a t^2 + b t + c, unordered; returns how many were written.
int real_quadratic_roots(double a, double b, double c, double roots[2]) {
  if (a == 0.0) {
    if (b == 0.0) return 0;
    roots[0] = -c / b;
    return 1;
  }
  const double disc = b * b - 4.0 * a * c;
  if (disc < 0.0) return 0;
  const double q = -0.5 * (b + std::copysign(std::sqrt(disc), b));  // no cancellation
  if (q == 0.0) {  // b = c = 0: a double root at zero
    roots[0] = 0.0;
    return 1;
  }
  roots[0] = q / a;
  roots[1] = c / q;
  return 2;
}

// First point where g, decreasing through zero on [lo, hi] (g(lo) > 0 >= g(hi)), reaches zero:
// Newton steps, with bisection whenever Newton leaves the bracket or stops halving its step.
// Fn returns {g(x), g'(x)}. The result always lies above the bracket's lower end, which only
// rises: once that end passes `beyond`, so will the result, and kNever is returned at once
// (the same iterates up to there, so a result at or before `beyond` is the one without it).
template <class Fn>
double polish_root(Fn g, double lo, double hi, double beyond = kNever) {
  double x = lo + 0.5 * (hi - lo);
  double step = hi - lo;
  for (int i = 0; i < 256; ++i) {
    const auto [gx, dgx] = g(x);
    if (gx == 0.0) return x;
    (gx > 0.0 ? lo : hi) = x;
    if (lo > beyond) return kNever;
    const double prev_step = step;
    step = gx / dgx;
    double next = x - step;
    if (!(next > lo && next < hi && std::fabs(step) < 0.5 * std::fabs(prev_step))) {
      next = lo + 0.5 * (hi - lo);
      step = x - next;
      if (next <= lo || next >= hi) return hi;  // the bracket is two adjacent doubles
    }
    if (std::fabs(step) <= 2.0 * kEps * std::fabs(next)) return next;  // converged
    x = next;
  }
  return x;
}

// A short sorted list of split points in time.
struct SplitPoints {
  std::array<double, 3> t{};  // 0 and the two roots of f
  int n = 0;
  void insert(double x) {
    int k = n++;
    for (; k > 0 && t[k - 1] > x; --k) {
      t[k] = t[k - 1];
    }
    t[k] = x;
  }
  double operator[](int i) const { return t[i]; }
};

// Smallest end = from + 2^k (k >= 0) at which done(end) holds, or kNever if none is finite.
// Used on an unbounded monotone piece, where done(end) stays true beyond its first success.
template <class Pred>
double expand_until(double from, Pred done) {
  for (double w = 1.0; std::isfinite(from + w); w *= 2.0) {
    if (done(from + w)) return from + w;
  }
  return kNever;
}

// The sign of f' as t grows without bound: that of its leading coefficient (0 for a constant f).
double slope_at_infinity(const Quartic& q) {
  for (int k = 4; k >= 1; --k)
    if (q.c[k] != 0.0) return q.c[k];
  return 0.0;
}

// The root of f' in (lo, hi), where f' is monotone (hi may be infinite); NaN if f' keeps its
// sign there. At infinity f' takes the sign of its leading coefficient.
double slope_root(const Quartic& q, double lo, double hi) {
  const double d_lo = q.df(lo);
  if (d_lo == 0.0) return kNaN;  // lo itself is the critical point, and a split point already
  if (std::isinf(hi) && (d_lo > 0.0) == (slope_at_infinity(q) > 0.0)) return kNaN;  // no flip
  const auto flipped = [&](double t) { return q.df(t) * d_lo <= 0.0; };
  const double end = std::isinf(hi) ? expand_until(lo, flipped) : hi;
  if (std::isinf(end) || !flipped(end)) return kNaN;
  const double sign = d_lo > 0.0 ? 1.0 : -1.0;
  return polish_root([&](double t) { return std::pair{sign * q.df(t), sign * q.d2f(t)}; }, lo, end);
}

}  // namespace

double vibrated_plane_event_time(const NormalMotion& m, const VibratedPlane& p, double t_max) {
  if (p.amplitude == 0.0 || p.omega == 0.0) {
    return fixed_plane_event_time(m, vibrated_plane_offset(p, 0.0), t_max);
  }
  const double p0 = m.height - p.d0;
  const double amp = std::fabs(p.amplitude);
  const double w = std::fabs(p.omega);
  const double slack = 1.0 + 16.0 * kEps;  // the bounds' own round-off
  const PlaneBounds bounds{amp, amp * w, (std::fabs(m.accel) + amp * w * w) * slack,
                           amp * w * w * w * slack};
  return certified_plane_event_time(
      m, bounds, [&](double t) { return vibrated_gap(m, p, p0, t); }, t_max);
}

OffsetJet oscillating_plane_offset(const OscillatingPlane& p, double t) {
  OffsetJet o = displacement_jet(p, t);
  o.d += p.d0;
  return o;
}

double oscillating_plane_event_time(const NormalMotion& m, const OscillatingPlane& p,
                                    double t_max) {
  const double transient = p.transient();
  const double amp = std::fabs(p.amplitude);
  const double w = std::fabs(p.omega);
  const double w0 = p.w0();
  const double k3 = transient * w0 * w0 * w0 + amp * w * w * w;
  if (k3 == 0.0) return fixed_plane_event_time(m, oscillating_plane_offset(p, 0.0).d, t_max);
  const double slack = 1.0 + 16.0 * kEps;
  const PlaneBounds bounds{transient + amp, transient * w0 + amp * w,
                           (std::fabs(m.accel) + transient * w0 * w0 + amp * w * w) * slack,
                           k3 * slack};
  const double p0 = m.height - p.d0;
  return certified_plane_event_time(
      m, bounds, [&](double t) { return oscillating_gap(m, p, p0, transient, w0, t); }, t_max);
}

namespace {

// The event on the monotone piece [s, e] of f (e may be infinite), if f falls through zero
// there: its time (kNever once it is known to come after t_max), else NaN.
double event_on_piece(const Quartic& q, double s, double e, double t_max) {
  if (!(e > s)) return kNaN;
  const double probe = std::isinf(e) ? 2.0 * s + 1.0 : s + 0.5 * (e - s);
  if (!(q.df(probe) < 0.0)) return kNaN;  // only a falling piece can hold the event
  if (q.f(s) <= 0.0) return s;            // overlapping when f' turns negative (or at t = 0)
  const auto below = [&](double t) { return q.f(t) < 0.0 || (q.f(t) == 0.0 && q.df(t) < 0.0); };
  const double end = std::isinf(e) ? expand_until(s, below) : e;
  if (std::isinf(end) || !below(end)) return kNaN;  // stays positive, or only touches at e
  return polish_root([&](double t) { return std::pair{q.f(t), q.df(t)}; }, s, end, t_max);
}

// A polynomial of degree <= kMaxPolynomialDegree: c[0] + c[1] t + ... (degree: its highest
// nonzero coefficient).
struct Polynomial {
  std::array<double, kMaxPolynomialDegree + 1> c{};
  int degree = 0;
  double f(double t) const {
    double y = c[static_cast<std::size_t>(degree)];
    for (int k = degree - 1; k >= 0; --k) y = y * t + c[static_cast<std::size_t>(k)];
    return y;
  }
  Polynomial derivative() const {
    Polynomial d;
    d.degree = std::max(0, degree - 1);
    for (int k = 1; k <= degree; ++k)
      d.c[static_cast<std::size_t>(k - 1)] = k * c[static_cast<std::size_t>(k)];
    return d;
  }
  // The sign of p as t grows without bound.
  double sign_at_infinity() const {
    for (int k = degree; k >= 0; --k)
      if (c[static_cast<std::size_t>(k)] != 0.0)
        return c[static_cast<std::size_t>(k)] > 0.0 ? 1 : -1;
    return 0.0;
  }
};

// The roots of p in (0, infinity), sorted: each isolated on a piece where p is monotone, between
// consecutive roots of p' (found the same way, down to a quadratic in closed form), and
// polished there. The pieces never depend on a horizon (quartic_event_time says why).
int positive_roots(const Polynomial& p, std::array<double, kMaxPolynomialDegree>& out) {
  int n = 0;
  if (p.degree <= 2) {
    double r[2];
    const int k = real_quadratic_roots(p.c[2], p.c[1], p.c[0], r);
    for (int i = 0; i < k; ++i)
      if (r[i] > 0.0 && std::isfinite(r[i])) out[static_cast<std::size_t>(n++)] = r[i];
    if (n == 2 && out[0] > out[1]) std::swap(out[0], out[1]);
    return n;
  }
  const Polynomial dp = p.derivative();
  std::array<double, kMaxPolynomialDegree> crit{};
  const int m = positive_roots(dp, crit);
  for (int i = 0; i <= m; ++i) {
    const double lo = i == 0 ? 0.0 : crit[static_cast<std::size_t>(i - 1)];
    const double hi = i < m ? crit[static_cast<std::size_t>(i)] : kNever;
    const double p_lo = p.f(lo);
    if (p_lo == 0.0) {
      if (lo > 0.0 && (n == 0 || out[static_cast<std::size_t>(n - 1)] < lo))
        out[static_cast<std::size_t>(n++)] = lo;
      continue;
    }
    const double sign = p_lo > 0.0 ? 1.0 : -1.0;  // p monotone on the piece: falls if positive
    const auto crossed = [&](double t) { return sign * p.f(t) <= 0.0; };
    double end = hi;
    if (std::isinf(hi)) {
      if (p.sign_at_infinity() * sign > 0.0) continue;
      end = expand_until(lo, crossed);
    }
    if (std::isinf(end) || !crossed(end)) continue;
    const double r = polish_root(
        [&](double t) {
          return std::pair{sign * p.f(t), sign * dp.f(t)};
        },
        lo, end);
    if (r > 0.0 && (n == 0 || out[static_cast<std::size_t>(n - 1)] < r))
      out[static_cast<std::size_t>(n++)] = r;
  }
  return n;
}

}  // namespace

double polynomial_event_time(const double* coefficients, int degree, double t_max) {
  Polynomial p;
  p.degree = std::clamp(degree, 0, kMaxPolynomialDegree);
  for (int k = 0; k <= p.degree; ++k) p.c[static_cast<std::size_t>(k)] = coefficients[k];
  while (p.degree > 0 && p.c[static_cast<std::size_t>(p.degree)] == 0.0) --p.degree;
  if (p.degree <= 2) return within_horizon(quadratic_event_time(p.c[0], p.c[1], p.c[2]), t_max);
  const Polynomial dp = p.derivative();
  if (p.c[0] <= 0.0 && p.c[1] < 0.0) return within_horizon(0.0, t_max);  // overlapping, closing
  // The monotone pieces of f, between the roots of f', walked in time order: the first that
  // falls through zero holds the event.
  std::array<double, kMaxPolynomialDegree> crit{};
  const int m = positive_roots(dp, crit);
  for (int i = 0; i <= m; ++i) {
    const double lo = i == 0 ? 0.0 : crit[static_cast<std::size_t>(i - 1)];
    const double hi = i < m ? crit[static_cast<std::size_t>(i)] : kNever;
    if (lo > t_max) return kNever;
    const double probe = std::isinf(hi) ? 2.0 * lo + 1.0 : lo + 0.5 * (hi - lo);
    if (!(dp.f(probe) < 0.0)) continue;  // only a falling piece can hold the event
    if (p.f(lo) <= 0.0) return within_horizon(lo, t_max);
    const auto below = [&](double t) { return p.f(t) < 0.0 || (p.f(t) == 0.0 && dp.f(t) < 0.0); };
    const double end = std::isinf(hi) ? expand_until(lo, below) : hi;
    if (std::isinf(end) || !below(end)) continue;
    return within_horizon(polish_root(
                              [&](double t) {
                                return std::pair{p.f(t), dp.f(t)};
                              },
                              lo, end, t_max),
                          t_max);
  }
  return kNever;
}

double ring_contact_time(const double* r, const double* v, const double* g, const double* n,
                         double ring_radius, double radius, double t_max) {
  double rr = 0.0, rv = 0.0, vv = 0.0, rg = 0.0, vg = 0.0, gg = 0.0;
  double nr = 0.0, nv = 0.0, ng = 0.0;
  for (int k = 0; k < 3; ++k) {
    rr += r[k] * r[k];
    rv += r[k] * v[k];
    vv += v[k] * v[k];
    rg += r[k] * g[k];
    vg += v[k] * g[k];
    gg += g[k] * g[k];
    nr += n[k] * r[k];
    nv += n[k] * v[k];
    ng += n[k] * g[k];
  }
  const double R2 = ring_radius * ring_radius;
  // q(t) = |r + v t + g t^2 / 2|^2 and z(t) = n . (the same), as coefficients in t.
  const std::array<double, 5> q{rr, 2.0 * rv, vv + rg, vg, 0.25 * gg};
  const std::array<double, 3> z{nr, nv, 0.5 * ng};
  std::array<double, 5> s = q, w = q;  // s = q + R^2 - a^2, w = q - z^2
  s[0] += R2 - radius * radius;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) w[static_cast<std::size_t>(i + j)] -= z[i] * z[j];
  std::array<double, 9> f{};
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j) f[static_cast<std::size_t>(i + j)] += s[i] * s[j];
  for (int i = 0; i < 5; ++i) f[static_cast<std::size_t>(i)] -= 4.0 * R2 * w[i];
  // f(0) and f'(0) from the product form (dist^2 - a^2) ((rho + R)^2 + z^2 - a^2): the expanded
  // coefficients carry round-off of the size of (2 R^2)^2, which for a wide ring (R >> a) swamps
  // a grazing particle's f(0) and f'(0), and the solver's "overlapping and closing" at t = 0
  // fired on noise (a clock frozen on a grain sliding over the rim).
  double px = 0.0, pv = 0.0;  // r and v across the axis: |r_perp|^2, r_perp . v_perp
  for (int k = 0; k < 3; ++k) {
    const double rp = r[k] - nr * n[k], vp = v[k] - nv * n[k];
    px += rp * rp;
    pv += rp * vp;
  }
  if (px > 0.0) {
    const double rho = std::sqrt(px), drho = pv / rho;
    const double a2 = radius * radius;
    const double A = (rho - ring_radius) * (rho - ring_radius) + nr * nr - a2;
    const double B = (rho + ring_radius) * (rho + ring_radius) + nr * nr - a2;
    const double dA = 2.0 * (rho - ring_radius) * drho + 2.0 * nr * nv;
    const double dB = 2.0 * (rho + ring_radius) * drho + 2.0 * nr * nv;
    f[0] = A * B;
    f[1] = dA * B + A * dB;
  }
  return polynomial_event_time(f.data(), 8, t_max);
}

double quartic_event_time(const std::array<double, 5>& c, double t_max) {
  if (c[4] == 0.0 && c[3] == 0.0) {
    return within_horizon(quadratic_event_time(c[0], c[1], c[2]), t_max);
  }
  if (c[0] <= 0.0 && c[1] < 0.0) return within_horizon(0.0, t_max);  // overlapping, approaching
  const Quartic q{c};
  // Split the half-line where f'' vanishes (f' is monotone between), then each such segment
  // where f' vanishes, so that f is monotone on every piece, and walk the pieces in time order.
  // The pieces are never cut at the horizon, which only ends the walk: the brackets, and so
  // the polished root to its last bit, do not depend on it. A candidate loop passes its running
  // best as the horizon, which depends on the order of its candidates (and that order on the
  // CPU's gather): cut pieces gave runs that differed in the last bits from one CPU to another.
  SplitPoints mono;
  mono.insert(0.0);
  double r2[2];
  const int n2 = real_quadratic_roots(12.0 * c[4], 6.0 * c[3], 2.0 * c[2], r2);
  for (int i = 0; i < n2; ++i) {
    if (r2[i] > 0.0 && std::isfinite(r2[i])) mono.insert(r2[i]);
  }
  for (int i = 0; i < mono.n; ++i) {
    const double lo = mono[i];
    const double hi = i + 1 < mono.n ? mono[i + 1] : kNever;
    if (lo > t_max) return kNever;
    // f rising up to the horizon on this segment (f' >= 0 at its start and > 0 at the horizon,
    // f' monotone): no event before the horizon, the same answer as the walk, without the search
    // for f''s root beyond it.
    if (t_max < hi && q.df(lo) >= 0.0 && q.df(t_max) > 0.0) return kNever;
    const double r = slope_root(q, lo, hi);
    const bool split = r == r && r > lo && r < hi;  // not NaN, inside
    double t = event_on_piece(q, lo, split ? r : hi, t_max);
    if (t != t && split) {
      if (r > t_max) return kNever;
      t = event_on_piece(q, r, hi, t_max);
    }
    if (t == t) return within_horizon(t, t_max);
  }
  return kNever;
}

}  // namespace kairos
