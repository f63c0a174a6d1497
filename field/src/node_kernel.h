#pragma once
/// Internal to field/: the value of one voxel node from the samples (law.h's probe() and the
/// plane ratio of node_build.cpp), written once for the CPU block build and the CUDA kernel
/// (node_build_cuda.cu). No OpenVDB, no Eigen: plain doubles, so that nvcc compiles it too.
///
/// The samples are read through a "neighbourhood" (a template parameter, `Hood`) with:
///   void sum(D3 center, double radius, bool track, Accum& a);  // adds every sample within
///       radius of center (a superset is fine: the terms and the nearest search filter by
///       distance), tracking the nearest sample if `track`
///   D3 point(const Accum& a), normal(const Accum& a);  // of the nearest sample (a.best_at)
///   bool farFace(const Accum& a);  // whether the nearest sample is a far face (farFaces)
///   void nearFace(D3 x, D3 q, D3 n, double eta, Accum& a);  // law.h's thin-wall rule: the
///       nearest near face within sqrt(a.best_sq) of x (nearFaceScalar), every sample searched
///   void round(D3 foot, D3 nj, double reach, Round& r);  // law.h's roundTerm over the samples
///       within reach of the foot (roundScalar), every sample searched
///   bool pending() const;  // a sum it could not answer yet: the value being made is thrown
///                          // away, so probe() and nodeValue() stop at once
/// The GPU passes a cell list (never pending); the CPU block build a node's sums made in lanes
/// with other nodes' (node_block.cpp ReplayHood: pending until they are).
#include <cmath>
#include <cstdint>

#if defined(__CUDACC__)
#define FP_HD __host__ __device__ inline
#else
#define FP_HD inline
#endif

