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

/// A plate [0, side]² × [0, t], closed, outward normals, its bottom split otherwise than its top
/// (four triangles fanned from (0.365, 0.405)·side against two), so that the faces' samples lie
/// apart: beside a face the nearest sample may be the other face's (law.h's thin-wall rule).
inline geometry::TriangleMesh plateSampledApart(double side_mm, double t_mm) {
  geometry::TriangleMesh m = box(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(side_mm, side_mm, t_mm));
  m.vertices.emplace_back(0.365 * side_mm, 0.405 * side_mm, 0.0);  // 8
  m.triangles[0] = {0, 8, 1};  // the bottom (0 1 3 2 round it), seen from below
  m.triangles[1] = {1, 8, 3};
  m.triangles.push_back({3, 8, 2});
  m.triangles.push_back({2, 8, 0});
  return m;
}

}  // namespace fieldpath::field::test
