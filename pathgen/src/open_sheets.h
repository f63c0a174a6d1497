#pragma once
/// Internal to pathgen: open obstacle sheets turned to face the tool (generate.cpp).
#include <cstddef>
#include <span>
#include <vector>

#include "fieldpath/geometry/mesh.h"
#include "fieldpath/geometry/posture.h"

namespace fieldpath::pathgen {

/// An open shell of one of the meshes: its triangles.
struct OpenSheet {
  std::size_t mesh;
  std::vector<int> triangles;
};

/// The open shells of `meshes` (sheets: their inside is not defined) whose normals face away
/// from most of the `points` near them (within `near_mm` of one of their triangles' centres).
/// The field pushes along the normals, so such a sheet pulls the tool into it: turn them
/// (turnSheets) before sampling. Closed shells are never listed.
std::vector<OpenSheet> sheetsFacingAway(std::span<const geometry::TriangleMesh> meshes,
                                        std::span<const geometry::Vec3> points, double near_mm);

/// Meshes with the listed sheets' triangles wound the other way.
void turnSheets(std::vector<geometry::TriangleMesh>& meshes, std::span<const OpenSheet> sheets);

}  // namespace fieldpath::pathgen
