#include "dem/dem_integrator.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>
#include <unordered_map>

#include <fmt/format.h>

#include "boundaries/outlet_placement.hpp"
#include "core/error.hpp"
#include "core/periodic.hpp"

namespace kairos {

double dem_default_time_step(const SoftContactLaw& law, double reduced_mass, double reference_speed,
                             double steps_per_contact) {
  if (!(steps_per_contact > 0.0) || !std::isfinite(steps_per_contact))
    throw InputError(fmt::format("DEM: steps_per_contact must be positive and finite, got {}",
                                 steps_per_contact));
  const double t_c = law.model == SoftModel::LinearDashpot
                         ? dashpot_head_on(reduced_mass, law.stiffness, law.damping).contact_time
                         : hertz_elastic_contact_time(reduced_mass, law.stiffness, reference_speed);
  return t_c / steps_per_contact;
}

namespace {

inline double wrap_once(double x, double L) {
  if (x >= L) return x - L;
  if (x < 0.0) return x + L;
  return x;
}

// A neighbour cell beyond a wall (none).
constexpr std::size_t kNoCell = std::numeric_limits<std::size_t>::max();
constexpr std::uint32_t kNoCell32 = std::numeric_limits<std::uint32_t>::max();

// The tangential force of a frictional contact (Cundall-Strack): the spring xi is turned into
// the present tangent plane (normal n) and advanced by the slip velocity vt over `advance` (the
// time step; 0 at the constructor's force evaluation), F_t = -(kt xi + gt vt) is cut to the
// Coulomb limit |F_t| <= limit, and the spring's energy and the force's power on the slip are
// added up. Sliding, the spring alone carries the Coulomb force (xi = -F_t / kt): it holds no
// more than (mu F_n)^2 / 2 kt, and the force stays continuous when the slip stops (vt -> 0).
template <int D>
Vec<D> tangential_force(Vec<D>& xi, const Vec<D>& n, const Vec<D>& vt, double kt, double gt,
                        double limit, double advance, double& spring, double& slip) {
  if (advance > 0.0) xi = xi - dot(xi, n) * n + advance * vt;
  Vec<D> ft = -1.0 * (kt * xi + gt * vt);
  const double ft2 = norm2(ft);
  if (ft2 > limit * limit) {  // sliding: the force at the Coulomb limit
    ft = (limit / std::sqrt(ft2)) * ft;
    xi = (-1.0 / kt) * ft;
  }
  spring += 0.5 * kt * norm2(xi);
  slip += dot(ft, vt);
  return ft;
}

// The normal force of a contact at `overlap` and gap rate `rdot` under a dashpot (k, gamma) or
// Hertz law (rho, c = (3/2) A rho), clipped at zero (the force-zero end: no attraction), with
// its elastic part and elastic energy; `root` is sqrt(overlap) for Hertz and 1 for a dashpot,
// the factor the Hertz friction coefficients scale with. Pairs and walls alike.
struct NormalForce {
  double elastic, energy, force, root;
};
[[gnu::always_inline]] inline NormalForce normal_force(bool hertz, double k, double c,
                                                       double overlap, double rdot) {
  if (!hertz) {
    const double elastic = k * overlap;
    return {elastic, 0.5 * elastic * overlap, std::max(0.0, elastic - c * rdot), 1.0};
  }
  const double root = std::sqrt(overlap);
  const double elastic = k * overlap * root;
  return {elastic, 0.4 * elastic * overlap, std::max(0.0, elastic - c * rdot * root), root};
}

// The tangential spring and dashpot of a frictional contact: fractions of the normal law's
// stiffness and damping, for Hertz of its tangent stiffness (3/2) rho sqrt(xi) and damping
// coefficient (3/2) A rho sqrt(xi) (SoftFriction).
struct TangentialLaw {
  double kt, gt;
};
inline TangentialLaw tangential_law(const SoftFriction& fr, bool hertz, double k, double c,
                                    double root) {
  return {fr.stiffness_ratio * k * (hertz ? 1.5 * root : 1.0), fr.damping_ratio * c * root};
}

// With half_L infinite (an axis between walls) the difference is kept as it is.
inline double min_image_once(double d, double half_L, double L) {
  if (d > half_L) return d - L;
  if (d < -half_L) return d + L;
  return d;
}

}  // namespace

template <int D>
DemIntegrator<D>::DemIntegrator(const ParticleSystem<D>& system, const SoftContactLaw& law,
                                const DemOptions& options)
    : base_(system), laws_{law}, species_(1), box_(system.box), time_(system.time) {
  set_walls(Environment<D>{});
  init(options);
}

template <int D>
DemIntegrator<D>::DemIntegrator(const ParticleSystem<D>& system,
                                const std::vector<SoftContactLaw>& laws, std::uint32_t species,
                                const DemOptions& options)
    : base_(system), laws_(laws), species_(species), box_(system.box), time_(system.time) {
  if (species == 0 || laws.size() != static_cast<std::size_t>(species) * species)
    throw InputError(fmt::format("DEM: {} contact laws for {} species (one per species pair)",
                                 laws.size(), species));
  set_walls(Environment<D>{});
  init(options);
}

template <int D>
DemIntegrator<D>::DemIntegrator(const ParticleSystem<D>& system, const Environment<D>& env,
                                const DemOptions& options)
    : base_(system), laws_(env.soft), species_(env.species), box_(system.box), time_(system.time) {
  if (env.soft.empty())
    throw InputError("DEM: no soft contact laws (the DEM integrates the forces of [soft])");
  if (species_ == 0 || laws_.size() != static_cast<std::size_t>(species_) * species_)
    throw InputError(fmt::format("DEM: {} contact laws for {} species (one per species pair)",
                                 laws_.size(), species_));
  if (env.sheared()) throw InputError("DEM: Lees-Edwards shear is not supported");
  if (env.stepped()) throw InputError("DEM: stepped potentials are not supported");
  // The environment is the model (as for the event engine): its faces and field win over the
  // flags the state carries.
  for (int k = 0; k < D; ++k) base_.periodic[k] = env.periodic(k);
  base_.gravity = env.gravity;
  set_walls(env);
  set_friction(env);
  init(options);
}

template <int D>
void DemIntegrator<D>::set_friction(const Environment<D>& env) {
  const auto check = [](const std::vector<SoftFriction>& given, std::size_t size,
                        const char* what) {
    if (!given.empty() && given.size() != size)
      throw InputError(fmt::format("DEM: {} friction laws for {} {}", given.size(), size, what));
    for (const SoftFriction& f : given) {
      if (!(f.coefficient >= 0.0) || !std::isfinite(f.coefficient) || !(f.stiffness_ratio > 0.0) ||
          !std::isfinite(f.stiffness_ratio) || !(f.damping_ratio >= 0.0) ||
          !std::isfinite(f.damping_ratio))
        throw InputError(fmt::format(
            "DEM: friction law (mu {}, k_t/k_n {}, gamma_t/gamma_n {}) of the {}: mu and "
            "gamma_t/gamma_n must be >= 0, k_t/k_n > 0",
            f.coefficient, f.stiffness_ratio, f.damping_ratio, what));
    }
  };
  check(env.soft_friction, laws_.size(), "species pairs");
  if (any_wall_) check(env.soft_wall_friction, species_, "species against the walls");
  const auto rough = [](const std::vector<SoftFriction>& v) {
    return std::any_of(v.begin(), v.end(), [](const SoftFriction& f) { return f.coefficient > 0; });
  };
  friction_ = rough(env.soft_friction) || (any_wall_ && rough(env.soft_wall_friction));
  if (!friction_) return;
  friction_pair_ = env.soft_friction;
  friction_pair_.resize(laws_.size(), SoftFriction{});  // smooth where none is given
  friction_wall_ = any_wall_ ? env.soft_wall_friction : std::vector<SoftFriction>{};
  if (any_wall_) friction_wall_.resize(species_, SoftFriction{});
  inertia_factor_.resize(species_);
  for (std::uint32_t s = 0; s < species_; ++s) inertia_factor_[s] = env.inertia_factor_of(s);
}

template <int D>
void DemIntegrator<D>::set_walls(const Environment<D>& env) {
  for (int k = 0; k < D; ++k) {
    periodic_[k] = env.periodic(k);
    if (base_.periodic[k] != periodic_[k])
      throw InputError(
          fmt::format("DEM: axis {} is not periodic (walls need the environment constructor)", k));
  }
  for (int f = 0; f < 2 * D; ++f) {
    const FaceKind kind = env.faces[static_cast<std::size_t>(f)].kind;
    if (kind == FaceKind::kOpen)
      throw InputError(fmt::format(
          "DEM: face {} of the box is open (particles leaving the box are not supported)", f));
    wall_on_[static_cast<std::size_t>(f)] = kind == FaceKind::kWall;
    walls_[static_cast<std::size_t>(f)] = env.faces[static_cast<std::size_t>(f)].wall;
    any_wall_ = any_wall_ || kind == FaceKind::kWall;
  }
  boundaries_ = Boundaries<D>(env, box_);
  any_outlet_ = boundaries_.outlets().any();
  any_massive_ = boundaries_.any_massive();
  for_each_massive_face([&](int f) {
    lightest_wall_ = std::min(lightest_wall_, walls_[static_cast<std::size_t>(f)].mass);
  });
  wall_shear_.assign(static_cast<std::size_t>(boundaries_.surfaces()), {});
  for (int s = 2 * D; s < boundaries_.surfaces(); ++s)
    any_surface_ = any_surface_ || boundaries_.is_surface(s);
  any_wall_ = any_wall_ || any_surface_;
  if (any_wall_) {
    if (env.soft_wall.size() != species_)
      throw InputError(fmt::format("DEM: {} particle-wall laws for {} species (one per species)",
                                   env.soft_wall.size(), species_));
    for (const SoftContactLaw& given : env.soft_wall) {
      const SoftContactLaw law =
          given.model == SoftModel::LinearDashpot
              ? SoftContactLaw::linear_dashpot(given.stiffness, given.damping)
              : SoftContactLaw::viscoelastic_hertz(given.stiffness, given.damping);
      const bool hertz = law.model == SoftModel::ViscoelasticHertz;
      wall_laws_.push_back(law);
      wall_hertz_.push_back(hertz ? 1 : 0);
      wall_stiffness_.push_back(law.stiffness);
      wall_damping_.push_back(hertz ? 1.5 * law.damping * law.stiffness : law.damping);
    }
  }
  for (int k = 0; k < D; ++k) {
    if (!std::isfinite(env.gravity[k]))
      throw InputError(fmt::format("DEM: gravity along axis {} is not finite", k));
    gravity_[k] = env.gravity[k];
    gravity_on_ = gravity_on_ || gravity_[k] != 0.0;
  }
}

template <int D>
void DemIntegrator<D>::init(const DemOptions& options) {
  const ParticleSystem<D>& system = base_;
  // The laws (SoftContactLaw's factories validate; a hand-built one is checked here).
  const std::size_t ns = species_;
  stiffness_.resize(ns * ns);
  damping_coefficient_.resize(ns * ns);
  hertz_.resize(ns * ns);
  for (std::size_t a = 0; a < ns; ++a) {
    for (std::size_t b = 0; b < ns; ++b) {
      SoftContactLaw& law = laws_[a * ns + b];
      law = law.model == SoftModel::LinearDashpot
                ? SoftContactLaw::linear_dashpot(law.stiffness, law.damping)
                : SoftContactLaw::viscoelastic_hertz(law.stiffness, law.damping);
      const SoftContactLaw& other = laws_[b * ns + a];
      if (law.model != other.model || law.stiffness != other.stiffness ||
          law.damping != other.damping)
        throw InputError(fmt::format(
            "DEM: the contact laws of species pairs ({}, {}) and ({}, {}) differ (must be "
            "symmetric)",
            a, b, b, a));
      const bool hertz = law.model == SoftModel::ViscoelasticHertz;
      hertz_[a * ns + b] = hertz ? 1 : 0;
      stiffness_[a * ns + b] = law.stiffness;
      damping_coefficient_[a * ns + b] = hertz ? 1.5 * law.damping * law.stiffness : law.damping;
    }
  }
  const auto hertz_pairs = std::count(hertz_.begin(), hertz_.end(), std::uint8_t{1});
  kind_ = hertz_pairs == 0                                            ? Laws::kDashpot
          : hertz_pairs == static_cast<std::ptrdiff_t>(hertz_.size()) ? Laws::kHertz
                                                                      : Laws::kMixed;
  collisions_ = system.counters.collisions;
  virial_ = system.counters.virial;
  dissipated_ = system.counters.dissipated_in_collisions;
  wall_collisions_ = system.counters.wall_collisions;
  dissipated_walls_ = system.counters.dissipated_at_walls;
  work_by_walls_ = system.counters.work_by_walls;
  outlet_passes_ = system.counters.outlet_passes;
  outlet_mass_ = system.counters.outlet_mass;
  outlet_energy_ = system.counters.outlet_energy;

  const std::size_t n = system.size();
  if (n == 0) throw InputError("DEM: the system has no particles");
  if (system.mass.size() != n)
    throw InputError(fmt::format("DEM: {} masses for {} particles", system.mass.size(), n));
  if (!std::isfinite(system.time)) throw InputError("DEM: the system time is not finite");
  for (int k = 0; k < D; ++k) {
    if (!(box_[k] > 0.0) || !std::isfinite(box_[k]))
      throw InputError(
          fmt::format("DEM: box length {} along axis {} must be positive", box_[k], k));
    if (system.gravity[k] != gravity_[k])
      throw InputError("DEM: gravity needs the environment constructor");
  }
  if (!system.bonds.empty()) throw InputError("DEM: bonds are not supported");
  for (std::size_t i = 0; i < n; ++i)
    if (system.is_asleep(i)) throw InputError("DEM: sleeping particles are not supported");
  if (!(options.skin > 0.0) || !std::isfinite(options.skin))
    throw InputError(fmt::format("DEM: skin must be positive, got {}", options.skin));
  if (!(options.dt >= 0.0) || !std::isfinite(options.dt) || std::signbit(options.dt))
    throw InputError(
        fmt::format("DEM: time step dt must be positive (0 = default), got {}", options.dt));

  for (int k = 0; k < D; ++k) {
    x_[k].resize(n);
    v_[k].resize(n);
    u_[k].resize(n);
    f_[k].assign(n, 0.0);
    vp_[k].resize(n);
  }
  mass_.resize(n);
  inv_mass_.resize(n);
  radius_.resize(n);
  sp_.assign(n, 0);
  if (species_ > 1) {
    if (system.species.size() != n)
      throw InputError(
          fmt::format("DEM: {} species indices for {} particles", system.species.size(), n));
    for (std::size_t i = 0; i < n; ++i) {
      if (system.species[i] >= species_)
        throw InputError(fmt::format("DEM: particle {} has species {}, but laws are given for {}",
                                     i, system.species[i], species_));
      sp_[i] = system.species[i];
    }
  }
  // Per species: the lightest particle (for the default time step); infinity when absent.
  std::vector<double> m_min(species_, std::numeric_limits<double>::infinity());
  double v_max = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double m = system.mass[i], R = system.kinematics[i].radius;
    if (!(m > 0.0) || !std::isfinite(m))
      throw InputError(fmt::format("DEM: mass of particle {} must be positive, got {}", i, m));
    if (!(R > 0.0) || !std::isfinite(R))
      throw InputError(fmt::format("DEM: radius of particle {} must be positive, got {}", i, R));
    mass_[i] = m;
    inv_mass_[i] = 1.0 / m;
    radius_[i] = R;
    m_min[sp_[i]] = std::min(m_min[sp_[i]], m);
    max_diameter_ = std::max(max_diameter_, 2.0 * R);
    if (!std::isfinite(system.kinematics[i].time))
      throw InputError(fmt::format("DEM: local time of particle {} is not finite", i));
    for (int k = 0; k < D; ++k) {
      if (!std::isfinite(system.kinematics[i].vel[k]))
        throw InputError(fmt::format("DEM: velocity of particle {} is not finite", i));
      if (!std::isfinite(system.kinematics[i].pos[k]))
        throw InputError(fmt::format("DEM: position of particle {} is not finite", i));
    }
    const Vec<D> p = system.position(i, system.time);
    const Vec<D> v = system.velocity(i, system.time);
    double v2 = 0.0;
    for (int k = 0; k < D; ++k) {
      if (!std::isfinite(p[k]))
        throw InputError(fmt::format("DEM: position of particle {} is not finite", i));
      if (!std::isfinite(v[k]))
        throw InputError(fmt::format("DEM: velocity of particle {} is not finite", i));
      x_[k][i] = periodic_[k] ? wrap_into_box(p[k], box_[k]) : p[k];
      v_[k][i] = v[k];
      vp_[k][i] = v[k];
      v2 += v[k] * v[k];
    }
    v_max = std::max(v_max, std::sqrt(v2));
  }
  if (friction_) {
    for (int c = 0; c < kSpin; ++c) {
      w_[c].assign(n, 0.0);
      uw_[c].assign(n, 0.0);
      wp_[c].assign(n, 0.0);
      tq_[c].assign(n, 0.0);
    }
    inertia_.resize(n);
    inv_inertia_.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      inertia_[i] = inertia_factor_[sp_[i]] * mass_[i] * radius_[i] * radius_[i];
      inv_inertia_[i] = 1.0 / inertia_[i];
      if (!system.angular_velocity.empty()) {
        for (int c = 0; c < kSpin; ++c) {
          const double w = system.angular_velocity.at(i)[static_cast<std::size_t>(c)];
          if (!std::isfinite(w))
            throw InputError(fmt::format("DEM: angular velocity of particle {} is not finite", i));
          w_[c][i] = wp_[c][i] = w;
        }
      }
    }
    for (int f = 0; f < boundaries_.surfaces(); ++f)
      if (f < 2 * D ? wall_on_[static_cast<std::size_t>(f)] : boundaries_.is_surface(f))
        wall_shear_[static_cast<std::size_t>(f)].assign(n, Vec<D>{});
  }
  skin_ = options.skin * max_diameter_;
  for (int k = 0; k < D; ++k) {
    if (periodic_[k] && !(box_[k] > 2.0 * (max_diameter_ + skin_)))
      throw InputError(
          fmt::format("DEM: box length {} along axis {} must exceed 2 (d_max + skin) = {}", box_[k],
                      k, 2.0 * (max_diameter_ + skin_)));
    if (!periodic_[k] && !(box_[k] > max_diameter_))
      throw InputError(fmt::format(
          "DEM: box length {} along axis {} (between walls) must exceed the largest diameter {}",
          box_[k], k, max_diameter_));
  }

  // Walls with mass: their motion from the state (at rest on their faces without one), before
  // anything asks where the walls are; an InputError for a motion of a face without mass.
  if (any_massive_ || !system.wall_motion.empty()) boundaries_.restore(system.wall_motion, time_);
  if (any_outlet_) {
    for (std::size_t i = 0; i < n; ++i) {
      Vec<D> x;
      for (int k = 0; k < D; ++k) x[k] = x_[k][i];
      boundaries_.outlets().check_start(x, radius_[i], time_, i);
    }
    check_outlet_regions<D>(boundaries_, 0.5 * max_diameter_, time_, periodic_, box_);
  }

  if (options.dt > 0.0) {
    dt_ = options.dt;
  } else {
    double v_ref = options.reference_speed;
    if (!(v_ref >= 0.0) || !std::isfinite(v_ref))
      throw InputError(fmt::format("DEM: reference_speed must be >= 0, got {}", v_ref));
    if (v_ref == 0.0) {
      v_ref = v_max > 0.0 ? 2.0 * v_max : 1.0;
      // Under gravity particles speed up: a fall across the box sets the impact speed; a wall
      // with mass pushed across the box by its force and the field, likewise.
      for (int k = 0; k < D; ++k)
        v_ref = std::max(v_ref, std::sqrt(2.0 * std::abs(gravity_[k]) * box_[k]));
      for_each_massive_face([&](int f) {
        const Wall<D>& w = walls_[static_cast<std::size_t>(f)];
        const double push = std::abs(w.inward_push(f, gravity_)) / w.mass;
        v_ref = std::max(v_ref, std::sqrt(2.0 * push * box_[f / 2]));
      });
    }
    dt_ = std::numeric_limits<double>::infinity();
    for (std::size_t a = 0; a < species_; ++a) {
      for (std::size_t b = a; b < species_; ++b) {
        if (!std::isfinite(m_min[a]) || !std::isfinite(m_min[b])) continue;  // no such pair
        const double mu = m_min[a] * m_min[b] / (m_min[a] + m_min[b]);
        dt_ = std::min(dt_, dem_default_time_step(laws_[a * species_ + b], mu, v_ref,
                                                  options.steps_per_contact));
      }
      if (any_wall_ && std::isfinite(m_min[a])) {  // a wall of infinite mass: mu = m
        // A wall with mass M: the contact is shorter, at mu = m M / (m + M).
        const double mu = std::isfinite(lightest_wall_)
                              ? m_min[a] * lightest_wall_ / (m_min[a] + lightest_wall_)
                              : m_min[a];
        dt_ = std::min(dt_,
                       dem_default_time_step(wall_laws_[a], mu, v_ref, options.steps_per_contact));
      }
    }
  }

  id_.resize(n);
  slot_.resize(n);
  for (std::size_t i = 0; i < n; ++i) id_[i] = slot_[i] = static_cast<std::uint32_t>(i);
  time_origin_ = system.time;
  step_base_ = 0;
  if (!system.dem.empty() && resume(system.dem)) return;
  build_neighbours();
  compute_forces(/*count_collisions=*/false, time_);  // also rejects absurd initial overlaps
  synchronise(/*from_half_step=*/false);              // u = v - (dt/2) a
}

