#include "analysis/granular_theory.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

namespace kairos {
namespace {

void require_dimension(int d) {
  if (d != 2 && d != 3)
    throw std::invalid_argument("granular theory: the dimension must be 2 or 3, got " +
                                std::to_string(d));
}

void require_within(double x, double lo, double hi, const char* what) {
  if (!(std::isfinite(x) && x >= lo && x <= hi))
    throw std::invalid_argument(std::string("granular theory: ") + what + " must be in [" +
                                std::to_string(lo) + ", " + std::to_string(hi) + "], got " +
                                std::to_string(x));
}

void require_rough_parameters(int d, double e, double beta, double q) {
  require_dimension(d);
  require_within(e, 0.0, 1.0, "e");
  require_within(beta, -1.0, 1.0, "beta");
  if (!(std::isfinite(q) && q > 0.0))
    throw std::invalid_argument("granular theory: q must be finite and > 0, got " +
                                std::to_string(q));
}

// Tangential impulse factor: J_t = -m eta g_t for equal masses (m_t (1 + beta) = m eta).
double eta_t(double beta, double q) {
  return q * (1.0 + beta) / (2.0 * (1.0 + q));
}

}  // namespace

int rotational_degrees_of_freedom(int d) {
  require_dimension(d);
  return d == 3 ? 3 : 1;
}

double packing_fraction(int d, double number_density, double sigma) {
  require_dimension(d);
  return d == 3 ? std::numbers::pi * number_density * sigma * sigma * sigma / 6.0
                : std::numbers::pi * number_density * sigma * sigma / 4.0;
}

double contact_value(int d, double packing_fraction) {
  require_dimension(d);
  const double eta = packing_fraction;
  const double free = 1.0 - eta;
  return d == 3 ? (1.0 - eta / 2.0) / (free * free * free)
                : (1.0 - 7.0 * eta / 16.0) / (free * free);
}

double enskog_collision_frequency(int d, double number_density, double sigma, double temperature,
                                  double mass) {
  const double g = contact_value(d, packing_fraction(d, number_density, sigma));
  const double thermal = std::sqrt(std::numbers::pi * temperature / mass);
  return d == 3 ? 4.0 * sigma * sigma * number_density * g * thermal
                : 2.0 * sigma * number_density * g * thermal;
}

double haff_time(int d, double e, double collision_frequency) {
  require_dimension(d);
  return 2.0 * d / ((1.0 - e * e) * collision_frequency);
}

double haff_temperature(double initial_temperature, double tau0, double t) {
  const double s = 1.0 + t / tau0;
  return initial_temperature / (s * s);
}

double temperature_ratio_after_collisions(int d, double e, double collisions_per_particle) {
  require_dimension(d);
  return std::exp(-(1.0 - e * e) * collisions_per_particle / d);
}

double sonine_a2(int d, double e) {
  require_dimension(d);
  return 16.0 * (1.0 - e) * (1.0 - 2.0 * e * e) /
         (9.0 + 24.0 * d + (8.0 * d - 41.0) * e + 30.0 * e * e * (1.0 - e));
}

double hcs_sonine_factor(int d, double e) {
  require_dimension(d);
  require_within(e, kHcsTheoryMinRestitution, 1.0, "e");
  // examples/validation/hcs_sonine.py, order 5 (orders 4 and 5 differ by < 0.1 % for e >= 0.7,
  // 0.3 % at e = 0.6; the Monte Carlo brackets add ~0.03 %).
  static constexpr double kFactor3[] = {0.97450, 0.97878, 0.98407, 0.98933, 0.99506,
                                        1.00063, 1.00661, 1.01283, 1.01892};
  static constexpr double kFactor2[] = {0.96631, 0.97179, 0.97830, 0.98540, 0.99306,
                                        1.00117, 1.00993, 1.01843, 1.02694};
  const double* f = d == 3 ? kFactor3 : kFactor2;
  const double x = (e - kHcsTheoryMinRestitution) / 0.05;
  const int k = std::min(7, static_cast<int>(std::floor(x)));
  return f[k] + (x - k) * (f[k + 1] - f[k]);
}

HcsSelfDiffusion hcs_self_diffusion(int d, double e, double number_density, double sigma) {
  require_dimension(d);
  require_within(e, kHcsTheoryMinRestitution, 1.0, "e");
  if (!(std::isfinite(number_density) && number_density > 0.0 && std::isfinite(sigma) &&
        sigma > 0.0))
    throw std::invalid_argument("granular theory: the density and diameter must be > 0");
  HcsSelfDiffusion out;
  out.a2 = sonine_a2(d, e);
  out.contact_value = contact_value(d, packing_fraction(d, number_density, sigma));
  // T = m = 1: D_s does not depend on them.
  const double omega = enskog_collision_frequency(d, number_density, sigma, 1.0, 1.0);
  const auto first_sonine = [&](double a2) {
    return d / (omega * omega * (1.0 - a2 / 16.0) * (1.0 + e) *
                ((1.0 + e) / 2.0 - a2 * (4.0 - 3.0 * e) / 32.0));
  };
  out.first_sonine = first_sonine(out.a2);
  out.maxwellian = first_sonine(0.0);
  out.sonine_factor = hcs_sonine_factor(d, e);
  out.per_collision = out.first_sonine * out.sonine_factor;
  const double scale = number_density * (d == 3 ? sigma * sigma : sigma);
  out.reduced = out.per_collision * scale * scale;
  return out;
}

RoughEnergyChange rough_energy_change_per_collision(int d, double e, double beta, double q,
                                                    double translational_temperature,
                                                    double rotational_temperature) {
  require_rough_parameters(d, e, beta, q);
  const double eta = eta_t(beta, q);
  const double tangential = 2.0 * (d - 1);  // twice the tangential directions
  const double tt = translational_temperature, tr = rotational_temperature;
  return {
      -(1.0 - e * e) * tt - tangential * eta * (1.0 - eta) * tt + tangential * (eta * eta / q) * tr,
      tangential * (eta * eta / q) * tt - tangential * (eta / q) * (1.0 - eta / q) * tr};
}

RoughCoolingCoefficients rough_cooling_coefficients(int d, double e, double beta, double q) {
  // dT_tr/dt = omega_E <dE_tr> / d and dT_rot/dt = omega_E <dE_rot> / d_rot: each collision
  // involves two particles, each with d (d_rot) degrees of freedom of T/2 per particle.
  const RoughEnergyChange per_tr = rough_energy_change_per_collision(d, e, beta, q, 1.0, 0.0);
  const RoughEnergyChange per_rot = rough_energy_change_per_collision(d, e, beta, q, 0.0, 1.0);
  const double d_tr = d, d_rot = rotational_degrees_of_freedom(d);
  return {-per_tr.translational / d_tr, per_rot.translational / d_tr, per_tr.rotational / d_rot,
          -per_rot.rotational / d_rot};
}

RoughCoolingRates rough_cooling_rates(int d, double e, double beta, double q, double ratio) {
  const RoughCoolingCoefficients k = rough_cooling_coefficients(d, e, beta, q);
  return {k.a - k.b * ratio, k.c - k.b_rot / ratio};
}

double rough_hcs_temperature_ratio(int d, double e, double beta, double q) {
  const RoughCoolingCoefficients k = rough_cooling_coefficients(d, e, beta, q);
  // B R^2 - (A - C) R - B_rot = 0 with B, B_rot >= 0: the positive root, written without
  // cancellation for either sign of A - C.
  const double p = k.a - k.c;
  const double root = std::sqrt(p * p + 4.0 * k.b * k.b_rot);
  if (k.b == 0.0)
    return p > 0.0 ? std::numeric_limits<double>::infinity()
                   : std::numeric_limits<double>::quiet_NaN();
  return p >= 0.0 ? (p + root) / (2.0 * k.b) : 2.0 * k.b_rot / (root - p);
}

double rough_hcs_cooling_rate(int d, double e, double beta, double q) {
  const double ratio = rough_hcs_temperature_ratio(d, e, beta, q);
  if (!std::isfinite(ratio)) return rough_cooling_coefficients(d, e, beta, q).a;
  return rough_cooling_rates(d, e, beta, q, ratio).translational;
}

}  // namespace kairos
