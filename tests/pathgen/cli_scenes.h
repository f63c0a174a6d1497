#pragma once
/// Scenes the command-line tests of check and generate write: a part of boxes and an obstacle.
#include <array>
#include <initializer_list>
#include <string>

#include "fieldpath/geometry/mesh_io.h"
#include "fixtures.h"
#include "run_fieldpath.h"

namespace fieldpath::pathgen::test {

/// part.stl of the boxes `part` (x0 x1 y0 y1 z0 z1, mm), far.stl of the box `far` (a scene needs an
/// obstacle: by default one far from every job here) and scene.yaml with them and a ball-end mill
/// R 3 up to 40, in `dir`.
inline void writeBoxPartScene(const fieldpath::test::TempDir& dir,
                              std::initializer_list<std::array<double, 6>> part,
                              const std::array<double, 6>& far = {-100, -90, -100, -90, -50, -40}) {
  geometry::TriangleMesh part_mesh, far_mesh;
  for (const auto& b : part) addBox(part_mesh, b[0], b[1], b[2], b[3], b[4], b[5]);
  addBox(far_mesh, far[0], far[1], far[2], far[3], far[4], far[5]);
  geometry::saveMesh(part_mesh, dir.path() / "part.stl");
  geometry::saveMesh(far_mesh, dir.path() / "far.stl");
  dir.write("scene.yaml",
            "obstacles:\n  - mesh: far.stl\npart: part.stl\n"
            "tool: { shape: ball, radius: 3, length: 40 }\n");
}

}  // namespace fieldpath::pathgen::test
