// Event times of accelerated trajectories: the rule of docs/physics.md#stable-event-rule and the
// values of docs/physics.md#quartic-pair-contact, plus randomized checks against dense
// brute-force sampling (the solver must never report a later event than the first sampled one,
// and at its time the stable-rule condition must hold).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "dynamics/collision_time.hpp"
#include "dynamics/trajectory_events.hpp"

namespace kairos {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// ---------------------------------------------------------------------------------------------
// quadratic_event_time (docs/physics.md#accelerated-motion)

TEST(QuadraticEventTime, PositiveCurvatureIsTheContactQuadratic) {
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  for (int i = 0; i < 1000; ++i) {
    const double a = u(rng), b = u(rng), c = std::fabs(u(rng)) + 1e-3;
    EXPECT_EQ(quadratic_event_time(a, b, c), quadratic_contact_time(a, b, c));
  }
}

TEST(QuadraticEventTime, NegativeCurvature) {
  EXPECT_DOUBLE_EQ(quadratic_event_time(1.0, 0.0, -1.0), 1.0);   // closing gap
  EXPECT_DOUBLE_EQ(quadratic_event_time(0.0, 2.0, -1.0), 2.0);   // leaves, comes back at 2
  EXPECT_EQ(quadratic_event_time(-1.0, -1.0, -1.0), 0.0);        // overlapping, approaching
  EXPECT_DOUBLE_EQ(quadratic_event_time(-1.0, 1.0, -1.0), 0.5);  // turns while overlapping
  EXPECT_EQ(quadratic_event_time(0.0, 0.0, -1.0), 0.0);          // resting, pushed in: now
  // Overlapping, rising, and back out before turning: the later root.
  EXPECT_DOUBLE_EQ(quadratic_event_time(-0.75, 2.0, -1.0), 1.5);
}

TEST(QuadraticEventTime, ZeroCurvature) {
  EXPECT_DOUBLE_EQ(quadratic_event_time(2.0, -1.0, 0.0), 2.0);
  EXPECT_EQ(quadratic_event_time(-2.0, -1.0, 0.0), 0.0);
  EXPECT_EQ(quadratic_event_time(2.0, 1.0, 0.0), kNever);
  EXPECT_EQ(quadratic_event_time(-2.0, 0.0, 0.0), kNever);  // overlapping at rest: no approach
}

// ---------------------------------------------------------------------------------------------
// interval_exit_time_accelerated

double trajectory(double x, double v, double a, double t) {
  return x + v * t + 0.5 * a * t * t;
}

TEST(IntervalExitAccelerated, ZeroAccelerationIsTheBallisticExit) {
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> u(-1.0, 2.0);
  for (int i = 0; i < 1000; ++i) {
    const double x = u(rng), v = u(rng) - 0.5;
    EXPECT_EQ(interval_exit_time_accelerated(x, v, 0.0, 0.0, 1.0),
              interval_exit_time(x, v, 0.0, 1.0));
  }
  EXPECT_EQ(interval_exit_time_accelerated(0.5, 0.0, 0.0, 0.0, 1.0), kNever);
}

TEST(IntervalExitAccelerated, AnalyticExits) {
  EXPECT_DOUBLE_EQ(interval_exit_time_accelerated(0.5, 0.0, -1.0, 0.0, 1.0), 1.0);  // falls
  // Thrown up, peaks at 0.6 inside, falls back out through lo.
  EXPECT_DOUBLE_EQ(interval_exit_time_accelerated(0.1, 1.0, -1.0, 0.0, 10.0), 1.0 + std::sqrt(1.2));
  // Thrown up hard enough to reach hi.
  EXPECT_DOUBLE_EQ(interval_exit_time_accelerated(0.1, 2.0, -1.0, 0.0, 1.0), 2.0 - std::sqrt(2.2));
  // Launched downwards against an upward acceleration, turning before lo: exits through hi.
  EXPECT_DOUBLE_EQ(interval_exit_time_accelerated(0.5, -0.5, 1.0, 0.0, 1.0), 0.5 + std::sqrt(1.25));
}

TEST(IntervalExitAccelerated, Faces) {
  EXPECT_EQ(interval_exit_time_accelerated(1.0, 1.0, -1.0, 0.0, 1.0), 0.0);  // on hi, outward
  EXPECT_EQ(interval_exit_time_accelerated(0.0, -1.0, 1.0, 0.0, 1.0), 0.0);  // on lo, outward
  EXPECT_EQ(interval_exit_time_accelerated(0.0, 0.0, -1.0, 0.0, 1.0), 0.0);  // at rest, pulled out
  EXPECT_DOUBLE_EQ(interval_exit_time_accelerated(0.0, 0.0, 2.0, 0.0, 1.0), 1.0);  // pulled in
  // On lo moving inward under gravity: back at lo after 2 v / g, not at 0.
  EXPECT_DOUBLE_EQ(interval_exit_time_accelerated(0.0, 1.0, -1.0, 0.0, 10.0), 2.0);
}

TEST(IntervalExitAccelerated, SlightlyOutsideExitsOnlyWhenMovingOutward) {
  const double out = 1.0 + 1e-15;
  EXPECT_EQ(interval_exit_time_accelerated(out, 1.0, -1.0, 0.0, 1.0), 0.0);
  EXPECT_EQ(interval_exit_time_accelerated(out, 0.0, 1.0, 0.0, 1.0), 0.0);
  // Moving inward: treated as on the face; falls through the cell to lo.
  EXPECT_DOUBLE_EQ(interval_exit_time_accelerated(out, 0.0, -2.0, 0.0, 1.0), 1.0);
  EXPECT_DOUBLE_EQ(interval_exit_time_accelerated(out, -1.0, 1.0, 0.0, 1.0), 2.0);  // returns
  EXPECT_EQ(interval_exit_time_accelerated(-1e-15, -1.0, 1.0, 0.0, 1.0), 0.0);
}

TEST(IntervalExitAccelerated, UnboundedSides) {
  EXPECT_EQ(interval_exit_time_accelerated(0.0, 1.0, -1.0, -kInf, kInf), kNever);
  EXPECT_EQ(interval_exit_time_accelerated(0.0, 1.0, -1.0, -kInf, 0.6), kNever);  // peaks at 0.5
  EXPECT_DOUBLE_EQ(interval_exit_time_accelerated(0.0, 1.0, -1.0, -kInf, 0.4),
                   1.0 - std::sqrt(0.2));
  EXPECT_EQ(interval_exit_time_accelerated(5.0, -3.0, 1.0, 0.0, kInf), kNever);  // turns at 0.5
  EXPECT_DOUBLE_EQ(interval_exit_time_accelerated(5.0, -3.0, 1.0, -kInf, 5.5),
                   3.0 + std::sqrt(10.0));
}

TEST(IntervalExitAccelerated, Horizon) {
  EXPECT_EQ(interval_exit_time_accelerated(0.5, 0.0, -1.0, 0.0, 1.0, 0.99), kNever);
  EXPECT_DOUBLE_EQ(interval_exit_time_accelerated(0.5, 0.0, -1.0, 0.0, 1.0, 1.01), 1.0);
  EXPECT_EQ(interval_exit_time_accelerated(0.5, 1.0, 0.0, 0.0, 1.0, 0.4), kNever);
}

TEST(IntervalExitAccelerated, RandomAgainstSampling) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < 5000; ++i) {
    const double lo = -u(rng), hi = u(rng) + 1e-3;
    double x = lo + (hi - lo) * u(rng);
    const int mode = i % 5;  // on a face, just outside one, or anywhere inside
    if (mode == 1) x = hi;
    if (mode == 2) x = lo;
    if (mode == 3) x = std::nextafter(hi, kInf);
    if (mode == 4) x = lo - 1e-15;
    const double v = 4.0 * u(rng) - 2.0;
    const double a = (i % 7 == 0) ? 0.0 : 6.0 * u(rng) - 3.0;
    const double t = interval_exit_time_accelerated(x, v, a, lo, hi);
    ASSERT_TRUE(t >= 0.0) << i;  // not negative, not NaN
    if (a == 0.0 && v == 0.0) continue;
    ASSERT_TRUE(std::isfinite(t)) << i;  // a finite cell is always left
    const double xt = trajectory(x, v, a, t);
    const double tol = 1e-12;
    EXPECT_TRUE(std::fabs(xt - lo) <= tol || std::fabs(xt - hi) <= tol) << i << " " << xt;
    // Never outside before t (x may start outside by round-off only).
    for (int k = 1; k < 200; ++k) {
      const double xs = trajectory(x, v, a, t * k / 200.0);
      ASSERT_TRUE(xs >= lo - tol && xs <= hi + tol) << i << " " << k;
    }
    // And it really leaves: just after t it is outside (unless grazing).
    const double dt = 1e-6 * (1.0 + t);
    const double after = trajectory(x, v, a, t + dt);
    EXPECT_TRUE(after < lo || after > hi || std::fabs(v + a * t) < 1e-5) << i;
  }
}