// The layout of a DemResume: scalars in this order, per particle u (D), f (D) and with friction
// the half-step spin and torque (kSpin each) and one spring (D) per wall face.
namespace {
enum DemScalar {
  kLayout,  // kDemLayout
  kTimeStep,
  kTimeOrigin,
  kStepsDone,
  kMoved,
  kPower,
  kVirialPower,
  kWallLoss,
  kWallWork,
  kSlip,
  kSpring,
  kWallSlip,
  kWallSpring,
  kPotential,
  kContacts,
  kFriction,
  kScalars
};
constexpr double kDemLayout = 1.0;
}  // namespace

template <int D>
DemResume DemIntegrator<D>::checkpoint() const {
  DemResume r;
  r.scalars.assign(kScalars, 0.0);
  r.scalars[kLayout] = kDemLayout;
  r.scalars[kTimeStep] = dt_;
  r.scalars[kTimeOrigin] = time_origin_;
  r.scalars[kStepsDone] = static_cast<double>(step_base_ + steps_);
  r.scalars[kMoved] = moved_since_build_;
  r.scalars[kPower] = power_;
  r.scalars[kVirialPower] = virial_power_;
  r.scalars[kWallLoss] = wall_loss_power_;
  r.scalars[kWallWork] = wall_work_power_;
  r.scalars[kSlip] = slip_power_;
  r.scalars[kSpring] = spring_energy_;
  r.scalars[kWallSlip] = wall_slip_power_;
  r.scalars[kWallSpring] = wall_spring_energy_;
  r.scalars[kPotential] = potential_;
  r.scalars[kContacts] = static_cast<double>(contacts_);
  r.scalars[kFriction] = friction_ ? 1.0 : 0.0;
  // Walls with mass: the contacts' force on each face at the last evaluation (the next step's
  // opening kick), after the fixed scalars.
  if (any_massive_) r.scalars.insert(r.scalars.end(), wall_force_.begin(), wall_force_.end());
  const std::size_t n = size(), stride = resume_stride();
  r.particles.resize(n * stride);
  for (std::size_t i = 0; i < n; ++i) {
    double* p = &r.particles[id_[i] * stride];
    for (int k = 0; k < D; ++k) {
      *p++ = u_[k][i];
      *p++ = f_[k][i];
    }
    if (!friction_) continue;
    for (int c = 0; c < kSpin; ++c) {
      *p++ = uw_[c][i];
      *p++ = tq_[c][i];
    }
    for (const std::vector<Vec<D>>& springs : wall_shear_)
      if (!springs.empty())
        for (int k = 0; k < D; ++k) *p++ = springs[i][static_cast<std::size_t>(k)];
  }
  r.order = id_;
  r.list_start = start_;
  r.list = nbr_;
  if (friction_) {
    r.springs.reserve(shear_.size() * D);
    for (const Vec<D>& s : shear_) r.springs.insert(r.springs.end(), s.begin(), s.end());
  }
  return r;
}

