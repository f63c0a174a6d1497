#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "fieldpath/common/errors.h"
#include "fieldpath/geometry/mesh.h"
#include "fieldpath/geometry/tool_model.h"

using namespace fieldpath::geometry;
using fieldpath::common::InputError;

namespace {

constexpr double kPi = std::numbers::pi;

/// Every tool body is a torus-ended cylinder: corner radius r (r = R: ball, r = 0: flat), corner
/// centre circle c = R - r, cylinder to L, flat top.
struct Analytic {
  double area_mm2, volume_mm3, mean_curvature_integral_mm;
};

Analytic analytic(const ToolSpec& t) {
  const double big_r = t.radius_mm, len = t.length_mm;
  const double r = t.shape == ToolShape::Ball    ? big_r
                   : t.shape == ToolShape::Torus ? t.corner_radius_mm
                                                 : 0.0;
  const double c = big_r - r;
  Analytic a;
  // bottom disc + corner (quarter torus) + cylinder + top disc
  a.area_mm2 = kPi * c * c + 2 * kPi * r * (c * kPi / 2 + r) + 2 * kPi * big_r * (len - r) +
               kPi * big_r * big_r;
  a.volume_mm3 =
      kPi * (c * c * r + kPi * c * r * r / 2 + 2 * r * r * r / 3) + kPi * big_r * big_r * (len - r);
  // ∫H dA: corner π(cπ/2 + 2r) (for r = 0 this is the bottom rim edge), cylinder π(L - r), top rim
  // π²R/2.
  a.mean_curvature_integral_mm =
      kPi * (c * kPi / 2 + 2 * r) + kPi * (len - r) + kPi * kPi * big_r / 2;
  return a;
}

std::vector<ToolSpec> sampleTools() {
  return {parseToolSpec("ball:3"),      parseToolSpec("ball:3:3"),  parseToolSpec("torus:5:1:25"),
          parseToolSpec("torus:2:2:8"), parseToolSpec("flat:4:10"), parseToolSpec("ball:0.5:30")};
}

}  // namespace

TEST(ToolModel, ParseToolSpec) {
  const ToolSpec b = parseToolSpec("ball:3");
  EXPECT_EQ(b.shape, ToolShape::Ball);
  EXPECT_EQ(b.radius_mm, 3.0);
  EXPECT_EQ(b.length_mm, 12.0);
  const ToolSpec t = parseToolSpec("torus:5:1.5:30");
  EXPECT_EQ(t.shape, ToolShape::Torus);
  EXPECT_EQ(t.corner_radius_mm, 1.5);
  EXPECT_EQ(t.length_mm, 30.0);
  EXPECT_EQ(parseToolSpec("flat:2:7").length_mm, 7.0);
  for (const char* bad :
       {"", "ball", "ball:", "ball:-1", "ball:0", "ball:3:2", "ball:3:x", "ball:3:12:1", "torus:3",
        "torus:3:4", "torus:3:0", "cone:3", "flat:nan", "flat:inf", "ball:1e999"}) {
    EXPECT_THROW(parseToolSpec(bad), InputError) << bad;
  }
  // Blanks around a number are spacing (`40:6 ,55:6` was refused as "'6 ' is not a number").
  EXPECT_EQ(parseToolSpec("ball:3 ").radius_mm, 3.0);
  EXPECT_EQ(parseHolderProfile("40:6 , 55:6").size(), 2u);
}

TEST(ToolModel, ParseHolderProfile) {
  const HolderProfile h = parseHolderProfile("40:6,55:6,55:12,90:12");
  ASSERT_EQ(h.size(), 4u);
  EXPECT_EQ(h[2].z_mm, 55.0);
  EXPECT_EQ(h[2].radius_mm, 12.0);
  EXPECT_TRUE(parseHolderProfile("").empty());
  for (const char* bad : {"40", "40:6", "40:6,30:8", "40:6,40:6", "40:0,50:6", "40:6,,50:6",
                          "a:b,1:2", "40:6:1,50:2"})
    EXPECT_THROW(parseHolderProfile(bad), InputError) << bad;
}

