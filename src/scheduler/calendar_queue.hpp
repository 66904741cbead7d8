// Calendar event queue (ideas from Paul, J. Comput. Phys. 221, 615 (2007)): O(1) amortised per
// update in 12.5 to 13 bytes per particle (key 8, next/state word 4, bucket heads 0.5 to 1).
//
// Time is cut into buckets of width dt. A window of nb buckets (a power of two, ~N/8) starts at
// a time origin t0; a particle's entry is in one of four states, kept in the top two bits of its
// next_ word:
//   - kHeap:   in the current bucket, a small binary heap of particle indices (the only sorted
//              part; no position map: an entry is found by a linear search of the small heap);
//   - kBucket: in a later bucket of the window, an unsorted singly-linked list threaded through
//              next_. Its bucket is recomputed from key_ (unchanged since insertion) to unlink;
//   - kBeyond: after the window. Only flagged: there is no overflow list;
//   - kNever:  infinite key. Never bucketed, never rescanned.
// When the current bucket passes the end of the window, a new turn starts: the origin moves to
// the end of the old window and the whole key array is rescanned to bucket the entries now in
// the window (O(N) per turn, i.e. O(1) per event, since a turn holds ~N/2 events). All buckets
// are empty at that moment, so dt and the origin may change freely; bucket numbers stay small,
// so huge absolute times keep their resolution.
//
// Pop order is exactly (time, particle index), the total order of BinaryHeapQueue, so both give
// bit-identical runs. The bucket map t -> floor((t - t0) / dt) is monotone, so the split into
// buckets can never reorder two entries; dt only affects speed. dt adapts at every turn to
// ~kTarget entries per bucket, and is cut mid-turn (a rebuild) when the current bucket grows
// past heap_limit_, i.e. when the time scale shrank. Many exactly equal times (a pile no dt can
// split) only raise that limit; re-keying a member of such a pile other than the top costs a
// linear search of the heap.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <vector>

#include "core/huge_page_allocator.hpp"

namespace kairos {

class CalendarQueue {
 public:
  CalendarQueue() = default;
  CalendarQueue(const CalendarQueue&) = delete;
  CalendarQueue& operator=(const CalendarQueue&) = delete;

  static constexpr const char* name() { return "calendar"; }

  void reset(const std::vector<double>& times) {
    if (times.size() > kIndexMask - 1) {
      throw std::length_error("CalendarQueue: at most 2^30 - 2 particles");
    }
    const auto n = static_cast<std::uint32_t>(times.size());
    // Fresh vectors (capacity == size), or the same ones refilled when the size is unchanged
    // (a renumbering: no second copy of them at any moment).
    if (key_.size() == n) {
      std::copy(times.begin(), times.end(), key_.begin());
      std::fill(next_.begin(), next_.end(), kBeyond);
    } else {
      key_ = HugeVector<double>(times.begin(), times.end());
      next_ = HugeVector<std::uint32_t>(n, kBeyond);
    }
    const std::uint32_t nb = std::bit_ceil(std::max<std::uint32_t>(1, n / kParticlesPerBucket));
    if (nb != nb_ || head_.size() != nb) {
      nb_ = nb;
      head_ = HugeVector<std::uint32_t>(nb_, kEnd);
    } else {
      std::fill(head_.begin(), head_.end(), kEnd);
    }
    heap_ = std::vector<std::uint32_t>(16);
    heap_n_ = 0;
    double tmin = kInf, sum = 0.0, count = 0.0;
    for (double t : key_) tmin = std::min(tmin, t);
    for (std::uint32_t i = 0; i < n; ++i) {
      if (key_[i] < kInf) {
        sum += key_[i] - tmin;
        count += 1.0;
      } else {
        next_[i] = kNever;
      }
    }
    // First guess of dt: exponential waiting times with this mean give kTarget entries in the
    // first bucket. Turns and rebuilds correct it.
    const double dt = sum > 0.0 ? kTarget * sum / (count * count) : 1.0;
    rebuild(std::isfinite(dt) && dt > 0.0 ? dt : 1.0, count > 0.0 ? tmin : 0.0);
  }

