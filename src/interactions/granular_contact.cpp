#include "interactions/granular_contact.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <stdexcept>

#include "core/error.hpp"
#include "interactions/parameter_domain.hpp"

namespace kairos {
namespace {

void require_restitution(double e, const char* what) {
  require_in(kRestitutionDomain, e, what);
}

void require_tangential(double beta, const char* what) {
  require_in(kTangentialRestitutionDomain, beta, what);
}

void require_non_negative(double x, const char* what) {
  require_in(kNonNegativeDomain, x, what);
}

// Inverse of the Padé form on x >= 0 by bisection (it is monotone); e in (0, 1].
double viscoelastic_variable_for(double e) {
  double lo = 0.0, hi = 1.0;
  while (viscoelastic_restitution(hi) > e) {
    lo = hi;
    hi *= 2.0;
  }
  for (int k = 0; k < 200; ++k) {
    const double mid = 0.5 * (lo + hi);
    if (mid <= lo || mid >= hi) break;  // bracket down to adjacent doubles
    (viscoelastic_restitution(mid) > e ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace

double viscoelastic_restitution(double x) {
  // The coefficients of Müller & Pöschel, Phys. Rev. E 84, 021302 (2011)
  // (docs/physics.md#restitution-models).
  constexpr double a1 = 0.501086, b2 = 1.15345, b3 = 0.577977, b4 = 0.532178;
  const double numerator = 1.0 + a1 * x;
  return numerator / (numerator + x * x * (b2 + x * (b3 + x * b4)));
}

NormalRestitution NormalRestitution::constant(double e) {
  require_restitution(e, "the restitution coefficient");
  NormalRestitution r;  // emplaced, not moved in: GCC 12 misreads the variant's move
  r.model_.emplace<Constant>(Constant{e});
  return r;
}

NormalRestitution NormalRestitution::viscoelastic(double k) {
  require_non_negative(k, "the viscoelastic constant k");
  NormalRestitution r;
  r.model_.emplace<Viscoelastic>(Viscoelastic{k});
  return r;
}

NormalRestitution NormalRestitution::viscoelastic_from_material(double dissipative_time,
                                                                double hertz_rho,
                                                                double reduced_mass) {
  require_non_negative(dissipative_time, "the dissipative time constant A");
  require_positive(hertz_rho, "the Hertz prefactor rho");
  require_positive(reduced_mass, "the reduced mass");
  // x^2 = beta_A v^(1/5) with beta_A = (3/2) A (rho/mu)^(2/5), so k = beta_A^(1/2).
  const double beta_a = 1.5 * dissipative_time * std::pow(hertz_rho / reduced_mass, 0.4);
  return viscoelastic(std::sqrt(beta_a));
}

NormalRestitution NormalRestitution::viscoelastic_at(double e_reference, double reference_speed) {
  require_in(kSoftRestitutionDomain, e_reference, "the viscoelastic reference restitution");
  require_positive(reference_speed, "the viscoelastic reference speed");
  const double x = e_reference == 1.0 ? 0.0 : viscoelastic_variable_for(e_reference);
  return viscoelastic(x / std::pow(reference_speed, 0.1));
}

NormalRestitution NormalRestitution::table(std::vector<double> speeds, std::vector<double> values) {
  if (speeds.empty()) throw InputError("the restitution table is empty");
  if (speeds.size() != values.size())
    throw InputError(fmt::format("the restitution table has {} speeds but {} values", speeds.size(),
                                 values.size()));
  for (std::size_t k = 0; k < speeds.size(); ++k) {
    const auto previous = k > 0 ? std::optional<double>(speeds[k - 1]) : std::nullopt;
    if (const auto fault = restitution_table_row_fault(speeds[k], previous, values[k]))
      throw InputError(fmt::format("restitution table, pair #{}: {}", k + 1, fault->why));
  }
  NormalRestitution r;
  r.model_.emplace<Table>(Table{std::move(speeds), std::move(values)});
  return r;
}

double NormalRestitution::operator()(double impact_speed) const {
  struct Evaluate {
    double v;
    double operator()(const Constant& c) const { return c.e; }
    double operator()(const Viscoelastic& m) const {
      return viscoelastic_restitution(m.k * std::pow(v, 0.1));
    }
    double operator()(const Table& t) const {
      const std::vector<double>& s = t.speeds;
      if (v <= s.front()) return t.values.front();
      if (v >= s.back()) return t.values.back();
      // s[k - 1] <= v < s[k]
      const auto k = static_cast<std::size_t>(std::upper_bound(s.begin(), s.end(), v) - s.begin());
      const double f = (v - s[k - 1]) / (s[k] - s[k - 1]);
      return t.values[k - 1] + f * (t.values[k] - t.values[k - 1]);
    }
  };
  return std::visit(Evaluate{impact_speed}, model_);
}

TangentialModel TangentialModel::constant(double beta) {
  require_tangential(beta, "the tangential restitution beta");
  return {beta, kUnlimited};
}

TangentialModel TangentialModel::walton(double friction, double sticking_beta) {
  require_non_negative(friction, "the friction coefficient");
  require_tangential(sticking_beta, "the sticking tangential restitution beta0");
  return {sticking_beta, friction};
}

bool TangentialModel::coulomb_limited() const {
  return std::isfinite(friction_);
}

namespace {

// The impulse of one collision, split into its normal and tangential parts.
template <int D>
struct Impulse {
  double e = 1.0;
  double normal = 0.0;  // J_n = m_n (1 + e) |g_n| >= 0
  Vec<D> tangential{};
  double dissipated = 0.0;
  bool elastic = false;
  bool slid = false;
};

template <int D>
Impulse<D> normal_impulse(const ContactModel& model, bool force_elastic, double speed,
                          double normal_mass) {
  Impulse<D> imp;
  imp.elastic = force_elastic || speed < model.elastic_below_speed;
  imp.e = imp.elastic ? 1.0 : model.normal(speed);
  imp.normal = normal_mass * (1.0 + imp.e) * speed;
  imp.dissipated = 0.5 * normal_mass * (1.0 - imp.e) * (1.0 + imp.e) * speed * speed;
  return imp;
}

// Sticking: J_t = -m_t (1 + beta) g_t, i.e. g_t -> -beta g_t. If that leaves the Coulomb cone
// |J_t| <= friction J_n, the contact slides for the whole collision: J_t = -friction J_n g_t/|g_t|.
// The energy lost, J_t . (g_t + g_t')/2 with g_t' = g_t + J_t/m_t, is written so that round-off
// cannot make it negative.
template <int D>
void add_tangential_impulse(Impulse<D>& imp, const TangentialModel& model, const Vec<D>& gt,
                            double tangential_mass) {
  const double beta = model.beta();
  const double sticking = tangential_mass * (1.0 + beta);
  const double gt2 = norm2(gt);
  if (model.coulomb_limited()) {
    const double limit = model.friction() * imp.normal;
    if (sticking * sticking * gt2 > limit * limit) {
      const double speed = std::sqrt(gt2);
      imp.tangential = (-limit / speed) * gt;
      imp.slid = true;
      // >= 0 as limit < m_t (1 + beta0) |g_t| <= 2 m_t |g_t|.
      imp.dissipated += std::max(0.0, limit * (speed - 0.5 * limit / tangential_mass));
      return;
    }
  }
  imp.tangential = (-sticking) * gt;
  imp.dissipated += 0.5 * tangential_mass * (1.0 - beta) * (1.0 + beta) * gt2;
}

template <int D>
ContactResult<D> result_of(const Impulse<D>& imp, const Vec<D>& n, double speed) {
  ContactResult<D> r;
  r.normal_impulse = imp.normal;
  r.tangential_impulse = imp.tangential;
  r.impulse = imp.normal * n + imp.tangential;
  r.impact_speed = speed;
  r.restitution = imp.e;
  r.dissipated = imp.dissipated;
  r.slid = imp.slid;
  r.made_elastic = imp.elastic;
  return r;
}

// v += J/m; returns the kinetic energy change (m/2)(v'^2 - v^2) = J.(v + v')/2.
template <int D>
double kick(const Vec<D>& impulse, double mass, Vec<D>& v) {
  const Vec<D> before = v;
  v = v + (1.0 / mass) * impulse;
  return 0.5 * dot(impulse, before + v);
}

// Spin change of a body hit at -R n by J_t (particle i) or at +R n by -J_t (particle j): both
// give dw = -(n x J_t) / (q m R). Returns the rotational energy change (I/2)(w'^2 - w^2).
template <int D>
double spin_kick(const Vec<D>& n, const Vec<D>& jt, double q, double mass, double radius,
                 Spin<D>& w) {
  const Spin<D> n_cross_j = cross(n, jt);
  const Spin<D> before = w;
  w = w - (1.0 / (q * mass * radius)) * n_cross_j;
  return -0.5 * radius * spin_dot(n_cross_j, before + w);
}

template <int D>
bool has_tangential(const Impulse<D>& imp) {
  return norm2(imp.tangential) > 0.0;
}

void require_smooth(const TangentialModel& model) {
  if (!model.is_smooth())
    throw std::logic_error("a contact without spins needs a smooth tangential model");
}

}  // namespace

template <int D>
ContactResult<D> resolve_contact(const ContactModel& model, const ContactInput<D>& in, Vec<D>& vi,
                                 Vec<D>& vj) {
  require_smooth(model.tangential);
  const double gn = dot(vi - vj, in.normal);
  if (!(gn < 0.0)) return {};  // not approaching: an impulse could only add energy
  const Impulse<D> imp = normal_impulse<D>(model, in.force_elastic, -gn, normal_mass(in));
  ContactResult<D> r = result_of<D>(imp, in.normal, -gn);
  r.translational_energy_change =
      kick<D>(r.impulse, in.mass_i, vi) + kick<D>((-1.0) * r.impulse, in.mass_j, vj);
  return r;
}

template <int D>
ContactResult<D> resolve_contact(const ContactModel& model, const ContactInput<D>& in, Vec<D>& vi,
                                 Vec<D>& vj, Spin<D>& wi, Spin<D>& wj) {
  if (model.tangential.is_smooth()) return resolve_contact(model, in, vi, vj);
  const Vec<D>& n = in.normal;
  // The spin terms of g are perpendicular to n, so g_n needs the centre velocities only (and
  // then agrees bit for bit with the smooth path).
  const double gn = dot(vi - vj, n);
  if (!(gn < 0.0)) return {};
  Impulse<D> imp = normal_impulse<D>(model, in.force_elastic, -gn, normal_mass(in));
  if (!imp.elastic) {
    const Vec<D> g = (vi - vj) - cross(in.radius_i * wi + in.radius_j * wj, n);
    add_tangential_impulse<D>(imp, model.tangential, g - gn * n, tangential_mass(in));
  }
  ContactResult<D> r = result_of<D>(imp, n, -gn);
  r.translational_energy_change =
      kick<D>(r.impulse, in.mass_i, vi) + kick<D>((-1.0) * r.impulse, in.mass_j, vj);
  if (has_tangential<D>(imp)) {
    r.rotational_energy_change =
        spin_kick<D>(n, imp.tangential, in.inertia_factor_i, in.mass_i, in.radius_i, wi) +
        spin_kick<D>(n, imp.tangential, in.inertia_factor_j, in.mass_j, in.radius_j, wj);
  }
  return r;
}

// The normal mass of a wall contact: the particle's, or m M / (m + M) for a wall with mass.
template <int D>
double wall_normal_mass(const WallContactInput<D>& in) {
  if (std::isinf(in.wall_mass)) return in.mass;
  return in.mass * in.wall_mass / (in.mass + in.wall_mass);
}

template <int D>
ContactResult<D> resolve_wall_contact(const ContactModel& model, const WallContactInput<D>& in,
                                      Vec<D>& v) {
  require_smooth(model.tangential);
  const double gn = dot(v - in.wall_velocity, in.normal);
  if (!(gn < 0.0)) return {};
  const Impulse<D> imp = normal_impulse<D>(model, in.force_elastic, -gn, wall_normal_mass(in));
  ContactResult<D> r = result_of<D>(imp, in.normal, -gn);
  r.translational_energy_change = kick<D>(r.impulse, in.mass, v);
  return r;
}

template <int D>
ContactResult<D> resolve_wall_contact(const ContactModel& model, const WallContactInput<D>& in,
                                      Vec<D>& v, Spin<D>& w) {
  if (model.tangential.is_smooth()) return resolve_wall_contact(model, in, v);
  const Vec<D>& n = in.normal;
  const Vec<D> relative = v - in.wall_velocity;
  const double gn = dot(relative, n);
  if (!(gn < 0.0)) return {};
  Impulse<D> imp = normal_impulse<D>(model, in.force_elastic, -gn, wall_normal_mass(in));
  if (!imp.elastic) {
    // The wall neither recoils nor turns: 1/m_t = 1/m + R^2/I = (1 + q)/(q m).
    const double q = in.inertia_factor;
    const Vec<D> g = relative - cross(in.radius * w, n);
    add_tangential_impulse<D>(imp, model.tangential, g - gn * n, q * in.mass / (1.0 + q));
  }
  ContactResult<D> r = result_of<D>(imp, n, -gn);
  r.translational_energy_change = kick<D>(r.impulse, in.mass, v);
  if (has_tangential<D>(imp))
    r.rotational_energy_change =
        spin_kick<D>(n, imp.tangential, in.inertia_factor, in.mass, in.radius, w);
  return r;
}

#define KAIROS_INSTANTIATE(D)                                                               \
  template ContactResult<D> resolve_contact<D>(const ContactModel&, const ContactInput<D>&, \
                                               Vec<D>&, Vec<D>&);                           \
  template ContactResult<D> resolve_contact<D>(const ContactModel&, const ContactInput<D>&, \
                                               Vec<D>&, Vec<D>&, Spin<D>&, Spin<D>&);       \
  template ContactResult<D> resolve_wall_contact<D>(const ContactModel&,                    \
                                                    const WallContactInput<D>&, Vec<D>&);   \
  template ContactResult<D> resolve_wall_contact<D>(                                        \
      const ContactModel&, const WallContactInput<D>&, Vec<D>&, Spin<D>&);
KAIROS_INSTANTIATE(2)
KAIROS_INSTANTIATE(3)
#undef KAIROS_INSTANTIATE

}  // namespace kairos
