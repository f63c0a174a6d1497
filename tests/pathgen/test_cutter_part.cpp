/// The cutter against the part, exactly (pathgen/cutter_part.h), against closed forms: an
/// upright shank beside a wall enters it by the wall's distance short of R; a shank tilted
/// towards a wall meets it with its top rim, e/(sin θ + cos θ) in the shrunk-all-round measure;
/// a rib passed by a motion between two clear postures; a cutter wholly inside a closed part.
#include <cmath>
#include <memory>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "fieldpath/geometry/mesh.h"
#include "fieldpath/pathgen/cutter_part.h"
#include "fieldpath/pathgen/link_check.h"
#include "fixtures.h"

using namespace fieldpath;
using namespace fieldpath::pathgen;
using geometry::Posture;
using pathgen::test::boxMesh;

namespace {

/// A ball-end mill R 3, L 20.
geometry::ToolSpec ball() { return {geometry::ToolShape::Ball, 3.0, 0.0, 20.0}; }

Posture upright(double x, double y, double z) {
  Posture p;
  p.tip_mm = {x, y, z};
  return p;
}

/// The depth's own resolution and FCL's (GJK) tolerance on the cylinder, mm.
constexpr double kDepthTolMm = 2e-4;

}  // namespace

// An upright tool whose ball and shank reach x = 3: a wall at x = 3 − e is entered by e along
// its normal, which is also the distance from the cutter's side to the deepest part point.
TEST(CutterPart, AShankBesideAWallEntersItByTheGapShortOfItsRadius) {
  const std::vector<Posture> at = {upright(0, 0, 0)};
  for (const double e : {0.02, 0.3, 1.5}) {
    const geometry::TriangleMesh wall = boxMesh(3.0 - e, 13, -30, 30, -10, 30);
    const CutterPartResult r = checkCutterAgainstPart(ball(), wall, at);
    EXPECT_EQ(r.stamps, 1u);
    EXPECT_EQ(r.gouging_postures, 1u) << e;
    EXPECT_EQ(r.first_gouging_posture, 0u);
    EXPECT_EQ(r.gouging_motions, 0u);
    EXPECT_NEAR(r.max_depth_mm, e, kDepthTolMm) << e;
    EXPECT_FALSE(r.deepest_on_motion);
  }
  // Within the tolerance (5 um) and clear: nothing.
  for (const double e : {0.004, 0.0, -0.1}) {
    const CutterPartResult r =
        checkCutterAgainstPart(ball(), boxMesh(3.0 - e, 13, -30, 30, -10, 30), at);
    EXPECT_FALSE(r.gouges()) << e;
    EXPECT_EQ(r.max_depth_mm, 0.0);
  }
}

// A ball shorter than its diameter (a necked tool written with L = R, its neck in the holder) has
// no material above its top: a ledge of the part 0.3 mm over the ball's equator and 2.8 mm from
// the axis is within the whole sphere (by 3 - √(2.8² + 0.3²) = 0.184 mm: a false gouge before,
// a helper's) and clear of the tool; under the top (L 20) the shank meets it by 0.2 mm.
TEST(CutterPart, ABallShorterThanItsDiameterHasNoMaterialAboveItsTop) {
  const geometry::TriangleMesh ledge = boxMesh(2.8, 12, -30, 30, 3.3, 30);
  const std::vector<Posture> at = {upright(0, 0, 0)};
  for (const double length : {3.0, 3.2, 5.5}) {
    const geometry::ToolSpec necked{geometry::ToolShape::Ball, 3.0, 0.0, length};
    const CutterPartResult r = checkCutterAgainstPart(necked, ledge, at);
    // Under 3.3 no part of the tool reaches the ledge; at 5.5 the shank does, by 0.2.
    EXPECT_EQ(r.gouges(), length > 3.3) << length;
    if (length > 3.3) EXPECT_NEAR(r.max_depth_mm, 0.2, kDepthTolMm);
  }
  // The ledge lowered to 2.5 (under the top of L 3): the cut ball's rim at (2.8, 0, 3 - s) is
  // within 3 - s of the centre while 2.8² + s² <= (3 - s)²: s = 1.16 / 6.
  const geometry::TriangleMesh low = boxMesh(2.8, 12, -30, 30, 2.5, 30);
  const CutterPartResult r =
      checkCutterAgainstPart({geometry::ToolShape::Ball, 3.0, 0.0, 3.0}, low, at);
  ASSERT_TRUE(r.gouges());
  EXPECT_NEAR(r.max_depth_mm, 1.16 / 6.0, kDepthTolMm);
}

