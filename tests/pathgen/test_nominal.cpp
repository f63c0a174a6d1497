/// Passes from a nominal path file: pass breaks (markers, blank lines, gaps, APT RAPID), frames at
/// degenerate postures, the largest axis turn (marked path files read back: test_path_files.cpp;
/// links and motions: test_links.cpp).
#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "fieldpath/common/errors.h"
#include "fieldpath/geometry/cl_file.h"
#include "fieldpath/geometry/tool_model.h"
#include "fieldpath/pathgen/clearance.h"
#include "fieldpath/pathgen/link_check.h"
#include "fieldpath/pathgen/links.h"
#include "fieldpath/pathgen/passes.h"
#include "fixtures.h"
#include "run_fieldpath.h"

using namespace fieldpath;
using namespace fieldpath::pathgen;
using fieldpath::test::TempDir;
using geometry::PathBlock;
using geometry::PathFile;
using geometry::Posture;
using pathgen::test::boxMesh;
using pathgen::test::errorOf;

namespace {

constexpr double kR = 3.0;

/// "x y z 0 0 1" lines along x at height z, every `step` mm from x0 to x1.
std::string straightLines(double x0, double x1, double step, double y, double z = 0.0) {
  std::string text;
  for (double x = x0; x <= x1 + 1e-9; x += step)
    text += std::to_string(x) + " " + std::to_string(y) + " " + std::to_string(z) + " 0 0 1\n";
  return text;
}

}  // namespace

// A lead written in the nominal path is not kept (the frame's n is the axis made square to the
// feed): each pass says how far its axes lean along the feed and where, for generate's note. A
// straight pass along x whose axes lean 20° towards +x from its third posture on (line 4; the
// feed there bends with the ball centre's step, so the full 20° is first met at line 5), and one
// with vertical axes.
TEST(NominalPasses, TheAxesLeanAlongTheFeedIsMeasured) {
  const double lean = 20.0 * M_PI / 180.0;
  std::string text = "# pass 1\n";
  for (int k = 0; k <= 10; ++k)
    text += std::to_string(k) + " 0 0 " + (k < 2 ? std::string("0 0 1")
                                                   : std::to_string(std::sin(lean)) + " 0 " +
                                                         std::to_string(std::cos(lean))) +
            "\n";
  text += "# pass 2\n" + straightLines(0, 10, 1, 10);
  TempDir dir;
  const auto passes =
      nominalPasses(geometry::readPathFile(dir.write("lean.cl", text)), PathParams{}, kR);
  ASSERT_EQ(passes.size(), 2u);
  EXPECT_NEAR(passes[0].nominal_lean_deg, 20.0, 1e-4);
  EXPECT_NE(passes[0].nominal_lean_at.find("lean.cl:5"), std::string::npos)
      << passes[0].nominal_lean_at;
  EXPECT_NEAR(passes[1].nominal_lean_deg, 0.0, 1e-9);
}

TEST(PathBlocks, ClMarkersBlankLinesAndLinksMakeBlocks) {
  TempDir dir;
  const auto file = dir.write("p.cl", "# header\n# pass 1\n" + straightLines(0, 2, 1, 0) +
                                          "# link\n5 5 20 0 0 1\n# pass 2\n" +
                                          straightLines(0, 1, 1, 4) + "\n" +
                                          straightLines(0, 1, 1, 8));
  const PathFile path = geometry::readPathFile(file);
  ASSERT_EQ(path.postures.size(), 8u);
  const std::vector<PathBlock> expected = {{PathBlock::Kind::Pass, 0, 3},
                                           {PathBlock::Kind::Link, 3, 4},
                                           {PathBlock::Kind::Pass, 4, 6},
                                           {PathBlock::Kind::Pass, 6, 8}};
  EXPECT_EQ(path.blocks, expected);
  EXPECT_EQ(path.lines[3], 7u);  // the line of the link posture
  // Nominal passes drop the link: three passes.
  EXPECT_EQ(nominalPasses(path, PathParams{}, kR).size(), 3u);
}