// ---------------------------------------------------------------------------------------------
// Fixed and moving planes

NormalMotion motion(double height, double velocity, double accel) {
  return NormalMotion{height, velocity, accel};
}

TEST(PlaneEvents, NormalMotionProjectsOntoTheNormal) {
  const double n[3] = {0.0, 0.6, 0.8};
  const double x[3] = {5.0, 1.0, 2.0}, v[3] = {7.0, -1.0, 0.5}, g[3] = {0.0, 0.0, -1.0};
  const NormalMotion m = normal_motion<3>(n, x, v, g, 0.5);
  EXPECT_DOUBLE_EQ(m.height, 0.6 + 1.6 - 0.5);
  EXPECT_DOUBLE_EQ(m.velocity, -0.6 + 0.4);
  EXPECT_DOUBLE_EQ(m.accel, -0.8);
}

TEST(PlaneEvents, DropOntoFloor) {
  EXPECT_DOUBLE_EQ(fixed_plane_event_time(motion(2.0, 0.0, -1.0), 0.0), 2.0);
  EXPECT_DOUBLE_EQ(fixed_plane_event_time(motion(3.0, 0.0, -1.0), 1.0), 2.0);  // offset plane
  EXPECT_EQ(fixed_plane_event_time(motion(2.0, 0.0, -1.0), 0.0, 1.9), kNever);
}

TEST(PlaneEvents, BouncingBallFlightTimeIsExact) {
  // Leaving the floor upward at v returns at exactly 2 v / g; t = 0 is not an event.
  for (const double v : {1e-8, 0.1, 0.3, 1.0, 7.0, 123.456}) {
    for (const double g : {0.01, 1.0, 9.81}) {
      EXPECT_EQ(fixed_plane_event_time(motion(0.0, v, -g), 0.0), 2.0 * v / g) << v << " " << g;
      EXPECT_EQ(fixed_plane_event_time(motion(4.0, v, -g), 4.0), 2.0 * v / g) << v << " " << g;
    }
  }
}