TEST(ToolModel, DistanceToAnalyticSurfaceClosedForm) {
  const ToolSpec ball = parseToolSpec("ball:3:12");
  EXPECT_NEAR(toolSurfaceDistance(ball, Vec3(0, 0, 0)), 0.0, 1e-15);
  EXPECT_NEAR(toolSurfaceDistance(ball, Vec3(0, 0, 3)), 3.0, 1e-15);   // ball centre
  EXPECT_NEAR(toolSurfaceDistance(ball, Vec3(0, 0, -1)), 1.0, 1e-15);  // below the tip
  EXPECT_NEAR(toolSurfaceDistance(ball, Vec3(0, 5, 8)), 2.0, 1e-15);   // beside the shank
  EXPECT_NEAR(toolSurfaceDistance(ball, Vec3(0, 0, 13)), 1.0, 1e-15);  // above the top
  EXPECT_NEAR(toolSurfaceDistance(ball, Vec3(4, 0, 13)), std::sqrt(2.0), 1e-15);  // off the rim
  const ToolSpec torus = parseToolSpec("torus:5:1:20");
  EXPECT_NEAR(toolSurfaceDistance(torus, Vec3(2, 0, -0.5)), 0.5, 1e-15);  // below the flat bottom
  EXPECT_NEAR(toolSurfaceDistance(torus, Vec3(4, 0, 1)), 1.0, 1e-15);     // corner centre circle
}

TEST(ToolModel, MeshesAreClosedAndWithinTolerance) {
  for (const ToolSpec& tool : sampleTools()) {
    for (double tol : {0.05, 0.01, 0.001}) {
      SCOPED_TRACE(testing::Message()
                   << "R " << tool.radius_mm << " shape " << int(tool.shape) << " tol " << tol);
      const TriangleMesh mesh = toolMesh(tool, {}, tol);
      const MeshReport report = validateMesh(mesh);
      ASSERT_TRUE(report.closed()) << report.summary();

      // Vertices on the surface; every point of a barycentric grid (centroid and edge midpoints
      // included) within the tolerance.
      double max_vertex_mm = 0, max_interior_mm = 0;
      for (const auto& v : mesh.vertices)
        max_vertex_mm = std::max(max_vertex_mm, toolSurfaceDistance(tool, v));
      for (const auto& t : mesh.triangles) {
        const Vec3 &a = mesh.vertices[t[0]], &b = mesh.vertices[t[1]], &c = mesh.vertices[t[2]];
        max_interior_mm = std::max(max_interior_mm, toolSurfaceDistance(tool, (a + b + c) / 3));
        constexpr int n = 4;
        for (int i = 0; i <= n; ++i)
          for (int j = 0; i + j <= n; ++j)
            max_interior_mm = std::max(
                max_interior_mm, toolSurfaceDistance(tool, a + (i * (b - a) + j * (c - a)) / n));
      }
      EXPECT_LT(max_vertex_mm, 1e-12);
      EXPECT_LE(max_interior_mm, tol);
      EXPECT_GT(max_interior_mm, 0.1 * tol);  // not needlessly fine

      // Convex body, inscribed polytope P with Hausdorff distance ≤ tol: P ⊂ K ⊂ P ⊕ B(tol), so
      // 0 ≤ V_K − V_P ≤ tol·A_K + tol²·M + 4π/3 tol³ and 0 ≤ A_K − A_P ≤ 2 tol·M + 4π tol²
      // (Steiner's formula; M = ∫H dA of K ≥ that of P).
      const Analytic exact = analytic(tool);
      const double dv = exact.volume_mm3 - meshVolume(mesh), da = exact.area_mm2 - meshArea(mesh);
      const double m = exact.mean_curvature_integral_mm;
      EXPECT_GE(dv, -1e-9 * exact.volume_mm3);
      EXPECT_LE(dv, tol * exact.area_mm2 + tol * tol * m + 4 * kPi / 3 * tol * tol * tol);
      EXPECT_GE(da, -1e-9 * exact.area_mm2);
      EXPECT_LE(da, 2 * tol * m + 4 * kPi * tol * tol);
    }
  }
}

TEST(ToolModel, TipIsOneVertexOnTheAxisWithoutDegenerateTriangles) {
  for (const ToolSpec& tool : sampleTools()) {
    const TriangleMesh mesh = toolMesh(tool, {}, 0.01);
    const auto on_axis = std::count_if(mesh.vertices.begin(), mesh.vertices.end(),
                                       [](const Vec3& v) { return v.x() == 0 && v.y() == 0; });
    EXPECT_EQ(on_axis, 2);  // tip and top centre
    EXPECT_EQ(std::count(mesh.vertices.begin(), mesh.vertices.end(), Vec3::Zero()), 1);
    EXPECT_EQ(validateMesh(mesh).degenerate_triangles, 0u);
  }
}

