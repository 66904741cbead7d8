// Collision operators for granular hard particles: inelastic and rough spheres (3D) or disks
// (2D), instantaneous binary collisions and collisions with a (possibly moving) wall.
//
// Pure functions of the pre-collision state; no engine knowledge. Conventions follow
// docs/physics.md#conventions and docs/physics.md#rough-collision: n = (x_i - x_j)/|x_i - x_j|,
// J is the impulse on i (-J acts on j), the contact-point relative velocity is
// g = v_i - v_j - (R_i w_i + R_j w_j) x n, and a collision maps g_n -> -e_n g_n and
// g_t -> -beta g_t (beta = -1 smooth, +1 perfectly rough). Moments of inertia are I = q m R^2
// with q per particle.
#pragma once

#include <limits>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "core/vec.hpp"

namespace kairos {

// Angular velocity: a vector in 3D; in 2D the z component alone (rotation in the plane).
template <int D>
using Spin = std::conditional_t<D == 3, Vec<3>, double>;

inline constexpr double kSolidSphereInertia = 0.4;  // q of a uniform solid sphere
inline constexpr double kDiskInertia = 0.5;         // q of a uniform disk

inline Vec<3> cross(const Vec<3>& a, const Vec<3>& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
// 2D: in-plane vectors and spins along z. a x b is along z.
inline double cross(const Vec<2>& a, const Vec<2>& b) {
  return a[0] * b[1] - a[1] * b[0];
}
// (w z) x a, an in-plane vector.
inline Vec<2> cross(double w, const Vec<2>& a) {
  return {-w * a[1], w * a[0]};
}
// a x (w z), an in-plane vector.
inline Vec<2> cross(const Vec<2>& a, double w) {
  return {w * a[1], -w * a[0]};
}

inline double spin_dot(double a, double b) {
  return a * b;
}
inline double spin_dot(const Vec<3>& a, const Vec<3>& b) {
  return dot(a, b);
}

// The compact [1/4] Padé form of the viscoelastic restitution of Müller & Pöschel, Phys. Rev. E
// 84, 021302 (2011) (docs/physics.md#restitution-models), in its series variable
// x = beta_A^(1/2) v^(1/10). Decreases monotonically from e(0) = 1 to 0.
double viscoelastic_restitution(double x);

// Normal restitution e_n as a function of the normal impact speed |g_n|. Construction
// validates its parameters (InputError naming the problem); evaluation is cheap.
class NormalRestitution {
 public:
  NormalRestitution() = default;  // elastic: e = 1

  // Constant e in [0, 1].
  static NormalRestitution constant(double e);
  // Viscoelastic spheres: e = viscoelastic_restitution(k |g_n|^(1/10)), k >= 0.
  static NormalRestitution viscoelastic(double k);
  // Viscoelastic spheres from the material (docs/physics.md#restitution-models): dissipative
  // time constant A, Hertz prefactor rho (F = rho xi^(3/2), docs/physics.md#soft-contact-laws)
  // and reduced mass mu. Because k depends on rho (hence on R_eff) and on mu, a model built this
  // way belongs to one species pair.
  static NormalRestitution viscoelastic_from_material(double dissipative_time, double hertz_rho,
                                                      double reduced_mass);
  // Viscoelastic spheres with the constant solved so that e(reference_speed) = e_reference,
  // e_reference in (0, 1].
  static NormalRestitution viscoelastic_at(double e_reference, double reference_speed);
  // Table of (speed, e) pairs, linearly interpolated and clamped to the end values outside.
  // Speeds finite, >= 0 and strictly increasing; e in [0, 1]; at least one pair.
  static NormalRestitution table(std::vector<double> speeds, std::vector<double> values);

  double operator()(double impact_speed) const;
  // e = 1 at every speed (a constant 1, the default).
  bool always_elastic() const {
    const auto* c = std::get_if<Constant>(&model_);
    return c != nullptr && c->e == 1.0;
  }

 private:
  struct Constant {
    double e = 1.0;
  };
  struct Viscoelastic {
    double k = 0.0;
  };
  struct Table {
    std::vector<double> speeds, values;
  };
  using Model = std::variant<Constant, Viscoelastic, Table>;

  Model model_{Constant{}};
};

// Tangential restitution. A constant beta is Walton's model with unlimited friction; the
// Coulomb-limited model uses beta0 while the sticking impulse stays inside the cone
// |J_t| <= friction |J_n| and slides on the cone otherwise.
class TangentialModel {
 public:
  TangentialModel() = default;  // smooth

  static TangentialModel smooth() { return {}; }
  // Constant beta in [-1, 1].
  static TangentialModel constant(double beta);
  // Walton: friction coefficient >= 0 and sticking beta0 in [-1, 1].
  static TangentialModel walton(double friction, double sticking_beta);

  double beta() const { return beta_; }          // beta0 for Walton's model
  double friction() const { return friction_; }  // +infinity unless Coulomb-limited
  bool coulomb_limited() const;
  // No tangential impulse ever: spins are neither used nor changed.
  bool is_smooth() const { return beta_ == -1.0 || friction_ == 0.0; }

 private:
  TangentialModel(double beta, double friction) : beta_(beta), friction_(friction) {}

  double beta_ = -1.0;
  double friction_ = kUnlimited;
  static constexpr double kUnlimited = std::numeric_limits<double>::infinity();
};

// The contact law of one species pair (or of a wall).
struct ContactModel {
  NormalRestitution normal;
  TangentialModel tangential;
  // DynamO-style cut-off against inelastic collapse: a collision with |g_n| below this speed
  // is elastic (0 = off). "Elastic" here (and for ContactInput::force_elastic) means e_n = 1
  // and no tangential impulse at all (g_t unchanged, spins untouched): that conserves both the
  // translational and the rotational energy separately, where beta = +1 would exchange them.
  double elastic_below_speed = 0.0;
};

template <int D>
struct ContactInput {
  Vec<D> normal{};  // unit vector (x_i - x_j) / |x_i - x_j|
  double mass_i = 1.0, mass_j = 1.0;
  double radius_i = 0.5, radius_j = 0.5;  // unused by smooth contacts
  double inertia_factor_i = D == 3 ? kSolidSphereInertia : kDiskInertia;  // q_i > 0
  double inertia_factor_j = D == 3 ? kSolidSphereInertia : kDiskInertia;  // q_j > 0
  bool force_elastic = false;                                             // e.g. by the TC model
};

// A wall: a body of infinite mass and inertia whose surface moves with `wall_velocity` at the
// contact point (a vibrating or sliding wall).
template <int D>
struct WallContactInput {
  Vec<D> normal{};  // unit normal from the wall towards the particle
  Vec<D> wall_velocity{};
  double mass = 1.0;
  // A wall with mass (boundaries/wall_body.hpp) recoils along the normal: the normal impulse
  // takes the reduced mass m M / (m + M). It neither turns nor moves in its plane, so the
  // tangential impulse is the fixed wall's. Infinite: the wall does not recoil.
  double wall_mass = std::numeric_limits<double>::infinity();
  double radius = 0.5;  // unused by smooth contacts
  double inertia_factor = D == 3 ? kSolidSphereInertia : kDiskInertia;
  bool force_elastic = false;
};

template <int D>
struct ContactResult {
  Vec<D> impulse{};             // J on i (normal_impulse n + tangential_impulse)
  double normal_impulse = 0.0;  // J . n, >= 0
  Vec<D> tangential_impulse{};
  double impact_speed = 0.0;  // |g_n| before the collision (0 if not approaching)
  double restitution = 1.0;   // e_n applied
  // Kinetic energy changes of the particles (both of a pair; the particle alone at a wall, in
  // the lab frame, so a moving wall can feed energy in).
  double translational_energy_change = 0.0;
  double rotational_energy_change = 0.0;
  // Energy dissipated, >= 0; frame independent. For a pair it equals minus the sum of the two
  // changes above; at a wall that sum minus this is the work done by the wall.
  double dissipated = 0.0;
  bool slid = false;          // the Coulomb limit applied
  bool made_elastic = false;  // elastic_below_speed or force_elastic applied
};

// Collision of particles i and j in contact. Updates their velocities and spins. A pair that
// is not approaching (g_n >= 0) is left untouched and gets a zero result.
template <int D>
ContactResult<D> resolve_contact(const ContactModel& model, const ContactInput<D>& in, Vec<D>& vi,
                                 Vec<D>& vj, Spin<D>& wi, Spin<D>& wj);
// Smooth fast path (no spins): requires model.tangential.is_smooth(), else std::logic_error.
template <int D>
ContactResult<D> resolve_contact(const ContactModel& model, const ContactInput<D>& in, Vec<D>& vi,
                                 Vec<D>& vj);

// Collision of a particle with a wall, same conventions with j = the wall.
template <int D>
ContactResult<D> resolve_wall_contact(const ContactModel& model, const WallContactInput<D>& in,
                                      Vec<D>& v, Spin<D>& w);
template <int D>
ContactResult<D> resolve_wall_contact(const ContactModel& model, const WallContactInput<D>& in,
                                      Vec<D>& v);

// Effective masses of a contact: g_n changes by J_n / m_n and g_t by J_t / m_t, with
// 1/m_n = 1/m_i + 1/m_j and 1/m_t = 1/m_i + 1/m_j + R_i^2/I_i + R_j^2/I_j. For equal q,
// m_t = m_n q / (1 + q) (docs/physics.md#tangential-restitution). R^2/I = 1/(q m) does not
// depend on R.
template <int D>
double normal_mass(const ContactInput<D>& in) {
  return 1.0 / (1.0 / in.mass_i + 1.0 / in.mass_j);
}
template <int D>
double tangential_mass(const ContactInput<D>& in) {
  return 1.0 / (1.0 / in.mass_i + 1.0 / in.mass_j + 1.0 / (in.inertia_factor_i * in.mass_i) +
                1.0 / (in.inertia_factor_j * in.mass_j));
}

}  // namespace kairos