// Tilted θ = 10° towards a wall, the shank's top rim reaches x = L sin θ + R cos θ. With the wall
// e = 0.05 mm short of it, the cutter shrunk by s (radius R − s, top L − s) stops meeting the
// wall at s = e / (sin θ + cos θ) = 0.0432 mm: the distance from the cutter's surface to the
// wall's deepest point inside it.
TEST(CutterPart, ATiltedShankMeetsAWallWithItsTopRim) {
  const double theta = 10.0 * M_PI / 180.0, e = 0.05;
  Posture p;
  p.axis = {std::sin(theta), 0.0, std::cos(theta)};
  const double reach = 20.0 * std::sin(theta) + 3.0 * std::cos(theta);
  const geometry::TriangleMesh wall = boxMesh(reach - e, reach + 10, -30, 30, -10, 30);
  const CutterPartResult r = checkCutterAgainstPart(ball(), wall, std::vector<Posture>{p});
  ASSERT_TRUE(r.gouges());
  EXPECT_NEAR(r.max_depth_mm, e / (std::sin(theta) + std::cos(theta)), kDepthTolMm);
  // Tilted away, the same wall is 2 L sin θ farther than the ball's side: clear.
  p.axis.x() = -p.axis.x();
  EXPECT_FALSE(checkCutterAgainstPart(ball(), wall, std::vector<Posture>{p}).gouges());
}

// A rib 1 mm wide standing 0.05 mm into the shank's way between two postures 20 mm apart, both
// clear: the stamps along the motion (0.17 mm apart) find it, on motion 0, 0.05 mm deep.
TEST(CutterPart, AMotionBetweenTwoClearPosturesIsStamped) {
  const geometry::TriangleMesh rib = boxMesh(2.95, 12, -0.5, 0.5, -10, 30);
  const std::vector<Posture> path = {upright(0, -10, 0), upright(0, 10, 0)};
  const CutterPartResult r = checkCutterAgainstPart(ball(), rib, path);
  // (That the stamps are close enough is the narrow rib's test below, against the bound.)
  EXPECT_GT(r.stamps, 2u);
  EXPECT_EQ(r.gouging_postures, 0u);
  EXPECT_EQ(r.gouging_motions, 1u);
  EXPECT_EQ(r.first_gouging_motion, 0u);
  EXPECT_TRUE(r.deepest_on_motion);
  EXPECT_NEAR(r.max_depth_mm, 0.05, kDepthTolMm);
}

// A rib 0.02 mm wide, narrower than a stamp step, 0.05 mm into the shank's way: the stamps need
// not fall on it, and the entry read is at most between_stamps_mm (the shank's circle, R, over
// half a step) short of the true 0.05 mm, never more than it.
TEST(CutterPart, ARibNarrowerThanAStepReadsWithinTheStampBound) {
  const geometry::TriangleMesh rib = boxMesh(2.95, 12, -0.01, 0.01, -10, 30);
  for (const double start : {-10.0, -10.05, -10.11}) {  // stamps falling anywhere on the rib
    const std::vector<Posture> path = {upright(0, start, 0), upright(0, 10, 0)};
    const CutterPartResult r = checkCutterAgainstPart(ball(), rib, path);
    ASSERT_TRUE(r.gouges()) << start;
    // The header's promise: a quarter of the tolerance (not the figure the code reports).
    EXPECT_GE(r.max_depth_mm, 0.05 - kGougeToleranceMm / 4.0 - kDepthTolMm) << start;
    EXPECT_LE(r.max_depth_mm, 0.05 + kDepthTolMm) << start;
  }
}

