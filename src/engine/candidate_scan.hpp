// The innermost loop of event-driven hard spheres: test one particle against its candidate
// partners and keep the soonest contact.
//
// Two implementations with bit-identical results: a scalar loop (any x86-64 or other CPU) and
// an AVX-512 loop that tests eight candidates at once without a branch per pair. Roughly half
// of all pairs are receding, at random, so the scalar loop's early exit mispredicts often; the
// vector loop computes every lane and masks instead. Both evaluate the same expressions in the
// same order with no fused multiply-add (the project builds with -ffp-contract=off), and both
// pick the first candidate in list order among equal contact times, so the choice of loop never
// changes a trajectory. The engine picks the vector loop when the CPU has AVX-512F.
#pragma once

#include <cstdint>
#include <vector>

#include "core/vec.hpp"
#include "dynamics/collision_time.hpp"
#include "engine/hot_record.hpp"
#include "engine/pair_steps.hpp"
#include "engine/relative_motion.hpp"

namespace kairos {

// Records are read through a raw base pointer: field f of record j sits at
// base[j * kStride + f] (kStride doubles per record): position 0..D-1, velocity D..2D-1,
// local time 2D.
template <int D>
struct CandidateScan {
  const double* records = nullptr;  // HotRecord array as doubles
  int stride = 0;                   // doubles per record
  // AVX-512 loops: read the records of eight candidates by one load each and a transpose
  // instead of one gather per field (the same values; faster where gathers are slow).
  bool row_loads = false;
  const std::uint32_t* candidates = nullptr;
  const std::uint32_t* shift_index = nullptr;  // per candidate, into shifts (0: no shift)
  const Vec<D>* shifts = nullptr;
  bool any_shift = false;  // false: shift_index is not read, no candidate is shifted
  std::uint32_t count = 0;
  // Contact distance: sigma_i + radius of the candidate (radius from its kind), or a constant.
  bool uniform = true;
  double sigma = 0.0;                       // uniform: the pair contact distance
  double radius_i = 0.0;                    // non-uniform: this particle's radius
  const std::uint16_t* kind = nullptr;      // non-uniform: per particle
  const double* kind_radius = nullptr;      // non-uniform: per kind
  const double* particle_radius = nullptr;  // non-uniform, per particle (then kinds unused)
  // Uniform acceleration (gravity) felt by every candidate: their positions and velocities at
  // time t gain g dt^2/2 and g dt. The pair's relative motion stays a straight line.
  const double* accel = nullptr;       // g (kAccelerated loops only)
  const double* half_accel = nullptr;  // g / 2
  // Soft spheres with deferred releases: a record whose local time lies after t belongs to a
  // particle still inside a contact (its record already holds the motion after the release).
  // Both loops skip such candidates and append their indices (into `candidates`) to
  // delayed[0 .. *delayed_count) (room for count + 8 entries); the caller tests them.
  std::uint32_t* delayed = nullptr;
  std::uint32_t* delayed_count = nullptr;
};

inline constexpr std::uint32_t kNoCandidate = 0xffffffffu;

// A non-uniform scan's radius of particle j: its own, or its kind's.
template <int D>
inline double radius_of_candidate(const CandidateScan<D>& s, std::uint32_t j) {
  return s.particle_radius != nullptr ? s.particle_radius[j] : s.kind_radius[s.kind[j]];
}

// Candidate k's record and its time to t (dtj); null for a record whose local time lies after t
// (a deferred soft contact), which is listed in s.delayed instead.
template <int D>
inline const double* record_at(const CandidateScan<D>& s, std::uint32_t k, double t, double& dtj) {
  const double* rec =
      s.records + static_cast<std::size_t>(s.candidates[k]) * static_cast<std::size_t>(s.stride);
  dtj = t - rec[2 * D];
  if (dtj < 0.0) [[unlikely]] {
    if (s.delayed != nullptr) s.delayed[(*s.delayed_count)++] = k;
    return nullptr;
  }
  return rec;
}

// Scalar reference. Returns the index (into `candidates`) of the soonest contact earlier than
// t + best and lowers best to it; kNoCandidate if none.
// kAccelerated: the loop with gravity's terms (s.accel must be set); a separate
// instantiation keeps them out of the hard-sphere loop.
template <int D, bool kAccelerated = false>
std::uint32_t scan_candidates_scalar(const CandidateScan<D>& s, double t, const Vec<D>& xi,
                                     const Vec<D>& vi, double& best) {
  std::uint32_t found = kNoCandidate;
  const Vec<D> no_shift{};
  for (std::uint32_t k = 0; k < s.count; ++k) {
    const std::uint32_t j = s.candidates[k];
    double dtj;
    const double* rec = record_at(s, k, t, dtj);
    if (rec == nullptr) [[unlikely]]
      continue;
    const Vec<D>& shift = s.any_shift ? s.shifts[s.shift_index[k]] : no_shift;
    const RelativeMotion p =
        relative_motion_at<D, kAccelerated>(xi, vi, rec, dtj, shift, s.half_accel, s.accel);
    const double sigma = s.uniform ? s.sigma : s.radius_i + radius_of_candidate(s, j);
    double dt;
    if (!contact_before(p, sigma * sigma, best, dt)) continue;
    if (dt < best) {
      best = dt;
      found = k;
    }
  }
  return found;
}

// scan_candidates_scalar for growing spheres (engine/growth.hpp): the contact distance is the
// loops' sigma (the radii at the growth's origin) times `scale`, growing at sigma * rate.
// `self` (the predicted particle) is skipped: with itself, a growing particle would overlap at
// once. scan_candidates_growing_avx512 gives the same bits.
template <int D>
std::uint32_t scan_candidates_growing(const CandidateScan<D>& s, std::uint32_t self, double t,
                                      const Vec<D>& xi, const Vec<D>& vi, double scale, double rate,
                                      double& best) {
  std::uint32_t found = kNoCandidate;
  const Vec<D> no_shift{};
  for (std::uint32_t k = 0; k < s.count; ++k) {
    const std::uint32_t j = s.candidates[k];
    if (j == self) continue;
    double dtj;
    const double* rec = record_at(s, k, t, dtj);
    if (rec == nullptr) [[unlikely]]
      continue;
    const Vec<D>& shift = s.any_shift ? s.shifts[s.shift_index[k]] : no_shift;
    const RelativeMotion p = relative_motion_at<D>(xi, vi, rec, dtj, shift);
    const double sigma0 = s.uniform ? s.sigma : s.radius_i + radius_of_candidate(s, j);
    double dt;
    if (!growing_contact_before(p, sigma0 * scale, sigma0 * rate, best, dt)) continue;
    best = dt;
    found = k;
  }
  return found;
}

// The start of a soft contact (EventEngine::try_place), in one pass over the candidates: does
// the placed particle (at `placed`, frozen at `frozen_velocity` for `span` from time t) overlap a
// candidate now (overlap), or meet one while frozen (met)? With `predict`, also the soonest
// contact of its motion after the release (at xi with velocity vi at time t, earlier than
// t + best, lowering best) exactly as the scan loops find it: the same expressions in the same
// order, the lowest index among equal times. Candidates skip_a and skip_b (the pair itself) are
// ignored; candidates in deferred contacts are listed as by the scan loops (not after an
// overlap) and left to the caller. The AVX-512 version gives the same answer.
template <int D>
struct ContactProbe {
  Vec<D> placed{}, frozen_velocity{};
  double span = 0.0;
  std::uint32_t skip_a = 0, skip_b = 0;
  bool predict = false;
};

struct ContactProbeResult {
  bool overlap = false;
  bool met = false;
  std::uint32_t found = kNoCandidate;  // index into candidates (predict only)
};

template <int D>
ContactProbeResult probe_contact_scalar(const CandidateScan<D>& s, double t,
                                        const ContactProbe<D>& probe, const Vec<D>& xi,
                                        const Vec<D>& vi, double& best) {
  ContactProbeResult out;
  const Vec<D> no_shift{};
  for (std::uint32_t k = 0; k < s.count; ++k) {
    const std::uint32_t j = s.candidates[k];
    if (j == probe.skip_a || j == probe.skip_b) continue;
    double dtj;
    const double* rec = record_at(s, k, t, dtj);
    if (rec == nullptr) [[unlikely]]
      continue;
    const Vec<D>& shift = s.any_shift ? s.shifts[s.shift_index[k]] : no_shift;
    // The placed particle, frozen, and its motion after the release.
    const RelativeMotion placed =
        relative_motion_at<D>(probe.placed, probe.frozen_velocity, rec, dtj, shift);
    const double sigma = s.uniform ? s.sigma : s.radius_i + radius_of_candidate(s, j);
    const double sigma2 = sigma * sigma;
    const double gap_placed = placed.r2 - sigma2;
    if (gap_placed < 0.0) {
      out.overlap = true;
      return out;
    }
    double met_after;
    if (contact_before(placed, sigma2, probe.span, met_after) && met_after < probe.span)
      out.met = true;
    if (!probe.predict) continue;
    double dt;
    if (!contact_before(relative_motion_at<D>(xi, vi, rec, dtj, shift), sigma2, best, dt)) continue;
    if (dt < best) {
      best = dt;
      out.found = k;
    }
  }
  return out;
}

// AVX-512 version (candidate_scan.cpp); only called when cpu_has_avx512().
template <int D>
ContactProbeResult probe_contact_avx512(const CandidateScan<D>& s, double t,
                                        const ContactProbe<D>& probe, const Vec<D>& xi,
                                        const Vec<D>& vi, double& best);

// The cell lists of a neighbourhood: `cells` lists, the c-th starting at heads[cell[c]] and
// linked through next[] to `end`; each list's members get the tag shift[c] (an index into the
// periodic shifts), or no tag when shift is null.
struct Neighbourhood {
  const std::uint32_t* heads;
  const std::uint32_t* next;
  std::uint32_t end;
  const std::uint32_t* cell;   // cell indices
  const std::uint32_t* shift;  // per cell, or null
  int cells;                   // at most 32
};

// Writes the first and second members of every list to out (and their tags to out_shift when
// the neighbourhood has shifts) with AVX-512 compress stores: all first members in cell order,
// then all second members. Members after the second are rare; their lists' third members are
// stored in third/third_shift (count in n_third) for the caller to follow. out needs room for
// 2 * cells entries. Returns the number written to out.
std::uint32_t gather_lists_avx512(const Neighbourhood& nb, std::uint32_t* out,
                                  std::uint32_t* out_shift, std::uint32_t* third,
                                  std::uint32_t* third_shift, std::uint32_t& n_third);

// Whether this CPU runs the AVX-512 loop.
bool cpu_has_avx512();
// Whether AVX-512 gathers are fast on this CPU (Intel's cores), which decides two things. The
// cell lists: gather_lists_avx512 beats walking them one by one on Intel; on AMD's Zen 4 the
// 16-lane 32-bit gathers are slow enough that the scalar walk made a dilute hard-sphere run 1.4x
// faster (either walk lists the same candidates; only their order differs, which decides only
// exact ties of contact times). The candidate records: on Zen 4 one load per record and a
// transpose (CandidateScan::row_loads) beat a gather per field by 1.05-1.19x (the same values).
// Measured on an AMD EPYC; docs/performance.md.
bool cpu_gathers_fast();

// AVX-512 loop (defined in candidate_scan.cpp); same contract and result as the scalar loop.
template <int D, bool kAccelerated = false>
std::uint32_t scan_candidates_avx512(const CandidateScan<D>& s, double t, const Vec<D>& xi,
                                     const Vec<D>& vi, double& best);

// AVX-512 loop for growing spheres (candidate_scan.cpp); the same contract and result as
// scan_candidates_growing, per-particle radii (s.particle_radius) included. No deferred soft
// contacts: growth refuses soft spheres.
template <int D>
std::uint32_t scan_candidates_growing_avx512(const CandidateScan<D>& s, std::uint32_t self,
                                             double t, const Vec<D>& xi, const Vec<D>& vi,
                                             double scale, double rate, double& best);

// The candidate loop of stepped potentials (EventEngine::scan_stepped): the hard-sphere loop's
// records and candidates (`base`: its contact-distance fields are not read), the predicted
// particle (skipped), and the capture map as PairSteps::load() left it. A candidate whose stamp
// carries `epoch` is listed, in the zone and table the stamp names; any other sits in zone 0 of
// its species pair's table, where only an approach to the outermost boundary (squared distance
// row_reach2[its kind], the contact distance for a pair without steps) counts.
template <int D>
struct SteppedScan {
  CandidateScan<D> base;
  std::uint32_t self = 0;
  const std::uint64_t* stamps = nullptr;  // per particle: epoch << 32 | table << 16 | zone
  std::uint32_t epoch = 0;
  const std::uint16_t* kind = nullptr;          // per particle (padded by one), null: a single kind
  const double* row_reach2 = nullptr;           // per kind
  const double* flat_r2 = nullptr;              // every table's squared boundaries, back to back
  const std::uint32_t* table_offset = nullptr;  // per table, into flat_r2; null: one table
  // Scratch for the listed candidates, held back and tested together after the others: room
  // for base.count + 8 entries each (r.r, r.g, g.g, stamp, index into base.candidates).
  double* held_r2 = nullptr;
  double* held_rg = nullptr;
  double* held_g2 = nullptr;
  std::uint64_t* held_stamp = nullptr;
  std::uint32_t* held_index = nullptr;
  const ZoneTable* tables = nullptr;  // the scalar loop's event times (ZoneTable::event_time)
};

// The stepped loops' scratch, kept between predictions: per kind, the squared reach of the
// predicted particle's pairs, and (AVX-512 loop) room for the held candidates.
struct SteppedScanScratch {
  std::vector<double> row_reach2;
  std::vector<double> held;  // r.r, r.g, g.g of each held candidate, in three runs
  std::vector<std::uint64_t> held_stamp;
  std::vector<std::uint32_t> held_index;
  // Points the scan's held arrays at room for `count` candidates.
  template <int D>
  void hold(SteppedScan<D>& scan, std::uint32_t count) {
    const std::size_t room = count + 8;
    if (held_index.size() < room) {
      held.resize(3 * room);
      held_stamp.resize(room);
      held_index.resize(room);
    }
    const std::size_t stride = held_index.size();
    scan.held_r2 = held.data();
    scan.held_rg = held.data() + stride;
    scan.held_g2 = held.data() + 2 * stride;
    scan.held_stamp = held_stamp.data();
    scan.held_index = held_index.data();
  }
};

// Scalar reference of the stepped loop: per candidate, the zone from the capture map's stamps
// and the time to the zone's next boundary (for a pair without steps, its contact). Most
// candidates sit beyond every step (zone 0): for them only an approach to the outermost
// boundary counts, and the hard-sphere test (contact_before) applies. Returns the index (into
// base.candidates) of the soonest event earlier than t + best and lowers best to it.
template <int D, bool kAccelerated = false>
std::uint32_t scan_stepped_scalar(const SteppedScan<D>& s, double t, const Vec<D>& xi,
                                  const Vec<D>& vi, double& best) {
  const CandidateScan<D>& c = s.base;
  // Read once: the loop's stores to `best` could alias them for the compiler.
  const std::uint32_t* candidates = c.candidates;
  const std::uint64_t* stamps = s.stamps;
  const std::uint16_t* kind = s.kind;
  const double* row_reach2 = s.row_reach2;
  const ZoneTable* tables = s.tables;
  const std::uint32_t self = s.self, epoch = s.epoch, count = c.count;
  // The engine's records (HotRecord<D>: its stride known here, as the engine's own loops had).
  constexpr std::size_t kStride = sizeof(HotRecord<D>) / sizeof(double);
  std::uint32_t found = kNoCandidate;
  double soonest = best;
  const Vec<D> no_shift{};
  for (std::uint32_t k = 0; k < count; ++k) {
    const std::uint32_t j = candidates[k];
    if (j == self) continue;
    const Vec<D>& shift = c.any_shift ? c.shifts[c.shift_index[k]] : no_shift;
    const double* rec = c.records + static_cast<std::size_t>(j) * kStride;
    const double dtj = t - rec[2 * D];
    const RelativeMotion p =
        relative_motion_at<D, kAccelerated>(xi, vi, rec, dtj, shift, c.half_accel, c.accel);
    const std::uint16_t sj = kind != nullptr ? kind[j] : 0;
    const std::uint64_t stamp = stamps[j];
    double dt;
    if ((stamp >> 32) != epoch || static_cast<std::uint16_t>(stamp) == 0) {  // zone 0
      if (!contact_before(p, row_reach2[sj], soonest, dt)) continue;
    } else {
      const ZoneTable& table = tables[static_cast<std::uint16_t>(stamp >> 16)];
      dt = table.event_time(static_cast<std::uint16_t>(stamp), p.r2, p.rg, p.g2);
    }
    if (dt < soonest) {
      soonest = dt;
      found = k;
    }
  }
  best = soonest;
  return found;
}

// AVX-512 version of scan_stepped_scalar: the same zone-0 test (cheap bound, then
// the approach to the outermost boundary) and, for listed lanes, ZoneTable::event_time, with
// the same expressions in the same order, so the result is bit-identical. Returns the index
// (into base.candidates) of the soonest event earlier than t + best and lowers best to it;
// kNoCandidate if none. Only called when cpu_has_avx512().
template <int D, bool kAccelerated = false>
std::uint32_t scan_stepped_avx512(const SteppedScan<D>& s, double t, const Vec<D>& xi,
                                  const Vec<D>& vi, double& best);

}  // namespace kairos
