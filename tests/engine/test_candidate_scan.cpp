// The candidate loops against the reference contact time of dynamics/collision_time.hpp: the
// same bits for every pair, the first candidate among equal times, the bound respected.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "engine/candidate_scan.hpp"
#include "interactions/hard_sphere.hpp"

namespace kairos {
namespace {

// Records laid out like the engine's hot record: position, velocity, local time, padding.
template <int D>
struct Records {
  static constexpr int kStride = D == 3 ? 8 : 6;
  std::vector<double> data;
  std::vector<std::uint32_t> ids;
  std::vector<std::uint32_t> shift_index;
  Vec<D> shifts[3] = {};
};

template <int D>
Records<D> random_records(std::mt19937_64& rng, int n) {
  std::uniform_real_distribution<double> pos(-2.0, 2.0), vel(-1.0, 1.0), time(-0.5, 0.0);
  Records<D> r;
  r.data.assign(static_cast<std::size_t>(n) * Records<D>::kStride, 0.0);
  for (int j = 0; j < n; ++j) {
    double* rec = r.data.data() + j * Records<D>::kStride;
    for (int a = 0; a < D; ++a) {
      rec[a] = pos(rng);
      rec[D + a] = vel(rng);
    }
    rec[2 * D] = time(rng);
    r.ids.push_back(static_cast<std::uint32_t>(j));
    r.shift_index.push_back(static_cast<std::uint32_t>(j % 3));
  }
  r.shifts[1][0] = 7.0;
  r.shifts[2][D - 1] = -7.0;
  return r;
}

// The reference: each candidate's contact time from HardSphere::contact_time, soonest first
// (strictly earlier wins, so the first of equal times).
template <int D>
std::uint32_t reference(const Records<D>& r, bool shifted, double t, const Vec<D>& xi,
                        const Vec<D>& vi, double sigma, double& best) {
  std::uint32_t found = kNoCandidate;
  for (std::uint32_t k = 0; k < r.ids.size(); ++k) {
    const double* rec = r.data.data() + r.ids[k] * Records<D>::kStride;
    const Vec<D> shift = shifted ? r.shifts[r.shift_index[k]] : Vec<D>{};
    double r2 = 0, rg = 0, g2 = 0;
    for (int a = 0; a < D; ++a) {
      const double d = xi[a] - ((rec[a] + rec[D + a] * (t - rec[2 * D])) + shift[a]);
      const double g = vi[a] - rec[D + a];
      r2 += d * d;
      rg += d * g;
      g2 += g * g;
    }
    const double dt = HardSphere::contact_time(r2, rg, g2, sigma);
    if (dt < best) {
      best = dt;
      found = k;
    }
  }
  return found;
}

template <int D>
void check_against_reference(bool vector) {
  std::mt19937_64 rng(42 + D);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int found_some = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const int n = 1 + trial % 37;  // every tail length of the 8-wide loop
    const Records<D> r = random_records<D>(rng, n);
    const bool shifted = trial % 2 == 1;
    CandidateScan<D> s;
    s.records = r.data.data();
    s.stride = Records<D>::kStride;
    s.candidates = r.ids.data();
    s.shift_index = r.shift_index.data();
    s.shifts = r.shifts;
    s.any_shift = shifted;
    s.count = static_cast<std::uint32_t>(n);
    s.uniform = true;
    s.sigma = 0.9;
    Vec<D> xi, vi;
    for (int a = 0; a < D; ++a) {
      xi[a] = u(rng);
      vi[a] = u(rng);
    }
    const double bound = trial % 3 == 0 ? 0.5 : kNever;
    double best_ref = bound, best = bound;
    const std::uint32_t want = reference<D>(r, shifted, 0.25, xi, vi, 0.9, best_ref);
    const std::uint32_t got = vector ? scan_candidates_avx512<D>(s, 0.25, xi, vi, best)
                                     : scan_candidates_scalar<D>(s, 0.25, xi, vi, best);
    ASSERT_EQ(got, want) << "trial " << trial;
    ASSERT_EQ(best, best_ref) << "trial " << trial;  // bit for bit
    found_some += want != kNoCandidate ? 1 : 0;
  }
  EXPECT_GT(found_some, 500);  // the trials exercise real contacts, not only misses
}

TEST(CandidateScan, ScalarLoopMatchesTheReferenceContactTime) {
  check_against_reference<3>(false);
  check_against_reference<2>(false);
}

TEST(CandidateScan, VectorLoopMatchesTheReferenceContactTime) {
  if (!cpu_has_avx512()) GTEST_SKIP() << "this CPU has no AVX-512";
  check_against_reference<3>(true);
  check_against_reference<2>(true);
}

TEST(CandidateScan, FirstOfEqualContactTimesWins) {
  // Two identical candidates: the first in list order must be chosen by both loops.
  std::mt19937_64 rng(7);
  for (int copies : {2, 9, 17}) {
    Records<3> r;
    r.data.assign(static_cast<std::size_t>(copies) * 8, 0.0);
    for (int j = 0; j < copies; ++j) {
      double* rec = r.data.data() + j * 8;
      rec[0] = 2.0;
      rec[3] = -1.0;
      r.ids.push_back(static_cast<std::uint32_t>(copies - 1 - j));  // list order != index order
      r.shift_index.push_back(0);
    }
    CandidateScan<3> s;
    s.records = r.data.data();
    s.stride = 8;
    s.candidates = r.ids.data();
    s.shift_index = r.shift_index.data();
    s.shifts = r.shifts;
    s.count = static_cast<std::uint32_t>(copies);
    s.sigma = 1.0;
    double best = kNever;
    EXPECT_EQ(scan_candidates_scalar<3>(s, 0.0, {0, 0, 0}, {0, 0, 0}, best), 0u);
    EXPECT_EQ(best, 1.0);
    if (cpu_has_avx512()) {
      best = kNever;
      EXPECT_EQ(scan_candidates_avx512<3>(s, 0.0, {0, 0, 0}, {0, 0, 0}, best), 0u);
      EXPECT_EQ(best, 1.0);
    }
  }
}

}  // namespace
}  // namespace kairos
