#pragma once
/// Internal to pathgen/: one pass steered (generate.cpp steers every pass through this, and the
/// repairs steer a faulty one again from its end). Its start settled and turned clear where
/// asked, the integrator loosened once where it stalls, and its corners held where DESIGN's frame
/// comes under the clearance and holding them keeps more, or swings the axis over 10 deg in a
/// step and holding them keeps the clearance and turns less (SteeringRequest::hold_corners).
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "fieldpath/dynamics/steering.h"
#include "fieldpath/pathgen/clearance.h"
#include "fieldpath/pathgen/generate.h"

namespace fieldpath::pathgen {

struct PassSteeringSetup {
  std::string label;                          ///< the pass's ("pass 3"), for what is said
  const ClearanceChecker* checker = nullptr;  ///< exact clearance of tool + holder, not owned
  double ball_radius_mm = 3.0;
  double required_mm = 0.0;  ///< `clearance`
  /// Start from the axis settled under the field (dynamics.start), at the pass's start and, for
  /// a pass steered from its end, there: each decided on the nominal posture's clearance there.
  bool settle_start = false, settle_end = false;
};

/// What steering one pass did (GenerateResult's lists of passes, per pass).
struct PassSteering {
  dynamics::SteeringResult run;  ///< in the pass's order, whichever way it was steered
  bool started_settled = false;
  bool turned_start = false;  ///< the settled start was within clearance: turned to a clear axis
  bool corners_held =
      false;  ///< steered with its corners held (DESIGN's frame came under or swung)
  bool from_end = false;      ///< steered from its end (dynamics/reversed_pass.h)
  std::string settle_failed;  ///< why, where settling failed
  std::string loosened;       ///< what was said where the integrator was loosened
};

/// `pass` steered under `request` (its stations and field; initial angles unset), from its start
/// or, `from_end`, from its end to its start (read forward: dynamics::forwardOf).
PassSteering steerOnePass(const dynamics::Pass& pass, const dynamics::SteeringRequest& request,
                          const PassSteeringSetup& setup, bool from_end);

/// The postures of a run of pass `pass` (0-based) as GenerateResult holds them.
std::vector<GeneratedPosture> generatedPostures(int pass, const dynamics::SteeringResult& run);

/// Pass `p` of a job (its index in GenerateResult::passes) steered again from its end, under
/// the job's field; nothing where the run is not Ok. generate.cpp makes it for the repairs.
using SteerFromEnd = std::function<std::optional<PassSteering>(std::size_t p)>;

}  // namespace fieldpath::pathgen
