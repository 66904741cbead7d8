// Initial configurations: lattices scaled to a packing fraction, random insertion, species
// assignment and Maxwell-Boltzmann velocities.
//
// Coordinates live in [0, L_k) along each axis k (the engine's convention; GSD output shifts
// them to HOOMD's centred box). All functions are deterministic given the RNG state.
#pragma once

#include <array>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "core/memory_budget.hpp"
#include "core/particle_system.hpp"
#include "core/release_pages.hpp"
#include "core/stop_flag.hpp"
#include "io/config.hpp"

namespace kairos {

// Marks "no particle" in worst-pair outputs.
inline constexpr std::uint32_t kNoParticle = 0xFFFFFFFFu;

// Volume of a sphere (D = 3, pi d^3 / 6) or area of a disk (D = 2, pi d^2 / 4) of diameter d.
template <int D>
constexpr double particle_volume(double diameter) {
  static_assert(D == 2 || D == 3);
  constexpr double pi = 3.141592653589793238462643383279502884;
  if constexpr (D == 3) {
    return pi * diameter * diameter * diameter / 6.0;
  } else {
    return pi * diameter * diameter / 4.0;
  }
}

// Splits `total` into counts proportional to the (non-negative, not all zero) weights by
// largest-remainder rounding: the counts sum to `total` exactly; ties go to the lower index.
std::vector<std::uint64_t> largest_remainder_counts(const std::vector<double>& weights,
                                                    std::uint64_t total);

template <int D>
struct InitialState {
  std::array<double, D> box{};                  // box edge lengths
  std::vector<std::array<double, D>> position;  // in [0, box)
  std::vector<std::array<double, D>> velocity;
  std::vector<std::uint32_t> species;  // index into species_names
  std::vector<double> diameter;        // per particle
  std::vector<double> mass;            // per particle
  std::vector<std::string> species_names;
  // Molecules (empty: none): bonds between particles of this state (its numbering) and the
  // names of the bond types they index.
  std::vector<Bond> bonds;
  std::vector<std::string> bond_types;
};

// Sum of the particle volumes divided by the box volume.
template <int D>
double packing_fraction(const InitialState<D>& state);

// The densest packing fraction random insertion is asked for (it jams a little above); a run
// asking for more with lattice = "random" inserts at this and grows the particles to its
// packing fraction (run/compression.hpp).
double random_insertion_limit(int dimension);

// Builds positions, species, diameters and masses from config.system (lattice or random
// insertion) and Maxwell-Boltzmann velocities at config.system.temperature.
//
// - Species: counts from the normalised number fractions by largest-remainder rounding (sum N
//   exactly). On a lattice the species are shuffled over the sites; random insertion places the
//   largest diameters first, so there the particles come sorted by decreasing diameter.
// - Box volume = sum of particle volumes / packing_fraction.
// - Lattices: fcc/bcc/sc in a cubic box of n^3 cubic cells (smallest n with enough sites);
//   square in n x n cells; hex (triangular) in nx x ny rectangular cells a x a sqrt(3) with two
//   sites each, nx = ceil(N / (2 ny)) and ny giving the box closest to square. With more sites
//   than N, particle i sits on site floor(i * sites / N) (uniform density). Offset by a quarter
//   cell along each axis, so no particle lies on the boundary.
// - Chains (system.chain_length L > 0; system.lattice is then ignored): N / L linear chains of
//   L beads, chain c = particles c L .. c L + L - 1, bonds (k, k + 1) within each chain, all of
//   bond type "backbone". The box is cubic/square (volume from the packing fraction as above);
//   the sites are a simple cubic/square lattice of spacing a = system.chain_spacing (0: the
//   largest diameter), floor(box / a) sites per axis at (c + 1/2) a, so that the gap across the
//   periodic boundary is at least a. The sites are ordered along a snake (boustrophedon) path:
//   consecutive sites of the path are neighbours at distance a (never across the boundary;
//   coordinates rounded so that the computed distance is never below a). Chain c occupies the
//   consecutive path sites from floor(c S / C) on (S sites, C chains): the chains fill the
//   path evenly, each on a straight-or-folded piece of it; with S = N particle k sits on site k.
//   Species as on a lattice (counts by fraction, shuffled over the particles). Not sorted
//   spatially. InputError when N is not a multiple of L, a < the largest diameter, or the box
//   holds fewer than N sites (the message gives the largest possible packing fraction).
// - "random": random sequential insertion in a cubic/square box, exact RSA statistics,
//   accelerated by a cell grid and a voxel list of the remaining free space; refused above
//   packing fraction 0.35 (3D) / 0.50 (2D) since it jams near 0.38 / 0.547.
// Throws InputError naming the key when the request is impossible: packing fraction above what
// the lattice allows for these N and diameters (the message gives the largest possible value,
// rounded down), random insertion too dense or failing, fewer particles than needed for a box
// of at least 3 x the largest diameter per axis (the message gives the minimum N), lattice not
// valid in this dimension, invalid species/particles/temperature values. Throws
// std::invalid_argument when system.dimension != D.
template <int D>
// `kind`: the integrator that will run it, for the memory estimate checked first.
InitialState<D> make_initial_state(const SystemConfig& system, std::mt19937_64& rng,
                                   RunKind kind = RunKind::kDem);

// The engine's starting state: every particle at time 0 with radius = diameter / 2, no
// scheduler state (the engine predicts every event). Takes the state over: its arrays are moved
// or released as they are read, so that the two forms of a large state are never in memory at
// once (pass a copy to keep it).
template <int D>
ParticleSystem<D> to_particle_system(InitialState<D>&& init) {
  ParticleSystem<D> s;
  s.box = init.box;
  // Written once each (reserve: no pages touched before), the pages read released as it goes.
  s.kinematics.reserve(init.position.size());
  for (std::size_t i = 0; i < init.position.size(); ++i) {
    if ((i & 0xffffu) == 0xffffu) throw_if_stop_requested();  // a setup loop (core/stop_flag)
    s.kinematics.push_back({init.position[i], init.velocity[i], 0.0, 0.5 * init.diameter[i]});
    release_read_front(init.position.data(), i + 1);
    release_read_front(init.velocity.data(), i + 1);
    release_read_front(init.diameter.data(), i + 1);
  }
  std::vector<std::array<double, D>>().swap(init.position);
  std::vector<std::array<double, D>>().swap(init.velocity);
  std::vector<double>().swap(init.diameter);
  s.mass = std::move(init.mass);
  s.species = std::move(init.species);
  s.species_names = std::move(init.species_names);
  s.bonds = std::move(init.bonds);
  s.bond_types = std::move(init.bond_types);
  return s;
}

template <int D>
ParticleSystem<D> to_particle_system(const InitialState<D>& init) {
  return to_particle_system<D>(InitialState<D>(init));
}

// Renumbers the particles in row-major order of cells as wide as the largest diameter, so
// particles close in space are close in memory (random insertion otherwise leaves them in
// insertion order). Applied to generated random states; files keep their particle order. Bonds
// are renumbered with their particles.
template <int D>
void sort_spatially(InitialState<D>& state);

// Maxwell-Boltzmann velocities: Gaussian components with variance kT/m (Box-Muller on 53-bit
// uniforms: the same numbers on every platform), zero total momentum, then rescaled so that
// 2 KE / (D (N - 1)) equals kT exactly. All zero when N < 2 or kT == 0. Throws InputError
// (system.temperature) for kT < 0 or non-finite; needs state.mass (> 0) and state.position of
// equal size.
template <int D>
void assign_maxwell_boltzmann_velocities(InitialState<D>& state, double kT, std::mt19937_64& rng);

// Fixed grains (fixed_species[s] for species s) start at rest; the particles that move keep
// their velocities' directions and get 2 KE / (D N_mobile) = kT (the fixed grains take up
// momentum: every degree of freedom is free). Nothing changes without a fixed species.
template <int D>
void rest_fixed_grains(InitialState<D>& state, const std::vector<bool>& fixed_species, double kT);

// Largest overlap (sigma_ij - r_ij, > 0 means overlapping) over all pairs under the minimum
// image convention, found with a cell grid (exact: every pair that can overlap is checked).
// Returns 0 when no pair overlaps. `worst_i` < `worst_j` (optional) receive the worst pair, or
// kNoParticle when no pair overlaps. Positions outside [0, box) are wrapped into it.
// `interruptible` (the setup's checks): polls throw_if_stop_requested() (core/stop_flag.hpp);
// never during a run, whose outputs must still be written after a stop.
template <int D>
double max_overlap(const std::array<double, D>& box, const std::vector<std::array<double, D>>& pos,
                   const std::vector<double>& diameter, std::uint32_t* worst_i = nullptr,
                   std::uint32_t* worst_j = nullptr, bool interruptible = false);

// The same in a box whose axes need not all be periodic (walls or open faces): along an axis
// with periodic[k] false no minimum image is taken (two particles at opposite faces are far
// apart), and positions are not wrapped (a grain thrown out of an open top stays where it is).
template <int D>
double max_overlap(const std::array<double, D>& box, const std::array<bool, D>& periodic,
                   const std::vector<std::array<double, D>>& pos,
                   const std::vector<double>& diameter, std::uint32_t* worst_i = nullptr,
                   std::uint32_t* worst_j = nullptr, bool interruptible = false);

// The largest overlap as a share of the smaller radius of its pair, overlap / min(R_i, R_j)
// (soft spheres may start overlapping by up to half of it), over the same pairs as max_overlap;
// 0 when no pair overlaps.
template <int D>
double max_relative_overlap(const std::array<double, D>& box, const std::array<bool, D>& periodic,
                            const std::vector<std::array<double, D>>& pos,
                            const std::vector<double>& diameter, std::uint32_t* worst_i = nullptr,
                            std::uint32_t* worst_j = nullptr, bool interruptible = false);

// The same by an O(N^2) loop over all pairs: the reference for tests (all axes periodic unless
// `periodic` says otherwise).
template <int D>
double max_overlap_bruteforce(const std::array<double, D>& box,
                              const std::vector<std::array<double, D>>& pos,
                              const std::vector<double>& diameter);
template <int D>
double max_overlap_bruteforce(const std::array<double, D>& box, const std::array<bool, D>& periodic,
                              const std::vector<std::array<double, D>>& pos,
                              const std::vector<double>& diameter);

}  // namespace kairos