template <int D>
std::size_t DemIntegrator<D>::resume_stride() const {
  std::size_t faces = 0;
  for (const std::vector<Vec<D>>& springs : wall_shear_) faces += springs.empty() ? 0 : 1;
  return 2 * D + (friction_ ? 2 * kSpin + faces * D : 0);
}

// Takes the state of checkpoint(): false (start afresh) when it was made with another time step;
// InputError when it does not fit the system.
template <int D>
bool DemIntegrator<D>::resume(const DemResume& r) {
  const std::size_t n = size();
  const std::size_t scalars = kScalars + (any_massive_ ? 2 * D : 0);
  if (r.scalars.size() < kScalars || r.scalars[kLayout] != kDemLayout)
    throw InputError("DEM: the saved integrator state has an unknown layout");
  if (r.scalars.size() != scalars) {
    throw InputError(
        "DEM: the saved integrator state does not fit this run's walls with mass (saved with "
        "walls with mass and continued without, or the other way round)");
  }
  if (r.scalars[kTimeStep] != dt_) return false;
  const std::size_t stride = resume_stride();
  const auto bad = [](const char* what) {
    throw InputError(fmt::format("DEM: the saved integrator state is inconsistent ({})", what));
  };
  if ((r.scalars[kFriction] != 0.0) != friction_) bad("friction");
  if (r.particles.size() != n * stride) bad("per-particle data");
  if (r.order.size() != n || r.list_start.size() != n + 1 || r.list_start[0] != 0 ||
      r.list_start[n] != r.list.size())
    bad("numbering or neighbour list");
  std::vector<std::uint8_t> seen(n, 0);
  for (const std::uint32_t id : r.order) {
    if (id >= n || seen[id]) bad("numbering");
    seen[id] = 1;
  }
  for (std::size_t i = 0; i < n; ++i)
    if (r.list_start[i] > r.list_start[i + 1]) bad("neighbour list");
  for (const std::uint32_t j : r.list)
    if (j >= n) bad("neighbour list");
  if (friction_ && r.springs.size() != r.list.size() * D) bad("springs");
  for (const double x : r.particles)
    if (!std::isfinite(x)) bad("a value is not finite");
  // The system's particles (slot = caller's number so far) into the saved order.
  std::vector<std::uint32_t> order(r.order.begin(), r.order.end());
  const auto permute = [&](std::vector<double>& a) {
    std::vector<double> tmp(n);
    for (std::size_t q = 0; q < n; ++q) tmp[q] = a[order[q]];
    a.swap(tmp);
  };
  for (int k = 0; k < D; ++k) {
    permute(x_[k]);
    permute(v_[k]);
  }
  permute(mass_);
  permute(inv_mass_);
  permute(radius_);
  if (friction_) {
    for (int c = 0; c < kSpin; ++c) permute(w_[c]);
    permute(inertia_);
    permute(inv_inertia_);
  }
  std::vector<std::uint32_t> sp(n);
  for (std::size_t q = 0; q < n; ++q) sp[q] = sp_[order[q]];
  sp_.swap(sp);
  id_ = order;
  for (std::size_t q = 0; q < n; ++q) slot_[id_[q]] = static_cast<std::uint32_t>(q);
  for (std::size_t i = 0; i < n; ++i) {
    const double* p = &r.particles[id_[i] * stride];
    for (int k = 0; k < D; ++k) {
      u_[k][i] = *p++;
      f_[k][i] = *p++;
      vp_[k][i] = v_[k][i];
    }
    if (!friction_) continue;
    for (int c = 0; c < kSpin; ++c) {
      uw_[c][i] = *p++;
      tq_[c][i] = *p++;
      wp_[c][i] = w_[c][i];
    }
    for (std::vector<Vec<D>>& springs : wall_shear_)
      if (!springs.empty())
        for (int k = 0; k < D; ++k) springs[i][static_cast<std::size_t>(k)] = *p++;
  }
  start_ = r.list_start;
  nbr_ = r.list;
  if (friction_) {
    shear_.resize(nbr_.size());
    for (std::size_t q = 0; q < nbr_.size(); ++q)
      for (int k = 0; k < D; ++k)
        shear_[q][static_cast<std::size_t>(k)] = r.springs[q * D + static_cast<std::size_t>(k)];
  }
  time_origin_ = r.scalars[kTimeOrigin];
  step_base_ = static_cast<long>(r.scalars[kStepsDone]);
  moved_since_build_ = r.scalars[kMoved];
  power_ = r.scalars[kPower];
  virial_power_ = r.scalars[kVirialPower];
  wall_loss_power_ = r.scalars[kWallLoss];
  wall_work_power_ = r.scalars[kWallWork];
  slip_power_ = r.scalars[kSlip];
  spring_energy_ = r.scalars[kSpring];
  wall_slip_power_ = r.scalars[kWallSlip];
  wall_spring_energy_ = r.scalars[kWallSpring];
  potential_ = r.scalars[kPotential];
  contacts_ = static_cast<std::size_t>(r.scalars[kContacts]);
  for (std::size_t f = 0; f < wall_force_.size() && any_massive_; ++f)
    wall_force_[f] = r.scalars[kScalars + f];
  time_ = time_at(0);
  return true;
}

