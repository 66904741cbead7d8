#include "analysis/contact_network.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace kairos {

template <int D>
ContactNetwork contact_network(const Configuration<D>& c, double tolerance,
                               const std::array<bool, 2 * D>& walls) {
  ContactNetwork out;
  out.gap_tolerance = tolerance;
  const std::size_t n = c.size();
  out.smallest_open_gap = std::numeric_limits<double>::infinity();
  // Pairs within 1.1 of their contact distance: the contacts and the nearest open gaps.
  for_each_pair_near_contact(c, 1.1, [&](std::size_t i, std::size_t j, const Vec<D>&, double r2) {
    const double sigma = c.radius[i] + c.radius[j];
    const double gap = (std::sqrt(r2) - sigma) / sigma;
    if (gap >= 0.1) return;  // beyond 1.1 contact distances: no gap of the packing's
    if (gap < tolerance) {
      out.contacts.push_back({static_cast<std::uint32_t>(std::min(i, j)),
                              static_cast<std::uint32_t>(std::max(i, j)), gap});
      out.largest_contact_gap = std::max(out.largest_contact_gap, gap);
    } else {
      out.smallest_open_gap = std::min(out.smallest_open_gap, gap);
    }
  });
  std::sort(out.contacts.begin(), out.contacts.end(),
            [](const Contact& a, const Contact& b) { return a.i != b.i ? a.i < b.i : a.j < b.j; });
  int periodic_axes = 0;
  for (int a = 0; a < D; ++a) periodic_axes += c.periodic[a] ? 1 : 0;
  for (int f = 0; f < 2 * D; ++f) {
    if (!walls[f]) continue;
    if (c.periodic[f / 2])
      throw std::invalid_argument("contact_network: a wall on a periodic axis");
    const double edge = c.box[f / 2];
    for (std::uint32_t i = 0; i < n; ++i) {
      const double x = c.position[i][f / 2];
      const double gap = ((f % 2 == 0 ? x : edge - x) - c.radius[i]) / (2.0 * c.radius[i]);
      if (gap < tolerance) {
        out.wall_contacts.push_back({i, f, gap});
        out.largest_contact_gap = std::max(out.largest_contact_gap, gap);
      } else if (gap < 0.1) {  // as the pairs': within 1.1 diameters
        out.smallest_open_gap = std::min(out.smallest_open_gap, gap);
      }
    }
  }
  // Rattlers, removed until every particle left has D + 1 contacts among the others left.
  std::vector<std::uint32_t> count(n, 0);
  std::vector<std::vector<std::uint32_t>> partners(n);
  for (const Contact& k : out.contacts) {
    ++count[k.i];
    ++count[k.j];
    partners[k.i].push_back(k.j);
    partners[k.j].push_back(k.i);
  }
  for (const WallContact& k : out.wall_contacts) ++count[k.i];
  out.rattler.assign(n, 0);
  std::vector<std::uint32_t> pending;
  for (std::uint32_t i = 0; i < n; ++i)
    if (count[i] < D + 1) pending.push_back(i);
  while (!pending.empty()) {
    const std::uint32_t i = pending.back();
    pending.pop_back();
    if (out.rattler[i] != 0) continue;
    out.rattler[i] = 1;
    ++out.rattlers;
    for (std::uint32_t j : partners[i]) {
      if (out.rattler[j] != 0) continue;
      if (--count[j] < D + 1) pending.push_back(j);
    }
  }
  for (const Contact& k : out.contacts)
    if (out.rattler[k.i] == 0 && out.rattler[k.j] == 0) ++out.backbone_contacts;
  for (const WallContact& k : out.wall_contacts)
    if (out.rattler[k.i] == 0) ++out.backbone_wall_contacts;
  const double dn = static_cast<double>(n);
  const double backbone = dn - static_cast<double>(out.rattlers);
  out.coordination = dn > 0 ? (2.0 * static_cast<double>(out.contacts.size()) +
                               static_cast<double>(out.wall_contacts.size())) /
                                  dn
                            : 0.0;
  out.backbone_coordination = backbone > 0 ? (2.0 * static_cast<double>(out.backbone_contacts) +
                                              static_cast<double>(out.backbone_wall_contacts)) /
                                                 backbone
                                           : 0.0;
  out.rattler_fraction = dn > 0 ? static_cast<double>(out.rattlers) / dn : 0.0;
  out.excess_contacts =
      static_cast<std::int64_t>(out.backbone_contacts + out.backbone_wall_contacts) -
      (static_cast<std::int64_t>(D) *
           (static_cast<std::int64_t>(n) - static_cast<std::int64_t>(out.rattlers)) -
       periodic_axes);
  return out;
}

template ContactNetwork contact_network<2>(const Configuration<2>&, double,
                                           const std::array<bool, 4>&);
template ContactNetwork contact_network<3>(const Configuration<3>&, double,
                                           const std::array<bool, 6>&);

}  // namespace kairos