TEST(PathBlocks, AptRapidMovesAreLinksAndRecordsAreReadPast) {
  TempDir dir;
  const auto file = dir.write("p.apt",
                              "PARTNO/TEST $$ a comment\nUNITS/MM\nMULTAX/ON\nLOAD/TOOL,1\n"
                              "SPINDL/RPM,12000,CLW\nFEDRAT/MMPM,800\n"
                              "GOTO / 0, 0, 0, 0, 0, 1\nGOTO/1,0,0,$\n 0,0,1\nGOTO/2,0,0\n"
                              "RAPID\nGOTO/2,0,20,0,0,1\nRAPID\nGOTO/0,5,20,0,0,1\n"
                              "FEDRAT/MMPM,800\nGOTO/0,5,0,0,0,1\nGOTO/1,5,0,0,0,1\n"
                              "COOLNT/ON\nEND-OF-PATH\nFINI\n");
  const PathFile path = geometry::readPathFile(file);
  const std::vector<PathBlock> expected = {{PathBlock::Kind::Pass, 0, 3},
                                           {PathBlock::Kind::Link, 3, 5},
                                           {PathBlock::Kind::Pass, 5, 7}};
  EXPECT_EQ(path.blocks, expected);
  EXPECT_EQ(path.postures[2].axis, Eigen::Vector3d::UnitZ());  // a 3-value GOTO keeps the axis
  EXPECT_EQ(path.lines[1], 8u);                                // the record's first line
  EXPECT_EQ(nominalPasses(path, PathParams{}, kR).size(), 2u);
}

// A zig-zag in one block whose step-overs hold one posture between the legs: three passes, the
// legs, and the two postures between them counted, with the first (they went unsaid: a
// newcomer's 1319 postures came out as 1308 on 12 passes); repeats counted apart.
TEST(PathBlocks, PosturesBetweenTheLegsOfAZigZagAreCounted) {
  std::ostringstream text;
  text << "# pass 1\n";
  for (int k = 0; k <= 10; ++k) text << k << " 0 0 0 0 1\n";  // postures 0-10
  text << "10 0.5 0 0 0 1\n";                                 // 11: between the legs
  for (int k = 10; k >= 0; --k) text << k << " 1 0 0 0 1\n";  // 12-22
  text << "0 1.5 0 0 0 1\n0 1.5 0 0 0 1\n";                   // 23 and its repeat
  for (int k = 0; k <= 10; ++k) text << k << " 2 0 0 0 1\n";  // 25-35
  TempDir dir;
  const PathFile path = geometry::readPathFile(dir.write("zigzag.cl", text.str()));
  NominalDropped dropped;
  const auto passes = nominalPasses(path, PathParams{}, kR, &dropped);
  ASSERT_EQ(passes.size(), 3u);
  for (const Pass& pass : passes) EXPECT_EQ(pass.samples.size(), 11u) << pass.label;
  EXPECT_EQ(dropped.between_legs, 3u);  // 11, 23 and its repeat
  EXPECT_EQ(dropped.first_between, 11u);
  EXPECT_EQ(dropped.repeated, 0u);  // (the repeat lies between the legs, in no pass)
  // A repeat changes no pass: the return leg's first posture written twice (its first copy ended
  // the turn, and the turn of one posture became a pass of two, a reviewer's case) gives the
  // same three legs, the step-over posture the link's.
  std::ostringstream twice;
  twice << "# pass 1\n";
  for (int k = 0; k <= 10; ++k) twice << k << " 0 0 0 0 1\n";
  twice << "10 0.5 0 0 0 1\n10 1 0 0 0 1\n";  // between the legs, then the return leg's first
  for (int k = 10; k >= 0; --k) twice << k << " 1 0 0 0 1\n";
  const auto legs =
      nominalPasses(geometry::readPathFile(dir.write("twice.cl", twice.str())), {}, kR);
  ASSERT_EQ(legs.size(), 2u);
  EXPECT_EQ(legs[0].samples.size(), 11u);
  EXPECT_EQ(legs[1].samples.size(), 11u);
}

