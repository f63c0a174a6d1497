#pragma once
/// Internal to pathgen/: a pass with corners steered with them held where DESIGN's frame comes
/// under the clearance (generate.cpp, GenerateResult::corners_held).
#include <algorithm>
#include <limits>
#include <utility>

#include "fieldpath/dynamics/steering.h"

namespace fieldpath::pathgen {

/// Corners: held in DESIGN's frame the axis turns with the feed, and beside a wall the pass turns
/// away from, a tilt leaning away from it leans at it after the turn (a helper's pocket corner:
/// 19.5 deg in a step, the holder 2.3 mm into the wall); held in the world the axis keeps its
/// direction, and loses a lean away from a boss the pass turns round (a reviewer's: 50 colliding
/// postures round a 150 deg turn). Where `steered` (DESIGN's, Ok) met corners and came under
/// `required_mm` (clearance(posture), mm), the pass is steered again with its corners held
/// (SteeringRequest::hold_corners) and that run replaces it if it keeps more: true then.
template <class Clearance>
bool steerWithCornersHeldIfClearer(const dynamics::Pass& pass,
                                   const dynamics::SteeringRequest& request,
                                   dynamics::SteeringResult& steered, Clearance&& clearance,
                                   double required_mm) {
  if (steered.status != dynamics::Status::Ok || steered.corners == 0) return false;
  const auto least = [&](const dynamics::SteeringResult& run) {
    double least_mm = std::numeric_limits<double>::infinity();
    for (const dynamics::PostureSample& sample : run.samples)
      least_mm = std::min(least_mm, clearance(sample.posture));
    return least_mm;
  };
  const double turning_mm = least(steered);
  if (turning_mm >= required_mm) return false;
  dynamics::SteeringRequest held = request;
  held.hold_corners = true;
  dynamics::SteeringResult kept = dynamics::steerPass(pass, held);
  if (kept.status != dynamics::Status::Ok || !(least(kept) > turning_mm)) return false;
  steered = std::move(kept);
  return true;
}

}  // namespace fieldpath::pathgen
