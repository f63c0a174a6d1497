#pragma once
/// Internal to pathgen: open obstacle sheets turned to face the tool (generate.cpp).
#include <cstddef>
#include <span>
#include <vector>

#include "fieldpath/geometry/mesh.h"
#include "fieldpath/geometry/posture.h"

namespace fieldpath::pathgen {

/// Turns each open shell of `meshes` (a sheet: its inside is not defined) whose normals face
/// away from most of the `points` near it (within `near_mm` of one of its triangles' centres)
/// to face them, and returns how many it turned. The field pushes along the normals, so a sheet
/// facing away from the passes pulls the tool into it. Closed shells are left alone.
std::size_t faceOpenSheetsToward(std::vector<geometry::TriangleMesh>& meshes,
                                 std::span<const geometry::Vec3> points, double near_mm);

}  // namespace fieldpath::pathgen
