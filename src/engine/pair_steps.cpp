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
  damping = t.damping;
  force_zero = t.force_zero;
  width.assign(t.boundary.size(), 0.0);
  for (std::size_t z = 1; z < t.boundary.size(); ++z) width[z] = t.boundary[z - 1] - t.boundary[z];
}

PairSteps::PairSteps(const std::vector<StepTable>& tables, const std::vector<int>& pair_table,
                     std::uint32_t species, std::size_t n)
    : species_(species), n_(n), slabs_(n * stride_, Entry{0, {}}), seen_(n, 0) {
  if (tables.size() >= kHard) throw InputError("too many step tables (at most 65534)");
  for (const StepTable& t : tables) {
    tables_.emplace_back(t);
    count_.emplace_back(tables_.back().energy.size(), 0);
    table_offset_.push_back(static_cast<std::uint32_t>(flat_r2_.size()));
    flat_r2_.insert(flat_r2_.end(), tables_.back().r2.begin(), tables_.back().r2.end());
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
  const Entry* slab = slab_of(i);
  const std::uint32_t n = slab[0].partner;
  for (std::uint32_t k = 1; k <= n; ++k)
    if (slab[k].partner == j) return slab[k].zone;
  return {fallback, 0};
}

// Every slab moved to a stride half as large again (rounded to whole cache lines).
void PairSteps::grow_slabs() {
  const std::size_t stride = (stride_ + stride_ / 2 + 7) / 8 * 8;
  HugeVector<Entry> moved(n_ * stride, Entry{0, {}});
  for (std::size_t i = 0; i < n_; ++i) {
    const Entry* from = slabs_.data() + i * stride_;
    std::copy(from, from + 1 + from[0].partner, moved.data() + i * stride);
  }
  slabs_.swap(moved);
  stride_ = stride;
}

std::uint32_t PairSteps::slot(std::uint32_t i, std::uint32_t j) const {
  const Entry* slab = slab_of(i);
  const std::uint32_t n = slab[0].partner;
  for (std::uint32_t k = 1; k <= n; ++k)
    if (slab[k].partner == j) return k;
  return 0;
}

void PairSteps::append(std::uint32_t i, std::uint32_t j, Zone z) {
  if (slab_of(i)[0].partner + 1 >= stride_) grow_slabs();
  Entry* slab = slab_of(i);
  const std::uint32_t n = slab[0].partner + 1;
  slab[n] = {j, z};
  slab[0].partner = n;
}

void PairSteps::remove(std::uint32_t i, std::uint32_t k) {
  Entry* slab = slab_of(i);
  const std::uint32_t n = slab[0].partner;
  slab[k] = slab[n];
  slab[0].partner = n - 1;
}

// A pair is listed under both particles or neither: one scan of i's list tells which, and j's
// is scanned only to update or remove an entry it has.
void PairSteps::set(std::uint32_t i, std::uint32_t j, Zone z) {
  const bool unlisted = z.zone == 0 && !bonded(z.table);
  const std::uint32_t ki = slot(i, j);
  if (ki == 0) {
    if (unlisted) return;
    append(i, j, z);
    append(j, i, z);
    ++count_[z.table][z.zone];
    return;
  }
  const Zone was = slab_of(i)[ki].zone;
  --count_[was.table][was.zone];
  const std::uint32_t kj = slot(j, i);
  if (unlisted) {
    remove(i, ki);
    remove(j, kj);
  } else {
    slab_of(i)[ki].zone = z;
    slab_of(j)[kj].zone = z;
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
  HugeVector<Entry> moved(slabs_.size(), Entry{0, {}});
  for (std::uint32_t old = 0; old < n_; ++old) {
    const Entry* from = slab_of(old);
    Entry* to = moved.data() + std::size_t{new_index[old]} * stride_;
    const std::uint32_t n = from[0].partner;
    to[0].partner = n;
    for (std::uint32_t k = 1; k <= n; ++k) to[k] = {new_index[from[k].partner], from[k].zone};
  }
  slabs_.swap(moved);
  std::fill(seen_.begin(), seen_.end(), 0);
  epoch_ = 0;
}

std::string PairSteps::check() const {
  std::vector<std::vector<std::uint64_t>> counted(count_.size());
  for (std::size_t t = 0; t < count_.size(); ++t) counted[t].assign(count_[t].size(), 0);
  const auto pair = [](std::uint32_t i, std::uint32_t j) {
    return "pair " + std::to_string(i) + "," + std::to_string(j);
  };
  for (std::uint32_t i = 0; i < n_; ++i) {
    const Entry* slab = slab_of(i);
    const std::uint32_t n = slab[0].partner;
    if (n + 1 > stride_) return "particle " + std::to_string(i) + " lists more pairs than fit";
    for (std::uint32_t k = 1; k <= n; ++k) {
      const std::uint32_t j = slab[k].partner;
      const Zone z = slab[k].zone;
      if (j >= n_ || j == i) return "particle " + std::to_string(i) + " lists a bad partner";
      for (std::uint32_t m = 1; m < k; ++m)
        if (slab[m].partner == j) return pair(i, j) + " is listed twice";
      if (z.table >= tables_.size() || z.zone > tables_[z.table].core_zone)
        return pair(i, j) + " has a zone outside its table";
      if (z.zone == 0 && !bonded(z.table)) return pair(i, j) + " is listed beyond its cut-off";
      const std::uint32_t back = slot(j, i);
      if (back == 0) return pair(i, j) + " is listed under one particle only";
      const Zone mirrored = slab_of(j)[back].zone;
      if (mirrored.table != z.table || mirrored.zone != z.zone)
        return pair(i, j) + " has two different zones";
      if (i < j) ++counted[z.table][z.zone];
    }
  }
  if (counted != count_) return "the counts of pairs per zone (the potential energy) are off";
  return "";
}

// In the caller's order (by i, then j) without a global sort: particles visited in caller
// order, each one's short list sorted.
std::vector<PairZone> PairSteps::export_zones(const std::uint32_t* id) const {
  const auto n = static_cast<std::uint32_t>(n_);
  std::vector<std::uint32_t> internal(n);
  for (std::uint32_t k = 0; k < n; ++k) internal[id[k]] = k;
  std::vector<PairZone> out;
  std::vector<PairZone> mine;
  for (std::uint32_t c = 0; c < n; ++c) {
    mine.clear();
    const Entry* slab = slab_of(internal[c]);
    for (std::uint32_t k = 1; k <= slab[0].partner; ++k)
      if (id[slab[k].partner] > c) mine.push_back({c, id[slab[k].partner], slab[k].zone.zone});
    std::sort(mine.begin(), mine.end(),
              [](const PairZone& x, const PairZone& y) { return x.j < y.j; });
    out.insert(out.end(), mine.begin(), mine.end());
  }
  return out;
}

}  // namespace kairos
