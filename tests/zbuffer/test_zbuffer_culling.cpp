/// Z-buffer culling: every floor (capsule, radial, float offsets, groups, tiles) is below the cut
/// it stands for and tight where it can be; the cut does not depend on the height it is given.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "fieldpath/zbuffer/engine.h"
#include "fieldpath/zbuffer/simulator.h"
#include "fieldpath/zbuffer/tool_mesh.h"
#include "zbuffer_cases.h"

namespace fieldpath::zbuffer {
namespace {

using cases::gridBottomTool;
using cases::pose;

TEST(Culling, CapsuleFloorIsBelowEveryCutAndTightForABall) {
  // The capsule floor of a line (and of a rectangle of lines) must never be above the height the
  // tool's exact entry gives any of its lines, for every tool kind and any tilt; where it says
  // FLT_MAX (out of the capsule's reach) the tool must miss the line.
  std::mt19937 rng(41);
  std::uniform_real_distribution<double> u(-1, 1);
  const Grid grid = Grid::fromRegion(-8, -8, 8, 8, 48, 48);
  const GridView g = detail::makeGridView(grid, 2);
  const std::vector<Tool> tools = {Tool::ball(2, 8),
                                   Tool::torus(3, 1, 10),
                                   Tool::flat(2.5, 6),
                                   Tool::fromMesh(analyticToolMesh(Tool::ball(2, 8), 32, 31)),
                                   Tool::fromMesh(analyticToolMesh(Tool::torus(3, 1, 10), 40, 8)),
                                   Tool::fromMesh(gridBottomTool())};
  int hits = 0;
  for (const Tool& tool : tools) {
    const detail::ToolData data = detail::prepareTool(tool);
    ASSERT_GT(data.view.cap_radius_mm, 0.f);
    for (int k = 0; k < 60; ++k) {
      const double tilt = k % 6 == 0 ? 0.0 : u(rng);
      const Posture p = pose(2 * u(rng), 2 * u(rng), u(rng), tilt, k % 5 == 0 ? 0.0 : u(rng),
                             k % 7 == 0 ? 0.05 : 0.3 + std::abs(u(rng)));
      const PreparedPosture pp = preparePosture(g, data.view, p);
      if (pp.ix0 > pp.ix1 || pp.iy0 > pp.iy1) continue;
      float rect_min = FLT_MAX;
      for (int iy = pp.iy0; iy <= pp.iy1; ++iy)
        for (int ix = pp.ix0; ix <= pp.ix1; ++ix) {
          float rx, ry;
          lineOffset(g, pp, ix, iy, rx, ry);
          const Vec3f o = mulTransposed(pp.rot, Vec3f{rx, ry, 0.f});
          const float t = tool.kind == ToolKind::Mesh ? meshEntry(data.view, pp, o, FLT_MAX)
                                                      : analyticEntry(data.view, o, pp.dir);
          const float floor = capsuleLineFloor(data.view, pp, rx, ry);
          if (t == FLT_MAX) continue;
          ++hits;
          const float h = pp.tip_mm.z + t;
          ASSERT_LE(floor, h) << "tool " << int(tool.kind) << " posture " << k << " line " << ix
                              << "," << iy;
          rect_min = std::min(rect_min, std::max(h, pp.lowest_z_mm));  // lineCut clamps so
        }
      // the whole footprint as one rectangle
      ASSERT_LE(rectFloor(g, data.view, pp, pp.ix0, pp.ix1, pp.iy0, pp.iy1), rect_min);
    }
  }
  EXPECT_GT(hits, 5000);
  // Tight where it matters: a vertical ball's floor is its exact height, less the margin.
  const detail::ToolData ball = detail::prepareTool(Tool::ball(2, 8));
  const PreparedPosture pp = preparePosture(g, ball.view, pose(0, 0, 0, 0, 0, 1));
  for (double d : {0.0, 0.5, 1.0, 1.5, 1.9})
    EXPECT_NEAR(capsuleLineFloor(ball.view, pp, float(d), 0.f), 2 - std::sqrt(4 - d * d), 1e-3)
        << d;
  EXPECT_EQ(capsuleLineFloor(ball.view, pp, 2.1f, 0.f), FLT_MAX);
  // ... and a tilted one's, along its lower edge: the ball's exact height, not the shank's.
  const double c = std::sqrt(0.5);
  const PreparedPosture tilted = preparePosture(g, ball.view, pose(0, 0, 0, c, 0, c));
  for (double x : {-0.5, 0.0, 0.7, 1.4})  // ball centre at (√2, 0, √2): exact height below it
    EXPECT_NEAR(capsuleLineFloor(ball.view, tilted, float(x), 0.f),
                std::sqrt(2.0) - std::sqrt(4 - (x - std::sqrt(2.0)) * (x - std::sqrt(2.0))), 1e-3)
        << x;
}

TEST(Culling, RadialFloorIsBelowEveryVerticalCutAndTight) {
  // The radial floor of a vertical line (the table entry of its float ρ²) must never be above the
  // height the binned triangle test gives it: lineCut clamps to it and skips lines at or under it.
  // It is the exact least height of the triangles' planes over each annulus, so for a ball mesh it
  // must also be within a few µm of the sphere (its lowest vertex per triangle was ~100 µm off).
  std::mt19937 rng(43);
  std::uniform_real_distribution<double> u(-1, 1);
  const GridView g = detail::makeGridView(Grid::fromRegion(-1, -1, 1, 1, 4, 4));
  const auto floorAt = [](const ToolView& v, float x, float y) {
    return radialFloor(v, x * x + y * y);
  };
  int hits = 0;
  for (const Tool& tool : {Tool::fromMesh(gridBottomTool()),
                           Tool::fromMesh(analyticToolMesh(Tool::torus(5, 1, 25), 127, 100)),
                           Tool::fromMesh(analyticToolMesh(Tool::ball(2, 8), 32, 31)),
                           Tool::fromMesh(analyticToolMesh(Tool::ball(5, 20), 79, 78))}) {
    const detail::ToolData data = detail::prepareTool(tool);
    ASSERT_GT(data.view.radial_bins, 0);
    const PreparedPosture pp = preparePosture(g, data.view, pose(0, 0, 0, 0, 0, 1));
    const float reach = data.view.hull_radius_mm * 1.05f;
    for (int k = 0; k < 40000; ++k) {
      Vec3f o{float(reach * u(rng)), float(reach * u(rng)), 0.f};
      if (k % 4 == 0) o = {std::round(o.x * 4) / 4, std::round(o.y * 4) / 4, 0.f};  // on edges
      if (k % 4 == 1) {  // on a vertex of the mesh
        const auto& vs = tool.mesh.vertices;
        const Vec3f p = vs[std::size_t(k) % vs.size()];
        o = {p.x, p.y, 0.f};
      }
      const float t = binnedEntry(data.view, pp, o);
      if (t == FLT_MAX) continue;
      ++hits;
      ASSERT_LE(floorAt(data.view, o.x, o.y), t)
          << "tool radius " << tool.radius_mm << " at " << o.x << "," << o.y;
    }
  }
  EXPECT_GT(hits, 50000);
  const detail::ToolData ball =
      detail::prepareTool(Tool::fromMesh(analyticToolMesh(Tool::ball(2, 8), 32, 31)));
  for (double rho : {0.0, 0.2, 0.5, 0.9, 1.2, 1.5}) {
    const double sphere = 2 - std::sqrt(4 - rho * rho);
    const float floor = floorAt(ball.view, float(rho), 0.f);
    EXPECT_GE(floor, sphere - 5e-3 * (rho + 0.1)) << rho;  // within the annulus width × slope
  }
}

TEST(Culling, FloatOffsetFloorsAreBelowTheExactOnes) {
  // The group kernel ranks postures by floors formed from float offsets (offsetNear); each must
  // be at or below the floor lineCut applies with the exact offsets, far from the origin (large
  // coordinates, few bits left for the offset), across zero and with lines and tips on both sides.
  std::mt19937 rng(47);
  std::uniform_real_distribution<double> u(-1, 1);
  const std::vector<Tool> tools = {Tool::fromMesh(analyticToolMesh(Tool::ball(5, 20), 79, 78)),
                                   Tool::ball(2, 8), Tool::torus(3, 1, 10)};
  int compared = 0, tight = 0;
  for (double origin : {0.0, -4.0, 997.0, -1999.5, 123456.0}) {
    const Grid grid = Grid::fromRegion(origin - 8, origin - 8, origin + 8, origin + 8, 160, 160);
    const GridView g = detail::makeGridView(grid, 3);
    for (const Tool& tool : tools) {
      const detail::ToolData data = detail::prepareTool(tool);
      for (int k = 0; k < 40; ++k) {
        const bool vertical = k % 2 == 0;
        const Posture p = pose(origin + 6 * u(rng), origin + 6 * u(rng), u(rng),
                               vertical ? 0.0 : 0.5 * u(rng), vertical ? 0.0 : 0.5 * u(rng), 1);
        const PreparedPosture pp = preparePosture(g, data.view, p);
        for (int iy = pp.iy0; iy <= pp.iy1; iy += 3)
          for (int ix = pp.ix0; ix <= pp.ix1; ix += 3) {
            float rx, ry;
            lineOffset(g, pp, ix, iy, rx, ry);
            const float exact = lineFloors(data.view, pp, rx, ry).skip_mm;
            float eps = 0.f;
            const float ax = offsetNear(splitCoord(lineX(g, ix)), pp.tip_mm.x, eps);
            const float ay = offsetNear(splitCoord(lineY(g, iy)), pp.tip_mm.y, eps);
            const float near = lineFloorNear(data.view, pp, ax, ay, eps);
            ASSERT_LE(near, exact)
                << "origin " << origin << " tool " << int(tool.kind) << " line " << ix << "," << iy;
            ++compared;
            tight += exact == FLT_MAX ? near == FLT_MAX : exact - near < 1e-3f;
          }
      }
    }
  }
  EXPECT_GT(compared, 50000);
  EXPECT_GT(tight, compared * 9 / 10);  // a floor that low would turn nothing away
}

TEST(Culling, CutDoesNotDependOnTheHeightItIsGiven) {
  // The CUDA group kernel hands each posture the running minimum of the group, not the stored
  // height; its bits equal the CPU's only if a cut, when it returns a height, returns the same one
  // whatever height above it it was given (the BVH walk is pruned by that height, with a slack).
  std::mt19937 rng(53);
  std::uniform_real_distribution<double> u(-1, 1);
  const GridView g = detail::makeGridView(Grid::fromRegion(-6, -6, 6, 6, 96, 96), 3);
  int checked = 0;
  for (const Tool& tool :
       {Tool::fromMesh(analyticToolMesh(Tool::ball(2, 8), 32, 31)),
        Tool::fromMesh(analyticToolMesh(Tool::torus(3, 1, 10), 40, 8)), Tool::torus(3, 1, 10)}) {
    const detail::ToolData data = detail::prepareTool(tool);
    for (int k = 0; k < 30; ++k) {
      const bool vertical = k % 3 == 0;
      const PreparedPosture pp = preparePosture(
          g, data.view,
          pose(2 * u(rng), 2 * u(rng), u(rng), vertical ? 0 : u(rng), vertical ? 0 : u(rng), 1));
      for (int iy = pp.iy0; iy <= pp.iy1; iy += 2)
        for (int ix = pp.ix0; ix <= pp.ix1; ix += 2) {
          float rx, ry;
          lineOffset(g, pp, ix, iy, rx, ry);
          const LineFloors f = lineFloors(data.view, pp, rx, ry);
          const float free = lineCutAt(data.view, pp, rx, ry, f, FLT_MAX);
          if (free == FLT_MAX) continue;
          for (float given : {std::nextafter(free, FLT_MAX), free + 1e-4f, free + 0.5f}) {
            const float h = lineCutAt(data.view, pp, rx, ry, f, given);
            ASSERT_EQ(std::memcmp(&h, &free, 4), 0)
                << "tool " << int(tool.kind) << " given " << given << ": " << h << " vs " << free;
            ++checked;
          }
          // and at or below it, no height
          ASSERT_EQ(lineCutAt(data.view, pp, rx, ry, f, free), FLT_MAX);
        }
    }
  }
  EXPECT_GT(checked, 10000);
}

TEST(Culling, MissesGridOnlyWhereTheFootprintIsEmpty) {
  // missesGrid turns postures away before any preparation (a zoom's nearly all): it may say so
  // only where the tool's footprint holds no line, for any axis, near the grid's edges too.
  std::mt19937 rng(59);
  std::uniform_real_distribution<double> u(-1, 1);
  const GridView g = detail::makeGridView(Grid::fromRegion(100, 100, 100.3, 100.3, 64, 64), 3);
  int misses = 0, near = 0;
  for (const Tool& tool : {Tool::ball(3, 12), Tool::torus(5, 1, 25),
                           Tool::fromMesh(analyticToolMesh(Tool::ball(3, 12), 32, 31))}) {
    const detail::ToolData data = detail::prepareTool(tool);
    for (int k = 0; k < 20000; ++k) {
      const double spread = k % 2 ? 14.0 : 30.0;
      const Posture p = pose(100.15 + spread * u(rng), 100.15 + spread * u(rng), u(rng), u(rng),
                             u(rng), k % 5 == 0 ? 0.0 : std::abs(u(rng)) + 1e-3);
      const bool miss = missesGrid(g, data.view, p);
      const PreparedPosture pp = preparePosture(g, data.view, p);
      const bool empty = pp.ix0 > pp.ix1 || pp.iy0 > pp.iy1;
      if (miss)
        ASSERT_TRUE(empty) << "tool " << int(tool.kind) << " tip " << p.tip_mm.x << ","
                           << p.tip_mm.y;
      // and, independently of the footprint code, no point of the placed tool's cylinder
      // (radius R about the axis, z from 0 to L: it holds the solid) is over the lines' box
      if (miss && tool.kind != ToolKind::Mesh) {
        const double ax = p.axis.x, ay = p.axis.y, az = p.axis.z;
        const double n = std::sqrt(ax * ax + ay * ay + az * az);
        const double a[3] = {ax / n, ay / n, az / n};
        const double e[3] = {std::abs(a[0]) < 0.9 ? 1.0 : 0.0, std::abs(a[0]) < 0.9 ? 0.0 : 1.0, 0};
        double b1[3] = {a[1] * e[2] - a[2] * e[1], a[2] * e[0] - a[0] * e[2],
                        a[0] * e[1] - a[1] * e[0]};
        const double m = std::sqrt(b1[0] * b1[0] + b1[1] * b1[1] + b1[2] * b1[2]);
        for (double& c : b1) c /= m;
        const double b2[3] = {a[1] * b1[2] - a[2] * b1[1], a[2] * b1[0] - a[0] * b1[2],
                              a[0] * b1[1] - a[1] * b1[0]};
        const double x0 = 100 + 0.5 * g.dx_mm, x1 = 100.3 - 0.5 * g.dx_mm;
        for (int s = 0; s <= 8; ++s)
          for (int c = 0; c < 32; ++c) {
            const double z = tool.length_mm * s / 8, th = 2 * std::numbers::pi * c / 32;
            const double r = tool.radius_mm, ct = r * std::cos(th), st = r * std::sin(th);
            const double px = p.tip_mm.x + z * a[0] + ct * b1[0] + st * b2[0];
            const double py = p.tip_mm.y + z * a[1] + ct * b1[1] + st * b2[1];
            ASSERT_FALSE(px >= x0 && px <= x1 && py >= x0 && py <= x1)
                << "tool " << int(tool.kind) << " point " << px << "," << py << " over the lines";
          }
      }
      misses += miss;
      near += !miss && empty;
    }
  }
  EXPECT_GT(misses, 10000);  // it does turn most far postures away
  EXPECT_GT(near, 100);      // and is conservative near the edge
}

TEST(Culling, GroupFloorIsBelowEveryPostureFloorOfTheGroup) {
  // The CUDA group kernel turns a line (or a tile) away for a whole group of vertical postures
  // with groupFloor: the lowest tip plus the radial floor at the distance from the tips' box. It
  // must be at or below each posture's own floor (lineFloors, exact offsets) on every line, far
  // from the origin too.
  std::mt19937 rng(67);
  std::uniform_real_distribution<double> u(-1, 1);
  int compared = 0;
  for (const Tool& tool : {Tool::fromMesh(analyticToolMesh(Tool::ball(5, 20), 79, 78)),
                           Tool::fromMesh(analyticToolMesh(Tool::torus(5, 1, 25), 127, 100))}) {
    const detail::ToolData data = detail::prepareTool(tool);
    for (double origin : {0.0, 997.0, -1999.5, 123456.0}) {
      const GridView g = detail::makeGridView(
          Grid::fromRegion(origin - 8, origin - 8, origin + 8, origin + 8, 80, 80), 3);
      for (int group = 0; group < 10; ++group) {
        const double x = origin + 2 * u(rng), y = origin + 2 * u(rng), z = u(rng);
        std::vector<PreparedPosture> pps;
        TipBox box{FLT_MAX, -FLT_MAX, FLT_MAX, -FLT_MAX, FLT_MAX, 0.f};
        for (int k = 0; k < 8; ++k) {  // a path's neighbours: 0.05 mm apart, z drifting
          const PreparedPosture pp = preparePosture(
              g, data.view, pose(x + 0.05 * k, y + 0.01 * k * u(rng), z + 0.01 * u(rng), 0, 0, 1));
          box = {std::min(box.x_lo, pp.tip_mm.x), std::max(box.x_hi, pp.tip_mm.x),
                 std::min(box.y_lo, pp.tip_mm.y), std::max(box.y_hi, pp.tip_mm.y),
                 std::min(box.z_lo, pp.tip_mm.z), 0.f};
          pps.push_back(pp);
        }
        box.pad_mm = tipBoxPad(box, data.view);
        for (int iy = 0; iy < g.ny; iy += 2)
          for (int ix = 0; ix < g.nx; ix += 2) {
            const float lx = static_cast<float>(lineX(g, ix)),
                        ly = static_cast<float>(lineY(g, iy));
            const float gf = groupFloor(data.view, box, lx, lx, ly, ly);
            for (const PreparedPosture& pp : pps) {
              float rx, ry;
              lineOffset(g, pp, ix, iy, rx, ry);
              ASSERT_LE(gf, lineFloors(data.view, pp, rx, ry).skip_mm)
                  << "origin " << origin << " line " << ix << "," << iy;
              ++compared;
            }
            // a tile of lines around it: below every line's floor in it
            const int x1 = std::min(ix + 7, g.nx - 1), y1 = std::min(iy + 7, g.ny - 1);
            const float tf = groupFloor(data.view, box, lx, static_cast<float>(lineX(g, x1)), ly,
                                        static_cast<float>(lineY(g, y1)));
            float rx, ry;
            lineOffset(g, pps[3], x1, y1, rx, ry);
            ASSERT_LE(tf, lineFloors(data.view, pps[3], rx, ry).skip_mm);
            ASSERT_LE(tf, gf);
          }
      }
    }
  }
  EXPECT_GT(compared, 100000);
}

TEST(Culling, WholeTileMeansEveryLineOfTheTile) {
  // A tile's maximum is lowered only by a work item that cut all of its lines (wholeTile): the
  // interior tiles' full rectangles, the edge tiles clipped by the grid (nx, ny not multiples of
  // the tile), and nothing less.
  const GridView g = detail::makeGridView(Grid::fromRegion(0, 0, 1, 1, 21, 13), 3);  // 8 × 8 tiles
  EXPECT_TRUE(wholeTile(g, 0, 7, 0, 7));
  EXPECT_TRUE(wholeTile(g, 8, 15, 8, 12));   // last row of tiles: lines 8..12 only
  EXPECT_TRUE(wholeTile(g, 16, 20, 0, 7));   // last column: lines 16..20
  EXPECT_TRUE(wholeTile(g, 16, 20, 8, 12));  // the corner
  EXPECT_FALSE(wholeTile(g, 0, 6, 0, 7));    // a line short
  EXPECT_FALSE(wholeTile(g, 1, 7, 0, 7));
  EXPECT_FALSE(wholeTile(g, 0, 7, 0, 6));
  EXPECT_FALSE(wholeTile(g, 16, 19, 8, 12));
  EXPECT_FALSE(wholeTile(g, 8, 15, 8, 11));
  // every rectangle of lines inside one tile: whole exactly when it holds all the tile's lines
  for (int tx = 0; tx < g.tiles_x; ++tx)
    for (int ty = 0; ty < g.tiles_y; ++ty) {
      const int x0 = tx * 8, x1 = std::min(x0 + 7, g.nx - 1), y0 = ty * 8,
                y1 = std::min(y0 + 7, g.ny - 1);
      for (int a = x0; a <= x1; ++a)
        for (int b = a; b <= x1; ++b)
          for (int c = y0; c <= y1; ++c)
            for (int d = c; d <= y1; ++d)
              ASSERT_EQ(wholeTile(g, a, b, c, d), a == x0 && b == x1 && c == y0 && d == y1)
                  << a << "-" << b << " × " << c << "-" << d;
    }
}

}  // namespace
}  // namespace fieldpath::zbuffer
