/// The CPU block build's sums in vector lanes (node_lanes.h): eq. 1 over spans of samples
/// (AVX-512 where present, a generic lane loop elsewhere), a row's samples gathered, a row's 8
/// first sums with the nodes in the lanes. No OpenVDB: quick to compile; the generic loops are
/// checked for vectorisation (`-fopt-info-vec`, CMakeLists.txt).
#include "node_lanes.h"

#include <cmath>
#include <cstdint>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace fieldpath::field::lanes {

using kernel::Accum;
using kernel::D3;
using kernel::Law;
using kernel::SampleSpan;

// File-local helpers are static; the API (node_lanes.h) is not.


/// The samples exactly at `at` among the first `count` of s (their term is along the normal).
static void addZeroTerms(const Law& L, const SampleSpan& s, int count, D3 at, Accum& a) {
  for (int j = 0; j < count; ++j) {
    const double dx = at.x - s.x[j], dy = at.y - s.y[j], dz = at.z - s.z[j];
    if (dx * dx + dy * dy + dz * dz == 0.0)
      kernel::addTerm(L, 0.0, 0.0, 0.0, 0.0, s.nx[j], s.ny[j], s.nz[j], s.w[j], a);
  }
}

/// The per-lane nearest samples merged into a (ties: lowest id).
void mergeNearest(const double* best, const std::int64_t* best_id, const std::int64_t* best_at,
                  Accum& a, int lanes) {
  for (int l = 0; l < lanes; ++l)
    if (best_id[l] >= 0 && (best[l] < a.best_sq ||
                            (best[l] == a.best_sq && (a.best_id < 0 || best_id[l] < a.best_id)))) {
      a.best_sq = best[l];
      a.best_id = int(best_id[l]);
      a.best_at = int(best_at[l]);
    }
}

/// Eq. 1 over a span in lanes of kLanes: the same terms as kernel::addTerm, summed per lane then
/// across the lanes; the nearest sample per lane (ties: lowest id), then across. The rest
/// (count % kLanes) runs scalar. Written for the compiler to vectorise (branch-free lane loops).
static void accumulateGeneric(const Law& L, const SampleSpan& s, D3 at, bool track, Accum& a) {
  const int full = s.count - s.count % kLanes;
  if (full > 0) {
    double fx[kLanes] = {}, fy[kLanes] = {}, fz[kLanes] = {};
    double best[kLanes];
    std::int64_t best_id[kLanes], best_at[kLanes];
    for (int l = 0; l < kLanes; ++l) {
      best[l] = a.best_sq;
      best_id[l] = -1;
      best_at[l] = -1;
    }
    int zero = 0;
    const double r0_sq = L.r0_sq, r_min = L.r_min, inv_r0 = L.inv_r0;
    for (int j = 0; j < full; j += kLanes) {
      double dx[kLanes], dy[kLanes], dz[kLanes], r2[kLanes], c[kLanes];
      for (int l = 0; l < kLanes; ++l) {
        dx[l] = at.x - s.x[j + l];
        dy[l] = at.y - s.y[j + l];
        dz[l] = at.z - s.z[j + l];
        r2[l] = dx[l] * dx[l] + dy[l] * dy[l] + dz[l] * dz[l];
      }
      for (int l = 0; l < kLanes; ++l) {
        const double in = r2[l] < r0_sq && r2[l] > 0.0 ? 1.0 : 0.0;
        const double r = std::sqrt(r2[l] > 0.0 ? r2[l] : 1.0);
        const double rc = r < r_min ? r_min : r;
        c[l] = in * (s.w[j + l] * ((1.0 / rc - inv_r0) / (rc * rc)) / r);
        zero += r2[l] == 0.0 ? 1 : 0;
      }
      for (int l = 0; l < kLanes; ++l) {
        fx[l] += c[l] * dx[l];
        fy[l] += c[l] * dy[l];
        fz[l] += c[l] * dz[l];
      }
      if (track)
        for (int l = 0; l < kLanes; ++l) {
          const std::int64_t id = s.id[j + l];
          const bool closer = r2[l] < best[l] || (r2[l] == best[l] && id < best_id[l]);
          best[l] = closer ? r2[l] : best[l];
          best_id[l] = closer ? id : best_id[l];
          best_at[l] = closer ? std::int64_t(s.base + j + l) : best_at[l];
        }
    }
    for (int l = 0; l < kLanes; ++l) {
      a.fx += fx[l];
      a.fy += fy[l];
      a.fz += fz[l];
    }
    if (track) mergeNearest(best, best_id, best_at, a);
    if (zero) addZeroTerms(L, s, full, at, a);
  }
  if (full < s.count) kernel::accumulateScalar(L, kernel::tail(s, full), at, track, a);
}

