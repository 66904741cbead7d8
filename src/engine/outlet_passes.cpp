// Outlets in the event engine (boundaries/outlets.hpp, docs/physics.md#outlets): a particle whose
// centre crosses an outlet is put back at once at a free place of the insertion region. Its
// old predictions become stale by its collision counter, as after a collision; its new one
// scans its new neighbourhood, which covers every pair it forms there (the engine's invariant
// needs no more: the sooner of two partners' events bounds their contact).
#include <algorithm>
#include <cmath>
#include <string>

#include <fmt/format.h>

#include "core/error.hpp"
#include "engine/event_engine.hpp"
#include "scheduler/binary_heap_queue.hpp"
#include "scheduler/calendar_queue.hpp"
#include "scheduler/tournament_tree_queue.hpp"

namespace kairos {

namespace {
// Tries for a free place before the region is declared full.
constexpr std::uint32_t kInsertionAttempts = 100000;
// Draws of the region at the start, looking for room inside the walls.
constexpr std::uint32_t kRegionProbes = 1000;
}  // namespace

template <int D, class Queue>
void EventEngine<D, Queue>::check_outlets(const ParticleSystem<D>& /*s*/) const {
  const auto refuse = [](const std::string& why) {
    throw InputError("boundary.outlet: an outlet cannot be combined with " + why);
  };
  if (soft_) refuse("soft spheres yet (soft.model)");
  if (stepped_) refuse("stepped potentials or bonds (a particle put back would break its zones)");
  if (sheared_) refuse("Lees-Edwards shear (boundary.shear_rate)");
  if (options_.track_helfand)
    refuse("transport analyses (analysis.transport): a particle put back jumps");
  // A region outside the walls (or behind a plane) would only show at the first pass, after
  // every draw failed: draws of the region must find room for the largest particle somewhere.
  double rmax = 0.0;
  for (const ParticleKind& kind : kinds_) rmax = std::max(rmax, kind.radius);
  const Outlets<D>& outlets = boundaries_.outlets();
  for (int k = 0; k < outlets.surfaces(); ++k) {
    bool inside = false;
    for (std::uint32_t attempt = 0; attempt < kRegionProbes && !inside; ++attempt) {
      inside =
          !boundaries_.overlaps(insertion_candidate(k, ~std::uint64_t{0}, attempt), rmax, time_);
    }
    if (!inside) {
      throw InputError(fmt::format(
          "boundary.outlet: no place in the insertion region (insert_lower to insert_upper) "
          "leaves room for a particle of radius {:.6g} inside the walls ({} draws): the region "
          "lies outside the box's walls or behind a plane; move it inside",
          rmax, kRegionProbes));
    }
  }
}

// The outlet's draw, wrapped into the box along its periodic axes.
template <int D, class Queue>
Vec<D> EventEngine<D, Queue>::insertion_candidate(int k, std::uint64_t pass,
                                                  std::uint32_t attempt) const {
  Vec<D> x = boundaries_.outlets().insertion_point(k, pass, attempt);
  for (int a = 0; a < D; ++a)
    if (cells_.grid().periodic(a)) x[a] = wrap_into_box(x[a], box_[a]);
  return x;
}

template <int D, class Queue>
double EventEngine<D, Queue>::mechanical_energy(std::uint32_t i, double t) const {
  const double m = mass_of(i);
  return 0.5 * m * norm2(velocity(i, t)) + spin_energy(i) - m * dot(env_.gravity, position(i, t));
}

template <int D, class Queue>
bool EventEngine<D, Queue>::free_place(std::uint32_t i, const Vec<D>& x, double t) {
  const double radius = radius_of(i);
  if (boundaries_.overlaps(x, radius, t)) return false;
  CandidateList& list = cells_.list(1);
  gather(cells_.grid().locate(x), list);
  for (std::uint32_t k = 0; k < list.count; ++k) {
    const std::uint32_t j = list.ids[k];
    if (j == i) continue;
    Vec<D> r = x - position(j, t);
    if (list.n_shifts > 1) r = r - list.shifts[list.shift[k]];
    const double sigma = radius + radius_of(j);
    if (norm2(r) < sigma * sigma) return false;
  }
  return true;
}

template <int D, class Queue>
void EventEngine<D, Queue>::pass_outlet(std::uint32_t i, int surface, double t) {
  const int k = boundaries_.outlet_index(surface);
  const Outlet<D>& outlet = boundaries_.outlets().outlet(k);
  advance_to(i, t);
  const double before = mechanical_energy(i, t);
  const std::uint64_t pass = counters_.outlet_passes;
  Vec<D> x{};
  bool placed = false;
  for (std::uint32_t attempt = 0; attempt < kInsertionAttempts && !placed; ++attempt) {
    x = insertion_candidate(k, pass, attempt);
    placed = free_place(i, x, t);
  }
  if (!placed) {
    throw InputError(fmt::format(
        "boundary.outlet: at t = {:.10g} particle {} passed the outlet, but no free place for "
        "it was found in the insertion region (insert_lower to insert_upper) in {} tries: the "
        "region is full, or lies outside the walls; make it larger, or place it inside the "
        "walls where the particles leave room",
        t, id_[i], kInsertionAttempts));
  }
  HotRecord<D>& h = hot_[i];
  h.pos = x;
  h.vel = outlet.insert_velocity;
  h.time = t;
  if (!spin_.empty()) spin_[i] = AngularVelocity<D>{};
  if (!last_collision_.empty()) last_collision_[i] = -kNever;  // the TC model: a new start
  relocate(i);
  if (images_.on()) images_.reset(i);  // a new path: its image flags start again
  ++h.collisions;                      // predictions made against its old motion are stale
  ++counters_.outlet_passes;
  counters_.outlet_mass += mass_of(i);
  counters_.outlet_energy += before - mechanical_energy(i, t);
  queue_.update(i, predict(i, t));
}

template class EventEngine<2, BinaryHeapQueue>;
template class EventEngine<3, BinaryHeapQueue>;
template class EventEngine<2, CalendarQueue>;
template class EventEngine<3, CalendarQueue>;
template class EventEngine<2, TournamentTreeQueue>;
template class EventEngine<3, TournamentTreeQueue>;

}  // namespace kairos
