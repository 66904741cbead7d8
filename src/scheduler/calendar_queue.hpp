// Calendar event queue (after Paul, J. Comput. Phys. 221, 615 (2007)): O(1) per update.
//
// Time is cut into buckets of width dt; nb (a power of two) buckets form a circular window of
// width nb*dt ahead of the current bucket. A particle's entry sits in one of three places:
//   - the current bucket, kept as a small indexed binary heap (the only sorted part);
//   - a future bucket inside the window, an unsorted intrusive doubly-linked list;
//   - the overflow list (beyond the window, or never), rescanned once per turn of the window.
// Pop order is exactly (time, particle index), the same total order as BinaryHeapQueue, so
// both queues give bit-identical runs. dt adapts, after a full turn of the window, when the
// number of entries per bucket drifts outside [0.25, 8].
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "scheduler/indexed_min_heap.hpp"

namespace kairos {

class CalendarQueue {
 public:
  // The heap points into this object's key array: not copyable.
  CalendarQueue() = default;
  CalendarQueue(const CalendarQueue&) = delete;
  CalendarQueue& operator=(const CalendarQueue&) = delete;

  static constexpr const char* name() { return "calendar"; }

  void reset(const std::vector<double>& times) {
    const auto n = static_cast<std::uint32_t>(times.size());
    key_ = times;
    next_.assign(n, kNone);
    prev_.assign(n, kNone);
    where_.assign(n, kOverflow);
    heap_.bind(&key_);
    nb_ = 1;
    while (nb_ < n) nb_ <<= 1;
    mask_ = nb_ - 1;
    rebuild(estimate_dt());
  }

  std::uint32_t top() {
    if (heap_.size() > heap_limit_) rebuild(estimate_dt());
    if (heap_.empty()) advance();
    return heap_.empty() ? 0 : heap_.top();
  }
  double top_time() {
    if (heap_.size() > heap_limit_) rebuild(estimate_dt());
    if (heap_.empty()) advance();
    return heap_.empty() ? std::numeric_limits<double>::infinity() : key_[heap_.top()];
  }
  double time_of(std::uint32_t i) const { return key_[i]; }

  void update(std::uint32_t i, double t) {
    remove(i);
    key_[i] = t;
    insert(i);
  }

  // key, list links, location, heap position, plus the bucket heads divided by N.
  std::size_t bytes_per_particle() const {
    return sizeof(double) + 4 * sizeof(std::uint32_t) +
           (key_.empty() ? 0 : bucket_head_.size() * sizeof(std::uint32_t) / key_.size());
  }
  std::size_t sorted_size() const { return heap_.size(); }  // entries in the current bucket

 private:
  static constexpr std::uint32_t kNone = 0xffffffffu;
  static constexpr std::int32_t kInHeap = -1;
  static constexpr std::int32_t kOverflow = -2;
  static constexpr std::uint64_t kFar = std::numeric_limits<std::uint64_t>::max();

  std::uint64_t bucket_number(double t) const {
    const double k = std::floor(t * inv_dt_);
    return (std::isfinite(k) && k < 1.8e19) ? (k > 0.0 ? static_cast<std::uint64_t>(k) : 0u) : kFar;
  }

  // Bucket width from the spread of the pending event times: about two events per bucket.
  double estimate_dt() const {
    double tmin = std::numeric_limits<double>::infinity();
    for (double t : key_) tmin = std::min(tmin, t);
    double sum = 0.0;
    std::size_t count = 0;
    for (double t : key_) {
      if (std::isfinite(t)) {
        sum += t - tmin;
        ++count;
      }
    }
    if (count == 0 || sum <= 0.0) return 1.0;
    return 2.0 * (sum / static_cast<double>(count)) / static_cast<double>(nb_);
  }

  void rebuild(double dt) {
    dt_ = dt;
    inv_dt_ = 1.0 / dt;
    heap_.clear();
    bucket_head_.assign(nb_, kNone);
    overflow_head_ = kNone;
    double tmin = std::numeric_limits<double>::infinity();
    for (double t : key_) tmin = std::min(tmin, t);
    current_ = std::isfinite(tmin) ? bucket_number(tmin) : 0;
    loaded_this_turn_ = buckets_this_turn_ = 0;
    for (std::uint32_t i = 0; i < key_.size(); ++i) insert(i);
    // Too many entries in the sorted bucket means dt is too coarse (the time scale shrank):
    // rebuild then. The limit grows with what a rebuild itself leaves there (equal times).
    heap_limit_ = std::max<std::size_t>(256, 4 * heap_.size());
  }

