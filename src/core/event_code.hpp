// What a particle's pending event is, in 32 bits (EventSlot::partner): a typed code with named
// constructors and predicates, so that a new kind of event is a change in this one file.
//
// The bits are those restart files store (EventSlot::partner, format 7), so they are fixed:
//
//   [0, kKeptBase)                       a collision with that particle (its index)
//   [kKeptBase, kNoneKept)               a cell crossing that keeps the contact with particle
//                                        bits - kKeptBase, found beyond the crossing by the
//                                        prediction that scheduled it (incremental crossings)
//   [kFirstSurface, kNoneKept)          a contact with boundary surface 2D + bits - kFirstSurface
//                                        (the surfaces after the box faces: planes, ...)
//   kNoneKept                            a cell crossing whose prediction found no contact at all
//   kRelease                             the release of the soft contact the particle is in
//   [kFirstWall, kFirstWall + 2D)        a contact with the wall on box face bits - kFirstWall
//   kNoPartner (all bits set)            a cell crossing that kept nothing: it scans every
//                                        neighbour cell
//
// Particle indices therefore stay below kFirstSurface - kKeptBase (kMaxParticles), so the kept
// range holds any index. The surfaces after the box faces took their codes from the top of the
// kept range, which no particle index reached, so the codes of format-7 files kept their meaning.
#pragma once

#include <cstdint>

#include "core/particle_system.hpp"

namespace kairos {

template <int D>
class EventCode {
 public:
  static constexpr std::uint32_t kNoPartner = EventSlot::kNoPartner;
  static constexpr std::uint32_t kKeptBase = EventSlot::kKeptBase;
  // Room for this many boundary surfaces: the 2D box faces (the first component of the
  // registry, model/boundaries.hpp) and kWallCodes - 2D more.
  static constexpr int kWallCodes = 4096;
  static constexpr std::uint32_t kFirstWall = kNoPartner - 2 * D;
  static constexpr std::uint32_t kRelease = kFirstWall - 1;
  static constexpr std::uint32_t kNoneKept = kRelease - 1;
  static constexpr std::uint32_t kFirstSurface = kNoneKept - (kWallCodes - 2 * D);
  // The most particles a code can name as a kept partner.
  static constexpr std::uint32_t kMaxParticles = kFirstSurface - kKeptBase;
  // Codes from here on are not particles.
  static constexpr std::uint32_t kFirstCode = kKeptBase;

  constexpr EventCode() = default;
  static constexpr EventCode collision(std::uint32_t partner) { return EventCode(partner); }
  // A crossing after which every neighbour cell is scanned.
  static constexpr EventCode crossing() { return EventCode(kNoPartner); }
  // A crossing that keeps the soonest contact found beyond it, with particle p.
  static constexpr EventCode crossing_keeping(std::uint32_t p) { return EventCode(kKeptBase + p); }
  // A crossing whose prediction found no contact at all.
  static constexpr EventCode crossing_keeping_none() { return EventCode(kNoneKept); }
  // A contact with boundary surface s (0 <= s < kWallCodes; the box faces are 0 .. 2D - 1).
  static constexpr EventCode wall(int s) {
    return EventCode(s < 2 * D ? kFirstWall + static_cast<std::uint32_t>(s)
                               : kFirstSurface + static_cast<std::uint32_t>(s - 2 * D));
  }
  static constexpr EventCode release() { return EventCode(kRelease); }
  // The stored form (restart files, EventSlot::partner).
  static constexpr EventCode from_bits(std::uint32_t bits) { return EventCode(bits); }
  constexpr std::uint32_t bits() const { return bits_; }

  constexpr bool is_collision() const { return bits_ < kFirstCode; }
  constexpr std::uint32_t partner() const { return bits_; }  // is_collision() only
  constexpr bool is_crossing() const {
    return bits_ == kNoPartner || bits_ == kNoneKept ||
           (bits_ >= kKeptBase && bits_ < kFirstSurface);
  }
  // A crossing that kept the contact with a particle (kept_partner()).
  constexpr bool keeps_contact() const { return bits_ >= kKeptBase && bits_ < kFirstSurface; }
  constexpr std::uint32_t kept_partner() const { return bits_ - kKeptBase; }
  constexpr bool keeps_nothing() const { return bits_ == kNoneKept; }
  // A crossing that scans every neighbour cell next.
  constexpr bool is_full_scan_crossing() const { return bits_ == kNoPartner; }
  constexpr bool is_wall() const {
    return (bits_ >= kFirstWall && bits_ < kNoPartner) ||
           (bits_ >= kFirstSurface && bits_ < kNoneKept);
  }
  // The surface of a wall code (is_wall()): its number in the boundary registry.
  constexpr int wall_face() const {
    return bits_ >= kFirstWall ? static_cast<int>(bits_ - kFirstWall)
                               : 2 * D + static_cast<int>(bits_ - kFirstSurface);
  }
  constexpr bool is_release() const { return bits_ == kRelease; }

  // Whether stored bits make sense for n particles (a collision or kept partner in range).
  static constexpr bool valid_bits(std::uint32_t bits, std::uint32_t n) {
    const EventCode c(bits);
    if (c.is_collision()) return bits < n;
    if (c.keeps_contact()) return c.kept_partner() < n;
    return true;
  }
  // The same code with its particle (partner or kept partner) renumbered by f.
  template <class Renumber>
  constexpr EventCode renumbered(Renumber&& f) const {
    if (is_collision()) return collision(f(bits_));
    if (keeps_contact()) return crossing_keeping(f(kept_partner()));
    return *this;
  }

  constexpr bool operator==(const EventCode&) const = default;

 private:
  constexpr explicit EventCode(std::uint32_t bits) : bits_(bits) {}
  std::uint32_t bits_ = kNoPartner;
};

// A particle's pending event (its time lives in the queue): the code, and the partner's (or
// the kept partner's) collision counter when the event was predicted, which tells a stale
// prediction from a valid one.
template <int D>
struct PendingEvent {
  EventCode<D> code;
  std::uint32_t partner_count = 0;
};
static_assert(sizeof(PendingEvent<3>) == 8, "a pending event is 8 bytes per particle");

}  // namespace kairos
