#pragma once
/// Small closed-form meshes for the field tests.
#include "fieldpath/geometry/mesh.h"

namespace fieldpath::field::test {

/// Square [-a, a]² in the plane z = 0, normal +z (two triangles).
inline geometry::TriangleMesh squarePlane(double half_side_mm) {
  const double a = half_side_mm;
  geometry::TriangleMesh m;
  m.vertices = {{-a, -a, 0}, {a, -a, 0}, {a, a, 0}, {-a, a, 0}};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  return m;
}

/// Axis-aligned box [lo, hi], outward normals (12 triangles, CCW from outside).
inline geometry::TriangleMesh box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  geometry::TriangleMesh m;
  for (int i = 0; i < 8; ++i)
    m.vertices.emplace_back(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(),
                            i & 4 ? hi.z() : lo.z());
  m.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                 {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return m;
}

}  // namespace fieldpath::field::test
