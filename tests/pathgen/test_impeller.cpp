#include <cmath>

#include <gtest/gtest.h>

#include "fieldpath/common/errors.h"
#include "fieldpath/geometry/mesh.h"
#include "fieldpath/pathgen/impeller.h"
#include "fixtures.h"

using namespace fieldpath;
using pathgen::Impeller;
using pathgen::ImpellerParams;
using pathgen::Vec3;

// Closed form first: a straight, flat, parallel channel is a plane strip between vertical walls.
TEST(Impeller, FlatChannelIsClosedForm) {
  ImpellerParams p = pathgen::test::flatChannel();
  const Impeller imp(p);
  EXPECT_NEAR((imp.hub(0.5, 0.25) - Vec3(36, -5, 0)).norm(), 0, 1e-12);
  EXPECT_NEAR((imp.hubNormal(0.3, 0.7) - Vec3::UnitZ()).norm(), 0, 1e-12);
  EXPECT_NEAR((imp.blade(0, 0.5, 1.0) - Vec3(36, -10, p.blade_height_mm)).norm(), 0, 1e-12);
  EXPECT_NEAR((imp.bladeNormal(0, 0.5, 0.5) - Vec3::UnitY()).norm(), 0, 1e-9);
  EXPECT_NEAR((imp.bladeNormal(1, 0.5, 0.5) + Vec3::UnitY()).norm(), 0, 1e-9);
  EXPECT_NEAR(imp.minGapMm(), 20.0, 1e-9);
  EXPECT_NEAR(geometry::meshArea(imp.hubMesh()), 72.0 * 20.0, 1e-9);
  EXPECT_NEAR(geometry::meshArea(imp.bladeMesh(0)), 72.0 * p.blade_height_mm, 1e-9);
}

TEST(Impeller, HubIsAHeightFieldWithConsistentNormals) {
  const Impeller imp{ImpellerParams{}};
  for (double u : {0.0, 0.3, 0.77, 1.0}) {
    for (double v : {0.0, 0.2, 0.5, 1.0}) {
      const Vec3 s = imp.hub(u, v);
      EXPECT_NEAR(imp.hubHeight(s.x(), s.y()), s.z(), 1e-12);
      const Vec3 n = imp.hubNormal(u, v);
      const double e = 1e-6;
      const Vec3 su = (imp.hub(u + e, v) - imp.hub(u - e, v)) / (2 * e);
      const Vec3 sv = (imp.hub(u, v + e) - imp.hub(u, v - e)) / (2 * e);
      EXPECT_NEAR(n.norm(), 1.0, 1e-12);
      EXPECT_NEAR(n.dot(su) / su.norm(), 0.0, 1e-7);
      EXPECT_NEAR(n.dot(sv) / sv.norm(), 0.0, 1e-7);
      EXPECT_GT(n.z(), 0.0);
    }
  }
}

TEST(Impeller, BladesStartOnTheHubAndLeanAsConfigured) {
  const Impeller imp{ImpellerParams{}};
  const auto& p = imp.params();
  for (double u : {0.0, 0.5, 1.0}) {
    for (int side : {0, 1}) {
      EXPECT_NEAR((imp.blade(side, u, 0.0) - imp.hub(u, side)).norm(), 0.0, 1e-12);
      const Vec3 ruling = (imp.blade(side, u, 1.0) - imp.blade(side, u, 0.0)) / p.blade_height_mm;
      const auto& lean = side == 0 ? p.lean_left_deg : p.lean_right_deg;
      const double lean_deg = lean[0] + (lean[1] - lean[0]) * u;
      EXPECT_NEAR(std::acos(ruling.z()) * 180 / M_PI, std::abs(lean_deg), 1e-9);
      // Leaning over the channel (> 0) moves the tip towards the other blade.
      const double towards = (imp.blade(side, u, 1.0) - imp.blade(side, u, 0.0))
                                 .dot(imp.hub(u, 1 - side) - imp.hub(u, side));
      if (lean_deg > 0) EXPECT_GT(towards, 0.0);
      if (lean_deg < 0) EXPECT_LT(towards, 0.0);
    }
  }
}

TEST(Impeller, MeshesStayWithinTheChordTolerance) {
  ImpellerParams p;
  p.chord_tol_mm = 0.02;
  const Impeller imp(p);
  const geometry::TriangleMesh hub = imp.hubMesh();
  double worst_mm = 0;
  for (const auto& t : hub.triangles) {
    const Vec3 c = (hub.vertices[t[0]] + hub.vertices[t[1]] + hub.vertices[t[2]]) / 3.0;
    worst_mm = std::max(worst_mm, std::abs(c.z() - imp.hubHeight(c.x(), c.y())));
    const Vec3 n =
        (hub.vertices[t[1]] - hub.vertices[t[0]]).cross(hub.vertices[t[2]] - hub.vertices[t[0]]);
    ASSERT_GT(n.z(), 0.0);  // normals up
  }
  EXPECT_LE(worst_mm, p.chord_tol_mm);
  EXPECT_GT(worst_mm, 0.0);
  const geometry::TriangleMesh blade = imp.bladeMesh(0);
  const auto report = geometry::validateMesh(blade);
  EXPECT_EQ(report.degenerate_triangles, 0u);
  EXPECT_EQ(report.inconsistent_edges, 0u);
  const auto& t = blade.triangles[blade.triangles.size() / 2];
  const Vec3 n = (blade.vertices[t[1]] - blade.vertices[t[0]])
                     .cross(blade.vertices[t[2]] - blade.vertices[t[0]]);
  EXPECT_GT(n.dot(imp.hub(0.5, 1) - imp.hub(0.5, 0)), 0.0);  // left blade faces the channel
}

// Sized like seed 004's case: blades ≈ 5100 points at 1 mm (area ≈ 5100 mm²).
TEST(Impeller, DefaultSizeMatchesTheSeedCase) {
  const Impeller imp{ImpellerParams{}};
  const double area = geometry::meshArea(imp.bladeMesh(0)) + geometry::meshArea(imp.bladeMesh(1));
  EXPECT_NEAR(area, 2 * 72.0 * 16.5, 150.0);
}

void expectInputError(ImpellerParams p, const std::string& key) {
  try {
    Impeller imp(p);
    FAIL() << "no error for " << key;
  } catch (const common::InputError& e) {
    EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
  }
}

TEST(Impeller, BadValuesNameTheirKey) {
  ImpellerParams p;
  p.length_mm = -1;
  expectInputError(p, "impeller.length");
  p = {};
  p.width_out_mm = NAN;
  expectInputError(p, "impeller.width_out");
  p = {};
  p.lean_left_deg = {40, 40};  // over a 22 mm channel with 34 mm blades: the tips cross
  p.lean_right_deg = {40, 40};
  expectInputError(p, "blades cross");
  p = {};
  p.passes_v = {0.0, 0.5};
  expectInputError(p, "impeller.passes_v");
  p = {};
  p.u_range = {0.6, 0.4};
  expectInputError(p, "impeller.u_range");
}

TEST(Impeller, HubUVInvertsTheParametrisation) {
  const Impeller imp{ImpellerParams{}};
  for (double u : {0.0, 0.4, 1.0})
    for (double v : {0.1, 0.5, 0.95}) {
      const Vec3 s = imp.hub(u, v);
      const auto uv = imp.hubUV(s.x(), s.y());
      EXPECT_NEAR(uv[0], u, 1e-12);
      EXPECT_NEAR(uv[1], v, 1e-12);
    }
}