TEST(PathBlocks, GapsSplitPassesAtFourMedianSteps) {
  // Steps of 0.5 mm, then a jump of 2.1 mm (> 4 × 0.5): two passes; with pass_gap 3: one.
  const std::string text = straightLines(0, 5, 0.5, 0) + straightLines(7.1, 10, 0.5, 0);
  TempDir dir;
  const PathFile path = geometry::readPathFile(dir.write("g.cl", text));
  ASSERT_EQ(path.blocks.size(), 1u);
  NominalDropped split;
  const auto passes = nominalPasses(path, PathParams{}, kR, &split);
  ASSERT_EQ(passes.size(), 2u);
  EXPECT_EQ(passes[0].samples.size(), 11u);
  EXPECT_NEAR(passes[0].length_mm, 5.0, 1e-9);
  // The move between them, said (generate's note): after line 11, 2.1 mm, over 4 x 0.5.
  ASSERT_EQ(split.gaps.size(), 1u);
  EXPECT_EQ(split.gaps[0].at, 11u);
  EXPECT_NEAR(split.gaps[0].move_mm, 2.1, 1e-9);
  EXPECT_NEAR(split.gaps[0].gap_mm, 2.0, 1e-9);
  PathParams wide;
  wide.pass_gap_mm = 3.0;
  NominalDropped none;
  EXPECT_EQ(nominalPasses(path, wide, kR, &none).size(), 1u);
  EXPECT_TRUE(none.gaps.empty());

  // DESIGN's gap is the tips': tips 0.5 mm apart whose axis swings 60 deg once throw the ball
  // centre 3 mm (> 4 × 0.5), one pass still (it read as two, with a link generate made in it,
  // where check read one); a flip so is named at its line, not called a pass of its own.
  std::string swing, flip;
  for (int k = 0; k < 12; ++k) {
    const std::string tip = std::to_string(0.5 * k) + " 20 0 ";
    swing += tip + (k < 6 ? "0 0 1\n" : "0 -0.8660254037844386 0.5\n");
    flip += tip + (k < 6 ? "0 0 1\n" : "0 0 -1\n");
  }
  EXPECT_EQ(passRanges(geometry::readPathFile(dir.write("swing.cl", swing)), 0.0, kR).size(), 1u);
  // ... also swung along the feed (about the binormal): the centre's jump back is no zig-zag.
  std::string lead;
  for (int k = 0; k < 12; ++k)
    lead +=
        std::to_string(0.5 * k) + " 20 0 " + (k < 6 ? "0 0 1\n" : "-0.8660254037844386 0 0.5\n");
  EXPECT_EQ(nominalPasses(geometry::readPathFile(dir.write("lead.cl", lead)), {}, kR).size(), 1u);
  const std::string m =
      errorOf([&] { nominalPasses(geometry::readPathFile(dir.write("flip6.cl", flip)), {}, kR); });
  EXPECT_NE(m.find("flip6.cl:7: the tool axis turns 180 deg"), std::string::npos) << m;
  // A swivel about a steady ball centre in mid-pass (15°, 30°, 45°), written to 6 decimals: the
  // centre moves a few nm up, then down, which read as the feed turning back and left "pass 2
  // has a single posture" (a helper's lines). One pass.
  std::string swivel;
  for (int k = 0; k <= 6; ++k) swivel += std::to_string(-3.0 + 0.5 * k) + " 0 0 0 0 1\n";
  swivel +=
      "0.000000 0.776457 0.102223 0.000000 -0.258819 0.965926\n"
      "0.000000 1.500000 0.401924 0.000000 -0.500000 0.866025\n"
      "0.000000 2.121320 0.878680 0.000000 -0.707107 0.707107\n";
  for (int k = 1; k <= 6; ++k)
    swivel += std::to_string(0.5 * k) + " 2.121320 0.878680 0.000000 -0.707107 0.707107\n";
  const PathFile swivelled = geometry::readPathFile(dir.write("swivel.cl", swivel));
  EXPECT_EQ(passRanges(swivelled, 0.0, kR).size(), 1u);
  // ... and its frames run along the feed (+x) throughout: the swivel's postures are one place
  // (the centre's nm steps turned the frames 90°, a reviewer's finding).
  NominalDropped dropped;
  const auto swivel_passes = nominalPasses(swivelled, {}, kR, &dropped);
  ASSERT_EQ(swivel_passes.size(), 1u);
  EXPECT_EQ(dropped.repeated, 3u);
  for (const PassSample& sample : swivel_passes[0].samples)
    EXPECT_GT(sample.feed.x(), 0.999) << sample.s_mm;
}

