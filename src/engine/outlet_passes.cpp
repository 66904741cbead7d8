// Outlets in the event engine (boundaries/outlets.hpp, docs/physics.md#outlets-and-strips): a
// particle whose centre crosses an outlet is put back at once at a free place of the insertion
// region. Its old predictions become stale by its collision counter, as after a collision; its new
// one scans its new neighbourhood, which covers every pair it forms there (the engine's invariant
// needs no more: the sooner of two partners' events bounds their contact).
#include <algorithm>
#include <cmath>
#include <string>

#include "boundaries/outlet_placement.hpp"
#include "core/error.hpp"
#include "engine/event_engine.hpp"
#include "scheduler/binary_heap_queue.hpp"
#include "scheduler/calendar_queue.hpp"
#include "scheduler/tournament_tree_queue.hpp"

namespace kairos {

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
  double rmax = 0.0;
  for (const ParticleKind& kind : kinds_) rmax = std::max(rmax, kind.radius);
  check_outlet_regions<D>(boundaries_, rmax, time_, periodic_axes(), box_);
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
  const Vec<D> x =
      outlet_place<D>(boundaries_.outlets(), k, counters_.outlet_passes, periodic_axes(), box_, t,
                      id_[i], [&](const Vec<D>& place) { return free_place(i, place, t); });
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