template <int D>
void DemIntegrator<D>::build_neighbours() {
  const std::size_t n = size();
  const double cutoff = max_diameter_ + skin_;
  const double cutoff2 = cutoff * cutoff;
  std::array<int, D> nc;
  std::size_t ncells = 1;
  for (int k = 0; k < D; ++k) {
    nc[k] = std::max(1, static_cast<int>(std::floor(box_[k] / cutoff)));
    ncells *= static_cast<std::size_t>(nc[k]);
  }
  // The pairs' tangential springs, keyed by the caller's numbers (a < b; the spring of a
  // relative to b), to be carried into the new list.
  std::vector<std::uint64_t> carried_keys;
  std::vector<Vec<D>> carried;
  if (friction_ && !shear_.empty()) {
    for (std::size_t i = 0; i < n; ++i) {
      for (std::uint32_t q = start_[i]; q < start_[i + 1]; ++q) {
        if (shear_[q] == Vec<D>{}) continue;
        const std::uint64_t a = id_[i], b = id_[nbr_[q]];
        carried_keys.push_back(a < b ? (a << 32) | b : (b << 32) | a);
        carried.push_back(a < b ? shear_[q] : -1.0 * shear_[q]);
      }
    }
  }
  std::vector<std::uint32_t> cell_of(n), cell_start(ncells + 1, 0), cell_list(n);
  for (std::size_t i = 0; i < n; ++i) {
    std::size_t c = 0;
    for (int k = D - 1; k >= 0; --k) {
      int ck = static_cast<int>(x_[k][i] / box_[k] * nc[k]);
      ck = std::clamp(ck, 0, nc[k] - 1);
      c = c * static_cast<std::size_t>(nc[k]) + static_cast<std::size_t>(ck);
    }
    cell_of[i] = static_cast<std::uint32_t>(c);
    ++cell_start[c + 1];
  }
  for (std::size_t c = 0; c < ncells; ++c) cell_start[c + 1] += cell_start[c];
  {
    std::vector<std::uint32_t> fill(cell_start.begin(), cell_start.end() - 1);
    for (std::size_t i = 0; i < n; ++i)
      cell_list[fill[cell_of[i]]++] = static_cast<std::uint32_t>(i);
  }
  // Renumber the particles in cell order (spatial locality of the pair loops); cell_list then
  // becomes the identity.
  {
    std::vector<double> tmp(n);
    auto permute = [&](std::vector<double>& a) {
      for (std::size_t q = 0; q < n; ++q) tmp[q] = a[cell_list[q]];
      a.swap(tmp);
    };
    for (int k = 0; k < D; ++k) {
      permute(x_[k]);
      permute(v_[k]);
      permute(u_[k]);
      permute(vp_[k]);  // f_ and tq_ are zero here: the kick cleared them
    }
    permute(mass_);
    permute(inv_mass_);
    permute(radius_);
    if (friction_) {
      for (int c = 0; c < kSpin; ++c) {
        permute(w_[c]);
        permute(uw_[c]);
        permute(wp_[c]);
      }
      permute(inertia_);
      permute(inv_inertia_);
      std::vector<Vec<D>> tmp_v(n);
      for (std::vector<Vec<D>>& springs : wall_shear_) {
        if (springs.empty()) continue;
        for (std::size_t q = 0; q < n; ++q) tmp_v[q] = springs[cell_list[q]];
        springs.swap(tmp_v);
      }
    }
    std::vector<std::uint32_t> tmp_u(n);
    for (std::size_t q = 0; q < n; ++q) tmp_u[q] = sp_[cell_list[q]];
    sp_.swap(tmp_u);
    for (std::size_t q = 0; q < n; ++q) tmp_u[q] = id_[cell_list[q]];
    id_.swap(tmp_u);
    for (std::size_t q = 0; q < n; ++q) {
      slot_[id_[q]] = static_cast<std::uint32_t>(q);
      tmp_u[q] = cell_of[cell_list[q]];
    }
    cell_of.swap(tmp_u);
    for (std::size_t q = 0; q < n; ++q) cell_list[q] = static_cast<std::uint32_t>(q);
  }

  const Vec<D> half = half_box();
  // Per axis, the distinct neighbouring cell coordinates of coordinate c (3 of them, fewer when
  // a periodic axis has fewer than 3 cells), as offsets into the flat index; between walls a
  // neighbour beyond the outer cells does not exist (kNoCell).
  bool all_three = true;
  for (int k = 0; k < D; ++k) all_three = all_three && (nc[k] >= 3 || !periodic_[k]);
  start_.assign(n + 1, 0);
  nbr_.clear();
  std::vector<std::uint32_t> around;
  around.reserve(27);
  for (std::size_t i = 0; i < n; ++i) {
    std::array<int, D> ci;
    std::size_t c = cell_of[i];
    for (int k = 0; k < D; ++k) {
      ci[k] = static_cast<int>(c % static_cast<std::size_t>(nc[k]));
      c /= static_cast<std::size_t>(nc[k]);
    }
    std::array<std::array<std::size_t, 3>, D> axis;  // neighbour coordinate times its stride
    std::size_t stride = 1;
    for (int k = 0; k < D; ++k) {
      for (int off = -1; off <= 1; ++off) {
        int ck = ci[k] + off;
        std::size_t& out = axis[k][static_cast<std::size_t>(off + 1)];
        if (!periodic_[k] && (ck < 0 || ck >= nc[k])) {
          out = kNoCell;
          continue;
        }
        if (ck < 0) ck += nc[k];
        if (ck >= nc[k]) ck -= nc[k];
        out = static_cast<std::size_t>(ck) * stride;
      }
      stride *= static_cast<std::size_t>(nc[k]);
    }
    around.clear();
    const bool walls = any_wall_;  // only then can a neighbour cell be missing
    if constexpr (D == 3) {
      for (const std::size_t a : axis[2])
        for (const std::size_t b2 : axis[1])
          for (const std::size_t c0 : axis[0])
            around.push_back(walls && (a == kNoCell || b2 == kNoCell || c0 == kNoCell)
                                 ? kNoCell32
                                 : static_cast<std::uint32_t>(a + b2 + c0));
    } else {
      for (const std::size_t b2 : axis[1])
        for (const std::size_t c0 : axis[0])
          around.push_back(walls && (b2 == kNoCell || c0 == kNoCell)
                               ? kNoCell32
                               : static_cast<std::uint32_t>(b2 + c0));
    }
    Vec<D> xi;
    for (int k = 0; k < D; ++k) xi[k] = x_[k][i];
    auto scan = [&](std::uint32_t from, std::uint32_t to) {
      for (std::uint32_t j = from; j < to; ++j) {  // cell_list is the identity after the sort
        double r2 = 0.0;
        for (int k = 0; k < D; ++k) {
          const double d = min_image_once(xi[k] - x_[k][j], half[k], box_[k]);
          r2 += d * d;
        }
        if (r2 < cutoff2) nbr_.push_back(j);
      }
    };
    const auto self = static_cast<std::uint32_t>(i);
    if (all_three) {
      // Half stencil: i's own cell (partners after i) and the (3^D - 1)/2 cells after it in
      // the (z, y, x) lexicographic order of the offsets; all distinct with >= 3 cells per axis,
      // so every pair is found once.
      const std::size_t centre = around.size() / 2;
      scan(self + 1, cell_start[around[centre] + 1]);
      for (std::size_t m = centre + 1; m < around.size(); ++m)
        if (around[m] != kNoCell32) scan(cell_start[around[m]], cell_start[around[m] + 1]);
    } else {  // some cells appear twice: keep one of each, pairs j > i
      std::sort(around.begin(), around.end());
      around.erase(std::unique(around.begin(), around.end()), around.end());
      for (const std::uint32_t cc : around)
        if (cc != kNoCell32)
          scan(std::max(cell_start[cc], self + 1), std::max(cell_start[cc + 1], self + 1));
    }
    start_[i + 1] = static_cast<std::uint32_t>(nbr_.size());
  }
  if (friction_) carry_shear_over(carried_keys, carried);
  moved_since_build_ = 0.0;
  ++builds_;
}

