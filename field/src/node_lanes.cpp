/// The CPU block build's sums in vector lanes (node_lanes.h): the samples near a box picked,
/// eq. 1 at 8 points with the points in the lanes. AVX-512 where present, generic loops over
/// the 8 lanes elsewhere (checked for vectorisation: `-fopt-info-vec`, CMakeLists.txt). No
/// OpenVDB: quick to compile.
#include "node_lanes.h"

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace fieldpath::field::lanes {

using kernel::Accum;
using kernel::D3;
using kernel::Law;
using kernel::SampleSpan;

// File-local helpers are static; the API (node_lanes.h) is not.

/// The picked samples exactly at `at` (their term is along the normal, φ held at r_min).
static void addZeroTerms(const Law& L, const SampleSpan& s, const Picks& picks, D3 at, Accum& a) {
  for (int k = 0; k < picks.count; ++k) {
    const int j = picks.at[std::size_t(k)];
    const double dx = at.x - s.x[j], dy = at.y - s.y[j], dz = at.z - s.z[j];
    if (dx * dx + dy * dy + dz * dz == 0.0)
      kernel::addTerm(L, 0.0, 0.0, 0.0, 0.0, s.nx[j], s.ny[j], s.nz[j], s.w[j], a);
  }
}

/// The gap between p and [lo, hi] (0 inside), as gather512 computes it.
static inline double gapTo(double p, double lo, double hi) {
  const double below = lo - p, above = p - hi;
  return below > 0.0 ? below : above > 0.0 ? above : 0.0;
}

static void gatherGeneric(const SampleSpan& f, const Box& box, double near_sq, double far_sq,
                          Picks& near, Picks* far) {
  int n_near = 0, n_far = 0;
  for (int t = 0; t < f.count; ++t) {
    const double dx = gapTo(f.x[t], box.lo[0], box.hi[0]);
    const double dy = gapTo(f.y[t], box.lo[1], box.hi[1]);
    const double dz = gapTo(f.z[t], box.lo[2], box.hi[2]);
    const double d2 = dx * dx + dy * dy + dz * dz;
    if (d2 <= near_sq)
      near.at[std::size_t(n_near++)] = t;
    else if (far && d2 <= far_sq)
      far->at[std::size_t(n_far++)] = t;
  }
  near.count = n_near;
  if (far) far->count = n_far;
}

/// The sums at the lanes' points over the picked samples (laneSums' contract), one picked sample
/// at a time against the 8 points: the same terms, sum order and nearest as laneSums512.
static void laneSumsGeneric(const Law& L, const SampleSpan& s, const Picks& core,
                            const Picks& ring, const double* px, const double* py,
                            const double* pz, const double* init_sq, Accum* out) {
  double fx[2][kLanes] = {}, fy[2][kLanes] = {}, fz[2][kLanes] = {};
  double best[2][kLanes], lowest[kLanes];
  std::int64_t best_id[2][kLanes];
  for (int l = 0; l < kLanes; ++l) {
    best[0][l] = best[1][l] = init_sq[l];
    best_id[0][l] = best_id[1][l] = -1;
    lowest[l] = HUGE_VAL;
  }
  const double r0_sq = L.r0_sq, inv_r_min = L.inv_r_min, inv_r0 = L.inv_r0;
  for (int k = 0; k < core.count; ++k) {
    const int j = core.at[std::size_t(k)], set = k & 1;  // two sets, as laneSums512's chains
    const double x = s.x[j], y = s.y[j], z = s.z[j], w = s.w[j];
    const std::int64_t id = s.id[j];
    for (int l = 0; l < kLanes; ++l) {
      const double dx = px[l] - x, dy = py[l] - y, dz = pz[l] - z;
      const double r2 = dx * dx + dy * dy + dz * dz;
      const bool in = r2 < r0_sq;
      const double inv_r = 1.0 / std::sqrt(r2 > 0.0 ? r2 : 1.0);
      const double inv_rc = inv_r < inv_r_min ? inv_r : inv_r_min;
      const double c = in && r2 > 0.0 ? w * (inv_rc - inv_r0) * (inv_rc * inv_rc) * inv_r : 0.0;
      fx[set][l] += c * dx;
      fy[set][l] += c * dy;
      fz[set][l] += c * dz;
      lowest[l] = r2 < lowest[l] ? r2 : lowest[l];
      const bool closer = r2 < best[set][l] || (r2 == best[set][l] && id < best_id[set][l]);
      best[set][l] = closer ? r2 : best[set][l];
      best_id[set][l] = closer ? id : best_id[set][l];
    }
  }
  for (int l = 0; l < kLanes; ++l) {
    const bool take = best[1][l] < best[0][l] ||
                      (best[1][l] == best[0][l] && best_id[1][l] < best_id[0][l]);
    if (take) {
      best[0][l] = best[1][l];
      best_id[0][l] = best_id[1][l];
    }
  }
  bool shell = false;
  for (int l = 0; l < kLanes; ++l) shell = shell || best[0][l] >= r0_sq;
  if (shell)
    for (int k = 0; k < ring.count; ++k) {
      const int j = ring.at[std::size_t(k)];
      const std::int64_t id = s.id[j];
      for (int l = 0; l < kLanes; ++l) {
        const double dx = px[l] - s.x[j], dy = py[l] - s.y[j], dz = pz[l] - s.z[j];
        const double r2 = dx * dx + dy * dy + dz * dz;
        const bool closer = r2 < best[0][l] || (r2 == best[0][l] && id < best_id[0][l]);
        best[0][l] = closer ? r2 : best[0][l];
        best_id[0][l] = closer ? id : best_id[0][l];
      }
    }
  for (int l = 0; l < kLanes; ++l) {
    Accum& a = out[l];
    a = Accum{};
    a.fx = fx[0][l] + fx[1][l];
    a.fy = fy[0][l] + fy[1][l];
    a.fz = fz[0][l] + fz[1][l];
    a.best_sq = best[0][l];
    a.best_id = int(best_id[0][l]);
    if (lowest[l] == 0.0) addZeroTerms(L, s, core, D3{px[l], py[l], pz[l]}, a);
  }
}

#if defined(__x86_64__)
/// gatherGeneric in AVX-512 lanes: the same test, one pass for both pick lists, the positions
/// compressed in registers and stored whole (the lanes past the passing ones are written over
/// by the next store, or lie in the padding: Picks::reserveFor).
static __attribute__((target("avx512f"))) void gather512(const SampleSpan& f, const Box& box,
                                                         double near_sq, double far_sq,
                                                         Picks& near, Picks* far) {
  const __m512d zero = _mm512_setzero_pd();
  __m512d blo[3], bhi[3];
  for (int a = 0; a < 3; ++a) {
    blo[a] = _mm512_set1_pd(box.lo[a]);
    bhi[a] = _mm512_set1_pd(box.hi[a]);
  }
  const __m512d vnear = _mm512_set1_pd(near_sq), vfar = _mm512_set1_pd(far ? far_sq : near_sq);
  std::int32_t* near_at = near.at.data();
  std::int32_t* far_at = far ? far->at.data() : nullptr;
  int n_near = 0, n_far = 0;
  __m512i position = _mm512_set_epi32(15, 14, 13, 12, 11, 10, 9, 8, 7, 6, 5, 4, 3, 2, 1, 0);
  const __m512i step = _mm512_set1_epi32(kLanes);
  for (int t = 0; t < f.count; t += kLanes, position = _mm512_add_epi32(position, step)) {
    const int left = f.count - t;
    const __mmask8 valid = left >= kLanes ? __mmask8(0xff) : __mmask8((1u << left) - 1u);
    const __m512d p[3] = {_mm512_maskz_loadu_pd(valid, f.x + t),
                          _mm512_maskz_loadu_pd(valid, f.y + t),
                          _mm512_maskz_loadu_pd(valid, f.z + t)};
    // max(0, lo - p, p - hi): gapTo's value (one of the two differences is <= 0)
    __m512d d[3];
    for (int a = 0; a < 3; ++a)
      d[a] = _mm512_max_pd(zero,
                           _mm512_max_pd(_mm512_sub_pd(blo[a], p[a]), _mm512_sub_pd(p[a], bhi[a])));
    const __m512d d2 =
        _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(d[0], d[0]), _mm512_mul_pd(d[1], d[1])),
                      _mm512_mul_pd(d[2], d[2]));
    // Stored whether any lane passes or not: which do is data, not a branch to mispredict.
    const __mmask8 in_near = _mm512_mask_cmp_pd_mask(valid, d2, vnear, _CMP_LE_OQ);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(near_at + n_near),
                        _mm512_castsi512_si256(_mm512_maskz_compress_epi32(in_near, position)));
    n_near += __builtin_popcount(in_near);
    if (far) {
      const __mmask8 in_far = _mm512_mask_cmp_pd_mask(valid, d2, vfar, _CMP_LE_OQ) & ~in_near;
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(far_at + n_far),
                          _mm512_castsi512_si256(_mm512_maskz_compress_epi32(in_far, position)));
      n_far += __builtin_popcount(in_far);
    }
  }
  near.count = n_near;
  if (far) far->count = n_far;
}