// FCL meets surfaces only: a cutter wholly inside a closed part touches no triangle. Its inside
// counts: the depth reads the cutter's radius (the most this measure gives).
TEST(CutterPart, ACutterWhollyInsideAClosedPartReadsItsRadius) {
  const geometry::TriangleMesh block = boxMesh(-50, 50, -50, 50, -50, 50);
  const CutterPartResult r =
      checkCutterAgainstPart(ball(), block, std::vector<Posture>{upright(0, 0, -40)});
  ASSERT_TRUE(r.gouges());
  EXPECT_NEAR(r.max_depth_mm, 3.0, kDepthTolMm + 1e-4);
}

// A hollow block: its void's shell is wound inward, into the void. A cutter in the void touches
// nothing and is inside no material (it read as buried, its radius: a helper's case); one in
// the block's wall is inside.
TEST(CutterPart, ACutterInAVoidOfAClosedPartIsClear) {
  geometry::TriangleMesh hollow = boxMesh(-50, 50, -50, 50, -50, 50);
  const geometry::TriangleMesh cavity = boxMesh(-20, 20, -20, 20, -20, 20);
  const int base = static_cast<int>(hollow.vertices.size());
  hollow.vertices.insert(hollow.vertices.end(), cavity.vertices.begin(), cavity.vertices.end());
  for (const auto& t : cavity.triangles)  // wound the other way: facing into the void
    hollow.triangles.emplace_back(base + t[0], base + t[2], base + t[1]);
  EXPECT_FALSE(
      checkCutterAgainstPart(ball(), hollow, std::vector<Posture>{upright(0, 0, -10)}).gouges());
  const CutterPartResult wall =
      checkCutterAgainstPart(ball(), hollow, std::vector<Posture>{upright(35, 0, -10)});
  EXPECT_NEAR(wall.max_depth_mm, 3.0, kDepthTolMm + 1e-4);
  // The same block with every facet flipped (its void wound outward): the same part. Its void
  // read as a body, a cutter in it 999.9 um deep (a helper's case).
  geometry::TriangleMesh flipped = hollow;
  for (auto& t : flipped.triangles) std::swap(t[1], t[2]);
  EXPECT_FALSE(
      checkCutterAgainstPart(ball(), flipped, std::vector<Posture>{upright(0, 0, -10)}).gouges());
  EXPECT_NEAR(checkCutterAgainstPart(ball(), flipped, std::vector<Posture>{upright(35, 0, -10)})
                  .max_depth_mm,
              3.0, kDepthTolMm + 1e-4);
  // A body wound inward that only overlaps the block (one corner inside it) is no void of it: a
  // cutter inside both is inside the part (one vertex decided it: a reviewer's case).
  geometry::TriangleMesh overlap = boxMesh(-50, 50, -50, 50, -50, 50);
  const geometry::TriangleMesh other = boxMesh(40, 80, -30, 30, -30, 30);
  const int at = static_cast<int>(overlap.vertices.size());
  overlap.vertices.insert(overlap.vertices.end(), other.vertices.begin(), other.vertices.end());
  for (const auto& t : other.triangles)
    overlap.triangles.emplace_back(at + t[0], at + t[2], at + t[1]);
  EXPECT_NEAR(checkCutterAgainstPart(ball(), overlap, std::vector<Posture>{upright(45, 0, -10)})
                  .max_depth_mm,
              3.0, kDepthTolMm + 1e-4);
}

