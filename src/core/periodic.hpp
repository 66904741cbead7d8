// Periodic boundaries: the one definition of wrapping a coordinate into the box and of the
// minimum image.
#pragma once

#include <algorithm>
#include <array>
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

// sigma_ij - r_ij of a pair at positions a and b (diameters da and db) when positive, else 0:
// the nearest image along every axis (periodic == nullptr) or along the periodic ones. The
// one overlap arithmetic of the cell search and the brute force (init/initial_state) and of
// the engine's own check (EventEngine::max_overlap_now), so that all give the same bits.
template <int D>
double pair_overlap(const std::array<double, D>& box, const std::array<double, D>& a,
                    const std::array<double, D>& b, double da, double db,
                    const std::array<bool, D>* periodic = nullptr) {
  double r2 = 0.0;
  for (int k = 0; k < D; ++k) {
    double dx = a[k] - b[k];
    if (periodic == nullptr || (*periodic)[k]) dx = minimum_image(dx, box[k]);
    r2 += dx * dx;
  }
  const double sigma = 0.5 * (da + db);
  if (!(r2 < sigma * sigma)) return 0.0;
  return std::max(0.0, sigma - std::sqrt(r2));
}

}  // namespace kairos