/// The nearest sample per lane so far (laneSums512).
struct Nearest512 {
  __m512d best;
  __m512i id;
};
/// Sample `id` at squared distances r2 from the lanes' points: nearer (or as near with a lower
/// id) replaces a lane's nearest. Branch-free: which lanes change is data.
static __attribute__((target("avx512f"), always_inline)) inline void trackNearest(Nearest512& n,
                                                                                  __m512d r2,
                                                                                  std::int64_t id) {
  const __m512i vid = _mm512_set1_epi64(id);
  const __mmask8 closer = _mm512_cmp_pd_mask(r2, n.best, _CMP_LT_OQ) |
                          (_mm512_cmp_pd_mask(r2, n.best, _CMP_EQ_OQ) &
                           _mm512_cmplt_epi64_mask(vid, n.id));
  n.best = _mm512_mask_blend_pd(closer, n.best, r2);
  n.id = _mm512_mask_blend_epi64(closer, n.id, vid);
}

struct LaneConsts512 {
  __m512d r0_sq, inv_r_min, inv_r0, half, three_eighths, one, tiny;
};
/// The term of sample j of s at the lanes' points added to (fx, fy, fz), its distance to `near`,
/// the least r² to `lowest`. r² summed in the scalar's order (same nearest, same cut at r0); 1/r
/// from the 14-bit reciprocal square root and two Newton steps (relative error ~1e-16, no
/// division or square root); a lane on the sample gets 0 here (dx = dy = dz = 0, r² held at
/// `tiny`: no infinity) and its normal term from addZeroTerms.
/// Track: the nearest tracked (off: every lane untracked, init_sq 0); Lowest: the least r² kept
/// (off: every lane tracked from init_sq > 0, so a lane on a sample has its nearest at 0).
template <bool Track, bool Lowest>
static __attribute__((target("avx512f"), always_inline)) inline void laneTerm512(
    const LaneConsts512& k, const SampleSpan& s, int j, __m512d ax, __m512d ay, __m512d az,
    __m512d& fx, __m512d& fy, __m512d& fz, Nearest512& near, __m512d& lowest) {
  const __m512d dx = _mm512_sub_pd(ax, _mm512_set1_pd(s.x[j]));
  const __m512d dy = _mm512_sub_pd(ay, _mm512_set1_pd(s.y[j]));
  const __m512d dz = _mm512_sub_pd(az, _mm512_set1_pd(s.z[j]));
  const __m512d r2 = _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(dx, dx), _mm512_mul_pd(dy, dy)),
                                   _mm512_mul_pd(dz, dz));
  const __mmask8 in = _mm512_cmp_pd_mask(r2, k.r0_sq, _CMP_LT_OQ);
  if constexpr (Lowest) lowest = _mm512_min_pd(lowest, r2);
  const __m512d r2s = _mm512_max_pd(r2, k.tiny);
  // 1/r: the 14-bit estimate y0 and one third-order step, y0 (1 + e/2 + 3e²/8) with
  // e = 1 - r² y0² (relative error 5/16 e³ < 1e-13; two Newton steps took two more operations)
  const __m512d y0 = _mm512_rsqrt14_pd(r2s);
  const __m512d e = _mm512_fnmadd_pd(_mm512_mul_pd(r2s, y0), y0, k.one);
  const __m512d y =
      _mm512_fmadd_pd(y0, _mm512_mul_pd(e, _mm512_fmadd_pd(e, k.three_eighths, k.half)), y0);
  const __m512d inv_rc = _mm512_min_pd(y, k.inv_r_min);
  const __m512d phi = _mm512_mul_pd(_mm512_sub_pd(inv_rc, k.inv_r0), _mm512_mul_pd(inv_rc, inv_rc));
  const __m512d c = _mm512_maskz_mul_pd(in, _mm512_mul_pd(_mm512_set1_pd(s.w[j]), phi), y);
  fx = _mm512_mask3_fmadd_pd(c, dx, fx, in);
  fy = _mm512_mask3_fmadd_pd(c, dy, fy, in);
  fz = _mm512_mask3_fmadd_pd(c, dz, fz, in);
  if constexpr (Track) trackNearest(near, r2, s.id[j]);
}