// A closed box with a sliver of no area on its top edge (as an export closes a T-junction): FCL's
// sphere-triangle test took its zero normal for "inside" and met a ball 0.54 mm clear of the
// edge (841 um of false gouge: a reviewer's case). Such triangles are not in the tree.
TEST(CutterPart, ASliverOfNoAreaIsNoSurface) {
  geometry::TriangleMesh box = boxMesh(-10, 10, -10, 10, -10, 0);
  const int a = static_cast<int>(box.vertices.size());
  box.vertices.emplace_back(0, 10, 0);
  box.vertices.emplace_back(10, 10, 0);
  box.vertices.emplace_back(-10, 10, 0);
  box.triangles.emplace_back(a, a + 1, a + 2);
  // The ball's centre 2.5 mm out and 2.5 mm up from the edge: 3.54 from it, R 3.
  const std::vector<Posture> at = {upright(0, 12.5, -0.5)};
  EXPECT_FALSE(checkCutterAgainstPart(ball(), box, at).gouges());
  // 0.1 mm nearer the edge than R on the same diagonal: 0.1 mm deep, sliver or not.
  const double d = (3.0 - 0.1) / std::sqrt(2.0);
  const CutterPartResult near =
      checkCutterAgainstPart(ball(), box, std::vector<Posture>{upright(0, 10 + d, d - 3.0)});
  EXPECT_NEAR(near.max_depth_mm, 0.1, kDepthTolMm);
}

// A torus tool R 3, r 1: its corner shrunk by s is the points within r − s of its disc (radius
// R − r = 2 at height r). A floor 0.1 mm above the tip meets the slab over the disc: 0.1 deep.
TEST(CutterPart, ATorusFloorIsEnteredByItsHeightAboveTheTip) {
  const geometry::ToolSpec torus{geometry::ToolShape::Torus, 3.0, 1.0, 20.0};
  const std::vector<Posture> at = {upright(0, 0, 0)};
  EXPECT_NEAR(checkCutterAgainstPart(torus, boxMesh(-20, 20, -20, 20, -10, 0.1), at).max_depth_mm,
              0.1, kDepthTolMm);
  EXPECT_FALSE(checkCutterAgainstPart(torus, boxMesh(-20, 20, -20, 20, -10, 0.0), at).gouges());
  // Plunged 2 mm, past its corner radius: shrunk by s > r the torus is a flat end whose bottom
  // stands s over the tip (read R, 3 mm, while its bottom stayed at r).
  EXPECT_NEAR(checkCutterAgainstPart(torus, boxMesh(-20, 20, -20, 20, -10, 2.0), at).max_depth_mm,
              2.0, kDepthTolMm);
}

// A wall whose top (z 0.5) stands below the corner's top (z 1) is met by the ring alone (the
// shank starts at z 1): its top edge at x = 3 − e lies sqrt((1 − e)² + 0.5²) from the disc's rim,
// so the corner enters it by 1 − that (the Z-buffer's vertical lines see only the wall's top).
TEST(CutterPart, ATorusCornerEntersAWallBelowItsShankByTheRingsClosedForm) {
  const geometry::ToolSpec torus{geometry::ToolShape::Torus, 3.0, 1.0, 20.0};
  const std::vector<Posture> at = {upright(0, 0, 0)};
  for (const double e : {0.3, 0.6}) {
    const CutterPartResult r =
        checkCutterAgainstPart(torus, boxMesh(3.0 - e, 13, -30, 30, -10, 0.5), at);
    EXPECT_NEAR(r.max_depth_mm, 1.0 - std::hypot(1.0 - e, 0.5), kDepthTolMm) << e;
  }
  // Whose top edge stays farther than r from the rim: clear (e = 0.1: 0.9 and 0.5 → 1.03).
  EXPECT_FALSE(checkCutterAgainstPart(torus, boxMesh(2.9, 13, -30, 30, -10, 0.5), at).gouges());
}

