// A wall with mass on a spring: tied by a spring of stiffness k and a dashpot c (in parallel) to
// an anchor that moves along the wall's axis as a(t) = A sin(W t + phi), displacements counted
// from the wall's rest place (its face). Between the particles' kicks the wall's displacement X
// obeys M X'' = -k (X - a) - c (X' - a') + M g (g: its constant force over M plus the field),
// a driven, damped oscillator, solved in closed form (docs/physics.md#the-spring-driven-container):
//   X(t) = X_s + P sin(W t + phi + psi) + e^(-gamma s) (h0 cos(wd s) + b0 sin(wd s)),
// s the time since the last kick, X_s = g / w0^2 the static sag, P e^(i psi) = A G with the
// base-excitation gain G = (k + i c W) / (k - M W^2 + i c W), w0^2 = k / M, gamma = c / 2M,
// wd^2 = w0^2 - gamma^2 (underdamped: gamma < w0). Its mechanical energy is
//   E = M X'^2 / 2 + k (X - a)^2 / 2 - M g X,
// which changes between kicks by the anchor's work on the spring and dashpot less the
// dashpot's dissipation, both integrated in closed form here (flight_work), so the energy
// budget closes to round-off.
#pragma once

#include <complex>
#include <utility>

namespace kairos {

struct WallSpring {
  double stiffness = 0.0;  // k; 0: no spring
  double damping = 0.0;    // c
  double amplitude = 0.0;  // A, of the anchor
  double omega = 0.0;      // W, the anchor's angular frequency
  double phase = 0.0;      // phi
  bool on() const { return stiffness > 0.0; }
  bool operator==(const WallSpring&) const = default;
};

// Springs that cannot be run: critically damped or overdamped (c >= 2 sqrt(k M): the event
// search needs the underdamped transient), or undamped and driven at its resonance (within 1e-9
// of k = M W^2: no steady motion). The reader names the keys; SpringMotion throws.
enum class SpringProblem { kNone, kOverdamped, kResonant };
SpringProblem spring_problem(const WallSpring& spring, double mass);

// The anchor's work on the spring and dashpot, and what the dashpot dissipated, over a time.
struct SpringWork {
  double drive = 0.0;
  double dashpot = 0.0;
};

class SpringMotion {
 public:
  SpringMotion() = default;
  // Throws InputError if the spring is overdamped (gamma >= w0) or undamped at resonance.
  SpringMotion(const WallSpring& spring, double mass, double accel);

  bool on() const { return spring_.on(); }
  const WallSpring& spring() const { return spring_; }
  double gamma() const { return gamma_; }
  double wd() const { return wd_; }
  double sag() const { return sag_; }
  double response() const { return response_; }   // P
  double response_phase() const { return psi_; }  // psi
  double w0() const { return w0_; }
  // The steady response's phase W t + phi + psi at absolute time t (W t + phi reduced first).
  double response_phase_at(double t) const { return phase_at(t) + psi_; }

  // The steady part X_s + P sin(W t + phi + psi) and its speed, at absolute time t; the anchor.
  double steady(double t) const;
  double steady_speed(double t) const;
  double anchor(double t) const;
  double anchor_speed(double t) const;
  // The transient's coefficients (h0, b0) of a wall at displacement x and speed v at time t.
  std::pair<double, double> transient_at(double x, double v, double t) const;
  // The transient's value and its derivative s after it had (h0, b0).
  double transient(double h0, double b0, double s) const;
  // The transient's coefficients a time s after it had (h0, b0): e^(-gamma s) times (h0, b0)
  // turned by wd s, so that from then on it is e^(-gamma r) (h cos(wd r) + b sin(wd r)).
  std::pair<double, double> transient_coefficients(double h0, double b0, double s) const;
  double transient_speed(double h0, double b0, double s) const;
  // Its mechanical energy at displacement x, speed v, time t.
  double energy(double x, double v, double t) const;
  // The anchor's work and the dashpot's dissipation from t0 (transient (h0, b0)) to t1.
  SpringWork flight_work(double t0, double h0, double b0, double t1) const;

 private:
  WallSpring spring_{};
  double mass_ = 0.0;
  double accel_ = 0.0;
  double w0_ = 0.0, gamma_ = 0.0, wd_ = 0.0, sag_ = 0.0, response_ = 0.0, psi_ = 0.0;
  std::complex<double> gain_{};
  double phase_at(double t) const;  // W t + phi, reduced to [-pi, pi]
};

}  // namespace kairos
