// Fixed-size vectors for D = 2 or 3 dimensions.
//
// Plain aggregates so that records holding them stay trivially copyable and tightly packed.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>

namespace kairos {

template <int D>
using Vec = std::array<double, static_cast<std::size_t>(D)>;

template <std::size_t D>
inline std::array<double, D> operator+(const std::array<double, D>& a,
                                       const std::array<double, D>& b) {
  std::array<double, D> r;
  for (std::size_t k = 0; k < D; ++k) r[k] = a[k] + b[k];
  return r;
}
template <std::size_t D>
inline std::array<double, D> operator-(const std::array<double, D>& a,
                                       const std::array<double, D>& b) {
  std::array<double, D> r;
  for (std::size_t k = 0; k < D; ++k) r[k] = a[k] - b[k];
  return r;
}
template <std::size_t D>
inline std::array<double, D> operator*(double s, const std::array<double, D>& a) {
  std::array<double, D> r;
  for (std::size_t k = 0; k < D; ++k) r[k] = s * a[k];
  return r;
}
template <std::size_t D>
inline double dot(const std::array<double, D>& a, const std::array<double, D>& b) {
  double s = 0.0;
  for (std::size_t k = 0; k < D; ++k) s += a[k] * b[k];
  return s;
}
template <std::size_t D>
inline double norm2(const std::array<double, D>& a) {
  return dot(a, a);
}

}  // namespace kairos
