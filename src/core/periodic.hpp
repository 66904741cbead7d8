// Periodic boundaries: the one definition of wrapping a coordinate into the box and of the
// minimum image.
#pragma once

#include <cmath>

namespace kairos {

// x mapped into [0, L). Round-off can make x - L floor(x/L) come out as exactly L (or a hair
// below 0); both are folded back so the result is always inside the half-open interval.
inline double wrap_into_box(double x, double L) {
  if (x >= 0.0 && x < L) return x;
  double y = x - L * std::floor(x / L);
  if (y >= L) y -= L;
  if (y < 0.0) y = 0.0;
  return y;
}

// The minimum-image component of a separation d in a periodic box of length L.
inline double minimum_image(double d, double L) {
  if (std::abs(d) > 0.5 * L) d -= L * std::round(d / L);
  return d;
}

}  // namespace kairos
