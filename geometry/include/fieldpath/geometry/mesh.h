#pragma once
/// Indexed triangle meshes (mm). Orientation: counter-clockwise seen from outside (outward normals).
#include <vector>

#include <Eigen/Core>

namespace fieldpath::geometry {

struct TriangleMesh {
  std::vector<Eigen::Vector3d> vertices;   ///< mm
  std::vector<Eigen::Vector3i> triangles;  ///< vertex indices, CCW from outside
};

}  // namespace fieldpath::geometry
