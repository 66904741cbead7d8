// Collision operators for granular particles (src/interactions/granular_contact.hpp) against
// docs/physics.md#restitution-models and docs/physics.md#rough-collision (with its reference
// values), and against the conservation laws they must obey.
#include "interactions/granular_contact.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "core/error.hpp"

namespace kairos {
namespace {

// ---------------------------------------------------------------------------------------------
// Helpers: a particle with its state, random pairs in contact, and the conserved quantities.

template <int D>
struct Body {
  Vec<D> x{}, v{};
  Spin<D> w{};
  double m = 1.0, radius = 0.5, q = 0.4;
  double inertia() const { return q * m * radius * radius; }
};

template <int D>
Spin<D> spin_of(double x, double y, double z) {
  if constexpr (D == 3) {
    return Vec<3>{x, y, z};
  } else {
    (void)x;
    (void)y;
    return z;
  }
}

template <int D>
Vec<D> random_vec(std::mt19937_64& rng, double scale) {
  std::uniform_real_distribution<double> u(-scale, scale);
  Vec<D> a;
  for (double& c : a) c = u(rng);
  return a;
}

template <int D>
Vec<D> random_unit(std::mt19937_64& rng) {
  std::normal_distribution<double> gauss;
  Vec<D> a;
  for (double& c : a) c = gauss(rng);
  return (1.0 / std::sqrt(norm2(a))) * a;
}

template <int D>
Spin<D> random_spin(std::mt19937_64& rng, double scale) {
  const Vec<3> a = random_vec<3>(rng, scale);
  return spin_of<D>(a[0], a[1], a[2]);
}

// Two bodies touching along a random normal, approaching, with unequal masses, radii and q.
template <int D>
std::pair<Body<D>, Body<D>> random_pair(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.3, 3.0);
  Body<D> i, j;
  i.m = u(rng), j.m = u(rng);
  i.radius = 0.3 * u(rng), j.radius = 0.3 * u(rng);
  i.q = 0.2 * u(rng), j.q = 0.2 * u(rng);
  const Vec<D> n = random_unit<D>(rng);
  j.x = random_vec<D>(rng, 5.0);
  i.x = j.x + (i.radius + j.radius) * n;
  i.v = random_vec<D>(rng, 1.0), j.v = random_vec<D>(rng, 1.0);
  if (dot(i.v - j.v, n) > 0.0) std::swap(i.v, j.v);
  i.w = random_spin<D>(rng, 2.0), j.w = random_spin<D>(rng, 2.0);
  return {i, j};
}

template <int D>
ContactInput<D> input_of(const Body<D>& i, const Body<D>& j) {
  ContactInput<D> in;
  in.normal = (1.0 / (i.radius + j.radius)) * (i.x - j.x);
  in.mass_i = i.m, in.mass_j = j.m;
  in.radius_i = i.radius, in.radius_j = j.radius;
  in.inertia_factor_i = i.q, in.inertia_factor_j = j.q;
  return in;
}

template <int D>
ContactResult<D> collide(const ContactModel& model, Body<D>& i, Body<D>& j) {
  return resolve_contact(model, input_of(i, j), i.v, j.v, i.w, j.w);
}

template <int D>
double translational_energy(const Body<D>& b) {
  return 0.5 * b.m * norm2(b.v);
}
template <int D>
double rotational_energy(const Body<D>& b) {
  return 0.5 * b.inertia() * spin_dot(b.w, b.w);
}
template <int D>
double energy(const Body<D>& b) {
  return translational_energy(b) + rotational_energy(b);
}

// Angular momentum about the origin: m x cross v + I w.
template <int D>
Spin<D> angular_momentum(const Body<D>& b) {
  return b.m * cross(b.x, b.v) + b.inertia() * b.w;
}

template <int D>
Vec<D> contact_velocity(const Body<D>& i, const Body<D>& j, const Vec<D>& n) {
  return (i.v - j.v) - cross(i.radius * i.w + j.radius * j.w, n);
}

template <int D>
double spin_distance(const Spin<D>& a, const Spin<D>& b) {
  const Spin<D> d = a - b;
  return std::sqrt(spin_dot(d, d));
}

template <int D>
double distance(const Vec<D>& a, const Vec<D>& b) {
  return std::sqrt(norm2(a - b));
}

ContactModel model_of(double e, const TangentialModel& tangential) {
  return {NormalRestitution::constant(e), tangential, 0.0};
}

// ---------------------------------------------------------------------------------------------
// The reference collision of two rough spheres (docs/physics.md#rough-collision).

TEST(GranularContact, RoughSpheresReferenceValues) {
  Body<3> i, j;
  i.m = 1, j.m = 2, i.radius = 0.5, j.radius = 0.7, i.q = j.q = 0.4;
  const Vec<3> n{1.0 / 3, 2.0 / 3, 2.0 / 3};
  j.x = {0.1, -0.2, 0.3};
  i.x = j.x + 1.2 * n;
  i.v = {-1, 0.5, 0.2}, j.v = {0.3, -0.2, 0.4};
  i.w = {0.5, -1, 2}, j.w = {-0.7, 0.3, 0.1};
  const double e0 = energy(i) + energy(j);
  const ContactResult<3> r = collide(model_of(0.8, TangentialModel::constant(0.3)), i, j);

  constexpr double tol = 1e-12;  // the reference values are printed to 12 decimals
  EXPECT_NEAR(r.impact_speed, 0.1, 1e-15);
  EXPECT_NEAR(std::sqrt(norm2(r.tangential_impulse)) / tangential_mass(input_of(i, j)) / 1.3,
              0.4438468204, 1e-10);  // |J_t| = m_t (1 + beta) |g_t|
  const Vec<3> impulse{0.129142857143, 0.018095238095, 0.097333333333};
  const Vec<3> vi{-0.870857142857, 0.518095238095, 0.297333333333};
  const Vec<3> vj{0.235428571429, -0.209047619048, 0.351333333333};
  const Vec<3> wi{0.235873015873, -1.268253968254, 2.400317460317};
  const Vec<3> wj{-0.794331065760, 0.204195011338, 0.242970521542};
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(r.impulse[k], impulse[k], tol);
    EXPECT_NEAR(i.v[k], vi[k], tol);
    EXPECT_NEAR(j.v[k], vj[k], tol);
    EXPECT_NEAR(i.w[k], wi[k], tol);
    EXPECT_NEAR(j.w[k], wj[k], tol);
  }
  const double direct = energy(i) + energy(j) - e0;
  EXPECT_NEAR(direct, -0.0182733333, 1e-10);
  EXPECT_NEAR(r.translational_energy_change + r.rotational_energy_change, direct, 1e-15);
  EXPECT_NEAR(r.dissipated, -direct, 1e-15);
  EXPECT_NEAR(r.normal_impulse, dot(r.impulse, n), 1e-15);
  EXPECT_DOUBLE_EQ(r.restitution, 0.8);
  EXPECT_FALSE(r.slid);
  EXPECT_FALSE(r.made_elastic);
}

