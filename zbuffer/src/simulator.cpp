#include "fieldpath/zbuffer/engine.h"
#include "fieldpath/zbuffer/simulator.h"

#include <unistd.h>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <numeric>
#include <sstream>

#include "fieldpath/common/errors.h"

namespace fieldpath::zbuffer {

using common::InputError;

Grid Grid::fromRegion(double x0_mm, double y0_mm, double x1_mm, double y1_mm, int nx, int ny) {
  if (!std::isfinite(x0_mm) || !std::isfinite(y0_mm) || !std::isfinite(x1_mm) ||
      !std::isfinite(y1_mm))
    throw InputError("region: non-finite coordinate");
  if (!(x1_mm > x0_mm) || !(y1_mm > y0_mm))
    throw InputError("region: zero or negative area (need x0 < x1 and y0 < y1)");
  if (nx <= 0 || ny <= 0)
    throw InputError("grid: " + std::to_string(nx) + "x" + std::to_string(ny) +
                     " has no lines (need >= 1 in each direction)");
  Grid g;
  g.x0_mm = x0_mm;
  g.y0_mm = y0_mm;
  g.nx = nx;
  g.ny = ny;
  g.dx_mm = (x1_mm - x0_mm) / nx;
  g.dy_mm = (y1_mm - y0_mm) / ny;
  return g;
}

namespace {
void requireDims(bool ok, const char* what) {
  if (!ok) throw InputError(std::string("tool: ") + what);
}
}  // namespace

Tool Tool::ball(double radius_mm, double length_mm) {
  requireDims(std::isfinite(radius_mm) && radius_mm > 0, "ball radius must be finite and > 0");
  requireDims(std::isfinite(length_mm) && length_mm >= radius_mm,
              "length must be >= the ball radius");
  return Tool{ToolKind::Ball, float(radius_mm), float(radius_mm), float(length_mm), {}};
}
Tool Tool::torus(double radius_mm, double corner_radius_mm, double length_mm) {
  requireDims(std::isfinite(radius_mm) && radius_mm > 0, "torus radius must be finite and > 0");
  requireDims(
      std::isfinite(corner_radius_mm) && corner_radius_mm > 0 && corner_radius_mm <= radius_mm,
      "torus corner radius must be in (0, R]");
  requireDims(std::isfinite(length_mm) && length_mm >= corner_radius_mm,
              "length must be >= the corner radius");
  return Tool{ToolKind::Torus, float(radius_mm), float(corner_radius_mm), float(length_mm), {}};
}
Tool Tool::flat(double radius_mm, double length_mm) {
  requireDims(std::isfinite(radius_mm) && radius_mm > 0, "flat radius must be finite and > 0");
  requireDims(std::isfinite(length_mm) && length_mm > 0, "length must be > 0");
  return Tool{ToolKind::Flat, float(radius_mm), 0.f, float(length_mm), {}};
}
Tool Tool::fromMesh(ToolMesh mesh) {
  requireDims(!mesh.triangles.empty(), "mesh has no triangles");
  for (const auto& v : mesh.vertices)
    requireDims(std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z),
                "mesh has a non-finite vertex");
  for (const auto& t : mesh.triangles)
    for (auto i : t) requireDims(i < mesh.vertices.size(), "mesh triangle index out of range");
  Tool tool;
  tool.kind = ToolKind::Mesh;
  tool.mesh = std::move(mesh);
  return tool;
}

const char* backendName(Backend backend) {
  switch (backend) {
    case Backend::Auto:
      return "auto";
    case Backend::Cpu:
      return "cpu";
    case Backend::Cuda:
      return "cuda";
  }
  return "?";
}

Backend backendFromName(const std::string& name, const std::string& key) {
  for (Backend b : {Backend::Auto, Backend::Cpu, Backend::Cuda})
    if (name == backendName(b)) return b;
  throw InputError(key + " '" + name + "': expected auto, cpu or cuda");
}

namespace detail {

GridView makeGridView(const Grid& grid, int tile_shift) {
  GridView g;
  g.x0_mm = grid.x0_mm;
  g.y0_mm = grid.y0_mm;
  g.dx_mm = grid.dx_mm;
  g.dy_mm = grid.dy_mm;
  g.nx = grid.nx;
  g.ny = grid.ny;
  g.tile_shift = tile_shift;
  g.tiles_x = (grid.nx + (1 << tile_shift) - 1) >> tile_shift;
  g.tiles_y = (grid.ny + (1 << tile_shift) - 1) >> tile_shift;
  return g;
}

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

}  // namespace detail

std::size_t estimateHostBytes(const Grid& grid) {
  // heights + initial copy (float each), culling tiles, and the outputs (STL/PNG are decimated).
  const double lines = double(grid.nx) * double(grid.ny);
  return static_cast<std::size_t>(std::min(lines * 12.0 + 64.0 * 1024 * 1024, 1e19));
}

