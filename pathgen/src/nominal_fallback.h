#pragma once
/// Passes the steering made collide or come under the clearance: steered again from their end
/// where that checks better, written with their nominal axes where those are clear.
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "fieldpath/pathgen/clearance.h"
#include "fieldpath/pathgen/generate.h"
#include "fieldpath/pathgen/link_check.h"
#include "pass_steering.h"

namespace fieldpath::pathgen {

/// The passes of `result` whose steered postures or motions collide (`result.clearance` and
/// `result.motions` of the linked `result.path`, and `part_marks`: the holder or the cutter in
/// the part) and whose nominal axes (the pass's axis made square to the feed, path.lead_deg, no
/// tilt) clear the obstacles and the part at every posture and motion: their postures in
/// `result.postures` replaced by the nominal ones, listed in `result.kept_nominal`. The part never
/// repels, so the steering can turn a clear pass into a crash (a helper's mould cavity: the axis
/// tilted 23 deg away from a boss, into the cavity's draft walls); a pass that collides either
/// way keeps its steering. `part`: the part's model (prepareObstacle), where the request has one.
/// Returns whether any pass was replaced (the caller links and checks
/// the path again).
bool keepClearNominalPasses(const GenerateRequest& request, const ClearanceChecker& checker,
                            const std::shared_ptr<const ObstacleModel>& part,
                            GenerateResult& result,
                            const std::optional<PartContacts::Marks>& part_marks);

/// A pass steered again from its end: its index in GenerateResult::passes, its postures, and
/// what the steering said of it.
struct FromEndPass {
  std::size_t pass = 0;
  std::vector<GeneratedPosture> postures;
  PassSteering said;  ///< its run emptied (the postures hold it)
};

/// The passes of `result` that collide, or come under the required clearance where their ball
/// does not (as keepClearNominalPasses finds them), steered again from their end
/// (`steer_from_end`, in parallel; `progress` per pass done): those that check better alone
/// (fewer collisions, or as many and over 1 um more clearance; their postures and motions
/// against the obstacles and the part), in pass order. useFromEnd writes them into a result.
std::vector<FromEndPass> steerFaultyPassesFromEnd(
    const GenerateRequest& request, const ClearanceChecker& checker,
    const std::shared_ptr<const ObstacleModel>& part, const SteerFromEnd& steer_from_end,
    const GenerateResult& result, const std::optional<PartContacts::Marks>& part_marks,
    const common::Progress& progress = {});

/// `passes` written into `result`: their postures replaced, listed in `result.steered_from_end`,
/// and what the steering from the start said of them (settled and turned starts, corners held,
/// solver loosened) replaced by what this one says. The caller links and checks the path again.
void useFromEnd(GenerateResult& result, const std::vector<FromEndPass>& passes);

/// How pass `p` (its index in `result.passes`) checks in the linked path of `result`, with the
/// link into it and the link out of it, ordered as pathFaults orders a path: its postures and
/// motions that collide (with the obstacles, or marked in `part_marks`), then its least
/// clearance of the obstacles, negated. Which of several passes made a path worse: a pass's
/// links come down its own end axes.
std::pair<std::size_t, double> faultsAround(const GenerateResult& result,
                                            const std::optional<PartContacts::Marks>& part_marks,
                                            std::size_t p);

/// Whether a pass of `result` collides or comes under the required clearance (what
/// keepClearNominalPasses may mend): the caller keeps a copy of the steered result only then.
bool hasFaultyPasses(const GenerateRequest& request, const GenerateResult& result,
                     const std::optional<PartContacts::Marks>& part_marks);

/// How bad a checked path is, compared lexicographically: its collisions (postures and motions
/// with the obstacles, the links and the holder in the part), then its least clearance of the
/// obstacles, negated. A path written with nominal passes is kept only where it is no worse than
/// the steered one by this: the links to a pass come down its new axes, and can meet what the
/// steered ones missed (a reviewer's cube 400 mm up a nominal axis).
std::pair<std::size_t, double> pathFaults(const GenerateResult& result);

}  // namespace fieldpath::pathgen