template <int D>
void DemIntegrator<D>::carry_shear_over(const std::vector<std::uint64_t>& keys,
                                        const std::vector<Vec<D>>& values) {
  shear_.assign(nbr_.size(), Vec<D>{});
  if (keys.empty()) return;
  std::unordered_map<std::uint64_t, Vec<D>> spring;
  spring.reserve(keys.size());
  for (std::size_t k = 0; k < keys.size(); ++k) spring.emplace(keys[k], values[k]);
  for (std::size_t i = 0; i + 1 < start_.size(); ++i) {
    for (std::uint32_t q = start_[i]; q < start_[i + 1]; ++q) {
      const std::uint64_t a = id_[i], b = id_[nbr_[q]];
      const auto it = spring.find(a < b ? (a << 32) | b : (b << 32) | a);
      if (it != spring.end()) shear_[q] = a < b ? it->second : -1.0 * it->second;
    }
  }
}

template <int D>
Spin<D> DemIntegrator<D>::spin(const std::vector<double> (&a)[kSpin], std::size_t i) const {
  if constexpr (D == 3) {
    return Vec<3>{a[0][i], a[1][i], a[2][i]};
  } else {
    return a[0][i];
  }
}

template <int D>
void DemIntegrator<D>::add_spin(std::vector<double> (&a)[kSpin], std::size_t i, const Spin<D>& s) {
  if constexpr (D == 3) {
    for (int c = 0; c < 3; ++c) a[c][i] += s[static_cast<std::size_t>(c)];
  } else {
    a[0][i] += s;
  }
}

template <int D>
template <typename DemIntegrator<D>::Laws L, bool Friction>
void DemIntegrator<D>::compute_forces_for(bool count_collisions) {
  const std::size_t n = size();
  // f_ is zero here (cleared by the constructor or by step's kick pass).
  const Vec<D> half = half_box();
  double potential = 0.0, power = 0.0, virial = 0.0, spring = 0.0, slip = 0.0;
  std::size_t contacts = 0;
  std::uint64_t entered = 0;
  const std::size_t ns = species_;
  const double* const stiffness = stiffness_.data();
  const double* const damping = damping_coefficient_.data();
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t b = start_[i], e = start_[i + 1];
    if (b == e) continue;
    Vec<D> xi, vi, fi{};
    for (int k = 0; k < D; ++k) {
      xi[k] = x_[k][i];
      vi[k] = vp_[k][i];
    }
    const double Ri = radius_[i];
    Spin<D> wi{}, ti{};  // predicted angular velocity and torque (friction)
    if constexpr (Friction) wi = spin(wp_, i);
    const std::size_t row = ns == 1 ? 0 : sp_[i] * ns;
    for (std::uint32_t q = b; q < e; ++q) {
      const std::uint32_t j = nbr_[q];
      Vec<D> d;
      double r2 = 0.0;
      for (int k = 0; k < D; ++k) {
        d[k] = min_image_once(xi[k] - x_[k][j], half[k], box_[k]);
        r2 += d[k] * d[k];
      }
      const double l = Ri + radius_[j];
      if (r2 >= l * l) {
        if constexpr (Friction) shear_[q] = Vec<D>{};  // apart: the spring is gone
        continue;
      }
      // Overlapping pair.
      const double r = std::sqrt(r2);
      const double overlap = l - r;
      if (overlap > max_overlap_fraction_ * std::min(Ri, radius_[j]))
        throw InputError(fmt::format(
            "DEM: particles {} and {} overlap by {} (more than {} of the smaller radius) at t = "
            "{}: time step dt = {} too large or the initial state overlapping",
            id_[i], id_[j], overlap, max_overlap_fraction_, time_, dt_));
      if (count_collisions) {  // apart one step earlier (u_ holds the drift velocity)?
        double r2_before = 0.0;
        for (int k = 0; k < D; ++k) {
          const double dk = d[k] - dt_ * (u_[k][i] - u_[k][j]);
          r2_before += dk * dk;
        }
        if (r2_before >= l * l) ++entered;
      }
      const double inv_r = 1.0 / r;
      double rdot = 0.0;
      for (int k = 0; k < D; ++k) rdot += d[k] * (vi[k] - vp_[k][j]);
      rdot *= inv_r;
      const std::size_t ab = ns == 1 ? 0 : row + sp_[j];
      const double kk = stiffness[ab], c = damping[ab];
      bool hertz = L == Laws::kHertz;
      if constexpr (L == Laws::kMixed) hertz = hertz_[ab] != 0;
      const NormalForce nf = normal_force(hertz, kk, c, overlap, rdot);
      const double F = nf.force;
      potential += nf.energy;
      power += (nf.elastic - F) * rdot;
      if constexpr (Friction) {
        const SoftFriction& fr = friction_pair_[ab];
        if (fr.coefficient > 0.0) {
          Vec<D> unit, vc;
          for (int k = 0; k < D; ++k) {
            unit[k] = d[k] * inv_r;
            vc[k] = vi[k] - vp_[k][j];
          }
          // The contact points' relative velocity: both at the middle of the overlap, i's at
          // x_i - a_i unit and j's at x_j + a_j unit, a = R - overlap / 2, so a_i + a_j = r and
          // the torques of the force pair cancel about any point (angular momentum kept).
          const double ai = Ri - 0.5 * overlap, aj = radius_[j] - 0.5 * overlap;
          vc = vc - cross(ai * wi + aj * spin(wp_, j), unit);
          const Vec<D> vt = vc - dot(vc, unit) * unit;
          const auto [kt, gt] = tangential_law(fr, hertz, kk, c, nf.root);
          const Vec<D> ft = tangential_force<D>(shear_[q], unit, vt, kt, gt, fr.coefficient * F,
                                                count_collisions ? dt_ : 0.0, spring, slip);
          for (int k = 0; k < D; ++k) {
            fi[k] += ft[k];
            f_[k][j] -= ft[k];
          }
          const Spin<D> turn = cross(unit, ft);
          ti = ti - ai * turn;
          add_spin(tq_, j, -aj * turn);
        }
      }
      if (F > 0.0) {
        ++contacts;
        virial += F * r;
        const double s = F * inv_r;
        for (int k = 0; k < D; ++k) {
          fi[k] += s * d[k];
          f_[k][j] -= s * d[k];
        }
      }
    }
    for (int k = 0; k < D; ++k) f_[k][i] += fi[k];
    if constexpr (Friction) add_spin(tq_, i, ti);
  }
  potential_ = potential + spring;
  spring_energy_ = spring;
  slip_power_ = slip;
  power_ = power;
  virial_power_ = virial;
  contacts_ = contacts;
  collisions_ += entered;
}

