#pragma once
/// Mesh files through assimp (which stays inside the .cpp): STL ascii and binary, OBJ, PLY, and
/// anything else assimp reads.
#include <filesystem>

#include "fieldpath/geometry/mesh.h"

namespace fieldpath::geometry {

/// Reads every triangle of every mesh in `file` (mm, as stored), joining identical vertices.
/// Throws common::InputError "FILE: reason" for a missing, unreadable, broken or empty file.
TriangleMesh loadMesh(const std::filesystem::path& file);

/// Writes by extension: .stl (binary), .obj, .ply (binary); atomically (temporary name, then
/// rename). Throws common::InputError for an unknown extension.
void saveMesh(const TriangleMesh& mesh, const std::filesystem::path& file);

}  // namespace fieldpath::geometry