TEST(PlaneEvents, RestingContact) {
  // f = 0, f' = 0, f'' < 0: f' < 0 right after while f <= 0, so the stable rule says now. The
  // engine must handle the zero-speed contact (see trajectory_events.hpp).
  EXPECT_EQ(fixed_plane_event_time(motion(0.0, 0.0, -1.0), 0.0), 0.0);
  EXPECT_EQ(fixed_plane_event_time(motion(0.0, 0.0, 0.0), 0.0), kNever);     // no force: rests
  EXPECT_EQ(fixed_plane_event_time(motion(0.0, 0.0, 1.0), 0.0), kNever);     // pulled away
  EXPECT_EQ(fixed_plane_event_time(motion(0.0, 1.0, 0.0), 0.0), kNever);     // leaving
  EXPECT_EQ(fixed_plane_event_time(motion(-1e-12, 0.0, -1.0), 0.0), 0.0);    // round-off below
  EXPECT_EQ(fixed_plane_event_time(motion(-1e-12, -1.0, 0.0), 0.0), 0.0);    // overlap, approach
  EXPECT_EQ(fixed_plane_event_time(motion(-1e-12, 1.0, 0.0), 0.0), kNever);  // overlap, recede
}

TEST(PlaneEvents, GrazingParallelMotionNeverCollides) {
  EXPECT_EQ(fixed_plane_event_time(motion(0.0, 0.0, 0.0), 0.0), kNever);
  EXPECT_EQ(fixed_plane_event_time(motion(1e-300, 0.0, 0.0), 0.0), kNever);
  // Thrown down against an upward pull, turning just above the plane: no event.
  EXPECT_EQ(fixed_plane_event_time(motion(0.5 + 1e-12, -1.0, 1.0), 0.0), kNever);
  EXPECT_GT(fixed_plane_event_time(motion(0.5 - 1e-9, -1.0, 1.0), 0.0), 0.999);
}

TEST(PlaneEvents, MovingPlane) {
  // A piston rising at 0.5 toward a particle at rest 1 above it; in-plane motion is irrelevant.
  EXPECT_DOUBLE_EQ(moving_plane_event_time(motion(1.0, 0.0, 0.0), 0.0, 0.5), 2.0);
  EXPECT_EQ(moving_plane_event_time(motion(1.0, 0.0, 0.0), 0.0, -0.5), kNever);
  // Falling particle (g = 1) meeting a rising piston: 1 - 0.5 t^2 = 0.5 t... t = -0.5+sqrt(2.25).
  EXPECT_DOUBLE_EQ(moving_plane_event_time(motion(1.0, 0.0, -1.0), 0.0, 0.5), 1.0);
  // A particle resting on a plane that moves along it, and one receding with it.
  EXPECT_EQ(moving_plane_event_time(motion(0.0, 0.5, 0.0), 0.0, 0.5), kNever);
  EXPECT_EQ(moving_plane_event_time(motion(0.0, 0.0, 0.0), 0.0, 0.5), 0.0);  // plane pushes in
  EXPECT_EQ(moving_plane_event_time(motion(1.0, 0.0, 0.0), 0.0, 0.5, 1.5), kNever);
}

// ---------------------------------------------------------------------------------------------
// Vibrated plane

struct GapSample {
  double f, df;
};

GapSample vibrated_gap(const NormalMotion& m, const VibratedPlane& p, double t) {
  const double poly = m.height - p.d0 + m.velocity * t + 0.5 * m.accel * t * t;
  return {poly - p.amplitude * std::sin(p.omega * t + p.phase),
          m.velocity + m.accel * t - p.amplitude * p.omega * std::cos(p.omega * t + p.phase)};
}

TEST(VibratedPlane, OffsetVelocityAndRephase) {
  const VibratedPlane p{1.0, 0.5, 3.0, 0.25};
  EXPECT_DOUBLE_EQ(vibrated_plane_offset(p, 0.7), 1.0 + 0.5 * std::sin(2.1 + 0.25));
  EXPECT_DOUBLE_EQ(vibrated_plane_velocity(p, 0.7), 1.5 * std::cos(2.1 + 0.25));
  const VibratedPlane q = rephased(p, 100.0);
  EXPECT_LE(std::fabs(q.phase), M_PI);
  EXPECT_NEAR(vibrated_plane_offset(q, 0.7), vibrated_plane_offset(p, 100.7), 1e-12);
}

TEST(VibratedPlane, ZeroAmplitudeIsTheFixedPlane) {
  const NormalMotion m = motion(2.0, 0.3, -1.0);
  EXPECT_EQ(vibrated_plane_event_time(m, {0.5, 0.0, 3.0, 0.0}), fixed_plane_event_time(m, 0.5));
  EXPECT_EQ(vibrated_plane_event_time(m, {0.5, 0.2, 0.0, 0.3}),
            fixed_plane_event_time(m, 0.5 + 0.2 * std::sin(0.3)));
}

TEST(VibratedPlane, RisingPlaneHitsParticleAtRest) {
  // No gravity: the event is where A sin(w t + phi) first climbs through the particle.
  const NormalMotion m = motion(0.5, 0.0, 0.0);
  EXPECT_NEAR(vibrated_plane_event_time(m, {0.0, 1.0, 50.0, 0.0}), M_PI / 300.0, 1e-15);
  // Plane moving down first: it hits on the way up in the next period.
  EXPECT_NEAR(vibrated_plane_event_time(m, {0.0, 1.0, 50.0, M_PI}), (M_PI + M_PI / 6.0) / 50.0,
              1e-14);
  // Large amplitude and frequency, particle just below the plane's top.
  const NormalMotion high = motion(4.9, 0.0, 0.0);
  EXPECT_NEAR(vibrated_plane_event_time(high, {0.0, 5.0, 200.0, 0.0}), std::asin(0.98) / 200.0,
              1e-14);
  // Just above the top: never, even over a long horizon (the global bound settles it at once).
  EXPECT_EQ(vibrated_plane_event_time(motion(5.0 + 1e-9, 0.0, 0.0), {0.0, 5.0, 200.0, 0.0}),
            kNever);
  // With gravity, a falling particle at rest 1 above the top of a violently shaken plate.
  const NormalMotion falling = motion(1.05, 0.0, -1.0);
  const VibratedPlane plate{0.0, 0.05, 400.0, 0.0};
  const double t = vibrated_plane_event_time(falling, plate);
  EXPECT_GE(t, std::sqrt(2.0));  // cannot reach the top before falling 1
  EXPECT_LE(t, std::sqrt(2.2));  // and has met the plate when it is at the bottom
  EXPECT_NEAR(vibrated_gap(falling, plate, t).f, 0.0, 1e-13);
  EXPECT_LT(vibrated_gap(falling, plate, t).df, 0.0);
}