// Particles pass at the end of a step, once the forces at the new positions are known, and only
// a particle that touches nothing (free_place at its own position): its force is then zero and
// its elastic energy nothing, so the energy it takes out, (1/2) m v^2 + (1/2) I w^2 - m g.x with
// v = u + (dt/2) (f / m + g), is exact, and the forces of the others hold with it moved. A
// particle beyond the plane that still touches a neighbour (a jet's dense head) waits for the
// first step it is free (outlet_waiting() counts those waiting). It is put back with u = v_out -
// (dt/2) g (no force at a free place: v = v_out at once) and no spin; its springs are gone already
// (reset whenever a contact is not touching).
template <int D>
bool DemIntegrator<D>::pass_outlets(double t) {
  const Outlets<D>& outlets = boundaries_.outlets();
  const double h = 0.5 * dt_;
  bool passed = false;
  outlet_waiting_ = 0;
  for (std::size_t i = 0; i < size(); ++i) {
    Vec<D> x;
    for (int a = 0; a < D; ++a) x[a] = x_[a][i];
    for (int k = 0; k < outlets.surfaces(); ++k) {
      if (!(outlets.gap(k, x, t) < 0.0)) continue;
      if (!free_place(i, x, t)) {
        ++outlet_waiting_;
        break;
      }
      const double m = mass_[i];
      Vec<D> v;
      for (int a = 0; a < D; ++a) v[a] = u_[a][i] + h * (inv_mass_[i] * f_[a][i] + gravity_[a]);
      double before = 0.5 * m * norm2(v) - m * dot(gravity_, x);
      if (friction_) {
        for (int c = 0; c < kSpin; ++c) {
          const double w = uw_[c][i] + h * inv_inertia_[i] * tq_[c][i];
          before += 0.5 * inertia_[i] * w * w;
        }
      }
      x = outlet_place<D>(outlets, k, outlet_passes_, periodic_, box_, t, id_[i],
                          [&](const Vec<D>& place) { return free_place(i, place, t); });
      if (friction_)
        for (int c = 0; c < kSpin; ++c) uw_[c][i] = 0.0;
      const Vec<D>& out = outlets.outlet(k).insert_velocity;
      for (int a = 0; a < D; ++a) {
        x_[a][i] = x[a];
        u_[a][i] = out[a] - h * gravity_[a];
      }
      ++outlet_passes_;
      outlet_mass_ += m;
      outlet_energy_ += before - (0.5 * m * norm2(out) - m * dot(gravity_, x));
      passed = true;
      break;  // the place is on every outlet's own side
    }
  }
  return passed;
}

// At least R from every wall and R + R_j from every other particle (the minimum image along
// periodic axes): a search over all particles, for passes are rare next to steps.
template <int D>
bool DemIntegrator<D>::free_place(std::size_t i, const Vec<D>& x, double t) const {
  const double R = radius_[i];
  if (boundaries_.overlaps(x, R, t)) return false;
  const Vec<D> half = half_box();
  for (std::size_t j = 0; j < size(); ++j) {
    if (j == i) continue;
    double r2 = 0.0;
    for (int a = 0; a < D; ++a) {
      const double d = min_image_once(x[a] - x_[a][j], half[a], box_[a]);
      r2 += d * d;
    }
    const double sigma = R + radius_[j];
    if (r2 < sigma * sigma) return false;
  }
  return true;
}

template <int D>
Vec<D> DemIntegrator<D>::half_box() const {
  Vec<D> half;
  for (int k = 0; k < D; ++k)
    half[k] = periodic_[k] ? 0.5 * box_[k] : std::numeric_limits<double>::infinity();
  return half;
}

// Whether slot i (of radius R) touches surface s at `gap`: if not, its spring there is reset;
// InputError if it overlaps by more than the integrator allows.
template <int D>
bool DemIntegrator<D>::touches(std::size_t i, int s, double gap, double t,
                               std::vector<Vec<D>>& springs) {
  const double R = radius_[i];
  if (gap >= R) {
    if (friction_ && springs[i] != Vec<D>{}) springs[i] = Vec<D>{};
    return false;
  }
  const double overlap = R - gap;
  if (overlap > max_overlap_fraction_ * R)
    throw InputError(fmt::format(
        "DEM: particle {} overlaps the wall {} by {} (more than {} of its radius) at t = {}: "
        "time step dt = {} too large, the wall too fast, the contacts too soft for the load on "
        "them (a wall's force, the field) or the initial state outside",
        id_[i], boundaries_.name(s), overlap, max_overlap_fraction_, t, dt_));
  return true;
}

// One wall contact of slot i (both loops): the normal force of its species' wall law, its
// energy split and the surface's work, and with friction the tangential spring.
template <int D>
double DemIntegrator<D>::add_wall_contact(std::size_t i, const WallContact& c, Vec<D>* spring,
                                          bool count_collisions, WallSums& sums,
                                          double damping_scale) {
  const std::size_t s = sp_[i];
  const double kk = wall_stiffness_[s], damping = wall_damping_[s] * damping_scale;
  const bool hertz = wall_hertz_[s] != 0;
  const NormalForce nf = normal_force(hertz, kk, damping, radius_[i] - c.gap, c.rdot);
  const double F = nf.force;
  sums.potential += nf.energy;
  sums.loss += (nf.elastic - F) * c.rdot;
  // d(KE + U)/dt = -(F_el - F) rdot + F w_n, w_n the surface's velocity along the normal.
  sums.work += F * c.normal_speed;
  if (c.axis >= 0) {
    f_[c.axis][i] += c.normal[c.axis] * F;  // a face: the other components stay untouched
  } else {
    for (int a = 0; a < D; ++a) f_[a][i] += F * c.normal[a];
  }
  if (!friction_ || !(friction_wall_[s].coefficient > 0.0)) return F;
  const SoftFriction& fr = friction_wall_[s];
  Vec<D> v;
  for (int a = 0; a < D; ++a) v[a] = vp_[a][i];
  // The contact point (on the surface, at x - gap n) relative to the surface.
  const Vec<D> vc = v - c.gap * cross(spin(wp_, i), c.normal) - c.velocity;
  const Vec<D> vt = vc - dot(vc, c.normal) * c.normal;
  const auto [kt, gt] = tangential_law(fr, hertz, kk, damping, nf.root);
  const Vec<D> ft = tangential_force<D>(*spring, c.normal, vt, kt, gt, fr.coefficient * F,
                                        count_collisions ? dt_ : 0.0, sums.spring, sums.slip);
  for (int a = 0; a < D; ++a) f_[a][i] += ft[a];
  add_spin(tq_, i, -c.gap * cross(c.normal, ft));
  sums.work += dot(ft, c.velocity);  // a sliding wall drags (and heats) by friction
  return F;
}

// Half a kick (dt/2 times the contacts' force of the last evaluation) on every wall with mass at
// time t; between kicks each moves by its own closed-form motion (boundaries/wall_body.hpp).
template <int D>
void DemIntegrator<D>::kick_walls(double t) {
  FaceWalls<D>& faces = boundaries_.faces();
  for_each_massive_face(
      [&](int f) { faces.kick(f, t, 0.5 * dt_ * wall_force_[static_cast<std::size_t>(f)]); });
}

// The factor on a wall law's damping coefficient for particle i against a wall of mass M: the
// dimensionless damping that sets the restitution is the dashpot's gamma / (2 sqrt(mu k)) and
// the viscoelastic law's A (rho / mu)^(2/5) v^(1/5) (Schwager & Poeschel, Phys. Rev. E 57, 650
// (1998)), so keeping it at mu = m M / (m + M) instead of m scales gamma by sqrt(mu / m) and A
// by (mu / m)^(2/5).
template <int D>
double DemIntegrator<D>::reduced_mass_damping(std::size_t i, double wall_mass) const {
  const double ratio = wall_mass / (mass_[i] + wall_mass);  // mu / m
  return wall_hertz_[sp_[i]] != 0 ? std::pow(ratio, 0.4) : std::sqrt(ratio);
}

