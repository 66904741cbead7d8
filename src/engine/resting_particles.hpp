// Resting particles under gravity: who sleeps, and the rules that put particles to sleep after
// a contact with a static support (a fixed wall or a sleeper). A component of the event engine
// with its own state (one byte per particle, allocated only when sleeping is on), its part of
// the restart file (ParticleSystem::asleep) and of the renumbering; the engine applies what
// the rules decide. docs/architecture.md, "Resting particles", says why they are needed: a
// bouncing ball with e < 1 bounces infinitely often in finite time, and a pile is full of such
// cascades; docs/physics.md#sleeping gives the rules.
#pragma once

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "core/huge_page_allocator.hpp"
#include "core/permutation.hpp"
#include "core/vec.hpp"

namespace kairos {

template <int D>
class RestingParticles {
 public:
  // What a contact with a support leaves the particle: nothing changes, it falls asleep, or it
  // leaves along the normal n with `lift` added to its normal velocity (so that it leaves with
  // half the sleep speed).
  struct Settle {
    enum Kind { kNothing, kSleep, kLift } kind = kNothing;
    double lift = 0.0;
  };

  RestingParticles() = default;
  // Sleeping on, below `speed`, for n particles under gravity g (speed > 0).
  RestingParticles(std::size_t n, double speed, const Vec<D>& gravity)
      : asleep_(n, 0), speed_(speed), gravity_(gravity) {}

  // The sleep speed of a run: resting particles sleep only under gravity with walls, when no
  // wall moves along its normal (a sleeper predicts no events of its own and would not see it
  // coming) and without steps (a sleeper would miss its steps). `configured` < 0: automatic,
  // sqrt(2 |g| 1e-6 d_min); 0: never.
  static double speed_for(double configured, const Vec<D>& gravity, double min_diameter) {
    return configured >= 0.0 ? configured
                             : std::sqrt(2.0 * std::sqrt(norm2(gravity)) * 1e-6 * min_diameter);
  }

  bool on() const { return speed_ > 0.0; }
  double speed() const { return speed_; }
  // How many sleep now; while none does, the engine's paths test nothing else.
  std::uint32_t count() const { return count_; }
  bool asleep(std::uint32_t i) const { return !asleep_.empty() && asleep_[i] != 0; }
  // Whether some of the listed particles sleeps (one OR per candidate, no branch).
  bool any_of(const std::uint32_t* ids, std::uint32_t n) const {
    const std::uint8_t* asleep = asleep_.data();
    std::uint8_t any = 0;
    for (std::uint32_t k = 0; k < n; ++k) any |= asleep[ids[k]];
    return any != 0;
  }
  void fall_asleep(std::uint32_t i) {
    asleep_[i] = 1;
    ++count_;
  }
  void wake(std::uint32_t i) {
    asleep_[i] = 0;
    --count_;
  }

  // Whether a contact of normal n (unit, from the support to the particle) holds the particle
  // up against gravity: n within 60 degrees of straight up. Steeper contacts are side contacts.
  bool holds_up(const Vec<D>& n) const {
    return dot(gravity_, n) < -0.5 * std::sqrt(norm2(gravity_));
  }
  // How close to a support a particle of this radius must be to rest on it: a few sleep-speed
  // bounce heights.
  double support_distance(double radius) const {
    return 4.0 * speed_ * speed_ / std::sqrt(norm2(gravity_)) + 1e-12 * radius;
  }
  // Whether a particle that moved this far since its previous event, meeting something again,
  // is wedged: between resting things with no clearance (a gap of exactly its size, to
  // round-off) its contacts would follow each other without end.
  static bool wedged(double moved, double radius) { return moved <= 2e-9 * radius; }
  // Whether an awake particle meeting a sleeper at normal speed gn (< 0: approaching) wakes
  // it for an ordinary collision; a gentler hit treats the sleeper as an immovable support.
  bool hit_wakes(double gn) const { return -gn >= speed_; }

  // The rule after a contact with a support of velocity `support_velocity` (normal n): v is
  // the particle's velocity after the contact, `again` whether it is wedged, supported() whether
  // something it touches holds it up (asked only when needed: it gathers the neighbourhood).
  //  - wedged on a still support: it stops and sleeps;
  //  - slow and held up (by this contact, or from the side by a support underneath): it sleeps;
  //  - pressed into the contact by gravity but still sliding, on a slope too steep to rest on,
  //    or carried by a moving support: it leaves with half the sleep speed along n, so that the
  //    next contact is a finite flight away (half: a particle rattling in a pocket then lands
  //    slower than the sleep speed and sleeps).
  template <class Supported>
  Settle settle(const Vec<D>& v, const Vec<D>& n, const Vec<D>& support_velocity, bool again,
                Supported&& supported) const {
    if (speed_ <= 0.0) return {};
    const bool still = norm2(support_velocity) == 0.0;
    if (again && still) return {Settle::kSleep};
    const Vec<D> rel = v - support_velocity;
    if (still && norm2(rel) < speed_ * speed_ && (holds_up(n) || supported()))
      return {Settle::kSleep};
    if (!(dot(gravity_, n) < 0.0)) return {};  // gravity does not press it into this contact
    const double vn = dot(rel, n);
    if (vn >= speed_) return {};  // a real bounce
    return {Settle::kLift, 0.5 * speed_ - vn};
  }

  // Restart data: the flags of the state's particles (`stored`, in the caller's numbering,
  // empty: none asleep), for the engine's particles k whose caller's number is id[k].
  template <class Ids>
  void restore(const std::vector<std::uint8_t>& stored, const Ids& id) {
    if (stored.size() != asleep_.size()) return;
    count_ = 0;  // the flags are replaced, not added to
    for (std::uint32_t k = 0; k < asleep_.size(); ++k) {
      asleep_[k] = stored[id[k]] != 0 ? 1 : 0;
      count_ += asleep_[k];
    }
  }
  // The flag to export for particle k (the state's `asleep` is written only while some sleep).
  std::uint8_t flag(std::uint32_t k) const { return asleep_[k]; }
  void permute(const std::vector<std::uint32_t>& order, std::vector<bool>& done) {
    if (!asleep_.empty()) permute_in_place(asleep_, order, done);
  }
  double bytes_per_particle() const { return asleep_.empty() ? 0.0 : 1.0; }
  // The count matches the flags, and a sleeper is at rest: velocity(k) is the velocity its
  // record holds; fail(message) otherwise.
  template <class Velocity, class Fail, class Name>
  void validate(Velocity&& velocity, Fail&& fail, Name&& name) const {
    std::uint32_t n = 0;
    for (std::uint32_t k = 0; k < asleep_.size(); ++k) {
      if (asleep_[k] == 0) continue;
      ++n;
      if (norm2(velocity(k)) != 0.0) fail("sleeping particle " + name(k) + " moves");
    }
    if (n != count_) fail("the count of sleepers is not the number of sleeping particles");
  }

 private:
  HugeVector<std::uint8_t> asleep_;  // per particle, 1 asleep; empty unless on()
  std::uint32_t count_ = 0;
  double speed_ = 0.0;
  Vec<D> gravity_{};
};

}  // namespace kairos
