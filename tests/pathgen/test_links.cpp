/// Links between passes (leave along the axis, travel above safe_z, turn in small steps; an axis
/// near horizontal left straight up) and motions checked between clear postures, against the
/// obstacles and the part (split from test_nominal.cpp).
#include <algorithm>
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "fieldpath/common/errors.h"
#include "fieldpath/geometry/cl_file.h"
#include "fieldpath/geometry/tool_model.h"
#include "fieldpath/pathgen/clearance.h"
#include "fieldpath/pathgen/link_check.h"
#include "fieldpath/pathgen/links.h"
#include "fixtures.h"

using namespace fieldpath;
using namespace fieldpath::pathgen;
using geometry::PathBlock;
using geometry::PathFile;
using geometry::Posture;
using pathgen::test::boxMesh;
using pathgen::test::errorOf;

// Between passes whose axes differ the travel plane's tip height keeps the whole tool above
// safe_z at every axis on the way: here the lowest point is the holder's rim at the next pass's
// axis (a wide holder low on the tool, tilted 40 deg), so z = safe_z - lowestPointBelowTip(that
// axis), not the first's; and the travel ends on that axis right above the next pass, then comes
// down it. (The last axis of the turn left out, or the point above the next pass dropped, was
// caught only by the wording of a note: a mutation audit.)
TEST(Links, TheTravelBetweenTwoAxesClearsSafeZAtTheNextAxisAndEndsAboveIt) {
  const geometry::ToolSpec tool{geometry::ToolShape::Ball, 3.0, 0.0, 40.0};
  const geometry::HolderProfile holder = {{10, 20}, {30, 20}};
  const double t = 40 * M_PI / 180;
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ(), leaning(0, -std::sin(t), std::cos(t));
  std::vector<std::vector<Posture>> passes(2);
  for (int i = 0; i <= 4; ++i) {
    passes[0].push_back({Eigen::Vector3d(i, 0, 0), up, 0.0, false});
    passes[1].push_back({Eigen::Vector3d(4 - i, 30, 0), leaning, 0.0, false});
  }
  LinkRequest request;
  request.safe_z_mm = 25.0;
  request.tool = tool;
  request.holder = holder;
  const PathFile out = linkPasses(passes, request);
  ASSERT_EQ(out.blocks.size(), 5u);
  const PathBlock& middle = out.blocks[2];
  ASSERT_EQ(middle.kind, PathBlock::Kind::Link);
  const double lowest = 10 * std::cos(t) - 20 * std::sin(t);  // closed form: the rim, tilted
  ASSERT_NEAR(lowestPointBelowTip(tool, holder, leaning), lowest, 1e-12);
  const double z = 25.0 - lowest;
  std::vector<std::size_t> travel;  // the link's postures in the travel plane
  for (std::size_t i = middle.begin; i < middle.end; ++i)
    if (std::abs(out.postures[i].tip_mm.z() - z) < 1e-9) travel.push_back(i);
  ASSERT_GE(travel.size(), 2u);
  for (std::size_t i = middle.begin + 1; i + 1 < middle.end; ++i)
    EXPECT_GE(out.postures[i].tip_mm.z() + lowestPointBelowTip(tool, holder, out.postures[i].axis),
              25.0 - 1e-9);
  const Posture& above = out.postures[travel.back()];
  EXPECT_LT(geometry::axisAngle(above.axis, leaning), 1e-12);
  const Eigen::Vector3d along = above.tip_mm - passes[1].front().tip_mm;
  EXPECT_LT(along.cross(leaning).norm(), 1e-9);  // on the next pass's axis
  EXPECT_GT(along.dot(leaning), 0.0);
}