template <int D>
void DemIntegrator<D>::compute_wall_forces(bool count_collisions, double t) {
  const std::size_t n = size();
  WallSums sums;
  // The walls with mass's predicted velocity at t, as the particles' (v = u + (dt/2) a with the
  // last evaluation's force): its speed after the opening half kick and its own motion, plus
  // the half kick still to come from the forces of the last evaluation on its body (both faces
  // of a container), for the contacts' damping. The set-up's evaluation (no kick yet) reads the
  // body's speed as it is, its last force being 0.
  if (any_massive_) {
    for_each_massive_face([&](int f) {
      const FaceWalls<D>& faces = boundaries_.faces();
      const Wall<D>& wall = walls_[static_cast<std::size_t>(f)];
      double force = wall_force_[static_cast<std::size_t>(f)];
      if (wall.joined) force += wall_force_[static_cast<std::size_t>(f ^ 1)];
      predicted_wall_speed_[static_cast<std::size_t>(f)] =
          faces.body(f).speed_at(t) + (count_collisions ? 0.5 * dt_ * force / wall.mass : 0.0);
    });
  }
  for (int f = 0; f < 2 * D; ++f) {
    if (!wall_on_[static_cast<std::size_t>(f)]) continue;
    const int k = f / 2;
    const double sign = f % 2 == 0 ? 1.0 : -1.0;  // the wall's normal (into the box) along k
    const Wall<D>& wall = walls_[static_cast<std::size_t>(f)];
    // A wall with mass: where its body has taken it (the opening half kick at the step's start,
    // then its own motion), and that body's speed, as the particles' predicted velocities.
    const bool massive = wall.massive();
    const FaceWalls<D>& faces = boundaries_.faces();
    const double p = massive ? faces.position(f, t) : wall.plane_position(f, box_, t);
    const double w =
        massive ? predicted_wall_speed_[static_cast<std::size_t>(f)] : wall.plane_speed(f, t);
    const double p_before =
        massive ? faces.position(f, t - dt_) : wall.plane_position(f, box_, t - dt_);
    double on_wall = 0.0;  // the contacts' force on it along the axis
    const double* const x = x_[k].data();
    // The wall's velocity (sliding in its plane, moving along its normal) and normal.
    WallContact c{.axis = k};
    c.velocity = wall.velocity;
    c.velocity[k] = w;
    c.normal[k] = sign;
    // A wall with mass: its work on the particles is counted below, at its speed after the
    // step's kicks (the predicted one would bias it by dt F^2 / 2M per step).
    c.normal_speed = massive ? 0.0 : sign * w;
    std::vector<Vec<D>>& springs = wall_shear_[static_cast<std::size_t>(f)];
    // One loop per kind of wall (a wall of infinite mass pays nothing for the other's terms).
    const auto contacts = [&](auto with_mass) {
      for (std::size_t i = 0; i < n; ++i) {
        c.gap = sign * (x[i] - p);  // the centre's distance from the plane
        if (!touches(i, f, c.gap, t, springs)) continue;
        // Apart one step earlier (u_ holds the drift velocity)?
        if (count_collisions && sign * (x[i] - dt_ * u_[k][i] - p_before) >= radius_[i])
          ++sums.entered;
        c.rdot = sign * (vp_[k][i] - w);  // the gap's rate of change
        Vec<D>* spring = friction_ ? &springs[i] : nullptr;
        if constexpr (decltype(with_mass)::value) {
          // Against a wall with mass M the contact's damping is the law's at the reduced mass
          // m M / (m + M), so that the two-body restitution is the law's (as the event
          // engine's).
          on_wall -= sign * add_wall_contact(i, c, spring, count_collisions, sums,
                                             reduced_mass_damping(i, wall.mass));
        } else {
          add_wall_contact(i, c, spring, count_collisions, sums);
        }
      }
    };
    massive ? contacts(std::true_type{}) : contacts(std::false_type{});
    wall_force_[static_cast<std::size_t>(f)] = on_wall;
  }
  if (any_massive_) {
    // The closing half kick of the walls with mass (a time step's, not the set-up's
    // evaluation), after which each body has its velocity at t (velocity Verlet's v(t)), with
    // which its work on the particles, minus its force times its speed, is counted.
    if (count_collisions) kick_walls(t);
    for_each_massive_face([&](int f) {
      sums.work -=
          wall_force_[static_cast<std::size_t>(f)] * boundaries_.faces().body(f).speed_at(t);
    });
  }
  if (any_surface_) add_surface_forces(count_collisions, t, sums);
  potential_ += sums.potential + sums.spring;
  wall_spring_energy_ = sums.spring;
  wall_slip_power_ = sums.slip;
  wall_loss_power_ = sums.loss;
  wall_work_power_ = sums.work;
  wall_collisions_ += count_collisions ? sums.entered : 0;
}

template <int D>
void DemIntegrator<D>::add_surface_forces(bool count_collisions, double t, WallSums& sums) {
  int first = 0;
  boundaries_.for_each([&](const auto& c) {
    // The faces have their own loop (compute_wall_forces); particles pass through outlets
    // (pass_outlets).
    using Component = std::decay_t<decltype(c)>;
    if constexpr (!std::is_same_v<Component, FaceWalls<D>> &&
                  !std::is_same_v<Component, Outlets<D>>)
      add_component_forces(c, first, count_collisions, t, sums);
    first += c.surfaces();
  });
}

// As the faces' loop with the surface's own gap, normal (into the domain) and velocity at the
// particle's contact point.
template <int D>
template <class Component>
void DemIntegrator<D>::add_component_forces(const Component& component, int first,
                                            bool count_collisions, double t, WallSums& sums) {
  const std::size_t n = size();
  for (int k = 0; k < component.surfaces(); ++k) {
    if (!component.is_surface(k)) continue;
    std::vector<Vec<D>>& springs = wall_shear_[static_cast<std::size_t>(first + k)];
    for (std::size_t i = 0; i < n; ++i) {
      Vec<D> x;
      for (int a = 0; a < D; ++a) x[a] = x_[a][i];
      WallContact c{.gap = component.gap(k, x, t)};
      if (!touches(i, first + k, c.gap, t, springs)) continue;
      c.normal = component.normal(k, x, t);
      c.velocity = component.velocity(k, x, t);
      c.normal_speed = dot(c.normal, c.velocity);
      if (count_collisions) {  // apart one step earlier (u_ holds the drift velocity)?
        Vec<D> before;
        for (int a = 0; a < D; ++a) before[a] = x[a] - dt_ * u_[a][i];
        if (component.gap(k, before, t - dt_) >= radius_[i]) ++sums.entered;
      }
      Vec<D> v;
      for (int a = 0; a < D; ++a) v[a] = vp_[a][i];
      c.rdot = dot(v - c.velocity, c.normal);  // the gap's rate of change
      add_wall_contact(i, c, friction_ ? &springs[i] : nullptr, count_collisions, sums);
    }
  }
}

template <int D>
void DemIntegrator<D>::compute_forces(bool count_collisions, double t) {
  switch (kind_) {
    case Laws::kDashpot:
      friction_ ? compute_forces_for<Laws::kDashpot, true>(count_collisions)
                : compute_forces_for<Laws::kDashpot, false>(count_collisions);
      break;
    case Laws::kHertz:
      friction_ ? compute_forces_for<Laws::kHertz, true>(count_collisions)
                : compute_forces_for<Laws::kHertz, false>(count_collisions);
      break;
    case Laws::kMixed:
      friction_ ? compute_forces_for<Laws::kMixed, true>(count_collisions)
                : compute_forces_for<Laws::kMixed, false>(count_collisions);
      break;
  }
  if (any_wall_) compute_wall_forces(count_collisions, t);
}

// The fused kick (by `kick`) and drift of every particle; forces cleared for the next
// evaluation, the predicted velocity v(t + dt) for the damping forces. Gravity adds to every
// particle's acceleration; axes between walls are not wrapped.
template <int D>
template <bool Gravity, bool Walls>
void DemIntegrator<D>::kick_drift(double& vmax2_out, double& vsum2_out) {
  const std::size_t np = size();
  const double h = 0.5 * dt_;
  const std::array<bool, D> periodic = periodic_;
  double vmax2 = 0.0, vsum2 = 0.0;  // locals: the stores into the arrays could alias them
  for (std::size_t i = 0; i < np; ++i) {
    const double w = inv_mass_[i];
    double v2 = 0.0;
    for (int k = 0; k < D; ++k) {
      const double f = f_[k][i];
      f_[k][i] = 0.0;
      double v, vp;
      if constexpr (Gravity) {
        const double a = w * f + gravity_[k];
        v = u_[k][i] + dt_ * a;
        vp = v + h * a;
      } else {
        v = u_[k][i] + dt_ * w * f;
        vp = v + h * w * f;
      }
      u_[k][i] = v;
      const double x = x_[k][i] + dt_ * v;
      x_[k][i] = !Walls || periodic[k] ? wrap_once(x, box_[k]) : x;
      vp_[k][i] = vp;
      v2 += v * v;
    }
    vmax2 = std::max(vmax2, v2);
    vsum2 += v2;
  }
  vmax2_out = vmax2;
  vsum2_out = vsum2;
  if (!friction_) return;
  for (std::size_t i = 0; i < np; ++i) {  // the same for the rotation
    const double w = inv_inertia_[i];
    for (int c = 0; c < kSpin; ++c) {
      const double tq = tq_[c][i];
      tq_[c][i] = 0.0;
      const double spin_now = uw_[c][i] + dt_ * w * tq;
      uw_[c][i] = spin_now;
      wp_[c][i] = spin_now + h * w * tq;
    }
  }
}

