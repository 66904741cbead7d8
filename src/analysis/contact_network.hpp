// The contact network of a dense packing (a jammed state from compression, run/compression.hpp):
// which pairs touch, the rattlers, the mean coordination with and without them, isostaticity
// (docs/physics.md#jammed-packings). Hard particles never overlap, so "touching" means a gap
// h = r - sigma_ij below a tolerance: near jamming at reduced pressure Z the gaps of touching
// pairs are of order sigma / Z, those of the others orders of magnitude larger.
#pragma once

#include <cstdint>
#include <vector>

#include "analysis/neighbour_pairs.hpp"

namespace kairos {

struct Contact {
  std::uint32_t i = 0, j = 0;  // i < j
  double gap = 0.0;            // r - sigma_ij, relative to sigma_ij
};

struct ContactNetwork {
  double gap_tolerance = 0.0;  // relative gaps below this are contacts
  std::vector<Contact> contacts;
  // Rattlers: fewer than D + 1 contacts among the particles left, removed until none is left.
  std::vector<std::uint8_t> rattler;
  std::uint64_t rattlers = 0;
  std::uint64_t backbone_contacts = 0;  // between non-rattlers
  double coordination = 0.0;            // 2 contacts / N
  double backbone_coordination = 0.0;   // 2 backbone contacts / (N - rattlers)
  double rattler_fraction = 0.0;
  // The smallest relative gap above the tolerance (how clear the cut is; kNever-like if none
  // within 1.1 sigma) and the largest below it.
  double largest_contact_gap = 0.0;
  double smallest_open_gap = 0.0;
  // Isostatic: backbone contacts = D (N - rattlers) - D (the global translations; frictionless
  // spheres in a periodic box), i.e. z = 2D up to that O(1) term.
  std::int64_t excess_contacts = 0;  // backbone contacts - (D (N - rattlers) - D)
};

// The network of `c` (a periodic box) with relative gap tolerance `tolerance`.
template <int D>
ContactNetwork contact_network(const Configuration<D>& c, double tolerance);

}  // namespace kairos
