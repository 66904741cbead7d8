// The Helfand moments of momentum and energy, kept exactly from the event stream for the
// Einstein-Helfand transport coefficients (analysis.transport;
// docs/physics.md#einstein-helfand-transport-coefficients).
//
// For a periodic box the moment of the momentum flux is
//   G_ab(t) = integral_0^t sum_i m_i c_ia c_ib dt'  +  sum_{pair events <= t} r_ij,a dp_i,b
// (c: the velocity relative to the centre of mass, r_ij the minimum-image separation at the
// event, dp_i the impulse on i), and that of the energy flux
//   G_a(t) = integral_0^t sum_i c_ia e_i dt'  +  sum_{pair events <= t} r_ij,a de_i,
// with e_i = m c_i^2 / 2 + I w_i^2 / 2 + (half of each of i's pair energies). Between events the
// velocities are constant, so the integrals are exact: this component keeps the two rates (the
// kinetic stress tensor and the kinetic energy flux) and their integrals up to the last event;
// the engine tells it each pair event's velocities before and after (and a stepped pair's
// change of potential energy). The collisional part of G_ab is the engine's virial tensor
// (EventCounters::virial_tensor), kept anyway; the collisional energy moment is kept here.
//
// A soft contact (engine/soft_contacts.cpp, the Muller-Poschel map) moves its pair at once: it
// is placed where the contact ends, and later released or deferred. Between events the moments
// are the time integrals of the fluxes, and across such a jump they follow the sums themselves:
// for the pair (r = r_i - r_j, g = v_i - v_j, mu its reduced mass, M its mass)
//   sum m x c = M R (V - drift) + mu r g,   sum x e = R (e_i + e_j) + r (m_j e_i - m_i e_j) / M,
// and the centre of mass R, V and the pair's energy stay, so the jump adds
// mu (r' g' - r g) to G_ab and the change of r (m_j e_i - m_i e_j) / M to G_a (before_jump,
// after_jump). The virial tensor has already counted the contact's impulse at the mean lever
// arm (docs/physics.md#pressure-and-compressibility); the rest is kept here (jump_stress), so
// that the sum is exact once the contact is over, whatever the contact did in between.
// While a pair is frozen its relative kinetic energy is held as each particle's share:
// m_k |v_k' - V|^2 / 2 with v_k' its velocity after the release.
//
// The moments need a conservative, translation-invariant system (periodic faces, no field,
// walls, driving or shear; elastic contact laws): the configuration refuses the rest. Off unless
// EngineOptions::track_helfand; no restart data of its own (rebuilt from the state when a run
// starts: only differences of the moments are ever used).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/huge_page_allocator.hpp"
#include "core/permutation.hpp"
#include "core/vec.hpp"

namespace kairos {

template <int D>
class HelfandMoments {
 public:
  // The moments at a time, without the virial tensor's part (see above).
  struct Moments {
    std::array<double, 9> kinetic_stress{};  // integral of sum m c_a c_b (row-major D x D)
    Vec<D> kinetic_energy_flux{};            // integral of sum c e
    Vec<D> collisional_energy_flux{};        // sum of r_ij de_i (and soft contacts' jumps)
    // Soft contacts: their jumps' part of the collisional G_ab beyond the virial tensor's.
    std::array<double, 9> jump_stress{};
    // Soft contacts, for the temperature: the integral of the frozen pairs' count, and what
    // the kinetic trace's integral holds beyond the particles' frozen motion (a deferred
    // contact's records move as after the release). Each contact is added whole when it
    // begins and its unspent part taken back at an early release: exact once it is over.
    double frozen_pair_time = 0.0;
    double frozen_kinetic = 0.0;  // to be added to the trace of kinetic_stress
  };

  bool on() const { return on_; }

  // Starts at time t for n particles whose centre of mass moves with `drift` (constant: the
  // system conserves momentum); every particle then given once with add_particle().
  void start(double t, const Vec<D>& drift, std::size_t n) {
    on_ = true;
    time_ = t;
    drift_ = drift;
    stress_rate_ = {};
    energy_rate_ = {};
    moments_ = Moments{};
    share_.assign(n, 0.0);
  }
  // Particle k's half of a pair energy (stepped potentials; before add_particle()).
  void add_potential_share(std::uint32_t k, double energy) { share_[k] += energy; }
  void add_particle(double mass, const Vec<D>& v, double energy) { add(mass, v, energy); }

  // The energy e_k of particle k: kinetic (relative to the centre of mass), rotational, and its
  // share of the pair energies.
  double energy(std::uint32_t k, double mass, const Vec<D>& v, double rotational) const {
    const Vec<D> c = v - drift_;
    return 0.5 * mass * dot(c, c) + rotational + share_[k];
  }