TEST(NominalPasses, FramesFollowThePolylineAndKeepPosturesOneForOne) {
  // A circle of radius 20 in the plane z = 0, axis +z: f the tangent, n = +z, C = p + R e_z.
  std::string text;
  for (int k = 0; k <= 40; ++k) {
    const double t = k * 0.05;
    text +=
        std::to_string(20 * std::cos(t)) + " " + std::to_string(20 * std::sin(t)) + " 0 0 0 1\n";
  }
  TempDir dir;
  const PathFile path = geometry::readPathFile(dir.write("c.cl", text));
  const auto passes = nominalPasses(path, PathParams{}, kR);
  ASSERT_EQ(passes.size(), 1u);
  ASSERT_EQ(passes[0].samples.size(), 41u);
  for (std::size_t k = 0; k < 41; ++k) {
    const PassSample& s = passes[0].samples[k];
    const double t = k * 0.05;
    EXPECT_NEAR((s.centre_mm - (path.postures[k].tip_mm + kR * Eigen::Vector3d::UnitZ())).norm(), 0,
                1e-12);
    EXPECT_NEAR((s.normal - Eigen::Vector3d::UnitZ()).norm(), 0, 1e-12);
    // Central differences of a circle: the tangent exactly, away from the ends.
    if (k > 0 && k < 40)
      EXPECT_NEAR((s.feed - Eigen::Vector3d(-std::sin(t), std::cos(t), 0)).norm(), 0, 1e-6);
    EXPECT_NEAR(s.binormal.norm(), 1.0, 1e-12);
  }
  // Between postures the frame stays orthonormal and finite.
  for (double s_mm = 0; s_mm <= passes[0].length_mm; s_mm += 0.137) {
    const PassSample s = passes[0].at(s_mm);
    EXPECT_NEAR(s.feed.norm(), 1, 1e-12);
    EXPECT_NEAR(s.feed.dot(s.normal), 0, 1e-12);
  }
  // With path.step the pass is resampled evenly.
  PathParams step;
  step.step_given = true;
  step.step_mm = 0.25;
  const auto resampled = nominalPasses(path, step, kR);
  EXPECT_EQ(resampled[0].samples.size(),
            static_cast<std::size_t>(std::ceil(resampled[0].length_mm / 0.25 - 1e-9)) + 1);
}

// path.step keeps the corners it would cut (a helper's 90° corner at step 1.8: the written
// centre line passed 0.385 mm inside it, unsaid) and steps over a smooth curve's small turns.
TEST(NominalPasses, AResampledPassKeepsItsCornersAndStepsOverSmoothTurns) {
  TempDir dir;
  // An L: 50 mm along x, then 40 mm along y, a posture every 1 mm.
  std::string text = straightLines(0, 50, 1, 0);
  for (int y = 1; y <= 40; ++y) text += "50 " + std::to_string(y) + " 0 0 0 1\n";
  PathParams step;
  step.step_given = true;
  step.step_mm = 1.8;
  const auto corner = nominalPasses(geometry::readPathFile(dir.write("l.cl", text)), step, kR);
  ASSERT_EQ(corner.size(), 1u);
  const Eigen::Vector3d vertex(50, 0, kR);  // the corner's ball centre
  double nearest = HUGE_VAL, widest = 0.0;
  const auto& samples = corner[0].samples;
  for (std::size_t k = 0; k < samples.size(); ++k) {
    nearest = std::min(nearest, (samples[k].centre_mm - vertex).norm());
    if (k > 0) widest = std::max(widest, (samples[k].centre_mm - samples[k - 1].centre_mm).norm());
  }
  EXPECT_LT(nearest, 1e-12);
  EXPECT_LE(widest, 1.8 + 1e-9);
  // 50 mm in 28 steps, 40 in 23 (a step each of 50/28 and 40/23 mm): 52 stations.
  EXPECT_EQ(samples.size(), 52u);
  // A 90 mm straight pass at 0.25 mm: 360 steps (361 by its length's rounding before).
  step.step_mm = 0.25;
  const auto straight = nominalPasses(
      geometry::readPathFile(dir.write("s.cl", straightLines(0, 90, 0.1, 0))), step, kR);
  EXPECT_EQ(straight[0].samples.size(), 361u);
  // An arc of radius 50 every 0.05 mm (0.057° a posture: cut by 0.25 mm · sin(0.029°) = 0.1 um)
  // resampled every 0.5 mm: evenly, its vertices stepped over.
  std::string arc;
  for (int k = 0; k <= 400; ++k) {
    const double t = k * 0.001;
    arc += std::to_string(50 * std::cos(t)) + " " + std::to_string(50 * std::sin(t)) + " 0 0 0 1\n";
  }
  step.step_mm = 0.5;
  const auto smooth = nominalPasses(geometry::readPathFile(dir.write("a.cl", arc)), step, kR);
  EXPECT_EQ(smooth[0].samples.size(),
            static_cast<std::size_t>(std::ceil(smooth[0].length_mm / 0.5 * (1 - 1e-6))) + 1);
}

