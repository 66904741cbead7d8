// A force-based (time-stepped) DEM integrator for frictionless soft spheres, in a periodic box
// or between walls, with or without gravity (issue 6): the yardstick the event-driven
// soft-sphere engine is checked against, and an integrator for dense granular matter.
//
// Physics (docs/physics.md#dem-normal-forces): the normal force of a pair is that of a
// SoftContactLaw (interactions/soft_contact.hpp: linear dashpot or viscoelastic Hertz), clipped
// at zero, F = max(0, F_law(xi, rdot)) while r < R_i + R_j: no attraction, so a receding pair
// whose law force turned negative (the force-zero end of contact,
// docs/physics.md#force-zero-end-of-contact) feels nothing although it still overlaps.
//
// Integrator: velocity Verlet. The damping force depends on the velocity, so the force at the
// new positions is evaluated with the predicted velocity v_n + dt a_n (not the half-step
// velocity, which would make the damping first order); the scheme stays second order in dt
// (the restitution and contact time of a head-on collision converge as dt^2, tests).
//
// Energy bookkeeping: E_kin + U + E_dis is constant to the Verlet accuracy (O(dt^2), not
// round-off), where U sums the elastic energy of every overlapping pair (dashpot k xi^2 / 2,
// Hertz (2/5) rho xi^(5/2)), including receding pairs past the force-zero end, and E_dis
// accumulates, by the trapezoidal rule, the power sum over pairs (F_el - F) rdot: the work of
// the damping force, and after the force-zero end the elastic energy left in the overlap.
//
// Laws per species pair: laws[a * species + b] (symmetric) for particles of species a and b
// (ParticleSystem::species); one law for all pairs is the case species = 1. Dashpot and Hertz
// pairs may be mixed (a slower loop then tests the model per pair).
//
// Collisions: a pair *enters contact* when r < R_i + R_j now and r >= R_i + R_j one step
// earlier (positions of the previous step recomputed from the drift); collisions() counts these
// events, the DEM's analogue of the event-driven collision count (a run's length in collisions
// per particle). The virial sum_pairs r F (time-integrated by the trapezoidal rule, like the
// dissipation) gives the pressure as the collisional virial does for hard spheres.
//
// Exact continuation: the stepping carries the half-step velocities u = v(t - dt/2) (and
// spins), from which v(t) is made for readers at the end of every call, so splitting the
// steps into calls changes no bit; checkpoint() holds the rest of the integrator's state, with
// which a new integrator continues bit for bit (restart files carry it).
//
// Walls and gravity (the Environment constructor): a face of the box may be a wall, a plane
// that is fixed, slides in its plane (felt through friction only) or moves along its normal (a
// piston's constant speed, a vibration A sin(w t + phi): Environment's Wall); plane walls
// anywhere ([[boundary.plane]], boundaries/plane_walls.hpp) move the same ways. A
// particle of species s closer to a wall than its radius feels the normal force of the law
// soft_wall[s] (the law of the particle alone: a spring on the particle's own mass), the
// overlap R - d and the gap's rate of change, clipped at zero like a pair's. The wall's work on
// the particles (force times the plane's normal velocity) and the energy the wall contacts
// dissipate are accumulated by the same trapezoidal rule as the pairs'. Gravity is a constant
// acceleration in the kicks; its potential energy is field_energy().
//
// Walls with mass (a face's Wall::mass: a lid, a container; FaceWalls' bodies,
// boundaries/wall_body.hpp): the contacts' force on the body along its axis kicks it by dt/2 at
// the start of a step (last evaluation's force) and at its end (the new one), and between kicks
// it moves by its own closed form (constant acceleration, or the driven damped oscillator):
// velocity Verlet for the wall with the closed-form part exact, second order, the momentum
// exchanged exactly. Its work on the particles is counted at its velocity after the closing
// kick (docs/physics.md#walls-with-mass-in-the-dem). Its motion travels in the exported state
// (wall_motion) and the last force in the checkpoint, so a restart is bit-identical.
//
// Friction (env.soft_friction / soft_wall_friction with a coefficient > 0; SoftFriction in
// interactions/soft_contact.hpp): a tangential spring per contact on the slip of the contact
// points (their relative velocity, rotation included, in the tangent plane), projected onto the
// tangent plane as the contact turns, with a tangential dashpot and the Coulomb cut; torques
// turn the particles (moment of inertia q m R^2, q = Environment::inertia_factor). The springs
// of the pairs ride along with the neighbour list (carried over at every rebuild), those of the
// walls per particle and face. Energy: the springs' energy counts as potential energy, and the
// dissipation of a contact is what the tangential force took from the slip beyond what its
// spring holds. Without friction the smooth loops run, unchanged.
//
// Outlets (boundary.outlet, boundaries/outlets.hpp; docs/physics.md#outlets-and-strips): at the end
// of a step, a particle whose centre is beyond an outlet's plane and that touches nothing is put
// back at a free place of the insertion region (the event engine's rule and draws,
// boundaries/outlet_placement.hpp; free: at least R from every wall, R + R_j from every
// particle now), with the set velocity and no spin; the neighbour list is rebuilt. One still
// touching a neighbour waits for its first free step (outlet_waiting()), so that the energy a
// pass takes out (kinetic, rotational and gravitational: no elastic part) is exact and enters
// the energy budget. The passes and their mass are counted as the engine counts them.
//
// Neighbours: a half neighbour list (pairs closer than d_max + skin), built from a linked-cell
// grid (cells >= d_max + skin) and rebuilt when the particles may have moved skin/2.
// Hot data are structure-of-arrays (x, y, z, vx, ... separately), renumbered into cell order at
// every build.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/particle_system.hpp"
#include "interactions/granular_contact.hpp"
#include "interactions/soft_contact.hpp"
#include "model/boundaries.hpp"
#include "model/environment.hpp"

