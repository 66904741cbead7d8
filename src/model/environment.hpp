// What particles meet besides each other's hard cores: a uniform field (gravity), the faces of
// the box (periodic, hard walls that may slide or vibrate, or open), and the contact laws of
// every species pair (restitution, roughness). The default environment is the elastic,
// fully periodic hard-sphere fluid.
//
// The environment is set up from the run configuration, never stored in a restart file: it is
// the model, not the state. Walls are the faces of the box (boundaries/face_wall.hpp: their
// planes are functions of the time alone, so restarts need nothing more).
#pragma once

#include <array>
#include <cmath>
#include <concepts>
#include <cstdint>
#include <string>
#include <vector>

#include <memory>
#include "core/periodic.hpp"
#include "core/type_list.hpp"
#include "core/vec.hpp"

#include "boundaries/cylinder_walls.hpp"
#include "boundaries/face_wall.hpp"
#include "boundaries/outlets.hpp"
#include "boundaries/plane_walls.hpp"
#include "interactions/granular_contact.hpp"
#include "interactions/soft_contact.hpp"
#include "interactions/soft_map_table.hpp"
#include "interactions/step_potential.hpp"

namespace kairos {

// How a soft contact is carried out (docs/physics.md#event-driven-soft-contacts): kMapped, the
// Müller–Pöschel algorithm (the pair is placed where the contact ends, frozen in its
// centre-of-mass frame, and released with the post-contact velocities t_c later);
// kInstantaneous, a hard-sphere collision at first contact with the same normal restitution
// e(v_n) = -eps_rdot (the model the mapping improves on, kept for comparisons).
enum class SoftCollisions { kMapped, kInstantaneous };

// The boundary geometries beyond the box's faces, each a component of boundaries/ that keeps
// its surfaces' specifications here: the one line a new geometry adds on the model side
// (docs/extending.md). Their order numbers the surfaces: after the faces, before the outlets.
//
// A geometry is a component of the boundary registry (BoundaryComponent, model/boundaries.hpp)
// that also has the model's side below: one surface's specification, a constructor from its
// specifications, the box, the box's faces and the field, its checks against the box
// (periodic[a]: axis a is periodic; InputError naming the entry), the event codes its surfaces
// take, and a surface's contact law.
template <class G, int D>
concept SurfaceGeometry = requires(const std::vector<typename G::Spec>& specs,
                                   const typename G::Spec& spec,
                                   const std::array<bool, D>& periodic, const Vec<D>& box,
                                   const std::array<Face<D>, 2 * D>& faces) {
  G::check_specs(specs, periodic);
  { G::codes(specs) } -> std::convertible_to<std::size_t>;
  { G::contact_of(spec) } -> std::same_as<const ContactModel&>;
  G(specs, box, faces, box);
};

template <int D>
using SurfaceGeometries = TypeList<PlaneWalls<D>, CylinderWalls<D>, SphereWalls<D>>;
template <class Geometry>
using GeometrySpec = typename Geometry::Spec;

template <int D>
struct Environment {
  Vec<D> gravity{};
  // Face 2k is the low face of axis k, 2k + 1 the high face. An axis is periodic iff both of
  // its faces are.
  std::array<Face<D>, 2 * D> faces{};
  // The surfaces of every geometry of SurfaceGeometries after the faces (plane walls at any
  // position and orientation, cylinders, spheres): surface_specs<PlaneWalls<D>>(env).
  VectorsOf<SurfaceGeometries<D>, GeometrySpec> surfaces;
  // Outlets particles pass through, to be put back in an insertion region
  // (boundaries/outlets.hpp); not walls.
  std::vector<Outlet<D>> outlets;
  // Contact law of species pair (a, b) at contact[a * species + b] (symmetric); empty: every
  // pair collides elastically and smoothly.
  std::vector<ContactModel> contact;
  std::uint32_t species = 0;
  // Moment of inertia I = q m R^2 per species; empty: 2/5 (spheres) or 1/2 (disks).
  std::vector<double> inertia_factor;
  // Fixed grains (docs/physics.md#fixed-grains): fixed[s] != 0 when particles of species s never
  // move (infinite mass, at rest); empty: every particle moves.
  std::vector<std::uint8_t> fixed;
  bool fixed_species(std::uint32_t s) const { return s < fixed.size() && fixed[s] != 0; }
  bool has_fixed_grains() const {
    for (const std::uint8_t f : fixed)
      if (f != 0) return true;
    return false;
  }
  // TC model (Luding & McNamara): a collision within tc of either partner's previous one is
  // elastic. 0: off.
  double tc = 0.0;
  // Resting particles under gravity: a particle that leaves a fixed wall, or a sleeping
  // particle, slower than this is put to sleep (it stops and feels no gravity until something
  // hits it harder than this). < 0: automatic, sqrt(2 |g| 1e-6 d_min) with gravity and walls;
  // 0: never (then resting particles need the TC model or elastic_below_speed). Never with a
  // wall that moves along its normal (vibrating or a piston).
  double sleep_speed = -1.0;
  // Lees-Edwards sliding-brick boundaries for simple shear: the periodic images above the box
  // (y + L_y) are displaced along x by shear_rate * L_y * t and move at shear_rate * L_y, so
  // the mean flow is u_x = shear_rate * (y - L_y / 2). Flow along x, gradient along y; both
  // axes periodic, no gravity. 0: an ordinary periodic box.
  double shear_rate = 0.0;
  // Stepped potentials (docs/physics.md#step-tables): the step table of species pair (a, b) is
  // tables[pair_table[a * species + b]] (symmetric; -1: hard spheres), that of a bond of type k
  // tables[bond_table[k]]. A table's hard core must be the pair's contact distance (the sum of
  // the radii). Empty pair_table and bond_table: hard spheres only.
  std::vector<StepTable> tables;
  std::vector<int> pair_table;
  std::vector<int> bond_table;
  // Soft spheres (docs/physics.md#soft-spheres): the soft contact law of species pair (a, b) at
  // soft[a * species + b] (symmetric), and of species s against every wall at soft_wall[s].
  // Empty: contacts are hard (the `contact` laws). A soft law replaces the pair's ContactModel.
  // soft_tables / soft_wall_tables (same indices, null or empty: none) hold the lookup tables
  // of the map; collisions outside a table, or without one, integrate the map directly.
  std::vector<SoftContactLaw> soft;
  std::vector<SoftContactLaw> soft_wall;
  // Coulomb friction of the soft contacts (same indices as soft / soft_wall; empty: smooth).
  // The DEM integrates it; the event integrator's contacts are smooth.
  std::vector<SoftFriction> soft_friction;
  std::vector<SoftFriction> soft_wall_friction;
  std::vector<std::shared_ptr<const SoftMapTable>> soft_tables;
  std::vector<std::shared_ptr<const SoftMapTable>> soft_wall_tables;
  SoftCollisions soft_collisions = SoftCollisions::kMapped;