  void insert(std::uint32_t i) {
    const std::uint64_t k = bucket_number(key_[i]);
    if (k <= current_) {
      heap_push(i);
    } else if (k - current_ < nb_) {
      link(i, bucket_head_[k & mask_], static_cast<std::int32_t>(k & mask_));
    } else {
      link(i, overflow_head_, kOverflow);
    }
  }

  void remove(std::uint32_t i) {
    const std::int32_t w = where_[i];
    if (w == kInHeap) {
      heap_erase(i);
    } else {
      std::uint32_t& head = (w == kOverflow) ? overflow_head_ : bucket_head_[w];
      if (prev_[i] != kNone) {
        next_[prev_[i]] = next_[i];
      } else {
        head = next_[i];
      }
      if (next_[i] != kNone) prev_[next_[i]] = prev_[i];
    }
  }

  void link(std::uint32_t i, std::uint32_t& head, std::int32_t where) {
    where_[i] = where;
    prev_[i] = kNone;
    next_[i] = head;
    if (head != kNone) prev_[head] = i;
    head = i;
  }

  // Moves to the next non-empty bucket; rescans the overflow list once per turn.
  void advance() {
    std::uint64_t scanned = 0;
    while (heap_.empty()) {
      ++current_;
      ++scanned;
      if ((current_ & mask_) == 0 && turn_complete()) return;  // rebuilt or nothing left
      std::uint32_t p = bucket_head_[current_ & mask_];
      bucket_head_[current_ & mask_] = kNone;
      ++buckets_this_turn_;
      while (p != kNone) {
        const std::uint32_t nxt = next_[p];
        heap_push(p);
        ++loaded_this_turn_;
        p = nxt;
      }
      if (scanned > 4 * static_cast<std::uint64_t>(nb_) + 4) return;  // only infinite times left
    }
  }

  // Start of a new turn of the window: adapt dt if needed, pull due entries from overflow.
  // Returns true when the caller must stop advancing (the queue was rebuilt or is empty).
  bool turn_complete() {
    // Adapt only on a full turn's statistics (a rebuild starts mid-turn).
    const double per_bucket = static_cast<double>(loaded_this_turn_) /
                              static_cast<double>(std::max<std::uint64_t>(1, buckets_this_turn_));
    const bool full_turn = buckets_this_turn_ >= nb_ / 2;
    loaded_this_turn_ = buckets_this_turn_ = 0;
    if (full_turn && (per_bucket > 8.0 || (per_bucket > 0.0 && per_bucket < 0.25))) {
      rebuild(dt_ * 2.0 / per_bucket);
      return true;
    }
    std::uint32_t p = overflow_head_;
    std::uint64_t earliest = kFar;
    bool window_empty = true;
    for (std::uint32_t b = 0; b < nb_ && window_empty; ++b) window_empty = bucket_head_[b] == kNone;
    if (window_empty) {
      for (std::uint32_t q = p; q != kNone; q = next_[q]) {
        earliest = std::min(earliest, bucket_number(key_[q]));
      }
      if (earliest == kFar) return true;  // only events that never happen
      if (earliest > current_) current_ = earliest & ~static_cast<std::uint64_t>(mask_);
    }
    overflow_head_ = kNone;
    while (p != kNone) {
      const std::uint32_t nxt = next_[p];
      const std::uint64_t k = bucket_number(key_[p]);
      if (k < current_) {
        heap_push(p);
      } else if (k - current_ < nb_) {
        link(p, bucket_head_[k & mask_], static_cast<std::int32_t>(k & mask_));
      } else {
        link(p, overflow_head_, kOverflow);
      }
      p = nxt;
    }
    return false;
  }

  void heap_push(std::uint32_t p) {
    where_[p] = kInHeap;
    heap_.push(p);
  }
  void heap_erase(std::uint32_t p) { heap_.erase(p); }

  std::vector<double> key_;
  std::vector<std::uint32_t> next_, prev_;  // intrusive bucket / overflow lists
  std::vector<std::int32_t> where_;         // bucket index, kInHeap or kOverflow
  IndexedMinHeap heap_;                     // the current bucket, sorted
  std::vector<std::uint32_t> bucket_head_;
  std::uint32_t overflow_head_ = kNone;
  std::uint32_t nb_ = 1, mask_ = 0;
  double dt_ = 1.0, inv_dt_ = 1.0;
  std::uint64_t current_ = 0;  // absolute number of the current bucket
  std::size_t heap_limit_ = 256;
  std::uint64_t loaded_this_turn_ = 0;   // entries moved from buckets into the heap this turn
  std::uint64_t buckets_this_turn_ = 0;  // buckets advanced this turn
};

}  // namespace kairos
