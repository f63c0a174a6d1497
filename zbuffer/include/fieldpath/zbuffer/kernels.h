#pragma once
/// The per-posture, per-line and per-triangle math of the Z-buffer, shared by the CPU reference
/// (OpenMP) and the CUDA backend: postures prepared and culled, floors, the cut of a line, tiles,
/// triangles rastered. The views they take are tool_view.h's; where a line enters the tool is
/// tool_entry.h's.
#include <cfloat>
#include <cstdint>
#include <cstring>

#include "fieldpath/zbuffer/hd.h"
#include "fieldpath/zbuffer/tool_entry.h"
#include "fieldpath/zbuffer/tool_view.h"

namespace fieldpath::zbuffer {

/// First / last line index in [0, n-1] at or after / before the fractional index f (clamped in
/// double before the conversion, so far-away coordinates cannot overflow an int).
FIELDPATH_HD int firstLine(double f, int n) {
  return static_cast<int>(ceil(f < 0.0 ? 0.0 : (f > n - 1.0 ? n - 1.0 : f)));
}
FIELDPATH_HD int lastLine(double f, int n) {
  return static_cast<int>(floor(f < 0.0 ? 0.0 : (f > n - 1.0 ? n - 1.0 : f)));
}

/// Lines that the part of the hull between axial heights z0 and z1 (tool frame, mm) may meet.
FIELDPATH_HD void setFootprint(const GridView& g, PreparedPosture& pp, float hull_r, float z0,
                               float z1, float margin) {
  const float i = pp.rot.m[0][2], j = pp.rot.m[1][2];
  const float ex = hull_r * sqrtf(maxf(0.f, 1.f - i * i)) + margin;
  const float ey = hull_r * sqrtf(maxf(0.f, 1.f - j * j)) + margin;
  const float xa = pp.tip_mm.x + z0 * i, xb = pp.tip_mm.x + z1 * i;
  const float ya = pp.tip_mm.y + z0 * j, yb = pp.tip_mm.y + z1 * j;
  const double xmin = minf(xa, xb) - ex, xmax = maxf(xa, xb) + ex;
  const double ymin = minf(ya, yb) - ey, ymax = maxf(ya, yb) + ey;
  const double fx0 = (xmin - g.x0_mm) / g.dx_mm - 0.5, fx1 = (xmax - g.x0_mm) / g.dx_mm - 0.5;
  const double fy0 = (ymin - g.y0_mm) / g.dy_mm - 0.5, fy1 = (ymax - g.y0_mm) / g.dy_mm - 0.5;
  if (fx1 < 0.0 || fy1 < 0.0 || fx0 > g.nx - 1.0 || fy0 > g.ny - 1.0 || !(fx0 <= fx1) ||
      !(fy0 <= fy1)) {
    pp.ix0 = pp.iy0 = 1;
    pp.ix1 = pp.iy1 = 0;
  } else {
    pp.ix0 = firstLine(fx0, g.nx);
    pp.ix1 = lastLine(fx1, g.nx);
    pp.iy0 = firstLine(fy0, g.ny);
    pp.iy1 = lastLine(fy1, g.ny);
  }
}

/// Lowest possible world z of the placed tool and its footprint on the grid.
FIELDPATH_HD PreparedPosture preparePosture(const GridView& g, const ToolView& tool, Posture pose) {
  PreparedPosture pp;
  pp.rot = postureRotation(pose);
  pp.tip_mm = pose.tip_mm;
  const float i = pp.rot.m[0][2], j = pp.rot.m[1][2], k = pp.rot.m[2][2];
  pp.dir = {pp.rot.m[2][0], pp.rot.m[2][1], pp.rot.m[2][2]};
  const float s = sqrtf(maxf(0.f, i * i + j * j));
  const float hull_r = tool.hull_radius_mm, z0 = tool.hull_zmin_mm, z1 = tool.hull_zmax_mm;
  float lowest = pose.tip_mm.z + minf(z0 * k, z1 * k) - hull_r * s;
  if (tool.kind != ToolKind::Mesh) {
    // Analytic: corner piece (disk of radius R-r at height r, swept by a ball of radius r) and
    // shank cylinder (radius R, z from r to L).
    const float r = tool.corner_radius_mm, big_r = tool.radius_mm;
    const float corner = r * k - (big_r - r) * s - r;
    const float shank = minf(r * k, tool.length_mm * k) - big_r * s;
    lowest = pose.tip_mm.z + minf(corner, shank);
  }
  const float margin = 1e-5f * (absf(pose.tip_mm.z) + hull_r + z1 - z0) + 1e-6f;
  pp.vertical = pp.dir.x == 0.f && pp.dir.y == 0.f && pp.dir.z == 1.f;
  // Vertical: the lowest point is exactly the tip plus the lowest vertex (heights are clamped to it
  // in lineCut, so a line already at that height can be skipped without changing a bit).
  pp.lowest_z_mm =
      pp.vertical ? pose.tip_mm.z + (tool.kind == ToolKind::Mesh ? z0 : 0.f) : lowest - margin;

  setFootprint(g, pp, hull_r, z0, z1, margin);

  // Shear constants of the watertight test for rays along pp.dir (tool frame).
  const float ax = absf(pp.dir.x), ay = absf(pp.dir.y), az = absf(pp.dir.z);
  pp.kz = (ax > ay) ? (ax > az ? 0 : 2) : (ay > az ? 1 : 2);
  pp.kx = (pp.kz + 1) % 3;
  pp.ky = (pp.kx + 1) % 3;
  const float dkz = comp(pp.dir, pp.kz);
  if (dkz < 0.f) {
    const int t = pp.kx;
    pp.kx = pp.ky;
    pp.ky = t;
  }
  pp.sx = comp(pp.dir, pp.kx) / dkz;
  pp.sy = comp(pp.dir, pp.ky) / dkz;
  pp.sz = 1.f / dkz;
  pp.inv_dir = {safeInverse(pp.dir.x), safeInverse(pp.dir.y), safeInverse(pp.dir.z)};

  const float c0 = tool.cap_z0_mm, c1 = tool.cap_z1_mm;
  pp.cap_ax = c0 * i;
  pp.cap_ay = c0 * j;
  pp.cap_bx = c1 * i;
  pp.cap_by = c1 * j;
  pp.cap_za_mm = pose.tip_mm.z + c0 * k;
  pp.cap_zb_mm = pose.tip_mm.z + c1 * k;
  pp.cap_margin_mm =
      1e-5f * (absf(pose.tip_mm.z) + tool.cap_radius_mm + absf(c0) + absf(c1)) + 1e-6f;
  const float ex = pp.cap_bx - pp.cap_ax, ey = pp.cap_by - pp.cap_ay;
  const float len = sqrtf(ex * ex + ey * ey);
  pp.cap_len_mm = len > pp.cap_margin_mm ? len : 0.f;
  pp.cap_ux = pp.cap_len_mm > 0.f ? ex / len : 0.f;
  pp.cap_uy = pp.cap_len_mm > 0.f ? ey / len : 0.f;
  pp.cap_slope = pp.cap_len_mm > 0.f ? (pp.cap_zb_mm - pp.cap_za_mm) / len : 0.f;
  pp.cap_kstar = pp.cap_slope / sqrtf(1.f + pp.cap_slope * pp.cap_slope);
  return pp;
}

/// Floor of the lower envelope of a ball of radius R (tool.cap_radius_mm) centred at height
/// zc_mm, over the points at grid-plane distance >= d_mm from its centre: sqrt(R² - d²) below
/// zc. FLT_MAX where it does not reach (d >= R). The distance is shrunk and the floor lowered by
/// the posture's margin, far more than the float rounding of d, of this expression and of the
/// tool's own entry height, so the floor is never above a height lineCut can give.
FIELDPATH_HD float ballFloor(const ToolView& tool, const PreparedPosture& pp, float zc_mm,
                             float d_mm, float grow_mm = 0.f) {
  const float r = tool.cap_radius_mm + grow_mm;
  const float d = maxf(d_mm * (1.f - 1e-5f) - pp.cap_margin_mm, 0.f);
  if (!(d < r)) return FLT_MAX;
  return zc_mm - sqrtf((r - d) * (r + d)) - pp.cap_margin_mm;
}

/// The capsule's lower envelope at the line (px, py) (mm, relative to the tip), less the margin:
/// the minimum over the segment of z(s) - sqrt(ρ² - (s - along)²), with z linear along the
/// segment and ρ² = R² - d⊥², is convex in s; its stationary point, clamped to the segment, is
/// the minimum. ρ is inflated by the margin (no cancellation at the rim can raise the floor).
/// With the radius grown by g, it is a floor for every point within g of (px, py) too:
/// (R+g)² - |p-q|² >= R² - |p'-q|² where |p'-p| <= g and |p'-q| <= R.
FIELDPATH_HD float capsuleLineFloor(const ToolView& tool, const PreparedPosture& pp, float px,
                                    float py, float grow_mm = 0.f) {
  const float m = pp.cap_margin_mm, r = tool.cap_radius_mm + grow_mm, len = pp.cap_len_mm;
  if (len == 0.f) {  // (nearly) vertical: one ball at the lower end
    const bool a_low = pp.cap_za_mm <= pp.cap_zb_mm;
    const float dx = px - (a_low ? pp.cap_ax : pp.cap_bx),
                dy = py - (a_low ? pp.cap_ay : pp.cap_by);
    // the segment's other points are within the margin of that end and no lower
    return ballFloor(tool, pp, minf(pp.cap_za_mm, pp.cap_zb_mm),
                     maxf(sqrtf(dx * dx + dy * dy) - m, 0.f), grow_mm);
  }
  const float qx = px - pp.cap_ax, qy = py - pp.cap_ay;
  const float along = qx * pp.cap_ux + qy * pp.cap_uy;
  const float dperp = maxf(absf(qx * pp.cap_uy - qy * pp.cap_ux) * (1.f - 1e-5f) - m, 0.f);
  if (!(dperp < r)) return FLT_MAX;
  const float rho = sqrtf((r - dperp) * (r + dperp)) + m;
  const float lo = maxf(0.f, along - rho), hi = minf(len, along + rho);
  if (lo > hi) return FLT_MAX;
  const float s_star = along - pp.cap_kstar * rho;
  const float s = s_star < lo ? lo : (s_star > hi ? hi : s_star);
  const float w = absf(s - along);
  return pp.cap_za_mm + pp.cap_slope * s - sqrtf(maxf((rho - w) * (rho + w), 0.f)) - m;
}

/// The capsule's floor over the rectangle [x0, x1] × [y0, y1] (mm, relative to the tip): the
/// line floor at its centre with the radius grown by its half-diagonal (one line's cost).
FIELDPATH_HD float capsuleRectFloor(const ToolView& tool, const PreparedPosture& pp, float x0,
                                    float x1, float y0, float y1) {
  const float hx = 0.5f * (x1 - x0), hy = 0.5f * (y1 - y0);
  const float grow = sqrtf(hx * hx + hy * hy) * (1.f + 1e-5f) + pp.cap_margin_mm;
  return capsuleLineFloor(tool, pp, x0 + hx, y0 + hy, grow);
}

/// World coordinates (double, mm) of line (ix, iy).
FIELDPATH_HD double lineX(const GridView& g, int ix) { return g.x0_mm + (ix + 0.5) * g.dx_mm; }
FIELDPATH_HD double lineY(const GridView& g, int iy) { return g.y0_mm + (iy + 0.5) * g.dy_mm; }

/// The line at world (xd, yd) (lineX, lineY) relative to the tip, rounded once: the same bits
/// as lineOffset, for a caller that offsets one line from several postures.
FIELDPATH_HD void lineOffsetAt(double xd, double yd, const PreparedPosture& pp, float& rx,
                               float& ry) {
  rx = static_cast<float>(xd - static_cast<double>(pp.tip_mm.x));
  ry = static_cast<float>(yd - static_cast<double>(pp.tip_mm.y));
}

/// World coordinates of line (ix, iy) relative to the tip, formed in double, rounded once.
FIELDPATH_HD void lineOffset(const GridView& g, const PreparedPosture& pp, int ix, int iy,
                             float& rx, float& ry) {
  lineOffsetAt(lineX(g, ix), lineY(g, iy), pp, rx, ry);
}

/// The floors lineCut applies to the line at (rx, ry) from the tip (mm): `skip`, no height it
/// gives is below it (FLT_MAX: it cannot reach the line); `clamp`, its heights are raised to it
/// (the radial floor of a vertical mesh tool, so that a line at that floor is skipped without
/// changing a bit; else the posture's lowest point). The capsule floor only skips: its margin
/// keeps it below any height computed.
struct LineFloors {
  float skip_mm, clamp_mm;
};
FIELDPATH_HD LineFloors lineFloors(const ToolView& tool, const PreparedPosture& pp, float rx,
                                   float ry) {
  LineFloors f{pp.lowest_z_mm, pp.lowest_z_mm};
  if (pp.vertical && tool.radial_bins > 0) {
    const float r = radialFloor(tool, rx * rx + ry * ry);
    if (r == FLT_MAX) return {FLT_MAX, FLT_MAX};
    f.clamp_mm = f.skip_mm = maxf(f.skip_mm, pp.tip_mm.z + r);
  } else if (tool.cap_radius_mm > 0.f) {
    f.skip_mm = maxf(f.skip_mm, capsuleLineFloor(tool, pp, rx, ry));
  }
  return f;
}

/// A line's world coordinate split for cheap offsets from many tips: hi = float(x), lo =
/// float(x - hi) (x from lineX / lineY).
struct SplitCoord {
  float hi, lo;
};
FIELDPATH_HD SplitCoord splitCoord(double x) {
  const float hi = static_cast<float>(x);
  return {hi, static_cast<float>(x - static_cast<double>(hi))};
}

/// The offset of a split coordinate from a tip coordinate t in float only: (hi - t) + lo, which
/// differs from lineOffset's float(x - t) by at most a few ulps of the offset (hi - t is exact
/// where the two are within a factor 2 of each other, and where they are not, both are within
/// a few times the offset). `err` grows by a bound on that difference.
FIELDPATH_HD float offsetNear(SplitCoord c, float t, float& err) {
  const float r = (c.hi - t) + c.lo;
  err += 1e-6f * (absf(r) + absf(c.lo)) + 1e-30f;
  return r;
}

/// A floor of lineFloors(tool, pp, rx, ry).skip_mm at the line whose exact offsets (lineOffset)
/// are within eps_mm of (rx, ry): the radial floor at the radius shrunk by eps (the table is
/// non-decreasing and the float expressions monotone), or the capsule floor with its radius grown
/// by eps (a floor for every point within eps). Lets the group kernel rank and turn away postures
/// without forming each offset in double.
FIELDPATH_HD float lineFloorNear(const ToolView& tool, const PreparedPosture& pp, float rx,
                                 float ry, float eps_mm) {
  if (pp.vertical && tool.radial_bins > 0) {
    const float ax = maxf(absf(rx) - eps_mm, 0.f), ay = maxf(absf(ry) - eps_mm, 0.f);
    const float r = radialFloor(tool, ax * ax + ay * ay);
    return r == FLT_MAX ? FLT_MAX : maxf(pp.lowest_z_mm, pp.tip_mm.z + r);
  }
  if (tool.cap_radius_mm > 0.f)
    return maxf(pp.lowest_z_mm, capsuleLineFloor(tool, pp, rx, ry, eps_mm));
  return pp.lowest_z_mm;
}

/// The box of a group of vertical postures' tips (world xy, mm), its lowest tip z and a pad (far
/// more than the rounding of any posture's own line radius).
struct TipBox {
  float x_lo, x_hi, y_lo, y_hi, z_lo, pad_mm;
};

/// The box's pad for `tool`: relative to the coordinates' size, far above float rounding.
FIELDPATH_HD float tipBoxPad(const TipBox& b, const ToolView& tool) {
  return 1e-5f * (absf(b.x_lo) + absf(b.x_hi) + absf(b.y_lo) + absf(b.y_hi) + tool.hull_radius_mm) +
         1e-6f;
}

/// The group floor (vertical postures, radial floors) over the world rectangle [x0, x1] × [y0, y1]
/// (mm): the lowest tip plus the radial floor at the rectangle's distance from the tips' box,
/// shrunk by the pad; FLT_MAX beyond the tool's reach. No posture of the group gives a line there
/// a height below it (the CUDA group kernel turns lines and tiles away with it).
FIELDPATH_HD float groupFloor(const ToolView& tool, const TipBox& box, float x0, float x1, float y0,
                              float y1) {
  const float dx = maxf(maxf(box.x_lo - x1, x0 - box.x_hi) - box.pad_mm, 0.f);
  const float dy = maxf(maxf(box.y_lo - y1, y0 - box.y_hi) - box.pad_mm, 0.f);
  const float rho2 = (dx * dx + dy * dy) * (1.f - 1e-5f);
  const float r = radialFloor(tool, rho2);
  return r == FLT_MAX ? FLT_MAX : box.z_lo + r;
}

/// The height the posture would give the line at (rx, ry) from the tip (mm) whose floors are
/// `floors`, or FLT_MAX if it cannot lower it below `current_mm`. Analytic and mesh tools; -0
/// folded to +0 so that both backends store equal bits. A height it returns does not depend on
/// `current_mm` (the BVH is only pruned by it), so the minimum over postures is the same in any
/// order and grouping.
FIELDPATH_HD float lineCutAt(const ToolView& tool, const PreparedPosture& pp, float rx, float ry,
                             LineFloors floors, float current_mm) {
  if (!(current_mm > floors.skip_mm)) return FLT_MAX;
  const Vec3f o = mulTransposed(pp.rot, Vec3f{rx, ry, 0.f});
  float t;
  if (tool.kind == ToolKind::Mesh) {
    const float slack = 1e-5f * (absf(current_mm) + absf(pp.tip_mm.z) + 1.f);
    t = pp.vertical && tool.bins > 0 ? binnedEntry(tool, pp, o)
                                     : meshEntry(tool, pp, o, current_mm - pp.tip_mm.z + slack);
  } else {
    t = analyticEntry(tool, o, pp.dir);
  }
  if (t == FLT_MAX) return FLT_MAX;
  const float h = maxf(pp.tip_mm.z + t, floors.clamp_mm) + 0.f;
  return h < current_mm ? h : FLT_MAX;
}

/// lineCutAt for line (ix, iy): the shared per-line code path of both backends.
FIELDPATH_HD float lineCut(const GridView& g, const ToolView& tool, const PreparedPosture& pp,
                           int ix, int iy, float current_mm) {
  if (!(current_mm > pp.lowest_z_mm)) return FLT_MAX;
  float rx, ry;
  lineOffset(g, pp, ix, iy, rx, ry);
  return lineCutAt(tool, pp, rx, ry, lineFloors(tool, pp, rx, ry), current_mm);
}

/// A floor of the heights the posture can give the lines of the rectangle [ix0, ix1] × [iy0, iy1]:
/// lineCut gives none of them a height below it (FLT_MAX: it lowers none of them), so a rectangle
/// whose highest line is at or below it is skipped whole without changing a bit. Vertical mesh
/// tools: the radial floor at the rectangle's smallest line radius (the table is non-decreasing,
/// and each line's float radius is at least that one: the same monotone float expressions).
/// Other postures and tools: the capsule's floor over the rectangle (capsuleRectFloor).
FIELDPATH_HD float rectFloor(const GridView& g, const ToolView& tool, const PreparedPosture& pp,
                             int ix0, int ix1, int iy0, int iy1) {
  float ax, ay, bx, by;
  lineOffset(g, pp, ix0, iy0, ax, ay);
  lineOffset(g, pp, ix1, iy1, bx, by);
  if (!(pp.vertical && tool.radial_bins > 0)) {
    if (!(tool.cap_radius_mm > 0.f)) return pp.lowest_z_mm;
    return maxf(pp.lowest_z_mm, capsuleRectFloor(tool, pp, ax, bx, ay, by));
  }
  const float rx = (ax <= 0.f && bx >= 0.f) ? 0.f : minf(absf(ax), absf(bx));
  const float ry = (ay <= 0.f && by >= 0.f) ? 0.f : minf(absf(ay), absf(by));
  const float r = radialFloor(tool, rx * rx + ry * ry);
  return r == FLT_MAX ? FLT_MAX : maxf(pp.lowest_z_mm, pp.tip_mm.z + r);
}

/// A height or tile maximum as read while other work items may lower it: a relaxed atomic load on
/// the CPU, a plain load on the GPU (the CUDA backend keeps heights as ordered keys and reads them
/// itself). Any value read bounds the line or tile from then on: heights only decrease.
FIELDPATH_HD float loadRelaxed(const float* slot) {
#ifdef __CUDA_ARCH__
  return *slot;
#else
  float v;
  __atomic_load(slot, &v, __ATOMIC_RELAXED);
  return v;
#endif
}
FIELDPATH_HD float readTileMax(const float* tile_max, int tile) {
  return loadRelaxed(tile_max + tile);
}

/// True if lines [ix0, ix1] × [iy0, iy1] are all the lines of their tile (clipped to the grid):
/// the highest height after cutting them bounds the tile (live tile maxima).
FIELDPATH_HD bool wholeTile(const GridView& g, int ix0, int ix1, int iy0, int iy1) {
  const int mask = (1 << g.tile_shift) - 1;
  const int xe = (ix0 | mask) < g.nx - 1 ? (ix0 | mask) : g.nx - 1;
  const int ye = (iy0 | mask) < g.ny - 1 ? (iy0 | mask) : g.ny - 1;
  return (ix0 & mask) == 0 && (iy0 & mask) == 0 && ix1 == xe && iy1 == ye;
}

/// Visits the tiles of the (culled) footprint: tiles tile_first, tile_first + tile_step, ... in
/// footprint order; a tile whose maximum top(tile) (possibly stale-high) is at or below its
/// rectangle's floor is skipped whole; the others' rectangles (clipped to the footprint) go to
/// visit(ix0, ix1, iy0, iy1, tile). Shared by the CPU loop (0, 1) and the CUDA threads and warps
/// (blockIdx.y, gridDim.y); `top` reads the tile maximum (readTileMax, or one lane's read shared by
/// a warp so that its lanes take the same tiles).
template <class TileTop, class VisitRect>
FIELDPATH_HD void forEachLiveTile(const GridView& g, const ToolView& tool,
                                  const PreparedPosture& pp, bool skip, int tile_first,
                                  int tile_step, TileTop top, VisitRect visit) {
  const int tx0 = pp.ix0 >> g.tile_shift, tx1 = pp.ix1 >> g.tile_shift;
  const int ty0 = pp.iy0 >> g.tile_shift, ty1 = pp.iy1 >> g.tile_shift;
  const int tw = tx1 - tx0 + 1, tiles = tw * (ty1 - ty0 + 1);
  for (int t = tile_first; t < tiles; t += tile_step) {
    const int tx = tx0 + t % tw, ty = ty0 + t / tw;
    const int ix0 = tx << g.tile_shift > pp.ix0 ? tx << g.tile_shift : pp.ix0;
    const int iy0 = ty << g.tile_shift > pp.iy0 ? ty << g.tile_shift : pp.iy0;
    const int ix1 =
        ((tx + 1) << g.tile_shift) - 1 < pp.ix1 ? ((tx + 1) << g.tile_shift) - 1 : pp.ix1;
    const int iy1 =
        ((ty + 1) << g.tile_shift) - 1 < pp.iy1 ? ((ty + 1) << g.tile_shift) - 1 : pp.iy1;
    const int tile = ty * g.tiles_x + tx;
    if (skip && top(tile) <= rectFloor(g, tool, pp, ix0, ix1, iy0, iy1)) continue;
    visit(ix0, ix1, iy0, iy1, tile);
  }
}

/// Cuts lines first, first + step, ... of the rectangle [ix0, ix1] × [iy0, iy1] (row by row) with
/// lineCut: height(ix, iy) reads a line's current height, lower(ix, iy, z) lowers it to z. Returns
/// the highest height the visited lines are left at or under (a bound for the tile when they are
/// all of its lines: wholeTile). The per-rectangle loop of the CPU engine (0, 1) and of the CUDA
/// threads and warps (lane, 32).
template <class Height, class Lower>
FIELDPATH_HD float cutRect(const GridView& g, const ToolView& tool, const PreparedPosture& pp,
                           int ix0, int ix1, int iy0, int iy1, int first, int step, Height height,
                           Lower lower) {
  float highest = -FLT_MAX;
  const auto cut = [&](int ix, int iy) {
    const float current = height(ix, iy);
    const float z = lineCut(g, tool, pp, ix, iy, current);
    if (z != FLT_MAX) lower(ix, iy, z);
    highest = maxf(highest, z != FLT_MAX ? z : current);
  };
  if (first == 0 && step == 1) {  // one work item takes every line: no division per line
    for (int iy = iy0; iy <= iy1; ++iy)
      for (int ix = ix0; ix <= ix1; ++ix) cut(ix, iy);
  } else {
    const int w = ix1 - ix0 + 1, lines = w * (iy1 - iy0 + 1);
    for (int l = first; l < lines; l += step) cut(ix0 + l % w, iy0 + l / w);
  }
  return highest;
}

/// True if the posture cannot lower any line: its lowest point is not below the highest height of
/// the culling tiles under its footprint (tile maxima may be stale-high, which stays conservative).
/// Otherwise shrinks the footprint to the part of the tool that can reach below that height (the
/// shank of a tilted tool mostly cannot), which changes no result.
FIELDPATH_HD bool cullPosture(const GridView& g, const ToolView& tool, PreparedPosture& pp,
                              const float* tile_max_mm) {
  if (pp.ix0 > pp.ix1 || pp.iy0 > pp.iy1) return true;
  const int tx0 = pp.ix0 >> g.tile_shift, tx1 = pp.ix1 >> g.tile_shift;
  const int ty0 = pp.iy0 >> g.tile_shift, ty1 = pp.iy1 >> g.tile_shift;
  float top = -FLT_MAX;
  for (int ty = ty0; ty <= ty1; ++ty)
    for (int tx = tx0; tx <= tx1; ++tx)
      top = maxf(top, readTileMax(tile_max_mm, ty * g.tiles_x + tx));
  if (pp.lowest_z_mm >= top) return true;
  // a footprint clipped by the grid (a zoom) may lie where the tool is far above its lowest point
  if (rectFloor(g, tool, pp, pp.ix0, pp.ix1, pp.iy0, pp.iy1) >= top) return true;
  const float i = pp.rot.m[0][2], j = pp.rot.m[1][2], k = pp.rot.m[2][2];
  if (k > 1e-3f) {
    const float margin =
        1e-5f * (absf(pp.tip_mm.z) + absf(top) + tool.hull_radius_mm + tool.hull_zmax_mm) + 1e-6f;
    const float reach =
        (top - pp.tip_mm.z + tool.hull_radius_mm * sqrtf(i * i + j * j) + margin) / k + margin;
    if (reach < tool.hull_zmax_mm)
      setFootprint(g, pp, tool.hull_radius_mm, tool.hull_zmin_mm, maxf(tool.hull_zmin_mm, reach),
                   margin);
  }
  return false;
}

/// True if the tool, whatever its axis, stays off the grid's lines: the ball about the tip that
/// holds it (radius from the hull, grown by far more than any rounding) misses the lines' box.
/// A zoom's postures are mostly such; this costs a few compares instead of a preparePosture.
FIELDPATH_HD bool missesGrid(const GridView& g, const ToolView& tool, Posture pose) {
  const float zr = maxf(absf(tool.hull_zmin_mm), absf(tool.hull_zmax_mm));
  const float reach = sqrtf(tool.hull_radius_mm * tool.hull_radius_mm + zr * zr) * 1.001f +
                      1e-4f * (absf(pose.tip_mm.x) + absf(pose.tip_mm.y)) + 1e-3f;
  const double x0 = g.x0_mm + 0.5 * g.dx_mm, x1 = g.x0_mm + (g.nx - 0.5) * g.dx_mm;
  const double y0 = g.y0_mm + 0.5 * g.dy_mm, y1 = g.y0_mm + (g.ny - 0.5) * g.dy_mm;
  return pose.tip_mm.x + reach < x0 || pose.tip_mm.x - reach > x1 || pose.tip_mm.y + reach < y0 ||
         pose.tip_mm.y - reach > y1;
}

/// Sort key of a posture for lowest-first processing: its lowest point over the grid (the floor of
/// its footprint's lines) as an unsigned key that orders like the float (postures that miss the
/// grid last). Processing a block lowest first makes the first cut of a line nearly its final
/// one, so later (higher) postures are culled by the tile maxima or skipped per line at one
/// compare; the minimum, hence every bit, is the same.
FIELDPATH_HD std::uint32_t lowestKey(const GridView& g, const ToolView& tool, Posture pose) {
  if (missesGrid(g, tool, pose)) return 0xffffffffu;
  const PreparedPosture pp = preparePosture(g, tool, pose);
  if (pp.ix0 > pp.ix1 || pp.iy0 > pp.iy1) return 0xffffffffu;
  // over the grid only: in a zoom, the postures that cut its lines lowest come first
  const float lowest = maxf(pp.lowest_z_mm, rectFloor(g, tool, pp, pp.ix0, pp.ix1, pp.iy0, pp.iy1));
  if (lowest == FLT_MAX) return 0xffffffffu;
  std::int32_t bits;
  memcpy(&bits, &lowest, 4);
  return static_cast<std::uint32_t>(orderedBits(bits)) ^ 0x80000000u;
}

/// Canonical 2D edge function: the same two points give exactly opposite values whichever way
/// round the edge is traversed (watertight rasterisation of a shared edge).
FIELDPATH_HD float edgeFunction(Vec3f a, Vec3f b, float px, float py) {
  const bool swap = (b.x < a.x) || (b.x == a.x && b.y < a.y);
  const Vec3f p = swap ? b : a, q = swap ? a : b;
  const float e = (q.x - p.x) * (py - p.y) - (q.y - p.y) * (px - p.x);
  return swap ? -e : e;
}

/// Rasterises one world-frame triangle onto the lines. `sign` = -1 keeps triangles facing down
/// (clockwise seen from above) and calls lower(ix, iy, z); +1 keeps those facing up.
template <class Visit>
FIELDPATH_HD void rasterTriangle(const GridView& g, Vec3f w0, Vec3f w1, Vec3f w2, float sign,
                                 Visit visit) {
  const float area2 = (w1.x - w0.x) * (w2.y - w0.y) - (w1.y - w0.y) * (w2.x - w0.x);
  if (!(area2 * sign > 0.f)) return;
  const double xmin = minf(w0.x, minf(w1.x, w2.x)), xmax = maxf(w0.x, maxf(w1.x, w2.x));
  const double ymin = minf(w0.y, minf(w1.y, w2.y)), ymax = maxf(w0.y, maxf(w1.y, w2.y));
  const double fx0 = (xmin - g.x0_mm) / g.dx_mm - 0.5, fx1 = (xmax - g.x0_mm) / g.dx_mm - 0.5;
  const double fy0 = (ymin - g.y0_mm) / g.dy_mm - 0.5, fy1 = (ymax - g.y0_mm) / g.dy_mm - 0.5;
  if (!(fx1 >= -1.0 && fy1 >= -1.0 && fx0 <= g.nx && fy0 <= g.ny)) return;
  const int ix0 = clampi(firstLine(fx0, g.nx) - 1, 0, g.nx - 1),
            ix1 = clampi(lastLine(fx1, g.nx) + 1, 0, g.nx - 1);
  const int iy0 = clampi(firstLine(fy0, g.ny) - 1, 0, g.ny - 1),
            iy1 = clampi(lastLine(fy1, g.ny) + 1, 0, g.ny - 1);
  for (int iy = iy0; iy <= iy1; ++iy) {
    const float py = static_cast<float>(g.y0_mm + (iy + 0.5) * g.dy_mm);
    for (int ix = ix0; ix <= ix1; ++ix) {
      const float px = static_cast<float>(g.x0_mm + (ix + 0.5) * g.dx_mm);
      const float e0 = edgeFunction(w1, w2, px, py) * sign;
      const float e1 = edgeFunction(w2, w0, px, py) * sign;
      const float e2 = edgeFunction(w0, w1, px, py) * sign;
      if (e0 < 0.f || e1 < 0.f || e2 < 0.f) continue;
      const float sum = e0 + e1 + e2;
      if (sum == 0.f) continue;
      visit(ix, iy, (e0 * w0.z + e1 * w1.z + e2 * w2.z) / sum + 0.f);
    }
  }
}

/// SIMSURF1's coarse work item: one posture, every triangle transformed and rasterised.
template <class Lower>
FIELDPATH_HD void coarsePosture(const GridView& g, const ToolView& tool, Posture pose,
                                Lower lower) {
  const Mat3f rot = postureRotation(pose);
  for (int t = 0; t < tool.triangle_count; ++t) {
    const Vec3f w0 = mul(rot, tool.vertices[tool.indices[3 * t]]) + pose.tip_mm;
    const Vec3f w1 = mul(rot, tool.vertices[tool.indices[3 * t + 1]]) + pose.tip_mm;
    const Vec3f w2 = mul(rot, tool.vertices[tool.indices[3 * t + 2]]) + pose.tip_mm;
    rasterTriangle(g, w0, w1, w2, -1.f, lower);
  }
}

}  // namespace fieldpath::zbuffer
