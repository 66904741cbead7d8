// Particles grouped by size for the neighbour searches of set-up and analysis over wide size
// distributions (the multilevel idea of Ogarko and Luding, Comput. Phys. Commun. 183, 931
// (2012)): a class holds the sizes within a factor 2 of its largest, and each class gets a cell
// grid sized for its own largest member. With one class (sizes within a factor 2 of each other)
// a search is the plain one-grid search. The engine's own two levels are engine/size_levels.hpp.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace kairos {

struct SizeClasses {
  std::vector<std::uint8_t> of;      // each particle's class, 0 for the largest sizes
  std::vector<double> largest;       // the largest size of each class
  std::vector<std::size_t> members;  // how many particles each class holds

  std::size_t count() const { return largest.size(); }
};

// Class k holds the sizes in (top / 2^(k+1), top / 2^k], top the largest size; the last of at
// most `max_classes` takes every smaller one (zero, too); empty classes are left out. Sizes are
// diameters or radii alike (only ratios matter); non-finite ones belong to class 0.
inline SizeClasses size_classes(const std::vector<double>& sizes, int max_classes = 8) {
  SizeClasses out;
  out.of.assign(sizes.size(), 0);
  double top = 0.0;
  for (const double s : sizes)
    if (std::isfinite(s)) top = std::max(top, s);
  std::vector<double> largest(static_cast<std::size_t>(std::max(max_classes, 1)), 0.0);
  std::vector<std::size_t> members(largest.size(), 0);
  const int last = static_cast<int>(largest.size()) - 1;
  for (std::size_t i = 0; i < sizes.size(); ++i) {
    int k = 0;
    const double s = sizes[i];
    if (top > 0.0 && std::isfinite(s)) {
      // ratio in (0, 1]: k = floor(-log2(ratio)), found by halving (exact at the boundaries).
      double bound = 0.5 * top;
      while (k < last && !(s > bound)) {
        ++k;
        bound *= 0.5;
      }
    }
    out.of[i] = static_cast<std::uint8_t>(k);
    if (std::isfinite(s)) largest[static_cast<std::size_t>(k)] = std::max(largest[k], s);
    ++members[static_cast<std::size_t>(k)];
  }
  std::vector<std::uint8_t> renumber(largest.size(), 0);
  for (std::size_t k = 0; k < largest.size(); ++k) {
    renumber[k] = static_cast<std::uint8_t>(out.largest.size());
    if (members[k] == 0) continue;
    out.largest.push_back(largest[k]);
    out.members.push_back(members[k]);
  }
  for (std::uint8_t& k : out.of) k = renumber[k];
  if (out.largest.empty()) {  // no particle: one empty class keeps the callers simple
    out.largest.push_back(0.0);
    out.members.push_back(0);
  }
  return out;
}

}  // namespace kairos
