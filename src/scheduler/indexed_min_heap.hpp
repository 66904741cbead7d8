// An indexed binary min-heap of particle indices ordered by (key[i], i), with the position of
// every member known so that any member can be re-keyed or removed in O(log n).
//
// The keys live outside (the owning queue's array); the heap is told when one changes. The
// index tie-break makes the order total, so pop order never depends on the insertion history
// (bit-identical restarts, and identical runs whichever queue is used).
#pragma once

#include <cstdint>
#include <vector>

namespace kairos {

class IndexedMinHeap {
 public:
  explicit IndexedMinHeap(const std::vector<double>* keys = nullptr) : key_(keys) {}
  void bind(const std::vector<double>* keys) {
    key_ = keys;
    pos_.assign(keys->size(), 0);
    heap_.clear();
  }

  bool empty() const { return heap_.empty(); }
  std::size_t size() const { return heap_.size(); }
  std::uint32_t top() const { return heap_[0]; }
  void clear() { heap_.clear(); }

  // Builds the heap of all particles 0..n-1 in O(n).
  void fill_all() {
    const auto n = static_cast<std::uint32_t>(key_->size());
    heap_.resize(n);
    for (std::uint32_t i = 0; i < n; ++i) place(i, i);
    for (std::uint32_t k = n / 2; k-- > 0;) sift_down(k);
  }
  void push(std::uint32_t p) {
    heap_.push_back(p);
    sift_up(static_cast<std::uint32_t>(heap_.size() - 1));
  }
  void erase(std::uint32_t p) {
    const std::uint32_t at = pos_[p];
    const std::uint32_t last = heap_.back();
    heap_.pop_back();
    if (at == heap_.size()) return;
    place(at, last);
    restore(last);
  }
  // Re-establishes the order after key[p] changed.
  void restore(std::uint32_t p) {
    sift_up(pos_[p]);
    sift_down(pos_[p]);
  }

 private:
  bool less(std::uint32_t a, std::uint32_t b) const {
    const double ka = (*key_)[a], kb = (*key_)[b];
    return ka < kb || (ka == kb && a < b);
  }
  void place(std::uint32_t at, std::uint32_t p) {
    heap_[at] = p;
    pos_[p] = at;
  }
  void sift_up(std::uint32_t at) {
    const std::uint32_t p = heap_[at];
    while (at > 0) {
      const std::uint32_t parent = (at - 1) / 2;
      if (!less(p, heap_[parent])) break;
      place(at, heap_[parent]);
      at = parent;
    }
    place(at, p);
  }
  void sift_down(std::uint32_t at) {
    const auto n = static_cast<std::uint32_t>(heap_.size());
    const std::uint32_t p = heap_[at];
    while (true) {
      std::uint32_t child = 2 * at + 1;
      if (child >= n) break;
      if (child + 1 < n && less(heap_[child + 1], heap_[child])) ++child;
      if (!less(heap_[child], p)) break;
      place(at, heap_[child]);
      at = child;
    }
    place(at, p);
  }

  const std::vector<double>* key_;
  std::vector<std::uint32_t> heap_;  // heap position -> particle
  std::vector<std::uint32_t> pos_;   // particle -> heap position
};

}  // namespace kairos
