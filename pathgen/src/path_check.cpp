#include "path_check.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "fieldpath/geometry/units.h"
#include "link_reroute.h"
#include "nominal_fallback.h"

namespace fieldpath::pathgen {

using common::scaled;

void linkCheckAndRepair(const GenerateRequest& request, const ClearanceChecker& checker,
                        double safe_z_mm, const CheckStages& stages,
                        const SteerFromEnd& steer_from_end, GenerateResult& result) {
  std::optional<PartContacts::Marks> part_marks;  // of result.path, where the part is touched
  // The part's model (its tree and shells), prepared once for every check of the path and of the
  // repairs: a 1 M-triangle part takes seconds a preparation.
  std::shared_ptr<const ObstacleModel> part_model;
  // The postures and motions checked: a repair's check of the path it changed measures again
  // only what changed (a third of a reversed impeller's generate checked the same again).
  ClearanceMemo checked;
  PartMemo part_checked;  // the same for the checks against the part
  // The first check reports in the job's bar (steer_end to 1); a repair's check again as a stage
  // of its own, from 0 % (it ran back from 100 % to the steering's end, unsaid: a reviewer's).
  common::Progress progress = request.progress;
  const auto linkAndCheck = [&] {
    std::vector<std::vector<geometry::Posture>> pass_postures(result.passes.size());
    for (const GeneratedPosture& g : result.postures) pass_postures[g.pass].push_back(g.posture);
    result.link_postures = 0;
    result.path = {};
    if (request.passes_only) {
      for (const auto& postures : pass_postures)
        for (const auto& p : postures) result.path.postures.push_back(p);
      result.path = geometry::singlePass(std::move(result.path.postures));
    } else {
      LinkRequest links;
      links.params = request.links;
      links.tool = request.tool;
      links.holder = request.holder;
      links.safe_z_mm = safe_z_mm;
      linkWays(result, links);
      for (const Pass& pass : result.passes) links.labels.push_back(pass.label);
      result.safe_z_mm = links.safe_z_mm;
      result.path = linkPasses(pass_postures, links);
    }
    // Where each pass posture landed in the output path.
    {
      std::size_t next = 0;
      for (const geometry::PathBlock& block : result.path.blocks) {
        if (block.kind == geometry::PathBlock::Kind::Link) {
          result.link_postures += block.size();
          continue;
        }
        for (std::size_t i = block.begin; i < block.end; ++i) result.postures[next++].output = i;
      }
    }
    for (const GeneratedPosture& g : result.postures)
      if (g.limited) result.path.limited.push_back(g.output);
    // (each memo keeps what this check uses: at most two checks' worth)
    checked.forgetUnused();
    part_checked.forgetUnused();
    ClearanceRequest postures;
    postures.memo = &checked;
    result.clearance =
        checker.check(result.path.postures, postures,
                      scaled(progress, stages.steer_end, stages.clearance_end, "clearance"));
    if (!request.passes_only) {
      MotionRequest motions;
      motions.memo = &checked;
      motions.required_mm = request.clearance_mm;
      motions.posture_clearance_mm = result.clearance.clearance_mm;
      result.motions = checker.checkMotions(
          result.path.postures, motions,
          scaled(progress, stages.clearance_end, stages.motions_end, "motions"));
      if (request.part) {
        // With its own progress: the cutter's stamps along 46 000 postures took 95 s after the
        // motions' 100 %, with no word (a scale sweep's finding).
        const common::Progress part = scaled(progress, stages.motions_end, 1.0, "part");
        common::report(part, 0.0, "part");
        if (!part_model) part_model = prepareObstacle(*request.part, "part");
        PartContacts contacts = checkAgainstPart(
            request.tool, request.holder, part_model, result.path, kGougeToleranceMm, part,
            farFromPartMm(request.tool.radius_mm), &part_checked);
        result.ball_part_mm = contacts.ball_part_mm;
        result.far_from_part = contacts.far;
        part_marks = contacts.marks(result.path.postures.size());
        result.link_part = std::move(contacts.links);
        result.holder_part = std::move(contacts.holder);
        result.cutter_part = std::move(contacts.cutter);
      }
    }
  };
  linkAndCheck();
  // `result` changed by a repair, linked and checked again (`what`: the repair's stage).
  const auto recheck = [&](const char* what) {
    if (request.progress)
      progress = [&request, &stages, what = std::string(what)](double f, std::string_view) {
        return request.progress((f - stages.steer_end) / (1.0 - stages.steer_end), what);
      };
    common::report(progress, stages.steer_end, what);
    linkAndCheck();
  };
  // `result` changed by a repair (`changed` things): linked and checked again, and kept only
  // where its path checks no worse than `before`'s (pathFaults), else `before` is restored with
  // its `undone` counting them.
  const auto keepIfNoWorse =
      [&](GenerateResult before, std::optional<PartContacts::Marks> before_marks,
          std::size_t changed, std::size_t GenerateResult::*undone, const char* what) {
        recheck(what);
        if (pathFaults(result) > pathFaults(before)) {
          before.*undone = changed;
          result = std::move(before);
          part_marks = std::move(before_marks);
        }
      };
  if (steer_from_end && !request.nominal && !request.passes_only &&
      hasFaultyPasses(request, result, part_marks)) {
    std::vector<FromEndPass> better = steerFaultyPassesFromEnd(
        request, checker, part_model, steer_from_end, result, part_marks,
        scaled(request.progress, 0.0, 1.0, "faulty passes steered from their end"));
    if (!better.empty()) {
      // The path as steered from the passes' starts, kept until the one with passes steered
      // from their ends checks no worse (their links come down other axes).
      const GenerateResult from_starts = result;
      const std::optional<PartContacts::Marks> from_starts_marks = part_marks;
      const auto restore = [&] {
        result = from_starts;
        part_marks = from_starts_marks;
      };
      const std::size_t tried = better.size();
      const char* what = "passes steered from their end: checked again";
      useFromEnd(result, better);
      recheck(what);
      if (pathFaults(result) > pathFaults(from_starts)) {
        // Worse where a link comes down a new end axis into something: that link taken another
        // way up first, as the stage below would (a helper's block 78 mm up a pass's first axis,
        // out of the field's reach, undid two passes' mends for one link it takes elsewhere).
        auto routed = rerouteLinkEnds(request, checker, part_model, safe_z_mm, result, part_marks);
        if (!routed.empty()) {
          result.routed_link_ends = std::move(routed);
          recheck(what);
        }
      }
      if (pathFaults(result) > pathFaults(from_starts)) {
        // Worse: kept without the passes whose own links and moves check worse (one pass's
        // links undid every other pass's mend, all or nothing), where that checks no worse.
        std::erase_if(better, [&](const FromEndPass& f) {
          return faultsAround(result, part_marks, f.pass) >
                 faultsAround(from_starts, from_starts_marks, f.pass);
        });
        restore();
        if (!better.empty() && better.size() < tried) {
          useFromEnd(result, better);
          recheck(what);
          if (pathFaults(result) > pathFaults(from_starts)) {
            restore();
            better.clear();
          }
        } else {
          better.clear();
        }
        result.steered_from_end_undone = tried - better.size();
      }
    }
  }
  if (!request.nominal && !request.passes_only && hasFaultyPasses(request, result, part_marks)) {
    // The steered path, kept until the one with nominal passes is checked no worse (its links
    // come down the new axes): a copy only where a pass is faulty.
    GenerateResult steered = result;
    std::optional<PartContacts::Marks> steered_marks = part_marks;
    if (keepClearNominalPasses(request, checker, part_model, result, part_marks))
      keepIfNoWorse(std::move(steered), std::move(steered_marks), result.kept_nominal.size(),
                    &GenerateResult::kept_nominal_undone, "passes kept nominal: checked again");
  }
  if (!request.passes_only) {
    // Links whose way along a pass's axis runs into something, taken another way up where one
    // checks clearer.
    std::vector<std::string> unfreed;
    auto routed =
        rerouteLinkEnds(request, checker, part_model, safe_z_mm, result, part_marks, &unfreed);
    if (!routed.empty()) {
      GenerateResult along_axes = result;
      std::optional<PartContacts::Marks> along_marks = part_marks;
      // (with those a repair above took: a new way for the same end replaces its old one)
      for (auto& end : routed) {
        const auto same =
            std::find_if(result.routed_link_ends.begin(), result.routed_link_ends.end(),
                         [&](const auto& e) { return e.pass == end.pass && e.into == end.into; });
        if (same != result.routed_link_ends.end())
          *same = std::move(end);
        else
          result.routed_link_ends.push_back(std::move(end));
      }
      keepIfNoWorse(std::move(along_axes), std::move(along_marks), routed.size(),
                    &GenerateResult::routed_link_ends_undone,
                    "links taken off the axis: checked again");
    }
    result.unfreed_link_ends = std::move(unfreed);
  }
  for (GeneratedPosture& g : result.postures) {
    g.clearance_mm = result.clearance.clearance_mm[g.output];
    result.max_tilt_deg = std::max(result.max_tilt_deg, std::abs(g.tilt_rad) / geometry::kDegToRad);
    result.max_lead_deg = std::max(result.max_lead_deg, std::abs(g.lead_rad) / geometry::kDegToRad);
    result.limited_colliding += g.limited && g.clearance_mm <= 0.0;
  }
}

}  // namespace fieldpath::pathgen