  std::uint32_t top() {
    settle();
    return heap_n_ > 0 ? heap_[0] : 0;
  }
  double top_time() {
    settle();
    return heap_n_ > 0 ? key_[heap_[0]] : kInf;
  }
  double time_of(std::uint32_t i) const { return key_[i]; }
  // The entry most likely to be popped after the top (the smaller child of the heap's root),
  // for prefetching its data; the top itself when there is no other.
  std::uint32_t likely_next() const {
    if (heap_n_ < 2) return heap_n_ > 0 ? heap_[0] : 0;
    if (heap_n_ < 3) return heap_[1];
    return key_[heap_[2]] < key_[heap_[1]] ? heap_[2] : heap_[1];
  }

  void update(std::uint32_t i, double t) {
    const double x = slot(t);
    const std::uint32_t state = next_[i] & kStateMask;
    if (state == kHeap) {
      const std::uint32_t at = heap_find(i);
      key_[i] = t;
      if (x < current_end_) {  // stays in the current bucket (never true for t = inf)
        sift_up(at);
        sift_down(at);
        ++loaded_;
        return;
      }
      heap_erase(at);
    } else if (state == kBucket) {
      unlink(i, static_cast<std::uint32_t>(slot(key_[i])));
      key_[i] = t;
    } else {
      key_[i] = t;
    }
    place(i, x);
  }

  // key, next/state word, bucket heads and the current bucket's heap, divided by N (rounded up).
  std::size_t bytes_per_particle() const {
    if (key_.empty()) return 0;
    const std::size_t bytes = key_.capacity() * sizeof(double) +
                              (next_.capacity() + head_.capacity() + heap_.capacity()) * 4;
    return (bytes + key_.size() - 1) / key_.size();
  }
  std::size_t sorted_size() const { return heap_n_; }  // entries in the current bucket

 private:
  static constexpr double kInf = std::numeric_limits<double>::infinity();
  static constexpr std::uint32_t kIndexMask = (1u << 30) - 1;
  static constexpr std::uint32_t kEnd = kIndexMask;  // end of a bucket list
  static constexpr std::uint32_t kStateMask = ~kIndexMask;
  static constexpr std::uint32_t kBucket = 0u << 30;  // next_ holds the list successor
  static constexpr std::uint32_t kHeap = 1u << 30;
  static constexpr std::uint32_t kBeyond = 2u << 30;
  static constexpr std::uint32_t kNever = 3u << 30;
  static constexpr std::uint32_t kParticlesPerBucket = 8;  // nb = bit_ceil(N / 8): <= 1 B/particle
  static constexpr double kTarget = 4.0;          // entries through the current bucket, per bucket
  static constexpr std::uint32_t kMinLimit = 64;  // smallest heap size that triggers a rebuild

  // Bucket coordinate of time t: bucket floor(slot(t)). The one formula used for placing and
  // unlinking, so that both always agree. Infinite t gives +inf, i.e. never in the window.
  double slot(double t) const { return (t - t0_) * inv_dt_; }

  // Files particle i (its key already set) by its slot x.
  void place(std::uint32_t i, double x) {
    if (x < current_end_) {
      heap_push(i);
    } else if (x < nb_double_) {
      const auto b = static_cast<std::uint32_t>(x);
      next_[i] = head_[b];
      head_[b] = i;
    } else if (key_[i] < kInf) {
      next_[i] = kBeyond;
    } else {
      next_[i] = kNever;
      return;
    }
    idle_ = false;
  }

  // Removes i from the singly-linked list of bucket b.
  void unlink(std::uint32_t i, std::uint32_t b) {
    std::uint32_t* link = &head_[b];
    while (*link != i) link = &next_[*link];
    *link = next_[i];
  }