/// laneSums in AVX-512: two picked samples a step in two sets of sums (independent chains for
/// the out-of-order core), added at the end; the nearest of the two sets merged (ties: lowest
/// id). Track and Lowest as laneTerm512's: the untracked sums (the surface rule's lifted point)
/// skip the nearest's 5 operations of ~30 a step, the tracked ones the least r²'s one.
template <bool Track, bool Lowest>
static __attribute__((target("avx512f"))) void laneSums512(const Law& L, const SampleSpan& s,
                                                           const Picks& core, const Picks& ring,
                                                           const double* px, const double* py,
                                                           const double* pz, const double* init_sq,
                                                           Accum* out) {
  const __m512d ax = _mm512_loadu_pd(px), ay = _mm512_loadu_pd(py), az = _mm512_loadu_pd(pz);
  const LaneConsts512 k{_mm512_set1_pd(L.r0_sq),  _mm512_set1_pd(L.inv_r_min),
                        _mm512_set1_pd(L.inv_r0), _mm512_set1_pd(0.5),
                        _mm512_set1_pd(0.375),    _mm512_set1_pd(1.0),
                        _mm512_set1_pd(1e-300)};
  const __m512d zero = _mm512_setzero_pd();
  __m512d fx = zero, fy = zero, fz = zero, gx = zero, gy = zero, gz = zero;
  __m512d lowest = _mm512_set1_pd(HUGE_VAL);
  Nearest512 near{_mm512_loadu_pd(init_sq), _mm512_set1_epi64(-1)};
  Nearest512 near2 = near;
  const std::int32_t* picked = core.at.data();
  int c = 0;
  for (; c + 1 < core.count; c += 2) {
    laneTerm512<Track, Lowest>(k, s, picked[c], ax, ay, az, fx, fy, fz, near, lowest);
    laneTerm512<Track, Lowest>(k, s, picked[c + 1], ax, ay, az, gx, gy, gz, near2, lowest);
  }
  if (c < core.count)
    laneTerm512<Track, Lowest>(k, s, picked[c], ax, ay, az, fx, fy, fz, near, lowest);
  fx = _mm512_add_pd(fx, gx);
  fy = _mm512_add_pd(fy, gy);
  fz = _mm512_add_pd(fz, gz);
  {  // the second set's nearest where nearer, or as near with a lower id
    const __mmask8 take = _mm512_cmp_pd_mask(near2.best, near.best, _CMP_LT_OQ) |
                          (_mm512_cmp_pd_mask(near2.best, near.best, _CMP_EQ_OQ) &
                           _mm512_cmplt_epi64_mask(near2.id, near.id));
    near.best = _mm512_mask_blend_pd(take, near.best, near2.best);
    near.id = _mm512_mask_blend_epi64(take, near.id, near2.id);
  }
  // The ring's samples lie farther than r0 from every point: only a shell point's nearest.
  if (Track && _mm512_cmp_pd_mask(near.best, k.r0_sq, _CMP_GE_OQ))
    for (int r = 0; r < ring.count; ++r) {
      const int j = ring.at[std::size_t(r)];
      const __m512d dx = _mm512_sub_pd(ax, _mm512_set1_pd(s.x[j]));
      const __m512d dy = _mm512_sub_pd(ay, _mm512_set1_pd(s.y[j]));
      const __m512d dz = _mm512_sub_pd(az, _mm512_set1_pd(s.z[j]));
      trackNearest(near,
                   _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(dx, dx), _mm512_mul_pd(dy, dy)),
                                 _mm512_mul_pd(dz, dz)),
                   s.id[j]);
    }
  alignas(64) double f[3][kLanes], b[kLanes];
  alignas(64) std::int64_t bid[kLanes];
  _mm512_store_pd(f[0], fx);
  _mm512_store_pd(f[1], fy);
  _mm512_store_pd(f[2], fz);
  _mm512_store_pd(b, near.best);
  _mm512_store_epi64(bid, near.id);
  const __mmask8 on_sample = _mm512_cmp_pd_mask(Lowest ? lowest : near.best, zero, _CMP_EQ_OQ);
  for (int l = 0; l < kLanes; ++l) {
    Accum& a = out[l];
    a = Accum{};
    a.fx = f[0][l];
    a.fy = f[1][l];
    a.fz = f[2][l];
    a.best_sq = b[l];
    a.best_id = int(bid[l]);
    if ((on_sample >> l) & 1) addZeroTerms(L, s, core, D3{px[l], py[l], pz[l]}, a);
  }
}

