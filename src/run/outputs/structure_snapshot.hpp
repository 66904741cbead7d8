// The configuration the structure analyses read (analysis/structure.hpp; the outputs rdf.tsv,
// sk.tsv and bond_order.tsv): every particle's position now (wrapped into the box along
// periodic axes), species and radius, read from the integrator's state in blocks
// (core/state_blocks.hpp) at most once per moment: analyses sampled at the same moment share
// one read. It keeps these arrays (D + 1.5 doubles per particle) between samples.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "analysis/neighbour_pairs.hpp"
#include "run/integrator.hpp"

namespace kairos {

template <int D>
class StructureSnapshot {
 public:
  // The configuration at the integrator's present (read again only when its time, events or
  // collisions moved since the last read).
  const Configuration<D>& at(const Integrator<D>& integrator);

  // Of the last read: the species' names (the state's; "0", "1", ... where it names none), how
  // many particles each has, and each one's radius (NaN where its particles differ).
  const std::vector<std::string>& species_names() const { return names_; }
  const std::vector<std::size_t>& counts() const { return counts_; }
  const std::vector<double>& species_radius() const { return radius_; }
  double largest_radius() const;

 private:
  Configuration<D> configuration_;
  std::vector<std::string> names_;
  std::vector<std::size_t> counts_;
  std::vector<double> radius_;
  bool read_ = false;
  double time_ = 0.0;
  std::uint64_t events_ = 0, collisions_ = 0;
};

}  // namespace kairos