// ---------------------------------------------------------------------------------------------
// Effective masses.

TEST(GranularContact, TangentialMassReducesToSection5ForEqualQ) {
  ContactInput<3> in;
  in.mass_i = 1.3, in.mass_j = 0.7;
  in.radius_i = 0.2, in.radius_j = 0.9;  // radii drop out: R^2 / I = 1 / (q m)
  for (double q : {0.4, 0.5, 2.0 / 3.0, 1.0}) {
    in.inertia_factor_i = in.inertia_factor_j = q;
    const double mu = in.mass_i * in.mass_j / (in.mass_i + in.mass_j);
    EXPECT_NEAR(normal_mass(in), mu, 1e-15);
    EXPECT_NEAR(tangential_mass(in), mu * q / (1.0 + q), 1e-15);
  }
  in.inertia_factor_i = 0.4, in.inertia_factor_j = 0.25;
  EXPECT_NEAR(1.0 / tangential_mass(in),
              1 / 1.3 + 1 / 0.7 + 0.2 * 0.2 / (0.4 * 1.3 * 0.2 * 0.2) +
                  0.9 * 0.9 / (0.25 * 0.7 * 0.9 * 0.9),
              1e-13);
}

// The defining rule g_n' = -e g_n, g_t' = -beta g_t holds for unequal q: this is what the
// general tangential mass is for.
template <int D>
void check_restitution_rule() {
  std::mt19937_64 rng(11 + D);
  for (int trial = 0; trial < 200; ++trial) {
    auto [i, j] = random_pair<D>(rng);
    const double e = (trial % 21) / 20.0, beta = -1.0 + (trial % 21) / 10.0;
    const Vec<D> n = input_of(i, j).normal;
    const Vec<D> g = contact_velocity(i, j, n);
    collide(model_of(e, TangentialModel::constant(beta)), i, j);
    const Vec<D> g_after = contact_velocity(i, j, n);
    const double gn = dot(g, n);
    EXPECT_NEAR(dot(g_after, n), -e * gn, 1e-13);
    EXPECT_LT(distance<D>(g_after - dot(g_after, n) * n, (-beta) * (g - gn * n)), 1e-13);
  }
}
TEST(GranularContact, RestitutionRuleHoldsForUnequalInertia3D) {
  check_restitution_rule<3>();
}
TEST(GranularContact, RestitutionRuleHoldsForUnequalInertia2D) {
  check_restitution_rule<2>();
}

// ---------------------------------------------------------------------------------------------
// Conservation laws and the energy balance, on random pairs.

std::vector<ContactModel> assorted_models() {
  return {model_of(0.8, TangentialModel::constant(0.3)),
          model_of(0.5, TangentialModel::constant(-0.6)),
          model_of(1.0, TangentialModel::constant(1.0)),
          model_of(0.9, TangentialModel::walton(0.2, 0.4)),  // mostly sliding
          model_of(0.7, TangentialModel::walton(5.0, 0.6)),  // mostly sticking
          model_of(0.6, TangentialModel::smooth())};
}

