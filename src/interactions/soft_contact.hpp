// Soft, frictionless spheres: the two-body contact and the Müller–Pöschel collision map
// (docs/physics.md#soft-spheres).
//
// Pure functions, no engine knowledge. A contact starts when the centres are l = R_i + R_j
// apart and approaching, and ends at the first instant the normal force would turn attractive
// (F = 0 with rdot > 0, docs/physics.md#force-zero-end-of-contact): both models end while the
// particles still overlap. Conventions of docs/physics.md#conventions: r = r_i - r_j,
// g = v_i - v_j, overlap xi = l - |r|, rdot = d|r|/dt, F > 0 repulsive, v_n = -g.n (> 0
// approaching), v_t = |g - (g.n) n|.
//
// Units: any consistent set (SI in the comments). Lengths [m], masses [kg], times [s],
// velocities [m/s]; a dashpot's k [N/m] and gamma [kg/s]; Hertz's rho [N/m^(3/2)] and its
// dissipative time constant A [s]; Young's modulus [Pa]. Every function validates its inputs and
// throws InputError (core/error.hpp) naming the offending parameter.
#pragma once

#include "core/vec.hpp"

namespace kairos {

// ---------------------------------------------------------------------------------------------
// Pair and material helpers.

double reduced_mass(double m_i, double m_j);      // mu = m_i m_j / (m_i + m_j)
double effective_radius(double R_i, double R_j);  // R_eff = R_i R_j / (R_i + R_j)
// Two materials: 1/E* = (1 - nu_i^2)/Y_i + (1 - nu_j^2)/Y_j; Y > 0, nu in (-1, 1/2].
double effective_modulus(double young_i, double poisson_i, double young_j, double poisson_j);
// Hertz prefactor rho = (4/3) E* sqrt(R_eff) (F = rho xi^(3/2)).
double hertz_rho(double effective_modulus, double effective_radius);
// One material: rho = 2 Y sqrt(R_eff) / (3 (1 - nu^2)) (the same as hertz_rho with E* of Y, nu).
double hertz_rho_one_material(double young, double poisson, double effective_radius);

// ---------------------------------------------------------------------------------------------
// Force laws (docs/physics.md#soft-contact-laws).

enum class SoftModel { LinearDashpot, ViscoelasticHertz };

struct SoftContactLaw {
  SoftModel model = SoftModel::LinearDashpot;
  double stiffness = 1.0;  // dashpot: k; Hertz: rho
  double damping = 0.0;    // dashpot: gamma; Hertz: the dissipative time constant A

  // F = k xi - gamma rdot; k > 0, gamma >= 0.
  static SoftContactLaw linear_dashpot(double k, double gamma);
  // F = rho xi^(3/2) - (3/2) A rho rdot sqrt(xi); rho > 0, A >= 0.
  static SoftContactLaw viscoelastic_hertz(double rho, double A);

