// The DEM with a soft law per species pair, as a run sets it up from [soft] / [[soft.pair]]
// (run/environment_setup): binary collisions of unequal species reproduce their pair's
// restitution, entering contact counts one collision; the inverse maps e -> dissipation.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "core/error.hpp"
#include "dem/dem_integrator.hpp"
#include "interactions/soft_contact.hpp"
#include "io/config.hpp"
#include "run/environment_setup.hpp"

namespace kairos {
namespace {

// Species A (m = 1, d = 1) and B (m = 3, d = 1.4).
constexpr const char* kSpecies = R"([system]
particles = 2
packing_fraction = 0.01
[[system.species]]
name = "A"
[[system.species]]
name = "B"
diameter = 1.4
mass = 3.0
)";

// Two particles of species a and b (0: A, 1: B) at first contact along x, approaching at
// relative speed v, moved back by dt/2 of free flight (the contact starts mid-step).
ParticleSystem<3> pair_state(std::uint32_t a, std::uint32_t b, double v, double dt) {
  const double radius[2] = {0.5, 0.7}, mass[2] = {1.0, 3.0};
  ParticleSystem<3> s;
  s.box.fill(30.0);
  s.species_names = {"A", "B"};
  const double l = radius[a] + radius[b];
  const double M = mass[a] + mass[b];
  // Centre-of-mass frame: v_a = +v m_b / M, v_b = -v m_a / M along x.
  const Vec<3> va{v * mass[b] / M, 0.0, 0.0}, vb{-v * mass[a] / M, 0.0, 0.0};
  const Vec<3> ra{15.0 - l, 15.0, 15.0}, rb{15.0, 15.0, 15.0};
  s.kinematics.push_back({ra - (0.5 * dt) * va, va, 0.0, radius[a]});
  s.kinematics.push_back({rb - (0.5 * dt) * vb, vb, 0.0, radius[b]});
  s.mass = {mass[a], mass[b]};
  s.species = {a, b};
  return s;
}

struct Outcome {
  double restitution = 0.0;
  std::uint64_t collisions = 0;
};

// Runs the head-on collision until the pair is apart; e = receding / approaching speed.
Outcome collide(const Environment<3>& env, std::uint32_t a, std::uint32_t b, double v, double dt) {
  DemOptions options;
  options.dt = dt;
  DemIntegrator<3> dem(pair_state(a, b, v, dt), env.soft, env.species, options);
  const double l = (a == 0 ? 0.5 : 0.7) + (b == 0 ? 0.5 : 0.7);
  bool touched = false;
  for (long n = 0; n < 10'000'000; ++n) {
    dem.step(1);
    const double r = std::abs(dem.position(1)[0] - dem.position(0)[0]);
    touched = touched || r < l;
    if (touched && r > l) break;
  }
  EXPECT_TRUE(touched);
  const double g = dem.velocity(1)[0] - dem.velocity(0)[0];
  return {g / v, dem.collisions()};
}

Environment<3> environment(const std::string& soft) {
  const Config config = parse_config(std::string(kSpecies) + soft, "test.toml");
  return make_environment<3>(config, pair_state(0, 1, 1.0, 0.0));
}

TEST(DemSpecies, DashpotPairsReproduceTheirOwnRestitution) {
  const Environment<3> env = environment(R"(
[soft]
model = "dashpot"
stiffness = 1e4
restitution = 0.9
[[soft.pair]]
species = ["A", "B"]
restitution = 0.6
)");
  ASSERT_EQ(env.species, 2u);
  ASSERT_EQ(env.soft.size(), 4u);
  // gamma of each pair from its reduced mass: the closed form gives back e.
  const double mu_aa = 0.5, mu_ab = 0.75, mu_bb = 1.5;
  EXPECT_NEAR(dashpot_head_on(mu_aa, 1e4, env.soft[0].damping).restitution, 0.9, 1e-12);
  EXPECT_NEAR(dashpot_head_on(mu_ab, 1e4, env.soft[1].damping).restitution, 0.6, 1e-12);
  EXPECT_EQ(env.soft[1].damping, env.soft[2].damping);
  EXPECT_NEAR(dashpot_head_on(mu_bb, 1e4, env.soft[3].damping).restitution, 0.9, 1e-12);
  // The DEM at dt = t_c / 1000 of the pair.
  for (const auto& [a, b, e, mu] : {std::tuple{0u, 1u, 0.6, mu_ab}, std::tuple{0u, 0u, 0.9, mu_aa},
                                    std::tuple{1u, 1u, 0.9, mu_bb}}) {
    const double t_c = dashpot_head_on(mu, 1e4, env.soft[a * 2 + b].damping).contact_time;
    const Outcome out = collide(env, a, b, 1.0, t_c / 1000.0);
    EXPECT_NEAR(out.restitution, e, 1e-4) << "species " << a << ", " << b;
    EXPECT_EQ(out.collisions, 1u);
  }
}

TEST(DemSpecies, MixedModelsEachPairItsOwnLaw) {
  // A-A a dashpot, A-B viscoelastic Hertz with e = 0.8 at impact speed 2 (the exact map).
  const Environment<3> env = environment(R"(
[soft]
model = "dashpot"
stiffness = 1e4
restitution = 0.9
[[soft.pair]]
species = ["A", "B"]
model = "hertz"
young = 1e5
poisson = 0.25
restitution = 0.8
restitution_speed = 2.0
)");
  const SoftContactLaw& ab = env.soft[1];
  ASSERT_EQ(ab.model, SoftModel::ViscoelasticHertz);
  const double mu = 0.75, r_eff = effective_radius(0.5, 0.7);
  EXPECT_DOUBLE_EQ(ab.stiffness, hertz_rho_one_material(1e5, 0.25, r_eff));
  const double T = std::pow(mu * mu / (ab.stiffness * ab.stiffness * 2.0), 0.2);
  EXPECT_NEAR(viscoelastic_head_on_restitution(ab.damping / T), 0.8, 1e-10);
  const double t_h = hertz_elastic_contact_time(mu, ab.stiffness, 2.0);
  EXPECT_NEAR(collide(env, 0, 1, 2.0, t_h / 2000.0).restitution, 0.8, 2e-4);
  // At another speed, the law's own e(v): slower impacts are more elastic.
  const double T_slow = std::pow(mu * mu / (ab.stiffness * ab.stiffness * 0.5), 0.2);
  const double e_slow = viscoelastic_head_on_restitution(ab.damping / T_slow);
  EXPECT_GT(e_slow, 0.8 + 0.02);
  EXPECT_NEAR(collide(env, 0, 1, 0.5, t_h / 2000.0).restitution, e_slow, 2e-4);
  const double t_c = dashpot_head_on(0.5, 1e4, env.soft[0].damping).contact_time;
  EXPECT_NEAR(collide(env, 0, 0, 1.0, t_c / 1000.0).restitution, 0.9, 1e-4);
}

TEST(DemSpecies, WallLawsUseTheParticleAsTheReducedMassAndRadius) {
  const Config config = parse_config(std::string(kSpecies) + R"(
[soft]
model = "hertz"
young = 1e5
dissipation = 1e-3
[[boundary.wall]]
face = "z-"
[[boundary.wall]]
face = "z+"
)",
                                     "test.toml");
  const Environment<3> env = make_environment<3>(config, pair_state(0, 1, 1.0, 0.0));
  ASSERT_EQ(env.soft_wall.size(), 2u);
  EXPECT_DOUBLE_EQ(env.soft_wall[1].stiffness, hertz_rho_one_material(1e5, 0.3, 0.7));
  EXPECT_DOUBLE_EQ(env.soft_wall[1].damping, 1e-3);
}