template <int D>
void check_conservation() {
  std::mt19937_64 rng(7 * D);
  int slid = 0, stuck = 0;
  for (const ContactModel& model : assorted_models()) {
    for (int trial = 0; trial < 100; ++trial) {
      auto [i, j] = random_pair<D>(rng);
      const Vec<D> p0 = i.m * i.v + j.m * j.v;
      const Spin<D> l0 = angular_momentum(i) + angular_momentum(j);
      const double tr0 = translational_energy(i) + translational_energy(j);
      const double rot0 = rotational_energy(i) + rotational_energy(j);
      const ContactResult<D> r = collide(model, i, j);
      (r.slid ? slid : stuck) += model.tangential.coulomb_limited() ? 1 : 0;

      EXPECT_LT(distance<D>(i.m * i.v + j.m * j.v, p0), 1e-13);
      EXPECT_LT(spin_distance<D>(angular_momentum(i) + angular_momentum(j), l0), 1e-12);
      const double tr = translational_energy(i) + translational_energy(j);
      const double rot = rotational_energy(i) + rotational_energy(j);
      EXPECT_NEAR(r.translational_energy_change, tr - tr0, 1e-13);
      EXPECT_NEAR(r.rotational_energy_change, rot - rot0, 1e-13);
      EXPECT_NEAR(r.dissipated, (tr0 + rot0) - (tr + rot), 1e-13);
      EXPECT_GE(r.dissipated, 0.0);
    }
  }
  EXPECT_GT(slid, 20);  // both Walton regimes were exercised
  EXPECT_GT(stuck, 20);
}
TEST(GranularContact, ConservesMomentumAndAngularMomentum3D) {
  check_conservation<3>();
}
TEST(GranularContact, ConservesMomentumAndAngularMomentum2D) {
  check_conservation<2>();
}

// The energy formula of docs/physics.md#rough-collision, with the general tangential mass and,
// for equal q, literally.
template <int D>
void check_energy_formula() {
  std::mt19937_64 rng(3 + D);
  for (int trial = 0; trial < 200; ++trial) {
    auto [i, j] = random_pair<D>(rng);
    if (trial % 2 == 0) j.q = i.q;
    const double e = (trial % 21) / 20.0, beta = 1.0 - (trial % 21) / 10.0;
    const ContactInput<D> in = input_of(i, j);
    const Vec<D> g = contact_velocity(i, j, in.normal);
    const double gn = dot(g, in.normal);
    const double gt2 = norm2(g - gn * in.normal);
    const double mu = normal_mass(in), mt = tangential_mass(in);
    const double e0 = energy(i) + energy(j);
    collide(model_of(e, TangentialModel::constant(beta)), i, j);
    const double direct = energy(i) + energy(j) - e0;
    EXPECT_NEAR(direct, -0.5 * mu * (1 - e * e) * gn * gn - 0.5 * mt * (1 - beta * beta) * gt2,
                1e-13);
    if (trial % 2 == 0) {
      const double q = i.q;
      EXPECT_NEAR(direct,
                  -0.5 * mu * ((1 - e * e) * gn * gn + q / (1 + q) * (1 - beta * beta) * gt2),
                  1e-13);
    }
  }
}
TEST(GranularContact, EnergyChangeMatchesSection5Formula3D) {
  check_energy_formula<3>();
}
TEST(GranularContact, EnergyChangeMatchesSection5Formula2D) {
  check_energy_formula<2>();
}

template <int D>
void check_perfectly_rough_elastic() {
  std::mt19937_64 rng(5 + D);
  for (int trial = 0; trial < 100; ++trial) {
    auto [i, j] = random_pair<D>(rng);
    const double e0 = energy(i) + energy(j);
    const ContactResult<D> r = collide(model_of(1.0, TangentialModel::constant(1.0)), i, j);
    EXPECT_NEAR(energy(i) + energy(j), e0, 1e-13);
    EXPECT_NEAR(r.dissipated, 0.0, 1e-13);
  }
}
TEST(GranularContact, PerfectlyRoughElasticConservesEnergy3D) {
  check_perfectly_rough_elastic<3>();
}
TEST(GranularContact, PerfectlyRoughElasticConservesEnergy2D) {
  check_perfectly_rough_elastic<2>();
}

// beta = -1 (or Walton without friction) is the smooth collision, bit for bit, spins untouched.
template <int D>
void check_smooth_limit() {
  std::mt19937_64 rng(9 + D);
  for (const TangentialModel& t :
       {TangentialModel::constant(-1.0), TangentialModel::walton(0.0, 0.5)}) {
    EXPECT_TRUE(t.is_smooth());
    for (int trial = 0; trial < 50; ++trial) {
      auto [i, j] = random_pair<D>(rng);
      Body<D> i2 = i, j2 = j;
      const ContactResult<D> rough = collide(model_of(0.7, t), i, j);
      const ContactResult<D> smooth =
          resolve_contact(model_of(0.7, TangentialModel::smooth()), input_of(i2, j2), i2.v, j2.v);
      EXPECT_EQ(i.v, i2.v);
      EXPECT_EQ(j.v, j2.v);
      EXPECT_EQ(i.w, i2.w);
      EXPECT_EQ(j.w, j2.w);
      EXPECT_EQ(rough.impulse, smooth.impulse);
      EXPECT_EQ(rough.rotational_energy_change, 0.0);
    }
  }
}
TEST(GranularContact, SmoothLimitLeavesSpinsAlone3D) {
  check_smooth_limit<3>();
}
TEST(GranularContact, SmoothLimitLeavesSpinsAlone2D) {
  check_smooth_limit<2>();
}

