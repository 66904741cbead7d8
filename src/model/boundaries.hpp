// Every boundary component of a run, behind one interface: the registry of boundary geometries
// (docs/extending.md, "A boundary geometry").
//
// A component owns some contact surfaces (FaceWalls: the walls on the box's faces). Surfaces
// are numbered across the components in the order of the registry below, and a wall event's
// code names its surface (EventCode::wall). Each component provides, for its own surfaces s
// (0 .. surfaces() - 1), what the concept BoundaryComponent below states (and the registry
// checks at compile time):
//
//   bool any() const;                           it has a surface in this run
//   int surfaces() const;                       how many it owns (some may be absent: is_surface)
//   bool is_surface(int s) const;               surface s exists in this run
//   double event_time(int s, x, v, radius, t, horizon) const;
//                                               when a particle (at x, velocity v at time t,
//                                               under the uniform field) first touches it
//   bool reaches(int s, cell, grid) const;      a particle in `cell` can touch surface s before
//                                               it leaves the cell (the component's own filter
//                                               by cells; false for an absent surface)
//   double gap(int s, x, t) const;              centre to surface, positive inside
//   Vec<D> normal(int s, x, t) const;           unit normal into the domain at x's contact point
//   Vec<D> velocity(int s, x, t) const;         the surface's velocity there
//   bool holds_still(int s) const;              never moves (a support resting particles sleep on)
//   bool surface_moves(int s) const;            the surface itself moves through space (a piston,
//                                               a vibration; not a plane sliding in itself)
//   bool accelerates(int s) const;              its velocity changes (a vibration)
//   bool flat(int s) const;                     one normal over its whole surface (a plane)
//   std::string name(int s) const;              how messages name it ("z-", "boundary.plane[0]")
//   const ContactModel& contact(int s) const;   its contact law
//   double approach_speed(int s) const;         the speed it moves into the domain at (a
//                                               piston; its vibration aside)
//   ContactResult<D> resolve(int s, x, t, mass, radius, inertia_factor, force_elastic, v, w) const;
//                                               the contact's response and its energy split
//   void check_start(x, radius, t, id) const;   throws InputError naming particle and surface
//   double squeeze_time() const;                when moving surfaces leave no room (kNever)
//   [[noreturn]] void throw_squeezed(t, dmax, uniform) const;
//                                               the InputError of a run that reached it
//   void prepare(grid, rmax, particle_volume, uniform);
//                                               set-up once the cells and particles are known
//                                               (which cells each surface reaches, the squeeze)
//
// is made from the run's model (Environment) in the constructor below, and has no per-particle
// state. A surface with a motion of its own (a wall with mass, boundaries/wall_body.hpp, which
// FaceWalls provides) is a component that also has the members of MovingBoundary below; the
// set dispatches them, and the engine meets such a surface only through them (its contacts
// push it, its events carry the version of its motion, its plane's change of cell layer is an
// event, its motion travels in ParticleSystem::wall_motion). Dispatch is static (the tuple
// below): no virtual call. Surface codes: EventCode::wall has room for
// EventCode<D>::kWallCodes surfaces, the box faces first.
#pragma once

#include <algorithm>
#include <concepts>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "boundaries/cylinder_walls.hpp"
#include "boundaries/face_walls.hpp"
#include "boundaries/outlets.hpp"
#include "boundaries/plane_walls.hpp"
#include "boundaries/wall_body.hpp"
#include "core/error.hpp"
#include "model/environment.hpp"
#include "scheduler/cell_grid.hpp"

