/// The float host/device rotation of the Z-buffer agrees with geometry's double reference
/// (DESIGN.md posture convention), including the poles and axes 1e-9 from them.
#include <gtest/gtest.h>

#include <random>

#include "fieldpath/geometry/posture.h"
#include "fieldpath/zbuffer/hd.h"

namespace fieldpath::zbuffer {
namespace {

TEST(PostureTwin, FloatRotationMatchesGeometryReference) {
  std::mt19937 rng(2);
  std::normal_distribution<double> n;
  std::vector<geometry::Vec3> axes = {{0, 0, 1},     {0, 0, -1}, {1e-9, 0, 1},
                                      {0, 1e-9, -1}, {1, 0, 0},  {0, 1, 1e-3}};
  for (int k = 0; k < 500; ++k) axes.push_back({n(rng), n(rng), n(rng)});
  for (const auto& a : axes) {
    const geometry::Vec3 u = a.normalized();
    const Eigen::Matrix3d ref = geometry::rotationFromZ(u);
    const Mat3f r = rotationFromZ(Vec3f{float(u.x()), float(u.y()), float(u.z())});
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        EXPECT_NEAR(r.m[i][j], ref(i, j), 2e-6) << a.transpose() << " (" << i << "," << j << ")";
  }
}

}  // namespace
}  // namespace fieldpath::zbuffer
