#include "dem/dem_integrator.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <fmt/format.h>

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
  init(options);
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

  const std::size_t n = system.size();
  if (n == 0) throw InputError("DEM: the system has no particles");
  if (system.mass.size() != n)
    throw InputError(fmt::format("DEM: {} masses for {} particles", system.mass.size(), n));
  if (!std::isfinite(system.time)) throw InputError("DEM: the system time is not finite");
  for (int k = 0; k < D; ++k) {
    if (!(box_[k] > 0.0) || !std::isfinite(box_[k]))
      throw InputError(
          fmt::format("DEM: box length {} along axis {} must be positive", box_[k], k));
    if (!system.periodic[k])
      throw InputError(fmt::format("DEM: axis {} is not periodic (only periodic boxes)", k));
    if (system.gravity[k] != 0.0) throw InputError("DEM: gravity is not supported");
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
    const Vec<D> p = system.position_at(i, system.time);
    const Vec<D> v = system.velocity_at(i, system.time);
    double v2 = 0.0;
    for (int k = 0; k < D; ++k) {
      if (!std::isfinite(p[k]))
        throw InputError(fmt::format("DEM: position of particle {} is not finite", i));
      if (!std::isfinite(v[k]))
        throw InputError(fmt::format("DEM: velocity of particle {} is not finite", i));
      x_[k][i] = wrap_into_box(p[k], box_[k]);
      v_[k][i] = v[k];
      vp_[k][i] = v[k];
      v2 += v[k] * v[k];
    }
    v_max = std::max(v_max, std::sqrt(v2));
  }
  skin_ = options.skin * max_diameter_;
  for (int k = 0; k < D; ++k)
    if (!(box_[k] > 2.0 * (max_diameter_ + skin_)))
      throw InputError(
          fmt::format("DEM: box length {} along axis {} must exceed 2 (d_max + skin) = {}", box_[k],
                      k, 2.0 * (max_diameter_ + skin_)));

  if (options.dt > 0.0) {
    dt_ = options.dt;
  } else {
    double v_ref = options.reference_speed;
    if (!(v_ref >= 0.0) || !std::isfinite(v_ref))
      throw InputError(fmt::format("DEM: reference_speed must be >= 0, got {}", v_ref));
    if (v_ref == 0.0) v_ref = v_max > 0.0 ? 2.0 * v_max : 1.0;
    dt_ = std::numeric_limits<double>::infinity();
    for (std::size_t a = 0; a < species_; ++a) {
      for (std::size_t b = a; b < species_; ++b) {
        if (!std::isfinite(m_min[a]) || !std::isfinite(m_min[b])) continue;  // no such pair
        const double mu = m_min[a] * m_min[b] / (m_min[a] + m_min[b]);
        dt_ = std::min(dt_, dem_default_time_step(laws_[a * species_ + b], mu, v_ref,
                                                  options.steps_per_contact));
      }
    }
  }

  id_.resize(n);
  slot_.resize(n);
  for (std::size_t i = 0; i < n; ++i) id_[i] = slot_[i] = static_cast<std::uint32_t>(i);
  build_neighbours();
  compute_forces(/*count_collisions=*/false);  // also rejects absurd initial overlaps
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
      permute(vp_[k]);
      permute(f_[k]);
    }
    permute(mass_);
    permute(inv_mass_);
    permute(radius_);
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

  Vec<D> half;
  for (int k = 0; k < D; ++k) half[k] = 0.5 * box_[k];
  // Per axis, the distinct neighbouring cell coordinates of coordinate c (3 of them, fewer when
  // the axis has fewer than 3 cells), as offsets into the flat index.
  bool all_three = true;
  for (int k = 0; k < D; ++k) all_three = all_three && nc[k] >= 3;
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
        if (ck < 0) ck += nc[k];
        if (ck >= nc[k]) ck -= nc[k];
        axis[k][static_cast<std::size_t>(off + 1)] = static_cast<std::size_t>(ck) * stride;
      }
      stride *= static_cast<std::size_t>(nc[k]);
    }
    around.clear();
    if constexpr (D == 3) {
      for (const std::size_t a : axis[2])
        for (const std::size_t b2 : axis[1])
          for (const std::size_t c0 : axis[0])
            around.push_back(static_cast<std::uint32_t>(a + b2 + c0));
    } else {
      for (const std::size_t b2 : axis[1])
        for (const std::size_t c0 : axis[0]) around.push_back(static_cast<std::uint32_t>(b2 + c0));
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
        scan(cell_start[around[m]], cell_start[around[m] + 1]);
    } else {  // some cells appear twice: keep one of each, pairs j > i
      std::sort(around.begin(), around.end());
      around.erase(std::unique(around.begin(), around.end()), around.end());
      for (const std::uint32_t cc : around)
        scan(std::max(cell_start[cc], self + 1), std::max(cell_start[cc + 1], self + 1));
    }
    start_[i + 1] = static_cast<std::uint32_t>(nbr_.size());
  }
  moved_since_build_ = 0.0;
  ++builds_;
}

