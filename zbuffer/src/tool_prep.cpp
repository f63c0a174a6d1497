/// Preparation of a tool for the kernels (detail::prepareTool): the BVH of a mesh tool in leaf
/// order, its down-facing triangles binned for vertical lines, the radial floors of vertical lines,
/// and the capsule that holds any tool. Done once per tool (simulator.cpp caches it).
#include <algorithm>
#include <atomic>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <vector>

#include "fieldpath/common/errors.h"
#include "fieldpath/zbuffer/engine.h"

namespace fieldpath::zbuffer::detail {

using common::InputError;

namespace {

struct Box {
  float lo[3] = {FLT_MAX, FLT_MAX, FLT_MAX};
  float hi[3] = {-FLT_MAX, -FLT_MAX, -FLT_MAX};
  void add(Vec3f p) {
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], comp(p, k));
      hi[k] = std::max(hi[k], comp(p, k));
    }
  }
};

/// Median-split BVH over triangle centroids, leaves of <= 4 triangles, depth-first layout.
struct BvhBuilder {
  const ToolMesh& mesh;
  std::vector<std::uint32_t> order;
  std::vector<Vec3f> centroid;
  std::vector<BvhNode> nodes;
  float pad;

  int build(std::size_t begin, std::size_t end) {
    Box box, cbox;
    for (std::size_t i = begin; i < end; ++i) {
      for (auto v : mesh.triangles[order[i]]) box.add(mesh.vertices[v]);
      cbox.add(centroid[order[i]]);
    }
    const int index = static_cast<int>(nodes.size());
    BvhNode node{};
    for (int k = 0; k < 3; ++k) {
      node.lo[k] = box.lo[k] - pad;
      node.hi[k] = box.hi[k] + pad;
    }
    nodes.push_back(node);
    if (end - begin <= 4) {
      nodes[index].first = static_cast<std::int32_t>(begin);
      nodes[index].count = static_cast<std::int32_t>(end - begin);
      return index;
    }
    int axis = 0;
    for (int k = 1; k < 3; ++k)
      if (cbox.hi[k] - cbox.lo[k] > cbox.hi[axis] - cbox.lo[axis]) axis = k;
    const std::size_t mid = (begin + end) / 2;
    std::nth_element(order.begin() + begin, order.begin() + mid, order.begin() + end,
                     [&](std::uint32_t a, std::uint32_t b) {
                       return comp(centroid[a], axis) < comp(centroid[b], axis);
                     });
    build(begin, mid);
    const int right = build(mid, end);
    nodes[index].first = right;
    nodes[index].count = 0;
    return index;
  }
};

/// Lowest z of the plane of triangle p (9 floats, tool frame) over the part of the triangle whose
/// distance from the axis lies in [ra, rb] (mm), or +inf where that part is empty. Exact in double:
/// a linear function's minimum over that region is on its boundary, at a vertex in the annulus, a
/// crossing of an edge with a circle, or the point of a circle arc inside the triangle where the
/// function is least along the circle (opposite the gradient).
double annulusPlaneMin(const float* p, double gx, double gy, double ra, double rb) {
  const double x0 = p[0], y0 = p[1], z0 = p[2];
  const auto plane = [&](double x, double y) { return z0 + gx * (x - x0) + gy * (y - y0); };
  double best = HUGE_VAL;
  for (int k = 0; k < 3; ++k) {
    const double ax = p[3 * k], ay = p[3 * k + 1], r = std::hypot(ax, ay);
    if (r >= ra && r <= rb) best = std::min(best, double(p[3 * k + 2]));
    const double ex = p[3 * ((k + 1) % 3)] - ax, ey = p[3 * ((k + 1) % 3) + 1] - ay;
    const double a = ex * ex + ey * ey, b = ax * ex + ay * ey, c0 = ax * ax + ay * ay;
    if (a == 0) continue;
    for (double rc : {ra, rb}) {  // |a + s e| = rc, s in [0, 1]
      const double disc = b * b - a * (c0 - rc * rc);
      if (rc <= 0 || disc < 0) continue;
      for (double s : {(-b - std::sqrt(disc)) / a, (-b + std::sqrt(disc)) / a})
        if (s >= 0 && s <= 1) best = std::min(best, plane(ax + s * ex, ay + s * ey));
    }
  }
  const double gn = std::hypot(gx, gy);
  for (double rc : {ra, rb}) {
    if (rc <= 0) continue;
    // the circle's point of least z (any point of it where the plane is flat)
    const double qx = gn > 0 ? -rc * gx / gn : rc, qy = gn > 0 ? -rc * gy / gn : 0.0;
    double side[3];
    for (int k = 0; k < 3; ++k) {
      const int n = (k + 1) % 3;
      side[k] = (double(p[3 * n]) - p[3 * k]) * (qy - p[3 * k + 1]) -
                (double(p[3 * n + 1]) - p[3 * k + 1]) * (qx - p[3 * k]);
    }
    const double tol = 1e-9 * (std::abs(side[0]) + std::abs(side[1]) + std::abs(side[2]));
    const bool inside = (side[0] >= -tol && side[1] >= -tol && side[2] >= -tol) ||
                        (side[0] <= tol && side[1] <= tol && side[2] <= tol);
    if (inside) best = std::min(best, plane(qx, qy));
  }
  return best;
}

