/// Passes steered from their end (dynamics/reversed_pass.h): the causal axis turns after the
/// field has pushed, so a pass given in the other direction meets the blade it reaches first
/// late; a faulty pass is steered again from its end and kept where it checks better.
#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "fieldpath/geometry/tool_model.h"
#include "fieldpath/pathgen/generate.h"
#include "fieldpath/pathgen/passes.h"

using namespace fieldpath;
using namespace fieldpath::pathgen;

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