namespace kairos {

struct DemOptions {
  // Time step; 0 = default, t_c / steps_per_contact with t_c the head-on contact time of the
  // lightest pair (reduced mass m_min / 2) at reference_speed (default_time_step below).
  double dt = 0.0;
  double steps_per_contact = 50.0;
  // Impact speed for the Hertz contact time; 0 = twice the largest initial speed (1 if all rest).
  double reference_speed = 0.0;
  // Neighbour-list skin as a fraction of the largest diameter.
  double skin = 0.1;
};

// t_c / steps_per_contact: the dashpot's contact time with the force-zero end
// (dashpot_head_on), or the elastic Hertz contact time at reference_speed
// (hertz_elastic_contact_time; damping shortens it a little).
double dem_default_time_step(const SoftContactLaw& law, double reduced_mass, double reference_speed,
                             double steps_per_contact = 50.0);

template <int D>
class DemIntegrator {
 public:
  // The system: periodic on every axis, no gravity, no bonds, nobody asleep, finite positions
  // and velocities, masses and radii > 0, box > 2 (d_max + skin) on every periodic axis (> d_max
  // between walls), no pair or wall contact overlapping by more than half the smaller radius.
  // InputError naming the problem otherwise. Each particle's position is taken at system.time
  // (position).
  DemIntegrator(const ParticleSystem<D>& system, const SoftContactLaw& law,
                const DemOptions& options = {});
  // One law per species pair: laws.size() == species * species, symmetric, every particle's
  // species < species. The default time step is the smallest over the species pairs present
  // (each at the reduced mass of its lightest particles). The counters of `system`
  // (collisions, events, virial, dissipated_in_collisions) are continued, so a state exported
  // and handed back in (a restart) keeps counting.
  DemIntegrator(const ParticleSystem<D>& system, const std::vector<SoftContactLaw>& laws,
                std::uint32_t species, const DemOptions& options = {});
  // Laws, walls and gravity from an environment: env.soft and env.species as above, a wall at
  // every face of kind kWall and every surface of env.surfaces (planes, cylinders, spheres) with
  // the law env.soft_wall[s] for particles of species s, and env.gravity. The system's periodic
  // axes and gravity must be the environment's. InputError for what the DEM does not integrate:
  // open faces, shear, stepped potentials, no soft laws. The default time step also covers the wall
  // contacts (reduced mass m_min, with a wall's mass M: m_min M / (m_min + M)) and, under gravity
  // or a wall's force, impacts at the speed of a fall (or a wall's push) across the box.
  DemIntegrator(const ParticleSystem<D>& system, const Environment<D>& env,
                const DemOptions& options = {});