TEST(GranularContact, SmoothPathWithoutSpinsRejectsRoughModels) {
  Vec<3> vi{-1, 0, 0}, vj{};
  ContactInput<3> in;
  in.normal = {1, 0, 0};
  EXPECT_THROW(resolve_contact(model_of(0.9, TangentialModel::constant(0.0)), in, vi, vj),
               std::logic_error);
}

// A 3D collision confined to the xy plane (spins along z) is the 2D collision.
TEST(GranularContact, PlanarCollisionAgreesIn2DAnd3D) {
  std::mt19937_64 rng(21);
  for (int trial = 0; trial < 50; ++trial) {
    auto [i, j] = random_pair<2>(rng);
    Body<3> i3, j3;
    for (auto [b2, b3] : {std::pair{&i, &i3}, std::pair{&j, &j3}}) {
      b3->x = {b2->x[0], b2->x[1], 0.0};
      b3->v = {b2->v[0], b2->v[1], 0.0};
      b3->w = {0.0, 0.0, b2->w};
      b3->m = b2->m, b3->radius = b2->radius, b3->q = b2->q;
    }
    const ContactModel model = model_of(0.8, TangentialModel::walton(0.3, 0.5));
    const ContactResult<2> r2 = collide(model, i, j);
    const ContactResult<3> r3 = collide(model, i3, j3);
    EXPECT_EQ(r2.slid, r3.slid);
    for (int k = 0; k < 2; ++k) {
      EXPECT_NEAR(i.v[k], i3.v[k], 1e-14);
      EXPECT_NEAR(j.v[k], j3.v[k], 1e-14);
    }
    EXPECT_NEAR(i.w, i3.w[2], 1e-13);
    EXPECT_NEAR(j.w, j3.w[2], 1e-13);
    EXPECT_EQ(i3.w[0], 0.0);
    EXPECT_EQ(i3.v[2], 0.0);
  }
}

TEST(GranularContact, CrossProductsIn2DAreTheZComponentsOf3D) {
  const Vec<2> a{0.3, -1.2}, b{2.0, 0.7};
  const Vec<3> a3{0.3, -1.2, 0}, b3{2.0, 0.7, 0}, w3{0, 0, 1.5};
  EXPECT_DOUBLE_EQ(cross(a, b), cross(a3, b3)[2]);
  const Vec<2> wa = cross(1.5, a), aw = cross(a, 1.5);
  EXPECT_DOUBLE_EQ(wa[0], cross(w3, a3)[0]);
  EXPECT_DOUBLE_EQ(wa[1], cross(w3, a3)[1]);
  EXPECT_DOUBLE_EQ(aw[0], cross(a3, w3)[0]);
  EXPECT_DOUBLE_EQ(aw[1], cross(a3, w3)[1]);
}

// ---------------------------------------------------------------------------------------------
// Walton's Coulomb-limited model.

// A pair and the friction at which its sticking impulse just touches the Coulomb cone.
struct WaltonCase {
  Body<3> i, j;
  double critical_friction;
};
WaltonCase walton_case(double e, double beta0) {
  Body<3> i, j;
  i.m = 1.0, j.m = 1.7, i.radius = 0.5, j.radius = 0.4, i.q = 0.4, j.q = 0.3;
  const Vec<3> n{0.0, 0.6, 0.8};
  i.x = (i.radius + j.radius) * n;
  i.v = {0.4, -0.3, -0.2}, j.v = {-0.1, 0.2, 0.3};
  i.w = {0.3, 1.0, -0.5}, j.w = {0.2, -0.4, 0.6};
  const ContactInput<3> in = input_of(i, j);
  const Vec<3> g = contact_velocity(i, j, n);
  const double gn = dot(g, n);
  const double jn = normal_mass(in) * (1 + e) * -gn;
  const double sticking = tangential_mass(in) * (1 + beta0) * std::sqrt(norm2(g - gn * n));
  return {i, j, sticking / jn};
}

TEST(GranularContact, WaltonSticksLikeConstantBeta) {
  WaltonCase c = walton_case(0.8, 0.4);
  Body<3> i2 = c.i, j2 = c.j;
  const ContactResult<3> walton =
      collide(model_of(0.8, TangentialModel::walton(c.critical_friction * 1.001, 0.4)), c.i, c.j);
  const ContactResult<3> constant = collide(model_of(0.8, TangentialModel::constant(0.4)), i2, j2);
  EXPECT_FALSE(walton.slid);
  EXPECT_EQ(c.i.v, i2.v);
  EXPECT_EQ(c.j.v, j2.v);
  EXPECT_EQ(c.i.w, i2.w);
  EXPECT_EQ(c.j.w, j2.w);
  EXPECT_EQ(walton.dissipated, constant.dissipated);
}

