#include "interactions/soft_contact.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "core/error.hpp"
#include "core/stop_flag.hpp"
#include "interactions/parameter_domain.hpp"

namespace kairos {
namespace {

// ---------------------------------------------------------------------------------------------
// Input checks: InputError naming the parameter.

void require_positive(double x, const char* what) {
  kairos::require_positive(x, what, "soft contact: ");
}

void require_non_negative(double x, const char* what) {
  require_in(kNonNegativeDomain, x, what, "soft contact: ");
}

void require_poisson(double nu, const char* what) {
  require_in(kPoissonRatioDomain, nu, what, "soft contact: ");
}

void require_finite(const Vec<3>& a, const char* what) {
  for (double c : a)
    if (!std::isfinite(c))
      throw InputError(
          fmt::format("soft contact: {} must be finite, got ({}, {}, {})", what, a[0], a[1], a[2]));
}

}  // namespace

void validate(const SoftContactLaw& law) {
  if (law.model == SoftModel::LinearDashpot) {
    require_positive(law.stiffness, "the spring constant k");
    require_non_negative(law.damping, "the dashpot coefficient gamma");
  } else if (law.model == SoftModel::ViscoelasticHertz) {
    require_positive(law.stiffness, "the Hertz prefactor rho");
    require_non_negative(law.damping, "the dissipative time constant A");
  } else {
    throw InputError("soft contact: unknown contact model");
  }
}

namespace {

void validate(const ReducedCollision& reduced) {
  if (reduced.model != SoftModel::LinearDashpot && reduced.model != SoftModel::ViscoelasticHertz)
    throw InputError("soft contact: unknown contact model");
  require_non_negative(reduced.c_phi, "c_phi");
  require_positive(reduced.l_tilde, "l_tilde");
  require_non_negative(reduced.c_dis, "c_dis");
}

void validate(const SoftPair& pair) {
  require_positive(pair.m_i, "the mass m_i");
  require_positive(pair.m_j, "the mass m_j");
  require_positive(pair.radius_i, "the radius R_i");
  require_positive(pair.radius_j, "the radius R_j");
}

void validate(const MapOptions& options) {
  require_positive(options.tolerance, "the integration tolerance");
  if (options.max_steps <= 0)
    throw InputError(fmt::format("soft contact: max_steps must be > 0, got {}", options.max_steps));
}

// ---------------------------------------------------------------------------------------------
// Dormand–Prince 8(5,3) (Hairer, Nørsett & Wanner, Solving ODEs I, §II.10; the coefficients as
// tabulated in SciPy's dop853_coefficients.py), with its combined 5th/3rd-order error estimate
// and the usual step-size control (safety 0.9, factor in [0.2, 10], exponent -1/8).

// clang-format off
constexpr double kC[12] = {0.0, 0.05260015195876773, 0.0789002279381516, 0.1183503419072274, 0.2816496580927726, 0.3333333333333333, 0.25, 0.3076923076923077, 0.6512820512820513, 0.6, 0.8571428571428571, 1.0};
constexpr double kA[12][12] = {
  {0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
  {0.05260015195876773, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
  {0.0197250569845379, 0.0591751709536137, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
  {0.02958758547680685, 0.0, 0.08876275643042054, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
  {0.2413651341592667, 0.0, -0.8845494793282861, 0.924834003261792, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
  {0.037037037037037035, 0.0, 0.0, 0.17082860872947386, 0.12546768756682242, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
  {0.037109375, 0.0, 0.0, 0.17025221101954405, 0.06021653898045596, -0.017578125, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
  {0.03709200011850479, 0.0, 0.0, 0.17038392571223998, 0.10726203044637328, -0.015319437748624402, 0.008273789163814023, 0.0, 0.0, 0.0, 0.0, 0.0},
  {0.6241109587160757, 0.0, 0.0, -3.3608926294469414, -0.868219346841726, 27.59209969944671, 20.154067550477894, -43.48988418106996, 0.0, 0.0, 0.0, 0.0},
  {0.47766253643826434, 0.0, 0.0, -2.4881146199716677, -0.590290826836843, 21.230051448181193, 15.279233632882423, -33.28821096898486, -0.020331201708508627, 0.0, 0.0, 0.0},
  {-0.9371424300859873, 0.0, 0.0, 5.186372428844064, 1.0914373489967295, -8.149787010746927, -18.52006565999696, 22.739487099350505, 2.4936055526796523, -3.0467644718982196, 0.0, 0.0},
  {2.273310147516538, 0.0, 0.0, -10.53449546673725, -2.0008720582248625, -17.9589318631188, 27.94888452941996, -2.8589982771350235, -8.87285693353063, 12.360567175794303, 0.6433927460157636, 0.0},
};
constexpr double kB[12] = {0.054293734116568765, 0.0, 0.0, 0.0, 0.0, 4.450312892752409, 1.8915178993145003, -5.801203960010585, 0.3111643669578199, -0.1521609496625161, 0.20136540080403034, 0.04471061572777259};
constexpr double kE3[12] = {-0.18980075407240762, 0.0, 0.0, 0.0, 0.0, 4.450312892752409, 1.8915178993145003, -5.801203960010585, -0.4226823213237919, -0.1521609496625161, 0.20136540080403034, 0.02265179219836082};
constexpr double kE5[12] = {0.01312004499419488, 0.0, 0.0, 0.0, 0.0, -1.2251564463762044, -0.4957589496572502, 1.6643771824549864, -0.35032884874997366, 0.3341791187130175, 0.08192320648511571, -0.022355307863886294};
// clang-format on

template <std::size_t N>
using State = std::array<double, N>;

// One step of size h from (t, y), f0 = rhs(t, y). Returns y(t + h); with err != nullptr also the
// error norm (rms over components, scaled by atol + rtol max(|y|, |y_new|)).
template <std::size_t N, class Rhs>
State<N> dop853_step(const Rhs& rhs, double t, const State<N>& y, const State<N>& f0, double h,
                     const State<N>& atol, double rtol, double* err) {
  std::array<State<N>, 12> k;
  k[0] = f0;
  for (int s = 1; s < 12; ++s) {
    State<N> ys = y;
    for (std::size_t c = 0; c < N; ++c) {
      double sum = 0.0;
      for (int j = 0; j < s; ++j) sum += kA[s][j] * k[static_cast<std::size_t>(j)][c];
      ys[c] += h * sum;
    }
    k[static_cast<std::size_t>(s)] = rhs(t + kC[s] * h, ys);
  }
  State<N> y_new;
  double e5 = 0.0, e3 = 0.0;
  for (std::size_t c = 0; c < N; ++c) {
    double sum = 0.0, s5 = 0.0, s3 = 0.0;
    for (std::size_t j = 0; j < 12; ++j) {
      sum += kB[j] * k[j][c];
      s5 += kE5[j] * k[j][c];
      s3 += kE3[j] * k[j][c];
    }
    y_new[c] = y[c] + h * sum;
    if (err != nullptr) {
      const double scale = atol[c] + rtol * std::max(std::abs(y[c]), std::abs(y_new[c]));
      e5 += (s5 / scale) * (s5 / scale);
      e3 += (s3 / scale) * (s3 / scale);
    }
  }
  if (err != nullptr) {
    if (e5 == 0.0 && e3 == 0.0) {
      *err = 0.0;
    } else {
      *err = std::abs(h) * e5 / std::sqrt((e5 + 0.01 * e3) * static_cast<double>(N));
    }
  }
  return y_new;
}

template <std::size_t N>
struct Endpoint {
  double t = 0.0;
  State<N> y{};
  long steps = 0;
};

// Integrates y' = rhs(t, y) from (0, y0) until ended(y) first holds, located by bisection of the
// last step's size down to adjacent doubles. check(t, y) is called on every accepted state (it
// may throw). The ended predicate must be false at y0. interruptible: the stop flag is polled
// at the start and every 1024 steps (MapOptions::interruptible).
template <std::size_t N, class Rhs, class Ended, class Check>
Endpoint<N> integrate_until(const Rhs& rhs, const State<N>& y0, const State<N>& atol, double rtol,
                            double h0, long max_steps, bool interruptible, const Ended& ended,
                            const Check& check) {
  constexpr double kSafety = 0.9, kMinFactor = 0.2, kMaxFactor = 10.0, kExponent = -1.0 / 8.0;
  double t = 0.0, h = h0;
  State<N> y = y0;
  State<N> f = rhs(t, y);
  long accepted = 0;
  for (long attempt = 0; attempt < max_steps; ++attempt) {
    if (interruptible && (attempt & 1023) == 0) throw_if_stop_requested();
    double err = 0.0;
    const State<N> y_new = dop853_step<N>(rhs, t, y, f, h, atol, rtol, &err);
    if (!(err <= 1.0)) {  // rejected (a NaN error too)
      h *= std::isfinite(err) ? std::max(kMinFactor, kSafety * std::pow(err, kExponent))
                              : kMinFactor;
      if (!(t + h > t))
        throw std::runtime_error(fmt::format(
            "soft contact: the step size underflowed at t = {} (the contact is singular)", t));
      continue;
    }
    if (ended(y_new)) {
      double lo = 0.0, hi = h;
      for (int k = 0; k < 200; ++k) {
        const double mid = 0.5 * (lo + hi);
        if (!(mid > lo && mid < hi)) break;
        (ended(dop853_step<N>(rhs, t, y, f, mid, atol, rtol, nullptr)) ? hi : lo) = mid;
      }
      // The partial step up to the event must pass the error test too (the full step's estimate
      // covered the region beyond the end, where the force law changes); otherwise approach the
      // end with smaller steps.
      double err_hi = 0.0;
      const State<N> y_end = dop853_step<N>(rhs, t, y, f, hi, atol, rtol, &err_hi);
      if (err_hi <= 1.0) return {t + hi, y_end, accepted + 1};
      h = hi * (std::isfinite(err_hi) ? std::max(kMinFactor, kSafety * std::pow(err_hi, kExponent))
                                      : kMinFactor);
      continue;
    }
    t += h;
    y = y_new;
    f = rhs(t, y);
    ++accepted;
    check(t, y);
    h *= err == 0.0 ? kMaxFactor : std::min(kMaxFactor, kSafety * std::pow(err, kExponent));
  }
  throw std::logic_error(
      fmt::format("soft contact: no end of contact after {} integration steps", max_steps));
}

// Hertz's force per rho, sqrt(xi) (xi + damping_term), with the overlap clamped at 0 past the end
// of contact (the dashpot's force is continued analytically, which keeps an elastic dashpot's end
// at xi = 0 smooth).
double hertz_force_shape(double overlap, double damping_term) {
  const double xi = std::max(overlap, 0.0);
  return std::sqrt(xi) * (xi + damping_term);
}

double end_coefficient(SoftModel model) {
  return model == SoftModel::LinearDashpot ? 1.0 : 1.5;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Pair and material helpers.

double reduced_mass(double m_i, double m_j) {
  require_positive(m_i, "the mass m_i");
  require_positive(m_j, "the mass m_j");
  return m_i * m_j / (m_i + m_j);
}

double effective_radius(double R_i, double R_j) {
  require_positive(R_i, "the radius R_i");
  require_positive(R_j, "the radius R_j");
  return R_i * R_j / (R_i + R_j);
}

double effective_modulus(double young_i, double poisson_i, double young_j, double poisson_j) {
  require_positive(young_i, "Young's modulus Y_i");
  require_poisson(poisson_i, "Poisson's ratio nu_i");
  require_positive(young_j, "Young's modulus Y_j");
  require_poisson(poisson_j, "Poisson's ratio nu_j");
  return 1.0 / ((1.0 - poisson_i * poisson_i) / young_i + (1.0 - poisson_j * poisson_j) / young_j);
}

double hertz_rho(double effective_modulus, double effective_radius) {
  require_positive(effective_modulus, "the effective modulus E*");
  require_positive(effective_radius, "the effective radius R_eff");
  return 4.0 / 3.0 * effective_modulus * std::sqrt(effective_radius);
}

double hertz_rho_one_material(double young, double poisson, double effective_radius) {
  require_positive(young, "Young's modulus Y");
  require_poisson(poisson, "Poisson's ratio nu");
  require_positive(effective_radius, "the effective radius R_eff");
  return 2.0 * young * std::sqrt(effective_radius) / (3.0 * (1.0 - poisson * poisson));
}

// ---------------------------------------------------------------------------------------------
// Force laws.

SoftContactLaw SoftContactLaw::linear_dashpot(double k, double gamma) {
  SoftContactLaw law{SoftModel::LinearDashpot, k, gamma};
  validate(law);
  return law;
}

SoftContactLaw SoftContactLaw::viscoelastic_hertz(double rho, double A) {
  SoftContactLaw law{SoftModel::ViscoelasticHertz, rho, A};
  validate(law);
  return law;
}

double SoftContactLaw::force(double overlap, double rdot) const {
  if (!(overlap > 0.0)) return 0.0;
  if (model == SoftModel::LinearDashpot) return stiffness * overlap - damping * rdot;
  return stiffness * std::sqrt(overlap) * (overlap - 1.5 * damping * rdot);
}

double SoftContactLaw::end_overlap_per_speed() const {
  return model == SoftModel::LinearDashpot ? damping / stiffness : 1.5 * damping;
}

bool SoftContactLaw::contact_ended(double overlap, double rdot) const {
  return rdot > 0.0 && overlap <= end_overlap_per_speed() * rdot;
}

// ---------------------------------------------------------------------------------------------
// Reduced units.

CollisionUnits reduce_collision(const SoftContactLaw& law, double reduced_mass,
                                double contact_distance, double v_n, double v_t) {
  validate(law);
  require_positive(reduced_mass, "the reduced mass mu");
  require_positive(contact_distance, "the contact distance l");
  require_positive(v_n, "the normal impact speed v_n");
  require_non_negative(v_t, "the tangential speed v_t");
  return reduce_collision_unchecked(law, reduced_mass, contact_distance, v_n, v_t);
}

CollisionUnits reduce_collision_unchecked(const SoftContactLaw& law, double reduced_mass,
                                          double contact_distance, double v_n, double v_t) {
  CollisionUnits u;
  u.reduced.model = law.model;
  if (law.model == SoftModel::LinearDashpot) {
    u.time_unit = std::sqrt(reduced_mass / law.stiffness);
    u.reduced.c_dis = law.damping / std::sqrt(law.stiffness * reduced_mass);
  } else {
    u.time_unit =
        std::pow(reduced_mass * reduced_mass / (law.stiffness * law.stiffness * v_n), 0.2);
    u.reduced.c_dis = law.damping / u.time_unit;
  }
  u.length_unit = v_n * u.time_unit;
  u.reduced.l_tilde = contact_distance / u.length_unit;
  u.reduced.c_phi = u.reduced.l_tilde * (v_t / v_n);
  u.angle_unit = v_t * u.time_unit / contact_distance;
  return u;
}

// ---------------------------------------------------------------------------------------------
// The collision map.

CollisionMap collision_map(const ReducedCollision& reduced, const MapOptions& options) {
  validate(reduced);
  validate(options);
  const bool hertz = reduced.model == SoftModel::ViscoelasticHertz;
  const double l = reduced.l_tilde, c_phi = reduced.c_phi, c_dis = reduced.c_dis;
  const double kappa = end_coefficient(reduced.model) * c_dis;  // damping term kappa * p
  // The Hertz force's sqrt(xi) is not analytic where xi = 0, at the start of contact (and at the
  // end of an elastic one): a plain integration in tau loses its order there. A Sundman
  // transformation removes it: integrate in theta with d tau / d theta = sigma = sqrt(xi), the
  // square root of the reduced overlap xi = l~ - x, carried as a state variable. Then
  //   d sigma/d theta = p / 2,   d p/d theta = -sigma (c_phi^2 / x^3 + f),
  // with p = xi' = -x' and f = sigma^2 + c_dis p (dashpot) or sigma (sigma^2 + (3/2) c_dis p)
  // (Hertz): polynomial right-hand sides, analytic through both ends (sigma starts at 0 with
  // slope 1/2 and crosses 0 transversally at an elastic end). The same variable serves the
  // dashpot. Also integrated: tau, psi = phi / Phi (psi' = l~^2 / x^2, from phi' = c_phi / x^2)
  // and w = phi' / phi'(0) on its own (w' = 2 p w / x, i.e. phi'' = -2 x' phi' / x) as the
  // check eps_phidot = eps_r^-2.
  using S = State<5>;  // sigma, p, psi, w, tau
  const auto rhs = [&](double, const S& y) {
    const double sigma = y[0], p = y[1];
    const double x = l - sigma * sigma;
    const double centrifugal = (c_phi / x) * (c_phi / x) / x;
    const double spring = sigma * sigma + kappa * p;
    const double f = hertz ? sigma * spring : spring;
    return S{0.5 * p, -sigma * (centrifugal + f), sigma * (l / x) * (l / x),
             sigma * 2.0 * p * y[3] / x, sigma};
  };
  // Force zero, receding: xi + kappa p <= 0 (sigma > 0, damped), or the elastic end sigma <= 0.
  const auto ended = [&](const S& y) {
    return y[1] < 0.0 && (y[0] <= 0.0 || y[0] * y[0] + kappa * y[1] <= 0.0);
  };
  const auto check = [&](double, const S& y) {
    if (!(l - y[0] * y[0] > 1e-3 * l))
      throw InputError(fmt::format(
          "soft contact: l_tilde = {} is too small: the centres would meet during the contact "
          "(it must exceed the reduced penetration, about 1)",
          l));
  };
  const double atol = 1e-3 * options.tolerance;
  const Endpoint<5> end = integrate_until<5>(
      rhs, S{0.0, 1.0, 0.0, 1.0, 0.0}, S{atol, atol, atol, atol, atol}, options.tolerance, 1e-2,
      options.max_steps, options.interruptible, ended, check);
  check(end.t, end.y);
  CollisionMap map;
  const double sigma = std::max(end.y[0], 0.0);
  map.eps_t = end.y[4];
  map.end_overlap = sigma * sigma;
  map.eps_r = (l - map.end_overlap) / l;
  map.eps_rdot = end.y[1];
  map.eps_phi = end.y[2];
  map.eps_phidot = end.y[3];
  map.phi_c = end.y[2] * (c_phi / (l * l));
  map.steps = end.steps;
  return map;
}

// ---------------------------------------------------------------------------------------------
// The pair in 3D.

namespace {

double norm(const Vec<3>& a) {
  return std::sqrt(norm2(a));
}

struct ContactFrame {
  Vec<3> n0{}, t0{};  // unit normal (i from j) and unit tangent of g at contact (0 if v_t = 0)
  double v_n = 0.0, v_t = 0.0;
  double contact_distance = 0.0;
};

ContactFrame contact_frame(const SoftPair& pair, const PairState& s) {
  validate(pair);
  require_finite(s.r_i, "the position r_i");
  require_finite(s.r_j, "the position r_j");
  require_finite(s.v_i, "the velocity v_i");
  require_finite(s.v_j, "the velocity v_j");
  ContactFrame f;
  f.contact_distance = pair.radius_i + pair.radius_j;
  const Vec<3> r = s.r_i - s.r_j;
  const double d = norm(r);
  if (!(std::abs(d - f.contact_distance) <= 1e-6 * f.contact_distance))
    throw InputError(fmt::format(
        "soft contact: the pre-contact state must be at first contact, |r_i - r_j| = R_i + R_j "
        "= {}, got {}",
        f.contact_distance, d));
  f.n0 = (1.0 / d) * r;
  const Vec<3> g = s.v_i - s.v_j;
  const double g_n = dot(g, f.n0);
  if (!(g_n < 0.0))
    throw InputError(fmt::format(
        "soft contact: the pre-contact state must be approaching, (v_i - v_j).n < 0, got {}", g_n));
  f.v_n = -g_n;
  const Vec<3> g_t = g - g_n * f.n0;
  f.v_t = norm(g_t);
  if (f.v_t > 0.0) f.t0 = (1.0 / f.v_t) * g_t;
  return f;
}

}  // namespace

PairState apply_collision_map(const SoftPair& pair, const PairState& at_contact,
                              const CollisionUnits& units, const CollisionMap& map) {
  const ContactFrame f = contact_frame(pair, at_contact);
  const double M = pair.m_i + pair.m_j;
  const double wi = pair.m_i / M, wj = pair.m_j / M;
  const double phi = map.eps_phi * units.angle_unit;
  const double c = std::cos(phi), s = std::sin(phi);
  const Vec<3> n_c = c * f.n0 + s * f.t0;
  const Vec<3> t_c = c * f.t0 - s * f.n0;
  const Vec<3> r_c = (map.eps_r * f.contact_distance) * n_c;
  const Vec<3> g_c = (-map.eps_rdot * f.v_n) * n_c + (f.v_t / map.eps_r) * t_c;
  const double t_contact = map.eps_t * units.time_unit;
  const Vec<3> V = wi * at_contact.v_i + wj * at_contact.v_j;
  const Vec<3> R = wi * at_contact.r_i + wj * at_contact.r_j + t_contact * V;
  PairState out;
  out.r_i = R + wj * r_c;
  out.r_j = R - wi * r_c;
  out.v_i = V + wj * g_c;
  out.v_j = V - wi * g_c;
  return out;
}

SoftCollision soft_collision(const SoftContactLaw& law, const SoftPair& pair,
                             const PairState& at_contact, const MapOptions& options) {
  const ContactFrame f = contact_frame(pair, at_contact);
  SoftCollision out;
  out.units =
      reduce_collision(law, reduced_mass(pair.m_i, pair.m_j), f.contact_distance, f.v_n, f.v_t);
  out.map = collision_map(out.units.reduced, options);
  out.contact_time = out.map.eps_t * out.units.time_unit;
  out.state = apply_collision_map(pair, at_contact, out.units, out.map);
  return out;
}

DirectContact integrate_contact_directly(const SoftContactLaw& law, const SoftPair& pair,
                                         const PairState& at_contact, const MapOptions& options) {
  validate(law);
  validate(options);
  const ContactFrame f = contact_frame(pair, at_contact);
  const double l = f.contact_distance, mi = pair.m_i, mj = pair.m_j;
  const double k = law.stiffness, damping = law.damping;
  const SoftModel model = law.model;
  const double kappa = law.end_overlap_per_speed();
  // State: r_i, r_j, v_i, v_j (12 components) as functions of s = sqrt(t - t0).
  using S = State<12>;
  const auto unpack = [](const S& y, int block) {
    const auto b = static_cast<std::size_t>(3 * block);
    return Vec<3>{y[b], y[b + 1], y[b + 2]};
  };
  const auto rhs = [&](double s, const S& y) {
    const Vec<3> r = unpack(y, 0) - unpack(y, 1);
    const Vec<3> g = unpack(y, 2) - unpack(y, 3);
    const double d = norm(r);
    const Vec<3> n = (1.0 / d) * r;
    const double rdot = dot(n, g);
    const double xi = l - d;
    // F = k xi - gamma rdot, or rho sqrt(xi) (xi - 3/2 A rdot), continued past the end.
    const double F = model == SoftModel::LinearDashpot
                         ? k * xi - damping * rdot
                         : k * hertz_force_shape(xi, -1.5 * damping * rdot);
    const double two_s = 2.0 * s;
    S dy;
    for (std::size_t c = 0; c < 3; ++c) {
      dy[c] = two_s * y[6 + c];
      dy[3 + c] = two_s * y[9 + c];
      dy[6 + c] = two_s * F * n[c] / mi;
      dy[9 + c] = -two_s * F * n[c] / mj;
    }
    return dy;
  };
  const auto ended = [&](const S& y) {
    const Vec<3> r = unpack(y, 0) - unpack(y, 1);
    const double d = norm(r);
    const double rdot = dot(r, unpack(y, 2) - unpack(y, 3)) / d;
    return rdot > 0.0 && (l - d) <= kappa * rdot;
  };
  const auto check = [](double, const S&) {};
  S y0;
  S atol;
  const double speed = f.v_n + f.v_t;
  for (std::size_t c = 0; c < 3; ++c) {
    y0[c] = at_contact.r_i[c];
    y0[3 + c] = at_contact.r_j[c];
    y0[6 + c] = at_contact.v_i[c];
    y0[9 + c] = at_contact.v_j[c];
    atol[c] = atol[3 + c] = 1e-3 * options.tolerance * l;
    atol[6 + c] = atol[9 + c] = 1e-3 * options.tolerance * speed;
  }
  // Initial step: a hundredth of sqrt(T), T the collision's natural time scale.
  const double mu = reduced_mass(mi, mj);
  const double T = model == SoftModel::LinearDashpot ? std::sqrt(mu / k)
                                                     : std::pow(mu * mu / (k * k * f.v_n), 0.2);
  const Endpoint<12> end =
      integrate_until<12>(rhs, y0, atol, options.tolerance, 1e-2 * std::sqrt(T), options.max_steps,
                          options.interruptible, ended, check);
  DirectContact out;
  out.state = {unpack(end.y, 0), unpack(end.y, 1), unpack(end.y, 2), unpack(end.y, 3)};
  out.contact_time = end.t * end.t;
  out.steps = end.steps;
  return out;
}

// ---------------------------------------------------------------------------------------------
// Closed forms.

HeadOn dashpot_head_on_reduced(double zeta) {
  require_non_negative(zeta, "the damping ratio zeta");
  HeadOn h;
  if (zeta < 1.0) {  // omega = sqrt(1 - zeta^2): t_c = 2 atan(omega / zeta) / omega
    const double w = std::sqrt((1.0 - zeta) * (1.0 + zeta));
    h.contact_time = 2.0 * std::atan2(w, zeta) / w;
  } else if (zeta > 1.0) {  // Omega = sqrt(zeta^2 - 1): t_c = ln((zeta+Omega)/(zeta-Omega))/Omega
    const double W = std::sqrt((zeta - 1.0) * (zeta + 1.0));
    h.contact_time = 2.0 * std::log1p((zeta - 1.0) + W) / W;  // = 2 ln(zeta + Omega) / Omega
  } else {
    h.contact_time = 2.0;
  }
  h.restitution = std::exp(-zeta * h.contact_time);
  return h;
}

HeadOn dashpot_head_on(double reduced_mass, double k, double gamma) {
  require_positive(reduced_mass, "the reduced mass mu");
  const SoftContactLaw law = SoftContactLaw::linear_dashpot(k, gamma);
  const double omega0 = std::sqrt(law.stiffness / reduced_mass);
  HeadOn h = dashpot_head_on_reduced(law.damping / (2.0 * reduced_mass) / omega0);
  h.contact_time /= omega0;
  return h;
}

HeadOn dashpot_head_on_naive_reduced(double zeta) {
  require_non_negative(zeta, "the damping ratio zeta");
  if (!(zeta < 1.0))
    throw InputError(fmt::format(
        "soft contact: the naive dashpot end (xi = 0) needs an underdamped damping ratio zeta < 1, "
        "got {}",
        zeta));
  const double w = std::sqrt((1.0 - zeta) * (1.0 + zeta));
  return {std::numbers::pi / w, std::exp(-std::numbers::pi * zeta / w)};
}

double dashpot_end_overlap(double reduced_mass, double k, double gamma, double v) {
  require_positive(v, "the impact speed v");
  const HeadOn h = dashpot_head_on(reduced_mass, k, gamma);
  return gamma / k * h.restitution * v;  // 2 beta / omega_0^2 = gamma / k
}

double viscoelastic_series_variable(double c_dis) {
  require_non_negative(c_dis, "c_dis");
  return std::sqrt(1.5 * c_dis);
}

double viscoelastic_series_coefficient(int k) {
  const double c1 = std::tgamma(0.6) * std::sqrt(std::numbers::pi) /
                    (std::pow(2.0, 0.2) * std::pow(5.0, 0.4) * std::tgamma(2.1));
  switch (k) {
    case 2:
      return -c1;
    case 3:
      return 0.0;
    case 4:
      return 0.6 * c1 * c1;
    case 5:
      return 4.0 / 15.0;
    case 6:
      return -0.522;  // fitted, third digit uncertain (docs/physics.md#viscoelastic-head-on)
    case 7:
      return -0.48;  // fitted
    default:
      throw InputError(fmt::format(
          "soft contact: the viscoelastic series coefficient h_k is known for k = 2..7, not {}",
          k));
  }
}

double viscoelastic_restitution_series(double x, int order) {
  require_non_negative(x, "the series variable x");
  if (order < 2 || order > 7)
    throw InputError(
        fmt::format("soft contact: the viscoelastic series order must be 2..7, got {}", order));
  double e = 0.0;
  for (int k = order; k >= 2; --k) e = (e + viscoelastic_series_coefficient(k)) * x;
  return 1.0 + e * x;
}

namespace {

// The x >= 0 where the decreasing e_of(x) equals e in (0, 1), by bracketing from [0, 1] upwards
// and bisecting to round-off; `what` names the parameter in errors.
template <class F>
double solve_decreasing(F&& e_of, double e, double x_max, const char* what) {
  double lo = 0.0, hi = 1.0;
  while (e_of(hi) > e) {
    lo = hi;
    hi *= 2.0;
    if (hi > x_max)
      throw InputError(fmt::format(
          "soft contact: no {} gives a coefficient of restitution as small as {}", what, e));
  }
  for (int it = 0; it < 200 && hi - lo > 4.0 * std::numeric_limits<double>::epsilon() * hi; ++it) {
    const double mid = 0.5 * (lo + hi);
    (e_of(mid) > e ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

void require_restitution(double e) {
  require_in(kSoftRestitutionDomain, e, "the coefficient of restitution", "soft contact: ");
}

}  // namespace

double dashpot_zeta_for_restitution(double e) {
  require_restitution(e);
  if (e == 1.0) return 0.0;
  return solve_decreasing([](double zeta) { return dashpot_head_on_reduced(zeta).restitution; }, e,
                          1e12, "damping");
}

double dashpot_damping_for_restitution(double reduced_mass, double k, double e) {
  require_positive(reduced_mass, "the reduced mass mu");
  require_positive(k, "the stiffness k");
  return 2.0 * dashpot_zeta_for_restitution(e) * std::sqrt(k * reduced_mass);
}

double viscoelastic_head_on_restitution(double c_dis) {
  require_non_negative(c_dis, "c_dis");
  if (c_dis == 0.0) return 1.0;
  // Head-on, the reduced equations depend on l~ - x only: any l~ above the penetration will do.
  ReducedCollision r;
  r.model = SoftModel::ViscoelasticHertz;
  r.c_phi = 0.0;
  r.l_tilde = 10.0;
  r.c_dis = c_dis;
  MapOptions options;
  options.interruptible = true;  // only solving for a restitution at setup calls this
  return -collision_map(r, options).eps_rdot;
}

double viscoelastic_c_dis_for_restitution(double e) {
  require_restitution(e);
  if (e == 1.0) return 0.0;
  return solve_decreasing(viscoelastic_head_on_restitution, e, 1e6, "dissipation");
}

double viscoelastic_dissipation_for_restitution(double reduced_mass, double rho, double e,
                                                double v) {
  require_positive(reduced_mass, "the reduced mass mu");
  require_positive(rho, "the Hertz prefactor rho");
  require_positive(v, "the impact speed v");
  const double T = std::pow(reduced_mass * reduced_mass / (rho * rho * v), 0.2);
  return viscoelastic_c_dis_for_restitution(e) * T;
}

double hertz_contact_time_constant() {
  // 2 (5/4)^(2/5) (2/5) B(2/5, 1/2), B(a, b) = Gamma(a) Gamma(b) / Gamma(a + b).
  return 2.0 * std::pow(1.25, 0.4) * 0.4 * std::tgamma(0.4) * std::sqrt(std::numbers::pi) /
         std::tgamma(0.9);
}

double hertz_elastic_contact_time(double reduced_mass, double rho, double v) {
  require_positive(reduced_mass, "the reduced mass mu");
  require_positive(rho, "the Hertz prefactor rho");
  require_positive(v, "the impact speed v");
  return hertz_contact_time_constant() *
         std::pow(reduced_mass * reduced_mass / (rho * rho * v), 0.2);
}

double hertz_max_overlap(double reduced_mass, double rho, double v) {
  require_positive(reduced_mass, "the reduced mass mu");
  require_positive(rho, "the Hertz prefactor rho");
  require_positive(v, "the impact speed v");
  return std::pow(5.0 * reduced_mass * v * v / (4.0 * rho), 0.4);
}

}  // namespace kairos