TEST(ToolModel, HolderJoinsTheToolIntoOneClosedSolid) {
  const ToolSpec tool = parseToolSpec("ball:3:40");
  // Stepped holder from the scene example, and one that starts above the tool (shank runs on).
  for (const char* text : {"40:6,55:6,55:12,90:12", "45:8,60:10,80:10"}) {
    const HolderProfile holder = parseHolderProfile(text);
    const TriangleMesh mesh = toolMesh(tool, holder, 0.01);
    const MeshReport report = validateMesh(mesh);
    EXPECT_TRUE(report.closed()) << text << ": " << report.summary();
    // Volume: between the inscribed prism approximation and the exact revolved solid.
    const double r = 3, shank_top = holder.front().z_mm;
    double exact_mm3 = 2 * kPi / 3 * r * r * r + kPi * r * r * (shank_top - r);
    for (std::size_t i = 0; i + 1 < holder.size(); ++i) {
      const double h = holder[i + 1].z_mm - holder[i].z_mm, a = holder[i].radius_mm,
                   b = holder[i + 1].radius_mm;
      exact_mm3 += kPi * h * (a * a + a * b + b * b) / 3;  // frustum
    }
    EXPECT_LT(meshVolume(mesh), exact_mm3);
    EXPECT_GT(meshVolume(mesh), exact_mm3 * (1 - 1e-3));
    double top = 0;
    for (const auto& v : mesh.vertices) top = std::max(top, v.z());
    EXPECT_EQ(top, holder.back().z_mm);
  }
  EXPECT_THROW(toolMesh(tool, parseHolderProfile("2:6,50:6"), 0.01),
               InputError);  // below the ball's top
}

TEST(ToolModel, HolderOverlappingTheShankIsTheUnion) {
  // ball R 3, L 40. Volumes of the union, by hand: ball end 18π, then cylinders and frustums.
  const ToolSpec tool = parseToolSpec("ball:3:40");
  struct Case {
    const char* holder;
    double volume_over_pi;
  };
  const Case cases[] = {
      {"30:6,50:6", 18 + 9 * 27 + 36 * 20},                      // holder swallows the shank top
      {"30:2,36:8,50:8", 18 + 9 * 28 + 5.0 * 97 / 3 + 64 * 14},  // cone crosses R at z 31
      {"20:5,30:5", 18 + 9 * 17 + 25 * 10 + 9 * 10},             // collar, shank and top above it
      {"30:2,40:2,50:6",
       18 + 9 * 37 + 10.0 * (4 + 12 + 36) / 3},               // narrower than R up to L, then wider
      {"35:4,40:4,40:1,45:1", 18 + 9 * 32 + 16 * 5 + 1 * 5},  // steps in to a neck at L
  };
  for (const Case& c : cases) {
    const HolderProfile holder = parseHolderProfile(c.holder);
    const TriangleMesh mesh = toolMesh(tool, holder, 0.002);
    EXPECT_TRUE(validateMesh(mesh).closed()) << c.holder << ": " << validateMesh(mesh).summary();
    for (const auto& v : mesh.vertices)
      ASSERT_LT(toolSurfaceDistance(tool, holder, v), 1e-12) << c.holder;
    const double exact = kPi * c.volume_over_pi;
    EXPECT_LT(meshVolume(mesh), exact) << c.holder;
    EXPECT_LT(exact - meshVolume(mesh), 0.002 * meshArea(mesh)) << c.holder;  // chordal shell
    for (const auto& n : surfaceNodes(tool, holder, 0.5))
      EXPECT_LT(toolSurfaceDistance(tool, holder, n.position_mm), 1e-12) << c.holder;
  }
}