  // The normal force at overlap xi and rdot during a contact (0 for xi <= 0). May be negative:
  // the contact has then ended, which is the caller's business (contact_ended).
  double force(double overlap, double rdot) const;
  // True once the force-zero end is reached: rdot > 0 and F <= 0, i.e. xi <= kappa rdot with
  // kappa = gamma/k (dashpot) or (3/2) A (Hertz).
  bool contact_ended(double overlap, double rdot) const;
  // kappa above [s]: the overlap at the end of contact is kappa * rdot_c.
  double end_overlap_per_speed() const;
};

// Coulomb friction of a soft contact, integrated by the DEM alone (the collision map is that of
// smooth spheres): a tangential spring on the contact's accumulated tangential displacement
// xi_t with a dashpot on the tangential slip velocity v_t (Cundall-Strack),
// F_t = -(k_t xi_t + gamma_t v_t), cut to |F_t| <= mu F_n (the spring then reset to match).
// k_t and gamma_t are fractions of the normal law's: k_t = stiffness_ratio k and gamma_t =
// damping_ratio gamma (dashpot); for Hertz of the normal tangent stiffness (3/2) rho sqrt(xi)
// and damping coefficient (3/2) A rho sqrt(xi), as LAMMPS's gran/hertz/history scales both.
struct SoftFriction {
  double coefficient = 0.0;            // mu >= 0; 0: smooth (no tangential force)
  double stiffness_ratio = 2.0 / 7.0;  // k_t / k_n > 0
  double damping_ratio = 0.5;          // gamma_t / gamma_n >= 0
  bool operator==(const SoftFriction&) const = default;
};

// ---------------------------------------------------------------------------------------------
// Reduced units (docs/physics.md#reduced-units). The two-body problem in the collision plane,
//   x'' = c_phi^2 / x^3 + f(x, x'),  phi' = c_phi / x^2,  x(0) = l~, x'(0) = -1, phi(0) = 0,
// with x = r / (v_n T) and tau = t / T; f = (l~ - x) - c_dis x' (dashpot) or
// (l~ - x)^(3/2) - (3/2) c_dis x' (l~ - x)^(1/2) (Hertz).

struct ReducedCollision {
  SoftModel model = SoftModel::LinearDashpot;
  double c_phi = 0.0;    // l~ v_t / v_n >= 0
  double l_tilde = 1.0;  // l / (v_n T) > 0
  double c_dis = 0.0;    // gamma / sqrt(k mu) (dashpot) or A / T (Hertz), >= 0
};

struct CollisionUnits {
  ReducedCollision reduced;
  double time_unit = 1.0;    // T: sqrt(mu/k) (dashpot) or (mu^2 / (rho^2 v_n))^(1/5) (Hertz) [s]
  double length_unit = 1.0;  // v_n T [m]
  double angle_unit = 0.0;   // Phi = phidot(0) T = c_phi / l~^2 = v_t T / l [rad]
};

// From physical inputs: reduced mass mu > 0, contact distance l = R_i + R_j > 0, normal impact
// speed v_n > 0, tangential speed v_t >= 0.
CollisionUnits reduce_collision(const SoftContactLaw& law, double reduced_mass,
                                double contact_distance, double v_n, double v_t);
// Throws InputError naming what is wrong with the law (model, stiffness, damping).
void validate(const SoftContactLaw& law);

// reduce_collision without checking its inputs: for the event engine's collisions, whose laws
// were validated once (validate) when the run started and whose speeds and distances are positive
// by construction (the checks were a few percent of a mapped collision's cost).
CollisionUnits reduce_collision_unchecked(const SoftContactLaw& law, double reduced_mass,
                                          double contact_distance, double v_n, double v_t);

// ---------------------------------------------------------------------------------------------
// The collision map (docs/physics.md#collision-map), by adaptive Dormand–Prince 8(5,3)
// integration of the reduced problem up to the force-zero end of contact, located to round-off
// (bisection on the last step). The Hertz force's sqrt(l~ - x) is not analytic at the start (nor
// at an elastic end); the integration runs in a Sundman variable theta, d tau/d theta =
// sqrt(l~ - x), with sqrt(l~ - x) a state variable, in which both models' equations are
// polynomial and the solution analytic through both ends. Default tolerance: ~1e-13 on every
// component (tested against the independent values of docs/physics.md#collision-map).

struct MapOptions {
  double tolerance = 1e-13;    // relative local error per step (absolute 1e-3 of it); > 0
  long max_steps = 1'000'000;  // accepted + rejected steps before giving up (logic_error)
  // Setup (table builds, solving for a restitution): poll the stop flag at the start and every
  // 1024 steps (throw_if_stop_requested, core/stop_flag.hpp), so that SIGINT ends a long
  // integration. The engine's collisions leave it off: an event is never abandoned half done.
  bool interruptible = false;
};

struct CollisionMap {
  double eps_t = 0.0;        // t_c / T
  double eps_r = 1.0;        // r(t_c) / l (< 1: the pair still overlaps)
  double eps_rdot = -1.0;    // rdot(t_c) / rdot(0) <= 0; -eps_rdot is the head-on e
  double eps_phi = 0.0;      // phi(t_c) / Phi; for v_t -> 0 its finite limit (phi_c is then 0)
  double eps_phidot = 1.0;   // phidot(t_c) / phidot(0), integrated on its own: = eps_r^-2 (check)
  double end_overlap = 0.0;  // l~ (1 - eps_r): the reduced overlap at the end, no cancellation
  double phi_c = 0.0;        // eps_phi * Phi: the rotation of the line of centres [rad]
  long steps = 0;            // accepted integration steps
};

// Reduced inputs: c_phi >= 0, l~ > 0, c_dis >= 0. InputError if l~ is so small that the centres
// would (nearly) meet during the contact (x < 1e-3 l~; l~ must exceed the reduced penetration,
// about 1). About 50 steps (13 right-hand sides each) at the default tolerance.
CollisionMap collision_map(const ReducedCollision& reduced, const MapOptions& options = {});

// ---------------------------------------------------------------------------------------------
// The pair in 3D and the post-contact state (docs/physics.md#collision-map).

struct SoftPair {
  double m_i = 1.0, m_j = 1.0;            // masses > 0
  double radius_i = 0.5, radius_j = 0.5;  // radii > 0
};

struct PairState {
  Vec<3> r_i{}, r_j{};  // positions
  Vec<3> v_i{}, v_j{};  // velocities
};

struct SoftCollision {
  PairState state;            // positions and velocities at t0 + t_c
  double contact_time = 0.0;  // t_c [s]
  CollisionUnits units;       // reduced parameters and units of this collision
  CollisionMap map;
};

// The state at first contact t0: |r_i - r_j| = R_i + R_j (to 1e-6 relative) and approaching
// (g.n < 0); InputError otherwise. Computes the map and rebuilds the state at t0 + t_c.
SoftCollision soft_collision(const SoftContactLaw& law, const SoftPair& pair,
                             const PairState& at_contact, const MapOptions& options = {});
// The rebuilding alone, from a map computed (or interpolated) for this pair's units: reads
// eps_t, eps_r, eps_rdot and eps_phi (phi_c = eps_phi * units.angle_unit), not phi_c.
PairState apply_collision_map(const SoftPair& pair, const PairState& at_contact,
                              const CollisionUnits& units, const CollisionMap& map);

// The force-based reference: Newton's equations of both particles in 3D Cartesian coordinates,
// same force law, integrated by the same adaptive Dormand–Prince 8(5,3) (in s = sqrt(t - t0),
// which makes the start analytic; an elastic Hertz end stays a weak singularity, ~1e-12)
// from first contact to the force-zero end, located to round-off. Independent of the reduced
// equations and of the map; the tests compare the two.
struct DirectContact {
  PairState state;            // at the end of contact
  double contact_time = 0.0;  // t_c [s]
  long steps = 0;
};
DirectContact integrate_contact_directly(const SoftContactLaw& law, const SoftPair& pair,
                                         const PairState& at_contact,
                                         const MapOptions& options = {});

// ---------------------------------------------------------------------------------------------
// Closed forms for head-on collisions (docs/physics.md#dashpot-head-on and the sections after it).

struct HeadOn {
  double contact_time = 0.0;  // t_c
  double restitution = 1.0;   // e = -rdot(t_c) / rdot(0)
};

// Linear dashpot with the force-zero end, any damping ratio zeta = beta/omega_0 = c_dis/2 >= 0
// (under-, critically and overdamped): t_c = (2/omega) atan(omega/beta), e = exp(-beta t_c).
// The contact time is in units of 1/omega_0.
HeadOn dashpot_head_on_reduced(double zeta);
// The same in physical units, mu > 0, k > 0, gamma >= 0.
HeadOn dashpot_head_on(double reduced_mass, double k, double gamma);
// The naive end at xi = 0 (with its attractive phase): t = pi/omega, e = exp(-pi beta/omega);
// underdamped only, 0 <= zeta < 1, units of 1/omega_0.
HeadOn dashpot_head_on_naive_reduced(double zeta);
// Overlap at the force-zero end of a head-on dashpot contact at impact speed v > 0:
// xi_c = (2 beta / omega_0^2) e v [m].
double dashpot_end_overlap(double reduced_mass, double k, double gamma, double v);

// Viscoelastic spheres: the series variable x = sqrt(beta_A) v^(1/10) = sqrt((3/2) c_dis), and
// e = 1 + sum_{k=2}^{order} h_k x^k with h_2 = -C_1 = -Gamma(3/5) sqrt(pi) /
// (2^(1/5) 5^(2/5) Gamma(21/10)), h_3 = 0, h_4 = (3/5) C_1^2, h_5 = 4/15 (exact) and the fitted
// h_6 = -0.522, h_7 = -0.48 (order 2..7).
double viscoelastic_series_variable(double c_dis);
double viscoelastic_series_coefficient(int k);  // h_k, k = 2..7
double viscoelastic_restitution_series(double x, int order = 5);

// Inverse problems: the dissipation that gives a head-on coefficient of restitution e in (0, 1]
// (e = 1: none). Both e maps are strictly decreasing; solved by bisection to round-off.
// Dashpot with the force-zero end: e depends only on zeta = gamma / (2 sqrt(k mu)); returns zeta.
double dashpot_zeta_for_restitution(double e);
// ... and gamma = 2 zeta sqrt(k mu) for mu > 0, k > 0.
double dashpot_damping_for_restitution(double reduced_mass, double k, double e);
// Viscoelastic Hertz: the exact head-on e(c_dis) = -eps_rdot of collision_map (not the series
// or the Padé form), and its inverse c_dis(e).
double viscoelastic_head_on_restitution(double c_dis);
double viscoelastic_c_dis_for_restitution(double e);
// ... and A = c_dis T with T = (mu^2 / (rho^2 v))^(1/5): e at impact speed v > 0.
double viscoelastic_dissipation_for_restitution(double reduced_mass, double rho, double e,
                                                double v);

// Elastic Hertz spheres: t_H = K (mu^2 / (rho^2 v))^(1/5), K = 2 (5/4)^(2/5) (2/5) B(2/5, 1/2)
// = 3.2180654597, and the maximum overlap xi_max = (5 mu v^2 / (4 rho))^(2/5); mu, rho, v > 0.
double hertz_contact_time_constant();
double hertz_elastic_contact_time(double reduced_mass, double rho, double v);
double hertz_max_overlap(double reduced_mass, double rho, double v);

}  // namespace kairos
