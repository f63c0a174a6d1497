#include <cmath>

#include <gtest/gtest.h>

#include "fieldpath/common/errors.h"
#include "fieldpath/geometry/tool_model.h"
#include "fieldpath/pathgen/clearance.h"
#include "fieldpath/pathgen/generate.h"
#include "fieldpath/pathgen/link_check.h"
#include "fixtures.h"

using namespace fieldpath;
using geometry::Posture;
using geometry::TriangleMesh;
using geometry::Vec3;

namespace {

/// Closed axis-aligned box [lo, hi], outward triangles.
TriangleMesh box(const Vec3& lo, const Vec3& hi) {
  TriangleMesh m;
  for (int i = 0; i < 8; ++i)
    m.vertices.emplace_back(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(),
                            i & 4 ? hi.z() : lo.z());
  const int f[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                        {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  for (const auto& t : f) m.triangles.emplace_back(t[0], t[1], t[2]);
  return m;
}

/// A wall: the plane x = x0 as two triangles, large.
TriangleMesh wall(double x0) {
  TriangleMesh m;
  m.vertices = {{x0, -100, -100}, {x0, 100, -100}, {x0, 100, 100}, {x0, -100, 100}};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  return m;
}

}  // namespace

// FCL measures between surfaces, so an open sheet (a fin, a lone triangle) wholly inside the tool
// touches none of its triangles: it read 1.56 mm clear from inside a shank (a helper's finding).
// Inside the box tool: colliding, whichever sheet; moved beside it: the closed-form distance.
TEST(Clearance, ASheetWhollyInsideTheToolCollides) {
  const TriangleMesh tool = box(Vec3(-1, -1, 0), Vec3(1, 1, 10));
  TriangleMesh fin;  // 1 × 4 mm in the plane y = 0, 5..9 mm up, and a lone triangle by the tip
  fin.vertices = {{-0.5, 0, 5}, {0.5, 0, 5},   {0.5, 0, 9},  {-0.5, 0, 9},
                  {0, 0.5, 1},  {0.5, 0.5, 1}, {0, 0.5, 1.5}};
  fin.triangles = {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}};
  const std::vector<TriangleMesh> obstacles = {wall(-20.0), fin};
  const pathgen::ClearanceChecker checker(tool, obstacles);
  Posture inside;
  int obstacle = -1;
  EXPECT_EQ(checker.clearance(inside, &obstacle), 0.0);
  EXPECT_EQ(obstacle, 1);
  TriangleMesh triangle_only = fin;  // the lone triangle alone: the fin is not what tells
  triangle_only.triangles = {{4, 5, 6}};
  const std::vector<TriangleMesh> one = {triangle_only};
  EXPECT_EQ(pathgen::ClearanceChecker(tool, one).clearance(inside), 0.0);
  Posture beside;  // the tool 3 mm along -x: the fin's nearest point (-0.5, 0) is 1.5 from x = -2
  beside.tip_mm = Vec3(-3, 0, 0);
  EXPECT_NEAR(checker.clearance(beside), 1.5, 1e-9);
}

// A lone sliver is its longest edge (a review's needle 100 mm long and 1e-5 mm wide was left out
// of the tree: a tool through it read 199 mm clear): the box tool through it collides, beside it
// reads the closed form less the padding (at most 1 um).
TEST(Clearance, ALoneSliverIsItsLongestEdge) {
  const TriangleMesh tool = box(Vec3(-1, -1, 0), Vec3(1, 1, 10));
  TriangleMesh needle;
  needle.vertices = {{-50, 0, 5}, {50, 0, 5}, {50, 1e-5, 5}};
  needle.triangles = {{0, 1, 2}};
  const std::vector<TriangleMesh> obstacles = {needle, wall(-200.0)};
  const pathgen::ClearanceChecker checker(tool, obstacles);
  int obstacle = -1;
  EXPECT_EQ(checker.clearance(Posture{}, &obstacle), 0.0);
  EXPECT_EQ(obstacle, 0);
  Posture above;  // the tool's tip 2 mm over the needle
  above.tip_mm = Vec3(0, 0, 7);
  EXPECT_NEAR(checker.clearance(above), 2.0, 1e-3 + 1e-9);
  EXPECT_LE(checker.clearance(above), 2.0);
}

// Far from the origin (mesh files hold single precision there) every distance is lowered by √3
// float steps at the farthest point: 0.108 mm at 9e5 mm (a review's face written at 900000.03
// read 0.03 mm farther: a path 0.490 mm clear read 0.508, ok; a slanted face's three coordinates
// rounded alike, 0.022 mm more); near the origin, not at all.
TEST(Clearance, FarFromTheOriginDistancesAreLoweredByFloatSteps) {
  const TriangleMesh tool = box(Vec3(-1, -1, 0), Vec3(1, 1, 10));
  const std::vector<TriangleMesh> far = {wall(900005.0)};
  Posture beside;
  beside.tip_mm = Vec3(900000.0, 0, 0);
  EXPECT_NEAR(pathgen::ClearanceChecker(tool, far).clearance(beside), 4.0 - std::sqrt(3.0) * 0.0625,
              1e-6);
  const std::vector<TriangleMesh> near = {wall(5.0)};
  EXPECT_NEAR(pathgen::ClearanceChecker(tool, near).clearance(Posture{}), 4.0, 1e-9);
}

// Closed form: a 2 × 2 × 10 "tool" (tool frame, tip at the origin) beside the wall x = 5.
TEST(Clearance, BoxToolBesideAWallClosedForm) {
  const TriangleMesh tool = box(Vec3(-1, -1, 0), Vec3(1, 1, 10));
  const std::vector<TriangleMesh> obstacles = {wall(5.0), wall(-20.0)};
  const pathgen::ClearanceChecker checker(tool, obstacles);
  Posture upright;
  EXPECT_NEAR(checker.clearance(upright), 4.0, 1e-9);

  // Tilted towards +x by θ about y: the top far corner comes to x = 10 sin θ + cos θ.
  const double theta = 0.3;
  Posture tilted;
  tilted.axis = Vec3(std::sin(theta), 0, std::cos(theta));
  int nearest = -1;
  EXPECT_NEAR(checker.clearance(tilted, &nearest), 5.0 - (10 * std::sin(theta) + std::cos(theta)),
              1e-9);
  EXPECT_EQ(nearest, 0);

  Posture crossing;
  crossing.tip_mm = Vec3(4.5, 0, 0);  // box spans x ∈ [3.5, 5.5]: it crosses the wall
  Posture beyond;
  beyond.tip_mm = Vec3(-17, 0, 0);  // 2 mm from the second wall
  const std::vector<Posture> postures = {upright, tilted, crossing, beyond, crossing};
  const auto result =
      checker.check(postures, pathgen::ClearanceRequest{.per_posture = true, .batch = 2});
  EXPECT_EQ(result.postures, 5u);
  EXPECT_EQ(result.colliding, 2u);
  EXPECT_EQ(result.first_colliding, 2u);
  EXPECT_EQ(result.min_index, 2u);
  EXPECT_EQ(result.min_clearance_mm, 0.0);
  ASSERT_EQ(result.clearance_mm.size(), 5u);
  EXPECT_NEAR(result.clearance_mm[3], 2.0, 1e-9);
  EXPECT_NEAR(result.clearance_mm[0], 4.0, 1e-9);

  const std::vector<Posture> safe = {upright, beyond};
  const auto ok = checker.check(safe);
  EXPECT_EQ(ok.colliding, 0u);
  EXPECT_NEAR(ok.min_clearance_mm, 2.0, 1e-9);
  EXPECT_EQ(ok.min_index, 1u);
  EXPECT_EQ(ok.min_obstacle, 1);

  // A chordal tolerance is taken off every distance (a faceted tool's vertices on the true
  // surface lie inside it by that much: never optimistic), and a touch stays 0.
  const pathgen::ClearanceChecker chorded(tool, obstacles, 0.05);
  EXPECT_NEAR(chorded.clearance(upright), 4.0 - 0.05, 1e-9);
  EXPECT_NEAR(chorded.clearance(tilted), 5.0 - (10 * std::sin(theta) + std::cos(theta)) - 0.05,
              1e-9);
  EXPECT_NEAR(chorded.check(safe).min_clearance_mm, 2.0 - 0.05, 1e-9);
  EXPECT_EQ(chorded.clearance(crossing), 0.0);
}

// A micro tool's clearance: the tool mesh within 1/150 of its smallest radius, that chordal
// error subtracted (at 0.02 mm a 0.1 mm ball read 0.02 mm short: a required 0.02 mm failed at
// every posture, a helper's). A ball R 0.1 on a neck 0.05 beside a wall 0.03 mm from the ball.
TEST(Clearance, AMicroToolsClearanceIsWithinAHundredAndFiftiethOfItsRadius) {
  const geometry::ToolSpec micro{geometry::ToolShape::Ball, 0.1, 0.0, 0.1};
  const geometry::HolderProfile neck = {{0.2, 0.05}, {5, 0.05}, {5, 0.08}, {30, 0.08}};
  const double tol_mm = pathgen::clearanceMeshTolMm(micro, neck);
  EXPECT_DOUBLE_EQ(tol_mm, 0.05 / 150);
  EXPECT_DOUBLE_EQ(
      pathgen::clearanceMeshTolMm({geometry::ToolShape::Ball, 3, 0, 40}, {{40, 6}, {90, 12}}),
      pathgen::kClearanceMeshTolMm);
  const std::vector<TriangleMesh> obstacles = {wall(0.13)};  // the ball's side at x = 0.1
  const pathgen::ClearanceChecker checker(geometry::toolMesh(micro, neck, tol_mm), obstacles,
                                          tol_mm);
  const double got = checker.clearance(Posture{});
  EXPECT_LE(got, 0.03);
  EXPECT_GE(got, 0.03 - 2 * tol_mm);
}

// A posture whose tool touches or crosses an obstacle (fcl::collide) is reported as colliding
// with clearance exactly 0 and the obstacle it meets, wherever on the tool the contact is.
TEST(Clearance, CollidingPostureIsZeroAndNamesTheObstacle) {
  const TriangleMesh tool = box(Vec3(-1, -1, 0), Vec3(1, 1, 10));
  const std::vector<TriangleMesh> obstacles = {wall(-20.0), wall(5.0)};
  const pathgen::ClearanceChecker checker(tool, obstacles);
  Posture crossing;  // x ∈ [3.5, 5.5] along the whole length
  crossing.tip_mm = Vec3(4.5, 0, 0);
  Posture touching;  // the face x = 5 lies on the wall
  touching.tip_mm = Vec3(4, 0, 0);
  Posture shank;  // tip 4 mm clear; tilted 0.6 rad the top far corner reaches x ≈ 6.5
  shank.axis = Vec3(std::sin(0.6), 0, std::cos(0.6));
  ASSERT_GT(10 * std::sin(0.6) + std::cos(0.6), 5.0);
  for (const Posture& p : {crossing, touching, shank}) {
    int nearest = -1;
    EXPECT_EQ(checker.clearance(p, &nearest), 0.0);
    EXPECT_EQ(nearest, 1);
  }
  Posture clear;
  clear.tip_mm = Vec3(2, 0, 0);  // 2 mm from the wall
  const auto result = checker.check(std::vector<Posture>{clear, shank, clear, touching, crossing});
  EXPECT_EQ(result.colliding, 3u);
  EXPECT_EQ(result.first_colliding, 1u);
  EXPECT_EQ(result.min_clearance_mm, 0.0);
  EXPECT_EQ(result.min_index, 1u);
  EXPECT_EQ(result.min_obstacle, 1);
  ASSERT_EQ(result.clearance_mm.size(), 5u);
  for (std::size_t i : {1u, 3u, 4u}) EXPECT_EQ(result.clearance_mm[i], 0.0) << i;
  for (std::size_t i : {0u, 2u}) EXPECT_NEAR(result.clearance_mm[i], 2.0, 1e-9) << i;
}

TEST(Clearance, EmptyMeshIsBadInput) {
  const std::vector<TriangleMesh> obstacles = {TriangleMesh{}};
  EXPECT_THROW(pathgen::ClearanceChecker(box(Vec3(-1, -1, 0), Vec3(1, 1, 1)), obstacles),
               common::InputError);
}

// Closed form: a ball of radius 1 centred 5 mm from the wall x = 5 clears it by 4 mm; the
// nearest of several centres is reported.
TEST(Clearance, BallClearanceIsCentreDistanceLessTheRadius) {
  const TriangleMesh tool = box(Vec3(-1, -1, 0), Vec3(1, 1, 10));
  const std::vector<TriangleMesh> obstacles = {wall(5.0), wall(-20.0)};
  const pathgen::ClearanceChecker checker(tool, obstacles);
  const std::vector<Vec3> centres = {Vec3(0, 0, 0), Vec3(2.5, 3, -4), Vec3(-10, 0, 0)};
  const pathgen::BallResult balls = checker.ballClearance(centres, pathgen::BallRequest{1.0});
  EXPECT_NEAR(balls.min_mm, 1.5, 1e-3);
  EXPECT_EQ(balls.at, 1u);
  EXPECT_EQ(balls.obstacle, 0);
  const std::vector<Vec3> touching = {Vec3(4.5, 0, 0)};
  EXPECT_EQ(checker.ballClearance(touching, 1.0), 0.0);
}

// Only the clearance under `exact_below_mm` is asked for exactly: a dense path (0.01 mm stations)
// swinging towards the wall x = 5 from 12 mm off and back gives the every-station minimum, value
// and index, bit for bit where it is under the threshold, and a lower bound of at least the
// threshold (at most the true minimum) where it is not. So with stations 0.3 mm apart far from
// the origin (x + 6e5 mm, the meshes read to 0.108 mm there, a margin every figure subtracts): a
// bound skipped at the threshold read under it by the margin (a pass 17 mm from a wall was
// refused as the ball entering it, a helper's).
TEST(Clearance, BallClearanceSkipsStationsThatCannotComeUnderTheThreshold) {
  const TriangleMesh tool = box(Vec3(-1, -1, 0), Vec3(1, 1, 10));
  for (const auto& [offset, stations] : {std::pair{0.0, 6000}, std::pair{6e5, 200}})
    for (const double nearest_x : {-7.0, 2.5, 3.9}) {  // ball clearance 11, 1.5, 0.1 mm at the apex
      const std::vector<TriangleMesh> obstacles = {wall(5.0 + offset), wall(-20.0 + offset)};
      const pathgen::ClearanceChecker checker(tool, obstacles);
      std::vector<Vec3> centres;
      for (int k = 0; k <= stations; ++k) {
        const double t = double(k) / stations;
        centres.emplace_back(offset - 7.0 + (nearest_x + 7.0) * std::sin(M_PI * t), 60.0 * t, 1.0);
      }
      const pathgen::BallResult all = checker.ballClearance(centres, pathgen::BallRequest{1.0});
      for (const double threshold : {0.5, 2.0}) {
        const pathgen::BallResult skipped =
            checker.ballClearance(centres, pathgen::BallRequest{1.0, threshold});
        if (all.min_mm < threshold) {
          EXPECT_EQ(skipped.min_mm, all.min_mm) << nearest_x << ' ' << threshold;
          EXPECT_EQ(skipped.at, all.at);
          EXPECT_EQ(skipped.obstacle, all.obstacle);
        } else {
          EXPECT_GE(skipped.min_mm, threshold) << nearest_x << ' ' << threshold;
          EXPECT_LE(skipped.min_mm, all.min_mm + 1e-12) << nearest_x << ' ' << threshold;
        }
      }
    }
}

// Split at `split_mm`: every station of the same swinging path told nearer or farther than it
// as the every-station clearances tell it (closed form: the ball's distance to the wall x = 5 is
// 4 - x), the minimum exact under the threshold; a station proven nearer by the walk is not
// measured, its value a lower bound between the two.
TEST(Clearance, BallClearanceSplitTellsEachStationNearerOrFartherExactly) {
  const TriangleMesh tool = box(Vec3(-1, -1, 0), Vec3(1, 1, 10));
  const std::vector<TriangleMesh> obstacles = {wall(5.0), wall(-20.0)};
  const pathgen::ClearanceChecker checker(tool, obstacles);
  for (const double nearest_x : {-7.0, 2.5, 3.99}) {  // ball clearance 11, 1.5, 0.01 at the apex
    std::vector<Vec3> centres;
    for (int k = 0; k <= 6000; ++k) {
      const double t = k / 6000.0;
      centres.emplace_back(-7.0 + (nearest_x + 7.0) * std::sin(M_PI * t), 60.0 * t, 1.0);
    }
    const double split_mm = 6.0, exact_mm = 0.05;
    const pathgen::BallResult balls =
        checker.ballClearance(centres, pathgen::BallRequest{1.0, exact_mm, split_mm, true});
    const std::vector<double>& each = balls.each_mm;
    const double least = balls.min_mm;
    ASSERT_EQ(each.size(), centres.size());
    for (std::size_t i = 0; i < centres.size(); ++i) {
      const double exact = 4.0 - centres[i].x();  // the nearer wall, x = 5
      EXPECT_EQ(each[i] < split_mm, exact < split_mm) << nearest_x << ' ' << i;
      EXPECT_LE(each[i], exact + 1e-9) << nearest_x << ' ' << i;
    }
    if (4.0 - nearest_x < exact_mm)
      EXPECT_NEAR(least, 4.0 - nearest_x, 2e-4) << nearest_x;  // the point model: 0.1 um
    else
      EXPECT_GE(least, exact_mm) << nearest_x;
  }
}

// exact_min_only (the holder against the part): a dense path of a ball-end tool and holder that
// tilts towards a wall and into it, its axis's azimuth swinging (each posture's minimal rotation
// then twists the faceted mesh about the axis: a bound by the axes' angle alone was 0.36 um above
// the measured figure, a reviewer's case), gives the every-posture minimum (value, posture,
// obstacle), the colliding postures and the first, bit for bit; every other posture's figure is
// a bound never above its measured one.
TEST(Clearance, OnlyTheMinimumExactMeasuresFewerPosturesAndAgrees) {
  const TriangleMesh tool =
      geometry::toolMesh(geometry::parseToolSpec("ball:3:20"),
                         geometry::parseHolderProfile("20:6,40:6,40:12,60:12"), 0.02);
  const std::vector<TriangleMesh> obstacles = {wall(5.0), wall(-40.0)};
  const pathgen::ClearanceChecker checker(tool, obstacles, 0.02);
  for (const double deepest_deg : {5.0, 30.0}) {  // clear all along; the holder into the wall
    std::vector<Posture> postures;
    for (int k = 0; k <= 3000; ++k) {
      const double t = k / 3000.0;
      const double tilt = (2.0 + (deepest_deg - 2.0) * std::sin(M_PI * t)) * M_PI / 180.0;
      const double azimuth = 0.6 * std::sin(6.0 * M_PI * t);
      postures.push_back(
          {Vec3(-15.0, 30.0 * t, 0.0), Vec3(std::sin(tilt) * std::cos(azimuth),
                                            std::sin(tilt) * std::sin(azimuth), std::cos(tilt))});
    }
    pathgen::ClearanceRequest only_min;
    only_min.exact_min_only = true;
    const pathgen::ClearanceResult all = checker.check(postures);
    const pathgen::ClearanceResult some = checker.check(postures, only_min);
    EXPECT_EQ(some.min_clearance_mm, all.min_clearance_mm) << deepest_deg;
    EXPECT_EQ(some.min_index, all.min_index);
    EXPECT_EQ(some.min_obstacle, all.min_obstacle);
    EXPECT_EQ(some.colliding, all.colliding);
    EXPECT_EQ(some.first_colliding, all.first_colliding);
    std::size_t spared = 0;
    for (std::size_t i = 0; i < postures.size(); ++i) {
      EXPECT_LE(some.clearance_mm[i], all.clearance_mm[i]) << i;
      spared += some.clearance_mm[i] != all.clearance_mm[i];
    }
    // Clear all along: most spared; colliding in the middle: the clear postures near the ends.
    EXPECT_GT(spared, postures.size() / (deepest_deg < 10.0 ? 2 : 10)) << deepest_deg;
  }
}

// The reviewer's twist: a holder (ball R3 L20, holder R3 from 40 to 90) with its axis 60 deg
// off vertical beside a wall, then the same tip with the axis's azimuth turned 0.006 rad, then a
// posture in the wall. The wall is placed (bisection) where the second posture just touches:
// its minimal rotation twists the faceted mesh about the axis, so it touches though the bound by
// the axes' angle from the first said 0.18 um clear (1 colliding posture where 2 are).
TEST(Clearance, OnlyTheMinimumExactSeesATwistOfTheFacetedMesh) {
  const TriangleMesh holder = geometry::holderMesh(geometry::parseToolSpec("ball:3:20"),
                                                   geometry::parseHolderProfile("40:3,90:3"), 0.02);
  const double phi0 = 0.04, tilt = 60.0 * M_PI / 180.0;
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(phi0, Vec3::UnitZ()).toRotationMatrix();
  const auto axis = [&](double phi) {
    return Vec3(std::sin(tilt) * std::cos(phi), std::sin(tilt) * std::sin(phi), std::cos(tilt));
  };
  const std::vector<Posture> postures = {{Vec3::Zero(), axis(phi0)},
                                         {Vec3::Zero(), axis(phi0 + 0.006)},
                                         {10.0 * (turn * Vec3::UnitY()), axis(phi0)}};
  const auto checked = [&](double gap, bool only_min) {
    TriangleMesh wall_mesh = box(Vec3(-100, 3 + gap, -100), Vec3(100, 23 + gap, 100));
    for (Vec3& v : wall_mesh.vertices) v = turn * v;
    const pathgen::ClearanceChecker checker(holder, std::vector<TriangleMesh>{wall_mesh}, 0.02);
    pathgen::ClearanceRequest request;
    request.exact_min_only = only_min;
    return checker.check(postures, request);
  };
  double touching = 0.0, clear = 2.0;  // the second posture: clearance 0 / > 0
  for (int k = 0; k < 50; ++k) {
    const double mid = 0.5 * (touching + clear);
    (checked(mid, false).clearance_mm[1] > 0.0 ? clear : touching) = mid;
  }
  const pathgen::ClearanceResult all = checked(touching, false), some = checked(touching, true);
  ASSERT_EQ(all.clearance_mm[1], 0.0);
  ASSERT_GT(all.clearance_mm[0], 0.0);
  EXPECT_EQ(some.colliding, all.colliding);
  EXPECT_EQ(some.first_colliding, all.first_colliding);
  EXPECT_EQ(some.clearance_mm[1], 0.0);
}

// The moves out of and into passes are checked with the tool 0.1 mm smaller all round, its top
// 0.1 mm lower: a ball as long as its radius (3 mm, up to 3.1) was refused as "too short for
// its cutting end" after the job's work (a helper's); it is taken, and still finds a link that
// runs through a block on the part.
TEST(Links, ABallAsLongAsItsRadiusIsChecked) {
  TriangleMesh part;
  pathgen::test::addBox(part, -10, 50, -10, 10, -5, 0);
  pathgen::test::addBox(part, 20, 24, -10, 10, 0, 4);
  for (const double length : {3.0, 3.0001, 3.05, 3.1}) {
    SCOPED_TRACE(length);
    const geometry::ToolSpec tool{geometry::ToolShape::Ball, 3.0, 0.0, length};
    const pathgen::ClearanceChecker checker(geometry::toolMesh(tool, {}, 0.02), {&part, 1}, 0.02);
    const pathgen::GrazingChecker grazing = pathgen::grazingPartChecker(tool, {}, part);
    auto at = [](double x, double z) { return Posture{Vec3(x, 0, z), Vec3::UnitZ(), 0.0, false}; };
    geometry::PathFile path;
    path.postures = {at(0, 0),  at(10, 0), at(10, 0), at(10, 1),
                     at(40, 1), at(40, 0), at(40, 0), at(45, 0)};
    path.blocks = {{geometry::PathBlock::Kind::Pass, 0, 2},
                   {geometry::PathBlock::Kind::Link, 2, 6},
                   {geometry::PathBlock::Kind::Pass, 6, 8}};
    const pathgen::LinkPartResult links = pathgen::checkLinksAgainstPart(checker, grazing, path);
    EXPECT_EQ(links.motion_contacts, std::vector<std::size_t>{3});
  }
}

// A query starts under the closest pair of the posture before it (FCL's branch and bound skips
// the boxes farther apart): the values must be a lone query's, bit for bit, wherever the nearest
// obstacle changes, the tool touches one, or two stand at nearly the same distance. A tool
// swept over a box, between two walls, and into the box: every posture's clearance, the
// minimum's obstacle, and the ball's clearance from a run of centres, each against lone queries.
TEST(Clearance, AQueryAfterItsNeighbourGivesALoneQuerysValues) {
  const TriangleMesh tool =
      geometry::toolMesh(geometry::parseToolSpec("ball:3:20"),
                         geometry::parseHolderProfile("20:6,40:6,40:12,60:12"), 0.02);
  const std::vector<TriangleMesh> obstacles = {wall(31.0), box(Vec3(-4, 13, -20), Vec3(4, 16, -2)),
                                               wall(-31.0)};
  const pathgen::ClearanceChecker checker(tool, obstacles, 0.02);
  std::vector<Posture> postures;
  std::vector<Vec3> centres;
  for (int k = 0; k <= 600; ++k) {
    const double t = k / 600.0;
    const double tilt = 0.3 * std::sin(5.0 * M_PI * t);  // rad: towards either wall and back
    const Vec3 tip(3.0 * std::sin(3.0 * M_PI * t), 30.0 * t, -0.5 + 2.0 * std::cos(2.0 * M_PI * t));
    postures.push_back({tip, Vec3(std::sin(tilt), 0.0, std::cos(tilt))});
    centres.push_back(tip + Vec3(0, 0, 3));
  }
  pathgen::ClearanceRequest request;
  request.batch = 1000;  // one batch: the chains run as long as TBB's ranges
  const pathgen::ClearanceResult all = checker.check(postures, request);
  std::size_t touching = 0, by_obstacle[3] = {0, 0, 0};
  for (std::size_t i = 0; i < postures.size(); ++i) {
    int obstacle = -1;
    const double alone = checker.clearance(postures[i], &obstacle);
    EXPECT_EQ(all.clearance_mm[i], alone) << i;
    touching += alone == 0.0;
    ++by_obstacle[obstacle];
    if (i == all.min_index) EXPECT_EQ(all.min_obstacle, obstacle);
  }
  pathgen::ClearanceRequest only_min;  // every 8th posture measured, in chains of their own
  only_min.exact_min_only = true;
  const pathgen::ClearanceResult some = checker.check(postures, only_min);
  for (std::size_t i = 0; i < postures.size(); i += 8)
    EXPECT_EQ(some.clearance_mm[i], all.clearance_mm[i]) << i;
  EXPECT_GT(touching, 10u);  // (the sweep meets the box, and each obstacle is the nearest)
  EXPECT_LT(touching, postures.size() / 2);
  for (const std::size_t n : by_obstacle) EXPECT_GE(n, 10u);
  pathgen::BallRequest every{3.0};
  every.each = true;
  const std::vector<double> each = checker.ballClearance(centres, every).each_mm;
  for (std::size_t i = 0; i < centres.size(); ++i)
    EXPECT_EQ(each[i], checker.ballClearance(std::span<const Vec3>(&centres[i], 1), 3.0)) << i;
}

// A repair checks again the path it changed: the memo gives back the postures and motions
// checked before (the same bits) and measures the rest. The results must be those of a check
// without it, bit for bit; what it gives back is exactly what did not change.
TEST(Clearance, AMemoGivesBackWhatWasCheckedAndMeasuresOnlyWhatChanged) {
  const TriangleMesh tool =
      geometry::toolMesh(geometry::parseToolSpec("ball:3:20"),
                         geometry::parseHolderProfile("20:6,40:6,40:12,60:12"), 0.02);
  const std::vector<TriangleMesh> obstacles = {wall(31.0), box(Vec3(-4, 13, -20), Vec3(4, 16, -2))};
  const pathgen::ClearanceChecker checker(tool, obstacles, 0.02);
  std::vector<Posture> before;
  for (int k = 0; k <= 300; ++k) {
    const double t = k / 300.0, tilt = 0.3 * std::sin(5.0 * M_PI * t);
    before.push_back({Vec3(3.0 * std::sin(3.0 * M_PI * t), 30.0 * t, -1.0 + 2.0 * std::cos(2 * t)),
                      Vec3(std::sin(tilt), 0.0, std::cos(tilt))});
  }
  // Postures 100-149 turned, as a repair re-steers a pass (the tips held: the axis is the key
  // too), and 160-169 moved.
  std::vector<Posture> after = before;
  for (int k = 100; k < 150; ++k)
    after[k].axis = (after[k].axis + Vec3(0.0, 0.05, 0.0)).normalized();
  for (int k = 160; k < 170; ++k) after[k].tip_mm.x() += 0.7;
  pathgen::ClearanceMemo memo;
  pathgen::ClearanceRequest with;
  with.memo = &memo;
  pathgen::MotionRequest motions_with;
  motions_with.required_mm = 0.5;
  motions_with.memo = &memo;
  const auto motions = [&](const std::vector<Posture>& path, const pathgen::ClearanceResult& at,
                           pathgen::MotionRequest request) {
    request.posture_clearance_mm = at.clearance_mm;
    return checker.checkMotions(path, request);
  };
  motions(before, checker.check(before, with), motions_with);
  ASSERT_EQ(memo.reused(), 0u);
  const pathgen::ClearanceResult remembered = checker.check(after, with);
  EXPECT_EQ(memo.reused(), after.size() - 60);
  const pathgen::ClearanceResult measured = checker.check(after);
  EXPECT_EQ(remembered.clearance_mm, measured.clearance_mm);
  EXPECT_EQ(remembered.min_index, measured.min_index);
  EXPECT_EQ(remembered.min_obstacle, measured.min_obstacle);
  EXPECT_EQ(remembered.colliding, measured.colliding);
  pathgen::MotionRequest motions_without = motions_with;
  motions_without.memo = nullptr;
  const std::size_t before_motions = memo.reused();
  const pathgen::MotionResult moved = motions(after, remembered, motions_with);
  // (the motions into and out of each changed run changed too; the stop, from the closest
  // posture, is the same: the box stays the nearest)
  EXPECT_EQ(memo.reused() - before_motions, after.size() - 1 - 51 - 11);
  const pathgen::MotionResult fresh = motions(after, measured, motions_without);
  EXPECT_EQ(moved.clearance_mm, fresh.clearance_mm);
  EXPECT_EQ(moved.samples, fresh.samples);
  EXPECT_EQ(moved.colliding, fresh.colliding);
  EXPECT_EQ(moved.under_required, fresh.under_required);
  EXPECT_GT(fresh.samples, 0u);
}
