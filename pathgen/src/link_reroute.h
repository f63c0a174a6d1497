#pragma once
/// Link ends taken off the pass's axis where DESIGN's way (up and down the axis) runs into
/// something.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "fieldpath/pathgen/clearance.h"
#include "fieldpath/pathgen/generate.h"
#include "fieldpath/pathgen/link_check.h"

namespace fieldpath::pathgen {

/// For each pass of the checked `result` whose link in or out (the postures and motions from the
/// pass's end posture to the travel plane, `result.clearance` / `result.motions` and
/// `part_marks`) collides or comes under the required clearance: the ways up from that posture
/// with its axis held, on the great circle from the axis through the vertical and on past it,
/// are checked against the obstacles and the part, and the first that clears them by the
/// required clearance (else the best: fewer collisions, then more clearance) is returned where
/// it is better than the axis's way (the caller puts them in `result.routed_link_ends`, links
/// and checks the path again: the links take them, linkWays). The faulty ends no way frees are
/// added to `unfreed` ("the way into pass 2 (nominal.cl:44)"). `part`: the part's model
/// (prepareObstacle), where the request has one.
std::vector<GenerateResult::RoutedLinkEnd> rerouteLinkEnds(
    const GenerateRequest& request, const ClearanceChecker& checker,
    const std::shared_ptr<const ObstacleModel>& part, double safe_z_mm,
    const GenerateResult& result, const std::optional<PartContacts::Marks>& part_marks,
    std::vector<std::string>* unfreed = nullptr);

/// The ways of `result.routed_link_ends` as the links take them (LinkRequest::out_ways, in_ways).
void linkWays(const GenerateResult& result, LinkRequest& links);

}  // namespace fieldpath::pathgen