namespace kairos {

// The boundary interface of the header comment, stated once: a type the registry (or a test's
// BoundarySet) accepts.
template <class C, int D>
concept BoundaryComponent = requires(const C& c, C& setup, int s, const Vec<D>& x, double value,
                                     bool flag, CellCode cell, const CellGrid<D>& grid, Vec<D>& v,
                                     Spin<D>& w, std::uint64_t id) {
  { c.any() } -> std::convertible_to<bool>;
  { c.surfaces() } -> std::convertible_to<int>;
  { c.is_surface(s) } -> std::convertible_to<bool>;
  { c.event_time(s, x, x, value, value, value) } -> std::convertible_to<double>;
  { c.reaches(s, cell, grid) } -> std::convertible_to<bool>;
  { c.gap(s, x, value) } -> std::convertible_to<double>;
  { c.normal(s, x, value) } -> std::convertible_to<Vec<D>>;
  { c.velocity(s, x, value) } -> std::convertible_to<Vec<D>>;
  { c.holds_still(s) } -> std::convertible_to<bool>;
  { c.surface_moves(s) } -> std::convertible_to<bool>;
  { c.accelerates(s) } -> std::convertible_to<bool>;
  { c.flat(s) } -> std::convertible_to<bool>;
  { c.name(s) } -> std::convertible_to<std::string>;
  { c.contact(s) } -> std::same_as<const ContactModel&>;
  { c.approach_speed(s) } -> std::convertible_to<double>;
  { c.resolve(s, x, value, value, value, value, flag, v, w) } -> std::same_as<ContactResult<D>>;
  c.check_start(x, value, value, id);
  { c.squeeze_time() } -> std::convertible_to<double>;
  c.throw_squeezed(value, value, flag);
  setup.prepare(grid, value, value, flag);
};

// The members of a component whose surfaces may move by themselves (walls with mass), for its
// own surfaces s:
//
//   bool any_massive() const;                   some surface has a motion of its own
//   bool massive(int s) const;                  surface s has one
//   std::uint32_t event_version(int s) const;   the version a wall event predicted now carries
//                                               (0 for a surface without mass); stale when the
//                                               motion has changed since
//   void push(int s, t, impulse_on_particle);   a contact's impulse moves surface s
//   void for_each_disturbed(s, f) const;        f(surface) for each surface a push on s may
//                                               have brought nearer the particles later on
//   double next_layer_change() const;           when a surface next enters another layer of
//                                               cells (kNever: never)
//   int change_layer(double t);                 that change made; returns the surface (-1:
//                                               none changed, its search was renewed)
//   void for_each_band_cell(s, grid, f) const;  f(cell index) for every cell holding particles
//                                               that can touch s while it stays in its layer
//   double energy(int s, double t) const;       its mechanical energy
//   std::vector<WallMotion> motion() const;     the motions for a restart (face = surface)
//   void restore(motion, t);                    set from a state at time t
//   std::vector<WallReading> readings(t) const; what outputs show of each
template <class C, int D>
concept MovingBoundary = requires(const C& c, C& moved, int s, double t, const Vec<D>& impulse,
                                  const CellGrid<D>& grid, const std::vector<WallMotion>& motion,
                                  void (*visit)(std::uint32_t)) {
  { c.any_massive() } -> std::convertible_to<bool>;
  { c.massive(s) } -> std::convertible_to<bool>;
  { c.event_version(s) } -> std::convertible_to<std::uint32_t>;
  moved.push(s, t, impulse);
  c.for_each_disturbed(s, visit);
  { c.next_layer_change() } -> std::convertible_to<double>;
  { moved.change_layer(t) } -> std::convertible_to<int>;
  c.for_each_band_cell(s, grid, visit);
  { c.energy(s, t) } -> std::convertible_to<double>;
  { c.motion() } -> std::same_as<std::vector<WallMotion>>;
  moved.restore(motion, t);
  { c.readings(t) } -> std::same_as<std::vector<WallReading>>;
};

// Surfaces over a set of components, numbered in the order the components are given. The run's
// registry is Boundaries below; a test can put other sets together.
template <int D, class... C>
requires(BoundaryComponent<C, D>&&...) class BoundarySet {
 public:
  using Components = std::tuple<C...>;

  BoundarySet() = default;
  explicit BoundarySet(C... components) : components_(std::move(components)...) {
    for_each([&](const auto& c) {
      any_ = any_ || c.any();
      surfaces_ += c.surfaces();
    });
  }

  bool any() const { return any_; }
  int surfaces() const { return surfaces_; }
  template <class Component>
  const Component& get() const {
    return std::get<Component>(components_);
  }
  template <class Component>
  Component& get() {
    return std::get<Component>(components_);
  }

  // f(component, first surface) for each component, in registry order.
  template <class F>
  void for_each(F&& f) const {
    std::apply([&](const auto&... c) { (f(c), ...); }, components_);
  }
  template <class F>
  void for_each(F&& f) {
    std::apply([&](auto&... c) { (f(c), ...); }, components_);
  }

  // g(component, local surface) for surface s; returns what g returns.
  template <class G>
  decltype(auto) at(int s, G&& g) const {
    return dispatch<0>(s, std::forward<G>(g));
  }

  bool is_surface(int s) const {
    return at(s, [](const auto& c, int k) { return c.is_surface(k); });
  }
  // (radius_speed: a growing radius, as in next_contact; flat surfaces only.)
  double event_time(int s, const Vec<D>& x, const Vec<D>& v, double radius, double t,
                    double horizon, double radius_speed = 0.0) const {
    return at(s, [&](const auto& c, int k) {
      return radius_speed == 0.0
                 ? c.event_time(k, x, v, radius, t, horizon)
                 : c.event_time(k, x, v - radius_speed * c.normal(k, x, t), radius, t, horizon);
    });
  }
  double gap(int s, const Vec<D>& x, double t) const {
    return at(s, [&](const auto& c, int k) { return c.gap(k, x, t); });
  }
  Vec<D> normal(int s, const Vec<D>& x, double t) const {
    return at(s, [&](const auto& c, int k) { return c.normal(k, x, t); });
  }
  Vec<D> velocity(int s, const Vec<D>& x, double t) const {
    return at(s, [&](const auto& c, int k) { return c.velocity(k, x, t); });
  }
  bool holds_still(int s) const {
    return at(s, [](const auto& c, int k) { return c.holds_still(k); });
  }
  bool surface_moves(int s) const {
    return at(s, [](const auto& c, int k) { return c.surface_moves(k); });
  }
  bool accelerates(int s) const {
    return at(s, [](const auto& c, int k) { return c.accelerates(k); });
  }
  bool flat(int s) const {
    return at(s, [](const auto& c, int k) { return c.flat(k); });
  }
  std::string name(int s) const {
    return at(s, [](const auto& c, int k) { return c.name(k); });
  }
  const ContactModel& contact(int s) const {
    return at(s, [](const auto& c, int k) -> const ContactModel& { return c.contact(k); });
  }
  double approach_speed(int s) const {
    return at(s, [](const auto& c, int k) { return c.approach_speed(k); });
  }
  ContactResult<D> resolve(int s, const Vec<D>& x, double t, double mass, double radius,
                           double inertia_factor, bool force_elastic, Vec<D>& v, Spin<D>& w) const {
    return at(s, [&](const auto& c, int k) {
      return c.resolve(k, x, t, mass, radius, inertia_factor, force_elastic, v, w);
    });
  }
  // Whether particles pass through surface s (an outlet: no contact, no support, no overlap);
  // a component says so with a member passes(s), which the others lack.
  bool passes(int s) const {
    return at(s, [](const auto& c, int k) -> bool {
      if constexpr (requires { c.passes(k); }) return c.passes(k);
      return false;
    });
  }
  // Whether some surface is one particles pass through.
  bool any_passes() const {
    bool any = false;
    for (int s = 0; s < surfaces_; ++s) any = any || (is_surface(s) && passes(s));
    return any;
  }
  // Whether some surface moves (a sleeper predicts no events of its own and would not see it
  // coming).
  bool any_surface_moves() const {
    bool moves = false;
    for (int s = 0; s < surfaces_; ++s) moves = moves || (is_surface(s) && surface_moves(s));
    return moves;
  }
  // Whether some surface is not still (it slides, moves or vibrates: it can do work).
  bool any_surface_drives() const {
    bool drives = false;
    for (int s = 0; s < surfaces_; ++s) drives = drives || (is_surface(s) && !holds_still(s));
    return drives;
  }
  // The soonest contact of a particle in `cell` with any surface but `skip` (a soft contact's
  // wall while the particle is frozen against it; -1: none) from time t before t + horizon:
  // (relative time, surface), surface -1 if none. A radius growing at `radius_speed` (growing
  // particles; flat surfaces only) brings the particle's surface nearer a plane as a velocity
  // radius_speed towards it would: the contact of a particle of the radius at t moving at
  // v - radius_speed n.
  std::pair<double, int> next_contact(const Vec<D>& x, const Vec<D>& v, double radius,
                                      CellCode cell, const CellGrid<D>& grid, double t,
                                      double horizon, int skip = -1,
                                      double radius_speed = 0.0) const {
    std::pair<double, int> best{horizon, -1};
    int first = 0;
    for_each([&](const auto& c) {
      for (int k = 0; k < c.surfaces(); ++k) {
        if (first + k == skip || !c.reaches(k, cell, grid)) continue;
        const double when =
            radius_speed == 0.0
                ? c.event_time(k, x, v, radius, t, best.first)
                : c.event_time(k, x, v - radius_speed * c.normal(k, x, t), radius, t, best.first);
        if (when < best.first) best = {when, first + k};
      }
      first += c.surfaces();
    });
    return best;
  }
  // Whether a particle overlaps some surface other than `skip` (-1: none skipped): its centre
  // nearer than its radius, from the components' gaps (one rule for every geometry).
  bool overlaps(const Vec<D>& x, double radius, double t, int skip = -1) const {
    bool any = false;
    int first = 0;
    for_each([&](const auto& c) {
      for (int k = 0; k < c.surfaces() && !any; ++k) {
        if constexpr (requires { c.passes(k); })
          if (c.passes(k)) continue;
        any = first + k != skip && c.is_surface(k) && c.gap(k, x, t) < radius;
      }
      first += c.surfaces();
    });
    return any;
  }
  void check_start(const Vec<D>& x, double radius, double t, std::uint64_t id) const {
    for_each([&](const auto& c) { c.check_start(x, radius, t, id); });
  }
  double squeeze_time() const {
    double t = kNever;
    for_each([&](const auto& c) { t = std::min(t, c.squeeze_time()); });
    return t;
  }
  void prepare(const CellGrid<D>& grid, double rmax, double particle_volume, bool uniform) {
    for_each([&](auto& c) { c.prepare(grid, rmax, particle_volume, uniform); });
  }
  bool reaches(int s, CellCode cell, const CellGrid<D>& grid) const {
    return at(s, [&](const auto& c, int k) { return c.reaches(k, cell, grid); });
  }

  // Surfaces with a motion of their own (MovingBoundary; none in a component without them).
  bool any_massive() const {
    bool any = false;
    for_each([&](const auto& c) {
      if constexpr (MovingBoundary<std::remove_cvref_t<decltype(c)>, D>)
        any = any || c.any_massive();
    });
    return any;
  }
  bool massive(int s) const {
    return at(s, [](const auto& c, int k) -> bool {
      if constexpr (MovingBoundary<std::remove_cvref_t<decltype(c)>, D>) return c.massive(k);
      return false;
    });
  }
  std::uint32_t event_version(int s) const {
    return at(s, [](const auto& c, int k) -> std::uint32_t {
      if constexpr (MovingBoundary<std::remove_cvref_t<decltype(c)>, D>) return c.event_version(k);
      return 0u;
    });
  }
  // (Only a surface with mass moves: a push on another is ignored.)
  void push(int s, double t, const Vec<D>& impulse_on_particle) {
    at_moving(s, [&](auto& c, int k) {
      if (c.massive(k)) c.push(k, t, impulse_on_particle);
    });
  }
  template <class F>
  void for_each_disturbed(int s, F&& f) const {
    int first = 0;
    for_each([&](const auto& c) {
      if constexpr (MovingBoundary<std::remove_cvref_t<decltype(c)>, D>) {
        if (s >= first && s < first + c.surfaces())
          c.for_each_disturbed(s - first, [&](int k) { f(first + k); });
      }
      first += c.surfaces();
    });
  }
  double next_layer_change() const {
    double when = kNever;
    for_each([&](const auto& c) {
      if constexpr (MovingBoundary<std::remove_cvref_t<decltype(c)>, D>)
        when = std::min(when, c.next_layer_change());
    });
    return when;
  }
  // The soonest change of layer made (at its time t); returns its surface (-1: none changed).
  int change_layer(double t) {
    const double when = next_layer_change();
    if (!(when < kNever)) throw std::logic_error("Boundaries::change_layer: no change due");
    int first = 0, changed = -1;
    bool done = false;
    for_each([&](auto& c) {
      if constexpr (MovingBoundary<std::remove_cvref_t<decltype(c)>, D>) {
        if (!done && c.next_layer_change() == when) {
          done = true;
          const int k = c.change_layer(t);
          changed = k < 0 ? -1 : first + k;
        }
      }
      first += c.surfaces();
    });
    if (!done) throw std::logic_error("Boundaries::change_layer: no change due");
    return changed;
  }
  template <class F>
  void for_each_band_cell(int s, const CellGrid<D>& grid, F&& f) const {
    at(s, [&](const auto& c, int k) {
      if constexpr (MovingBoundary<std::remove_cvref_t<decltype(c)>, D>)
        c.for_each_band_cell(k, grid, f);
    });
  }
  double energy(int s, double t) const {
    return at(s, [&](const auto& c, int k) -> double {
      if constexpr (MovingBoundary<std::remove_cvref_t<decltype(c)>, D>) return c.energy(k, t);
      return 0.0;
    });
  }
  // The motions of every surface with mass, numbered as the set numbers surfaces.
  std::vector<WallMotion> motion() const {
    std::vector<WallMotion> out;
    int first = 0;
    for_each([&](const auto& c) {
      if constexpr (MovingBoundary<std::remove_cvref_t<decltype(c)>, D>) {
        for (WallMotion m : c.motion()) {
          m.face += static_cast<std::uint32_t>(first);
          out.push_back(m);
        }
      }
      first += c.surfaces();
    });
    return out;
  }
  // Each moving component gets the motions of its surfaces (renumbered as its own); a motion
  // of a surface of no moving component is an InputError.
  void restore(const std::vector<WallMotion>& motion, double t) {
    int first = 0;
    std::size_t taken = 0;
    for_each([&](auto& c) {
      if constexpr (MovingBoundary<std::remove_cvref_t<decltype(c)>, D>) {
        std::vector<WallMotion> own;
        for (WallMotion m : motion) {
          if (m.face < static_cast<std::uint32_t>(first) ||
              m.face >= static_cast<std::uint32_t>(first + c.surfaces()))
            continue;
          m.face -= static_cast<std::uint32_t>(first);
          own.push_back(m);
        }
        taken += own.size();
        c.restore(own, t);
      }
      first += c.surfaces();
    });
    if (taken != motion.size()) {
      throw InputError(
          "the state holds the motion of a wall with mass at a surface that "
          "cannot have one (surface numbers beyond the box's faces)");
    }
  }
  std::vector<WallReading> readings(double t) const {
    std::vector<WallReading> out;
    for_each([&](const auto& c) {
      if constexpr (MovingBoundary<std::remove_cvref_t<decltype(c)>, D>) {
        const std::vector<WallReading> own = c.readings(t);
        out.insert(out.end(), own.begin(), own.end());
      }
    });
    return out;
  }

  // The error of the component whose surfaces leave no room first (squeeze_time() <= t).
  [[noreturn]] void throw_squeezed(double t, double dmax, bool uniform) const {
    const double when = squeeze_time();
    for_each([&](const auto& c) {
      if (c.squeeze_time() == when) c.throw_squeezed(t, dmax, uniform);
    });
    throw std::logic_error("Boundaries::throw_squeezed: no surface leaves no room");
  }

 private:
  // g(component, local surface) for surface s of a moving component (nothing for another).
  template <class G>
  void at_moving(int s, G&& g) {
    int first = 0;
    bool done = false;
    for_each([&](auto& c) {
      if (!done && s >= first && s < first + c.surfaces()) {
        if constexpr (MovingBoundary<std::remove_cvref_t<decltype(c)>, D>) g(c, s - first);
        done = true;
      }
      first += c.surfaces();
    });
  }

  template <std::size_t I, class G>
  decltype(auto) dispatch(int s, G&& g) const {
    const auto& c = std::get<I>(components_);
    if constexpr (I + 1 == sizeof...(C)) {
      return g(c, s);
    } else {
      if (s < c.surfaces()) return g(c, s);
      return dispatch<I + 1>(s - c.surfaces(), std::forward<G>(g));
    }
  }

  Components components_;
  bool any_ = false;
  int surfaces_ = 0;
};

// The run's boundaries: the box's faces, the geometries of SurfaceGeometries (the registry,
// model/environment.hpp: each made from its specifications in the Environment, the box, its
// faces and the field) and the outlets, numbered in that order.
template <int D, class Geometries = SurfaceGeometries<D>>
class Boundaries;

template <int D, class... Geometry>
class Boundaries<D, TypeList<Geometry...>>
    : public BoundarySet<D, FaceWalls<D>, Geometry..., Outlets<D>> {
 public:
  Boundaries() = default;
  Boundaries(const Environment<D>& environment, const Vec<D>& box)
      : BoundarySet<D, FaceWalls<D>, Geometry..., Outlets<D>>(
            FaceWalls<D>(environment.faces, box, environment.gravity),
            Geometry(surface_specs<Geometry>(environment), box, environment.faces,
                     environment.gravity)...,
            Outlets<D>(environment.outlets, environment.gravity)) {}

  const FaceWalls<D>& faces() const { return this->template get<FaceWalls<D>>(); }
  FaceWalls<D>& faces() { return this->template get<FaceWalls<D>>(); }
  const Outlets<D>& outlets() const { return this->template get<Outlets<D>>(); }
  // The outlet (its number in outlets()) of surface s, which passes(s).
  int outlet_index(int s) const {
    int first = 0;
    bool reached = false;
    this->for_each([&](const auto& c) {
      reached = reached || std::is_same_v<std::remove_cvref_t<decltype(c)>, Outlets<D>>;
      if (!reached) first += c.surfaces();
    });
    return s - first;
  }
};

}  // namespace kairos