  bool soft_spheres() const { return !soft.empty(); }
  bool stepped() const {
    for (const int t : pair_table)
      if (t >= 0) return true;
    return !bond_table.empty();
  }
  // Some step table has a dashpot (spring_dashpot): energy is dissipated at steps.
  bool dissipative_steps() const {
    for (const StepTable& t : tables)
      if (t.damping > 0.0) return true;
    return false;
  }
  bool periodic(int axis) const { return faces[2 * axis].kind == FaceKind::kPeriodic; }
  std::array<bool, D> periodic_axes() const {
    std::array<bool, D> out{};
    for (int a = 0; a < D; ++a) out[a] = periodic(a);
    return out;
  }
  bool has_gravity() const {
    for (int a = 0; a < D; ++a)
      if (gravity[a] != 0.0) return true;
    return false;
  }
  bool sheared() const { return shear_rate != 0.0; }
  // The mean shear flow at position x (any periodic image) in a box of edges `box`: zero
  // without shear.
  Vec<D> streaming_velocity(const Vec<D>& x, const Vec<D>& box) const {
    Vec<D> u{};
    u[0] = shear_rate * (wrap_into_box(x[1], box[1]) - 0.5 * box[1]);
    return u;
  }
  // Whether face f is a wall whose plane moves (a normal velocity or a vibration).
  bool wall_moves(int f) const {
    return faces[f].kind == FaceKind::kWall && faces[f].wall.plane_moves(f);
  }
  // Some face is a wall, or some plane wall is given.
  bool has_walls() const {
    for (const Face<D>& f : faces)
      if (f.kind == FaceKind::kWall) return true;
    return !surfaces.empty();
  }
  const ContactModel* contact_of(std::uint32_t a, std::uint32_t b) const {
    return contact.empty() ? nullptr : &contact[a * species + b];
  }
  double inertia_factor_of(std::uint32_t s) const {
    return inertia_factor.empty() ? (D == 3 ? 0.4 : 0.5) : inertia_factor[s];
  }
  // Whether any contact (pair or wall) can change spins: then angular velocities are tracked.
  bool rotates() const;
  // Whether every contact is elastic and smooth, with no field, walls or open faces.
  bool plain() const;
  // Throws InputError naming the first inconsistency (an axis periodic on one face only, a
  // velocity that is not finite, a negative amplitude, contact table size...).
  void check() const;

 private:
  void check_outlets() const;
};

// The specifications of geometry G's surfaces in `env` (G one of SurfaceGeometries<D>).
template <class G, int D>
std::vector<typename G::Spec>& surface_specs(Environment<D>& env) {
  return env.surfaces.template of<G>();
}
template <class G, int D>
const std::vector<typename G::Spec>& surface_specs(const Environment<D>& env) {
  return env.surfaces.template of<G>();
}

}  // namespace kairos
