#include <cmath>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "fieldpath/common/errors.h"
#include "fieldpath/pathgen/passes.h"
#include "fixtures.h"

using namespace fieldpath;
using namespace fieldpath::pathgen;

// Closed form first: on a flat straight channel a pass is the straight line z = R, y = const.
TEST(Passes, FlatChannelGivesStraightLinesAtBallHeight) {
  ImpellerParams p = test::flatChannel();
  p.passes_v = {0.25, 0.75};
  const Impeller imp(p);
  PathParams path;
  path.passes = 3;
  path.step_mm = 0.7;
  const auto passes = impellerPasses(imp, path, 3.0);
  ASSERT_EQ(passes.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    const Pass& pass = passes[k];
    EXPECT_NEAR(pass.length_mm, 72.0, 1e-9);
    ASSERT_EQ(pass.samples.size(), 104u);  // ceil(72 / 0.7) = 103 intervals
    for (const PassSample& s : pass.samples) {
      EXPECT_NEAR(s.centre_mm.z(), 3.0, 1e-12);
      EXPECT_NEAR(s.centre_mm.y(), -5.0 + 5.0 * k, 1e-12);
      EXPECT_NEAR(s.centre_mm.x(), s.s_mm, 1e-9);
      EXPECT_NEAR((s.feed - Vec3::UnitX()).norm(), 0, 1e-9);
      EXPECT_NEAR((s.binormal - Vec3::UnitY()).norm(), 0, 1e-9);
    }
  }
  // Lead turns n about b towards f.
  const Vec3 a = nominalAxis(passes[0].samples[5], M_PI / 6);
  EXPECT_NEAR((a - Vec3(0.5, 0, std::sqrt(0.75))).norm(), 0, 1e-9);
}

TEST(Passes, OffsetCurvesAreArcLengthSteppedWithOrthonormalFrames) {
  const Impeller imp{ImpellerParams{}};
  const PathParams path;  // 7 passes, 0.5 mm
  const double r = 3.0;
  const auto passes = impellerPasses(imp, path, r);
  ASSERT_EQ(passes.size(), 7u);
  double total_mm = 0;
  for (const Pass& pass : passes) {
    total_mm += pass.length_mm;
    const double step = pass.samples[1].s_mm - pass.samples[0].s_mm;
    EXPECT_LE(step, path.step_mm + 1e-12);
    EXPECT_GT(step, path.step_mm * 0.98);
    for (size_t i = 0; i < pass.samples.size(); ++i) {
      const PassSample& s = pass.samples[i];
      // C = S + R n: the ball touches the hub at S(u, v).
      EXPECT_NEAR((s.centre_mm - r * s.normal - imp.hub(s.u, pass.v)).norm(), 0, 1e-9);
      EXPECT_NEAR(s.feed.norm(), 1, 1e-12);
      EXPECT_NEAR(s.feed.dot(s.normal), 0, 1e-9);
      EXPECT_NEAR((s.binormal - s.normal.cross(s.feed)).norm(), 0, 1e-12);
      if (i > 0) {  // chord between stations = arc-length step (flat enough at 0.5 mm)
        const double chord = (s.centre_mm - pass.samples[i - 1].centre_mm).norm();
        EXPECT_NEAR(chord, step, 1e-4);
        EXPECT_GT(s.feed.dot(s.centre_mm - pass.samples[i - 1].centre_mm), 0);
      }
    }
  }
  EXPECT_NEAR(total_mm, 500.0, 25.0);  // seed 004: 7 passes ≈ 500 mm
}

TEST(Passes, EmptyPassAndBadPathValuesNameThePassOrKey) {
  ImpellerParams p;
  p.u_range = {0.5, 0.5};
  const Impeller imp(p);
  try {
    impellerPasses(imp, PathParams{}, 3.0);
    FAIL();
  } catch (const common::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("pass 1"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("empty"), std::string::npos) << e.what();
  }
  const Impeller good{ImpellerParams{}};
  PathParams path;
  path.passes = 0;
  EXPECT_THROW(impellerPasses(good, path, 3.0), common::InputError);
  path = {};
  path.step_mm = 0;
  EXPECT_THROW(impellerPasses(good, path, 3.0), common::InputError);
}

