/// Passes with corners (the feed turning over 20 deg within 2 mm): steered in DESIGN's frame, and
/// with the axis held through the corners where that frame comes under the clearance or swings
/// the axis over 10 deg in a step (split from test_generate.cpp).
#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "fieldpath/geometry/tool_model.h"
#include "fieldpath/pathgen/generate.h"
#include "fixtures.h"

using namespace fieldpath;
using namespace fieldpath::pathgen;

namespace {

/// The largest turn of the axis between two consecutive postures, deg.
double largestTurnDeg(const GenerateResult& r) {
  double largest = 0.0;
  for (std::size_t i = 1; i < r.postures.size(); ++i)
    largest = std::max(
        largest, geometry::axisAngle(r.postures[i].posture.axis, r.postures[i - 1].posture.axis));
  return largest * 180.0 / M_PI;
}

/// A wall at y 4.5-8.5 beside a floor machined at z = 0 (a pass along it at y = 0 keeps 1.5 mm
/// from the ball); the steered postures, not the nominal ones a colliding pass keeps.
GenerateRequest besideAWall() {
  GenerateRequest job;
  job.tool = {geometry::ToolShape::Ball, 3.0, 0.0, 15.0};
  job.holder = {{15, 6}, {30, 6}, {30, 12}, {70, 12}};
  job.mode = FieldMode::Direct;
  job.field.sample_step_mm = 1.0;
  job.obstacles = {test::boxMesh(-10, 60, 4.5, 8.5, -1, 30)};
  job.part = test::boxMesh(-10, 60, -40, 4.5, -5, 0);
  job.passes_only = true;
  return job;
}

}  // namespace

// A pass along a wall (its side 1.5 mm from the ball, the holder's r 6 over it: the axis leans
// away) that turns 90 deg away from it at x = 40. Held in the turning frame, the tilt leaning
// away from the wall leaned the axis along it, the field kicked, and the axis swung 19.5 deg in
// one 0.5 mm step, the holder 2.3 mm into the wall (a helper's pocket corner, UNSAFE). That
// coming under the clearance, the pass is steered again with the feed held through its corners
// and the angles re-expressed after (the clearer kept): clear, the axis turning under 10 deg a
// posture (a machine's rotary axes follow at feed). So through a corner filleted
// R 2 (it turns 9 deg a 0.5 mm: 2 colliding postures held in the turning frame).
TEST(GenerateCorners, CornersAreHeldWhereTheFeedsFrameComesUnderOrSwingsAndHeldIsClear) {
  GenerateRequest job = besideAWall();
  for (const double fillet_mm : {0.0, 2.0}) {  // sharp, and filleted (R 2, 0.2 mm steps)
    std::vector<geometry::Posture> nominal;
    const auto add = [&nominal](double x, double y) {
      nominal.push_back({Vec3(x, y, 0), Vec3::UnitZ(), 0.0, false});
    };
    for (double x = 0.0; x < 40.0 - fillet_mm - 1e-9; x += 0.5) add(x, 0.0);
    for (int k = 0; k <= 16; ++k) {  // the fillet's arc (one point where sharp)
      const double a = 0.5 * M_PI * k / 16;
      add(40.0 - fillet_mm + fillet_mm * std::sin(a), -fillet_mm + fillet_mm * std::cos(a));
      if (fillet_mm == 0.0) break;
    }
    for (double y = fillet_mm + 0.5; y <= 30.0 + 1e-9; y += 0.5) add(40.0, -y);
    job.passes = nominalPasses(geometry::singlePass(std::move(nominal)), PathParams{}, 3.0);
    ASSERT_EQ(job.passes.size(), 1u);
    const GenerateResult r = generatePath(job);
    EXPECT_EQ(r.clearance.colliding, 0u) << fillet_mm;
    EXPECT_EQ(r.motions.colliding, 0u) << fillet_mm;
    EXPECT_GE(r.clearance.min_clearance_mm, job.clearance_mm) << fillet_mm;
    EXPECT_LT(largestTurnDeg(r), 10.0) << fillet_mm;
    EXPECT_EQ(r.corners_held, std::vector<int>{0}) << fillet_mm;
  }
  // Round a boss's convex corner (the pass turning toward the block it leans from): the axis
  // turning with the feed keeps the lean away from the block's second face, 1.48 mm, but swings
  // 19.1 deg in one 0.5 mm step; held, it keeps 0.88 mm, turning under 6 deg a posture: kept
  // held, being clear. Where the clearance asks for more than the held run keeps (1 mm), the
  // feed's frame is kept, swing and all (every corner held regardless, a reviewer's 150 deg turn
  // had 50 colliding postures).
  job.obstacles = {test::boxMesh(-10, 40, 4.5, 34.5, -1, 30)};
  std::vector<geometry::Posture> round_boss;
  for (double x = 0.0; x < 44.5 - 1e-9; x += 0.5)
    round_boss.push_back({Vec3(x, 0, 0), Vec3::UnitZ(), 0.0, false});
  for (double y = 0.0; y <= 30.0 + 1e-9; y += 0.5)
    round_boss.push_back({Vec3(44.5, y, 0), Vec3::UnitZ(), 0.0, false});
  job.passes = nominalPasses(geometry::singlePass(std::move(round_boss)), PathParams{}, 3.0);
  const GenerateResult boss = generatePath(job);
  EXPECT_EQ(boss.clearance.colliding, 0u);
  EXPECT_GE(boss.clearance.min_clearance_mm, job.clearance_mm);
  EXPECT_LT(largestTurnDeg(boss), 10.0);
  EXPECT_EQ(boss.corners_held, std::vector<int>{0});
  job.clearance_mm = 1.0;
  const GenerateResult wide = generatePath(job);
  EXPECT_GE(wide.clearance.min_clearance_mm, 1.4);
  EXPECT_GT(largestTurnDeg(wide), 10.0);
  EXPECT_TRUE(wide.corners_held.empty());
}

// A jog of 0.5 mm in a pass beside a wall (one posture sideways, then on): the feed turns 45 deg
// and back within a posture, and in DESIGN's frame the axis, leaning 26 deg away from the wall,
// turned with it: 11.7 deg in a 0.5 mm step (the rotary axes asked for ~400 deg/s at 1000 mm/min),
// clear all the same. The pass is steered again with the corner held and, clear too, kept for
// its smaller turns.
TEST(GenerateCorners, AJogBesideAWallIsHeldWhereTheFeedsFrameSwingsTheAxis) {
  GenerateRequest job = besideAWall();
  std::vector<geometry::Posture> nominal;
  for (double x = 0.0; x < 20.0 - 1e-9; x += 0.5)
    nominal.push_back({Vec3(x, 0, 0), Vec3::UnitZ(), 0.0, false});
  for (double x = 20.0; x <= 45.0 + 1e-9; x += 0.5)
    nominal.push_back({Vec3(x, -0.5, 0), Vec3::UnitZ(), 0.0, false});
  job.passes = nominalPasses(geometry::singlePass(std::move(nominal)), PathParams{}, 3.0);
  const GenerateResult r = generatePath(job);
  EXPECT_EQ(r.corners_held, std::vector<int>{0});
  EXPECT_EQ(r.clearance.colliding, 0u);
  EXPECT_GE(r.clearance.min_clearance_mm, 1.4);
  EXPECT_LT(largestTurnDeg(r), 1.0);  // 11.7 deg turning with the feed
}
