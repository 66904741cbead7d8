// The event-driven engine for hard spheres (D = 3) and hard disks (D = 2).
//
// One event's path: the queue yields the particle with the soonest pending event; its EventSlot
// says whether that is a cell crossing or a collision. A collision whose partner has collided
// since the prediction is stale: the particle is re-predicted and nothing else happens. A valid
// collision advances both particles to the event time (their local clocks), applies the elastic
// impulse, bumps both collision counters and re-predicts both. A crossing moves the particle to
// the next cell and tests it only against the newly adjacent layer of cells: its stored
// collision stays a lower bound for the old neighbours.
//
// Invariant (checked by validate()): for every pair in neighbouring cells, the smaller of the
// two stored collision times is no later than the pair's true next contact; so the queue never
// passes over a collision.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/particle_system.hpp"
#include "scheduler/cell_grid.hpp"

namespace kairos {

enum class EventKind { kNone, kCollision, kCellCrossing, kStale };

// How an engine starts: predict every event from the state, or resume the scheduler state the
// ParticleSystem carries (from export_state() or a restart file) to continue bit-identically.
enum class StartMode { kPredict, kResume };

template <int D, class Queue>
class EventEngine {
 public:
  // Takes the state. kResume requires the scheduler state (events and cells) and throws
  // InputError if it is missing or inconsistent with the positions.
  explicit EventEngine(ParticleSystem<D> system, StartMode mode = StartMode::kPredict);

  // Processes the next event. Returns kNone when nothing can ever happen again.
  EventKind step();

  double time() const { return sys_.time; }
  const EventCounters& counters() const { return sys_.counters; }
  const ParticleSystem<D>& system() const { return sys_; }
  // The complete state including the scheduler's, for restarts: an engine built from it
  // continues bit-identically.
  ParticleSystem<D> export_state() const;
  std::size_t size() const { return sys_.size(); }

  double kinetic_energy() const;
  Vec<D> momentum() const;
  // Positions at the current time, wrapped into the box.
  std::vector<Vec<D>> current_positions() const;

  // Debug: checks cell membership, queue order and the prediction invariant against brute
  // force; throws std::logic_error describing the first violation. O(N^2).
  void validate();

  std::size_t bytes_per_particle() const;
  const char* queue_name() const { return Queue::name(); }
  const CellGrid<D>& grid() const { return grid_; }

 private:
  void advance_to(std::uint32_t i, double t);
  double event_time(std::uint32_t i) const {
    const EventSlot& s = sys_.events[i];
    return s.collision_time < s.crossing_time ? s.collision_time : s.crossing_time;
  }
  void predict_collision(std::uint32_t i, double t);
  void reset_candidates();
  void gather(const typename CellGrid<D>::Neighbour& nb);
  void test_candidates(double t, const Vec<D>& xi, const Vec<D>& vi, double ri,
                       EventSlot& slot) const;
  void predict_crossing(std::uint32_t i);
  void collide(std::uint32_t i, std::uint32_t j, double t);
  void cross(std::uint32_t i, double t);
  void predict_all();
  void check_restored_cell(std::uint32_t i) const;

  ParticleSystem<D> sys_;
  CellGrid<D> grid_;
  Queue queue_;
  // Scratch of one prediction: candidate partners and the periodic shift of each one's cell.
  std::vector<std::uint32_t> candidates_;
  std::vector<std::uint8_t> candidate_shift_;
  Vec<D> shifts_[CellGrid<D>::kNeighbourCells + 1] = {};
  std::uint32_t n_candidates_ = 0, n_shifts_ = 0;
};

}  // namespace kairos
