// Stepped potentials in the event engine (docs/architecture.md, "Stepped potentials"): the
// capture map at the start, the candidate loop's set-up, and a pair event at a step. The zone
// tables and the map are engine/pair_steps.hpp; the step rule is interactions/step_potential.
#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <string_view>

#include "core/error.hpp"
#include "core/periodic.hpp"
#include "engine/candidate_scan.hpp"
#include "engine/event_engine.hpp"
#include "engine/relative_motion.hpp"
#include "interactions/step_potential.hpp"
#include "scheduler/binary_heap_queue.hpp"
#include "scheduler/calendar_queue.hpp"
#include "scheduler/tournament_tree_queue.hpp"

namespace kairos {

namespace {
constexpr std::uint32_t kNoPartner = EventSlot::kNoPartner;
}  // namespace

template <int D, class Queue>
Vec<D> EventEngine<D, Queue>::separation(std::uint32_t i, std::uint32_t j, double t) const {
  if (sheared_) {  // through the sliding images (a bonded pair across a y face)
    Vec<D> image_velocity;
    return sheared_separation(i, j, t, image_velocity);
  }
  Vec<D> r = position(i, t) - position(j, t);
  for (int a = 0; a < D; ++a)
    if (cells_.grid().periodic(a)) r[a] = minimum_image(r[a], box_[a]);
  return r;
}

// The capture map at the start: bonds first (each always listed), then the stored zones, or,
// for a fresh state, every non-bonded pair's zone from its distance.
template <int D, class Queue>
void EventEngine<D, Queue>::init_zones(const ParticleSystem<D>& s, StartMode mode) {
  if (!stepped_) return;
  const auto n = static_cast<std::uint32_t>(size());
  std::vector<std::uint32_t> internal(n);
  for (std::uint32_t k = 0; k < n; ++k) internal[id_[k]] = k;
  auto pair_name = [](std::uint32_t a, std::uint32_t b) {
    return std::to_string(a) + "-" + std::to_string(b);
  };
  for (const Bond& b : bonds_) {
    if (b.i >= n || b.j >= n || b.i == b.j) {
      throw InputError("bond " + pair_name(b.i, b.j) + " names a particle that does not exist");
    }
    if (b.type >= env_.bond_table.size()) {
      throw InputError("bond " + pair_name(b.i, b.j) + " has type " + std::to_string(b.type) +
                       " but only " + std::to_string(env_.bond_table.size()) +
                       " bond potential(s) are given");
    }
    const auto table = static_cast<std::uint16_t>(env_.bond_table[b.type]);
    const std::uint32_t i = internal[b.i], j = internal[b.j];
    const double r2 = norm2(separation(i, j, time_));
    const std::uint16_t zone = steps_.table(table).zone_at(r2);
    if (zone == 0 && !s.zones) {
      throw InputError("bond " + pair_name(b.i, b.j) + " is stretched to " +
                       std::to_string(std::sqrt(r2)) + ", beyond its maximum length " +
                       std::to_string(std::sqrt(steps_.table(table).r2[0])));
    }
    steps_.set(i, j, {table, zone});
  }
  if (s.zones) {
    for (const PairZone& z : *s.zones) {
      if (z.i >= n || z.j >= n || z.i == z.j) {
        throw InputError("the zone of pair " + pair_name(z.i, z.j) +
                         " names a particle that does not exist");
      }
      const std::uint32_t i = internal[z.i], j = internal[z.j];
      const PairSteps::Zone now =
          steps_.find(i, j, steps_.pair_table(species_of(i), species_of(j)));
      if (now.table == PairSteps::kHard || z.zone > steps_.table(now.table).core_zone ||
          (z.zone == 0 && !steps_.bonded(now.table))) {
        throw InputError("the stored zone " + std::to_string(z.zone) + " of pair " +
                         pair_name(z.i, z.j) + " does not fit its step potential");
      }
      steps_.set(i, j, {now.table, static_cast<std::uint16_t>(z.zone)});
    }
    return;
  }
  if (mode == StartMode::kResume) {
    throw InputError("cannot resume: the state carries no pair zones of the stepped potentials");
  }
  const Vec<D> no_shift{};
  for (std::uint32_t i = 0; i < n; ++i) {
    gather(hot_[i].cell, cells_.list(0));
    const CandidateList& list = cells_.list(0);
    const Vec<D> xi = position(i, time_);
    for (std::uint32_t k = 0; k < list.count; ++k) {
      const std::uint32_t j = list.ids[k];
      if (j <= i) continue;
      const std::uint16_t table = steps_.pair_table(species_of(i), species_of(j));
      if (table == PairSteps::kHard ||
          steps_.find(i, j, PairSteps::kHard).table != PairSteps::kHard)
        continue;  // no steps, or bonded
      const Vec<D>& shift = list.n_shifts > 1 ? list.shifts[list.shift[k]] : no_shift;
      const double r2 = norm2(xi - (position(j, time_) + shift));
      const std::uint16_t zone = steps_.table(table).zone_at(r2);
      if (zone > 0) steps_.set(i, j, {table, zone});
    }
  }
}

// The candidate loop of stepped potentials (scan_stepped_scalar, or eight candidates at a time
// by scan_stepped_avx512 with the same result), after the capture map's list of i is loaded.
template <int D, class Queue>
std::uint32_t EventEngine<D, Queue>::scan_stepped(const CandidateList& list, std::uint32_t i,
                                                  double t, double& best) {
  steps_.load(i);
  if (list.sheared) [[unlikely]]
    return scan_stepped_sheared(list, i, t, best);
  // Per kind of the candidate: the squared distance of its pair's outermost boundary with i
  // (the contact distance of a pair without steps).
  const std::uint32_t si = species_of(i);
  const double ri = radius_of(i);
  const std::size_t kinds = kinds_.size();
  step_scratch_.row_reach2.resize(kinds);
  for (std::size_t k = 0; k < kinds; ++k) {
    const std::uint16_t table = steps_.pair_table(si, kinds_[k].species);
    const double sigma = ri + kinds_[k].radius;
    step_scratch_.row_reach2[k] =
        table == PairSteps::kHard ? sigma * sigma : steps_.table(table).r2[0];
  }
  SteppedScan<D> scan{.base = scan_of(list, i, nullptr),  // its contact distances are not read
                      .self = i,
                      .stamps = steps_.stamps(),
                      .epoch = steps_.epoch(),
                      .kind = kind_.empty() ? nullptr : kind_.data(),
                      .row_reach2 = step_scratch_.row_reach2.data(),
                      .flat_r2 = steps_.flat_r2(),
                      .table_offset = steps_.tables() > 1 ? steps_.table_offset() : nullptr,
                      .tables = &steps_.table(0)};
  const HotRecord<D>& h = hot_[i];
  const Vec<D> xi = flight_position(h, t), vi = flight_velocity(h, t);
  std::uint32_t k;
  if (vector_scan_) {
    step_scratch_.hold(scan, list.count);
    k = accelerated_ ? scan_stepped_avx512<D, true>(scan, t, xi, vi, best)
                     : scan_stepped_avx512<D, false>(scan, t, xi, vi, best);
  } else {
    k = accelerated_ ? scan_stepped_scalar<D, true>(scan, t, xi, vi, best)
                     : scan_stepped_scalar<D, false>(scan, t, xi, vi, best);
  }
  return k == kNoCandidate ? kNoPartner : list.ids[k];
}

// A pair event under a stepped potential. Approaching, the pair meets its zone's inner boundary
// (the hard core in the innermost zone: returns false, an ordinary collision); receding, the
// outer one. It crosses into the next zone if its normal kinetic energy pays the step, else
// bounces (docs/physics.md#step-event); with a dashpot on the table the crossing also pays the
// dashpot's work, which counts as dissipated (docs/physics.md#spring-dashpot-by-steps).
template <int D, class Queue>
bool EventEngine<D, Queue>::step_pair(std::uint32_t i, std::uint32_t j, double t) {
  const PairSteps::Zone z = steps_.find(i, j, steps_.pair_table(species_of(i), species_of(j)));
  if (z.table == PairSteps::kHard) return false;
  advance_to(i, t);
  advance_to(j, t);
  HotRecord<D>& hi = hot_[i];
  HotRecord<D>& hj = hot_[j];
  // Under shear i meets an image of j, which moves with j's velocity plus u (boundaries/
  // lees_edwards.hpp): the step acts on the relative motion with that image, as a collision.
  Vec<D> u{};
  const Vec<D> r = sheared_ ? sheared_separation(i, j, t, u) : separation(i, j, t);
  const Vec<D> vj_before = hj.vel;
  const double r2 = norm2(r), rg = dot(r, hi.vel - (hj.vel + u));
  const ZoneTable& table = steps_.table(z.table);
  std::uint16_t next;
  if (rg < 0.0) {
    if (z.zone == table.core_zone) return false;
    next = static_cast<std::uint16_t>(z.zone + 1);
  } else {
    if (z.zone == 0) {  // a graze of the cut-off that round-off calls a miss: nothing happens
      predict_pair(i, j, t);
      return true;
    }
    next = static_cast<std::uint16_t>(z.zone - 1);
  }
  const double distance = std::sqrt(r2);
  const double mi = mass_of(i), mj = mass_of(j);
  StepOutcome out;
  if (table.damping > 0.0) [[unlikely]] {  // docs/physics.md#spring-dashpot-by-steps
    const DissipativeStepOutcome d = dissipative_step_event(
        mi * mj / (mi + mj), rg / distance, table.energy[next] - table.energy[z.zone],
        table.damping, table.width[std::max(next, z.zone)], table.force_zero);
    out = {d.crosses, d.impulse};
    counters_.dissipated_in_collisions += d.dissipated;
  } else {
    out = step_event(mi * mj / (mi + mj), rg / distance, table.energy[next] - table.energy[z.zone]);
  }
  const Vec<D> impulse = (out.impulse / distance) * r;
  if (helfand_.on()) [[unlikely]]
    helfand_before(i, j, t);
  hi.vel = hi.vel + (1.0 / mi) * impulse;
  hj.vel = hj.vel - (1.0 / mj) * impulse;
  // The kinetic energy the image's extra velocity adds in the box frame: work by the shear.
  if (sheared_) counters_.work_by_shear -= mj * dot(u, hj.vel - vj_before);
  counters_.virial += out.impulse * distance;
  add_virial_tensor(r, impulse);
  if (out.crosses) {
    steps_.set(i, j, {z.table, next});
    ++counters_.step_crossings;
    step_captures_ += z.zone == 0 ? 1u : 0u;
    if (helfand_.on()) [[unlikely]]
      helfand_.pair_energy_changed(i, j, table.energy[next] - table.energy[z.zone]);
  } else {
    ++counters_.step_bounces;
  }
  if (helfand_.on()) [[unlikely]]
    helfand_after(i, j, r);
  ++counters_.collisions;
  ++hi.collisions;
  ++hj.collisions;
  predict_pair(i, j, t);
  return true;
}

// The stepped candidate loop for a list next to a sheared face (after steps_.load(i)): each
// candidate's image moves with its own velocity shift. A listed pair meets its zone's
// boundaries through the image within its cut-off; another image of it (a narrow box repeats
// columns) lies beyond its zone and is skipped. Scalar: only the face rows take it.
template <int D, class Queue>
std::uint32_t EventEngine<D, Queue>::scan_stepped_sheared(const CandidateList& list,
                                                          std::uint32_t i, double t,
                                                          double& best) const {
  const Vec<D> xi = flight_position(hot_[i], t), vi = hot_[i].vel;
  const std::uint32_t si = species_of(i);
  std::uint32_t found = kNoPartner;
  for (std::uint32_t k = 0; k < list.count; ++k) {
    const std::uint32_t j = list.ids[k];
    if (j == i) continue;
    const std::uint32_t tag = list.shift[k];
    const HotRecord<D>& hj = hot_[j];
    const RelativeMotion p = relative_motion_at<D, false, true>(
        xi, vi, reinterpret_cast<const double*>(&hj), t - hj.time, list.shifts[tag], nullptr,
        nullptr, list.velocity_shifts[tag].data());
    const PairSteps::Zone z = steps_.lookup(j, steps_.pair_table(si, species_of(j)));
    double dt;
    if (z.table == PairSteps::kHard) {
      dt = quadratic_contact_time(p, radius_of(i) + radius_of(j));
    } else {
      const ZoneTable& table = steps_.table(z.table);
      if (z.zone > 0 && p.r2 > 4.0 * table.r2[0]) continue;  // another image of a listed pair
      dt = table.event_time(z.zone, p.r2, p.rg, p.g2);
    }
    if (dt < best) {
      best = dt;
      found = j;
    }
  }
  return found;
}

template class EventEngine<2, BinaryHeapQueue>;
template class EventEngine<3, BinaryHeapQueue>;
template class EventEngine<2, CalendarQueue>;
template class EventEngine<3, CalendarQueue>;
template class EventEngine<2, TournamentTreeQueue>;
template class EventEngine<3, TournamentTreeQueue>;

}  // namespace kairos