  // n velocity Verlet steps. InputError if a pair overlaps by more than half its smaller radius
  // (time step far too large) or a coordinate turns non-finite.
  void step(long n = 1);
  // Up to n steps, stopping after the step in which collisions() reaches `collisions`;
  // returns the number of steps taken.
  long step_until(long n, std::uint64_t collisions);

  double time() const { return time_; }
  double dt() const { return dt_; }
  long steps() const { return steps_; }
  std::size_t size() const { return mass_.size(); }

  // What export_state() leaves out for a bit-identical continuation: handed back in the
  // system's `dem` field (with export_state()'s positions and velocities and the same time
  // step), the integrator continues exactly as this one would. A different time step, or a
  // system without it, starts afresh (forces recomputed).
  DemResume checkpoint() const;

  // Positions wrapped into [0, L), velocities, time set (every particle's local time too);
  // scheduler state (events, cells, order, zones, dem) cleared; counters.dissipated_in_collisions
  // set to dissipated_energy(). Everything else as given to the constructor.
  ParticleSystem<D> export_state() const;

  double kinetic_energy() const;     // translational
  double rotational_energy() const;  // 0 without friction
  // Elastic energy of every overlapping pair at the current positions.
  double potential_energy() const { return potential_; }
  // Accumulated work of the damping forces (see the header comment), >= 0 up to O(dt^2).
  double dissipated_energy() const { return dissipated_; }
  // Pairs with r < R_i + R_j and a positive force at the last force evaluation.
  std::size_t contact_count() const { return contacts_; }
  // Pairs that entered contact, including those counted in the constructor's system.
  std::uint64_t collisions() const { return collisions_; }
  // Particle-wall contacts begun, the energy wall contacts dissipated and the work the walls
  // did on the particles, each continuing the constructor's system's counters.
  std::uint64_t wall_collisions() const { return wall_collisions_; }
  double dissipated_at_walls() const { return dissipated_walls_; }
  double work_by_walls() const { return work_by_walls_; }
  // Potential energy in the gravity field, -sum m g.x: 0 without gravity, NaN when gravity has
  // a component along a periodic axis (unbounded there). Then kinetic + potential + field +
  // dissipated (pairs and walls) - work by walls is constant to O(dt^2).
  double field_energy() const;
  // Time integral of sum over pairs of r_ij F_ij (F > 0 repulsive), including the system's.
  double virial() const { return virial_; }
  // Walls with mass: what outputs show of each now (FaceWalls::readings), none without.
  std::vector<WallReading> walls_with_mass() const { return boundaries_.readings(time_); }
  bool any_wall_with_mass() const { return any_massive_; }
  // Outlets: the particles that passed and were put back, their mass and the energy they took
  // out, each continuing the constructor's system's counters (EventCounters::outlet_*).
  bool any_outlet() const { return any_outlet_; }
  std::uint64_t outlet_passes() const { return outlet_passes_; }
  double outlet_mass() const { return outlet_mass_; }
  double outlet_energy() const { return outlet_energy_; }
  // Particles beyond an outlet's plane at the end of the last step that still touched something
  // (they pass at their first free step).
  std::size_t outlet_waiting() const { return outlet_waiting_; }
  Vec<D> momentum() const;
  long neighbour_list_builds() const { return builds_; }

  // Of particle i in the caller's numbering (the integrator renumbers internally).
  Vec<D> position(std::size_t i) const;
  Vec<D> velocity(std::size_t i) const;

