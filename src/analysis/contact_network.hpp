// The contact network of a dense packing (a jammed state from compression, run/compression.hpp):
// which pairs touch, the rattlers, the mean coordination with and without them, isostaticity
// (docs/physics.md#jammed-packings). Hard particles never overlap, so "touching" means a gap
// h = r - sigma_ij below a tolerance: near jamming at reduced pressure Z the gaps of touching
// pairs are of order sigma / Z, those of the others orders of magnitude larger.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "analysis/neighbour_pairs.hpp"

namespace kairos {

struct Contact {
  std::uint32_t i = 0, j = 0;  // i < j
  double gap = 0.0;            // r - sigma_ij, relative to sigma_ij
};

// A particle touching a wall on a face of the box (face 2k: the low face of axis k).
struct WallContact {
  std::uint32_t i = 0;
  int face = 0;
  double gap = 0.0;  // centre to wall less the radius, relative to the diameter
};

struct ContactNetwork {
  double gap_tolerance = 0.0;  // relative gaps below this are contacts
  std::vector<Contact> contacts;
  std::vector<WallContact> wall_contacts;  // each holds the particle as a contact does
  // Rattlers: fewer than D + 1 contacts among the particles left, removed until none is left.
  std::vector<std::uint8_t> rattler;
  std::uint64_t rattlers = 0;
  std::uint64_t backbone_contacts = 0;       // between non-rattlers
  std::uint64_t backbone_wall_contacts = 0;  // of non-rattlers with walls
  // Contacts per particle, a wall contact counted once (for its particle): (2 contacts + wall
  // contacts) / N, and the same among the non-rattlers.
  double coordination = 0.0;
  double backbone_coordination = 0.0;
  double rattler_fraction = 0.0;
  // The smallest relative gap above the tolerance (how clear the cut is; kNever-like if none
  // within 1.1 sigma) and the largest below it.
  double largest_contact_gap = 0.0;
  double smallest_open_gap = 0.0;
  // Isostatic: backbone contacts (with walls) = D (N - rattlers) - P, P the periodic axes (the
  // global translations walls do not hold; frictionless spheres), i.e. z = 2D up to O(1) terms
  // in a periodic box.
  std::int64_t excess_contacts = 0;  // backbone contacts (with walls) - (D (N - rattlers) - P)
};

// The network of `c` with relative gap tolerance `tolerance`; `walls`: the faces (2k: the low
// face of axis k, at 0; 2k + 1 the high one, at the box's edge) that are walls, on axes that are
// not periodic.
template <int D>
ContactNetwork contact_network(const Configuration<D>& c, double tolerance,
                               const std::array<bool, 2 * D>& walls = {});

}  // namespace kairos
