#pragma once
/// A scene's mesh file made ready for the job (an obstacle's or the part's): read, refused when it
/// has no surface, mended where an exported solid needs it, its closed shells wound outward, and
/// the notes of what was done said on stderr. Split from scene.cpp, which reads the keys.
#include <filesystem>
#include <string>
#include <vector>

#include "fieldpath/geometry/mesh.h"

namespace fieldpath::app {

/// Loads `file` and prepares it as above. Throws common::InputError (naming the file) where it
/// cannot be read or has no surface; the scene reader adds the key and line.
geometry::TriangleMesh loadSceneMesh(const std::filesystem::path& file);

/// Mends the export defects that leave a solid's shell open or wound both ways (repairShells:
/// T-junctions, slivers of no area, facets turned against their neighbours) and says what it did
/// (meshNotes). Used for the scene's meshes and for a `--tool` mesh alike.
void mendExportDefects(geometry::TriangleMesh& mesh, const std::filesystem::path& file);

/// The notes loadSceneMesh said since the scene's loading began (loadScene clears them): what was
/// mended or turned, kept for generate's report.json (`mesh_notes`; they were on stderr only).
std::vector<std::string>& meshNotes();

}  // namespace fieldpath::app
