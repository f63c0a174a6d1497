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

constexpr double kLength = 90.0, kHeight = 45.0, kHalfGap = 20.0, kTwist = 15.0 * M_PI / 180.0;

/// The point of wall `side` (±1) at x (mm) and v (mm up the ruling from its foot), world frame.
inline Eigen::Vector3d wallPoint(double side, double x, double v) {
  const double angle = side * kTwist * (2.0 * (x + 0.5 * kLength) / kLength - 1.0);
  return Eigen::Vector3d(x, side * kHalfGap + v * std::sin(angle), v * std::cos(angle));
}

/// Unit normal of wall `side` at (x, v), towards the channel.
inline Eigen::Vector3d wallNormal(double side, double x, double v) {
  const double e = 1e-4;
  const Eigen::Vector3d du = wallPoint(side, x + e, v) - wallPoint(side, x - e, v);
  const Eigen::Vector3d dv = wallPoint(side, x, v + e) - wallPoint(side, x, v - e);
  const Eigen::Vector3d n = du.cross(dv).normalized();
  return n.y() * side > 0 ? Eigen::Vector3d(-n) : n;
}

inline geometry::TriangleMesh twistedWall(double side, double grid_mm = 3.6) {
  const int nu = static_cast<int>(std::ceil(kLength / grid_mm)),
            nv = static_cast<int>(std::ceil(kHeight / grid_mm));
  geometry::TriangleMesh m;
  for (int i = 0; i <= nu; ++i)
    for (int j = 0; j <= nv; ++j) {
      const double x = -0.5 * kLength + kLength * i / nu, v = kHeight * j / nv;
      m.vertices.push_back(wallPoint(side, x, v));  // leaning toward ±y by the twist
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
