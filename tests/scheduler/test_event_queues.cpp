// The event queues against a reference ordered set, on the access pattern of the engine: pop
// the soonest particle, give it (and sometimes others) a new time no earlier than now. Every
// queue must pop in exactly (time, index) order, so that runs are bit-identical whichever
// queue is used.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <set>

#include "scheduler/binary_heap_queue.hpp"
#include "scheduler/calendar_queue.hpp"
#include "scheduler/tournament_tree_queue.hpp"

namespace kairos {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

template <class Queue>
class QueueChecker {
 public:
  explicit QueueChecker(const std::vector<double>& times) { reset(times); }
  void reset(const std::vector<double>& times) {
    key_ = times;
    ref_.clear();
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
  void check_keys() const {
    for (std::uint32_t i = 0; i < key_.size(); ++i) ASSERT_EQ(queue_.time_of(i), key_[i]);
  }
  std::uint32_t size() const { return static_cast<std::uint32_t>(key_.size()); }
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
  q.check_keys();
}

// A harsher mix than the engine's: several kinds of update per pop, each no earlier than now.
//   - +inf (the particle has no event), and later a finite time again;
//   - times on a coarse grid, so that many keys are exactly equal;
//   - bursts far in the future (far beyond any window);
//   - the time scale jumping by 1e6 down and back up during the run.
template <class Queue>
void stress_sequence(QueueChecker<Queue>& q, std::uint64_t steps, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::exponential_distribution<double> unit(1.0);
  const std::uint32_t n = q.size();
  for (std::uint64_t s = 0; s < steps; ++s) {
    const double scale = (s / (steps / 5)) % 2 == 1 ? 1e-6 : 1.0;  // 1, 1e-6, 1, 1e-6, 1
    const auto [i, now] = q.top();
    if (!std::isfinite(now)) {  // everything infinite: wake a few particles up
      for (int k = 0; k < 3; ++k) q.update(static_cast<std::uint32_t>(rng() % n), unit(rng));
      continue;
    }
    const double r = u(rng);
    double t = now + scale * unit(rng);
    if (r < 0.05) {
      t = kInf;
    } else if (r < 0.25) {
      t = now + scale * std::floor(4.0 * unit(rng)) * 0.25;  // equal keys, including now itself
    } else if (r < 0.28) {
      t = now + 1e6 * scale * (1.0 + unit(rng));  // far future
    }
    q.update(i, t);
    const int others = static_cast<int>(rng() % 3);
    for (int k = 0; k < others; ++k) {
      const auto j = static_cast<std::uint32_t>(rng() % n);
      const double r2 = u(rng);
      if (r2 < 0.1) {
        q.update(j, kInf);
      } else if (r2 < 0.3) {
        q.update(j, q.queue().time_of(j) < kInf ? q.queue().time_of(j) : now);  // unchanged
      } else if (r2 < 0.5) {
        q.update(j, now);  // equal to the current top
      } else {
        q.update(j, now + scale * unit(rng));
      }
    }
  }
  q.check_keys();
}

template <class Queue>
class EventQueue : public testing::Test {};

using QueueTypes = testing::Types<BinaryHeapQueue, CalendarQueue, TournamentTreeQueue>;
TYPED_TEST_SUITE(EventQueue, QueueTypes);

TYPED_TEST(EventQueue, IsNotCopyable) {
  static_assert(!std::is_copy_constructible_v<TypeParam>);
  static_assert(!std::is_copy_assignable_v<TypeParam>);
}

TYPED_TEST(EventQueue, EngineLikeSequencesMatchReference) {
  engine_like_sequence<TypeParam>(1000, 0.0, 1.0, 50000, 1);
  engine_like_sequence<TypeParam>(1, 0.0, 1.0, 1000, 2);
  engine_like_sequence<TypeParam>(2, 0.0, 1.0, 1000, 2);
  engine_like_sequence<TypeParam>(3000, 1e4, 0.01, 50000, 3);     // late start, fine scale
  engine_like_sequence<TypeParam>(500, 0.0, 1.0, 20000, 4, 0.2);  // some never happen
  engine_like_sequence<TypeParam>(777, 1e12, 1e-3, 20000, 5);     // huge absolute times
}

TYPED_TEST(EventQueue, StressSequencesMatchReference) {
  for (std::uint32_t n : {1u, 7u, 100u, 5000u}) {
    std::mt19937_64 rng(100 + n);
    std::exponential_distribution<double> unit(1.0);
    std::vector<double> times(n);
    for (double& t : times) t = unit(rng);
    QueueChecker<TypeParam> q(times);
    stress_sequence(q, 20000, rng);
  }
}

TYPED_TEST(EventQueue, ResetTwiceStartsAfresh) {
  std::mt19937_64 rng(7);
  std::exponential_distribution<double> unit(1.0);
  std::vector<double> times(3000);
  for (double& t : times) t = 5.0 + unit(rng);
  QueueChecker<TypeParam> q(times);
  stress_sequence(q, 10000, rng);
  // Smaller, with earlier times than anything the queue has seen, lattice-like equal times.
  std::vector<double> again(1200);
  for (std::uint32_t i = 0; i < again.size(); ++i) again[i] = (i % 3 == 0) ? 1.0 : unit(rng);
  q.reset(again);
  stress_sequence(q, 10000, rng);
  // Larger again.
  std::vector<double> larger(6000);
  for (double& t : larger) t = 1e3 * unit(rng);
  q.reset(larger);
  stress_sequence(q, 10000, rng);
}

TYPED_TEST(EventQueue, AllInfiniteAndOneFarFutureEvent) {
  std::vector<double> times(100, kInf);
  QueueChecker<TypeParam> all_inf(times);
  EXPECT_EQ(all_inf.queue().top_time(), kInf);
  EXPECT_EQ(all_inf.queue().top_time(), kInf);
  all_inf.update(17, 3.0);  // a finite key after only infinite ones
  EXPECT_EQ(all_inf.top().first, 17u);
  times[42] = 1e6;  // far beyond the first window
  QueueChecker<TypeParam> far(times);
  EXPECT_EQ(far.top().first, 42u);
  far.update(42, kInf);
  EXPECT_EQ(far.queue().top_time(), kInf);
  TypeParam empty;
  empty.reset({});
  EXPECT_EQ(empty.top_time(), kInf);
}

TYPED_TEST(EventQueue, EqualTimesPopInIndexOrder) {
  const std::vector<double> times = {2.0, 1.0, 1.0, 3.0, 1.0};
  QueueChecker<TypeParam> q(times);
  std::vector<std::uint32_t> order;
  for (int k = 0; k < 5; ++k) {
    const auto [i, t] = q.top();
    order.push_back(i);
    q.update(i, kInf);
  }
  EXPECT_EQ(order, (std::vector<std::uint32_t>{1, 2, 4, 0, 3}));
}

TYPED_TEST(EventQueue, ManyEqualTimes) {
  // A lattice-like start: a large share of the keys identical, popped in index order.
  std::vector<double> times(4000);
  for (std::uint32_t i = 0; i < times.size(); ++i) times[i] = (i % 4 == 0) ? 0.5 : 1.0;
  QueueChecker<TypeParam> q(times);
  std::mt19937_64 rng(9);
  std::exponential_distribution<double> unit(1.0);
  for (int s = 0; s < 12000; ++s) {
    const auto [i, now] = q.top();
    q.update(i, now + unit(rng));
    if (s % 3 == 0) q.update(static_cast<std::uint32_t>(rng() % times.size()), now + unit(rng));
  }
}

TYPED_TEST(EventQueue, KeysOnBucketEdges) {
  // Integer multiples of a power of two land exactly on bucket boundaries.
  std::vector<double> times(256);
  for (std::uint32_t i = 0; i < times.size(); ++i) times[i] = 0.125 * (i % 17);
  QueueChecker<TypeParam> q(times);
  for (int s = 0; s < 5000; ++s) {
    const auto [i, now] = q.top();
    q.update(i, now + 0.125 * static_cast<double>(1 + (s % 7)));
  }
}

TEST(CalendarQueue, TimeScaleChangesKeepTheSortedBucketSmall) {
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

TEST(CalendarQueue, SmallFootprintAfterARealisticRun) {
  // The engine's pattern at N = 1e5: the popped particle and a partner get new times.
  std::mt19937_64 rng(11);
  std::exponential_distribution<double> exp_time(1.0);
  const std::uint32_t n = 100000;
  std::vector<double> times(n);
  for (double& t : times) t = exp_time(rng);
  CalendarQueue q;
  q.reset(times);
  std::size_t largest = 0;
  for (std::uint32_t s = 0; s < 20 * n; ++s) {
    const std::uint32_t i = q.top();
    const double now = q.top_time();
    q.update(i, now + exp_time(rng));
    q.update(static_cast<std::uint32_t>(rng() % n), now + exp_time(rng));
    largest = std::max(largest, q.sorted_size());
  }
  EXPECT_LE(q.bytes_per_particle(), 14u);
  EXPECT_LE(largest, 256u);
}

TEST(TournamentTreeQueue, Footprint) {
  std::vector<double> times(100000, 1.0);
  TournamentTreeQueue q;
  q.reset(times);
  EXPECT_EQ(q.bytes_per_particle(), 12u);
}

}  // namespace
}  // namespace kairos