template <int D>
template <typename DemIntegrator<D>::Laws L>
void DemIntegrator<D>::compute_forces_for(bool count_collisions) {
  const std::size_t n = size();
  // f_ is zero here (cleared by the constructor or by step's kick pass).
  Vec<D> half;
  for (int k = 0; k < D; ++k) half[k] = 0.5 * box_[k];
  double potential = 0.0, power = 0.0, virial = 0.0;
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
      if (r2 >= l * l) continue;
      // Overlapping pair.
      const double r = std::sqrt(r2);
      const double overlap = l - r;
      if (overlap > max_overlap_fraction_ * std::min(Ri, radius_[j]))
        throw InputError(fmt::format(
            "DEM: particles {} and {} overlap by {} (more than {} of the smaller radius) at t = "
            "{}: time step dt = {} too large or the initial state overlapping",
            id_[i], id_[j], overlap, max_overlap_fraction_, time_, dt_));
      if (count_collisions) {  // apart one step earlier (v_ holds the drift velocity)?
        double r2_before = 0.0;
        for (int k = 0; k < D; ++k) {
          const double dk = d[k] - dt_ * (v_[k][i] - v_[k][j]);
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
      double elastic, energy, F;
      if (!hertz) {
        elastic = kk * overlap;
        energy = 0.5 * elastic * overlap;
        F = elastic - c * rdot;
      } else {
        const double root = std::sqrt(overlap);
        elastic = kk * overlap * root;
        energy = 0.4 * elastic * overlap;
        F = elastic - c * rdot * root;
      }
      F = std::max(0.0, F);  // the force-zero end: no attraction
      potential += energy;
      power += (elastic - F) * rdot;
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
  }
  potential_ = potential;
  power_ = power;
  virial_power_ = virial;
  contacts_ = contacts;
  collisions_ += entered;
}

template <int D>
void DemIntegrator<D>::compute_forces(bool count_collisions) {
  switch (kind_) {
    case Laws::kDashpot:
      compute_forces_for<Laws::kDashpot>(count_collisions);
      break;
    case Laws::kHertz:
      compute_forces_for<Laws::kHertz>(count_collisions);
      break;
    case Laws::kMixed:
      compute_forces_for<Laws::kMixed>(count_collisions);
      break;
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
  const std::size_t np = size();
  const double h = 0.5 * dt_;
  if (n == 0) return 0;
  long s = 0;
  // Velocity Verlet with the closing half kick of one step and the opening half kick of the
  // next fused into one kick by dt (one pass over the arrays less); v_ holds v(t) only between
  // calls. The same pass clears the forces for the next evaluation.
  while (s < n && collisions_ < collisions) {
    const double kick = s == 0 ? h : dt_;
    double vmax2 = 0.0, vsum2 = 0.0;
    for (std::size_t i = 0; i < np; ++i) {
      const double w = inv_mass_[i];
      double v2 = 0.0;
      for (int k = 0; k < D; ++k) {
        const double f = f_[k][i];
        f_[k][i] = 0.0;
        const double v = v_[k][i] + kick * w * f;
        v_[k][i] = v;
        x_[k][i] = wrap_once(x_[k][i] + dt_ * v, box_[k]);
        vp_[k][i] = v + h * w * f;  // predicted v(t + dt) for the damping force
        v2 += v * v;
      }
      vmax2 = std::max(vmax2, v2);
      vsum2 += v2;
    }
    if (!std::isfinite(vsum2))
      throw InputError(
          fmt::format("DEM: a velocity turned non-finite at t = {} (dt = {})", time_, dt_));
    moved_since_build_ += dt_ * std::sqrt(vmax2);
    if (2.0 * moved_since_build_ >= skin_) build_neighbours();
    const double power_before = power_, virial_before = virial_power_;
    compute_forces();
    dissipated_ += h * (power_before + power_);
    virial_ += h * (virial_before + virial_power_);
    ++steps_;
    ++s;
    time_ = base_.time + static_cast<double>(steps_) * dt_;
  }
  for (std::size_t i = 0; i < np; ++i) {  // the closing half kick of the last step
    const double hw = h * inv_mass_[i];
    for (int k = 0; k < D; ++k) v_[k][i] += hw * f_[k][i];
  }
  return s;
}

template <int D>
double DemIntegrator<D>::kinetic_energy() const {
  double e = 0.0;
  for (std::size_t i = 0; i < size(); ++i) {
    double v2 = 0.0;
    for (int k = 0; k < D; ++k) v2 += v_[k][i] * v_[k][i];
    e += 0.5 * mass_[i] * v2;
  }
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
      kin.pos[k] = wrap_into_box(x_[k][i], box_[k]);
      kin.vel[k] = v_[k][i];
    }
    kin.time = time_;
  }
  s.events.clear();
  s.cell.clear();
  s.order.clear();
  s.zones.reset();
  s.counters.dissipated_in_collisions = dissipated_;
  s.counters.collisions = collisions_;
  s.counters.events = base_.counters.events + static_cast<std::uint64_t>(steps_);
  s.counters.virial = virial_;
  return s;
}

template class DemIntegrator<2>;
template class DemIntegrator<3>;

}  // namespace kairos
