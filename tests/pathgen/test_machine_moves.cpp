/// pathgen::axisByAngles and rotaryStray against closed forms: the angles interpolated (tilt
/// from z and C about z, each linear), and the stray of a motion near the vertical whose C swings
/// 120 deg for 8.7 deg of axis turn (a machine-side helper's case: check said ok, a post writing
/// angles crossed the obstacle).
#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "fieldpath/pathgen/machine_moves.h"

namespace fieldpath::pathgen {
namespace {

using geometry::Posture;

Vec3 tilted(double tilt_deg, double azimuth_deg) {
  const double t = tilt_deg * M_PI / 180.0, a = azimuth_deg * M_PI / 180.0;
  return {std::sin(t) * std::cos(a), std::sin(t) * std::sin(a), std::cos(t)};
}

void expectNear(const Vec3& got, const Vec3& want) {
  EXPECT_NEAR((got - want).norm(), 0.0, 1e-12) << got.transpose() << " vs " << want.transpose();
}

TEST(RotaryAngles, TiltAndCAreEachLinear) {
  expectNear(axisByAngles(tilted(5, 0), tilted(5, 120), 0.5), tilted(5, 60));
  expectNear(axisByAngles(tilted(10, 30), tilted(40, 30), 0.25), tilted(17.5, 30));
  // C the shorter way round: 170 to -170 deg passes 180, not 0.
  expectNear(axisByAngles(tilted(20, 170), tilted(20, -170), 0.5), tilted(20, 180));
  // An axis on the vertical has no C of its own: C stays at the other's.
  expectNear(axisByAngles(Vec3::UnitZ(), tilted(30, 75), 0.5), tilted(15, 75));
  expectNear(axisByAngles(tilted(30, -40), Vec3::UnitZ(), 0.5), tilted(15, -40));
  expectNear(axisByAngles(tilted(30, -40), tilted(12, 95), 0.0), tilted(30, -40));
  expectNear(axisByAngles(tilted(30, -40), tilted(12, 95), 1.0), tilted(12, 95));
}

TEST(RotaryAngles, TheStrayOfAMotionNearTheVerticalAgainstItsClearance) {
  std::vector<Posture> path(2);
  path[0].tip_mm = Vec3(0, 0, 0);
  path[0].axis = tilted(5, 0);
  path[1].tip_mm = Vec3(0.5, 0, 0);
  path[1].axis = tilted(5, 120);
  MotionResult motions;
  motions.tool_reach_mm = 100.0;
  // Symmetric in t: the largest gap is at t = 1/2 (sampled), between tilt 5 deg at C 60 and the
  // great circle's midpoint.
  const double expected =
      100.0 * (tilted(5, 60) - (path[0].axis + path[1].axis).normalized()).norm();
  ASSERT_GT(expected, 4.0);
  struct Case {
    double clearance_mm;
    std::size_t beyond, under;
  };
  for (const Case c : {Case{1.5, 1, 1}, Case{expected + 0.3, 0, 1}, Case{10.0, 0, 0},
                       Case{0.2, 0, 0}}) {  // 0.2: under the required 0.5 as checked: not here
    motions.clearance_mm = {c.clearance_mm};
    const RotaryStray s = rotaryStray(path, motions, 0.5);
    ASSERT_EQ(s.offset_mm.size(), 1u);
    EXPECT_NEAR(s.offset_mm[0], expected, 1e-9);
    EXPECT_EQ(s.max_at, 0u);
    EXPECT_EQ(s.beyond_clearance, c.beyond) << c.clearance_mm;
    EXPECT_EQ(s.under_required, c.under) << c.clearance_mm;
    EXPECT_NEAR(s.c_deg, 120.0, 1e-9);
    EXPECT_NEAR(s.turn_deg,
                2 * std::asin(std::sin(5 * M_PI / 180) * std::sin(M_PI / 3)) * 180 / M_PI, 1e-9);
  }
  // A turn in a plane through z (C still): the same arc at the same even pace, no stray (the
  // normalised chord that check paces by would read 0.069 mm here: not the angles' doing).
  path[0].axis = tilted(10, 30);
  path[1].axis = tilted(30, 30);
  motions.clearance_mm = {0.6};
  const RotaryStray plane = rotaryStray(path, motions, 0.5);
  EXPECT_LT(plane.offset_mm[0], 1e-12);
  EXPECT_EQ(plane.beyond_clearance, 0u);
  EXPECT_EQ(plane.under_required, 0u);
  EXPECT_NEAR(plane.c_deg, 0.0, 1e-9);
}

// A retract along an axis 30 deg off the vertical, 20 mm: run axis by axis its tip may pass the
// box's corner, 20 sin 30 cos 30 = 8.66 mm off the segment; a vertical one stays on it. Only the
// motions into link postures are rapids.
TEST(DogLegRapids, TheBoxOfARetractAgainstItsClearance) {
  geometry::PathFile path;
  const Vec3 axis = tilted(30, 0);
  path.postures.resize(4);
  path.postures[0].tip_mm = Vec3(0, 0, 0);                 // the pass's end
  path.postures[1].tip_mm = 20.0 * axis;                   // the retract
  path.postures[2].tip_mm = 20.0 * axis + Vec3(0, 0, 15);  // straight up
  path.postures[3].tip_mm = Vec3(50, 0, 0);                // the next pass (a feed move into it)
  for (Posture& p : path.postures) p.axis = axis;
  path.postures[3].axis = Vec3::UnitZ();
  path.blocks = {{geometry::PathBlock::Kind::Pass, 0, 1},
                 {geometry::PathBlock::Kind::Link, 1, 3},
                 {geometry::PathBlock::Kind::Pass, 3, 4}};
  MotionResult motions;
  motions.tool_reach_mm = 100.0;
  const double corner = 20.0 * std::sin(M_PI / 6) * std::cos(M_PI / 6);
  motions.clearance_mm = {corner + 0.6, 0.6, 0.6};  // the vertical climb: on its segment
  DogLegRapids d = dogLegRapids(path, motions, 0.5);
  EXPECT_EQ(d.rapids, 2u);  // 0 -> 1 and 1 -> 2; 2 -> 3 runs at the feed
  EXPECT_EQ(d.unproven, 0u);
  EXPECT_EQ(d.checked_under, 0u);
  motions.clearance_mm = {corner + 0.4, 0.6, 0.0};  // under 0.5 once the corner is off it
  d = dogLegRapids(path, motions, 0.5);
  EXPECT_EQ(d.unproven, 1u);
  EXPECT_EQ(d.lowest, 0u);
  EXPECT_NEAR(d.lowest_box_mm, corner, 1e-9);
  EXPECT_NEAR(d.lowest_bound_mm, 0.4, 1e-9);
  // A turn of the axis adds the tool's reach times its angle; a motion already under the
  // required clearance as checked is the check's to say.
  path.postures[2].axis = tilted(25, 0);
  motions.clearance_mm = {corner + 0.6, 0.6 + 100.0 * 5 * M_PI / 180 - 0.2, 0.6};
  d = dogLegRapids(path, motions, 0.5);
  EXPECT_EQ(d.unproven, 1u);
  EXPECT_EQ(d.lowest, 1u);
  EXPECT_NEAR(d.lowest_box_mm, 100.0 * 5 * M_PI / 180, 1e-9);
  motions.clearance_mm = {corner + 0.6, 0.3, 0.6};
  d = dogLegRapids(path, motions, 0.5);
  EXPECT_EQ(d.unproven, 0u);
  // Counted apart: a note over all the rapids called two colliding ones proven (a links
  // adversary's "the 7 rapid moves are proven clear", 2 of them colliding).
  EXPECT_EQ(d.checked_under, 1u);
}

}  // namespace
}  // namespace fieldpath::pathgen
