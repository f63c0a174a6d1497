/// Passes steered from their end (dynamics/reversed_pass.h): the causal axis turns after the
/// field has pushed, so a pass given in the other direction meets the blade it reaches first
/// late; a faulty pass is steered again from its end and kept where it checks better.
#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "fieldpath/geometry/tool_model.h"
#include "fieldpath/pathgen/generate.h"
#include "fieldpath/pathgen/passes.h"
#include "fixtures.h"
#include "impeller_job.h"

using namespace fieldpath;
using namespace fieldpath::pathgen;
using fieldpath::pathgen::test::useImpeller;

namespace {

/// The example impeller (examples/impeller: its defaults), its passes as a nominal path file
/// would give them: every pass's nominal postures, each pass in reverse order where `reversed`.
GenerateRequest impellerFromFile(bool reversed) {
  GenerateRequest job;
  job.path.passes = 7;
  job.path.step_mm = 0.5;
  job.tool = {geometry::ToolShape::Ball, 3.0, 0.0, 40.0};
  job.holder = {{40, 6}, {55, 6}, {55, 12}, {90, 12}};
  job.field.voxel.voxel_size_mm = 0.5;
  job.clearance_mm = 0.5;
  useImpeller(job, Impeller(ImpellerParams{}));
  geometry::PathFile file;
  for (const Pass& pass : job.passes) {
    std::vector<geometry::Posture> postures =
        nominalPostures(std::span(&pass, 1), 0.0, job.tool.radius_mm);
    if (reversed) std::reverse(postures.begin(), postures.end());
    const std::size_t begin = file.postures.size();
    file.postures.insert(file.postures.end(), postures.begin(), postures.end());
    file.blocks.push_back({geometry::PathBlock::Kind::Pass, begin, file.postures.size()});
  }
  job.passes = nominalPasses(file, PathParams{}, job.tool.radius_mm);
  return job;
}

}  // namespace

// The impeller's passes given outlet to inlet: steered from their start, pass 7 runs into the
// right blade (7 postures, UNSAFE; `generate` before this). Steered from its end it is the pass
// given inlet to outlet steered from its start: the same postures (the reference: the forward
// file's job), clear. The other passes keep their steering from the start.
TEST(GenerateFromEnd, AnImpellerPassGivenBackwardsIsSteeredFromItsEndAsForwards) {
  GenerateRequest backwards = impellerFromFile(true);
  GenerateRequest steered_only = backwards;
  steered_only.passes_only = true;  // no repairs: the steering from the starts alone
  const GenerateResult from_starts = generatePath(steered_only);
  EXPECT_GT(from_starts.clearance.colliding, 0u);

  const GenerateResult repaired = generatePath(backwards);
  EXPECT_EQ(repaired.clearance.colliding + repaired.motions.colliding, 0u);
  EXPECT_GE(repaired.clearance.min_clearance_mm, backwards.clearance_mm);
  ASSERT_FALSE(repaired.steered_from_end.empty());
  EXPECT_TRUE(repaired.kept_nominal.empty());

  const GenerateResult forwards = generatePath(impellerFromFile(false));
  ASSERT_EQ(forwards.postures.size(), repaired.postures.size());
  for (const int pass : repaired.steered_from_end) {
    std::vector<const GeneratedPosture*> ahead, back;
    for (const GeneratedPosture& g : forwards.postures)
      if (g.pass == pass) ahead.push_back(&g);
    for (const GeneratedPosture& g : repaired.postures)
      if (g.pass == pass) back.push_back(&g);
    ASSERT_EQ(ahead.size(), back.size());
    std::reverse(ahead.begin(), ahead.end());
    double worst_deg = 0.0, worst_mm = 0.0;
    for (std::size_t k = 0; k < back.size(); ++k) {
      worst_deg =
          std::max(worst_deg, geometry::axisAngle(ahead[k]->posture.axis, back[k]->posture.axis) *
                                  180.0 / M_PI);
      worst_mm = std::max(worst_mm, (ahead[k]->posture.tip_mm - back[k]->posture.tip_mm).norm());
    }
    // The same run up to rounding (9e-11 deg, 5e-12 mm measured): stations mirrored twice.
    EXPECT_LT(worst_deg, 1e-6) << pass;
    EXPECT_LT(worst_mm, 1e-9) << pass;
  }
}

// Two passes along walls they reach late from their start (each coming to 0.43 mm of 0.5),
// steered from their end clear (1.48 mm), the first one's first axis then leaning 24 deg toward
// a block 78 mm up it: beyond the field's reach, so no steering sees it, but the link down that
// axis runs into it. The path linked so checked worse, and both passes' mends were undone, the
// path written under the clearance (a helper's tower). The link is taken another way up first,
// as the links' own repair would, and both passes are kept: clear, 1.48 mm.
TEST(GenerateFromEnd, ALinkIntoSomethingUpAPassesNewAxisIsTakenElsewhereBeforeItsMendIsJudged) {
  GenerateRequest job;
  job.tool = {geometry::ToolShape::Ball, 3.0, 0.0, 15.0};
  job.holder = {{15, 6}, {30, 6}, {30, 12}, {70, 12}};
  job.field.sample_step_mm = 1.0;
  job.dynamics.feed_mm_per_min = 2000.0;
  job.clearance_mm = 0.5;
  job.obstacles = {test::boxMesh(15, 60, 4.5, 8.5, -1, 30)};
  test::addBox(job.obstacles[0], 15, 60, 44.5, 48.5, -1, 30);
  test::addBox(job.obstacles[0], -6, 6, -36.89172, -24.89172, 69.34224, 73.34224);
  job.part = test::boxMesh(-40, 100, -70, 70, -5, 0);
  geometry::PathFile file;
  for (const double y : {0.0, 40.0}) {
    const std::size_t begin = file.postures.size();
    for (int k = 0; k <= 80; ++k)
      file.postures.push_back({Vec3(0.5 * k, y, 0), Vec3::UnitZ(), 0.0, false});
    file.blocks.push_back({geometry::PathBlock::Kind::Pass, begin, file.postures.size()});
  }
  job.passes = nominalPasses(file, PathParams{}, job.tool.radius_mm);
  ASSERT_EQ(job.passes.size(), 2u);

  const GenerateResult r = generatePath(job);
  EXPECT_EQ(r.steered_from_end, (std::vector<int>{0, 1}));
  EXPECT_EQ(r.steered_from_end_undone, 0u);
  EXPECT_EQ(r.clearance.colliding + r.motions.colliding, 0u);
  EXPECT_GE(std::min(r.clearance.min_clearance_mm, r.motions.min_clearance_mm), job.clearance_mm);
  ASSERT_FALSE(r.routed_link_ends.empty());
  EXPECT_EQ(r.routed_link_ends.front().pass, 0);
  EXPECT_TRUE(r.routed_link_ends.front().into);
}