TEST(VibratedPlane, DepartureIsNotAnEvent) {
  // On the plane, leaving it faster than it moves: the next event is after a flight.
  const VibratedPlane p{0.0, 0.01, 20.0, 0.0};  // plane at d0, moving up at 0.2
  const NormalMotion m = motion(0.0, 1.2, -1.0);
  const double t = vibrated_plane_event_time(m, p);
  EXPECT_GT(t, 1.5);  // roughly 2 (1.2 - 0.2) / 1 plus the plane's wobble
  EXPECT_LT(t, 2.6);
  EXPECT_NEAR(vibrated_gap(m, p, t).f, 0.0, 1e-13);
  // Same with the particle slightly inside the plane by round-off.
  EXPECT_NEAR(vibrated_plane_event_time(motion(-1e-16, 1.2, -1.0), p), t, 1e-9);
}

TEST(VibratedPlane, RestingContact) {
  // Resting on the plate at its top. If the plate decelerates faster than gravity the particle
  // lifts off (no event now); otherwise gravity presses it in: event now.
  const VibratedPlane p{0.0, 0.1, 10.0, M_PI / 2.0};  // A w^2 = 10
  EXPECT_GT(vibrated_plane_event_time(motion(0.1, 0.0, -1.0), p), 0.0);
  EXPECT_EQ(vibrated_plane_event_time(motion(0.1, 0.0, -20.0), p), 0.0);
}

TEST(VibratedPlane, OverlapTurningIsTheEvent) {
  // Inside the plate, rising relative to it, and then overtaken by it while still inside:
  // the event is where the relative speed turns negative, with f <= 0 there.
  const VibratedPlane p{0.0, 0.1, 10.0, -M_PI / 2.0};  // plate at its bottom, about to rise
  const NormalMotion m = motion(-0.2, 0.5, 0.0);
  const double t = vibrated_plane_event_time(m, p);
  const GapSample at = vibrated_gap(m, p, t);
  EXPECT_LE(at.f, 0.0);
  EXPECT_NEAR(at.df, 0.0, 1e-12);
  for (int k = 0; k < 1000; ++k) {  // receding (f' >= 0) before it
    EXPECT_GE(vibrated_gap(m, p, t * k / 1000.0).df, -1e-12);
  }
}

TEST(VibratedPlane, Horizon) {
  const NormalMotion m = motion(0.5, 0.0, 0.0);
  const VibratedPlane p{0.0, 1.0, 50.0, 0.0};
  EXPECT_EQ(vibrated_plane_event_time(m, p, 0.01), kNever);
  EXPECT_NEAR(vibrated_plane_event_time(m, p, 0.011), M_PI / 300.0, 1e-15);
}

// The stable-rule event from samples: the first grid time with f <= -tol and f' < -tol (a
// clearly overlapping, clearly approaching state), or +inf.
template <class Gap>
double first_sampled_event(Gap gap, double horizon, int samples, double tol) {
  for (int k = 0; k <= samples; ++k) {
    const double t = horizon * k / samples;
    const auto s = gap(t);
    if (s.f <= -tol && s.df < -tol) return t;
  }
  return kInf;
}

// A solver's event time t for a random case (gap's jet at relative times, up to the horizon)
// against dense sampling: never later than the first sampled event (no event skipped), and at
// t the stable-rule condition, in contact (or overlapping) and not receding; reached from an
// open gap, a contact (f = 0 up to round-off). `event`: whether t is an event.
template <class Gap>
void check_against_sampling(double t, Gap gap, double horizon, bool& event) {
  ASSERT_TRUE(t >= 0.0);
  const double brute = first_sampled_event(gap, horizon, 10000, 1e-9);
  ASSERT_LE(t, brute + 1e-12);
  event = t != kNever;
  if (!event) return;
  ASSERT_LE(t, horizon);
  const GapSample at = gap(t);
  ASSERT_LE(at.f, 1e-12);
  ASSERT_LE(at.df, 1e-9);
  if (gap(0.0).f > 1e-12) {
    ASSERT_NEAR(at.f, 0.0, 1e-12);
  }
}

TEST(VibratedPlane, RandomAgainstSampling) {
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int events = 0;
  for (int i = 0; i < 3000; ++i) {
    NormalMotion m =
        motion(3.0 * u(rng) - 0.5, 6.0 * u(rng) - 3.0, (i % 4 == 0) ? 0.0 : 2.5 * u(rng) - 2.0);
    const VibratedPlane p{0.0, u(rng), 0.1 + 30.0 * u(rng), 2.0 * M_PI * u(rng) - M_PI};
    if (i % 3 == 0) m.height = vibrated_plane_offset(p, 0.0);  // starts on the plate
    const double horizon = 0.5 + 4.5 * u(rng);
    const double t = vibrated_plane_event_time(m, p, horizon);
    bool event = false;
    check_against_sampling(
        t, [&](double s) { return vibrated_gap(m, p, s); }, horizon, event);
    if (::testing::Test::HasFatalFailure()) FAIL() << "case " << i;
    events += event ? 1 : 0;
  }
  EXPECT_GT(events, 1000);
}

// ---------------------------------------------------------------------------------------------
// Oscillating plane (a wall with mass on a spring, boundaries/wall_spring.hpp)