TEST(Links, LeaveAlongTheAxisTravelAboveSafeZAndTurnInSmallSteps) {
  geometry::ToolSpec tool{geometry::ToolShape::Ball, 3.0, 0.0, 40.0};
  const geometry::HolderProfile holder = {{40, 6}, {55, 6}, {55, 12}, {90, 12}};
  // Closed form: a vertical axis's lowest point is the tip; tilted by t, the holder's rim.
  EXPECT_NEAR(lowestPointBelowTip(tool, holder, Eigen::Vector3d::UnitZ()), 0.0, 1e-12);
  const double t = 30 * M_PI / 180;
  const Eigen::Vector3d tilted(std::sin(t), 0, std::cos(t));
  EXPECT_NEAR(lowestPointBelowTip(tool, holder, tilted),
              std::min(3 * std::cos(t) - 3, 40 * std::cos(t) - 6 * std::sin(t)), 1e-12);
  // Where the holder's rim is the lowest (a wide holder low on the tool, tilted 60 deg): its
  // rim's lowest point, 10 cos t - 20 sin t, below the ball's 3 cos t - 3.
  const double steep = 60 * M_PI / 180;
  EXPECT_NEAR(lowestPointBelowTip(tool, {{10, 20}, {30, 20}},
                                  Eigen::Vector3d(std::sin(steep), 0, std::cos(steep))),
              10 * std::cos(steep) - 20 * std::sin(steep), 1e-12);
  std::vector<std::vector<Posture>> passes(2);
  for (int i = 0; i <= 4; ++i) {
    passes[0].push_back({Eigen::Vector3d(i, 0, 0), tilted, 0.0, false});
    passes[1].push_back(
        {Eigen::Vector3d(4 - i, 10, 0), Eigen::Vector3d(0, -0.5, 1).normalized(), 0.0, false});
  }
  LinkRequest request;
  request.safe_z_mm = 25.0;
  request.tool = tool;
  request.holder = holder;
  const PathFile out = linkPasses(passes, request);
  ASSERT_EQ(out.blocks.size(), 5u);  // link, pass, link, pass, link
  EXPECT_EQ(out.blocks[0].kind, PathBlock::Kind::Link);
  EXPECT_EQ(out.blocks[1].size(), 5u);
  for (const PathBlock& block : out.blocks) {
    if (block.kind != PathBlock::Kind::Link) continue;
    for (std::size_t i = block.begin; i < block.end; ++i) {
      const Posture& p = out.postures[i];
      if (i > block.begin) {
        const double turn = std::acos(std::min(1.0, p.axis.dot(out.postures[i - 1].axis)));
        EXPECT_LE(turn, kMaxLinkTurnDeg * M_PI / 180 + 1e-12);
      }
    }
  }
  // The travel between the passes: every posture of the middle link but its first and last two
  // (retract, climb / descent, approach) has the whole tool above safe_z.
  const PathBlock& middle = out.blocks[2];
  for (std::size_t i = middle.begin + 1; i + 1 < middle.end; ++i)
    EXPECT_GE(out.postures[i].tip_mm.z() + lowestPointBelowTip(tool, holder, out.postures[i].axis),
              25.0 - 1e-9);
  // The first link posture after a pass is `retract` along its last axis.
  EXPECT_NEAR((out.postures[middle.begin].tip_mm - (passes[0].back().tip_mm + 10 * tilted)).norm(),
              0, 1e-12);
}