TEST(GranularContact, WaltonSlidesOnTheCoulombCone) {
  const double e = 0.8, beta0 = 0.4;
  WaltonCase c = walton_case(e, beta0);
  const double friction = 0.5 * c.critical_friction;
  const Vec<3> n = input_of(c.i, c.j).normal;
  const Vec<3> g = contact_velocity(c.i, c.j, n);
  const Vec<3> gt = g - dot(g, n) * n;
  const double e0 = energy(c.i) + energy(c.j);
  const ContactResult<3> r =
      collide(model_of(e, TangentialModel::walton(friction, beta0)), c.i, c.j);
  ASSERT_TRUE(r.slid);
  const double jt = std::sqrt(norm2(r.tangential_impulse));
  EXPECT_NEAR(jt, friction * r.normal_impulse, 1e-15 * jt);
  // Along -g_t.
  EXPECT_LT(distance<3>((1.0 / jt) * r.tangential_impulse, (-1.0 / std::sqrt(norm2(gt))) * gt),
            1e-14);
  // g_t' = -beta_eff g_t with -1 <= beta_eff < beta0: sliding slows the contact less than
  // sticking would, without reversing it beyond that.
  const Vec<3> g_after = contact_velocity(c.i, c.j, n);
  const Vec<3> gt_after = g_after - dot(g_after, n) * n;
  const double beta_eff = -dot(gt_after, gt) / norm2(gt);
  EXPECT_LT(distance<3>(gt_after, (-beta_eff) * gt), 1e-14);
  EXPECT_GE(beta_eff, -1.0);
  EXPECT_LT(beta_eff, beta0);
  // Energy: docs/physics.md#rough-collision with beta_eff; and the tangential loss is positive.
  const ContactInput<3> in = input_of(c.i, c.j);
  const double gn = dot(g, n);
  const double normal_loss = 0.5 * normal_mass(in) * (1 - e * e) * gn * gn;
  const double tangential_loss = 0.5 * tangential_mass(in) * (1 - beta_eff * beta_eff) * norm2(gt);
  EXPECT_NEAR(e0 - energy(c.i) - energy(c.j), normal_loss + tangential_loss, 1e-14);
  EXPECT_NEAR(r.dissipated, normal_loss + tangential_loss, 1e-14);
  EXPECT_GT(tangential_loss, 0.0);
}

TEST(GranularContact, WaltonIsContinuousAtTheConeEdge) {
  WaltonCase c = walton_case(0.6, 0.8);
  Body<3> i2 = c.i, j2 = c.j;
  const ContactResult<3> sticks = collide(
      model_of(0.6, TangentialModel::walton(c.critical_friction * (1 + 1e-9), 0.8)), c.i, c.j);
  const ContactResult<3> slides = collide(
      model_of(0.6, TangentialModel::walton(c.critical_friction * (1 - 1e-9), 0.8)), i2, j2);
  EXPECT_FALSE(sticks.slid);
  EXPECT_TRUE(slides.slid);
  EXPECT_LT(distance<3>(sticks.impulse, slides.impulse), 1e-9);
  EXPECT_LT(spin_distance<3>(c.i.w, i2.w), 1e-8);
}

// ---------------------------------------------------------------------------------------------
// Elastic cut-offs and non-approaching pairs.

TEST(GranularContact, SlowOrForcedCollisionsAreElasticWithoutTangentialImpulse) {
  std::mt19937_64 rng(31);
  for (int trial = 0; trial < 40; ++trial) {
    auto [i, j] = random_pair<3>(rng);
    const double speed = -dot(i.v - j.v, input_of(i, j).normal);
    ContactModel model = model_of(0.5, TangentialModel::constant(0.5));
    model.elastic_below_speed = trial % 2 == 0 ? 1.01 * speed : 0.0;
    ContactInput<3> in = input_of(i, j);
    in.force_elastic = trial % 2 == 1;
    const Spin<3> wi = i.w, wj = j.w;
    const double e0 = energy(i) + energy(j);
    const ContactResult<3> r = resolve_contact(model, in, i.v, j.v, i.w, j.w);
    EXPECT_TRUE(r.made_elastic);
    EXPECT_EQ(r.restitution, 1.0);
    EXPECT_EQ(i.w, wi);
    EXPECT_EQ(j.w, wj);
    EXPECT_EQ(norm2(r.tangential_impulse), 0.0);
    EXPECT_NEAR(energy(i) + energy(j), e0, 1e-13);
    EXPECT_EQ(r.dissipated, 0.0);
  }
  // Just above the cut-off: the model applies.
  auto [i, j] = random_pair<3>(rng);
  ContactModel model = model_of(0.5, TangentialModel::constant(0.5));
  model.elastic_below_speed = 0.99 * -dot(i.v - j.v, input_of(i, j).normal);
  const ContactResult<3> r = collide(model, i, j);
  EXPECT_FALSE(r.made_elastic);
  EXPECT_EQ(r.restitution, 0.5);
}

