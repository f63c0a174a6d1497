#pragma once
/// Shared test scenes for pathgen.
#include <string>

#include "fieldpath/common/errors.h"
#include "fieldpath/geometry/mesh.h"
#include "fieldpath/pathgen/impeller.h"

namespace fieldpath::pathgen::test {

/// The InputError message of `f`, or "" if it did not throw one.
template <class F>
std::string errorOf(F&& f) {
  try {
    f();
  } catch (const common::InputError& e) {
    return e.what();
  }
  return {};
}

/// A straight, flat, parallel channel 72 × 20 mm with vertical 34 mm walls: closed forms apply.
inline ImpellerParams flatChannel() {
  ImpellerParams p;
  p.bend_mm = 0;
  p.hub_rise_mm = 0;
  p.hub_dish_mm = 0;
  p.width_in_mm = p.width_out_mm = 20;
  p.lean_left_deg = {0, 0};
  p.lean_right_deg = {0, 0};
  return p;
}

/// The box [x0, x1] × [y0, y1] × [z0, z1] appended to `mesh` as a closed shell, wound outward;
/// with `y_per_z` its top leans: y moved by y_per_z (z - z0) (a fin leaning over a channel).
inline void addBox(geometry::TriangleMesh& mesh, double x0, double x1, double y0, double y1,
                   double z0, double z1, double y_per_z = 0.0) {
  const int base = static_cast<int>(mesh.vertices.size());
  for (double x : {x0, x1})
    for (double y : {y0, y1})
      for (double z : {z0, z1}) mesh.vertices.emplace_back(x, y + y_per_z * (z - z0), z);
  const int faces[12][3] = {{0, 3, 2}, {0, 1, 3}, {4, 7, 5}, {4, 6, 7}, {0, 5, 1}, {0, 4, 5},
                            {2, 7, 6}, {2, 3, 7}, {0, 6, 4}, {0, 2, 6}, {1, 7, 3}, {1, 5, 7}};
  for (const auto& f : faces) mesh.triangles.emplace_back(base + f[0], base + f[1], base + f[2]);
}

/// The box alone.
inline geometry::TriangleMesh boxMesh(double x0, double x1, double y0, double y1, double z0,
                                      double z1) {
  geometry::TriangleMesh box;
  addBox(box, x0, x1, y0, y1, z0, z1);
  return box;
}

}  // namespace fieldpath::pathgen::test