TEST(DemSpecies, SpeciesOfUnequalSizesNeedTheirOwnRadius) {
  // A species whose particles differ in size has no R_eff for Hertz.
  const Config config = parse_config(std::string(kSpecies) + R"(
[soft]
model = "hertz"
young = 1e5
)",
                                     "test.toml");
  ParticleSystem<3> s = pair_state(0, 1, 1.0, 0.0);
  s.species = {0, 0};
  try {
    make_environment<3>(config, s);
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("species A"), std::string::npos) << e.what();
  }
}

TEST(SoftInverse, RestitutionToDissipationMatchesTheReferenceTables) {
  // The head-on values of docs/physics.md#dashpot-head-on and
  // docs/physics.md#viscoelastic-head-on.
  EXPECT_NEAR(dashpot_zeta_for_restitution(0.7440793977), 0.1, 1e-9);
  EXPECT_NEAR(dashpot_zeta_for_restitution(0.0237695141), 3.0, 1e-8);  // overdamped
  EXPECT_EQ(dashpot_zeta_for_restitution(1.0), 0.0);
  EXPECT_NEAR(viscoelastic_head_on_restitution(0.1), 0.8451438063, 1e-9);
  EXPECT_NEAR(viscoelastic_c_dis_for_restitution(0.8451438063), 0.1, 1e-8);
  EXPECT_NEAR(viscoelastic_c_dis_for_restitution(0.2811310301), 1.0, 1e-8);
  // The physical example of docs/physics.md#viscoelastic-head-on: mu = 1e-3, rho = 1e7, v = 1
  // -> T = 1e-4, A = c T = 1e-5.
  EXPECT_NEAR(viscoelastic_dissipation_for_restitution(1e-3, 1e7, 0.845143806333, 1.0), 1e-5,
              1e-13);
  EXPECT_THROW(dashpot_zeta_for_restitution(0.0), InputError);
  EXPECT_THROW(viscoelastic_c_dis_for_restitution(1.5), InputError);
}

}  // namespace
}  // namespace kairos
