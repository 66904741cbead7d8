// Outlets ([boundary.outlet]): a boundary component (docs/extending.md, "Adding a boundary
// geometry") whose surface particles pass through instead of meeting. An outlet is the plane
// n . x = c with n pointing to the side the particles come from; a particle whose centre
// crosses it (leaving that side) is taken out and put back at once at a random free place of
// the insertion region, an axis-aligned box, with a set velocity and no spin: the recirculating
// silo of granular-flow studies, where the count through the outlet per unit time is the
// discharge rate (docs/physics.md#outlets-and-strips).
//
// It is a surface of the registry so that the crossing is found as any wall event is (its own
// event time, its own filter by cells, the brute-force check of validate()), but it is no
// contact: passes(s) says so, and the engine, not the component, finds the free place among the
// particles (EventEngine::pass_outlet). The places are drawn from a counter-based generator
// (the seed, the number of passes so far, the attempt): a restart needs only the count, which
// the counters carry (EventCounters::outlet_passes).
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "core/vec.hpp"
#include "dynamics/collision_time.hpp"
#include "interactions/granular_contact.hpp"
#include "scheduler/cell_grid.hpp"

namespace kairos {

template <int D>
struct Outlet {
  Vec<D> normal{};      // unit, towards the side the particles come from
  double offset = 0.0;  // the plane n . x = offset
  // Where a particle that passed is put back: a free place drawn uniformly in the box
  // [insert_lower, insert_upper] (its centre), moving at insert_velocity.
  Vec<D> insert_lower{}, insert_upper{};
  Vec<D> insert_velocity{};
  std::uint64_t seed = 1;
};

template <int D>
class Outlets {
 public:
  Outlets() = default;
  Outlets(std::vector<Outlet<D>> outlets, const Vec<D>& gravity)
      : outlets_(std::move(outlets)), gravity_(gravity) {}

  // The boundary interface (model/boundaries.hpp): surface s is outlet s.
  bool any() const { return !outlets_.empty(); }
  int surfaces() const { return static_cast<int>(outlets_.size()); }
  bool is_surface(int /*s*/) const { return true; }
  const Outlet<D>& outlet(int s) const { return outlets_[static_cast<std::size_t>(s)]; }
  std::string name(int /*s*/) const { return "boundary.outlet"; }
  // Particles pass through: no contact, no support for sleepers, no overlap.
  bool passes(int /*s*/) const { return true; }
  const ContactModel& contact(int /*s*/) const { return kNoContact; }
  double approach_speed(int /*s*/) const { return 0.0; }
  // The centre's distance from the plane, positive on the particles' side.
  double gap(int s, const Vec<D>& x, double /*t*/) const {
    return dot(outlet(s).normal, x) - outlet(s).offset;
  }
  Vec<D> normal(int s, const Vec<D>& /*x*/, double /*t*/) const { return outlet(s).normal; }
  Vec<D> velocity(int /*s*/, const Vec<D>& /*x*/, double /*t*/) const { return Vec<D>{}; }
  bool holds_still(int /*s*/) const { return true; }
  bool surface_moves(int /*s*/) const { return false; }
  bool accelerates(int /*s*/) const { return false; }
  bool flat(int /*s*/) const { return true; }

  // When the centre (not the particle's surface: the radius is not used) crosses the plane.
  double event_time(int s, const Vec<D>& x, const Vec<D>& v, double radius, double t,
                    double horizon) const;
  // Whether a particle in `cell` can cross the plane before it leaves the cell.
  bool reaches(int s, CellCode cell, const CellGrid<D>& grid) const;
  // Never called: the engine handles a passing surface itself.
  ContactResult<D> resolve(int s, const Vec<D>& x, double t, double mass, double radius,
                           double inertia_factor, bool force_elastic, Vec<D>& v, Spin<D>& w) const;
  // Throws InputError naming a particle whose centre starts beyond the outlet.
  void check_start(const Vec<D>& x, double radius, double t, std::uint64_t id) const;
  void prepare(const CellGrid<D>& /*grid*/, double /*rmax*/, double /*particle_volume*/,
               bool /*uniform*/) {}
  double squeeze_time() const { return kNever; }
  [[noreturn]] void throw_squeezed(double t, double dmax, bool uniform) const;

  // The attempt-th candidate place for the pass numbered `pass` (0, 1, ... over the run) of
  // outlet s: uniform in its insertion region, the same for the same three numbers.
  Vec<D> insertion_point(int s, std::uint64_t pass, std::uint32_t attempt) const;

 private:
  static inline const ContactModel kNoContact{};
  std::vector<Outlet<D>> outlets_;
  Vec<D> gravity_{};
};

}  // namespace kairos
