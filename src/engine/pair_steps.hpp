// Stepped potentials inside the engine: the step tables in the form the event loops read, and
// the capture map, which says in which zone of its table every pair inside some step sits.
//
// Zones of a table with boundaries r_0 (cut-off) > r_1 > ... > r_K (hard core): zone 0 lies
// beyond r_0, zone z (1 <= z <= K) between r_z and r_{z-1}. A pair in zone z meets its inner
// boundary r_z when it approaches (at z = K that is the hard core: a collision) and its outer
// boundary r_{z-1} when it recedes. Which of the two an event is follows from the sign of r.g
// at the event, and the zone from the map, never from the distance: a pair that bounced off a
// step sits on it, where round-off could put it on either side.
//
// The map is a short list per particle of (partner, table, zone) entries, each pair listed
// under both particles; a non-bonded pair is listed only while inside its cut-off, a bonded
// pair always. Before a prediction of particle i, load(i) stamps i's entries into an array
// indexed by partner, so a candidate's zone is one read (lookup()).
//
// The lists live in one array of fixed-stride slabs, particle i's at i * stride (a count, then
// the entries): its address follows from i alone, so a list costs one cache miss, not two
// dependent ones (a vector header, then its heap block). The stride grows (every slab moved)
// when some list outgrows it: 8 entries (one cache line) hold a square-well fluid's lists.
#pragma once

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "core/huge_page_allocator.hpp"
#include "core/particle_system.hpp"
#include "dynamics/collision_time.hpp"
#include "interactions/step_potential.hpp"

namespace kairos {

// A StepTable as the event loops read it.
struct ZoneTable {
  std::vector<double> r2;       // squared boundaries r_0^2 > ... > r_K^2
  std::vector<double> energy;   // energy of zone z = 0..K (zone 0: beyond the cut-off)
  std::uint16_t core_zone = 0;  // K: the zone next to the hard core
  // A dashpot by steps (StepTable::damping; 0: none): a crossing between zones z and z +- 1
  // costs damping |v_n| width[deeper of the two], width[z] = r_{z-1} - r_z (z >= 1; width[0]
  // unused).
  double damping = 0.0;
  bool force_zero = true;
  std::vector<double> width;

  explicit ZoneTable(const StepTable& t);
  // The zone of a pair at squared distance r2 (a pair on a boundary counts as outside it);
  // core_zone for a pair inside the core.
  std::uint16_t zone_at(double r2_pair) const {
    std::uint16_t z = 0;
    while (z < core_zone && r2_pair < r2[z]) ++z;
    return z;
  }
  // Time until a pair in `zone`, at squared distance r2_pair with r.g = rg and g.g = g2, meets
  // the next boundary: its inner one if it approaches and reaches it, else its outer one (kNever
  // in zone 0). Stable roots; 0 when round-off has the pair already past the boundary it moves
  // towards.
  double event_time(std::uint32_t zone, double r2_pair, double rg, double g2) const {
    if (rg < 0.0) {
      const double gap = r2_pair - r2[zone];
      const double disc = rg * rg - g2 * gap;
      if (disc > 0.0) {
        const double dt = gap / (-rg + std::sqrt(disc));
        return dt > 0.0 ? dt : 0.0;
      }
    }
    if (zone == 0 || !(g2 > 0.0)) return kNever;
    // The later root of g2 t^2 + 2 rg t + gap = 0 (gap < 0 inside the outer boundary).
    const double gap = r2_pair - r2[zone - 1];
    const double disc = rg * rg - g2 * gap;
    if (!(disc > 0.0)) return 0.0;  // never inside it again: leave now
    const double root = std::sqrt(disc);
    const double dt = rg > 0.0 ? -gap / (rg + root) : (root - rg) / g2;
    return dt > 0.0 ? dt : 0.0;
  }
};

class PairSteps {
 public:
  static constexpr std::uint16_t kHard = 0xffff;  // table of a pair without steps
  struct Zone {
    std::uint16_t table = kHard;
    std::uint16_t zone = 0;
  };
  struct Entry {
    std::uint32_t partner;
    Zone zone;
  };

  PairSteps() = default;
  // pair_table: species x species table indices (-1: hard); n particles.
  PairSteps(const std::vector<StepTable>& tables, const std::vector<int>& pair_table,
            std::uint32_t species, std::size_t n);

  const ZoneTable& table(std::uint16_t t) const { return tables_[t]; }
  std::size_t tables() const { return tables_.size(); }
  std::uint16_t pair_table(std::uint32_t a, std::uint32_t b) const {
    return pair_table_.empty() ? kHard : pair_table_[a * species_ + b];
  }
  bool bonded(std::uint16_t t) const { return std::isinf(tables_[t].energy[0]); }
  // The largest cut-off of any table: cells must be at least this wide.
  double max_range() const;

