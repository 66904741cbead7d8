// A wall with mass on a spring to a moving anchor (boundaries/wall_spring.hpp,
// docs/physics.md#the-spring-driven-container): the closed-form motion against an independent
// Runge-Kutta integration of M X'' = -k (X - a) - c (X' - a') + M g; the steady amplitude
// against the textbook base-excitation transmissibility; the anchor's work and the dashpot's
// dissipation against quadrature and against the energy they change; the refused springs.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "../interactions/input_error_matchers.hpp"
#include "boundaries/wall_body.hpp"
#include "core/error.hpp"
#include "spring_reference.hpp"

namespace kairos {
namespace {

struct Case {
  WallSpring spring;
  double mass, accel;
};

// M = 2, k = 50 (w0 = 5), c = 3 (gamma = 0.75), anchor 0.4 sin(3 t + 0.2), field -1.
const Case kCase{{50.0, 3.0, 0.4, 3.0, 0.2}, 2.0, -1.0};

// The reference integration (spring_reference.hpp) for this case.
std::pair<double, double> integrate(const Case& c, double t0, double x, double v, double t1,
                                    int n) {
  return testing::integrate_spring(c.spring, c.mass, c.accel, t0, x, v, t1, n);
}

WallBody body_of(const Case& c, double rest) {
  WallBody b;
  b.mass = c.mass;
  b.accel = c.accel;
  b.rest = rest;
  b.spring = SpringMotion(c.spring, c.mass, c.accel);
  return b;
}

TEST(WallSpring, ClosedFormMotionAgreesWithRungeKutta) {
  WallBody b = body_of(kCase, 10.0);
  b.set(1.5, 10.3, -0.8);
  for (const double t : {1.5, 1.9, 3.0, 7.5}) {
    const auto [x, v] = integrate(kCase, 1.5, 0.3, -0.8, t, 20000);
    EXPECT_NEAR(b.position_at(t) - 10.0, x, 1e-10) << t;
    EXPECT_NEAR(b.speed_at(t), v, 1e-10) << t;
  }
  // A kick changes the speed only, and the motion goes on from there.
  const double x2 = b.position_at(2.0), v2 = b.speed_at(2.0);
  b.kick(2.0, -1.0);
  EXPECT_NEAR(b.position_at(2.0), x2, 1e-14);
  EXPECT_NEAR(b.speed_at(2.0), v2 - 0.5, 1e-14);
  const auto [x, v] = integrate(kCase, 2.0, x2 - 10.0, v2 - 0.5, 4.0, 20000);
  EXPECT_NEAR(b.position_at(4.0) - 10.0, x, 1e-10);
  EXPECT_NEAR(b.speed_at(4.0), v, 1e-10);
}

// The base-excitation transmissibility |X / A| = sqrt(k^2 + (c W)^2) / sqrt((k - M W^2)^2 +
// (c W)^2) (e.g. Rao, Mechanical Vibrations, section 3.6), and the static sag M g / k.
TEST(WallSpring, SteadyAmplitudeIsTheTransmissibility) {
  for (const double w : {0.5, 3.0, 5.0, 9.0}) {
    Case c = kCase;
    c.spring.omega = w;
    const SpringMotion s(c.spring, c.mass, c.accel);
    const double k = c.spring.stiffness, d = c.spring.damping, m = c.mass;
    const double expected =
        c.spring.amplitude * std::hypot(k, d * w) / std::hypot(k - m * w * w, d * w);
    EXPECT_NEAR(s.response(), expected, 1e-13 * expected) << w;
    EXPECT_NEAR(s.sag(), m * c.accel / k, 1e-15);
    // After the transient has died out (e^(-0.75 * 60) ~ 1e-20) the wall swings with it.
    WallBody b = body_of(c, 0.0);
    b.set(0.0, 0.0, 0.0);
    double lo = 1e300, hi = -1e300;
    for (int i = 0; i < 4000; ++i) {
      const double x = b.position_at(60.0 + i * 2.0 * std::numbers::pi / w / 4000.0);
      lo = std::min(lo, x), hi = std::max(hi, x);
    }
    EXPECT_NEAR(0.5 * (hi - lo), expected, 1e-6 * expected) << w;
    EXPECT_NEAR(0.5 * (hi + lo), s.sag(), 1e-6) << w;
  }
}

// drive - dashpot is the energy's change over a flight, to round-off; each term on its own
// against Simpson's rule.
TEST(WallSpring, AnchorWorkAndDashpotCloseTheEnergy) {
  WallBody b = body_of(kCase, 0.0);
  b.set(0.7, 0.25, 1.1);
  const SpringMotion& s = b.spring;
  for (const double t1 : {0.7 + 1e-6, 0.9, 2.0, 12.0}) {
    const SpringWork w = b.work_at(t1);
    const double e0 = b.energy_at(0.7), e1 = b.energy_at(t1);
    EXPECT_NEAR(e1 - e0, w.drive - w.dashpot, 1e-12 * (std::abs(e0) + std::abs(w.drive))) << t1;
    const int n = 200000;
    double drive = 0.0, dashpot = 0.0;
    for (int i = 0; i <= n; ++i) {
      const double t = 0.7 + (t1 - 0.7) * i / n;
      const double weight = (i == 0 || i == n) ? 1.0 : (i % 2 == 1 ? 4.0 : 2.0);
      const double stretch = b.position_at(t) - s.anchor(t);
      const double rate = b.speed_at(t) - s.anchor_speed(t);
      drive += weight * -(kCase.spring.stiffness * stretch + kCase.spring.damping * rate) *
               s.anchor_speed(t);
      dashpot += weight * kCase.spring.damping * rate * rate;
    }
    drive *= (t1 - 0.7) / n / 3.0;
    dashpot *= (t1 - 0.7) / n / 3.0;
    EXPECT_NEAR(w.drive, drive, 1e-9 * (1.0 + std::abs(drive))) << t1;
    EXPECT_NEAR(w.dashpot, dashpot, 1e-9 * (1.0 + dashpot)) << t1;
  }
  // A kick keeps the sums up to it.
  const SpringWork before = b.work_at(3.0);
  b.kick(3.0, 0.4);
  EXPECT_EQ(b.work.drive, before.drive);
  EXPECT_EQ(b.work.dashpot, before.dashpot);
}

TEST(WallSpring, OverdampedAndUndampedResonantSpringsAreRefused) {
  EXPECT_INPUT_ERROR((void)SpringMotion(WallSpring{50.0, 20.0, 0.4, 3.0, 0.0}, 2.0, 0.0),
                     "underdamped");
  EXPECT_INPUT_ERROR((void)SpringMotion(WallSpring{50.0, 0.0, 0.4, 5.0, 0.0}, 2.0, 0.0),
                     "resonance");
}

}  // namespace
}  // namespace kairos