#if defined(__x86_64__)
/// accumulateGeneric with AVX-512 (8 doubles a register) over `n` spans in the same lanes (one
/// reduction for them all: the cell list's columns are short): 1/r from the 14-bit reciprocal
/// square root and two Newton steps (relative error ~1e-16: no division, no square root), r²
/// summed in the scalar's order (same nearest sample, same cut at r0); each span's last
/// count % 8 samples under a load mask.
static __attribute__((target("avx512f"))) void accumulate512(const Law& L, const SampleSpan* spans, int n,
                                                      D3 at, bool track, Accum& a) {
  const __m512d ax = _mm512_set1_pd(at.x), ay = _mm512_set1_pd(at.y), az = _mm512_set1_pd(at.z);
  const __m512d r0_sq = _mm512_set1_pd(L.r0_sq), inv_r_min = _mm512_set1_pd(1.0 / L.r_min);
  const __m512d inv_r0 = _mm512_set1_pd(L.inv_r0), one = _mm512_set1_pd(1.0);
  const __m512d half = _mm512_set1_pd(0.5), three_halves = _mm512_set1_pd(1.5);
  const __m512d far = _mm512_set1_pd(HUGE_VAL);  // lanes past a span's end: never in, never nearest
  __m512d fx = _mm512_setzero_pd(), fy = _mm512_setzero_pd(), fz = _mm512_setzero_pd();
  __m512d best = _mm512_set1_pd(a.best_sq);
  __m512i best_id = _mm512_set1_epi64(-1), best_at = _mm512_set1_epi64(-1);
  const __m512i lane = _mm512_set_epi64(7, 6, 5, 4, 3, 2, 1, 0);
  for (int k = 0; k < n; ++k) {
    const SampleSpan& s = spans[k];
    __mmask8 zero = 0;
    for (int j = 0; j < s.count; j += kLanes) {
      const int left = s.count - j;
      const __mmask8 valid = left >= kLanes ? __mmask8(0xff) : __mmask8((1u << left) - 1u);
      const __m512d dx = _mm512_sub_pd(ax, _mm512_mask_loadu_pd(far, valid, s.x + j));
      const __m512d dy = _mm512_sub_pd(ay, _mm512_maskz_loadu_pd(valid, s.y + j));
      const __m512d dz = _mm512_sub_pd(az, _mm512_maskz_loadu_pd(valid, s.z + j));
      const __m512d r2 = _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(dx, dx), _mm512_mul_pd(dy, dy)),
                                       _mm512_mul_pd(dz, dz));
      const __mmask8 positive = _mm512_cmp_pd_mask(r2, _mm512_setzero_pd(), _CMP_GT_OQ);
      const __mmask8 in = _mm512_mask_cmp_pd_mask(positive, r2, r0_sq, _CMP_LT_OQ);
      zero |= _mm512_mask_cmp_pd_mask(valid, r2, _mm512_setzero_pd(), _CMP_EQ_OQ);
      if (in) {
        const __m512d r2s = _mm512_mask_blend_pd(in, one, r2);
        __m512d y = _mm512_rsqrt14_pd(r2s);  // 1/r
        const __m512d hr2 = _mm512_mul_pd(half, r2s);
        y = _mm512_mul_pd(y, _mm512_fnmadd_pd(hr2, _mm512_mul_pd(y, y), three_halves));
        y = _mm512_mul_pd(y, _mm512_fnmadd_pd(hr2, _mm512_mul_pd(y, y), three_halves));
        const __m512d inv_rc = _mm512_min_pd(y, inv_r_min);
        const __m512d phi = _mm512_mul_pd(_mm512_sub_pd(inv_rc, inv_r0),
                                          _mm512_mul_pd(inv_rc, inv_rc));
        const __m512d c = _mm512_maskz_mul_pd(
            in, _mm512_mul_pd(_mm512_maskz_loadu_pd(valid, s.w + j), phi), y);
        fx = _mm512_mask3_fmadd_pd(c, dx, fx, in);  // masked: 0 · inf past the end
        fy = _mm512_mask3_fmadd_pd(c, dy, fy, in);
        fz = _mm512_mask3_fmadd_pd(c, dz, fz, in);
      }
      if (track) {
        const __m512i id = _mm512_cvtepi32_epi64(
            _mm512_castsi512_si256(_mm512_maskz_loadu_epi32(__mmask16(valid), s.id + j)));
        const __mmask8 closer =
            _mm512_mask_cmp_pd_mask(valid, r2, best, _CMP_LT_OQ) |
            (_mm512_mask_cmp_pd_mask(valid, r2, best, _CMP_EQ_OQ) &
             _mm512_cmplt_epi64_mask(id, best_id));
        if (closer) {
          best = _mm512_mask_blend_pd(closer, best, r2);
          best_id = _mm512_mask_blend_epi64(closer, best_id, id);
          best_at = _mm512_mask_blend_epi64(
              closer, best_at, _mm512_add_epi64(lane, _mm512_set1_epi64(s.base + j)));
        }
      }
    }
    if (zero) addZeroTerms(L, s, s.count, at, a);
  }
  a.fx += _mm512_reduce_add_pd(fx);
  a.fy += _mm512_reduce_add_pd(fy);
  a.fz += _mm512_reduce_add_pd(fz);
  if (track) {
    alignas(64) double b[kLanes];
    alignas(64) std::int64_t bid[kLanes], bat[kLanes];
    _mm512_store_pd(b, best);
    _mm512_store_epi64(bid, best_id);
    _mm512_store_epi64(bat, best_at);
    mergeNearest(b, bid, bat, a);
  }
}