void checkGridFits(const Grid& grid, std::size_t available_bytes) {
  if (available_bytes == 0) {
    const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
    available_bytes =
        pages > 0 && page > 0 ? std::size_t(pages) * std::size_t(page) / 2 : (std::size_t{4} << 30);
  }
  const std::size_t need = estimateHostBytes(grid);
  if (need > available_bytes || grid.lineCount() > (std::size_t{1} << 31)) {
    std::ostringstream os;
    os << "grid " << grid.nx << "x" << grid.ny << " is too large: it needs about "
       << need / (1 << 20) << " MiB of memory, " << available_bytes / (1 << 20)
       << " MiB available (and at most 2^31 lines)";
    throw InputError(os.str());
  }
}

std::vector<float> stockFromPart(const Grid& grid, std::span<const Vec3f> vertices,
                                 std::span<const std::array<std::uint32_t, 3>> triangles) {
  if (triangles.empty()) throw InputError("part: mesh has no triangles");
  float zmin = FLT_MAX;
  for (const auto& v : vertices) zmin = std::min(zmin, v.z);
  const GridView g = detail::makeGridView(grid);
  std::vector<float> top(grid.lineCount(), -FLT_MAX);
  for (const auto& t : triangles) {
    if (t[0] >= vertices.size() || t[1] >= vertices.size() || t[2] >= vertices.size())
      throw InputError("part: triangle index out of range");
    rasterTriangle(g, vertices[t[0]], vertices[t[1]], vertices[t[2]], 1.f,
                   [&](int ix, int iy, float z) {
                     float& h = top[std::size_t(iy) * grid.nx + ix];
                     h = std::max(h, z);
                   });
  }
  for (auto& h : top)
    if (h == -FLT_MAX) h = zmin;
  return top;
}