TEST(NominalPasses, DegeneratePosturesAreClearErrorsNamingTheLine) {
  TempDir dir;
  // Feed along the axis (a plunge) on line 3.
  const auto plunge = dir.write("plunge.cl", "0 0 0 1 0 0\n1 0 0 1 0 0\n2 0 0 1 0 0\n");
  const std::string m1 = errorOf([&] { nominalPasses(geometry::readPathFile(plunge), {}, kR); });
  EXPECT_NE(m1.find("plunge.cl:1:"), std::string::npos) << m1;
  EXPECT_NE(m1.find("along the tool axis"), std::string::npos) << m1;
  // A pass of two identical postures.
  const auto twice =
      dir.write("twice.cl", straightLines(0, 3, 1, 0) + "# pass\n5 5 0 0 0 1\n5 5 0 0 0 1\n");
  const std::string m2 = errorOf([&] { nominalPasses(geometry::readPathFile(twice), {}, kR); });
  EXPECT_NE(m2.find("twice.cl:6:"), std::string::npos) << m2;
  EXPECT_NE(m2.find("pass 2"), std::string::npos) << m2;
  // One posture.
  const auto one = dir.write("one.cl", "1 2 3 0 0 1\n");
  const std::string m3 = errorOf([&] { nominalPasses(geometry::readPathFile(one), {}, kR); });
  EXPECT_NE(m3.find("one.cl:1:"), std::string::npos) << m3;
  // Repeated postures inside a pass are dropped and counted, the rest keeps finite frames.
  const auto repeated = dir.write("rep.cl", "0 0 0 0 0 1\n1 0 0 0 0 1\n1 0 0 0 0 1\n2 0 0 0 0 1\n");
  NominalDropped dropped;
  const auto passes = nominalPasses(geometry::readPathFile(repeated), {}, kR, &dropped);
  EXPECT_EQ(dropped.repeated, 1u);
  EXPECT_EQ(dropped.between_legs, 0u);
  ASSERT_EQ(passes[0].samples.size(), 3u);
  for (const auto& s : passes[0].samples) EXPECT_TRUE(s.feed.allFinite() && s.normal.allFinite());
  // An axis flipped on line 3 (0 0 -1 among 0 0 1): named with the turn; 60 deg is a path.
  const auto flipped =
      dir.write("flip.cl", "0 0 0 0 0 1\n1 0 0 0 0 1\n2 0 0 0 0 -1\n3 0 0 0 0 1\n");
  const std::string m4 = errorOf([&] { nominalPasses(geometry::readPathFile(flipped), {}, kR); });
  EXPECT_NE(m4.find("flip.cl:3: the tool axis turns 180 deg"), std::string::npos) << m4;
  const auto turned = dir.write("turn.cl", "0 0 0 0 0 1\n1 0 0 0 0 1\n2 0 0 0 0.866 0.5\n");
  EXPECT_EQ(nominalPasses(geometry::readPathFile(turned), {}, kR).size(), 1u);
}