// The offset written out here from its formula, independently of the solver's jet.
GapSample oscillating_gap(const NormalMotion& m, const OscillatingPlane& p, double t) {
  const double e = std::exp(-p.gamma * t);
  const double c = std::cos(p.wd * t), s = std::sin(p.wd * t);
  const double d = p.d0 + e * (p.u * c + p.b * s) + p.amplitude * std::sin(p.omega * t + p.phase);
  const double dd = -p.gamma * e * (p.u * c + p.b * s) + e * p.wd * (p.b * c - p.u * s) +
                    p.amplitude * p.omega * std::cos(p.omega * t + p.phase);
  return {m.height + m.velocity * t + 0.5 * m.accel * t * t - d, m.velocity + m.accel * t - dd};
}

TEST(OscillatingPlane, OffsetAndItsDerivativesAgreeWithFiniteDifferences) {
  const OscillatingPlane p{0.3, 0.7, -0.4, 0.2, 2.5, 0.6, 3.1, 0.4};
  for (const double t : {0.0, 0.37, 1.9, 6.0}) {
    const double h = 1e-5;
    const OffsetJet j = oscillating_plane_offset(p, t);
    const OffsetJet lo = oscillating_plane_offset(p, t - h);
    const OffsetJet hi = oscillating_plane_offset(p, t + h);
    EXPECT_NEAR(j.d1, (hi.d - lo.d) / (2.0 * h), 1e-8) << t;
    EXPECT_NEAR(j.d2, (hi.d1 - lo.d1) / (2.0 * h), 1e-8) << t;
    EXPECT_NEAR(j.d, -oscillating_gap({0.0, 0.0, 0.0}, p, t).f, 1e-14) << t;
  }
}

TEST(OscillatingPlane, WithoutTransientItIsTheVibratedPlane) {
  const NormalMotion m = motion(0.8, -0.5, -1.0);
  const OscillatingPlane p{0.1, 0.0, 0.0, 0.3, 2.0, 0.25, 7.0, 0.5};
  const VibratedPlane v{0.1, 0.25, 7.0, 0.5};
  EXPECT_NEAR(oscillating_plane_event_time(m, p), vibrated_plane_event_time(m, v), 1e-12);
}

// A particle at rest at height 1; the plane, released at rest from -2 (a pure transient, u = -2
// and b = -2 gamma / wd), swings up to about 2 e^(-gamma pi / wd) = 1.8 half a period later and
// meets it on the way.
TEST(OscillatingPlane, FreeOscillationReachesAParticleAtRest) {
  const double g = 0.1, wd = 3.0;
  const OscillatingPlane p{0.0, -2.0, -2.0 * g / wd, g, wd, 0.0, 0.0, 0.0};
  const NormalMotion m = motion(1.0, 0.0, 0.0);
  const double t = oscillating_plane_event_time(m, p);
  ASSERT_LT(t, kInf);
  EXPECT_NEAR(oscillating_gap(m, p, t).f, 0.0, 1e-13);
  EXPECT_LT(oscillating_gap(m, p, t).df, 0.0);
  for (int k = 0; k < 1000; ++k) EXPECT_GT(oscillating_gap(m, p, t * k / 1000.0).f, 0.0);
  // Too high to reach: the transient's bound alone keeps the search short.
  EXPECT_EQ(oscillating_plane_event_time(motion(2.5, 0.0, 0.0), p), kNever);
}

TEST(OscillatingPlane, RandomAgainstSampling) {
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int events = 0;
  for (int i = 0; i < 3000; ++i) {
    NormalMotion m =
        motion(3.0 * u(rng) - 0.5, 6.0 * u(rng) - 3.0, (i % 4 == 0) ? 0.0 : 2.5 * u(rng) - 2.0);
    const double w0 = 0.5 + 20.0 * u(rng);
    const double gamma = (i % 5 == 0 ? 0.0 : 0.9 * u(rng)) * w0;
    const OscillatingPlane p{0.0,
                             2.0 * u(rng) - 1.0,
                             2.0 * u(rng) - 1.0,
                             gamma,
                             std::sqrt(w0 * w0 - gamma * gamma),
                             (i % 7 == 0) ? 0.0 : u(rng),
                             0.1 + 30.0 * u(rng),
                             2.0 * M_PI * u(rng) - M_PI};
    if (i % 3 == 0) m.height = oscillating_plane_offset(p, 0.0).d;  // starts on the plate
    const double horizon = 0.5 + 4.5 * u(rng);
    const double t = oscillating_plane_event_time(m, p, horizon);
    bool event = false;
    check_against_sampling(
        t, [&](double s) { return oscillating_gap(m, p, s); }, horizon, event);
    if (::testing::Test::HasFatalFailure()) FAIL() << "case " << i;
    events += event ? 1 : 0;
  }
  EXPECT_GT(events, 1000);
}

// ---------------------------------------------------------------------------------------------
// Quartic pair contact (docs/physics.md#quartic-pair-contact)

double quartic(std::array<double, 3> r, std::array<double, 3> v, std::array<double, 3> a,
               double t_max = kNever) {
  return pair_contact_time_accelerated<3>(r.data(), v.data(), a.data(), 1.0, t_max);
}

TEST(QuarticContact, FormulaSheetValues) {
  const std::array<double, 3> g{0, 0, -1};
  EXPECT_NEAR(quartic({0.3, 0, 3}, {0.2, 0, 0}, g), 2.152736853088476, 1e-14);
  EXPECT_NEAR(quartic({0, 0.5, 1.5}, {0, 0, 2}, g), 4.2952013402817455, 1e-14);
  EXPECT_EQ(quartic({1.2, 0, 3}, {0.5, 0, 0}, g), kNever);
  EXPECT_NEAR(quartic({0, 0, 0.99}, {0, 0, 0.1}, g), 0.1, 1e-15);  // turning while overlapped
}