// An axis within 5° of horizontal (a wall finished with the ball's side): no climb along it
// reaches the travel plane (the job was refused; at 84.9° the climb ran 446 mm sideways). The
// link leaves `retract` along the axis, then straight up, and comes down the same way; an axis
// pointing down is refused, saying how to proceed.
TEST(Links, AHorizontalAxisIsLeftStraightUpAfterItsRetract) {
  geometry::ToolSpec tool{geometry::ToolShape::Ball, 3.0, 0.0, 40.0};
  const geometry::HolderProfile holder = {{40, 6}, {55, 6}, {55, 12}, {90, 12}};
  const Eigen::Vector3d side = Eigen::Vector3d(1, 0, 0.02).normalized();  // 88.9° from vertical
  std::vector<std::vector<Posture>> passes(2);
  for (int i = 0; i <= 4; ++i) {
    passes[0].push_back({Eigen::Vector3d(0, i, 0), side, 0.0, false});
    passes[1].push_back({Eigen::Vector3d(0, 4 - i, -5), side, 0.0, false});
  }
  LinkRequest request;
  request.safe_z_mm = 60.0;
  request.tool = tool;
  request.holder = holder;
  request.params.retract_mm = 10.0;
  const PathFile out = linkPasses(passes, request);
  ASSERT_EQ(out.blocks.size(), 5u);
  const PathBlock& middle = out.blocks[2];
  const Posture& retracted = out.postures[middle.begin];
  EXPECT_NEAR((retracted.tip_mm - (passes[0].back().tip_mm + 10 * side)).norm(), 0, 1e-12);
  const Posture& risen = out.postures[middle.begin + 1];  // straight up from the retract
  EXPECT_NEAR(risen.tip_mm.x(), retracted.tip_mm.x(), 1e-12);
  EXPECT_NEAR(risen.tip_mm.y(), retracted.tip_mm.y(), 1e-12);
  EXPECT_GE(risen.tip_mm.z() + lowestPointBelowTip(tool, holder, side), 60.0 - 1e-9);
  const Posture& above = out.postures[middle.end - 2];  // over the next pass's retract point
  const Posture& entry = out.postures[middle.end - 1];
  EXPECT_NEAR((entry.tip_mm - (passes[1].front().tip_mm + 10 * side)).norm(), 0, 1e-12);
  EXPECT_NEAR((above.tip_mm - entry.tip_mm).head<2>().norm(), 0, 1e-12);
  for (std::size_t i = 1; i < out.postures.size(); ++i)  // nothing runs hundreds of mm aside
    EXPECT_LT((out.postures[i].tip_mm - out.postures[i - 1].tip_mm).head<2>().norm(), 20.0) << i;
  // Both sides of a rib: the axis turns over from +x to -x through +z (the great circle between
  // opposite axes is no arc: a reviewer's link wrote axes of 0 0 0), 5° a step at most.
  std::vector<std::vector<Posture>> sides = passes;
  for (Posture& p : sides[1]) p.axis = Eigen::Vector3d(-1, 0, 0);
  for (Posture& p : sides[0]) p.axis = Eigen::Vector3d(1, 0, 0);
  const PathFile over = linkPasses(sides, request);
  for (std::size_t i = 1; i < over.postures.size(); ++i) {
    const Eigen::Vector3d& axis = over.postures[i].axis;
    EXPECT_NEAR(axis.norm(), 1.0, 1e-12) << i;
    EXPECT_GE(axis.z(), -1e-12) << i;
    EXPECT_LE(std::acos(std::min(1.0, axis.dot(over.postures[i - 1].axis))),
              kMaxLinkTurnDeg * M_PI / 180 + 1e-9)
        << i;
  }
  // Pointing down (an undercut), even a little: refused, saying how to proceed.
  for (Posture& p : sides[1]) p.axis = Eigen::Vector3d(-1, 0, -0.05).normalized();
  EXPECT_NE(errorOf([&] { linkPasses(sides, request); }).find("pointing down"), std::string::npos);
  for (Posture& p : passes[1]) p.axis = Eigen::Vector3d(1, 0, -0.3).normalized();
  const std::string error = errorOf([&] { linkPasses(passes, request); });
  EXPECT_NE(error.find("links: pass 2 starts with the tool axis 107 deg from vertical, pointing "
                       "down: no link from the travel plane above reaches it (write its links in "
                       "the nominal path and run `check` on it)"),
            std::string::npos)
      << error;
  // Named by its label where the caller gives one (generate: the pass's line in its file).
  request.labels = {"pass 1 (p.cl:2)", "pass 2 (p.cl:40)"};
  EXPECT_NE(errorOf([&] {
              linkPasses(passes, request);
            }).find("links: pass 2 (p.cl:40) starts with the tool axis 107 deg"),
            std::string::npos);
}

