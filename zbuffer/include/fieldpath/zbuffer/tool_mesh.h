#pragma once
/// Closed meshes of revolved tool profiles, generated here so that the Z-buffer (which must build
/// without the geometry module) can test mesh tools against their analytic shapes and benchmark
/// the seeds' mesh sizes (torus 25904, sphere 12482 triangles).
#include <utility>
#include <vector>

#include "fieldpath/zbuffer/simulator.h"

namespace fieldpath::zbuffer {

/// Revolves a profile of (radius, z) points (tool frame, mm, bottom to top) about +z with
/// `segments_around` segments. A point of radius 0 at either end is a pole (a fan of n
/// triangles); otherwise that end is closed by a flat polygon (n-2 triangles). Outward, CCW.
ToolMesh revolveProfile(const std::vector<std::pair<double, double>>& profile, int segments_around);

/// Mesh of an analytic tool (ball, torus or flat with its shank to L): `segments_arc` segments on
/// the quarter-circle corner, one on the shank. Ball: 2·n·(arc+1) triangles with poles at the tip
/// and the top; torus: 2·n·(arc+2) - 4; flat: 2·n·2 - 4.
ToolMesh analyticToolMesh(const Tool& tool, int segments_around, int segments_arc);

/// Upper bound (mm) of the distance from the analytic surface to the mesh of analyticToolMesh:
/// the mesh is inscribed (vertices on the surface), so it lies inside the solid, and the solid
/// shrunk by this bound lies inside the mesh.
double analyticToolMeshError(const Tool& tool, int segments_around, int segments_arc);

}  // namespace fieldpath::zbuffer
