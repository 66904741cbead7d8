#include "boundaries/wall_spring.hpp"

#include <array>
#include <cmath>
#include <numbers>
#include <string>

#include "core/error.hpp"

namespace kairos {
namespace {

using Complex = std::complex<double>;

// (e^w - 1) / w, accurate near w = 0 (where e^w - 1 cancels) by its series.
Complex expm1_over(Complex w) {
  if (std::abs(w) < 0.5) {
    Complex sum = 1.0, term = 1.0;
    for (int n = 2; n < 24; ++n) {
      term *= w / static_cast<double>(n);
      sum += term;
    }
    return sum;
  }
  return (std::exp(w) - 1.0) / w;
}

// A signal Re[c e^(mu s)] of the time s since the flight began.
struct Mode {
  Complex c;
  Complex mu;
};

// The integral over [0, T] of the product of two sums of modes:
// Re[x e^(mu s)] Re[y e^(nu s)] = Re[x y e^((mu + nu) s) + x conj(y) e^((mu + conj(nu)) s)] / 2.
template <std::size_t N, std::size_t M>
double integral_of_product(const std::array<Mode, N>& x, const std::array<Mode, M>& y, double T) {
  double sum = 0.0;
  for (const Mode& a : x) {
    for (const Mode& b : y) {
      const Complex same = a.c * b.c * T * expm1_over((a.mu + b.mu) * T);
      const Complex conj = a.c * std::conj(b.c) * T * expm1_over((a.mu + std::conj(b.mu)) * T);
      sum += 0.5 * (same + conj).real();
    }
  }
  return sum;
}

}  // namespace

SpringProblem spring_problem(const WallSpring& spring, double mass) {
  if (!spring.on()) return SpringProblem::kNone;
  const double k = spring.stiffness, c = spring.damping, W = spring.omega;
  if (!(c < 2.0 * std::sqrt(k * mass))) return SpringProblem::kOverdamped;
  if (c == 0.0 && spring.amplitude != 0.0 && std::abs(k - mass * W * W) <= 1e-9 * k)
    return SpringProblem::kResonant;
  return SpringProblem::kNone;
}

SpringMotion::SpringMotion(const WallSpring& spring, double mass, double accel)
    : spring_(spring), mass_(mass), accel_(accel) {
  if (!spring.on()) return;
  const double k = spring.stiffness, c = spring.damping;
  switch (spring_problem(spring, mass)) {
    case SpringProblem::kOverdamped:
      throw InputError(
          "boundary.container: the spring is critically damped or overdamped (damping " +
          std::to_string(c) +
          " >= 2 sqrt(stiffness mass) = " + std::to_string(2.0 * std::sqrt(k * mass)) +
          "); only an underdamped spring is supported: lower spring_damping");
    case SpringProblem::kResonant:
      throw InputError(
          "boundary.container: an undamped spring driven at its resonance (drive_frequency "
          "equals sqrt(spring_stiffness / mass) / 2 pi) has no steady motion: its amplitude "
          "grows without bound; give the spring some damping or drive it off resonance");
    case SpringProblem::kNone:
      break;
  }
  w0_ = std::sqrt(k / mass);
  gamma_ = c / (2.0 * mass);
  wd_ = std::sqrt((w0_ - gamma_) * (w0_ + gamma_));
  sag_ = accel / (w0_ * w0_);
  const double W = spring.omega;
  const Complex denominator{k - mass * W * W, c * W};
  gain_ = spring.amplitude != 0.0 ? Complex{k, c * W} / denominator : Complex{1.0, 0.0};
  response_ = std::abs(gain_) * spring.amplitude;
  psi_ = std::arg(gain_);
}

double SpringMotion::phase_at(double t) const {
  return std::remainder(spring_.omega * t + spring_.phase, 2.0 * std::numbers::pi);
}

double SpringMotion::steady(double t) const {
  return sag_ + response_ * std::sin(phase_at(t) + psi_);
}
double SpringMotion::steady_speed(double t) const {
  return response_ * spring_.omega * std::cos(phase_at(t) + psi_);
}
double SpringMotion::anchor(double t) const {
  return spring_.amplitude * std::sin(phase_at(t));
}
double SpringMotion::anchor_speed(double t) const {
  return spring_.amplitude * spring_.omega * std::cos(phase_at(t));
}

std::pair<double, double> SpringMotion::transient_at(double x, double v, double t) const {
  const double h0 = x - steady(t);
  const double h1 = v - steady_speed(t);
  return {h0, (h1 + gamma_ * h0) / wd_};
}

std::pair<double, double> SpringMotion::transient_coefficients(double h0, double b0,
                                                               double s) const {
  const double e = std::exp(-gamma_ * s);
  const double c = std::cos(wd_ * s), sn = std::sin(wd_ * s);
  return {e * (h0 * c + b0 * sn), e * (b0 * c - h0 * sn)};
}

double SpringMotion::transient(double h0, double b0, double s) const {
  return transient_coefficients(h0, b0, s).first;
}
double SpringMotion::transient_speed(double h0, double b0, double s) const {
  return std::exp(-gamma_ * s) * ((-gamma_ * h0 + wd_ * b0) * std::cos(wd_ * s) +
                                  (-gamma_ * b0 - wd_ * h0) * std::sin(wd_ * s));
}

double SpringMotion::energy(double x, double v, double t) const {
  const double stretch = x - anchor(t);
  return 0.5 * mass_ * v * v + 0.5 * spring_.stiffness * stretch * stretch - mass_ * accel_ * x;
}

// With C = A e^(i theta0) the anchor's phasor at t0, H = h0 - i b0 and lambda = -gamma + i wd:
//   X - a   = X_s + Re[H e^(lambda s)] + Re[-i (G - 1) C e^(i W s)],
//   X' - a' = Re[lambda H e^(lambda s)] + Re[W (G - 1) C e^(i W s)],   a' = Re[W C e^(i W s)];
// the anchor's work is -int (k (X - a) + c (X' - a')) a' ds, the dashpot's dissipation
// c int (X' - a')^2 ds.
SpringWork SpringMotion::flight_work(double t0, double h0, double b0, double t1) const {
  const double T = t1 - t0;
  if (!(T > 0.0)) return {};
  const double k = spring_.stiffness, c = spring_.damping, W = spring_.omega;
  const Complex C = std::polar(spring_.amplitude, phase_at(t0));
  const Complex H{h0, -b0};
  const Complex lambda{-gamma_, wd_};
  const Complex iW{0.0, W};
  const Complex G1 = gain_ - 1.0;
  const std::array<Mode, 3> force{Mode{k * sag_, 0.0}, Mode{(k + c * lambda) * H, lambda},
                                  Mode{Complex{c * W, -k} * G1 * C, iW}};
  const std::array<Mode, 1> anchor_speed{Mode{W * C, iW}};
  const std::array<Mode, 2> stretch_rate{Mode{lambda * H, lambda}, Mode{W * G1 * C, iW}};
  return {-integral_of_product(force, anchor_speed, T),
          c * integral_of_product(stretch_rate, stretch_rate, T)};
}

}  // namespace kairos