TEST(Motions, AThinWallBetweenTwoClearPosturesIsACollidingMotion) {
  // A wall 0.2 mm thick (x in [4.9, 5.1]), 10 mm high; the tool jumps over it from x = 0 to 10 at
  // a height where the ball goes through it, both ends 4.9 - 3 = 1.9 mm clear.
  geometry::TriangleMesh wall;
  const double x0 = 4.9, x1 = 5.1;
  for (double x : {x0, x1})
    for (double y : {-20.0, 20.0})
      for (double z : {0.0, 10.0}) wall.vertices.emplace_back(x, y, z);
  const int faces[12][3] = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                            {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  for (const auto& f : faces) wall.triangles.emplace_back(f[0], f[1], f[2]);
  const geometry::ToolSpec tool{geometry::ToolShape::Ball, 3.0, 0.0, 20.0};
  const ClearanceChecker checker(geometry::toolMesh(tool, {}, 0.02), {&wall, 1}, 0.02);
  const std::vector<Posture> jump = {
      {Eigen::Vector3d(0, 0, 2), Eigen::Vector3d::UnitZ(), 0, false},
      {Eigen::Vector3d(10, 0, 2), Eigen::Vector3d::UnitZ(), 0, false}};
  const ClearanceResult at_postures = checker.check(jump);
  EXPECT_EQ(at_postures.colliding, 0u);
  EXPECT_NEAR(at_postures.min_clearance_mm, 1.9 - 0.02, 0.03);
  MotionRequest request;
  request.required_mm = 0.5;
  const MotionResult motions = checker.checkMotions(jump, request);
  EXPECT_EQ(motions.colliding, 1u);
  EXPECT_EQ(motions.first_colliding, 0u);
  // Above the wall the same motion is clear, and its bound is within max(0.01 mm, 1 %) of the
  // closest approach (the ball's bottom passes 2 mm above the wall's top: 2 - 0.02), less the
  // resolution.
  const std::vector<Posture> over = {
      {Eigen::Vector3d(0, 0, 12), Eigen::Vector3d::UnitZ(), 0, false},
      {Eigen::Vector3d(10, 0, 12), Eigen::Vector3d::UnitZ(), 0, false}};
  const MotionResult clear = checker.checkMotions(over, request);
  EXPECT_EQ(clear.colliding, 0u);
  EXPECT_LE(clear.min_clearance_mm, 2.0 - 0.02 + 1e-9);
  EXPECT_GE(clear.min_clearance_mm, (2.0 - 0.02) * 0.99 - 0.001 - 0.005);
  // A 460 mm motion 25 mm over the wall: its closest approach (25 - 0.02) is found to the same
  // slack without halving the whole stretch nearer than the ends to the resolution (a helper's
  // motion over a rib: ~10^5 samples, 68 s of a holder; the lowest bound is refined first).
  const std::vector<Posture> far = {
      {Eigen::Vector3d(-225, 0, 35), Eigen::Vector3d::UnitZ(), 0, false},
      {Eigen::Vector3d(235, 0, 35), Eigen::Vector3d::UnitZ(), 0, false}};
  const MotionResult long_motion = checker.checkMotions(far, request);
  EXPECT_EQ(long_motion.colliding, 0u);
  EXPECT_LE(long_motion.min_clearance_mm, 25.0 - 0.02 + 1e-9);
  EXPECT_GE(long_motion.min_clearance_mm, (25.0 - 0.02) * 0.99 - 0.005);
  EXPECT_LT(long_motion.samples, 200u);
}

TEST(Links, AGivenSafeZBelowTheMeshesIsRefusedNamingTheKey) {
  const std::vector<geometry::TriangleMesh> meshes = {boxMesh(0, 10, 0, 10, 0, 5),
                                                      boxMesh(20, 30, 0, 10, 0, 8)};
  const double top = topOfMeshes(meshes);
  EXPECT_DOUBLE_EQ(top, 8.0);
  EXPECT_DOUBLE_EQ(resolveSafeZ(std::nullopt, top, 0.5), 8 + 0.5 + kSafeZMarginMm);
  EXPECT_DOUBLE_EQ(resolveSafeZ(9.0, top, 0.5), 9.0);
  EXPECT_DOUBLE_EQ(resolveSafeZ(8.5, top, 0.5), 8.5);  // the top + clearance: allowed
  try {
    resolveSafeZ(6.0, top, 0.5);  // above the first box, through the second
    FAIL();
  } catch (const common::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("links.safe_z"), std::string::npos) << e.what();
  }
}