TEST(ToolModel, HolderMeshesWithinTolerance) {
  // Steps, a steep cone from a thin neck (rings of very different sizes) and a narrowing top.
  const ToolSpec tool = parseToolSpec("torus:4:1:30");
  for (const char* text : {"30:6,45:6,45:12,90:12", "30:1,32:1,40:16,60:16,70:5"}) {
    const HolderProfile holder = parseHolderProfile(text);
    for (double tol : {0.05, 0.002}) {
      SCOPED_TRACE(testing::Message() << text << " tol " << tol);
      const TriangleMesh mesh = toolMesh(tool, holder, tol);
      EXPECT_TRUE(validateMesh(mesh).closed()) << validateMesh(mesh).summary();
      double max_mm = 0;
      for (const auto& v : mesh.vertices) EXPECT_LT(toolSurfaceDistance(tool, holder, v), 1e-12);
      for (const auto& t : mesh.triangles) {
        const Vec3 &a = mesh.vertices[t[0]], &b = mesh.vertices[t[1]], &c = mesh.vertices[t[2]];
        for (const Vec3& p :
             {Vec3((a + b + c) / 3), Vec3((a + b) / 2), Vec3((b + c) / 2), Vec3((c + a) / 2)})
          max_mm = std::max(max_mm, toolSurfaceDistance(tool, holder, p));
      }
      EXPECT_LE(max_mm, tol);
    }
  }
}

TEST(ToolModel, BadToleranceIsInputError) {
  for (double tol : {0.0, -1.0, std::nan(""), HUGE_VAL})
    EXPECT_THROW(toolMesh(parseToolSpec("ball:3"), {}, tol), InputError) << tol;
  // Absurdly fine: refused up front instead of exhausting memory.
  EXPECT_THROW(toolMesh(parseToolSpec("ball:3"), {}, 1e-12), InputError);
  EXPECT_THROW(surfaceNodes(parseToolSpec("ball:3"), {}, 1e-6), InputError);
  EXPECT_THROW(surfaceNodes(parseToolSpec("ball:3"), {}, 0.0), InputError);
}

TEST(ToolModel, SurfaceNodesLieOnTheSurfaceAboutSpacingApart) {
  for (const ToolSpec& tool : sampleTools()) {
    for (double spacing : {0.25, 1.0}) {
      SCOPED_TRACE(testing::Message() << "R " << tool.radius_mm << " spacing " << spacing);
      const auto nodes = surfaceNodes(tool, {}, spacing);
      ASSERT_FALSE(nodes.empty());
      for (const auto& n : nodes) {
        EXPECT_LT(toolSurfaceDistance(tool, n.position_mm), 1e-12);
        EXPECT_NEAR(n.normal.norm(), 1.0, 1e-12);
        EXPECT_EQ(n.part, NodePart::Tool);
        // Outward: a step along the normal leaves the body (distance grows as the step).
        EXPECT_NEAR(toolSurfaceDistance(tool, n.position_mm + 1e-3 * n.normal), 1e-3, 1e-9);
      }
      // The tip is a node.
      EXPECT_TRUE(std::any_of(nodes.begin(), nodes.end(),
                              [](const SurfaceNode& n) { return n.position_mm == Vec3::Zero(); }));
      // Coverage: random points of the analytic surface (from a fine mesh) are within `spacing` of
      // a node.
      const TriangleMesh fine = toolMesh(tool, {}, 1e-3);
      std::mt19937 rng(7);
      std::uniform_int_distribution<std::size_t> pick(0, fine.vertices.size() - 1);
      for (int t = 0; t < 300; ++t) {
        const Vec3& p = fine.vertices[pick(rng)];
        double nearest = HUGE_VAL;
        for (const auto& n : nodes) nearest = std::min(nearest, (n.position_mm - p).norm());
        EXPECT_LE(nearest, spacing);
      }
      // Density: about one node per spacing² of area.
      const double expected = analytic(tool).area_mm2 / (spacing * spacing);
      EXPECT_GT(nodes.size(), 0.7 * expected);
      EXPECT_LT(nodes.size(), 2.0 * expected);
    }
  }
}

TEST(ToolModel, HolderNodesAreMarked) {
  const ToolSpec tool = parseToolSpec("ball:3:40");
  const auto nodes = surfaceNodes(tool, parseHolderProfile("40:6,55:6,55:12,90:12"), 1.0);
  std::size_t holder_nodes = 0;
  for (const auto& n : nodes) {
    EXPECT_LT(toolSurfaceDistance(tool, parseHolderProfile("40:6,55:6,55:12,90:12"), n.position_mm),
              1e-12);
    if (n.part == NodePart::Tool) {
      EXPECT_LE(n.position_mm.z(), 40.0);
      EXPECT_LT(toolSurfaceDistance(tool, n.position_mm), 1e-12);
    } else {
      ++holder_nodes;
      EXPECT_GE(n.position_mm.z(), 40.0);
    }
  }
  EXPECT_GT(holder_nodes, 1000u);  // holder area ≈ 2π(6·15 + 12·35) + ... ≈ 3.7e3 mm²
}
