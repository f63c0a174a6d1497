#pragma once
/// A pass steered from its end to its start, read forward. The dynamics are causal: the axis
/// turns after the field has pushed, so the side of an obstacle a pass meets first is met late.
/// An impeller's passes reversed (outlet to inlet) put 5 postures into the overhanging blade
/// that the same passes run inlet to outlet keep 0.5 mm from: steered from the other end, the
/// axis has turned before it reaches them. Any axis sequence steered either way is a path the
/// machine runs forward; pathgen keeps the clearer (pass_steering.h).
#include <vector>

#include "fieldpath/dynamics/steering.h"

namespace fieldpath::dynamics {

/// The output stations of `request` on `pass` (mm, from 0, ascending): its `output_s_mm`, or
/// every `step_mm` with the last on the pass's length (what steerPass samples).
std::vector<double> outputStations(const Pass& pass, const SteeringRequest& request);

/// `pass` run from its end: s' = length - s, the feed reversed (so f' = -f and b' = -b: an
/// axis's angles there are (-lead, -tilt), axisFromAngles) and the nominal angles negated with
/// it: the same nominal axes.
Pass reversedPass(const Pass& pass);

/// `request` for reversedPass(pass): its stations mirrored (length - s, ascending) and its
/// initial angles and rates unset (they were the start's; the caller sets the end's, in the
/// reversed frame, as for any pass).
SteeringRequest reversedRequest(const Pass& pass, SteeringRequest request);

/// A run of reversedPass(pass) under reversedRequest(pass, request), read forward: its samples
/// in the pass's order at the forward stations themselves (`outputStations`, bit for bit, not
/// length - s'), each sample's axis and moment as steered, its centre and angles the forward
/// pass's at that station (anglesOfAxis: the same axis), its torques negated (b' = -b); the
/// angles' rates are those in time run forward (d(-θ)/d(-t): the same). A run that stopped
/// early keeps the stations from the pass's end that it reached.
SteeringResult forwardOf(SteeringResult backward, const Pass& pass, const SteeringRequest& request);

}  // namespace fieldpath::dynamics
