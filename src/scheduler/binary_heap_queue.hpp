// Binary-heap event queue: every particle in one indexed min-heap keyed by its next event time.
// O(log N) per update; the reference the calendar queue is measured against (bench/README.md).
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include "scheduler/indexed_min_heap.hpp"

namespace kairos {

class BinaryHeapQueue {
 public:
  // The heap points into this object's key array: not copyable.
  BinaryHeapQueue() = default;
  BinaryHeapQueue(const BinaryHeapQueue&) = delete;
  BinaryHeapQueue& operator=(const BinaryHeapQueue&) = delete;

  static constexpr const char* name() { return "heap"; }

  void reset(const std::vector<double>& times) {
    key_ = times;
    heap_.bind(&key_);
    heap_.fill_all();
  }

  std::uint32_t top() const { return heap_.empty() ? 0 : heap_.top(); }
  // +inf when empty, as the other queues.
  double top_time() const {
    return heap_.empty() ? std::numeric_limits<double>::infinity() : key_[heap_.top()];
  }
  double time_of(std::uint32_t i) const { return key_[i]; }

  void update(std::uint32_t i, double t) {
    key_[i] = t;
    heap_.restore(i);
  }

  std::size_t bytes_per_particle() const { return sizeof(double) + 2 * sizeof(std::uint32_t); }

 private:
  std::vector<double> key_;
  IndexedMinHeap heap_;
};

}  // namespace kairos