// The grazing checker's holder: thinner by the graze and 2 grazes shorter, as any holder the
// scene accepts (a helper's holders ending in a step, a short top piece or a 0.1 mm neck were
// refused mid-job: a last station lowered under a step at its z, a radius thinned to 0).
TEST(Links, TheGrazingHolderIsValidForEveryHolderTheSceneAccepts) {
  const double by = kPassGrazeMm;
  const geometry::HolderProfile top_step = {{40, 6}, {55, 6}, {55, 12}, {90, 12}, {90, 20}};
  const geometry::HolderProfile thin = thinnerHolder(top_step, by);
  EXPECT_NO_THROW(geometry::validateHolderProfile(thin));
  ASSERT_EQ(thin.size(), 4u);  // the step at the top is above the new top (89.8)
  EXPECT_DOUBLE_EQ(thin.back().z_mm, 90 - 2 * by);
  EXPECT_DOUBLE_EQ(thin.back().radius_mm, 12 - by);
  EXPECT_DOUBLE_EQ(thin[2].radius_mm, 12 - by);
  EXPECT_EQ(thin[2].z_mm, thin[1].z_mm);  // the step kept
  // A cone to its top: the new top on the cone.
  const geometry::HolderProfile cone = thinnerHolder({{40, 6}, {90, 11}}, by);
  ASSERT_EQ(cone.size(), 2u);
  EXPECT_NEAR(cone.back().radius_mm, 6 + 5 * (90 - 2 * by - 40) / 50 - by, 1e-12);
  // A 0.1 mm neck keeps half its radius; a holder 0.15 mm high keeps nothing.
  const geometry::HolderProfile neck = thinnerHolder({{0.5, 0.1}, {20, 0.1}, {20, 3}, {40, 3}}, by);
  EXPECT_NO_THROW(geometry::validateHolderProfile(neck));
  EXPECT_DOUBLE_EQ(neck.front().radius_mm, 0.05);
  EXPECT_TRUE(thinnerHolder({{40, 6}, {40.15, 6}}, by).empty());
  // The whole checker is made for each (it validates tool and holder again).
  geometry::TriangleMesh part;
  pathgen::test::addBox(part, -10, 10, -10, 10, -5, 0);
  const geometry::ToolSpec ball{geometry::ToolShape::Ball, 3.0, 0.0, 40.0};
  for (const geometry::HolderProfile& h :
       {top_step, geometry::HolderProfile{{40, 6}, {90, 12}, {90, 3}},
        geometry::HolderProfile{{40, 6}, {40.15, 6}}})
    EXPECT_NO_THROW((void)grazingPartChecker(ball, h, part));
  const geometry::ToolSpec micro{geometry::ToolShape::Ball, 0.25, 0.0, 0.5};
  EXPECT_NO_THROW((void)grazingPartChecker(micro, {{0.5, 0.1}, {20, 0.1}}, part));
}

