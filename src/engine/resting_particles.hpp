// Resting particles under gravity: who sleeps, and the rules that put particles to sleep after
// a contact with a static support (a fixed wall or a sleeper). A component of the event engine
// with its own state (one byte per particle, allocated only when sleeping is on), its part of
// the restart file (ParticleSystem::asleep) and of the renumbering; the engine applies what
// the rules decide. docs/architecture.md, "Resting particles", says why they are needed: a
// bouncing ball with e < 1 bounces infinitely often in finite time, and a pile is full of such
// cascades; docs/physics.md#sleeping gives the rules.
//
// Fixed grains (docs/physics.md#fixed-grains) are sleepers that never wake: flag 2 instead of 1.
// The engine meets them as it meets any sleeper (they do not move and feel no gravity), but a
// hit never wakes them, so a collision with one is always the contact with an immovable
// support. They need the flags without the sleeping rules: on() is false when only they rest.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
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
  // Sleeping on, below `speed`, for n particles under gravity g (speed > 0; 0: the flags only,
  // for fixed grains, and no particle falls asleep).
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
  // A fixed grain: asleep for good (a hit never wakes it).
  bool fixed(std::uint32_t i) const { return !asleep_.empty() && asleep_[i] == kFixed; }
  std::uint32_t fixed_count() const { return fixed_; }
  // Particles asleep now that may wake (the fixed grains aside).
  std::uint32_t sleepers() const { return count_ - fixed_; }
  // Makes particle i a fixed grain (once, at the start; it must be at rest).
  void fix(std::uint32_t i) {
    if (asleep_[i] == kFixed) return;
    if (asleep_[i] == 0) ++count_;
    asleep_[i] = kFixed;
    ++fixed_;
  }
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
    if (asleep_[i] == kFixed) throw std::logic_error("RestingParticles::wake: a fixed grain");
    asleep_[i] = 0;
    --count_;
  }

  // Whether a contact of normal n (unit, from the support to the particle) holds the particle
  // up against gravity: n within 60 degrees of straight up. Steeper contacts are side contacts.
  bool holds_up(const Vec<D>& n) const {
    return dot(gravity_, n) < -0.5 * std::sqrt(norm2(gravity_));
  }
  // Whether supports of these unit normals (each from a support to the particle) hold the
  // particle up together: one of them holds it up alone, or straight up lies in the cone they
  // span (up = sum of a_k n_k with every a_k >= 0: two normals on either side of the vertical
  // in 2D, three around it in 3D), as two steep supports of a V hold a grain that neither holds
  // alone (in 3D also two, when the vertical lies in their plane: a level trough).
  bool hold_up(const Vec<D>* normals, int count) const {
    for (int k = 0; k < count; ++k)
      if (holds_up(normals[k])) return true;
    const Vec<D> up = (-1.0 / std::sqrt(norm2(gravity_))) * gravity_;
    if constexpr (D == 2) {
      for (int a = 0; a < count; ++a)
        for (int b = a + 1; b < count; ++b)
          if (in_cone(up, normals[a], normals[b])) return true;
    } else {
      for (int a = 0; a < count; ++a)
        for (int b = a + 1; b < count; ++b)
          if (in_level_trough(up, normals[a], normals[b])) return true;
      for (int a = 0; a < count; ++a)
        for (int b = a + 1; b < count; ++b)
          for (int c = b + 1; c < count; ++c)
            if (in_cone(up, normals[a], normals[b], normals[c])) return true;
    }
    return false;
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
  // empty: none asleep), for the engine's particles k whose caller's number is id[k]. Fixed
  // grains stay fixed (they are the model's, marked by fix(), not the state's).
  template <class Ids>
  void restore(const std::vector<std::uint8_t>& stored, const Ids& id) {
    if (stored.size() != asleep_.size()) return;
    count_ = fixed_;  // the flags are replaced, not added to
    for (std::uint32_t k = 0; k < asleep_.size(); ++k) {
      if (asleep_[k] == kFixed) continue;
      asleep_[k] = stored[id[k]] != 0 ? 1 : 0;
      count_ += asleep_[k];
    }
  }
  // The flag to export for particle k, 1 asleep or fixed (the state's `asleep` is written only
  // while some particle rests).
  std::uint8_t flag(std::uint32_t k) const { return asleep_[k] != 0 ? 1 : 0; }
  void permute(const std::vector<std::uint32_t>& order, std::vector<bool>& done) {
    if (!asleep_.empty()) permute_in_place(asleep_, order, done);
  }
  double bytes_per_particle() const { return asleep_.empty() ? 0.0 : 1.0; }
  // The count matches the flags, and a sleeper is at rest: velocity(k) is the velocity its
  // record holds; fail(message) otherwise.
  template <class Velocity, class Fail, class Name>
  void validate(Velocity&& velocity, Fail&& fail, Name&& name) const {
    std::uint32_t n = 0, fixed = 0;
    for (std::uint32_t k = 0; k < asleep_.size(); ++k) {
      if (asleep_[k] == 0) continue;
      ++n;
      if (asleep_[k] == kFixed) ++fixed;
      if (norm2(velocity(k)) != 0.0)
        fail((asleep_[k] == kFixed ? "fixed particle " : "sleeping particle ") + name(k) +
             " moves");
    }
    if (n != count_) fail("the count of sleepers is not the number of sleeping particles");
    if (fixed != fixed_) fail("the count of fixed grains is not the number of fixed particles");
  }

 private:
  // Whether u = a n1 + b n2 with a, b >= 0 (2D; n1, n2 not parallel).
  static bool in_cone(const Vec<2>& u, const Vec<2>& n1, const Vec<2>& n2) {
    const double det = n1[0] * n2[1] - n1[1] * n2[0];
    if (std::abs(det) < 1e-12) return false;
    const double a = (u[0] * n2[1] - u[1] * n2[0]) / det;
    const double b = (n1[0] * u[1] - n1[1] * u[0]) / det;
    return a >= 0.0 && b >= 0.0;
  }
  // Whether u = a n1 + b n2 + c n3 with a, b, c >= 0 (3D; the normals not coplanar), by
  // Cramer's rule with triple products.
  static bool in_cone(const Vec<3>& u, const Vec<3>& n1, const Vec<3>& n2, const Vec<3>& n3) {
    const auto triple = [](const Vec<3>& x, const Vec<3>& y, const Vec<3>& z) {
      return x[0] * (y[1] * z[2] - y[2] * z[1]) - x[1] * (y[0] * z[2] - y[2] * z[0]) +
             x[2] * (y[0] * z[1] - y[1] * z[0]);
    };
    const double det = triple(n1, n2, n3);
    if (std::abs(det) < 1e-12) return false;
    return triple(u, n2, n3) / det >= 0.0 && triple(n1, u, n3) / det >= 0.0 &&
           triple(n1, n2, u) / det >= 0.0;
  }

  // Two supports hold a sphere (3D) when up lies in the plane of their normals, to round-off
  // (a level trough: along it the sphere has no slope to roll down), and between them.
  static bool in_level_trough(const Vec<3>& u, const Vec<3>& n1, const Vec<3>& n2) {
    const Vec<3> axis{n1[1] * n2[2] - n1[2] * n2[1], n1[2] * n2[0] - n1[0] * n2[2],
                      n1[0] * n2[1] - n1[1] * n2[0]};
    const double length2 = norm2(axis);
    if (length2 < 1e-24) return false;
    const double off = dot(u, axis);
    if (off * off > 1e-18 * length2) return false;  // a slope along the trough
    const double g12 = dot(n1, n2);
    const double det = 1.0 - g12 * g12;  // unit normals
    const double a = (dot(u, n1) - g12 * dot(u, n2)) / det;
    const double b = (dot(u, n2) - g12 * dot(u, n1)) / det;
    return a >= 0.0 && b >= 0.0;
  }

  static constexpr std::uint8_t kFixed = 2;
  HugeVector<std::uint8_t> asleep_;  // per particle, 1 asleep, kFixed fixed; empty unless needed
  std::uint32_t count_ = 0;          // asleep or fixed
  std::uint32_t fixed_ = 0;
  double speed_ = 0.0;
  Vec<D> gravity_{};
};

}  // namespace kairos
