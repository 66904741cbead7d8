// Tournament (winner) tree event queue: O(log N) per update in 12 bytes per particle.
//
// A complete binary tree in one array: internal node k (1 <= k < N) has children 2k and 2k+1,
// and node N + i is the leaf of particle i (implicit, not stored). Every node in [2, 2N) has
// exactly one parent, so node 1 is the root over all leaves for any N, power of two or not.
// Each internal node stores the index of the winning particle of its subtree, the smallest
// (key, index) pair: the same total order as BinaryHeapQueue, so runs are bit-identical.
// An update replays the matches on the path from the particle's leaf to the root; nothing
// needs to know where a particle sits, so there is no position map.
#pragma once

#include <cstdint>
#include <limits>
#include <stdexcept>
#include <vector>

namespace kairos {

class TournamentTreeQueue {
 public:
  TournamentTreeQueue() = default;
  TournamentTreeQueue(const TournamentTreeQueue&) = delete;
  TournamentTreeQueue& operator=(const TournamentTreeQueue&) = delete;

  static constexpr const char* name() { return "tree"; }

  void reset(const std::vector<double>& times) {
    if (times.size() >= (std::size_t{1} << 31)) {
      throw std::length_error("TournamentTreeQueue: at most 2^31 - 1 particles");
    }
    n_ = static_cast<std::uint32_t>(times.size());
    key_ = std::vector<double>(times);
    win_ = std::vector<std::uint32_t>(n_, 0);  // win_[0] is unused
    for (std::uint32_t k = n_; k-- > 1;) win_[k] = better(winner(2 * k), winner(2 * k + 1));
  }

  std::uint32_t top() const { return n_ > 1 ? win_[1] : 0; }
  double top_time() const { return n_ > 0 ? key_[top()] : std::numeric_limits<double>::infinity(); }
  double time_of(std::uint32_t i) const { return key_[i]; }

  void update(std::uint32_t i, double t) {
    key_[i] = t;
    std::uint32_t w = i;  // winner of the subtree below node k
    for (std::uint32_t k = n_ + i; k > 1; k >>= 1) {
      w = better(w, winner(k ^ 1));
      // A winner other than i that was already there: nothing above can change.
      if (win_[k >> 1] == w && w != i) return;
      win_[k >> 1] = w;
    }
  }

  std::size_t bytes_per_particle() const {
    if (n_ == 0) return 0;
    const std::size_t bytes = key_.capacity() * sizeof(double) + win_.capacity() * 4;
    return (bytes + n_ - 1) / n_;
  }

 private:
  std::uint32_t winner(std::uint32_t node) const { return node >= n_ ? node - n_ : win_[node]; }
  std::uint32_t better(std::uint32_t a, std::uint32_t b) const {
    const double ka = key_[a], kb = key_[b];
    return (kb < ka || (kb == ka && b < a)) ? b : a;
  }

  std::uint32_t n_ = 0;
  std::vector<double> key_;
  std::vector<std::uint32_t> win_;  // win_[k]: winning particle of internal node k
};

}  // namespace kairos