const bool kHaveAvx512 = __builtin_cpu_supports("avx512f");
#endif

void accumulateLanes(const Law& L, const SampleSpan* spans, int n, D3 at, bool track, Accum& a) {
#if defined(__x86_64__)
  if (kHaveAvx512) return accumulate512(L, spans, n, at, track, a);
#endif
  for (int k = 0; k < n; ++k) accumulateGeneric(L, spans[k], at, track, a);
}
void accumulateLanes(const Law& L, const SampleSpan& s, D3 at, bool track, Accum& a) {
  accumulateLanes(L, &s, 1, at, track, a);
}

/// The gap between p and [lo, hi] (0 inside): for a row's segment (lo = hi) |p - lo|, whose
/// square is (p - lo)² to the bit, so that a row's set is the same through a box or not.
static inline double gapTo(double p, double lo, double hi) {
  const double below = lo - p, above = p - hi;
  return below > 0.0 ? below : above > 0.0 ? above : 0.0;
}

namespace {
/// A SampleSet's arrays as plain pointers (loaded once: through the vectors, every store made
/// the compiler load them again).
struct SetOut {
  double* v[7];
  std::int32_t* id;
  explicit SetOut(SampleSet& s) : id(s.id.data()) {
    const auto arrays = s.doubles();
    for (int k = 0; k < 7; ++k) v[k] = arrays[k]->data();
  }
};
}  // namespace