TEST(GranularContact, RecedingOrGrazingPairsAreLeftAlone) {
  ContactModel model = model_of(0.5, TangentialModel::constant(0.5));
  for (double vx : {0.3, 0.0}) {  // receding, grazing
    Body<3> i, j;
    i.x = {1.0, 0, 0};
    i.v = {vx, 0.4, 0}, j.v = {0, -0.2, 0.1};
    i.w = {1, 2, 3};
    const Body<3> i0 = i, j0 = j;
    const ContactResult<3> r = collide(model, i, j);
    EXPECT_EQ(i.v, i0.v);
    EXPECT_EQ(j.v, j0.v);
    EXPECT_EQ(i.w, i0.w);
    EXPECT_EQ(norm2(r.impulse), 0.0);
    EXPECT_EQ(r.dissipated, 0.0);
    EXPECT_EQ(r.impact_speed, 0.0);
  }
}

// ---------------------------------------------------------------------------------------------
// Walls.

template <int D>
WallContactInput<D> wall_input(const Body<D>& b, const Vec<D>& n, const Vec<D>& wall_velocity) {
  WallContactInput<D> in;
  in.normal = n;
  in.wall_velocity = wall_velocity;
  in.mass = b.m, in.radius = b.radius, in.inertia_factor = b.q;
  return in;
}

// Energy in the frame of the wall.
template <int D>
double wall_frame_energy(const Body<D>& b, const Vec<D>& wall_velocity) {
  return 0.5 * b.m * norm2(b.v - wall_velocity) + rotational_energy(b);
}

template <int D>
void check_moving_wall() {
  std::mt19937_64 rng(41 + D);
  for (const TangentialModel& t : {TangentialModel::smooth(), TangentialModel::constant(1.0)}) {
    for (int trial = 0; trial < 50; ++trial) {
      auto [b, unused] = random_pair<D>(rng);
      const Vec<D> n = random_unit<D>(rng);
      const Vec<D> u = random_vec<D>(rng, 1.0);  // vibrating and sliding at once
      if (dot(b.v - u, n) > 0.0) b.v = b.v - (2.0 * dot(b.v - u, n)) * n;
      const Spin<D> w0 = b.w;
      const double e0 = wall_frame_energy(b, u), lab0 = energy(b);
      const ContactResult<D> r =
          resolve_wall_contact(model_of(1.0, t), wall_input(b, n, u), b.v, b.w);
      EXPECT_NEAR(wall_frame_energy(b, u), e0, 1e-13);
      EXPECT_NEAR(r.dissipated, 0.0, 1e-13);
      EXPECT_NEAR(r.translational_energy_change + r.rotational_energy_change, energy(b) - lab0,
                  1e-13);
      EXPECT_GT(dot(b.v - u, n), 0.0);
      if (t.is_smooth()) {
        EXPECT_EQ(b.w, w0);
      }
    }
  }
}
TEST(GranularContact, ElasticCollisionWithMovingWallConservesWallFrameEnergy3D) {
  check_moving_wall<3>();
}
TEST(GranularContact, ElasticCollisionWithMovingWallConservesWallFrameEnergy2D) {
  check_moving_wall<2>();
}

// A wall is a partner of infinite mass and inertia; its angular momentum about the contact
// point is conserved since the impulse acts there.
template <int D>
void check_wall_as_heavy_partner() {
  std::mt19937_64 rng(51 + D);
  const ContactModel model = model_of(0.7, TangentialModel::walton(0.4, 0.5));
  for (int trial = 0; trial < 50; ++trial) {
    auto [b, heavy] = random_pair<D>(rng);
    const Vec<D> n = input_of(b, heavy).normal;
    heavy.m = 1e12;
    heavy.w = spin_of<D>(0, 0, 0);
    Body<D> wall_hit = b;
    const auto l_contact = [&](const Body<D>& p) {
      return p.m * cross(p.radius * n, p.v) + p.inertia() * p.w;
    };
    const Spin<D> l0 = l_contact(b);
    const ContactResult<D> pair = collide(model, b, heavy);
    const ContactResult<D> wall =
        resolve_wall_contact(model, wall_input(wall_hit, n, heavy.v), wall_hit.v, wall_hit.w);
    EXPECT_EQ(pair.slid, wall.slid);
    EXPECT_LT(distance<D>(wall_hit.v, b.v), 1e-9);
    EXPECT_LT(spin_distance<D>(wall_hit.w, b.w), 1e-9);
    EXPECT_NEAR(wall.dissipated, pair.dissipated, 1e-9);
    EXPECT_LT(spin_distance<D>(l_contact(wall_hit), l0), 1e-13);
  }
}
TEST(GranularContact, WallIsTheInfiniteMassLimit3D) {
  check_wall_as_heavy_partner<3>();
}
TEST(GranularContact, WallIsTheInfiniteMassLimit2D) {
  check_wall_as_heavy_partner<2>();
}

TEST(GranularContact, SmoothWallReflectsTheNormalVelocity) {
  Vec<3> v{0.3, -2.0, 0.5};
  WallContactInput<3> in;
  in.normal = {0, 1, 0};
  in.wall_velocity = {0.0, 0.5, 0.0};  // wall moving up at 0.5: relative normal speed 2.5
  const ContactResult<3> r = resolve_wall_contact(model_of(0.6, TangentialModel::smooth()), in, v);
  EXPECT_DOUBLE_EQ(r.impact_speed, 2.5);
  EXPECT_DOUBLE_EQ(v[1], 0.5 + 0.6 * 2.5);
  EXPECT_EQ(v[0], 0.3);
  EXPECT_EQ(v[2], 0.5);
  EXPECT_NEAR(r.dissipated, 0.5 * (1 - 0.36) * 2.5 * 2.5, 1e-15);
}

