#pragma once
/// Two twisted walls of the size of the seed's impeller channel (seed 004 §2.3: ≈5100 obstacle
/// points, 660 cm³ voxelised box): ruled sheets 90 mm long (x), 45 mm high (z), 40 mm apart
/// (y), each turned about its foot line by ±15° from one end to the other, normals facing the
/// channel. The reachable region is the box x ∈ [-55, 55], y ∈ [-30, 30], z ∈ [-10, 90].
#include <cmath>
#include <vector>

#include <Eigen/Geometry>

#include "fieldpath/geometry/mesh.h"

namespace fieldpath::bench {

inline geometry::TriangleMesh twistedWall(double side, double grid_mm = 3.6) {
  constexpr double kLength = 90.0, kHeight = 45.0, kHalfGap = 20.0, kTwist = 15.0 * M_PI / 180.0;
  const int nu = static_cast<int>(std::ceil(kLength / grid_mm)),
            nv = static_cast<int>(std::ceil(kHeight / grid_mm));
  geometry::TriangleMesh m;
  for (int i = 0; i <= nu; ++i)
    for (int j = 0; j <= nv; ++j) {
      const double x = -0.5 * kLength + kLength * i / nu, v = kHeight * j / nv;
      const double angle = side * kTwist * (2.0 * i / nu - 1.0);  // lean toward ±y
      m.vertices.emplace_back(x, side * kHalfGap + v * std::sin(angle), v * std::cos(angle));
    }
  auto id = [nv](int i, int j) { return i * (nv + 1) + j; };
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      // (x, z) grid; CCW seen from the channel side (-side·y) gives a normal toward the channel.
      if (side > 0) {
        m.triangles.emplace_back(id(i, j), id(i + 1, j), id(i + 1, j + 1));
        m.triangles.emplace_back(id(i, j), id(i + 1, j + 1), id(i, j + 1));
      } else {
        m.triangles.emplace_back(id(i, j), id(i + 1, j + 1), id(i + 1, j));
        m.triangles.emplace_back(id(i, j), id(i, j + 1), id(i + 1, j + 1));
      }
    }
  return m;
}

inline std::vector<geometry::TriangleMesh> twistedWalls() {
  return {twistedWall(+1.0), twistedWall(-1.0)};
}

inline Eigen::AlignedBox3d wallsRegion() {
  return Eigen::AlignedBox3d(Eigen::Vector3d(-55, -30, -10), Eigen::Vector3d(55, 30, 90));
}

}  // namespace fieldpath::bench