// Approaches and retracts that CAM systems write as feed moves are the links' (made anew): a move
// down the axis before the cut and up it after, and a lone posture a gap parts from the cut (an
// approach's start after FEDRAT: "pass 1 has a single posture"). The pass is the cut's, a step
// along the axis within it included.
TEST(NominalPasses, ApproachesAndRetractsAtFeedAreTheLinks) {
  TempDir dir;
  std::string cut;
  for (int x = 0; x <= 10; ++x) cut += std::to_string(x) + " 0 0 0 0 1\n";
  // Lines 1-2 the approach (z 10, 2), 3-13 the cut, 14 the retract up the axis.
  const auto ends = dir.write("ends.cl", "0 0 10 0 0 1\n0 0 2 0 0 1\n" + cut + "10 0 3 0 0 1\n");
  NominalDropped dropped;
  const auto passes = nominalPasses(geometry::readPathFile(ends), {}, kR, &dropped);
  ASSERT_EQ(passes.size(), 1u);
  EXPECT_DOUBLE_EQ(passes[0].length_mm, 10.0);
  EXPECT_EQ(passes[0].samples.size(), 11u);
  EXPECT_DOUBLE_EQ(passes[0].samples.front().centre_mm.x(), 0.0);
  EXPECT_DOUBLE_EQ(passes[0].samples.front().centre_mm.z(), kR);
  EXPECT_EQ(dropped.approaches, 3u);
  EXPECT_EQ(dropped.first_approach, 0u);
  // The approach's start 20 mm above, a gap from the cut: alone, dropped.
  const auto lone = dir.write("lone.cl", "0 0 20 0 0 1\n" + cut);
  NominalDropped alone;
  const auto after_gap = nominalPasses(geometry::readPathFile(lone), {}, kR, &alone);
  ASSERT_EQ(after_gap.size(), 1u);
  EXPECT_DOUBLE_EQ(after_gap[0].length_mm, 10.0);
  EXPECT_EQ(alone.approaches, 1u);
  // Straight down z with the tool tilted 11.3 deg, in steps no gap parts from the cut: not along
  // the axis, so the cut's (a ball climbing a 75 deg wall with the axis upright steps 15 deg off
  // it, and was dropped as an approach when 30 deg did: a regression hunt).
  std::string tilted_cut;
  for (int x = 0; x <= 10; ++x)
    tilted_cut += std::to_string(x) + " 0 0 0 0.19611613513818402 0.98058067569092010\n";
  const auto tilted = dir.write("tilted.cl",
                                "0 0 3 0 0.19611613513818402 0.98058067569092010\n0 0 1.5 0 "
                                "0.19611613513818402 0.98058067569092010\n" +
                                    tilted_cut);
  NominalDropped down_z;
  const auto tilted_passes = nominalPasses(geometry::readPathFile(tilted), {}, kR, &down_z);
  ASSERT_EQ(tilted_passes.size(), 1u);
  EXPECT_EQ(down_z.approaches, 0u);
  EXPECT_EQ(tilted_passes[0].samples.size(), 13u);
  // Along the axis, the pass is named by its first cut line.
  const auto along = dir.write("along.cl", "0 0 3 0 0 1\n0 0 1.5 0 0 1\n" + cut);
  const auto along_passes = nominalPasses(geometry::readPathFile(along), {}, kR);
  ASSERT_EQ(along_passes.size(), 1u);
  EXPECT_NE(along_passes[0].label.find("along.cl:3"), std::string::npos) << along_passes[0].label;
  // A cut written as its two ends at a pass's start (7 mm along the floor, then steps of 1 mm):
  // the lone posture is reached across the axis, no approach: refused as before, not dropped.
  std::string two_ends = "-7 0 0 0 0 1\n" + cut;
  const std::string lone_cut = errorOf(
      [&] { nominalPasses(geometry::readPathFile(dir.write("ends2.cl", two_ends)), {}, kR); });
  EXPECT_NE(lone_cut.find("a single posture"), std::string::npos) << lone_cut;
  // A plunge down the axis at the end is no retract: the cut's, refused at its line (it was
  // dropped as a retract, its cut lost: a reviewer's).
  const auto plunge_end = dir.write("plunge_end.cl", cut + "10 0 -1 0 0 1\n");
  const std::string end_error =
      errorOf([&] { nominalPasses(geometry::readPathFile(plunge_end), {}, kR); });
  EXPECT_NE(end_error.find("along the tool axis"), std::string::npos) << end_error;
  // Down the axis in the middle of the cut (a step down a floor): the cut's, kept.
  std::string dip;
  for (int x = 0; x <= 5; ++x) dip += std::to_string(x) + " 0 0 0 0 1\n";
  dip += "5 0 -1 0 0 1\n";
  for (int x = 6; x <= 10; ++x) dip += std::to_string(x) + " 0 -1 0 0 1\n";
  NominalDropped within;
  const auto stepped =
      nominalPasses(geometry::readPathFile(dir.write("dip.cl", dip)), {}, kR, &within);
  ASSERT_EQ(stepped.size(), 1u);
  EXPECT_EQ(stepped[0].samples.size(), 12u);
  EXPECT_EQ(within.approaches, 0u);
}

