#pragma once
/// The impeller job of a scene, shared by `generate` and `check` (defined in scene_impeller.cpp).
#include <nlohmann/json.hpp>

#include "fieldpath/pathgen/generate.h"
#include "scene.h"

namespace fieldpath::app {

/// The generate request of `scene` (obstacle meshes besides the blades, tool, holder, params).
/// Throws common::InputError "SCENE: guide: ..." unless the scene has the parametric impeller
/// as its guide (the passes follow its hub).
pathgen::GenerateRequest impellerJob(const Scene& scene);

/// The `clearance` block of report.json and check.json (posture and obstacle indices 0- and
/// 1-based as printed; null when there is none).
inline nlohmann::json clearanceJson(const pathgen::ClearanceResult& c, double required_mm) {
  auto index = [](std::size_t i) {
    return i == pathgen::ClearanceResult::npos ? nlohmann::json(nullptr) : nlohmann::json(i);
  };
  return {{"required_mm", required_mm},
          {"min_mm", c.min_clearance_mm},
          {"min_posture", index(c.min_index)},
          {"min_obstacle", c.min_obstacle + 1},
          {"colliding_postures", c.colliding},
          {"first_colliding_posture", index(c.first_colliding)},
          {"tool_mesh_chord_tol_mm", pathgen::kClearanceMeshTolMm},
          {"ok", c.colliding == 0 && c.min_clearance_mm >= required_mm}};
}

}  // namespace fieldpath::app
