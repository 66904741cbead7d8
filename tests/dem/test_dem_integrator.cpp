// The force-based DEM reference integrator (src/dem/dem_integrator.hpp): head-on collisions
// against the closed forms (docs/physics.md#dashpot-head-on, docs/physics.md#hertz-contact-time)
// with dt^2 convergence, an oblique unequal-mass collision against integrate_contact_directly,
// energy and momentum in elastic gases, the energy budget of a cooling gas, 2D and 3D, input
// validation.
#include "dem/dem_integrator.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <string>

#include "core/error.hpp"

namespace kairos {
namespace {

using ::testing::HasSubstr;

template <int D>
ParticleSystem<D> make_system(double L) {
  ParticleSystem<D> s;
  s.box.fill(L);
  s.species_names = {"A"};
  return s;
}

template <int D>
void add(ParticleSystem<D>& s, const Vec<D>& r, const Vec<D>& v, double m, double R) {
  s.kinematics.push_back({r, v, s.time, R});
  s.mass.push_back(m);
  s.species.push_back(0);
}

// One two-body collision run through the DEM. The pair is given at first contact (t0); the
// particles are moved back by dt/2 of free flight so that the contact starts in the middle of a
// step (a linear dashpot's force jumps from 0 to gamma v_n there: a jump at a step boundary
// would cost an O(dt) impulse error, one mid-step cancels it to O(dt^2)).
struct PairRun {
  double contact_time = 0.0;  // from the force-zero crossing, interpolated linearly
  double restitution = 0.0;   // -rdot after / rdot before
  double t_after = 0.0;       // time of the first step after the end (from t0)
  Vec<3> r_i{}, r_j{}, v_i{}, v_j{};
};

template <int D>
PairRun run_pair(const SoftContactLaw& law, double m_i, double m_j, double R_i, double R_j,
                 const Vec<D>& r_i, const Vec<D>& r_j, const Vec<D>& v_i, const Vec<D>& v_j,
                 double dt) {
  const double L = 40.0;
  ParticleSystem<D> s = make_system<D>(L);
  Vec<D> shift;
  shift.fill(0.5 * L);
  add<D>(s, shift + r_i - (0.5 * dt) * v_i, v_i, m_i, R_i);
  add<D>(s, shift + r_j - (0.5 * dt) * v_j, v_j, m_j, R_j);
  DemOptions opt;
  opt.dt = dt;
  DemIntegrator<D> dem(s, law, opt);
  const double l = R_i + R_j, kappa = law.end_overlap_per_speed();
  auto phase = [&](double& overlap, double& rdot) {
    const Vec<D> d = dem.position(0) - dem.position(1);
    const Vec<D> g = dem.velocity(0) - dem.velocity(1);
    const double r = std::sqrt(norm2(d));
    overlap = l - r;
    rdot = dot(d, g) / r;
    return overlap - kappa * rdot;  // > 0 in contact, crosses 0 downwards at the end
  };
  double xi = 0.0, rdot = 0.0;
  const double rdot0 = dot(r_i - r_j, v_i - v_j) / l;
  double phi_prev = phase(xi, rdot);
  bool started = false;
  PairRun out;
  for (long n = 1; n < 10'000'000; ++n) {
    dem.step(1);
    const double phi = phase(xi, rdot);
    if (xi > 0.0) started = true;
    if (started && phi <= 0.0 && rdot > 0.0) {
      const double t_now = dem.time() - 0.5 * dt;  // from t0
      out.contact_time = t_now - dt * phi / (phi - phi_prev);
      out.t_after = t_now;
      for (int k = 0; k < D; ++k) {
        out.r_i[k] = dem.position(0)[k] - shift[k];
        out.r_j[k] = dem.position(1)[k] - shift[k];
        out.v_i[k] = dem.velocity(0)[k];
        out.v_j[k] = dem.velocity(1)[k];
      }
      out.restitution = -rdot / rdot0;  // free flight from here: rdot no longer changes much
      break;
    }
    phi_prev = phi;
  }
  // Free flight until apart: the rate of separation is then the final one.
  while (xi > 0.0) {
    dem.step(1);
    phase(xi, rdot);
  }
  out.restitution = -rdot / rdot0;
  return out;
}

template <int D>
PairRun head_on(const SoftContactLaw& law, double dt) {
  Vec<D> ri{}, rj{}, vi{}, vj{};
  ri[0] = 0.5;
  rj[0] = -0.5;
  vi[0] = -0.5;
  vj[0] = 0.5;
  return run_pair<D>(law, 1.0, 1.0, 0.5, 0.5, ri, rj, vi, vj, dt);
}

// Dashpot k = 1e4, zeta = 0.2 (mu = 1/2); impact speed 1.
SoftContactLaw dashpot_law(double zeta = 0.2) {
  const double k = 1e4, mu = 0.5;
  return SoftContactLaw::linear_dashpot(k, 2.0 * zeta * std::sqrt(k * mu));
}
// Hertz rho = 1e4, A = c_dis T at impact speed 1 (mu = 1/2).
SoftContactLaw hertz_law(double c_dis = 0.1) {
  const double rho = 1e4, mu = 0.5;
  const double T = std::pow(mu * mu / (rho * rho), 0.2);
  return SoftContactLaw::viscoelastic_hertz(rho, c_dis * T);
}

// ---------------------------------------------------------------------------------------------
// Head-on: closed forms, dt^2 convergence.

template <int D>
void check_head_on(const SoftContactLaw& law, double t_ref, double e_ref, double tol_1000,
                   double order_min, bool elastic = false) {
  double err_t[3], err_e[3];
  for (int m = 0; m < 3; ++m) {
    const double dt = t_ref / (250.0 * std::pow(2.0, m));
    const PairRun run = head_on<D>(law, dt);
    err_t[m] = std::abs(run.contact_time / t_ref - 1.0);
    err_e[m] = std::abs(run.restitution / e_ref - 1.0);
    std::printf("D=%d dt=t_c/%g: t_c rel err %.3e, e rel err %.3e\n", D, 250.0 * std::pow(2.0, m),
                err_t[m], err_e[m]);
  }
  EXPECT_LT(err_t[2], tol_1000);
  EXPECT_LT(err_e[2], tol_1000);
  for (int m = 0; m < 2; ++m) {
    EXPECT_GT(std::log2(err_t[m] / err_t[m + 1]), order_min) << "contact time, halving " << m;
    // Elastic: e = 1 to far better than dt^2 (time reversibility), no order to see.
    if (!elastic) {
      EXPECT_GT(std::log2(err_e[m] / err_e[m + 1]), order_min) << "restitution, halving " << m;
    }
  }
}

TEST(Dem, HeadOnDashpotMatchesClosedFormWithDtSquaredConvergence) {
  const SoftContactLaw law = dashpot_law();
  const HeadOn ref = dashpot_head_on(0.5, law.stiffness, law.damping);
  check_head_on<3>(law, ref.contact_time, ref.restitution, 1e-4, 1.8);
  check_head_on<2>(law, ref.contact_time, ref.restitution, 1e-4, 1.8);
}

TEST(Dem, HeadOnElasticDashpotIsElastic) {
  const SoftContactLaw law = SoftContactLaw::linear_dashpot(1e4, 0.0);
  const HeadOn ref = dashpot_head_on(0.5, law.stiffness, 0.0);
  check_head_on<3>(law, ref.contact_time, 1.0, 1e-4, 1.8, true);
}

TEST(Dem, HeadOnElasticHertzMatchesClosedForm) {
  const SoftContactLaw law = SoftContactLaw::viscoelastic_hertz(1e4, 0.0);
  const double t_H = hertz_elastic_contact_time(0.5, 1e4, 1.0);
  check_head_on<3>(law, t_H, 1.0, 1e-4, 1.8, true);
  check_head_on<2>(law, t_H, 1.0, 1e-4, 1.8, true);
}

TEST(Dem, HeadOnViscoelasticHertzMatchesDirectIntegration) {
  const SoftContactLaw law = hertz_law(0.1);
  PairState at{};
  at.r_i = {0.5, 0.0, 0.0};
  at.r_j = {-0.5, 0.0, 0.0};
  at.v_i = {-0.5, 0.0, 0.0};
  at.v_j = {0.5, 0.0, 0.0};
  const DirectContact direct = integrate_contact_directly(law, SoftPair{}, at);
  const double e_ref = (direct.state.v_i[0] - direct.state.v_j[0]) / 1.0;
  check_head_on<3>(law, direct.contact_time, e_ref, 1e-4, 1.4);
}

// ---------------------------------------------------------------------------------------------
// Oblique, unequal masses and radii: the direct 3D force integration of soft_contact.hpp.

double max_abs3(const Vec<3>& a) {
  return std::max({std::abs(a[0]), std::abs(a[1]), std::abs(a[2])});
}

TEST(Dem, ObliqueUnequalMassCollisionAgreesWithDirectIntegration) {
  for (const SoftContactLaw& law : {dashpot_law(0.3), hertz_law(0.2)}) {
    const SoftPair pair{1.0, 3.0, 0.5, 0.7};
    const double l = pair.radius_i + pair.radius_j;
    Vec<3> n = {1.0, 0.3, -0.2};
    n = (1.0 / std::sqrt(norm2(n))) * n;
    PairState at{};
    at.r_i = l * n;
    at.r_j = {0.0, 0.0, 0.0};
    at.v_i = {-1.0, 0.4, 0.2};
    at.v_j = {0.1, -0.2, 0.3};
    const DirectContact direct = integrate_contact_directly(law, pair, at);
    const double g0 = std::sqrt(norm2(at.v_i - at.v_j));
    double previous = 0.0;
    for (const double per_contact : {250.0, 500.0, 1000.0, 4000.0}) {
      const double dt = direct.contact_time / per_contact;
      const PairRun run = run_pair<3>(law, pair.m_i, pair.m_j, pair.radius_i, pair.radius_j, at.r_i,
                                      at.r_j, at.v_i, at.v_j, dt);
      // The direct end state, moved on in free flight to the DEM's sample time.
      const double tau = run.t_after - direct.contact_time;
      const double err_v =
          std::max(max_abs3(run.v_i - direct.state.v_i), max_abs3(run.v_j - direct.state.v_j)) / g0;
      const double err_r =
          std::max(max_abs3(run.r_i - (direct.state.r_i + tau * direct.state.v_i)),
                   max_abs3(run.r_j - (direct.state.r_j + tau * direct.state.v_j))) /
          l;
      const double err_t = std::abs(run.contact_time / direct.contact_time - 1.0);
      const double err = std::max({err_v, err_r, err_t});
      std::printf("%s dt=t_c/%g: velocity %.3e position %.3e contact time %.3e\n",
                  law.model == SoftModel::LinearDashpot ? "dashpot" : "hertz", per_contact, err_v,
                  err_r, err_t);
      if (previous > 0.0) {
        EXPECT_LT(err, 0.45 * previous) << per_contact;  // shrinks with dt
      }
      previous = err;
    }
    EXPECT_LT(previous, 1e-6);  // at dt = t_c / 4000
  }
}

// ---------------------------------------------------------------------------------------------
// Gases: lattice start, Maxwellian velocities with zero total momentum.

template <int D>
ParticleSystem<D> gas(int per_side, double packing, std::uint32_t seed) {
  const double R = 0.5;
  const double vol = D == 3 ? 4.0 / 3.0 * M_PI * R * R * R : M_PI * R * R;
  const int N = D == 3 ? per_side * per_side * per_side : per_side * per_side;
  const double L = std::pow(N * vol / packing, 1.0 / D);
  ParticleSystem<D> s = make_system<D>(L);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss;
  std::uniform_real_distribution<double> jitter(-0.05, 0.05);
  Vec<D> p{};
  for (int i = 0; i < N; ++i) {
    Vec<D> r, v;
    int rest = i;
    for (int k = 0; k < D; ++k) {
      r[k] = (rest % per_side + 0.5 + jitter(rng)) * L / per_side;
      rest /= per_side;
      v[k] = gauss(rng);
    }
    const double m = i % 2 == 0 ? 1.0 : 2.0;  // unequal masses
    add<D>(s, r, v, m, i % 3 == 0 ? 0.4 : R);
    p = p + m * v;
  }
  double M = 0.0;
  for (double m : s.mass) M += m;
  for (auto& k : s.kinematics) k.vel = k.vel - (1.0 / M) * p;
  return s;
}

struct GasRun {
  double max_energy_error = 0.0;  // max |E_kin + U + E_dis - E0| / E0 over the run
  double max_momentum = 0.0;      // max |P_k| / sum m |v|
  double kinetic_ratio = 0.0;     // E_kin(end) / E_kin(0)
  double dissipated = 0.0;        // E_dis / E0
  long builds = 0;
};

template <int D>
GasRun run_gas(const SoftContactLaw& law, double steps_per_contact, double duration) {
  const ParticleSystem<D> s = gas<D>(D == 3 ? 5 : 10, 0.2, 7);
  DemOptions opt;
  opt.steps_per_contact = steps_per_contact;
  opt.reference_speed = 4.0;
  DemIntegrator<D> dem(s, law, opt);
  const double e0 = dem.kinetic_energy() + dem.potential_energy();
  double scale = 0.0;
  for (std::size_t i = 0; i < dem.size(); ++i)
    scale += s.mass[i] * std::sqrt(norm2(dem.velocity(i)));
  GasRun out;
  const long steps = std::lround(duration / dem.dt());
  for (long n = 0; n < steps; n += 10) {
    dem.step(10);
    const double e = dem.kinetic_energy() + dem.potential_energy() + dem.dissipated_energy();
    out.max_energy_error = std::max(out.max_energy_error, std::abs(e / e0 - 1.0));
    for (double pk : dem.momentum())
      out.max_momentum = std::max(out.max_momentum, std::abs(pk) / scale);
  }
  out.kinetic_ratio = dem.kinetic_energy() / e0;
  out.dissipated = dem.dissipated_energy() / e0;
  out.builds = dem.neighbour_list_builds();
  std::printf(
      "D=%d steps/contact %g: energy %.3e momentum %.3e E_kin ratio %.4f E_dis %.4f "
      "(%ld steps, %ld list builds)\n",
      D, steps_per_contact, out.max_energy_error, out.max_momentum, out.kinetic_ratio,
      out.dissipated, dem.steps(), out.builds);
  return out;
}

template <int D>
void check_gas(const SoftContactLaw& law, bool elastic) {
  const GasRun a = run_gas<D>(law, 50.0, 5.0);
  const GasRun b = run_gas<D>(law, 100.0, 5.0);
  const GasRun c = run_gas<D>(law, 200.0, 5.0);
  for (const GasRun* g : {&a, &b, &c}) EXPECT_LT(g->max_momentum, 1e-13);
  // Verlet accuracy: the budget error shrinks ~4x per halving of dt (the maximum over a chaotic
  // elastic run is noisier: 16x over two halvings, give or take).
  EXPECT_LT(a.max_energy_error, 1e-2);
  EXPECT_GT(a.max_energy_error / c.max_energy_error, 8.0);
  if (!elastic) {
    EXPECT_GT(a.max_energy_error / b.max_energy_error, 2.8);
    EXPECT_GT(b.max_energy_error / c.max_energy_error, 2.8);
  }
  if (elastic) {
    EXPECT_LT(std::abs(c.dissipated), 1e-12);  // round-off of F_el - F
  } else {
    EXPECT_LT(c.kinetic_ratio, 0.7);  // it cooled
    EXPECT_GT(c.dissipated, 0.3);
  }
  EXPECT_GT(c.builds, 10);
}

TEST(Dem, ElasticGasConservesEnergyToDtSquaredAndMomentumToRoundOff) {
  check_gas<3>(SoftContactLaw::linear_dashpot(1e4, 0.0), true);
  check_gas<2>(SoftContactLaw::linear_dashpot(1e4, 0.0), true);
  check_gas<3>(SoftContactLaw::viscoelastic_hertz(1e4, 0.0), true);
  check_gas<2>(SoftContactLaw::viscoelastic_hertz(1e4, 0.0), true);
}

TEST(Dem, InelasticGasCoolsAndTheDissipationCounterClosesTheBudget) {
  check_gas<3>(dashpot_law(0.3), false);
  check_gas<2>(dashpot_law(0.3), false);
  check_gas<3>(hertz_law(0.3), false);
  check_gas<2>(hertz_law(0.3), false);
}

// ---------------------------------------------------------------------------------------------
// Neighbour search: the elastic energy (a sum over overlapping pairs) against all pairs by brute
// force, for boxes of 2 (deduplicated stencil), 3 and many cells per axis, after renumbering.

template <int D>
double brute_force_energy(const ParticleSystem<D>& s, double k) {
  double u = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i)
    for (std::size_t j = i + 1; j < s.size(); ++j) {
      double r2 = 0.0;
      for (int a = 0; a < D; ++a) {
        double d = s.kinematics[i].pos[a] - s.kinematics[j].pos[a];
        d -= s.box[a] * std::round(d / s.box[a]);
        r2 += d * d;
      }
      const double xi = s.kinematics[i].radius + s.kinematics[j].radius - std::sqrt(r2);
      if (xi > 0.0) u += 0.5 * k * xi * xi;
    }
  return u;
}

template <int D>
void check_neighbour_search(double L, int N) {
  ParticleSystem<D> s = make_system<D>(L);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  while (static_cast<int>(s.size()) < N) {
    Vec<D> r, v;
    for (int a = 0; a < D; ++a) {
      r[a] = L * u01(rng);
      v[a] = u01(rng) - 0.5;
    }
    const double R = s.size() % 2 == 0 ? 0.5 : 0.35;
    bool ok = true;
    for (std::size_t j = 0; j < s.size() && ok; ++j) {
      double r2 = 0.0;
      for (int a = 0; a < D; ++a) {
        double d = r[a] - s.kinematics[j].pos[a];
        d -= L * std::round(d / L);
        r2 += d * d;
      }
      ok = std::sqrt(r2) > R + s.kinematics[j].radius - 0.1;  // shallow overlaps allowed
    }
    if (ok) add<D>(s, r, v, 1.0, R);
  }
  const double k = 1e3;
  DemIntegrator<D> dem(s, SoftContactLaw::linear_dashpot(k, 0.0));
  const double u0 = brute_force_energy(s, k);
  EXPECT_GT(u0, 0.0) << "no overlaps to find, L = " << L;
  EXPECT_NEAR(dem.potential_energy(), u0, 1e-12 * u0) << "L = " << L;
  dem.step(3000);
  EXPECT_GE(dem.neighbour_list_builds(), 3);
  const ParticleSystem<D> out = dem.export_state();
  const double u1 = brute_force_energy(out, k);
  EXPECT_NEAR(dem.potential_energy(), u1, 1e-9 * (u0 + u1) + 1e-300) << "L = " << L;
  for (std::size_t i = 0; i < out.size(); ++i)
    for (int a = 0; a < D; ++a) EXPECT_EQ(out.kinematics[i].pos[a], dem.position(i)[a]);
}

TEST(Dem, NeighbourSearchFindsEveryOverlappingPair) {
  check_neighbour_search<3>(3.0, 20);   // 2 cells per axis
  check_neighbour_search<3>(3.5, 30);   // 3
  check_neighbour_search<3>(8.0, 300);  // 7
  check_neighbour_search<2>(3.0, 9);
  check_neighbour_search<2>(3.5, 12);
  check_neighbour_search<2>(20.0, 250);
}

// ---------------------------------------------------------------------------------------------
// Default time step, export, validation.

TEST(Dem, DefaultTimeStepIsAFiftiethOfTheContactTime) {
  ParticleSystem<3> s = make_system<3>(10.0);
  add<3>(s, {2, 2, 2}, {1, 0, 0}, 1.0, 0.5);
  add<3>(s, {5, 5, 5}, {0, -1, 0}, 2.0, 0.5);
  const SoftContactLaw dash = dashpot_law();
  EXPECT_DOUBLE_EQ(DemIntegrator<3>(s, dash).dt(),
                   dashpot_head_on(0.5, dash.stiffness, dash.damping).contact_time / 50.0);
  const SoftContactLaw hz = hertz_law();
  EXPECT_DOUBLE_EQ(DemIntegrator<3>(s, hz).dt(),
                   hertz_elastic_contact_time(0.5, hz.stiffness, 2.0) / 50.0);
}

TEST(Dem, ExportWrapsPositionsAndSetsTime) {
  ParticleSystem<2> s = make_system<2>(10.0);
  add<2>(s, {9.99, 5.0}, {1.0, 0.0}, 1.0, 0.5);
  add<2>(s, {3.0, 5.0}, {0.0, 0.0}, 1.0, 0.5);
  s.events.resize(2);
  DemOptions opt;
  opt.dt = 0.01;
  DemIntegrator<2> dem(s, SoftContactLaw::linear_dashpot(1e4, 0.0), opt);
  dem.step(100);
  const ParticleSystem<2> out = dem.export_state();
  EXPECT_DOUBLE_EQ(out.time, dem.time());
  EXPECT_NEAR(out.time, 1.0, 1e-12);
  EXPECT_NEAR(out.kinematics[0].pos[0], 0.99, 1e-9);
  EXPECT_EQ(out.kinematics[0].time, out.time);
  EXPECT_TRUE(out.events.empty());
  EXPECT_EQ(dem.contact_count(), 0u);
}

template <typename F>
void expect_input_error(F&& f, const std::string& needle) {
  try {
    f();
    ADD_FAILURE() << "no InputError; expected one mentioning '" << needle << "'";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr(needle));
  }
}