TEST(QuarticContact, ZeroAccelerationIsTheQuadratic) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  const std::array<double, 3> zero{0, 0, 0};
  for (int i = 0; i < 2000; ++i) {
    const std::array<double, 3> r{u(rng), u(rng), u(rng)}, v{u(rng), u(rng), u(rng)};
    EXPECT_EQ(quartic(r, v, zero), pair_contact_time<3>(r.data(), v.data(), 1.0));
  }
  // Formula-sheet quadratic values through the accelerated entry point.
  EXPECT_EQ(quartic({0.999, 0, 0}, {-1, 0, 0}, zero), 0.0);
  EXPECT_NEAR(quartic({1.0 + 1e-10, 0, 0}, {-1, 0, 0}, zero), 1.000000082690371e-10, 1e-24);
}

TEST(QuarticContact, StableRule) {
  const std::array<double, 3> g{0, 0, -1};
  EXPECT_EQ(quartic({0, 0, 0.999}, {0, 0, -1}, g), 0.0);          // overlapping, approaching
  EXPECT_EQ(quartic({0, 0, 0.999}, {0, 0, 0}, g), 0.0);           // at rest, pulled in
  EXPECT_EQ(quartic({0, 0, 1.0}, {0, 0, 0}, g), 0.0);             // resting on it: now
  EXPECT_EQ(quartic({0, 0, -0.999}, {0, 0, -2}, g), kNever);      // receding below, falling
  EXPECT_EQ(quartic({0, 0, 1.0}, {0, 0, 0}, {0, 0, 1}), kNever);  // touching, pulled away
  EXPECT_DOUBLE_EQ(quartic({0, 0, 1.0}, {0, 0, 1}, g), 2.0);      // bounce flight time
  EXPECT_DOUBLE_EQ(quartic({0, 0, 3.0}, {0, 0, 0}, g), 2.0);      // drop from 3 onto it
}

TEST(QuarticContact, GrazingAndTangency) {
  const std::array<double, 3> g{0, 0, -1};
  // Falling past at lateral distance 1 + eps: a near miss; 1 - eps: a hit near sqrt(6).
  EXPECT_EQ(quartic({1.0 + 1e-9, 0, 3}, {0, 0, 0}, g), kNever);
  const double hit = quartic({1.0 - 1e-9, 0, 3}, {0, 0, 0}, g);
  EXPECT_NEAR(hit, std::sqrt(6.0), 1e-4);
  EXPECT_LT(hit, std::sqrt(6.0));
  // Exact tangency: no event, or one within round-off of the touching point.
  const double touch = quartic({1.0, 0, 3}, {0, 0, 0}, g);
  EXPECT_TRUE(touch == kNever || std::fabs(touch - std::sqrt(6.0)) < 1e-6) << touch;
}

TEST(QuarticContact, Horizon) {
  const std::array<double, 3> g{0, 0, -1};
  EXPECT_EQ(quartic({0.3, 0, 3}, {0.2, 0, 0}, g, 2.15), kNever);
  EXPECT_NEAR(quartic({0.3, 0, 3}, {0.2, 0, 0}, g, 2.16), 2.152736853088476, 1e-14);
  EXPECT_NEAR(quartic({0, 0, 0.99}, {0, 0, 0.1}, g, 0.2), 0.1, 1e-15);
  EXPECT_EQ(quartic({0, 0, 0.99}, {0, 0, 0.1}, g, 0.05), kNever);
}

TEST(QuarticContact, DegenerateCubic) {
  // Leading coefficient zero: 1 - t^3 falls to -inf; the unbounded piece is searched.
  EXPECT_NEAR(quartic_event_time({1.0, 0.0, 0.0, -1.0, 0.0}), 1.0, 1e-15);
  EXPECT_EQ(quartic_event_time({1.0, 0.0, 0.0, 1.0, 0.0}), kNever);
  EXPECT_EQ(quartic_event_time({-1.0, -1.0, 0.0, 1.0, 1.0}, 0.0), 0.0);  // now, zero horizon
  // A general quartic with roots 1, 2, 3, 4: falls through zero first at 1.
  EXPECT_NEAR(quartic_event_time({24.0, -50.0, 35.0, -10.0, 1.0}), 1.0, 1e-15);
  // Starting at its root 1, between 1 and 2 it is negative and falling: the event is now.
  EXPECT_EQ(quartic_event_time({0.0, -6.0, 11.0, -6.0, 1.0}), 0.0);  // (t)(t-1)(t-2)(t-3)
  // Sign flipped: positive on (0, 1), falls through zero at 1.
  EXPECT_NEAR(quartic_event_time({0.0, 6.0, -11.0, 6.0, -1.0}), 1.0, 1e-15);
  // (t+1)(t-1)(t-2)(t-3): overlapping at 0 but rising out at 1; the event is the fall at 2.
  EXPECT_NEAR(quartic_event_time({-6.0, 5.0, 5.0, -5.0, 1.0}), 2.0, 1e-15);
}

// The horizon only decides whether the event is reported, never its bits: a candidate loop
// passes its running best, which depends on the order the candidates come in (and that order
// on the CPU), so an event time that moved with the horizon made runs differ between CPUs.
TEST(QuarticContact, TheHorizonNeverChangesTheEventsBits) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0), fraction(0.0, 1.0);
  int events = 0;
  for (int i = 0; i < 20000; ++i) {
    const std::array<double, 3> r{2 * u(rng), 2 * u(rng), 2 * u(rng)};
    const std::array<double, 3> v{2 * u(rng), 2 * u(rng), 2 * u(rng)};
    const std::array<double, 3> a{u(rng), u(rng), u(rng)};
    const double unbounded = quartic(r, v, a, kNever);
    if (unbounded == kNever) continue;
    ++events;
    // Horizons from just past the event to far beyond it, and one just before it.
    for (const double h :
         {std::nextafter(unbounded, kNever), unbounded * (1.0 + 1e-9) + 1e-300,
          unbounded + fraction(rng), unbounded + 10.0 * fraction(rng), 2.0 * unbounded + 1.0}) {
      ASSERT_EQ(quartic(r, v, a, h), unbounded) << i << " horizon " << h;
    }
    if (unbounded > 0.0) {
      ASSERT_EQ(quartic(r, v, a, std::nextafter(unbounded, 0.0)), kNever) << i;
      ASSERT_EQ(quartic(r, v, a, unbounded * fraction(rng)), kNever) << i;
    }
  }
  EXPECT_GT(events, 2000);
}