 private:
  void init(const DemOptions& options);
  bool resume(const DemResume& r);
  std::size_t resume_stride() const;
  void set_walls(const Environment<D>& env);
  void set_friction(const Environment<D>& env);
  // Wall forces (added to f_) at positions x and predicted velocities vp at time t.
  void compute_wall_forces(bool count_collisions, double t);
  // What the wall contacts add up to in one force evaluation.
  struct WallSums {
    double potential = 0.0, loss = 0.0, work = 0.0, spring = 0.0, slip = 0.0;
    std::uint64_t entered = 0;
  };
  // A particle's contact with a surface: the centre's distance from it, the gap's rate of
  // change, the surface's normal (into the domain), its velocity there and that velocity along
  // the normal; axis >= 0 when the normal is that axis (a box face).
  struct WallContact {
    double gap = 0.0, rdot = 0.0, normal_speed = 0.0;
    Vec<D> normal{}, velocity{};
    int axis = -1;
  };
  // Inlined into both loops (a call per contact cost the faces' loop 2 %). `spring`: the
  // contact's tangential spring (friction only; null without).
  [[gnu::always_inline]] inline bool touches(std::size_t i, int surface, double gap, double t,
                                             std::vector<Vec<D>>& springs);
  // Returns the normal force's size F (along c.normal on the particle); the law's damping
  // coefficient times damping_scale (reduced_mass_damping against a wall with mass).
  [[gnu::always_inline]] inline double add_wall_contact(std::size_t i, const WallContact& c,
                                                        Vec<D>* spring, bool count_collisions,
                                                        WallSums& sums, double damping_scale = 1.0);
  double reduced_mass_damping(std::size_t i, double wall_mass) const;
  template <class F>
  void for_each_massive_face(F&& visit) const {
    for (int f = 0; f < 2 * D; ++f)
      if (wall_on_[static_cast<std::size_t>(f)] && walls_[static_cast<std::size_t>(f)].massive())
        visit(f);
  }
  void kick_walls(double t);
  // The contacts with the surfaces of the boundary components other than the box faces (plane
  // walls): the faces' force law through the boundary interface (gap, normal and velocity at
  // the contact), component by component (static dispatch).
  void add_surface_forces(bool count_collisions, double t, WallSums& sums);
  template <class Component>
  void add_component_forces(const Component& c, int first, bool count_collisions, double t,
                            WallSums& sums);
  template <bool Gravity, bool Walls>
  void kick_drift(double& vmax2, double& vsum2);
  void synchronise(bool from_half_step);
  double time_at(long steps) const;
  // Half the box on periodic axes (minimum image), infinite between walls (no image).
  Vec<D> half_box() const;
  long advance(long n, std::uint64_t collisions);
  void build_neighbours();
  // Outlets: every particle whose centre is beyond an outlet's plane at the end of the step (time
  // t) and that touches nothing put back; returns whether one was.
  bool pass_outlets(double t);
  bool free_place(std::size_t i, const Vec<D>& x, double t) const;
  // Forces, potential_, power_, virial_power_, contacts_ at x with the predicted velocity;
  // counts pairs entering contact when count_collisions.
  void compute_forces(bool count_collisions, double t);
  enum class Laws { kDashpot, kHertz, kMixed };
  template <Laws L, bool Friction>
  void compute_forces_for(bool count_collisions);
  void carry_shear_over(const std::vector<std::uint64_t>& keys, const std::vector<Vec<D>>& values);
  static constexpr int kSpin = D == 3 ? 3 : 1;
  Spin<D> spin(const std::vector<double> (&a)[kSpin], std::size_t i) const;
  void add_spin(std::vector<double> (&a)[kSpin], std::size_t i, const Spin<D>& s);

  ParticleSystem<D> base_;
  // Per species pair a * species_ + b: the model, the stiffness (k or rho) and the damping
  // coefficient (gamma, or (3/2) A rho for Hertz: F = rho xi^1.5 - c rdot xi^0.5).
  std::vector<SoftContactLaw> laws_;
  std::uint32_t species_ = 1;
  std::vector<double> stiffness_, damping_coefficient_;
  std::vector<std::uint8_t> hertz_;
  Laws kind_ = Laws::kDashpot;
  Vec<D> box_{};
  double dt_ = 0.0;
  double time_ = 0.0;
  long steps_ = 0;
  // time = time_origin_ + (step_base_ + steps_) dt: the same bits whether or not a run went
  // through a restart file in between.
  double time_origin_ = 0.0;
  long step_base_ = 0;