static void gatherGeneric(const SampleSpan& f, const Box& box, double near_sq, double far_sq,
                          SampleSet& near, SampleSet* far) {
  int counts[2] = {0, 0};
  SampleSet* sets[2] = {&near, far};
  for (int t = 0; t < f.count; ++t) {
    const double dx = gapTo(f.x[t], box.lo[0], box.hi[0]);
    const double dy = gapTo(f.y[t], box.lo[1], box.hi[1]);
    const double dz = gapTo(f.z[t], box.lo[2], box.hi[2]);
    const double d2 = dx * dx + dy * dy + dz * dz;
    const int which = d2 <= near_sq ? 0 : far && d2 <= far_sq ? 1 : -1;
    if (which < 0) continue;
    SampleSet& to = *sets[which];
    const int n = counts[which]++;
    to.x[n] = f.x[t];
    to.y[n] = f.y[t];
    to.z[n] = f.z[t];
    to.nx[n] = f.nx[t];
    to.ny[n] = f.ny[t];
    to.nz[n] = f.nz[t];
    to.w[n] = f.w[t];
    to.id[n] = f.id[t];
  }
  near.count = counts[0];
  if (far) far->count = counts[1];
}

#if defined(__x86_64__)
/// The lanes `in` of one batch of 8 samples (px, py, pz and the rest at f's position t)
/// appended to `to` at n: compressed in registers and stored whole (the lanes past the passing
/// ones are written over by the next store, or lie in the arrays' padding; the memory form of
/// vcompresspd is microcoded).
static __attribute__((target("avx512f"), always_inline)) inline void append512(
    const SampleSpan& f, int t, __mmask8 valid, __mmask8 in, __m512d px, __m512d py, __m512d pz,
    const SetOut& to, int n) {
  _mm512_storeu_pd(to.v[0] + n, _mm512_maskz_compress_pd(in, px));
  _mm512_storeu_pd(to.v[1] + n, _mm512_maskz_compress_pd(in, py));
  _mm512_storeu_pd(to.v[2] + n, _mm512_maskz_compress_pd(in, pz));
  const double* rest[4] = {f.nx, f.ny, f.nz, f.w};
  for (int k = 0; k < 4; ++k)
    _mm512_storeu_pd(to.v[3 + k] + n,
                     _mm512_maskz_compress_pd(in, _mm512_maskz_loadu_pd(valid, rest[k] + t)));
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(to.id + n),
                      _mm512_castsi512_si256(_mm512_maskz_compress_epi32(
                          __mmask16(in), _mm512_maskz_loadu_epi32(__mmask16(valid), f.id + t))));
}

/// gatherGeneric in AVX-512 lanes: the same test, one pass for both sets.
static __attribute__((target("avx512f"))) void gather512(const SampleSpan& f, const Box& box,
                                                         double near_sq, double far_sq,
                                                         SampleSet& near, SampleSet* far) {
  const __m512d zero = _mm512_setzero_pd();
  __m512d blo[3], bhi[3];
  for (int a = 0; a < 3; ++a) {
    blo[a] = _mm512_set1_pd(box.lo[a]);
    bhi[a] = _mm512_set1_pd(box.hi[a]);
  }
  const __m512d vnear = _mm512_set1_pd(near_sq), vfar = _mm512_set1_pd(far ? far_sq : near_sq);
  const SetOut near_out(near);
  const SetOut far_out(far ? *far : near);
  int n_near = 0, n_far = 0;
  for (int t = 0; t < f.count; t += kLanes) {
    const int left = f.count - t;
    const __mmask8 valid = left >= kLanes ? __mmask8(0xff) : __mmask8((1u << left) - 1u);
    const __m512d px = _mm512_maskz_loadu_pd(valid, f.x + t);
    const __m512d py = _mm512_maskz_loadu_pd(valid, f.y + t);
    const __m512d pz = _mm512_maskz_loadu_pd(valid, f.z + t);
    // max(0, lo - p, p - hi): gapTo's value (one of the two differences is <= 0)
    __m512d d[3];
    const __m512d p[3] = {px, py, pz};
    for (int a = 0; a < 3; ++a)
      d[a] = _mm512_max_pd(zero, _mm512_max_pd(_mm512_sub_pd(blo[a], p[a]), _mm512_sub_pd(p[a], bhi[a])));
    const __m512d d2 = _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(d[0], d[0]), _mm512_mul_pd(d[1], d[1])),
                                     _mm512_mul_pd(d[2], d[2]));
    const __mmask8 in_near = _mm512_mask_cmp_pd_mask(valid, d2, vnear, _CMP_LE_OQ);
    const __mmask8 in_far =
        far ? __mmask8(_mm512_mask_cmp_pd_mask(valid, d2, vfar, _CMP_LE_OQ) & ~in_near) : 0;
    if (in_near) {
      append512(f, t, valid, in_near, px, py, pz, near_out, n_near);
      n_near += __builtin_popcount(in_near);
    }
    if (in_far) {
      append512(f, t, valid, in_far, px, py, pz, far_out, n_far);
      n_far += __builtin_popcount(in_far);
    }
  }
  near.count = n_near;
  if (far) far->count = n_far;
}
#endif