/// gatherGeneric in AVX2 lanes (4 samples a step): the same test and order; the positions
/// written branch-free, each at the count so far (Picks::reserveFor's room past it).
static __attribute__((target("avx2,fma"))) void gather256(const SampleSpan& f, const Box& box,
                                                          double near_sq, double far_sq,
                                                          Picks& near, Picks* far) {
  const __m256d zero = _mm256_setzero_pd();
  __m256d blo[3], bhi[3];
  for (int a = 0; a < 3; ++a) {
    blo[a] = _mm256_set1_pd(box.lo[a]);
    bhi[a] = _mm256_set1_pd(box.hi[a]);
  }
  const __m256d vnear = _mm256_set1_pd(near_sq), vfar = _mm256_set1_pd(far ? far_sq : near_sq);
  std::int32_t* near_at = near.at.data();
  std::int32_t* far_at = far ? far->at.data() : nullptr;
  int n_near = 0, n_far = 0, t = 0;
  for (; t + 4 <= f.count; t += 4) {
    const __m256d p[3] = {_mm256_loadu_pd(f.x + t), _mm256_loadu_pd(f.y + t),
                          _mm256_loadu_pd(f.z + t)};
    __m256d d[3];
    for (int a = 0; a < 3; ++a)
      d[a] = _mm256_max_pd(zero,
                           _mm256_max_pd(_mm256_sub_pd(blo[a], p[a]), _mm256_sub_pd(p[a], bhi[a])));
    const __m256d d2 =
        _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(d[0], d[0]), _mm256_mul_pd(d[1], d[1])),
                      _mm256_mul_pd(d[2], d[2]));
    const int in_near = _mm256_movemask_pd(_mm256_cmp_pd(d2, vnear, _CMP_LE_OQ));
    for (int b = 0; b < 4; ++b) {
      near_at[n_near] = t + b;
      n_near += (in_near >> b) & 1;
    }
    if (far) {
      const int in_far = _mm256_movemask_pd(_mm256_cmp_pd(d2, vfar, _CMP_LE_OQ)) & ~in_near;
      for (int b = 0; b < 4; ++b) {
        far_at[n_far] = t + b;
        n_far += (in_far >> b) & 1;
      }
    }
  }
  for (; t < f.count; ++t) {  // the last few, as gatherGeneric
    const double dx = gapTo(f.x[t], box.lo[0], box.hi[0]);
    const double dy = gapTo(f.y[t], box.lo[1], box.hi[1]);
    const double dz = gapTo(f.z[t], box.lo[2], box.hi[2]);
    const double d2 = dx * dx + dy * dy + dz * dz;
    if (d2 <= near_sq)
      near_at[n_near++] = t;
    else if (far && d2 <= far_sq)
      far_at[n_far++] = t;
  }
  near.count = n_near;
  if (far) far->count = n_far;
}

