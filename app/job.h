#pragma once
/// The job of a scene, shared by `generate`, `study` and the benchmark (defined in job.cpp), and
/// the JSON blocks that `generate` and `check` both write.
#include <nlohmann/json.hpp>

#include "fieldpath/pathgen/generate.h"
#include "scene.h"

namespace fieldpath::app {

/// The generate request of `scene`: its passes from their source (the nominal path file
/// `path.nominal`, or the parametric impeller with `guide: { impeller: hub }`), its obstacles,
/// part, tool, holder and settings. Throws common::InputError "SCENE: path.nominal: ..." when the
/// scene has neither source, or both, and what nominalPasses / impellerPasses throw.
pathgen::GenerateRequest sceneJob(const Scene& scene);

/// JSON null for a missing index (npos), else the index.
inline nlohmann::json jsonIndex(std::size_t i) {
  return i == pathgen::ClearanceResult::npos ? nlohmann::json(nullptr) : nlohmann::json(i);
}

/// A finite number, or null (JSON has no inf / nan).
inline nlohmann::json jsonNumber(double value) {
  return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(nullptr);
}

/// The `clearance` block of report.json and check.json (posture and obstacle indices 0- and
/// 1-based as printed; null when there is none).
inline nlohmann::json clearanceJson(const pathgen::ClearanceResult& c, double required_mm,
                                    double chord_tol_mm) {
  return {{"required_mm", required_mm},
          {"min_mm", jsonNumber(c.min_clearance_mm)},
          {"min_posture", jsonIndex(c.min_index)},
          {"min_obstacle", c.min_obstacle + 1},
          {"colliding_postures", c.colliding},
          {"first_colliding_posture", jsonIndex(c.first_colliding)},
          {"tool_mesh_chord_tol_mm", chord_tol_mm},
          {"distances",
           "exact mesh distances (FCL) less the tool mesh's chordal tolerance: never optimistic; "
           "a posture within it of an obstacle counts as colliding"},
          {"ok", c.colliding == 0 && c.min_clearance_mm >= required_mm}};
}

/// The `motions` block of report.json and check.json (motion i: posture i → i + 1).
inline nlohmann::json motionsJson(const pathgen::MotionResult& m, double required_mm,
                                  double resolution_mm) {
  return {{"motions", m.motions},
          {"method",
           "tip and axis interpolated linearly; adaptive sampling with a certified lower bound "
           "(tool + holder move at most |dtip| + reach * dangle between samples; the distance "
           "is 1-Lipschitz in that): halved until the bound reaches max(required_mm, closest "
           "posture - 0.01 mm), a sample touches, or the sub-motion moves <= 2 * resolution_mm"},
          {"resolution_mm", resolution_mm},
          {"min_mm", jsonNumber(m.min_clearance_mm)},
          {"min_is", "a lower bound, within 0.01 mm of the true minimum when that is above required_mm"},
          {"min_motion", jsonIndex(m.min_index)},
          {"colliding_motions", m.colliding},
          {"first_colliding_motion", jsonIndex(m.first_colliding)},
          {"motions_under_required", m.under_required},
          {"first_motion_under_required", jsonIndex(m.first_under_required)},
          {"samples", m.samples},
          {"ok", m.colliding == 0 && m.under_required == 0 &&
                     !(m.min_clearance_mm < required_mm)}};
}

}  // namespace fieldpath::app
