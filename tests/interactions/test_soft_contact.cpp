// Soft frictionless spheres (src/interactions/soft_contact.hpp): the reduced two-body solver and
// collision map against independent values (docs/physics.md#dashpot-head-on,
// docs/physics.md#viscoelastic-head-on, docs/physics.md#collision-map) and the closed forms, the
// 3D reconstruction against direct force integration, the hard-sphere failure
// (docs/physics.md#hard-sphere-failure), and input validation.
#include "interactions/soft_contact.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "interactions/granular_contact.hpp"

namespace kairos {
namespace {

using ::testing::HasSubstr;

// |got - given| within half a unit of the last digit of `given` (a decimal string, optionally
// with an exponent), plus `slack` units of it.
void expect_digits(double got, const std::string& given, double slack = 0.0,
                   const std::string& what = "") {
  const std::size_t e = given.find_first_of("eE");
  const std::string mantissa = given.substr(0, e);
  const int exponent = e == std::string::npos ? 0 : std::stoi(given.substr(e + 1));
  const std::size_t dot = mantissa.find('.');
  const int decimals = dot == std::string::npos ? 0 : static_cast<int>(mantissa.size() - dot - 1);
  const double unit = std::pow(10.0, exponent - decimals);
  const double value = std::strtod(given.c_str(), nullptr);
  EXPECT_LE(std::abs(got - value), (0.5 + slack) * unit)
      << what << ": got " << std::to_string(got) << " (" << got - value << " off), given " << given;
}

double norm(const Vec<3>& a) {
  return std::sqrt(norm2(a));
}

Vec<3> cross3(const Vec<3>& a, const Vec<3>& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

double max_abs(const Vec<3>& a) {
  return std::max({std::abs(a[0]), std::abs(a[1]), std::abs(a[2])});
}

CollisionMap head_on(SoftModel model, double c_dis) {
  return collision_map({model, 0.0, 100.0, c_dis});
}

// ---------------------------------------------------------------------------------------------
// Dashpot head-on (docs/physics.md#dashpot-head-on), closed form and ODE, to the digits given.

struct DashpotRow {
  double zeta;
  const char* omega0_tc;
  const char* e;
  const char* e_naive;  // empty where not given
};

const std::vector<DashpotRow> kDashpotRows = {
    {0.05, "3.0453600222", "0.8587581018", "0.8544678930"},
    {0.1, "2.9560753247", "0.7440793977", "0.7292476143"},
    {0.3, "2.6544745638", "0.4509754529", "0.3723261049"},
    {0.5, "2.4183991523", "0.2984360592", "0.1630335348"},
    {0.8, "2.1450036960", "0.1797833154", ""},
    {1.0, "2.0000000000", "0.1353352832", ""},
    {1.5, "1.7216357639", "0.0755883094", ""},
    {3.0, "1.2464504803", "0.0237695141", ""},
};

TEST(SoftContact, DashpotHeadOnTableClosedForm) {
  for (const DashpotRow& row : kDashpotRows) {
    const HeadOn h = dashpot_head_on_reduced(row.zeta);
    const std::string at = "zeta " + std::to_string(row.zeta);
    expect_digits(h.contact_time, row.omega0_tc, 0.0, at);
    expect_digits(h.restitution, row.e, 0.0, at);
    if (*row.e_naive != '\0')
      expect_digits(dashpot_head_on_naive_reduced(row.zeta).restitution, row.e_naive, 0.0, at);
  }
}

TEST(SoftContact, DashpotHeadOnTableOde) {
  for (const DashpotRow& row : kDashpotRows) {
    const CollisionMap m = head_on(SoftModel::LinearDashpot, 2.0 * row.zeta);
    const std::string at = "zeta " + std::to_string(row.zeta);
    expect_digits(m.eps_t, row.omega0_tc, 0.0, at);
    expect_digits(-m.eps_rdot, row.e, 0.0, at);
    EXPECT_EQ(m.phi_c, 0.0);
  }
}

TEST(SoftContact, DashpotPhysicalExample) {
  // mu = 0.5, k = 1e4, gamma = 20 (SI).
  const HeadOn h = dashpot_head_on(0.5, 1e4, 20.0);
  expect_digits(h.contact_time, "2.041284674558e-2");
  expect_digits(h.restitution, "0.664808044481");
  const double omega0 = std::sqrt(1e4 / 0.5), zeta = 20.0 / (2.0 * 0.5) / omega0;
  const HeadOn naive = dashpot_head_on_naive_reduced(zeta);
  expect_digits(naive.contact_time / omega0, "2.243994752564e-2");
  expect_digits(naive.restitution, "0.638394434666");
  // The same collision in 3D (m_i = m_j = 1, so mu = 0.5) through the map.
  const SoftPair pair{1.0, 1.0, 0.5, 0.5};
  const PairState s{{0.5, 0, 0}, {-0.5, 0, 0}, {-0.7, 0, 0}, {0.7, 0, 0}};
  const SoftCollision c = soft_collision(SoftContactLaw::linear_dashpot(1e4, 20.0), pair, s);
  expect_digits(c.contact_time, "2.041284674558e-2");
  expect_digits((c.state.v_i[0] - c.state.v_j[0]) / 1.4, "0.664808044481");
  // The overlap at the end: xi_c = (gamma/k) e v.
  EXPECT_NEAR(1.0 - norm(c.state.r_i - c.state.r_j), dashpot_end_overlap(0.5, 1e4, 20.0, 1.4),
              1e-15);
  EXPECT_NEAR(dashpot_end_overlap(0.5, 1e4, 20.0, 1.4), 20.0 / 1e4 * h.restitution * 1.4, 1e-18);
}

// ---------------------------------------------------------------------------------------------
// Viscoelastic head-on (docs/physics.md#viscoelastic-head-on).

TEST(SoftContact, ViscoelasticHeadOnTable) {
  const std::vector<double> c = {0, 0.001, 0.01, 0.05, 0.1, 0.2, 0.5, 1, 2};
  const std::vector<const char*> tc = {"3.2180654597", "3.2171227127", "3.2086804313",
                                       "3.1720748104", "3.1283575446", "3.0472153558",
                                       "2.8445511271", "2.5969161397", "2.2738562741"};
  const std::vector<const char*> e = {"1",
                                      "0.9982716442",
                                      "0.9828832905",
                                      "0.9181328552",
                                      "0.8451438063",
                                      "0.7220854397",
                                      "0.4788382707",
                                      "0.2811310301",
                                      "0.1337166224"};
  const std::vector<const char*> pade = {"1",        "0.998272", "0.982884", "0.918155", "0.845276",
                                         "0.722744", "0.482196", "0.288002", "0.142359"};
  for (std::size_t k = 0; k < c.size(); ++k) {
    const std::string at = "c_dis " + std::to_string(c[k]);
    const CollisionMap m = head_on(SoftModel::ViscoelasticHertz, c[k]);
    expect_digits(m.eps_t, tc[k], 0.0, at);
    // At c = 0.01 the given e (…2905) is a rounding of the reference's DOP853 value at rtol
    // 1e-12, 0.98288329045388; converged (here, and SciPy's DOP853 at 1e-13 and Radau at 1e-12
    // and 1e-13) it is 0.98288329044(67..88), 5.2e-11 from the given digits: a 0.1-unit slack.
    const double slack = c[k] == 0.0 ? 1e-10 : (c[k] == 0.01 ? 0.1 : 0.0);  // "1": to 1e-10
    expect_digits(-m.eps_rdot, e[k], slack, at);
    // The MP2011 Padé row, through granular_contact's form in the series variable.
    expect_digits(viscoelastic_restitution(viscoelastic_series_variable(c[k])), pade[k], 0.0, at);
  }
}

TEST(SoftContact, ViscoelasticPhysicalExample) {
  // mu = 1e-3 kg, rho = 1e7 N m^-3/2, A = 1e-5 s, v = 1 m/s.
  const SoftContactLaw law = SoftContactLaw::viscoelastic_hertz(1e7, 1e-5);
  const CollisionUnits u = reduce_collision(law, 1e-3, 0.01, 1.0, 0.0);
  EXPECT_NEAR(u.time_unit, 1e-4, 1e-18);
  EXPECT_NEAR(u.reduced.c_dis, 0.1, 1e-14);
  EXPECT_NEAR(std::pow(viscoelastic_series_variable(u.reduced.c_dis), 2.0), 0.15, 1e-14);  // beta_A
  const CollisionMap m = collision_map(u.reduced);
  // Given to 12 digits (0.845143806333, 3.128357544578e-4), which carry the reference's own
  // integration error: SciPy's DOP853 at rtol 1e-12 prints them, at 1e-13 (and Radau at 1e-12,
  // 1e-13) it gives 0.84514380632(75..79) and 3.12835754458(20..25)e-4, as here. Checked to 11.
  expect_digits(-m.eps_rdot, "0.845143806333", 6.0);
  expect_digits(m.eps_t * u.time_unit, "3.128357544578e-4", 6.0);
  expect_digits(-m.eps_rdot, "0.84514380633");
  expect_digits(m.eps_t * u.time_unit, "3.12835754458e-4");
}

// ---------------------------------------------------------------------------------------------
// Oblique maps (docs/physics.md#collision-map).

struct ObliqueRow {
  SoftModel model;
  double c_dis, l_tilde, ratio;
  const char *eps_t, *eps_r, *eps_rdot, *phi_c, *eps_phi;
};

TEST(SoftContact, ObliqueMapsTable) {
  const SoftModel D = SoftModel::LinearDashpot, H = SoftModel::ViscoelasticHertz;
  const std::vector<ObliqueRow> rows = {
      {D, 0.2, 10, 0.1, "2.953175721", "0.985114748", "-0.744262597", "3.334099468e-2",
       "3.334099468"},
      {D, 0.2, 10, 1, "2.682367270", "0.984827490", "-0.758625484", "2.993269269e-1",
       "2.993269269"},
      {D, 0.2, 10, 5, "0.569072011", "0.988381544", "-0.580922808", "2.923254520e-1",
       "0.584650904"},
      {D, 0.2, 100, 1, "2.932214627", "0.998508864", "-0.745568215", "2.966277879e-2",
       "2.966277879"},
      {D, 0.2, 100, 5, "2.402680004", "0.998468062", "-0.765968996", "1.212693651e-1",
       "2.425387303"},
      {H, 0.1, 10, 1, "2.917816077", "0.987133303", "-0.857779828", "3.317410457e-1",
       "3.317410457"},
      {H, 0.1, 10, 5, "0.629925567", "0.989780901", "-0.681273249", "3.240080428e-1",
       "0.648016086"},
      {H, 0.1, 100, 1, "3.111977368", "0.998730433", "-0.846377984", "3.153660282e-2",
       "3.153660282"},
      {H, 0.1, 100, 5, "2.695240503", "0.998704877", "-0.863415178", "1.362540240e-1",
       "2.725080480"},
  };
  for (const ObliqueRow& row : rows) {
    const std::string at = std::string(row.model == D ? "dashpot" : "Hertz") + " l~ " +
                           std::to_string(row.l_tilde) + " vt/vn " + std::to_string(row.ratio);
    const CollisionMap m =
        collision_map({row.model, row.l_tilde * row.ratio, row.l_tilde, row.c_dis});
    expect_digits(m.eps_t, row.eps_t, 0.0, at + " eps_t");
    expect_digits(m.eps_r, row.eps_r, 0.0, at + " eps_r");
    expect_digits(m.eps_rdot, row.eps_rdot, 0.0, at + " eps_rdot");
    expect_digits(m.phi_c, row.phi_c, 0.0, at + " phi_c");
    expect_digits(m.eps_phi, row.eps_phi, 0.0, at + " eps_phi");
    EXPECT_NEAR(m.eps_phidot * m.eps_r * m.eps_r, 1.0, 1e-12) << at;
    EXPECT_NEAR(m.end_overlap, row.l_tilde * (1.0 - m.eps_r), 1e-13 * row.l_tilde) << at;
  }
}

// With c_dis = 0: eps_r = 1 and eps_rdot = -1 exactly (energy conservation); eps_phidot eps_r^2 = 1
// always (angular momentum, eps_phidot integrated on its own).
TEST(SoftContact, ElasticAndAngularMomentumChecks) {
  for (SoftModel model : {SoftModel::LinearDashpot, SoftModel::ViscoelasticHertz}) {
    for (double l_tilde : {3.0, 10.0, 100.0, 1e4}) {
      for (double ratio : {0.0, 0.01, 0.3, 1.0, 5.0, 20.0}) {
        for (double c_dis : {0.0, 0.05, 0.5, 3.0}) {
          const CollisionMap m = collision_map({model, l_tilde * ratio, l_tilde, c_dis});
          const std::string at = "model " + std::to_string(static_cast<int>(model)) + " l~ " +
                                 std::to_string(l_tilde) + " vt/vn " + std::to_string(ratio) +
                                 " c " + std::to_string(c_dis);
          EXPECT_NEAR(m.eps_phidot * m.eps_r * m.eps_r, 1.0, 1e-12) << at;
          EXPECT_LT(m.eps_r, c_dis > 0.0 ? 1.0 : 1.0 + 1e-12) << at;
          EXPECT_LT(m.eps_rdot, 0.0) << at;
          if (c_dis == 0.0) {
            EXPECT_NEAR(m.eps_r, 1.0, 1e-13) << at;
            EXPECT_NEAR(m.eps_rdot, -1.0, 1e-12) << at;
          }
        }
      }
    }
  }
}

// The map converges: default tolerance against a ten times tighter one, grazing cases included.
TEST(SoftContact, MapConvergesWithTolerance) {
  MapOptions tight;
  tight.tolerance = 1e-14;
  for (SoftModel model : {SoftModel::LinearDashpot, SoftModel::ViscoelasticHertz}) {
    for (const ReducedCollision& base :
         {ReducedCollision{model, 100.0 * 20.0, 100.0, 0.1},
          ReducedCollision{model, 7.0, 10.0, 0.01}, ReducedCollision{model, 3e4, 1e3, 1.0}}) {
      ReducedCollision r = base;
      r.model = model;
      const CollisionMap a = collision_map(r), b = collision_map(r, tight);
      EXPECT_NEAR(a.eps_t, b.eps_t, 1e-12 * b.eps_t);
      EXPECT_NEAR(a.eps_rdot, b.eps_rdot, 1e-12);
      EXPECT_NEAR(a.end_overlap, b.end_overlap, 1e-12 * (1.0 + b.end_overlap));
      EXPECT_NEAR(a.eps_phi, b.eps_phi, 1e-12 * b.eps_phi);
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Closed forms against the ODE, to at least 10 digits.

// The piecewise forms of docs/physics.md#dashpot-head-on, written independently of
// dashpot_head_on_reduced.
double piecewise_dashpot_time(double zeta) {
  const double beta = zeta;  // omega_0 = 1
  if (zeta < 1.0) {
    const double w = std::sqrt(1.0 - beta * beta);
    if (beta < 1.0 / std::numbers::sqrt2)
      return (std::numbers::pi - std::atan(2.0 * beta * w / (w * w - beta * beta))) / w;
    if (beta == 1.0 / std::numbers::sqrt2) return std::numbers::pi / (2.0 * w);
    return std::atan(2.0 * beta * w / (beta * beta - w * w)) / w;
  }
  if (zeta == 1.0) return 2.0;
  const double W = std::sqrt(beta * beta - 1.0);
  return std::log((beta + W) / (beta - W)) / W;
}

TEST(SoftContact, DashpotClosedFormAgainstOdeAllRegimes) {
  for (double zeta : {0.0, 0.01, 0.2, 0.6, 1.0 / std::numbers::sqrt2, 0.75, 0.999999, 1.0, 1.000001,
                      1.2, 2.0, 5.0, 10.0}) {
    const HeadOn h = dashpot_head_on_reduced(zeta);
    const CollisionMap m = head_on(SoftModel::LinearDashpot, 2.0 * zeta);
    EXPECT_NEAR(m.eps_t, h.contact_time, 1e-10 * h.contact_time) << zeta;
    EXPECT_NEAR(-m.eps_rdot, h.restitution, 1e-10 * h.restitution) << zeta;
    EXPECT_NEAR(h.restitution, std::exp(-zeta * h.contact_time), 1e-15);
    EXPECT_NEAR(piecewise_dashpot_time(zeta), h.contact_time, 1e-12 * h.contact_time) << zeta;
    // xi_c = 2 beta e v / omega_0^2 in reduced units (v = 1): l~ (1 - eps_r) = 2 zeta e.
    EXPECT_NEAR(m.end_overlap, 2.0 * zeta * h.restitution, 1e-11) << zeta;
  }
  // Overdamped in closed form: e = ((beta - Omega)/(beta + Omega))^(beta/Omega).
  const double W = std::sqrt(8.0);
  EXPECT_NEAR(dashpot_head_on_reduced(3.0).restitution, std::pow((3.0 - W) / (3.0 + W), 3.0 / W),
              1e-15);
  EXPECT_NEAR(dashpot_head_on_reduced(1.0).restitution, std::exp(-2.0), 1e-16);
  // The corrected e is larger than the naive one (0.7441 vs 0.7292 at zeta = 0.1).
  for (double zeta : {0.01, 0.1, 0.5, 0.9})
    EXPECT_GT(dashpot_head_on_reduced(zeta).restitution,
              dashpot_head_on_naive_reduced(zeta).restitution);
}

TEST(SoftContact, HertzElasticDurationAgainstOde) {
  const double K = hertz_contact_time_constant();
  expect_digits(K, "3.2180654597");
  EXPECT_NEAR(head_on(SoftModel::ViscoelasticHertz, 0.0).eps_t, K, 1e-10 * K);
  // Physical: t_H = K (mu^2/(rho^2 v))^(1/5), = 2.9432751843 xi_max / v
  // = 2.8682656992 (mu^2 / (E*^2 R_eff v))^(1/5).
  const double mu = 0.02, E = 3e6, R = 0.05, v = 0.7;
  const double rho = hertz_rho(E, R);
  const double t = hertz_elastic_contact_time(mu, rho, v);
  EXPECT_NEAR(t, K * std::pow(mu * mu / (rho * rho * v), 0.2), 1e-15 * t);
  expect_digits(t * v / hertz_max_overlap(mu, rho, v), "2.9432751843");
  expect_digits(t / std::pow(mu * mu / (E * E * R * v), 0.2), "2.8682656992");
  // Against the 3D map of an elastic head-on collision with these parameters.
  const SoftPair pair{0.03, 0.06, 0.2, 0.3};  // mu = 0.02
  const PairState s{{0.3, 0, 0}, {-0.2, 0, 0}, {-0.4, 0, 0}, {0.3, 0, 0}};
  const SoftCollision c = soft_collision(SoftContactLaw::viscoelastic_hertz(rho, 0.0), pair, s);
  EXPECT_NEAR(c.contact_time, t, 1e-10 * t);
}

TEST(SoftContact, ViscoelasticSeriesAgainstOde) {
  EXPECT_NEAR(viscoelastic_series_coefficient(2), -1.1534489, 5e-8);
  EXPECT_NEAR(viscoelastic_series_coefficient(4), 0.7982666, 5e-8);
  EXPECT_EQ(viscoelastic_series_coefficient(3), 0.0);
  EXPECT_EQ(viscoelastic_series_coefficient(5), 4.0 / 15.0);
  // c = 1e-4: the exact terms h_2..h_5 leave h_6 x^6 ~ 2e-12.
  {
    const double c = 1e-4, x = viscoelastic_series_variable(c);
    EXPECT_NEAR(-head_on(SoftModel::ViscoelasticHertz, c).eps_rdot,
                viscoelastic_restitution_series(x, 5), 5e-12);
  }
  // c = 1e-3: through the fitted h_6, h_7 the ODE agrees to 1e-11 (h_6 is uncertain in its third
  // digit, 1e-3 x^6 = 3e-12); h_2..h_5 alone miss by h_6 x^6 + h_7 x^7 = -1.8e-9.
  {
    const double c = 1e-3, x = viscoelastic_series_variable(c);
    const double e = -head_on(SoftModel::ViscoelasticHertz, c).eps_rdot;
    EXPECT_NEAR(e, viscoelastic_restitution_series(x, 7), 1e-11);
    EXPECT_GT(std::abs(e - viscoelastic_restitution_series(x, 5)), 1.5e-9);
  }
  // Each exact order brings the series closer: the error falls like x^(next order) as c -> 0.
  struct Order {
    int order, next;
    double c1, c2;
  };
  for (const Order& o :
       {Order{2, 4, 1e-4, 1e-5}, Order{4, 5, 1e-4, 1e-5}, Order{5, 6, 1e-3, 1e-4}}) {
    const double x1 = viscoelastic_series_variable(o.c1), x2 = viscoelastic_series_variable(o.c2);
    const double err1 = std::abs(-head_on(SoftModel::ViscoelasticHertz, o.c1).eps_rdot -
                                 viscoelastic_restitution_series(x1, o.order));
    const double err2 = std::abs(-head_on(SoftModel::ViscoelasticHertz, o.c2).eps_rdot -
                                 viscoelastic_restitution_series(x2, o.order));
    EXPECT_NEAR(std::log(err1 / err2) / std::log(x1 / x2), o.next, 0.15) << o.order;
  }
}

// ---------------------------------------------------------------------------------------------
// Reduced parameters from physical inputs.

TEST(SoftContact, ReducedParametersFromPhysicalInputs) {
  const double mu = reduced_mass(1.0, 3.0), l = 0.4 + 0.9;
  EXPECT_DOUBLE_EQ(mu, 0.75);
  EXPECT_DOUBLE_EQ(effective_radius(0.4, 0.9), 0.36 / 1.3);
  const CollisionUnits d =
      reduce_collision(SoftContactLaw::linear_dashpot(300.0, 6.0), mu, l, 2.0, 0.5);
  EXPECT_DOUBLE_EQ(d.time_unit, 0.05);  // sqrt(0.75/300)
  EXPECT_DOUBLE_EQ(d.length_unit, 0.1);
  EXPECT_DOUBLE_EQ(d.reduced.l_tilde, 13.0);
  EXPECT_DOUBLE_EQ(d.reduced.c_phi, 13.0 * 0.25);
  EXPECT_DOUBLE_EQ(d.reduced.c_dis, 6.0 / 15.0);  // gamma / sqrt(k mu)
  EXPECT_DOUBLE_EQ(d.angle_unit, d.reduced.c_phi / (13.0 * 13.0));
  EXPECT_EQ(d.reduced.model, SoftModel::LinearDashpot);
  // Hertz: T = (mu^2/(rho^2 v_n))^(1/5), c_dis = A/T.
  const CollisionUnits h =
      reduce_collision(SoftContactLaw::viscoelastic_hertz(1e3, 2e-3), mu, l, 0.5, 1.5);
  const double T = std::pow(mu * mu / (1e6 * 0.5), 0.2);
  EXPECT_NEAR(h.time_unit, T, 1e-15 * T);
  EXPECT_NEAR(h.reduced.c_dis, 2e-3 / T, 1e-14);
  EXPECT_NEAR(h.reduced.l_tilde, l / (0.5 * T), 1e-12 * h.reduced.l_tilde);
  EXPECT_NEAR(h.reduced.c_phi, h.reduced.l_tilde * 3.0, 1e-12 * h.reduced.c_phi);
  // Materials: one material = two equal materials; E* of equal materials is Y / (2 (1 - nu^2)).
  EXPECT_NEAR(hertz_rho_one_material(2e11, 0.3, 5e-4),
              hertz_rho(effective_modulus(2e11, 0.3, 2e11, 0.3), 5e-4), 1e-6);
  EXPECT_NEAR(effective_modulus(2e11, 0.3, 7e10, 0.25), 1.0 / (0.91 / 2e11 + 0.9375 / 7e10), 1e-3);
  // docs/physics.md#reduced-units: steel, R = 1 mm, at 1 m/s gives l~ ~ 1.05e3 (Hertz). Assumed
  // steel: Y = 200 GPa, nu = 0.3, density 7850 kg/m^3, two equal spheres.
  const double m = 7850.0 * 4.0 / 3.0 * std::numbers::pi * 1e-9;
  const double rho = hertz_rho_one_material(2e11, 0.3, effective_radius(1e-3, 1e-3));
  const CollisionUnits steel = reduce_collision(SoftContactLaw::viscoelastic_hertz(rho, 0.0),
                                                reduced_mass(m, m), 2e-3, 1.0, 0.0);
  EXPECT_NEAR(steel.reduced.l_tilde, 1.05e3, 0.005e3);
}

TEST(SoftContact, ForceLawsAndEndOfContact) {
  const SoftContactLaw d = SoftContactLaw::linear_dashpot(100.0, 2.0);
  EXPECT_DOUBLE_EQ(d.force(0.01, -0.5), 100.0 * 0.01 + 2.0 * 0.5);
  EXPECT_DOUBLE_EQ(d.force(0.01, 0.3), 1.0 - 0.6);  // negative: contact over
  EXPECT_EQ(d.force(-0.01, -0.5), 0.0);
  EXPECT_DOUBLE_EQ(d.end_overlap_per_speed(), 0.02);
  EXPECT_TRUE(d.contact_ended(0.01, 0.5));
  EXPECT_FALSE(d.contact_ended(0.01, 0.4));
  EXPECT_FALSE(d.contact_ended(0.0, -0.1));
  const SoftContactLaw h = SoftContactLaw::viscoelastic_hertz(1e4, 0.01);
  EXPECT_DOUBLE_EQ(h.force(0.04, -2.0), 1e4 * std::pow(0.04, 1.5) + 1.5 * 0.01 * 1e4 * 2.0 * 0.2);
  EXPECT_DOUBLE_EQ(h.end_overlap_per_speed(), 0.015);
  EXPECT_TRUE(h.contact_ended(0.015, 1.0));
  EXPECT_FALSE(h.contact_ended(0.016, 1.0));
  EXPECT_LE(h.force(0.015, 1.0), 1e-12);
}

// ---------------------------------------------------------------------------------------------
// The 3D reconstruction against direct 3D force integration.

struct PairAtContact {
  SoftPair pair;
  PairState state;
  Vec<3> n0{}, t0{};
};

// A pair at first contact along a skew normal, relative velocity -v_n n0 + v_t t0, moving centre
// of mass away from the origin.
PairAtContact make_pair(double m_i, double m_j, double R_i, double R_j, double v_n, double v_t) {
  PairAtContact s;
  s.pair = {m_i, m_j, R_i, R_j};
  s.n0 = {1.0 / 3.0, 2.0 / 3.0, -2.0 / 3.0};
  const Vec<3> a{0.3, -0.5, 0.8};
  const Vec<3> t = a - dot(a, s.n0) * s.n0;
  s.t0 = (1.0 / norm(t)) * t;
  const double M = m_i + m_j, l = R_i + R_j;
  const Vec<3> R{0.3, -1.2, 0.7}, V{0.25, 0.1, -0.4};
  const Vec<3> g = -v_n * s.n0 + v_t * s.t0;
  s.state.r_i = R + (m_j / M * l) * s.n0;
  s.state.r_j = R - (m_i / M * l) * s.n0;
  s.state.v_i = V + (m_j / M) * g;
  s.state.v_j = V - (m_i / M) * g;
  return s;
}

Vec<3> angular_momentum(const SoftPair& p, const PairState& s) {
  return p.m_i * cross3(s.r_i, s.v_i) + p.m_j * cross3(s.r_j, s.v_j);
}

Vec<3> momentum(const SoftPair& p, const PairState& s) {
  return p.m_i * s.v_i + p.m_j * s.v_j;
}

struct ReconstructionCase {
  SoftContactLaw law;
  double v_n, v_t;
};

TEST(SoftContact, ReconstructionMatchesDirect3DIntegration) {
  const double R_i = 0.4, R_j = 0.9, m_i = 1.0, m_j = 3.7;
  const double E = effective_modulus(2e5, 0.3, 5e5, 0.45);
  const double rho = hertz_rho(E, effective_radius(R_i, R_j));
  const std::vector<ReconstructionCase> cases = {
      {SoftContactLaw::linear_dashpot(2e4, 30.0), 1.3, 0.9},   // l~ ~ 160, c_dis 0.24
      {SoftContactLaw::linear_dashpot(100.0, 0.5), 1.3, 2.6},  // l~ ~ 11
      {SoftContactLaw::linear_dashpot(1e3, 0.0), 0.8, 0.1},    // elastic
      {SoftContactLaw::linear_dashpot(1e3, 150.0), 0.5, 1.0},  // overdamped (c_dis 5.3)
      {SoftContactLaw::linear_dashpot(2e4, 30.0), 0.1, 2.0},   // grazing, v_t/v_n = 20
      {SoftContactLaw::viscoelastic_hertz(rho, 2e-3), 1.3, 0.9},
      {SoftContactLaw::viscoelastic_hertz(rho, 5e-3), 0.6, 2.4},
      {SoftContactLaw::viscoelastic_hertz(rho, 0.0), 1.0, 0.3},   // elastic
      {SoftContactLaw::viscoelastic_hertz(rho, 1e-2), 0.1, 2.0},  // grazing
  };
  for (const ReconstructionCase& c : cases) {
    const PairAtContact s = make_pair(m_i, m_j, R_i, R_j, c.v_n, c.v_t);
    const SoftCollision mapped = soft_collision(c.law, s.pair, s.state);
    const DirectContact direct = integrate_contact_directly(c.law, s.pair, s.state);
    const std::string at = "model " + std::to_string(static_cast<int>(c.law.model)) + " damping " +
                           std::to_string(c.law.damping) + " v_n " + std::to_string(c.v_n) +
                           " v_t " + std::to_string(c.v_t) + " l~ " +
                           std::to_string(mapped.units.reduced.l_tilde) + " c_dis " +
                           std::to_string(mapped.units.reduced.c_dis);
    ASSERT_GT(mapped.units.reduced.l_tilde, 5.0) << at;
    const double l = R_i + R_j, g0 = std::hypot(c.v_n, c.v_t);
    EXPECT_NEAR(mapped.contact_time, direct.contact_time, 1e-12 * direct.contact_time) << at;
    // Positions relative to the contact distance, velocities to the impact speed (the issue asks
    // 1e-6 against the engine's DEM later; here the two agree to ~1e-13).
    EXPECT_LT(max_abs(mapped.state.r_i - direct.state.r_i), 1e-12 * l) << at;
    EXPECT_LT(max_abs(mapped.state.r_j - direct.state.r_j), 1e-12 * l) << at;
    EXPECT_LT(max_abs(mapped.state.v_i - direct.state.v_i), 1e-12 * g0) << at;
    EXPECT_LT(max_abs(mapped.state.v_j - direct.state.v_j), 1e-12 * g0) << at;
    // The rotation is real: the line of centres moved by phi_c.
    const Vec<3> r_end = direct.state.r_i - direct.state.r_j;
    EXPECT_NEAR(std::atan2(dot(r_end, s.t0), dot(r_end, s.n0)), mapped.map.phi_c, 1e-12) << at;
    // eps_phidot from the direct integration: omega_c / omega_0 = eps_r^-2.
    const Vec<3> g_end = direct.state.v_i - direct.state.v_j;
    const double omega_c = norm(cross3(r_end, g_end)) / norm2(r_end);
    EXPECT_NEAR(omega_c / (c.v_t / l) * mapped.map.eps_r * mapped.map.eps_r, 1.0, 1e-12) << at;
    // Angular momentum: exact (to round-off) in the map, to the tolerance in the integration.
    const Vec<3> L0 = angular_momentum(s.pair, s.state);
    const double L_scale = norm(L0) + m_i * l * g0;
    EXPECT_LT(max_abs(angular_momentum(s.pair, mapped.state) - L0), 1e-14 * L_scale) << at;
    EXPECT_LT(max_abs(angular_momentum(s.pair, direct.state) - L0), 1e-12 * L_scale) << at;
    const Vec<3> P0 = momentum(s.pair, s.state);
    EXPECT_LT(max_abs(momentum(s.pair, mapped.state) - P0), 1e-15 * (m_i + m_j) * g0) << at;
    // The end is the force-zero end: the direct state has F = 0 there, receding.
    const double d = norm(r_end), rdot = dot(r_end, g_end) / d;
    EXPECT_GT(rdot, 0.0) << at;
    EXPECT_NEAR(c.law.end_overlap_per_speed() * rdot, l - d, 1e-12 * l) << at;
    EXPECT_NEAR(l - norm(mapped.state.r_i - mapped.state.r_j),
                mapped.map.end_overlap * mapped.units.length_unit, 1e-12 * l)
        << at;
  }
}

// v_t = 0: no rotation, -eps_rdot = e(v) of docs/physics.md#dashpot-head-on and
// docs/physics.md#viscoelastic-head-on, the velocities stay along n0; eps_phi is the finite
// limit v_t -> 0 (phi_c = eps_phi Phi is 0 because Phi is).
TEST(SoftContact, HeadOnLimit) {
  for (SoftModel model : {SoftModel::LinearDashpot, SoftModel::ViscoelasticHertz}) {
    const double c = 0.2;
    const CollisionMap m = collision_map({model, 0.0, 50.0, c});
    EXPECT_EQ(m.phi_c, 0.0);
    const CollisionMap tiny = collision_map({model, 50.0 * 1e-7, 50.0, c});
    EXPECT_NEAR(m.eps_phi, tiny.eps_phi, 1e-10);
    EXPECT_NEAR(m.eps_rdot, tiny.eps_rdot, 1e-12);
    if (model == SoftModel::LinearDashpot) {
      EXPECT_NEAR(-m.eps_rdot, dashpot_head_on_reduced(c / 2).restitution, 1e-12);
    } else {
      expect_digits(-m.eps_rdot, "0.7220854397");
    }
    // In 3D.
    const SoftContactLaw law = model == SoftModel::LinearDashpot
                                   ? SoftContactLaw::linear_dashpot(1e3, 3.0)
                                   : SoftContactLaw::viscoelastic_hertz(1e4, 1e-3);
    const PairAtContact s = make_pair(2.0, 0.5, 0.3, 0.6, 1.1, 0.0);
    const SoftCollision sc = soft_collision(law, s.pair, s.state);
    EXPECT_LT(std::abs(sc.map.phi_c), 1e-15);  // v_t = |g - g_n n0| is round-off, not 0
    const Vec<3> g = sc.state.v_i - sc.state.v_j;
    EXPECT_LT(max_abs(g - dot(g, s.n0) * s.n0), 1e-15);
    const double e = dot(g, s.n0) / 1.1;
    if (model == SoftModel::LinearDashpot) {
      const double mu = reduced_mass(2.0, 0.5);
      EXPECT_NEAR(e, dashpot_head_on(mu, 1e3, 3.0).restitution, 1e-12);
      EXPECT_NEAR(sc.contact_time, dashpot_head_on(mu, 1e3, 3.0).contact_time, 1e-14);
    }
    EXPECT_NEAR(e, -sc.map.eps_rdot, 1e-14);
    const DirectContact direct = integrate_contact_directly(law, s.pair, s.state);
    EXPECT_LT(max_abs(direct.state.v_i - sc.state.v_i), 1e-11);
  }
}

// ---------------------------------------------------------------------------------------------
// The hard-sphere failure (docs/physics.md#hard-sphere-failure). e_eff = -(g_c.n0)/(g0.n0) at
// l~ = 100, v_t/v_n = 20 is -0.95 (dashpot) and -0.99 (Hertz), with head-on e 0.74 and 0.85; at
// l~ = 1000, -0.08 and -0.11.

double effective_restitution(const CollisionMap& m, double ratio) {
  // In the (n0, t0) basis with v_n = 1: g_c.n0 = -eps_rdot cos(phi_c) - (v_t/eps_r) sin(phi_c).
  return -m.eps_rdot * std::cos(m.phi_c) - ratio / m.eps_r * std::sin(m.phi_c);
}

TEST(SoftContact, HardSphereFailureNumbers) {
  const double c_dashpot = 0.2, c_hertz = 0.1;
  expect_digits(-head_on(SoftModel::LinearDashpot, c_dashpot).eps_rdot, "0.74");
  expect_digits(-head_on(SoftModel::ViscoelasticHertz, c_hertz).eps_rdot, "0.85");
  const auto e_eff = [](SoftModel model, double c, double l_tilde) {
    return effective_restitution(collision_map({model, 20.0 * l_tilde, l_tilde, c}), 20.0);
  };
  expect_digits(e_eff(SoftModel::LinearDashpot, c_dashpot, 100.0), "-0.95");
  expect_digits(e_eff(SoftModel::ViscoelasticHertz, c_hertz, 100.0), "-0.99");
  expect_digits(e_eff(SoftModel::LinearDashpot, c_dashpot, 1000.0), "-0.08");
  expect_digits(e_eff(SoftModel::ViscoelasticHertz, c_hertz, 1000.0), "-0.11");
  // The same through the 3D reconstruction (dashpot, l~ = 100): g_c.n0 / v_n.
  const double l = 1.0, v_n = 0.05, mu = reduced_mass(1.0, 2.0);
  const double k = mu * std::pow(100.0 * v_n / l, 2.0);  // T = sqrt(mu/k) = l / (100 v_n)
  const SoftContactLaw law = SoftContactLaw::linear_dashpot(k, c_dashpot * std::sqrt(k * mu));
  const PairAtContact s = make_pair(1.0, 2.0, 0.5, 0.5, v_n, 20.0 * v_n);
  const SoftCollision sc = soft_collision(law, s.pair, s.state);
  EXPECT_NEAR(sc.units.reduced.l_tilde, 100.0, 1e-10);
  const double e3d = dot(sc.state.v_i - sc.state.v_j, s.n0) / v_n;
  EXPECT_NEAR(e3d, e_eff(SoftModel::LinearDashpot, c_dashpot, 100.0), 1e-10);
  EXPECT_LT(e3d, 0.0);  // negative normal restitution measured against n0
}

// ---------------------------------------------------------------------------------------------
// Bad inputs: InputError naming the parameter.

template <class F>
void expect_input_error(F f, const std::string& name) {
  try {
    f();
    ADD_FAILURE() << "no InputError for " << name;
  } catch (const InputError& e) {
    EXPECT_THAT(std::string(e.what()), HasSubstr(name));
  }
}

TEST(SoftContact, BadInputsAreInputErrors) {
  const double nan = std::nan("");
  expect_input_error([] { SoftContactLaw::linear_dashpot(0.0, 1.0); }, "spring constant k");
  expect_input_error([] { SoftContactLaw::linear_dashpot(1.0, -1.0); }, "gamma");
  expect_input_error([&] { SoftContactLaw::viscoelastic_hertz(nan, 1.0); }, "rho");
  expect_input_error([] { SoftContactLaw::viscoelastic_hertz(1.0, -1e-3); }, "time constant A");
  expect_input_error([] { reduced_mass(-1.0, 1.0); }, "m_i");
  expect_input_error([] { effective_radius(1.0, 0.0); }, "R_j");
  expect_input_error([] { effective_modulus(1e9, 0.6, 1e9, 0.3); }, "nu_i");
  expect_input_error([] { effective_modulus(1e9, 0.3, -1e9, 0.3); }, "Y_j");
  expect_input_error([] { hertz_rho_one_material(1e9, -1.0, 1.0); }, "Poisson");
  expect_input_error([] { hertz_rho(1e9, -1.0); }, "R_eff");
  const SoftContactLaw law = SoftContactLaw::linear_dashpot(1.0, 0.1);
  expect_input_error([&] { reduce_collision(law, 0.0, 1.0, 1.0, 0.0); }, "reduced mass");
  expect_input_error([&] { reduce_collision(law, 1.0, -1.0, 1.0, 0.0); }, "contact distance");
  expect_input_error([&] { reduce_collision(law, 1.0, 1.0, 0.0, 0.0); }, "v_n");
  expect_input_error([&] { reduce_collision(law, 1.0, 1.0, 1.0, -0.1); }, "v_t");
  SoftContactLaw broken = law;
  broken.stiffness = -1.0;
  expect_input_error([&] { reduce_collision(broken, 1.0, 1.0, 1.0, 0.0); }, "spring constant k");
  using R = ReducedCollision;
  const SoftModel D = SoftModel::LinearDashpot;
  expect_input_error([&] { collision_map(R{D, -1.0, 10.0, 0.1}); }, "c_phi");
  expect_input_error([&] { collision_map(R{D, 1.0, 0.0, 0.1}); }, "l_tilde");
  expect_input_error([&] { collision_map(R{D, 1.0, 10.0, nan}); }, "c_dis");
  expect_input_error(
      [&] {
        collision_map(R{D, 1.0, 10.0, 0.1}, MapOptions{0.0, 100});
      },
      "tolerance");
  // l~ below the reduced penetration: the centres would meet.
  expect_input_error(
      [&] {
        collision_map(R{SoftModel::ViscoelasticHertz, 0.0, 0.5, 0.0});
      },
      "l_tilde");
  expect_input_error([&] { collision_map(R{D, 0.0, 0.3, 0.0}); }, "l_tilde");
  // The pre-contact state.
  const PairAtContact s = make_pair(1.0, 2.0, 0.5, 0.7, 1.0, 0.5);
  PairState apart = s.state;
  apart.r_i = apart.r_i + 1e-3 * s.n0;
  expect_input_error([&] { soft_collision(law, s.pair, apart); }, "first contact");
  PairState receding = s.state;
  receding.v_i = s.state.v_j;
  expect_input_error([&] { soft_collision(law, s.pair, receding); }, "approaching");
  PairState inf = s.state;
  inf.v_j[1] = std::numeric_limits<double>::infinity();
  expect_input_error([&] { integrate_contact_directly(law, s.pair, inf); }, "v_j");
  expect_input_error([&] { soft_collision(law, SoftPair{1.0, 0.0, 0.5, 0.7}, s.state); }, "m_j");
  expect_input_error([] { dashpot_head_on_reduced(-0.1); }, "zeta");
  expect_input_error([] { dashpot_head_on_naive_reduced(1.0); }, "zeta < 1");
  expect_input_error([] { dashpot_head_on(0.5, 0.0, 1.0); }, "spring constant k");
  expect_input_error([] { dashpot_end_overlap(0.5, 1.0, 1.0, 0.0); }, "impact speed v");
  expect_input_error([] { viscoelastic_restitution_series(0.1, 8); }, "order");
  expect_input_error([] { viscoelastic_series_coefficient(1); }, "h_k");
  expect_input_error([] { hertz_elastic_contact_time(1.0, 0.0, 1.0); }, "rho");
  expect_input_error([] { hertz_max_overlap(1.0, 1.0, -1.0); }, "impact speed v");
}

}  // namespace
}  // namespace kairos