/// Radial floors of the down-facing triangles `down`: for each annulus of the table (even in ρ²),
/// a z below which no vertical line at that distance from the axis can enter the tool. Each
/// triangle lowers the floor of every annulus its projection meets by the exact least height of
/// its plane over that part of it, widened by one annulus each side (the rounding of the line's
/// float ρ²) and by the pad (lines a rounding outside the triangle that the watertight test still
/// takes), and no higher than its lowest vertex; less a margin. Tight to the annulus width times
/// the slope (the lowest vertex of the triangle was a floor loose by the triangle's size times the
/// slope: ~60 µm at 1.4 mm from the axis of the 12482-triangle ball of radius 5; far more than the
/// scallop between postures, so that lines were cut that could not be lowered).
void radialFloors(ToolData& data, const std::vector<std::int32_t>& down, float pad) {
  ToolView& v = data.view;
  float rmax = 0.f;
  for (auto t : down)
    for (int k = 0; k < 3; ++k) {
      const float* p = data.bvh_triangles.data() + 9 * t + 3 * k;
      rmax = std::max(rmax, std::sqrt(p[0] * p[0] + p[1] * p[1]));
    }
  const int rbins = 4096;
  const float radial_max_mm = rmax * (1.f + 1e-5f) + pad;
  v.radial_max_mm2 = radial_max_mm * radial_max_mm;
  v.radial_inv_mm2 = rbins / v.radial_max_mm2;
  const double bin_mm2 = 1.0 / v.radial_inv_mm2;
  data.radial_floor.assign(rbins, FLT_MAX);
#pragma omp parallel
  {
    std::vector<float> floor(rbins, FLT_MAX);
#pragma omp for schedule(dynamic, 64)
    for (std::size_t i = 0; i < down.size(); ++i) {
      const float* p = data.bvh_triangles.data() + 9 * down[i];
      double rlo = 1e300, rhi = 0;
      const float zmin = std::min({p[2], p[5], p[8]});
      for (int k = 0; k < 3; ++k) {
        const double ax = p[3 * k], ay = p[3 * k + 1], bx = p[3 * ((k + 1) % 3)],
                     by = p[3 * ((k + 1) % 3) + 1];
        const double ex = bx - ax, ey = by - ay, len2 = ex * ex + ey * ey;
        const double u = len2 > 0 ? std::clamp(-(ax * ex + ay * ey) / len2, 0.0, 1.0) : 0.0;
        rlo = std::min(rlo, std::hypot(ax + u * ex, ay + u * ey));
        rhi = std::max(rhi, std::hypot(ax, ay));
      }
      // origin inside the projection: the annulus starts at 0
      const auto side = [&](int k) {
        const int n = (k + 1) % 3;
        return (p[3 * n] - p[3 * k]) * (0.0 - p[3 * k + 1]) -
               (p[3 * n + 1] - p[3 * k + 1]) * (0.0 - p[3 * k]);
      };
      const double s0 = side(0), s1 = side(1), s2 = side(2);
      if ((s0 >= 0 && s1 >= 0 && s2 >= 0) || (s0 <= 0 && s1 <= 0 && s2 <= 0)) rlo = 0;
      const double lo = std::max(0.0, rlo - pad), hi = rhi + pad;
      const int b0 = std::max(0, static_cast<int>(lo * lo * v.radial_inv_mm2) - 1);
      const int b1 = std::min(rbins - 1, static_cast<int>(hi * hi * v.radial_inv_mm2) + 1);
      // the plane z = z0 + g·(q - p0); a nearly vertical triangle (|g| huge or undefined) keeps
      // its lowest vertex as the floor of every annulus it meets
      const double e1x = p[3] - p[0], e1y = p[4] - p[1], e1z = p[5] - p[2];
      const double e2x = p[6] - p[0], e2y = p[7] - p[1], e2z = p[8] - p[2];
      const double det = e1x * e2y - e1y * e2x;
      const double gx = det != 0 ? (e1z * e2y - e2z * e1y) / det : HUGE_VAL;
      const double gy = det != 0 ? (e1x * e2z - e2x * e1z) / det : HUGE_VAL;
      const double slope = std::hypot(gx, gy);
      const double margin = pad * (1.0 + (std::isfinite(slope) ? slope : 0.0));
      for (int b = b0; b <= b1; ++b) {
        double z = zmin;
        if (slope < 1e3) {
          const double ra = std::sqrt(std::max(0.0, (b - 1) * bin_mm2)) - pad,
                       rb = std::sqrt((b + 2) * bin_mm2) + pad;
          const double least = annulusPlaneMin(p, gx, gy, std::max(0.0, ra), rb);
          if (least == HUGE_VAL) continue;  // the triangle does not reach this annulus
          z = std::max(double(zmin), least) - margin;
        }
        floor[b] = std::min(floor[b], static_cast<float>(z));
      }
    }
#pragma omp critical
    for (int b = 0; b < rbins; ++b) data.radial_floor[b] = std::min(data.radial_floor[b], floor[b]);
  }
  // Made non-decreasing in the radius (each floor lowered to the smallest beyond it, still a
  // floor), so that the floor at a rectangle's smallest radius bounds all its lines (rectFloor).
  for (int b = rbins - 2; b >= 0; --b)
    data.radial_floor[b] = std::min(data.radial_floor[b], data.radial_floor[b + 1]);
  v.radial_bins = rbins;
}