TEST(Dem, BadInputThrowsInputErrorNamingIt) {
  const SoftContactLaw law = dashpot_law();
  auto pair = [](double sep) {
    ParticleSystem<3> s = make_system<3>(10.0);
    add<3>(s, {5, 5, 5}, {0, 0, 0}, 1.0, 0.5);
    add<3>(s, {5 + sep, 5, 5}, {0, 0, 0}, 1.0, 0.5);
    return s;
  };
  expect_input_error([&] { DemIntegrator<3>(pair(0.6), law); }, "overlap");
  EXPECT_NO_THROW(DemIntegrator<3>(pair(0.9), law));
  DemOptions bad;
  bad.dt = -1e-3;
  expect_input_error([&] { DemIntegrator<3>(pair(2.0), law, bad); }, "dt");
  bad.dt = std::nan("");
  expect_input_error([&] { DemIntegrator<3>(pair(2.0), law, bad); }, "dt");
  ParticleSystem<3> s = pair(2.0);
  s.kinematics[1].pos[2] = std::nan("");
  expect_input_error([&] { DemIntegrator<3>(s, law); }, "position of particle 1");
  s = pair(2.0);
  s.kinematics[0].vel[0] = std::numeric_limits<double>::infinity();
  expect_input_error([&] { DemIntegrator<3>(s, law); }, "velocity of particle 0");
  s = pair(2.0);
  s.mass[1] = 0.0;
  expect_input_error([&] { DemIntegrator<3>(s, law); }, "mass of particle 1");
  s = pair(2.0);
  s.box[1] = 2.0;
  expect_input_error([&] { DemIntegrator<3>(s, law); }, "box length");
  s = pair(2.0);
  s.periodic[0] = false;
  expect_input_error([&] { DemIntegrator<3>(s, law); }, "periodic");
  expect_input_error(
      [&] {
        DemIntegrator<3>(pair(2.0), SoftContactLaw{SoftModel::LinearDashpot, -1.0, 0.0});
      },
      "k");
  // A time step far too large: the pair runs deep into each other within one step.
  s = pair(1.05);
  s.kinematics[0].vel = {20.0, 0, 0};
  DemOptions huge;
  huge.dt = 0.05;
  DemIntegrator<3> dem(s, law, huge);
  expect_input_error([&] { dem.step(10); }, "time step dt");
}

}  // namespace
}  // namespace kairos