  // A pair event at time t is about to change the velocities of i and j (energies e_i, e_j as
  // energy() gives them now).
  void before_pair(double t, double mi, const Vec<D>& vi, double ei, double mj, const Vec<D>& vj,
                   double ej) {
    integrate_to(t);
    add(mi, vi, -ei, -1.0);
    add(mj, vj, -ej, -1.0);
    energy_before_ = ei;
  }
  // A stepped pair crossed a step of height du: each partner carries half of it.
  void pair_energy_changed(std::uint32_t i, std::uint32_t j, double du) {
    share_[i] += 0.5 * du;
    share_[j] += 0.5 * du;
  }
  // ... and has changed them: r = r_i - r_j at the event (minimum image).
  void after_pair(const Vec<D>& r, double mi, const Vec<D>& vi, double ei, double mj,
                  const Vec<D>& vj, double ej) {
    add(mi, vi, ei);
    add(mj, vj, ej);
    const double de = ei - energy_before_;
    for (int a = 0; a < D; ++a) moments_.collisional_energy_flux[a] += r[a] * de;
  }

  // A soft contact is about to move the pair i, j at time t (r = r_i - r_j, both positions as
  // their records continue them to t; energies as energy() gives them now; the virial tensor
  // now).
  void before_jump(double t, const Vec<D>& r, double mi, const Vec<D>& vi, double ei, double mj,
                   const Vec<D>& vj, double ej, const std::array<double, 9>& virial) {
    integrate_to(t);
    add(mi, vi, -ei, -1.0);
    add(mj, vj, -ej, -1.0);
    jump_from_ = pair_moments(r, mi, vi, ei, mj, vj, ej);
    virial_from_ = virial;
  }
  // Particle k's share of a frozen contact's energy (0 once it is released).
  void set_share(std::uint32_t k, double energy) { share_[k] = energy; }
  double share(std::uint32_t k) const { return share_[k]; }
  // A frozen contact lasts `duration` more (negative: an early release takes back the rest).
  void frozen_pair_for(double duration) { moments_.frozen_pair_time += duration; }
  // ... during which its records' sum m v^2 exceeds the frozen pair's by `excess` (deferred).
  void records_ahead(double excess, double duration) {
    moments_.frozen_kinetic -= excess * duration;
  }
  // ... and has moved it (the virial tensor after it: what the jump added there is not added
  // twice).
  void after_jump(const Vec<D>& r, double mi, const Vec<D>& vi, double ei, double mj,
                  const Vec<D>& vj, double ej, const std::array<double, 9>& virial) {
    add(mi, vi, ei);
    add(mj, vj, ej);
    const PairMoments to = pair_moments(r, mi, vi, ei, mj, vj, ej);
    for (int a = 0; a < D; ++a) {
      for (int b = 0; b < D; ++b) {
        const int k = a * D + b;
        moments_.jump_stress[k] +=
            (to.stress[k] - jump_from_.stress[k]) - (virial[k] - virial_from_[k]);
      }
      moments_.collisional_energy_flux[a] += to.energy[a] - jump_from_.energy[a];
    }
  }

  Moments at(double t) const {
    Moments m = moments_;
    const double dt = t - time_;
    for (int k = 0; k < D * D; ++k) m.kinetic_stress[k] += stress_rate_[k] * dt;
    for (int a = 0; a < D; ++a) m.kinetic_energy_flux[a] += energy_rate_[a] * dt;
    return m;
  }

  void permute(const std::vector<std::uint32_t>& order, std::vector<bool>& done) {
    if (on_) permute_in_place(share_, order, done);
  }
  double bytes_per_particle() const { return on_ ? sizeof(double) : 0.0; }

 private:
  void integrate_to(double t) {
    const double dt = t - time_;
    for (int k = 0; k < D * D; ++k) moments_.kinetic_stress[k] += stress_rate_[k] * dt;
    for (int a = 0; a < D; ++a) moments_.kinetic_energy_flux[a] += energy_rate_[a] * dt;
    time_ = t;
  }
  // Adds sign x particle's rates (its energy already signed).
  void add(double mass, const Vec<D>& v, double signed_energy, double sign = 1.0) {
    const Vec<D> c = v - drift_;
    for (int a = 0; a < D; ++a) {
      for (int b = 0; b < D; ++b) stress_rate_[a * D + b] += sign * mass * c[a] * c[b];
      energy_rate_[a] += c[a] * signed_energy;
    }
  }

  // A pair's own part of sum m x c and sum x e (see above: mu r g and r (m_j e_i - m_i e_j)/M).
  struct PairMoments {
    std::array<double, 9> stress{};
    Vec<D> energy{};
  };
  static PairMoments pair_moments(const Vec<D>& r, double mi, const Vec<D>& vi, double ei,
                                  double mj, const Vec<D>& vj, double ej) {
    const double total = mi + mj, mu = mi * mj / total;
    const Vec<D> g = vi - vj;
    const double weighted = (mj * ei - mi * ej) / total;
    PairMoments p;
    for (int a = 0; a < D; ++a) {
      for (int b = 0; b < D; ++b) p.stress[a * D + b] = mu * r[a] * g[b];
      p.energy[a] = r[a] * weighted;
    }
    return p;
  }

  bool on_ = false;
  double time_ = 0.0;
  Vec<D> drift_{};
  std::array<double, 9> stress_rate_{};  // sum m c_a c_b now
  Vec<D> energy_rate_{};                 // sum c e now
  Moments moments_;                      // up to time_
  double energy_before_ = 0.0;           // e_i before the pair event in progress
  PairMoments jump_from_;                // the jumping pair's moments before the jump
  std::array<double, 9> virial_from_{};  // and the virial tensor then
  HugeVector<double> share_;             // per particle: half its pairs' energies
};

}  // namespace kairos
