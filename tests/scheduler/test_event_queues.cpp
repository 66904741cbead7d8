// Both event queues against a reference ordered set, on the access pattern of the engine: pop
// the soonest particle, give it (and sometimes others) a new time no earlier than now.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <set>

#include "scheduler/binary_heap_queue.hpp"
#include "scheduler/calendar_queue.hpp"

namespace kairos {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

template <class Queue>
class QueueChecker {
 public:
  explicit QueueChecker(const std::vector<double>& times) : key_(times) {
    queue_.reset(times);
    for (std::uint32_t i = 0; i < times.size(); ++i) ref_.insert({times[i], i});
  }
  void update(std::uint32_t i, double t) {
    ref_.erase({key_[i], i});
    key_[i] = t;
    ref_.insert({t, i});
    queue_.update(i, t);
  }
  // Checks the queue's top against the reference; returns (particle, time).
  std::pair<std::uint32_t, double> top() {
    const auto [t, i] = *ref_.begin();
    EXPECT_EQ(queue_.top_time(), t);
    if (std::isfinite(t)) {
      EXPECT_EQ(queue_.top(), i);
    }
    return {i, t};
  }
  Queue& queue() { return queue_; }

 private:
  Queue queue_;
  std::vector<double> key_;
  std::set<std::pair<double, std::uint32_t>> ref_;
};

template <class Queue>
void engine_like_sequence(std::uint32_t n, double t0, double scale, std::uint64_t steps,
                          std::uint64_t seed, double p_inf = 0.0) {
  std::mt19937_64 rng(seed);
  std::exponential_distribution<double> exp_time(1.0 / scale);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> times(n);
  for (double& t : times) t = u(rng) < p_inf ? kInf : t0 + exp_time(rng);
  QueueChecker<Queue> q(times);
  for (std::uint64_t s = 0; s < steps; ++s) {
    const auto [i, now] = q.top();
    if (!std::isfinite(now)) return;
    q.update(i, u(rng) < p_inf ? kInf : now + exp_time(rng));
    if (u(rng) < 0.5) {  // a partner, elsewhere in the queue, is re-predicted too
      const auto j = static_cast<std::uint32_t>(rng() % n);
      q.update(j, now + exp_time(rng));
    }
  }
}

TEST(EventQueues, EngineLikeSequencesMatchReference) {
  engine_like_sequence<BinaryHeapQueue>(1000, 0.0, 1.0, 50000, 1);
  engine_like_sequence<CalendarQueue>(1000, 0.0, 1.0, 50000, 1);
  engine_like_sequence<CalendarQueue>(1, 0.0, 1.0, 1000, 2);
  engine_like_sequence<CalendarQueue>(3000, 1e4, 0.01, 50000, 3);     // late start, fine scale
  engine_like_sequence<CalendarQueue>(500, 0.0, 1.0, 20000, 4, 0.2);  // some never happen
}

TEST(EventQueues, TimeScaleChangesKeepTheSortedBucketSmall) {
  // The event time scale shrinks 1000-fold mid-run (a cooling granular gas does the opposite):
  // the calendar must re-adapt its bucket width, not degrade into one big heap.
  std::mt19937_64 rng(5);
  std::exponential_distribution<double> slow(1.0), fast(1000.0);
  const std::uint32_t n = 4096;
  std::vector<double> times(n);
  for (double& t : times) t = slow(rng);
  QueueChecker<CalendarQueue> q(times);
  std::size_t largest = 0;
  for (int s = 0; s < 200000; ++s) {
    const auto [i, now] = q.top();
    q.update(i, now + (s < 20000 ? slow(rng) : fast(rng)));
    if (s > 100000) largest = std::max(largest, q.queue().sorted_size());
  }
  EXPECT_LE(largest, n / 8);  // without adaptation it would hold most of the 4096
}

TEST(EventQueues, AllInfiniteAndOneFarFutureEvent) {
  std::vector<double> times(100, kInf);
  QueueChecker<CalendarQueue> all_inf(times);
  EXPECT_EQ(all_inf.queue().top_time(), kInf);
  times[42] = 1e6;  // far beyond the first window: found by the overflow jump
  QueueChecker<CalendarQueue> far(times);
  EXPECT_EQ(far.top().first, 42u);
  far.update(42, kInf);
  EXPECT_EQ(far.queue().top_time(), kInf);
}

TEST(EventQueues, EqualTimesPopInIndexOrder) {
  std::vector<double> times = {2.0, 1.0, 1.0, 3.0, 1.0};
  for (int variant = 0; variant < 2; ++variant) {
    std::vector<std::uint32_t> order;
    if (variant == 0) {
      QueueChecker<CalendarQueue> q(times);
      for (int k = 0; k < 5; ++k) {
        const auto [i, t] = q.top();
        order.push_back(i);
        q.update(i, kInf);
      }
    } else {
      QueueChecker<BinaryHeapQueue> q(times);
      for (int k = 0; k < 5; ++k) {
        const auto [i, t] = q.top();
        order.push_back(i);
        q.update(i, kInf);
      }
    }
    EXPECT_EQ(order, (std::vector<std::uint32_t>{1, 2, 4, 0, 3}));
  }
}

TEST(EventQueues, KeysOnBucketEdges) {
  // Integer multiples of a power of two land exactly on bucket boundaries.
  std::vector<double> times(256);
  for (std::uint32_t i = 0; i < times.size(); ++i) times[i] = 0.125 * (i % 17);
  QueueChecker<CalendarQueue> q(times);
  for (int s = 0; s < 5000; ++s) {
    const auto [i, now] = q.top();
    q.update(i, now + 0.125 * static_cast<double>(1 + (s % 7)));
  }
}

}  // namespace
}  // namespace kairos
