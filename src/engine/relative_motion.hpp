// The state of a pair at time t, written once: every scalar candidate loop (hard spheres,
// stepped potentials, the soft-contact probe, the sheared lists) and the kept-contact test
// include it, and a new
// interaction supplies only the math that turns r.r, r.g and g.g into an event time (as HOOMD's
// pair evaluators do for forces). The AVX-512 loops (candidate_scan.cpp) evaluate the same
// expressions in the same order, lane by lane, so every loop gives the same bits.
//
// Conventions: r = x_i - x_j and g = v_i - v_j; the candidate j is read from its engine record
// (position and velocity at its local time, dtj = t - local time before t) and seen through the
// periodic image `shift` of its cell; with uniform acceleration (kAccelerated) both particles
// follow parabolas, which leaves their relative motion a straight line.
#pragma once

#include <cmath>

#include "core/vec.hpp"
#include "dynamics/collision_time.hpp"

namespace kairos {

// r.r, r.g and g.g of a pair at one time: all its candidate tests need of it.
struct RelativeMotion {
  double r2 = 0.0;  // r.r
  double rg = 0.0;  // r.g
  double g2 = 0.0;  // g.g
};

// The pair (i, j) at time t: i at xi with velocity vi, j from its record `rec` (position at
// rec[0 .. D), velocity at rec[D .. 2D)) dtj after the record's time, seen through `shift`.
// half_accel and accel: g / 2 and g (kAccelerated only). kMovingImage: under Lees-Edwards
// shear the image moves with j's velocity plus image_velocity (boundaries/lees_edwards.hpp).
template <int D, bool kAccelerated = false, bool kMovingImage = false>
inline RelativeMotion relative_motion_at(const Vec<D>& xi, const Vec<D>& vi, const double* rec,
                                         double dtj, const Vec<D>& shift,
                                         const double* half_accel = nullptr,
                                         const double* accel = nullptr,
                                         const double* image_velocity = nullptr) {
  RelativeMotion p;
  for (int a = 0; a < D; ++a) {
    double xj = rec[a] + rec[D + a] * dtj;
    double vj = rec[D + a];
    if constexpr (kAccelerated) {
      xj = xj + (half_accel[a] * dtj) * dtj;
      vj = vj + accel[a] * dtj;
    }
    if constexpr (kMovingImage) vj = vj + image_velocity[a];
    const double r = xi[a] - (xj + shift[a]);
    const double g = vi[a] - vj;
    p.r2 = p.r2 + r * r;
    p.rg = p.rg + r * g;
    p.g2 = p.g2 + g * g;
  }
  return p;
}

// The soonest contact at squared distance sigma2 of a pair in state p, if it comes before
// `best`: the stable root, with a cheap rejection before the square root (the contact time
// gap / (-rg + sqrt(...)) is at least gap / (-2 rg)). Receding pairs (r.g >= 0, a particle
// with itself included) and near misses give kNever-like `false`; an overlapping, approaching
// pair meets now (0). docs/physics.md#hard-sphere-contact-time.
// `true` means only that the cheap bound did not rule the pair out: dt may still exceed `best`
// (the bound is a lower bound), so every caller compares dt with its best before keeping it.
inline bool contact_before(const RelativeMotion& p, double sigma2, double best, double& dt) {
  const double gap = p.r2 - sigma2;
  if (!(p.rg < 0.0) || gap > -2.0 * p.rg * best) return false;
  const double disc = p.rg * p.rg - p.g2 * gap;
  if (!(disc > 0.0)) return false;  // a near miss
  dt = gap / (-p.rg + std::sqrt(disc));
  if (!(dt > 0.0)) dt = 0.0;  // overlapping and approaching: now
  return true;
}

// contact_before() for growing spheres: contact distance sigma now, growing at u
// (dynamics/collision_time.hpp growing_contact_time). The cheap bound applies when the growth
// is slower than the approach (g^2 > u^2): the root a / (-h + sqrt(h^2 - a c)) >= a / (-2 h).
inline bool growing_contact_before(const RelativeMotion& p, double sigma, double u, double best,
                                   double& dt) {
  const double gap = p.r2 - sigma * sigma;
  const double h = p.rg - sigma * u;
  const double c = p.g2 - u * u;
  if (c > 0.0 && (!(h < 0.0) || gap > -2.0 * h * best)) return false;
  dt = growing_contact_time(gap, h, c);
  return dt < best;
}

// The contact time of a pair in state p at distance sigma by the quadratic's rule
// (dynamics/collision_time.hpp quadratic_contact_time, as pair_contact_time takes it): the
// loops that test pairs one by one against an unknown best (sheared lists).
inline double quadratic_contact_time(const RelativeMotion& p, double sigma) {
  return quadratic_contact_time(p.r2 - sigma * sigma, 2.0 * p.rg, p.g2);
}

}  // namespace kairos