// ---------------------------------------------------------------------------------------------
// Normal restitution models.

TEST(NormalRestitution, ConstantAndDefault) {
  EXPECT_EQ(NormalRestitution{}(3.0), 1.0);
  EXPECT_EQ(NormalRestitution::constant(0.7)(0.0), 0.7);
  EXPECT_EQ(NormalRestitution::constant(0.7)(100.0), 0.7);
  EXPECT_THROW(NormalRestitution::constant(1.1), InputError);
  EXPECT_THROW(NormalRestitution::constant(-0.1), InputError);
  EXPECT_THROW(NormalRestitution::constant(std::nan("")), InputError);
}

// e(x) = 1 + h2 x^2 + h4 x^4 + h5 x^5 + O(x^6) with the coefficients of
// docs/physics.md#viscoelastic-head-on; h3 = 0.
TEST(NormalRestitution, PadeReproducesItsSeries) {
  const double c1 = std::tgamma(0.6) * std::sqrt(std::numbers::pi) /
                    (std::pow(2.0, 0.2) * std::pow(5.0, 0.4) * std::tgamma(2.1));
  EXPECT_NEAR(c1, 1.1534489, 5e-8);
  const double h2 = -c1, h4 = 0.6 * c1 * c1, h5 = 4.0 / 15.0;
  for (double x : {0.01, 0.02, 0.05, 0.1}) {
    const double series = 1 + h2 * x * x + h4 * std::pow(x, 4) + h5 * std::pow(x, 5);
    // The printed Padé coefficients round h2..h5 at ~1e-6; the remainder is ~0.44 x^6.
    EXPECT_LT(std::abs(viscoelastic_restitution(x) - series), 3e-6 * x * x + 0.5 * std::pow(x, 6))
        << x;
  }
  EXPECT_EQ(viscoelastic_restitution(0.0), 1.0);
  double previous = 1.0;
  for (double x = 0.01; x < 50.0; x *= 1.1) {
    EXPECT_LT(viscoelastic_restitution(x), previous);
    previous = viscoelastic_restitution(x);
  }
}

// The Padé row of the viscoelastic head-on values to its printed digits, and its error against
// the exact ODE as quoted in docs/physics.md#restitution-models.
TEST(NormalRestitution, PadeMatchesTheTabulatedViscoelasticValues) {
  struct Row {
    double c, exact, pade, quoted_error, last_digit;  // error quoted in docs/physics.md (0: none)
  };
  for (const Row& row :
       {Row{0.001, 0.9982716442, 0.998272, 0, 0}, Row{0.01, 0.9828832905, 0.982884, 2e-7, 1e-7},
        Row{0.05, 0.9181328552, 0.918155, 0, 0}, Row{0.1, 0.8451438063, 0.845276, 1.3e-4, 1e-5},
        Row{0.2, 0.7220854397, 0.722744, 0, 0}, Row{0.5, 0.4788382707, 0.482196, 3.4e-3, 1e-4},
        Row{1.0, 0.2811310301, 0.288002, 0, 0}, Row{2.0, 0.1337166224, 0.142359, 8.6e-3, 1e-4}}) {
    const double e = viscoelastic_restitution(std::sqrt(1.5 * row.c));  // x^2 = (3/2) c_dis
    EXPECT_NEAR(e, row.pade, 5e-7) << row.c;
    if (row.quoted_error > 0) {
      EXPECT_NEAR(e - row.exact, row.quoted_error, 0.5 * row.last_digit) << row.c;
    }
  }
}

TEST(NormalRestitution, ViscoelasticFromMaterial) {
  // The physical example of docs/physics.md#viscoelastic-head-on: mu = 1e-3 kg,
  // rho = 1e7 N m^-3/2, A = 1e-5 s, v = 1 m/s gives beta_A = 0.15, c_dis = 0.1.
  const NormalRestitution e = NormalRestitution::viscoelastic_from_material(1e-5, 1e7, 1e-3);
  EXPECT_NEAR(e(1.0), viscoelastic_restitution(std::sqrt(0.15)), 1e-15);
  EXPECT_NEAR(e(1.0), 0.845276, 5e-7);
  EXPECT_NEAR(e(1.0), 0.845143806333, 1.4e-4);
  // x grows as v^(1/10): 2^10 times faster doubles x.
  EXPECT_NEAR(e(1024.0), viscoelastic_restitution(2.0 * std::sqrt(0.15)), 1e-15);
  EXPECT_EQ(e(0.0), 1.0);
  EXPECT_THROW(NormalRestitution::viscoelastic_from_material(-1e-5, 1e7, 1e-3), InputError);
  EXPECT_THROW(NormalRestitution::viscoelastic_from_material(1e-5, 0.0, 1e-3), InputError);
  EXPECT_THROW(NormalRestitution::viscoelastic_from_material(1e-5, 1e7, 0.0), InputError);
  EXPECT_THROW(NormalRestitution::viscoelastic(-1.0), InputError);
}

