#pragma once
/// Where a line enters the tool (tool frame, mm): the analytic ball, torus and flat end mills with
/// their shank, and mesh tools through their BVH (any line) or bins (vertical ones); the radial
/// floor table of vertical mesh postures. Shared by the CPU reference and the CUDA backend
/// (kernels.h's lineCut calls them).
#include <cfloat>

#include "fieldpath/zbuffer/hd.h"
#include "fieldpath/zbuffer/tool_view.h"

namespace fieldpath::zbuffer {

/// Smallest t with o + t d inside the infinite cylinder x²+y² <= R² (tool frame); returns false if
/// the line misses it. Stable roots (no cancellation), exact for d parallel to the axis.
FIELDPATH_HD bool cylinderInterval(Vec3f o, Vec3f d, float radius, float& lo, float& hi) {
  const float a = d.x * d.x + d.y * d.y;
  const float b = o.x * d.x + o.y * d.y;
  const float c = o.x * o.x + o.y * o.y - radius * radius;
  if (a == 0.f) {
    if (c > 0.f) return false;
    lo = -FLT_MAX;
    hi = FLT_MAX;
    return true;
  }
  const float disc = b * b - a * c;
  if (disc < 0.f) return false;
  const float q = -(b + (b >= 0.f ? sqrtf(disc) : -sqrtf(disc)));
  if (q == 0.f) {
    lo = hi = 0.f;
    return true;
  }
  const float t1 = q / a, t2 = c / q;
  lo = minf(t1, t2);
  hi = maxf(t1, t2);
  return true;
}

/// Entry parameter of the line o + t d into the slab zlo <= z <= zhi ∩ cylinder of `radius`.
FIELDPATH_HD float cappedCylinderEntry(Vec3f o, Vec3f d, float radius, float zlo, float zhi) {
  float lo, hi;
  if (!cylinderInterval(o, d, radius, lo, hi)) return FLT_MAX;
  if (d.z == 0.f) {
    if (o.z < zlo || o.z > zhi) return FLT_MAX;
  } else {
    const float ta = (zlo - o.z) / d.z, tb = (zhi - o.z) / d.z;
    lo = maxf(lo, minf(ta, tb));
    hi = minf(hi, maxf(ta, tb));
  }
  return lo <= hi ? lo : FLT_MAX;
}

/// Entry into the ball of radius r centred at (0, 0, zc): stable quadratic roots.
FIELDPATH_HD float ballEntry(Vec3f o, Vec3f d, float r, float zc) {
  const Vec3f w{o.x, o.y, o.z - zc};
  const float a = dot(d, d), b = dot(w, d), c = dot(w, w) - r * r;
  const float disc = b * b - a * c;
  if (disc < 0.f) return FLT_MAX;
  const float root = sqrtf(disc);
  // lower root: (-b - root)/a, computed as c/(-b + root) when b < 0 (no cancellation)
  if (b >= 0.f) return (-b - root) / a;
  const float den = -b + root;
  return den > 0.f ? c / den : 0.f;
}

/// Entry into the convex corner piece of a torus end mill: the points within r of the disk of
/// radius rho in the plane z = r. Newton's method on the convex distance function, started at the
/// entry of the bounding ball: it approaches the root monotonically from below.
FIELDPATH_HD float torusCornerEntry(Vec3f o, Vec3f d, float rho, float r) {
  float t = ballEntry(o, d, rho + r, r);
  if (t == FLT_MAX) return FLT_MAX;
  const float tol = 1e-7f * (rho + r);
  for (int it = 0; it < 40; ++it) {
    const Vec3f q = o + t * d;
    const float rq = sqrtf(q.x * q.x + q.y * q.y);
    const float scale = rq > rho ? rho / rq : 1.f;
    const Vec3f diff{q.x - scale * q.x, q.y - scale * q.y, q.z - r};
    const float dist = sqrtf(dot(diff, diff));
    const float g = dist - r;
    if (g <= tol) return t;
    const float slope = dist > 0.f ? dot(diff, d) / dist : 0.f;
    if (slope >= 0.f) return FLT_MAX;  // past the closest approach without reaching the piece
    const float step = g / slope;
    t -= step;
    if (-step <= tol) return t;
  }
  return t;
}

/// Whether p lies within r of the disk of radius rho in the plane z = r (the torus corner piece;
/// rho = 0: the ball of radius r centred at (0, 0, r)).
FIELDPATH_HD bool inCornerPiece(Vec3f p, float rho, float r) {
  const float rq = sqrtf(p.x * p.x + p.y * p.y);
  const float out = maxf(rq - rho, 0.f), dz = p.z - r;
  return out * out + dz * dz <= r * r;
}

/// The entry t of the line into the corner piece (convex, entered at t_entry) cut by the tool's
/// flat top z <= top: where it enters above the top, it enters the cut piece where it crosses
/// the top plane going down, if that point is in the piece, else never. A ball or torus shorter
/// than its end's height (L < 2r: a necked tool written with L = R, its neck in the holder) has
/// no material above L: the whole sphere cut there (322 of 11 092 lines 0.9 mm too low at 25°
/// of tilt, a helper's).
FIELDPATH_HD float cutAtTop(float t_entry, Vec3f o, Vec3f d, float top, float rho, float r) {
  if (t_entry == FLT_MAX || o.z + t_entry * d.z <= top) return t_entry;
  if (!(d.z < 0.f)) return FLT_MAX;  // level or rising: above the top from the entry on
  const float t_top = (top - o.z) / d.z;
  Vec3f p = o + t_top * d;
  p.z = top;
  return inCornerPiece(p, rho, r) ? t_top : FLT_MAX;
}

/// Entry parameter of the line o + t d (tool frame) into an analytic tool, FLT_MAX if it misses.
FIELDPATH_HD float analyticEntry(const ToolView& tool, Vec3f o, Vec3f d) {
  const float big_r = tool.radius_mm, r = tool.corner_radius_mm;
  float t = cappedCylinderEntry(o, d, big_r, r, tool.length_mm);
  if (r > 0.f) {
    const float rho = big_r - r;
    float corner = rho > 0.f ? torusCornerEntry(o, d, rho, r) : ballEntry(o, d, r, r);
    if (tool.length_mm < 2.f * r) corner = cutAtTop(corner, o, d, tool.length_mm, rho, r);
    t = minf(t, corner);
  }
  return t;
}

/// Slab test of a (padded) box against the ray; returns the entry parameter or FLT_MAX.
FIELDPATH_HD float boxEntry(const BvhNode& n, Vec3f o, Vec3f inv, float t_max) {
  const float tx0 = (n.lo[0] - o.x) * inv.x, tx1 = (n.hi[0] - o.x) * inv.x;
  const float ty0 = (n.lo[1] - o.y) * inv.y, ty1 = (n.hi[1] - o.y) * inv.y;
  const float tz0 = (n.lo[2] - o.z) * inv.z, tz1 = (n.hi[2] - o.z) * inv.z;
  const float tnear = maxf(maxf(minf(tx0, tx1), minf(ty0, ty1)), minf(tz0, tz1));
  const float tfar = minf(minf(maxf(tx0, tx1), maxf(ty0, ty1)), maxf(tz0, tz1));
  return (tnear <= tfar && tnear <= t_max) ? tnear : FLT_MAX;
}

/// Watertight ray/triangle test (Woop et al. 2013), only triangles the upward world line enters
/// (facing down after placement). Edge values of a shared edge are exact negatives in both
/// triangles, and zero counts as inside, so a line through a shared edge or vertex is never missed.
FIELDPATH_HD float triangleEntry(const PreparedPosture& pp, const float* v, Vec3f o) {
  const Vec3f a{v[0] - o.x, v[1] - o.y, v[2] - o.z};
  const Vec3f b{v[3] - o.x, v[4] - o.y, v[5] - o.z};
  const Vec3f c{v[6] - o.x, v[7] - o.y, v[8] - o.z};
  const float az = comp(a, pp.kz), bz = comp(b, pp.kz), cz = comp(c, pp.kz);
  const float ax = comp(a, pp.kx) - pp.sx * az, ay = comp(a, pp.ky) - pp.sy * az;
  const float bx = comp(b, pp.kx) - pp.sx * bz, by = comp(b, pp.ky) - pp.sy * bz;
  const float cx = comp(c, pp.kx) - pp.sx * cz, cy = comp(c, pp.ky) - pp.sy * cz;
  const float u = cx * by - cy * bx;
  const float w_v = ax * cy - ay * cx;
  const float w = bx * ay - by * ax;
  if (u < 0.f || w_v < 0.f || w < 0.f) return FLT_MAX;
  const float det = u + w_v + w;
  if (det == 0.f) return FLT_MAX;
  const float t_num = u * (pp.sz * az) + w_v * (pp.sz * bz) + w * (pp.sz * cz);
  return t_num / det;
}

/// Lowest entry of the line o + t dir into a mesh tool, below t_max, through the BVH (tool frame).
FIELDPATH_HD float meshEntry(const ToolView& tool, const PreparedPosture& pp, Vec3f o,
                             float t_max) {
  int stack[64];
  int top = 0;
  float best = FLT_MAX;
  float limit = t_max;
  int node = 0;
  if (boxEntry(tool.bvh_nodes[0], o, pp.inv_dir, limit) == FLT_MAX) return FLT_MAX;
  for (;;) {
    const BvhNode& n = tool.bvh_nodes[node];
    if (n.count > 0) {
      for (int t = n.first; t < n.first + n.count; ++t) {
        const float th = triangleEntry(pp, tool.bvh_triangles + 9 * t, o);
        if (th < best) {
          best = th;
          limit = minf(limit, th);
        }
      }
    } else {
      const int left = node + 1, right = n.first;
      const float tl = boxEntry(tool.bvh_nodes[left], o, pp.inv_dir, limit);
      const float tr = boxEntry(tool.bvh_nodes[right], o, pp.inv_dir, limit);
      if (tl != FLT_MAX && tr != FLT_MAX) {
        const bool left_first = tl <= tr;
        stack[top++] = left_first ? right : left;
        node = left_first ? left : right;
        continue;
      }
      if (tl != FLT_MAX) {
        node = left;
        continue;
      }
      if (tr != FLT_MAX) {
        node = right;
        continue;
      }
    }
    // pop, skipping boxes that can no longer hold a lower hit
    bool found = false;
    while (top > 0) {
      node = stack[--top];
      if (boxEntry(tool.bvh_nodes[node], o, pp.inv_dir, limit) != FLT_MAX) {
        found = true;
        break;
      }
    }
    if (!found) return best;
  }
}

/// Lowest entry of a vertical line (tool frame origin o, direction +z) into a mesh tool: only the
/// triangles of o's bin, tested with the same watertight test as the BVH. Every triangle such a
/// line can enter faces down and has o inside its padded xy box, hence sits in o's bin (the bin
/// index is the same monotone float expression as at binning), so the minimum is the BVH's, bit
/// for bit, at a handful of triangle tests instead of a tree walk.
FIELDPATH_HD float binnedEntry(const ToolView& tool, const PreparedPosture& pp, Vec3f o) {
  const float fx = (o.x - tool.bin_x0_mm) * tool.bin_inv_mm;
  const float fy = (o.y - tool.bin_y0_mm) * tool.bin_inv_mm;
  // outside every padded triangle box (a margin of one bin keeps the clamped edge bins exact)
  if (!(fx > -1.f && fy > -1.f && fx < tool.bins + 1.f && fy < tool.bins + 1.f)) return FLT_MAX;
  const int cx = clampi(static_cast<int>(fx), 0, tool.bins - 1);
  const int cy = clampi(static_cast<int>(fy), 0, tool.bins - 1);
  const int cell = cy * tool.bins + cx;
  float best = FLT_MAX;
  for (int k = tool.bin_start[cell]; k < tool.bin_start[cell + 1]; ++k)
    best = minf(best, triangleEntry(pp, tool.bvh_triangles + 9 * tool.bin_items[k], o));
  return best;
}

/// The radial floor table (vertical mesh postures) at squared distance rho2_mm2 from the axis: a
/// tool-frame z below which no down-facing triangle lies; FLT_MAX beyond the outermost triangle.
/// The table is non-decreasing in the radius (each floor lowered to the least beyond it), so the
/// floor at a smaller radius bounds every larger one: lineFloorNear, rectFloor and groupFloor
/// rely on it.
FIELDPATH_HD float radialFloor(const ToolView& tool, float rho2_mm2) {
  if (!(rho2_mm2 <= tool.radial_max_mm2)) return FLT_MAX;
  const int b = static_cast<int>(rho2_mm2 * tool.radial_inv_mm2);
  return tool.radial_floor_mm[b < tool.radial_bins ? b : tool.radial_bins - 1];
}

}  // namespace fieldpath::zbuffer
