// The candidate loops against the reference contact time of dynamics/collision_time.hpp: the
// same bits for every pair, the first candidate among equal times, the bound respected.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
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

// The growing loops (Lubachevsky-Stillinger): the contact time of every pair from
// growing_contact_time, the soonest kept; scalar and AVX-512 loops to the bit, for one radius,
// radii by kind and radii per particle, scale and rate such that the growth outruns some pairs'
// approach (c < 0), and, in one trial of three, dyadic states with c == 0 exactly.
template <int D>
void check_growing_loops() {
  std::mt19937_64 rng(99 + D);
  std::uniform_real_distribution<double> u(-1.0, 1.0), rate_of(0.0, 1.5), radius_of(0.3, 0.6);
  int found_some = 0, vector_trials = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const int n = 1 + trial % 37;
    Records<D> r = random_records<D>(rng, n);
    const bool flat = trial % 3 == 2;  // c == 0: |g| == u exactly
    Vec<D> xi, vi;
    for (int a = 0; a < D; ++a) {
      xi[a] = flat ? 0.0 : u(rng);
      vi[a] = flat ? 0.0 : u(rng);
    }
    double scale = 0.8 + 0.4 * (u(rng) + 1.0), rate = rate_of(rng);
    const int sizes = trial % 4;  // 0, 1: one radius; 2: by kind; 3: per particle
    std::vector<double> particle_radius(static_cast<std::size_t>(n) + 1);
    std::vector<std::uint16_t> kind(static_cast<std::size_t>(n) + 2);
    double kind_radius[3] = {0.45, 0.3, 0.6};
    for (int j = 0; j < n; ++j) {
      particle_radius[j] = radius_of(rng);
      kind[j] = static_cast<std::uint16_t>(j % 3);
    }
    if (flat) {  // sigma0 = 1, scale 1, rate 0.5, g = (+-0.5, 0...), records at time t
      scale = 1.0;
      rate = 0.5;
      for (int j = 0; j < n; ++j) {
        double* rec = r.data.data() + j * Records<D>::kStride;
        for (int a = 0; a < D; ++a) {
          rec[a] = std::ldexp(std::round(std::ldexp(rec[a], 4)), -4);
          rec[D + a] = a == 0 ? (j % 2 == 0 ? 0.5 : -0.5) : 0.0;
        }
        rec[2 * D] = 0.25;
      }
    }
    const std::uint32_t self = static_cast<std::uint32_t>(trial % (n + 3));  // sometimes absent
    CandidateScan<D> s;
    s.records = r.data.data();
    s.stride = Records<D>::kStride;
    s.candidates = r.ids.data();
    s.shift_index = r.shift_index.data();
    s.shifts = r.shifts;
    s.any_shift = trial % 2 == 1 && !flat;
    s.count = static_cast<std::uint32_t>(n);
    s.uniform = sizes < 2 || flat;
    s.sigma = flat ? 1.0 : 0.9;
    s.radius_i = 0.45;
    s.kind = kind.data();
    s.kind_radius = kind_radius;
    s.particle_radius = sizes == 3 ? particle_radius.data() : nullptr;
    const double bound = trial % 5 == 0 ? 0.5 : kNever;
    // The reference: each pair by growing_contact_time.
    double best_ref = bound;
    std::uint32_t want = kNoCandidate;
    for (std::uint32_t k = 0; k < s.count; ++k) {
      const std::uint32_t j = s.candidates[k];
      if (j == self) continue;
      const double* rec = r.data.data() + j * Records<D>::kStride;
      const Vec<D> shift = s.any_shift ? r.shifts[r.shift_index[k]] : Vec<D>{};
      double r2 = 0, rg = 0, g2 = 0;
      for (int a = 0; a < D; ++a) {
        const double d = xi[a] - ((rec[a] + rec[D + a] * (0.25 - rec[2 * D])) + shift[a]);
        const double g = vi[a] - rec[D + a];
        r2 += d * d;
        rg += d * g;
        g2 += g * g;
      }
      const double sigma0 = s.uniform    ? s.sigma
                            : sizes == 3 ? s.radius_i + particle_radius[j]
                                         : s.radius_i + kind_radius[kind[j]];
      const double sigma = sigma0 * scale, speed = sigma0 * rate;
      const double dt =
          growing_contact_time(r2 - sigma * sigma, rg - sigma * speed, g2 - speed * speed);
      if (dt < best_ref) {
        best_ref = dt;
        want = k;
      }
    }
    double best = bound;
    const std::uint32_t got = scan_candidates_growing<D>(s, self, 0.25, xi, vi, scale, rate, best);
    ASSERT_EQ(got, want) << "scalar, trial " << trial;
    ASSERT_EQ(best, best_ref) << "scalar, trial " << trial;
    found_some += want != kNoCandidate ? 1 : 0;
    if (!cpu_has_avx512()) continue;
    s.row_loads = trial % 2 == 0;  // records by rows and a transpose, or by gathers
    double best_vector = bound;
    const std::uint32_t got_vector =
        scan_candidates_growing_avx512<D>(s, self, 0.25, xi, vi, scale, rate, best_vector);
    ASSERT_EQ(got_vector, want) << "AVX-512, trial " << trial;
    ASSERT_EQ(std::memcmp(&best_vector, &best_ref, sizeof best), 0)
        << "AVX-512, trial " << trial << ": " << best_vector << " vs " << best_ref;
    ++vector_trials;
  }
  EXPECT_GT(found_some, 1000);
  EXPECT_EQ(vector_trials, cpu_has_avx512() ? 3000 : 0);
}

TEST(CandidateScan, GrowingLoopsMatchTheReferenceContactTime) {
  check_growing_loops<3>();
  check_growing_loops<2>();
}

}  // namespace
}  // namespace kairos