TEST(QuarticContact, RandomAgainstSampling) {
  std::mt19937_64 rng(6);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int events = 0;
  for (int i = 0; i < 4000; ++i) {
    const std::array<double, 3> r{2 * u(rng), 2 * u(rng), 2 * u(rng)};
    const std::array<double, 3> v{2 * u(rng), 2 * u(rng), 2 * u(rng)};
    const std::array<double, 3> a{u(rng), u(rng), u(rng)};
    const double horizon = 6.0;
    const double t = quartic(r, v, a, horizon);
    ASSERT_TRUE(t >= 0.0) << i;
    const auto gap = [&](double s) {
      double rr = 0.0, rd = 0.0;
      for (int k = 0; k < 3; ++k) {
        const double x = r[k] + v[k] * s + 0.5 * a[k] * s * s;
        rr += x * x;
        rd += x * (v[k] + a[k] * s);
      }
      return GapSample{rr - 1.0, 2.0 * rd};
    };
    ASSERT_LE(t, first_sampled_event(gap, horizon, 20000, 1e-9) + 1e-12) << i;
    if (t == kNever) continue;
    ++events;
    const GapSample at = gap(t);
    ASSERT_LE(at.f, 1e-12) << i;
    ASSERT_LE(at.df, 1e-9) << i;
    if (gap(0.0).f > 0.0) {
      ASSERT_NEAR(at.f, 0.0, 1e-12) << i;
    }
  }
  EXPECT_GT(events, 300);
}

// polynomial_event_time of degree 8, built from known roots: the first root where f falls
// (through zero from above), against the roots themselves and dense sampling; it agrees with
// quartic_event_time on quartics to round-off; the horizon never changes its bits.
TEST(PolynomialEvent, RandomRootsAgainstTheFirstFallingRoot) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 3.0);
  int events = 0;
  for (int i = 0; i < 3000; ++i) {
    // f(t) = s * prod (t - t_k) over 8 real roots, or 6 with a positive quadratic factor.
    std::vector<double> roots;
    const int real = i % 2 == 0 ? 8 : 6;
    for (int k = 0; k < real; ++k) roots.push_back(u(rng));
    std::vector<double> c{i % 4 < 2 ? 1.0 : -1.0};
    const auto times = [&](double a0, double a1, double a2) {  // c *= a0 + a1 t + a2 t^2
      std::vector<double> out(c.size() + 2, 0.0);
      for (std::size_t k = 0; k < c.size(); ++k) {
        out[k] += a0 * c[k];
        out[k + 1] += a1 * c[k];
        out[k + 2] += a2 * c[k];
      }
      c = out;
    };
    for (const double t : roots) times(-t, 1.0, 0.0);
    if (real == 6) {
      const double x = u(rng), a0 = 0.3 + x * x, a1 = 0.3 * u(rng);  // a1^2 < 0.81 < 4 a0
      times(a0, a1, 1.0);
    }
    c.resize(9, 0.0);
    const auto f = [&](double t) {
      double y = 0.0;
      for (int k = 8; k >= 0; --k) y = y * t + c[static_cast<std::size_t>(k)];
      return y;
    };
    const auto df = [&](double t) {
      double y = 0.0;
      for (int k = 8; k >= 1; --k) y = y * t + k * c[static_cast<std::size_t>(k)];
      return y;
    };
    const double t = polynomial_event_time(c.data(), 8, 10.0);
    ASSERT_TRUE(t >= 0.0) << i;
    // The expected event: t = 0 when f(0) <= 0 and falling, else the first root > 0 at which f
    // changes sign from + to - (cases with roots closer than 1e-3 are left out: the expanded
    // coefficients move such near-double roots by up to sqrt(eps) of their spacing's scale).
    std::sort(roots.begin(), roots.end());
    bool crowded = false;
    for (std::size_t k = 1; k < roots.size(); ++k) crowded |= roots[k] - roots[k - 1] < 1e-3;
    if (crowded) continue;
    double expected = kNever;
    if (f(0.0) <= 0.0 && df(0.0) < 0.0) {
      expected = 0.0;
    } else {
      for (const double r : roots) {
        if (r > 0.0 && df(r) < 0.0) {
          expected = r;
          break;
        }
      }
    }
    if (expected == kNever) {
      ASSERT_EQ(t, kNever) << i;
      continue;
    }
    ++events;
    // The root of the product form, moved by the expanded coefficients' round-off (eight roots
    // within a few units are ill-conditioned: up to ~1e-8); at t the given polynomial vanishes
    // to round-off of its terms, and dense sampling finds no earlier falling crossing.
    ASSERT_NEAR(t, expected, 1e-6 * (1.0 + expected)) << i;
    if (expected > 0.0) {  // a crossing (t = 0: overlapping and closing at the start)
      double terms = 0.0, power = 1.0;
      for (int k = 0; k <= 8; ++k, power *= t)
        terms += std::abs(c[static_cast<std::size_t>(k)]) * power;
      ASSERT_LE(std::abs(f(t)), 1e-13 * terms) << i;
    }
    const auto gap = [&](double x) { return GapSample{f(x), df(x)}; };
    ASSERT_LE(t, first_sampled_event(gap, 10.0, 20000, 1e-9) + 1e-12) << i;
    // The horizon decides whether it is reported, never its bits.
    ASSERT_EQ(polynomial_event_time(c.data(), 8, t + 1.0), t) << i;
    if (t > 0.0) {
      ASSERT_EQ(polynomial_event_time(c.data(), 8, std::nextafter(t, 0.0)), kNever) << i;
    }
  }
  EXPECT_GT(events, 1000);
  // A quartic: as quartic_event_time.
  std::uniform_real_distribution<double> w(-1.0, 1.0);
  for (int i = 0; i < 2000; ++i) {
    const std::array<double, 5> q{0.1 + w(rng) * w(rng), w(rng), w(rng), w(rng), w(rng)};
    const double a = quartic_event_time(q, 50.0), b = polynomial_event_time(q.data(), 4, 50.0);
    if (a == kNever) {
      ASSERT_EQ(b, kNever) << i;
    } else {
      ASSERT_NEAR(a, b, 1e-12 * (1.0 + a)) << i;
    }
  }
}

