/// The motions between postures, checked against closed forms where the minimum lies between the
/// postures: an axis swung through a post about a steady tip, a shank passing a rod at every
/// facet's angle (never optimistic: the faceted tool is inside the true one), a motion coming
/// under the required clearance while its postures keep it. (A test audit: every motion test
/// moved an upright tool in a straight line, so the turn's share of the sweep and the chordal
/// error of the samples could be dropped unseen.)
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "fieldpath/geometry/tool_model.h"
#include "fieldpath/pathgen/clearance.h"
#include "fixtures.h"

using namespace fieldpath;
using namespace fieldpath::pathgen;
using geometry::Posture;
using pathgen::test::boxMesh;

namespace {

constexpr double kChordMm = 0.02;  // the tool mesh's chordal tolerance, as the commands use

Posture posture(const Eigen::Vector3d& tip, const Eigen::Vector3d& axis) {
  return {tip, axis.normalized(), 0.0, false};
}

}  // namespace

// The tip held, the axis swung from vertical to 40° about y: halfway, at 20°, the shank passes
// through a 1 mm post 30 mm up the axis; at both ends the shank is 30 sin 20° - 0.71 - 3 ≈ 6.5 mm
// from it. The motion's sweep is the turn's (the tip moves 0): the motion collides.
TEST(Motions, AnAxisSwungThroughAPostAboutASteadyTipCollides) {
  const double rad = 20.0 * M_PI / 180.0;
  const Eigen::Vector3d post = 30.0 * Eigen::Vector3d(std::sin(rad), 0, std::cos(rad));
  const geometry::TriangleMesh mesh =
      boxMesh(post.x() - 0.5, post.x() + 0.5, -0.5, 0.5, post.z() - 0.5, post.z() + 0.5);
  const geometry::ToolSpec tool{geometry::ToolShape::Ball, 3.0, 0.0, 40.0};
  const ClearanceChecker checker(geometry::toolMesh(tool, {}, kChordMm), {&mesh, 1}, kChordMm);
  const std::vector<Posture> swing = {
      posture(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ()),
      posture(Eigen::Vector3d::Zero(), Eigen::Vector3d(std::sin(2 * rad), 0, std::cos(2 * rad)))};
  const ClearanceResult ends = checker.check(swing);
  ASSERT_EQ(ends.colliding, 0u);
  EXPECT_GT(ends.min_clearance_mm, 6.0);
  MotionRequest request;
  request.required_mm = 0.5;
  const MotionResult motions = checker.checkMotions(swing, request);
  EXPECT_EQ(motions.colliding, 1u);
  EXPECT_EQ(motions.first_colliding, 0u);
}

// A vertical tool passing a thin upright rod: the closest approach, halfway, is the rod's distance
// from the axis less the shank's radius, exactly (a = 4.02 mm: 1.02 mm). Turned to every angle of
// a facet, the motion's minimum is never above it (the facets lie inside the true shank: a sample
// read between two vertices is farther by up to the chordal error, which is subtracted) and
// within the chordal error and the refinement's slack below it.
TEST(Motions, AMotionsMinimumIsNeverAboveTheTrueClearance) {
  const geometry::ToolSpec tool{geometry::ToolShape::Ball, 3.0, 0.0, 40.0};
  const geometry::TriangleMesh tool_mesh = geometry::toolMesh(tool, {}, kChordMm);
  const double a = 4.02, exact = a - 3.0;
  MotionRequest request;
  request.required_mm = 0.5;
  int sagging = 0;  // angles where a facet, not a vertex, faces the rod
  for (int k = 0; k < 24; ++k) {
    const double phi = k * 1.5 * M_PI / 180.0;
    const Eigen::Vector3d out(std::cos(phi), std::sin(phi), 0),
        along(-std::sin(phi), std::cos(phi), 0);
    // The rod: 0.1 mm square, from z 5 to 15 (along the shank), its near face at a from the axis.
    geometry::TriangleMesh rod = boxMesh(a, a + 0.1, -0.05, 0.05, 5, 15);
    for (Eigen::Vector3d& v : rod.vertices)
      v = Eigen::Vector3d(v.x() * out + v.y() * along) + Eigen::Vector3d(0, 0, v.z());
    const ClearanceChecker checker(tool_mesh, {&rod, 1}, kChordMm);
    const std::vector<Posture> pass = {posture(-10.0 * along, Eigen::Vector3d::UnitZ()),
                                       posture(10.0 * along, Eigen::Vector3d::UnitZ())};
    const MotionResult m = checker.checkMotions(pass, request);
    EXPECT_EQ(m.colliding, 0u) << k;
    EXPECT_LE(m.min_clearance_mm, exact + 1e-9) << k;
    EXPECT_GE(m.min_clearance_mm, exact - kChordMm - 0.011) << k;
    const Posture mid = posture(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ());
    sagging += checker.check(std::vector<Posture>{mid}).min_clearance_mm > exact - kChordMm + 0.005;
  }
  // The angles cover facets' middles too (else the subtraction is not what this reads).
  EXPECT_GT(sagging, 0);
}

// Postures 2.9 mm clear of a ridge, the straight move between them 0.3 mm over it: the motion is
// under the required clearance (0.5 mm) and not colliding; required 0.2 mm, it is not under.
TEST(Motions, AMotionUnderTheRequiredClearanceBetweenClearPosturesIsCounted) {
  const geometry::TriangleMesh ridge = boxMesh(4.9, 5.1, -20, 20, -10, 10);
  const geometry::ToolSpec tool{geometry::ToolShape::Ball, 3.0, 0.0, 20.0};
  const ClearanceChecker checker(geometry::toolMesh(tool, {}, kChordMm), {&ridge, 1}, kChordMm);
  const std::vector<Posture> over = {
      posture(Eigen::Vector3d(0, 0, 10.3), Eigen::Vector3d::UnitZ()),
      posture(Eigen::Vector3d(10, 0, 10.3), Eigen::Vector3d::UnitZ())};
  ASSERT_GT(checker.check(over).min_clearance_mm, 2.5);
  MotionRequest request;
  request.required_mm = 0.5;
  const MotionResult under = checker.checkMotions(over, request);
  EXPECT_EQ(under.colliding, 0u);
  EXPECT_EQ(under.under_required, 1u);
  EXPECT_EQ(under.first_under_required, 0u);
  EXPECT_LE(under.min_clearance_mm, 0.3 + 1e-9);
  EXPECT_GE(under.min_clearance_mm, 0.3 - kChordMm - 0.011);
  request.required_mm = 0.2;
  const MotionResult enough = checker.checkMotions(over, request);
  EXPECT_EQ(enough.under_required, 0u);
  EXPECT_GE(enough.min_clearance_mm, 0.2);
}
