#pragma once
/// geometry's double-precision types → the float types of zbuffer (which depends on no other
/// module), shared by `simulate` and `check`.
#include <cstdint>
#include <span>
#include <vector>

#include "fieldpath/geometry/cl_file.h"
#include "fieldpath/geometry/mesh.h"
#include "fieldpath/geometry/posture.h"
#include "fieldpath/zbuffer/simulator.h"

namespace fieldpath::app {

/// Tool tips, axes (mm, world frame) and spindle angles (rad), rounded to float.
inline std::vector<zbuffer::Posture> toZbuffer(std::span<const geometry::Posture> path) {
  std::vector<zbuffer::Posture> out;
  out.reserve(path.size());
  for (const auto& p : path) {
    const geometry::CompactPosture c = geometry::compact(p);  // the spindle's cos and sin too
    out.push_back({{c.tip_mm[0], c.tip_mm[1], c.tip_mm[2]},
                   {c.axis[0], c.axis[1], c.axis[2]},
                   c.spindle_cos,
                   c.spindle_sin});
  }
  return out;
}

/// The same triangles with float vertices (mm).
inline zbuffer::ToolMesh toZbuffer(const geometry::TriangleMesh& mesh) {
  zbuffer::ToolMesh out;
  out.vertices.reserve(mesh.vertices.size());
  for (const auto& v : mesh.vertices)
    out.vertices.push_back(
        {static_cast<float>(v.x()), static_cast<float>(v.y()), static_cast<float>(v.z())});
  out.triangles.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles)
    out.triangles.push_back({static_cast<std::uint32_t>(t.x()), static_cast<std::uint32_t>(t.y()),
                             static_cast<std::uint32_t>(t.z())});
  return out;
}

}  // namespace fieldpath::app
