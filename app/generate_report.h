#pragma once
/// What `generate` writes of its job besides the path: report.json (the scene's settings, the
/// field, the steering, the checks, the repairs) and angles.csv (one row per pass posture).
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "fieldpath/pathgen/generate.h"
#include "fieldpath/pathgen/machine_moves.h"
#include "scene.h"

namespace fieldpath::app {

/// Said after an unsafe reason whose first posture or motion is a link's: generate made it, and
/// these keys place it (the move along the axis, the travel plane).
inline const std::string kLinkHint =
    "generate's link: `links.retract` (along the axis) and `links.safe_z` (the travel plane) "
    "place it";

/// The notes of a job (said on stdout and kept in report.json), each found once: the part's
/// nearly-closed shells are a search of its edges.
struct JobNotes {
  std::vector<std::string> tool, obstacle, link;
};

/// report.json of a generated job (the rotary angles, dog-leg rapids, times and digests are added
/// by the command once the files are written).
nlohmann::json reportJson(const Scene& scene, const pathgen::GenerateRequest& job,
                          const pathgen::GenerateResult& r, const pathgen::AxisTurn& axis_turn,
                          const JobNotes& notes);

/// angles.csv: one row per pass posture; `posture` is its index in path.cl (links are not rows).
std::string anglesCsv(const pathgen::GenerateResult& r);

}  // namespace fieldpath::app