  // Makes the heap hold the soonest entry, unless no finite key is left (idle_).
  void settle() {
    if (heap_n_ - 1 >= heap_limit_) [[unlikely]] {  // empty (wraps around) or too large
      if (heap_n_ > 0) {
        shrink_dt();
      } else {
        advance();
      }
    }
  }

  void advance() {
    while (heap_n_ == 0 && !idle_) {
      if (++current_ == nb_) {
        new_turn();
        continue;
      }
      current_end_ = static_cast<double>(current_) + 1.0;
      std::uint32_t p = head_[current_];
      head_[current_] = kEnd;
      while (p != kEnd) {
        const std::uint32_t nxt = next_[p];
        next_[p] = kHeap;
        heap_append(p);
        p = nxt;
      }
      loaded_ += heap_n_;
      heapify();
    }
  }

  // The window is used up (all buckets and the heap are empty): adapt dt to the number of
  // entries that went through the heap in this turn, move the origin to the window's end and
  // rescan. If the new window is empty (a gap in time), restart it at the soonest key.
  void new_turn() {
    const double per_bucket = static_cast<double>(loaded_) / nb_double_;
    const double dt_old = 1.0 / inv_dt_;
    const double dt = dt_old * kTarget / std::max(per_bucket, 1.0 / nb_double_);
    if (relink(t0_ + nb_double_ * dt_old, std::isfinite(dt) ? dt : dt_old) == 0) {
      double tmin = kInf;
      for (std::uint32_t i = 0; i < next_.size(); ++i) {
        if (next_[i] == kBeyond) tmin = std::min(tmin, key_[i]);
      }
      if (tmin < kInf) {
        relink(tmin, 1.0 / inv_dt_);
      } else {
        idle_ = true;  // only infinite keys: nothing to do until a finite one arrives
      }
    }
  }

  // The current bucket holds too many entries: dt is too coarse for the present time scale.
  // Cut it so that the heap's entries would spread over ~size/kTarget buckets, and rebuild from
  // the soonest key. A heap of equal times cannot be split: then only raise the limit.
  void shrink_dt() {
    const double tmin = key_[heap_[0]];
    double tmax = tmin;
    for (std::uint32_t k = 0; k < heap_n_; ++k) tmax = std::max(tmax, key_[heap_[k]]);
    const double dt = (tmax - tmin) * kTarget / heap_n_;
    if (dt > 0.0 && dt * inv_dt_ < 1.0) {
      rebuild(dt, tmin);
    } else {
      heap_limit_ = 2 * heap_n_;
    }
  }

  void rebuild(double dt, double origin) {
    std::fill(head_.begin(), head_.end(), kEnd);
    heap_n_ = 0;
    for (std::uint32_t& w : next_) {
      if (w != kNever) w = kBeyond;
    }
    idle_ = relink(origin, dt) == 0;
  }

  // Starts a turn at `origin` with bucket width dt: files every kBeyond entry that now falls in
  // the window (all buckets and the heap must be empty). Returns how many it filed.
  std::uint32_t relink(double origin, double dt) {
    t0_ = origin;
    inv_dt_ = 1.0 / dt;
    current_ = 0;
    current_end_ = 1.0;
    nb_double_ = static_cast<double>(nb_);
    loaded_ = 0;
    // The hot loop of a turn: most entries stay beyond. Plain locals, so nothing is reloaded.
    const auto n = static_cast<std::uint32_t>(next_.size());
    std::uint32_t* const next = next_.data();
    std::uint32_t* const head = head_.data();
    const double* const key = key_.data();
    const double t0 = t0_, inv_dt = inv_dt_, nbd = nb_double_;
    std::uint32_t placed = 0;
    for (std::uint32_t i = 0; i < n; ++i) {
      if (next[i] != kBeyond) continue;
      const double x = (key[i] - t0) * inv_dt;  // slot(key[i])
      if (x >= nbd) continue;
      ++placed;
      if (x < 1.0) {
        next[i] = kHeap;
        heap_append(i);
      } else {
        const auto b = static_cast<std::uint32_t>(x);
        next[i] = head[b];
        head[b] = i;
      }
    }
    loaded_ += heap_n_;
    heapify();
    heap_limit_ = std::max(kMinLimit, 4 * heap_n_);
    if (heap_.size() > 4 * heap_limit_) {  // give back what a pile of equal times needed
      heap_.resize(2 * heap_limit_);
      heap_.shrink_to_fit();
    }
    return placed;
  }