/// Bins the triangles that face down in the tool frame (candidates for vertical lines) on a
/// uniform grid over their xy extent; each triangle goes to every bin its padded box overlaps.
void binDownFacing(ToolData& data, float pad) {
  ToolView& v = data.view;
  const std::size_t count = data.bvh_triangles.size() / 9;
  std::vector<std::int32_t> down;
  Box box;
  for (std::size_t t = 0; t < count; ++t) {
    const float* p = data.bvh_triangles.data() + 9 * t;
    const float area2 = (p[3] - p[0]) * (p[7] - p[1]) - (p[4] - p[1]) * (p[6] - p[0]);
    const float scale = std::max({std::abs(p[3] - p[0]), std::abs(p[6] - p[0]),
                                  std::abs(p[4] - p[1]), std::abs(p[7] - p[1])});
    if (area2 > 1e-4f * scale * scale) continue;  // facing up (nearly vertical ones are kept)
    down.push_back(static_cast<std::int32_t>(t));
    for (int k = 0; k < 3; ++k)
      box.add({p[3 * k] - pad, p[3 * k + 1] - pad, 0.f}),
          box.add({p[3 * k] + pad, p[3 * k + 1] + pad, 0.f});
  }
  if (down.empty()) return;
  // 4·√(down-facing triangles) bins per side: a revolved tool's triangles crowd at the axis (a fan
  // of `around` triangles meets at the tip), so coarser bins (√(n/2) per side before) left dozens
  // of triangles in the central ones; CPU, seed 001 spiral: 1776 → 521 ms, random 730 → 342 ms.
  const int bins = std::clamp(static_cast<int>(std::ceil(std::sqrt(down.size() * 16.0))), 1, 2048);
  const float side = std::max(box.hi[0] - box.lo[0], box.hi[1] - box.lo[1]) * (1.f + 1e-6f);
  v.bins = bins;
  v.bin_x0_mm = box.lo[0];
  v.bin_y0_mm = box.lo[1];
  v.bin_inv_mm = bins / side;
  const auto cellOf = [&](float x, float x0) {
    return std::clamp(static_cast<int>((x - x0) * v.bin_inv_mm), 0, bins - 1);
  };
  // Two passes (count, then fill after a prefix sum): no per-cell vectors for ~10^5 cells.
  const auto forEachCell = [&](auto visit) {
    for (auto t : down) {
      const float* p = data.bvh_triangles.data() + 9 * t;
      const float xlo = std::min({p[0], p[3], p[6]}) - pad,
                  xhi = std::max({p[0], p[3], p[6]}) + pad;
      const float ylo = std::min({p[1], p[4], p[7]}) - pad,
                  yhi = std::max({p[1], p[4], p[7]}) + pad;
      // Row by row: the cells the triangle's part within the row's band (grown by the pad and a
      // tenth of a cell for the rounding of the bin index) can touch, not its whole bounding box.
      const double cell_mm = 1.0 / v.bin_inv_mm, grow = pad + 0.1 * cell_mm;
      for (int cy = cellOf(ylo, v.bin_y0_mm); cy <= cellOf(yhi, v.bin_y0_mm); ++cy) {
        const double y0 = v.bin_y0_mm + cy * cell_mm - grow,
                     y1 = v.bin_y0_mm + (cy + 1) * cell_mm + grow;
        double xmin = 1e300, xmax = -1e300;
        for (int k = 0; k < 3; ++k) {
          const double ax = p[3 * k], ay = p[3 * k + 1], bx = p[3 * ((k + 1) % 3)],
                       by = p[3 * ((k + 1) % 3) + 1];
          if (ay >= y0 && ay <= y1) xmin = std::min(xmin, ax), xmax = std::max(xmax, ax);
          for (double yc : {y0, y1})  // the edge's crossings of the band's borders
            if ((ay - yc) * (by - yc) < 0) {
              const double xc = ax + (bx - ax) * (yc - ay) / (by - ay);
              xmin = std::min(xmin, xc);
              xmax = std::max(xmax, xc);
            }
        }
        if (xmin > xmax) continue;
        for (int cx = cellOf(float(xmin - grow), v.bin_x0_mm);
             cx <= cellOf(float(xmax + grow), v.bin_x0_mm); ++cx)
          visit(std::size_t(cy) * bins + cx, t);
      }
    }
  };
  data.bin_start.assign(std::size_t(bins) * bins + 1, 0);
  forEachCell([&](std::size_t cell, std::int32_t) { ++data.bin_start[cell + 1]; });
  for (std::size_t c = 1; c < data.bin_start.size(); ++c)
    data.bin_start[c] += data.bin_start[c - 1];
  data.bin_items.resize(static_cast<std::size_t>(data.bin_start.back()));
  std::vector<std::int32_t> fill(data.bin_start.begin(), data.bin_start.end() - 1);
  forEachCell([&](std::size_t cell, std::int32_t t) { data.bin_items[fill[cell]++] = t; });

  radialFloors(data, down, pad);
}

}  // namespace

