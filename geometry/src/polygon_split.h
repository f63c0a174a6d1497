#pragma once
/// Internal to geometry/: a mesh file's polygon face split into triangles (mesh_io.cpp).
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace fieldpath::geometry {

/// The triangles of the polygon whose corners are `points` (in order, wound as the file wrote
/// it), as index triples into `points`, wound the same way. A convex polygon (CAD's quads) is the
/// fan from its first corner; a concave one (an L-shaped face of an OBJ or PLY: the fan covered the
/// notch) is cut ear by ear in its own plane. Nothing where the polygon is too large to cut
/// (over kMaxClippedCorners corners and concave) or crosses itself so that no ear is left: the
/// caller says so rather than guessing a surface.
std::optional<std::vector<Eigen::Vector3i>> splitPolygon(
    const std::vector<Eigen::Vector3d>& points);

/// A concave face of more corners than this is refused (ear clipping is quadratic in them).
inline constexpr std::size_t kMaxClippedCorners = 1024;

}  // namespace fieldpath::geometry