/// The nearest sample per lane so far, 4 lanes (laneSums256).
struct Nearest256 {
  __m256d best;
  __m256i id;
};
static __attribute__((target("avx2,fma"), always_inline)) inline void trackNearest256(Nearest256& n,
                                                                                      __m256d r2,
                                                                                      __m256i vid) {
  const __m256d closer =
      _mm256_or_pd(_mm256_cmp_pd(r2, n.best, _CMP_LT_OQ),
                   _mm256_and_pd(_mm256_cmp_pd(r2, n.best, _CMP_EQ_OQ),
                                 _mm256_castsi256_pd(_mm256_cmpgt_epi64(n.id, vid))));
  n.best = _mm256_blendv_pd(n.best, r2, closer);
  n.id = _mm256_castpd_si256(
      _mm256_blendv_pd(_mm256_castsi256_pd(n.id), _mm256_castsi256_pd(vid), closer));
}

/// Squared distances below this (mm², a node within 1e-15 mm of a sample, yet not on it) are
/// past the float estimate of 1/r: such a call runs the generic loops.
constexpr double kLeast256Sq = 1e-30;

struct LaneConsts256 {
  __m256d r0_sq, inv_r_min, inv_r0, half, three_eighths, one, least, zero;
};
/// The term of sample j at 4 points (ax, ay, az): laneTerm512's. 1/r from the 12-bit float
/// estimate and two third-order steps (relative error ~1e-10 after the first, rounding after
/// the second); lanes under kLeast256Sq add nothing here and flag `tiny` (a lane on the sample,
/// r² 0, adds nothing in laneTerm512 either: addZeroTerms gives its term).
template <bool Track>
static __attribute__((target("avx2,fma"), always_inline)) inline void laneTerm256(
    const LaneConsts256& k, const SampleSpan& s, int j, __m256d ax, __m256d ay, __m256d az,
    __m256d& fx, __m256d& fy, __m256d& fz, Nearest256& near, __m256d& lowest, __m256d& tiny) {
  const __m256d dx = _mm256_sub_pd(ax, _mm256_set1_pd(s.x[j]));
  const __m256d dy = _mm256_sub_pd(ay, _mm256_set1_pd(s.y[j]));
  const __m256d dz = _mm256_sub_pd(az, _mm256_set1_pd(s.z[j]));
  const __m256d r2 = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(dx, dx), _mm256_mul_pd(dy, dy)),
                                   _mm256_mul_pd(dz, dz));
  const __m256d usable = _mm256_cmp_pd(r2, k.least, _CMP_GE_OQ);
  const __m256d in = _mm256_and_pd(_mm256_cmp_pd(r2, k.r0_sq, _CMP_LT_OQ), usable);
  tiny = _mm256_or_pd(tiny, _mm256_andnot_pd(usable, _mm256_cmp_pd(r2, k.zero, _CMP_GT_OQ)));
  lowest = _mm256_min_pd(lowest, r2);
  // the estimate from r² held within float's range (out-of-range lanes are masked off below)
  const __m256d r2s = _mm256_min_pd(_mm256_max_pd(r2, k.least), k.r0_sq);
  __m256d y = _mm256_cvtps_pd(_mm_rsqrt_ps(_mm256_cvtpd_ps(r2s)));
  for (int step = 0; step < 2; ++step) {
    const __m256d e = _mm256_fnmadd_pd(_mm256_mul_pd(r2s, y), y, k.one);
    y = _mm256_fmadd_pd(y, _mm256_mul_pd(e, _mm256_fmadd_pd(e, k.three_eighths, k.half)), y);
  }
  const __m256d inv_rc = _mm256_min_pd(y, k.inv_r_min);
  const __m256d phi = _mm256_mul_pd(_mm256_sub_pd(inv_rc, k.inv_r0), _mm256_mul_pd(inv_rc, inv_rc));
  const __m256d c = _mm256_and_pd(in, _mm256_mul_pd(_mm256_mul_pd(_mm256_set1_pd(s.w[j]), phi), y));
  fx = _mm256_fmadd_pd(c, dx, fx);
  fy = _mm256_fmadd_pd(c, dy, fy);
  fz = _mm256_fmadd_pd(c, dz, fz);
  if constexpr (Track) trackNearest256(near, r2, _mm256_set1_epi64x(s.id[j]));
}