void ToolData::pointViewAtVectors() {
  view.bvh_nodes = bvh_nodes.data();
  view.bvh_triangles = bvh_triangles.data();
  view.vertices = vertices.data();
  view.indices = indices.data();
  view.bin_start = bin_start.data();
  view.bin_items = bin_items.data();
  view.radial_floor_mm = radial_floor.data();
}

ToolData prepareTool(const Tool& tool) {
  ToolData data;
  ToolView& v = data.view;
  v.kind = tool.kind;
  v.radius_mm = tool.radius_mm;
  v.corner_radius_mm = tool.corner_radius_mm;
  v.length_mm = tool.length_mm;
  static std::atomic<std::uint64_t> next_id{1};
  data.id = next_id++;
  if (tool.kind != ToolKind::Mesh) {
    v.hull_radius_mm = tool.radius_mm;
    v.hull_zmin_mm = 0.f;
    v.hull_zmax_mm = tool.length_mm;
    // The capsule of radius R about the axis from z = r up: the corner piece's points are within
    // R of (0, 0, r) ((R-r)² + 2(R-r) r cos θ + r² <= R²), the shank's within R of the axis.
    const float pad = 1e-6f * (tool.radius_mm + tool.length_mm);
    v.cap_radius_mm = tool.radius_mm * (1.f + 1e-6f) + pad;
    v.cap_z0_mm = tool.corner_radius_mm - pad;
    v.cap_z1_mm = tool.length_mm + pad;
    return data;
  }
  const ToolMesh& mesh = tool.mesh;
  if (mesh.triangles.empty()) throw InputError("tool: mesh has no triangles");
  Box all;
  float hull_r = 0.f;
  for (const auto& p : mesh.vertices) {
    all.add(p);
    hull_r = std::max(hull_r, std::sqrt(p.x * p.x + p.y * p.y));
  }
  const float size =
      std::max({all.hi[0] - all.lo[0], all.hi[1] - all.lo[1], all.hi[2] - all.lo[2], 1e-3f});
  v.hull_radius_mm = hull_r * (1.f + 1e-6f) + 1e-6f * size;
  v.hull_zmin_mm = all.lo[2];
  v.hull_zmax_mm = all.hi[2];
  // Capsule: radius the hull's; its segment starts as low as every vertex allows (vertex within R
  // of (0, 0, c) or above it: c <= z + sqrt(R² - ρ²)). It holds every vertex, hence (convex) the
  // whole mesh.
  double cap_z0 = all.hi[2];
  const double cap_r = v.hull_radius_mm;
  for (const auto& p : mesh.vertices) {
    const double rho2 = double(p.x) * p.x + double(p.y) * p.y;
    cap_z0 = std::min(cap_z0, p.z + std::sqrt(std::max(0.0, cap_r * cap_r - rho2)));
  }
  v.cap_radius_mm = v.hull_radius_mm;
  v.cap_z0_mm = static_cast<float>(cap_z0 - 1e-6 * size);
  v.cap_z1_mm = all.hi[2] + 1e-6f * size;

  BvhBuilder b{mesh, {}, {}, {}, 1e-5f * size};
  b.order.resize(mesh.triangles.size());
  std::iota(b.order.begin(), b.order.end(), 0u);
  b.centroid.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles) {
    const Vec3f c = mesh.vertices[t[0]] + mesh.vertices[t[1]] + mesh.vertices[t[2]];
    b.centroid.push_back((1.f / 3.f) * c);
  }
  b.build(0, mesh.triangles.size());
  data.bvh_nodes = std::move(b.nodes);
  data.bvh_triangles.reserve(9 * mesh.triangles.size());
  for (auto t : b.order)
    for (auto vi : mesh.triangles[t]) {
      const Vec3f p = mesh.vertices[vi];
      data.bvh_triangles.insert(data.bvh_triangles.end(), {p.x, p.y, p.z});
    }
  data.vertices = mesh.vertices;
  for (const auto& t : mesh.triangles) data.indices.insert(data.indices.end(), t.begin(), t.end());
  v.triangle_count = static_cast<std::int32_t>(mesh.triangles.size());
  binDownFacing(data, 1e-5f * size);
  data.pointViewAtVectors();
  return data;
}

}  // namespace fieldpath::zbuffer::detail