// A sphere against a ring (a circular hole's edge): the degree-8 contact time against dense
// sampling of the distance from the circle itself, falling under gravity at random, from every
// side; never a missed contact, and at the event the distance is the radius.
TEST(RingContact, FallingSpheresAgainstDenseSampling) {
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double R = 1.5, a = 0.5;
  int events = 0;
  for (int i = 0; i < 3000; ++i) {
    std::array<double, 3> n{u(rng), u(rng), u(rng)};
    const double nn = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (double& x : n) x /= nn;
    const std::array<double, 3> r{3 * u(rng), 3 * u(rng), 3 * u(rng)};
    const std::array<double, 3> v{2 * u(rng), 2 * u(rng), 2 * u(rng)};
    std::array<double, 3> g{0.0, 0.0, i % 3 == 0 ? 0.0 : -1.0};
    if (i % 5 == 0) g = {0.3 * u(rng), 0.3 * u(rng), -1.0};
    const auto distance2 = [&](double t) {  // from the circle, and its rate
      std::array<double, 3> x{}, xv{};
      double z = 0.0, zv = 0.0;
      for (int k = 0; k < 3; ++k) {
        x[k] = r[k] + v[k] * t + 0.5 * g[k] * t * t;
        xv[k] = v[k] + g[k] * t;
        z += n[k] * x[k];
        zv += n[k] * xv[k];
      }
      double rho2 = 0.0, rhov = 0.0;
      for (int k = 0; k < 3; ++k) {
        const double p = x[k] - z * n[k], pv = xv[k] - zv * n[k];
        rho2 += p * p;
        rhov += p * pv;
      }
      const double rho = std::sqrt(rho2);
      return GapSample{(rho - R) * (rho - R) + z * z - a * a,
                       2.0 * (rho - R) * (rho > 0.0 ? rhov / rho : 0.0) + 2.0 * z * zv};
    };
    if (distance2(0.0).f < 0.0) continue;  // starts overlapping the ring: not a case
    const double horizon = 4.0;
    const double t = ring_contact_time(r.data(), v.data(), g.data(), n.data(), R, a, horizon);
    ASSERT_TRUE(t >= 0.0) << i;
    ASSERT_LE(t, first_sampled_event(distance2, horizon, 20000, 1e-9) + 1e-12) << i;
    if (t == kNever) continue;
    ++events;
    const GapSample at = distance2(t);
    ASSERT_NEAR(at.f, 0.0, 1e-9) << i;
    ASSERT_LE(at.df, 1e-9) << i;
  }
  EXPECT_GT(events, 100);
}

// A wide ring (R = 200 a): a sphere just touching it (to round-off) and leaving or sliding past
// it has no contact at t = 0, though the expanded polynomial's terms are (2 R^2)^2 and their
// round-off larger than its f(0) and f'(0) (which ring_contact_time takes from the product form:
// a review found the clock frozen on a grain sliding over such a rim); one closing in is met at
// at once (within round-off).
TEST(RingContact, AWideRingsGrazingSphereIsNotMetOnRoundOff) {
  const double R = 100.0, a = 0.5;
  const std::array<double, 3> n{0.0, 0.0, 1.0}, none{0.0, 0.0, 0.0};
  int checked = 0;
  for (const double angle : {0.3, 0.9, 1.2}) {
    for (const double slack : {0.0, 1e-13, 1e-12, -1e-13}) {
      // On the circle of centres at distance a (1 + slack) from the rim, above the plate.
      const double d = a * (1.0 + slack);
      const double rho = R + d * std::cos(angle), z = d * std::sin(angle);
      const std::array<double, 3> r{rho, 0.0, z};
      // Leaving along the normal, sliding along the rim (tangent), and both.
      for (const std::array<double, 3>& v :
           {std::array<double, 3>{std::cos(angle), 0.0, std::sin(angle)},
            std::array<double, 3>{0.0, 0.66, 0.0},
            std::array<double, 3>{0.1 * std::cos(angle), 0.66, 0.1 * std::sin(angle)}}) {
        const double t = ring_contact_time(r.data(), v.data(), none.data(), n.data(), R, a);
        EXPECT_TRUE(t == kNever || t > 1e-3) << angle << " " << slack << " " << t;
        ++checked;
      }
      // Closing in along the normal: met now.
      const std::array<double, 3> in{-std::cos(angle), 0.0, -std::sin(angle)};
      if (slack <= 0.0) {
        EXPECT_LT(ring_contact_time(r.data(), in.data(), none.data(), n.data(), R, a), 1e-12);
      }
    }
  }
  EXPECT_EQ(checked, 36);
}

}  // namespace
}  // namespace kairos