namespace {

bool sameTool(const Tool& a, const Tool& b) {
  const auto bytesEqual = [](const auto& x, const auto& y) {
    return x.size() == y.size() &&
           (x.empty() || std::memcmp(x.data(), y.data(), x.size() * sizeof(x[0])) == 0);
  };
  return a.kind == b.kind && a.radius_mm == b.radius_mm &&
         a.corner_radius_mm == b.corner_radius_mm && a.length_mm == b.length_mm &&
         bytesEqual(a.mesh.vertices, b.mesh.vertices) &&
         bytesEqual(a.mesh.triangles, b.mesh.triangles);
}

/// prepareTool with a one-entry cache: a mesh tool's BVH, bins and radial floors (several ms for
/// 25 000 triangles) are built once for a run of simulations with the same tool (compared bit
/// for bit, a fraction of a millisecond).
std::shared_ptr<const detail::ToolData> preparedTool(const Tool& tool) {
  static std::mutex mutex;
  static Tool cached_tool;
  static std::shared_ptr<const detail::ToolData> cached;
  {
    std::lock_guard lock(mutex);
    if (cached && sameTool(cached_tool, tool)) return cached;
  }
  auto data = std::make_shared<detail::ToolData>(detail::prepareTool(tool));
  data->pointViewAtVectors();
  std::lock_guard lock(mutex);
  cached_tool = tool;
  cached = data;
  return data;
}

/// Runs the blocks that `next` hands out (an empty span ends), without copying them;
/// `expected_postures` (0: unknown) scales the progress.
template <class NextBlock>
SimulationResult run(const SimulationRequest& request, std::size_t expected_postures,
                     NextBlock next) {
  const Grid& grid = request.grid;
  if (grid.nx <= 0 || grid.ny <= 0) throw InputError("grid: no lines");
  checkGridFits(grid);
  if (!request.initial_heights_mm.empty() && request.initial_heights_mm.size() != grid.lineCount())
    throw InputError("initial heights: size does not match the grid");
  if (request.engine == Engine::Coarse && request.tool.kind != ToolKind::Mesh)
    throw InputError("the coarse engine needs a mesh tool");
  Backend backend = request.backend;
  if (backend == Backend::Auto) backend = cudaAvailable() ? Backend::Cuda : Backend::Cpu;
  if (backend == Backend::Cuda && !cudaAvailable())
    throw InputError("backend cuda: no CUDA device available (built without CUDA or no GPU)");

  const auto entered = std::chrono::steady_clock::now();
  const int shift = request.tuning.tile_shift;
  if (shift < 1 || shift > 8) throw InputError("tuning: tile_shift must be in [1, 8]");
  if (request.tuning.prepass_stride < 0)
    throw InputError("tuning: prepass_stride must be 0 (off) or positive");
  if (request.tuning.group_postures != 0 && request.tuning.group_postures != 8 &&
      request.tuning.group_postures != 16 && request.tuning.group_postures != 32)
    throw InputError("tuning: group_postures must be 0 (off), 8, 16 or 32");
  detail::EngineSetup setup;
  setup.grid = detail::makeGridView(grid, shift);
  setup.tool = preparedTool(request.tool);  // shared, never copied: the view points into it
  setup.view = setup.tool->view;
  if (!request.tuning.vertical_bins) setup.view.bins = 0;
  if (!request.tuning.capsule_floor) setup.view.cap_radius_mm = 0.f;
  setup.heights_mm = request.initial_heights_mm;  // empty: every line at the stock
  setup.stock_mm = request.stock_mm;
  setup.tuning = request.tuning;
  // Lowest first pays where one footprint covers a quarter of the grid or more (a zoom: the first
  // cut of a line is then nearly its last); elsewhere the prepass does that and path order keeps
  // the neighbours of a path together (bench/results/zbuffer-h200.md, runs 13-22: path order vs
  // sorted, case 3 105 vs 119 ms, case 8 859 vs 1014, C (a footprint is 1/16 of its grid) 25 vs
  // 177; zooms sorted vs path order: Fz 64 vs 415, Rz 13 vs 30).
  const double span_x = 2.0 * setup.view.hull_radius_mm / grid.dx_mm + 1.0,
               span_y = 2.0 * setup.view.hull_radius_mm / grid.dy_mm + 1.0;
  setup.tuning.lowest_first =
      request.tuning.lowest_first && span_x * span_y * 4.0 > double(grid.lineCount());

  const auto start = std::chrono::steady_clock::now();
  std::unique_ptr<detail::BackendEngine> engine =
      backend == Backend::Cuda ? detail::makeCudaEngine(setup) : detail::makeCpuEngine(setup);
  SimulationResult result;
  result.backend = backend;
  for (;;) {
    const std::span<const Posture> block = next();
    if (block.empty()) break;
    engine->cut(block, request.engine);
    result.postures += block.size();
    const double total = double(std::max(expected_postures, result.postures));
    common::report(request.progress, double(result.postures) / total, "simulate");
  }
  const auto cut_done = std::chrono::steady_clock::now();
  result.heights_mm = engine->heights();
  result.postures_culled = engine->culled();
  const auto read = std::chrono::steady_clock::now();
  result.seconds = std::chrono::duration<double>(read - start).count();
  const float* h = result.heights_mm.data();
  const float* initial =
      request.initial_heights_mm.empty() ? nullptr : request.initial_heights_mm.data();
  const float stock = request.stock_mm;
  const long lines = static_cast<long>(result.heights_mm.size());
  std::size_t lowered = 0;
#pragma omp parallel for schedule(static) reduction(+ : lowered) if (lines > (1 << 20))
  for (long i = 0; i < lines; ++i) lowered += h[i] < (initial ? initial[i] : stock);
  result.lines_lowered = lowered;
  if (std::getenv("FIELDPATH_ZB_TRACE")) {  // benchmarks: where the host's time goes
    const auto ms = [](auto a, auto b) {
      return std::chrono::duration<double, std::milli>(b - a).count();
    };
    std::fprintf(stderr,
                 "trace: host: set-up %.2f ms, engine + cut calls %.2f, heights %.2f, count %.2f\n",
                 ms(entered, start), ms(start, cut_done), ms(cut_done, read),
                 ms(read, std::chrono::steady_clock::now()));
  }
  common::report(request.progress, 1.0, "simulate");
  return result;
}

}  // namespace

SimulationResult simulate(const SimulationRequest& request, const PostureSource& source) {
  std::vector<Posture> buffer(std::max<std::size_t>(1, request.block_postures));
  return run(request, request.expected_postures, [&] {
    const std::size_t n = std::min(source(std::span<Posture>(buffer)), buffer.size());
    return std::span<const Posture>(buffer.data(), n);
  });
}

SimulationResult simulate(const SimulationRequest& request, std::span<const Posture> postures) {
  const std::size_t block = std::max<std::size_t>(1, request.block_postures);
  std::size_t next = 0;
  // no copy of the request (its tool mesh and initial heights) to fill in the expected count
  const std::size_t expected =
      request.expected_postures ? request.expected_postures : postures.size();
  return run(request, expected, [&] {
    const std::size_t n = std::min(block, postures.size() - next);
    const auto out = postures.subspan(next, n);
    next += n;
    return out;
  });
}

double toolReach(const Tool& tool) {
  if (tool.kind != ToolKind::Mesh) return tool.radius_mm;
  double reach = 0;
  for (const auto& p : tool.mesh.vertices)
    reach = std::max(reach, std::sqrt(double(p.x) * p.x + double(p.y) * p.y));
  return reach;
}

}  // namespace fieldpath::zbuffer
