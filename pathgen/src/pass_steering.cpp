#include "pass_steering.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>
#include <utility>

#include "clear_start.h"
#include "fieldpath/dynamics/frame.h"
#include "fieldpath/dynamics/reversed_pass.h"
#include "fieldpath/geometry/posture.h"
#include "fieldpath/geometry/units.h"
#include "fieldpath/pathgen/passes.h"

namespace fieldpath::pathgen {
namespace {

/// The exact clearance of a run's postures, mm (as one check: each query starts from the
/// closest pair of the one before it).
std::vector<double> clearances(const dynamics::SteeringResult& run,
                               const PassSteeringSetup& setup) {
  std::vector<geometry::Posture> postures;
  postures.reserve(run.samples.size());
  for (const dynamics::PostureSample& sample : run.samples) postures.push_back(sample.posture);
  return setup.checker->check(postures).clearance_mm;
}

double least(const std::vector<double>& mm) {
  return mm.empty() ? std::numeric_limits<double>::infinity()
                    : *std::min_element(mm.begin(), mm.end());
}

/// Whether a run's motions keep the required clearance (`at_mm`: its postures' clearances),
/// certified no further than that.
bool motionsKeepClearance(const dynamics::SteeringResult& run, const PassSteeringSetup& setup,
                          const std::vector<double>& at_mm) {
  std::vector<geometry::Posture> postures;
  postures.reserve(run.samples.size());
  for (const dynamics::PostureSample& sample : run.samples) postures.push_back(sample.posture);
  MotionRequest request;
  request.required_mm = setup.required_mm;
  request.enough_mm = setup.required_mm;
  request.posture_clearance_mm = at_mm;
  return setup.checker->checkMotions(postures, request).under_required == 0;
}

/// The largest turn of the axis between two consecutive postures of a run, deg.
double largestTurnDeg(const dynamics::SteeringResult& run) {
  double largest_rad = 0.0;
  for (std::size_t k = 1; k < run.samples.size(); ++k)
    largest_rad = std::max(largest_rad, geometry::axisAngle(run.samples[k - 1].posture.axis,
                                                            run.samples[k].posture.axis));
  return largest_rad * geometry::kRadToDeg;
}

/// One way along `pass` (the pass itself, or reversedPass of it): the start settled where
/// `settle`, turned clear where that is within the clearance, the run, once more loosened where
/// the integrator stalls, and its corners held where DESIGN's frame comes under the clearance or
/// swings the axis over kNoteAxisTurnDeg in a step.
PassSteering steerOneWay(const dynamics::Pass& pass, dynamics::SteeringRequest steer, bool settle,
                         const PassSteeringSetup& setup) {
  PassSteering out;
  const dynamics::DynamicsParams& params = steer.params;
  // The integrator stalled (its step to 1e-10 mm where the interpolated field turns sharply:
  // a start inside a wall on a 1 mm grid, a helper's overhang that --direct and rtol 1e-3
  // steer clear): once more with the tolerances loosened, said. The path is checked exactly
  // all the same; a second failure is the job's error.
  const auto loosen = [&] {  // a copy of the request as it stands, only when needed
    dynamics::SteeringRequest looser = steer;
    looser.params.rtol = std::max(params.rtol * 100.0, 1e-3);
    looser.params.atol = std::max(params.atol * 1000.0, 1e-6);
    return looser;
  };
  const auto sayLoosened = [&](const char* what, const std::string& why,
                               const dynamics::SteeringRequest& looser) {
    std::ostringstream said;
    said << setup.label << ": the integrator failed" << what << " (" << why << "); "
         << "done again with dynamics.rtol " << looser.params.rtol << ", atol "
         << looser.params.atol;
    out.loosened += (out.loosened.empty() ? "" : "; ") + said.str();
  };
  if (settle) {
    dynamics::SettledStart at_rest = dynamics::settleAtStart(pass, steer);
    if (!at_rest.settled) {  // the same stall at rest
      const dynamics::SteeringRequest looser = loosen();
      dynamics::SettledStart again = dynamics::settleAtStart(pass, looser);
      if (again.settled) {
        sayLoosened(" settling at the start", at_rest.why, looser);
        at_rest = std::move(again);
      }
    }
    if (at_rest.settled) {  // else the nominal start: the pass reports what goes wrong
      steer.initial_lead_rad = at_rest.lead_rad;
      steer.initial_tilt_rad = at_rest.tilt_rad;
      out.started_settled = true;
    } else {
      out.settle_failed = at_rest.why.empty() ? "the settling failed" : at_rest.why;
    }
    // Still within `clearance` (a holder upright through a rib thinner than its reach: the
    // field pushes its nodes on the far side further and the axis settles there, 588
    // colliding postures on a helper's ribbed pocket): the clear axis nearest the nominal
    // one within the limits, on a grid kClearStartStepDeg apart, nearest first; the spring
    // then pulls it back towards the nominal against the near face's field.
    const dynamics::PassFrame at = pass.frameAt(0.0);
    const dynamics::LocalFrame frame = dynamics::localFrame(at);
    auto clearanceAt = [&](double lead, double tilt) {
      return setup.checker->clearance(geometry::ballEndPosture(
          at.centre_mm, dynamics::axisFromAngles(frame, lead, tilt), setup.ball_radius_mm));
    };
    if (clearanceAt(steer.initial_lead_rad.value_or(at.lead0_rad),
                    steer.initial_tilt_rad.value_or(at.tilt0_rad)) < setup.required_mm)
      if (const auto clear =
              clearStart(at.lead0_rad, at.tilt0_rad, params, clearanceAt, setup.required_mm)) {
        steer.initial_lead_rad = clear->first;
        steer.initial_tilt_rad = clear->second;
        out.turned_start = true;
      }
  }
  out.run = dynamics::steerPass(pass, steer);
  if (out.run.status == dynamics::Status::SolverFailed) {
    const dynamics::SteeringRequest looser = loosen();
    dynamics::SteeringResult again = dynamics::steerPass(pass, looser);
    if (again.status == dynamics::Status::Ok) {
      sayLoosened("", out.run.message, looser);
      out.run = std::move(again);
    }
  }
  // Corners: in DESIGN's frame the axis turns with the feed, and beside a wall the pass turns
  // away from, a tilt leaning away from it leans at it after the turn (a helper's pocket
  // corner: 19.5 deg in a step, the holder 2.3 mm into the wall); held in the world the axis
  // keeps its direction, and loses a lean away from a boss the pass turns round (a reviewer's:
  // 50 colliding postures round a 150 deg turn). The held run only where DESIGN's comes under,
  // and kept only if it keeps more.
  // Clear, but swinging the axis over kNoteAxisTurnDeg in a step (a 0.5 mm jog beside a wall:
  // 19.5 deg in 0.5 mm, the rotary axes asked for 650 deg/s at 1000 mm/min): the held run where
  // it keeps the clearance and turns less.
  if (out.run.status != dynamics::Status::Ok || out.run.corners == 0) return out;
  const double turning_mm = least(clearances(out.run, setup));
  const double turning_deg = largestTurnDeg(out.run);
  const bool under = turning_mm < setup.required_mm;
  if (!under && turning_deg <= kNoteAxisTurnDeg) return out;
  dynamics::SteeringRequest held = steer;
  held.hold_corners = true;
  dynamics::SteeringResult kept = dynamics::steerPass(pass, held);
  if (kept.status != dynamics::Status::Ok) return out;
  const std::vector<double> held_at_mm = clearances(kept, setup);
  const double held_mm = least(held_at_mm);
  // (Turning less by a degree at least: runs alike to 1e-14 deg were "held", a reviewer's.)
  // A clear run is given up for its swing only where the held one keeps the clearance along its
  // motions too (its postures alone were asked: a motion under it would make a clear pass
  // faulty).
  if (under ? !(held_mm > turning_mm)
            : !(held_mm >= setup.required_mm && largestTurnDeg(kept) < turning_deg - 1.0 &&
                motionsKeepClearance(kept, setup, held_at_mm)))
    return out;
  out.run = std::move(kept);
  out.corners_held = true;
  return out;
}

}  // namespace

PassSteering steerOnePass(const dynamics::Pass& pass, const dynamics::SteeringRequest& request,
                          const PassSteeringSetup& setup, bool from_end) {
  if (!from_end) return steerOneWay(pass, request, setup.settle_start, setup);
  const dynamics::Pass back = dynamics::reversedPass(pass);
  PassSteering out =
      steerOneWay(back, dynamics::reversedRequest(pass, request), setup.settle_end, setup);
  out.run = dynamics::forwardOf(std::move(out.run), pass, request);
  out.from_end = true;
  return out;
}

std::vector<GeneratedPosture> generatedPostures(int pass, const dynamics::SteeringResult& run) {
  std::vector<GeneratedPosture> out;
  out.reserve(run.samples.size());
  for (const dynamics::PostureSample& s : run.samples) {
    GeneratedPosture g;
    g.pass = pass;
    g.s_mm = s.s_mm;
    g.lead_rad = s.lead_rad;
    g.tilt_rad = s.tilt_rad;
    g.moment = s.moment.norm();
    g.limited = s.limited;
    g.posture = s.posture;
    out.push_back(g);
  }
  return out;
}

}  // namespace fieldpath::pathgen