TEST(NominalPasses, LargestAxisTurnIsOfThePassesAndItsClosedForm) {
  // Pass 1: the axis tilts 12 deg then 30 deg about y between postures 1 mm apart; a link whose
  // axis swings 80 deg is not a pass (rapid moves turn as they like); pass 2 turns 20 deg.
  auto at = [](double x, double deg) {
    const double r = deg * M_PI / 180.0;
    return Posture{Eigen::Vector3d(x, 0, 0), Eigen::Vector3d(std::sin(r), 0, std::cos(r)), 0.0,
                   false};
  };
  PathFile path;
  path.postures = {at(0, 0), at(1, 12), at(2, 42), at(2, 42), at(3, -38), at(4, 0), at(5, 20)};
  path.blocks = {
      {PathBlock::Kind::Pass, 0, 3}, {PathBlock::Kind::Link, 3, 5}, {PathBlock::Kind::Pass, 5, 7}};
  const AxisTurn t = largestAxisTurn(path, 3.0);
  EXPECT_NEAR(t.deg, 30.0, 1e-9);
  EXPECT_EQ(t.at, 1u);
  // The ball centres p + R a: (1 + 3 sin 12, 0, 3 cos 12) to (2 + 3 sin 42, 0, 3 cos 42).
  const double s12 = std::sin(12 * M_PI / 180), c12 = std::cos(12 * M_PI / 180);
  const double s42 = std::sin(42 * M_PI / 180), c42 = std::cos(42 * M_PI / 180);
  EXPECT_NEAR(t.step_mm, std::hypot(1 + 3 * (s42 - s12), 3 * (c42 - c12)), 1e-12);
  // A pass whose tips jump 10 mm (more than 4 x its median step) holds two passes: the
  // jump's 60 deg turn is a link's, not the cut's.
  PathFile jump = geometry::singlePass({at(0, 0), at(1, 0), at(2, 5), at(12, 65), at(13, 65)});
  const AxisTurn j = largestAxisTurn(jump, 3.0);
  EXPECT_NEAR(j.deg, 5.0, 1e-9);
  EXPECT_EQ(j.at, 1u);
  // The axis leaning forward 45 deg in 1 mm of the ball centre's travel: the tip moves back
  // 1.12 mm, which read as the feed turning back (a new pass) and the turn went uncounted (a
  // helper's finding); the passes follow the ball centres.
  auto centred = [](double x, double deg) {
    const double r = deg * M_PI / 180.0;
    const Eigen::Vector3d axis(std::sin(r), 0, std::cos(r));
    return Posture{Eigen::Vector3d(x, 0, 3) - 3.0 * axis, axis, 0.0, false};
  };
  const PathFile forward =
      geometry::singlePass({centred(0, 0), centred(1, 45), centred(2, 45), centred(3, 45)});
  ASSERT_LT(forward.postures[1].tip_mm.x(), forward.postures[0].tip_mm.x());
  const AxisTurn f = largestAxisTurn(forward, 3.0);
  EXPECT_NEAR(f.deg, 45.0, 1e-9);
  EXPECT_EQ(f.at, 0u);
  EXPECT_NEAR(f.step_mm, 1.0, 1e-12);
  EXPECT_EQ(passRanges(forward, 0.0, 3.0).size(), 1u);
  // A file with markers: every move of a pass block is cut. A posture turned 15 deg about its
  // tip throws the ball centre 0.78 mm on, past the next one: passRanges splits the block there,
  // and the turn went unwarned (a newcomer's audit).
  PathFile marked;
  marked.postures = {at(0, 0), at(0.5, 0), at(1, 15), at(1.5, 0), at(2, 0), at(20, 0), at(21, 0)};
  marked.blocks = {
      {PathBlock::Kind::Pass, 0, 5}, {PathBlock::Kind::Link, 5, 6}, {PathBlock::Kind::Pass, 6, 7}};
  ASSERT_GT(passRanges(marked, 0.0, 3.0).size(), 2u);
  const AxisTurn m = largestAxisTurn(marked, 3.0);
  EXPECT_NEAR(m.deg, 15.0, 1e-9);
  EXPECT_EQ(m.at, 1u);
  // No pass of two postures: no turn.
  PathFile single = geometry::singlePass({at(0, 0)});
  EXPECT_EQ(largestAxisTurn(single, 3.0).at, static_cast<std::size_t>(-1));
  EXPECT_EQ(largestAxisTurn(single, 3.0).deg, 0.0);
}