namespace fieldpath::field::kernel {

struct D3 {
  double x, y, z;
};
FP_HD D3 operator+(D3 a, D3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
FP_HD D3 operator-(D3 a, D3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
FP_HD D3 operator*(double s, D3 a) { return {s * a.x, s * a.y, s * a.z}; }
FP_HD double dot(D3 a, D3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
FP_HD double norm(D3 a) { return sqrt(dot(a, a)); }
FP_HD double dmax(double a, double b) { return a > b ? a : b; }
FP_HD double dmin(double a, double b) { return a < b ? a : b; }

/// Samples in structure-of-arrays form (world frame, mm); `id` is the sample's index in
/// ObstacleSamples (ties of the nearest sample go to the lowest id, whatever the order here).
struct SampleSpan {
  const double *x, *y, *z, *nx, *ny, *nz, *w;
  const std::int32_t* id;
  int count;
  int base;  ///< position of sample 0 of the span in its neighbourhood's table
};

/// The samples of s from position `from` on (pointers, count and base moved together).
FP_HD SampleSpan tail(const SampleSpan& s, int from) {
  SampleSpan rest = s;
  rest.x += from;
  rest.y += from;
  rest.z += from;
  rest.nx += from;
  rest.ny += from;
  rest.nz += from;
  rest.w += from;
  rest.id += from;
  rest.count -= from;
  rest.base += from;
  return rest;
}

/// eq. 1 and the plane law (law.h phi, sampleTerm, PlaneLaw) with their constants.
struct Law {
  double r0, r0_sq, inv_r0, r_min, r_min_sq, gain;
  double inv_r_min;     ///< 1 / r_min
  double plane_scale;  ///< PlaneLaw::scale
  double face_reach;   ///< law.h thin-wall rule: kThinReachSteps · sample_step, mm
  /// PlaneLaw::at
  FP_HD double planeAt(double d_mm) const {
    const double d = dmax(fabs(d_mm), r_min);
    if (d >= r0) return 0.0;
    return plane_scale * (r0 - d) * (r0 - d) / d;
  }
  /// PlaneLaw::height
  FP_HD double planeHeight(double magnitude) const {
    if (!(magnitude > 0.0) || !(plane_scale > 0.0)) return r0;
    const double b = 2.0 * plane_scale * r0 + magnitude;
    return 2.0 * plane_scale * r0 * r0 /
           (b + sqrt(magnitude * (4.0 * plane_scale * r0 + magnitude)));
  }
};

/// What a node is made of beyond the law (node_build.cpp NodeRules; VoxelRequest).
struct Rules {
  bool ratio;          ///< StoredQuantity::PlaneRatio
  double band_in_mm;   ///< inside band depth
  double reach_mm;     ///< nearest-sample search radius
  double over_mm;      ///< sideways reach of a sample (overSurface)
  double near_mm;      ///< plane_near_mm
  bool has_region;
  double region_lo[3], region_hi[3];
};

constexpr double kOverCos = 0.7;  ///< |cos| of the field's angle to n* over the surface
constexpr double kPlaneFit = 0.1;  ///< voxel_field.h kPlaneFitTolerance (a device constant)
constexpr double kPlaneRescale = 2.0;  ///< voxel_field.h kPlaneRescaleLimit

/// A running sum of eq. 1 and the nearest sample (by squared distance, then lowest id).
struct Accum {
  double fx = 0.0, fy = 0.0, fz = 0.0;
  double best_sq;   ///< nearest squared distance so far (starts at the search radius²)
  int best_id = -1; ///< ObstacleSamples index of the nearest, -1 if none
  int best_at = -1; ///< its position in the neighbourhood's table (SampleSpan::base + j)
};

/// One sample's term (law.h sampleTerm) added to a, for d = at - q, r2 = |d|², r2 < r0².
FP_HD void addTerm(const Law& L, double dx, double dy, double dz, double r2, double nx, double ny,
                   double nz, double w, Accum& a) {
  if (r2 > 0.0) {
#if defined(__CUDA_ARCH__)
    // The same term from 1/r (rsqrt, 1 ulp): no double division or square root, which cost
    // the GPU most of its time; the CPU's AVX-512 lanes do the same (node_block.cpp).
    const double inv_r = rsqrt(r2);
    const double inv_rc = dmin(inv_r, L.inv_r_min);
    const double c = w * (inv_rc - L.inv_r0) * (inv_rc * inv_rc) * inv_r;
#else
    const double r = sqrt(r2);
    const double rc = dmax(r, L.r_min);
    const double c = w * ((1.0 / rc - L.inv_r0) / (rc * rc)) / r;
#endif
    a.fx += c * dx;
    a.fy += c * dy;
    a.fz += c * dz;
  } else {  // on the sample: along its normal, φ held at r_min
    const double c = w * ((1.0 / L.r_min - L.inv_r0) / L.r_min_sq);
    a.fx += c * nx;
    a.fy += c * ny;
    a.fz += c * nz;
  }
}

/// The scalar sum over one span (GPU; the CPU block build has its own vector loop with the
/// same terms, node_build.cpp).
FP_HD void accumulateScalar(const Law& L, const SampleSpan& s, D3 at, bool track, Accum& a) {
  for (int j = 0; j < s.count; ++j) {
    const double dx = at.x - s.x[j], dy = at.y - s.y[j], dz = at.z - s.z[j];
    const double r2 = dx * dx + dy * dy + dz * dz;
    if (track && (r2 < a.best_sq || (r2 == a.best_sq && a.best_id >= 0 && s.id[j] < a.best_id))) {
      a.best_sq = r2;
      a.best_id = s.id[j];
      a.best_at = s.base + j;
    }
    if (r2 >= L.r0_sq) continue;
    addTerm(L, dx, dy, dz, r2, s.nx[j], s.ny[j], s.nz[j], s.w[j], a);
  }
}

/// law.h isNearFace: sample j a face between x and the face of q (normal n) behind which x
/// reads at height eta < 0.
FP_HD bool isNearFace(D3 x, D3 q, D3 n, double eta, D3 qj, D3 nj) {
  return dot(nj, n) < 0.0 && dot(qj - q, n) < 0.0 && fabs(dot(x - qj, nj)) < -eta;
}

/// The thin-wall rule's search over one span (law.h probe): the nearest near face (isNearFace)
/// within sqrt(a.best_sq) of x, ties to the lowest id, into a's best_*; no terms summed.
FP_HD void nearFaceScalar(const SampleSpan& s, D3 x, D3 q, D3 n, double eta, Accum& a) {
  for (int j = 0; j < s.count; ++j) {
    const double dx = x.x - s.x[j], dy = x.y - s.y[j], dz = x.z - s.z[j];
    const double r2 = dx * dx + dy * dy + dz * dz;
    if (!(r2 < a.best_sq || (r2 == a.best_sq && a.best_id >= 0 && s.id[j] < a.best_id))) continue;
    if (!isNearFace(x, q, n, eta, D3{s.x[j], s.y[j], s.z[j]}, D3{s.nx[j], s.ny[j], s.nz[j]}))
      continue;
    a.best_sq = r2;
    a.best_id = s.id[j];
    a.best_at = s.base + j;
  }
}

/// law.h roundTerm and surrounded: the near face's samples round x's foot on its plane.
struct Round {
  D3 sum{0, 0, 0};
  int count = 0;
  FP_HD bool surrounded() const { return count >= 3 && norm(sum) <= 0.5 * count; }
};
FP_HD void roundScalar(const SampleSpan& s, D3 foot, D3 nj, double reach, Round& r) {
  for (int i = 0; i < s.count; ++i) {
    if (!(s.nx[i] * nj.x + s.ny[i] * nj.y + s.nz[i] * nj.z >= 0.95)) continue;
    const D3 d{s.x[i] - foot.x, s.y[i] - foot.y, s.z[i] - foot.z};
    const double off = dot(d, nj);
    if (!(fabs(off) <= 0.5 * reach)) continue;
    const D3 lateral = d - off * nj;
    const double length = norm(lateral);
    if (!(length <= reach)) continue;
    ++r.count;
    if (length > 0.0) r.sum = r.sum + (1.0 / length) * lateral;
  }
}

/// The samples sorted by cell (node_block.h SampleTable) as plain pointers.
struct CellTable {
  SampleSpan all;  ///< every sample, base 0
  const std::int32_t* cell_start;
  const std::uint8_t* far_face;  ///< farFaces' flags (law.h's thin-wall rule), table order
  double lo[3];
  double cell_mm, inv_cell;
  int dim[3];
};

/// Calls visit(span) for runs of cells (a z column each) that hold every sample within `radius`
/// of c; columns whose xy rectangle lies farther than `radius` from c are skipped.
template <class Visit>
FP_HD void cellSpans(const CellTable& T, D3 c, double radius, Visit& visit) {
  const double cc[3] = {c.x, c.y, c.z};
  int ilo[3], ihi[3];
  for (int a = 0; a < 3; ++a) {
    const double flo = floor((cc[a] - radius - T.lo[a]) * T.inv_cell);
    const double fhi = floor((cc[a] + radius - T.lo[a]) * T.inv_cell);
    if (fhi < 0.0 || flo > double(T.dim[a] - 1)) return;
    ilo[a] = flo < 0.0 ? 0 : int(flo);
    ihi[a] = fhi > double(T.dim[a] - 1) ? T.dim[a] - 1 : int(fhi);
  }
  const double r_sq = radius * radius;
  for (int ix = ilo[0]; ix <= ihi[0]; ++ix) {
    const double x0 = T.lo[0] + ix * T.cell_mm;
    const double dx = dmax(0.0, dmax(x0 - c.x, c.x - (x0 + T.cell_mm)));
    for (int iy = ilo[1]; iy <= ihi[1]; ++iy) {
      const double y0 = T.lo[1] + iy * T.cell_mm;
      const double dy = dmax(0.0, dmax(y0 - c.y, c.y - (y0 + T.cell_mm)));
      if (dx * dx + dy * dy > r_sq) continue;
      const int column = (ix * T.dim[1] + iy) * T.dim[2];
      const int first = T.cell_start[column + ilo[2]];
      const int last = T.cell_start[column + ihi[2] + 1];
      if (first >= last) continue;
      SampleSpan s = tail(T.all, first);
      s.count = last - first;
      visit(s);
    }
  }
}

/// The thin-wall rule's search (nearFaceScalar) over the cells within sqrt(a.best_sq) of x.
FP_HD void nearFaceIn(const CellTable& T, D3 x, D3 q, D3 n, double eta, Accum& a) {
  struct Visit {
    D3 x, q, n;
    double eta;
    Accum* a;
    FP_HD void operator()(const SampleSpan& s) { nearFaceScalar(s, x, q, n, eta, *a); }
  } v{x, q, n, eta, &a};
  cellSpans(T, x, sqrt(a.best_sq), v);
}

/// roundScalar over the cells within `reach` of the foot.
FP_HD void roundIn(const CellTable& T, D3 foot, D3 nj, double reach, Round& r) {
  struct Visit {
    D3 foot, nj;
    double reach;
    Round* r;
    FP_HD void operator()(const SampleSpan& s) { roundScalar(s, foot, nj, reach, *r); }
  } v{foot, nj, reach, &r};
  cellSpans(T, foot, reach, v);
}

/// The cell list as a neighbourhood, summing with accumulateScalar (the GPU's).
struct CellHood {
  const CellTable* table;
  const Law* law;
  struct Visit {
    const Law* law;
    D3 at;
    bool track;
    Accum* a;
    FP_HD void operator()(const SampleSpan& s) { accumulateScalar(*law, s, at, track, *a); }
  };
  FP_HD void sum(D3 c, double radius, bool track, Accum& a) {
    Visit v{law, c, track, &a};
    cellSpans(*table, c, radius, v);
  }
  FP_HD bool farFace(const Accum& a) const { return table->far_face[a.best_at] != 0; }
  FP_HD void nearFace(D3 x, D3 q, D3 n, double eta, Accum& a) {
    nearFaceIn(*table, x, q, n, eta, a);
  }
  FP_HD void round(D3 foot, D3 nj, double reach, Round& r) { roundIn(*table, foot, nj, reach, r); }
  FP_HD D3 point(const Accum& a) const {
    return {table->all.x[a.best_at], table->all.y[a.best_at], table->all.z[a.best_at]};
  }
  FP_HD D3 normal(const Accum& a) const {
    return {table->all.nx[a.best_at], table->all.ny[a.best_at], table->all.nz[a.best_at]};
  }
  FP_HD bool pending() const { return false; }
};

/// law.h Probe, with the nearest sample's point and normal.
struct Probe {
  bool has_force = false;
  D3 force{0, 0, 0};
  bool has_nearest = false;
  double nearest_mm = 0.0, height_mm = 0.0;
  D3 q{0, 0, 0}, n{0, 0, 0};
};

/// law.h detail::probe: eq. 1 with the surface rule; the nearest sample within `search_mm`.
/// `sum(center, radius, track, accum)` adds the samples near center (Hood::sum).
template <class Hood>
FP_HD Probe probe(Hood& hood, const Law& L, D3 x, double search_mm) {
  Probe out;
  Accum a;
  a.best_sq = dmax(search_mm, L.r0);
  a.best_sq *= a.best_sq;
  hood.sum(x, sqrt(a.best_sq), true, a);
  if (hood.pending() || a.best_id < 0) return out;
  out.has_nearest = true;
  out.q = hood.point(a);
  out.n = hood.normal(a);
  out.nearest_mm = sqrt(a.best_sq);
  out.height_mm = dot(x - out.q, out.n);
  if (out.height_mm < 0.0 && hood.farFace(a)) {  // law.h's thin-wall rule
    Accum face;
    face.best_sq = (out.nearest_mm + L.face_reach) * (out.nearest_mm + L.face_reach);
    hood.nearFace(x, out.q, out.n, out.height_mm, face);
    if (face.best_id >= 0) {  // under x's foot (law.h)
      const D3 qj = hood.point(face), nj = hood.normal(face);
      Round r;
      hood.round(x - dot(x - qj, nj) * nj, nj, L.face_reach, r);
      if (!r.surrounded()) face.best_id = -1;
    }
    if (face.best_id >= 0) {
      out.q = hood.point(face);
      out.n = hood.normal(face);
      out.nearest_mm = sqrt(face.best_sq);
      out.height_mm = dot(x - out.q, out.n);
    }
  }
  if (a.best_sq >= L.r0_sq) return out;
  D3 f{a.fx, a.fy, a.fz};
  if (out.height_mm < L.r_min) {
    const double lifted_mm = dmax(fabs(out.height_mm), L.r_min);
    Accum b;
    b.best_sq = 0.0;
    hood.sum(x + (lifted_mm - out.height_mm) * out.n, L.r0, false, b);
    if (hood.pending()) return out;
    f = D3{b.fx, b.fy, b.fz};
  }
  out.has_force = true;
  out.force = L.gain * f;
  return out;
}

/// What the build writes at a node (node_build.cpp NodeBuilder: the value grid and, for the
/// plane ratio, the closeness grid, whose active mask says "over the surface").
struct NodeValue {
  float v[3];
  float closeness;
  std::uint8_t flags;  ///< kNodeOn, kCloseOn, kCloseSet
};
constexpr std::uint8_t kNodeOn = 1;    ///< value set and active
constexpr std::uint8_t kCloseSet = 2;  ///< closeness value written
constexpr std::uint8_t kCloseOn = 4;   ///< ... and active (over the surface)

/// The value of the node at x (node_build.cpp planeRatio and the build's rules).
template <class Hood>
FP_HD NodeValue nodeValue(Hood& hood, const Law& L, const Rules& R, D3 x) {
  NodeValue out{{0.f, 0.f, 0.f}, 0.f, 0};
  if (R.has_region && (x.x < R.region_lo[0] || x.y < R.region_lo[1] || x.z < R.region_lo[2] ||
                       x.x > R.region_hi[0] || x.y > R.region_hi[1] || x.z > R.region_hi[2]))
    return out;
  const Probe p = probe(hood, L, x, R.reach_mm);
  if (hood.pending() || !p.has_nearest) return out;
  const double lateral_sq = p.nearest_mm * p.nearest_mm - p.height_mm * p.height_mm;
  const bool over_surface = lateral_sq <= R.over_mm * R.over_mm;
  if (p.height_mm < -R.band_in_mm && over_surface) return out;
  if (!R.ratio) {
    if (!p.has_force) return out;
    out.v[0] = float(p.force.x);
    out.v[1] = float(p.force.y);
    out.v[2] = float(p.force.z);
    out.flags = kNodeOn;
    return out;
  }
  // The plane ratio (node_build.cpp planeRatio).
  const double eta = p.height_mm;
  bool over = over_surface && (!p.has_force || fabs(dot(p.force, p.n)) >= kOverCos * norm(p.force));
  const double sign = L.gain < 0.0 ? -1.0 : 1.0;
  double s_mm;
  D3 g;
  if (!p.has_force) {  // shell: no sample within r0
    if (!over) {
      s_mm = dmax(p.nearest_mm, L.r0);
      g = (sign / p.nearest_mm) * (x - p.q);
      // (x - q) / nearest, times sign: as the reference, sign * (x - q) / nearest
    } else if (eta >= 0.0) {
      s_mm = dmax(eta, L.r0);
      g = sign * p.n;
    } else {
      s_mm = -dmax(-eta, L.r0);
      g = D3{0, 0, 0};
    }
  } else {
    D3 f = p.force;
    double lift_mm = 0.0;
    if (over && eta < R.near_mm) {
      lift_mm = R.near_mm - eta;
      const Probe lifted = probe(hood, L, x + lift_mm * p.n, L.r0);
      if (hood.pending()) return out;
      f = lifted.has_force ? lifted.force : D3{0, 0, 0};
    }
    const double e = L.planeHeight(norm(f));
    double plane = L.planeAt(e);
    s_mm = e - lift_mm;
    // The continuation at the node itself, against the node's exact force: where it gives more
    // than kPlaneFit above it, G scaled to the node's own force at the continuation's height, or
    // past kPlaneRescale × the node's own force (voxel_build.cpp planeRatio).
    const double continued = L.planeAt(s_mm) * norm(f), own = plane * norm(p.force);
    if (lift_mm > 0.0 && plane > 0.0 && continued > (1.0 + kPlaneFit) * own) {
      f = p.force;
      if (continued <= kPlaneRescale * own) {
        plane = L.planeAt(s_mm);
      } else {
        s_mm = L.planeHeight(norm(f));
        if (eta < 0.0) s_mm = dmax(-s_mm, eta);  // under, no deeper than the node (voxel_refine)
        plane = L.planeAt(s_mm);
        over = false;
      }
    }
    g = plane > 0.0 ? D3{f.x / plane, f.y / plane, f.z / plane} : D3{0, 0, 0};
  }
  out.closeness = float(L.r0 - s_mm);
  out.flags = kNodeOn | kCloseSet | (over ? kCloseOn : 0);
  out.v[0] = float(g.x);
  out.v[1] = float(g.y);
  out.v[2] = float(g.z);
  return out;
}

/// The constants of a level's node build (voxel_build.cpp NodeBuilder).
struct NodeJob {
  Law law;
  Rules rules;
  double h_mm;
};

/// A leaf's nodes to build: its origin (index space, a multiple of 8) and a bit per node
/// (offset (i·8 + j)·8 + k, OpenVDB's leaf order).
struct LeafTask {
  std::int32_t origin[3];
  std::uint64_t mask[8];
};

}  // namespace fieldpath::field::kernel