/// The sums of 4 of the 8 lanes (`first`: lanes first..first+3) over the picks, in laneSums512's
/// order: samples c and c + 1 of a step in two sets, added at the end, the nearest of the two
/// merged (ties: lowest id); stored to f, best, id, low at `first`. AVX2 has 16 registers: a
/// set of 8 lanes (laneSums512's) would spill, so the halves run one after the other.
template <bool Track>
static __attribute__((target("avx2,fma"))) void halfSums256(
    const LaneConsts256& k, const SampleSpan& s, const Picks& core, const double* px,
    const double* py, const double* pz, const double* init_sq, int first, double (*f)[kLanes],
    double* best, std::int64_t* id, double* low, __m256d& tiny) {
  const __m256d ax = _mm256_loadu_pd(px + first), ay = _mm256_loadu_pd(py + first),
                az = _mm256_loadu_pd(pz + first);
  __m256d fx = k.zero, fy = k.zero, fz = k.zero, gx = k.zero, gy = k.zero, gz = k.zero;
  __m256d lowest = _mm256_set1_pd(HUGE_VAL);
  Nearest256 near{_mm256_loadu_pd(init_sq + first), _mm256_set1_epi64x(-1)};
  Nearest256 near2 = near;
  const std::int32_t* picked = core.at.data();
  int c = 0;
  for (; c + 1 < core.count; c += 2) {
    laneTerm256<Track>(k, s, picked[c], ax, ay, az, fx, fy, fz, near, lowest, tiny);
    laneTerm256<Track>(k, s, picked[c + 1], ax, ay, az, gx, gy, gz, near2, lowest, tiny);
  }
  if (c < core.count)
    laneTerm256<Track>(k, s, picked[c], ax, ay, az, fx, fy, fz, near, lowest, tiny);
  const __m256d take =
      _mm256_or_pd(_mm256_cmp_pd(near2.best, near.best, _CMP_LT_OQ),
                   _mm256_and_pd(_mm256_cmp_pd(near2.best, near.best, _CMP_EQ_OQ),
                                 _mm256_castsi256_pd(_mm256_cmpgt_epi64(near.id, near2.id))));
  _mm256_storeu_pd(f[0] + first, _mm256_add_pd(fx, gx));
  _mm256_storeu_pd(f[1] + first, _mm256_add_pd(fy, gy));
  _mm256_storeu_pd(f[2] + first, _mm256_add_pd(fz, gz));
  _mm256_storeu_pd(best + first, _mm256_blendv_pd(near.best, near2.best, take));
  _mm256_storeu_pd(
      reinterpret_cast<double*>(id + first),
      _mm256_blendv_pd(_mm256_castsi256_pd(near.id), _mm256_castsi256_pd(near2.id), take));
  _mm256_storeu_pd(low + first, lowest);
}

