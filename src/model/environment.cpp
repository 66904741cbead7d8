#include "model/environment.hpp"

#include "core/event_code.hpp"

#include <cmath>
#include <string>

#include "core/error.hpp"
#include "interactions/parameter_domain.hpp"

namespace kairos {

namespace {
const char* face_name(int face) {
  static const char* names[] = {"x-", "x+", "y-", "y+", "z-", "z+"};
  return names[face];
}

template <int D>
void check_wall_motion(const Wall<D>& w, const std::string& name) {
  for (int a = 0; a < D; ++a) {
    if (!std::isfinite(w.velocity[a])) throw InputError(name + ": velocity must be finite");
  }
  if (!(w.amplitude >= 0.0) || !std::isfinite(w.amplitude)) {
    throw InputError(name + ": amplitude must be finite and >= 0");
  }
  if (!(w.angular_frequency >= 0.0) || !std::isfinite(w.angular_frequency) ||
      !std::isfinite(w.phase)) {
    throw InputError(name + ": frequency must be finite and >= 0 and the phase finite");
  }
  if (!(w.mass >= 0.0) || !std::isfinite(w.mass) || !std::isfinite(w.force))
    throw InputError(name + ": mass must be finite and >= 0 and the force finite");
  if (w.mass == 0.0 && w.force != 0.0)
    throw InputError(name + ": a force moves only a wall with mass");
  if (w.mass > 0.0 && (w.vibrates() || norm2(w.velocity) != 0.0))
    throw InputError(name +
                     ": a wall with mass moves as the impulses it takes say (no velocity "
                     "or vibration of its own)");
}
}  // namespace

template <int D>
bool Environment<D>::rotates() const {
  for (const ContactModel& c : contact)
    if (!c.tangential.is_smooth()) return true;
  for (const Face<D>& f : faces)
    if (f.kind == FaceKind::kWall && !f.wall.contact.tangential.is_smooth()) return true;
  for (const PlaneWall<D>& p : planes)
    if (!p.wall.contact.tangential.is_smooth()) return true;
  for (const auto* round : {&cylinders, &spheres})
    for (const CylinderWall<D>& c : *round)
      if (!c.contact.tangential.is_smooth()) return true;
  return false;
}

template <int D>
bool Environment<D>::plain() const {
  return contact.empty();
}

// The plane n.x = offset of a wall or an outlet (`name`): a finite unit normal, a finite point,
// and not across a periodic axis (it would not meet its own periodic image).
template <int D>
void Environment<D>::check_plane(const Vec<D>& normal, double offset,
                                 const std::string& name) const {
  double n2 = 0.0;
  for (int a = 0; a < D; ++a) {
    if (!std::isfinite(normal[a])) throw InputError(name + ".normal must be finite");
    n2 += normal[a] * normal[a];
  }
  if (!(std::abs(n2 - 1.0) <= 1e-12)) throw InputError(name + ".normal must be a unit vector");
  if (!std::isfinite(offset)) throw InputError(name + ".point must be finite");
  for (int a = 0; a < D; ++a) {
    if (normal[a] != 0.0 && periodic(a)) {
      throw InputError(name + ".normal has a component along the periodic axis " +
                       std::string(1, "xyz"[a]) +
                       ": a plane must not cut a periodic axis (it would not meet its own "
                       "periodic image); make that axis bounded (walls or open faces) or the "
                       "normal perpendicular to it");
    }
  }
}

// A plane cut to a strip (span_axis): still, across a bounded axis, with edges along a box axis.
template <int D>
void Environment<D>::check_strip(const PlaneWall<D>& p, const std::string& name) const {
  if (p.span_axis >= D) throw InputError(name + ".span_axis: not an axis of the box");
  const std::string axis(1, "xyz"[p.span_axis]);
  if (periodic(p.span_axis)) {
    throw InputError(name + ".span_axis: " + axis +
                     " is periodic; a strip must end across a bounded axis (walls or open faces)");
  }
  if (!(p.span_min < p.span_max) || std::isnan(p.span_min) || std::isnan(p.span_max))
    throw InputError(name + ": span_min must be below span_max");
  if (p.plane_moves() || norm2(p.wall.velocity) != 0.0) {
    throw InputError(name +
                     ": a strip (span_axis) must hold still: no velocity or vibration (its "
                     "edges do not move)");
  }
  const auto [along, across] = p.edge_axes();
  if (across < 0) {
    throw InputError(name + ".span_axis: the plane is perpendicular to " + axis +
                     ", so it cannot be cut along it; choose an axis the plane runs along");
  }
  if (along < 0) {
    throw InputError(name +
                     ".span_axis: in 3D a strip's edges run along a box axis, so the normal "
                     "must have no component along one of the two axes besides " +
                     axis);
  }
}

// A plane with a circular hole: 3D, still, not a strip; the hole's size and centre finite.
template <int D>
void Environment<D>::check_hole(const PlaneWall<D>& p, const std::string& name) const {
  if (D != 3) {
    throw InputError(name +
                     ".hole_radius: a hole is for planes in 3D (in 2D cut the line into "
                     "two strips: span_axis)");
  }
  if (p.spanned())
    throw InputError(name + ".hole_radius: a strip (span_axis) cannot also have a hole");
  if (!std::isfinite(p.hole_radius)) throw InputError(name + ".hole_radius: must be finite");
  for (int a = 0; a < D; ++a)
    if (!std::isfinite(p.hole_center[a])) throw InputError(name + ".hole_center: must be finite");
  if (p.plane_moves() || norm2(p.wall.velocity) != 0.0) {
    throw InputError(name +
                     ".hole_radius: a plane with a hole must hold still: no velocity or "
                     "vibration (its edge does not move)");
  }
}

// An outlet's plane, like a plane wall's, must not cut a periodic axis; its insertion region is
// a box on the particles' side of it (a particle put back behind it would pass again at once).
template <int D>
void Environment<D>::check_outlets() const {
  for (const Outlet<D>& o : outlets) {
    const std::string name = "boundary.outlet";
    check_plane(o.normal, o.offset, name);
    for (int a = 0; a < D; ++a) {
      if (!std::isfinite(o.insert_lower[a]) || !std::isfinite(o.insert_upper[a]) ||
          !std::isfinite(o.insert_velocity[a]))
        throw InputError(name + ": insert_lower, insert_upper and insert_velocity must be finite");
      if (!(o.insert_lower[a] <= o.insert_upper[a])) {
        throw InputError(name + ": insert_lower must not exceed insert_upper (along " +
                         std::string(1, "xyz"[a]) + ")");
      }
    }
    // The region's corner nearest the plane, along the normal.
    double nearest = 0.0;
    for (int a = 0; a < D; ++a)
      nearest += o.normal[a] * (o.normal[a] > 0.0 ? o.insert_lower[a] : o.insert_upper[a]);
    if (!(nearest > o.offset)) {
      throw InputError(name +
                       ": the insertion region (insert_lower to insert_upper) reaches the "
                       "outlet's plane or beyond it: a particle put back there would pass "
                       "again; move the region to the side the normal points to");
    }
  }
}

template <int D>
void Environment<D>::check() const {
  for (int a = 0; a < D; ++a) {
    const bool low = faces[2 * a].kind == FaceKind::kPeriodic;
    const bool high = faces[2 * a + 1].kind == FaceKind::kPeriodic;
    if (low != high) {
      throw InputError(std::string("boundary: face ") + face_name(2 * a + (low ? 1 : 0)) +
                       " is a wall or open but " + face_name(2 * a + (low ? 0 : 1)) +
                       " is periodic; an axis is periodic on both faces or on neither");
    }
  }
  for (int f = 0; f < 2 * D; ++f)
    if (faces[f].kind == FaceKind::kWall)
      check_wall_motion(faces[f].wall, std::string("wall ") + face_name(f));
  for (std::size_t s = 0; s < planes.size(); ++s) {
    const PlaneWall<D>& p = planes[s];
    const std::string name = "boundary.plane[" + std::to_string(s) + "]";
    check_wall_motion(p.wall, name);
    check_plane(p.normal, p.offset, name);
    if (p.spanned()) check_strip(p, name);
    if (p.holed()) check_hole(p, name);
  }
  check_outlets();
  const std::size_t surfaces = 2 * D + planes.size() + cylinders.size() + spheres.size() +
                               outlets.size() + 2 * strips() + holes();
  if (surfaces > static_cast<std::size_t>(EventCode<D>::kWallCodes)) {
    throw InputError("boundary: " + std::to_string(surfaces - 2 * D) +
                     " plane, cylinder and sphere walls; at most " +
                     std::to_string(EventCode<D>::kWallCodes - 2 * D) +
                     " fit the event codes (build a rough floor of grains instead)");
  }
  for (const bool sphere : {false, true}) {
    const std::vector<CylinderWall<D>>& round = sphere ? spheres : cylinders;
    for (std::size_t s = 0; s < round.size(); ++s) {
      const CylinderWall<D>& c = round[s];
      const std::string name =
          std::string(sphere ? "boundary.sphere[" : "boundary.cylinder[") + std::to_string(s) + "]";
      if (c.axis < 0 || c.axis >= D) throw InputError(name + ": axis must be a box axis");
      require_positive(c.radius, "radius", name + ": ");
      if (!std::isfinite(c.angular_velocity))
        throw InputError(name + ": angular_velocity must be finite");
      for (int a = 0; a < D; ++a) {
        if (!std::isfinite(c.center[a])) throw InputError(name + ": center must be finite");
        if ((sphere || D == 2 || a != c.axis) && periodic(a)) {
          throw InputError(
              name + ": the axis " + std::string(1, "xyz"[a]) +
              (sphere ? " is periodic: a sphere" : " across the cylinder is periodic: a cylinder") +
              " must not cross a periodic face (it would not meet its own periodic "
              "image); make that axis bounded (walls or open faces)");
        }
      }
    }
  }
  for (int a = 0; a < D; ++a) {
    if (!std::isfinite(gravity[a])) throw InputError("gravity must be finite");
  }
  if (!contact.empty() && contact.size() != static_cast<std::size_t>(species) * species) {
    throw InputError("contact laws: expected one per species pair");
  }
  for (const double q : inertia_factor) {
    if (!(q > 0.0) || !std::isfinite(q)) {
      throw InputError("inertia factor (I = q m R^2) must be finite and > 0");
    }
  }
  if (!pair_table.empty() && pair_table.size() != static_cast<std::size_t>(species) * species) {
    throw InputError("step potentials: expected one table index per species pair");
  }
  for (const auto* indices : {&pair_table, &bond_table}) {
    for (const int t : *indices) {
      if (t >= static_cast<int>(tables.size()) || t < -1 || (t < 0 && indices == &bond_table))
        throw InputError("step potentials: a table index is out of range");
    }
  }
  for (const StepTable& t : tables) t.check();
  if (!(tc >= 0.0) || !std::isfinite(tc)) throw InputError("tc must be finite and >= 0");
  if (!std::isfinite(shear_rate)) throw InputError("boundary.shear_rate must be finite");
  if (sheared()) {
    if (!periodic(0) || !periodic(1)) {
      throw InputError(
          "boundary.shear_rate: Lees-Edwards shear needs periodic x (flow) and y (gradient) axes; "
          "remove the walls or open faces on x and y");
    }
    if (has_gravity()) throw InputError("boundary.shear_rate: shear with gravity is not supported");
  }
}

template struct Environment<2>;
template struct Environment<3>;

}  // namespace kairos
