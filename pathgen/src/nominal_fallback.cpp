#include "nominal_fallback.h"

#include <algorithm>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "fieldpath/geometry/tool_model.h"
#include "fieldpath/geometry/units.h"
#include "fieldpath/pathgen/cutter_part.h"
#include "fieldpath/pathgen/passes.h"

namespace fieldpath::pathgen {
namespace {

/// Per pass, the postures of the checked path that collide there or on the move to the pass's
/// next posture, those that come under the required clearance there without colliding, and the
/// least clearance of its postures and in-pass motions (mm).
struct PassFaults {
  std::vector<std::size_t> colliding, under;
  std::vector<double> min_mm;
};
PassFaults faultsByPass(const GenerateResult& result, double required_mm,
                        const std::optional<PartContacts::Marks>& part_marks) {
  PassFaults out{
      std::vector<std::size_t>(result.passes.size(), 0),
      std::vector<std::size_t>(result.passes.size(), 0),
      std::vector<double>(result.passes.size(), std::numeric_limits<double>::infinity())};
  const auto& postures = result.postures;
  const auto& at = result.clearance.clearance_mm;
  const auto& moving = result.motions.clearance_mm;
  for (std::size_t k = 0; k < postures.size(); ++k) {
    const std::size_t i = postures[k].output;
    bool hit = i < at.size() && at[i] <= 0.0;
    bool under = i < at.size() && at[i] < required_mm;
    hit = hit || (part_marks && i < part_marks->posture.size() && part_marks->posture[i]);
    // The motion to the pass's next posture (a link's motions are the links').
    const auto p = static_cast<std::size_t>(postures[k].pass);
    if (i < at.size()) out.min_mm[p] = std::min(out.min_mm[p], at[i]);
    if (k + 1 < postures.size() && postures[k + 1].pass == postures[k].pass) {
      hit = hit || (i < moving.size() && moving[i] <= 0.0);
      under = under || (i < moving.size() && moving[i] < required_mm);
      hit = hit || (part_marks && i < part_marks->motion.size() && part_marks->motion[i]);
      if (i < moving.size()) out.min_mm[p] = std::min(out.min_mm[p], moving[i]);
    }
    out.colliding[p] += hit;
    out.under[p] += !hit && under;
  }
  return out;
}

/// Whether `postures` (one pass) clear the obstacles and the part (`part`: its model, prepared
/// once for every pass tried: a 1 M-triangle part takes seconds) at every posture and motion,
/// the obstacles by more than `above_mm` (0: clear; the steered pass's least clearance: nearer
/// to the required one than the steering came).
bool clearPass(const GenerateRequest& request, const ClearanceChecker& checker,
               const std::shared_ptr<const ObstacleModel>& part,
               const std::vector<geometry::Posture>& postures, double above_mm) {
  const ClearanceResult at_postures = checker.check(postures);
  if (at_postures.colliding > 0 || !(at_postures.min_clearance_mm > above_mm)) return false;
  MotionRequest motions;
  motions.required_mm = request.clearance_mm;
  motions.posture_clearance_mm = at_postures.clearance_mm;
  const MotionResult moved = checker.checkMotions(postures, motions);
  if (moved.colliding > 0 || !(moved.min_clearance_mm > above_mm)) return false;
  if (!part) return true;
  const std::optional<LinkPartResult> holder =
      checkHolderAgainstPart(request.tool, request.holder, part, postures);
  if (holder && holder->collides()) return false;
  return request.tool.shape == geometry::ToolShape::Flat ||
         !checkCutterAgainstPart(request.tool, part, postures).gouges();
}

}  // namespace

bool hasFaultyPasses(const GenerateRequest& request, const GenerateResult& result,
                     const std::optional<PartContacts::Marks>& part_marks) {
  const PassFaults faults = faultsByPass(result, request.clearance_mm, part_marks);
  for (std::size_t p = 0; p < faults.colliding.size(); ++p)
    if (faults.colliding[p] + faults.under[p] > 0) return true;
  return false;
}

std::pair<std::size_t, double> pathFaults(const GenerateResult& result) {
  std::size_t collisions = result.clearance.colliding + result.motions.colliding;
  for (const auto* part : {&result.link_part, &result.holder_part})
    if (*part) collisions += (*part)->colliding_postures + (*part)->colliding_motions;
  return {collisions,
          -std::min(result.clearance.min_clearance_mm, result.motions.min_clearance_mm)};
}

bool keepClearNominalPasses(const GenerateRequest& request, const ClearanceChecker& checker,
                            const std::shared_ptr<const ObstacleModel>& part,
                            GenerateResult& result,
                            const std::optional<PartContacts::Marks>& part_marks) {
  const PassFaults faults = faultsByPass(result, request.clearance_mm, part_marks);
  const double lead_rad = request.path.lead_deg * geometry::kDegToRad;
  bool replaced = false;
  std::size_t first = 0;  // the pass's first posture in result.postures
  for (std::size_t p = 0; p < result.passes.size(); ++p) {
    const Pass& pass = result.passes[p];
    std::size_t end = first;
    while (end < result.postures.size() && result.postures[end].pass == pass.index) ++end;
    const std::size_t begin = first;
    first = end;
    const std::size_t colliding = faults.colliding[p], under = faults.under[p];
    if ((colliding == 0 && under == 0) || end - begin != pass.samples.size()) continue;
    const std::vector<geometry::Posture> nominal =
        nominalPostures(std::span(&pass, 1), lead_rad, request.tool.radius_mm);
    // A pass that collided steered takes axes that clear; one that only came under the required
    // clearance, axes that come less near (a helper's channel: the tilt away from one fin
    // brought the shank 0.45 mm from the other, leaning over it, where the nominal axes kept
    // 0.64 of 0.5; a vertical-arc engage's steered pass came to 0.065, its nominal one 0.375).
    if (!clearPass(request, checker, part, nominal, colliding == 0 ? faults.min_mm[p] : 0.0))
      continue;
    for (std::size_t k = begin; k < end; ++k) {
      GeneratedPosture& g = result.postures[k];
      g.posture = nominal[k - begin];
      g.lead_rad = lead_rad;
      g.tilt_rad = 0.0;
      g.moment = 0.0;
      g.limited = false;
    }
    result.kept_nominal.push_back({pass.index, pass.label, colliding, under});
    replaced = true;
  }
  if (replaced) {
    // What the steering said of a pass written nominal is not of the path written (a reviewer).
    const auto kept = [&result](int pass) {
      for (const auto& k : result.kept_nominal)
        if (k.pass == pass) return true;
      return false;
    };
    std::erase_if(result.settled_starts, kept);
    std::erase_if(result.turned_starts, kept);
    std::erase_if(result.corners_held, kept);
    std::erase_if(result.settle_failures, [&](const auto& f) { return kept(f.pass); });
    std::erase_if(result.loosened_solver, [&](const std::string& line) {
      for (const auto& k : result.kept_nominal)
        if (line.rfind(k.label + ": ", 0) == 0) return true;
      return false;
    });
  }
  if (replaced) {  // the limits held are the steered postures' that remain
    result.limited_postures = 0;
    result.first_limited = ClearanceResult::npos;
    for (std::size_t k = 0; k < result.postures.size(); ++k)
      if (result.postures[k].limited) {
        if (result.first_limited == ClearanceResult::npos) result.first_limited = k;
        ++result.limited_postures;
      }
  }
  return replaced;
}

}  // namespace fieldpath::pathgen