// The velocities (and spins) at the present step from the half-step ones and the forces:
// v = u + (dt/2) a. Only read by the outside: the stepping itself carries u, so where a run
// splits its steps into calls does not change a bit.
template <int D>
void DemIntegrator<D>::synchronise(bool from_half_step) {
  const double h = 0.5 * dt_;
  const double sign = from_half_step ? 1.0 : -1.0;  // false: u = v - (dt/2) a instead
  std::vector<double>(&from)[D] = from_half_step ? u_ : v_;
  std::vector<double>(&to)[D] = from_half_step ? v_ : u_;
  for (std::size_t i = 0; i < size(); ++i) {
    const double hw = h * inv_mass_[i];
    for (int k = 0; k < D; ++k) to[k][i] = from[k][i] + sign * (hw * f_[k][i] + h * gravity_[k]);
    if (!friction_) continue;
    const double hi = h * inv_inertia_[i];
    for (int c = 0; c < kSpin; ++c)
      (from_half_step ? w_ : uw_)[c][i] = (from_half_step ? uw_ : w_)[c][i] + sign * hi * tq_[c][i];
  }
}

template <int D>
void DemIntegrator<D>::step(long n) {
  advance(n, std::numeric_limits<std::uint64_t>::max());
}

template <int D>
long DemIntegrator<D>::step_until(long n, std::uint64_t collisions) {
  return advance(n, collisions);
}

template <int D>
long DemIntegrator<D>::advance(long n, std::uint64_t collisions) {
  if (n < 0) throw InputError(fmt::format("DEM: step count must be >= 0, got {}", n));
  const double h = 0.5 * dt_;
  if (n == 0) return 0;
  long s = 0;
  // Velocity Verlet with the closing half kick of one step and the opening half kick of the
  // next fused into one kick by dt on the half-step velocities u (one pass over the arrays
  // less); v_ holds v(t), made from u, between calls. The same pass clears the forces for the
  // next evaluation.
  while (s < n && collisions_ < collisions) {
    // The opening half kick of the walls with mass, at the step's start, by the forces of the
    // last evaluation (with the closing one of the step before: one kick by dt, as the
    // particles' fused kick).
    if (any_massive_) kick_walls(time_);
    double vmax2 = 0.0, vsum2 = 0.0;
    if (gravity_on_) {
      any_wall_ ? kick_drift<true, true>(vmax2, vsum2) : kick_drift<true, false>(vmax2, vsum2);
    } else {
      any_wall_ ? kick_drift<false, true>(vmax2, vsum2) : kick_drift<false, false>(vmax2, vsum2);
    }
    if (!std::isfinite(vsum2))
      throw InputError(
          fmt::format("DEM: a velocity turned non-finite at t = {} (dt = {})", time_, dt_));
    moved_since_build_ += dt_ * std::sqrt(vmax2);
    if (2.0 * moved_since_build_ >= skin_) build_neighbours();
    const double power_before = power_, virial_before = virial_power_;
    const double loss_before = wall_loss_power_, work_before = wall_work_power_;
    const double slip_before = slip_power_, spring_before = spring_energy_;
    const double wall_slip_before = wall_slip_power_, wall_spring_before = wall_spring_energy_;
    compute_forces(/*count_collisions=*/true, time_at(steps_ + 1));
    dissipated_ += h * (power_before + power_);
    virial_ += h * (virial_before + virial_power_);
    dissipated_walls_ += h * (loss_before + wall_loss_power_);
    if (friction_) {  // what the tangential forces took from the slip beyond their springs
      dissipated_ -= h * (slip_before + slip_power_) + (spring_energy_ - spring_before);
      dissipated_walls_ -=
          h * (wall_slip_before + wall_slip_power_) + (wall_spring_energy_ - wall_spring_before);
    }
    work_by_walls_ += h * (work_before + wall_work_power_);
    ++steps_;
    ++s;
    time_ = time_at(steps_);
    // A particle put back jumped: the list no longer holds its neighbours.
    if (any_outlet_ && pass_outlets(time_)) moved_since_build_ = skin_;
  }
  synchronise(/*from_half_step=*/true);
  return s;
}

template <int D>
double DemIntegrator<D>::time_at(long steps) const {
  return time_origin_ + static_cast<double>(step_base_ + steps) * dt_;
}

namespace {
// Sum over particles of w_i |a_i|^2 / 2, the C components of a stored apart (kinetic energies).
template <int C>
double half_weighted_squares(const std::vector<double> (&a)[C], const std::vector<double>& w) {
  double e = 0.0;
  for (std::size_t i = 0; i < w.size(); ++i) {
    double a2 = 0.0;
    for (int c = 0; c < C; ++c) a2 += a[c][i] * a[c][i];
    e += 0.5 * w[i] * a2;
  }
  return e;
}
}  // namespace

template <int D>
double DemIntegrator<D>::kinetic_energy() const {
  return half_weighted_squares(v_, mass_);
}

template <int D>
double DemIntegrator<D>::rotational_energy() const {
  return friction_ ? half_weighted_squares(w_, inertia_) : 0.0;
}

template <int D>
double DemIntegrator<D>::field_energy() const {
  if (!gravity_on_) return 0.0;
  for (int k = 0; k < D; ++k)
    if (periodic_[k] && gravity_[k] != 0.0) return std::numeric_limits<double>::quiet_NaN();
  double e = 0.0;
  for (std::size_t i = 0; i < size(); ++i)
    for (int k = 0; k < D; ++k) e -= mass_[i] * gravity_[k] * x_[k][i];
  return e;
}

template <int D>
Vec<D> DemIntegrator<D>::momentum() const {
  Vec<D> p{};
  for (std::size_t i = 0; i < size(); ++i)
    for (int k = 0; k < D; ++k) p[k] += mass_[i] * v_[k][i];
  return p;
}

template <int D>
Vec<D> DemIntegrator<D>::position(std::size_t particle) const {
  const std::size_t i = slot_.at(particle);
  Vec<D> p;
  for (int k = 0; k < D; ++k) p[k] = x_[k][i];
  return p;
}

template <int D>
Vec<D> DemIntegrator<D>::velocity(std::size_t particle) const {
  const std::size_t i = slot_.at(particle);
  Vec<D> v;
  for (int k = 0; k < D; ++k) v[k] = v_[k][i];
  return v;
}

template <int D>
ParticleSystem<D> DemIntegrator<D>::export_state() const {
  ParticleSystem<D> s = base_;
  s.time = time_;
  for (std::size_t i = 0; i < size(); ++i) {
    auto& kin = s.kinematics[id_[i]];
    for (int k = 0; k < D; ++k) {
      kin.pos[k] = periodic_[k] ? wrap_into_box(x_[k][i], box_[k]) : x_[k][i];
      kin.vel[k] = v_[k][i];
    }
    kin.time = time_;
  }
  s.events.clear();
  s.cell.clear();
  s.order.clear();
  s.zones.reset();
  s.dem = DemResume{};
  s.counters.dissipated_in_collisions = dissipated_;
  s.counters.collisions = collisions_;
  s.counters.events = base_.counters.events + static_cast<std::uint64_t>(steps_);
  s.counters.virial = virial_;
  if (friction_) {
    s.angular_velocity.assign(size(), AngularVelocity<D>{});
    for (std::size_t i = 0; i < size(); ++i)
      for (int c = 0; c < kSpin; ++c)
        s.angular_velocity[id_[i]][static_cast<std::size_t>(c)] = w_[c][i];
  }
  s.counters.wall_collisions = wall_collisions_;
  s.counters.dissipated_at_walls = dissipated_walls_;
  s.counters.work_by_walls = work_by_walls_;
  s.wall_motion = boundaries_.motion();
  s.counters.outlet_passes = outlet_passes_;
  s.counters.outlet_mass = outlet_mass_;
  s.counters.outlet_energy = outlet_energy_;
  return s;
}

template class DemIntegrator<2>;
template class DemIntegrator<3>;

}  // namespace kairos
