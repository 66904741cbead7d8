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

}  // namespace

template <int D>
bool Environment<D>::rotates() const {
  for (const ContactModel& c : contact)
    if (!c.tangential.is_smooth()) return true;
  for (const Face<D>& f : faces)
    if (f.kind == FaceKind::kWall && !f.wall.contact.tangential.is_smooth()) return true;
  bool rough = false;
  SurfaceGeometries<D>::each([&](auto geometry) {
    using G = typename decltype(geometry)::type;
    for (const typename G::Spec& spec : surfaces.template of<G>())
      rough = rough || !G::contact_of(spec).tangential.is_smooth();
  });
  return rough;
}

template <int D>
bool Environment<D>::plain() const {
  return contact.empty();
}

// An outlet's plane, like a plane wall's, must not cut a periodic axis; its insertion region is
// a box on the particles' side of it (a particle put back behind it would pass again at once).
template <int D>
void Environment<D>::check_outlets() const {
  for (const Outlet<D>& o : outlets) {
    const std::string name = "boundary.outlet";
    check_plane_placement<D>(o.normal, o.offset, name, periodic_axes());
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
  // Each geometry checks its surfaces against the box and counts the event codes they take.
  std::size_t surface_codes = 2 * D + outlets.size();
  SurfaceGeometries<D>::each([&](auto geometry) {
    using G = typename decltype(geometry)::type;
    static_assert(SurfaceGeometry<G, D>);
    G::check_specs(surfaces.template of<G>(), periodic_axes());
    surface_codes += G::codes(surfaces.template of<G>());
  });
  check_outlets();
  if (surface_codes > static_cast<std::size_t>(EventCode<D>::kWallCodes)) {
    throw InputError(
        "boundary: " + std::to_string(surface_codes - 2 * D) +
        " surfaces beyond the faces (planes, cylinders, spheres, their edges, outlets); at most " +
        std::to_string(EventCode<D>::kWallCodes - 2 * D) +
        " fit the event codes (build a rough floor of grains instead)");
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
