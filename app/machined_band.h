#pragma once
/// The machined band of a path (`check`, `simulate`): the strips of the part between passes that
/// lie side by side, where a scallop is told. A pass with no neighbour beside it has none.
#include <vector>

#include <Eigen/Core>

#include "fieldpath/geometry/cl_file.h"
#include "fieldpath/geometry/posture.h"
#include "fieldpath/zbuffer/simulator.h"

namespace fieldpath::app {

/// The part's upward unit normal at plan point p (mm), from its top heights on the grid (central
/// differences of the lines either side of the nearest one; a facet's own slope on a mesh); +z
/// where the part or a neighbour line is missing.
geometry::Vec3 partNormal(const zbuffer::Grid& grid, const std::vector<float>& top,
                          const Eigen::Vector2d& p);

/// Per grid line, 1 in the machined band: between two passes' contact lines (each posture's
/// touch of the part in plan) that face each other across at most 4 R, found from every pass
/// by casting from its contact line sideways, both sides, to the nearest other contact line. It
/// depends on where the cuts are, not on how the path writes them: passes in any order, either
/// direction, or in pieces (pieces that continue one another are one line) give the same band.
/// `radius_mm` the tool's R, `corner_mm` its cutting edge's curvature radius (a ball: R); `top`
/// the part's top height per line (NaN off it).
std::vector<char> machinedBand(const zbuffer::Grid& grid, const geometry::PathFile& path,
                               double radius_mm, double corner_mm, const std::vector<float>& top);

}  // namespace fieldpath::app
