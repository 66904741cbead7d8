// Kinetic-theory predictions for granular gases, used by validation tests and the docs.
//
// Smooth inelastic spheres/disks: docs/physics.md#granular-kinetic-theory (Enskog collision
// frequency, Haff's law, van Noije–Ernst a2). Rough spheres/disks with constant e and beta:
// our mean-field (Huthmann–Zippelius type) theory of the homogeneous cooling state, derived in
// docs/theory-rough-hcs.md for equal particles (mass m, diameter sigma, I = q m sigma^2/4).
//
// Temperatures are per degree of freedom: T_tr = m<v_a^2> (d of them), T_rot = I<w_a^2> (3
// rotational degrees of freedom for spheres, 1 for disks). Every function takes the dimension d
// (2 or 3) first and throws std::invalid_argument for parameters outside their range.
#pragma once

namespace kairos {

int rotational_degrees_of_freedom(int d);  // 3 in 3D, 1 in 2D

// eta = pi n sigma^3 / 6 (3D) or pi n sigma^2 / 4 (2D).
double packing_fraction(int d, double number_density, double sigma);
// Pair correlation at contact: Carnahan–Starling (3D), Henderson (2D).
double contact_value(int d, double packing_fraction);
// Enskog collision frequency per particle: 4 sigma^2 n g sqrt(pi T/m) (3D),
// 2 sigma n g sqrt(pi T/m) (2D).
double enskog_collision_frequency(int d, double number_density, double sigma, double temperature,
                                  double mass);

// Haff's law for smooth spheres: T(t) = T0 / (1 + t/tau0)^2, tau0 = 2d / ((1 - e^2) omega_E(T0)).
double haff_time(int d, double e, double collision_frequency);
double haff_temperature(double initial_temperature, double tau0, double t);
// T/T0 after c collisions per particle (c = 2 N_coll / N): exp(-(1 - e^2) c / d).
double temperature_ratio_after_collisions(int d, double e, double collisions_per_particle);
// van Noije–Ernst Sonine coefficient a2 of the homogeneous cooling state.
double sonine_a2(int d, double e);

// Self-diffusion in the homogeneous cooling state of equal smooth inelastic spheres/disks
// (constant e in [0.6, 1], number density n, diameter sigma; Enskog's kinetic theory;
// docs/physics.md#self-diffusion-in-the-homogeneous-cooling-state). D(t) = (T/m) / (nu_D -
// zeta/2) decays with sqrt(T), but against the collisions per particle s (ds = omega dt, omega
// the collision frequency) the mean-square displacement grows linearly, <|r(s) - r(0)|^2> ->
// 2 d D_s s, with the constant D_s = D / omega. In the first Sonine approximation, with
// nu_D = (1 + e) omega_E (1 - a2/32) / d, zeta = (1 - e^2) omega_E (1 + 3 a2/16) / d and
// omega = omega_E (1 - a2/16) (omega_E the Enskog collision frequency of the Maxwellian, a2 van
// Noije–Ernst's),
//   D_s = d (T/m) / (omega_E^2 (1 - a2/16) (1 + e) [(1 + e)/2 - a2 (4 - 3e)/32]),
// independent of T; for e = 1 Enskog's D over omega_E. The higher Sonine orders multiply it by
// hcs_sonine_factor(d, e) (1.019 for elastic spheres, Chapman and Cowling's factor).
struct HcsSelfDiffusion {
  double per_collision = 0.0;  // D_s: length^2 per collision per particle (all Sonine orders)
  double reduced = 0.0;        // D_s (n sigma^(d-1))^2: a function of e and the packing fraction
  double first_sonine = 0.0;   // D_s in the first Sonine approximation
  double maxwellian = 0.0;     // the same with a2 = 0
  double sonine_factor = 0.0;  // per_collision / first_sonine
  double a2 = 0.0;             // van Noije–Ernst
  double contact_value = 0.0;  // g(sigma) of the Enskog collision frequency
};
HcsSelfDiffusion hcs_self_diffusion(int d, double e, double number_density, double sigma);
// The factor of the Sonine orders beyond the first for D_s (e in [0.6, 1]): the fifth-order
// Galerkin solution of the Boltzmann–Lorentz equation of a tagged particle in a Maxwellian gas at
// e = 0.60, 0.65, ..., 1.00 (examples/validation/hcs_sonine.py), interpolated linearly.
double hcs_sonine_factor(int d, double e);
constexpr double kHcsTheoryMinRestitution = 0.6;

// Rough spheres/disks with constant e in [0, 1], beta in [-1, 1] and q > 0.
//
// Mean kinetic-energy change of one collision (of the pair), for Maxwellian translational and
// rotational velocities at T_tr and T_rot:
//   <dE_tr>  = -(1 - e^2) T_tr - 2(d-1) eta (1 - eta) T_tr + 2(d-1) (eta^2/q) T_rot
//   <dE_rot> =  2(d-1) (eta^2/q) T_tr - 2(d-1) (eta/q)(1 - eta/q) T_rot
// with eta = q (1 + beta) / (2 (1 + q)).
struct RoughEnergyChange {
  double translational = 0.0;
  double rotational = 0.0;
};
RoughEnergyChange rough_energy_change_per_collision(int d, double e, double beta, double q,
                                                    double translational_temperature,
                                                    double rotational_temperature);

// The temperature equations in collision time (omega_E = collisions per particle per time):
//   dT_tr/dt  = omega_E (-A T_tr + B T_rot)
//   dT_rot/dt = omega_E ( B_rot T_tr - C T_rot)
struct RoughCoolingCoefficients {
  double a = 0.0, b = 0.0, b_rot = 0.0, c = 0.0;
};
RoughCoolingCoefficients rough_cooling_coefficients(int d, double e, double beta, double q);

// Cooling rates -d ln T / (omega_E dt) of both temperatures at the ratio R = T_rot / T_tr:
// translational A - B R, rotational C - B_rot / R.
struct RoughCoolingRates {
  double translational = 0.0;
  double rotational = 0.0;
};
RoughCoolingRates rough_cooling_rates(int d, double e, double beta, double q, double ratio);

// Homogeneous cooling state: the stable ratio R = T_rot / T_tr at which both rates agree, the
// positive root of B R^2 - (A - C) R - B_rot = 0. For beta = -1 the two motions decouple: the
// result is +infinity for e < 1 (T_rot stays while T_tr decays) and NaN for e = 1.
double rough_hcs_temperature_ratio(int d, double e, double beta, double q);
// The common cooling rate zeta = A - B R of the homogeneous cooling state: T_tr decays as
// Haff's law with tau0 = 2 / (zeta omega_E(T0)), and as exp(-zeta c) with c collisions per
// particle.
double rough_hcs_cooling_rate(int d, double e, double beta, double q);

}  // namespace kairos