// Tilted θ = 20° away from a wall at +x (axis (−sin θ, 0, cos θ)), the torus reaches farthest
// with its ring: x = −r sin θ + (R − r) cos θ + r = 2.537 mm, past its shank's lowest rim
// (−r sin θ + R cos θ = 2.477). A wall e = 0.04 short of the ring's reach is entered by e.
TEST(CutterPart, ATiltedTorusCornerEntersAWallByItsReachPastIt) {
  const geometry::ToolSpec torus{geometry::ToolShape::Torus, 3.0, 1.0, 20.0};
  const double theta = 20.0 * M_PI / 180.0, e = 0.04;
  Posture p = upright(0, 0, 0);
  p.axis = {-std::sin(theta), 0.0, std::cos(theta)};
  const double reach = -std::sin(theta) + 2.0 * std::cos(theta) + 1.0;
  const CutterPartResult r = checkCutterAgainstPart(torus, boxMesh(reach - e, 20, -30, 30, -10, 30),
                                                    std::vector<Posture>{p});
  EXPECT_NEAR(r.max_depth_mm, e, kDepthTolMm);
  // The stamps along a motion: no farther apart than √(2 r tol) (the corner's curvature), r = 1.
  EXPECT_LE(r.step_mm, std::sqrt(2.0 * 1.0 * kGougeToleranceMm) + 1e-12);
}

// A flat end's sharp rim is not tested (`check` refuses the tool).
TEST(CutterPart, AFlatEndIsNotTested) {
  const geometry::ToolSpec flat{geometry::ToolShape::Flat, 3.0, 0.0, 20.0};
  EXPECT_EQ(checkCutterAgainstPart(flat, boxMesh(2.9, 13, -30, 30, -10, 30),
                                   std::vector<Posture>{upright(0, 0, 0)})
                .stamps,
            0u);
}

/// Every result of two part checks alike, bit for bit (a memo's and a fresh check's).
void expectSameContacts(const PartContacts& kept, const PartContacts& fresh) {
  ASSERT_TRUE(kept.cutter && fresh.cutter && kept.links && fresh.links && kept.holder &&
              fresh.holder);
  const CutterPartResult &a = *kept.cutter, &b = *fresh.cutter;
  EXPECT_EQ(a.stamps, b.stamps);
  EXPECT_EQ(a.posture_contacts, b.posture_contacts);
  EXPECT_EQ(a.motion_contacts, b.motion_contacts);
  EXPECT_EQ(a.max_depth_mm, b.max_depth_mm);
  EXPECT_EQ(a.deepest, b.deepest);
  EXPECT_EQ(a.deepest_on_motion, b.deepest_on_motion);
  for (const auto* r : {&kept.links, &kept.holder}) {
    const LinkPartResult& x = **r;
    const LinkPartResult& y = r == &kept.links ? *fresh.links : *fresh.holder;
    EXPECT_EQ(x.postures, y.postures);
    EXPECT_EQ(x.motions, y.motions);
    EXPECT_EQ(x.colliding_postures, y.colliding_postures);
    EXPECT_EQ(x.colliding_motions, y.colliding_motions);
    EXPECT_EQ(x.min_clearance_mm, y.min_clearance_mm);
    EXPECT_EQ(x.posture_contacts, y.posture_contacts);
    EXPECT_EQ(x.motion_contacts, y.motion_contacts);
  }
  EXPECT_EQ(kept.ball_part_mm, fresh.ball_part_mm);
}

