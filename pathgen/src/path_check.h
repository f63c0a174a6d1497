#pragma once
/// generate's last stage: the passes linked, every posture and motion checked, and the repairs
/// (passes written nominal, link ends taken off the axis) each kept where the path checks no worse.
#include "fieldpath/pathgen/clearance.h"
#include "fieldpath/pathgen/generate.h"
#include "pass_steering.h"

namespace fieldpath::pathgen {

/// Where the checking stages end in the job's progress (fractions).
struct CheckStages {
  double steer_end = 0.0, clearance_end = 0.0, motions_end = 0.0;
};

/// Links the postures of `result` (its passes, steered or nominal) into `result.path`
/// (linkPasses; `request.passes_only`: one pass, no links) and checks every posture and motion
/// against the obstacles (`checker`) and the part (`result.clearance`, `motions`, `link_part`,
/// `holder_part`, `cutter_part`); then passes that collided or came under the clearance are
/// steered again from their end (`steer_from_end`, where given) and kept where they check
/// better (steerFaultyPassesFromEnd), then written nominal where that clears
/// (keepClearNominalPasses) and link ends whose way along the
/// axis collided are taken another way (rerouteLinkEnds), each kept only where the path linked
/// and checked again is no worse (pathFaults). Fills each posture's clearance, the largest
/// angles and the limited postures that collide.
void linkCheckAndRepair(const GenerateRequest& request, const ClearanceChecker& checker,
                        double safe_z_mm, const CheckStages& stages,
                        const SteerFromEnd& steer_from_end, GenerateResult& result);

}  // namespace fieldpath::pathgen
