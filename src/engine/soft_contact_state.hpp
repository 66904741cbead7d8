// The soft contacts in progress of the event engine (Müller–Pöschel mapping, engine/
// soft_contacts.cpp; docs/architecture.md, "Soft spheres"): per particle, the partner of its
// contact (a particle, a wall, or none), when it is released and with what velocity, and
// whether its release is deferred (its record already moves as after the release). A component
// with its own state (allocated only with soft spheres), its part of the renumbering and of
// the restart file (ParticleSystem::frozen, written and read by the engine, which knows the
// records). It decides nothing about events: the engine's soft-contact code does.
#pragma once

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "core/huge_page_allocator.hpp"
#include "core/particle_system.hpp"
#include "core/permutation.hpp"
#include "core/vec.hpp"
#include "dynamics/collision_time.hpp"

namespace kairos {

template <int D>
class SoftContactState {
 public:
  // A contact's partner: a particle index, a wall's event code (above the indices), or kNone.
  static constexpr std::uint32_t kNone = EventSlot::kNoPartner;

  SoftContactState() = default;
  // For n particles; `defer`: releases may be deferred.
  SoftContactState(std::size_t n, bool defer)
      : partner_(n, kNone),
        release_time_(n, kNever),
        release_velocity_(n, Vec<D>{}),
        awaiting_release_((n + 63) / 64, 0) {
    if (defer) deferred_.assign(n, 0);
  }

  bool defers() const { return !deferred_.empty(); }

  // The partner of particle k's contact (kNone: none). A deferred contact keeps its flags after
  // its release (nothing needs to happen then) until the particle's next contact overwrites
  // them: readers take a particle with deferred(k) and a record time not after the present as
  // in no contact.
  std::uint32_t partner(std::uint32_t k) const { return partner_[k]; }
  bool deferred(std::uint32_t k) const { return !deferred_.empty() && deferred_[k] != 0; }
  void set_deferred(std::uint32_t k, bool on) { deferred_[k] = on ? 1 : 0; }
  // Particle k frozen with `partner` (a particle or a wall code), not (yet) deferred.
  void begin(std::uint32_t k, std::uint32_t partner) {
    partner_[k] = partner;
    if (!deferred_.empty()) deferred_[k] = 0;
  }
  // A deferred contact given back early (or over): no partner, not deferred.
  void forget(std::uint32_t k) {
    deferred_[k] = 0;
    partner_[k] = kNone;
  }
  // Particle k's frozen contact ends at `time` with velocity `velocity` (a release event).
  void schedule_release(std::uint32_t k, double time, const Vec<D>& velocity) {
    release_time_[k] = time;
    release_velocity_[k] = velocity;
    set_awaits_release(k, true);
  }
  // The state of a contact restored from a file: partner, release time and velocity, without
  // the release bit (rebuild_awaiting_release sets them all).
  void restore(std::uint32_t k, std::uint32_t partner, double time, const Vec<D>& velocity) {
    partner_[k] = partner;
    release_time_[k] = time;
    release_velocity_[k] = velocity;
  }
  // The release of particle k's frozen contact happened: no partner, no release.
  void end_release(std::uint32_t k) {
    partner_[k] = kNone;
    set_awaits_release(k, false);
    release_time_[k] = kNever;
  }
  double release_time(std::uint32_t k) const { return release_time_[k]; }
  const Vec<D>& release_velocity(std::uint32_t k) const { return release_velocity_[k]; }

  // Particles frozen until a release event, one bit each: every prediction asks, and the bits
  // stay in the first-level cache where the per-particle arrays would not.
  bool awaits_release(std::uint32_t i) const {
    return ((awaiting_release_[i >> 6] >> (i & 63u)) & 1u) != 0;
  }
  void rebuild_awaiting_release() {
    std::fill(awaiting_release_.begin(), awaiting_release_.end(), 0);
    for (std::uint32_t k = 0; k < partner_.size(); ++k)
      if (partner_[k] != kNone && (deferred_.empty() || deferred_[k] == 0))
        set_awaits_release(k, true);
  }

  // Renumbering: partners first (new_index[old] = new), then the arrays (order[new] = old).
  void renumber_partners(const std::vector<std::uint32_t>& new_index, std::uint32_t first_code) {
    for (std::uint32_t& p : partner_)
      if (p < first_code) p = new_index[p];
  }
  void permute(const std::vector<std::uint32_t>& order, std::vector<bool>& done) {
    const auto apply = [&](auto& values) {
      if (!values.empty()) permute_in_place(values, order, done);
    };
    apply(partner_);
    apply(release_time_);
    apply(release_velocity_);
    apply(deferred_);
    if (!partner_.empty()) rebuild_awaiting_release();
  }
  std::size_t size() const { return partner_.size(); }
  // Pairs are mutual (a particle's partner names it back, unless the contact is a deferred one
  // that is over, `ended(k)`), and a release bit is set exactly for the frozen contacts that wait
  // for a release event; fail(message) otherwise. Partners from `first_code` on are walls.
  template <class Ended, class Fail, class Name>
  void validate(std::uint32_t first_code, Ended&& ended, Fail&& fail, Name&& name) const {
    for (std::uint32_t k = 0; k < partner_.size(); ++k) {
      const std::uint32_t p = partner_[k];
      const bool live = p != kNone && !ended(k);
      if (live && p < first_code && (p >= partner_.size() || partner_[p] != k))
        fail("particle " + name(k) + " is in a soft contact its partner is not in");
      const bool waits = p != kNone && !deferred(k);
      if (awaits_release(k) != waits)
        fail("particle " + name(k) + " has a release bit that does not match its contact");
    }
  }
  double bytes_per_particle() const {
    if (partner_.empty()) return 0.0;
    return static_cast<double>(sizeof(std::uint32_t) + sizeof(double) + sizeof(Vec<D>) +
                               (deferred_.empty() ? 0 : 1)) +
           1.0 / 8.0;
  }

 private:
  void set_awaits_release(std::uint32_t i, bool on) {
    const std::uint64_t bit = std::uint64_t{1} << (i & 63u);
    awaiting_release_[i >> 6] =
        on ? awaiting_release_[i >> 6] | bit : awaiting_release_[i >> 6] & ~bit;
  }

  HugeVector<std::uint32_t> partner_;
  HugeVector<double> release_time_;
  HugeVector<Vec<D>> release_velocity_;
  // Deferred releases: 1 while the contact is deferred (its record holds the motion after the
  // release). The energy a deferred contact holds is summed from its records when asked for.
  HugeVector<std::uint8_t> deferred_;
  std::vector<std::uint64_t> awaiting_release_;  // see awaits_release()
};

}  // namespace kairos
