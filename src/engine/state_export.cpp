// EventEngine's state given back to the caller: whole (export_state), in blocks of particles
// read in the engine's memory order (state_blocks, for_each_block; core/state_blocks.hpp), and
// the present positions, velocities and masses in the caller's numbering. Outputs read the
// engine only through these (docs/architecture.md).
#include <algorithm>
#include <memory>
#include <stdexcept>
#include <vector>

#include "core/periodic.hpp"
#include "engine/event_engine.hpp"
#include "scheduler/binary_heap_queue.hpp"
#include "scheduler/calendar_queue.hpp"
#include "scheduler/tournament_tree_queue.hpp"

namespace kairos {

namespace {
constexpr std::uint32_t kNoPartner = EventSlot::kNoPartner;
}  // namespace

// Particle k's position now, wrapped into the box along the periodic axes: what outputs and
// the overlap check read.
template <int D, class Queue>
Vec<D> EventEngine<D, Queue>::wrapped_position_now(std::uint32_t k) const {
  Vec<D> x = position(k, time_);
  for (int a = 0; a < D; ++a)
    if (cells_.grid().periodic(a)) x[a] = wrap_into_box(x[a], box_[a]);
  return x;
}

template <int D, class Queue>
ParticleSystem<D> EventEngine<D, Queue>::export_state(bool with_zones) const {
  const std::size_t n = size();
  ParticleSystem<D> out = export_globals(with_zones);
  size_particle_arrays(out, n);
  out.order.assign(id_.begin(), id_.end());
  for (std::uint32_t k = 0; k < n; ++k) export_particle(k, id_[k], out, StateBlocks<D>::kAll);
  return out;
}

template <int D, class Queue>
StateBlocks<D> EventEngine<D, Queue>::state_blocks(bool with_zones) const {
  StateBlocks<D> blocks;
  blocks.globals_ = std::make_shared<const ParticleSystem<D>>(export_globals(with_zones));
  blocks.particles = size();
  block_order();
  std::shared_ptr<const BlockOrder> order = block_order_;
  blocks.fill = [this, order](std::size_t first, std::size_t count, ParticleSystem<D>& out,
                              unsigned fields) {
    size_particle_arrays(out, count);
    if ((fields & StateBlocks<D>::kScheduler) != 0)
      out.order.assign(id_.begin() + static_cast<std::ptrdiff_t>(first),
                       id_.begin() + static_cast<std::ptrdiff_t>(first + count));
    if (count == 0) return;
    const std::size_t last = (first + count - 1) / StateBlocks<D>::kBlock;
    for (std::size_t b = first / StateBlocks<D>::kBlock; b <= last; ++b) {
      for (std::uint32_t m = order->start[b]; m < order->start[b + 1]; ++m) {
        const std::uint32_t k = order->members[m];
        const std::size_t c = id_[k];
        if (c >= first && c < first + count)
          export_particle(k, static_cast<std::uint32_t>(c - first), out, fields);
      }
    }
  };
  return blocks;
}

// The engine's particles grouped by block of the caller's numbering (a counting sort on
// id_ / kBlock), each block's in increasing internal index: a pass over the blocks then reads
// the records in memory order, each once, where reading them in the caller's order would jump
// at random (at N = 10^6, 20 times slower).
template <int D, class Queue>
const typename EventEngine<D, Queue>::BlockOrder& EventEngine<D, Queue>::block_order() const {
  if (block_order_) return *block_order_;
  constexpr std::size_t kBlock = StateBlocks<D>::kBlock;
  const std::size_t blocks = (size() + kBlock - 1) / kBlock;
  BlockOrder order;
  order.start.assign(blocks + 1, 0);
  for (std::uint32_t k = 0; k < size(); ++k) ++order.start[id_[k] / kBlock + 1];
  for (std::size_t b = 0; b < blocks; ++b) order.start[b + 1] += order.start[b];
  std::vector<std::uint32_t> next(order.start.begin(), order.start.end() - 1);
  order.members.resize(size());
  for (std::uint32_t k = 0; k < size(); ++k) order.members[next[id_[k] / kBlock]++] = k;
  block_order_ = std::make_shared<const BlockOrder>(std::move(order));
  return *block_order_;
}

// export_state() but for the per-particle arrays.
template <int D, class Queue>
ParticleSystem<D> EventEngine<D, Queue>::export_globals(bool with_zones) const {
  ParticleSystem<D> out;
  out.box = box_;
  out.time = time_;
  out.counters = counters_;
  out.species_names = species_names_;
  out.gravity = env_.gravity;
  for (int a = 0; a < D; ++a) out.periodic[a] = cells_.grid().periodic(a);
  out.bonds = bonds_;
  out.bond_types = bond_types_;
  out.wall_motion = boundaries_.motion();
  if (stepped_ && with_zones) out.zones = steps_.export_zones(id_.data());
  for (std::uint32_t k = 0; soft_ && k < size(); ++k) {
    const std::uint32_t p = soft_state_.partner(k);
    if (p == kNoPartner || (is_particle(p) && p < k)) continue;  // each pair once
    if (soft_state_.deferred(k) && !in_deferred_contact(k, time_)) continue;
    FrozenContact<D> c;
    c.i = id_[k];
    c.deferred = soft_state_.deferred(k);
    c.release_time = c.deferred ? hot_[k].time : soft_state_.release_time(k);
    c.velocity_i = c.deferred ? hot_[k].vel : soft_state_.release_velocity(k);
    if (c.deferred) c.release_position_i = hot_[k].pos;
    if (is_particle(p)) {
      c.j = id_[p];
      c.velocity_j = c.deferred ? hot_[p].vel : soft_state_.release_velocity(p);
      if (c.deferred) c.release_position_j = hot_[p].pos;
    } else {
      c.face = Code::from_bits(p).wall_face();
    }
    out.frozen.push_back(c);
  }
  return out;
}

// The per-particle arrays of `out` for n particles (order excepted), those the engine keeps.
template <int D, class Queue>
void EventEngine<D, Queue>::size_particle_arrays(ParticleSystem<D>& out, std::size_t n) const {
  out.kinematics.resize(n);
  out.mass.resize(n);
  out.species.resize(n);
  out.collision_count.resize(n);
  out.events.resize(n);
  out.cell.resize(n);
  out.asleep.assign(resting_.count() > 0 ? n : 0, 0);
  out.image.resize(images_.on() ? n : 0);
  out.angular_velocity.resize(spin_.empty() ? 0 : n);
  out.last_collision_time.resize(last_collision_.empty() ? 0 : n);
}

// Internal particle k into entry c of out's per-particle arrays (sized by size_particle_arrays).
template <int D, class Queue>
void EventEngine<D, Queue>::export_particle(std::uint32_t k, std::uint32_t c,
                                            ParticleSystem<D>& out, unsigned fields) const {
  using Blocks = StateBlocks<D>;
  const ParticleKind& sh = kinds_[kind_.empty() ? 0 : kind_[k]];
  if ((fields & Blocks::kKinematics) != 0) {
    const HotRecord<D>& h = hot_[k];
    const double radius = radius_of(k) * growth_.scale(time_);  // grown to now
    out.kinematics[c] = {h.pos, h.vel, h.time, radius};
    if (in_deferred_contact(k, time_)) [[unlikely]]  // where it is, frozen, now
      out.kinematics[c] = {position(k, time_), frozen_velocity_of(k), time_, radius};
    if (resting_.count() > 0) out.asleep[c] = resting_.flag(k);
    if (images_.on()) out.image[c] = images_.of(k);
  }
  if ((fields & Blocks::kIdentity) != 0) {
    out.mass[c] = sh.mass;
    out.species[c] = sh.species;
  }
  if ((fields & Blocks::kExtras) != 0) {
    if (!spin_.empty()) out.angular_velocity[c] = spin_[k];
    if (!last_collision_.empty()) out.last_collision_time[c] = last_collision_[k];
  }
  if ((fields & Blocks::kScheduler) != 0) {
    const HotRecord<D>& h = hot_[k];
    out.collision_count[c] = h.collisions;
    out.cell[c] = h.cell;
    const PendingEvent& e = pending_[k];
    const Code code = e.code.renumbered([&](std::uint32_t p) { return id_[p]; });
    out.events[c] = {queue_.time_of(k), code.bits(), e.partner_count};
  }
}

template <int D, class Queue>
void EventEngine<D, Queue>::unwrapped_positions(const std::vector<std::uint32_t>& slot,
                                                std::vector<Vec<D>>& out) const {
  if (!images_.on()) throw std::logic_error("unwrapped_positions: images are not tracked");
  for (std::uint32_t k = 0; k < size(); ++k) {
    const std::uint32_t s = slot[id_[k]];
    if (s == kNotFollowed) continue;
    Vec<D> x = position(k, time_);
    for (int a = 0; a < D; ++a) x[a] += images_.of(k)[a] * box_[a];
    out[s] = x;
  }
}

template <int D, class Queue>
void EventEngine<D, Queue>::velocities(const std::vector<std::uint32_t>& slot,
                                       std::vector<Vec<D>>& out) const {
  for (std::uint32_t k = 0; k < size(); ++k) {
    const std::uint32_t s = slot[id_[k]];
    if (s != kNotFollowed) out[s] = velocity(k, time_);
  }
}

template <int D, class Queue>
std::vector<Vec<D>> EventEngine<D, Queue>::current_positions() const {
  std::vector<Vec<D>> out(size());
  for (std::uint32_t i = 0; i < size(); ++i) out[id_[i]] = wrapped_position_now(i);
  return out;
}

template <int D, class Queue>
void EventEngine<D, Queue>::for_each_block(const BlockVisitor& f, bool with_positions) const {
  const std::size_t n = size();
  const BlockOrder& order = block_order();
  const std::size_t block = std::min(n, StateBlocks<D>::kBlock);
  std::vector<Vec<D>> x(with_positions ? block : 0), v(block);
  std::vector<double> m(block);
  for (std::size_t b = 0, first = 0; first < n; ++b, first += block) {
    const std::size_t count = std::min(block, n - first);
    for (std::uint32_t e = order.start[b]; e < order.start[b + 1]; ++e) {
      const std::uint32_t k = order.members[e];
      const std::size_t j = id_[k] - first;
      if (with_positions) x[j] = wrapped_position_now(k);
      v[j] = velocity(k, time_);
      m[j] = mass_of(k);
    }
    f(first, {x.data(), with_positions ? count : 0}, {v.data(), count}, {m.data(), count});
  }
}

template <int D, class Queue>
double EventEngine<D, Queue>::max_overlap_now() const {
  if (sheared_) throw std::logic_error("max_overlap_now: the images of a sheared box slide");
  std::array<bool, D> periodic{};
  for (int a = 0; a < D; ++a) periodic[a] = cells_.grid().periodic(a);
  CandidateList list;
  Cells::size_list(list);
  double worst = 0.0;
  for (std::uint32_t i = 0; i < size(); ++i) {
    cells_.gather_particle(i, hot_[i].cell, list, hot_.data());
    const Vec<D> xi = wrapped_position_now(i);
    for (std::uint32_t c = 0; c < list.count; ++c) {
      const std::uint32_t j = list.ids[c];
      if (j <= i) continue;  // each pair once (a small grid may list a cell twice: no matter)
      const double grown = 2.0 * growth_.scale(time_);
      worst =
          std::max(worst, pair_overlap<D>(box_, xi, wrapped_position_now(j), grown * radius_of(i),
                                          grown * radius_of(j), &periodic));
    }
  }
  return worst;
}

template <int D, class Queue>
std::vector<Vec<D>> EventEngine<D, Queue>::current_velocities() const {
  std::vector<Vec<D>> out(size());
  for (std::uint32_t i = 0; i < size(); ++i) out[id_[i]] = velocity(i, time_);
  return out;
}

template <int D, class Queue>
std::vector<double> EventEngine<D, Queue>::masses() const {
  std::vector<double> out(size());
  for (std::uint32_t i = 0; i < size(); ++i) out[id_[i]] = mass_of(i);
  return out;
}

template class EventEngine<2, BinaryHeapQueue>;
template class EventEngine<3, BinaryHeapQueue>;
template class EventEngine<2, CalendarQueue>;
template class EventEngine<3, CalendarQueue>;
template class EventEngine<2, TournamentTreeQueue>;
template class EventEngine<3, TournamentTreeQueue>;

}  // namespace kairos