void gather(const SampleSpan& from, const Box& box, double near_sq, double far_sq,
            SampleSet& near, SampleSet* far) {
#if defined(__x86_64__)
  if (kHaveAvx512) return gather512(from, box, near_sq, far_sq, near, far);
#endif
  gatherGeneric(from, box, near_sq, far_sq, near, far);
}

#if defined(__x86_64__)
/// The nearest sample per lane so far (rowFirstSums512).
struct Nearest512 {
  __m512d best;
  __m512i id, at;
};
/// Sample (id, at) at squared distances r2 from the lanes' points: nearer (or as near with a
/// lower id) replaces a lane's nearest.
static __attribute__((target("avx512f"), always_inline)) inline void trackNearest(Nearest512& n,
                                                                          __m512d r2,
                                                                          std::int64_t id,
                                                                          std::int64_t at) {
  const __m512i vid = _mm512_set1_epi64(id);
  const __mmask8 closer = _mm512_cmp_pd_mask(r2, n.best, _CMP_LT_OQ) |
                          (_mm512_cmp_pd_mask(r2, n.best, _CMP_EQ_OQ) &
                           _mm512_cmplt_epi64_mask(vid, n.id));
  if (closer) {
    n.best = _mm512_mask_blend_pd(closer, n.best, r2);
    n.id = _mm512_mask_blend_epi64(closer, n.id, vid);
    n.at = _mm512_mask_blend_epi64(closer, n.at, _mm512_set1_epi64(at));
  }
}

