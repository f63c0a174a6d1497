#pragma once
/// A job on the parametric impeller for the tests that call pathgen directly (the program makes
/// the same job from a scene: app/scene_impeller.cpp puts the blades where the scene lists the
/// impeller among its obstacles, and app/job.cpp takes the passes and the hub as the part).
#include <utility>
#include <vector>

#include "fieldpath/pathgen/generate.h"
#include "fieldpath/pathgen/impeller.h"

namespace fieldpath::pathgen::test {

/// The impeller as the job's source: its passes (from job.path and the tool radius), its two
/// blades before job's other obstacles, its hub as job.part.
inline void useImpeller(GenerateRequest& job, const Impeller& impeller) {
  job.passes = impellerPasses(impeller, job.path, job.tool.radius_mm);
  std::vector<geometry::TriangleMesh> obstacles = bladeMeshes(impeller);
  obstacles.insert(obstacles.end(), job.obstacles.begin(), job.obstacles.end());
  job.obstacles = std::move(obstacles);
  job.part = impeller.hubMesh();
}

}  // namespace fieldpath::pathgen::test
