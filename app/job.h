#pragma once
/// The job of a scene, shared by `generate`, `study` and the benchmark (defined in job.cpp). The
/// JSON blocks and messages that `generate` and `check` both write: path_report.h.
#include "fieldpath/pathgen/generate.h"
#include "scene.h"

namespace fieldpath::app {

/// The generate request of `scene`: its passes from their source (the nominal path file
/// `path.nominal`, or the parametric impeller with `guide: { impeller: hub }`), its obstacles,
/// part, tool, holder and settings. Throws common::InputError "SCENE: path.nominal: ..." when the
/// scene has neither source, or both, and what nominalPasses / impellerPasses throw.
pathgen::GenerateRequest sceneJob(const Scene& scene);

}  // namespace fieldpath::app
