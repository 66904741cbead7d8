// Reordering per-particle arrays in place: a renumbering of a large system without a second
// copy of each array (docs/performance.md, "Memory").
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

namespace kairos {

// Reorders the first order.size() entries of `values` so that afterwards values[k] holds what
// values[order[k]] held (order: a permutation of 0 .. n-1), following the permutation's cycles:
// O(n) moves, n bits of scratch (`done`, reused between calls).
template <class Values>
void permute_in_place(Values& values, const std::vector<std::uint32_t>& order,
                      std::vector<bool>& done) {
  const auto n = static_cast<std::uint32_t>(order.size());
  done.assign(n, false);
  for (std::uint32_t start = 0; start < n; ++start) {
    if (done[start]) continue;
    auto first = std::move(values[start]);
    std::uint32_t k = start;
    while (true) {
      done[k] = true;
      const std::uint32_t from = order[k];
      if (from == start) {
        values[k] = std::move(first);
        break;
      }
      values[k] = std::move(values[from]);
      k = from;
    }
  }
}

}  // namespace kairos