/// The first sums (kernel::probe's) of a row's 8 nodes at once, the nodes in the lanes: every
/// sample of `core` (those within r0 of the row's segment) read once for the 8, eq. 1 summed for
/// those within r0, the nearest within sqrt(init_sq) tracked (ties: lowest id); then, for nodes
/// with no sample within r0 (the shell), the nearest among `ring` (the rest of the row's reach).
/// Each node's terms as accumulate512's, summed in the samples' order.
static __attribute__((target("avx512f"))) void rowFirstSums512(const Law& L, const SampleSpan& core,
                                                        const SampleSpan& ring, double x,
                                                        double y, const double* node_z,
                                                        double init_sq, Accum* out) {
  const __m512d az = _mm512_loadu_pd(node_z);
  const __m512d r0_sq = _mm512_set1_pd(L.r0_sq), inv_r_min = _mm512_set1_pd(1.0 / L.r_min);
  const __m512d inv_r0 = _mm512_set1_pd(L.inv_r0);
  const __m512d half = _mm512_set1_pd(0.5), three_halves = _mm512_set1_pd(1.5);
  const __m512d one = _mm512_set1_pd(1.0), zero_v = _mm512_setzero_pd();
  __m512d fx = zero_v, fy = zero_v, fz = zero_v;
  Nearest512 near{_mm512_set1_pd(init_sq), _mm512_set1_epi64(-1), _mm512_set1_epi64(-1)};
  __mmask8 zero = 0;
  for (int j = 0; j < core.count; ++j) {
    const __m512d dx = _mm512_set1_pd(x - core.x[j]), dy = _mm512_set1_pd(y - core.y[j]);
    const __m512d dz = _mm512_sub_pd(az, _mm512_set1_pd(core.z[j]));
    const __m512d r2 = _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(dx, dx), _mm512_mul_pd(dy, dy)),
                                     _mm512_mul_pd(dz, dz));
    const __mmask8 positive = _mm512_cmp_pd_mask(r2, zero_v, _CMP_GT_OQ);
    const __mmask8 in = _mm512_mask_cmp_pd_mask(positive, r2, r0_sq, _CMP_LT_OQ);
    zero |= _mm512_cmp_pd_mask(r2, zero_v, _CMP_EQ_OQ);
    if (in) {
      const __m512d r2s = _mm512_mask_blend_pd(in, one, r2);
      __m512d yv = _mm512_rsqrt14_pd(r2s);  // 1/r, two Newton steps (as accumulate512)
      const __m512d hr2 = _mm512_mul_pd(half, r2s);
      yv = _mm512_mul_pd(yv, _mm512_fnmadd_pd(hr2, _mm512_mul_pd(yv, yv), three_halves));
      yv = _mm512_mul_pd(yv, _mm512_fnmadd_pd(hr2, _mm512_mul_pd(yv, yv), three_halves));
      const __m512d inv_rc = _mm512_min_pd(yv, inv_r_min);
      const __m512d phi =
          _mm512_mul_pd(_mm512_sub_pd(inv_rc, inv_r0), _mm512_mul_pd(inv_rc, inv_rc));
      const __m512d c =
          _mm512_maskz_mul_pd(in, _mm512_mul_pd(_mm512_set1_pd(core.w[j]), phi), yv);
      fx = _mm512_mask3_fmadd_pd(c, dx, fx, in);
      fy = _mm512_mask3_fmadd_pd(c, dy, fy, in);
      fz = _mm512_mask3_fmadd_pd(c, dz, fz, in);
    }
    trackNearest(near, r2, core.id[j], core.base + j);
  }
  // The ring's samples lie farther than r0 from every node: only a shell node's nearest.
  if (_mm512_cmp_pd_mask(near.best, r0_sq, _CMP_GE_OQ))
    for (int j = 0; j < ring.count; ++j) {
      const __m512d dx = _mm512_set1_pd(x - ring.x[j]), dy = _mm512_set1_pd(y - ring.y[j]);
      const __m512d dz = _mm512_sub_pd(az, _mm512_set1_pd(ring.z[j]));
      trackNearest(near,
                   _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(dx, dx), _mm512_mul_pd(dy, dy)),
                                 _mm512_mul_pd(dz, dz)),
                   ring.id[j], ring.base + j);
    }
  alignas(64) double f[3][kLanes], b[kLanes];
  alignas(64) std::int64_t bid[kLanes], bat[kLanes];
  _mm512_store_pd(f[0], fx);
  _mm512_store_pd(f[1], fy);
  _mm512_store_pd(f[2], fz);
  _mm512_store_pd(b, near.best);
  _mm512_store_epi64(bid, near.id);
  _mm512_store_epi64(bat, near.at);
  for (int l = 0; l < kLanes; ++l) {
    Accum& a = out[l];
    a = Accum{};
    a.fx = f[0][l];
    a.fy = f[1][l];
    a.fz = f[2][l];
    a.best_sq = b[l];
    a.best_id = int(bid[l]);
    a.best_at = int(bat[l]);
    if ((zero >> l) & 1) addZeroTerms(L, core, core.count, D3{x, y, node_z[l]}, a);
  }
}
#endif

bool rowFirstSums(const Law& L, const SampleSpan& core, const SampleSpan& ring, double x, double y,
                  const double* node_z, double init_sq, Accum* out) {
#if defined(__x86_64__)
  if (kHaveAvx512) {
    rowFirstSums512(L, core, ring, x, y, node_z, init_sq, out);
    return true;
  }
#endif
  return false;
}

}  // namespace fieldpath::field::lanes