  // Positions, velocities (at the present step, for readers), half-step velocities (what the
  // stepping carries), forces, predicted velocities (for the damping forces).
  std::vector<double> x_[D], v_[D], u_[D], f_[D], vp_[D];
  std::vector<double> mass_, inv_mass_, radius_;
  std::vector<std::uint32_t> sp_;  // species per slot
  // Internal numbering, cell order of the last neighbour-list build: id_[slot] = the caller's
  // index, slot_[index] = its slot.
  std::vector<std::uint32_t> id_, slot_;
  double max_diameter_ = 0.0, skin_ = 0.0, max_overlap_fraction_ = 0.5;

  // Half neighbour list, CSR: neighbours of i (all j > i in the list sense) in
  // nbr_[start_[i] .. start_[i+1]).
  std::vector<std::uint32_t> start_, nbr_;
  double moved_since_build_ = 0.0;  // upper bound on any displacement since the last build
  long builds_ = 0;

  // Walls and gravity (set_walls): per face whether it is a wall and how its plane moves; per
  // species the wall law (stiffness, damping coefficient as for the pairs, Hertz or not).
  std::array<bool, D> periodic_{};
  std::array<bool, 2 * D> wall_on_{};
  std::array<Wall<D>, 2 * D> walls_{};
  // Every surface of the run (model/boundaries.hpp): the faces above run their own loop over the
  // coordinate arrays; the other components' surfaces (any_surface_) go through add_surface_forces.
  Boundaries<D> boundaries_;
  bool any_surface_ = false;
  bool any_wall_ = false;  // a face wall or another surface
  std::vector<SoftContactLaw> wall_laws_;
  std::vector<double> wall_stiffness_, wall_damping_;
  std::vector<std::uint8_t> wall_hertz_;
  Vec<D> gravity_{};
  bool gravity_on_ = false;
  double wall_loss_power_ = 0.0, dissipated_walls_ = 0.0;
  double wall_work_power_ = 0.0, work_by_walls_ = 0.0;
  std::uint64_t wall_collisions_ = 0;
  // Walls with mass (the faces' bodies in boundaries_, FaceWalls): the contacts' force on each
  // face along its axis at the last evaluation, the lightest wall's mass.
  bool any_massive_ = false;
  std::array<double, 2 * D> wall_force_{};
  std::array<double, 2 * D> predicted_wall_speed_{};  // at the evaluation (compute_wall_forces)
  double lightest_wall_ = std::numeric_limits<double>::infinity();
  bool any_outlet_ = false;
  std::uint64_t outlet_passes_ = 0;
  double outlet_mass_ = 0.0, outlet_energy_ = 0.0;
  std::size_t outlet_waiting_ = 0;

  // Friction (see the header comment): per species pair and per species against the walls
  // mu, k_t / k_n and gamma_t / gamma_n; the springs of the list entries and, per wall face,
  // of the particles; angular velocity, its predicted value, torque, 1/I and I per slot.
  bool friction_ = false;
  std::vector<SoftFriction> friction_pair_, friction_wall_;
  std::vector<Vec<D>> shear_;
  std::vector<std::vector<Vec<D>>> wall_shear_;  // per surface (faces first), per slot
  std::vector<double> w_[kSpin], uw_[kSpin], wp_[kSpin], tq_[kSpin];
  std::vector<double> inertia_, inv_inertia_;
  std::vector<double> inertia_factor_;  // q per species: I = q m R^2
  // Sum over contacts of F_t . v_t (the tangential forces' power on the slip) and of the springs'
  // energy, pairs and walls, at the last force evaluation.
  double slip_power_ = 0.0, spring_energy_ = 0.0;
  double wall_slip_power_ = 0.0, wall_spring_energy_ = 0.0;

  double potential_ = 0.0, power_ = 0.0, dissipated_ = 0.0;
  double virial_power_ = 0.0, virial_ = 0.0;
  std::size_t contacts_ = 0;
  std::uint64_t collisions_ = 0;
};

extern template class DemIntegrator<2>;
extern template class DemIntegrator<3>;

}  // namespace kairos
