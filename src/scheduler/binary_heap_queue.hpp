// Indexed binary min-heap over particles: one entry per particle, keyed by its next event time.
//
// The reference priority structure (O(log N) per update). Ties are broken by particle index so
// the pop order never depends on the heap's history (needed for bit-identical restarts).
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

namespace kairos {

class BinaryHeapQueue {
 public:
  static constexpr const char* name() { return "heap"; }

  // Builds the heap from the event times of particles 0..n-1.
  void reset(const std::vector<double>& times) {
    const auto n = static_cast<std::uint32_t>(times.size());
    key_ = times;
    heap_.resize(n);
    slot_.resize(n);
    for (std::uint32_t i = 0; i < n; ++i) heap_[i] = slot_[i] = i;
    for (std::uint32_t k = n / 2; k-- > 0;) sift_down(k);
  }

  std::uint32_t top() const { return heap_[0]; }
  double top_time() const { return key_[heap_[0]]; }
  double time_of(std::uint32_t i) const { return key_[i]; }
  std::size_t size() const { return heap_.size(); }

  void update(std::uint32_t i, double t) {
    const double old = key_[i];
    key_[i] = t;
    if (t < old) {
      sift_up(slot_[i]);
    } else {
      sift_down(slot_[i]);
    }
  }

  std::size_t bytes_per_particle() const { return sizeof(double) + 2 * sizeof(std::uint32_t); }

 private:
  bool less(std::uint32_t a, std::uint32_t b) const {
    return key_[a] < key_[b] || (key_[a] == key_[b] && a < b);
  }
  void place(std::uint32_t pos, std::uint32_t particle) {
    heap_[pos] = particle;
    slot_[particle] = pos;
  }
  void sift_up(std::uint32_t pos) {
    const std::uint32_t p = heap_[pos];
    while (pos > 0) {
      const std::uint32_t parent = (pos - 1) / 2;
      if (!less(p, heap_[parent])) break;
      place(pos, heap_[parent]);
      pos = parent;
    }
    place(pos, p);
  }
  void sift_down(std::uint32_t pos) {
    const std::uint32_t n = static_cast<std::uint32_t>(heap_.size());
    const std::uint32_t p = heap_[pos];
    while (true) {
      std::uint32_t child = 2 * pos + 1;
      if (child >= n) break;
      if (child + 1 < n && less(heap_[child + 1], heap_[child])) ++child;
      if (!less(heap_[child], p)) break;
      place(pos, heap_[child]);
      pos = child;
    }
    place(pos, p);
  }

  std::vector<double> key_;
  std::vector<std::uint32_t> heap_;  // heap position -> particle
  std::vector<std::uint32_t> slot_;  // particle -> heap position
};

}  // namespace kairos
