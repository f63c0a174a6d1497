#include "nominal_fallback.h"

#include <memory>
#include <string>
#include <vector>

#include "fieldpath/geometry/tool_model.h"
#include "fieldpath/geometry/units.h"
#include "fieldpath/pathgen/cutter_part.h"
#include "fieldpath/pathgen/passes.h"

namespace fieldpath::pathgen {
namespace {

/// Postures and in-pass motions of each pass that collide in the checked path (0: none).
std::vector<std::size_t> collidingByPass(const GenerateResult& result,
                                         const std::optional<PartContacts::Marks>& part_marks) {
  std::vector<std::size_t> colliding(result.passes.size(), 0);
  const auto& postures = result.postures;
  for (std::size_t k = 0; k < postures.size(); ++k) {
    const std::size_t i = postures[k].output;
    bool hit = i < result.clearance.clearance_mm.size() && result.clearance.clearance_mm[i] <= 0.0;
    hit = hit || (part_marks && i < part_marks->posture.size() && part_marks->posture[i]);
    // The motion to the pass's next posture (a link's motions are the links').
    if (k + 1 < postures.size() && postures[k + 1].pass == postures[k].pass) {
      hit =
          hit || (i < result.motions.clearance_mm.size() && result.motions.clearance_mm[i] <= 0.0);
      hit = hit || (part_marks && i < part_marks->motion.size() && part_marks->motion[i]);
    }
    colliding[static_cast<std::size_t>(postures[k].pass)] += hit;
  }
  return colliding;
}

/// Whether `postures` (one pass) clear the obstacles and the part (`part`: its model, prepared
/// once for every pass tried: a 1 M-triangle part takes seconds) at every posture and motion.
bool clearPass(const GenerateRequest& request, const ClearanceChecker& checker,
               const std::shared_ptr<const ObstacleModel>& part,
               const std::vector<geometry::Posture>& postures) {
  const ClearanceResult at_postures = checker.check(postures);
  if (at_postures.colliding > 0) return false;
  MotionRequest motions;
  motions.required_mm = request.clearance_mm;
  motions.posture_clearance_mm = at_postures.clearance_mm;
  if (checker.checkMotions(postures, motions).colliding > 0) return false;
  if (!part) return true;
  const std::optional<LinkPartResult> holder =
      checkHolderAgainstPart(request.tool, request.holder, part, postures);
  if (holder && holder->collides()) return false;
  return request.tool.shape == geometry::ToolShape::Flat ||
         !checkCutterAgainstPart(request.tool, part, postures).gouges();
}

}  // namespace

bool keepClearNominalPasses(const GenerateRequest& request, const ClearanceChecker& checker,
                            GenerateResult& result,
                            const std::optional<PartContacts::Marks>& part_marks) {
  const std::vector<std::size_t> colliding = collidingByPass(result, part_marks);
  const double lead_rad = request.path.lead_deg * geometry::kDegToRad;
  std::shared_ptr<const ObstacleModel> part;
  bool replaced = false;
  std::size_t first = 0;  // the pass's first posture in result.postures
  for (std::size_t p = 0; p < result.passes.size(); ++p) {
    const Pass& pass = result.passes[p];
    std::size_t end = first;
    while (end < result.postures.size() && result.postures[end].pass == pass.index) ++end;
    const std::size_t begin = first;
    first = end;
    if (colliding[p] == 0 || end - begin != pass.samples.size()) continue;
    const std::vector<geometry::Posture> nominal =
        nominalPostures(std::span(&pass, 1), lead_rad, request.tool.radius_mm);
    if (request.part && !part) part = prepareObstacle(*request.part, "part");
    if (!clearPass(request, checker, part, nominal)) continue;
    for (std::size_t k = begin; k < end; ++k) {
      GeneratedPosture& g = result.postures[k];
      g.posture = nominal[k - begin];
      g.lead_rad = lead_rad;
      g.tilt_rad = 0.0;
      g.moment = 0.0;
      g.limited = false;
    }
    result.kept_nominal.push_back({pass.index, pass.label, colliding[p]});
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