/// laneSums in AVX2 (a CPU without AVX-512): laneSums512's terms, order and nearest, 4 lanes at
/// a time (halfSums256); the generic loops where a lane falls under kLeast256Sq of a sample.
static __attribute__((target("avx2,fma"))) void laneSums256(const Law& L, const SampleSpan& s,
                                                            const Picks& core, const Picks& ring,
                                                            const double* px, const double* py,
                                                            const double* pz, const double* init_sq,
                                                            Accum* out) {
  const LaneConsts256 k{_mm256_set1_pd(L.r0_sq),     _mm256_set1_pd(L.inv_r_min),
                        _mm256_set1_pd(L.inv_r0),    _mm256_set1_pd(0.5),
                        _mm256_set1_pd(0.375),       _mm256_set1_pd(1.0),
                        _mm256_set1_pd(kLeast256Sq), _mm256_setzero_pd()};
  bool track = false;
  for (int l = 0; l < kLanes; ++l) track = track || init_sq[l] > 0.0;
  alignas(32) double f[3][kLanes], b[kLanes], low[kLanes];
  alignas(32) std::int64_t bid[kLanes];
  __m256d tiny = k.zero;
  for (int first = 0; first < kLanes; first += 4) {
    if (track)
      halfSums256<true>(k, s, core, px, py, pz, init_sq, first, f, b, bid, low, tiny);
    else
      halfSums256<false>(k, s, core, px, py, pz, init_sq, first, f, b, bid, low, tiny);
  }
  if (_mm256_movemask_pd(tiny) != 0)
    return laneSumsGeneric(L, s, core, ring, px, py, pz, init_sq, out);
  // The ring's samples lie farther than r0 from every point: only a shell point's nearest.
  bool shell = false;
  for (int l = 0; l < kLanes; ++l) shell = shell || b[l] >= L.r0_sq;
  if (track && shell)
    for (int first = 0; first < kLanes; first += 4) {
      const __m256d ax = _mm256_loadu_pd(px + first), ay = _mm256_loadu_pd(py + first),
                    az = _mm256_loadu_pd(pz + first);
      Nearest256 near{_mm256_load_pd(b + first),
                      _mm256_load_si256(reinterpret_cast<const __m256i*>(bid + first))};
      for (int r = 0; r < ring.count; ++r) {
        const int j = ring.at[std::size_t(r)];
        const __m256d dx = _mm256_sub_pd(ax, _mm256_set1_pd(s.x[j]));
        const __m256d dy = _mm256_sub_pd(ay, _mm256_set1_pd(s.y[j]));
        const __m256d dz = _mm256_sub_pd(az, _mm256_set1_pd(s.z[j]));
        trackNearest256(near,
                        _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(dx, dx), _mm256_mul_pd(dy, dy)),
                                      _mm256_mul_pd(dz, dz)),
                        _mm256_set1_epi64x(s.id[j]));
      }
      _mm256_store_pd(b + first, near.best);
      _mm256_store_si256(reinterpret_cast<__m256i*>(bid + first), near.id);
    }
  for (int l = 0; l < kLanes; ++l) {
    Accum& a = out[l];
    a = Accum{};
    a.fx = f[0][l];
    a.fy = f[1][l];
    a.fz = f[2][l];
    a.best_sq = b[l];
    a.best_id = int(bid[l]);
    if (low[l] == 0.0) addZeroTerms(L, s, core, D3{px[l], py[l], pz[l]}, a);
  }
}

