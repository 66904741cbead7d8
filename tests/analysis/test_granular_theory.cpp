// Granular kinetic theory (src/analysis/granular_theory.hpp): the reference values of
// docs/physics.md#homogeneous-cooling, and the rough homogeneous cooling state of
// docs/theory-rough-hcs.md checked against a Monte Carlo of collision-weighted binary encounters
// run through the real collision operator.
#include "analysis/granular_theory.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <stdexcept>

#include "interactions/granular_contact.hpp"

namespace kairos {
namespace {

// ---------------------------------------------------------------------------------------------
// Smooth spheres: independent reference values (T0 = m = sigma = 1), to the printed digits
// (docs/physics.md#homogeneous-cooling, docs/physics.md#van-noije-ernst-a2).

TEST(GranularTheory, HaffReferenceValues) {
  struct Row {
    int d;
    double n, e, g, omega, tau0, a2;
  };
  for (const Row& row : {Row{3, 0.05, 0.9, 1.0686645719, 0.3788317272, 83.358771467, -0.014560},
                         Row{3, 0.1, 0.9, 1.1443223926, 0.8113034526, 38.923718700, -0.014560},
                         Row{3, 0.1, 0.8, 1.1443223926, 0.8113034526, 20.543073759, -0.012577},
                         Row{2, 0.1, 0.9, 1.1372647368, 0.4031498525, 52.220362852, -0.026862}}) {
    const double g = contact_value(row.d, packing_fraction(row.d, row.n, 1.0));
    const double omega = enskog_collision_frequency(row.d, row.n, 1.0, 1.0, 1.0);
    EXPECT_NEAR(g, row.g, 5e-11);
    EXPECT_NEAR(omega, row.omega, 5e-11);
    EXPECT_NEAR(haff_time(row.d, row.e, omega), row.tau0, 5e-10);
    EXPECT_NEAR(sonine_a2(row.d, row.e), row.a2, 5e-7);
  }
  EXPECT_NEAR(temperature_ratio_after_collisions(3, 0.9, 10.0), 0.5308194506, 5e-11);
  EXPECT_NEAR(temperature_ratio_after_collisions(2, 0.9, 10.0), 0.3867410235, 5e-11);
}

TEST(GranularTheory, HaffLawShapeAndScaling) {
  EXPECT_DOUBLE_EQ(haff_temperature(2.0, 10.0, 0.0), 2.0);
  EXPECT_DOUBLE_EQ(haff_temperature(2.0, 10.0, 10.0), 0.5);
  // omega_E grows as sqrt(T / m); a2 changes sign at e = 1/sqrt(2) and vanishes at e = 1.
  EXPECT_NEAR(enskog_collision_frequency(3, 0.1, 1.0, 4.0, 1.0),
              2.0 * enskog_collision_frequency(3, 0.1, 1.0, 1.0, 1.0), 1e-15);
  EXPECT_NEAR(sonine_a2(3, std::sqrt(0.5)), 0.0, 1e-16);
  EXPECT_EQ(sonine_a2(2, 1.0), 0.0);
  EXPECT_EQ(rotational_degrees_of_freedom(3), 3);
  EXPECT_EQ(rotational_degrees_of_freedom(2), 1);
  EXPECT_THROW(contact_value(4, 0.1), std::invalid_argument);
  EXPECT_THROW(rough_hcs_temperature_ratio(3, 1.2, 0.0, 0.4), std::invalid_argument);
  EXPECT_THROW(rough_hcs_temperature_ratio(3, 0.9, -1.5, 0.4), std::invalid_argument);
  EXPECT_THROW(rough_hcs_temperature_ratio(3, 0.9, 0.0, 0.0), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------
// Self-diffusion in the homogeneous cooling state
// (docs/physics.md#self-diffusion-in-the-homogeneous-cooling-state).

TEST(GranularTheory, CoolingStateDiffusionIsEnskogsPerCollisionWhenElastic) {
  // e = 1: a2 = 0, and D_s is Enskog's D (first Sonine: 3 / (8 n sigma^2 g) sqrt(T / (pi m)) in
  // 3D, 1 / (2 n sigma g) sqrt(T / (pi m)) in 2D) over omega_E, times Chapman and Cowling's
  // factor for the higher orders (1.019 for spheres).
  for (const double n : {0.02, 0.2}) {
    const double sigma = 1.3;
    const HcsSelfDiffusion s3 = hcs_self_diffusion(3, 1.0, n, sigma);
    const double g3 = contact_value(3, packing_fraction(3, n, sigma));
    const double d3 = 3.0 / (8.0 * n * sigma * sigma * g3) * std::sqrt(1.0 / M_PI);
    EXPECT_NEAR(s3.first_sonine / (d3 / enskog_collision_frequency(3, n, sigma, 1.0, 1.0)), 1.0,
                1e-13);
    EXPECT_EQ(s3.a2, 0.0);
    EXPECT_NEAR(s3.per_collision / s3.first_sonine, 1.019, 0.0005);
    const HcsSelfDiffusion s2 = hcs_self_diffusion(2, 1.0, n, sigma);
    const double g2 = contact_value(2, packing_fraction(2, n, sigma));
    const double d2 = 1.0 / (2.0 * n * sigma * g2) * std::sqrt(1.0 / M_PI);
    EXPECT_NEAR(s2.first_sonine / (d2 / enskog_collision_frequency(2, n, sigma, 1.0, 1.0)), 1.0,
                1e-13);
    EXPECT_NEAR(s2.reduced, s2.per_collision * n * sigma * n * sigma, 1e-15);
  }
}

TEST(GranularTheory, CoolingStateDiffusionReferenceValues) {
  // Without a2 the first Sonine approximation scales as 4 / (1 + e)^2 from the elastic value:
  // nu_D - zeta/2 = (1 + e)^2 omega_E / (2d).
  for (const int d : {2, 3}) {
    const double elastic = hcs_self_diffusion(d, 1.0, 0.01, 1.0).maxwellian;
    for (const double e : {0.6, 0.75, 0.9}) {
      EXPECT_NEAR(hcs_self_diffusion(d, e, 0.01, 1.0).maxwellian / elastic,
                  4.0 / ((1.0 + e) * (1.0 + e)), 1e-13);
    }
  }
  struct Row {
    int d;
    double e, n, first, factor, total;
  };
  // docs/physics.md's values (sigma = 1).
  // docs/physics.md's values: packing fraction 0.01, sigma = 1.
  for (const Row& r : {Row{3, 0.9, 6 * 0.01 / M_PI, 86.07381969, 1.00661, 86.64276764},
                       Row{3, 0.8, 6 * 0.01 / M_PI, 95.90782261, 0.99506, 95.43403797},
                       Row{3, 0.7, 6 * 0.01 / M_PI, 107.7012818, 0.98407, 105.9856004},
                       Row{3, 1.0, 6 * 0.01 / M_PI, 77.80072686, 1.01892, 79.27271661},
                       Row{2, 0.8, 4 * 0.01 / M_PI, 585.7468427, 0.99306, 581.6817596}}) {
    const HcsSelfDiffusion s = hcs_self_diffusion(r.d, r.e, r.n, 1.0);
    EXPECT_NEAR(s.sonine_factor, r.factor, 1e-12);
    EXPECT_NEAR(s.first_sonine / r.first, 1.0, 1e-9);
    EXPECT_NEAR(s.per_collision / r.total, 1.0, 1e-9);
  }
  // Between the table's points, linear.
  EXPECT_NEAR(hcs_sonine_factor(3, 0.825), 0.5 * (0.99506 + 1.00063), 1e-12);
  EXPECT_THROW(hcs_self_diffusion(3, 0.5, 0.01, 1.0), std::invalid_argument);
  EXPECT_THROW(hcs_self_diffusion(3, 0.9, 0.0, 1.0), std::invalid_argument);
  EXPECT_THROW(hcs_sonine_factor(4, 0.9), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------
// Rough spheres: limits of the mean-field theory.

TEST(GranularTheory, SmoothLimitHasNoRotationalCoupling) {
  for (int d : {2, 3}) {
    const RoughCoolingCoefficients k = rough_cooling_coefficients(d, 0.8, -1.0, 0.4);
    EXPECT_NEAR(k.a, (1 - 0.64) / d, 1e-16);
    EXPECT_EQ(k.b, 0.0);
    EXPECT_EQ(k.b_rot, 0.0);
    EXPECT_EQ(k.c, 0.0);
    EXPECT_EQ(rough_hcs_temperature_ratio(d, 0.8, -1.0, 0.4),
              std::numeric_limits<double>::infinity());
    EXPECT_TRUE(std::isnan(rough_hcs_temperature_ratio(d, 1.0, -1.0, 0.4)));
    EXPECT_NEAR(rough_hcs_cooling_rate(d, 0.8, -1.0, 0.4), (1 - 0.64) / d, 1e-16);
  }
}

TEST(GranularTheory, ElasticPerfectlyRoughParticlesReachEquipartition) {
  for (int d : {2, 3}) {
    for (double q : {0.4, 0.5, 2.0 / 3.0}) {
      EXPECT_NEAR(rough_hcs_temperature_ratio(d, 1.0, 1.0, q), 1.0, 1e-14);
      EXPECT_NEAR(rough_hcs_cooling_rate(d, 1.0, 1.0, q), 0.0, 1e-15);
      // Energy is conserved at any ratio: d T_tr dT_tr + d_rot dT_rot = 0.
      const RoughEnergyChange de = rough_energy_change_per_collision(d, 1.0, 1.0, q, 1.3, 0.4);
      EXPECT_NEAR(de.translational + de.rotational, 0.0, 1e-15);
      EXPECT_GT(de.rotational, 0.0);  // the colder rotations heat up
    }
  }
}

// The ratio is the stable fixed point: equal rates there, and d ln R / dc = rate_tr - rate_rot
// drives any start towards it.
TEST(GranularTheory, HcsRatioIsTheStableFixedPoint) {
  for (int d : {2, 3}) {
    for (double e : {0.5, 0.9, 1.0}) {
      for (double beta : {-0.8, 0.0, 0.5, 1.0}) {
        const double q = d == 3 ? 0.4 : 0.5;
        const double r = rough_hcs_temperature_ratio(d, e, beta, q);
        ASSERT_GT(r, 0.0);
        const RoughCoolingRates at = rough_cooling_rates(d, e, beta, q, r);
        EXPECT_NEAR(at.translational, at.rotational, 1e-13);
        EXPECT_NEAR(rough_hcs_cooling_rate(d, e, beta, q), at.translational, 1e-15);
        for (double start : {0.01, 30.0}) {
          // RK2 in ln R against collisions per particle, with steps scaled by the local
          // relaxation rate B R + B_rot / R (small for nearly smooth particles).
          const RoughCoolingCoefficients k = rough_cooling_coefficients(d, e, beta, q);
          const auto slope = [&](double lr) {
            const RoughCoolingRates at_lr = rough_cooling_rates(d, e, beta, q, std::exp(lr));
            return at_lr.translational - at_lr.rotational;
          };
          double log_ratio = std::log(start);
          for (int step = 0; step < 2000; ++step) {
            const double ratio = std::exp(log_ratio);
            const double dc = 0.2 / (k.b * ratio + k.b_rot / ratio);
            log_ratio += dc * slope(log_ratio + 0.5 * dc * slope(log_ratio));
          }
          EXPECT_NEAR(std::exp(log_ratio), r, 1e-8 * r) << d << " " << e << " " << beta;
        }
      }
    }
  }
}

// Huthmann & Zippelius's 3D coefficients (A, B, C, with G = 4/3 in collision time) follow from
// ours; in 3D B_rot = B, in 2D B_rot = 2 B (one rotational degree of freedom against two).
TEST(GranularTheory, CoefficientsHaveTheHuthmannZippeliusForm) {
  const double e = 0.85, beta = 0.3, q = 0.4;
  const double eta = q * (1 + beta) / (2 * (1 + q));
  const RoughCoolingCoefficients k3 = rough_cooling_coefficients(3, e, beta, q);
  EXPECT_NEAR(k3.a, 4.0 / 3.0 * ((1 - e * e) / 4 + eta * (1 - eta)), 1e-15);
  EXPECT_NEAR(k3.b, 4.0 / 3.0 * eta * eta / q, 1e-15);
  EXPECT_NEAR(k3.b_rot, k3.b, 1e-15);
  EXPECT_NEAR(k3.c, 4.0 / 3.0 * eta / q * (1 - eta / q), 1e-15);
  const RoughCoolingCoefficients k2 = rough_cooling_coefficients(2, e, beta, q);
  EXPECT_NEAR(k2.a, 2.0 * ((1 - e * e) / 4 + eta * (1 - eta) / 2), 1e-15);
  EXPECT_NEAR(k2.b_rot, 2.0 * k2.b, 1e-15);
}

// ---------------------------------------------------------------------------------------------
// Monte Carlo of collision-weighted binary encounters through resolve_contact.

struct McEstimate {
  double translational, translational_error;
  double rotational, rotational_error;
};

// Velocities and spins from Maxwellians at T_tr and T_rot; a uniformly random normal, flipped
// to make the pair approach (the flip doubles the density of approaching normals uniformly);
// each encounter weighted by |g_n|. Returns the weighted means of the energy changes with their
// standard errors (ratio estimator).
template <int D>
McEstimate monte_carlo(double e, double beta, double q, double t_tr, double t_rot, int samples,
                       std::uint64_t seed) {
  const double m = 1.3, radius = 0.6, inertia = q * m * radius * radius;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss;
  const double sv = std::sqrt(t_tr / m), sw = std::sqrt(t_rot / inertia);
  const auto velocity = [&] {
    Vec<D> v;
    for (double& c : v) c = sv * gauss(rng);
    return v;
  };
  const auto spin = [&] {
    if constexpr (D == 3) {
      return Vec<3>{sw * gauss(rng), sw * gauss(rng), sw * gauss(rng)};
    } else {
      return sw * gauss(rng);
    }
  };
  const ContactModel model{NormalRestitution::constant(e), TangentialModel::constant(beta), 0.0};
  ContactInput<D> in;
  in.mass_i = in.mass_j = m;
  in.radius_i = in.radius_j = radius;
  in.inertia_factor_i = in.inertia_factor_j = q;

  double sw_total = 0, s_tr = 0, s_rot = 0, s_tr2 = 0, s_rot2 = 0, s_w2 = 0;
  double s_w2tr = 0, s_w2rot = 0;
  for (int k = 0; k < samples; ++k) {
    Vec<D> vi = velocity(), vj = velocity(), n;
    for (double& c : n) c = gauss(rng);
    n = (1.0 / std::sqrt(norm2(n))) * n;
    if (dot(vi - vj, n) > 0.0) n = (-1.0) * n;
    in.normal = n;
    Spin<D> wi = spin(), wj = spin();
    const ContactResult<D> r = resolve_contact(model, in, vi, vj, wi, wj);
    const double w = r.impact_speed;
    const double tr = r.translational_energy_change, rot = r.rotational_energy_change;
    sw_total += w, s_w2 += w * w;
    s_tr += w * tr, s_rot += w * rot;
    s_tr2 += w * w * tr * tr, s_rot2 += w * w * rot * rot;
    s_w2tr += w * w * tr, s_w2rot += w * w * rot;
  }
  // Var of sum w (x - mean) / sum w: sum w^2 (x - mean)^2 / (sum w)^2.
  const auto error = [&](double mean, double s_x2, double s_w2x) {
    return std::sqrt(s_x2 - 2 * mean * s_w2x + mean * mean * s_w2) / sw_total;
  };
  const double tr_mean = s_tr / sw_total, rot_mean = s_rot / sw_total;
  return {tr_mean, error(tr_mean, s_tr2, s_w2tr), rot_mean, error(rot_mean, s_rot2, s_w2rot)};
}

template <int D>
void check_monte_carlo(std::uint64_t seed) {
  struct Case {
    double e, beta, q, t_tr, t_rot;
  };
  for (const Case& c : {Case{0.9, 0.4, 0.4, 1.1, 0.7}, Case{0.6, -0.5, 0.5, 0.8, 1.9},
                        Case{1.0, 1.0, 2.0 / 3.0, 1.0, 0.3}, Case{0.75, 0.9, 0.25, 2.0, 2.0}}) {
    const McEstimate mc = monte_carlo<D>(c.e, c.beta, c.q, c.t_tr, c.t_rot, 250000, seed++);
    const RoughEnergyChange theory =
        rough_energy_change_per_collision(D, c.e, c.beta, c.q, c.t_tr, c.t_rot);
    // 4 standard errors; the estimates resolve the changes to 1-3 %.
    EXPECT_NEAR(mc.translational, theory.translational, 4 * mc.translational_error)
        << D << "D e=" << c.e << " beta=" << c.beta;
    EXPECT_NEAR(mc.rotational, theory.rotational, 4 * mc.rotational_error)
        << D << "D e=" << c.e << " beta=" << c.beta;
    EXPECT_LT(mc.translational_error, 0.03 * std::abs(theory.translational));
    EXPECT_LT(mc.rotational_error, 0.03 * std::abs(theory.rotational));
  }
}
TEST(GranularTheory, MonteCarloEncountersMatchTheEnergyChanges3D) {
  check_monte_carlo<3>(101);
}
TEST(GranularTheory, MonteCarloEncountersMatchTheEnergyChanges2D) {
  check_monte_carlo<2>(201);
}

}  // namespace
}  // namespace kairos