// The links against the part: a link that travels through a block standing on the part is
// reported (its postures and the motion between them), the ball's contact where a pass starts
// and ends is not (retract 0: the link's first posture is the pass's last).
TEST(Links, ALinkThroughThePartIsReportedAndThePassContactIsNot) {
  const geometry::ToolSpec tool{geometry::ToolShape::Ball, 3.0, 0.0, 20.0};
  // The part: a floor at z = 0 with a block 4 mm high on it between x = 20 and 24.
  geometry::TriangleMesh part;
  pathgen::test::addBox(part, -10, 50, -10, 10, -5, 0);
  pathgen::test::addBox(part, 20, 24, -10, 10, 0, 4);
  const ClearanceChecker checker(geometry::toolMesh(tool, {}, 0.02), {&part, 1}, 0.02);
  const GrazingChecker grazing = grazingPartChecker(tool, {}, part);
  auto posture = [](double x, double z) {
    return Posture{Eigen::Vector3d(x, 0, z), Eigen::Vector3d::UnitZ(), 0.0, false};
  };
  geometry::PathFile path;
  // pass 1 on the floor (tip at z = 0), a link at z = 1 across the block, pass 2 on the floor.
  path.postures = {posture(0, 0),  posture(10, 0), posture(10, 0), posture(10, 1),
                   posture(40, 1), posture(40, 0), posture(40, 0), posture(45, 0)};
  path.blocks = {
      {PathBlock::Kind::Pass, 0, 2}, {PathBlock::Kind::Link, 2, 6}, {PathBlock::Kind::Pass, 6, 8}};
  LinkPartResult through = checkLinksAgainstPart(checker, grazing, path);
  EXPECT_EQ(through.postures, 2u);  // the two at z = 1; those at the passes' contact left out
  EXPECT_EQ(through.colliding_postures, 0u);  // 1 mm above the floor, either side of the block
  EXPECT_EQ(through.colliding_motions, 1u);
  EXPECT_EQ(through.first_colliding_motion, 3u);
  EXPECT_TRUE(through.collides());
  // The contacts one by one (what view colours, clearance.csv marks), as the counts say.
  EXPECT_TRUE(through.posture_contacts.empty());
  EXPECT_EQ(through.motion_contacts, std::vector<std::size_t>{3});
  // Over the block (the tool's tip 2 mm above its top) the same link is clear.
  path.postures[3] = posture(10, 6);
  path.postures[4] = posture(40, 6);
  const LinkPartResult over = checkLinksAgainstPart(checker, grazing, path);
  EXPECT_FALSE(over.collides());
  // A lower bound, within 10 % of the true 2 mm less the chord (the links' are told so).
  EXPECT_LE(over.min_clearance_mm, 2.0 - 0.02 + 0.01);
  EXPECT_GE(over.min_clearance_mm, 0.9 * (2.0 - 0.02) - 0.01);
  // The move out of a pass: a retract along an axis leaning 45° towards the block (the ball on
  // the floor, its centre 5 mm before the block at the pass's end) drives the ball into the
  // block's top edge; leaning away, it leaves clear. The first 0.1 mm, where the ball leaves the
  // floor it cuts, is not counted either way.
  for (const double lean : {45.0, -45.0}) {
    const double rad = lean * M_PI / 180.0;
    const Eigen::Vector3d axis(std::sin(rad), 0.0, std::cos(rad));
    auto ball = [&](double x) {  // the ball resting on the floor, centre at x
      return Posture{Eigen::Vector3d(x, 0, 3) - 3.0 * axis, axis, 0.0, false};
    };
    geometry::PathFile leaning = path;
    leaning.postures[0] = ball(5);
    leaning.postures[1] = leaning.postures[2] = ball(15);
    leaning.postures[3] = Posture{leaning.postures[1].tip_mm + 10.0 * axis, axis, 0.0, false};
    leaning.postures[4] = Posture{Eigen::Vector3d(40, 0, 10), Eigen::Vector3d::UnitZ(), 0.0, false};
    const LinkPartResult out = checkLinksAgainstPart(checker, grazing, leaning);
    EXPECT_EQ(out.colliding_postures, 0u) << lean;
    EXPECT_EQ(out.colliding_motions, lean > 0 ? 1u : 0u) << lean;
    if (lean > 0) EXPECT_EQ(out.first_colliding_motion, 2u);  // posture 2 (the pass's end) to 3
    EXPECT_EQ(out.motion_contacts,
              lean > 0 ? std::vector<std::size_t>{2} : std::vector<std::size_t>{});
  }
  // A pass finishing the floor along a wall of the part, the ball tangent to both: its retract
  // and plunge along the axis slide up the wall, tangent to it all the way: not a collision.
  geometry::TriangleMesh corner;
  pathgen::test::addBox(corner, -10, 50, -10, 10, -5, 0);  // the floor
  pathgen::test::addBox(corner, -10, 50, 3, 10, 0, 30);    // a wall along the pass, 3 mm off
  const ClearanceChecker corner_checker(geometry::toolMesh(tool, {}, 0.02), {&corner, 1}, 0.02);
  const GrazingChecker corner_grazing = grazingPartChecker(tool, {}, corner);
  geometry::PathFile along = path;
  along.postures = {posture(0, 0),   posture(10, 0), posture(10, 0), posture(10, 40),
                    posture(40, 40), posture(40, 0), posture(40, 0), posture(45, 0)};
  const LinkPartResult tangent = checkLinksAgainstPart(corner_checker, corner_grazing, along);
  EXPECT_EQ(tangent.motions, 3u);  // the travel at z = 40, the retract and the plunge
  EXPECT_FALSE(tangent.collides());
}