/// Which lanes run: AVX-512 where the CPU has it, else AVX2 with FMA, else the generic loops;
/// FIELDPATH_LANES=generic or =avx2 asks for those (what a CPU without AVX-512 runs, on one that
/// has it; the suite runs the build tests so: tests/field/CMakeLists.txt), never for more than
/// the CPU has.
enum class LaneKind { Generic, Avx2, Avx512 };
static const LaneKind kLaneKind = [] {
  const char* asked = std::getenv("FIELDPATH_LANES");
  const bool has512 = __builtin_cpu_supports("avx512f");
  const bool has256 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  if (asked && std::strcmp(asked, "generic") == 0) return LaneKind::Generic;
  if (asked && std::strcmp(asked, "avx2") == 0) return has256 ? LaneKind::Avx2 : LaneKind::Generic;
  return has512 ? LaneKind::Avx512 : has256 ? LaneKind::Avx2 : LaneKind::Generic;
}();
#endif

void gather(const SampleSpan& from, const Box& box, double near_sq, double far_sq, Picks& near,
            Picks* far) {
#if defined(__x86_64__)
  if (kLaneKind == LaneKind::Avx512) return gather512(from, box, near_sq, far_sq, near, far);
  if (kLaneKind == LaneKind::Avx2) return gather256(from, box, near_sq, far_sq, near, far);
#endif
  gatherGeneric(from, box, near_sq, far_sq, near, far);
}

void laneSums(const Law& L, const SampleSpan& from, const Picks& core, const Picks& ring,
              const double* px, const double* py, const double* pz, const double* init_sq,
              Accum* out) {
#if defined(__x86_64__)
  if (kLaneKind == LaneKind::Avx2)
    return laneSums256(L, from, core, ring, px, py, pz, init_sq, out);
  if (kLaneKind == LaneKind::Avx512) {
    int tracked = 0;
    for (int l = 0; l < kLanes; ++l) tracked += init_sq[l] > 0.0;
    if (tracked == kLanes)
      return laneSums512<true, false>(L, from, core, ring, px, py, pz, init_sq, out);
    if (tracked == 0)
      return laneSums512<false, true>(L, from, core, ring, px, py, pz, init_sq, out);
    return laneSums512<true, true>(L, from, core, ring, px, py, pz, init_sq, out);
  }
#endif
  laneSumsGeneric(L, from, core, ring, px, py, pz, init_sq, out);
}

}  // namespace fieldpath::field::lanes