  // The current bucket: a binary min-heap of particle indices in heap_[0, heap_n_), ordered by
  // (key, index).
  std::uint32_t heap_find(std::uint32_t i) const {
    if (heap_[0] == i) return 0;  // the usual case: the engine re-predicts the particle it popped
    std::uint32_t at = 1;
    while (heap_[at] != i) ++at;
    return at;
  }
  void heap_append(std::uint32_t i) {
    if (heap_n_ == heap_.size()) heap_.resize(2 * heap_.size());
    heap_[heap_n_++] = i;
  }
  void heap_push(std::uint32_t i) {
    next_[i] = kHeap;
    heap_append(i);
    ++loaded_;
    sift_up(heap_n_ - 1);
  }
  void heap_erase(std::uint32_t at) {
    const std::uint32_t last = heap_[--heap_n_];
    if (at == heap_n_) return;
    heap_[at] = last;
    sift_up(at);
    sift_down(at);
  }
  void heapify() {
    for (std::uint32_t k = heap_n_ / 2; k-- > 0;) sift_down(k);
  }
  bool before(std::uint32_t a, double ka, std::uint32_t b, double kb) const {
    return ka < kb || (ka == kb && a < b);
  }
  void sift_up(std::uint32_t at) {
    const std::uint32_t p = heap_[at];
    const double kp = key_[p];
    while (at > 0) {
      const std::uint32_t parent = (at - 1) / 2;
      const std::uint32_t q = heap_[parent];
      if (!before(p, kp, q, key_[q])) break;
      heap_[at] = q;
      at = parent;
    }
    heap_[at] = p;
  }
  void sift_down(std::uint32_t at) {
    const std::uint32_t p = heap_[at];
    const double kp = key_[p];
    while (true) {
      std::uint32_t child = 2 * at + 1;
      if (child >= heap_n_) break;
      std::uint32_t q = heap_[child];
      double kq = key_[q];
      if (child + 1 < heap_n_) {
        const std::uint32_t r = heap_[child + 1];
        const double kr = key_[r];
        if (before(r, kr, q, kq)) {
          ++child;
          q = r;
          kq = kr;
        }
      }
      if (!before(q, kq, p, kp)) break;
      heap_[at] = q;
      at = child;
    }
    heap_[at] = p;
  }

  HugeVector<double> key_;
  HugeVector<std::uint32_t> next_;   // state (top 2 bits) | bucket-list successor
  HugeVector<std::uint32_t> head_;   // first entry of each bucket of the window, or kEnd
  std::vector<std::uint32_t> heap_;  // the current bucket, sorted; heap_n_ used of its size
  std::uint32_t heap_n_ = 0;
  std::uint32_t heap_limit_ = kMinLimit;
  std::uint32_t nb_ = 1;            // buckets in the window, a power of two
  std::uint32_t current_ = 0;       // the current bucket, 0 <= current_ < nb_
  double current_end_ = 1.0;        // current_ + 1: slot(t) below it goes to the heap
  double nb_double_ = 1.0;          // nb_: slot(t) from here on is beyond the window
  double t0_ = 0.0, inv_dt_ = 1.0;  // origin of bucket 0 of this turn, 1 / bucket width
  std::uint64_t loaded_ = 0;        // entries pushed into the heap this turn
  bool idle_ = true;                // no finite key anywhere: top_time() is +inf
};

}  // namespace kairos
