#include "engine/pair_steps.hpp"

#include <algorithm>

#include "core/error.hpp"

namespace kairos {

ZoneTable::ZoneTable(const StepTable& t) {
  t.check();
  if (t.boundary.size() > 0xfffe) throw InputError("a step table may have at most 65534 steps");
  for (const double r : t.boundary) r2.push_back(r * r);
  energy.push_back(t.beyond);
  energy.insert(energy.end(), t.energy.begin(), t.energy.end());
  core_zone = static_cast<std::uint16_t>(t.energy.size());
}

PairSteps::PairSteps(const std::vector<StepTable>& tables, const std::vector<int>& pair_table,
                     std::uint32_t species, std::size_t n)
    : species_(species), list_(n), seen_(n, 0) {
  if (tables.size() >= kHard) throw InputError("too many step tables (at most 65534)");
  for (const StepTable& t : tables) {
    tables_.emplace_back(t);
    count_.emplace_back(tables_.back().energy.size(), 0);
  }
  for (const int k : pair_table)
    pair_table_.push_back(k < 0 ? kHard : static_cast<std::uint16_t>(k));
}

double PairSteps::max_range() const {
  double r2 = 0.0;
  for (const ZoneTable& t : tables_) r2 = std::max(r2, t.r2.front());
  return std::sqrt(r2);
}

PairSteps::Zone PairSteps::find(std::uint32_t i, std::uint32_t j, std::uint16_t fallback) const {
  for (const Entry& e : list_[i])
    if (e.partner == j) return e.zone;
  return {fallback, 0};
}

void PairSteps::insert_or_update(std::uint32_t i, std::uint32_t j, Zone z) {
  for (Entry& e : list_[i]) {
    if (e.partner == j) {
      e.zone = z;
      return;
    }
  }
  list_[i].push_back({j, z});
}

void PairSteps::erase(std::uint32_t i, std::uint32_t j) {
  auto& l = list_[i];
  for (std::size_t k = 0; k < l.size(); ++k) {
    if (l[k].partner == j) {
      l[k] = l.back();
      l.pop_back();
      return;
    }
  }
}

void PairSteps::set(std::uint32_t i, std::uint32_t j, Zone z) {
  const Zone listed = find(i, j, kHard);
  if (listed.table != kHard) --count_[listed.table][listed.zone];
  if (z.zone == 0 && !bonded(z.table)) {
    erase(i, j);
    erase(j, i);
  } else {
    insert_or_update(i, j, z);
    insert_or_update(j, i, z);
    ++count_[z.table][z.zone];
  }
}

double PairSteps::energy() const {
  double u = 0.0;
  for (std::size_t t = 0; t < tables_.size(); ++t)
    for (std::size_t z = 0; z < count_[t].size(); ++z)
      if (count_[t][z] > 0) u += static_cast<double>(count_[t][z]) * tables_[t].energy[z];
  return u;
}

void PairSteps::renumber(const std::vector<std::uint32_t>& new_index) {
  std::vector<std::vector<Entry>> moved(list_.size());
  for (std::uint32_t old = 0; old < list_.size(); ++old) {
    auto& l = moved[new_index[old]];
    l = std::move(list_[old]);
    for (Entry& e : l) e.partner = new_index[e.partner];
  }
  list_.swap(moved);
  std::fill(seen_.begin(), seen_.end(), 0);
  epoch_ = 0;
}

// In the caller's order (by i, then j) without a global sort: particles visited in caller
// order, each one's short list sorted.
std::vector<PairZone> PairSteps::export_zones(const std::uint32_t* id) const {
  const auto n = static_cast<std::uint32_t>(list_.size());
  std::vector<std::uint32_t> internal(n);
  for (std::uint32_t k = 0; k < n; ++k) internal[id[k]] = k;
  std::vector<PairZone> out;
  std::vector<PairZone> mine;
  for (std::uint32_t c = 0; c < n; ++c) {
    mine.clear();
    for (const Entry& e : list_[internal[c]])
      if (id[e.partner] > c) mine.push_back({c, id[e.partner], e.zone.zone});
    std::sort(mine.begin(), mine.end(),
              [](const PairZone& x, const PairZone& y) { return x.j < y.j; });
    out.insert(out.end(), mine.begin(), mine.end());
  }
  return out;
}

}  // namespace kairos
