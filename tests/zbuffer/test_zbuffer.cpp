/// Z-buffer CPU reference: closed forms first (ball envelope), then an independent double-precision
/// reference for 5-axis postures, mesh tools against their analytic shape, watertightness, zoom,
/// order independence and bad input (the culling floors: test_zbuffer_culling.cpp; the output
/// files: test_zbuffer_outputs.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <omp.h>
#include <random>

#include "fieldpath/common/errors.h"
#include "fieldpath/zbuffer/engine.h"
#include "fieldpath/zbuffer/simulator.h"
#include "fieldpath/zbuffer/tool_mesh.h"
#include "reference.h"
#include "zbuffer_cases.h"

namespace fieldpath::zbuffer {
namespace {

using cases::gridBottomTool;
using cases::pose;

constexpr float kStock = 100.f;

SimulationResult runCpu(const Grid& grid, const Tool& tool, const std::vector<Posture>& postures,
                        Engine engine = Engine::Fast, std::size_t block = 1 << 20) {
  SimulationRequest req;
  req.grid = grid;
  req.tool = tool;
  req.stock_mm = kStock;
  req.backend = Backend::Cpu;
  req.engine = engine;
  req.block_postures = block;
  return simulate(req, postures);
}

test::PlacedTool placed(const Tool& tool, const Posture& p) {
  const double ax = p.axis.x, ay = p.axis.y, az = p.axis.z,
               n = std::sqrt(ax * ax + ay * ay + az * az);
  return {tool.radius_mm,
          tool.kind == ToolKind::Flat ? 0.0 : double(tool.corner_radius_mm),
          tool.length_mm,
          {p.tip_mm.x, p.tip_mm.y, p.tip_mm.z},
          {ax / n, ay / n, az / n}};
}

/// Reference height map: min over postures of the reference lowest point, stock elsewhere.
std::vector<double> referenceHeights(const Grid& g, const Tool& tool,
                                     const std::vector<Posture>& postures, double dx_off = 0,
                                     double dy_off = 0) {
  std::vector<double> h(g.lineCount(), kStock);
  for (const auto& p : postures) {
    const auto t = placed(tool, p);
    for (int iy = 0; iy < g.ny; ++iy)
      for (int ix = 0; ix < g.nx; ++ix) {
        const double x = g.x0_mm + (ix + 0.5) * g.dx_mm + dx_off,
                     y = g.y0_mm + (iy + 0.5) * g.dy_mm + dy_off;
        const double reach = std::hypot(x - t.tip[0], y - t.tip[1]);
        if (reach > t.len + t.big_r + 1) continue;
        if (auto z = test::lowestZ(t, x, y))
          h[std::size_t(iy) * g.nx + ix] = std::min(h[std::size_t(iy) * g.nx + ix], *z);
      }
  }
  return h;
}

/// Compares float heights with the reference: equal within tol, or (at a steep wall or a
/// silhouette) within the reference's range over lines moved by ±delta.
void expectMatchesReference(const Grid& g, const Tool& tool, const std::vector<Posture>& postures,
                            const std::vector<float>& got, double tol = 2e-4, double delta = 2e-4) {
  const auto ref = referenceHeights(g, tool, postures);
  std::vector<std::vector<double>> moved;
  int steep = 0, bad = 0;
  for (std::size_t i = 0; i < ref.size(); ++i) {
    if (std::abs(got[i] - ref[i]) <= tol) continue;
    if (moved.empty())
      for (auto [ox, oy] : {std::pair{delta, 0.0}, {-delta, 0.0}, {0.0, delta}, {0.0, -delta}})
        moved.push_back(referenceHeights(g, tool, postures, ox, oy));
    double lo = ref[i], hi = ref[i];
    for (const auto& m : moved) {
      lo = std::min(lo, m[i]);
      hi = std::max(hi, m[i]);
    }
    if (got[i] >= lo - tol && got[i] <= hi + tol) {
      ++steep;
      continue;
    }
    if (++bad <= 5)
      ADD_FAILURE() << "line " << i % g.nx << "," << i / g.nx << ": got " << got[i] << " reference "
                    << ref[i];
  }
  EXPECT_EQ(bad, 0);
  EXPECT_LE(steep, int(ref.size() / 50)) << "too many lines only within the neighbourhood band";
}

TEST(Rotation, FloatTwinIsOrthonormalAndMapsEz) {
  std::mt19937 rng(1);
  std::normal_distribution<double> n;
  std::vector<Vec3f> axes = {{0, 0, 1},     {0, 0, -1},     {1, 0, 0},
                             {0, 1e-9f, 1}, {1e-9f, 0, -1}, {0.6f, 0.8f, 0}};
  for (int k = 0; k < 200; ++k) axes.push_back({float(n(rng)), float(n(rng)), float(n(rng))});
  for (const auto a : axes) {
    const Mat3f r = rotationFromZ(a);
    const double len = std::sqrt(double(a.x) * a.x + double(a.y) * a.y + double(a.z) * a.z);
    for (int row = 0; row < 3; ++row) {
      EXPECT_NEAR(r.m[row][2], comp(a, row) / len, 1e-6);  // maps e_z to a
      for (int col = 0; col < 3; ++col) {
        double d = 0;
        for (int k = 0; k < 3; ++k) d += double(r.m[k][row]) * r.m[k][col];
        EXPECT_NEAR(d, row == col ? 1.0 : 0.0, 1e-6);
      }
    }
    const double det = r.m[0][0] * (r.m[1][1] * r.m[2][2] - r.m[1][2] * r.m[2][1]) -
                       r.m[0][1] * (r.m[1][0] * r.m[2][2] - r.m[1][2] * r.m[2][0]) +
                       r.m[0][2] * (r.m[1][0] * r.m[2][1] - r.m[1][1] * r.m[2][0]);
    EXPECT_NEAR(det, 1.0, 1e-6);
  }
}

TEST(Analytic, BallThreeAxisEqualsSphereClosedForm) {
  const Grid g = Grid::fromRegion(-5, -5, 5, 5, 100, 100);
  const Tool tool = Tool::ball(3, 12);
  const std::vector<Posture> postures = {pose(0.37, -0.21, 1.5, 0, 0, 1)};
  const auto got = runCpu(g, tool, postures).heights_mm;
  for (int iy = 0; iy < g.ny; ++iy)
    for (int ix = 0; ix < g.nx; ++ix) {
      const double x = g.x0_mm + (ix + 0.5) * g.dx_mm - 0.37,
                   y = g.y0_mm + (iy + 0.5) * g.dy_mm + 0.21;
      const double rho2 = x * x + y * y;
      const double want = rho2 <= 9.0 ? 1.5 + 3.0 - std::sqrt(9.0 - rho2) : kStock;
      const float h = got[std::size_t(iy) * g.nx + ix];
      if (std::abs(std::sqrt(rho2) - 3.0) < 1e-3) continue;  // the rim itself: vertical wall
      EXPECT_NEAR(h, want, 2e-5) << ix << "," << iy;
    }
}

std::vector<Posture> awkwardPostures(int random_count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Posture> p = {
      pose(0, 0, 0, 0, 0, 1),                 // vertical
      pose(3.3, -2.1, 0.4, 1e-9, 0, 1),       // 1e-9 from vertical
      pose(-3.1, 2.7, -0.3, 0, -1e-9, 1),     //
      pose(2.2, 3.1, 1.1, 1, 0.05, 1e-3),     // nearly horizontal
      pose(-2.4, -3.3, 0.7, -0.3, 1, 0.002),  //
      pose(0.5, -4.0, 2.0, 0.4, 0.3, 1),      // 5-axis tilts
  };
  for (int k = 0; k < random_count; ++k) {
    const bool three_axis = k % 2 == 0;
    p.push_back(three_axis ? pose(4 * u(rng), 4 * u(rng), u(rng), 0, 0, 1)
                           : pose(4 * u(rng), 4 * u(rng), u(rng), 0.8 * u(rng), 0.8 * u(rng), 1));
  }
  return p;
}

TEST(Analytic, BallEnvelopeMatchesReferenceFor3And5Axis) {
  const Grid g = Grid::fromRegion(-6, -6, 6, 6, 48, 48);
  const Tool tool = Tool::ball(2, 8);
  const auto postures = awkwardPostures(10, 7);
  expectMatchesReference(g, tool, postures, runCpu(g, tool, postures).heights_mm);
}

TEST(Analytic, TorusAndFlatMatchReference) {
  const Grid g = Grid::fromRegion(-6, -6, 6, 6, 40, 40);
  const auto postures = awkwardPostures(6, 11);
  for (const Tool& tool : {Tool::torus(2, 0.6, 8), Tool::flat(1.5, 6)})
    expectMatchesReference(g, tool, postures, runCpu(g, tool, postures).heights_mm);
}

// Lines apart by other steps in x and y, over a region longer in y (every grid above is square:
// a line's y taken from the x step was caught only by an app test, a mutation audit).
TEST(Analytic, NonSquareGridsMatchTheReference) {
  const Grid g = Grid::fromRegion(-6, -8, 6, 9, 48, 40);  // 0.25 mm in x, 0.425 mm in y
  ASSERT_NE(g.dx_mm, g.dy_mm);
  const auto postures = awkwardPostures(8, 5);
  for (const Tool& tool : {Tool::ball(2, 8), Tool::torus(2, 0.6, 8), Tool::flat(1.5, 6)})
    expectMatchesReference(g, tool, postures, runCpu(g, tool, postures).heights_mm);
}

TEST(Analytic, OrderAndBlocksDoNotChangeABit) {
  const Grid g = Grid::fromRegion(-6, -6, 6, 6, 64, 64);
  const Tool tool = Tool::torus(2, 0.5, 8);
  auto postures = awkwardPostures(200, 3);
  const auto a = runCpu(g, tool, postures).heights_mm;
  std::shuffle(postures.begin(), postures.end(), std::mt19937(5));
  const auto b = runCpu(g, tool, postures, Engine::Fast, 7).heights_mm;
  EXPECT_EQ(0, std::memcmp(a.data(), b.data(), a.size() * sizeof(float)));
}

// One block of 50 000 postures (a file read as one chunk): the progress moves within it, in
// order (it said 0 % until the block was cut: 35 s without a line on a 2048² grid).
TEST(Progress, MovesWithinOneBlock) {
  SimulationRequest req;
  req.grid = Grid::fromRegion(-6, -6, 6, 6, 16, 16);
  req.tool = Tool::ball(2, 8);
  req.stock_mm = kStock;
  req.backend = Backend::Cpu;
  req.block_postures = 1 << 20;
  const auto postures = awkwardPostures(50000, 3);
  req.expected_postures = postures.size();
  req.progress_piece_s = 0.0;  // pieces of 4096 postures however fast (a slow block's case)
  std::vector<double> seen;
  req.progress = [&seen](double fraction, std::string_view) {
    seen.push_back(fraction);
    return true;
  };
  simulate(req, postures);
  ASSERT_GE(seen.size(), 10u);
  EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
  EXPECT_LT(seen.front(), 0.2);
  EXPECT_EQ(seen.back(), 1.0);
}

TEST(Mesh, BallMeshWithinChordalToleranceOfAnalytic) {
  const Grid g = Grid::fromRegion(-6, -6, 6, 6, 60, 60);
  const Tool ana = Tool::ball(2, 8);
  const int around = 64, arc = 16;
  const Tool mesh = Tool::fromMesh(analyticToolMesh(ana, around, arc));
  const double eps = analyticToolMeshError(ana, around, arc);
  ASSERT_LT(eps, 0.05);
  const auto postures = awkwardPostures(8, 21);
  // Shrunk solid: radius R-ε about the same ball centre and axis, top at L-ε.
  std::vector<Posture> shrunk = postures;
  for (auto& p : shrunk) {
    const Mat3f r = rotationFromZ(p.axis);
    p.tip_mm = p.tip_mm + float(eps) * Vec3f{r.m[0][2], r.m[1][2], r.m[2][2]};
  }
  const auto h_ana = runCpu(g, ana, postures).heights_mm;
  const auto h_mesh = runCpu(g, mesh, postures).heights_mm;
  const auto h_in = runCpu(g, Tool::ball(2 - eps, 8 - 2 * eps), shrunk).heights_mm;
  const double tol = 1e-4;
  for (std::size_t i = 0; i < h_ana.size(); ++i) {
    EXPECT_GE(h_mesh[i], h_ana[i] - tol) << i;  // the mesh lies inside the solid
    EXPECT_LE(h_mesh[i], h_in[i] + tol) << i;   // and contains the solid shrunk by ε
  }
}

TEST(Mesh, FastBvhAgreesWithCoarseRasteriser) {
  const Grid g = Grid::fromRegion(-6, -6, 6, 6, 64, 64);
  const Tool mesh = Tool::fromMesh(analyticToolMesh(Tool::torus(2, 0.5, 8), 48, 8));
  const auto postures = awkwardPostures(20, 9);
  const auto fast = runCpu(g, mesh, postures, Engine::Fast).heights_mm;
  const auto coarse = runCpu(g, mesh, postures, Engine::Coarse).heights_mm;
  int differ = 0;
  for (std::size_t i = 0; i < fast.size(); ++i) differ += std::abs(fast[i] - coarse[i]) > 1e-3f;
  EXPECT_LE(differ, int(fast.size() / 200));  // only grazing lines on vertical walls may differ
}

/// A blade: a box x 0..3, y -0.5..0.5, z 0..10 (tool frame), turned by `angle` about +z. Not a
/// body of revolution: the spindle angle decides where it cuts.
ToolMesh bladeMesh(double angle_rad) {
  ToolMesh m;
  const double c = std::cos(angle_rad), s = std::sin(angle_rad);
  for (int k = 0; k < 8; ++k) {
    const double x = (k & 1) ? 3.0 : 0.0, y = (k & 2) ? 0.5 : -0.5, z = (k & 4) ? 10.0 : 0.0;
    m.vertices.push_back({float(c * x - s * y), float(s * x + c * y), float(z)});
  }
  m.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                 {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return m;
}

// The 7th column turns a mesh tool about its own axis before the axis is placed (the seed's
// "Cutting" case: a worn edge and the spindle's turn): simulate ignored it, a blade cut the same
// at 0 and at 90 degrees. Vertical at pi/2 the blade lies along +y: the line at (0, 2) is cut to
// the tip, (2, 0) is not; on tilted postures a spindle angle cuts as the mesh turned beforehand.
TEST(Mesh, TheSpindleAngleTurnsAMeshToolAboutItsAxis) {
  const Grid g = Grid::fromRegion(-4, -4, 4, 4, 80, 80);
  Posture upright = pose(0, 0, 1, 0, 0, 1);
  upright.spindle_cos = float(std::cos(std::numbers::pi / 2));
  upright.spindle_sin = 1.f;
  const auto h = runCpu(g, Tool::fromMesh(bladeMesh(0)), {upright}).heights_mm;
  const auto at = [&](double x, double y) {
    return h[std::size_t(std::floor((y + 4) / 0.1)) * 80 + std::size_t(std::floor((x + 4) / 0.1))];
  };
  EXPECT_EQ(at(0.05, 2.05), 1.f);
  EXPECT_EQ(at(2.05, 0.05), kStock);
  EXPECT_EQ(at(0.05, -0.35), kStock);  // the blade's back is at -x, 0.5 from the axis

  const float angle = 0.7f;
  auto turned = awkwardPostures(12, 29);
  for (auto& p : turned) {
    p.spindle_cos = std::cos(angle);
    p.spindle_sin = std::sin(angle);
  }
  const auto unturned = awkwardPostures(12, 29);
  for (Engine engine : {Engine::Fast, Engine::Coarse}) {
    const auto a = runCpu(g, Tool::fromMesh(bladeMesh(0)), turned, engine).heights_mm;
    const auto b = runCpu(g, Tool::fromMesh(bladeMesh(angle)), unturned, engine).heights_mm;
    const auto c = runCpu(g, Tool::fromMesh(bladeMesh(0)), unturned, engine).heights_mm;
    int differ_from_unturned = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
      EXPECT_NEAR(a[i], b[i], 1e-4) << i;  // float rounding of the turn, vertices or rotation
      differ_from_unturned += std::abs(a[i] - c[i]) > 0.01f;
    }
    EXPECT_GT(differ_from_unturned, 100);
  }
}

TEST(Mesh, LinesThroughSharedVerticesAndEdgesAreNeverMissed) {
  const Tool tool = Tool::fromMesh(gridBottomTool());
  // Lines at every quarter unit: through vertices, along edges, through diagonals.
  const Grid g = Grid::fromRegion(-4.125, -4.125, 4.125, 4.125, 33, 33);
  for (Engine engine : {Engine::Fast, Engine::Coarse})
    for (auto shift : {0.0, 0.5, 1.0}) {
      const std::vector<Posture> postures = {pose(shift, -shift, -1, 0, 0, 1)};
      const auto h = runCpu(g, tool, postures, engine).heights_mm;
      for (int iy = 0; iy < g.ny; ++iy)
        for (int ix = 0; ix < g.nx; ++ix) {
          const double x = g.x0_mm + (ix + 0.5) * g.dx_mm - shift,
                       y = g.y0_mm + (iy + 0.5) * g.dy_mm + shift;
          const bool under = std::abs(x) <= 2 && std::abs(y) <= 2;
          EXPECT_EQ(h[std::size_t(iy) * g.nx + ix], under ? -1.f : kStock)
              << "engine " << int(engine) << " line at " << x << "," << y;
        }
    }
}

TEST(Mesh, VerticalBinsEqualTheBvhBitForBit) {
  // A vertical line tests only its bin's triangles; the result must be the BVH walk's, bit for bit,
  // also for lines through the shared vertices and edges of the grid-bottom tool.
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-1, 1);
  const GridView g = detail::makeGridView(Grid::fromRegion(-1, -1, 1, 1, 4, 4));
  for (const Tool& tool : {Tool::fromMesh(gridBottomTool()),
                           Tool::fromMesh(analyticToolMesh(Tool::torus(5, 1, 25), 127, 100)),
                           Tool::fromMesh(analyticToolMesh(Tool::ball(2, 8), 32, 31))}) {
    const detail::ToolData data = detail::prepareTool(tool);
    ASSERT_GT(data.view.bins, 0);
    const PreparedPosture pp = preparePosture(g, data.view, pose(0, 0, 0, 0, 0, 1));
    ASSERT_TRUE(pp.vertical);
    const float reach = data.view.hull_radius_mm * 1.1f;
    int hits = 0;
    for (int k = 0; k < 20000; ++k) {
      Vec3f o{float(reach * u(rng)), float(reach * u(rng)), 0.f};
      if (k % 4 == 0) o = {std::round(o.x * 4) / 4, std::round(o.y * 4) / 4, 0.f};  // on edges
      const float bvh = meshEntry(data.view, pp, o, FLT_MAX);
      const float binned = binnedEntry(data.view, pp, o);
      ASSERT_EQ(std::memcmp(&bvh, &binned, 4), 0)
          << o.x << "," << o.y << ": " << bvh << " vs " << binned;
      hits += bvh != FLT_MAX;
    }
    EXPECT_GT(hits, 5000);
  }
}

/// Roughing-like postures: vertical, z-levels top down, plus the awkward ones.
std::vector<Posture> roughingPostures(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Posture> p = awkwardPostures(100, seed);
  for (int level = 0; level < 5; ++level)
    for (int k = 0; k < 200; ++k)
      p.push_back(pose(4 * u(rng), 4 * u(rng), 1.5 - 0.5 * level + 0.1 * u(rng), 0, 0, 1));
  return p;
}

TEST(Tuning, EveryVariantGivesTheSameBits) {
  // The tuning knobs change the order, the culling and the triangle look-up, never a height.
  const Grid g = Grid::fromRegion(-6, -6, 6, 6, 64, 64);
  const auto postures = roughingPostures(23);
  const Tool tool = Tool::fromMesh(analyticToolMesh(Tool::torus(2, 0.5, 8), 40, 6));
  std::vector<float> first;
  for (int variant = 0; variant < 8; ++variant) {
    SimulationRequest req;
    req.grid = g;
    req.tool = tool;
    req.stock_mm = kStock;
    req.backend = Backend::Cpu;
    req.tuning.vertical_bins = variant & 1;
    req.tuning.lowest_first = variant & 2;
    req.tuning.tile_skip = variant & 4;
    req.tuning.tile_shift = 2 + variant % 3;
    req.tuning.prepass_stride = variant % 2 ? 0 : 3 + variant;
    req.tuning.capsule_floor = variant % 3 != 1;
    req.tuning.live_tiles = variant % 4 != 2;
    req.block_postures = variant == 3 || variant == 6 ? 97 : 1 << 20;
    const auto h = simulate(req, postures).heights_mm;
    if (first.empty()) first = h;
    ASSERT_EQ(std::memcmp(first.data(), h.data(), 4 * h.size()), 0) << "variant " << variant;
  }
}

TEST(Tool, ReachIsTheRadiusThatHoldsTheTool) {
  EXPECT_EQ(toolReach(Tool::torus(3, 1, 12)), 3.0);
  // a revolved mesh's vertices lie on the profile: the largest radius is the tool's
  const Tool mesh = Tool::fromMesh(analyticToolMesh(Tool::ball(2, 8), 32, 31));
  EXPECT_NEAR(toolReach(mesh), 2.0, 1e-6);
  EXPECT_NEAR(toolReach(Tool::fromMesh(gridBottomTool())),
              detail::prepareTool(Tool::fromMesh(gridBottomTool())).view.hull_radius_mm, 1e-5);
}

TEST(Mesh, TiltedSphereMeshHasNoHoles) {
  // Inside the silhouette (by a margin) every line must be lowered, for random tilts.
  const Tool ana = Tool::ball(2, 6);  // the shank covers the upper half of the ball
  const Tool mesh = Tool::fromMesh(analyticToolMesh(ana, 37, 11));
  const Grid g = Grid::fromRegion(-3, -3, 3, 3, 301, 301);
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Posture> p;
  for (int k = 0; k < 12; ++k) {
    const Engine engine = k % 2 ? Engine::Coarse : Engine::Fast;
    if (k % 2 == 0)
      p = {pose(0.1 * u(rng), 0.1 * u(rng), 0, u(rng), u(rng), 0.2 + std::abs(u(rng)))};
    const auto h = runCpu(g, mesh, p, engine).heights_mm;
    const Mat3f r = rotationFromZ(p[0].axis);
    const Vec3f c = p[0].tip_mm + 2.f * Vec3f{r.m[0][2], r.m[1][2], r.m[2][2]};
    int holes = 0;
    for (int iy = 0; iy < g.ny; ++iy)
      for (int ix = 0; ix < g.nx; ++ix) {
        const double x = g.x0_mm + (ix + 0.5) * g.dx_mm, y = g.y0_mm + (iy + 0.5) * g.dy_mm;
        if (std::hypot(x - c.x, y - c.y) < 1.9) holes += h[std::size_t(iy) * g.nx + ix] == kStock;
      }
    EXPECT_EQ(holes, 0) << "posture " << k / 2 << " engine " << int(engine);
  }
}

TEST(Zoom, ZoomEqualsTheSameLinesOfTheFullRun) {
  const Grid full = Grid::fromRegion(-8, -8, 8, 8, 128, 128);
  const int ix0 = 40, iy0 = 70, nx = 30, ny = 20;
  const Grid zoom = Grid::fromRegion(full.x0_mm + ix0 * full.dx_mm, full.y0_mm + iy0 * full.dy_mm,
                                     full.x0_mm + (ix0 + nx) * full.dx_mm,
                                     full.y0_mm + (iy0 + ny) * full.dy_mm, nx, ny);
  const auto postures = awkwardPostures(300, 13);
  for (const Tool& tool :
       {Tool::ball(2, 8), Tool::fromMesh(analyticToolMesh(Tool::torus(2, 0.5, 8), 40, 6))}) {
    const auto a = runCpu(full, tool, postures);
    const auto b = runCpu(zoom, tool, postures);
    EXPECT_GT(b.postures_culled,
              a.postures_culled);  // the zoom skips postures that do not reach it
    for (int iy = 0; iy < ny; ++iy)
      for (int ix = 0; ix < nx; ++ix)
        ASSERT_EQ(b.heights_mm[std::size_t(iy) * nx + ix],
                  a.heights_mm[std::size_t(iy + iy0) * full.nx + ix + ix0])
            << ix << "," << iy;
  }
}

TEST(Stock, PartTopIsTheStartingHeight) {
  const Grid g = Grid::fromRegion(0, 0, 10, 10, 20, 20);
  // a box 2..8 × 2..8, top at z = 5, bottom at z = 1 (only the top faces up)
  std::vector<Vec3f> v = {{2, 2, 5}, {8, 2, 5}, {8, 8, 5}, {2, 8, 5},
                          {2, 2, 1}, {8, 2, 1}, {8, 8, 1}, {2, 8, 1}};
  std::vector<std::array<std::uint32_t, 3>> t = {{0, 1, 2}, {0, 2, 3}, {4, 6, 5}, {4, 7, 6}};
  const auto h = stockFromPart(g, v, t);
  for (int iy = 0; iy < g.ny; ++iy)
    for (int ix = 0; ix < g.nx; ++ix) {
      // lines at 0.25, 0.75, ...: none on the box's edges
      const double x = g.x0_mm + (ix + 0.5) * g.dx_mm, y = g.y0_mm + (iy + 0.5) * g.dy_mm;
      const bool on_top = x > 2 && x < 8 && y > 2 && y < 8;
      EXPECT_EQ(h[std::size_t(iy) * g.nx + ix], on_top ? 5.f : 1.f)  // outside: the lowest z
          << ix << "," << iy;
    }
}

TEST(BadInput, RegionGridAndToolAreChecked) {
  EXPECT_THROW(Grid::fromRegion(0, 0, 0, 5, 10, 10), common::InputError);
  EXPECT_THROW(Grid::fromRegion(0, 0, 5, 5, 0, 10), common::InputError);
  EXPECT_THROW(Grid::fromRegion(0, 0, std::nan(""), 5, 10, 10), common::InputError);
  const Grid huge = Grid::fromRegion(0, 0, 1, 1, 2000000, 2000000);
  try {
    checkGridFits(huge);
    ADD_FAILURE() << "absurd grid accepted";
  } catch (const common::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("it needs about 7.45e+04 GiB of memory"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(Tool::ball(-1, 4), common::InputError);
  EXPECT_THROW(Tool::torus(2, 3, 8), common::InputError);
  EXPECT_THROW(Tool::fromMesh({}), common::InputError);
  SimulationRequest req;
  req.grid = Grid::fromRegion(0, 0, 1, 1, 4, 4);
  req.tool = Tool::ball(1, 4);
  req.engine = Engine::Coarse;
  EXPECT_THROW(simulate(req, std::span<const Posture>{}), common::InputError);
  // A NaN starting line: the CPU never lowered it, the GPU did (a reviewer's reading).
  req.engine = Engine::Fast;
  req.backend = Backend::Cpu;
  req.initial_heights_mm.assign(req.grid.lineCount(), 1.0f);
  req.initial_heights_mm[5] = std::nanf("");
  EXPECT_THROW(simulate(req, std::span<const Posture>{}), common::InputError);
  req.initial_heights_mm[5] = INFINITY;
  EXPECT_THROW(simulate(req, std::span<const Posture>{}), common::InputError);
}

}  // namespace
}  // namespace fieldpath::zbuffer

namespace fieldpath::zbuffer {
namespace {

/// auto's choice: the CPU estimate is postures × footprint lines / (5e7 × cores), the footprint
/// a disc of the tool's reach in lines (closed form), and the CPU is chosen under 0.25 s.
TEST(AutoBackend, CpuEstimateIsTheFootprintClosedForm) {
  const Tool ball = Tool::ball(3.0, 12.0);
  const Grid grid = Grid::fromRegion(0, 0, 102.4, 102.4, 1024, 1024);  // 0.1 mm lines
  const double lines = 3.14159 * 31.0 * 31.0;                         // (3 / 0.1 + 1)²
  const double cores = std::max(1, omp_get_max_threads());
  double seconds = 0;
  const bool few = cpuFinishesFirst(ball, grid, 1000, &seconds);
  EXPECT_NEAR(seconds, 1000 * lines / (5e7 * cores), 1e-9);
  EXPECT_TRUE(few);
  EXPECT_FALSE(cpuFinishesFirst(ball, grid, 27.4e6, &seconds));  // 27 M postures: the GPU
  // a footprint larger than the grid counts the grid's lines only
  const Grid tiny = Grid::fromRegion(0, 0, 1, 1, 4, 4);
  cpuFinishesFirst(ball, tiny, 1000, &seconds);
  EXPECT_NEAR(seconds, 1000 * 16 / (5e7 * cores), 1e-12);
}

}  // namespace
}  // namespace fieldpath::zbuffer