  // Makes i's entries visible to lookup() (until the next load).
  void load(std::uint32_t i) {
    if (++epoch_ == 0) {  // wrapped after 2^32 loads: forget every stamp
      std::fill(seen_.begin(), seen_.end(), 0);
      epoch_ = 1;
    }
    const std::uint64_t e = std::uint64_t{epoch_} << 32;
    const Entry* slab = slab_of(i);
    const std::uint32_t n = slab[0].partner;
    for (std::uint32_t k = 1; k <= n; ++k)
      seen_[slab[k].partner] = e | (std::uint64_t{slab[k].zone.table} << 16) | slab[k].zone.zone;
  }
  // The zone of (loaded particle, j); `fallback` (the species pair's table) in zone 0 if the
  // pair is not listed.
  Zone lookup(std::uint32_t j, std::uint16_t fallback) const {
    const std::uint64_t s = seen_[j];
    if ((s >> 32) != epoch_) return {fallback, 0};
    return {static_cast<std::uint16_t>(s >> 16), static_cast<std::uint16_t>(s)};
  }
  // What lookup() reads, for the vector candidate loop: the stamps (per particle, epoch << 32 |
  // table << 16 | zone; a stamp whose epoch is not epoch() belongs to an unlisted pair), and
  // every table's squared boundaries back to back, table t's from flat_r2()[table_offset()[t]].
  const std::uint64_t* stamps() const { return seen_.data(); }
  std::uint32_t epoch() const { return epoch_; }
  const double* flat_r2() const { return flat_r2_.data(); }
  const std::uint32_t* table_offset() const { return table_offset_.data(); }
  // The same without load(), by a scan of i's list.
  Zone find(std::uint32_t i, std::uint32_t j, std::uint16_t fallback) const;
  // Moves pair (i, j) into zone z: listed, or unlisted if z is zone 0 of a non-bonded table.
  void set(std::uint32_t i, std::uint32_t j, Zone z);

  // Particle i's entries: [entries_begin(i), entries_begin(i) + entry_count(i)).
  const Entry* entries_begin(std::uint32_t i) const { return slab_of(i) + 1; }
  std::uint32_t entry_count(std::uint32_t i) const { return slab_of(i)[0].partner; }
  // Potential energy: the sum over listed pairs of their zone's energy (from the counts per
  // zone: exact, and the same bits whatever the order of the lists).
  double energy() const;
  // Particles renumbered: new_index[old] is the new number.
  void renumber(const std::vector<std::uint32_t>& new_index);
  // Every listed pair once, in the numbering given by id (internal -> caller's), i < j.
  std::vector<PairZone> export_zones(const std::uint32_t* id) const;
  // The map's own consistency: every entry mirrored under its partner with the same zone, no
  // pair with itself or listed twice, zones inside their tables, a non-bonded pair never listed
  // in zone 0, and the counts per (table, zone) those of the lists. "" if so, else the first
  // fault (particles in the engine's numbering).
  std::string check() const;

 private:
  // Position of j in i's slab (1..count), 0 if absent.
  std::uint32_t slot(std::uint32_t i, std::uint32_t j) const;
  void append(std::uint32_t i, std::uint32_t j, Zone z);  // j not in i's list
  void remove(std::uint32_t i, std::uint32_t k);          // the entry at slot k of i's list
  // Slab of particle i: slot 0 holds the entry count (in `partner`), slots 1.. the entries.
  Entry* slab_of(std::uint32_t i) { return slabs_.data() + std::size_t{i} * stride_; }
  const Entry* slab_of(std::uint32_t i) const { return slabs_.data() + std::size_t{i} * stride_; }
  void grow_slabs();

  std::vector<ZoneTable> tables_;
  std::vector<std::uint16_t> pair_table_;
  std::uint32_t species_ = 0;
  std::size_t n_ = 0;        // particles
  std::size_t stride_ = 8;   // slots per slab (count + entries)
  HugeVector<Entry> slabs_;  // n_ * stride_
  // Listed pairs per (table, zone), kept as pairs move: energy() without a pass over the lists,
  // and independent of their order.
  std::vector<std::vector<std::uint64_t>> count_;
  std::vector<std::uint64_t> seen_;  // per particle: epoch << 32 | table << 16 | zone
  std::uint32_t epoch_ = 0;
  std::vector<double> flat_r2_;
  std::vector<std::uint32_t> table_offset_;
};

}  // namespace kairos
