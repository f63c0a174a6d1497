#pragma once
/// The impeller job of a scene, shared by `generate` and `check` (defined in scene_impeller.cpp).
#include "fieldpath/pathgen/generate.h"
#include "scene.h"

namespace fieldpath::app {

/// The generate request of `scene` (obstacle meshes besides the blades, tool, holder, params).
/// Throws common::InputError "SCENE: guide: ..." unless the scene has the parametric impeller
/// as its guide (the passes follow its hub).
pathgen::GenerateRequest impellerJob(const Scene& scene);

}  // namespace fieldpath::app