// The holder against the part at every posture and motion: a pass on the floor beside a wall of
// the part (the ball 8 mm from it, the holder's r 12 section reaching 4 mm into it) collides at
// each posture and motion, whatever the ball does; 5 mm farther off it clears by the distance
// left (1 mm, less the chordal tolerance); with no holder there is nothing to check.
TEST(Links, TheHolderIntoThePartIsReportedAtEveryPostureAndMotion) {
  const geometry::ToolSpec tool{geometry::ToolShape::Ball, 3.0, 0.0, 40.0};
  const geometry::HolderProfile holder = {{40, 6}, {55, 6}, {55, 12}, {90, 12}};
  geometry::TriangleMesh part;
  pathgen::test::addBox(part, -30, 7, -30, 30, -10, 0);  // the floor
  pathgen::test::addBox(part, 8, 30, -30, 30, -10, 60);  // a wall 60 mm high beside the pass
  auto pass = [](double x) {
    std::vector<Posture> p;
    for (int i = 0; i <= 20; ++i)
      p.push_back(
          Posture{Eigen::Vector3d(x, -5 + 0.5 * i, 0), Eigen::Vector3d::UnitZ(), 0.0, false});
    return p;
  };
  const auto into = checkHolderAgainstPart(tool, holder, part, pass(0.0));
  ASSERT_TRUE(into.has_value());
  EXPECT_EQ(into->postures, 21u);
  EXPECT_EQ(into->colliding_postures, 21u);
  EXPECT_EQ(into->colliding_motions, 20u);
  EXPECT_EQ(into->first_colliding_posture, 0u);
  ASSERT_EQ(into->posture_contacts.size(), 21u);
  ASSERT_EQ(into->motion_contacts.size(), 20u);
  for (std::size_t i = 0; i < 21; ++i) EXPECT_EQ(into->posture_contacts[i], i);
  for (std::size_t i = 0; i < 20; ++i) EXPECT_EQ(into->motion_contacts[i], i);
  // The marks of a path: both lists as one flag a posture (this pass is the whole path).
  const PartContacts contacts{std::nullopt, into};
  const PartContacts::Marks marks = contacts.marks(21);
  EXPECT_EQ(std::count(marks.posture.begin(), marks.posture.end(), 1), 21);
  EXPECT_EQ(std::count(marks.motion.begin(), marks.motion.end(), 1), 20);
  EXPECT_EQ(marks.motion[20], 0);  // no motion after the last posture
  const auto clear = checkHolderAgainstPart(tool, holder, part, pass(-5.0));
  ASSERT_TRUE(clear.has_value());
  EXPECT_FALSE(clear->collides());
  EXPECT_TRUE(clear->posture_contacts.empty() && clear->motion_contacts.empty());
  EXPECT_NEAR(clear->min_clearance_mm, 1.0 - 0.02, 0.03);
  EXPECT_FALSE(checkHolderAgainstPart(tool, {}, part, pass(0.0)).has_value());
  // The tip resting on the top of a closed part: the holder 40 mm above it is clear (the tip was
  // the point of the "inside the part" test: on the face, its parity read "inside" at this y).
  const geometry::TriangleMesh block = boxMesh(20, 60, -40, 40, -10, 37);
  const std::vector<Posture> on_top = {
      Posture{Eigen::Vector3d(40, 19.6551724, 37), Eigen::Vector3d::UnitZ(), 0.0, false},
      Posture{Eigen::Vector3d(40, -30, 37), Eigen::Vector3d::UnitZ(), 0.0, false}};
  const auto above = checkHolderAgainstPart(tool, holder, block, on_top);
  ASSERT_TRUE(above.has_value());
  EXPECT_FALSE(above->collides());
  // (the motions' bound: within max(0.01 mm, 1 %) of the closest posture, less the resolution)
  EXPECT_LE(above->min_clearance_mm, 40.0 - 0.02 + 1e-9);
  EXPECT_GE(above->min_clearance_mm, (40.0 - 0.02) * 0.99 - 0.006);
}