TEST(NormalRestitution, ViscoelasticFromAReferenceValue) {
  for (double e_ref : {0.99, 0.9, 0.5, 0.1, 0.001}) {
    for (double v_ref : {1e-3, 1.0, 30.0}) {
      const NormalRestitution e = NormalRestitution::viscoelastic_at(e_ref, v_ref);
      EXPECT_NEAR(e(v_ref), e_ref, 1e-14 * (1 + e_ref));
      EXPECT_GT(e(0.5 * v_ref), e_ref);  // slower impacts are more elastic
      EXPECT_LT(e(2.0 * v_ref), e_ref);
    }
  }
  EXPECT_EQ(NormalRestitution::viscoelastic_at(1.0, 2.0)(50.0), 1.0);
  EXPECT_THROW(NormalRestitution::viscoelastic_at(0.0, 1.0), InputError);
  EXPECT_THROW(NormalRestitution::viscoelastic_at(1.2, 1.0), InputError);
  EXPECT_THROW(NormalRestitution::viscoelastic_at(0.5, 0.0), InputError);
}

TEST(NormalRestitution, TableInterpolatesAndClamps) {
  const NormalRestitution e = NormalRestitution::table({0.1, 1.0, 3.0}, {0.95, 0.8, 0.5});
  EXPECT_EQ(e(0.0), 0.95);
  EXPECT_EQ(e(0.1), 0.95);
  EXPECT_DOUBLE_EQ(e(0.55), 0.875);
  EXPECT_EQ(e(1.0), 0.8);
  EXPECT_DOUBLE_EQ(e(2.5), 0.575);
  EXPECT_EQ(e(3.0), 0.5);
  EXPECT_EQ(e(1e9), 0.5);
  EXPECT_EQ(NormalRestitution::table({2.0}, {0.3})(7.0), 0.3);
  EXPECT_EQ(NormalRestitution::table({0.0, 1.0}, {1.0, 0.0})(0.25), 0.75);
}

TEST(NormalRestitution, TableRejectsBadInputNamingTheProblem) {
  const auto message = [](std::vector<double> v, std::vector<double> e) -> std::string {
    try {
      NormalRestitution::table(std::move(v), std::move(e));
    } catch (const InputError& err) {
      return err.what();
    }
    return "accepted";
  };
  const double nan = std::nan("");
  EXPECT_NE(message({}, {}).find("empty"), std::string::npos);
  EXPECT_NE(message({1, 2}, {0.5}).find("2 speeds but 1 values"), std::string::npos);
  EXPECT_NE(message({1, 0.5}, {0.5, 0.5}).find("strictly increasing"), std::string::npos);
  EXPECT_NE(message({1, 1}, {0.5, 0.5}).find("strictly increasing"), std::string::npos);
  EXPECT_NE(message({-1, 1}, {0.5, 0.5}).find(">= 0"), std::string::npos);
  EXPECT_NE(message({nan, 1}, {0.5, 0.5}).find("finite"), std::string::npos);
  EXPECT_NE(message({0, 1}, {0.5, 1.5}).find("restitution must be in [0, 1]"), std::string::npos);
  EXPECT_NE(message({0, 1}, {-0.1, 0.5}).find("restitution must be in [0, 1]"), std::string::npos);
  EXPECT_NE(message({0, 1}, {0.5, nan}).find("restitution must be in [0, 1]"), std::string::npos);
}

TEST(NormalRestitution, SpeedDependentRestitutionIsUsedPerCollision) {
  const ContactModel model{NormalRestitution::table({0.0, 2.0}, {1.0, 0.0}),
                           TangentialModel::smooth(), 0.0};
  Vec<2> vi{-0.5, 0.0}, vj{0.5, 0.0};  // impact speed 1: e = 0.5
  ContactInput<2> in;
  in.normal = {1.0, 0.0};
  const ContactResult<2> r = resolve_contact(model, in, vi, vj);
  EXPECT_EQ(r.restitution, 0.5);
  EXPECT_DOUBLE_EQ(vi[0], 0.25);
  EXPECT_DOUBLE_EQ(vj[0], -0.25);
}

TEST(TangentialModel, ValidatesItsParameters) {
  EXPECT_TRUE(TangentialModel{}.is_smooth());
  EXPECT_TRUE(TangentialModel::smooth().is_smooth());
  EXPECT_FALSE(TangentialModel::constant(0.0).is_smooth());
  EXPECT_FALSE(TangentialModel::constant(0.0).coulomb_limited());
  EXPECT_TRUE(TangentialModel::walton(0.3, 0.2).coulomb_limited());
  EXPECT_THROW(TangentialModel::constant(1.5), InputError);
  EXPECT_THROW(TangentialModel::constant(-1.01), InputError);
  EXPECT_THROW(TangentialModel::walton(-0.1, 0.0), InputError);
  EXPECT_THROW(TangentialModel::walton(0.1, 2.0), InputError);
  EXPECT_THROW(TangentialModel::walton(std::nan(""), 0.0), InputError);
}

}  // namespace
}  // namespace kairos