TEST(Passes, AZigZagInOnePassBlockIsOnePassALeg) {
  // Forward along x, a 1 mm step-over in y, back along -x, another step-over, forward again:
  // one `# pass` block. The steering frame turns over with the feed, so each leg is a pass of
  // its own, starting with its first step; the step-overs fall between passes (links).
  geometry::PathFile path;
  const auto leg = [&](double y, double from, double to) {
    for (int k = 0; k <= 10; ++k)
      path.postures.push_back({Vec3(from + (to - from) * k / 10.0, y, 0), Vec3::UnitZ()});
  };
  leg(0, 0, 10);   // postures 0-10
  leg(1, 10, 0);   // 11-21 (posture 11 is the step-over's end)
  leg(2, 0, 10);   // 22-32
  path.blocks = {{geometry::PathBlock::Kind::Pass, 0, path.postures.size()}};
  const auto ranges = passRanges(path, 0.0, 1.0);
  ASSERT_EQ(ranges.size(), 3u);
  EXPECT_EQ(ranges[0], std::make_pair(std::size_t{0}, std::size_t{11}));
  EXPECT_EQ(ranges[1], std::make_pair(std::size_t{11}, std::size_t{22}));
  EXPECT_EQ(ranges[2], std::make_pair(std::size_t{22}, std::size_t{33}));
  // A block that starts with its step-over, where the block before ended (a continuous zig-zag
  // cut into `# pass` blocks, a helper's file): the step-over's start is no pass of its own
  // (nominalPasses refused it: "pass 2 has a single posture").
  geometry::PathFile continued;
  for (int k = 0; k <= 10; ++k) continued.postures.push_back({Vec3(k, 0, 0), Vec3::UnitZ()});
  continued.postures.push_back({Vec3(10, 0, 0), Vec3::UnitZ()});  // 11: where block 1 ended
  continued.postures.push_back({Vec3(11, 1, 0), Vec3::UnitZ()});  // 12: a step-over on the skew
  for (int k = 1; k <= 11; ++k) continued.postures.push_back({Vec3(11 - k, 1, 0), Vec3::UnitZ()});
  continued.blocks = {{geometry::PathBlock::Kind::Pass, 0, 11},
                      {geometry::PathBlock::Kind::Pass, 11, continued.postures.size()}};
  const auto legs = passRanges(continued, 0.0, 1.0);
  ASSERT_EQ(legs.size(), 2u);
  EXPECT_EQ(legs[0], std::make_pair(std::size_t{0}, std::size_t{11}));
  EXPECT_EQ(legs[1], std::make_pair(std::size_t{12}, std::size_t{24}));
  // Step-overs that lean back against the leg they end (a raster over a sloped floor, its tips
  // below centres on the surface normal: a helper's pocket): the leg keeps its last posture and
  // the step-over is the link (the leg's end went to the next pass, its corner cut in it).
  geometry::PathFile leaning;
  const auto legFrom = [&](double x0, double y, double dx) {
    for (int k = 0; k <= 10; ++k)
      leaning.postures.push_back({Vec3(x0 + dx * k, y, 0), Vec3::UnitZ()});
  };
  legFrom(0, 0, 1);     // 0-10, ends at x = 10
  legFrom(9.8, 1, -1);  // 11-21: the step-over 10 -> 11 leans back 0.2 mm
  legFrom(0.3, 2, 1);   // 22-32: this one 0.3 mm forward
  leaning.blocks = {{geometry::PathBlock::Kind::Pass, 0, leaning.postures.size()}};
  const auto leaning_legs = passRanges(leaning, 0.0, 1.0);
  ASSERT_EQ(leaning_legs.size(), 3u);
  EXPECT_EQ(leaning_legs[0], std::make_pair(std::size_t{0}, std::size_t{11}));
  EXPECT_EQ(leaning_legs[1], std::make_pair(std::size_t{11}, std::size_t{22}));
  EXPECT_EQ(leaning_legs[2], std::make_pair(std::size_t{22}, std::size_t{33}));
  // A square step-over and a return leg whose first step is followed by a kink (a reviewer's
  // case: the kink made that first step read as the step-over): the return leg starts after the
  // step-over, with its first step.
  geometry::PathFile kinked;
  for (int k = 0; k <= 9; ++k) kinked.postures.push_back({Vec3(k, 0, 0), Vec3::UnitZ()});
  kinked.postures.push_back({Vec3(10, 0, 1), Vec3::UnitZ()});  // 10: the leg's end, lifted
  kinked.postures.push_back({Vec3(10, 1, 1), Vec3::UnitZ()});  // 11: the step-over's end
  for (int k = 9; k >= 0; --k) kinked.postures.push_back({Vec3(k, 1, 0), Vec3::UnitZ()});
  kinked.blocks = {{geometry::PathBlock::Kind::Pass, 0, kinked.postures.size()}};
  const auto kinked_legs = passRanges(kinked, 0.0, 1.0);
  ASSERT_EQ(kinked_legs.size(), 2u);
  EXPECT_EQ(kinked_legs[0], std::make_pair(std::size_t{0}, std::size_t{11}));
  EXPECT_EQ(kinked_legs[1], std::make_pair(std::size_t{11}, std::size_t{22}));
  // Step-overs of several postures (square, leaning back) and a semicircle turn: the legs split
  // at the turn's ends, the turn between them the link (legs of 88/84/92 postures, the axis 43 deg
  // in one step, 30 postures colliding: a helper's pocket).
  for (const std::string shape : {"square", "leaning", "arc"}) {
    geometry::PathFile turns;
    const auto add = [&](double x, double y) {
      turns.postures.push_back({Vec3(x, y, 0), Vec3::UnitZ()});
    };
    std::vector<std::size_t> leg_starts;
    double x = 0.0;
    for (int k = 0; k < 3; ++k) {
      const double y = 2.0 * k, dir = k % 2 ? -1.0 : 1.0;  // this leg's feed along x
      if (k > 0) {  // the turn from the last leg's end: 3 postures between, then this leg's first
        for (int t = 1; t <= 3; ++t) {
          if (shape == "square") add(x, y - 2.0 + 0.5 * t);
          if (shape == "leaning") add(x + 0.3 * dir * t, y - 2.0 + 0.5 * t);  // back, 31 deg
          if (shape == "arc")
            add(x - dir * std::sin(M_PI * t / 4.0), y - 1.0 - std::cos(M_PI * t / 4.0));
        }
        if (shape == "leaning") x += 1.2 * dir;
      }
      leg_starts.push_back(turns.postures.size());
      for (int j = 0; j <= 10; ++j) add(x + dir * j, y);
      x += 10.0 * dir;
    }
    turns.blocks = {{geometry::PathBlock::Kind::Pass, 0, turns.postures.size()}};
    const auto ranges = passRanges(turns, 0.0, 1.5);
    // The legs, and between them the turns' 3 postures as passes of their own (the steps from
    // and to the legs the links: a contour's short side is not lost, no frame turns over).
    std::vector<std::pair<std::size_t, std::size_t>> legs;
    for (const auto& r : ranges)
      if (r.second - r.first > 4) legs.push_back(r);
    ASSERT_EQ(legs.size(), 3u) << shape;
    if (shape != "arc") {
      ASSERT_EQ(ranges.size(), 5u) << shape;
      for (int k = 0; k < 2; ++k)
        EXPECT_EQ(ranges[2 * k + 1], std::make_pair(leg_starts[k + 1] - 3, leg_starts[k + 1]))
            << shape << k;
    }
    for (int k = 0; k < 3; ++k) {
      if (shape != "arc") {
        EXPECT_EQ(legs[k], std::make_pair(leg_starts[k], leg_starts[k] + 11)) << shape << k;
        continue;
      }
      // The arc's first half goes with its leg, its second with the next.
      EXPECT_LE(legs[k].first, leg_starts[k]) << k;
      EXPECT_GE(legs[k].first + 3, leg_starts[k]) << k;
      EXPECT_GE(legs[k].second, leg_starts[k] + 11) << k;
      EXPECT_LE(legs[k].second, leg_starts[k] + 14) << k;
    }
  }
  // Small circles and a helix (20 deg a step) stay one pass (their arcs read as step-overs
  // and became links: a reviewer's case).
  geometry::PathFile circle;
  for (int j = 0; j <= 36; ++j) {
    const double a = 2.0 * M_PI * j / 18.0;
    circle.postures.push_back(
        {Vec3(2.5 * std::cos(a), 2.5 * std::sin(a), 0.05 * j), Vec3::UnitZ()});
  }
  circle.blocks = {{geometry::PathBlock::Kind::Pass, 0, circle.postures.size()}};
  EXPECT_EQ(passRanges(circle, 0.0, 3.0).size(), 1u);
  // A rectangle 20 x 4 followed around twice: its short sides are cut (in the passes), only the
  // first step of each the link.
  geometry::PathFile rectangle;
  const Vec3 rect[] = {Vec3(0, 0, 0), Vec3(20, 0, 0), Vec3(20, 4, 0), Vec3(0, 4, 0)};
  for (int loop = 0; loop < 2; ++loop)
    for (int side = 0; side < 4; ++side) {
      const Vec3 &a = rect[side], &b = rect[(side + 1) % 4];
      const int n = static_cast<int>((b - a).norm());
      for (int j = 0; j < n; ++j)
        rectangle.postures.push_back({a + (b - a) * j / n, Vec3::UnitZ()});
    }
  rectangle.postures.push_back({rect[0], Vec3::UnitZ()});
  rectangle.blocks = {{geometry::PathBlock::Kind::Pass, 0, rectangle.postures.size()}};
  std::size_t covered = 0, last_end = 0;
  for (const auto& [begin, end] : passRanges(rectangle, 0.0, 3.0)) {
    EXPECT_EQ(begin, last_end);  // no posture left out
    covered += end - begin;
    last_end = end;
  }
  EXPECT_EQ(covered, rectangle.postures.size());
  // A square loop whose corners turn 90 +- 10 deg (ball centres over a sloped floor) is one pass
  // (it was cut at random corners).
  geometry::PathFile loop;
  const Vec3 corners[] = {Vec3(0, 0, 0), Vec3(10, 0.9, 0), Vec3(10.9, 10, 0), Vec3(0, 9.1, 0),
                          Vec3(0, 1, 0)};
  for (int side = 0; side < 4; ++side)
    for (int j = 0; j < 10; ++j)
      loop.postures.push_back(
          {corners[side] + (corners[side + 1] - corners[side]) * j / 10.0, Vec3::UnitZ()});
  loop.blocks = {{geometry::PathBlock::Kind::Pass, 0, loop.postures.size()}};
  EXPECT_EQ(passRanges(loop, 0.0, 1.5).size(), 1u);
  // A corner of 90 deg (an L) is one pass still.
  geometry::PathFile corner;
  for (int k = 0; k <= 10; ++k) corner.postures.push_back({Vec3(k, 0, 0), Vec3::UnitZ()});
  for (int k = 1; k <= 10; ++k) corner.postures.push_back({Vec3(10, k, 0), Vec3::UnitZ()});
  corner.blocks = {{geometry::PathBlock::Kind::Pass, 0, corner.postures.size()}};
  EXPECT_EQ(passRanges(corner, 0.0, 1.0).size(), 1u);
}

// Steps of exactly the gap (4 x the median, or path.pass_gap) are no gap wherever they fall: the
// file's decimals read 2.000000000000007 at one x and 1.9999999999999964 at another, and one
// split the pass where others did not. A step 1 % over is a gap.
TEST(Passes, StepsOfExactlyThePassGapSplitNowhere) {
  for (const double gap_mm : {2.0, 2.02}) {
    geometry::PathFile file;
    double x = 0.0;
    for (int k = 0; k < 120; ++k) {
      x += k % 10 == 9 ? gap_mm : 0.5;  // a gap every 10 steps, at 12 different x
      char text[32];
      std::snprintf(text, sizeof text, "%.6f", 0.1234 + x);  // as a CAM file writes it
      file.postures.push_back({Vec3(std::stod(text), 0.7, 0.0), Vec3::UnitZ(), 0.0, false});
    }
    file.blocks.push_back({geometry::PathBlock::Kind::Pass, 0, file.postures.size()});
    for (const double pass_gap_mm : {0.0, 2.0}) {
      const auto ranges = passRanges(file, pass_gap_mm, 3.0);
      EXPECT_EQ(ranges.size(), gap_mm == 2.0 ? 1u : 13u) << gap_mm << " " << pass_gap_mm;
    }
  }
}
