// Lees-Edwards shear in the event engine: what the images (boundaries/lees_edwards.hpp) add to a
// prediction, a collision and a crossing, and the re-predictions when the images move on.
#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <string_view>

#include "core/error.hpp"
#include "core/periodic.hpp"
#include "engine/event_engine.hpp"
#include "engine/relative_motion.hpp"
#include "scheduler/binary_heap_queue.hpp"
#include "scheduler/calendar_queue.hpp"
#include "scheduler/tournament_tree_queue.hpp"

namespace kairos {

namespace {
constexpr std::uint32_t kNoPartner = EventSlot::kNoPartner;
}  // namespace

// The images moved on by a cell width: the particles of the two face rows (every (x, z) column
// at y = 0 and y = n_y - 1) are predicted again.
template <int D, class Queue>
void EventEngine<D, Queue>::shift_images() {
  time_ = shear_.shift();
  const int nx = cells_.grid().cells_along(0), ny = cells_.grid().cells_along(1);
  const int nz = D == 3 ? cells_.grid().cells_along(D - 1) : 1;
  for (const int y : {0, ny - 1}) {
    for (int column = 0; column < nx * nz; ++column) {
      std::array<int, D> at{};
      at[0] = column % nx;
      at[1] = y;
      if constexpr (D == 3) at[2] = column / nx;
      const std::uint32_t cell = cells_.grid().index(cells_.grid().code_at(at));
      for (std::uint32_t p = cells_.grid().first(cell); p != cells_.grid().end();
           p = cells_.grid().next(p))
        queue_.update(p, predict(p, time_));
    }
  }
}

// The neighbourhood of a cell in the first or last row along y: its own row and the inner one
// as usual, the row beyond the face through the sliding images.
template <int D, class Queue>
void EventEngine<D, Queue>::gather_sheared(CellCode cell, CandidateList& list) {
  std::uint32_t n = 0, n_shifts = 1;  // shifts[0]: none
  list.shifts[0] = Vec<D>{};
  list.velocity_shifts[0] = Vec<D>{};
  // Predictions happen at time_.
  shear_.for_each_neighbour_cell(
      cell, cells_.grid(), time_,
      [&](const std::array<int, D>& at, const Vec<D>& shift, const Vec<D>& vshift) {
        const std::uint32_t tag = n_shifts++;
        list.shifts[tag] = shift;
        list.velocity_shifts[tag] = vshift;
        for (std::uint32_t p = cells_.grid().first(cells_.grid().index(cells_.grid().code_at(at)));
             p != cells_.grid().end(); p = cells_.grid().next(p)) {
          if (list.ids.size() - n < Cells::kCandidateSlack) Cells::grow(list);
          list.ids[n] = p;
          list.shift[n++] = tag;
        }
      });
  list.count = n;
  list.n_shifts = n_shifts;
}

// The candidate test for a sheared list: like the scalar loop, with each image's velocity.
template <int D, class Queue>
std::uint32_t EventEngine<D, Queue>::scan_sheared(const CandidateList& list, std::uint32_t i,
                                                  double t, double& best) const {
  const Vec<D> xi = flight_position(hot_[i], t), vi = hot_[i].vel;
  std::uint32_t found = kNoPartner;
  for (std::uint32_t k = 0; k < list.count; ++k) {
    const std::uint32_t j = list.ids[k];
    const std::uint32_t tag = list.shift[k];
    const HotRecord<D>& hj = hot_[j];
    const RelativeMotion p = relative_motion_at<D, false, true>(
        xi, vi, reinterpret_cast<const double*>(&hj), t - hj.time, list.shifts[tag], nullptr,
        nullptr, list.velocity_shifts[tag].data());
    const double dt = quadratic_contact_time(p, radius_of(i) + radius_of(j));
    if (dt < best) {
      best = dt;
      found = j;
    }
  }
  return found;
}

// Pairs in contact are closer than a third of the box along y, so the image is unambiguous.
template <int D, class Queue>
Vec<D> EventEngine<D, Queue>::sheared_separation(std::uint32_t i, std::uint32_t j, double t,
                                                 Vec<D>& image_velocity) const {
  return shear_.separation(position(i, t) - position(j, t), t, periodic_axes(), image_velocity);
}

// A collision under shear: the impulse is the ordinary one between i and the image of j it
// meets; only the velocity j's image has beyond j's own is taken out again. The kinetic energy
// that adds in the box frame is work done by the shearing boundaries.
template <int D, class Queue>
void EventEngine<D, Queue>::collide_sheared(std::uint32_t i, std::uint32_t j, double t) {
  advance_to(i, t);
  advance_to(j, t);
  HotRecord<D>& hi = hot_[i];
  HotRecord<D>& hj = hot_[j];
  Vec<D> u;
  const Vec<D> r = sheared_separation(i, j, t, u);
  const double r2 = norm2(r);
  const Vec<D> vj_before = hj.vel;
  hj.vel = hj.vel + u;
  resolve_pair(i, j, t, r, r2);
  hj.vel = hj.vel - u;
  counters_.work_by_shear -= mass_of(j) * dot(u, hj.vel - vj_before);
  ++counters_.collisions;
  ++hi.collisions;
  ++hj.collisions;
  predict_pair(i, j, t);
}

// Particle i leaves through the high (side +1) or low (-1) y face and comes back as its image:
// its y is already wrapped; x and v_x follow the image, and its column is found again.
template <int D, class Queue>
void EventEngine<D, Queue>::cross_shear_face(std::uint32_t i, int side, double t,
                                             std::array<int, D>& c) {
  HotRecord<D>& h = hot_[i];
  const double ke = norm2(h.vel);
  const double x = h.pos[0];
  c[0] = shear_.cross_face(h.pos, h.vel, side, t, cells_.grid());
  // The x shift by the images' whole displacement, less the boxes it was wrapped by
  // (engine/image_counters.hpp: the lab-frame unwrapped x stays continuous).
  if (images_.on()) images_.wrapped(i, 0, x - side * shear_.image_speed() * t, h.pos[0], box_[0]);
  counters_.work_by_shear += 0.5 * mass_of(i) * (norm2(h.vel) - ke);
}

template class EventEngine<2, BinaryHeapQueue>;
template class EventEngine<3, BinaryHeapQueue>;
template class EventEngine<2, CalendarQueue>;
template class EventEngine<3, CalendarQueue>;
template class EventEngine<2, TournamentTreeQueue>;
template class EventEngine<3, TournamentTreeQueue>;

}  // namespace kairos