// generate checks its path against the part again after each repair, with a memo of what it
// found (PartMemo, forgetting before each check what the check before did not use): the results
// must be those of a check without it, bit for bit, and the cutter's postures and motions given
// back exactly those unchanged and clear. A plate with a fin, two passes and a link over the
// fin; the first pass dips 0.05 mm into the plate at three postures (gouges kept out of the
// memo); the repair tilts five postures of the second pass by 20 deg, which drives its ball
// 0.18 mm into the plate (a key blind to the axis gives them back clear). The path before the
// repair checked again gives back the same count: its upright five, unused by the check between,
// were forgotten. Another tolerance, or another part, is not given back at all.
TEST(CutterPart, AMemoGivesBackTheChecksOfWhatDidNotChange) {
  geometry::TriangleMesh part;
  pathgen::test::addBox(part, -10, 60, -10, 10, -5, 0);
  pathgen::test::addBox(part, 20, 24, -10, 10, 0, 4);
  const std::shared_ptr<const ObstacleModel> model = prepareObstacle(part, "part");
  const geometry::HolderProfile holder = geometry::parseHolderProfile("20:6,40:6,40:12,60:12");
  geometry::PathFile before;
  for (int k = 0; k <= 30; ++k)
    before.postures.push_back(upright(0.5 * k, 0, k >= 10 && k <= 12 ? -0.05 : 0));
  for (const double z : {2.0, 12.0}) before.postures.push_back(upright(15, 0, z));
  for (const double z : {12.0, 2.0}) before.postures.push_back(upright(30, 0, z));
  for (int k = 0; k <= 30; ++k) before.postures.push_back(upright(30.0 + 0.5 * k, 0, 0));
  using geometry::PathBlock;
  before.blocks = {{PathBlock::Kind::Pass, 0, 31},
                   {PathBlock::Kind::Link, 31, 35},
                   {PathBlock::Kind::Pass, 35, 66}};
  geometry::PathFile after = before;
  const double tilt = 20.0 * M_PI / 180.0;
  for (std::size_t i = 40; i < 45; ++i)
    after.postures[i].axis = {std::sin(tilt), 0, std::cos(tilt)};

  const auto check = [&](const geometry::PathFile& path, PartMemo* memo,
                         double tolerance_mm = kGougeToleranceMm,
                         const std::shared_ptr<const ObstacleModel>& against = nullptr) {
    if (memo) memo->forgetUnused();
    return checkAgainstPart(ball(), holder, against ? against : model, path, tolerance_mm, {},
                            kReachesPartMm, memo);
  };
  PartMemo memo;
  check(before, &memo);
  ASSERT_EQ(memo.reused(), 0u);
  const PartContacts kept = check(after, &memo);
  const PartContacts fresh = check(after, nullptr);
  expectSameContacts(kept, fresh);
  // (the tilted postures gouge, the dips too)
  ASSERT_TRUE(fresh.cutter);
  const CutterPartResult& b = *fresh.cutter;
  EXPECT_EQ(b.posture_contacts, (std::vector<std::size_t>{10, 11, 12, 40, 41, 42, 43, 44}));
  EXPECT_NEAR(b.max_depth_mm, 3.0 - 3.0 * std::cos(tilt), 2e-4);
  // Given back: the postures but the five turned and the three gouging, and the motions but the
  // six into, between and out of the turned ones and those gouging.
  std::size_t motions_gouging_unchanged = 0;
  for (const std::size_t i : b.motion_contacts) motions_gouging_unchanged += i < 39 || i > 44;
  const std::size_t n = after.postures.size();
  const std::size_t unchanged = (n - 5 - 3) + (n - 1 - 6 - motions_gouging_unchanged);
  EXPECT_EQ(memo.cutter.reused(), unchanged);
  EXPECT_GT(memo.links.reused(), 0u);    // the link's postures
  EXPECT_GT(memo.holder.reused(), 0u);   // the holder's motions far from the turned ones
  EXPECT_GT(memo.grazing.reused(), 0u);  // the moves into and out of the passes
  // The path before again: its upright five were forgotten (not used by the check of `after`).
  const PartContacts again = check(before, &memo);
  expectSameContacts(again, check(before, nullptr));
  EXPECT_EQ(memo.cutter.reused(), 2 * unchanged);
  // Another part, then another tolerance: nothing given back, the results a fresh check's.
  const std::size_t so_far = memo.reused();
  geometry::TriangleMesh higher;  // the plate 0.02 mm higher
  pathgen::test::addBox(higher, -10, 60, -10, 10, -5, 0.02);
  pathgen::test::addBox(higher, 20, 24, -10, 10, 0.02, 4);
  const std::shared_ptr<const ObstacleModel> other = prepareObstacle(higher, "part");
  const PartContacts on_other = check(after, &memo, kGougeToleranceMm, other);
  expectSameContacts(on_other, check(after, nullptr, kGougeToleranceMm, other));
  EXPECT_EQ(memo.reused(), so_far);
  ASSERT_TRUE(on_other.cutter);
  EXPECT_GT(on_other.cutter->posture_contacts.size(), b.posture_contacts.size());
  expectSameContacts(check(after, &memo, 0.01, other), check(after, nullptr, 0.01, other));
  EXPECT_EQ(memo.reused(), so_far);
}
