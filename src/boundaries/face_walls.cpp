#include "boundaries/face_walls.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

#include "core/error.hpp"
#include "dynamics/collision_time.hpp"
#include "dynamics/trajectory_events.hpp"

namespace kairos {

// The horizon of a spring's layer search, in periods of its fastest motion.
constexpr double kSpringSearchPeriods = 4.0;

template <int D>
FaceWalls<D>::FaceWalls(const std::array<Face<D>, 2 * D>& faces, const Vec<D>& box,
                        const Vec<D>& gravity)
    : faces_(faces), box_(box), gravity_(gravity) {
  for (int f = 0; f < 2 * D; ++f) {
    if (faces_[f].kind != FaceKind::kWall) continue;
    any_ = true;
    const Wall<D>& w = faces_[f].wall;
    if (!w.massive()) continue;
    any_massive_ = true;
    if (!own_body(f)) continue;  // the high wall of a container: its low wall's body
    // The force acts along the normal (into the box), the field on the wall's mass.
    const double sgn = f % 2 == 0 ? 1.0 : -1.0;
    bodies_[f].mass = w.mass;
    bodies_[f].accel = sgn * w.force / w.mass + gravity_[f / 2];
    bodies_[f].rest = rest_position(f);
    bodies_[f].position = rest_position(f);
    if (!std::isfinite(bodies_[f].accel)) {
      throw InputError("boundary.wall (" + name(f) + "): the force over the mass, " +
                       std::to_string(w.force) + " / " + std::to_string(w.mass) +
                       ", is not a finite acceleration");
    }
    if (w.spring.on()) {
      bodies_[f].spring = SpringMotion(w.spring, w.mass, bodies_[f].accel);
      bodies_[f].set(0.0, bodies_[f].rest, 0.0);
    }
    if (w.joined && !(faces_[f ^ 1].kind == FaceKind::kWall && faces_[f ^ 1].wall.joined &&
                      faces_[f ^ 1].wall.mass == w.mass && faces_[f ^ 1].wall.spring == w.spring)) {
      throw InputError("boundary.container: the walls " + name(f & ~1) + " and " + name(f | 1) +
                       " are joined as one body but differ (both must be walls of the same "
                       "mass and spring)");
    }
  }
}

// Along the wall's normal n (into the box: +e_a at the low face, -e_a at the high one) the
// plane's offset is d(t) = d0 + u t (+ the vibration): in the frame moving with u the particle's
// normal velocity is v - u, and the solvers of a fixed or vibrated plane apply. With u = 0 the
// result is the fixed (vibrated) plane's bit for bit.
template <int D>
double FaceWalls<D>::event_time(int face, const Vec<D>& x, const Vec<D>& v, double radius, double t,
                                double horizon) const {
  const Wall<D>& w = faces_[face].wall;
  const int a = face / 2;
  const double sgn = face % 2 == 0 ? 1.0 : -1.0;
  const NormalMotion m{sgn * x[a] - radius, sgn * v[a], sgn * gravity_[a]};
  if (w.massive()) [[unlikely]] {
    const WallBody& b = body(face);
    // On a spring: the certified search against the driven oscillator's path.
    if (b.sprung()) return oscillating_plane_event_time(m, b.plane(t, sgn, shift(face)), horizon);
    // The gap between the particle's lowest point and the plane, both on parabolas: a
    // quadratic in the time from t.
    return within_horizon(
        quadratic_event_time(m.height - sgn * position(face, t), m.velocity - sgn * b.speed_at(t),
                             0.5 * (m.accel - sgn * b.accel)),
        horizon);
  }
  const double u = sgn * w.velocity[a];
  const double d = (face % 2 == 0 ? 0.0 : -box_[a]) + (u != 0.0 ? u * t : 0.0);
  if (w.vibrates()) {
    const NormalMotion rel{m.height, m.velocity - u, m.accel};
    const VibratedPlane plane{d, sgn * w.amplitude, w.angular_frequency,
                              std::remainder(w.angular_frequency * t + w.phase, 2.0 * M_PI)};
    return vibrated_plane_event_time(rel, plane, horizon);
  }
  return moving_plane_event_time(m, d, u, horizon);
}

template <int D>
void FaceWalls<D>::set_reach(const CellGrid<D>& grid, double rmax) {
  for (int f = 0; f < 2 * D; ++f) {
    const double reach = faces_[f].wall.amplitude + rmax;
    layers_[f] = 1 + static_cast<int>(std::floor(reach / grid.width(f / 2)));
  }
  for (int a = 0; a < D; ++a) {
    widths_[a] = grid.width(a);
    cells_along_[a] = grid.cells_along(a);
  }
  for (int f = 0; f < 2 * D; ++f)
    if (massive(f)) layer_[f] = layer_of(f, body(f).position + shift(f));
}

// Whether a particle in cell c can touch face f: f has a wall, and the cell lies within
// layers_[f] layers of it (a non-periodic axis) unless the wall moves along its normal (a piston
// may reach any layer).
template <int D>
bool FaceWalls<D>::reaches(int f, CellCode c, const CellGrid<D>& grid) const {
  const int a = f / 2;
  if (faces_[f].kind != FaceKind::kWall) return false;
  if (faces_[f].wall.velocity[a] != 0.0) return true;
  const int k = grid.coordinate(c, a);
  if (massive(f)) [[unlikely]] {
    const auto [first, last] = band(f);
    return k >= first && k <= last;
  }
  return f % 2 == 0 ? k < layers_[f] : grid.cells_along(a) - 1 - k < layers_[f];
}

template <int D>
ContactResult<D> FaceWalls<D>::resolve(int f, const Vec<D>& x, double t, double mass, double radius,
                                       double inertia_factor, bool force_elastic, Vec<D>& v,
                                       Spin<D>& w) const {
  const Wall<D>& wall = faces_[f].wall;
  return resolve_surface_contact<D>(wall.contact, face_normal<D>(f), velocity(f, x, t), mass,
                                    radius, inertia_factor, force_elastic, v, w,
                                    wall.massive() ? wall.mass : kNever);
}

template <int D>
int FaceWalls<D>::layer_of(int f, double x) const {
  const int a = f / 2;
  const int k = static_cast<int>(std::floor(x / widths_[a]));
  return std::clamp(k, 0, cells_along_[a] - 1);
}

// A particle touching the plane has its centre within its radius of it, on the box's side:
// within layers_[f] layers of the plane's layer (set_reach), one more on the far side for
// positions a round-off across a cell's face.
template <int D>
std::pair<int, int> FaceWalls<D>::band(int f) const {
  const int last = cells_along_[f / 2] - 1;
  if (f % 2 == 0) return {std::max(0, layer_[f] - 1), std::min(last, layer_[f] + layers_[f])};
  return {std::max(0, layer_[f] - layers_[f]), std::min(last, layer_[f] + 1)};
}

template <int D>
void FaceWalls<D>::restore(const std::vector<WallMotion>& motion, double t) {
  for (int f = 0; f < 2 * D; ++f) {
    if (!massive(f) || !own_body(f)) continue;
    bodies_[f].set(t, rest_position(f), 0.0);
    bodies_[f].work = {};
    bodies_[f].version = 0;
  }
  const bool cells = cells_along_[0] > 0;  // prepare() has run (not in the DEM)
  for (int f = 0; f < 2 * D; ++f)
    if (massive(f) && cells) layer_[f] = layer_of(f, position(f, t));
  for (const WallMotion& m : motion) {
    const int f = static_cast<int>(m.face);
    if (f >= 2 * D || !massive(f) || !own_body(f)) {
      throw InputError("the state holds the motion of a wall with mass at face " +
                       (f < 2 * D ? name(f) : std::to_string(f)) +
                       " but this run gives that face no mass of its own (boundary.wall.mass, "
                       "or the low wall of a boundary.container)");
    }
    const auto same_face = [&](const WallMotion& other) { return other.face == m.face; };
    if (std::count_if(motion.begin(), motion.end(), same_face) > 1) {
      throw InputError("the state holds two motions of the wall with mass at face " + name(f));
    }
    WallBody& b = bodies_[f];
    // The motion the state was made with (its acceleration, and spring if any).
    WallBody before = b;
    before.accel = m.accel;
    before.spring = m.sprung() ? SpringMotion(spring_of(m), m.spring[0], m.accel) : SpringMotion{};
    before.set(m.time, m.position, m.speed);
    before.work = {m.drive_work, m.dashpot};
    b.version = m.version;
    b.work = before.work;
    const bool same = m.accel == b.accel && m.sprung() == b.sprung() &&
                      (!b.sprung() || (m.spring[0] == b.mass && spring_of(m) == b.spring.spring()));
    if (same) {
      b.set(m.time, m.position, m.speed);
    } else {
      // Another force, mass, field or spring from now on: the wall moved with the state's own
      // up to its time t, and moves on from there (wall events predicted before are stale).
      b.work = before.work_at(t);
      b.set(t, before.position_at(t), before.speed_at(t));
      ++b.version;
    }
    if (!std::isfinite(b.position_at(t)) || !std::isfinite(b.speed)) {
      throw InputError("the state's motion of the wall with mass at face " + name(f) +
                       " is not finite");
    }
    // The layer the run had it in (a plane within round-off of a cell face could be put in
    // either), unless the state does not say or the grid differs. A container's high wall:
    // from its place (the state holds one row per body).
    for (const int g : {f, f ^ 1}) {
      if (!cells || (g != f && !faces_[f].wall.joined)) continue;
      const int layer = g == f ? m.layer : -1;
      const bool kept = layer >= 0 && layer < cells_along_[g / 2] &&
                        std::abs(layer_of(g, position(g, t)) - layer) <= 1;
      layer_[g] = kept ? layer : layer_of(g, position(g, t));
    }
  }
  if (cells) find_next_change(t);
}

template <int D>
std::vector<WallMotion> FaceWalls<D>::motion() const {
  std::vector<WallMotion> out;
  for (int f = 0; f < 2 * D; ++f)
    if (massive(f) && own_body(f)) out.push_back(bodies_[f].state(f, layer_[f]));
  return out;
}

template <int D>
void FaceWalls<D>::push(int f, double t, const Vec<D>& impulse_on_particle) {
  bodies_[body_index(f)].kick(t, -impulse_on_particle[f / 2]);
  find_next_change(t);
}

// The plane leaves [lower, upper] of its layer: the cell's faces, as the particles' crossings
// find them; the outer layers extend to infinity (a lid pushed out of the box moves on in the
// outermost layer, and the particles follow it there).
template <int D>
void FaceWalls<D>::find_next_change(double t) {
  next_change_ = kNever;
  next_change_face_ = -1;
  next_change_recheck_ = false;
  for (int f = 0; f < 2 * D; ++f) {
    if (!massive(f)) continue;
    const int a = f / 2;
    const WallBody& b = body(f);
    const double lo = layer_[f] == 0 ? -kNever : layer_[f] * widths_[a];
    const double hi = layer_[f] == cells_along_[a] - 1 ? kNever : (layer_[f] + 1) * widths_[a];
    bool recheck = false;
    double when = kNever;
    if (b.sprung()) [[unlikely]] {
      const OscillatingPlane up = b.plane(t, 1.0, shift(f));
      const double reach = up.transient() + std::abs(up.amplitude);
      if (up.d0 - reach > lo && up.d0 + reach < hi) continue;  // it cannot leave before a kick
      // The first time the oscillator's path reaches either face of the layer, searched up to a
      // horizon of a few periods (the search's cost grows with the periods it covers); if
      // none, the search is made again then.
      const double horizon = kSpringSearchPeriods * 2.0 * std::numbers::pi /
                             std::max(b.spring.wd(), b.spring.spring().omega);
      double dt = kNever;
      if (hi < kNever) dt = oscillating_plane_event_time({hi, 0.0, 0.0}, up, horizon);
      if (lo > -kNever) {
        const OscillatingPlane down{-up.d0, -up.u,         -up.b,    up.gamma,
                                    up.wd,  -up.amplitude, up.omega, up.phase};
        dt = std::min(dt,
                      oscillating_plane_event_time({-lo, 0.0, 0.0}, down, std::min(dt, horizon)));
      }
      recheck = !(dt < kNever);
      when = t + (recheck ? horizon : dt);
    } else {
      when = t + interval_exit_time_accelerated(position(f, t), b.speed_at(t), b.accel, lo, hi);
    }
    if (when < next_change_) {
      next_change_ = when;
      next_change_face_ = f;
      next_change_recheck_ = recheck;
    }
  }
}

template <int D>
int FaceWalls<D>::change_layer(double t) {
  const int f = next_change_face_;
  if (next_change_recheck_) {
    find_next_change(t);
    return -1;
  }
  const int a = f / 2;
  const double x = position(f, t);
  const double lo = layer_[f] * widths_[a];
  const double hi = (layer_[f] + 1) * widths_[a];
  // Through the nearer face of the layer (an inner face: the outer layers have none outside).
  layer_[f] = std::clamp(layer_[f] + (std::abs(x - hi) < std::abs(x - lo) ? 1 : -1), 0,
                         cells_along_[a] - 1);
  find_next_change(t);
  return f;
}

template <int D>
std::vector<WallReading> FaceWalls<D>::readings(double t) const {
  std::vector<WallReading> out;
  for (int f = 0; f < 2 * D; ++f) {
    if (!is_wall(f) || !massive(f)) continue;
    const Wall<D>& w = faces_[f].wall;
    if (w.joined && f % 2 == 1) continue;  // the container, read at its low wall
    double area = 1.0;
    for (int a = 0; a < D; ++a)
      if (a != f / 2) area *= box_[a];
    const WallBody& b = body(f);
    WallReading r{w.joined ? std::string(1, "xyz"[f / 2]) : name(f),
                  position(f, t),
                  b.speed_at(t),
                  energy(f, t),
                  w.mass,
                  w.force,
                  w.joined ? 0.0 : w.inward_push(f, gravity_) / area};
    r.sprung = b.sprung();
    r.container = w.joined;
    const SpringWork work = b.work_at(t);
    r.drive_work = work.drive;
    r.dashpot = work.dashpot;
    out.push_back(r);
  }
  return out;
}

template <int D>
void FaceWalls<D>::check_start(const Vec<D>& x, double radius, double t, std::uint64_t id) const {
  for (int f = 0; f < 2 * D; ++f) {
    if (faces_[f].kind != FaceKind::kWall) continue;
    const int a = f / 2;
    const double g = gap(f, x, t);
    if (g < radius * (1.0 - 1e-12)) {
      throw InputError("particle " + std::to_string(id) + " overlaps the wall at the " +
                       (f % 2 == 0 ? "low" : "high") + " face of axis " + std::string(1, "xyz"[a]) +
                       " (centre " + std::to_string(g) + " from the wall, radius " +
                       std::to_string(radius) + ")");
    }
  }
}

// Relative margin of find_squeeze_time: a lone particle squeezed between approaching walls
// bounces ever faster (speed times gap is an adiabatic invariant), so the exact limit would take
// without end to reach; this one is reached after some 1e4 bounces, while its events are still
// 1e7 ulps of the clock apart, far from a frozen clock (at a margin of 1e-6 the clock froze
// first, 1e-5 time units short of it).
constexpr double kSqueezeMargin = 1e-3;

// The first time at which the walls of an axis, moving towards each other, are no more than the
// largest diameter (times 1 + kSqueezeMargin) apart, or leave less room between them than the
// particles' volume at the densest packing, vibration amplitudes counted as if both walls were
// at their innermost: from then on the particles have no room between them (a gas compressed by
// a piston jams before that, which the run drivers' frozen-clock watch reports). The densest
// packing: pi / sqrt 18 for equal spheres (Kepler's conjecture, Hales, Ann. Math. 162, 1065
// (2005)), pi / sqrt 12 for equal disks (Thue); particles of several sizes can pack denser,
// so for them the bound is 1 (no room at all).
template <int D>
void FaceWalls<D>::find_squeeze_time(double rmax, double particle_volume, bool uniform) {
  squeeze_time_ = kNever;
  const double densest = !uniform ? 1.0 : D == 3 ? M_PI / std::sqrt(18.0) : M_PI / std::sqrt(12.0);
  for (int a = 0; a < D; ++a) {
    const Face<D>& lo = faces_[2 * a];
    const Face<D>& hi = faces_[2 * a + 1];
    if (lo.kind != FaceKind::kWall || hi.kind != FaceKind::kWall) continue;
    const double approach = lo.wall.velocity[a] - hi.wall.velocity[a];
    if (!(approach > 0.0)) continue;
    double cross_section = 1.0;
    for (int b = 0; b < D; ++b)
      if (b != a) cross_section *= box_[b];
    const double needed =
        std::max(2.0 * rmax * (1.0 + kSqueezeMargin), particle_volume / (densest * cross_section));
    const double room = box_[a] - lo.wall.amplitude - hi.wall.amplitude - needed;
    if (room / approach < squeeze_time_) {
      squeeze_time_ = room / approach;
      squeeze_axis_ = a;
      squeeze_needed_ = needed;
    }
  }
}

template <int D>
void FaceWalls<D>::throw_squeezed(double t, double dmax, bool uniform) const {
  const int a = squeeze_axis_;
  const std::string lo = std::string(1, "xyz"[a]) + "-", hi = std::string(1, "xyz"[a]) + "+";
  const Wall<D>& wl = faces_[2 * a].wall;
  const Wall<D>& wh = faces_[2 * a + 1].wall;
  std::ostringstream msg;
  msg.precision(10);
  msg << "boundary: at t = " << t << " the walls " << lo << " and " << hi << " are "
      << box_[a] + (wh.velocity[a] - wl.velocity[a]) * t << " apart";
  if (wl.vibrates() || wh.vibrates()) {
    msg << " (their vibrations take up to " << wl.amplitude + wh.amplitude << " of that)";
  }
  if (squeeze_needed_ > dmax * (1.0 + 2.0 * kSqueezeMargin)) {
    msg << ", less than the " << squeeze_needed_
        << " the particles need between them at the densest packing"
        << (uniform ? (D == 3 ? " of equal spheres" : " of equal disks") : "")
        << ": there is no room left between them (";
  } else {
    msg << ", no more than the largest particle diameter " << dmax
        << ": there is no room left between them (";
  }
  if (wl.velocity[a] != 0.0 && wh.velocity[a] != 0.0) {
    msg << "the walls " << lo << " and " << hi << " move towards each other";
  } else {
    msg << "the wall " << (wl.velocity[a] != 0.0 ? lo : hi) << " moves towards "
        << (wl.velocity[a] != 0.0 ? hi : lo);
  }
  msg << " at " << wl.velocity[a] - wh.velocity[a]
      << ", from the box's faces at t = 0); end the run before t = " << squeeze_time_
      << ", or move the walls more slowly or less far";
  throw InputError(msg.str());
}

template class FaceWalls<2>;
template class FaceWalls<3>;

}  // namespace kairos
