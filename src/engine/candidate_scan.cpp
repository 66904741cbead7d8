#include "engine/candidate_scan.hpp"

#include <immintrin.h>

#include <limits>

namespace kairos {

bool cpu_has_avx512() {
#if defined(__x86_64__) && defined(__GNUC__)
  static const bool has = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
                          __builtin_cpu_supports("avx512bw");
  return has;
#else
  return false;
#endif
}

bool cpu_gathers_fast() {
#if defined(__x86_64__) && defined(__GNUC__)
  static const bool fast = cpu_has_avx512() && __builtin_cpu_is("intel");
  return fast;
#else
  return false;
#endif
}

#if defined(__x86_64__) && defined(__GNUC__)

// Everything up to the matching pop_options is compiled for AVX-512 (and only ever called
// after cpu_has_avx512()).
#pragma GCC push_options
#pragma GCC target("avx512f,avx512vl,avx512bw")
// GCC 12 flags its own _mm512_undefined_pd() inside the intrinsics headers (a known false
// positive of -Wmaybe-uninitialized); nothing in this file reads an uninitialised value.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"

namespace {

// Field f of the eight records whose first doubles sit at offsets `base` (masked lanes: 0).
inline __m512d gather_field(const double* records, __m256i base, __mmask8 live, int f) {
  return _mm512_mask_i32gather_pd(_mm512_setzero_pd(), live,
                                  _mm256_add_epi32(base, _mm256_set1_epi32(f)), records, 8);
}

// The position, velocity and local time of eight candidates' records, one vector per field.
template <int D>
struct RecordColumns {
  __m512d pos[D], vel[D], time;
};

// By one gather per field (masked lanes: 0).
template <int D>
[[gnu::always_inline]] inline RecordColumns<D> gather_columns(const double* records, __m256i base,
                                                              __mmask8 live) {
  RecordColumns<D> c;
  c.time = gather_field(records, base, live, 2 * D);
  for (int a = 0; a < D; ++a) {
    c.pos[a] = gather_field(records, base, live, a);
    c.vel[a] = gather_field(records, base, live, D + a);
  }
  return c;
}

// 128-bit lanes 0 and 2 of a, then of b; odd(): lanes 1 and 3.
[[gnu::always_inline]] inline __m512d even(__m512d a, __m512d b) {
  return _mm512_shuffle_f64x2(a, b, 0x88);
}
[[gnu::always_inline]] inline __m512d odd(__m512d a, __m512d b) {
  return _mm512_shuffle_f64x2(a, b, 0xdd);
}

// By one load per record (its 2D + 1 fields: most of a cache line) and an 8 x 8 transpose, for
// CPUs whose gathers are slow. Lanes whose ids are 0 (masked) read record 0.
template <int D>
[[gnu::always_inline]] inline RecordColumns<D> load_columns(const double* records, int stride,
                                                            __m256i ids) {
  alignas(32) std::uint32_t id[8];
  _mm256_store_si256(reinterpret_cast<__m256i*>(id), ids);
  constexpr __mmask8 kFields = static_cast<__mmask8>((1u << (2 * D + 1)) - 1u);
  __m512d r[8];
  for (int l = 0; l < 8; ++l)
    r[l] = _mm512_maskz_loadu_pd(kFields, records + static_cast<std::size_t>(id[l]) * stride);
  // Pairs of rows interleaved: 128-bit lane q of lo[p] holds field 2q of rows 2p and 2p + 1,
  // of hi[p] field 2q + 1.
  __m512d lo[4], hi[4];
  for (int p = 0; p < 4; ++p) {
    lo[p] = _mm512_unpacklo_pd(r[2 * p], r[2 * p + 1]);
    hi[p] = _mm512_unpackhi_pd(r[2 * p], r[2 * p + 1]);
  }
  // 128-bit lanes (0, 2) or (1, 3) of two such vectors, twice: eight rows of one field.
  __m512d field[8];
  const __m512d e0 = even(lo[0], lo[1]), e1 = odd(lo[0], lo[1]);
  const __m512d e2 = even(lo[2], lo[3]), e3 = odd(lo[2], lo[3]);
  const __m512d o0 = even(hi[0], hi[1]), o1 = odd(hi[0], hi[1]);
  const __m512d o2 = even(hi[2], hi[3]), o3 = odd(hi[2], hi[3]);
  field[0] = even(e0, e2);
  field[4] = odd(e0, e2);
  field[2] = even(e1, e3);
  field[6] = odd(e1, e3);
  field[1] = even(o0, o2);
  field[5] = odd(o0, o2);
  field[3] = even(o1, o3);
  RecordColumns<D> c;
  c.time = field[2 * D];
  for (int a = 0; a < D; ++a) {
    c.pos[a] = field[a];
    c.vel[a] = field[D + a];
  }
  return c;
}

template <int D>
[[gnu::always_inline]] inline RecordColumns<D> record_columns(const CandidateScan<D>& s,
                                                              __m256i ids, __m256i base,
                                                              __mmask8 live) {
  return s.row_loads ? load_columns<D>(s.records, s.stride, ids)
                     : gather_columns<D>(s.records, base, live);
}

// r.r, r.g and g.g of the eight candidates k..k+7 (lanes `live`, record fields `c`) against
// particle i (position vxi, velocity vvi, broadcast): the part both AVX-512 loops share, in the
// scalar loop's order of operations.
template <int D, bool kAccelerated>
[[gnu::always_inline]] inline void pair_terms(const CandidateScan<D>& s, std::uint32_t k,
                                              const RecordColumns<D>& c, __mmask8 live, __m512d vt,
                                              const __m512d* vxi, const __m512d* vvi, __m512d& r2,
                                              __m512d& rg, __m512d& g2, __m512d& dtj) {
  const __m512d zero = _mm512_setzero_pd();
  dtj = _mm512_sub_pd(vt, c.time);
  r2 = zero;
  rg = zero;
  g2 = zero;
  __m256i shift_base = _mm256_setzero_si256();
  if (s.any_shift) {
    const __m256i sidx = _mm256_maskz_loadu_epi32(live, s.shift_index + k);
    shift_base = _mm256_mullo_epi32(sidx, _mm256_set1_epi32(D));
  }
  for (int a = 0; a < D; ++a) {
    __m512d vel = c.vel[a];
    __m512d xj = _mm512_add_pd(c.pos[a], _mm512_mul_pd(vel, dtj));
    if constexpr (kAccelerated) {
      xj = _mm512_add_pd(xj,
                         _mm512_mul_pd(_mm512_mul_pd(_mm512_set1_pd(s.half_accel[a]), dtj), dtj));
      vel = _mm512_add_pd(vel, _mm512_mul_pd(_mm512_set1_pd(s.accel[a]), dtj));
    }
    if (s.any_shift) {
      const __m512d sh =
          _mm512_mask_i32gather_pd(zero, live, _mm256_add_epi32(shift_base, _mm256_set1_epi32(a)),
                                   reinterpret_cast<const double*>(s.shifts), 8);
      xj = _mm512_add_pd(xj, sh);
    }
    const __m512d r = _mm512_sub_pd(vxi[a], xj);
    const __m512d g = _mm512_sub_pd(vvi[a], vel);
    r2 = _mm512_add_pd(r2, _mm512_mul_pd(r, r));
    rg = _mm512_add_pd(rg, _mm512_mul_pd(r, g));
    g2 = _mm512_add_pd(g2, _mm512_mul_pd(g, g));
  }
}

// Appends the indices of the lanes `lanes` of the block starting at k to s.delayed (candidates
// in deferred soft contacts, left to the caller).
template <int D>
[[gnu::always_inline]] inline void list_lanes(const CandidateScan<D>& s, std::uint32_t k,
                                              __mmask8 lanes) {
  const __m256i index = _mm256_add_epi32(_mm256_set1_epi32(static_cast<int>(k)),
                                         _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
  _mm256_mask_compressstoreu_epi32(s.delayed + *s.delayed_count, lanes, index);
  *s.delayed_count += static_cast<std::uint32_t>(__builtin_popcount(lanes));
}

// The contact distances radius_i + the candidate's radius of mixed sizes: its own radius
// (s.particle_radius, growing loop only) or its kind's. Kinds are 16-bit: gather 32 bits at each
// and keep the low half (the array is padded by the engine so the last read stays inside it).
template <int D>
[[gnu::always_inline]] inline __m512d contact_distance(const CandidateScan<D>& s, __m256i ids,
                                                       __mmask8 live, __m512d vradius_i) {
  if (s.particle_radius != nullptr) {
    const __m512d rj =
        _mm512_mask_i32gather_pd(_mm512_setzero_pd(), live, ids, s.particle_radius, 8);
    return _mm512_add_pd(vradius_i, rj);
  }
  const __m512i raw = _mm512_mask_i32gather_epi32(_mm512_setzero_si512(), __mmask16(live),
                                                  _mm512_castsi256_si512(ids), s.kind, 2);
  const __m256i shp = _mm256_and_si256(_mm512_castsi512_si256(raw), _mm256_set1_epi32(0xffff));
  const __m512d rj = _mm512_mask_i32gather_pd(_mm512_setzero_pd(), live, shp, s.kind_radius, 8);
  return _mm512_add_pd(vradius_i, rj);
}

// Their squares, for the hard-sphere loops.
template <int D>
[[gnu::always_inline]] inline __m512d contact_distance2(const CandidateScan<D>& s, __m256i ids,
                                                        __mmask8 live, __m512d vradius_i) {
  const __m512d sigma = contact_distance<D>(s, ids, live, vradius_i);
  return _mm512_mul_pd(sigma, sigma);
}

// The pair test of the scan loops for the lanes `lanes`: the contact time gap/(-rg + sqrt(disc))
// of approaching lanes that the cheap bound (at least gap/(-2 rg)) does not rule out; lowers best
// to the soonest and sets found to the lowest lane holding it (k: the first lane's index).
[[gnu::always_inline]] inline void keep_soonest(__mmask8 lanes, __m512d gap, __m512d rg, __m512d g2,
                                                std::uint32_t k, double& best,
                                                std::uint32_t& found) {
  const __m512d zero = _mm512_setzero_pd();
  const __m512d bound =
      _mm512_mul_pd(_mm512_mul_pd(_mm512_set1_pd(-2.0), rg), _mm512_set1_pd(best));
  __mmask8 ok = _mm512_mask_cmp_pd_mask(lanes, rg, zero, _CMP_LT_OQ);
  ok = _mm512_mask_cmp_pd_mask(ok, gap, bound, _CMP_LE_OQ);
  if (ok == 0) return;
  const __m512d disc = _mm512_sub_pd(_mm512_mul_pd(rg, rg), _mm512_mul_pd(g2, gap));
  ok = _mm512_mask_cmp_pd_mask(ok, disc, zero, _CMP_GT_OQ);
  if (ok == 0) return;
  __m512d dt = _mm512_div_pd(gap, _mm512_sub_pd(_mm512_sqrt_pd(disc), rg));
  dt = _mm512_mask_blend_pd(_mm512_cmp_pd_mask(dt, zero, _CMP_GT_OQ), zero, dt);
  dt = _mm512_mask_blend_pd(ok, _mm512_set1_pd(std::numeric_limits<double>::infinity()), dt);
  const double m = _mm512_reduce_min_pd(dt);
  if (m < best) {
    const __mmask8 at = _mm512_mask_cmp_pd_mask(ok, dt, _mm512_set1_pd(m), _CMP_EQ_OQ);
    best = m;
    found = k + static_cast<std::uint32_t>(__builtin_ctz(at));
  }
}

}  // namespace

// Eight candidates per iteration. Record fields come in by gathers or row loads (record_columns;
// the records were prefetched while the candidate list was built); lanes past the end read
// record 0 and are masked out.
// Every lane computes the full contact time; invalid lanes (receding, near miss, beaten by the
// cheap bound) become +inf, and the lowest lane holding the minimum wins, as in list order.
template <int D, bool kAccelerated>
std::uint32_t scan_candidates_avx512(const CandidateScan<D>& s, double t, const Vec<D>& xi,
                                     const Vec<D>& vi, double& best) {
  const __m512d zero = _mm512_setzero_pd();
  const __m512d vt = _mm512_set1_pd(t);
  __m512d vxi[D], vvi[D];
  for (int a = 0; a < D; ++a) {
    vxi[a] = _mm512_set1_pd(xi[a]);
    vvi[a] = _mm512_set1_pd(vi[a]);
  }
  const __m512d vsigma2 = _mm512_set1_pd(s.sigma * s.sigma);
  const __m512d vradius_i = _mm512_set1_pd(s.radius_i);
  const __m256i vstride = _mm256_set1_epi32(s.stride);
  std::uint32_t found = kNoCandidate;
  for (std::uint32_t k = 0; k < s.count; k += 8) {
    const std::uint32_t left = s.count - k;
    const __mmask8 live = left >= 8 ? __mmask8(0xff) : __mmask8((1u << left) - 1u);
    const __m256i ids = _mm256_maskz_loadu_epi32(live, s.candidates + k);
    const __m256i base = _mm256_mullo_epi32(ids, vstride);
    __m512d r2, rg, g2, dtj;
    pair_terms<D, kAccelerated>(s, k, record_columns(s, ids, base, live), live, vt, vxi, vvi, r2,
                                rg, g2, dtj);
    // Candidates inside a deferred soft contact (local time after t) are left to the caller.
    const __mmask8 future = _mm512_mask_cmp_pd_mask(live, dtj, zero, _CMP_LT_OQ);
    if (future != 0 && s.delayed != nullptr) [[unlikely]]
      list_lanes<D>(s, k, future);
    const __m512d sigma2 = s.uniform ? vsigma2 : contact_distance2<D>(s, ids, live, vradius_i);
    keep_soonest(static_cast<__mmask8>(live & ~future), _mm512_sub_pd(r2, sigma2), rg, g2, k, best,
                 found);
  }
  return found;
}

// Eight candidates per iteration, as scan_candidates_avx512 (no gravity): the record fields are
// read once and serve both the placed particle's tests and the prediction.
template <int D>
ContactProbeResult probe_contact_avx512(const CandidateScan<D>& s, double t,
                                        const ContactProbe<D>& probe, const Vec<D>& xi,
                                        const Vec<D>& vi, double& best) {
  ContactProbeResult out;
  const __m512d zero = _mm512_setzero_pd();
  const __m512d vt = _mm512_set1_pd(t);
  const __m512d vspan = _mm512_set1_pd(probe.span);
  const __m512d minus_two = _mm512_set1_pd(-2.0);
  __m512d vxp[D], vvp[D], vxi[D], vvi[D];
  for (int a = 0; a < D; ++a) {
    vxp[a] = _mm512_set1_pd(probe.placed[a]);
    vvp[a] = _mm512_set1_pd(probe.frozen_velocity[a]);
    vxi[a] = _mm512_set1_pd(xi[a]);
    vvi[a] = _mm512_set1_pd(vi[a]);
  }
  const __m512d vsigma2 = _mm512_set1_pd(s.sigma * s.sigma);
  const __m512d vradius_i = _mm512_set1_pd(s.radius_i);
  const __m256i vstride = _mm256_set1_epi32(s.stride);
  const __m256i va = _mm256_set1_epi32(static_cast<int>(probe.skip_a));
  const __m256i vb = _mm256_set1_epi32(static_cast<int>(probe.skip_b));
  __mmask8 met = 0;
  for (std::uint32_t k = 0; k < s.count; k += 8) {
    const std::uint32_t left = s.count - k;
    __mmask8 live = left >= 8 ? __mmask8(0xff) : __mmask8((1u << left) - 1u);
    const __m256i ids = _mm256_maskz_loadu_epi32(live, s.candidates + k);
    live = _mm256_mask_cmpneq_epu32_mask(live, ids, va);
    live = _mm256_mask_cmpneq_epu32_mask(live, ids, vb);
    const __m256i base = _mm256_mullo_epi32(ids, vstride);
    const RecordColumns<D> rec = record_columns(s, ids, base, live);
    const __m512d dtj = _mm512_sub_pd(vt, rec.time);
    const __mmask8 future = _mm512_mask_cmp_pd_mask(live, dtj, zero, _CMP_LT_OQ);
    if (future != 0 && s.delayed != nullptr) [[unlikely]]
      list_lanes<D>(s, k, future);
    live &= static_cast<__mmask8>(~future);
    __m256i shift_base = _mm256_setzero_si256();
    if (s.any_shift) {
      const __m256i sidx = _mm256_maskz_loadu_epi32(live, s.shift_index + k);
      shift_base = _mm256_mullo_epi32(sidx, _mm256_set1_epi32(D));
    }
    __m512d p2 = zero, pg = zero, q2 = zero, r2 = zero, rg = zero, g2 = zero;
    for (int a = 0; a < D; ++a) {
      const __m512d vel = rec.vel[a];
      __m512d xj = _mm512_add_pd(rec.pos[a], _mm512_mul_pd(vel, dtj));
      if (s.any_shift) {
        xj = _mm512_add_pd(xj, _mm512_mask_i32gather_pd(
                                   zero, live, _mm256_add_epi32(shift_base, _mm256_set1_epi32(a)),
                                   reinterpret_cast<const double*>(s.shifts), 8));
      }
      const __m512d rp = _mm512_sub_pd(vxp[a], xj), gp = _mm512_sub_pd(vvp[a], vel);
      p2 = _mm512_add_pd(p2, _mm512_mul_pd(rp, rp));
      pg = _mm512_add_pd(pg, _mm512_mul_pd(rp, gp));
      q2 = _mm512_add_pd(q2, _mm512_mul_pd(gp, gp));
      const __m512d r = _mm512_sub_pd(vxi[a], xj), g = _mm512_sub_pd(vvi[a], vel);
      r2 = _mm512_add_pd(r2, _mm512_mul_pd(r, r));
      rg = _mm512_add_pd(rg, _mm512_mul_pd(r, g));
      g2 = _mm512_add_pd(g2, _mm512_mul_pd(g, g));
    }
    const __m512d sigma2 = s.uniform ? vsigma2 : contact_distance2<D>(s, ids, live, vradius_i);
    // The placed particle: an overlap now, a meeting while frozen.
    const __m512d gap_placed = _mm512_sub_pd(p2, sigma2);
    if (_mm512_mask_cmp_pd_mask(live, gap_placed, zero, _CMP_LT_OQ) != 0) {
      out.overlap = true;
      return out;
    }
    __mmask8 near = _mm512_mask_cmp_pd_mask(live, pg, zero, _CMP_LT_OQ);
    near = _mm512_mask_cmp_pd_mask(near, gap_placed,
                                   _mm512_mul_pd(_mm512_mul_pd(minus_two, pg), vspan), _CMP_LE_OQ);
    if (near != 0) {
      const __m512d disc = _mm512_sub_pd(_mm512_mul_pd(pg, pg), _mm512_mul_pd(q2, gap_placed));
      near = _mm512_mask_cmp_pd_mask(near, disc, zero, _CMP_GT_OQ);
      const __m512d dt = _mm512_div_pd(gap_placed, _mm512_sub_pd(_mm512_sqrt_pd(disc), pg));
      met |= _mm512_mask_cmp_pd_mask(near, dt, vspan, _CMP_LT_OQ);
    }
    if (!probe.predict) continue;
    // The motion after the release: scan_candidates_avx512's test.
    const __m512d gap = _mm512_sub_pd(r2, sigma2);
    keep_soonest(live, gap, rg, g2, k, best, out.found);
  }
  out.met = met != 0;
  return out;
}

template ContactProbeResult probe_contact_avx512<2>(const CandidateScan<2>&, double,
                                                    const ContactProbe<2>&, const Vec<2>&,
                                                    const Vec<2>&, double&);
template ContactProbeResult probe_contact_avx512<3>(const CandidateScan<3>&, double,
                                                    const ContactProbe<3>&, const Vec<3>&,
                                                    const Vec<3>&, double&);

// Instantiated here, inside the AVX-512 target region: an instantiation after the region
// cannot inline the intrinsics (GCC: "target specific option mismatch"). The scalar stand-in
// below repeats the list for builds without AVX-512.
template std::uint32_t scan_candidates_avx512<2, false>(const CandidateScan<2>&, double,
                                                        const Vec<2>&, const Vec<2>&, double&);
template std::uint32_t scan_candidates_avx512<3, false>(const CandidateScan<3>&, double,
                                                        const Vec<3>&, const Vec<3>&, double&);
template std::uint32_t scan_candidates_avx512<2, true>(const CandidateScan<2>&, double,
                                                       const Vec<2>&, const Vec<2>&, double&);
template std::uint32_t scan_candidates_avx512<3, true>(const CandidateScan<3>&, double,
                                                       const Vec<3>&, const Vec<3>&, double&);

// The eight candidates k..k+7 of a list of `count` (lanes past the end masked) with the
// predicted particle `self` masked out, and their records' offsets: the block the growing and
// stepped loops start each iteration with.
[[gnu::always_inline]] inline __mmask8 load_block(const std::uint32_t* candidates,
                                                  std::uint32_t count, std::uint32_t k,
                                                  __m256i vself, __m256i vstride, __m256i& ids,
                                                  __m256i& base) {
  const std::uint32_t left = count - k;
  const __mmask8 all = left >= 8 ? __mmask8(0xff) : __mmask8((1u << left) - 1u);
  ids = _mm256_maskz_loadu_epi32(all, candidates + k);
  base = _mm256_mullo_epi32(ids, vstride);
  return _mm256_mask_cmpneq_epu32_mask(all, ids, vself);
}

// -x, exactly as the scalar unary minus (the sign bit flipped: -(+0) is -0).
[[gnu::always_inline]] inline __m512d negated(__m512d x) {
  return _mm512_castsi512_pd(_mm512_xor_si512(
      _mm512_castpd_si512(x), _mm512_set1_epi64(static_cast<long long>(0x8000000000000000ull))));
}

// scan_candidates_growing, eight candidates per iteration: every lane evaluates the branches of
// growing_contact_before / growing_contact_time (dynamics/collision_time.hpp) with the same
// operations in the same order, and a mask picks each lane's branch.
template <int D>
std::uint32_t scan_candidates_growing_avx512(const CandidateScan<D>& s, std::uint32_t self,
                                             double t, const Vec<D>& xi, const Vec<D>& vi,
                                             double scale, double rate, double& best) {
  const __m512d zero = _mm512_setzero_pd();
  const __m512d inf = _mm512_set1_pd(std::numeric_limits<double>::infinity());
  const __m512d vt = _mm512_set1_pd(t);
  const __m512d vscale = _mm512_set1_pd(scale), vrate = _mm512_set1_pd(rate);
  const __m512d two = _mm512_set1_pd(2.0), minus_two = _mm512_set1_pd(-2.0);
  __m512d vxi[D], vvi[D];
  for (int a = 0; a < D; ++a) {
    vxi[a] = _mm512_set1_pd(xi[a]);
    vvi[a] = _mm512_set1_pd(vi[a]);
  }
  const __m512d vsigma0 = _mm512_set1_pd(s.sigma);
  const __m512d vradius_i = _mm512_set1_pd(s.radius_i);
  const __m256i vstride = _mm256_set1_epi32(s.stride);
  const __m256i vself = _mm256_set1_epi32(static_cast<int>(self));
  std::uint32_t found = kNoCandidate;
  for (std::uint32_t k = 0; k < s.count; k += 8) {
    __m256i ids, base;
    const __mmask8 live = load_block(s.candidates, s.count, k, vself, vstride, ids, base);
    __m512d r2, rg, g2, dtj;
    pair_terms<D, false>(s, k, record_columns(s, ids, base, live), live, vt, vxi, vvi, r2, rg, g2,
                         dtj);
    const __m512d sigma0 = s.uniform ? vsigma0 : contact_distance<D>(s, ids, live, vradius_i);
    const __m512d sigma = _mm512_mul_pd(sigma0, vscale);
    const __m512d u = _mm512_mul_pd(sigma0, vrate);
    const __m512d gap = _mm512_sub_pd(r2, _mm512_mul_pd(sigma, sigma));
    const __m512d h = _mm512_sub_pd(rg, _mm512_mul_pd(sigma, u));
    const __m512d c = _mm512_sub_pd(g2, _mm512_mul_pd(u, u));
    const __mmask8 growth_wins = _mm512_mask_cmp_pd_mask(live, c, zero, _CMP_NGT_UQ);
    const __mmask8 approach = _mm512_mask_cmp_pd_mask(live, h, zero, _CMP_LT_OQ);
    // c > 0: the hard-sphere case, with its cheap bound gap <= -2 h best.
    const __m512d bound = _mm512_mul_pd(_mm512_mul_pd(minus_two, h), _mm512_set1_pd(best));
    const __mmask8 hard = _mm512_mask_cmp_pd_mask(static_cast<__mmask8>(approach & ~growth_wins),
                                                  gap, bound, _CMP_NGT_UQ);
    const __mmask8 flat = _mm512_mask_cmp_pd_mask(live, c, zero, _CMP_EQ_OQ);
    const __mmask8 shrinking = _mm512_mask_cmp_pd_mask(live, c, zero, _CMP_LT_OQ);
    const __mmask8 rooted = static_cast<__mmask8>(hard | shrinking);
    if ((rooted | (flat & approach)) == 0) continue;
    const __m512d disc = _mm512_sub_pd(_mm512_mul_pd(h, h), _mm512_mul_pd(gap, c));
    const __mmask8 real = _mm512_mask_cmp_pd_mask(rooted, disc, zero, _CMP_NLE_UQ);
    const __m512d root = _mm512_sqrt_pd(_mm512_mask_blend_pd(real, zero, disc));
    const __m512d neg_h = negated(h);
    // a / (-h + sqrt(disc)): the stable root of an approach (c > 0, or c < 0 with h <= 0).
    const __m512d approach_root = _mm512_div_pd(gap, _mm512_add_pd(neg_h, root));
    // c < 0 and h > 0: (-h - sqrt(disc)) / c; c < 0 without a real root: -h / c.
    const __m512d receding_root = _mm512_div_pd(_mm512_sub_pd(neg_h, root), c);
    const __m512d turn = _mm512_div_pd(neg_h, c);
    const __mmask8 h_positive = _mm512_cmp_pd_mask(h, zero, _CMP_GT_OQ);
    __m512d dt = _mm512_mask_blend_pd(h_positive, approach_root, receding_root);
    dt = _mm512_mask_blend_pd(static_cast<__mmask8>(shrinking & ~real), dt, turn);
    dt = _mm512_mask_blend_pd(_mm512_cmp_pd_mask(dt, zero, _CMP_GT_OQ), zero, dt);
    // c == 0: f is linear; -a / (2 h) when a > 0, else now.
    const __m512d linear = _mm512_mask_blend_pd(_mm512_cmp_pd_mask(gap, zero, _CMP_GT_OQ), zero,
                                                _mm512_div_pd(negated(gap), _mm512_mul_pd(two, h)));
    dt = _mm512_mask_blend_pd(flat, dt, linear);
    // Lanes with an event: c > 0 with a real root, c < 0, or c == 0 approaching.
    const __mmask8 valid = static_cast<__mmask8>((hard & real) | shrinking | (flat & approach));
    dt = _mm512_mask_blend_pd(valid, inf, dt);
    const double m = _mm512_reduce_min_pd(dt);
    if (m < best) {
      const __mmask8 at = _mm512_mask_cmp_pd_mask(valid, dt, _mm512_set1_pd(m), _CMP_EQ_OQ);
      best = m;
      found = k + static_cast<std::uint32_t>(__builtin_ctz(at));
    }
  }
  return found;
}

template std::uint32_t scan_candidates_growing_avx512<2>(const CandidateScan<2>&, std::uint32_t,
                                                         double, const Vec<2>&, const Vec<2>&,
                                                         double, double, double&);
template std::uint32_t scan_candidates_growing_avx512<3>(const CandidateScan<3>&, std::uint32_t,
                                                         double, const Vec<3>&, const Vec<3>&,
                                                         double, double, double&);

// The stepped loop, eight candidates per iteration. Every lane computes r.r, r.g and g.g as
// the scalar loop does. Zone-0 lanes (unlisted: the most) then take the hard-sphere loop's cheap
// bound and the approach to their outermost boundary. Listed lanes (zone >= 1) are compressed
// into the held arrays and tested together at the end, eight at a time, by ZoneTable::event_time
// (the approach to the inner boundary if it comes, else the exit through the outer one, both
// branches evaluated and blended): a square-well prediction has ~5 of them among ~49
// candidates, spread over most blocks. The soonest event is the scalar loop's: the lowest
// index among equal times, whichever pass found it.
template <int D, bool kAccelerated>
std::uint32_t scan_stepped_avx512(const SteppedScan<D>& s, double t, const Vec<D>& xi,
                                  const Vec<D>& vi, double& best) {
  const CandidateScan<D>& c = s.base;
  const __m512d inf = _mm512_set1_pd(std::numeric_limits<double>::infinity());
  const __m512d zero = _mm512_setzero_pd();
  const __m512d vt = _mm512_set1_pd(t);
  __m512d vxi[D], vvi[D];
  for (int a = 0; a < D; ++a) {
    vxi[a] = _mm512_set1_pd(xi[a]);
    vvi[a] = _mm512_set1_pd(vi[a]);
  }
  const __m256i vstride = _mm256_set1_epi32(c.stride);
  const __m256i vself = _mm256_set1_epi32(static_cast<int>(s.self));
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const __m512i vepoch = _mm512_set1_epi64(static_cast<long long>(s.epoch));
  const __m512i low16 = _mm512_set1_epi64(0xffff);
  const __m512d reach2_one = _mm512_set1_pd(s.row_reach2[0]);
  std::uint32_t found = kNoCandidate;
  std::uint32_t held = 0;
  for (std::uint32_t k = 0; k < c.count; k += 8) {
    __m256i ids, base;
    __mmask8 live = load_block(c.candidates, c.count, k, vself, vstride, ids, base);
    __m512d r2, rg, g2, dtj;  // no deferred soft contacts under steps: dtj >= 0
    pair_terms<D, kAccelerated>(c, k, record_columns(c, ids, base, live), live, vt, vxi, vvi, r2,
                                rg, g2, dtj);
    // Zones from the capture map's stamps: listed lanes in zone >= 1 are held back.
    const __m512i stamp =
        _mm512_mask_i32gather_epi64(_mm512_setzero_si512(), live, ids, s.stamps, 8);
    const __mmask8 listed =
        _mm512_mask_cmpeq_epu64_mask(live, _mm512_srli_epi64(stamp, 32), vepoch);
    const __mmask8 inside = _mm512_mask_test_epi64_mask(listed, stamp, low16);
    if (inside != 0) {
      _mm512_mask_compressstoreu_pd(s.held_r2 + held, inside, r2);
      _mm512_mask_compressstoreu_pd(s.held_rg + held, inside, rg);
      _mm512_mask_compressstoreu_pd(s.held_g2 + held, inside, g2);
      _mm512_mask_compressstoreu_epi64(s.held_stamp + held, inside, stamp);
      _mm256_mask_compressstoreu_epi32(
          s.held_index + held, inside,
          _mm256_add_epi32(lane, _mm256_set1_epi32(static_cast<int>(k))));
      held += static_cast<std::uint32_t>(__builtin_popcount(inside));
    }
    // Zone 0: the approach to the outermost boundary, after the cheap bound.
    const __mmask8 outside = static_cast<__mmask8>(live & ~inside);
    __m512d reach2 = reach2_one;
    if (s.kind != nullptr) {
      const __m512i raw = _mm512_mask_i32gather_epi32(_mm512_setzero_si512(), __mmask16(outside),
                                                      _mm512_castsi256_si512(ids), s.kind, 2);
      const __m256i shp = _mm256_and_si256(_mm512_castsi512_si256(raw), _mm256_set1_epi32(0xffff));
      reach2 = _mm512_mask_i32gather_pd(zero, outside, shp, s.row_reach2, 8);
    }
    const __m512d gap = _mm512_sub_pd(r2, reach2);
    keep_soonest(outside, gap, rg, g2, k, best, found);
  }
  // The held (listed) candidates, in list order: ZoneTable::event_time.
  const __m512i sign = _mm512_set1_epi64(static_cast<long long>(0x8000000000000000ull));
  for (std::uint32_t h = 0; h < held; h += 8) {
    const std::uint32_t left = held - h;
    const __mmask8 live = left >= 8 ? __mmask8(0xff) : __mmask8((1u << left) - 1u);
    const __m512d r2 = _mm512_maskz_loadu_pd(live, s.held_r2 + h);
    const __m512d rg = _mm512_maskz_loadu_pd(live, s.held_rg + h);
    const __m512d g2 = _mm512_maskz_loadu_pd(live, s.held_g2 + h);
    const __m512i stamp = _mm512_maskz_loadu_epi64(live, s.held_stamp + h);
    __m256i at = _mm512_cvtepi64_epi32(_mm512_and_si512(stamp, low16));  // the zone
    if (s.table_offset != nullptr) {
      const __m256i table =
          _mm512_cvtepi64_epi32(_mm512_and_si512(_mm512_srli_epi64(stamp, 16), low16));
      at = _mm256_add_epi32(
          at, _mm256_mmask_i32gather_epi32(_mm256_setzero_si256(), live, table, s.table_offset, 4));
    }
    const __m512d inner = _mm512_mask_i32gather_pd(zero, live, at, s.flat_r2, 8);
    const __m512d outer = _mm512_mask_i32gather_pd(
        zero, live, _mm256_sub_epi32(at, _mm256_set1_epi32(1)), s.flat_r2, 8);
    const __m512d rg_rg = _mm512_mul_pd(rg, rg);
    // Approaching, and the inner boundary is reached.
    const __m512d gap_in = _mm512_sub_pd(r2, inner);
    const __m512d disc_in = _mm512_sub_pd(rg_rg, _mm512_mul_pd(g2, gap_in));
    const __mmask8 approaching = _mm512_mask_cmp_pd_mask(live, rg, zero, _CMP_LT_OQ);
    const __mmask8 hits = _mm512_mask_cmp_pd_mask(approaching, disc_in, zero, _CMP_GT_OQ);
    __m512d t_in = _mm512_div_pd(gap_in, _mm512_sub_pd(_mm512_sqrt_pd(disc_in), rg));
    t_in = _mm512_mask_blend_pd(_mm512_cmp_pd_mask(t_in, zero, _CMP_GT_OQ), zero, t_in);
    // Otherwise the later root at the outer boundary (never if g.g is not > 0; now if the pair
    // is past it already).
    const __mmask8 rest =
        _mm512_mask_cmp_pd_mask(static_cast<__mmask8>(live & ~hits), g2, zero, _CMP_GT_OQ);
    const __m512d gap_out = _mm512_sub_pd(r2, outer);
    const __m512d disc_out = _mm512_sub_pd(rg_rg, _mm512_mul_pd(g2, gap_out));
    const __mmask8 leaves = _mm512_mask_cmp_pd_mask(rest, disc_out, zero, _CMP_GT_OQ);
    const __m512d root = _mm512_sqrt_pd(disc_out);
    const __m512d receding_t =
        _mm512_div_pd(_mm512_castsi512_pd(_mm512_xor_si512(_mm512_castpd_si512(gap_out), sign)),
                      _mm512_add_pd(rg, root));
    const __m512d closing_t = _mm512_div_pd(_mm512_sub_pd(root, rg), g2);
    __m512d t_out =
        _mm512_mask_blend_pd(_mm512_cmp_pd_mask(rg, zero, _CMP_GT_OQ), closing_t, receding_t);
    t_out = _mm512_mask_blend_pd(_mm512_cmp_pd_mask(t_out, zero, _CMP_GT_OQ), zero, t_out);
    __m512d dt = _mm512_mask_blend_pd(hits, inf, t_in);
    dt = _mm512_mask_blend_pd(static_cast<__mmask8>(rest & ~leaves), dt, zero);
    dt = _mm512_mask_blend_pd(leaves, dt, t_out);
    const double m = _mm512_reduce_min_pd(dt);
    if (m <= best) {
      const __mmask8 first = _mm512_mask_cmp_pd_mask(live, dt, _mm512_set1_pd(m), _CMP_EQ_OQ);
      const std::uint32_t index =
          s.held_index[h + static_cast<std::uint32_t>(__builtin_ctz(first))];
      // Equal to the best of the other candidates: the one earlier in the list wins.
      if (m < best || (found != kNoCandidate && index < found)) {
        best = m;
        found = index;
      }
    }
  }
  return found;
}

template std::uint32_t scan_stepped_avx512<2, false>(const SteppedScan<2>&, double, const Vec<2>&,
                                                     const Vec<2>&, double&);
template std::uint32_t scan_stepped_avx512<3, false>(const SteppedScan<3>&, double, const Vec<3>&,
                                                     const Vec<3>&, double&);
template std::uint32_t scan_stepped_avx512<2, true>(const SteppedScan<2>&, double, const Vec<2>&,
                                                    const Vec<2>&, double&);
template std::uint32_t scan_stepped_avx512<3, true>(const SteppedScan<3>&, double, const Vec<3>&,
                                                    const Vec<3>&, double&);

// Up to 16 lists per register (two registers for the 27 cells of 3D): gather the heads,
// compress the non-empty ones out, gather their successors, compress again.
std::uint32_t gather_lists_avx512(const Neighbourhood& nb, std::uint32_t* out,
                                  std::uint32_t* out_shift, std::uint32_t* third,
                                  std::uint32_t* third_shift, std::uint32_t& n_third) {
  const __m512i end = _mm512_set1_epi32(static_cast<int>(nb.end));
  __m512i member[2], tag[2];
  __mmask16 has[2];
  const int blocks = nb.cells > 16 ? 2 : 1;
  std::uint32_t n = 0;
  for (int b = 0; b < blocks; ++b) {
    const int lanes = nb.cells - 16 * b < 16 ? nb.cells - 16 * b : 16;
    const auto live = static_cast<__mmask16>((1u << lanes) - 1u);
    const __m512i cell = _mm512_maskz_loadu_epi32(live, nb.cell + 16 * b);
    tag[b] = nb.shift ? _mm512_maskz_loadu_epi32(live, nb.shift + 16 * b) : _mm512_setzero_si512();
    member[b] = _mm512_mask_i32gather_epi32(end, live, cell, nb.heads, 4);
    has[b] = _mm512_mask_cmpneq_epu32_mask(live, member[b], end);
    _mm512_mask_compressstoreu_epi32(out + n, has[b], member[b]);
    if (nb.shift) _mm512_mask_compressstoreu_epi32(out_shift + n, has[b], tag[b]);
    n += static_cast<std::uint32_t>(__builtin_popcount(has[b]));
  }
  for (int b = 0; b < blocks; ++b) {
    member[b] = _mm512_mask_i32gather_epi32(end, has[b], member[b], nb.next, 4);
    has[b] = _mm512_mask_cmpneq_epu32_mask(has[b], member[b], end);
    _mm512_mask_compressstoreu_epi32(out + n, has[b], member[b]);
    if (nb.shift) _mm512_mask_compressstoreu_epi32(out_shift + n, has[b], tag[b]);
    n += static_cast<std::uint32_t>(__builtin_popcount(has[b]));
  }
  n_third = 0;
  for (int b = 0; b < blocks; ++b) {
    member[b] = _mm512_mask_i32gather_epi32(end, has[b], member[b], nb.next, 4);
    has[b] = _mm512_mask_cmpneq_epu32_mask(has[b], member[b], end);
    _mm512_mask_compressstoreu_epi32(third + n_third, has[b], member[b]);
    _mm512_mask_compressstoreu_epi32(third_shift + n_third, has[b], tag[b]);
    n_third += static_cast<std::uint32_t>(__builtin_popcount(has[b]));
  }
  return n;
}

#pragma GCC diagnostic pop
#pragma GCC pop_options

#else

template <int D, bool kAccelerated>
std::uint32_t scan_candidates_avx512(const CandidateScan<D>& s, double t, const Vec<D>& xi,
                                     const Vec<D>& vi, double& best) {
  return scan_candidates_scalar<D, kAccelerated>(s, t, xi, vi, best);
}

template std::uint32_t scan_candidates_avx512<2, false>(const CandidateScan<2>&, double,
                                                        const Vec<2>&, const Vec<2>&, double&);
template std::uint32_t scan_candidates_avx512<3, false>(const CandidateScan<3>&, double,
                                                        const Vec<3>&, const Vec<3>&, double&);
template std::uint32_t scan_candidates_avx512<2, true>(const CandidateScan<2>&, double,
                                                       const Vec<2>&, const Vec<2>&, double&);
template std::uint32_t scan_candidates_avx512<3, true>(const CandidateScan<3>&, double,
                                                       const Vec<3>&, const Vec<3>&, double&);

template <int D>
ContactProbeResult probe_contact_avx512(const CandidateScan<D>& s, double t,
                                        const ContactProbe<D>& probe, const Vec<D>& xi,
                                        const Vec<D>& vi, double& best) {
  return probe_contact_scalar<D>(s, t, probe, xi, vi, best);
}

template ContactProbeResult probe_contact_avx512<2>(const CandidateScan<2>&, double,
                                                    const ContactProbe<2>&, const Vec<2>&,
                                                    const Vec<2>&, double&);
template ContactProbeResult probe_contact_avx512<3>(const CandidateScan<3>&, double,
                                                    const ContactProbe<3>&, const Vec<3>&,
                                                    const Vec<3>&, double&);

template <int D, bool kAccelerated>
std::uint32_t scan_stepped_avx512(const SteppedScan<D>&, double, const Vec<D>&, const Vec<D>&,
                                  double&) {
  return kNoCandidate;  // never called: cpu_has_avx512() is false on this platform
}

template <int D>
std::uint32_t scan_candidates_growing_avx512(const CandidateScan<D>&, std::uint32_t, double,
                                             const Vec<D>&, const Vec<D>&, double, double,
                                             double&) {
  return kNoCandidate;  // never called: cpu_has_avx512() is false on this platform
}
template std::uint32_t scan_candidates_growing_avx512<2>(const CandidateScan<2>&, std::uint32_t,
                                                         double, const Vec<2>&, const Vec<2>&,
                                                         double, double, double&);
template std::uint32_t scan_candidates_growing_avx512<3>(const CandidateScan<3>&, std::uint32_t,
                                                         double, const Vec<3>&, const Vec<3>&,
                                                         double, double, double&);

template std::uint32_t scan_stepped_avx512<2, false>(const SteppedScan<2>&, double, const Vec<2>&,
                                                     const Vec<2>&, double&);
template std::uint32_t scan_stepped_avx512<3, false>(const SteppedScan<3>&, double, const Vec<3>&,
                                                     const Vec<3>&, double&);
template std::uint32_t scan_stepped_avx512<2, true>(const SteppedScan<2>&, double, const Vec<2>&,
                                                    const Vec<2>&, double&);
template std::uint32_t scan_stepped_avx512<3, true>(const SteppedScan<3>&, double, const Vec<3>&,
                                                    const Vec<3>&, double&);

std::uint32_t gather_lists_avx512(const Neighbourhood&, std::uint32_t*, std::uint32_t*,
                                  std::uint32_t*, std::uint32_t*, std::uint32_t& n_third) {
  n_third = 0;
  return 0;  // never called: cpu_has_avx512() is false on this platform
}

#endif

}  // namespace kairos
