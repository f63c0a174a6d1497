#pragma once
/// The cube field and voxel requests the voxel tests share (test_voxel.cpp,
/// test_voxel_refine.cpp).
#include <vector>

#include "fieldpath/field/voxel_field.h"
#include "meshes.h"

namespace fieldpath::field::test {

/// A 10 mm cube centred at the origin, sampled every 1 mm.
inline DirectField cubeField(const FieldParams& p) {
  const geometry::TriangleMesh cube = box(Vec3(-5, -5, -5), Vec3(5, 5, 5));
  return DirectField(sampleObstacles({&cube, 1}, 1.0, Weights::Area), p);
}

inline VoxelRequest request(double h, Interpolation interpolation = Interpolation::Trilinear,
                            StoredQuantity stored = StoredQuantity::PlaneRatio) {
  VoxelRequest r;
  r.voxel_size_mm = h;
  r.interpolation = interpolation;
  r.stored = stored;
  return r;
}

inline std::vector<Vec3> evaluate(const ForceField& field, const std::vector<Vec3>& x) {
  std::vector<Vec3> f(x.size());
  field.evaluate(x, f);
  return f;
}

}  // namespace fieldpath::field::test
