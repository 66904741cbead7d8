// Growing particles (Lubachevsky-Stillinger compression; docs/physics.md#growing-spheres): every
// diameter grows as sigma_i(t) = sigma_i(t0) (1 + rate (t - t0)), so size ratios are kept. The
// engine's radii are those at the origin t0; this component turns them into the radii at any
// time and bounds how long the engine's cells stay wide enough.
#pragma once

#include "dynamics/collision_time.hpp"

namespace kairos {

class Growth {
 public:
  Growth() = default;
  // rate: relative growth per unit time (0: no growth); origin: when the radii are the engine's.
  Growth(double rate, double origin) : rate_(rate), origin_(origin) {}
  // The same radii from time t on, growing at `rate` (relative to the radii at the origin).
  Growth changed_at(double t, double rate) const {
    Growth g(rate, t);
    g.start_ = scale(t);
    return g;
  }

  bool on() const { return rate_ > 0.0; }
  double rate() const { return rate_; }
  double origin() const { return origin_; }
  // sigma(t) / sigma(t0): 1 without growth.
  double scale(double t) const { return on() ? start_ + rate_ * (t - origin_) : start_; }
  // d sigma / dt of a contact distance sigma0 (at the origin).
  double speed(double sigma0) const { return sigma0 * rate_; }
  // The last moment at which a contact distance sigma0 (at the origin) still fits in cells of
  // width `width`: a pair that can touch must sit in neighbouring cells (kNever without growth).
  double fits_until(double sigma0, double width) const {
    if (!on()) return kNever;
    return origin_ + (width / sigma0 - start_) / rate_;
  }

 private:
  double rate_ = 0.0;
  double origin_ = 0.0;
  double start_ = 1.0;  // the scale at the origin
};

}  // namespace kairos
